/* Private to prescribed.c and prescribed_ep.c: the elasto-plastic bristle stepped over a segment of
 * constant velocity (docs/force-data.md#3-identification).
 *
 * With y = sgn(v) z and the displacement x = |v| t, the bristle's rate z' = v - alpha(z, v) sigma0 |v| z / g(v)
 * (friction.c: elastoplastic) is dy/dx = 1 - alpha(y) y / z_ss, z_ss = g(v) / sigma0: y = x + y0 while
 * y <= z_ba (alpha = 0: elastic; also where z opposes v), y = z_ss + (y0 - z_ss) e^{-x / z_ss} from y >= z_ss on
 * (alpha = 1: affine), both closed-form with closed-form sensitivities. Between (the transition, where alpha is
 * the half sine), y rises towards z_ss and never reaches it. There w = z_ss - y obeys
 * w' = -w / z_ss - (1 - w / z_ss) sin^2(phi), phi = pi w / (2 W), W = z_ss - z_ba (per unit displacement), and
 * rho = e^{x / z_ss} / w over s = 1 - e^{-x / z_ss} (in [0, 1) however long the segment) obeys
 *   d rho / ds = (z_ss - w) (sin(phi) / w)^2,   w = (1 - s) / rho,
 * exactly: the relaxation at the rate 1 / z_ss, stiff against a sample's motion, is taken out in closed form,
 * and what remains is smooth and bounded (-> z_ss (pi / 2W)^2 as w -> 0), nearly constant near z_ss. It is
 * integrated by Dormand-Prince 5(4) with the error it makes in y (w times rho's relative error) held below
 * TF_EP_TOL z_ss per step (near z_ss one step spans a segment), the variational equations of rho in its start,
 * z_ss and W carried by the same stages (the derivatives of the computed solution). The sensitivities to the
 * friction parameters follow through z_ss and z_ba. */
#ifndef THERMOFRICTION_PRESCRIBED_EP_H
#define THERMOFRICTION_PRESCRIBED_EP_H

#include "thermofriction/friction.h"

/* The local error in y allowed per step of the transition, relative to z_ss. */
#define TF_EP_TOL 1e-11

typedef struct {
    double av, zss, zba;   /* |v|, the steady and the break-away deflection on the side of v */
    double dzss[TF_NPARAM], dzba[TF_NPARAM]; /* their derivatives in the run's parameters (np of them) */
} tf_ep_segment;

/* The segment's values at velocity v: z_ss and z_ba, and their derivatives in every friction parameter
 * (tf_param order, the negative side's named where v < 0) into dzss_all, dzba_all unless dzss_all is NULL. */
void tf_ep_segment_set(tf_ep_segment *e, const double *p, double v, double *dzss_all, double *dzba_all);

/* The state z and its sensitivities S[np] over the time h at velocity v (that of tf_ep_segment_set),
 * e->dzss and e->dzba in the same np parameters. No allocation. */
void tf_ep_advance(const tf_ep_segment *e, double v, double *z, double *S, int np, double h);

#endif
