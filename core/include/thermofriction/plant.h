/* Plants (docs/models.md#plants) assembled with a friction model, its thermal extension, an input
 * waveform, a temperature signal and a load signal into one ODE system: right-hand side, analytic Jacobian,
 * outputs. */
#ifndef THERMOFRICTION_PLANT_H
#define THERMOFRICTION_PLANT_H

#include "friction.h"
#include "integrator.h"
#include "thermal.h"
#include "waveform.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    /* docs/models.md#stick-slip-actuator: states x_p, v_p, x_e, v_e, then friction states */
    TF_PLANT_STICK_SLIP = 0,
    /* docs/models.md#mass-plant: m x'' = u(t) + k_s (v_0 t - x) - F, v_r = x'; states x, v, then friction */
    TF_PLANT_MASS = 1,
    /* docs/models.md#prescribed-motion: x_r = u(t) [m] given, v_r = u'(t); friction states only */
    TF_PLANT_PRESCRIBED = 2
} tf_plant_kind;

/* Output channels, in this order, then the friction states, then the frictional work (where
 * the model has that state). */
typedef enum {
    TF_OUT_TIME = 0,
    TF_OUT_INPUT,
    TF_OUT_STAGE_DISPLACEMENT,    /* the driving surface (0 for the mass and prescribed plants) */
    TF_OUT_STAGE_VELOCITY,
    TF_OUT_DISPLACEMENT,          /* driven body: end effector, mass, or the prescribed motion */
    TF_OUT_VELOCITY,
    TF_OUT_RELATIVE_DISPLACEMENT, /* x_e - x_p */
    TF_OUT_RELATIVE_VELOCITY,     /* v_r = v_e - v_p */
    TF_OUT_FRICTION_FORCE,        /* F', the force resisting sliding (after the thermal model) */
    TF_OUT_TEMPERATURE,
    TF_OUT_NFIXED
} tf_output_channel;

/* The most states a model has: 4 mechanical, the friction states, temperature, frictional work. */
#define TF_MAX_STATES (TF_MAX_FRICTION_STATES + 6)

typedef struct {
    int plant;
    /* stick-slip, physical form: m x_p'' + c x_p' + k x_p = T_em u + F ; m_e x_e'' = -F
       mass: m x'' = u + k_s (v_0 t - x) - F (k_s = 0: force-driven only) */
    double m, c, k, T_em, m_e;
    double k_s, v_0;

    int friction;               /* tf_friction_kind */
    double p[TF_NPARAM];        /* parameters (temperature-independent values) */
    tf_gms_elements gms;        /* GMS elements; their modes here are a run's first (tf_model_data holds the run's) */
    int fs_follows_fc;          /* fs = fc at every temperature: no Stribeck effect */

    int thermal;                /* tf_thermal_kind */
    tf_law law[TF_NPARAM];      /* Model I: TF_LAW_NONE keeps p[i] */
    tf_law dF;                  /* Model II thermal-induced friction [N] */
    int dF_form;                /* tf_df_form */

    tf_waveform input;          /* voltage u(t) [V] */

    /* Temperature [degC]: constant T_const, or sampled (T_n > 1) with linear interpolation;
       or, with heat.on, a state of the lumped thermal model. */
    double T_const;
    int T_n;
    const double *T_t, *T_v;
    tf_heat heat;               /* the lumped heat balance (thermal.h) */

    /* States after the friction states: the temperature (heat.on), then the frictional work
       W = integral of |F' v_r| dt [J] (heat.on or work set): per-cycle dissipation to solver
       tolerance, for energy balances and the two-time-scale method. */
    int work;

    /* The load L [N or N m] the laws with a load term read (law.h: a preloaded stage's normal force, the
       stick-slip actuator's preload): the waveform `load` (periodic or sampled), or, where its kind is
       TF_WAVE_ZERO, the constant load_const. A model without such a law does not read either. */
    tf_waveform load;
    double load_const;
} tf_model;

/* The parameters at the last temperature and load a run evaluated them at, so that a constant temperature
 * and load cost no law evaluations per step. */
typedef struct {
    int valid;                  /* 0: filled at the next use */
    double T, p[TF_NPARAM], lambda, dF;
    double L;                   /* the load they were evaluated at (NaN for a model that reads none) */
    unsigned long loads;        /* tf_thermal_load_mask of the model's laws, taken when the cache is filled */
    int plain;                  /* p symmetric and without a position ripple: the plant's plain evaluation */
    unsigned long laws;         /* tf_thermal_law_mask of the model's laws, taken when the cache is filled */
} tf_params_cache;

