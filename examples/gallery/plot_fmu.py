"""
An FMU for Simulink, OpenModelica or fmpy
=========================================

``tf.export_fmu`` writes any model as an FMI 2.0 co-simulation FMU: voltage and temperature in;
displacement, velocity and friction force out; every parameter tunable. Here the Model I preset is
exported and run by `fmpy <https://github.com/CATIA-Systems/FMPy>`_ under a temperature ramp from 30
to 41.5 °C, next to ``tf.simulate`` on the same signals. The FMU's interface and integrators are in
:doc:`/fmu`.
"""

import tempfile
from pathlib import Path

import fmpy
import matplotlib.pyplot as plt
import numpy as np

import thermofriction as tf

path = Path(tempfile.mkdtemp()) / "li2009-model-i.fmu"
tf.export_fmu("li2009-model-i", path)
md = fmpy.read_model_description(path)
for causality in ("input", "output"):
    print(causality, [v.name for v in md.modelVariables if v.causality == causality])

# %%
# One second under the paper's sawtooth, with the temperature rising by 11.5 °C.
duration, interval = 1.0, 1e-5
t = np.linspace(0.0, duration, int(round(duration / interval)) + 1)
saw = tf.Sawtooth(amplitude=30.0, frequency=5.0, rise=0.999)
T = 30.0 + 11.5 * t
signal = np.array(list(zip(t, saw(t), T)),
                  dtype=[("time", float), ("voltage", float), ("temperature", float)])
out = fmpy.simulate_fmu(str(path), stop_time=duration, output_interval=interval,
                        input=signal, output=["displacement", "friction_force"])

ref = tf.simulate(tf.load_model("li2009-model-i"), duration, temperature=(t, T),
                  input=saw, sample_rate=1 / interval)
fmu_x = np.interp(ref.time, out["time"], out["displacement"])
gap = np.max(np.abs(fmu_x - ref.displacement))
print(f"largest gap, FMU against tf.simulate: {gap * 1e9:.1f} nm "
      f"of a {np.ptp(ref.displacement) * 1e6:.2f} um range")

fig, ax = plt.subplots(figsize=(7, 3.5))
ax.plot(out["time"], out["displacement"] * 1e6, label="FMU (fmpy)")
ax.plot(ref.time, ref.displacement * 1e6, "--", label="tf.simulate")
ax.set(xlabel="time [s]", ylabel="displacement [um]",
       title="li2009-model-i, 30 -> 41.5 C")
ax.legend()
