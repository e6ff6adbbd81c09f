"""The warm-up fit without a contact temperature (issue 45 item 1; docs/self-heating.md#warm-up-without-a-contact-
temperature), against independent truths (tests/warmup_truth.py: a joint with Stribeck friction whose fc and fs
follow linear laws of the contact temperature, a two-node heat path with eta = 0.8, integrated by scipy's solve_ivp
from equations written there; each run's own sensor offset, AR(1) noise of lag-1 correlation 0.7, a quantised
proxy). The issue's bounds: the heat path (per unit eta, what force data determine) and the laws within 5 %, the
contact temperature within 0.5 C at every time."""

from __future__ import annotations

import json

import numpy as np
import pytest

import thermofriction as tf
from thermofriction.identification.warm_up import identify_warm_up

from warmup_truth import (Truth, experiment, initial_model, measured, proxy_record, soak_runs, warm_up)

TRUTH = Truth()


@pytest.fixture(scope="module")
def record():
    """The truth's 25-minute warm-up from ambient, at 20 Hz."""
    return warm_up(TRUTH, duration=1500.0)


def _warm(record, rng, proxy=False, offset=0.03):
    t, v, x, T1, T2, Tp, _ = record
    F = measured(TRUTH, rng, t, v, T1, offset)
    return experiment("warm.csv", t, v, x, F, ambient=TRUTH.ambient, proxy=proxy_record(rng, Tp) if proxy else None)


def _check_path_and_laws(res):
    """The heat path per unit eta, the laws' coefficients and the constants within 5 % of the truth's."""
    p = res.parameters
    for name, true in TRUTH.per_eta().items():
        assert p[name].value == pytest.approx(true, rel=0.05), name
    for name, true in (("fc.a", TRUTH.fc_a), ("fc.b", TRUTH.fc_b), ("fs.a", TRUTH.fs_a), ("fs.b", TRUTH.fs_b),
                       ("vs", TRUTH.vs), ("sigma2", TRUTH.sigma2)):
        assert p[name].value == pytest.approx(true, rel=0.05), name


def _check_temperature(res, record, label="warm.csv", t_offset=0.0):
    """The contact temperature within 0.5 C of the truth's at every time of the trajectory (every bin edge of
    the heat balance: one a second), and its 95 % band covering the truth at most of them."""
    t, _, _, T1, *_ = record
    tr = res.details["temperature"][label]
    true = np.interp(np.asarray(tr["time"]) + t_offset, t, T1)
    assert np.max(np.abs(np.asarray(tr["contact"]) - true)) < 0.5
    covered = np.mean((np.asarray(tr["lower"]) <= true) & (true <= np.asarray(tr["upper"])))
    assert covered > 0.8
    return tr


def test_soak_calibrated_laws_recover_a_two_node_heat_path_and_the_contact_temperature(record):
    """Soak runs at 25-55 C calibrate the laws; the warm-up record (ambient only) gives the heat path: two nodes
    chosen (the truth has two), each value within 5 %, the temperature within 0.5 C."""
    rng = np.random.default_rng(1)
    res = identify_warm_up([_warm(record, rng)] + soak_runs(TRUTH, rng), initial_model(TRUTH))
    assert res.details["heat_path"]["nodes"] == 2
    assert res.details["heat_path"]["scale"].startswith("soak runs at 4")
    _check_path_and_laws(res)
    _check_temperature(res, record)
    assert res.adequate is not False
    assert not any("poorly determined" in w or "What record would" in w for w in res.warnings)
    d = json.loads(res.to_json())
    assert d["method"] == "warm-up" and d["details"]["heat_path"]["nodes"] == 2
    assert d["parameters"]["R_th"]["ci95"][0] < d["parameters"]["R_th"]["value"] < d["parameters"]["R_th"]["ci95"][1]


def test_a_lagging_proxy_alone_sets_the_scale_and_is_found_on_the_housing(record):
    """No soak run: a housing sensor lagging by 40 s (quantised to 0.1 C) fixes the scale; the fit finds which
    node it follows and its lag, the heat path and laws within 5 %, the temperature within 0.5 C."""
    rng = np.random.default_rng(2)
    res = identify_warm_up([_warm(record, rng, proxy=True)], initial_model(TRUTH))
    hp = res.details["heat_path"]
    assert hp["nodes"] == 2 and hp["proxy"]["node"] == "housing"
    assert res.parameters["tau_p"].value == pytest.approx(TRUTH.tau_p, rel=0.05)
    _check_path_and_laws(res)
    _check_temperature(res, record)


