/* Temperature laws and their load terms (see law.h). */
#include "thermofriction/law.h"
#include "law_private.h"
#include "waveform_private.h" /* tf_knots_ok */

#include <math.h>

static int segment(int n, const double *x, double T)
{
    int lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        int mid = lo + (hi - lo) / 2;
        if (x[mid] <= T) lo = mid; else hi = mid;
    }
    return lo;
}

static double sgn(double v) { return (v > 0) - (v < 0); }

/* One-sided three-point end slope, limited so the end interval keeps its shape. */
static double pchip_end(double h0, double h1, double m0, double m1)
{
    double d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
    if (sgn(d) != sgn(m0)) return 0.0;
    if (sgn(m0) != sgn(m1) && fabs(d) > 3.0 * fabs(m0)) return 3.0 * m0;
    return d;
}

void tf_pchip_slopes(int n, const double *x, const double *y, double *d)
{
    if (n < 2) { if (n == 1) d[0] = 0.0; return; }
    if (n == 2) { d[0] = d[1] = (y[1] - y[0]) / (x[1] - x[0]); return; }
    for (int k = 1; k < n - 1; k++) {
        double h0 = x[k] - x[k - 1], h1 = x[k + 1] - x[k];
        double m0 = (y[k] - y[k - 1]) / h0, m1 = (y[k + 1] - y[k]) / h1;
        if (m0 == 0.0 || m1 == 0.0 || sgn(m0) != sgn(m1)) { d[k] = 0.0; continue; }
        double w1 = 2.0 * h1 + h0, w2 = h1 + 2.0 * h0;
        d[k] = (w1 + w2) / (w1 / m0 + w2 / m1);
    }
    double h0 = x[1] - x[0], h1 = x[2] - x[1];
    d[0] = pchip_end(h0, h1, (y[1] - y[0]) / h0, (y[2] - y[1]) / h1);
    h0 = x[n - 1] - x[n - 2]; h1 = x[n - 2] - x[n - 3];
    d[n - 1] = pchip_end(h0, h1, (y[n - 1] - y[n - 2]) / h0, (y[n - 2] - y[n - 3]) / h1);
}

static double pwl(const tf_law *law, double T, double *dT)
{
    const double *x = law->x, *y = law->y;
    int n = law->n;
    if (n == 1) { *dT = 0.0; return y[0]; }
    int i = T <= x[0] ? 0 : (T >= x[n - 1] ? n - 2 : segment(n, x, T));
    double slope = (y[i + 1] - y[i]) / (x[i + 1] - x[i]);
    *dT = slope;
    return y[i] + slope * (T - x[i]);
}

static double table(const tf_law *law, double T, double *dT)
{
    const double *x = law->x, *y = law->y, *d = law->d;
    int n = law->n;
    if (n == 1) { *dT = 0.0; return y[0]; }
    if (T < x[0]) { *dT = d[0]; return y[0] + d[0] * (T - x[0]); }
    if (T > x[n - 1]) { *dT = d[n - 1]; return y[n - 1] + d[n - 1] * (T - x[n - 1]); }
    int i = segment(n, x, T);
    if (i > n - 2) i = n - 2;
    double h = x[i + 1] - x[i], s = (T - x[i]) / h;
    double s2 = s * s, s3 = s2 * s;
    double h00 = 2 * s3 - 3 * s2 + 1, h10 = s3 - 2 * s2 + s, h01 = -2 * s3 + 3 * s2, h11 = s3 - s2;
    double dh00 = 6 * s2 - 6 * s, dh10 = 3 * s2 - 4 * s + 1, dh01 = -6 * s2 + 6 * s, dh11 = 3 * s2 - 2 * s;
    *dT = (dh00 * y[i] + dh01 * y[i + 1]) / h + dh10 * d[i] + dh11 * d[i + 1];
    return h00 * y[i] + h10 * h * d[i] + h01 * y[i + 1] + h11 * h * d[i + 1];
}

double tf_law_eval(const tf_law *law, double T, double *dvalue_dT)
{
    double v = 0.0, d = 0.0;
    switch (law->kind) {
    case TF_LAW_CONST: v = law->a; break;
    case TF_LAW_LINEAR: v = law->a * T + law->b; d = law->a; break;
    case TF_LAW_EXP: v = law->a * exp(law->b * T); d = law->b * v; break;
    case TF_LAW_POLY:
        for (int i = law->n - 1; i >= 0; i--) { d = d * T + v; v = v * T + law->y[i]; }
        break;
    case TF_LAW_PWL: v = pwl(law, T, &d); break;
    case TF_LAW_TABLE: v = table(law, T, &d); break;
    default: break;
    }
    if (dvalue_dT) *dvalue_dT = d;
    return v;
}

/* Coefficients of the temperature law alone. */
static int base_ncoef(const tf_law *law)
{
    switch (law->kind) {
    case TF_LAW_CONST: return 1;
    case TF_LAW_LINEAR: case TF_LAW_EXP: return 2;
    case TF_LAW_POLY: case TF_LAW_PWL: return law->n;
    default: return 0;
    }
}

static int has_load(const tf_law *law) { return law->kind != TF_LAW_NONE && law->load.kind != TF_LOAD_NONE; }

