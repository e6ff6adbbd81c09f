/* Friction compensation for position control loops, and a fixed-step closed-loop simulation of a
 * single-mass stage (docs/models.md#mass-plant) that uses them. Allocation-free, plain C99 + libm.
 *
 *   - tf_pid: a PID on the position error with a first-order filter on the derivative.
 *   - Feed-forward compensation: the friction model driven by the reference velocity,
 *     u_ff = F(v_ref, T) -- a tf_rt_friction stepped with tf_rt_step.
 *   - Observer-based compensation (Canudas de Wit et al. 1995, Sec. IV): the LuGre state is
 *     estimated from the measured velocity v and position error e = x - x_ref,
 *         z^' = v - sigma0 |v| z^ / g(v) - k e,   F^ = sigma0 z^ + sigma1 z^' + sigma2 v,
 *     and F^ is added to the control; with k > 0 the estimation error is dissipated (their
 *     Lyapunov argument). Both take the measured temperature T, so that Model I / II parameters
 *     follow it. */
#ifndef THERMOFRICTION_CONTROL_H
#define THERMOFRICTION_CONTROL_H

#include "estimator.h"
#include "realtime.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    double kp, ki, kd;  /* u = kp e + ki int e + kd de/dt, e = x_ref - x */
    double tau_d;       /* derivative filter time constant [s] (0: none) */
    double integral, d_filtered, e_prev;
    int started;
} tf_pid;

/* Checks, as in realtime.h: every function validates its arguments and returns a tf_status (TF_OK,
 * TF_ERR_BAD_ARGUMENT, TF_ERR_NONFINITE), fills the error record *err (status.h; may be NULL), and a
 * refused call changes nothing. */

/* Gains finite, tau_d finite and >= 0. */
tf_status tf_pid_init(tf_pid *c, double kp, double ki, double kd, double tau_d, tf_error *err);
/* One control period of dt > 0 [s] with error e: the control u into *u (NaN on a refusal: a
 * non-finite e, dt <= 0 or not finite, non-finite gains, or a u that would not be finite; the
 * controller's state is then unchanged). */
tf_status tf_pid_step(tf_pid *c, double e, double dt, double *u, tf_error *err);

/* Observer-based compensation: advances z^ (in f->z) by dt and writes F^ [N] to *F.
 * v: measured velocity [m/s]; e = x - x_ref [m]; k: observer gain [1/s], finite and >= 0 (k = 0:
 * no correction); T: temperature [degC]; load: the load [N or N m] a law of the load reads (ignored
 * without one, NaN included). The observer of Canudas de Wit et al. estimates a bristle
 * deflection: it is defined for the models with one (LuGre, Dahl, elasto-plastic) and refused
 * (TF_ERR_BAD_ARGUMENT) for the others -- Coulomb and Stribeck have no state to observe (use
 * feed-forward, tf_rt_step), GMS has one per element and no published observer. Refusals as
 * tf_rt_step's (where "observer" for its own arguments). */
tf_status tf_observer_step(tf_rt_friction *f, double v, double e, double k, double T, double load, double dt,
                           double *F, tf_error *err);

typedef enum {
    TF_COMP_NONE = 0,
    TF_COMP_FEEDFORWARD = 1, /* F(v_ref, T_comp) */
    TF_COMP_OBSERVER = 2     /* F^(v, e, T_comp) */
} tf_compensation_kind;

/* What a loop run writes per period, each pointer NULL or n doubles (all NULL: nothing more). */
typedef struct {
    double *F_plant;    /* the plant's friction, mean over the period's substeps [N] */
    double *T_comp;     /* the temperature the compensation was told [degC] */
    double *T_variance; /* the estimator's variance of it [K^2] (0 without an estimator) */
    double *F_measured; /* the disturbance observer's friction, as given to the estimator [N] (NaN: none) */
} tf_loop_trace;

