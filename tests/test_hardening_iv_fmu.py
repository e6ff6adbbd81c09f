"""Issue 41 (the FMU): the FMI 2.0 and 3.0 wrappers (core/fmu/fmi2_cs.c, fmi3_cs.c around fmu_common.c) against
the standards' state machines, with fmpy's low-level FMU2Slave / FMU3Slave as the importer. A step past a
defined stop time answered OK; fmi2Terminate / fmi3Terminate were taken in every mode; fmi2SetFMUstate /
fmi3SetFMUState carried the state machine's mode with the values, so a terminated instance stepped and took
parameters again after restoring a state, and a state from before the initialization put an initialized
instance back into initialization mode (where a fixed step size is settable and fmi3DoStep refused). Each
case: fmi2Error / fmi3Error with a logged message naming the call, the instance unchanged (docs/fmu.md)."""

from __future__ import annotations

import ctypes

import pytest

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402
from fmpy.fmi3 import FMU3Slave  # noqa: E402

from thermofriction.fmu import binary_path, export_fmu  # noqa: E402

pytestmark = pytest.mark.skipif(not binary_path().is_file(), reason="no FMU binary (Linux x86-64 only)")

ERROR = 3


class Instance:
    """One instance of an exported FMU (FMI 2 or 3) through fmpy's low-level calls, its log kept. The
    calls common to both standards have one name here; ``refused`` checks a call's clean refusal."""

    def __init__(self, tmp_path, fmi, **export):
        path = tmp_path / f"m{fmi}.fmu"
        if not path.exists():
            export_fmu("li2009-model-i", path, fmi=fmi, **export)
        self.fmi = fmi
        self.md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        # a folder of its own: extracting over a loaded binary would change the code under a running instance
        unzipped = extract(str(path), unzipdir=str(tmp_path / f"x{fmi}-{len(list(tmp_path.glob('x*')))}"))
        self.messages = []
        identifier = self.md.coSimulation.modelIdentifier
        if fmi == 2:
            self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier=identifier,
                                 instanceName="h41")
            self.cb = fmi2CallbackFunctions()
            self.cb.logger = fmi2CallbackLoggerTYPE(lambda c, i, s, cat, m: self.messages.append((s, m.decode())))
            self.cb.allocateMemory, self.cb.freeMemory = defaultCallbacks.allocateMemory, defaultCallbacks.freeMemory
            self.fmu.instantiate(callbacks=self.cb, loggingOn=True)
        else:
            self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=unzipped, modelIdentifier=identifier,
                                 instanceName="h41")
            self.fmu.instantiate(loggingOn=True, logMessage=lambda env, s, cat, m: self.messages.append((s, m.decode())))

    def initialize(self, start=0.0, stop=None, exit=True):
        if self.fmi == 2:
            self.fmu.setupExperiment(startTime=start, stopTime=stop)
        self.fmu.enterInitializationMode(**({} if self.fmi == 2 else {"startTime": start, "stopTime": stop}))
        if exit:
            self.fmu.exitInitializationMode()

    def get(self, *names):
        vrs = [self.vr[n] for n in names]
        return list(self.fmu.getReal(vrs) if self.fmi == 2 else self.fmu.getFloat64(vrs))

    def set(self, name, value):
        (self.fmu.setReal if self.fmi == 2 else self.fmu.setFloat64)([self.vr[name]], [float(value)])

    def time(self):
        return self.fmu.getRealStatus(2) if self.fmi == 2 else self.get("time")[0]  # 2: fmi2LastSuccessfulTime

    def get_state(self):
        return self.fmu.getFMUstate() if self.fmi == 2 else self.fmu.getFMUState()

    def set_state(self, state):
        (self.fmu.setFMUstate if self.fmi == 2 else self.fmu.setFMUState)(state)

    def refused(self, call, *words):
        """``call`` raises (the FMU answered Error) and the last message logged is an error naming the
        standard's function (fmi2... or fmi3...) and each of ``words``."""
        before = len(self.messages)
        with pytest.raises(Exception):
            call()
        assert len(self.messages) > before, "an error without a logged message"
        status, message = self.messages[-1]
        assert status == ERROR and message.startswith(f"fmi{self.fmi}"), message
        for word in words:
            assert word in message, message
        return message

    def outputs(self):
        return self.get("displacement", "velocity", "friction_force")

    def close(self):
        self.fmu.freeInstance()


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_step_past_the_stop_time_is_refused(fmi, tmp_path):
    """With a stop time defined (fmi2SetupExperiment / fmi3EnterInitializationMode), a step ending past it
    answered OK. The standards require an error: refused with a message naming the stop time, the time and
    the outputs unchanged; a last step within rounding of the stop time (0.1 s three times to a stop of
    0.3 s, as an importer's grid gives) is taken; without a stop time, and after a reset, steps go on."""
    run = Instance(tmp_path, fmi)
    run.initialize(stop=2e-4)
    run.set("voltage", 10.0)
    run.fmu.doStep(0.0, 1e-4)
    before = run.outputs()
    run.refused(lambda: run.fmu.doStep(1e-4, 2e-4), "DoStep", "stop time", "0.00020000000000000001")
    assert run.time() == pytest.approx(1e-4, rel=1e-15) and run.outputs() == before
    run.fmu.doStep(1e-4, 1e-4)  # ends on the stop time: taken
    run.refused(lambda: run.fmu.doStep(2e-4, 1e-9), "stop time")  # even the smallest step past it
    assert run.time() == pytest.approx(2e-4, rel=1e-15)

    run.fmu.reset()  # the stop time goes with the experiment
    run.initialize(stop=0.3)
    for k in range(3):
        run.fmu.doStep(k * 0.1, 0.1)
    assert run.time() == 0.1 + 0.1 + 0.1 > 0.3
    run.fmu.reset()
    run.initialize()  # no stop time: no limit
    run.fmu.doStep(0.0, 1.0)
    run.close()


