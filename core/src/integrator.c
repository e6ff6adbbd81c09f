/* Adaptive integrators with dense output, behind one corner-aware driver.
 *
 * DOPRI5: Dormand & Prince 5(4), FSAL, PI step control, Hairer's 4th-order continuous
 *   extension and stiffness detection (Hairer & Wanner, Solving ODEs I, II.4-II.6).
 * RODAS4: Hairer & Wanner's 6-stage Rosenbrock method of order 4(3), L-stable and stiffly
 *   accurate, with its 3rd-order dense output (Solving ODEs II, IV.7), analytic state
 *   Jacobian, predictive (Gustafsson) step control.
 * AUTO: per phase of the input (every corner starts one), DOPRI5 at AUTO_EXPLICIT_TOL times the
 *   tolerances until its stiffness test fires (15 steps in a row near the stability
 *   boundary); then RODAS4 on probation: after PROBE_STEPS steps its work per simulated
 *   second is compared with DOPRI5's over its last window, and the cheaper method goes on
 *   (work counted in rhs evaluations, with Jacobians and LUs weighted by the system size).
 *   A failed probe doubles the number of explicit steps before the next one. The stiffness
 *   test says only that the explicit method sits at its stability limit, not that the stiff one
 *   will be cheaper: at every velocity reversal LuGre's |v| puts a kink in the right-hand side
 *   that both methods pay for, so the choice is made on measured work.
 */
#include "thermofriction/integrator.h"
#include "inline.h" /* TF_SIZED */

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

enum { PROBE_STEPS = 200, WINDOW_STEPS = 200, FIRST_LOCK = 2000 };

/* The step functions take the system size (and Rodas4 its reduced sizes) as an argument and are
 * inlined into dispatchers that pass constants for the common models (5 states: the stick-slip
 * actuator with LuGre; 3: the mass with LuGre), so that their loops over five numbers compile to
 * straight-line code; any other size runs the same code with the runtime value. */
#ifndef AUTO_EXPLICIT_TOL
#define AUTO_EXPLICIT_TOL 0.02 /* 1/50 */
#endif

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

typedef struct {
    const tf_ode *ode;
    const tf_solver_options *opt;
    tf_solver_stats *st;
    int n;
    double *k[7], *ytmp, *y1, *ysti, *ft, *cont[5], *J, *W;
    int *piv;
    /* Rodas4's linear solves, reduced by the kinematic rows (structure_of_jacobian): the rows p whose
     * Jacobian row is a unit vector e_q (x' = v) are eliminated, k_p = gamma h (b_p + k_q); the other
     * nred rows (red[]) form the reduced matrix, LU-factored in W with reciprocal pivots in dinv, and
     * Jpos (nred x npos) holds gamma h J[r][pos[j]], what the eliminated unknowns add to row r */
    int npos, nred, *pos, *partner, *red, *qcol;
    double gh, *dinv, *Jpos, *xr;
    double *rtol_w; /* each state's weight of the relative tolerance (opt->rtol_weight, or 1) */
    double t_clamp; /* stages never look past the corner that ends the segment */
    double *block; /* one allocation for all of the above */
} work;

TF_SIZED int rhs_n(work *w, double t, const double *y, double *dy, const int n)
{
    w->st->rhs_evals++;
    /* A stage at the end of a segment sees the waveform's left limit, so that a jump at a
     * corner (an ideal step) belongs to the next segment only. */
    if (t > w->t_clamp) t = w->t_clamp;
    if (w->ode->rhs(t, y, dy, w->ode->ctx)) return 1;
    /* one test for all: a NaN or an infinity in any component makes the sum non-finite (finite
     * components can overflow the sum only within a factor n of DBL_MAX) */
    double sum = 0.0;
    for (int i = 0; i < n; i++) sum += dy[i];
    return !isfinite(sum);
}

static int rhs(work *w, double t, const double *y, double *dy) { return rhs_n(w, t, y, dy, w->n); }

