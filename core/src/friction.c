/* Friction models (docs/models.md#friction-models). */
#include "thermofriction/friction.h"
#include "domain_tests.h"
#include "friction_private.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static double sgn(double v) { return (v > 0) - (v < 0); }

int tf_friction_nstate(int kind, int n_elements)
{
    if (kind < 0 || kind >= TF_NFRICTION) return -1;
    int n = tf_friction_states(kind);
    if (n != TF_STATES_PER_ELEMENT) return n;
    return (n_elements >= 1 && n_elements <= TF_MAX_FRICTION_STATES) ? n_elements : -1;
}

double tf_friction_reference_force(int kind, const double *p)
{
    (void)kind;
    return p[TF_P_FC];
}

/* (|v|/vs)^delta: the Gaussian Stribeck curve (delta = 2, the default) without a pow, the same number */
static double stribeck_power(double r, double delta) { return delta == 2.0 ? r * r : pow(r, delta); }

/* g(v), with dg/dv into *dg and its parameter partials into dg_p[TF_NPARAM] where not NULL: both from one
 * exponential (tf_stribeck, tf_stribeck_param_partials, and the bristle models' evaluations that need both);
 * the exponent delta's partial (a logarithm) only with delta_partial (else it stays zero). */
static inline double stribeck_curve(const double *p, double v, double *dg, double *dg_p, int delta_partial)
{
    double fc = p[TF_P_FC], fs = p[TF_P_FS], vs = p[TF_P_VS], delta = p[TF_P_DELTA];
    if (dg) *dg = 0.0;
    if (dg_p) {
        memset(dg_p, 0, sizeof(double) * TF_NPARAM);
        if (v == 0.0 || !(vs > 0.0)) dg_p[v == 0.0 ? TF_P_FS : TF_P_FC] = 1.0; /* g = fs at rest (fc without vs) */
    }
    if (v == 0.0 || !(vs > 0.0) || (fs == fc && !dg_p)) return v == 0.0 ? fs : fc;
    double r = fabs(v / vs);
    double rd = stribeck_power(r, delta);
    double e = exp(-rd);
    if (dg_p) {
        dg_p[TF_P_FC] = 1.0 - e;
        dg_p[TF_P_FS] = e;
    }
    if (fs == fc) return fc; /* no Stribeck effect: vs and delta do not act (their partials stay 0) */
    if (dg_p) {
        dg_p[TF_P_VS] = (fs - fc) * e * delta * rd / vs;
        if (delta_partial) dg_p[TF_P_DELTA] = -(fs - fc) * e * rd * log(r);
    }
    if (dg) *dg = -(fs - fc) * e * delta * (rd / r) * sgn(v) / vs;
    return fc + (fs - fc) * e;
}

double tf_stribeck(const double *p, double v, double *dg) { return stribeck_curve(p, v, dg, 0, 0); }

void tf_stribeck_param_partials(const double *p, double v, double *dg) { stribeck_curve(p, v, 0, dg, 1); }

/* LuGre (Canudas de Wit et al. 1995):
 *   z' = v - sigma0 |v| z / g(v),  F = sigma0 z + sigma1(v) z' + sigma2 v  (sigma1(v): tf_sigma1). */

/* What a bristle model's evaluation at one velocity needs, whatever the state: g(v) (dg/dv with jac), sigma1(v)
 * and its derivatives, and with dp g's parameter partials (LuGre: lugre_velocity; the exact stepping evaluates
 * two states at one velocity from one of these, tf_friction_affine_set). */
typedef struct {
    double g, dg, s1, ds1, ds1_dsigma1, ds1_dvd;
    double dg_p[TF_NPARAM];
} bristle_velocity;

static inline void lugre_velocity(const double *p, double v, int jac, int dp, int delta, bristle_velocity *w)
{
    w->dg = 0.0;
    w->g = stribeck_curve(p, v, jac ? &w->dg : 0, dp ? w->dg_p : 0, delta);
    w->ds1_dsigma1 = 0.0, w->ds1_dvd = 0.0;
    w->s1 = tf_sigma1(p, v, &w->ds1, dp ? &w->ds1_dsigma1 : 0, dp ? &w->ds1_dvd : 0);
}

