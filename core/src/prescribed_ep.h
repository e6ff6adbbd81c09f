/* Private to prescribed.c and prescribed_ep.c: the elasto-plastic bristle stepped over a segment of
 * constant velocity (docs/force-data.md#3-identification).
 *
 * With y = sgn(v) z and the displacement x = |v| t, the bristle's rate z' = v - alpha(z, v) sigma0 |v| z / g(v)
 * (friction.c: elastoplastic) is dy/dx = 1 - alpha(y) y / z_ss, z_ss = g(v) / sigma0: y = x + y0 while
 * y <= z_ba (alpha = 0: elastic; also where z opposes v), y = z_ss + (y0 - z_ss) e^{-x / z_ss} from y >= z_ss on
 * (alpha = 1: affine), both closed-form with closed-form sensitivities. Between (the transition, where alpha is
 * the half sine), y rises towards z_ss and never reaches it; there u = ln(z_ss - y) obeys
 * du/dx = -(sin^2 phi / w + cos^2 phi / z_ss), w = e^u, phi = pi w / (2 (z_ss - z_ba)), which is smooth and
 * bounded (-> -1/z_ss as y -> z_ss, where y's own equation becomes stiff against a sample's motion), and is
 * integrated by Dormand-Prince 5(4) with its error on u (a relative error of z_ss - y) held below
 * TF_EP_TOL per step, the variational equations of u in its start, z_ss and z_ba carried by the same stages
 * (the derivatives of the computed solution). The sensitivities to the friction parameters follow through
 * z_ss and z_ba. */
#ifndef THERMOFRICTION_PRESCRIBED_EP_H
#define THERMOFRICTION_PRESCRIBED_EP_H

#include "thermofriction/friction.h"

/* The local error allowed per step of the transition on u = ln(z_ss - y). */
#define TF_EP_TOL 1e-11

typedef struct {
    double av, zss, zba;   /* |v|, the steady and the break-away deflection on the side of v */
    double dzss[TF_NPARAM], dzba[TF_NPARAM]; /* their derivatives in the run's parameters (np of them) */
    double hx;             /* the transition's next step in displacement (kept across segments) */
    long steps, rejected;  /* the transition's steps, for tests */
} tf_ep_segment;

/* The segment's values at velocity v: z_ss and z_ba, and their derivatives in every friction parameter
 * (tf_param order, the negative side's named where v < 0) into dzss_all, dzba_all. */
void tf_ep_segment_set(tf_ep_segment *e, const double *p, double v, double *dzss_all, double *dzba_all);

/* The state z and its sensitivities S[np] over the time h at velocity v (that of tf_ep_segment_set),
 * e->dzss and e->dzba in the same np parameters. No allocation. */
void tf_ep_advance(tf_ep_segment *e, double v, double *z, double *S, int np, double h);

#endif