TF_SIZED double wnorm_n(const work *w, const double *e, const double *ya, const double *yb, const int n)
{
    double s = 0.0;
    for (int i = 0; i < n; i++) {
        double a = fabs(ya[i]), b = fabs(yb[i]);
        double sk = w->opt->atol[i] + w->opt->rtol * w->rtol_w[i] * (a > b ? a : b);
        double r = e[i] / sk;
        s += r * r;
    }
    return sqrt(s / n);
}

static double wnorm(const work *w, const double *e, const double *ya, const double *yb)
{
    return wnorm_n(w, e, ya, yb, w->n);
}

/* x^(1/4) for Rodas4's step-size control: two square roots cost a third of a pow */
static double root4(double x) { return sqrt(sqrt(x)); }

TF_SIZED int all_finite(const double *v, const int n)
{
    double sum = 0.0; /* as in rhs(): a NaN or an infinity anywhere makes the sum non-finite */
    for (int i = 0; i < n; i++) sum += v[i];
    return isfinite(sum);
}

/* ---- dense LU with partial pivoting, for the small systems of a Rosenbrock stage ---- */
int tf_lu_factor(double *A, int n, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        double big = fabs(A[k * n + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > big) { big = fabs(A[i * n + k]); p = i; }
        piv[k] = p;
        if (big == 0.0 || !isfinite(big)) return 1;
        /* LINPACK style: only the trailing columns move; the multipliers of earlier columns stay
         * where they were made, matching lu_solve, which interleaves interchanges and elimination */
        if (p != k)
            for (int j = k; j < n; j++) { double tmp = A[k * n + j]; A[k * n + j] = A[p * n + j]; A[p * n + j] = tmp; }
        double inv = 1.0 / A[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double l = A[i * n + k] *= inv;
            if (l != 0.0)
                for (int j = k + 1; j < n; j++) A[i * n + j] -= l * A[k * n + j];
        }
    }
    return 0;
}

void tf_lu_solve(const double *A, int n, const int *piv, double *b)
{
    for (int k = 0; k < n; k++) {
        if (piv[k] != k) { double tmp = b[k]; b[k] = b[piv[k]]; b[piv[k]] = tmp; }
        for (int i = k + 1; i < n; i++) b[i] -= A[i * n + k] * b[k];
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = b[i];
        for (int j = i + 1; j < n; j++) s -= A[i * n + j] * b[j];
        b[i] = s / A[i * n + i];
    }
}

/* ---- Rodas4's linear systems (I/(gamma h) - J) k = b, reduced by the kinematic rows ----
 * A mechanical system's position rows x' = v have a unit vector for their Jacobian row: their
 * unknowns follow from their velocity's, k_x = gamma h (b_x + k_v), and need no elimination. The
 * rest is a smaller dense system (3 x 3 instead of 5 x 5 for LuGre on the stick-slip actuator),
 * factored with partial pivoting and reciprocal pivots (no division in the six solves per step). */

/* Finds the kinematic rows of the current Jacobian (called after every Jacobian evaluation). */
static void structure_of_jacobian(work *w)
{
    int n = w->n;
    const double *J = w->J;
    for (int i = 0; i < n; i++) {
        int q = -1, nz = 0;
        for (int j = 0; j < n; j++)
            if (J[i * n + j] != 0.0) { nz++; q = j; }
        w->partner[i] = (nz == 1 && q != i && J[i * n + q] == 1.0) ? q : -1;
    }
    /* a partner must itself stay in the reduced system */
    for (int i = 0; i < n; i++)
        if (w->partner[i] >= 0 && w->partner[w->partner[i]] >= 0) w->partner[i] = -1;
    w->npos = w->nred = 0;
    for (int i = 0; i < n; i++) {
        if (w->partner[i] >= 0) w->pos[w->npos++] = i;
        else w->red[w->nred++] = i;
    }
    for (int j = 0; j < w->npos; j++) /* where each partner sits among the reduced unknowns */
        for (int b = 0; b < w->nred; b++)
            if (w->red[b] == w->partner[w->pos[j]]) w->qcol[j] = b;
}

