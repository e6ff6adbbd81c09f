/* Dense LU with partial pivoting (tf_lu_factor, tf_lu_solve: integrator.h) and the structure of
 * Rodas4's reduced systems (lu_reduced.h). */
#include "lu_reduced.h"

/* ---- dense LU with partial pivoting, for the small systems of a Rosenbrock stage ---- */
tf_status tf_lu_factor(double *A, int n, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        double big = fabs(A[k * n + k]);
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > big) { big = fabs(A[i * n + k]); p = i; }
        piv[k] = p;
        if (big == 0.0 || !isfinite(big)) return TF_ERR_SINGULAR;
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
    return TF_OK;
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

/* ---- the structure of Rodas4's reduced systems (lu_reduced.h) ---- */

/* The kinematic rows of the current Jacobian: a row whose only nonzero is a 1 off the diagonal. */
void tf_lu_structure(work *w)
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

