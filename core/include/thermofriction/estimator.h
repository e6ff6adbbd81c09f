/* Online contact-temperature estimator (docs/control.md#temperature-estimator): an extended Kalman
 * filter on the lumped heat path of a contact, driven by the friction model's own power and corrected
 * by a measured friction force (or torque) and, optionally, a lagging proxy temperature (a motor
 * winding or housing sensor). Allocation-free, O(1) per step, plain C99 + libm.
 *
 *     tf_temperature_config c = {.C_th = 40, .R_th = 1.5, .eta = 1, .C_2 = 400, .R_2 = 0.5,
 *                                .proxy = TF_PROXY_HOUSING, .tau_p = 30, .q = {1e-3, 1e-4, 0},
 *                                .r_F = 0.01, .r_p = 0.01, .v_min = 1e-4};
 *     tf_temperature_estimator e;
 *     tf_temperature_init(&e, &c, 25.0, 25.0, &err);          // T0 [degC], its variance [K^2]
 *     double F_hat;                                          // every control period:
 *     tf_temperature_step(&e, &f, v, load, F_meas, T_proxy, T_amb, dt, &F_hat, &err);   // NaN: not measured
 *     tf_temperature_estimate(&e), tf_temperature_variance(&e)
 *
 * The heat path (C_2 = 0: one node, R_th straight to ambient; proxy optional):
 *     C_th Tc' = eta P - (Tc - Tn) / R_th,    Tn = Th with a housing node, else T_amb
 *     C_2  Th' = (Tc - Th) / R_th - (Th - T_amb) / R_2
 *     tau_p Tp' = Ts - Tp,                    Ts = Tc or Th (the node the proxy lags)
 * with P = |F^ v|, F^ the friction model's force stepped at the estimate (tf_rt_step on the caller's
 * tf_rt_friction). The state x = [Tc, (Th), (Tp)] (the present nodes in this order), its covariance
 * P (n x n, n <= 3), white process noise of intensity q[i] [K^2/s] on each.
 *
 * One step (dt [s] > 0):
 *   1. the friction: f advances over dt at v, Tc^ and the load (tf_rt_step), F^ its force; the sensitivity
 *      s = dz/dTc of its internal states is carried along (the forward difference of the step over
 *      Tc^ + d with z + d s, d = 1e-4 K), and h = dF^/dTc, so that a bristle model's force, which
 *      carries the temperature in its state, is not taken as independent of it;
 *   2. predict: each node's exponential-Euler step (its own decay exact, its neighbours held: stable
 *      for any dt), P <- A P A' + diag(q) dt with A the step's Jacobian (the power's dP/dTc in it);
 *   3. update with F_measured (NaN: none): scalar Kalman update, H = [h, 0, 0], noise r_F [N^2],
 *      Joseph form; skipped (gated) where |v| < v_min or h^2 P_cc < 1e-9 r_F (the friction does not
 *      depend on the temperature there). With T_proxy (NaN: none) a second update, H = e_p, noise r_p
 *      [K^2]. The states of f follow the contact's correction (z += s dTc), and F^ too (F^ += h dTc):
 *      *F_hat is the friction at the corrected estimate, what a compensation uses.
 *
 * Checks, as in realtime.h: every function returns a tf_status and fills *err (may be NULL; where
 * "estimator" for its own arguments, "realtime" or "model" for the friction's); a refused call changes
 * nothing (the estimator, and f's states and position). */
#ifndef THERMOFRICTION_ESTIMATOR_H
#define THERMOFRICTION_ESTIMATOR_H

#include "realtime.h"
#include "status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which node the proxy temperature lags. */
typedef enum {
    TF_PROXY_NONE = 0,    /* no proxy sensor */
    TF_PROXY_CONTACT = 1, /* a first-order lag of the contact (e.g. a sensor near the contact) */
    TF_PROXY_HOUSING = 2  /* a first-order lag of the housing node (needs C_2 > 0) */
} tf_proxy_kind;

#define TF_ESTIMATOR_MAX_STATES 3