/* LuGre at state z, from its velocity's pieces w (lugre_velocity with jac and dp as here). */
static inline double lugre_state(const double *p, double v, const bristle_velocity *w, const double *z, double *dz,
                          tf_friction_partials *jac, tf_friction_param_partials *dp)
{
    double s0 = p[TF_P_SIGMA0], s2 = p[TF_P_SIGMA2];
    double g = w->g, dg = w->dg, s1 = w->s1;
    double r = s0 * fabs(v) / g; /* relaxation rate of z */
    double zd, F = tf_lugre_value(p, v, z[0], g, s1, &zd);
    dz[0] = zd;
    if (jac) {
        double dr = s0 * (sgn(v) * g - fabs(v) * dg) / (g * g);
        jac->ddz_dz[0] = -r;
        jac->ddz_dv[0] = 1.0 - z[0] * dr;
        jac->dF_dz[0] = s0 + s1 * jac->ddz_dz[0];
        jac->dF_dv = w->ds1 * zd + s1 * jac->ddz_dv[0] + s2;
    }
    if (dp) {
        double dzd_dg = s0 * fabs(v) * z[0] / (g * g); /* z' = v - sigma0 |v| z / g */
        for (int i = 0; i < TF_NPARAM; i++) dp->ddz_dp[0][i] = dzd_dg * w->dg_p[i];
        dp->ddz_dp[0][TF_P_SIGMA0] = -fabs(v) * z[0] / g;
        for (int i = 0; i < TF_NPARAM; i++) dp->dF_dp[i] = s1 * dp->ddz_dp[0][i];
        dp->dF_dp[TF_P_SIGMA0] += z[0];
        dp->dF_dp[TF_P_SIGMA1] = w->ds1_dsigma1 * zd;
        dp->dF_dp[TF_P_SIGMA2] = v;
        dp->dF_dp[TF_P_VD] = w->ds1_dvd * zd;
    }
    return F;
}

static double lugre(const double *p, double v, const double *z, double *dz, tf_friction_partials *jac,
                    tf_friction_param_partials *dp)
{
    bristle_velocity w;
    lugre_velocity(p, v, jac != 0, dp != 0, 1, &w);
    return lugre_state(p, v, &w, z, dz, jac, dp);
}

/* Static maps: F = G(v) s(v) + sigma2 v with the sign smoothed over v_smooth, s = tanh(v / v_smooth),
 * G = fc (Coulomb) or g(v) (Stribeck). */
static double static_map(int stribeck, const double *p, double v, tf_friction_partials *jac,
                         tf_friction_param_partials *dp)
{
    double vsm = p[TF_P_VSMOOTH], s2 = p[TF_P_SIGMA2];
    double dG = 0.0;
    double G = stribeck ? tf_stribeck(p, v, jac ? &dG : 0) : p[TF_P_FC];
    double s = tanh(v / vsm);
    if (jac) jac->dF_dv = G * (1.0 - s * s) / vsm + dG * s + s2;
    if (dp) {
        if (stribeck) {
            double dg[TF_NPARAM];
            tf_stribeck_param_partials(p, v, dg);
            for (int i = 0; i < TF_NPARAM; i++) dp->dF_dp[i] = dg[i] * s;
        } else {
            dp->dF_dp[TF_P_FC] = s;
        }
        dp->dF_dp[TF_P_SIGMA2] = v;
        dp->dF_dp[TF_P_VSMOOTH] = -G * (1.0 - s * s) * v / (vsm * vsm);
    }
    return G * s + s2 * v;
}