def test_a_stop_time_before_the_start_is_refused_and_a_refused_setup_changes_nothing(tmp_path):
    """fmi2SetupExperiment took a stop time before the start (and NaN) without a word, and a refusal of
    its start time had already taken its tolerance. Now a stop before the start is refused, and the
    refused call leaves the instance as it was: the run afterwards is the run of a fresh instance."""
    run = Instance(tmp_path, 2)
    run.refused(lambda: run.fmu.setupExperiment(startTime=1.0, stopTime=0.5), "stop time 0.5 s", "start time 1 s")
    run.refused(lambda: run.fmu.setupExperiment(startTime=0.0, stopTime=float("nan")), "stop time nan")
    run.refused(lambda: run.fmu.setupExperiment(tolerance=0.5, startTime=1e300), "start time")
    run.initialize()  # the default tolerance (1e-6) and start time (0 s), no stop time
    fresh = Instance(tmp_path, 2)
    fresh.initialize()
    for r in (run, fresh):
        r.set("voltage", 30.0)
        r.fmu.doStep(0.0, 2e-3)
        r.fmu.doStep(2e-3, 2e-3)
    assert run.time() == fresh.time() == 4e-3
    assert run.outputs() == fresh.outputs() and run.outputs()[0] != 0.0
    run.close()
    fresh.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_terminate_outside_step_mode_is_refused(fmi, tmp_path):
    """fmi2Terminate / fmi3Terminate answered OK before the initialization, in it and a second time; both
    standards allow it once initialized only. Refused where not allowed, naming the mode; the instance
    still initializes, steps and terminates after the refusals."""
    run = Instance(tmp_path, fmi)
    run.refused(run.fmu.terminate, "Terminate", "instantiated")
    run.initialize(exit=False)
    run.refused(run.fmu.terminate, "Terminate", "initialization mode")
    run.fmu.exitInitializationMode()
    run.fmu.doStep(0.0, 1e-4)
    run.fmu.terminate()
    run.refused(run.fmu.terminate, "Terminate", "terminated")
    run.refused(lambda: run.fmu.doStep(1e-4, 1e-4), "DoStep", "terminated")
    assert run.time() == pytest.approx(1e-4, rel=1e-15)
    run.close()