/* What changes while a model runs (MuJoCo's mjData beside tf_model's mjModel): the model, which a run only
 * reads, and its mutable part -- the parameter cache and the GMS elements' modes (the integrator's events
 * switch them). Caller-owned (a plain struct, no allocation); one per run, or per thread: runs of one model
 * on several threads each take their own. The evaluation functions below take it (the ODE's ctx is one). */
typedef struct {
    const tf_model *model;
    tf_params_cache cache;
    tf_gms_elements gms;        /* the model's GMS elements with the run's modes */
} tf_model_data;

/* A run's data for model: the cache empty, the GMS modes the model's (its gms.mode). */
void tf_model_data_init(tf_model_data *data, const tf_model *model);
/* After the model's fields changed between two uses of data (the real-time API's setters): the cache is
 * refilled at its next use; the modes are kept. */
void tf_model_data_changed(tf_model_data *data);

/* Checks a model before it is simulated: every number the plant, friction model, thermal
 * extension, input and temperature use is finite and in its domain (docs/models.md#plants,
 * #friction-models, #thermal-extensions: masses, stiffnesses, sigma0, fc, C, v_smooth > 0;
 * damping, sigma1, sigma2, z_ba >= 0; fs >= fc; vs > 0 where fs != fc; elasto-plastic z_ba <
 * fc/sigma0; 1..64 GMS elements with k_i, w_i > 0 summing to one; Model I parameters and Model
 * II's lambda checked at the constant temperature or over the sampled one, and, for a model that reads
 * the load, at the smallest and largest load magnitude it reaches (the load finite: "load"); periodic
 * inputs with a positive frequency; for prescribed motion a continuous input). Returns TF_OK, or
 * TF_ERR_BAD_ARGUMENT with the offending field's name in err->what (where "model"; err may be
 * NULL). tf_solve does not call it: callers that build models from user data must (the Python
 * package checks the same rules, with messages). */
tf_status tf_model_check(const tf_model *model, tf_error *err);
/* The same rules for the friction model and its thermal extension alone (the plant, input and
 * temperature and load signals are not looked at: the real-time API, realtime.h, holds no more): the
 * kind, GMS elements, the laws' structure (load terms included), and the parameters -- always for a
 * model without a thermal extension, at temperature T (and load L, for a model with a law of the load)
 * for one with it (not at all when T, or L for a model that reads it, is not finite). */
tf_status tf_model_check_friction(const tf_model *model, double T, double L, tf_error *err);
/* The same rules for parameters already evaluated at one temperature: p (TF_NPARAM values), Model
 * II's lambda and offset there (as tf_model_params_cached gives them). */
tf_status tf_model_check_params(const tf_model *model, const double *p, double lambda, double dF_offset,
                                tf_error *err);

int tf_model_nstate(const tf_model *model);
int tf_model_noutput(const tf_model *model);
/* Temperature at (t, y): the state with a heat model (y must then be given), else the
 * constant or sampled signal (y may be NULL). */
double tf_model_temperature(const tf_model *model, double t, const double *y);
/* Index of the temperature state and of the frictional-work state; -1 where there is none. */
int tf_model_temperature_index(const tf_model *model);
int tf_model_work_index(const tf_model *model);
/* The load at time t: the waveform, or the constant (see tf_model.load). */
double tf_model_load(const tf_model *model, double t);
/* Whether the model reads the load: a Model I law with a load term. */
int tf_model_reads_load(const tf_model *model);
/* Parameters at temperature T and load L (Model I laws applied). */
void tf_model_params_at(const tf_model *model, double T, double L, double *p);
/* The thermal factor lambda(T) of Model II's scale form (1 otherwise). */
double tf_model_lambda(const tf_model *model, double T);
/* Parameters at (T, L) (as tf_model_params_at), Model II's *lambda and offset force *dF_offset, cached
 * in the run's data for the last (T, L): a constant temperature and load cost no law evaluation (L is no
 * key for a model that does not read it). The pointer is into the data's cache, valid until the next call
 * with another T or L. */