def test_one_node_where_two_are_needed_is_not_called_adequate(record):
    """Held at one node on the two-node truth, the fit says it is not adequate (the second node lowers AICc by far
    more than the threshold) and never claims adequacy."""
    rng = np.random.default_rng(3)
    res = identify_warm_up([_warm(record, rng)] + soak_runs(TRUTH, rng), initial_model(TRUTH), nodes=1)
    assert res.details["heat_path"]["nodes"] == 1
    assert res.adequate is False
    assert res.warnings[0].startswith("the fit is not adequate: one node cannot follow")
    assert res.details["heat_path"]["choice"]["delta"] > res.details["heat_path"]["choice"]["threshold"]


def test_a_one_node_truth_keeps_one_node():
    """On a one-node truth (the contact alone, R = R1 + R2 to ambient), the second node does not lower AICc by the
    threshold and is not kept: the rule does not call for a node the data do not show; the one-node path within
    5 % and the temperature within 0.5 C."""
    rng = np.random.default_rng(21)
    t, v, x, T1, _, _, _ = rec = warm_up(TRUTH, duration=1500.0, two_nodes=False)
    F = measured(TRUTH, rng, t, v, T1, 0.03)
    exp = experiment("warm.csv", t, v, x, F, ambient=TRUTH.ambient)
    res = identify_warm_up([exp] + soak_runs(TRUTH, rng), initial_model(TRUTH))
    hp = res.details["heat_path"]
    assert hp["nodes"] == 1 and hp["choice"]["delta"] < hp["choice"]["threshold"]
    assert res.parameters["R_th"].value == pytest.approx(TRUTH.eta * (TRUTH.R1 + TRUTH.R2), rel=0.05)
    assert res.parameters["C_th"].value == pytest.approx(TRUTH.C1 / TRUTH.eta, rel=0.05)
    _check_temperature(res, rec)


def _true_time_constants():
    """The truth's two-node time constants [s], from its equations' matrix (independent of the package)."""
    C1, R1, C2, R2 = TRUTH.C1, TRUTH.R1, TRUTH.C2, TRUTH.R2
    A = np.array([[-1 / (R1 * C1), 1 / (R1 * C1)], [1 / (R1 * C2), -1 / (R1 * C2) - 1 / (R2 * C2)]])
    return sorted(-1 / np.linalg.eigvals(A).real)


@pytest.mark.parametrize("soak_at", [(), (40.0,)])
def test_without_soak_runs_at_two_temperatures_or_a_proxy_the_scale_is_undetermined(record, soak_at):
    """Neither soak runs at two temperatures nor a proxy: the heat path's gains and capacities, the laws'
    coefficients and the temperature are said to be undetermined, none as a number (in the result, its JSON and
    its report); the scale-free time constants are given, each within twice its 95 % half-width of the truth's
    (about four standard errors) and determined to 15 % or better."""
    rng = np.random.default_rng(4)
    soak = soak_runs(TRUTH, rng, temperatures=soak_at) if soak_at else []
    res = identify_warm_up([_warm(record, rng)] + soak, initial_model(TRUTH))
    assert res.details["temperature"] == "undetermined"
    hp = res.details["heat_path"]
    assert hp["scale"] == "undetermined" and hp["R_th"] == "undetermined" and hp["C_th"] == "undetermined"
    for name in ("C_th", "R_th", "C_2", "R_2", "T_0", "fc.a", "fc.b", "fs.a", "fs.b"):
        assert name not in res.parameters
    assert res.warnings[0].startswith("the temperature scale is undetermined")
    d = json.loads(res.to_json())
    assert d["details"]["temperature"] == "undetermined" and "R_th" not in d["parameters"]
    assert "undetermined" in res.report()
    for tc, true in zip(hp["time_constants"], _true_time_constants()):
        assert tc["ci95_half_width"] < 0.15 * tc["value"]
        assert abs(tc["value"] - true) < 2 * tc["ci95_half_width"]