TF_SIZED int reduced_factor(work *w, double h, const int n, const int nr, const int np)
{
    const double *J = w->J;
    double *A = w->W, gh = ro_gamma * h, c = 1.0 / gh;
    w->gh = gh;
    for (int a = 0; a < nr; a++) {
        int r = w->red[a];
        for (int b = 0; b < nr; b++) A[a * nr + b] = -J[r * n + w->red[b]];
        A[a * nr + a] += c;
        for (int j = 0; j < np; j++) {
            double Jrp = gh * J[r * n + w->pos[j]];
            w->Jpos[a * np + j] = Jrp;
            /* -J[r][p] k_p = -J[r][p] gh (b_p + k_q): the k_q part moves into q's column */
            A[a * nr + w->qcol[j]] -= Jrp;
        }
    }
    for (int k = 0; k < nr; k++) {
        int p = k;
        double big = fabs(A[k * nr + k]);
        for (int i = k + 1; i < nr; i++)
            if (fabs(A[i * nr + k]) > big) { big = fabs(A[i * nr + k]); p = i; }
        w->piv[k] = p;
        if (big == 0.0 || !isfinite(big)) return 1;
        if (p != k)
            for (int j = k; j < nr; j++) { double tmp = A[k * nr + j]; A[k * nr + j] = A[p * nr + j]; A[p * nr + j] = tmp; }
        double inv = w->dinv[k] = 1.0 / A[k * nr + k];
        for (int i = k + 1; i < nr; i++) {
            double l = A[i * nr + k] *= inv;
            if (l != 0.0)
                for (int j = k + 1; j < nr; j++) A[i * nr + j] -= l * A[k * nr + j];
        }
    }
    return 0;
}

TF_SIZED void reduced_solve(const work *w, double *b, const int nr, const int np)
{
    const double *A = w->W;
    double *xr = w->xr;
    for (int a = 0; a < nr; a++) {
        double s = b[w->red[a]];
        for (int j = 0; j < np; j++) s += w->Jpos[a * np + j] * b[w->pos[j]];
        xr[a] = s;
    }
    for (int k = 0; k < nr; k++) {
        if (w->piv[k] != k) { double tmp = xr[k]; xr[k] = xr[w->piv[k]]; xr[w->piv[k]] = tmp; }
        for (int i = k + 1; i < nr; i++) xr[i] -= A[i * nr + k] * xr[k];
    }
    for (int i = nr - 1; i >= 0; i--) {
        double s = xr[i];
        for (int j = i + 1; j < nr; j++) s -= A[i * nr + j] * xr[j];
        xr[i] = s * w->dinv[i];
    }
    for (int a = 0; a < nr; a++) b[w->red[a]] = xr[a];
    for (int j = 0; j < np; j++) b[w->pos[j]] = w->gh * (b[w->pos[j]] + b[w->partner[w->pos[j]]]);
}

/* ---- one attempted step of each method: y1, dense coefficients; returns the error norm,
 *      or a negative value when the step produced non-finite numbers ---- */
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

static double dopri5_step(work *w, double t, double h, const double *y, const double *f0)
{
    switch (w->n) {
    case 5: return dopri5_step_n(w, t, h, y, f0, 5);
    case 3: return dopri5_step_n(w, t, h, y, f0, 3);
    default: return dopri5_step_n(w, t, h, y, f0, w->n);
    }
}

TF_SIZED void dopri5_dense_n(const work *w, double s, double *y, const int n)
{
    double s1 = 1.0 - s;
    for (int i = 0; i < n; i++)
        y[i] = w->cont[0][i] +
               s * (w->cont[1][i] + s1 * (w->cont[2][i] + s * (w->cont[3][i] + s1 * w->cont[4][i])));
}

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
    if (reduced_factor(w, h, n, nr, np)) return -2;

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

/* The reduced sizes are known once the Jacobian's structure is (structure_of_jacobian). */
static double rodas4_step(work *w, double t, double h, const double *y, const double *f0)
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

static void dopri5_dense(const work *w, double s, double *y)
{
    switch (w->n) {
    case 5: dopri5_dense_n(w, s, y, 5); break;
    case 3: dopri5_dense_n(w, s, y, 3); break;
    default: dopri5_dense_n(w, s, y, w->n);
    }
}

