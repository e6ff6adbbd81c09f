/* The driver of the adaptive integrators (integrator.h: tf_solve): it integrates segment by segment
 * between the input's corners, restarts at every corner and event, writes the dense output on the
 * caller's grid, and bounds its work (max_steps, the interrupt poll). The methods are in dopri5.c and
 * rodas4.c, the choice between them (AUTO) in auto.c, event location in events.c. */
#include "solve.h"

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* A failure: the step size in the statistics, the rest in the error record (status.h). */
static tf_status fail(tf_solver_stats *st, tf_error *err, tf_status status, double t, double h, long index,
                      const char *what)
{
    st->h_fail = h;
    return tf_error_set(err, status, "solver", what ? what : tf_status_message(status), t, index);
}

/* Hairer's starting step: an explicit Euler step's change in f sets the scale. */
double tf_initial_step(work *w, double t, const double *y, const double *f0, int order, double hmax)
{
    int n = w->n;
    double d0 = wnorm(w, y, y, y), d1 = wnorm(w, f0, y, y);
    double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
    if (hmax > 0) h0 = fmin(h0, hmax);
    for (int i = 0; i < n; i++) w->ytmp[i] = y[i] + h0 * f0[i];
    if (rhs(w, t + h0, w->ytmp, w->k[1])) return h0 * 1e-3;
    for (int i = 0; i < n; i++) w->k[2][i] = w->k[1][i] - f0[i];
    double d2 = wnorm(w, w->k[2], y, y) / h0;
    double dm = fmax(d1, d2);
    double h1 = dm <= 1e-15 ? fmax(1e-6, h0 * 1e-3) : pow(0.01 / dm, 1.0 / (order + 1));
    return fmin(100.0 * h0, h1);
}

/* The work space: one allocation for all of the methods' vectors. */
static tf_status setup(work *w, const tf_ode *ode, const tf_solver_options *opt, tf_solver_stats *st)
{
    int n = ode->n;
    memset(w, 0, sizeof *w);
    w->t_clamp = INFINITY;
    w->ode = ode; w->opt = opt; w->st = st; w->n = n;
    size_t nvec = 7 + 4 + 5 + 3;
    w->block = (double *)malloc(sizeof(double) * (nvec * n + 3 * (size_t)n * n) + sizeof(int) * 5 * n);
    if (!w->block) return TF_ERR_NO_MEMORY;
    double *p = w->block;
    for (int i = 0; i < 7; i++, p += n) w->k[i] = p;
    w->ytmp = p; p += n;
    w->y1 = p; p += n;
    w->ysti = p; p += n;
    w->ft = p; p += n;
    for (int i = 0; i < 5; i++, p += n) w->cont[i] = p;
    w->J = p; p += n * n;
    w->W = p; p += n * n;
    w->Jpos = p; p += n * n;
    w->dinv = p; p += n;
    w->xr = p; p += n;
    w->rtol_w = p; p += n;
    for (int i = 0; i < n; i++) w->rtol_w[i] = opt->rtol_weight ? opt->rtol_weight[i] : 1.0;
    w->piv = (int *)p;
    w->pos = w->piv + n;
    w->partner = w->pos + n;
    w->red = w->partner + n;
    w->qcol = w->red + n;
    return TF_OK;
}

/* The grid is non-decreasing, finite and within +-1e12 s (beyond it a double resolves time to ~1e-4 s,
 * coarser than any dynamics here, and periodic inputs lose their phase); the options make sense. */
static tf_status check_arguments(const tf_ode *ode, const tf_solver_options *opt, const double *t_out, long n_out,
                                 tf_solver_stats *st, tf_error *err)
{
    const tf_status B = TF_ERR_BAD_ARGUMENT;
    if (!ode || !opt || !t_out || ode->n < 0 || n_out < 1)
        return fail(st, err, B, NAN, 0.0, -1, "ode, opt or t_out (NULL, no states or no output time)");
    if (!(opt->rtol > 0) || (ode->n > 0 && !opt->atol) || opt->max_steps <= 0)
        return fail(st, err, B, NAN, 0.0, -1, "options (rtol > 0, atol given, max_steps > 0)");
    for (long i = 0; i < n_out; i++)
        if (!(fabs(t_out[i]) <= 1e12) || (i && !(t_out[i] >= t_out[i - 1])))
            return fail(st, err, B, t_out[i], 0.0, i, "t_out (finite, within +-1e12 s, not decreasing)");
    return TF_OK;
}

