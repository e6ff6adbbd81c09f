"""Identifiability said (issue 40 item 5): the groups of parameters the data determine only together, with the
combination they do determine and what would separate them; and one display of an interval at a bound or
undetermined, everywhere.

The force data here are written by NumPy alone, not by the package: a static map
F = fc sign(v) (fc_neg in negative sliding) + sigma2 v + offset + white noise, in runs that slide in one direction
(v > 0 throughout) or in both. On one-direction runs a constant column (fc's) and the offset's are the same column,
so the data determine fc + offset and neither alone (the analytic reference); in both directions they are
separate, unless an asymmetry fc_neg is fitted too, whose column and fc's sum to the offset's."""

import math

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.fitting.identifiability import dependencies
from thermofriction.fitting.shown import cells, shown

FC, SIGMA2, OFFSET, NOISE = 1.604, 0.3, 0.2, 0.01


def write_static_map(folder, both, fc_neg=None, runs=2, n=800, seed=0):
    """A force dataset folder (rad, rad/s, N m) of the static map above; ``both``: the velocity changes sign."""
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    toml = ['name = "static-map"']
    for k in range(runs):
        t = np.linspace(0.0, 4.0, n)
        w = 2 * math.pi * (0.5 + 0.1 * k)
        a = 1.0 + 0.2 * k
        v = a * np.cos(w * t + 0.3) if both else a * (0.6 + 0.4 * np.cos(w * t))
        x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        level = np.where(v > 0, FC, -(FC if fc_neg is None else fc_neg))
        F = level + SIGMA2 * v + OFFSET + rng.normal(0.0, NOISE, n)
        np.savetxt(folder / f"run{k}.csv", np.column_stack([t, x, v, F]), delimiter=",", comments="", fmt="%.12g",
                   header="time[s],position[rad],velocity[rad/s],friction_torque[N*m]")
        toml += ["[[experiment]]", f'file = "run{k}.csv"', "temperature = 25.0", 'role = "fit"']
    (folder / "dataset.toml").write_text("\n".join(toml) + "\n")
    return folder


def fit(folder, parameters=("fc", "sigma2")):
    return tf.identify(tf.load_dataset(folder), method="base", friction="coulomb", parameters=list(parameters))


def test_one_direction_runs_name_the_coulomb_level_and_offset_group_with_their_sum(tmp_path):
    """One direction: fc's column is the offset's; the group {fc, sensor_offset} is named, its sum is determined
    (the analytic level fc + offset = 1.804, to within 4 of its standard errors, which are at the noise's
    sigma/sqrt(n) scale), the advice is "runs in both directions", and the offset's own error is infinite (it was a
    falsely tight 3e-4 N m around 0.0003, against a true 0.2)."""
    res = fit(write_static_map(tmp_path / "one", both=False))
    [group] = res.identifiability
    assert group["parameters"] == ["fc", "sensor_offset"]
    assert group["undetermined"] == pytest.approx({"fc": 1.0, "sensor_offset": -1.0}, abs=1e-6)
    d = group["determined"]
    assert d["combination"] == "fc + sensor_offset"
    assert 0 < d["stderr"] < 5 * NOISE / math.sqrt(1600)
    assert abs(d["value"] - (FC + OFFSET)) < 4 * d["stderr"] + 1e-4
    assert "runs in both directions" in group["separate"] and "--offset none" in group["separate"]
    assert any("'fc' and 'sensor_offset' are not determined separately" in w and "runs in both directions" in w
               for w in res.warnings)
    assert math.isinf(res.sensor_offset["stderr"])
    js = res.to_dict()
    assert js["identifiability"][0]["parameters"] == ["fc", "sensor_offset"]
    assert js["sensor_offset"]["stderr"] == "inf"


def test_both_directions_name_no_group_and_recover_the_level(tmp_path):
    """The same truth in both directions: no group, fc and the offset each determined (their 95 % intervals hold
    the truth)."""
    res = fit(write_static_map(tmp_path / "two", both=True))
    assert res.identifiability == []
    assert not any("not determined separately" in w for w in res.warnings)
    lo, hi = res.parameters["fc"].ci95
    assert lo < FC < hi
    o = res.sensor_offset
    assert abs(o["value"] - OFFSET) < 4 * o["stderr"] and o["stderr"] < 10 * NOISE / math.sqrt(1600)


