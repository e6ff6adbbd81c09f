/* Private to the integrators (dopri5.c, rodas4.c, lu.c, events.c, solve.c, auto.c): the work space
 * of one integration and the small helpers every method's stages use, inlined where they are called.
 *
 * The step functions take the system size (and Rodas4 its reduced sizes) as an argument and are
 * inlined into dispatchers that pass constants for the common models (5 states: the stick-slip
 * actuator with LuGre; 3: the mass with LuGre), so that their loops over five numbers compile to
 * straight-line code; any other size runs the same code with the runtime value. */
#ifndef THERMOFRICTION_SOLVER_H
#define THERMOFRICTION_SOLVER_H

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
 * crosses a fast transition or a kink (Rodas4's steps, rodas4.c; Dormand-Prince's across reversals, solve.c). */
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


/* ---- dopri5.c: Dormand-Prince 5(4) ---- */

/* One attempted step from (t, y) with f0 = f(t, y): w->y1, the dense coefficients and the stiffness
 * test's stages; returns the error norm, or a negative value when the step produced non-finite numbers. */
double tf_dopri5_step(work *w, double t, double h, const double *y, const double *f0);
/* The dense output at the fraction s of the last step. */
void tf_dopri5_dense(const work *w, double s, double *y);
/* Dormand-Prince's dense-output polynomial at the fraction s, from its five coefficients (one component's, or a
 * difference of components' taken coefficient by coefficient) */
static inline double tf_dopri5_dense_poly(const double c[5], double s)
{
    double s1 = 1.0 - s;
    return c[0] + s * (c[1] + s1 * (c[2] + s * (c[3] + s1 * c[4])));
}
/* ... and of its component i alone */
static inline double tf_dopri5_dense_component(const work *w, int i, double s)
{
    const double c[5] = {w->cont[0][i], w->cont[1][i], w->cont[2][i], w->cont[3][i], w->cont[4][i]};
    return tf_dopri5_dense_poly(c, s);
}
/* PI step-size control after an accepted step of error err; *facold is the controller's memory. */
double tf_dopri5_next_h(double err, double h, double *facold);
/* The step after a rejected one. */
double tf_dopri5_rejected_h(double err, double h);
/* Hairer's stiffness test after an accepted step: h |lambda| from the last two stages near the
 * stability boundary; returns 1 when it fired in 15 steps in a row (counters in *iasti, *nonsti). */
int tf_dopri5_stiff(const work *w, const tf_solver_options *opt, double h, int *iasti, int *nonsti);

/* ---- rodas4.c: Rodas4 ---- */

typedef struct {
    int first;            /* no step accepted yet since the last (re)start of the method */
    double hold, errold;  /* the last accepted step and its error (predictive control) */
} tf_rodas4_control;

/* The state Jacobian and the time derivative at (t, y), once per accepted step; nonzero if not finite. */
int tf_rodas4_jacobian(work *w, double t, double seg_end, const double *y, const double *f0);
/* One attempted step, with the mid-step check of its dense output (yd: n doubles of scratch):
 * returns the error norm, -1 for non-finite numbers, -2 for a singular iteration matrix. On an
 * accepted step w->k[6] holds f(t + h, y1). */
double tf_rodas4_step(work *w, double t, double h, const double *y, const double *f0, double *yd);
void tf_rodas4_dense(const work *w, double s, double *y);
/* Predictive (Gustafsson) step-size control after an accepted step. */
double tf_rodas4_next_h(double err, double h, tf_rodas4_control *c);
double tf_rodas4_rejected_h(double err, double h);

/* The dense output of the method that made the last step. */
static inline void dense(const work *w, int method, double s, double *y)
{
    if (method == TF_METHOD_RODAS4) tf_rodas4_dense(w, s, y);
    else tf_dopri5_dense(w, s, y);
}

/* ---- events.c ---- */
double tf_locate_event(work *w, int method, int ne, double t, double h, const double *g0, double t_new,
                       const double *y1, double *g1, double *gm, double *ym);

#endif