static void rodas4_dense(const work *w, double s, double *y)
{
    switch (w->n) {
    case 5: rodas4_dense_n(w, s, y, 5); break;
    case 3: rodas4_dense_n(w, s, y, 3); break;
    default: rodas4_dense_n(w, s, y, w->n);
    }
}

/* Hairer's starting step: an explicit Euler step's change in f sets the scale. */
static double initial_step(work *w, double t, const double *y, const double *f0, int order, double hmax)
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

/* Work in right-hand-side evaluations, for AUTO's choice. Deterministic (counted, not timed),
 * so that the same problem always takes the same path. An analytic Jacobian costs a few rhs
 * evaluations plus its n^2 entries; a dense LU ~n^3/3 flops, about one rhs evaluation of a
 * small system (calibrated on GMS with 50 elements, n = 52: ~35 us per LU against ~100 ns per
 * rhs evaluation, i.e. ~n^3/300 evaluations). */
static double work_units(const tf_solver_stats *st, int n)
{
    double nn = (double)n;
    return (double)st->rhs_evals + (3.0 + nn * nn / 100.0) * st->jac_evals +
           fmax(1.0, nn * nn * nn / 300.0) * st->decompositions;
}

static int fail(work *w, int status, double t, double h)
{
    w->st->status = status;
    w->st->t_fail = t;
    w->st->h_fail = h;
    return status;
}

const char *tf_status_message(int status)
{
    switch (status) {
    case TF_OK: return "success";
    case TF_ERR_NONFINITE: return "the state or its derivative became NaN or infinite";
    case TF_ERR_STEP_UNDERFLOW: return "the step size fell below the resolution of the time variable";
    case TF_ERR_MAX_STEPS: return "the maximum number of steps was reached";
    case TF_ERR_BAD_ARGUMENT: return "invalid solver arguments";
    case TF_ERR_NO_MEMORY: return "out of memory";
    case TF_ERR_INTERRUPTED: return "interrupted";
    default: return "unknown error";
    }
}

static int setup(work *w, const tf_ode *ode, const tf_solver_options *opt, tf_solver_stats *st)
{
    int n = ode->n;
    memset(w, 0, sizeof *w);
    w->t_clamp = INFINITY;
    w->ode = ode; w->opt = opt; w->st = st; w->n = n;
    size_t nvec = 7 + 4 + 5 + 3;
    w->block = (double *)malloc(sizeof(double) * (nvec * n + 3 * (size_t)n * n) + sizeof(int) * 5 * n);
    if (!w->block) return 1;
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
    return 0;
}

/* The earliest upward zero crossing of the event functions within an accepted step [t, t + h]
 * (g0 at t, g1 at the step's end y1), as a fraction s of h, located on the dense output by the
 * Illinois method to a few ulps of t; the right end of the final bracket, so that the crossing
 * has happened there. -1 if no function crosses. */
static double locate_event(work *w, int method, int ne, double t, double h, const double *g0, double t_new,
                           const double *y1, double *g1, double *gm, double *ym)
{
    const tf_ode *ode = w->ode;
    ode->events(t_new, y1, g1, ode->ctx);
    int any = 0;
    for (int i = 0; i < ne; i++) any |= g0[i] < 0.0 && g1[i] >= 0.0;
    if (!any) return -1.0;
    double sa = 0.0, sb = (t_new - t) / h;
    /* the crossing function with the earliest linear estimate brackets the search */
    int idx = -1;
    double best = INFINITY;
    for (int i = 0; i < ne; i++)
        if (g0[i] < 0.0 && g1[i] >= 0.0) {
            double s = sb * g0[i] / (g0[i] - g1[i]);
            if (s < best) { best = s; idx = i; }
        }
    double ga = g0[idx], gb = g1[idx];
    int side = 0;
    double tol = 4.0 * DBL_EPSILON * fmax(fabs(t), fabs(h)) / fabs(h);
    for (int it = 0; it < 200 && sb - sa > tol; it++) {
        double s = sa + (sb - sa) * ga / (ga - gb);
        if (!(s > sa && s < sb)) s = 0.5 * (sa + sb);
        if (method == TF_METHOD_RODAS4) rodas4_dense(w, s, ym); else dopri5_dense(w, s, ym);
        ode->events(t + s * h, ym, gm, ode->ctx);
        /* another function crossing earlier takes over the bracket */
        int hit = -1;
        for (int i = 0; i < ne; i++)
            if (g0[i] < 0.0 && gm[i] >= 0.0 && (hit < 0 || gm[i] > gm[hit])) hit = i;
        if (hit >= 0) {
            sb = s;
            gb = gm[hit];
            if (hit != idx) { idx = hit; ga = g0[idx]; side = 0; }
            if (side == 1) ga *= 0.5;
            side = 1;
        } else {
            sa = s;
            ga = gm[idx];
            if (side == -1) gb *= 0.5;
            side = -1;
        }
    }
    return sb;
}

