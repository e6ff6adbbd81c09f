/* Real-time friction models: a fixed-step, allocation-free interface for control loops
 * (10-100 kHz on a DSP or microcontroller). Every friction model of friction.h, with Model I (its laws
 * of temperature, or of temperature and load) or Model II, behind four calls:
 *
 *     tf_rt_friction f;
 *     tf_error err;                                        // status.h: why a call was refused
 *     tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &err);    // parameters p[TF_NPARAM]
 *     tf_rt_set_model_i(&f, TF_P_FC, &fc_law, &err);       // optional: a law of temperature (and load)
 *     double F;
 *     if (tf_rt_step(&f, v, T, load, dt, &F, &err) != TF_OK) ... // every control period
 *     tf_rt_set_param(&f, TF_P_SIGMA1, 3.0, NULL);         // at run time (err may be NULL)
 *     tf_rt_reset(&f, NULL);                               // internal states to rest
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
 * No allocation, no dependency beyond libm; a tf_rt_friction is a plain struct (about 5 kB with
 * its 64 GMS slots, twice: the model's and the run's) that the caller owns. Laws point to caller-owned breakpoint arrays. */
#ifndef THERMOFRICTION_REALTIME_H
#define THERMOFRICTION_REALTIME_H

#include "friction.h"
#include "plant.h"
#include "status.h"
#include "thermal.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    /* the friction model and its thermal extension, as the simulator holds them (plant.h; the
       plant fields are unused), and its run's data: the per-temperature parameter cache and the
       GMS elements' modes (data.model points to model: the functions below set it on every call) */
    tf_model model;
    tf_model_data data;
    double z[TF_MAX_FRICTION_STATES]; /* internal states */
    double x; /* the sliding position (the ripple's argument): v dt summed per step, or set */
} tf_rt_friction;

/* Checks. Every function validates its arguments and returns a tf_status (status.h), filling the
 * error record *err when err is not NULL: `what` names the argument (where "realtime") or the model
 * field (where "model") refused. A refused call changes nothing: the
 * internal states, the parameters and the laws stay as they were, so that a controller can skip a
 * bad sample and go on. The model is checked with the simulator's rules (tf_model_check_friction,
 * plant.h: sigma0, fc > 0, fs >= fc, ...; 1..64 GMS elements; laws with n >= 2 strictly increasing
 * finite breakpoints, TABLE slopes given); a model with a thermal extension has its parameters
 * (and Model II's lambda > 0) checked at each new temperature it is stepped at, which costs
 * nothing at a constant temperature. TF_ERR_BAD_ARGUMENT: a NULL pointer, an unknown kind or
 * index, a parameter out of its domain (at that temperature and load), a non-finite v, T (with a
 * thermal extension; without one T is ignored, NaN included), load (with a law of the load; without one
 * the load is ignored, NaN included) or dt. TF_ERR_NONFINITE: a step whose force
 * or state would not be finite (a velocity or step so large that the equations overflow). */

/* Sets up a model at rest. p: TF_NPARAM values (unused ones ignored); gms: the elements for
 * TF_FRICTION_GMS (else NULL). fs = fc when p[TF_P_FS] is not finite (no Stribeck effect). The
 * parameters must be valid as given (they are the model's while no law is set): give a
 * parameter that will follow a law its value at some temperature, not 0. */
tf_status tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms, tf_error *err);
/* Model I: parameter `param` follows `law` (copied; its arrays must outlive f): a law of temperature, or of
 * temperature and load (law.h's load term; the steps then need a finite load). Not with Model II. */
tf_status tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law, tf_error *err);
/* Model II: dF(T) [N] applied in `form` (TF_DF_SCALE: F (1 + dF / fc); TF_DF_OFFSET: + dF tanh(v / v_smooth)).
 * Not with Model I. */
tf_status tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form, tf_error *err);
/* Changes parameter `param` at run time (its law, if any, is dropped). With a thermal extension
 * the new value is checked at the last temperature stepped at (if any), else at the next step. */
tf_status tf_rt_set_param(tf_rt_friction *f, int param, double value, tf_error *err);
/* The sliding position x [m] (a measured one, e.g. the encoder's), the argument of the position
 * ripple (docs/models.md#direction-and-position); each step adds v dt to it. Refuses a non-finite x. */
tf_status tf_rt_set_position(tf_rt_friction *f, double x, tf_error *err);
/* Internal states to rest (z = 0, GMS elements stuck); the position is kept. */
tf_status tf_rt_reset(tf_rt_friction *f, tf_error *err);
/* Parameters at temperature T [degC] and load `load` [N or N m] (read by a law of the load only) into
 * p[TF_NPARAM]; *lambda, *dF_offset (may be NULL). Nothing is written if T, the load or the parameters
 * there are refused. */
tf_status tf_rt_params_at(tf_rt_friction *f, double T, double load, double *p, double *lambda, double *dF_offset,
                          tf_error *err);
/* Advances the internal states by dt [s] at sliding velocity v [m/s], temperature T [degC]
 * (ignored without a thermal model) and load `load` (a normal force [N] or a load torque [N m], read by
 * the laws with a load term; ignored by a model without one), the position by v dt, and writes the
 * friction force F [N]
 * (with the position ripple at the new position, if the model has one) to *F (the sign convention
 * of docs/models.md#conventions: the force resisting sliding, with v's sign in steady sliding).
 * dt <= 0 gives the force without advancing. On a refusal *F is NaN and the state is unchanged. */
tf_status tf_rt_step(tf_rt_friction *f, double v, double T, double load, double dt, double *F, tf_error *err);

/* The friction model and thermal extension of a simulation model (plant.h's tf_model), for
 * callers that already configure one; its laws' arrays must outlive f. */
tf_status tf_rt_from_model(tf_rt_friction *f, const tf_model *model, tf_error *err);
/* F' from the base model's force: Model II's scale factor and offset (docs/models.md#model-ii) as
 * tf_rt_params_at gives them, at sliding velocity v with parameters p (tf_thermal_force, thermal.h),
 * into *F. */
tf_status tf_rt_thermal_force(double F_base, double v, const double *p, double lambda, double dF_offset, double *F,
                              tf_error *err);

/* The core of tf_rt_step for callers that add terms to the state equation (observers): advances
 * z by one exponential-Euler step of z' = f(v, z) + extra[j] (extra: NULL, or one value per
 * internal state) with parameters p (already checked), writes the rates at the new state to dz
 * (with extra added) and the base force to *F. gms: the elements for TF_FRICTION_GMS (else may be
 * NULL). Refuses (TF_ERR_BAD_ARGUMENT, *F NaN, nothing changed) NULL p, z, dz or F, an unknown kind or
 * bad GMS elements. */
tf_status tf_rt_advance(int kind, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                        const double *extra, double *dz, double *F, tf_error *err);

#ifdef __cplusplus
}
#endif
#endif
