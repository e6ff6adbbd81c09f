/* Friction models (SPEC 4). A model maps relative velocity v, internal state z and parameters
 * p (already evaluated at the current temperature) to the force F that resists sliding and to
 * dz/dt. In steady sliding F has the sign of v. */
#ifndef THERMOFRICTION_FRICTION_H
#define THERMOFRICTION_FRICTION_H

#ifdef __cplusplus
extern "C" {
#endif

/* Parameter indices: every model reads the ones it needs from one array, so that a
 * temperature law or a sensitivity can address any parameter by index. */
typedef enum {
    TF_P_SIGMA0 = 0, /* bristle stiffness [N/m] */
    TF_P_SIGMA1,     /* bristle damping [N s/m] */
    TF_P_SIGMA2,     /* viscous friction [N s/m] */
    TF_P_FC,         /* Coulomb level [N] */
    TF_P_FS,         /* static (stiction) level [N]; fs = fc turns the Stribeck effect off */
    TF_P_VS,         /* Stribeck velocity [m/s] */
    TF_P_DELTA,      /* Stribeck exponent [-] */
    TF_P_VD,         /* sigma1 velocity scale [m/s]; <= 0: sigma1 constant */
    TF_P_VSMOOTH,    /* velocity band of smoothed signs [m/s] */
    TF_P_ZBA,        /* elasto-plastic break-away deflection [m] */
    TF_NPARAM
} tf_param;

typedef enum {
    TF_FRICTION_LUGRE = 0
} tf_friction_kind;

#define TF_MAX_FRICTION_STATES 64

/* Partial derivatives of one evaluation. State coupling is diagonal for every model
 * (each state's rate depends on v and on that state only), so dzdot/dz is a vector. */
typedef struct {
    double dF_dv;
    double dF_dz[TF_MAX_FRICTION_STATES];
    double ddz_dv[TF_MAX_FRICTION_STATES];
    double ddz_dz[TF_MAX_FRICTION_STATES];
} tf_friction_partials;

/* Partial derivatives with respect to the parameters, for forward sensitivities. */
typedef struct {
    double dF_dp[TF_NPARAM];
    double ddz_dp[TF_MAX_FRICTION_STATES][TF_NPARAM];
} tf_friction_param_partials;

int tf_friction_nstate(int kind);
/* Steady sliding friction level used by Model II's scale form (fc for LuGre). */
double tf_friction_reference_force(int kind, const double *p);
/* Stribeck curve g(v) = fc + (fs - fc) exp(-|v/vs|^delta), and dg/dv in *dg when not NULL. */
double tf_stribeck(const double *p, double v, double *dg);
/* Force and state rates; state partials when jac is not NULL, parameter partials when dp
 * is not NULL. */
double tf_friction_eval(int kind, const double *p, double v, const double *z, double *dz,
                        tf_friction_partials *jac, tf_friction_param_partials *dp);

#ifdef __cplusplus
}
#endif
#endif
