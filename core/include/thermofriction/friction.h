/* Friction models (docs/models.md#friction-models). A model maps relative velocity v, internal
 * state z and parameters p (already evaluated at the current temperature) to the force F that
 * resists sliding and to dz/dt. In steady sliding F has the sign of v. */
#ifndef THERMOFRICTION_FRICTION_H
#define THERMOFRICTION_FRICTION_H

#include "domains.h"

#include <math.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The friction parameters, one line each: X(symbol, name in model files, unit, meaning). Every
 * model reads the ones it needs from one array indexed by TF_P_<symbol>, so that a temperature law
 * or a sensitivity can address any parameter by index. This list is the one source of the
 * parameters: the enum below, the Python binding's parameter names and units, and so the package's
 * model files, laws and identification all come from it. */
#define TF_PARAMETERS(X)                                                                                \
    X(SIGMA0, "sigma0", "N/m", "bristle stiffness")                                                     \
    X(SIGMA1, "sigma1", "N s/m", "bristle damping")                                                     \
    X(SIGMA2, "sigma2", "N s/m", "viscous friction")                                                    \
    X(FC, "fc", "N", "Coulomb level")                                                                   \
    X(FS, "fs", "N", "static (stiction) level; fs = fc turns the Stribeck effect off")                  \
    X(VS, "vs", "m/s", "Stribeck velocity")                                                             \
    X(DELTA, "delta", "-", "Stribeck exponent")                                                         \
    X(VD, "vd", "m/s", "sigma1 velocity scale; 0: none, sigma1 constant")                                  \
    X(VSMOOTH, "v_smooth", "m/s", "velocity band of smoothed signs")                                    \
    X(ZBA, "z_ba", "m", "elasto-plastic break-away deflection")                                         \
    X(C, "C", "N/s", "GMS: rate at which a slipping element's force approaches its capacity")             \
    X(FC_NEG, "fc_neg", "N", "Coulomb level for negative sliding; NaN or 0: fc")                            \
    X(FS_NEG, "fs_neg", "N", "static level for negative sliding; NaN or 0: fs")      \
    X(VS_NEG, "vs_neg", "m/s", "Stribeck velocity for negative sliding; NaN or 0: vs")                      \
    X(SIGMA2_NEG, "sigma2_neg", "N s/m", "viscous friction for negative sliding; NaN or 0: sigma2")         \
    X(RIPPLE_PERIOD, "ripple_period", "m", "period P of the position ripple; <= 0: no ripple")         \
    X(RIPPLE_COS1, "ripple_cos1", "N", "ripple amplitude of cos(2 pi x / P)")                          \
    X(RIPPLE_SIN1, "ripple_sin1", "N", "ripple amplitude of sin(2 pi x / P)")                          \
    X(RIPPLE_COS2, "ripple_cos2", "N", "ripple amplitude of cos(4 pi x / P)")                          \
    X(RIPPLE_SIN2, "ripple_sin2", "N", "ripple amplitude of sin(4 pi x / P)")                          \
    X(RIPPLE_COS3, "ripple_cos3", "N", "ripple amplitude of cos(6 pi x / P)")                          \
    X(RIPPLE_SIN3, "ripple_sin3", "N", "ripple amplitude of sin(6 pi x / P)")

#define TF_PARAMETER_ENUM_(symbol, name, unit, meaning) TF_P_##symbol,
typedef enum { TF_PARAMETERS(TF_PARAMETER_ENUM_) TF_NPARAM } tf_param;
#undef TF_PARAMETER_ENUM_

/* The friction models' ids (TF_FRICTION_<symbol>, from 0 in the order of domains.h's TF_FRICTION_MODELS). */
#define TF_FRICTION_ENUM_(symbol, name, states, equations) TF_FRICTION_##symbol,
typedef enum { TF_FRICTION_MODELS(TF_FRICTION_ENUM_) TF_NFRICTION } tf_friction_kind;
#undef TF_FRICTION_ENUM_