/* Dahl (1968): z' = v - sigma0 |v| z / fc, F = sigma0 z. */
static double dahl(const double *p, double v, const double *z, double *dz, tf_friction_partials *jac,
                   tf_friction_param_partials *dp)
{
    double s0 = p[TF_P_SIGMA0], fc = p[TF_P_FC];
    dz[0] = v - s0 * fabs(v) * z[0] / fc;
    if (jac) {
        jac->ddz_dz[0] = -s0 * fabs(v) / fc;
        jac->ddz_dv[0] = 1.0 - s0 * sgn(v) * z[0] / fc;
        jac->dF_dz[0] = s0;
        jac->dF_dv = 0.0;
    }
    if (dp) {
        dp->ddz_dp[0][TF_P_SIGMA0] = -fabs(v) * z[0] / fc;
        dp->ddz_dp[0][TF_P_FC] = s0 * fabs(v) * z[0] / (fc * fc);
        dp->dF_dp[TF_P_SIGMA0] = z[0];
    }
    return s0 * z[0];
}

/* Elasto-plastic (Dupont et al. 2002): z' = v - alpha(z, v) sigma0 |v| z / g(v). alpha is zero
 * below the break-away deflection z_ba and when z opposes v (purely elastic: no drift under
 * small forces), one from the steady deflection z_ss = g(v)/sigma0 on, and a half sine between. */
static double elastoplastic(const double *p, double v, const double *z, double *dz, tf_friction_partials *jac,
                            tf_friction_param_partials *dp)
{
    double s0 = p[TF_P_SIGMA0], s2 = p[TF_P_SIGMA2], zba = p[TF_P_ZBA];
    double dg = 0.0;
    double g = tf_stribeck(p, v, jac ? &dg : 0);
    double zss = g / s0, az = fabs(z[0]);
    double alpha = 0.0, da_dz = 0.0, da_dzss = 0.0, da_dzba = 0.0;
    if (z[0] * v > 0.0 && az > zba) {
        if (az >= zss) {
            alpha = 1.0;
        } else {
            double width = zss - zba;
            double u = (az - 0.5 * (zss + zba)) / width;
            double du_dz = sgn(z[0]) / width, du_dzss = (zba - az) / (width * width);
            double du_dzba = (az - zss) / (width * width);
            alpha = 0.5 * sin(M_PI * u) + 0.5;
            double da_du = 0.5 * M_PI * cos(M_PI * u);
            da_dz = da_du * du_dz;
            da_dzss = da_du * du_dzss;
            da_dzba = da_du * du_dzba;
        }
    }
    double r = s0 * fabs(v) / g;
    double zd = v - alpha * r * z[0];
    double ds1, ds1_dsigma1 = 0.0, ds1_dvd = 0.0;
    double s1 = tf_sigma1(p, v, &ds1, dp ? &ds1_dsigma1 : 0, dp ? &ds1_dvd : 0);
    dz[0] = zd;
    if (jac) {
        double dr = s0 * (sgn(v) * g - fabs(v) * dg) / (g * g);
        double da_dv = da_dzss * dg / s0;
        jac->ddz_dz[0] = -r * (alpha + z[0] * da_dz);
        jac->ddz_dv[0] = 1.0 - z[0] * (da_dv * r + alpha * dr);
        jac->dF_dz[0] = s0 + s1 * jac->ddz_dz[0];
        jac->dF_dv = ds1 * zd + s1 * jac->ddz_dv[0] + s2;
    }
    if (dp) {
        /* g enters through r = sigma0 |v| / g and z_ss = g / sigma0; sigma0 through both as well */
        double dg_p[TF_NPARAM];
        tf_stribeck_param_partials(p, v, dg_p);
        double dzd_dg = -z[0] * (da_dzss * r / s0 - alpha * r / g);
        for (int i = 0; i < TF_NPARAM; i++) dp->ddz_dp[0][i] = dzd_dg * dg_p[i];
        dp->ddz_dp[0][TF_P_SIGMA0] = -z[0] * (-da_dzss * zss / s0 * r + alpha * r / s0);
        dp->ddz_dp[0][TF_P_ZBA] = -z[0] * r * da_dzba;
        for (int i = 0; i < TF_NPARAM; i++) dp->dF_dp[i] = s1 * dp->ddz_dp[0][i];
        dp->dF_dp[TF_P_SIGMA0] += z[0];
        dp->dF_dp[TF_P_SIGMA1] = ds1_dsigma1 * zd;
        dp->dF_dp[TF_P_SIGMA2] = v;
        dp->dF_dp[TF_P_VD] = ds1_dvd * zd;
    }
    return s0 * z[0] + s1 * zd + s2 * v;
}

