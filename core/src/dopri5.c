/* Dormand & Prince 5(4): FSAL, PI step control, Hairer's 4th-order continuous extension and
 * stiffness detection (Hairer & Wanner, Solving ODEs I, II.4-II.6). */
#include "dopri5.h"

#include <string.h>

/* ---- Dormand-Prince 5(4) ---- */
static const double
    dp_c2 = 1.0 / 5, dp_c3 = 3.0 / 10, dp_c4 = 4.0 / 5, dp_c5 = 8.0 / 9,
    dp_a21 = 1.0 / 5,
    dp_a31 = 3.0 / 40, dp_a32 = 9.0 / 40,
    dp_a41 = 44.0 / 45, dp_a42 = -56.0 / 15, dp_a43 = 32.0 / 9,
    dp_a51 = 19372.0 / 6561, dp_a52 = -25360.0 / 2187, dp_a53 = 64448.0 / 6561, dp_a54 = -212.0 / 729,
    dp_a61 = 9017.0 / 3168, dp_a62 = -355.0 / 33, dp_a63 = 46732.0 / 5247, dp_a64 = 49.0 / 176,
    dp_a65 = -5103.0 / 18656,
    dp_a71 = 35.0 / 384, dp_a73 = 500.0 / 1113, dp_a74 = 125.0 / 192, dp_a75 = -2187.0 / 6784,
    dp_a76 = 11.0 / 84,
    dp_e1 = 71.0 / 57600, dp_e3 = -71.0 / 16695, dp_e4 = 71.0 / 1920, dp_e5 = -17253.0 / 339200,
    dp_e6 = 22.0 / 525, dp_e7 = -1.0 / 40,
    dp_d1 = -12715105075.0 / 11282082432.0, dp_d3 = 87487479700.0 / 32700410799.0,
    dp_d4 = -10690763975.0 / 1880347072.0, dp_d5 = 701980252875.0 / 199316789632.0,
    dp_d6 = -1453857185.0 / 822651844.0, dp_d7 = 69997945.0 / 29380423.0;

/* ---- one attempted step: y1, dense coefficients; returns the error norm, or a negative value
 *      when the step produced non-finite numbers ---- */
TF_SIZED double dopri5_step_n(work *w, double t, double h, const double *y, const double *f0, const int n)
{
    int i;
    double **k = w->k, *yt = w->ytmp, *y1 = w->y1;
    memcpy(k[0], f0, sizeof(double) * n);
    for (i = 0; i < n; i++) yt[i] = y[i] + h * dp_a21 * k[0][i];
    if (rhs_n(w, t + dp_c2 * h, yt, k[1], n)) return -1;
    for (i = 0; i < n; i++) yt[i] = y[i] + h * (dp_a31 * k[0][i] + dp_a32 * k[1][i]);
    if (rhs_n(w, t + dp_c3 * h, yt, k[2], n)) return -1;
    for (i = 0; i < n; i++) yt[i] = y[i] + h * (dp_a41 * k[0][i] + dp_a42 * k[1][i] + dp_a43 * k[2][i]);
    if (rhs_n(w, t + dp_c4 * h, yt, k[3], n)) return -1;
    for (i = 0; i < n; i++)
        yt[i] = y[i] + h * (dp_a51 * k[0][i] + dp_a52 * k[1][i] + dp_a53 * k[2][i] + dp_a54 * k[3][i]);
    if (rhs_n(w, t + dp_c5 * h, yt, k[4], n)) return -1;
    for (i = 0; i < n; i++)
        w->ysti[i] = y[i] + h * (dp_a61 * k[0][i] + dp_a62 * k[1][i] + dp_a63 * k[2][i] +
                                 dp_a64 * k[3][i] + dp_a65 * k[4][i]);
    if (rhs_n(w, t + h, w->ysti, k[5], n)) return -1;
    for (i = 0; i < n; i++)
        y1[i] = y[i] + h * (dp_a71 * k[0][i] + dp_a73 * k[2][i] + dp_a74 * k[3][i] +
                            dp_a75 * k[4][i] + dp_a76 * k[5][i]);
    if (rhs_n(w, t + h, y1, k[6], n)) return -1;
    for (i = 0; i < n; i++)
        yt[i] = h * (dp_e1 * k[0][i] + dp_e3 * k[2][i] + dp_e4 * k[3][i] + dp_e5 * k[4][i] +
                     dp_e6 * k[5][i] + dp_e7 * k[6][i]);
    double err = wnorm_n(w, yt, y, y1, n);
    if (!isfinite(err) || !all_finite(y1, n)) return -1;
    for (i = 0; i < n; i++) {
        double dy = y1[i] - y[i], bspl = h * k[0][i] - dy;
        w->cont[0][i] = y[i];
        w->cont[1][i] = dy;
        w->cont[2][i] = bspl;
        w->cont[3][i] = dy - h * k[6][i] - bspl;
        w->cont[4][i] = h * (dp_d1 * k[0][i] + dp_d3 * k[2][i] + dp_d4 * k[3][i] + dp_d5 * k[4][i] +
                             dp_d6 * k[5][i] + dp_d7 * k[6][i]);
    }
    return err;
}

double tf_dopri5_step(work *w, double t, double h, const double *y, const double *f0)
{
    switch (w->n) {
    case 5: return dopri5_step_n(w, t, h, y, f0, 5);
    case 3: return dopri5_step_n(w, t, h, y, f0, 3);
    default: return dopri5_step_n(w, t, h, y, f0, w->n);
    }
}

TF_SIZED void dopri5_dense_n(const work *w, double s, double *y, const int n)
{
    for (int i = 0; i < n; i++) y[i] = tf_dopri5_dense_component(w, i, s);
}

void tf_dopri5_dense(const work *w, double s, double *y)
{
    switch (w->n) {
    case 5: dopri5_dense_n(w, s, y, 5); break;
    case 3: dopri5_dense_n(w, s, y, 3); break;
    default: dopri5_dense_n(w, s, y, w->n);
    }
}

double tf_dopri5_next_h(double err, double h, double *facold)
{
    /* PI control, Hairer's DOPRI5 constants */
    const double beta = 0.04, expo1 = 0.2 - beta * 0.75;
    double fac11 = pow(err, expo1);
    double fac = fac11 / pow(*facold, beta);
    fac = fmax(0.1, fmin(5.0, fac / 0.9));
    *facold = fmax(err, 1e-4);
    return h / fac;
}

double tf_dopri5_rejected_h(double err, double h) { return h / fmin(5.0, pow(err, 0.2 - 0.04 * 0.75) / 0.9); }

int tf_dopri5_stiff(const work *w, const tf_solver_options *opt, double h, int *iasti, int *nonsti)
{
    /* stiffness test: h * |lambda| from the last two stages */
    int n = w->n;
    double num = 0.0, den = 0.0;
    for (int i = 0; i < n; i++) {
        double sk = opt->atol[i] + opt->rtol * fabs(w->y1[i]);
        double a = (w->k[6][i] - w->k[5][i]) / sk, b = (w->y1[i] - w->ysti[i]) / sk;
        num += a * a;
        den += b * b;
    }
    if (den > 0.0 && h * sqrt(num / den) > 3.25) {
        *nonsti = 0;
        return ++*iasti >= 15;
    }
    if (++*nonsti >= 6) *iasti = 0;
    return 0;
}
