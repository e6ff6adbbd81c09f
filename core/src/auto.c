/* AUTO: per phase of the input (every corner starts one), DOPRI5 at AUTO_EXPLICIT_TOL (with the
 * reversal handling of solve.c: AUTO_EXPLICIT_TOL_KINKS) times the tolerances until its stiffness test
 * fires (15 steps in a row near the stability boundary) and the
 * relative velocity no longer oscillates (solve.c: reversals); then
 * RODAS4 on probation: after PROBE_STEPS steps its work per simulated second is compared with DOPRI5's
 * over its last window, and the cheaper method goes on (work counted in rhs evaluations, with
 * Jacobians and LUs weighted by the system size). A failed probe doubles the number of explicit steps
 * before the next one. The stiffness test says only that the explicit method sits at its stability
 * limit, not that the stiff one will be cheaper: at every velocity reversal LuGre's |v| puts a kink in
 * the right-hand side that both methods pay for, so the choice is made on measured work. */
#include "solve.h"

#include <stdlib.h>

enum { PROBE_STEPS = 200, WINDOW_STEPS = 200, FIRST_LOCK = 2000 };

#ifndef AUTO_EXPLICIT_TOL
#define AUTO_EXPLICIT_TOL 0.02 /* 1/50 */
#endif
/* ... and where the explicit method's steps end at reversals of a kink velocity (solve.c) */
#define AUTO_EXPLICIT_TOL_KINKS 0.05 /* 1/20 */

/* Work in right-hand-side evaluations, for AUTO's choice. Deterministic (counted, not timed),
 * so that the same problem always takes the same path. An analytic Jacobian costs a few rhs
 * evaluations plus its n^2 entries; a dense LU ~n^3/3 flops, about one rhs evaluation of a
 * small system (calibrated on GMS with 50 elements, n = 52: ~35 us per LU against ~100 ns per
 * rhs evaluation, i.e. ~n^3/300 evaluations). */
static double work_units(const tf_solver_stats *st, int n)
{
    double nn = (double)n;
    return (double)st->rhs_evals + (3.0 + nn * nn / 100.0) * st->jac_evals +
           fmax(1.0, nn * nn * nn / 300.0) * st->decompositions;
}

int tf_auto_start(tf_driver *d)
{
    /* AUTO's explicit phases run at AUTO_EXPLICIT_TOL times the tolerances: at equal tolerances
     * Dopri5's global error is ~10-50x Rodas4's on stick-slip, so that mixing the two at one
     * tolerance made the error depend on which ran where, not on the tolerance (and the cost
     * comparison that picks the method compared unequal accuracies). 1/20 where Dopri5's steps end at
     * the relative velocity's reversals (solve.c), whose kinks made most of that error; elsewhere (GMS,
     * whose looser explicit phases would reach the stability limit sooner and probe Rodas4's 52 x 52 LU
     * more) 1/50. */
    int n = d->n;
    d->atol_x = (double *)malloc(sizeof(double) * n);
    d->opt_x = *d->opt;
    const double factor = d->kinks ? AUTO_EXPLICIT_TOL_KINKS : AUTO_EXPLICIT_TOL;
    if (d->atol_x) {
        for (int i = 0; i < n; i++) d->atol_x[i] = factor * d->opt->atol[i];
        d->opt_x.rtol *= factor;
        d->opt_x.atol = d->atol_x;
    }
    if (d->requested == TF_METHOD_AUTO) d->w.opt = &d->opt_x;
    tf_auto *a = &d->au;
    a->win_t = d->t, a->win_work = a->explicit_rate = a->probe_t = a->probe_work = 0.0;
    a->win_steps = a->probe_steps = a->lock_steps = 0;
    a->lock_len = FIRST_LOCK;
    return !d->atol_x;
}

void tf_auto_restart(tf_driver *d)
{
    /* AUTO picks the method per phase: every restart -- a corner of the input, or an event (a GMS mode
     * switch) -- starts a new one (after a flyback its ringing, where the explicit method is cheaper;
     * then the ramp, where the stiff one is) */
    if (!(d->requested == TF_METHOD_AUTO && d->method == TF_METHOD_RODAS4 && d->t > d->t_out[0])) return;
    tf_auto *a = &d->au;
    d->method = TF_METHOD_DOPRI5;
    d->w.opt = &d->opt_x;
    d->iasti = d->nonsti = 0;
    a->probe_steps = -1;
    a->win_steps = 0;
    a->win_t = d->t;
    a->win_work = work_units(d->st, d->n);
    d->h = tf_initial_step(&d->w, d->t, d->y, d->f0, 5, d->opt->hmax); /* not the stiff method's long ramp step */
}

/* The explicit method's window of recent cost, and the lock-out's count. */
static void explicit_window(tf_driver *d, double t_new)
{
    tf_auto *a = &d->au;
    if (a->lock_steps > 0) a->lock_steps--;
    if (++a->win_steps >= WINDOW_STEPS && d->method == TF_METHOD_DOPRI5) {
        a->win_steps = 0;
        a->win_t = t_new;
        a->win_work = work_units(d->st, d->n);
    }
}

void tf_auto_explicit_step(tf_driver *d, double t_new, int stiff)
{
    tf_auto *a = &d->au;
    if (stiff && d->requested == TF_METHOD_AUTO && a->lock_steps <= 0 && t_new > a->win_t) {
        a->explicit_rate = (work_units(d->st, d->n) - a->win_work) / (t_new - a->win_t);
        d->method = TF_METHOD_RODAS4;
        d->w.opt = d->opt;
        d->rc.first = 1;
        d->st->switch_time = t_new;
        a->probe_t = t_new;
        a->probe_work = work_units(d->st, d->n);
        a->probe_steps = 0;
        d->iasti = 0;
    }
    explicit_window(d, t_new);
}

void tf_auto_probe(tf_driver *d, double t_new)
{
    tf_auto *a = &d->au;
    if (!(d->method == TF_METHOD_RODAS4 && d->requested == TF_METHOD_AUTO && a->probe_steps >= 0 &&
          ++a->probe_steps >= PROBE_STEPS))
        return;
    double rodas_rate = (work_units(d->st, d->n) - a->probe_work) / (t_new - a->probe_t);
    if (rodas_rate >= a->explicit_rate) { /* the stiff method does not pay: go back */
        d->method = TF_METHOD_DOPRI5;
        d->w.opt = &d->opt_x;
        d->st->switch_time = -1.0;
        a->lock_steps = a->lock_len;
        a->lock_len *= 2;
        a->win_steps = 0;
        a->win_t = t_new;
        a->win_work = work_units(d->st, d->n);
        d->iasti = d->nonsti = 0; /* f0 = f(t_new, y1) is current: Rodas4 computed it */
    } else {
        a->probe_steps = -1; /* it pays: stay */
    }
}
