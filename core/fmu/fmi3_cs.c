/* The FMI 3.0 co-simulation functions (docs/fmu.md): the standard's calling conventions around the
 * shared model and step logic of fmu_common.c. The variables are the FMI 2 export's, as Float64, plus
 * the independent variable time (value reference VR_TIME); FMI 3.0 co-simulation has no input
 * derivatives, so the inputs are held over each communication step (a prescribed motion moves in a
 * straight line to its new value). Model exchange, scheduled execution, clocks and event mode are not
 * provided (the model description declares co-simulation only): those functions exist, as importers
 * bind every function of the standard, and refuse. */
#include <stdlib.h>

#include "fmi3Functions.h"
#include "fmu_common.h"

#define VR_TIME 15u /* the independent variable (an unused reference of fmu_common.c's fixed ones) */

/* The FMI 2 names in fmu_common.c's messages, as an FMI 3 importer knows them. */
static const char *const NAMES[] = {"fmi2SetRealInputDerivatives", "fmi3SetFloat64", "fmi2SetReal", "fmi3SetFloat64",
                                    "fmi2GetReal", "fmi3GetFloat64", "fmi2Instantiate", "fmi3InstantiateCoSimulation",
                                    "fmi2SetupExperiment", "fmi3EnterInitializationMode",
                                    "fmi2EnterInitializationMode", "fmi3EnterInitializationMode",
                                    "fmi2ExitInitializationMode", "fmi3ExitInitializationMode",
                                    "fmi2DoStep", "fmi3DoStep", "fmi2GetFMUstate", "fmi3GetFMUState",
                                    "fmi2SetFMUstate", "fmi3SetFMUState", "fmi2FreeFMUstate", "fmi3FreeFMUState",
                                    "fmi2Terminate", "fmi3Terminate", NULL};

static void log_fmi3(const fmu_callbacks *cb, const char *name, fmu_status status, const char *category,
                     const char *message)
{
    ((fmi3LogMessageCallback)cb->host_logger)(cb->env, (fmi3Status)status, category, message);
}

static void *alloc(size_t n, size_t size) { return calloc(n, size); }

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance c, fmi3Boolean on, size_t n, const fmi3String categories[])
{
    return (fmi3Status)fmu_set_debug_logging(c, on);
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String name, fmi3String token, fmi3String resources, fmi3Boolean visible,
                                         fmi3Boolean logging, fmi3Boolean event_mode_used, fmi3Boolean early_return,
                                         const fmi3ValueReference required[], size_t n_required,
                                         fmi3InstanceEnvironment env, fmi3LogMessageCallback logger,
                                         fmi3IntermediateUpdateCallback intermediate_update)
{
    if (event_mode_used) {
        if (logger) logger(env, fmi3Error, "logStatusError", "this FMU has no event mode (hasEventMode is false)");
        return NULL;
    }
    fmu_callbacks f = {logger ? log_fmi3 : NULL, (fmu_host_function)logger, env, 0, NAMES, alloc, free};
    return fmu_instantiate(name, token, resources, 0, &f, logging);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String name, fmi3String token, fmi3String resources,
                                          fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env,
                                          fmi3LogMessageCallback logger)
{
    if (logger) logger(env, fmi3Error, "logStatusError", "this FMU supports co-simulation only");
    return NULL;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String name, fmi3String token, fmi3String resources,
                                               fmi3Boolean visible, fmi3Boolean logging, fmi3InstanceEnvironment env,
                                               fmi3LogMessageCallback logger, fmi3ClockUpdateCallback clock_update,
                                               fmi3LockPreemptionCallback lock, fmi3UnlockPreemptionCallback unlock)
{
    if (logger) logger(env, fmi3Error, "logStatusError", "this FMU supports co-simulation only");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance c) { fmu_free_instance(c); }

fmi3Status fmi3EnterInitializationMode(fmi3Instance c, fmi3Boolean tol_defined, fmi3Float64 tol, fmi3Float64 start,
                                       fmi3Boolean stop_defined, fmi3Float64 stop)
{
    fmu_status s = fmu_setup_experiment(c, tol_defined, tol, start, stop_defined, stop);
    return (fmi3Status)(s == FMU_OK ? fmu_enter_initialization(c) : s);
}
fmi3Status fmi3ExitInitializationMode(fmi3Instance c) { return (fmi3Status)fmu_exit_initialization(c); }
fmi3Status fmi3Terminate(fmi3Instance c) { return (fmi3Status)fmu_terminate(c); }
fmi3Status fmi3Reset(fmi3Instance c) { return (fmi3Status)fmu_reset(c); }
fmi3Status fmi3EnterEventMode(fmi3Instance c) { return (fmi3Status)fmu_fail(c, "fmi3EnterEventMode: no event mode"); }
fmi3Status fmi3EnterStepMode(fmi3Instance c) { return (fmi3Status)fmu_fail(c, "fmi3EnterStepMode: no event mode"); }