/* Generalized Maxwell-slip (Al-Bender, Lampaert and Swevers 2005): F = sum F_i + sigma2 v. */
static double gms(const double *p, const tf_gms_elements *el, double v, const double *z, double *dz,
                  tf_friction_partials *jac, tf_friction_param_partials *dp)
{
    double C = p[TF_P_C], dg = 0.0;
    double g = tf_stribeck(p, v, jac ? &dg : 0);
    double F = p[TF_P_SIGMA2] * v;
    double dg_p[TF_NPARAM];
    if (dp) {
        tf_stribeck_param_partials(p, v, dg_p);
        dp->dF_dp[TF_P_SIGMA2] = v;
    }
    for (int i = 0; i < el->n; i++) {
        F += z[i];
        if (el->mode[i] == 0) {
            dz[i] = el->k[i] * v; /* stuck: no parameter of the list enters (k_i are arrays) */
            if (jac) { jac->ddz_dz[i] = 0.0; jac->ddz_dv[i] = el->k[i]; }
        } else {
            dz[i] = C * (el->mode[i] * el->w[i] - z[i] / g);
            if (jac) { jac->ddz_dz[i] = -C / g; jac->ddz_dv[i] = C * z[i] * dg / (g * g); }
            if (dp) {
                for (int j = 0; j < TF_NPARAM; j++) dp->ddz_dp[i][j] = C * z[i] / (g * g) * dg_p[j];
                dp->ddz_dp[i][TF_P_C] = el->mode[i] * el->w[i] - z[i] / g;
            }
        }
        if (jac) jac->dF_dz[i] = 1.0;
    }
    if (jac) jac->dF_dv = p[TF_P_SIGMA2];
    return F;
}

double tf_friction_eval_side(int kind, const double *p, const tf_gms_elements *el, double v, const double *z,
                             double *dz, tf_friction_partials *jac, tf_friction_param_partials *dp)
{
    if (jac) jac->dF_dx = 0.0;
    if (kind == TF_FRICTION_LUGRE) return lugre(p, v, z, dz, jac, dp);
    if (dp) { /* each model writes the entries its equations have; the rest stay zero */
        int nz = kind == TF_FRICTION_GMS && el ? el->n : 1;
        memset(dp->dF_dp, 0, sizeof dp->dF_dp);
        memset(dp->ddz_dp, 0, sizeof(dp->ddz_dp[0]) * (size_t)(nz > 0 ? nz : 1));
    }
    switch (kind) {
    case TF_FRICTION_COULOMB: return static_map(0, p, v, jac, dp);
    case TF_FRICTION_STRIBECK: return static_map(1, p, v, jac, dp);
    case TF_FRICTION_DAHL: return dahl(p, v, z, dz, jac, dp);
    case TF_FRICTION_ELASTOPLASTIC: return elastoplastic(p, v, z, dz, jac, dp);
    case TF_FRICTION_GMS: return gms(p, el, v, z, dz, jac, dp);
    default: return NAN;
    }
}

/* ---- direction-dependent friction and the position ripple ---- */

static const int sided_pos[] = {TF_P_FC, TF_P_FS, TF_P_VS, TF_P_SIGMA2};
static const int sided_neg[] = {TF_P_FC_NEG, TF_P_FS_NEG, TF_P_VS_NEG, TF_P_SIGMA2_NEG};
#define NSIDED 4

/* fs_neg absent, fc_neg given and fs = fc: no Stribeck effect on the negative side either */
static int fs_neg_follows_fc_neg(const double *p)
{
    return !tf_side_given(p[TF_P_FS_NEG]) && tf_side_given(p[TF_P_FC_NEG]) && p[TF_P_FS] == p[TF_P_FC];
}

const double *tf_friction_side(const double *p, double v, double *q)
{
    if (!(v < 0.0) || !tf_friction_asymmetric(p)) return p;
    memcpy(q, p, sizeof(double) * TF_NPARAM);
    for (int i = 0; i < NSIDED; i++)
        if (tf_side_given(p[sided_neg[i]])) q[sided_pos[i]] = p[sided_neg[i]];
    if (fs_neg_follows_fc_neg(p)) q[TF_P_FS] = q[TF_P_FC];
    return q;
}