typedef struct {
    double C_th;   /* contact node's heat capacity [J/K], > 0 */
    double R_th;   /* contact to the next node (housing, or ambient) [K/W], > 0 */
    double eta;    /* fraction of the friction power that heats the contact, 0..1 */
    double C_2;    /* housing node's heat capacity [J/K]; 0: no housing node */
    double R_2;    /* housing to ambient [K/W], > 0 with a housing node (else unused) */
    int proxy;     /* a tf_proxy_kind */
    double tau_p;  /* the proxy's lag [s], > 0 with a proxy (else unused) */
    double q[TF_ESTIMATOR_MAX_STATES]; /* process noise per state [K^2/s], >= 0: contact, housing, proxy
                                          (the absent states' unused) */
    double r_F;    /* friction measurement noise variance [N^2], > 0 */
    double r_p;    /* proxy measurement noise variance [K^2], > 0 with a proxy (else unused) */
    double v_min;  /* [m/s] >= 0: no friction update where |v| < v_min (sticking: the measured force
                      is not the friction's temperature-dependent sliding force) */
} tf_temperature_config;

/* Readable fields: n, x, P, s, h, gated. Written by the functions below only. */
typedef struct {
    tf_temperature_config c;
    int n;                  /* states: 1 + (housing) + (proxy) */
    int i_housing, i_proxy; /* their indices in x, or -1 */
    double x[TF_ESTIMATOR_MAX_STATES];                          /* [degC] */
    double P[TF_ESTIMATOR_MAX_STATES][TF_ESTIMATOR_MAX_STATES]; /* [K^2] */
    double s[TF_MAX_FRICTION_STATES]; /* dz/dTc of the friction's internal states */
    double h;     /* dF^/dTc at the last step [N/K] */
    int gated;    /* 1 if the last step's friction measurement was given but not used (gated) */
    double g[TF_ESTIMATOR_MAX_STATES], g_dt; /* the nodes' decay factors 1 - exp(-dt / tau) at dt = g_dt */
} tf_temperature_estimator;

/* Checks the configuration (TF_ERR_BAD_ARGUMENT naming the field, e.g. "config.R_2 (> 0 with a housing
 * node)") and sets every node to T0 [degC] (finite), the covariance to var0 I [K^2] (finite, > 0), s
 * to 0 (the friction's states independent of the temperature: start f at rest or soaked). */
tf_status tf_temperature_init(tf_temperature_estimator *e, const tf_temperature_config *c, double T0, double var0,
                              tf_error *err);
/* Replaces the configuration at run time, keeping the state (the same nodes: C_2 > 0 and the proxy kind
 * as at init, else TF_ERR_BAD_ARGUMENT); checked as at init. */
tf_status tf_temperature_configure(tf_temperature_estimator *e, const tf_temperature_config *c, tf_error *err);
/* One step (see above): v [m/s], load [N or N m] (read by f's laws of the load, as tf_rt_step: a model
 * without one ignores it, NaN included), F_measured [N] (NaN: none), T_proxy [degC] (NaN: none; refused if
 * the configuration has no proxy), T_amb [degC], dt [s] > 0. Writes F^ [N] to *F_hat (NaN on a
 * refusal). TF_ERR_BAD_ARGUMENT: NULL e, f or F_hat, a non-finite v, T_amb or dt, dt <= 0, an
 * infinite F_measured or T_proxy, or f's model refused at the estimate and the load (where "realtime"/"model": a
 * non-finite load for a model with a law of the load, "load (not finite: ...)");
 * TF_ERR_NONFINITE: a force, state or covariance that would not be finite. */
tf_status tf_temperature_step(tf_temperature_estimator *e, tf_rt_friction *f, double v, double load,
                              double F_measured, double T_proxy, double T_amb, double dt, double *F_hat, tf_error *err);
/* The contact temperature estimate [degC] and its variance [K^2] (NaN for a NULL e). */
double tf_temperature_estimate(const tf_temperature_estimator *e);
double tf_temperature_variance(const tf_temperature_estimator *e);

#ifdef __cplusplus
}
#endif
#endif
