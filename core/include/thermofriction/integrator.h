/* Adaptive integrators with dense output: Dormand-Prince 5(4) (explicit) and Rodas4
 * (Rosenbrock, L-stable, for stiff problems), behind one driver that stops at every corner
 * of the input and writes results on a caller's output grid. */
#ifndef THERMOFRICTION_INTEGRATOR_H
#define THERMOFRICTION_INTEGRATOR_H

#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    int n;
    void *ctx;
    tf_status (*rhs)(double t, const double *y, double *dy, void *ctx); /* TF_OK, or the step fails */
    tf_status (*jac)(double t, const double *y, double *J, void *ctx); /* row-major n x n */
    double (*next_corner)(double t, void *ctx);                  /* may be NULL */
    /* Discrete modes (may be 0/NULL): nevent event functions g(t, y) that cross zero upwards
     * where a mode must change. After every accepted step the driver locates the earliest
     * crossing on the dense output, ends the step there and restarts; on_restart(t, y) is
     * called at every restart (start, corners, events) to set the modes for what follows; it
     * may change y there (a sensitivity system's jump where a mode switches). */
    int nevent;
    void (*events)(double t, const double *y, double *g, void *ctx);
    void (*on_restart)(double t, double *y, void *ctx);
    /* Optional (kink_scale 0: none): a velocity whose sign change puts a kink in the right-hand side
     * (LuGre's |v_r|), the state kink_plus minus the state kink_minus (kink_minus < 0: the state alone),
     * and its scale (a sign change within a few rtol times it is the integrator's noise). AUTO's Dormand-Prince
     * steps end at its reversals (solve.c), whose kink their error estimate does not see. */
    double kink_scale;
    int kink_plus, kink_minus;
    /* Optional (may be NULL): the longest step the problem allows from (t, y), for a time scale of its
     * input that no state carries, so that no error estimate sees it (a prescribed motion's velocity,
     * tf_model_max_step); every method's steps are held to it, as to the caller's hmax. */
    double (*max_step)(double t, const double *y, void *ctx);
} tf_ode;

typedef enum {
    TF_METHOD_AUTO = 0,   /* Dormand-Prince until it detects stiffness, then Rodas4 */
    TF_METHOD_DOPRI5 = 1,
    TF_METHOD_RODAS4 = 2
} tf_method;

typedef struct {
    int method;
    double rtol;
    const double *atol; /* n values */
    double h0;          /* first step; <= 0: chosen automatically */
    double hmax;        /* <= 0: unlimited */
    long max_steps;
    /* n weights of the relative tolerance in the error norm, atol_i + rtol_weight_i rtol |y_i|; NULL: all 1.
     * A state whose value is relative to an arbitrary origin (a position) gets 0: see tf_model_rtol_weights */
    const double *rtol_weight;
    /* Polled every TF_POLL_STEPS attempted steps (NULL: never): a nonzero return stops the integration
     * with TF_ERR_INTERRUPTED, y0 holding the state at the last accepted step (the error record: t). For a
     * caller that must react to a signal (Ctrl-C) during one long integration. */
    int (*interrupt)(void *ctx);
    void *interrupt_ctx;
} tf_solver_options;

#define TF_POLL_STEPS 64


typedef struct {
    long steps, rejected, rhs_evals, jac_evals, decompositions, events;
    int method_used;     /* the method at the end (AUTO may switch) */
    double switch_time;  /* when AUTO switched to Rodas4; -1 if it did not */
    int stiff_suspected; /* explicit method saw stiffness */
    double h_fail;       /* on failure: the step size (the time is in the error record) */
} tf_solver_stats;

/* Writes one output sample: index into the grid, its time and the state there. */
typedef void (*tf_emit_fn)(long i, double t, const double *y, void *ctx);

/* Integrates from (t_out[0], y0) through t_out[n_out-1]; y0 is overwritten by the final
 * state (or the state at failure). t_out must be non-decreasing, finite and within +-1e12 s
 * (else TF_ERR_BAD_ARGUMENT). Returns a tf_status and fills *err (status.h; may be NULL): where
 * "solver", what the status's message or the argument refused, t the time of the failure, index
 * the output sample for a failure there (else -1). */
tf_status tf_solve(const tf_ode *ode, const tf_solver_options *opt, const double *t_out, long n_out,
                   double *y0, tf_emit_fn emit, void *emit_ctx, tf_solver_stats *stats, tf_error *err);

/* Dense LU with partial pivoting (row-major n x n, in place) and the matching solve.
 * tf_lu_factor returns TF_ERR_SINGULAR for a singular (or non-finite) matrix. */
tf_status tf_lu_factor(double *A, int n, int *piv);
void tf_lu_solve(const double *A, int n, const int *piv, double *b);

#ifdef __cplusplus
}
#endif
#endif