/* One value at a time: the time is the wrapper's own, the others the shared instance's. */
fmi3Status fmi3GetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n, fmi3Float64 value[], size_t nv)
{
    if (!c) return fmi3Error;
    if (n > 0 && (!vr || !value)) return (fmi3Status)fmu_fail(c, "fmi3GetFloat64: NULL argument");
    if (nv != n) return (fmi3Status)fmu_fail(c, "fmi3GetFloat64: %lu values for %lu scalar variables",
                                                  (unsigned long)nv, (unsigned long)n);
    for (size_t k = 0; k < n; k++) {
        if (vr[k] == VR_TIME) {
            value[k] = fmu_time(c);
            continue;
        }
        fmu_status s = fmu_get_real(c, &vr[k], 1, &value[k]);
        if (s != FMU_OK) return (fmi3Status)s;
    }
    return fmi3OK;
}

fmi3Status fmi3SetFloat64(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Float64 value[],
                          size_t nv)
{
    if (!c) return fmi3Error;
    if (nv != n) return (fmi3Status)fmu_fail(c, "fmi3SetFloat64: %lu values for %lu scalar variables",
                                                  (unsigned long)nv, (unsigned long)n);
    for (size_t k = 0; vr && k < n; k++)
        if (vr[k] == VR_TIME) return (fmi3Status)fmu_fail(c, "fmi3SetFloat64: time cannot be set");
    return (fmi3Status)fmu_set_real(c, vr, n, value);
}

fmi3Status fmi3DoStep(fmi3Instance c, fmi3Float64 t, fmi3Float64 h, fmi3Boolean no_prior, fmi3Boolean *event,
                      fmi3Boolean *terminate, fmi3Boolean *early_return, fmi3Float64 *last_time)
{
    if (!c) return fmi3Error;
    if (!event || !terminate || !early_return || !last_time)
        return (fmi3Status)fmu_fail(c, "fmi3DoStep: NULL argument");
    fmu_status s = fmu_do_step(c, t, h, no_prior);
    *event = *terminate = *early_return = fmi3False;
    *last_time = fmu_time(c);
    return (fmi3Status)s;
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const fmi3Int32 order[],
                                    fmi3Float64 value[], size_t nv)
{
    return (fmi3Status)fmu_fail(c, "fmi3GetOutputDerivatives: not provided (maxOutputDerivativeOrder is 0)");
}

/* ---- FMU state: a copy of the instance ---- */

fmi3Status fmi3GetFMUState(fmi3Instance c, fmi3FMUState *state) { return (fmi3Status)fmu_get_state(c, state); }
fmi3Status fmi3SetFMUState(fmi3Instance c, fmi3FMUState state) { return (fmi3Status)fmu_set_state(c, state); }
fmi3Status fmi3FreeFMUState(fmi3Instance c, fmi3FMUState *state) { return (fmi3Status)fmu_free_state(c, state); }

#define SERIALIZE "FMU states cannot be serialized (canSerializeFMUState is false)"
fmi3Status fmi3SerializedFMUStateSize(fmi3Instance c, fmi3FMUState state, size_t *size)
{
    return (fmi3Status)fmu_fail(c, SERIALIZE);
}
fmi3Status fmi3SerializeFMUState(fmi3Instance c, fmi3FMUState state, fmi3Byte bytes[], size_t size)
{
    return (fmi3Status)fmu_fail(c, SERIALIZE);
}
fmi3Status fmi3DeserializeFMUState(fmi3Instance c, const fmi3Byte bytes[], size_t size, fmi3FMUState *state)
{
    return (fmi3Status)fmu_fail(c, SERIALIZE);
}

/* ---- what this FMU does not provide ---- */

