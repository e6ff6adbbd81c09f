/* One status type and one error record for every entry point of the core.
 *
 * Every function that can fail returns a tf_status and, given a non-NULL tf_error *err (its last
 * argument), fills it: on TF_OK err->code = TF_OK and empty strings; on a failure the code, what was
 * refused or failed (`what`), the part of the core that says so (`where`), and where known the time
 * and the sample, step or control period concerned. A NULL err is allowed everywhere: the status
 * alone then says what happened. The record is the caller's (no allocation, no global state). */
#ifndef THERMOFRICTION_STATUS_H
#define THERMOFRICTION_STATUS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TF_OK = 0,
    TF_ERR_NONFINITE = 1,      /* NaN or infinite state, derivative, force or output */
    TF_ERR_STEP_UNDERFLOW = 2, /* the step size fell below the resolution of the time variable */
    TF_ERR_MAX_STEPS = 3,      /* the bound on the work (max_steps) was reached */
    TF_ERR_BAD_ARGUMENT = 4,   /* an argument, parameter or model field refused: `what` names it */
    TF_ERR_NO_MEMORY = 5,
    TF_ERR_INTERRUPTED = 6,    /* the caller's interrupt poll asked to stop (integrator.h) */
    TF_ERR_SINGULAR = 7        /* a singular matrix (tf_lu_factor) */
} tf_status;

#define TF_ERROR_WHAT 96
#define TF_ERROR_WHERE 16

typedef struct {
    tf_status code;
    /* the argument, parameter or field refused (e.g. "fc", "v (not finite)", "t_out (decreasing)"),
     * or what failed; "" on TF_OK */
    char what[TF_ERROR_WHAT];
    /* the part that says so: "model", "solver", "realtime", "pid", "observer", "loop", "reference",
     * "plant", "compensation"; "" on TF_OK */
    char where[TF_ERROR_WHERE];
    double t;   /* the time [s] of a failure during an integration; NaN if none */
    long index; /* the output sample, step or control period concerned; -1 if none */
} tf_error;

/* A sentence for a status ("the maximum number of steps was reached"). */
const char *tf_status_message(tf_status status);

/* Fills *err (when not NULL) with the record and returns code: what every entry point does. where
 * and what may be NULL (empty); they are truncated to the record's sizes. */
tf_status tf_error_set(tf_error *err, tf_status code, const char *where, const char *what, double t, long index);

#ifdef __cplusplus
}
#endif
#endif
