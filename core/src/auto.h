/* Private header of auto.c: AUTO, the choice between the explicit and the stiff method, and the reversal
 * handling of its explicit steps, behind a small interface that the driver (solve.c) calls. AUTO decides
 * and says what it decided (the return values); the driver switches its method and resets its
 * controllers. Nothing here calls into the driver. */
#ifndef THERMOFRICTION_AUTO_H
#define THERMOFRICTION_AUTO_H

#include "work.h"

typedef struct {
    const tf_ode *ode;
    const tf_solver_stats *st;     /* the run's counts, read for the work done */
    int n, on;                     /* states; AUTO asked for */
    int kinks;                     /* AUTO with a kink velocity (integrator.h): its steps end at reversals */
    tf_solver_options opt_x;       /* the explicit phases' tolerances: AUTO_EXPLICIT_TOL times the caller's */
    double *atol_x;
    /* the explicit method's recent cost, the probe of the stiff one, the lock-out */
    double win_t, win_work, explicit_rate, probe_t, probe_work;
    long win_steps, probe_steps, lock_steps, lock_len;
    /* reversals of the kink velocity: a step cut at one (its size, the size it replaced, the cuts of the
     * step being attempted), the largest |v| of the current and of the last half-cycle, whether the
     * stiffness test fired since the restart, the accepted steps of the current and of the last half-cycle */
    double kink_h, kink_h_orig, kink_peak, kink_last_peak;
    int kink_cuts, stiff_seen, kink_steps, kink_last_steps;
} tf_auto;

/* From the start at t (method: the one asked for; the ODE without a Jacobian runs Dormand-Prince): the
 * explicit phases' tolerances and the bookkeeping. Nonzero without memory (release with tf_auto_free). */
int tf_auto_start(tf_auto *a, const tf_ode *ode, const tf_solver_options *opt, int method, double t,
                  const tf_solver_stats *st);
void tf_auto_free(tf_auto *a);
/* The tolerances Dormand-Prince runs at: the explicit phases' under AUTO, else the caller's. */
const tf_solver_options *tf_auto_explicit_options(const tf_auto *a, const tf_solver_options *opt);

/* At every restart at t (a corner, an event) with `method` running: the reversals forgotten, and 1 if AUTO
 * goes back to the explicit method there (the driver then takes a starting step of its own). */
int tf_auto_restart(tf_auto *a, int method, double t, double t_first);
/* After an accepted explicit step of size h from y ending at t_new (w: its dense output), its step-size
 * control's next step *hnew and its stiffness test's verdict (stiff): the next step shortened to end at a
 * predicted reversal, and 1 if AUTO switches to the stiff method (switch_time in *st). */
int tf_auto_explicit_step(tf_auto *a, const work *w, const double *y, double h, double t_new, int stiff,
                          double *hnew, tf_solver_stats *st);
/* After every accepted step ending at t_new with `method` running: 1 if the stiff method's probe decides
 * to go back to the explicit one (switch_time reset in *st). */
int tf_auto_probe(tf_auto *a, int method, double t_new, tf_solver_stats *st);
/* An explicit step of size h from (y, f0) with error err, judged again where it crosses a reversal
 * (w: its dense output; yd: n doubles of scratch): its error, larger if the mid-step check fails. */
double tf_auto_check_step(tf_auto *a, work *w, const double *y, const double *f0, double h, double *yd,
                          double err);
/* A rejected step's retry: the step that ends just past a reversal (then 0 next time), or 0 for the
 * method's own control. */
double tf_auto_retry_step(tf_auto *a);
/* An accepted step's successor hnew, at least the step that a cut at a reversal replaced. */
double tf_auto_accepted(tf_auto *a, double hnew);

#endif
