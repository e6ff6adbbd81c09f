/* Friction under a prescribed motion, stepped exactly (docs/force-data.md#3-identification).
 *
 * A prescribed motion given as a sampled position (tf_waveform TF_WAVE_SAMPLED: straight lines between
 * knots) has a constant velocity on each segment between knots. There, and at a constant temperature,
 * the state rate of LuGre, Dahl and each GMS element is affine in its own state, z' = a + b z, with
 * a, b and their parameter derivatives constant: the step over h is closed-form,
 * z(h) = z0 e^{bh} + a (e^{bh} - 1) / b, and so is the sensitivity S = dz/dtheta, whose ODE
 * S' = b S + a_theta + b_theta z(t) is linear with constant coefficients too. The coefficients come
 * from the friction model's own evaluation (tf_friction_eval at z = 0 and z = 1), so that every change
 * of a model's equations reaches this path. Static maps (Coulomb, Stribeck) have no state: F(v). The
 * elasto-plastic bristle is affine outside its transition band (elastic below z_ba, alpha = 1 from the
 * steady deflection on), closed-form there; inside the band it is integrated with its variational
 * equations, the relaxation taken out in closed form (prescribed_ep.c: a local error below 1e-11 of the
 * steady deflection per step). */
#ifndef THERMOFRICTION_PRESCRIBED_H
#define THERMOFRICTION_PRESCRIBED_H

#include "plant.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 if tf_prescribed_force applies to the model: a prescribed plant driven by a sampled position, a
 * constant temperature (no signal, no heat balance) and load (no load waveform), no Model II (any friction
 * model). */
int tf_prescribed_applies(const tf_model *model);

/* The friction force at the n_out output times t_out (non-decreasing, from t_out[0], where the
 * friction states are at rest: the integrator's start) into F[n_out]; with np > 0, its derivatives
 * with respect to the friction parameters params[0..np-1] (tf_param indices, at the temperature)
 * into dF (n_out x np, row-major). No allocation. The model is not changed (GMS modes are tracked
 * on a copy). Returns TF_OK, or TF_ERR_BAD_ARGUMENT (a model it does not apply to, or arguments) or
 * TF_ERR_NONFINITE (a non-finite force or sensitivity, with its time and sample) in *err. */
tf_status tf_prescribed_force(const tf_model *model, long n_out, const double *t_out, double *F, int np,
                              const int *params, double *dF, tf_error *err);

#ifdef __cplusplus
}
#endif
#endif