def test_an_asymmetry_on_one_direction_runs_says_the_negative_side_is_never_seen(tmp_path):
    """An asymmetric truth (fc_neg = 1.9) on one-direction runs: fc_neg's column is zero (it acts only in negative
    sliding), so it is named as not identifiable with that reason, and fc with the offset as a group."""
    res = fit(write_static_map(tmp_path / "asym1", both=False, fc_neg=1.9), ("fc", "fc_neg", "sigma2"))
    assert [g["parameters"] for g in res.identifiability] == [["fc", "sensor_offset"]]
    assert any(w.startswith("'fc_neg' is not identifiable") and "never slide in the negative direction" in w
               for w in res.warnings)


def test_an_asymmetry_with_an_offset_in_both_directions_is_one_group_only_the_zero_separates(tmp_path):
    """Both directions with fc_neg fitted: the columns [v > 0], -[v < 0] and 1 are dependent (the first minus the
    second is the third), whatever the runs: the group {fc, fc_neg, sensor_offset}, moving as +1, -1, -1, and the
    advice is the sensor's zero (--offset none), not more runs in both directions."""
    res = fit(write_static_map(tmp_path / "asym2", both=True, fc_neg=1.9), ("fc", "fc_neg", "sigma2"))
    [group] = res.identifiability
    assert group["parameters"] == ["fc", "fc_neg", "sensor_offset"]
    assert group["undetermined"] == pytest.approx({"fc": 1.0, "fc_neg": -1.0, "sensor_offset": -1.0}, abs=1e-6)
    assert "--offset none" in group["separate"] and "runs in both directions" not in group["separate"]


def test_dependencies_against_two_columns_at_a_known_angle():
    """Two unit columns with cosine c have singular values sqrt(1 + c) and sqrt(1 - c) (analytic): a condition
    index sqrt((1 + c)/(1 - c)), above 30 for c = 0.999 (44.7) and a group of both; below it for c = 0.99 (14.1),
    no group; a third orthogonal column never joins."""
    def cols(c):
        e1, e2, e3 = np.eye(3)
        J = np.column_stack([e1, c * e1 + math.sqrt(1 - c * c) * e2, 5 * e3])
        _, S, Vt = np.linalg.svd(J / np.linalg.norm(J, axis=0), full_matrices=False)
        return dependencies(S, Vt)
    [(k, index, members)] = cols(0.999)
    assert index == pytest.approx(math.sqrt(1.999 / 0.001), rel=1e-9) and members == [0, 1]
    assert cols(0.99) == []


def test_one_display_for_a_bound_an_undetermined_error_and_a_huge_one():
    """The issue's numbers: an interval [1.0e-317, 1.1e+291] at a lower bound, a relative error of
    1283940585335371 %, an infinite error: each shown by words and '—', never by those numbers."""
    at = {"value": 1e-317, "stderr": 3.0, "ci95": [0.0, 1.1e291], "vary": True, "at_bound": "lower"}
    assert shown(at) == ("1e-317", "—", "at lower bound", "—")
    bounded = {"value": 0.5, "stderr": 0.2, "ci95": [0.0, 0.9], "vary": True, "at_bound": "lower"}
    assert shown(bounded)[2:] == ("at lower bound", "<= 0.9 (one-sided)")
    huge = {"value": 1e-3, "stderr": 1.283940585335371e10, "ci95": [1e-302, 1e306], "vary": True}
    assert shown(huge)[2:] == ("> 1000 %", "—")
    assert shown({"value": 1.8, "stderr": "inf", "ci95": [0.0, "inf"], "vary": True})[1:] == \
        ("—", "not determined", "—")
    assert shown({"value": 1.6, "stderr": 0.0006, "ci95": [1.6029, 1.6052], "vary": True}) == \
        ("1.6", "0.0006", "0.037 %", "[1.6029, 1.6052]")
    assert cells(at) == ("1e-317", "at lower bound", "—")
    assert cells(huge)[1:] == ("1.284e+10 (> 1000 %)", "—")
    assert cells({"value": 2.0, "stderr": 0.0, "ci95": [2.0, 2.0], "vary": False}) == ("2", "fixed", "")


def test_the_report_and_the_html_rows_use_the_one_display(tmp_path):
    """The CLI's table and the force report's parameter rows of the one-direction fit: fc 'not determined' with
    '—', no 'inf' interval; the HTML section likewise, its offset row too."""
    from thermofriction.reporting.force import _parameters_section
    res = fit(write_static_map(tmp_path / "one", both=False))
    text = res.report()
    row = next(line for line in text.splitlines() if line.strip().startswith("fc "))
    assert "not determined" in row and "inf" not in row and "—" in row
    assert "+- inf" not in text and "not determined: see the warnings" in text

    class E:
        label, fit = "coulomb", res.to_dict()
    section = _parameters_section([E()], "N m")
    assert "not determined" in section and "inf]" not in section and "[0, " not in section
