/* Plants (SPEC 3.1) with friction and thermal extension, as one ODE system. */
#include "thermofriction/plant.h"

#include <math.h>
#include <string.h>

enum { XP = 0, VP, XE, VE, NMECH };

void tf_model_prepare(tf_model *model) { model->cache_valid = 0; }

int tf_model_nstate(const tf_model *model) { return NMECH + tf_friction_nstate(model->friction); }

int tf_model_noutput(const tf_model *model) { return TF_OUT_NFIXED + tf_friction_nstate(model->friction); }

double tf_model_temperature(const tf_model *model, double t)
{
    if (model->T_n > 0) return tf_pwl_value(model->T_n, model->T_t, model->T_v, t);
    return model->T_const;
}

void tf_model_params_at(const tf_model *model, double T, double *p)
{
    memcpy(p, model->p, sizeof(double) * TF_NPARAM);
    if (model->fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
    if (model->thermal != TF_THERMAL_MODEL_I) return;
    for (int i = 0; i < TF_NPARAM; i++)
        if (model->law[i].kind != TF_LAW_NONE) p[i] = tf_law_eval(&model->law[i], T, 0);
    if (model->fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
}

double tf_model_lambda(const tf_model *model, double T)
{
    if (model->thermal != TF_THERMAL_MODEL_II || model->dF_form != TF_DF_SCALE) return 1.0;
    double Fref = tf_friction_reference_force(model->friction, model->p);
    return 1.0 + tf_law_eval(&model->dF, T, 0) / Fref;
}

/* Parameters, scale factor and offset force at temperature T, cached per temperature. */
static const double *params(tf_model *m, double T, double *lambda, double *dF)
{
    /* (a model without a thermal part runs at T = NaN, which must hit the cache too) */
    if (!m->cache_valid || !(m->cache_T == T || (isnan(T) && isnan(m->cache_T)))) {
        tf_model_params_at(m, T, m->cache_p);
        m->cache_lambda = tf_model_lambda(m, T);
        m->cache_dF = (m->thermal == TF_THERMAL_MODEL_II && m->dF_form == TF_DF_OFFSET)
                          ? tf_law_eval(&m->dF, T, 0) : 0.0;
        m->cache_T = T;
        m->cache_valid = 1;
    }
    *lambda = m->cache_lambda;
    *dF = m->cache_dF;
    return m->cache_p;
}

/* F' and, when jac is given, its partials (overwriting the base model's partials). The base
 * model's parameter partials go to dp, untouched by the thermal factor (the caller applies it). */
static double friction_full(tf_model *m, double t, const double *y, double *dz, tf_friction_partials *jac,
                            tf_friction_param_partials *dp, double *F_base)
{
    double lambda, dF;
    const double *p = params(m, tf_model_temperature(m, t), &lambda, &dF);
    double v = y[VE] - y[VP];
    int nz = tf_friction_nstate(m->friction);
    double F = tf_friction_eval(m->friction, p, v, y + NMECH, dz, jac, dp);
    if (F_base) *F_base = F;
    if (lambda != 1.0) {
        F *= lambda;
        if (jac) {
            jac->dF_dv *= lambda;
            for (int j = 0; j < nz; j++) jac->dF_dz[j] *= lambda;
        }
    }
    if (dF != 0.0) { /* offset form: dF along a smoothed sign of v */
        double vs = p[TF_P_VSMOOTH];
        double s = tanh(v / vs);
        F += dF * s;
        if (jac) jac->dF_dv += dF * (1.0 - s * s) / vs;
    }
    return F;
}

static double friction(tf_model *m, double t, const double *y, double *dz, tf_friction_partials *jac)
{
    return friction_full(m, t, y, dz, jac, 0, 0);
}

double tf_model_friction(const tf_model *model, double t, const double *y)
{
    double dz[TF_MAX_FRICTION_STATES];
    return friction((tf_model *)model, t, y, dz, 0);
}

void tf_model_initial_state(const tf_model *model, double *y)
{
    memset(y, 0, sizeof(double) * tf_model_nstate(model));
}

static double input_peak(const tf_waveform *w)
{
    if (w->kind == TF_WAVE_SAMPLED) {
        double peak = 0.0;
        for (int i = 0; i < w->n; i++) peak = fmax(peak, fabs(w->v[i]));
        return peak;
    }
    if (w->kind == TF_WAVE_ZERO) return 0.0;
    return fabs(w->offset) + fabs(w->amplitude);
}

void tf_model_state_scale(const tf_model *model, double *scale)
{
    double p[TF_NPARAM];
    tf_model_params_at(model, tf_model_temperature(model, 0.0), p);
    double X = fabs(model->T_em) * input_peak(&model->input) / model->k;
    if (!(X > 0.0)) X = 1e-6;
    double V = X * sqrt(model->k / model->m);
    /* Friction can change over a velocity band far narrower than the stroke's velocity scale (the
       offset form's smoothed sign, the Stribeck curve): resolve velocities to 1e-3 of that band,
       otherwise the default atol lets the solver step across it (0.2 % error found by the
       differential tests on the offset form). */
    double band = V;
    if (model->thermal == TF_THERMAL_MODEL_II && model->dF_form == TF_DF_OFFSET && p[TF_P_VSMOOTH] > 0.0)
        band = p[TF_P_VSMOOTH];
    if (p[TF_P_FS] != p[TF_P_FC] && p[TF_P_VS] > 0.0 && p[TF_P_VS] < band) band = p[TF_P_VS];
    if (1e3 * band < V) V = 1e3 * band;
    double Z = (p[TF_P_SIGMA0] > 0.0 && p[TF_P_FC] > 0.0) ? p[TF_P_FC] / p[TF_P_SIGMA0] : 1e-3 * X;
    scale[XP] = scale[XE] = X;
    scale[VP] = scale[VE] = V;
    for (int j = 0; j < tf_friction_nstate(model->friction); j++) scale[NMECH + j] = Z;
}

int tf_model_rhs(double t, const double *y, double *dy, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double u = tf_waveform_value(&m->input, t);
    double F = friction(m, t, y, dy + NMECH, 0);
    dy[XP] = y[VP];
    dy[VP] = (-m->c * y[VP] - m->k * y[XP] + m->T_em * u + F) / m->m;
    dy[XE] = y[VE];
    dy[VE] = -F / m->m_e;
    return 0;
}

int tf_model_jac(double t, const double *y, double *J, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    int n = tf_model_nstate(m), nz = n - NMECH;
    double dz[TF_MAX_FRICTION_STATES];
    tf_friction_partials d;
    friction(m, t, y, dz, &d);
    memset(J, 0, sizeof(double) * n * n);
#define J_(i, j) J[(i) * n + (j)]
    J_(XP, VP) = 1.0;
    J_(VP, XP) = -m->k / m->m;
    J_(VP, VP) = (-m->c - d.dF_dv) / m->m;
    J_(VP, VE) = d.dF_dv / m->m;
    J_(XE, VE) = 1.0;
    J_(VE, VP) = d.dF_dv / m->m_e;
    J_(VE, VE) = -d.dF_dv / m->m_e;
    for (int j = 0; j < nz; j++) {
        J_(VP, NMECH + j) = d.dF_dz[j] / m->m;
        J_(VE, NMECH + j) = -d.dF_dz[j] / m->m_e;
        J_(NMECH + j, VP) = -d.ddz_dv[j];
        J_(NMECH + j, VE) = d.ddz_dv[j];
        J_(NMECH + j, NMECH + j) = d.ddz_dz[j];
    }
#undef J_
    return 0;
}

int tf_model_derivatives(tf_model *m, double t, const double *y, double *dy, double *J,
                         const tf_target *targets, int np, double *fp)
{
    int n = tf_model_nstate(m), nz = n - NMECH;
    tf_model_rhs(t, y, dy, m);
    if (J) tf_model_jac(t, y, J, m);
    if (!np) return 0;
    tf_friction_param_partials dp;
    double dz[TF_MAX_FRICTION_STATES], Fb, lambda, dF_offset;
    double T = tf_model_temperature(m, t);
    params(m, T, &lambda, &dF_offset);
    friction_full(m, t, y, dz, 0, &dp, &Fb);
    if (m->fs_follows_fc) { /* one parameter moves both */
        dp.dF_dp[TF_P_FC] += dp.dF_dp[TF_P_FS];
        for (int j = 0; j < nz; j++) dp.ddz_dp[j][TF_P_FC] += dp.ddz_dp[j][TF_P_FS];
    }
    int scale = m->thermal == TF_THERMAL_MODEL_II && m->dF_form == TF_DF_SCALE;
    double Fref = tf_friction_reference_force(m->friction, m->p);
    for (int k = 0; k < np; k++) {
        const tf_target *tg = &targets[k];
        double dF = 0.0, chain = 1.0; /* dF'/dtheta and d(param)/dtheta */
        int i = tg->param;
        if (tg->kind == TF_TARGET_DF) {
            double dlaw = tf_law_coef_derivative(&m->dF, tg->coef, T);
            if (scale) dF = Fb / Fref * dlaw;
            else dF = dlaw * tanh((y[VE] - y[VP]) / m->cache_p[TF_P_VSMOOTH]);
        } else {
            if (tg->kind == TF_TARGET_LAW) chain = tf_law_coef_derivative(&m->law[i], tg->coef, T);
            dF = chain * dp.dF_dp[i] * (scale ? lambda : 1.0);
            if (scale && i == TF_P_FC) dF -= (lambda - 1.0) / Fref * Fb; /* F_ref = fc; dF(T) = (lambda-1) F_ref */
        }
        for (int r = 0; r < n; r++) fp[r * np + k] = 0.0;
        fp[VP * np + k] = dF / m->m;
        fp[VE * np + k] = -dF / m->m_e;
        if (tg->kind != TF_TARGET_DF)
            for (int j = 0; j < nz; j++) fp[(NMECH + j) * np + k] = chain * dp.ddz_dp[j][i];
    }
    return 0;
}

double tf_model_next_corner(double t, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double c = tf_waveform_next_corner(&m->input, t);
    if (m->T_n > 0) c = fmin(c, tf_pwl_next_knot(m->T_n, m->T_t, t));
    return c;
}

void tf_model_outputs(const tf_model *model, double t, const double *y, double *out)
{
    int nz = tf_friction_nstate(model->friction);
    out[TF_OUT_TIME] = t;
    out[TF_OUT_INPUT] = tf_waveform_value(&model->input, t);
    out[TF_OUT_STAGE_DISPLACEMENT] = y[XP];
    out[TF_OUT_STAGE_VELOCITY] = y[VP];
    out[TF_OUT_DISPLACEMENT] = y[XE];
    out[TF_OUT_VELOCITY] = y[VE];
    out[TF_OUT_RELATIVE_DISPLACEMENT] = y[XE] - y[XP];
    out[TF_OUT_RELATIVE_VELOCITY] = y[VE] - y[VP];
    out[TF_OUT_FRICTION_FORCE] = tf_model_friction(model, t, y);
    out[TF_OUT_TEMPERATURE] = tf_model_temperature(model, t);
    for (int j = 0; j < nz; j++) out[TF_OUT_NFIXED + j] = y[NMECH + j];
}
