/* Input waveforms (docs/formats.md#inputs). */
#include "thermofriction/waveform.h"
#include "domain_tests.h"
#include "waveform_private.h"

#include <math.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Corners closer than this to t count as "at t": the integrator lands on a corner by
 * computing its time, so the next search must not find the same corner again. */
static double corner_margin(double t) { return 1e-12 * fmax(1.0, fabs(t)); }

/* Index i of the segment [x[i], x[i+1]) that holds t, clamped to [0, n-2]. */
static int pwl_segment(int n, const double *x, double t)
{
    int lo = 0, hi = n - 1;
    if (t <= x[0]) return 0;
    if (t >= x[n - 1]) return n - 2;
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (x[mid] <= t) lo = mid; else hi = mid;
    }
    return lo;
}

double tf_pwl_value(int n, const double *x, const double *y, double t)
{
    if (n <= 0) return 0.0;
    if (n == 1 || t <= x[0]) return y[0];
    if (t >= x[n - 1]) return y[n - 1];
    int i = pwl_segment(n, x, t);
    double s = (t - x[i]) / (x[i + 1] - x[i]);
    return y[i] + s * (y[i + 1] - y[i]);
}

double tf_pwl_slope(int n, const double *x, const double *y, double t)
{
    if (n <= 1 || t < x[0] || t >= x[n - 1]) return 0.0;
    int i = pwl_segment(n, x, t);
    return (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
}

double tf_pwl_next_knot(int n, const double *x, double t)
{
    double tt = t + corner_margin(t);
    if (n <= 0 || tt >= x[n - 1]) return INFINITY;
    if (tt < x[0]) return x[0];
    int i = pwl_segment(n, x, tt);
    return x[i + 1];
}

/* floor(x), by truncation where x fits a 64-bit integer (the same value; a third of the
 * instructions of the portable floor without SSE4.1, and the sawtooth is on every right-hand side) */
static double fast_floor(double x)
{
    if (!(fabs(x) < 4e18)) return floor(x);
    double f = (double)(long long)x;
    return f > x ? f - 1.0 : f;
}

/* Sawtooth shape in [0, 1] at phase ph in [0, 1). */
static double sawtooth_shape(double ph, double rise, double direction, double *dshape)
{
    if (direction < 0) { /* mirrored in time: fast rise, slow fall */
        double s = sawtooth_shape(1.0 - ph, rise, 1.0, dshape);
        if (dshape) *dshape = -*dshape;
        if (ph == 0.0) { /* right-hand slope at the period start */
            if (dshape) *dshape = 1.0 / (1.0 - rise);
            return 0.0;
        }
        return s;
    }
    if (ph < rise) {
        if (dshape) *dshape = 1.0 / rise;
        return ph / rise;
    }
    if (dshape) *dshape = -1.0 / (1.0 - rise);
    return (1.0 - ph) / (1.0 - rise);
}

/* Square shape in [0, 1] at time tau within the period P. */
static double square_shape(double tau, double P, double duty, double slew, double *dshape)
{
    double t_fall = duty * P;
    double d = 0.0, s;
    if (tau < slew) { s = tau / slew; d = 1.0 / slew; }
    else if (tau < t_fall) s = 1.0;
    else if (tau < t_fall + slew) { s = 1.0 - (tau - t_fall) / slew; d = -1.0 / slew; }
    else s = 0.0;
    if (dshape) *dshape = d;
    return s;
}

static double eval(const tf_waveform *w, double t, double *slope)
{
    double d = 0.0, v = 0.0;
    switch (w->kind) {
    case TF_WAVE_SAWTOOTH: {
        double x = t * w->frequency;
        double ph = x - fast_floor(x);
        /* the slope only when asked for: the value is on every right-hand side */
        v = w->offset + w->amplitude * sawtooth_shape(ph, w->rise, w->direction, slope ? &d : 0);
        d *= w->amplitude * w->frequency;
        break;
    }
    case TF_WAVE_SINE: {
        double om = 2.0 * M_PI * w->frequency;
        v = w->offset + w->amplitude * sin(om * t);
        d = w->amplitude * om * cos(om * t);
        break;
    }
    case TF_WAVE_SQUARE: {
        double P = 1.0 / w->frequency;
        double x = t * w->frequency;
        double tau = (x - floor(x)) * P;
        v = w->offset + w->amplitude * square_shape(tau, P, w->rise, w->slew, &d);
        d *= w->amplitude;
        break;
    }
    case TF_WAVE_STEP:
        if (t < w->t0) v = w->offset;
        else if (t < w->t0 + w->slew) {
            v = w->offset + w->amplitude * (t - w->t0) / w->slew;
            d = w->amplitude / w->slew;
        } else v = w->offset + w->amplitude;
        break;
    case TF_WAVE_SAMPLED:
        v = tf_pwl_value(w->n, w->t, w->v, t);
        d = tf_pwl_slope(w->n, w->t, w->v, t);
        break;
    default:
        break;
    }
    if (slope) *slope = d;
    return v;
}

double tf_waveform_value(const tf_waveform *w, double t) { return eval(w, t, 0); }

double tf_waveform_slope(const tf_waveform *w, double t)
{
    double d;
    eval(w, t, &d);
    return d;
}

double tf_waveform_peak_slope_rate(const tf_waveform *w)
{
    if (w->kind != TF_WAVE_SINE) return 0.0; /* piecewise linear: the slope changes only at corners */
    double om = 2.0 * M_PI * w->frequency;
    return fabs(w->amplitude) * om * om;
}

/* Smallest of the per-period corners (k + c_j)/f over this and the next period, > t. */
static double periodic_next(double t, double f, const double *c, int nc)
{
    double tt = t + corner_margin(t);
    double k = floor(tt * f);
    double best = INFINITY;
    for (int p = 0; p < 2; p++)
        for (int j = 0; j < nc; j++) {
            double tc = (k + p + c[j]) / f;
            if (tc > tt && tc < best) best = tc;
        }
    return best;
}

double tf_waveform_next_corner(const tf_waveform *w, double t)
{
    double tt = t + corner_margin(t);
    switch (w->kind) {
    case TF_WAVE_SAWTOOTH: {
        double c[2] = {0.0, w->direction < 0 ? 1.0 - w->rise : w->rise};
        return periodic_next(t, w->frequency, c, 2);
    }
    case TF_WAVE_SQUARE: {
        double P = 1.0 / w->frequency;
        double c[4] = {0.0, w->slew / P, w->rise, w->rise + w->slew / P};
        return periodic_next(t, w->frequency, c, 4);
    }
    case TF_WAVE_STEP:
        if (tt < w->t0) return w->t0;
        if (w->slew > 0 && tt < w->t0 + w->slew) return w->t0 + w->slew;
        return INFINITY;
    case TF_WAVE_SAMPLED:
        return tf_pwl_next_knot(w->n, w->t, t);
    default:
        return INFINITY;
    }
}

double tf_waveform_next_reversal(const tf_waveform *w, double t)
{
    if (w->kind != TF_WAVE_SINE || !(w->frequency > 0)) return INFINITY; /* the others: corners */
    double c[2] = {0.25, 0.75};
    return periodic_next(t, w->frequency, c, 2);
}

long tf_waveform_corners(const tf_waveform *w, double a, double b, double *out, long cap)
{
    /* start a little before a: next_corner skips corners within 1e-12 (relative) of its argument, and a
       corner exactly at a belongs in [a, b] */
    double margin = 1e-12 * fmax(1.0, fabs(a));
    double c = a - 3.0 * margin;
    long count = 0;
    for (int guard = 0; guard < 1000000; guard++) {
        c = tf_waveform_next_corner(w, c);
        if (!(c <= b)) break;
        if (c < a - margin) continue;
        if (count < cap) out[count] = c;
        count++;
    }
    return count;
}

/* ---- checks (tf_model_check, plant.h) ---- */

/* n >= 2 points with finite values and strictly increasing finite times (knots). */
int tf_knots_ok(int n, const double *x, const double *y)
{
    if (n < 2 || !x || !y) return 0;
    for (int i = 0; i < n; i++)
        if (!isfinite(x[i]) || !isfinite(y[i]) || (i && !(x[i] > x[i - 1]))) return 0;
    return 1;
}

const char *tf_waveform_problem(const tf_waveform *w, int prescribed)
{
    if (w->kind == TF_WAVE_ZERO) return 0;
    if (w->kind == TF_WAVE_SAMPLED) {
        if (!tf_knots_ok(w->n, w->t, w->v)) return "input (sampled: two or more finite points, times increasing)";
        for (int i = 1; prescribed && i < w->n; i++)
            if (!isfinite((w->v[i] - w->v[i - 1]) / (w->t[i] - w->t[i - 1])))
                return "input (sampled: slope not finite)";
        return 0;
    }
    if (!isfinite(w->amplitude) || !isfinite(w->offset)) return "input (amplitude, offset)";
    switch (w->kind) {
    case TF_WAVE_SAWTOOTH:
        if (!tf_pos(w->frequency)) return "input (frequency)";
        if (!(w->rise > 0.0 && w->rise < 1.0) && !(!prescribed && (w->rise == 0.0 || w->rise == 1.0)))
            return "input (rise)";
        if (w->direction != 1.0 && w->direction != -1.0) return "input (direction)";
        /* a prescribed motion's velocity is the slope: it must be finite on both flanks */
        if (prescribed && !(isfinite(w->amplitude * w->frequency / w->rise) &&
                            isfinite(w->amplitude * w->frequency / (1.0 - w->rise))))
            return "input (rise: slope not finite)";
        return 0;
    case TF_WAVE_SINE:
        if (!tf_pos(w->frequency)) return "input (frequency)";
        if (prescribed && !isfinite(6.283185307179586 * w->frequency * w->amplitude)) return "input (slope not finite)";
        return 0;
    case TF_WAVE_SQUARE: {
        if (!tf_pos(w->frequency)) return "input (frequency)";
        double P = 1.0 / w->frequency;
        if (!(w->rise > 0.0 && w->rise < 1.0)) return "input (duty)";
        if (!tf_nonneg(w->slew) || (prescribed && !(w->slew > 0.0)) ||
            !(w->slew < fmin(w->rise, 1.0 - w->rise) * P))
            return "input (slew)";
        if (prescribed && !isfinite(w->amplitude / w->slew)) return "input (slew: slope not finite)";
        return 0;
    }
    case TF_WAVE_STEP:
        if (!isfinite(w->t0)) return "input (time)";
        if (!tf_nonneg(w->slew) || (prescribed && !(w->slew > 0.0))) return "input (slew)";
        if (prescribed && !isfinite(w->amplitude / w->slew)) return "input (slew: slope not finite)";
        return 0;
    default:
        return "input (kind)";
    }
}
