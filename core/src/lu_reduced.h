/* Private to rodas4.c and lu.c: Rodas4's linear systems (I/(gamma h) - J) k = b, reduced by the
 * kinematic rows. A mechanical system's position rows x' = v have a unit vector for their Jacobian
 * row: their unknowns follow from their velocity's, k_x = gamma h (b_x + k_v), and need no
 * elimination. The rest is a smaller dense system (3 x 3 instead of 5 x 5 for LuGre on the stick-slip
 * actuator), factored with partial pivoting and reciprocal pivots (no division in the six solves per
 * step). The factor and solve are inlined into Rodas4's stages with constant sizes (work.h). */
#ifndef THERMOFRICTION_LU_REDUCED_H
#define THERMOFRICTION_LU_REDUCED_H

#include "work.h"

/* Finds the kinematic rows of the current Jacobian (lu.c; after every Jacobian evaluation). */
void tf_lu_structure(work *w);

/* Factors the reduced matrix of I/(gamma h) - J; nonzero if singular. */
TF_SIZED int reduced_factor(work *w, double h, const double gamma, const int n, const int nr, const int np)
{
    const double *J = w->J;
    double *A = w->W, gh = gamma * h, c = 1.0 / gh;
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

#endif