/* The driver's state at t_out[0] and its allocations (released by finish, whatever this returns). */
static tf_status start(tf_driver *d, const tf_ode *ode, const tf_solver_options *opt, const double *t_out,
                       long n_out, double *y, tf_emit_fn emit, void *emit_ctx, tf_solver_stats *st, tf_error *err)
{
    memset(d, 0, sizeof *d);
    d->ode = ode, d->opt = opt, d->st = st, d->err = err;
    d->t_out = t_out, d->n_out = n_out, d->emit = emit, d->emit_ctx = emit_ctx;
    d->n = ode->n, d->y = y, d->t = t_out[0];
    if (setup(&d->w, ode, opt, st)) return fail(st, err, TF_ERR_NO_MEMORY, d->t, 0.0, -1, 0);
    /* without a Jacobian (e.g. sensitivity systems) only the explicit method applies */
    d->requested = ode->jac ? opt->method : TF_METHOD_DOPRI5;
    d->method = d->requested == TF_METHOD_AUTO ? TF_METHOD_DOPRI5 : d->requested;
    d->kinks = d->requested == TF_METHOD_AUTO && ode->kink_scale > 0.0; /* reversals (below) */
    int no_memory = tf_auto_start(d);
    d->ne = ode->events ? ode->nevent : 0;
    d->f0 = (double *)malloc(sizeof(double) * d->n);
    d->yd = (double *)malloc(sizeof(double) * d->n);
    d->g0 = (double *)malloc(sizeof(double) * (d->ne + 1) * 3);
    if (d->g0) d->g1 = d->g0 + d->ne + 1, d->gm = d->g1 + d->ne + 1;
    d->facold = 1e-4;
    d->rc = (tf_rodas4_control){1, 0.0, 1.0};
    d->poll = TF_POLL_STEPS; /* steps to the next interrupt poll */
    if (!d->f0 || !d->yd || !d->g0 || no_memory) return fail(st, err, TF_ERR_NO_MEMORY, d->t, 0.0, -1, 0);
    return TF_OK;
}

static void finish(tf_driver *d)
{
    free(d->f0);
    free(d->yd);
    free(d->atol_x);
    free(d->g0);
    free(d->w.block);
}

/* Emits the grid's samples up to t_lim from the dense output of the step [t, t + h], each checked
 * (finite ends of a step can still interpolate to an overflow in between; found by fuzzing: a 1e-3 kg
 * mass under a huge sampled force). The fraction of the step is (t_i - t) * (1 / h) after a whole step
 * (one division per step, not per sample) and (t_i - t) / h before an event. */
static tf_status emit_until(tf_driver *d, double t_lim, int reciprocal)
{
    /* in locals: the emit callback could alias the driver, so that its fields would be reloaded */
    const double t = d->t, h = d->h, hinv = 1.0 / h, *t_out = d->t_out;
    const long n_out = d->n_out;
    const int method = d->method, n = d->n;
    double *yd = d->yd;
    long next = d->next;
    tf_status status = TF_OK;
    for (; next < n_out && t_out[next] <= t_lim; next++) {
        double s = reciprocal ? (t_out[next] - t) * hinv : (t_out[next] - t) / h;
        dense(&d->w, method, s, yd);
        if (!all_finite(yd, n)) {
            status = fail(d->st, d->err, TF_ERR_NONFINITE, t_out[next], h, next, 0);
            break;
        }
        d->emit(next, t_out[next], yd, d->emit_ctx);
    }
    d->next = next;
    return status;
}

/* A restart at t (the start, a corner, an event): the modes for what follows, f0, the method (AUTO),
 * a first step if none is known, and the clamp that keeps the stages before seg_end. */
