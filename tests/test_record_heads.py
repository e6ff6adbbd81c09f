"""Model I's first fit from the initial model on the records' first periods (identification/model_i.py,
_PerTemperature.from_heads, data/experiments.py first_periods; issue 42): what is cut, where it applies, and that the fit on the whole records then ends where it
ends without it. The data: truths integrated by SciPy through tests/reference (benchmarks/study_cost.py), not by
the package."""

import math
import sys
from pathlib import Path

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.data.experiments import first_periods
from thermofriction.identification import model_i

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import study_cost as S  # noqa: E402


def heads(experiments, input):
    """What Model I's first fit runs on."""
    return first_periods(experiments, model_i.HEAD_PERIODS, model_i.HEAD_MIN_PERIODS, input)


def _experiment(duration, rate=5000.0, input=S.SAW):
    t = np.arange(round(duration * rate) + 1) / rate
    return tf.Experiment(file="a.csv", time=t, voltage=np.sin(t), displacement=np.cos(t), temperature=35.0,
                         temperature_signal=35.0 + 0 * t, input=input)


def test_the_heads_are_the_first_two_periods_of_every_column():
    """A 2 s record of the 5 Hz sawtooth: every sampled column cut to t <= 0.4 s (two periods), the same values."""
    e = _experiment(2.0)
    (h,) = heads([e], S.SAW)
    n = int(np.sum(e.time <= 2 * S.SAW.period + 1e-12))
    assert n == 2001
    for column in ("time", "voltage", "displacement", "temperature_signal"):
        assert np.array_equal(getattr(h, column), getattr(e, column)[:n])
    assert h.temperature == e.temperature and h.file == e.file


def test_no_heads_on_short_records_or_an_input_without_a_period():
    """Fewer than HEAD_MIN_PERIODS periods in any record of the temperature, or a sampled input: None."""
    short = _experiment(model_i.HEAD_MIN_PERIODS * S.SAW.period * 0.95)
    assert heads([_experiment(2.0), short], S.SAW) is None
    sampled = _experiment(2.0, input=tf.Sampled(np.array([0.0, 2.0]), np.array([0.0, 1.0])))
    assert heads([sampled], None) is None


@pytest.mark.slow
def test_a_fit_with_heads_ends_where_the_fit_without_them_ends(monkeypatch):
    """A Model I truth of benchmarks/study_cost.py (seed 1; 5 temperatures x 2 s at 5 kHz, 10 periods) from its
    start 2-3x off, identified with the first fit on the heads and without (HEAD_MIN_PERIODS beyond the records):
    both adequate, every law value at the fit temperatures within 0.5 standard errors of the other fit's (each fit
    stops within SMALL_STEP, 0.2 standard errors, of the optimum)."""
    truth, temps, start, opts = S.case("model-i", 1, False)
    data = S.dataset(truth, temps, 2.0, 5000.0, 1)
    assert heads(data.fit[:1], start.input) is not None  # the records are long enough for the heads
    with_heads = tf.identify(data, init=start, **opts)
    monkeypatch.setattr(model_i, "HEAD_MIN_PERIODS", math.inf)
    without = tf.identify(data, init=start, **opts)
    assert with_heads.adequate and without.adequate
    for name in ("sigma0", "sigma1", "fc"):
        a, lo, hi = with_heads.law_interval(name, temps)
        b = without.law_interval(name, temps)[0]
        standard_error = np.where(b < a, a - lo, hi - a) / 1.96  # on the other fit's side (exp laws: asymmetric)
        assert np.all(np.abs(a - b) <= 0.5 * standard_error), (name, a, b, standard_error)
