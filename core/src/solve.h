/* Private to solve.c and auto.c: the state of one tf_solve, the driver's steps that AUTO's method
 * switching uses, and AUTO's own (auto.c). */
#ifndef THERMOFRICTION_SOLVE_H
#define THERMOFRICTION_SOLVE_H

#include "solver.h"

/* AUTO's bookkeeping: the explicit method's recent cost, the probe of the stiff one, the lock-out. */
typedef struct {
    double win_t, win_work, explicit_rate, probe_t, probe_work;
    long win_steps, probe_steps, lock_steps, lock_len;
} tf_auto;

typedef struct {
    work w;                        /* the methods' vectors (solver.h) */
    const tf_ode *ode;
    const tf_solver_options *opt;  /* the caller's tolerances (Rodas4's, and Dopri5's unless AUTO) */
    tf_solver_options opt_x;       /* AUTO's explicit phases: AUTO_EXPLICIT_TOL times them (auto.c) */
    double *atol_x;
    tf_solver_stats *st;
    tf_error *err;                 /* the caller's record (may be NULL) */
    const double *t_out;
    long n_out, next;              /* the output grid and its next sample */
    tf_emit_fn emit;
    void *emit_ctx;
    int n, ne, requested, method;  /* states, event functions, the method asked for, the one running */
    double t, h, *y;               /* where the integration is, the next step, the state (the caller's) */
    double *f0, *yd, *g0, *g1, *gm; /* f(t, y), a dense-output sample, the event functions at t, t + h, mid */
    int jac_current, reject, poll;
    double facold;                 /* Dopri5's PI control */
    int iasti, nonsti;             /* Dopri5's stiffness test */
    /* reversals of the kink velocity (solve.c): a step cut at one (its size, the size it replaced, the cuts
     * of the step being attempted), the largest |v| of the current and of the last half-cycle, whether
     * the stiffness test fired since the restart */
    double kink_h, kink_h_orig, kink_peak, kink_last_peak;
    int kinks, kink_cuts, stiff_seen; /* kinks: AUTO with a kink velocity */
    int kink_steps, kink_last_steps;  /* accepted steps of the current and of the last half-cycle */
    tf_rodas4_control rc;
    tf_auto au;
} tf_driver;

/* Hairer's starting step: an explicit Euler step's change in f sets the scale (solve.c). */
double tf_initial_step(work *w, double t, const double *y, const double *f0, int order, double hmax);

/* auto.c: AUTO's tolerances (0, or nonzero without memory) and bookkeeping from the start, ... */
int tf_auto_start(tf_driver *d);
/* ... at every restart (a corner, an event): the explicit method again, with a step of its own ... */
void tf_auto_restart(tf_driver *d);
/* ... after an accepted explicit step ending at t_new (stiff: its stiffness test fired) ... */
void tf_auto_explicit_step(tf_driver *d, double t_new, int stiff);
/* ... and after every accepted step: the stiff method's probe decides whether it goes on. */
void tf_auto_probe(tf_driver *d, double t_new);

#endif