#define NOT_PROVIDED(name, ...)                                                        \
    fmi3Status name(fmi3Instance c, __VA_ARGS__)                                       \
    {                                                                                  \
        return (fmi3Status)fmu_fail(c, #name ": not provided by this FMU");             \
    }
#define NO_VARIABLES(name, type)                                                                              \
    fmi3Status fmi3Get##name(fmi3Instance c, const fmi3ValueReference vr[], size_t n, type value[], size_t nv) \
    {                                                                                                         \
        return n == 0 ? fmi3OK : (fmi3Status)fmu_fail(c, "fmi3Get" #name ": this FMU has no " #name " variables"); \
    }                                                                                                         \
    fmi3Status fmi3Set##name(fmi3Instance c, const fmi3ValueReference vr[], size_t n, const type value[],       \
                             size_t nv)                                                                       \
    {                                                                                                         \
        fmu_status s = fmu_require_mode(c, "fmi3Set" #name, FMU_IN_ANY & ~FMU_IN_TERMINATED);                  \
        if (s != FMU_OK) return (fmi3Status)s; /* FMI 3: nothing is set once terminated */                     \
        return n == 0 ? fmi3OK : (fmi3Status)fmu_fail(c, "fmi3Set" #name ": this FMU has no " #name " variables"); \
    }
NO_VARIABLES(Float32, fmi3Float32)
NO_VARIABLES(Int8, fmi3Int8)
NO_VARIABLES(UInt8, fmi3UInt8)
NO_VARIABLES(Int16, fmi3Int16)
NO_VARIABLES(UInt16, fmi3UInt16)
NO_VARIABLES(Int32, fmi3Int32)
NO_VARIABLES(UInt32, fmi3UInt32)
NO_VARIABLES(Int64, fmi3Int64)
NO_VARIABLES(UInt64, fmi3UInt64)
NO_VARIABLES(Boolean, fmi3Boolean)
NO_VARIABLES(String, fmi3String)

NOT_PROVIDED(fmi3GetBinary, const fmi3ValueReference vr[], size_t n, size_t sizes[], fmi3Binary v[], size_t nv)
NOT_PROVIDED(fmi3SetBinary, const fmi3ValueReference vr[], size_t n, const size_t sizes[], const fmi3Binary v[],
             size_t nv)
NOT_PROVIDED(fmi3GetClock, const fmi3ValueReference vr[], size_t n, fmi3Clock v[])
NOT_PROVIDED(fmi3SetClock, const fmi3ValueReference vr[], size_t n, const fmi3Clock v[])
NOT_PROVIDED(fmi3GetNumberOfVariableDependencies, fmi3ValueReference vr, size_t *n)
NOT_PROVIDED(fmi3GetVariableDependencies, fmi3ValueReference dependent, size_t ei_dependent[],
             fmi3ValueReference independents[], size_t ei_independents[], fmi3DependencyKind kinds[], size_t n)
NOT_PROVIDED(fmi3GetDirectionalDerivative, const fmi3ValueReference u[], size_t nu, const fmi3ValueReference k[],
             size_t nk, const fmi3Float64 seed[], size_t ns, fmi3Float64 sens[], size_t nsens)
NOT_PROVIDED(fmi3GetAdjointDerivative, const fmi3ValueReference u[], size_t nu, const fmi3ValueReference k[],
             size_t nk, const fmi3Float64 seed[], size_t ns, fmi3Float64 sens[], size_t nsens)
NOT_PROVIDED(fmi3GetIntervalDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 iv[],
             fmi3IntervalQualifier q[])
NOT_PROVIDED(fmi3GetIntervalFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
             fmi3UInt64 resolutions[], fmi3IntervalQualifier q[])
NOT_PROVIDED(fmi3GetShiftDecimal, const fmi3ValueReference vr[], size_t n, fmi3Float64 shifts[])
NOT_PROVIDED(fmi3GetShiftFraction, const fmi3ValueReference vr[], size_t n, fmi3UInt64 counters[],
             fmi3UInt64 resolutions[])
NOT_PROVIDED(fmi3SetIntervalDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 iv[])
NOT_PROVIDED(fmi3SetIntervalFraction, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 counters[],
             const fmi3UInt64 resolutions[])
NOT_PROVIDED(fmi3SetShiftDecimal, const fmi3ValueReference vr[], size_t n, const fmi3Float64 shifts[])
NOT_PROVIDED(fmi3SetShiftFraction, const fmi3ValueReference vr[], size_t n, const fmi3UInt64 counters[],
             const fmi3UInt64 resolutions[])
/* model exchange and scheduled execution (exported: importers bind every function of the standard) */
NOT_PROVIDED(fmi3ActivateModelPartition, fmi3ValueReference clock, fmi3Float64 time)
NOT_PROVIDED(fmi3CompletedIntegratorStep, fmi3Boolean no_prior, fmi3Boolean *event, fmi3Boolean *terminate)
NOT_PROVIDED(fmi3SetTime, fmi3Float64 time)
NOT_PROVIDED(fmi3SetContinuousStates, const fmi3Float64 x[], size_t n)
NOT_PROVIDED(fmi3GetContinuousStateDerivatives, fmi3Float64 dx[], size_t n)
NOT_PROVIDED(fmi3GetEventIndicators, fmi3Float64 z[], size_t n)
NOT_PROVIDED(fmi3GetContinuousStates, fmi3Float64 x[], size_t n)
NOT_PROVIDED(fmi3GetNominalsOfContinuousStates, fmi3Float64 nominals[], size_t n)
NOT_PROVIDED(fmi3GetNumberOfEventIndicators, size_t *n)
NOT_PROVIDED(fmi3GetNumberOfContinuousStates, size_t *n)
NOT_PROVIDED(fmi3UpdateDiscreteStates, fmi3Boolean *update, fmi3Boolean *terminate, fmi3Boolean *nominals,
             fmi3Boolean *values, fmi3Boolean *next_defined, fmi3Float64 *next_time)

fmi3Status fmi3EnterConfigurationMode(fmi3Instance c)
{
    return (fmi3Status)fmu_fail(c, "fmi3EnterConfigurationMode: this FMU has no structural parameters");
}
fmi3Status fmi3ExitConfigurationMode(fmi3Instance c)
{
    return (fmi3Status)fmu_fail(c, "fmi3ExitConfigurationMode: this FMU has no structural parameters");
}
fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance c)
{
    return (fmi3Status)fmu_fail(c, "fmi3EnterContinuousTimeMode: this FMU supports co-simulation only");
}
fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance c)
{
    return (fmi3Status)fmu_fail(c, "fmi3EvaluateDiscreteStates: not provided by this FMU");
}
