/* Private header of rodas4.c: Rodas4's Jacobian, step, dense output and step-size control on the
 * integration's work space (work.h). */
#ifndef THERMOFRICTION_RODAS4_H
#define THERMOFRICTION_RODAS4_H

#include "work.h"

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

#endif
