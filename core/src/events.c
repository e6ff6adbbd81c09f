/* Event location for the discrete modes of tf_ode (GMS elements switching stick/slip): the earliest
 * upward zero crossing of the event functions within an accepted step, on the dense output. */
#include "events.h"

#include <float.h>

/* The earliest upward zero crossing of the event functions within an accepted step [t, t + h]
 * (g0 at t, g1 at the step's end y1), as a fraction s of h, located on the dense output by the
 * Illinois method to a few ulps of t; the right end of the final bracket, so that the crossing
 * has happened there. -1 if no function crosses. */
double tf_locate_event(work *w, int method, int ne, double t, double h, const double *g0, double t_new,
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
        dense(w, method, s, ym);
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
