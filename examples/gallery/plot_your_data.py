"""
Your own data: CSV files to a validated Model II
================================================

A measured dataset is a folder of CSV files, one per run, each column named with its unit, and a
``dataset.toml`` manifest that gives each run's temperature and which runs are held out. Here the
"measurements" are written by a stand-in actuator with 10 % more friction than the paper's; from the
files on, everything is what you do with your own runs. The step-by-step guide, with every decision
explained, is :doc:`/your-data`; the file formats are in :doc:`/formats`.
"""

import tempfile
from pathlib import Path

import numpy as np

import thermofriction as tf

folder = Path(tempfile.mkdtemp()) / "my-stage"
folder.mkdir()

# a stand-in actuator: the paper's Model II preset with 10 % more friction
paper = tf.load_model("li2009-model-ii")
f = paper.friction
truth = tf.Model(paper.plant,
                 tf.LuGre(sigma0=f.sigma0, sigma1=f.sigma1, fc=1.1 * f.fc, sigma2=0.0),
                 paper.thermal, paper.input)
temperatures = (30.5, 34.0, 36.0, 38.0, 41.0)
rng = np.random.default_rng(7)
for T in temperatures:
    res = tf.simulate(truth, duration=0.6, temperature=T, sample_rate=5000)
    noise = 20e-9 * rng.standard_normal(res.time.size)  # a 20 nm sensor noise
    x_um = (res.displacement + noise) * 1e6
    np.savetxt(folder / f"T{T:g}C.csv", np.column_stack([res.time, res.input, x_um]),
               delimiter=",", header="time[s],voltage[V],displacement[um]",
               comments="", fmt="%.9g")

print((folder / "T30.5C.csv").read_text().splitlines()[:3])

# %%
# The manifest: each run's temperature, and 36 °C held out (inside the fitted range).
manifest = 'name = "my-stage"\n'
for T in temperatures:
    manifest += (f'\n[[experiment]]\nfile = "T{T:g}C.csv"\ntemperature = {T}\n'
                 'input = "sawtooth:amplitude=30,frequency=5,rise=0.999"\n')
    if T == 36.0:
        manifest += 'role = "validate"\n'
(folder / "dataset.toml").write_text(manifest)
print(manifest)
data = tf.load_dataset(folder)
print([(e.file, e.temperature, e.role) for e in data.experiments])

# %%
# Model II from the paper's base model (the plant's masses and input are kept; the friction is
# fitted): the friction level at the reference temperature, then a thermal term per temperature and
# the joint refinement (the direct procedure of :doc:`/identification`).
fit = tf.identify(data, method="model-ii", init="li2009-base")
print(fit.report())

# %%
# Validation, the held-out run included; the HTML report would be ``tf.report([fit], data, path)``.
metrics = tf.validate(fit.model, data)
print(metrics.table())
fig = fit.plot(data)