static tf_status restart(tf_driver *d, double seg_end)
{
    const tf_ode *ode = d->ode;
    d->w.t_clamp = INFINITY;
    d->kink_h = d->kink_h_orig = d->kink_peak = d->kink_last_peak = 0.0;
    d->kink_cuts = d->kink_steps = d->kink_last_steps = d->stiff_seen = 0;
    if (ode->on_restart) ode->on_restart(d->t, d->y, ode->ctx);
    if (d->ne) ode->events(d->t, d->y, d->g0, ode->ctx);
    if (rhs(&d->w, d->t, d->y, d->f0)) return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, d->h, -1, 0);
    tf_auto_restart(d);
    if (d->h <= 0.0)
        d->h = d->opt->h0 > 0 ? d->opt->h0
                              : tf_initial_step(&d->w, d->t, d->y, d->f0, d->method == TF_METHOD_DOPRI5 ? 5 : 4,
                                                d->opt->hmax);
    d->w.t_clamp = nextafter(seg_end, -INFINITY);
    d->jac_current = 0;
    return TF_OK;
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
 * 1/50 (auto.c). A Dopri5 asked for by name keeps its steps: at its tolerance the cuts cost more steps
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
static inline double kink_amplitude(const tf_driver *d)
{
    return d->kink_peak > d->kink_last_peak ? d->kink_peak : d->kink_last_peak;
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
 * and the mid-step check's; one that fails the check is retried ending just past the reversal (reject). */
static double kink_check(tf_driver *d, double err)
{
    const tf_ode *ode = d->ode;
    work *w = &d->w;
    if (!(err >= 0.0 && err <= 1.0)) return err;
    double g0 = kink_velocity(ode, d->y), g1 = kink_velocity(ode, w->y1);
    if (!reversal(w, ode, g0, g1) || d->kink_steps + 1 < KINK_CUT_HALF_CYCLE) return err;
    if ((kink_dense(w, ode, 1.0 - KINK_AT_END) < 0.0) == (g0 < 0.0)) return err; /* a step cut just past it */
    const double h = d->h;
    tf_dopri5_dense(w, 0.5, d->yd);
    double e_mid = mid_step_error(w, h, d->y, d->f0, w->k[6], d->yd); /* k[6]: f at the end (FSAL) */
    if (!isfinite(e_mid)) return -1.0;
    if (e_mid <= 1.0 || d->kink_cuts >= KINK_MAX_CUTS) return fmax(err, e_mid);
    d->kink_h = fmin(kink_locate(w, ode, 0.0, g0, 1.0, g1) + KINK_PAST, 1.0) * h;
    if (!d->kink_cuts++) d->kink_h_orig = h;
    return fmax(e_mid, 2.0);
}

/* After an accepted Dormand-Prince step: the oscillation's half-cycle peaks, and the next step, hnew by
 * its control, shortened to end just past a reversal that its dense output, extrapolated, puts inside it. */
static double kink_next(tf_driver *d, double hnew)
{
    const tf_ode *ode = d->ode;
    const work *w = &d->w;
    const double h = d->h, g0 = kink_velocity(ode, d->y), g1 = kink_velocity(ode, w->y1), a1 = fabs(g1);
    if (g0 * g1 < 0.0) { /* a new half-cycle */
        d->kink_last_peak = d->kink_peak;
        d->kink_peak = a1;
        d->kink_last_steps = d->kink_steps + 1;
        d->kink_steps = 0;
    } else {
        if (a1 > d->kink_peak) d->kink_peak = a1;
        d->kink_steps++;
    }
    const double reach = hnew < KINK_PREDICT_REACH * h ? hnew / h : KINK_PREDICT_REACH;
    const double gb = kink_dense(w, ode, 1.0 + reach);
    if (!reversal(w, ode, g1, gb) || d->kink_steps + 2 < KINK_CUT_HALF_CYCLE) return hnew;
    double h_kink = (kink_locate(w, ode, 1.0, g1, 1.0 + reach, gb) - 1.0) * h * (1.0 + KINK_PAST);
    return h_kink > KINK_MIN_CUT * hnew ? h_kink : hnew;
}

/* AUTO's switch to the stiff method (stiff: Dormand-Prince's stiffness test fired) waits while v_r
 * rings significantly (above): while its half-cycles peak above the bound and last at least 2 steps
 * (Dormand-Prince's own oscillation changes sign every step or two) and fewer than the stiffness test's
 * count (a slower motion is no ringing that the explicit method sits on). */
static int kink_stiff(tf_driver *d, int stiff)
{
    if (stiff) d->stiff_seen = 1;
    int ringing = d->kink_steps < KINK_RINGING_STEPS && d->kink_last_steps >= KINK_RING_HALF_CYCLE &&
                  kink_amplitude(d) > kink_significant(&d->w, d->ode);
    return d->stiff_seen && !ringing;
}

/* One attempted step of the current method into *err (negative: non-finite or singular). */
static tf_status attempt(tf_driver *d, double seg_end, double *err)
{
    if (d->method == TF_METHOD_RODAS4) {
        if (!d->jac_current) {
            if (tf_rodas4_jacobian(&d->w, d->t, seg_end, d->y, d->f0))
                return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, d->h, -1, 0);
            d->jac_current = 1;
        }
        *err = tf_rodas4_step(&d->w, d->t, d->h, d->y, d->f0, d->yd);
    } else {
        *err = tf_dopri5_step(&d->w, d->t, d->h, d->y, d->f0);
        if (d->kinks) *err = kink_check(d, *err);
    }
    return TF_OK;
}

