"""
The paper's workflow: synthesise, identify Model I, validate
============================================================

What ``thermofriction demo`` does, in Python and at a smaller size: a dataset is simulated from the
paper's actuator (the ``li2009-model-i`` preset) at four temperatures with a displacement sensor's
noise, Model I is identified from a plain LuGre start at 30 °C (the ``li2009-base`` preset), and the
fitted model is validated on a temperature held out of the fit. The models are those of Li et al.
(Rev. Sci. Instrum. 80, 045104, 2009): see :doc:`/models` and :doc:`/identification`.
"""

import thermofriction as tf

truth = tf.load_model("li2009-model-i")
data = tf.synthesize(truth, [30.8, 35.7, 38.4, 41.5], validate=[33.0],
                     duration=0.6, sample_rate=5000, noise=20e-9, seed=1,
                     name="paper-workflow")
for e in data.experiments:
    print(f"{e.file:18s} {e.temperature:5.1f} C  {e.role:8s} "
          f"{e.duration:.1f} s at {e.sample_rate:.0f} Hz")

# %%
# Identify Model I: per-temperature LuGre fits, a law through each parameter's estimates (chosen by
# AICc), then a joint refinement of the laws on all fit experiments.
fit = tf.identify(data, method="model-i", init="li2009-base")
print(fit.report())


# %%
# The fitted model against the measurements: measured and predicted displacement, the residuals,
# and the fitted laws with each temperature's 95 % interval.
fig = fit.plot(data)

# %%
# Validation on every experiment, the held-out 33 °C one included (metrics of :doc:`/formats`).
metrics = tf.validate(fit.model, data)
print(metrics.table())
fig = metrics.plot()