int tf_law_ncoef(const tf_law *law)
{
    int n = base_ncoef(law);
    if (has_load(law)) n += (law->load.kind == TF_LOAD_AFFINE) + (law->load.interaction != 0);
    return n;
}

static double base_coef_derivative(const tf_law *law, int coef, double T)
{
    switch (law->kind) {
    case TF_LAW_CONST: return 1.0;
    case TF_LAW_LINEAR: return coef == 0 ? T : 1.0;
    case TF_LAW_EXP: return coef == 0 ? exp(law->b * T) : law->a * T * exp(law->b * T);
    case TF_LAW_POLY: return pow(T, coef);
    case TF_LAW_PWL: {
        int n = law->n;
        if (n == 1) return 1.0;
        const double *x = law->x;
        int i = T <= x[0] ? 0 : (T >= x[n - 1] ? n - 2 : segment(n, x, T));
        double s = (T - x[i]) / (x[i + 1] - x[i]); /* outside [x0, xn]: the end segment, extended */
        if (coef == i) return 1.0 - s;
        if (coef == i + 1) return s;
        return 0.0;
    }
    default: return NAN;
    }
}

/* s, the load's magnitude (saturated where the term has a saturation), and ds/dL into *ds. */
static double magnitude(const tf_load_term *t, double L, double *ds)
{
    double a = fabs(L), sg = sgn(L);
    if (!(t->saturation > 0.0)) { *ds = sg; return a; }
    double th = tanh(a / t->saturation);
    *ds = sg * (1.0 - th * th);
    return t->saturation * th;
}

/* The temperature law's multiplier in the load term: d p / d f. */
static double multiplier(const tf_load_term *t, double s)
{
    if (t->kind == TF_LOAD_PROPORTIONAL) return s;
    return t->combine == TF_COMBINE_PRODUCT ? 1.0 + t->k * s : 1.0;
}

double tf_law_eval_load(const tf_law *law, double T, double L, double *dT, double *dL)
{
    double df, f = tf_law_eval(law, T, &df);
    if (!has_load(law)) {
        if (dT) *dT = df;
        if (dL) *dL = 0.0;
        return f;
    }
    const tf_load_term *t = &law->load;
    double ds, s = magnitude(t, L, &ds), v, dv_ds; /* in models/load_laws.py's order of operations */
    if (t->kind == TF_LOAD_PROPORTIONAL) v = f * s, dv_ds = f;
    else if (t->combine == TF_COMBINE_PRODUCT) v = f * (1.0 + t->k * s), dv_ds = f * t->k;
    else v = f + t->k * s, dv_ds = t->k;
    double dv_dT = df * multiplier(t, s);
    if (t->interaction) {
        v = v + t->c * T * s;
        dv_dT += t->c * s;
        dv_ds += t->c * T;
    }
    if (dT) *dT = dv_dT;
    if (dL) *dL = dv_ds * ds;
    return v;
}

double tf_law_coef_derivative(const tf_law *law, int coef, double T, double L)
{
    if (coef < 0 || coef >= tf_law_ncoef(law) || law->kind == TF_LAW_TABLE) return NAN;
    int nb = base_ncoef(law);
    if (!has_load(law)) return base_coef_derivative(law, coef, T);
    const tf_load_term *t = &law->load;
    double ds, s = magnitude(t, L, &ds);
    if (coef < nb) return multiplier(t, s) * base_coef_derivative(law, coef, T);
    if (coef == nb && t->kind == TF_LOAD_AFFINE)
        return t->combine == TF_COMBINE_PRODUCT ? tf_law_eval(law, T, 0) * s : s;
    return T * s; /* the interaction's c */
}

/* ---- checks (tf_model_check, plant.h) ---- */

int tf_load_term_ok(const tf_load_term *t, int law_kind)
{
    if (t->kind < TF_LOAD_NONE || t->kind > TF_LOAD_AFFINE) return 0;
    if (t->kind == TF_LOAD_NONE) return 1;
    if (law_kind == TF_LAW_TABLE) return 0; /* no coefficient sensitivities */
    if (t->combine != TF_COMBINE_PRODUCT && t->combine != TF_COMBINE_SUM) return 0;
    if (t->kind == TF_LOAD_PROPORTIONAL && t->combine == TF_COMBINE_SUM) return 0;
    if (t->kind == TF_LOAD_AFFINE && !isfinite(t->k)) return 0;
    if (!(t->saturation == 0.0 || (t->saturation > 0.0 && isfinite(t->saturation)))) return 0;
    return !t->interaction || isfinite(t->c);
}

int tf_law_ok(const tf_law *L)
{
    if (L->kind < TF_LAW_NONE || L->kind > TF_LAW_TABLE) return 0;
    if (L->kind != TF_LAW_NONE && L->load.kind != TF_LOAD_NONE && !tf_load_term_ok(&L->load, L->kind)) return 0;
    if (L->kind == TF_LAW_POLY && (L->n < 1 || !L->y)) return 0;
    if (L->kind == TF_LAW_PWL || L->kind == TF_LAW_TABLE)
        return tf_knots_ok(L->n, L->x, L->y) && (L->kind != TF_LAW_TABLE || L->d);
    return 1;
}