/* A step that failed (non-finite numbers, a singular matrix) or whose error is too large: retried smaller. */
static tf_status reject(tf_driver *d, double err)
{
    d->st->rejected++;
    d->reject = 1;
    if (err < 0.0) {
        d->h *= 0.25;
        if (d->h <= 16.0 * DBL_EPSILON * fmax(fabs(d->t), 1e-300))
            return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, d->h, -1, 0);
    } else if (d->kink_h > 0.0) { /* retried ending just past a reversal (kink_check) */
        d->h = d->kink_h;
        d->kink_h = 0.0;
        d->reject = 0;
    } else {
        d->h = d->method == TF_METHOD_RODAS4 ? tf_rodas4_rejected_h(err, d->h) : tf_dopri5_rejected_h(err, d->h);
    }
    return TF_OK;
}

/* An event inside the accepted step [t, t_new]: the step ends there, the samples up to it are emitted,
 * *at_event is set (the segment restarts). An event located within the corner margin of the corner
 * that ends this segment is taken at the corner: a restart just before it would find the corner
 * already passed and integrate across it. */
static tf_status end_at_event(tf_driver *d, double t_new, int last, double seg_end, double corner, int *at_event)
{
    const tf_ode *ode = d->ode;
    double t = d->t, h = d->h;
    double s_ev = tf_locate_event(&d->w, d->method, d->ne, t, h, d->g0, t_new, d->w.y1, d->g1, d->gm, d->yd);
    if (s_ev >= 0.0 && s_ev < 1.0 && last && seg_end == corner && !(ode->next_corner(t + s_ev * h, ode->ctx) <= corner))
        s_ev = 1.0;
    if (s_ev < 0.0) {
        memcpy(d->g0, d->g1, sizeof(double) * d->ne);
        return TF_OK;
    }
    double t_ev = s_ev >= 1.0 ? t_new : t + s_ev * h;
    tf_status status = emit_until(d, t_ev, 0);
    if (status) return status;
    if (s_ev >= 1.0) memcpy(d->y, d->w.y1, sizeof(double) * d->n);
    else dense(&d->w, d->method, s_ev, d->y);
    d->st->steps++;
    d->st->events++;
    d->h = fmax(h * s_ev, 1e-6 * h); /* the next segment starts with a step like this one */
    d->t = t_ev;
    d->rc.first = 1;
    d->reject = 0;
    *at_event = 1;
    return TF_OK;
}

/* The next step after an accepted one of error err ending at t_new, and f0 there. */
static double next_step(tf_driver *d, double err, double t_new, int last)
{
    work *w = &d->w;
    double hnew;
    if (d->method == TF_METHOD_RODAS4) {
        hnew = tf_rodas4_next_h(err, d->h, &d->rc);
        if (!last) memcpy(d->f0, w->k[6], sizeof(double) * d->n); /* f(t_new, y1), from the mid-step check */
        d->jac_current = 0;
    } else {
        hnew = tf_dopri5_next_h(err, d->h, &d->facold);
        int stiff = tf_dopri5_stiff(w, d->opt, d->h, &d->iasti, &d->nonsti);
        if (stiff) d->st->stiff_suspected = 1;
        if (d->kinks) hnew = kink_next(d, hnew), stiff = kink_stiff(d, stiff);
        memcpy(d->f0, w->k[6], sizeof(double) * d->n); /* FSAL */
        tf_auto_explicit_step(d, t_new, stiff);
    }
    tf_auto_probe(d, t_new);
    return hnew;
}

/* An accepted step: to an event inside it (*at_event), else to its end with the samples on the way. */
static tf_status accept(tf_driver *d, double err, int last, double seg_end, double corner, int *at_event)
{
    double t_new = last ? seg_end : d->t + d->h;
    tf_status status;
    if (d->ne && ((status = end_at_event(d, t_new, last, seg_end, corner, at_event)) || *at_event)) return status;
    if ((status = emit_until(d, t_new, 1))) return status;
    d->st->steps++;
    double hnew = next_step(d, err, t_new, last);
    if (d->reject) hnew = fmin(hnew, d->h);
    if (d->kink_h_orig > 0.0) hnew = fmax(hnew, d->kink_h_orig); /* after a cut at a reversal: the step it cut */
    d->kink_h_orig = 0.0;
    d->kink_cuts = 0;
    d->reject = 0;
    memcpy(d->y, d->w.y1, sizeof(double) * d->n);
    d->t = t_new;
    d->h = hnew;
    return TF_OK;
}

