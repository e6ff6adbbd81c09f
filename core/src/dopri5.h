/* Private header of dopri5.c: Dormand-Prince 5(4)'s step, dense output, step-size control and
 * stiffness test on the integration's work space (work.h). */
#ifndef THERMOFRICTION_DOPRI5_H
#define THERMOFRICTION_DOPRI5_H

#include "work.h"

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

#endif