/* A model's states (TF_FRICTION_MODELS' states column; TF_STATES_PER_ELEMENT: one per GMS element), kind valid. */
static inline int tf_friction_states(int kind)
{
#define TF_FRICTION_STATES_(symbol, name, states, equations) states,
    static const int states[] = {TF_FRICTION_MODELS(TF_FRICTION_STATES_)};
#undef TF_FRICTION_STATES_
    return states[kind];
}

#define TF_MAX_FRICTION_STATES 64
/* Harmonics of the position ripple (TF_P_RIPPLE_COS1 ... TF_P_RIPPLE_SIN3, interleaved cos, sin). */
#define TF_RIPPLE_ORDER 3

/* Direction-dependent friction: the parameters that take their own value for negative sliding
 * (v < 0), each paired with its positive-side parameter. A negative value not given (NaN or 0,
 * tf_side_given) means "the positive value" (fs_neg: fc_neg where fs = fc, i.e. no Stribeck effect
 * on either side). */
/* Whether a negative-side value is given: NaN and 0 mean "the positive value" (so that a
 * zero-initialised parameter array stays symmetric; a negative side without any viscous term is
 * sigma2_neg = the smallest positive double, which the Python package writes for sigma2_neg = 0). */
static inline int tf_side_given(double x) { return x != 0.0 && x == x; }
/* Whether any negative-side value is given (the symmetric case: four tests). */
static inline int tf_friction_asymmetric(const double *p)
{
    return tf_side_given(p[TF_P_FC_NEG]) || tf_side_given(p[TF_P_FS_NEG]) || tf_side_given(p[TF_P_VS_NEG]) ||
           tf_side_given(p[TF_P_SIGMA2_NEG]);
}
/* The parameters acting at sliding velocity v: p itself where v >= 0 or nothing is direction-
 * dependent, else q filled with the negative side's values in the positive slots (so that every
 * model's equations serve both sides). */
const double *tf_friction_side(const double *p, double v, double *q);
/* Partials d[TF_NPARAM] computed with tf_friction_side's values moved, in place, to the negative-side
 * parameters they came from (nothing where v >= 0 or the model is symmetric). tf_friction_eval does
 * this for its own partials; callers that differentiate g(v) themselves use it. */
void tf_friction_side_partials(const double *p, double v, double *d);
/* The position ripple R(x) = sum_k a_k cos(2 pi k x / P) + b_k sin(2 pi k x / P) (zero when
 * P <= 0), added to the friction force of any model by the plant (which knows the position x).
 * dR/dx into *dR_dx when not NULL; dR/d(amplitude) added into dR_dp[TF_NPARAM] when not NULL
 * (the period is given, not fitted: its partial is left out). */
double tf_friction_ripple(const double *p, double x, double *dR_dx, double *dR_dp);

/* The elements of a Generalized Maxwell-slip model: stiffness k_i [N/m], capacity fraction w_i
 * (sum 1) and mode: 0 stuck (F_i' = k_i v), +1 or -1 slipping that way
 * (F_i' = C (mode w_i - F_i / g(v))). The mode is a discrete state: the integrator changes it
 * only at located events (tf_friction_events) and restarts, so no step straddles a switch. */
typedef struct {
    int n;
    double k[TF_MAX_FRICTION_STATES];
    double w[TF_MAX_FRICTION_STATES];
    int mode[TF_MAX_FRICTION_STATES];
} tf_gms_elements;

/* Partial derivatives of one evaluation. State coupling is diagonal for every model
 * (each state's rate depends on v and on that state only), so dzdot/dz is a vector. */
typedef struct {
    double dF_dv;
    double dF_dz[TF_MAX_FRICTION_STATES];
    double ddz_dv[TF_MAX_FRICTION_STATES];
    double ddz_dz[TF_MAX_FRICTION_STATES];
    double dF_dx; /* the position ripple's dR/dx: 0 from tf_friction_eval, set by the plant */
} tf_friction_partials;

/* Partial derivatives with respect to the parameters, for forward sensitivities. */
typedef struct {
    double dF_dp[TF_NPARAM];
    double ddz_dp[TF_MAX_FRICTION_STATES][TF_NPARAM];
} tf_friction_param_partials;

