/* AUTO: per phase of the input (every corner starts one), DOPRI5 at AUTO_EXPLICIT_TOL (with the
 * reversal handling below: AUTO_EXPLICIT_TOL_KINKS) times the tolerances until its stiffness test
 * fires (15 steps in a row near the stability boundary) and the relative velocity no longer oscillates
 * (reversals, below); then RODAS4 on probation: after PROBE_STEPS steps its work per simulated second
 * is compared with DOPRI5's over its last window, and the cheaper method goes on (work counted in rhs
 * evaluations, with Jacobians and LUs weighted by the system size). A failed probe doubles the number
 * of explicit steps before the next one. The stiffness test says only that the explicit method sits at
 * its stability limit, not that the stiff one will be cheaper: at every velocity reversal LuGre's |v|
 * puts a kink in the right-hand side that both methods pay for, so the choice is made on measured work.
 *
 * The driver (solve.c) calls this file's functions (auto.h) at its restarts and after its steps; they
 * return what AUTO decided, and the driver switches. */
#include "auto.h"
#include "dopri5.h"

#include <stdlib.h>

enum { PROBE_STEPS = 200, WINDOW_STEPS = 200, FIRST_LOCK = 2000 };

#ifndef AUTO_EXPLICIT_TOL
#define AUTO_EXPLICIT_TOL 0.02 /* 1/50 */
#endif
/* ... and where the explicit method's steps end at reversals of a kink velocity (below) */
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

int tf_auto_start(tf_auto *a, const tf_ode *ode, const tf_solver_options *opt, int method, double t,
                  const tf_solver_stats *st)
{
    /* AUTO's explicit phases run at AUTO_EXPLICIT_TOL times the tolerances: at equal tolerances
     * Dopri5's global error is ~10-50x Rodas4's on stick-slip, so that mixing the two at one
     * tolerance made the error depend on which ran where, not on the tolerance (and the cost
     * comparison that picks the method compared unequal accuracies). 1/20 where Dopri5's steps end at
     * the relative velocity's reversals (below), whose kinks made most of that error; elsewhere (GMS,
     * whose looser explicit phases would reach the stability limit sooner and probe Rodas4's 52 x 52 LU
     * more) 1/50. */
    int n = ode->n;
    *a = (tf_auto){0};
    a->ode = ode, a->st = st, a->n = n;
    a->on = method == TF_METHOD_AUTO;
    a->kinks = a->on && ode->kink_scale > 0.0; /* reversals (below) */
    a->atol_x = (double *)malloc(sizeof(double) * n);
    a->opt_x = *opt;
    const double factor = a->kinks ? AUTO_EXPLICIT_TOL_KINKS : AUTO_EXPLICIT_TOL;
    if (a->atol_x) {
        for (int i = 0; i < n; i++) a->atol_x[i] = factor * opt->atol[i];
        a->opt_x.rtol *= factor;
        a->opt_x.atol = a->atol_x;
    }
    a->win_t = t, a->win_work = a->explicit_rate = a->probe_t = a->probe_work = 0.0;
    a->win_steps = a->probe_steps = a->lock_steps = 0;
    a->lock_len = FIRST_LOCK;
    return !a->atol_x;
}

void tf_auto_free(tf_auto *a)
{
    free(a->atol_x);
    a->atol_x = 0;
}

const tf_solver_options *tf_auto_explicit_options(const tf_auto *a, const tf_solver_options *opt)
{
    return a->on ? &a->opt_x : opt;
}

int tf_auto_restart(tf_auto *a, int method, double t, double t_first)
{
    a->kink_h = a->kink_h_orig = a->kink_peak = a->kink_last_peak = 0.0;
    a->kink_cuts = a->kink_steps = a->kink_last_steps = a->stiff_seen = 0;
    /* AUTO picks the method per phase: every restart -- a corner of the input, or an event (a GMS mode
     * switch) -- starts a new one (after a flyback its ringing, where the explicit method is cheaper;
     * then the ramp, where the stiff one is) */
    if (!(a->on && method == TF_METHOD_RODAS4 && t > t_first)) return 0;
    a->probe_steps = -1;
    a->win_steps = 0;
    a->win_t = t;
    a->win_work = work_units(a->st, a->n);
    return 1;
}

