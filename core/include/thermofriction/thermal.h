/* Thermal extensions of a friction model (docs/models.md#thermal-extensions), in one place for the
 * simulator (plant.c) and the real-time model (realtime.c):
 *   Model I   parameters that follow temperature laws (law.h)            docs/models.md#model-i
 *   Model II  the thermal-induced friction dF(T), scale or offset form   docs/models.md#model-ii
 *   heat      the lumped heat balance that makes T a state               docs/models.md#self-heating
 * The functions work on the fields a tf_model (plant.h) holds, so that this file depends on the
 * friction models and laws only. */
#ifndef THERMOFRICTION_THERMAL_H
#define THERMOFRICTION_THERMAL_H

#include <math.h>

#include "friction.h"
#include "law.h"
#include "waveform.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How Model II applies its thermal-induced friction dF(T) (docs/models.md#model-ii). */
typedef enum {
    TF_THERMAL_NONE = 0,
    TF_THERMAL_MODEL_I = 1,  /* parameters follow laws of T */
    TF_THERMAL_MODEL_II = 2  /* base model plus dF(T) */
} tf_thermal_kind;

typedef enum {
    TF_DF_SCALE = 0,  /* F' = (1 + dF(T) / F_ref) F_base */
    TF_DF_OFFSET = 1  /* F' = F_base + dF(T) s(v) */
} tf_df_form;

/* ---- Model I ---- */

/* Parameters at temperature T and load L into p[TF_NPARAM]: p_base, with laws[i] evaluated at (T, L)
 * (tf_law_eval_load) wherever it is set (kind != TF_LAW_NONE) when thermal is TF_THERMAL_MODEL_I; fs = fc
 * when fs_follows_fc. L is read by the laws with a load term only. */
void tf_thermal_params(int thermal, const double *p_base, const tf_law *laws, int fs_follows_fc, double T,
                       double L, double *p);
/* The parameters that follow a law: bit i set where laws[i].kind != TF_LAW_NONE (TF_NPARAM <= 32). */
unsigned long tf_thermal_law_mask(const tf_law *laws);
/* The parameters whose law has a load term (Model I only; 0 otherwise): a model that reads the load. */
unsigned long tf_thermal_load_mask(int thermal, const tf_law *laws);
/* tf_thermal_params with the laws of `mask` only (tf_thermal_law_mask): the plant's per-temperature path,
 * which then visits only the parameters that have a law. */
void tf_thermal_params_masked(int thermal, const double *p_base, const tf_law *laws, unsigned long mask,
                              int fs_follows_fc, double T, double L, double *p);

/* ---- Model II: F' = lambda(T) F_base + dF_offset(T) s(v), s(v) = tanh(v / v_smooth) ---- */

/* lambda(T) = 1 + dF(T) / F_ref in the scale form, 1 otherwise (no Model II, or the offset form).
 * F_ref: tf_friction_reference_force of the base parameters (fc). Inline, as tf_thermal_offset:
 * both are on every cache miss of the parameters, i.e. every step at a changing temperature. */
static inline double tf_thermal_lambda(int thermal, int form, const tf_law *dF, double F_ref, double T)
{
    if (thermal != TF_THERMAL_MODEL_II || form != TF_DF_SCALE) return 1.0;
    return 1.0 + tf_law_eval(dF, T, 0) / F_ref;
}
/* dF(T) in the offset form, 0 otherwise. */
static inline double tf_thermal_offset(int thermal, int form, const tf_law *dF, double T)
{
    return thermal == TF_THERMAL_MODEL_II && form == TF_DF_OFFSET ? tf_law_eval(dF, T, 0) : 0.0;
}

/* F' from the base model's force F_base at sliding velocity v. With jac (the base model's partials
 * for nz states) not NULL, turns them into the partials of F' in place. Inline: it is on the
 * real-time step and on every right-hand side. */
static inline double tf_thermal_force(double F_base, double v, double v_smooth, double lambda, double dF_offset,
                                      int nz, tf_friction_partials *jac)
{
    double F = lambda * F_base;
    if (jac && lambda != 1.0) {
        jac->dF_dv *= lambda;
        jac->dF_dx *= lambda;
        for (int j = 0; j < nz; j++) jac->dF_dz[j] *= lambda;
    }
    if (dF_offset != 0.0) { /* offset form: dF along a smoothed sign of v */
        double s = tanh(v / v_smooth);
        F += dF_offset * s;
        if (jac) jac->dF_dv += dF_offset * (1.0 - s * s) / v_smooth;
    }
    return F;
}

/* dF'/dtheta for a base-model parameter `param` moved by theta, from the base force's dF_base/dtheta:
 * lambda times it in the scale form, less (lambda - 1) F_base / F_ref for fc (F_ref = fc, and dF(T)
 * = (lambda - 1) F_ref is held); itself otherwise. */
static inline double tf_thermal_param_partial(int thermal, int form, double lambda, double F_ref, int param,
                                              double dFbase_dtheta, double F_base)
{
    if (thermal != TF_THERMAL_MODEL_II || form != TF_DF_SCALE) return dFbase_dtheta;
    double d = dFbase_dtheta * lambda;
    if (param == TF_P_FC) d -= (lambda - 1.0) / F_ref * F_base;
    return d;
}

/* dF'/dc for coefficient `coef` of the dF law (Model II, no load term): F_base / F_ref dF_c in the scale
 * form, dF_c s(v) in the offset form (dF_c = tf_law_coef_derivative). */
double tf_thermal_df_coef_partial(int form, const tf_law *dF, int coef, double T, double F_base, double F_ref,
                                  double v, double v_smooth);

/* ---- Lumped heat balance ---- */

/* With `on` set the temperature is a state,
 *   C_th T' = eta P - (T - T_amb) / R_th + P_ext(t),   T(0) = T_0,   P = |F' v_r|,
 * and the model's T_const / T_n are not used. P counts all the friction force's power as heat,
 * including what a bristle model stores and returns elastically (docs/models.md#self-heating). */
typedef struct {
    int on;
    double C_th;       /* heat capacity [J/K] */
    double R_th;       /* thermal resistance to ambient [K/W] */
    double eta;        /* fraction of the frictional power that heats the interface, 0..1 */
    double T_amb;      /* ambient temperature [degC] */
    double T_0;        /* initial temperature [degC] */
    tf_waveform P_ext; /* external heat input [W]; TF_WAVE_ZERO: none */
} tf_heat;

/* TF_HEAT_T_0 enters through the initial state only (S_T(0) = 1): its right-hand-side partials are
 * zero, and whoever starts a sensitivity integration sets that column (the binding does). */
typedef enum { TF_HEAT_C_TH = 0, TF_HEAT_R_TH, TF_HEAT_ETA, TF_HEAT_T_AMB, TF_HEAT_T_0, TF_HEAT_NPARAM } tf_heat_param;

/* T' at time t, temperature T and friction power P [W]. */
double tf_heat_rate(const tf_heat *h, double t, double T, double P);
/* dT'/dP times dP (the heat balance is linear in P). */
static inline double tf_heat_rate_dP(const tf_heat *h, double dP) { return h->eta * dP / h->C_th; }
/* The Jacobian row of T' over n states, from dP/dy (dP_dy[iT] is dP/dT): row[k] = dT'/dy_k. */
void tf_heat_rate_jacobian(const tf_heat *h, int n, int iT, const double *dP_dy, double *row);
/* dT'/d(heat parameter `param`, a tf_heat_param) at temperature T, power P and rate T' = `rate`. */
double tf_heat_param_partial(const tf_heat *h, int param, double T, double P, double rate);

#ifdef __cplusplus
}
#endif
#endif
