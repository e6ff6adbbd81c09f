"""
Friction from measured torque: a robot joint
============================================

A tribometer, a load-cell stage or a joint with a torque sensor imposes a motion and records the
friction. Such data are fitted with a prescribed-motion model: the measured motion drives the
friction model and nothing else. Here a "measured" joint is made with a LuGre model in rotary units
(N m, rad) and a torque sensor's offset and noise; the files are then identified from a start that
names only the plant and the friction model (the starting values come from the data). The guide is
:doc:`/force-data`.
"""

import tempfile
from pathlib import Path

import numpy as np
import matplotlib.pyplot as plt

import thermofriction as tf

folder = Path(tempfile.mkdtemp()) / "joint"
folder.mkdir()
joint = tf.Model(tf.PrescribedMotion(motion="rotary"),
                 tf.LuGre(sigma0=3000.0, sigma1=0.3, fc=0.9, fs=1.4, vs=0.3, sigma2=0.35))
rng = np.random.default_rng(3)
motion = tf.Sine(amplitude=0.5, frequency=0.5)          # +-0.5 rad at 0.5 Hz
for name in ("run0.csv", "run1-validate.csv"):
    res = tf.simulate(joint, input=motion, duration=2.0, sample_rate=1000)
    noise = 0.01 * rng.standard_normal(res.time.size)
    torque = res.friction_force + 0.05 + noise  # the sensor's offset and noise
    np.savetxt(folder / name, np.column_stack([res.time, res.displacement, torque]),
               delimiter=",", header="time[s],position[rad],friction_torque[N*m]",
               comments="", fmt="%.10g")
(folder / "dataset.toml").write_text("""name = "joint"

[[experiment]]
file = "run0.csv"
temperature = 35.0

[[experiment]]
file = "run1-validate.csv"
temperature = 35.0
role = "validate"
""")
# the initial model: only the plant and the friction model, no values
(folder / "joint.toml").write_text("""[plant]
type = "prescribed"
motion = "rotary"

[friction]
model = "lugre"
""")

# %%
# Identify LuGre (six parameters and the sensor's offset) on the fit run.
data = tf.load_dataset(folder)
fit = tf.identify(data, "base", init=folder / "joint.toml")
print(fit.report())

# %%
# The held-out run: measured and predicted torque against the position (the friction loop, with
# presliding after each reversal).
metrics = tf.validate(fit.model, data)
print(metrics.table())
pred = metrics.predictions[1]
exp = data.experiments[1]
fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(exp.displacement, pred.measured, ".", ms=1.5, color="0.6",
        label="measured")
ax.plot(exp.displacement, pred.predicted, lw=1.2, label="fitted LuGre")
ax.set(xlabel="position [rad]", ylabel="friction torque [N m]", title="held-out run")
ax.legend()
