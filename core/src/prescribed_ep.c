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
    tf_stribeck_param_partials(ps, v, dzss_all); /* dg; sigma0's entry is zero */
    tf_friction_side_partials(p, v, dzss_all);
    for (int i = 0; i < TF_NPARAM; i++) dzss_all[i] /= s0;
    dzss_all[TF_P_SIGMA0] = -e->zss / s0;
    memset(dzba_all, 0, sizeof(double) * TF_NPARAM);
    dzba_all[TF_P_ZBA] = 1.0;
}

/* The transition's rate in Y = (u, du/du0, du/dz_ss, du/dz_ba) per unit displacement, into K. */
static void rate(const tf_ep_segment *e, const double *Y, double *K)
{
    double zss = e->zss, W = zss - e->zba, kw = 0.5 * M_PI / W;
    double w = exp(Y[0]), phi = kw * w, s = sin(phi), c = cos(phi);
    double G = -(s * s / w + c * c / zss);
    double G_u = s * s / w - 2.0 * kw * s * c * (1.0 - w / zss); /* w dG/dw */
    double G_W = 2.0 * s * c * phi / W * (1.0 / w - 1.0 / zss);  /* the band's width W = z_ss - z_ba */
    K[0] = G;
    K[1] = G_u * Y[1];
    K[2] = G_u * Y[2] + c * c / (zss * zss) + G_W;
    K[3] = G_u * Y[3] - G_W;
}

/* Dormand-Prince 5(4): the stages' coefficients, the fifth-order weights (the last row) and the error's. */
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

/* Y over the displacement X within the transition (Y[1..3] from 1, 0, 0); NaN in Y[0] if the error
 * estimate is not finite. */
static void transition(tf_ep_segment *e, double *Y, double X)
{
    double K[7][4], Z[4], x = 0.0;
    rate(e, Y, K[0]);
    while (x < X) {
        double rest = X - x, h = fmin(e->hx, rest);
        int last = h == rest;
        for (int i = 1; i < 7; i++) {
            for (int c = 0; c < 4; c++) {
                double sum = 0.0;
                for (int j = 0; j < i; j++) sum += A[i][j] * K[j][c];
                Z[c] = Y[c] + h * sum;
            }
            rate(e, Z, K[i]);
        }
        double est = 0.0;
        for (int i = 0; i < 7; i++) est += EC[i] * K[i][0];
        double err = fabs(h * est) / TF_EP_TOL;
        if (!(err <= 1e300)) { /* not finite */
            Y[0] = NAN;
            return;
        }
        double fac = err > 0.0 ? 0.9 * pow(err, -0.2) : 5.0;
        if (err <= 1.0) {
            memcpy(Y, Z, sizeof Z); /* the last stage is at the fifth-order solution */
            memcpy(K[0], K[6], sizeof K[0]);
            x = last ? X : x + h;
            e->steps++;
            double next = h * fmin(fac, 5.0);
            e->hx = last ? fmax(e->hx, next) : next; /* a step cut short by the segment's end is no guide */
        } else {
            e->hx = h * fmax(fac, 0.2);
            e->rejected++;
        }
    }
}

void tf_ep_advance(tf_ep_segment *e, double v, double *z, double *S, int np, double h)
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
        e->hx = 0.02 * (zss - e->zba); /* a fresh start into the band */
    }
    if (y >= zss) { /* alpha = 1: y' = 1 - y / z_ss */
        double E = exp(-X / zss), dz = 1.0 - E + (y - zss) * E * X / (zss * zss);
        *z = sg * (zss + (y - zss) * E);
        for (int j = 0; j < np; j++) S[j] = E * S[j] + sg * dz * e->dzss[j];
        return;
    }
    double u0 = log(zss - y), Y[4] = {u0, 1.0, 0.0, 0.0};
    if (!(e->hx > 0.0)) e->hx = 0.02 * (zss - e->zba);
    transition(e, Y, X);
    /* y = z_ss - e^u: dy/dtheta = dz_ss - w1 (du/du0 du0/dtheta + du/dz_ss dz_ss + du/dz_ba dz_ba), with
     * du0/dtheta = (dz_ss - dy0) / w0; w1 / w0 as one exponential (w0 may be tiny) */
    double w1 = exp(Y[0]), ratio = Y[1] * exp(Y[0] - u0);
    *z = sg * (zss - w1);
    for (int j = 0; j < np; j++) {
        double Sy = sg * S[j];
        double Sy1 = e->dzss[j] - ratio * (e->dzss[j] - Sy) - w1 * (Y[2] * e->dzss[j] + Y[3] * e->dzba[j]);
        S[j] = sg * Sy1;
    }
}
