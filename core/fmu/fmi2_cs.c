/* The FMI 2.0 co-simulation functions (docs/fmu.md): the standard's calling conventions around the
 * shared model and step logic of fmu_common.c. */
#include <stdlib.h>

#include "fmi2Functions.h"
#include "fmu_common.h"

/* The modes the FMI 2.0 co-simulation state machine (its table of calls and states) allows: variables are
 * read from initialization mode on (start values are the model description's) and set until terminated;
 * the status of the last step is asked once initialized. */
#define GETTABLE (FMU_IN_INITIALIZATION | FMU_IN_STEP | FMU_IN_TERMINATED)
#define SETTABLE (FMU_IN_INSTANTIATED | FMU_IN_INITIALIZATION | FMU_IN_STEP)
#define STEPPED (FMU_IN_STEP | FMU_IN_TERMINATED)

/* The importer's printf-like logger; the message is already its own format ('%' doubled). */
static void log_fmi2(const fmu_callbacks *cb, const char *name, fmu_status status, const char *category,
                 const char *message)
{
    ((fmi2CallbackLogger)cb->host_logger)(cb->env, name, (fmi2Status)status, category, message);
}

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[])
{
    return (fmi2Status)fmu_set_debug_logging(c, on);
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *cb, fmi2Boolean visible, fmi2Boolean logging)
{
    if (!cb || !cb->allocateMemory || !cb->freeMemory) return NULL;
    if (type != fmi2CoSimulation) {
        if (cb->logger) cb->logger(cb->componentEnvironment, name, fmi2Error, "logStatusError", "%s",
                                   "this FMU supports co-simulation only");
        return NULL;
    }
    fmu_callbacks f = {cb->logger ? log_fmi2 : NULL, (fmu_host_function)cb->logger, cb->componentEnvironment, 1, NULL,
                       cb->allocateMemory, cb->freeMemory};
    return fmu_instantiate(name, guid, resources, 1, &f, logging);
}

void fmi2FreeInstance(fmi2Component c) { fmu_free_instance(c); }

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tol_defined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stop_defined, fmi2Real stop)
{
    return (fmi2Status)fmu_setup_experiment(c, tol_defined, tol, start, stop_defined, stop);
}
fmi2Status fmi2EnterInitializationMode(fmi2Component c) { return (fmi2Status)fmu_enter_initialization(c); }
fmi2Status fmi2ExitInitializationMode(fmi2Component c) { return (fmi2Status)fmu_exit_initialization(c); }
fmi2Status fmi2Terminate(fmi2Component c) { return (fmi2Status)fmu_terminate(c); }
fmi2Status fmi2Reset(fmi2Component c) { return (fmi2Status)fmu_reset(c); }

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2GetReal", GETTABLE);
    return (fmi2Status)(s == FMU_OK ? fmu_get_real(c, vr, n, value) : s);
}
fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real value[])
{
    return (fmi2Status)fmu_set_real(c, vr, n, value);
}
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    return (fmi2Status)fmu_set_input_derivatives(c, vr, n, order, value);
}
fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n,
                                        const fmi2Integer order[], fmi2Real value[])
{
    return (fmi2Status)fmu_fail(c, "fmi2GetRealOutputDerivatives: not provided");
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean no_prior)
{
    return (fmi2Status)fmu_do_step(c, t, h, no_prior);
}
fmi2Status fmi2CancelStep(fmi2Component c)
{
    return (fmi2Status)fmu_fail(c, "fmi2CancelStep: steps are never asynchronous");
}

/* ---- FMU state: a copy of the instance ---- */

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *state) { return (fmi2Status)fmu_get_state(c, state); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate state) { return (fmi2Status)fmu_set_state(c, state); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *state) { return (fmi2Status)fmu_free_state(c, state); }

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate state, size_t *size)
{
    return (fmi2Status)fmu_fail(c, "FMU states cannot be serialized (canSerializeFMUstate is false)");
}
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    return (fmi2Status)fmu_fail(c, "FMU states cannot be serialized (canSerializeFMUstate is false)");
}
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    return (fmi2Status)fmu_fail(c, "FMU states cannot be serialized (canSerializeFMUstate is false)");
}
fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real du[], fmi2Real dz[])
{
    return (fmi2Status)fmu_fail(c, "fmi2GetDirectionalDerivative: not provided");
}

/* ---- the types this FMU has no variables of ---- */

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2GetInteger", GETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2GetInteger: this FMU has no integer variables");
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2GetBoolean", GETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2GetBoolean: this FMU has no boolean variables");
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2GetString", GETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2GetString: this FMU has no string variables");
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2SetInteger", SETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2SetInteger: this FMU has no integer variables");
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2SetBoolean", SETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2SetBoolean: this FMU has no boolean variables");
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String value[])
{
    fmu_status s = fmu_require_mode(c, "fmi2SetString", SETTABLE);
    return s != FMU_OK ? (fmi2Status)s : n == 0 ? fmi2OK : (fmi2Status)fmu_fail(c, "fmi2SetString: this FMU has no string variables");
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    return (fmi2Status)fmu_fail(c, "fmi2GetStatus: steps are never asynchronous");
}
fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    fmu_status ok = fmu_require_mode(c, "fmi2GetRealStatus", STEPPED);
    if (ok != FMU_OK) return (fmi2Status)ok;
    if (!value) return (fmi2Status)fmu_fail(c, "fmi2GetRealStatus: NULL argument");
    if (s == fmi2LastSuccessfulTime) { *value = fmu_time(c); return fmi2OK; }
    return (fmi2Status)fmu_fail(c, "fmi2GetRealStatus: only fmi2LastSuccessfulTime");
}
fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    return (fmi2Status)fmu_fail(c, "fmi2GetIntegerStatus: not provided");
}
fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    return (fmi2Status)fmu_fail(c, "fmi2GetBooleanStatus: not provided");
}
fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    return (fmi2Status)fmu_fail(c, "fmi2GetStringStatus: not provided");
}