/* Partials computed on the negative side's values (in the positive slots) moved to the negative
 * parameters they came from: the same expressions, on the negative side. */
static void to_negative_side(const double *p, double *d)
{
    if (fs_neg_follows_fc_neg(p)) d[TF_P_FC] += d[TF_P_FS], d[TF_P_FS] = 0.0;
    for (int i = 0; i < NSIDED; i++)
        if (tf_side_given(p[sided_neg[i]])) d[sided_neg[i]] = d[sided_pos[i]], d[sided_pos[i]] = 0.0;
}

void tf_friction_side_partials(const double *p, double v, double *d)
{
    if (v < 0.0 && tf_friction_asymmetric(p)) to_negative_side(p, d);
}

double tf_friction_eval(int kind, const double *p, const tf_gms_elements *el, double v, const double *z,
                        double *dz, tf_friction_partials *jac, tf_friction_param_partials *dp)
{
    if (!(v < 0.0) || !tf_friction_asymmetric(p)) return tf_friction_eval_side(kind, p, el, v, z, dz, jac, dp);
    double q[TF_NPARAM];
    tf_friction_side(p, v, q);
    double F = tf_friction_eval_side(kind, q, el, v, z, dz, jac, dp);
    if (dp) {
        int nz = tf_friction_nstate(kind, el ? el->n : 0);
        to_negative_side(p, dp->dF_dp);
        for (int j = 0; j < nz; j++) to_negative_side(p, dp->ddz_dp[j]);
    }
    return F;
}

/* ---- the one-state models at one velocity, for the exact stepping of a prescribed motion ---- */

int tf_friction_affine_in_z(int kind) { return kind == TF_FRICTION_LUGRE || kind == TF_FRICTION_DAHL; }

void tf_friction_affine_set(int kind, const double *p, double v, int delta, tf_friction_affine *a)
{
    static const double zero = 0.0, one = 1.0;
    double dz0, dz1;
    tf_friction_partials jac;
    tf_friction_param_partials d0, d1;
    a->kind = kind;
    a->v = v;
    a->negative = v < 0.0 && tf_friction_asymmetric(p);
    const double *q = a->negative ? tf_friction_side(p, v, a->q) : p;
    if (kind == TF_FRICTION_LUGRE) { /* g, sigma1 and g's partials once for both states */
        bristle_velocity w;
        lugre_velocity(q, v, 1, 1, delta, &w);
        lugre_state(q, v, &w, &zero, &dz0, &jac, &d0);
        lugre_state(q, v, &w, &one, &dz1, 0, &d1);
        a->g = w.g, a->s1 = w.s1;
    } else {
        tf_friction_eval_side(kind, q, 0, v, &zero, &dz0, &jac, &d0);
        tf_friction_eval_side(kind, q, 0, v, &one, &dz1, 0, &d1);
    }
    a->a = dz0;
    a->b = jac.ddz_dz[0];
    a->dF_dz = jac.dF_dz[0];
    for (int i = 0; i < TF_NPARAM; i++) {
        a->da[i] = d0.ddz_dp[0][i];
        a->db[i] = d1.ddz_dp[0][i] - a->da[i];
        a->dF0[i] = d0.dF_dp[i];
        a->dF1[i] = d1.dF_dp[i] - a->dF0[i];
    }
    if (a->negative) { /* the move is linear: on the slopes as on the values */
        to_negative_side(p, a->da);
        to_negative_side(p, a->db);
        to_negative_side(p, a->dF0);
        to_negative_side(p, a->dF1);
    }
}

double tf_friction_affine_force(const tf_friction_affine *a, const double *p, double z)
{
    const double *q = a->negative ? a->q : p;
    double zd;
    if (a->kind == TF_FRICTION_LUGRE) return tf_lugre_value(q, a->v, z, a->g, a->s1, &zd);
    return tf_friction_eval_side(a->kind, q, 0, a->v, &z, &zd, 0, 0);
}