/* Reversals. The friction models' right-hand side has a kink where the relative velocity v_r changes
 * sign (LuGre's |v_r|), and Dormand-Prince's embedded error estimate does not see a kink inside a step:
 * in the ringing after a sawtooth's flyback, which reverses v_r every 0.2-1 ms, the steps across a
 * reversal had true local errors of 2.5-92 times the tolerance while the estimate accepted them, and
 * these steps made the default's largest errors (docs/performance.md). So AUTO's Dormand-Prince steps end
 * at reversals of the ODE's kink velocity (integrator.h): the accepted step's dense output, extrapolated over
 * the next step, predicts a reversal in it, and the next step ends just past it (no step is wasted); a
 * step across a reversal that was not predicted is also judged by its dense output at mid-step against
 * the cubic Hermite interpolant of its ends (as Rodas4's steps are, rodas4.c), which tracks the kink's
 * error, and retried ending just past the reversal if that fails. Both sides of a kink are smooth.
 *
 * A sign change counts only where |v_r| exceeds KINK_SIGNIFICANT times its tolerance at an end of the
 * step, and only at the end of a half-cycle of at least KINK_CUT_HALF_CYCLE steps: at its stability limit
 * Dormand-Prince makes v_r oscillate by itself, changing sign every step or two, by 3.6 (li2009-model-i)
 * to 9 (li2009-base) times the tolerance, and cutting steps there buys no accuracy and keeps the steps
 * short, so that the stiffness test never fires (li2009-base ran in Dormand-Prince throughout, at 2.4
 * times the work); the ringing after a flyback changes sign every 3-5 steps. Ringing of v_r above that
 * bound also keeps AUTO from switching to Rodas4 (kink_stiff): Rodas4's long steps do not resolve it and
 * miss its reversals' kinks as well (on a set of the accuracy benchmark, an early switch in such ringing
 * drifted to 1.9e-3 %), while Dormand-Prince must resolve it anyway; the stiffness test's verdict waits
 * until the ringing has decayed below the bound.
 *
 * AUTO only: it pays there because the explicit phases can then run at 1/20 of the tolerances instead of
 * 1/50 (above). A Dopri5 asked for by name keeps its steps: at its tolerance the cuts cost more steps
 * (+20 % on the preset) than a tighter tolerance of the same accuracy would. */
enum {
    KINK_MAX_CUTS = 2,          /* a step is cut at most twice; then its mid-step check judges it */
    KINK_LOCATE_ITERATIONS = 8, /* of the regula falsi on the dense output */
    KINK_RINGING_STEPS = 15,    /* a half-cycle of more steps is no ringing (kink_stiff) */
    KINK_RING_HALF_CYCLE = 2,   /* ... nor one of fewer (kink_stiff) */
    KINK_CUT_HALF_CYCLE = 3     /* a reversal that ends a half-cycle of fewer steps is not cut */
};
static const double KINK_SIGNIFICANT = 5.0;   /* in tolerances of the kink velocity (above) */
static const double KINK_PAST = 1e-4;         /* a step cut at a reversal ends this fraction past it */
static const double KINK_PREDICT_REACH = 2.0; /* the dense output extrapolated at most 2 steps ahead */
static const double KINK_MIN_CUT = 1e-3;      /* a reversal this close (of the next step) is not cut */
static const double KINK_AT_END = 1e-3;       /* a kink this near a step's end makes no error: unchecked */

static inline double kink_velocity(const tf_ode *ode, const double *y)
{
    return ode->kink_minus >= 0 ? y[ode->kink_plus] - y[ode->kink_minus] : y[ode->kink_plus];
}

/* The kink velocity on Dormand-Prince's dense output of the last step, at its fraction s. */
static inline double kink_dense(const work *w, const tf_ode *ode, double s)
{
    double v = tf_dopri5_dense_component(w, ode->kink_plus, s);
    return ode->kink_minus >= 0 ? v - tf_dopri5_dense_component(w, ode->kink_minus, s) : v;
}

