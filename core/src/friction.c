/* Friction models (SPEC 4). */
#include "thermofriction/friction.h"

#include <math.h>
#include <string.h>

static double sgn(double v) { return (v > 0) - (v < 0); }

int tf_friction_nstate(int kind)
{
    switch (kind) {
    case TF_FRICTION_LUGRE: return 1;
    default: return -1;
    }
}

double tf_friction_reference_force(int kind, const double *p)
{
    (void)kind;
    return p[TF_P_FC];
}

double tf_stribeck(const double *p, double v, double *dg)
{
    double fc = p[TF_P_FC], fs = p[TF_P_FS], vs = p[TF_P_VS], delta = p[TF_P_DELTA];
    if (fs == fc || !(vs > 0.0) || v == 0.0) {
        if (dg) *dg = 0.0;
        return v == 0.0 ? fs : fc;
    }
    double r = fabs(v / vs);
    double rd = pow(r, delta);
    double e = exp(-rd);
    if (dg) *dg = -(fs - fc) * e * delta * (rd / r) * sgn(v) / vs;
    return fc + (fs - fc) * e;
}

/* LuGre (Canudas de Wit et al. 1995):
 *   z' = v - sigma0 |v| z / g(v),  F = sigma0 z + sigma1(v) z' + sigma2 v,
 *   sigma1(v) = sigma1 exp(-(v/vd)^2) when vd > 0. */
/* Partial derivatives of g(v) with respect to fc, fs, vs, delta. */
static void stribeck_param_partials(const double *p, double v, double *dg)
{
    double fc = p[TF_P_FC], fs = p[TF_P_FS], vs = p[TF_P_VS], delta = p[TF_P_DELTA];
    memset(dg, 0, sizeof(double) * TF_NPARAM);
    if (v == 0.0 || !(vs > 0.0)) { /* g = fs at rest (and fc without a Stribeck velocity) */
        dg[v == 0.0 ? TF_P_FS : TF_P_FC] = 1.0;
        return;
    }
    double r = fabs(v / vs), rd = pow(r, delta), e = exp(-rd);
    dg[TF_P_FC] = 1.0 - e;
    dg[TF_P_FS] = e;
    dg[TF_P_VS] = (fs - fc) * e * delta * rd / vs;
    dg[TF_P_DELTA] = -(fs - fc) * e * rd * log(r);
}

static double lugre(const double *p, double v, const double *z, double *dz, tf_friction_partials *jac,
                    tf_friction_param_partials *dp)
{
    double s0 = p[TF_P_SIGMA0], s2 = p[TF_P_SIGMA2], vd = p[TF_P_VD];
    double dg;
    double g = tf_stribeck(p, v, jac ? &dg : 0);
    double r = s0 * fabs(v) / g; /* relaxation rate of z */
    double zd = v - r * z[0];
    double s1 = p[TF_P_SIGMA1], ds1 = 0.0;
    if (vd > 0.0) {
        double q = v / vd;
        s1 *= exp(-q * q);
        ds1 = -2.0 * q / vd * s1;
    }
    dz[0] = zd;
    if (jac) {
        double dr = s0 * (sgn(v) * g - fabs(v) * dg) / (g * g);
        jac->ddz_dz[0] = -r;
        jac->ddz_dv[0] = 1.0 - z[0] * dr;
        jac->dF_dz[0] = s0 + s1 * jac->ddz_dz[0];
        jac->dF_dv = ds1 * zd + s1 * jac->ddz_dv[0] + s2;
    }
    if (dp) {
        double dg[TF_NPARAM];
        stribeck_param_partials(p, v, dg);
        double dzd_dg = s0 * fabs(v) * z[0] / (g * g); /* z' = v - sigma0 |v| z / g */
        for (int i = 0; i < TF_NPARAM; i++) dp->ddz_dp[0][i] = dzd_dg * dg[i];
        dp->ddz_dp[0][TF_P_SIGMA0] = -fabs(v) * z[0] / g;
        for (int i = 0; i < TF_NPARAM; i++) dp->dF_dp[i] = s1 * dp->ddz_dp[0][i];
        dp->dF_dp[TF_P_SIGMA0] += z[0];
        dp->dF_dp[TF_P_SIGMA1] = (vd > 0.0 ? exp(-(v / vd) * (v / vd)) : 1.0) * zd;
        dp->dF_dp[TF_P_SIGMA2] = v;
        dp->dF_dp[TF_P_VD] = vd > 0.0 ? s1 * 2.0 * v * v / (vd * vd * vd) * zd : 0.0;
    }
    return s0 * z[0] + s1 * zd + s2 * v;
}

double tf_friction_eval(int kind, const double *p, double v, const double *z, double *dz,
                        tf_friction_partials *jac, tf_friction_param_partials *dp)
{
    switch (kind) {
    case TF_FRICTION_LUGRE: return lugre(p, v, z, dz, jac, dp);
    default: return NAN;
    }
}