@pytest.mark.parametrize("fmi", [2, 3])
def test_a_restored_state_keeps_the_instance_in_its_mode(fmi, tmp_path):
    """fmi2SetFMUstate / fmi3SetFMUState is no transition of the state machines, but it restored the mode
    with the values: a terminated instance given a state from step mode answered OK to a step and to a
    tunable parameter; an initialized one given a state from initialization mode took a fixed step size
    (integrator.step) and refused steps. Now the instance keeps its mode (terminated stays terminated, its
    outputs those of the state), and a state from the other side of the initialization is refused."""
    run = Instance(tmp_path, fmi, solver="realtime", step=1e-5)
    run.initialize(exit=False)
    before_init = run.get_state()
    run.fmu.exitInitializationMode()
    run.set("voltage", 30.0)
    run.fmu.doStep(0.0, 1e-3)
    stepping = run.get_state()
    outputs = run.outputs()
    run.fmu.doStep(1e-3, 1e-3)
    run.fmu.terminate()

    run.set_state(stepping)  # allowed when terminated: the values come back, the mode stays
    assert run.time() == pytest.approx(1e-3, rel=1e-15) and run.outputs() == outputs
    run.refused(lambda: run.fmu.doStep(1e-3, 1e-3), "DoStep", "terminated")
    run.refused(lambda: run.set("thermal.fc.a", run.get("thermal.fc.a")[0]), "terminated")
    run.refused(lambda: run.set("voltage", 1.0), "terminated")

    run.fmu.reset()  # instantiated: a state from step mode is on the other side
    run.refused(lambda: run.set_state(stepping), "SetFMUState" if fmi == 3 else "SetFMUstate", "after initialization")
    run.set_state(before_init)  # same side: taken
    run.initialize()
    run.refused(lambda: run.set_state(before_init), "before initialization", "step mode")
    run.refused(lambda: run.set("integrator.step", 2e-5), "fixed")  # still in step mode
    run.set_state(stepping)
    run.fmu.doStep(1e-3, 1e-3)  # and it steps on from the restored time
    assert run.time() == pytest.approx(2e-3, rel=1e-15)
    run.close()


def test_fmi2_calls_the_state_table_does_not_allow_are_refused(tmp_path):
    """FMI 2.0's table of calls and states: fmi2GetReal (and the other getters) from initialization mode on,
    fmi2GetRealStatus once initialized, no setter once terminated, not even of zero variables. Each
    answered OK where not allowed; now refused naming the mode, and allowed where the table allows."""
    run = Instance(tmp_path, 2)
    dll, c = run.fmu.dll, run.fmu.component
    vr, value = (ctypes.c_uint * 1)(run.vr["voltage"]), (ctypes.c_double * 1)()
    run.refused(lambda: run.get("voltage"), "fmi2GetReal", "instantiated")
    run.refused(lambda: run.fmu.getRealStatus(2), "fmi2GetRealStatus", "instantiated")
    run.messages.clear()
    dll.fmi2GetInteger.argtypes = dll.fmi2SetInteger.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t,
                                                                  ctypes.c_void_p]
    assert dll.fmi2GetInteger(c, vr, 0, value) == ERROR and "instantiated" in run.messages[-1][1]
    run.initialize(exit=False)
    assert len(run.get("voltage")) == 1  # allowed from initialization mode on
    run.refused(lambda: run.fmu.getRealStatus(2), "fmi2GetRealStatus", "initialization mode")
    run.fmu.exitInitializationMode()
    run.fmu.doStep(0.0, 1e-4)
    run.fmu.terminate()
    assert run.fmu.getRealStatus(2) == pytest.approx(1e-4) and len(run.get("voltage")) == 1
    run.messages.clear()
    assert dll.fmi2SetInteger(c, vr, 0, value) == ERROR and "terminated" in run.messages[-1][1]
    assert dll.fmi2GetInteger(c, vr, 0, value) == 0  # nothing to get, allowed: OK
    run.close()


def test_fmi3_setters_of_no_variables_are_refused_once_terminated(tmp_path):
    """FMI 3.0: fmi3Set{VariableType} is not allowed in Terminated; the setters of the types this FMU has no
    variables of answered OK for zero variables there. Refused now; the getters stay allowed."""
    run = Instance(tmp_path, 3)
    run.initialize()
    run.fmu.doStep(0.0, 1e-4)
    run.fmu.terminate()
    dll, c = run.fmu.dll, run.fmu.component
    vr, value = (ctypes.c_uint * 1)(0), (ctypes.c_int32 * 1)()
    for name in ("fmi3SetInt32", "fmi3SetBoolean", "fmi3SetFloat32"):
        f = getattr(dll, name)
        f.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t]
        run.messages.clear()
        assert f(c, vr, 0, value, 0) == ERROR, name
        assert run.messages[-1][1].startswith(name) and "terminated" in run.messages[-1][1]
    dll.fmi3GetInt32.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t]
    assert dll.fmi3GetInt32(c, vr, 0, value, 0) == 0
    run.close()