double tf_friction_ripple(const double *p, double x, double *dR_dx, double *dR_dp)
{
    double P = p[TF_P_RIPPLE_PERIOD], R = 0.0, dx = 0.0;
    if (P > 0.0 && isfinite(P)) {
        double w = 2.0 * M_PI / P;
        for (int k = 1; k <= TF_RIPPLE_ORDER; k++) {
            int ic = TF_P_RIPPLE_COS1 + 2 * (k - 1), is = ic + 1;
            double c = cos(k * w * x), s = sin(k * w * x);
            R += p[ic] * c + p[is] * s;
            dx += k * w * (p[is] * c - p[ic] * s);
            if (dR_dp) dR_dp[ic] += c, dR_dp[is] += s;
        }
    }
    if (dR_dx) *dR_dx = dx;
    return R;
}

int tf_friction_nevent(int kind, const tf_gms_elements *el)
{
    return kind == TF_FRICTION_GMS && el ? 2 * el->n : 0;
}

void tf_friction_events(int kind, const double *p, const tf_gms_elements *el, double v, const double *z,
                        double *g_out)
{
    if (kind != TF_FRICTION_GMS) return;
    double q[TF_NPARAM];
    const double *pn = tf_friction_side(p, -1.0, q); /* the negative capacity's parameters */
    double g = tf_stribeck(p, v, 0), gn = tf_stribeck(pn, v, 0);
    /* A stuck element has one function per capacity, F_i - w_i g and -F_i - w_i g, rather than
     * |F_i| - w_i g: an element that sticks again at its capacity (a reversal) starts that
     * function at zero, where no upward crossing can be seen, but must still be caught at the
     * opposite capacity. Neither depends on sgn(v), which at a corner of prescribed motion is
     * already the next segment's. A slipping element's first function is -s v (the motion
     * reverses); its second, 3 vs - |v|, restarts the integration where v enters the Stribeck
     * band: outside it a slipping element's force rate is exactly zero (g = fc to the last
     * bit), so no error estimate would stop a step from carrying v across the whole band. */
    double band = (p[TF_P_FS] != p[TF_P_FC] && p[TF_P_VS] > 0.0) ? 3.0 * p[TF_P_VS] : -1.0;
    for (int i = 0; i < el->n; i++) {
        double cap = el->w[i] * g, cap_n = el->w[i] * gn;
        if (el->mode[i] == 0) {
            g_out[2 * i] = z[i] - cap;
            g_out[2 * i + 1] = -z[i] - cap_n;
        } else {
            g_out[2 * i] = -el->mode[i] * v;
            g_out[2 * i + 1] = band > 0.0 ? band - fabs(v) : -1.0;
        }
    }
}

void tf_friction_update_modes(int kind, const double *p, tf_gms_elements *el, double v, const double *z)
{
    if (kind != TF_FRICTION_GMS) return;
    double q[TF_NPARAM];
    double g = tf_stribeck(tf_friction_side(p, v, q), v, 0); /* the capacity on the side of v */
    for (int i = 0; i < el->n; i++) {
        if (el->mode[i] == 0) {
            /* at capacity and pushed further: it breaks loose (a rounding margin, so that the
               state at a located event counts as reached) */
            if (z[i] * v > 0.0 && fabs(z[i]) >= el->w[i] * g * (1.0 - 1e-9)) el->mode[i] = (v > 0) - (v < 0);
        } else if (el->mode[i] * v <= 0.0) {
            el->mode[i] = 0; /* the motion reversed (or stopped): it sticks where it is */
        }
    }
}

/* ---- checks (tf_model_check, plant.h) ---- */

/* The friction model's kind and its GMS elements. */
const char *tf_friction_structure_problem(int kind, const tf_gms_elements *gms)
{
    if (kind < 0 || kind >= TF_NFRICTION) return "friction";
    if (kind != TF_FRICTION_GMS) return 0;
    double sum = 0.0;
    if (gms->n < 1 || gms->n > TF_MAX_FRICTION_STATES) return "gms.n (1 to 64 elements)";
    for (int i = 0; i < gms->n; i++) {
        if (!tf_pos(gms->k[i])) return "gms.k";
        if (!tf_pos(gms->w[i])) return "gms.w";
        sum += gms->w[i];
    }
    if (!(fabs(sum - 1.0) <= 1e-9)) return "gms.w (must sum to one)";
    return 0;
}

