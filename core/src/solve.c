/* The driver of the adaptive integrators (integrator.h: tf_solve): it integrates segment by segment
 * between the input's corners, restarts at every corner and event, writes the dense output on the
 * caller's grid, and bounds its work (max_steps, the interrupt poll). The methods are in dopri5.c and
 * rodas4.c, the choice between them (AUTO) and the reversal handling of AUTO's explicit steps in auto.c (auto.h:
 * the driver asks, AUTO answers), event location in events.c, the work space in work.c. */
#include "auto.h"
#include "events.h" /* and the methods, dopri5.h and rodas4.h */

#include <float.h>
#include <stdlib.h>
#include <string.h>

/* The state of one tf_solve. */
typedef struct {
    work w;                        /* the methods' vectors (work.h) */
    const tf_ode *ode;
    const tf_solver_options *opt;  /* the caller's tolerances (Rodas4's, and Dopri5's unless AUTO) */
    tf_solver_stats *st;
    tf_error *err;                 /* the caller's record (may be NULL) */
    const double *t_out;
    long n_out, next;              /* the output grid and its next sample */
    tf_emit_fn emit;
    void *emit_ctx;
    int n, ne, method;             /* states, event functions, the method running */
    double t, h, *y;               /* where the integration is, the next step, the state (the caller's) */
    double *f0, *yd, *g0, *g1, *gm; /* f(t, y), a dense-output sample, the event functions at t, t + h, mid */
    int jac_current, reject, poll;
    double facold;                 /* Dopri5's PI control */
    int iasti, nonsti;             /* Dopri5's stiffness test */
    tf_rodas4_control rc;
    tf_auto au;                    /* AUTO's choice and its explicit steps' reversals (auto.h) */
} tf_driver;

/* A failure: the step size in the statistics, the rest in the error record (status.h). */
static tf_status fail(tf_solver_stats *st, tf_error *err, tf_status status, double t, double h, long index,
                      const char *what)
{
    st->h_fail = h;
    return tf_error_set(err, status, "solver", what ? what : tf_status_message(status), t, index);
}

/* Hairer's starting step: an explicit Euler step's change in f sets the scale. */
static double tf_initial_step(work *w, double t, const double *y, const double *f0, int order, double hmax)
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
    if (tf_work_setup(&d->w, ode, opt, st)) return fail(st, err, TF_ERR_NO_MEMORY, d->t, 0.0, -1, 0);
    /* without a Jacobian (e.g. sensitivity systems) only the explicit method applies */
    int requested = ode->jac ? opt->method : TF_METHOD_DOPRI5;
    d->method = requested == TF_METHOD_AUTO ? TF_METHOD_DOPRI5 : requested;
    int no_memory = tf_auto_start(&d->au, ode, opt, requested, d->t, st);
    d->w.opt = tf_auto_explicit_options(&d->au, opt);
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
    free(d->g0);
    tf_auto_free(&d->au);
    tf_work_free(&d->w);
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
    if (ode->on_restart) ode->on_restart(d->t, d->y, ode->ctx);
    if (d->ne) ode->events(d->t, d->y, d->g0, ode->ctx);
    if (rhs(&d->w, d->t, d->y, d->f0)) return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, d->h, -1, 0);
    if (tf_auto_restart(&d->au, d->method, d->t, d->t_out[0])) { /* AUTO: the explicit method again, */
        d->method = TF_METHOD_DOPRI5;
        d->w.opt = tf_auto_explicit_options(&d->au, d->opt);
        d->iasti = d->nonsti = 0;
        d->h = tf_initial_step(&d->w, d->t, d->y, d->f0, 5, d->opt->hmax); /* not the stiff method's long ramp step */
    }
    if (d->h <= 0.0)
        d->h = d->opt->h0 > 0 ? d->opt->h0
                              : tf_initial_step(&d->w, d->t, d->y, d->f0, d->method == TF_METHOD_DOPRI5 ? 5 : 4,
                                                d->opt->hmax);
    d->w.t_clamp = nextafter(seg_end, -INFINITY);
    d->jac_current = 0;
    return TF_OK;
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
        *err = tf_auto_check_step(&d->au, &d->w, d->y, d->f0, d->h, d->yd, *err); /* at a reversal */
    }
    return TF_OK;
}

/* A step that failed (non-finite numbers, a singular matrix) or whose error is too large: retried smaller. */
static tf_status reject(tf_driver *d, double err)
{
    double h_retry;
    d->st->rejected++;
    d->reject = 1;
    if (err < 0.0) {
        d->h *= 0.25;
        if (d->h <= 16.0 * DBL_EPSILON * fmax(fabs(d->t), 1e-300))
            return fail(d->st, d->err, TF_ERR_NONFINITE, d->t, d->h, -1, 0);
    } else if ((h_retry = tf_auto_retry_step(&d->au)) > 0.0) { /* ending just past a reversal (auto.c) */
        d->h = h_retry;
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
        if (tf_auto_explicit_step(&d->au, w, d->y, d->h, t_new, stiff, &hnew, d->st)) { /* AUTO: to Rodas4 */
            d->method = TF_METHOD_RODAS4;
            d->w.opt = d->opt;
            d->rc.first = 1;
            d->iasti = 0;
        }
        memcpy(d->f0, w->k[6], sizeof(double) * d->n); /* FSAL */
    }
    if (tf_auto_probe(&d->au, d->method, t_new, d->st)) { /* AUTO: Rodas4 did not pay, back to Dopri5 */
        d->method = TF_METHOD_DOPRI5;
        d->w.opt = tf_auto_explicit_options(&d->au, d->opt);
        d->iasti = d->nonsti = 0; /* f0 = f(t_new, y1) is current: Rodas4 computed it */
    }
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
    hnew = tf_auto_accepted(&d->au, hnew); /* after a cut at a reversal: at least the step it cut */
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
        if (d->ode->max_step) d->h = fmin(d->h, d->ode->max_step(d->t, d->y, d->ode->ctx)); /* the problem's */
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