/* A position-controlled single mass m x'' = u - F(v, z, T_plant): PID on e = x_ref - x at the
 * control period dt, plus compensation from `comp` told the temperature T_comp; the plant's own
 * friction `plant` at T_plant, integrated with `substeps` steps per period (semi-implicit Euler
 * for x, v; tf_rt_step for the friction states), u held over the period (zero-order hold).
 *
 * Temperatures that change over the run (the fields after `substeps`; a struct zeroed or initialised
 * with the first ten fields only has none of them):
 *   - T_plant_series: n values, the plant's temperature in each period (NULL: T_plant throughout);
 *   - the compensation's temperature, in this order of precedence: the estimator's (estimator not
 *     NULL), a perfect sensor's (T_comp_series, n values), or T_comp throughout (blind or soaked);
 *   - estimator (initialised by the caller, tf_temperature_init; its start is the loop's): stepped once
 *     per period before the control is computed, on its own friction model est_friction (initialised
 *     like comp; not the compensation's, whose states the observer corrects), with the ambient
 *     temperature T_amb, a proxy temperature T_proxy[i] (NULL: none) and the friction measured by a
 *     disturbance observer. That observer reads the encoder, x + position_noise[i] (NULL: no noise),
 *     and knows the mass and the control: at period i >= 2 it measures the friction around t_{i-1},
 *         F_dob = (u_{i-2} + u_{i-1}) / 2 - m (x_i - 2 x_{i-1} + x_{i-2}) / dt^2   (encoder positions),
 *     low-passed with time constant dob_tau [s] (0: none), at the velocity (x_i - x_{i-2}) / (2 dt),
 *     which is the velocity the estimator steps its model at (periods 0 and 1: no measurement,
 *     the velocity by one difference). The estimate after the step is the compensation's temperature.
 * The PID reads the true position (the noise is the friction measurement's). */
typedef struct {
    double mass;
    tf_rt_friction *plant;
    double T_plant;
    tf_pid pid;
    int compensation;
    tf_rt_friction *comp;
    double T_comp;
    double observer_gain;
    double dt;
    int substeps;
    const double *T_plant_series;
    const double *T_comp_series;
    tf_temperature_estimator *estimator;
    tf_rt_friction *est_friction;
    double T_amb;
    const double *T_proxy;
    const double *position_noise;
    double dob_tau;
    tf_loop_trace trace;
    /* 1: the control adds the reference's inertia force m (v_ref[i+1] - v_ref[i]) / dt (the last period:
       none), the mean acceleration over the period of a held control (needs v_ref); 0: none. Without it a
       large move's error is the PID's lag behind the acceleration, which hides the friction's part. */
    int inertia_feedforward;
    /* The loads [N or N m] the plant's and the compensation's laws of the load read (ignored by models without
       such a law; a zeroed struct has 0): load_plant_series / load_comp_series, n values, one per period (held
       over it, as the temperatures), or, where NULL, load_plant / load_comp throughout. A compensation told a
       constant load while the plant's varies is load-blind. The estimator steps est_friction at the
       compensation's load. */
    double load_plant, load_comp;
    const double *load_plant_series, *load_comp_series;
} tf_loop;

/* The most plant substeps (n x substeps) one tf_loop_run takes (~10 s of work): more is refused. */
#define TF_LOOP_MAX_SUBSTEPS 100000000.0

/* Runs n >= 1 control periods from rest at x = x_ref[0]. x_ref, v_ref: the reference at each
 * period start (v_ref may be NULL without feed-forward, friction's or inertia's). Writes, when not
 * NULL, per period: x (position at the period start), u (the control held over it, compensation and
 * inertia feed-forward included), F_comp (the friction compensation in it), and the trace's arrays. Returns TF_OK; TF_ERR_BAD_ARGUMENT, before
 * writing anything, for a NULL or non-finite argument (mass, dt > 0, substeps >= 1, n x substeps <=
 * TF_LOOP_MAX_SUBSTEPS, gains, a reference or series sample, dob_tau >= 0, T_amb, an estimator
 * without est_friction), an unknown compensation, an observer on a model without a bristle state,
 * or a plant or compensation model refused at one of its given (temperature, load) pairs; or, once running,
 * TF_ERR_NONFINITE if the loop goes unstable, or the estimator's status if it refuses a step or the
 * compensation is refused at the estimated temperature (outputs written up to that period). When it
 * stops short, *err (may be NULL) says which part refused (where: "loop", "reference", "pid",
 * "plant", "compensation", "estimator"), why (what: the argument or parameter) and the period
 * (index; -1: before the first). */
tf_status tf_loop_run(tf_loop *loop, long n, const double *x_ref, const double *v_ref, double *x, double *u,
                      double *F_comp, tf_error *err);

#ifdef __cplusplus
}
#endif
#endif