/* Number of internal states (n_elements is read for GMS only); -1 for an unknown kind. */
int tf_friction_nstate(int kind, int n_elements);
/* Steady sliding friction level used by Model II's scale form: fc for every model (GMS: the
 * element capacities w_i g(v) sum to g(v) -> fc). */
double tf_friction_reference_force(int kind, const double *p);
/* Stribeck curve g(v) = fc + (fs - fc) exp(-|v/vs|^delta), and dg/dv in *dg when not NULL. */
double tf_stribeck(const double *p, double v, double *dg);
/* Partial derivatives of g(v) with respect to the parameters (fc, fs, vs, delta; zeros elsewhere). */
void tf_stribeck_param_partials(const double *p, double v, double *dg);
/* LuGre's velocity-dependent damping (the bristle models: LuGre, elasto-plastic, the observer):
 * sigma1(v) = sigma1 exp(-(v/vd)^2) when vd > 0, else sigma1. Its derivatives with respect to v, to
 * the parameter sigma1 and to vd go where the pointers are not NULL. Inline: it is on every step. */
static inline double tf_sigma1(const double *p, double v, double *d_dv, double *d_dsigma1, double *d_dvd)
{
    double vd = p[TF_P_VD], s1 = p[TF_P_SIGMA1];
    if (!(vd > 0.0)) {
        if (d_dv) *d_dv = 0.0;
        if (d_dsigma1) *d_dsigma1 = 1.0;
        if (d_dvd) *d_dvd = 0.0;
        return s1;
    }
    double q = v / vd, e = exp(-q * q);
    s1 *= e;
    if (d_dv) *d_dv = -2.0 * q / vd * s1;
    if (d_dsigma1) *d_dsigma1 = e;
    if (d_dvd) *d_dvd = s1 * 2.0 * v * v / (vd * vd * vd);
    return s1;
}
/* LuGre's bristle rate and force at one sliding velocity, given g(v) and sigma1(v):
 * z' = v - sigma0 |v| z / g, F = sigma0 z + sigma1 z' + sigma2 v. The one statement of these
 * equations: the friction library (with its partials) and the plant's fast path both use it. */
static inline double tf_lugre_value(const double *p, double v, double z, double g, double s1, double *zd)
{
    double s0 = p[TF_P_SIGMA0];
    *zd = v - s0 * fabs(v) / g * z; /* (relaxation rate s0 |v| / g) times z */
    return s0 * z + s1 * *zd + p[TF_P_SIGMA2] * v;
}

/* Force and state rates; state partials when jac is not NULL, parameter partials when dp
 * is not NULL (every model, every parameter of the list it reads; dp->ddz_dp is written for
 * the model's states only). gms is read for TF_FRICTION_GMS only. GMS: the partials hold within
 * the current modes; where a mode switches, the sensitivities jump (tf_model_sensitivity_jump). */
double tf_friction_eval(int kind, const double *p, const tf_gms_elements *gms, double v, const double *z,
                        double *dz, tf_friction_partials *jac, tf_friction_param_partials *dp);

/* tf_friction_eval with p's values on both sides (no direction-dependent substitution): for callers
 * that know their parameters are symmetric (the plant caches that per temperature) or that have
 * already taken tf_friction_side's values. */
double tf_friction_eval_side(int kind, const double *p, const tf_gms_elements *gms, double v, const double *z,
                             double *dz, tf_friction_partials *jac, tf_friction_param_partials *dp);

/* Discrete modes (GMS). Event functions (two per element) cross zero upwards where a mode must
 * change: a stuck element when F_i reaches +w_i g(v) or -w_i g(v), a slipping one when v
 * reverses. tf_friction_update_modes
 * sets every mode consistent with (v, z): called at every restart of the integration. */
int tf_friction_nevent(int kind, const tf_gms_elements *gms);
void tf_friction_events(int kind, const double *p, const tf_gms_elements *gms, double v, const double *z,
                        double *g);
void tf_friction_update_modes(int kind, const double *p, tf_gms_elements *gms, double v, const double *z);

#ifdef __cplusplus
}
#endif
#endif
