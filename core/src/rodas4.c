/* Rodas4: Hairer & Wanner's 6-stage Rosenbrock method of order 4(3), L-stable and stiffly accurate,
 * with its 3rd-order dense output (Solving ODEs II, IV.7), the analytic state Jacobian and predictive
 * (Gustafsson) step control. Its linear systems are reduced by the kinematic rows (lu_reduced.h). */
#include "rodas4.h"
#include "lu_reduced.h"

#include <float.h>
#include <string.h>

/* ---- Rodas4 (Hairer & Wanner, METH = 1) ---- */
static const double
    ro_gamma = 0.25,
    ro_c2 = 0.386, ro_c3 = 0.21, ro_c4 = 0.63,
    ro_g1 = 0.25, ro_g2 = -0.1043, ro_g3 = 0.1035, ro_g4 = -0.3620000000000023e-01,
    ro_a21 = 0.1544000000000000e+01,
    ro_a31 = 0.9466785280815826e+00, ro_a32 = 0.2557011698983284e+00,
    ro_a41 = 0.3314825187068521e+01, ro_a42 = 0.2896124015972201e+01, ro_a43 = 0.9986419139977817e+00,
    ro_a51 = 0.1221224509226641e+01, ro_a52 = 0.6019134481288629e+01, ro_a53 = 0.1253708332932087e+02,
    ro_a54 = -0.6878860361058950e+00,
    ro_c21 = -0.5668800000000000e+01,
    ro_c31 = -0.2430093356833875e+01, ro_c32 = -0.2063599157091915e+00,
    ro_c41 = -0.1073529058151375e+00, ro_c42 = -0.9594562251023355e+01, ro_c43 = -0.2047028614809616e+02,
    ro_c51 = 0.7496443313967647e+01, ro_c52 = -0.1024680431464352e+02, ro_c53 = -0.3399990352819905e+02,
    ro_c54 = 0.1170890893206160e+02,
    ro_c61 = 0.8083246795921522e+01, ro_c62 = -0.7981132988064893e+01, ro_c63 = -0.3152159432874371e+02,
    ro_c64 = 0.1631930543123136e+02, ro_c65 = -0.6058818238834054e+01,
    ro_d21 = 0.1012623508344586e+02, ro_d22 = -0.7487995877610167e+01, ro_d23 = -0.3480091861555747e+02,
    ro_d24 = -0.7992771707568823e+01, ro_d25 = 0.1025137723295662e+01,
    ro_d31 = -0.6762803392801253e+00, ro_d32 = 0.6087714651680015e+01, ro_d33 = 0.1643084320892478e+02,
    ro_d34 = 0.2476722511418386e+02, ro_d35 = -0.6594389125716872e+01;


/* Time derivative of f at (t, y), one-sided within [t, t_end] (the segment has no corner). */
static int time_derivative(work *w, double t, double t_end, const double *y, const double *f0, double *ft)
{
    double dt = sqrt(DBL_EPSILON) * fmax(fabs(t), 1e-6);
    if (t + dt > t_end) dt = -dt;
    if (rhs(w, t + dt, y, ft)) return 1;
    for (int i = 0; i < w->n; i++) ft[i] = (ft[i] - f0[i]) / dt;
    return 0;
}

/* Returns the error norm; -1 for non-finite numbers, -2 for a singular iteration matrix. */
TF_SIZED double rodas4_step_n(work *w, double t, double h, const double *y, const double *f0, const int n,
                              const int nr, const int np)
{
    int i;
    double **k = w->k, *yt = w->ytmp, *fs = w->k[6], *ft = w->ft;
    w->st->decompositions++;
    if (reduced_factor(w, h, ro_gamma, n, nr, np)) return -2;

    for (i = 0; i < n; i++) k[0][i] = f0[i] + h * ro_g1 * ft[i];
    reduced_solve(w, k[0], nr, np);

    for (i = 0; i < n; i++) yt[i] = y[i] + ro_a21 * k[0][i];
    if (rhs_n(w, t + ro_c2 * h, yt, fs, n)) return -1;
    for (i = 0; i < n; i++) k[1][i] = fs[i] + h * ro_g2 * ft[i] + ro_c21 * k[0][i] / h;
    reduced_solve(w, k[1], nr, np);

    for (i = 0; i < n; i++) yt[i] = y[i] + ro_a31 * k[0][i] + ro_a32 * k[1][i];
    if (rhs_n(w, t + ro_c3 * h, yt, fs, n)) return -1;
    for (i = 0; i < n; i++) k[2][i] = fs[i] + h * ro_g3 * ft[i] + (ro_c31 * k[0][i] + ro_c32 * k[1][i]) / h;
    reduced_solve(w, k[2], nr, np);

    for (i = 0; i < n; i++) yt[i] = y[i] + ro_a41 * k[0][i] + ro_a42 * k[1][i] + ro_a43 * k[2][i];
    if (rhs_n(w, t + ro_c4 * h, yt, fs, n)) return -1;
    for (i = 0; i < n; i++)
        k[3][i] = fs[i] + h * ro_g4 * ft[i] + (ro_c41 * k[0][i] + ro_c42 * k[1][i] + ro_c43 * k[2][i]) / h;
    reduced_solve(w, k[3], nr, np);

    for (i = 0; i < n; i++)
        yt[i] = y[i] + ro_a51 * k[0][i] + ro_a52 * k[1][i] + ro_a53 * k[2][i] + ro_a54 * k[3][i];
    if (rhs_n(w, t + h, yt, fs, n)) return -1;
    for (i = 0; i < n; i++)
        k[4][i] = fs[i] + (ro_c51 * k[0][i] + ro_c52 * k[1][i] + ro_c53 * k[2][i] + ro_c54 * k[3][i]) / h;
    reduced_solve(w, k[4], nr, np);

    for (i = 0; i < n; i++) yt[i] += k[4][i];
    if (rhs_n(w, t + h, yt, fs, n)) return -1;
    for (i = 0; i < n; i++)
        k[5][i] = fs[i] + (ro_c61 * k[0][i] + ro_c62 * k[1][i] + ro_c63 * k[2][i] + ro_c64 * k[3][i] +
                           ro_c65 * k[4][i]) / h;
    reduced_solve(w, k[5], nr, np);

    for (i = 0; i < n; i++) w->y1[i] = yt[i] + k[5][i];
    double err = wnorm_n(w, k[5], y, w->y1, n);
    if (!isfinite(err) || !all_finite(w->y1, n)) return -1;
    for (i = 0; i < n; i++) {
        w->cont[0][i] = y[i];
        w->cont[1][i] = w->y1[i];
        w->cont[2][i] = ro_d21 * k[0][i] + ro_d22 * k[1][i] + ro_d23 * k[2][i] + ro_d24 * k[3][i] +
                        ro_d25 * k[4][i];
        w->cont[3][i] = ro_d31 * k[0][i] + ro_d32 * k[1][i] + ro_d33 * k[2][i] + ro_d34 * k[3][i] +
                        ro_d35 * k[4][i];
    }
    return err;
}

