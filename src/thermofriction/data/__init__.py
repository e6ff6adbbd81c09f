"""Measured data (docs/formats.md#datasets): experiment CSV files with units in their headers, dataset folders with
a ``dataset.toml`` manifest, and synthetic datasets with realistic sensor effects.

    data = tf.load_dataset("data/")            # checks everything; one clear InputError otherwise
    data.fit, data.validate                     # experiments by role
    data = tf.synthesize(model, [30.8, 35.7, 41.5], validate=[33.0], noise=20e-9, seed=1)
    tf.save_dataset(data, "data/")
"""

from .csv import read_experiment_csv
from .experiments import (MAX_ROWS, MAX_ROWS_ENV, MIN_SAMPLES, REQUIRED, ROLES, SAMPLING_TOLERANCE, TEMPERATURE_RANGE,
                          TEMPERATURE_VARIES, Dataset, Experiment, max_rows)
from .files import load_dataset
from .save import save_dataset
from .matlab import read_experiment_mat
from .synth import synthesize

__all__ = ["Experiment", "Dataset", "read_experiment_csv", "read_experiment_mat", "load_dataset", "save_dataset", "synthesize",
           "max_rows", "MAX_ROWS", "MAX_ROWS_ENV", "MIN_SAMPLES", "REQUIRED", "ROLES",
           "SAMPLING_TOLERANCE", "TEMPERATURE_RANGE", "TEMPERATURE_VARIES"]
