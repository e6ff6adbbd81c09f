/* Private header of events.c: the dense output of the method that made the last step, and event
 * location on it. */
#ifndef THERMOFRICTION_EVENTS_H
#define THERMOFRICTION_EVENTS_H

#include "dopri5.h"
#include "rodas4.h"

/* The dense output of the method that made the last step. */
static inline void dense(const work *w, int method, double s, double *y)
{
    if (method == TF_METHOD_RODAS4) tf_rodas4_dense(w, s, y);
    else tf_dopri5_dense(w, s, y);
}

/* The earliest upward zero crossing of the event functions within an accepted step (events.c). */
double tf_locate_event(work *w, int method, int ne, double t, double h, const double *g0, double t_new,
                       const double *y1, double *g1, double *gm, double *ym);

#endif