/* Steps from t to seg_end (a corner, or the grid's end), or to the first event before it. */
static tf_status segment(tf_driver *d, double seg_end, double corner)
{
    const tf_solver_options *opt = d->opt;
    while (d->t < seg_end) {
        if (d->st->steps + d->st->rejected >= opt->max_steps)
            return fail(d->st, d->err, TF_ERR_MAX_STEPS, d->t, d->h, -1, 0);
        if (opt->interrupt && --d->poll <= 0) {
            d->poll = TF_POLL_STEPS;
            if (opt->interrupt(opt->interrupt_ctx)) return fail(d->st, d->err, TF_ERR_INTERRUPTED, d->t, d->h, -1, 0);
        }
        if (opt->hmax > 0) d->h = fmin(d->h, opt->hmax);
        int last = 0, at_event = 0;
        tf_status status;
        if (d->t + 1.01 * d->h >= seg_end) { d->h = seg_end - d->t; last = 1; }
        if (d->h <= 16.0 * DBL_EPSILON * fmax(fabs(d->t), 1e-300))
            return fail(d->st, d->err, TF_ERR_STEP_UNDERFLOW, d->t, d->h, -1, 0);
        double err = -1.0; /* set by attempt */
        if ((status = attempt(d, seg_end, &err))) return status;
        if (err < 0.0 || !(err <= 1.0)) status = reject(d, err);
        else status = accept(d, err, last, seg_end, corner, &at_event);
        if (status || at_event) return status;
    }
    return TF_OK;
}

/* The whole grid: segments between the input's corners, each begun by a restart. */
static tf_status integrate(tf_driver *d)
{
    double t_end = d->t_out[d->n_out - 1];
    while (d->next < d->n_out && d->t_out[d->next] <= d->t) d->emit(d->next, d->t_out[d->next], d->y, d->emit_ctx), d->next++;
    if (!all_finite(d->y, d->n)) return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, 0.0, -1, 0);
    while (d->t < t_end) {
        /* what is left may be a rounding residue (a corner computed one ulp before the grid's
         * end): nothing to integrate, and a step that small would count as an underflow */
        if (t_end - d->t <= 64.0 * DBL_EPSILON * fabs(t_end)) break;
        double corner = d->ode->next_corner ? d->ode->next_corner(d->t, d->ode->ctx) : INFINITY;
        double seg_end = fmin(corner, t_end);
        if (!(seg_end > d->t) || t_end - seg_end <= 64.0 * DBL_EPSILON * fabs(t_end)) seg_end = t_end;
        tf_status status = restart(d, seg_end);
        if (!status) status = segment(d, seg_end, corner);
        if (status) return status;
    }
    while (d->next < d->n_out) d->emit(d->next, d->t_out[d->next], d->y, d->emit_ctx), d->next++;
    return TF_OK;
}

tf_status tf_solve(const tf_ode *ode, const tf_solver_options *opt, const double *t_out, long n_out,
                   double *y, tf_emit_fn emit, void *emit_ctx, tf_solver_stats *st, tf_error *err)
{
    tf_solver_stats unused;
    if (!st) st = &unused;
    memset(st, 0, sizeof *st);
    st->switch_time = -1.0;
    tf_status status = check_arguments(ode, opt, t_out, n_out, st, err);
    if (status) return status;
    if (!y || !emit) return fail(st, err, TF_ERR_BAD_ARGUMENT, NAN, 0.0, -1, "y0 or emit (NULL)");
    if (ode->n == 0) { /* nothing to integrate (a static friction map under prescribed motion) */
        for (long i = 0; i < n_out; i++) emit(i, t_out[i], y, emit_ctx);
        st->method_used = opt->method;
        return tf_error_set(err, TF_OK, 0, 0, NAN, -1);
    }
    tf_driver d;
    status = start(&d, ode, opt, t_out, n_out, y, emit, emit_ctx, st, err);
    if (!status) status = integrate(&d);
    st->method_used = d.method;
    finish(&d);
    return status ? status : tf_error_set(err, TF_OK, 0, 0, NAN, -1);
}