int tf_solve(const tf_ode *ode, const tf_solver_options *opt, const double *t_out, long n_out,
             double *y, tf_emit_fn emit, void *emit_ctx, tf_solver_stats *st)
{
    memset(st, 0, sizeof *st);
    st->switch_time = -1.0;
    int n = ode->n;
    if (n < 0 || n_out < 1 || !(opt->rtol > 0) || (n > 0 && !opt->atol) || opt->max_steps <= 0)
        return fail(&(work){.st = st}, TF_ERR_BAD_ARGUMENT, t_out[0], 0.0);
    /* times finite, within +-1e12 s (beyond it a double resolves time to ~1e-4 s, coarser than
     * any dynamics here, and periodic inputs lose their phase), and not decreasing */
    for (long i = 0; i < n_out; i++)
        if (!(fabs(t_out[i]) <= 1e12) || (i && !(t_out[i] >= t_out[i - 1])))
            return fail(&(work){.st = st}, TF_ERR_BAD_ARGUMENT, t_out[i], 0.0);
    if (n == 0) { /* nothing to integrate (a static friction map under prescribed motion) */
        for (long i = 0; i < n_out; i++) emit(i, t_out[i], y, emit_ctx);
        st->method_used = opt->method;
        return TF_OK;
    }

    work w;
    if (setup(&w, ode, opt, st)) { st->status = TF_ERR_NO_MEMORY; return TF_ERR_NO_MEMORY; }
    /* without a Jacobian (e.g. sensitivity systems) only the explicit method applies */
    const int requested = ode->jac ? opt->method : TF_METHOD_DOPRI5;
    int method = requested == TF_METHOD_AUTO ? TF_METHOD_DOPRI5 : requested;
    /* AUTO's explicit phases run at AUTO_EXPLICIT_TOL times the tolerances: at equal tolerances
     * Dopri5's global error is ~10-50x Rodas4's on stick-slip, so that mixing the two at one
     * tolerance made the error depend on which ran where, not on the tolerance (and the cost
     * comparison that picks the method compared unequal accuracies) */
    double *atol_x = (double *)malloc(sizeof(double) * n);
    tf_solver_options opt_x = *opt;
    if (atol_x) {
        for (int i = 0; i < n; i++) atol_x[i] = AUTO_EXPLICIT_TOL * opt->atol[i];
        opt_x.rtol *= AUTO_EXPLICIT_TOL;
        opt_x.atol = atol_x;
    }
    if (requested == TF_METHOD_AUTO) w.opt = &opt_x;
    double t = t_out[0], t_end = t_out[n_out - 1];
    double *f0 = (double *)malloc(sizeof(double) * n);
    double *yd = (double *)malloc(sizeof(double) * n);
    const int ne = ode->events ? ode->nevent : 0;
    double *g0 = (double *)malloc(sizeof(double) * (ne + 1) * 3), *g1 = g0 + ne + 1, *gm = g1 + ne + 1;
    int status = TF_OK;
    long next = 0;
    double h = 0.0, facold = 1e-4, hold = 0.0, errold = 1.0;
    int first_rodas = 1, reject = 0, iasti = 0, nonsti = 0;
    /* AUTO bookkeeping: the explicit method's recent cost, the probe, the lock-out */
    double win_t = t, win_work = 0.0, explicit_rate = 0.0, probe_t = 0.0, probe_work = 0.0;
    long win_steps = 0, probe_steps = 0, lock_steps = 0, lock_len = FIRST_LOCK;
    int poll = TF_POLL_STEPS; /* steps to the next interrupt poll */
    if (!f0 || !yd || !g0 || !atol_x) { status = TF_ERR_NO_MEMORY; st->status = status; goto done; }

    while (next < n_out && t_out[next] <= t) emit(next, t_out[next], y, emit_ctx), next++;
    if (!all_finite(y, n)) { status = fail(&w, TF_ERR_NONFINITE, t, 0.0); goto done; }

    while (t < t_end) {
        /* what is left may be a rounding residue (a corner computed one ulp before the grid's
         * end): nothing to integrate, and a step that small would count as an underflow */
        if (t_end - t <= 64.0 * DBL_EPSILON * fabs(t_end)) break;
        double corner = ode->next_corner ? ode->next_corner(t, ode->ctx) : INFINITY;
        double seg_end = fmin(corner, t_end);
        if (!(seg_end > t) || t_end - seg_end <= 64.0 * DBL_EPSILON * fabs(t_end)) seg_end = t_end;
        /* restart at every corner (the derivative may jump there) and every event */
        w.t_clamp = INFINITY;
        if (ode->on_restart) ode->on_restart(t, y, ode->ctx);
        if (ne) ode->events(t, y, g0, ode->ctx);
        if (rhs(&w, t, y, f0)) { status = fail(&w, TF_ERR_NONFINITE, t, h); goto done; }
        /* AUTO picks the method per phase: every restart -- a corner of the input, or an event
         * (a GMS mode switch) -- starts a new one (after a flyback its ringing, where the explicit
         * method is cheaper; then the ramp, where the stiff one is) */
        if (requested == TF_METHOD_AUTO && method == TF_METHOD_RODAS4 && t > t_out[0]) {
            method = TF_METHOD_DOPRI5;
            w.opt = &opt_x;
            iasti = nonsti = 0;
            probe_steps = -1;
            win_steps = 0;
            win_t = t;
            win_work = work_units(st, n);
            h = initial_step(&w, t, y, f0, 5, opt->hmax); /* not the stiff method's long ramp step */
        }
        if (h <= 0.0) {
            h = opt->h0 > 0 ? opt->h0 : initial_step(&w, t, y, f0, method == TF_METHOD_DOPRI5 ? 5 : 4, opt->hmax);
        }
        w.t_clamp = nextafter(seg_end, -INFINITY);
        int jac_current = 0;
        while (t < seg_end) {
            if (st->steps + st->rejected >= opt->max_steps) { status = fail(&w, TF_ERR_MAX_STEPS, t, h); goto done; }
            if (opt->interrupt && --poll <= 0) {
                poll = TF_POLL_STEPS;
                if (opt->interrupt(opt->interrupt_ctx)) { status = fail(&w, TF_ERR_INTERRUPTED, t, h); goto done; }
            }
            if (opt->hmax > 0) h = fmin(h, opt->hmax);
            int last = 0;
            if (t + 1.01 * h >= seg_end) { h = seg_end - t; last = 1; }
            if (h <= 16.0 * DBL_EPSILON * fmax(fabs(t), 1e-300)) {
                status = fail(&w, TF_ERR_STEP_UNDERFLOW, t, h);
                goto done;
            }
            double err;
            if (method == TF_METHOD_RODAS4) {
                if (!jac_current) {
                    st->jac_evals++;
                    ode->jac(t, y, w.J, ode->ctx);
                    if (!all_finite(w.J, n * n) || time_derivative(&w, t, seg_end, y, f0, w.ft)) {
                        status = fail(&w, TF_ERR_NONFINITE, t, h);
                        goto done;
                    }
                    structure_of_jacobian(&w);
                    jac_current = 1;
                }
                err = rodas4_step(&w, t, h, y, f0);
                /* Rodas4 estimates its error at the step's end, but a long step across a fast
                 * transition (a slip onset after a long stick) can be right there and wrong inside,
                 * where the output is interpolated. So the dense output at mid-step is compared with
                 * the cubic Hermite interpolant of the step's ends and slopes, and a disagreement
                 * above the tolerance counts as the step's error. The end slope is the next step's
                 * first derivative: the check costs a right-hand side only on rejection. */
                if (err >= 0.0 && err <= 1.0) {
                    double *f1 = w.k[6];
                    if (rhs(&w, t + h, w.y1, f1)) {
                        err = -1.0;
                    } else {
                        rodas4_dense(&w, 0.5, yd);
                        for (int i = 0; i < n; i++)
                            w.ytmp[i] = yd[i] - (0.5 * (y[i] + w.y1[i]) + 0.125 * h * (f0[i] - f1[i]));
                        double e_mid = wnorm(&w, w.ytmp, y, w.y1);
                        err = isfinite(e_mid) ? fmax(err, e_mid) : -1.0;
                    }
                }
            } else {
                err = dopri5_step(&w, t, h, y, f0);
            }
            if (err < 0.0) { /* non-finite or singular: retry smaller */
                st->rejected++;
                reject = 1;
                h *= 0.25;
                if (h <= 16.0 * DBL_EPSILON * fmax(fabs(t), 1e-300)) {
                    status = fail(&w, TF_ERR_NONFINITE, t, h);
                    goto done;
                }
                continue;
            }
            if (err <= 1.0) {
                double t_new = last ? seg_end : t + h;
                if (ne) { /* an event inside the step: end the step there, emit up to it, restart */
                    double s_ev = locate_event(&w, method, ne, t, h, g0, t_new, w.y1, g1, gm, yd);
                    /* an event located within the corner margin of the corner that ends this
                     * segment is taken at the corner: a restart just before it would find the
                     * corner already passed and integrate across it */
                    if (s_ev >= 0.0 && s_ev < 1.0 && last && seg_end == corner &&
                        !(ode->next_corner(t + s_ev * h, ode->ctx) <= corner))
                        s_ev = 1.0;
                    if (s_ev >= 0.0) {
                        double t_ev = s_ev >= 1.0 ? t_new : t + s_ev * h;
                        while (next < n_out && t_out[next] <= t_ev) {
                            double s = (t_out[next] - t) / h;
                            if (method == TF_METHOD_RODAS4) rodas4_dense(&w, s, yd); else dopri5_dense(&w, s, yd);
                            if (!all_finite(yd, n)) { status = fail(&w, TF_ERR_NONFINITE, t_out[next], h); goto done; }
                            emit(next, t_out[next], yd, emit_ctx);
                            next++;
                        }
                        if (s_ev >= 1.0) memcpy(y, w.y1, sizeof(double) * n);
                        else if (method == TF_METHOD_RODAS4) rodas4_dense(&w, s_ev, y);
                        else dopri5_dense(&w, s_ev, y);
                        st->steps++;
                        st->events++;
                        h = fmax(h * s_ev, 1e-6 * h); /* the next segment starts with a step like this one */
                        t = t_ev;
                        first_rodas = 1;
                        reject = 0;
                        break;
                    }
                    memcpy(g0, g1, sizeof(double) * ne);
                }
                const double hinv = 1.0 / h; /* one division per step, not per output sample */
                while (next < n_out && t_out[next] <= t_new) {
                    double s = (t_out[next] - t) * hinv;
                    if (method == TF_METHOD_RODAS4) rodas4_dense(&w, s, yd); else dopri5_dense(&w, s, yd);
                    /* finite ends of a step can still interpolate to an overflow in between (found by
                     * fuzzing: a 1e-3 kg mass under a huge sampled force): never emit it as TF_OK */
                    if (!all_finite(yd, n)) { status = fail(&w, TF_ERR_NONFINITE, t_out[next], h); goto done; }
                    emit(next, t_out[next], yd, emit_ctx);
                    next++;
                }
                st->steps++;
                double hnew;
                if (method == TF_METHOD_RODAS4) {
                    double fac = fmax(1.0 / 6.0, fmin(5.0, root4(err) / 0.9));
                    if (!first_rodas) {
                        double facpred = (hold / h) * root4(err * err / errold) / 0.9;
                        fac = fmax(fac, fmax(1.0 / 6.0, fmin(5.0, facpred)));
                    }
                    hnew = h / fac;
                    first_rodas = 0;
                    hold = h;
                    errold = fmax(0.01, err);
                    if (!last) memcpy(f0, w.k[6], sizeof(double) * n); /* f(t_new, y1), from the mid-step check */
                    jac_current = 0;
                } else {
                    /* PI control, Hairer's DOPRI5 constants */
                    const double beta = 0.04, expo1 = 0.2 - beta * 0.75;
                    double fac11 = pow(err, expo1);
                    double fac = fac11 / pow(facold, beta);
                    fac = fmax(0.1, fmin(5.0, fac / 0.9));
                    hnew = h / fac;
                    facold = fmax(err, 1e-4);
                    /* stiffness test: h * |lambda| from the last two stages */
                    double num = 0.0, den = 0.0;
                    for (int i = 0; i < n; i++) {
                        double sk = opt->atol[i] + opt->rtol * fabs(w.y1[i]);
                        double a = (w.k[6][i] - w.k[5][i]) / sk, b = (w.y1[i] - w.ysti[i]) / sk;
                        num += a * a;
                        den += b * b;
                    }
                    if (den > 0.0 && h * sqrt(num / den) > 3.25) {
                        nonsti = 0;
                        if (++iasti >= 15) {
                            st->stiff_suspected = 1;
                            if (requested == TF_METHOD_AUTO && lock_steps <= 0 && t_new > win_t) {
                                explicit_rate = (work_units(st, n) - win_work) / (t_new - win_t);
                                method = TF_METHOD_RODAS4;
                                w.opt = opt;
                                first_rodas = 1;
                                st->switch_time = t_new;
                                probe_t = t_new;
                                probe_work = work_units(st, n);
                                probe_steps = 0;
                                iasti = 0;
                            }
                        }
                    } else if (++nonsti >= 6) {
                        iasti = 0;
                    }
                    memcpy(f0, w.k[6], sizeof(double) * n); /* FSAL */
                    if (lock_steps > 0) lock_steps--;
                    if (++win_steps >= WINDOW_STEPS && method == TF_METHOD_DOPRI5) {
                        win_steps = 0;
                        win_t = t_new;
                        win_work = work_units(st, n);
                    }
                }
                if (method == TF_METHOD_RODAS4 && requested == TF_METHOD_AUTO && probe_steps >= 0 &&
                    ++probe_steps >= PROBE_STEPS) {
                    double rodas_rate = (work_units(st, n) - probe_work) / (t_new - probe_t);
                    if (rodas_rate >= explicit_rate) { /* the stiff method does not pay: go back */
                        method = TF_METHOD_DOPRI5;
                        w.opt = &opt_x;
                        st->switch_time = -1.0;
                        lock_steps = lock_len;
                        lock_len *= 2;
                        win_steps = 0;
                        win_t = t_new;
                        win_work = work_units(st, n);
                        iasti = nonsti = 0; /* f0 = f(t_new, y1) is current: Rodas4 computed it */
                    } else {
                        probe_steps = -1; /* it pays: stay */
                    }
                }
                if (reject) hnew = fmin(hnew, h);
                reject = 0;
                memcpy(y, w.y1, sizeof(double) * n);
                t = t_new;
                h = hnew;
            } else {
                st->rejected++;
                reject = 1;
                if (method == TF_METHOD_RODAS4)
                    h /= fmax(1.0 / 6.0, fmin(5.0, root4(err) / 0.9));
                else
                    h /= fmin(5.0, pow(err, 0.2 - 0.04 * 0.75) / 0.9);
            }
        }
    }
    while (next < n_out) emit(next, t_out[next], y, emit_ctx), next++;
done:
    st->method_used = method;
    free(f0);
    free(yd);
    free(atol_x);
    free(g0);
    free(w.block);
    return status;
}