/* The bound above which an oscillation of the kink velocity is the model's, not the integrator's. */
static inline double kink_significant(const work *w, const tf_ode *ode)
{
    return KINK_SIGNIFICANT * w->opt->rtol * ode->kink_scale;
}

/* The oscillation's amplitude: the larger of its last half-cycle's peak |v| and the current one's. */
static inline double kink_amplitude(const tf_auto *a)
{
    return a->kink_peak > a->kink_last_peak ? a->kink_peak : a->kink_last_peak;
}

/* A sign change of the kink velocity from g0 to g1, significant (above). */
static inline int reversal(const work *w, const tf_ode *ode, double g0, double g1)
{
    double a0 = fabs(g0), a1 = fabs(g1);
    return g0 * g1 < 0.0 && (a0 > a1 ? a0 : a1) > kink_significant(w, ode);
}

/* The reversal between the fractions a and b of the last step (kink velocities ga, gb of opposite
 * signs) on its dense output, from b's side: the Illinois variant of the regula falsi, until the bracket
 * is narrower than KINK_PAST of the step (2-4 iterations mostly; the cut needs no more). */
static double kink_locate(const work *w, const tf_ode *ode, double a, double ga, double b, double gb)
{
    double c[5]; /* the kink velocity's own dense-output coefficients (one polynomial, not two) */
    for (int k = 0; k < 5; k++)
        c[k] = w->cont[k][ode->kink_plus] - (ode->kink_minus >= 0 ? w->cont[k][ode->kink_minus] : 0.0);
    for (int it = 0, side = 0; it < KINK_LOCATE_ITERATIONS && b - a > KINK_PAST; it++) {
        double s = (a * gb - b * ga) / (gb - ga);
        double gs = tf_dopri5_dense_poly(c, s);
        if (gs == 0.0) return s;
        if ((gs < 0.0) == (ga < 0.0)) {
            a = s, ga = gs;
            if (side == -1) gb *= 0.5;
            side = -1;
        } else {
            b = s, gb = gs;
            if (side == 1) ga *= 0.5;
            side = 1;
        }
    }
    return b;
}

/* A Dormand-Prince step of error err (accepted by it) across a reversal: its error is the larger of err
 * and the mid-step check's; one that fails the check is retried ending just past the reversal. */
double tf_auto_check_step(tf_auto *a, work *w, const double *y, const double *f0, double h, double *yd,
                          double err)
{
    const tf_ode *ode = a->ode;
    if (!a->kinks || !(err >= 0.0 && err <= 1.0)) return err;
    double g0 = kink_velocity(ode, y), g1 = kink_velocity(ode, w->y1);
    if (!reversal(w, ode, g0, g1) || a->kink_steps + 1 < KINK_CUT_HALF_CYCLE) return err;
    if ((kink_dense(w, ode, 1.0 - KINK_AT_END) < 0.0) == (g0 < 0.0)) return err; /* a step cut just past it */
    tf_dopri5_dense(w, 0.5, yd);
    double e_mid = mid_step_error(w, h, y, f0, w->k[6], yd); /* k[6]: f at the end (FSAL) */
    if (!isfinite(e_mid)) return -1.0;
    if (e_mid <= 1.0 || a->kink_cuts >= KINK_MAX_CUTS) return fmax(err, e_mid);
    a->kink_h = fmin(kink_locate(w, ode, 0.0, g0, 1.0, g1) + KINK_PAST, 1.0) * h;
    if (!a->kink_cuts++) a->kink_h_orig = h;
    return fmax(e_mid, 2.0);
}

double tf_auto_retry_step(tf_auto *a)
{
    double h = a->kink_h;
    a->kink_h = 0.0;
    return h;
}

double tf_auto_accepted(tf_auto *a, double hnew)
{
    if (a->kink_h_orig > 0.0) hnew = fmax(hnew, a->kink_h_orig); /* after a cut at a reversal: the step it cut */
    a->kink_h_orig = 0.0;
    a->kink_cuts = 0;
    return hnew;
}

