/* Private to the integrators (work.c, dopri5.c, rodas4.c, lu.c, events.c, auto.c, solve.c): the work space
 * of one integration (set up by work.c) and the small helpers every method's stages use, inlined where they
 * are called.
 *
 * The step functions take the system size (and Rodas4 its reduced sizes) as an argument and are
 * inlined into dispatchers that pass constants for the common models (5 states: the stick-slip
 * actuator with LuGre; 3: the mass with LuGre), so that their loops over five numbers compile to
 * straight-line code; any other size runs the same code with the runtime value. */
#ifndef THERMOFRICTION_WORK_H
#define THERMOFRICTION_WORK_H

#include "thermofriction/integrator.h"
#include "inline.h" /* TF_SIZED */

#include <math.h>

typedef struct {
    const tf_ode *ode;
    const tf_solver_options *opt;
    tf_solver_stats *st;
    int n;
    double *k[7], *ytmp, *y1, *ysti, *ft, *cont[5], *J, *W;
    int *piv;
    /* Rodas4's linear solves, reduced by the kinematic rows (lu_reduced.h): the rows p whose
     * Jacobian row is a unit vector e_q (x' = v) are eliminated, k_p = gamma h (b_p + k_q); the other
     * nred rows (red[]) form the reduced matrix, LU-factored in W with reciprocal pivots in dinv, and
     * Jpos (nred x npos) holds gamma h J[r][pos[j]], what the eliminated unknowns add to row r */
    int npos, nred, *pos, *partner, *red, *qcol;
    double gh, *dinv, *Jpos, *xr;
    double *rtol_w; /* each state's weight of the relative tolerance (opt->rtol_weight, or 1) */
    double t_clamp; /* stages never look past the corner that ends the segment */
    double *block; /* one allocation for all of the above */
} work;

/* The work space of an integration of ode with the options opt: one allocation for all of the methods'
 * vectors (TF_ERR_NO_MEMORY if it fails), released by tf_work_free. */
tf_status tf_work_setup(work *w, const tf_ode *ode, const tf_solver_options *opt, tf_solver_stats *st);
void tf_work_free(work *w);

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

static inline int rhs(work *w, double t, const double *y, double *dy) { return rhs_n(w, t, y, dy, w->n); }

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

static inline double wnorm(const work *w, const double *e, const double *ya, const double *yb)
{
    return wnorm_n(w, e, ya, yb, w->n);
}

/* A step's error inside it: its dense output yd at mid-step against the cubic Hermite interpolant of its ends
 * (y, w->y1) and their slopes (f0, f1), which an error estimated at the step's end misses where the step
 * crosses a fast transition or a kink (Rodas4's steps, rodas4.c; Dormand-Prince's across reversals, auto.c). */
static inline double mid_step_error(work *w, double h, const double *y, const double *f0, const double *f1,
                                    const double *yd)
{
    for (int i = 0; i < w->n; i++)
        w->ytmp[i] = yd[i] - (0.5 * (y[i] + w->y1[i]) + 0.125 * h * (f0[i] - f1[i]));
    return wnorm(w, w->ytmp, y, w->y1);
}

/* x^(1/4) for Rodas4's step-size control: two square roots cost a third of a pow */
static inline double root4(double x) { return sqrt(sqrt(x)); }

TF_SIZED int all_finite(const double *v, const int n)
{
    double sum = 0.0; /* as in rhs(): a NaN or an infinity anywhere makes the sum non-finite */
    for (int i = 0; i < n; i++) sum += v[i];
    return isfinite(sum);
}

#endif
