/* The elasto-plastic bristle over a segment of constant velocity, with its sensitivities (prescribed_ep.h). */
#include "prescribed_ep.h"

#include <math.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void tf_ep_segment_set(tf_ep_segment *e, const double *p, double v, double *dzss_all, double *dzba_all)
{
    double q[TF_NPARAM];
    const double *ps = tf_friction_side(p, v, q); /* the side of v's values, as tf_friction_eval takes them */
    double s0 = p[TF_P_SIGMA0];
    e->av = fabs(v);
    e->zss = tf_stribeck(ps, v, 0) / s0;
    e->zba = p[TF_P_ZBA];
    if (!dzss_all) return;
    tf_stribeck_param_partials(ps, v, dzss_all); /* dg; sigma0's entry is zero */
    tf_friction_side_partials(p, v, dzss_all);
    for (int i = 0; i < TF_NPARAM; i++) dzss_all[i] /= s0;
    dzss_all[TF_P_SIGMA0] = -e->zss / s0;
    memset(dzba_all, 0, sizeof(double) * TF_NPARAM);
    dzba_all[TF_P_ZBA] = 1.0;
}

/* sin(phi) / phi and its derivative, without the cancellation near phi = 0 */
static double sinc(double phi, double sn) { return phi > 0.0 ? sn / phi : 1.0; }
static double dsinc(double phi, double sn, double cs)
{
    double p2 = phi * phi;
    return phi < 0.05 ? phi * (-1.0 / 3 + p2 * (1.0 / 30 - p2 / 840)) : (phi * cs - sn) / p2;
}

/* The transition's rate dY/ds at s, Y = (rho, drho/drho0, drho/dz_ss, drho/dW) (W = z_ss - z_ba, s and the
 * other two held), into K: rho' = (z_ss - w) (sin(phi) / w)^2 with w = (1 - s) / rho. */
static void rate(const tf_ep_segment *e, double s, const double *Y, double *K)
{
    double zss = e->zss, W = zss - e->zba, kw = 0.5 * M_PI / W;
    double w = (1.0 - s) / Y[0], phi = kw * w, sn = sin(phi), cs = cos(phi);
    double q = kw * sinc(phi, sn), dq_dw = kw * kw * dsinc(phi, sn, cs); /* q = sin(phi) / w */
    double R_w = -q * q + (zss - w) * 2.0 * q * dq_dw;
    double R_rho = -R_w * w / Y[0];
    double R_W = -(zss - w) * 2.0 * q * cs * kw / W;
    K[0] = (zss - w) * q * q;
    K[1] = R_rho * Y[1];
    K[2] = R_rho * Y[2] + q * q;
    K[3] = R_rho * Y[3] + R_W;
}

/* Dormand-Prince 5(4): the stages' nodes and coefficients, the fifth-order weights (the last row) and the
 * error's. */
static const double C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
static const double A[7][6] = {
    {0},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
static const double EC[7] = {71.0 / 57600, 0.0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200, 22.0 / 525,
                             -1.0 / 40};

/* Y from s = 0 to s1 <= 1 (Y[1..3] from 1, 0, 0); the rate at s1 into R1; NaN in Y[0] (reported by
 * prescribed.c as a non-finite force) if the error estimate is not finite or the step stops advancing. The
 * first step from the rate at the start: a relative change of rho of
 * (TF_EP_TOL z_ss / w)^(1/5), the error allowed in y being w times rho's relative error. */
static void transition(const tf_ep_segment *e, double *Y, double s1, double *R1)
{
    double K[7][4], Z[4], s = 0.0, zss = e->zss;
    rate(e, 0.0, Y, K[0]);
    double w0 = 1.0 / Y[0], rel = fabs(K[0][0]) / Y[0];
    double h = rel > 0.0 ? pow(TF_EP_TOL * zss / w0, 0.2) / rel : s1;
    while (s < s1) {
        double rest = s1 - s;
        int last = h >= rest;
        if (last) h = rest;
        if (!(s + h > s)) { /* no progress: the step has fallen below s's resolution */
            Y[0] = *R1 = NAN;
            return;
        }
        for (int i = 1; i < 7; i++) {
            for (int c = 0; c < 4; c++) {
                double sum = 0.0;
                for (int j = 0; j < i; j++) sum += A[i][j] * K[j][c];
                Z[c] = Y[c] + h * sum;
            }
            rate(e, last && i >= 5 ? s1 : s + C[i] * h, Z, K[i]);
        }
        double est = 0.0;
        for (int i = 0; i < 7; i++) est += EC[i] * K[i][0];
        double s_end = last ? s1 : s + h, w = (1.0 - s_end) / Z[0];
        double err = fabs(h * est) / Z[0] * w / (TF_EP_TOL * zss); /* y's error: w times rho's, relative */
        if (!(err <= 1e300)) { /* not finite */
            Y[0] = *R1 = NAN;
            return;
        }
        double fac = err > 0.0 ? 0.9 * pow(err, -0.2) : 5.0;
        if (err <= 1.0) {
            memcpy(Y, Z, sizeof Z); /* the last stage is at the fifth-order solution */
            memcpy(K[0], K[6], sizeof K[0]);
            s = s_end;
            h *= fmin(fac, 5.0);
        } else {
            h *= fmax(fac, 0.2);
        }
    }
    *R1 = K[0][0];
}

void tf_ep_advance(const tf_ep_segment *e, double v, double *z, double *S, int np, double h)
{
    if (!(h > 0.0) || v == 0.0) return; /* at rest the bristle holds (z' = v) */
    double sg = v > 0.0 ? 1.0 : -1.0, y = sg * *z, X = e->av * h, zss = e->zss;
    if (y <= e->zba) { /* elastic: y' = 1, its sensitivities constant, up to z_ba */
        double xa = e->zba - y;
        if (X <= xa) {
            *z = sg * (y + X);
            return;
        }
        y = e->zba;
        X -= xa;
    }
    if (y >= zss) { /* alpha = 1: y' = 1 - y / z_ss */
        double E = exp(-X / zss), dz = 1.0 - E + (y - zss) * E * X / (zss * zss);
        *z = sg * (zss + (y - zss) * E);
        for (int j = 0; j < np; j++) S[j] = E * S[j] + sg * dz * e->dzss[j];
        return;
    }
    /* the band: rho = e^{x / z_ss} / w over s = 1 - e^{-x / z_ss} (prescribed_ep.h); then w = e^{-x / z_ss} / rho
     * and y = z_ss - w, differentiated through rho's variational equations and the end s1 (z_ss moves it) */
    double E = exp(-X / zss), s1 = -expm1(-X / zss), rho0 = 1.0 / (zss - y), R1 = 0.0;
    double Y[4] = {rho0, 1.0, 0.0, 0.0};
    transition(e, Y, s1, &R1);
    double rho1 = Y[0], w1 = E / rho1, dE = X / (zss * zss); /* dE/dz_ss / E */
    *z = sg * (zss - w1);
    for (int j = 0; j < np; j++) {
        double dzss = e->dzss[j], dw0 = dzss - sg * S[j];
        double drho1 = -Y[1] * rho0 * rho0 * dw0 + Y[2] * dzss + Y[3] * (dzss - e->dzba[j]) - R1 * E * dE * dzss;
        double dw1 = w1 * (dE * dzss - drho1 / rho1);
        S[j] = sg * (dzss - dw1);
    }
}