const double *tf_model_params_cached(tf_model_data *data, double T, double L, double *lambda, double *dF_offset);
/* Friction force F' at (t, state). */
double tf_model_friction(tf_model_data *data, double t, const double *y);
void tf_model_initial_state(const tf_model *model, double *y);
/* The default absolute tolerances: rtol times each state's characteristic magnitude (tf_model_state_scale). */
void tf_model_default_atol(const tf_model *model, double rtol, double *atol);
/* The weights of the relative tolerance per state for tf_solver_options.rtol_weight: 0 for positions. */
void tf_model_rtol_weights(const tf_model *model, double *w);
/* What a sensitivity is taken with respect to. */
typedef enum {
    TF_TARGET_PARAM = 0, /* friction parameter `param` given as a number */
    TF_TARGET_LAW = 1,   /* coefficient `coef` of the Model I law of parameter `param` */
    TF_TARGET_DF = 2,    /* coefficient `coef` of Model II's dF law */
    TF_TARGET_HEAT = 3,  /* heat model parameter `param`: one of tf_heat_param (thermal.h) */
    TF_TARGET_PLANT = 4  /* plant parameter `param`: one of tf_plant_param */
} tf_target_kind;

/* Plant parameters a sensitivity can be taken with respect to. The stick-slip plant stores its physical
 * form (m, c, k, T_em); its modal parameters xi, wn, K (k = m wn^2, c = 2 xi wn m, T_em = K k) move c, k
 * and T_em together, and TF_PLANT_P_M_MODAL is the stage mass with xi, wn and K held. */
typedef enum {
    TF_PLANT_P_M = 0,       /* stage (or body) mass, c, k, T_em held */
    TF_PLANT_P_M_E,         /* end-effector mass */
    TF_PLANT_P_C,           /* stage damping */
    TF_PLANT_P_K,           /* stage stiffness */
    TF_PLANT_P_T_EM,        /* transducer ratio */
    TF_PLANT_P_XI,          /* damping ratio */
    TF_PLANT_P_WN,          /* natural frequency */
    TF_PLANT_P_GAIN,        /* static gain K */
    TF_PLANT_P_M_MODAL,     /* stage mass, xi, wn, K held */
    TF_PLANT_P_K_S,         /* mass plant: pulling spring stiffness */
    TF_PLANT_NPARAM
} tf_plant_param;

typedef struct {
    int kind, param, coef;
} tf_target;

/* Right-hand side, and, where the pointers are not NULL, its Jacobian (n x n, row-major) and
 * its derivatives with respect to the np targets (n x np, row-major). */
tf_status tf_model_derivatives(tf_model_data *data, double t, const double *y, double *dy, double *J,
                               const tf_target *targets, int np, double *fp);

/* Characteristic magnitude of each state, for default absolute tolerances. */
void tf_model_state_scale(const tf_model *model, double *scale);

/* The ODE's functions: data is a tf_model_data (tf_model_ode). */
tf_status tf_model_rhs(double t, const double *y, double *dy, void *data);
/* Jacobian d(rhs)/dy, row-major n x n. */
tf_status tf_model_jac(double t, const double *y, double *J, void *data);
/* Earliest time after t where the input, the temperature signal or the load (where read) has a corner. */
double tf_model_next_corner(double t, void *data);
/* The longest step from (t, y) (tf_ode.max_step): under a prescribed motion with a Stribeck effect, the time
 * in which the input's velocity changes by half of the larger of |v| and the Stribeck velocity; else
 * INFINITY. */
double tf_model_max_step(double t, const double *y, void *data);
/* Discrete modes of the friction model (GMS): event functions and the update at restarts (the data's modes). */
int tf_model_nevent(const tf_model *model);
void tf_model_events(double t, const double *y, double *g, void *data);
void tf_model_on_restart(double t, const double *y, void *data);
/* The same for a sensitivity run, Y = [y, S (n x np, row-major)]: sets the modes and, for each
 * GMS element whose mode changed at an event of the state, applies the sensitivities' jump
 * S+ = S- + (f- - f+) dtau/dtheta, dtau/dtheta = -(dg/dy S + dg/dtheta) / (dg/dt), g the
 * element's event function (docs/identification.md#friction-models). */
void tf_model_sensitivity_restart(tf_model_data *data, double t, double *Y, const tf_target *targets, int np);
/* The model of data as an ODE system for tf_solve (right-hand side, Jacobian, corners, events), ctx the data. */
tf_ode tf_model_ode(tf_model_data *data);
/* Writes the output channels at (t, y). */
void tf_model_outputs(tf_model_data *data, double t, const double *y, double *out);
/* The same, channel j written to out[j * stride] (a column-major block with stride samples per column). */
void tf_model_outputs_strided(tf_model_data *data, double t, const double *y, double *out, long stride);

#ifdef __cplusplus
}
#endif
#endif