/* The reduced sizes are known once the Jacobian's structure is (tf_lu_structure). */
static double rodas4_step_sized(work *w, double t, double h, const double *y, const double *f0)
{
    if (w->n == 5 && w->nred == 3 && w->npos == 2) return rodas4_step_n(w, t, h, y, f0, 5, 3, 2);
    if (w->n == 3 && w->nred == 2 && w->npos == 1) return rodas4_step_n(w, t, h, y, f0, 3, 2, 1);
    return rodas4_step_n(w, t, h, y, f0, w->n, w->nred, w->npos);
}

TF_SIZED void rodas4_dense_n(const work *w, double s, double *y, const int n)
{
    double s1 = 1.0 - s;
    for (int i = 0; i < n; i++)
        y[i] = w->cont[0][i] * s1 + s * (w->cont[1][i] + s1 * (w->cont[2][i] + s * w->cont[3][i]));
}


void tf_rodas4_dense(const work *w, double s, double *y)
{
    switch (w->n) {
    case 5: rodas4_dense_n(w, s, y, 5); break;
    case 3: rodas4_dense_n(w, s, y, 3); break;
    default: rodas4_dense_n(w, s, y, w->n);
    }
}

int tf_rodas4_jacobian(work *w, double t, double seg_end, const double *y, const double *f0)
{
    int n = w->n;
    w->st->jac_evals++;
    w->ode->jac(t, y, w->J, w->ode->ctx);
    if (!all_finite(w->J, n * n) || time_derivative(w, t, seg_end, y, f0, w->ft)) return 1;
    tf_lu_structure(w);
    return 0;
}

double tf_rodas4_step(work *w, double t, double h, const double *y, const double *f0, double *yd)
{
    double err = rodas4_step_sized(w, t, h, y, f0);
    /* Rodas4 estimates its error at the step's end, but a long step across a fast transition (a slip
     * onset after a long stick) can be right there and wrong inside, where the output is interpolated.
     * So the dense output at mid-step is compared with the cubic Hermite interpolant of the step's ends
     * and slopes, and a disagreement above the tolerance counts as the step's error. The end slope is
     * the next step's first derivative: the check costs a right-hand side only on rejection. */
    if (err >= 0.0 && err <= 1.0) {
        double *f1 = w->k[6];
        if (rhs(w, t + h, w->y1, f1)) {
            err = -1.0;
        } else {
            tf_rodas4_dense(w, 0.5, yd);
            double e_mid = mid_step_error(w, h, y, f0, f1, yd);
            err = isfinite(e_mid) ? fmax(err, e_mid) : -1.0;
        }
    }
    return err;
}

double tf_rodas4_next_h(double err, double h, tf_rodas4_control *c)
{
    double fac = fmax(1.0 / 6.0, fmin(5.0, root4(err) / 0.9));
    if (!c->first) {
        double facpred = (c->hold / h) * root4(err * err / c->errold) / 0.9;
        fac = fmax(fac, fmax(1.0 / 6.0, fmin(5.0, facpred)));
    }
    c->first = 0;
    c->hold = h;
    c->errold = fmax(0.01, err);
    return h / fac;
}

double tf_rodas4_rejected_h(double err, double h) { return h / fmax(1.0 / 6.0, fmin(5.0, root4(err) / 0.9)); }