/* The friction parameters the model uses, at one temperature. */
static const char *side_problem(int k, const double *p, int offset_form);

/* The negative side's parameter named for a problem found on its values. */
static const char *negative_name(const char *name)
{
    static const char *const pos[] = {"fc", "fs", "vs", "sigma2", "delta", "z_ba"};
    static const char *const neg[] = {"fc_neg", "fs_neg", "vs_neg", "sigma2_neg", "delta (negative side)",
                                      "z_ba (below fc_neg/sigma0)"};
    for (int i = 0; i < 6; i++)
        if (name && strcmp(name, pos[i]) == 0) return neg[i];
    return name;
}

const char *tf_friction_params_problem(int k, const double *p, int offset_form)
{
    const char *problem = side_problem(k, p, offset_form);
    if (problem) return problem;
    static const char *const neg_names[] = {"fc_neg", "fs_neg", "vs_neg", "sigma2_neg"};
    for (int i = 0; i < NSIDED; i++) /* NaN: the positive value; +-inf never */
        if (isinf(p[sided_neg[i]])) return neg_names[i];
    if (tf_friction_asymmetric(p)) {
        double q[TF_NPARAM];
        problem = side_problem(k, tf_friction_side(p, -1.0, q), offset_form);
        if (problem) return negative_name(problem);
    }
    double P = p[TF_P_RIPPLE_PERIOD];
    if (isnan(P) || isinf(P)) return "ripple_period";
    for (int i = TF_P_RIPPLE_COS1; i <= TF_P_RIPPLE_SIN3; i++)
        if (!isfinite(p[i])) return "ripple amplitudes (ripple_cos1 ... ripple_sin3)";
    return 0;
}

/* The friction models' domain table (domains.h), one row per rule. */
typedef struct {
    int model, param, rule, other, when;
} domain_row;

#define TF_DOMAIN_ROW_(model, param, rule, other, when) \
    {TF_FRICTION_##model, TF_P_##param, TF_DOMAIN_##rule, TF_P_##other, TF_DOMAIN_##when},
static const domain_row domains[] = {TF_FRICTION_DOMAINS(TF_DOMAIN_ROW_)};
#undef TF_DOMAIN_ROW_

#define TF_PARAMETER_NAME_(symbol, name, unit, meaning) name,
static const char *const parameter_names[TF_NPARAM] = {TF_PARAMETERS(TF_PARAMETER_NAME_)};
#undef TF_PARAMETER_NAME_

/* Whether x, the value of a row's parameter in p, is in its domain. */
static int in_domain(const domain_row *r, const double *p, double x)
{
    switch (r->rule) {
    case TF_DOMAIN_POSITIVE: return tf_pos(x);
    case TF_DOMAIN_NON_NEGATIVE: return tf_nonneg(x);
    case TF_DOMAIN_AT_LEAST: return isfinite(x) && x >= p[r->other];
    case TF_DOMAIN_BELOW_DEFLECTION: return tf_nonneg(x) && x < p[r->other] / p[TF_P_SIGMA0];
    case TF_DOMAIN_POSITIVE_OR_ABSENT: return x == 0.0 || tf_pos(x);
    default: return 0;
    }
}

/* The first of model k's parameters in p outside its domain (domains.h), in the table's order. */
static const char *side_problem(int k, const double *p, int offset_form)
{
    for (size_t i = 0; i < sizeof domains / sizeof domains[0]; i++) {
        const domain_row *r = &domains[i];
        if (r->model != k) continue;
        int applies = r->when == TF_DOMAIN_ALWAYS || (r->when == TF_DOMAIN_STRIBECK && p[TF_P_FS] != p[TF_P_FC]) ||
                      (r->when == TF_DOMAIN_OFFSET_FORM && offset_form);
        if (applies && !in_domain(r, p, p[r->param])) return parameter_names[r->param];
    }
    return 0;
}