/* After an accepted Dormand-Prince step of size h from y: the oscillation's half-cycle peaks, and the next
 * step, hnew by its control, shortened to end just past a reversal that its dense output, extrapolated, puts
 * inside it. */
static double kink_next(tf_auto *a, const work *w, const double *y, double h, double hnew)
{
    const tf_ode *ode = a->ode;
    const double g0 = kink_velocity(ode, y), g1 = kink_velocity(ode, w->y1), a1 = fabs(g1);
    if (g0 * g1 < 0.0) { /* a new half-cycle */
        a->kink_last_peak = a->kink_peak;
        a->kink_peak = a1;
        a->kink_last_steps = a->kink_steps + 1;
        a->kink_steps = 0;
    } else {
        if (a1 > a->kink_peak) a->kink_peak = a1;
        a->kink_steps++;
    }
    const double reach = hnew < KINK_PREDICT_REACH * h ? hnew / h : KINK_PREDICT_REACH;
    const double gb = kink_dense(w, ode, 1.0 + reach);
    if (!reversal(w, ode, g1, gb) || a->kink_steps + 2 < KINK_CUT_HALF_CYCLE) return hnew;
    double h_kink = (kink_locate(w, ode, 1.0, g1, 1.0 + reach, gb) - 1.0) * h * (1.0 + KINK_PAST);
    return h_kink > KINK_MIN_CUT * hnew ? h_kink : hnew;
}

/* AUTO's switch to the stiff method (stiff: Dormand-Prince's stiffness test fired) waits while v_r
 * rings significantly (above): while its half-cycles peak above the bound and last at least 2 steps
 * (Dormand-Prince's own oscillation changes sign every step or two) and fewer than the stiffness test's
 * count (a slower motion is no ringing that the explicit method sits on). */
static int kink_stiff(tf_auto *a, const work *w, int stiff)
{
    if (stiff) a->stiff_seen = 1;
    int ringing = a->kink_steps < KINK_RINGING_STEPS && a->kink_last_steps >= KINK_RING_HALF_CYCLE &&
                  kink_amplitude(a) > kink_significant(w, a->ode);
    return a->stiff_seen && !ringing;
}

/* The explicit method's window of recent cost (while it runs), and the lock-out's count. */
static void explicit_window(tf_auto *a, int explicit_runs, double t_new)
{
    if (a->lock_steps > 0) a->lock_steps--;
    if (++a->win_steps >= WINDOW_STEPS && explicit_runs) {
        a->win_steps = 0;
        a->win_t = t_new;
        a->win_work = work_units(a->st, a->n);
    }
}

int tf_auto_explicit_step(tf_auto *a, const work *w, const double *y, double h, double t_new, int stiff,
                          double *hnew, tf_solver_stats *st)
{
    if (a->kinks) *hnew = kink_next(a, w, y, h, *hnew), stiff = kink_stiff(a, w, stiff);
    int to_stiff = stiff && a->on && a->lock_steps <= 0 && t_new > a->win_t;
    if (to_stiff) {
        a->explicit_rate = (work_units(st, a->n) - a->win_work) / (t_new - a->win_t);
        st->switch_time = t_new;
        a->probe_t = t_new;
        a->probe_work = work_units(st, a->n);
        a->probe_steps = 0;
    }
    explicit_window(a, !to_stiff, t_new);
    return to_stiff;
}

int tf_auto_probe(tf_auto *a, int method, double t_new, tf_solver_stats *st)
{
    if (!(method == TF_METHOD_RODAS4 && a->on && a->probe_steps >= 0 && ++a->probe_steps >= PROBE_STEPS))
        return 0;
    double rodas_rate = (work_units(st, a->n) - a->probe_work) / (t_new - a->probe_t);
    if (!(rodas_rate >= a->explicit_rate)) {
        a->probe_steps = -1; /* it pays: stay */
        return 0;
    }
    /* the stiff method does not pay: go back */
    st->switch_time = -1.0;
    a->lock_steps = a->lock_len;
    a->lock_len *= 2;
    a->win_steps = 0;
    a->win_t = t_new;
    a->win_work = work_units(st, a->n);
    return 1;
}
