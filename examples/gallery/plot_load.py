"""
Friction of load and temperature: a joint under several payloads
================================================================

A robot joint's friction grows with the load torque it carries and falls as its grease warms. Here a joint is
"measured" at three load torques and three temperatures (a LuGre joint whose Coulomb level is a product of a
temperature law and the load, its static level a sum; a torque sensor's offset, re-zeroed between runs, and its
noise), with a ``load_torque[N*m]`` column in every file, and one run held out at a load beyond the fitted ones.
The initial model gives each law a temperature kind and a first, wrong form along the load; ``identify`` fits
each condition, the laws through them, chooses the forms and refines them on all runs. The guide is
:doc:`/force-data` (section 7) and :doc:`/identification`.
"""

import tempfile
from pathlib import Path

import numpy as np

import thermofriction as tf

folder = Path(tempfile.mkdtemp()) / "joint-loads"
folder.mkdir()
rng = np.random.default_rng(7)


def fc(T, L):
    return (0.9 - 0.004 * T) * (1 + 0.015 * L)        # a product with the load [N m]


def fs(T, L):
    return 1.4 - 0.006 * T + 0.02 * L                  # a sum [N m]


conditions = [(T, L, "fit") for T in (20.0, 35.0, 50.0) for L in (5.0, 15.0, 25.0)] + [(35.0, 32.0, "validate")]
entries = []
for k, (T, L, role) in enumerate(conditions):
    joint = tf.Model(tf.PrescribedMotion(motion="rotary"),
                     tf.LuGre(sigma0=3000.0, sigma1=0.3, sigma2=0.35, vs=0.3, fc=fc(T, L), fs=fs(T, L)))
    res = tf.simulate(joint, input=tf.Sine(amplitude=0.5, frequency=0.5), duration=4.0, sample_rate=250)
    torque = res.friction_force + rng.uniform(-0.05, 0.05) + 0.01 * rng.standard_normal(res.time.size)
    np.savetxt(folder / f"run{k}.csv", np.column_stack([res.time, res.displacement, torque,
                                                        np.full(res.time.size, L)]),
               delimiter=",", header="time[s],position[rad],friction_torque[N*m],load_torque[N*m]",
               comments="", fmt="%.10g")
    entries.append(f'[[experiment]]\nfile = "run{k}.csv"\ntemperature = {T}\nrole = "{role}"\n')
(folder / "dataset.toml").write_text('name = "joint-loads"\n\n' + "\n".join(entries))
# the start: fc's form along the load a sum (the truth: a product), fs's proportional (the truth: a sum)
(folder / "start.toml").write_text("""[plant]
type = "prescribed"
motion = "rotary"

[friction]
model = "lugre"
sigma0 = 3000.0
sigma1 = 0.3
sigma2 = 0.3
vs = 0.3

[thermal]
model = "I"
fc = { law = "linear", a = -0.002, b = 0.7, load = { law = "affine", k = 0.01, combine = "sum" } }
fs = { law = "linear", a = -0.0001, b = 0.08, load = { law = "proportional" } }
""")

# %%
# Identify the laws (and sigma2) with one offset per run; the report says the forms chosen, each law's equation
# and the per-condition estimates the laws went through.
data = tf.load_dataset(folder)
fit = tf.identify(data, init=folder / "start.toml", parameters=["sigma2"], offset="per-experiment")
print(fit.report())

# %%
# Each run predicted at its own temperature and load; the held-out run at 32 N m lies beyond the fitted 5-25 N m,
# and validation says so.
metrics = tf.validate(fit.model, data)
print(metrics.table())
print("\n".join(metrics.warnings))

# %%
# The laws over the load at each fit temperature, with their 95 % bands and the per-condition estimates.
fig = fit.plot()
