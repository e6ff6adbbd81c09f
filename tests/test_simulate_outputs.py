"""The outputs of a simulation as one block: the C binding writes either a row per sample (C order)
or a contiguous column per output (Fortran order, what ``simulate`` uses, so that the result's
fields are views and no array is copied); both must carry the same numbers, the joined period
starts must go, and a non-finite output must still be named at its earliest time."""

from __future__ import annotations

import numpy as np
import pytest

import thermofriction as tf
from thermofriction import _bridge
from thermofriction.simulation import _Grid, _pack

T_C = 35.7


@pytest.fixture(scope="module")
def model():
    return tf.load_model("li2009-model-i")


def test_c_and_fortran_layouts_write_identical_numbers(model):
    """The same run written both ways: bit-identical (the layout must not touch the numerics)."""
    t = np.arange(4001) / 10_000.0
    spec = _bridge.model_spec(model, T_C, model.input)
    n = _bridge.n_outputs(model, False)
    rows, cols = np.empty((t.size, n)), np.empty((n, t.size)).T
    _bridge.run(spec, t, rows)
    _bridge.run(spec, t, cols)
    assert cols.flags.f_contiguous and not cols.flags.c_contiguous
    np.testing.assert_array_equal(rows, cols)
    with pytest.raises(ValueError, match="contiguous float64 array of shape"):
        _bridge.run(spec, t, np.empty((t.size, 2 * n))[:, ::2])  # strided: neither layout


def test_result_fields_are_contiguous_views_of_one_block(model):
    res = tf.simulate(model, 0.05, temperature=T_C)
    fields = [res.time, res.input, res.displacement, res.velocity, res.friction_force, res.temperature,
              res.states[:, 0]]
    assert all(f.flags.c_contiguous for f in fields)
    block = res.displacement.base
    assert block is not None and all(f.base is block for f in fields[:-1])
    # still independent arrays to the user: writing one field leaves the others alone
    before = res.velocity.copy()
    res.displacement[:] = 0.0
    np.testing.assert_array_equal(res.velocity, before)


def test_joined_period_starts_are_removed(model):
    """A 3 Hz input on a 1 kHz grid: its period starts (k/3 s) are joined to the grid and removed again.
    The same run on the joined grid itself (t_eval) must agree on every requested row, exactly, and
    the step sizes are the displacement differences at the period starts."""
    wave = tf.Sawtooth(amplitude=30.0, frequency=3.0, rise=0.999)
    res = tf.simulate(model, 1.0, temperature=T_C, input=wave, sample_rate=1000.0)
    grid = _Grid(np.arange(1001) / 1000.0, 1 / 3.0)
    assert grid.extra.size == 2  # 1/3 and 2/3 s are not on the grid
    joined = tf.simulate(model, temperature=T_C, input=wave, t_eval=grid.times)
    keep = ~np.isin(grid.times, grid.extra)
    np.testing.assert_array_equal(res.time, grid.requested)
    for name in ("input", "displacement", "velocity", "friction_force"):
        np.testing.assert_array_equal(getattr(res, name), getattr(joined, name)[keep])
    x_at = np.interp(grid.cycle_times, joined.time, joined.displacement)  # exact: the times are on its grid
    np.testing.assert_array_equal(res.step_sizes, np.diff(x_at))
    assert res.displacement.flags.c_contiguous


def test_non_finite_output_named_at_its_earliest_time(model):
    grid = _Grid(np.arange(11) / 10.0, None)
    n = _bridge.n_outputs(model, False)
    out = np.zeros((n, grid.times.size)).T
    out[:, _bridge.OUTPUT_COLUMN["temperature"]] = np.nan  # NaN by design without a thermal part: allowed
    out[7, _bridge.OUTPUT_COLUMN["input"]] = np.inf
    out[3, _bridge.OUTPUT_COLUMN["friction_force"]] = np.nan
    with pytest.raises(tf.SolverError, match=r"the output 'friction_force' is not finite at t = 0\.3 s"):
        _pack(model, out, grid, {}, T_C, None, False, None)
