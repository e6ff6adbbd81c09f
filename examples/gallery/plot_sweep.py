"""
A design sweep: step size against temperature and drive amplitude
==================================================================

``tf.sweep`` simulates a model at every point of a grid — temperatures, input fields, any parameter
by name — and returns one row of metrics per point. By default the points run on threads in this
process, one per core (``scheduler=None``), or on a Dask cluster (``scheduler="tcp://HOST:8786"``);
this page runs them in its own process (``scheduler="sequential"``), which gives the same numbers.
The command line's ``thermofriction sweep`` does the same; fleets and uncertainty propagation are in
:doc:`/scale`.
"""

import matplotlib.pyplot as plt
import numpy as np

import thermofriction as tf

temperatures = np.arange(30.0, 42.01, 1.0)
amplitudes = (15.0, 20.0, 25.0, 30.0)
grid = {"temperature": temperatures, "amplitude": amplitudes}
res = tf.sweep("li2009-model-i", grid, duration=0.6, sample_rate=2000,
               scheduler="sequential")
print(res)
print(f"{res.failed} failed points, {res.wall_time:.2f} s")

# %%
# The mean step per cycle against temperature, one curve per amplitude: friction falls as the
# contact warms, so the actuator moves further per cycle.
fig, ax = plt.subplots(figsize=(6, 4))
for a in amplitudes:
    row = res["amplitude"] == a
    ax.plot(res["temperature"][row], res["mean_step"][row] * 1e6, "o-", ms=3,
            label=f"{a:g} V")
ax.set(xlabel="temperature [C]", ylabel="mean step per cycle [um]",
       title="li2009-model-i, 5 Hz sawtooth")
ax.legend(title="amplitude")
