/* The model and step logic shared by the FMI 2.0 and FMI 3.0 co-simulation wrappers (fmi2_cs.c,
 * fmi3_cs.c; docs/fmu.md): an instance reads its model from resources/model.tfm, takes parameters and
 * inputs by value reference, integrates between communication points and reports the outputs. The
 * wrappers translate the standards' calling conventions; the statuses have the values of both
 * standards' OK, Warning, Discard and Error. */
#ifndef TF_FMU_COMMON_H
#define TF_FMU_COMMON_H

#include <stddef.h>

typedef enum { FMU_OK = 0, FMU_WARNING = 1, FMU_DISCARD = 2, FMU_ERROR = 3 } fmu_status;
typedef unsigned int fmu_vr; /* a value reference (fmi2ValueReference, fmi3ValueReference) */
typedef void (*fmu_host_function)(void);

/* How an instance reaches its importer. log is the wrapper's adapter, calling host_logger (the
 * importer's logger, cast back to its own type) with env. */
typedef struct fmu_callbacks {
    void (*log)(const struct fmu_callbacks *cb, const char *name, fmu_status status, const char *category,
                const char *message);
    fmu_host_function host_logger;
    void *env;
    int printf_format;         /* the logger formats the message: its '%' are doubled (FMI 2) */
    const char *const *names;  /* NULL, or pairs {"fmi2SetReal", "fmi3SetFloat64", ..., NULL}: the names in messages */
    void *(*allocateMemory)(size_t n, size_t size);
    void (*freeMemory)(void *p);
} fmu_callbacks;

typedef struct fmu_instance fmu_instance;

/* NULL when the resources cannot be read, the GUID (instantiation token) is not theirs or the model
 * is invalid (logged). resources: a file: URI (resources_is_uri, FMI 2) or a folder path (FMI 3). */
/* The modes of the standards' co-simulation state machines this FMU goes through (FMI 2: instantiated,
 * initialization mode, slave initialized, terminated; FMI 3: Instantiated, Initialization Mode, Step
 * Mode, Terminated), as bits: the calls each mode allows (docs/fmu.md, "Calling sequence"). */
enum { FMU_IN_INSTANTIATED = 1, FMU_IN_INITIALIZATION = 2, FMU_IN_STEP = 4, FMU_IN_TERMINATED = 8 };
#define FMU_IN_ANY 15u

/* FMU_OK where the instance is in one of the modes `allowed` (FMU_IN_* bits); else logs that `call` is
 * not allowed in its mode and returns FMU_ERROR (a NULL instance: FMU_ERROR). */
fmu_status fmu_require_mode(fmu_instance *c, const char *call, unsigned allowed);

fmu_instance *fmu_instantiate(const char *name, const char *guid, const char *resources, int resources_is_uri,
                              const fmu_callbacks *cb, int logging);
void fmu_free_instance(fmu_instance *c);
fmu_status fmu_set_debug_logging(fmu_instance *c, int on);
fmu_status fmu_setup_experiment(fmu_instance *c, int tol_defined, double tol, double start, int stop_defined,
                                double stop);
fmu_status fmu_enter_initialization(fmu_instance *c);
fmu_status fmu_exit_initialization(fmu_instance *c);
fmu_status fmu_terminate(fmu_instance *c);
fmu_status fmu_reset(fmu_instance *c);
fmu_status fmu_get_real(fmu_instance *c, const fmu_vr vr[], size_t n, double value[]);
fmu_status fmu_set_real(fmu_instance *c, const fmu_vr vr[], size_t n, const double value[]);
fmu_status fmu_set_input_derivatives(fmu_instance *c, const fmu_vr vr[], size_t n, const int order[],
                                     const double value[]);
fmu_status fmu_do_step(fmu_instance *c, double t, double h, int no_prior);
fmu_status fmu_get_state(fmu_instance *c, void **state);
fmu_status fmu_set_state(fmu_instance *c, void *state);
fmu_status fmu_free_state(fmu_instance *c, void **state);
double fmu_time(const fmu_instance *c);
/* The instance's model (plant.h's tf_model, its laws pointing into the instance): for in-process importers that
 * step its friction with the real-time API (matlab/thermofriction_mex.c); valid while the instance lives. */
const void *fmu_model(const fmu_instance *c);
/* Logs an error (message formatted as printf) and returns FMU_ERROR: for the wrappers' own refusals. */
fmu_status fmu_fail(fmu_instance *c, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

#endif
