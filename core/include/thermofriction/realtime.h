/* Real-time friction models: a fixed-step, allocation-free interface for control loops
 * (10-100 kHz on a DSP or microcontroller). Every friction model of friction.h, with Model I or
 * Model II, behind four calls:
 *
 *     tf_rt_friction f;
 *     tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL);          // parameters p[TF_NPARAM]
 *     tf_rt_set_model_i(&f, TF_P_FC, &fc_law);             // optional: a law of temperature
 *     double F = tf_rt_step(&f, v, T, dt);                 // every control period
 *     tf_rt_set_param(&f, TF_P_SIGMA1, 3.0);               // at run time
 *     tf_rt_reset(&f);                                     // internal states to rest
 *
 * Discretisation: exponential (Rosenbrock-)Euler. Over one step the state equation
 * z' = f(v, z) is linearised in z at the start, z' ~ a - b (z - z_n), and that linear equation is
 * solved exactly with v held: z_{n+1} = z_n + f(v, z_n) (1 - exp(-b dt)) / b. Why this one:
 *   - it is exact for every bristle model while v is constant (LuGre, Dahl: z' = v - sigma0 |v| z
 *     / g(v) is linear in z), so it is first-order accurate in v's variation only;
 *   - it is unconditionally stable (0 < 1 - exp(-b dt) < 1 for b > 0): with dt far above the
 *     bristle time constant g / (sigma0 |v|) the state lands on its steady state g sgn(v) / sigma0
 *     instead of oscillating or blowing up as explicit Euler does beyond dt = 2 g / (sigma0 |v|);
 *   - it needs no iteration (a fixed cost per step) and reuses the core's own friction equations
 *     (tf_friction_eval and its partials): one source of truth with the simulator.
 * The force is the model's at the new state and v. GMS elements switch stick/slip after each step
 * (tf_friction_update_modes).
 *
 * No allocation, no dependency beyond libm; a tf_rt_friction is a plain struct (about 3 kB with
 * its 64 GMS slots) that the caller owns. Laws point to caller-owned breakpoint arrays. */
#ifndef THERMOFRICTION_REALTIME_H
#define THERMOFRICTION_REALTIME_H

#include "friction.h"
#include "plant.h"
#include "thermal.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    /* the friction model and its thermal extension, as the simulator holds them (plant.h; the
       plant fields are unused), with its per-temperature parameter cache */
    tf_model model;
    double z[TF_MAX_FRICTION_STATES]; /* internal states */
} tf_rt_friction;

/* Sets up a model at rest. p: TF_NPARAM values (unused ones ignored); gms: the elements for
 * TF_FRICTION_GMS (else NULL). fs = fc when p[TF_P_FS] is not finite (no Stribeck effect). Returns
 * TF_OK (0) or TF_ERR_BAD_ARGUMENT (4) for an unknown kind or a bad GMS element count. */
int tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms);
/* Model I: parameter `param` follows `law` (copied; its arrays must outlive f). */
int tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law);
/* Model II: dF(T) [N] applied in `form` (TF_DF_SCALE: F (1 + dF / fc); TF_DF_OFFSET: + dF tanh(v / v_smooth)). */
int tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form);
/* Changes parameter `param` at run time (its law, if any, is dropped). */
int tf_rt_set_param(tf_rt_friction *f, int param, double value);
/* Internal states to rest (z = 0, GMS elements stuck). */
void tf_rt_reset(tf_rt_friction *f);
/* Parameters at temperature T [degC] into p[TF_NPARAM]; *lambda, *dF_offset (may be NULL). */
void tf_rt_params_at(tf_rt_friction *f, double T, double *p, double *lambda, double *dF_offset);
/* Advances the internal states by dt [s] at sliding velocity v [m/s] and temperature T [degC]
 * (ignored without a thermal model) and returns the friction force F [N] (the sign convention of
 * docs/models.md#conventions: the force resisting sliding, with v's sign in steady sliding).
 * dt <= 0 returns the force without advancing. */
double tf_rt_step(tf_rt_friction *f, double v, double T, double dt);

/* The friction model and thermal extension of a simulation model (plant.h's tf_model), for
 * callers that already configure one; its laws' arrays must outlive f. */
int tf_rt_from_model(tf_rt_friction *f, const tf_model *model);
/* F' from the base model's force: Model II's scale factor and offset (docs/models.md#model-ii) as
 * tf_rt_params_at gives them, at sliding velocity v with parameters p (tf_thermal_force, thermal.h). */
double tf_rt_thermal_force(double F_base, double v, const double *p, double lambda, double dF_offset);

/* The core of tf_rt_step for callers that add terms to the state equation (observers): advances
 * z by one exponential-Euler step of z' = f(v, z) + extra[j] (extra may be NULL) with parameters
 * p, writes the rates at the new state to dz (with extra added) and returns the base force. */
double tf_rt_advance(int kind, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                     const double *extra, double *dz);

#ifdef __cplusplus
}
#endif
#endif