def test_a_record_that_continues_another_starts_where_that_one_ended(record, tmp_path):
    """The warm-up split into two files, the second marked ``continues`` in the manifest, its clock from zero:
    loaded from disk and fitted through tf.identify(method="warm-up"), the second record's trajectory starts at
    the first's end (not at ambient) and follows the truth within 0.5 C throughout."""
    rng = np.random.default_rng(5)
    t, v, x, T1, T2, Tp, _ = record
    cut = 14000  # 700 s
    F = measured(TRUTH, rng, t, v, T1, 0.0)
    P = proxy_record(rng, Tp)
    for name, sl, off in (("a.csv", slice(0, cut), 0.03), ("b.csv", slice(cut, None), -0.02)):
        tt = t[sl] - t[sl][0]
        cols = np.column_stack([tt, x[sl], v[sl], F[sl] + off, np.full(tt.size, TRUTH.ambient), P[sl]])
        np.savetxt(tmp_path / name, cols, delimiter=",", comments="",
                   header="time[s],position[rad],velocity[rad/s],friction_torque[N*m],ambient_temperature[C],"
                          "proxy_temperature[C]")
    (tmp_path / "dataset.toml").write_text('name = "joint"\n[[experiment]]\nfile = "a.csv"\n'
                                           '[[experiment]]\nfile = "b.csv"\ncontinues = "a.csv"\n')
    data = tf.load_dataset(tmp_path)
    assert [e.warm_up for e in data.experiments] == [True, True] and data.experiments[1].continues == "a.csv"
    res = tf.identify(data, method="warm-up", init=initial_model(TRUTH))
    assert "T_0" in res.parameters and not any(n.startswith("T_0[") for n in res.parameters)
    a = _check_temperature(res, record, "a.csv")
    b = _check_temperature(res, record, "b.csv", t_offset=t[cut])
    assert b["contact"][0] == pytest.approx(a["contact"][-1], abs=0.05)
    assert b["contact"][0] - TRUTH.ambient > 10.0


def test_a_short_warm_up_says_what_it_cannot_separate_and_what_record_would(record):
    """The first minute of the warm-up (the slow node's time constant is 8 minutes, the proxy's lag 40 s) with the
    proxy: the values the data leave loose are said, with the record that would determine them (a longer warm-up,
    more speeds, soak runs); the full record's fit (test above) says none of this."""
    rng = np.random.default_rng(8)
    t, v, x, T1, T2, Tp, _ = record
    n = 1200
    F = measured(TRUTH, rng, t[:n], v[:n], T1[:n], 0.03)
    exp = experiment("short.csv", t[:n], v[:n], x[:n], F, ambient=TRUTH.ambient, proxy=proxy_record(rng, Tp[:n]))
    res = identify_warm_up([exp], initial_model(TRUTH))
    assert any("is poorly determined by these data" in w for w in res.warnings)
    said = [w for w in res.warnings if "What record would: a longer warm-up" in w]
    assert len(said) == 1 and "at two speeds or more" in said[0] and "a proxy temperature" not in said[0]


def test_without_laws_the_soak_runs_give_them_first(record):
    """An initial model without laws (a plain Stribeck map): tf.identify fits Model I on the soak runs first (law
    kinds chosen by AICc), then the warm-up; the laws of fc and fs and the heat path within 5 % of the truth's."""
    rng = np.random.default_rng(1)
    data = tf.Dataset(experiments=[_warm(record, rng)] + soak_runs(TRUTH, rng))
    init = tf.Model(plant=tf.PrescribedMotion(motion="rotary"),
                    friction=tf.Stribeck(fc=1.0, fs=1.4, vs=0.1, sigma2=0.2, v_smooth=TRUTH.v_smooth))
    res = tf.identify(data, method="warm-up", init=init)
    assert res.model.laws["fc"].kind == res.model.laws["fs"].kind == "linear"
    for name, true in list(TRUTH.per_eta().items()) + [("fc.a", TRUTH.fc_a), ("fc.b", TRUTH.fc_b),
                                                       ("fs.a", TRUTH.fs_a), ("fs.b", TRUTH.fs_b)]:
        assert res.parameters[name].value == pytest.approx(true, rel=0.05), name
    assert not any("heat path are not separated" in w for w in res.warnings)


def test_warm_up_records_are_refused_by_the_other_methods(record):
    """A warm-up record has no contact temperature: Model I (or any other method) refuses it by name."""
    rng = np.random.default_rng(6)
    data = tf.Dataset(experiments=[_warm(record, rng)])
    with pytest.raises(tf.InputError, match="warm.csv is a warm-up record.*method 'warm-up'"):
        tf.identify(data, method="model-i", init=initial_model(TRUTH))


def test_the_warm_up_needs_laws_to_start_from(record):
    """Without laws in the initial model and without soak runs at two temperatures, one message says what to give."""
    rng = np.random.default_rng(7)
    data = tf.Dataset(experiments=[_warm(record, rng)])
    base = tf.Model(plant=tf.PrescribedMotion(motion="rotary"), friction=tf.Stribeck(fc=0.9, fs=1.3, vs=0.08))
    with pytest.raises(tf.InputError, match="soak runs at two temperatures or more"):
        tf.identify(data, method="warm-up", init=base)
