/* Plants (docs/models.md#plants) with friction and thermal extension, as one ODE system. */
#include "thermofriction/plant.h"
#include "inline.h" /* TF_SIZED */

#include <math.h>
#include <string.h>

/* State indices: stick-slip x_p, v_p, x_e, v_e; mass x, v (X, V); prescribed none. */
enum { XP = 0, VP, XE, VE };
enum { X = 0, V };

static int nmech(const tf_model *m)
{
    return m->plant == TF_PLANT_STICK_SLIP ? 4 : m->plant == TF_PLANT_MASS ? 2 : 0;
}

static int nfric(const tf_model *m) { return tf_friction_nstate(m->friction, m->gms.n); }

static int has_work(const tf_model *m) { return m->heat.on || m->work; }

void tf_model_prepare(tf_model *model) { model->cache_valid = 0; }

int tf_model_nstate(const tf_model *model)
{
    return nmech(model) + nfric(model) + (model->heat.on != 0) + has_work(model);
}

int tf_model_noutput(const tf_model *model) { return TF_OUT_NFIXED + nfric(model) + has_work(model); }

int tf_model_temperature_index(const tf_model *model)
{
    return model->heat.on ? nmech(model) + nfric(model) : -1;
}

int tf_model_work_index(const tf_model *model)
{
    return has_work(model) ? nmech(model) + nfric(model) + (model->heat.on != 0) : -1;
}

/* The common case: LuGre on the stick-slip actuator or the mass, at one constant temperature
 * (no temperature signal, no heat or work state). Its parameters, lambda and dF are then the
 * run's, and tf_model_ode gives it a right-hand side (rhs_lugre_constant_T) that dispatches on
 * nothing per call: a third of the general path's cost on the paper's workload. */
/* Whether a parameter is given (a number or a law): the direction-dependent ones are NaN when not,
 * the ripple's period <= 0. */
static int given(const tf_model *m, int i)
{
    return m->law[i].kind != TF_LAW_NONE || (i == TF_P_RIPPLE_PERIOD ? m->p[i] > 0.0 : tf_side_given(m->p[i]));
}

/* Direction-dependent friction or a position ripple: the general path handles them. */
static int sided_or_ripple(const tf_model *m)
{
    return given(m, TF_P_FC_NEG) || given(m, TF_P_FS_NEG) || given(m, TF_P_VS_NEG) || given(m, TF_P_SIGMA2_NEG) ||
           given(m, TF_P_RIPPLE_PERIOD);
}

static int lugre_constant_T(const tf_model *m)
{
    return m->friction == TF_FRICTION_LUGRE && m->T_n == 0 && !has_work(m) &&
           (m->plant == TF_PLANT_STICK_SLIP || m->plant == TF_PLANT_MASS) && !sided_or_ripple(m);
}

/* Relative sliding velocity v_r of the driven body on its driving surface. */
static double relative_velocity(const tf_model *m, double t, const double *y)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return y[VE] - y[VP];
    case TF_PLANT_MASS: return y[V];
    default: return tf_waveform_slope(&m->input, t);
    }
}

/* Relative position x_r of the same bodies (the position ripple's argument). */
static double relative_position(const tf_model *m, double t, const double *y)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return y[XE] - y[XP];
    case TF_PLANT_MASS: return y[X];
    default: return tf_waveform_value(&m->input, t);
    }
}

double tf_model_temperature(const tf_model *model, double t, const double *y)
{
    if (model->heat.on) return y[nmech(model) + nfric(model)];
    if (model->T_n > 0) return tf_pwl_value(model->T_n, model->T_t, model->T_v, t);
    return model->T_const;
}

/* Model II's F_ref: from the base parameters, the same at every temperature. */
static double reference_force(const tf_model *m) { return tf_friction_reference_force(m->friction, m->p); }

void tf_model_params_at(const tf_model *model, double T, double *p)
{
    tf_thermal_params(model->thermal, model->p, model->law, model->fs_follows_fc, T, p);
}

double tf_model_lambda(const tf_model *model, double T)
{
    return tf_thermal_lambda(model->thermal, model->dF_form, &model->dF, reference_force(model), T);
}

/* Parameters, scale factor and offset force at temperature T, cached per temperature. */
const double *tf_model_params_cached(tf_model *m, double T, double *lambda, double *dF)
{
    /* (a model without a thermal part runs at T = NaN, which must hit the cache too) */
    if (!m->cache_valid || !(m->cache_T == T || (isnan(T) && isnan(m->cache_T)))) {
        if (!m->cache_valid) m->cache_laws = tf_thermal_law_mask(m->law); /* after a prepare: laws may have changed */
        tf_thermal_params_masked(m->thermal, m->p, m->law, m->cache_laws, m->fs_follows_fc, T, m->cache_p);
        m->cache_lambda = tf_model_lambda(m, T);
        m->cache_dF = tf_thermal_offset(m->thermal, m->dF_form, &m->dF, T);
        m->cache_plain = !tf_friction_asymmetric(m->cache_p) && !(m->cache_p[TF_P_RIPPLE_PERIOD] > 0.0);
        m->cache_T = T;
        m->cache_valid = 1;
    }
    *lambda = m->cache_lambda;
    *dF = m->cache_dF;
    return m->cache_p;
}

/* F' at temperature T and, when jac is given, its partials (overwriting the base model's
 * partials). The base model's parameter partials go to dp, untouched by Model II (the caller
 * applies it: tf_thermal_param_partial). */
static double friction_at(tf_model *m, double T, double t, const double *y, double *dz, tf_friction_partials *jac,
                          tf_friction_param_partials *dp, double *F_base)
{
    double lambda, dF;
    const double *p = tf_model_params_cached(m, T, &lambda, &dF);
    double v = relative_velocity(m, t, y);
    int nz = nfric(m);
    double F;
    if (m->cache_plain) { /* symmetric, no ripple (cached with p): the models' equations alone */
        F = tf_friction_eval_side(m->friction, p, &m->gms, v, y + nmech(m), dz, jac, dp);
    } else {
        F = tf_friction_eval(m->friction, p, &m->gms, v, y + nmech(m), dz, jac, dp);
        if (p[TF_P_RIPPLE_PERIOD] > 0.0) /* on the base force: Model II scales it with the rest */
            F += tf_friction_ripple(p, relative_position(m, t, y), jac ? &jac->dF_dx : 0, dp ? dp->dF_dp : 0);
    }
    if (F_base) *F_base = F;
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, nz, jac);
}

static double friction(tf_model *m, double t, const double *y, double *dz, tf_friction_partials *jac)
{
    return friction_at(m, tf_model_temperature(m, t, y), t, y, dz, jac, 0, 0);
}

/* F' and z' of the common case (lugre_constant_T): the same equations as friction_at, with the
 * run's parameters. */
TF_SIZED double lugre_constant_T_friction(tf_model *m, double v, double z, double *zd)
{
    double lambda = m->cache_lambda, dF = m->cache_dF;
    const double *p = m->cache_p;
    if (!m->cache_valid || !(m->cache_T == m->T_const || (isnan(m->T_const) && isnan(m->cache_T))))
        p = tf_model_params_cached(m, m->T_const, &lambda, &dF);
    double g = p[TF_P_FS] == p[TF_P_FC] ? p[TF_P_FC] : tf_stribeck(p, v, 0);
    double F = tf_lugre_value(p, v, z, g, tf_sigma1(p, v, 0, 0, 0), zd);
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 1, 0);
}

double tf_model_friction(const tf_model *model, double t, const double *y)
{
    double dz[TF_MAX_FRICTION_STATES];
    if (lugre_constant_T(model))
        return lugre_constant_T_friction((tf_model *)model, relative_velocity(model, t, y), y[nmech(model)], dz);
    return friction((tf_model *)model, t, y, dz, 0);
}

void tf_model_initial_state(const tf_model *model, double *y)
{
    memset(y, 0, sizeof(double) * tf_model_nstate(model));
    if (model->heat.on) y[tf_model_temperature_index(model)] = model->heat.T_0;
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
    tf_model_params_at(model, model->heat.on ? model->heat.T_0 : tf_model_temperature(model, 0.0, 0), p);
    const tf_waveform *w = &model->input;
    double upeak = input_peak(w);
    double period = (w->kind == TF_WAVE_SAWTOOTH || w->kind == TF_WAVE_SINE || w->kind == TF_WAVE_SQUARE)
                        ? 1.0 / w->frequency : 1.0;
    double Xs, Vs; /* motion scales of the driven body */
    switch (model->plant) {
    case TF_PLANT_STICK_SLIP:
        Xs = fabs(model->T_em) * upeak / model->k;
        if (!(Xs > 0.0)) Xs = 1e-6;
        Vs = Xs * sqrt(model->k / model->m);
        break;
    case TF_PLANT_MASS: { /* the spring's pull speed, or the input force's and friction's acceleration */
        double Fs = fmax(upeak, p[TF_P_FC]);
        Vs = model->v_0 > 0.0 ? model->v_0 : Fs / model->m * period;
        if (!(Vs > 0.0)) Vs = 1e-6;
        Xs = Vs * period;
        break;
    }
    default: /* prescribed: the motion itself */
        Xs = upeak > 0.0 ? upeak : 1e-6;
        Vs = Xs / period;
    }
    /* Friction can change over a velocity band far narrower than the motion's velocity scale (the
       offset form's smoothed sign, the Stribeck curve, a smoothed static map): resolve velocities to
       1e-3 of that band, otherwise the default atol lets the solver step across it (0.2 % error
       found by the differential tests on the offset form). */
    double band = Vs;
    int static_map = model->friction == TF_FRICTION_COULOMB || model->friction == TF_FRICTION_STRIBECK;
    if (((model->thermal == TF_THERMAL_MODEL_II && model->dF_form == TF_DF_OFFSET) || static_map) &&
        p[TF_P_VSMOOTH] > 0.0)
        band = fmin(band, p[TF_P_VSMOOTH]);
    if (p[TF_P_FS] != p[TF_P_FC] && p[TF_P_VS] > 0.0) band = fmin(band, p[TF_P_VS]);
    if (1e3 * band < Vs) Vs = 1e3 * band;
    /* internal states: the presliding deflection fc/sigma0 (GMS: each element's force w_i fc) */
    double Z = (p[TF_P_SIGMA0] > 0.0 && p[TF_P_FC] > 0.0) ? p[TF_P_FC] / p[TF_P_SIGMA0] : 1e-3 * Xs;
    int nm = nmech(model), nz = nfric(model);
    if (model->plant == TF_PLANT_STICK_SLIP) {
        scale[XP] = scale[XE] = Xs;
        scale[VP] = scale[VE] = Vs;
    } else if (model->plant == TF_PLANT_MASS) {
        /* positions down to the presliding deflection: a mass may only creep */
        scale[X] = model->friction == TF_FRICTION_GMS || static_map ? Xs : fmin(Xs, Z);
        scale[V] = Vs;
    }
    for (int j = 0; j < nz; j++)
        scale[nm + j] = model->friction == TF_FRICTION_GMS ? p[TF_P_FC] * fmax(model->gms.w[j], 1e-3) : Z;
    /* temperature to rtol kelvin; work to rtol of friction times the stroke (one cycle's worth) */
    if (model->heat.on) scale[tf_model_temperature_index(model)] = 1.0;
    if (has_work(model)) {
        double W = fabs(p[TF_P_FC]) * Xs;
        scale[tf_model_work_index(model)] = W > 0.0 && isfinite(W) ? W : 1e-9;
    }
}

void tf_model_rtol_weights(const tf_model *model, double *w)
{
    int n = tf_model_nstate(model);
    for (int i = 0; i < n; i++) w[i] = 1.0;
    /* positions count from an arbitrary origin, and a stepping actuator or a pulled mass travels
     * without bound: rtol |x| would loosen their control as they go (a pulled mass 6 m out held its
     * position to 6 um, which moved its slip onsets by 0.5 % of the friction force's range). Their
     * error is held to rtol times their scale, the default atol, from start to end. */
    if (model->plant == TF_PLANT_STICK_SLIP) w[XP] = w[XE] = 0.0;
    else if (model->plant == TF_PLANT_MASS) w[X] = 0.0;
}

/* Heat balance (thermal.h) and frictional work from the friction power P = |F' v_r|. */
static void heat_rates(const tf_model *m, double t, const double *y, double F, double *dy)
{
    double P = fabs(F * relative_velocity(m, t, y));
    if (m->heat.on) {
        int iT = tf_model_temperature_index(m);
        dy[iT] = tf_heat_rate(&m->heat, t, y[iT], P);
    }
    if (has_work(m)) dy[tf_model_work_index(m)] = P;
}

/* The plant's mechanical rows under the friction force F (a prescribed motion has none): the one
 * statement of the plant equations, for every right-hand side. */
TF_SIZED void mechanical_rhs(const tf_model *m, double t, const double *y, double F, double *dy)
{
    if (m->plant == TF_PLANT_STICK_SLIP) {
        double u = tf_waveform_value(&m->input, t);
        dy[XP] = y[VP];
        dy[VP] = (-m->c * y[VP] - m->k * y[XP] + m->T_em * u + F) / m->m;
        dy[XE] = y[VE];
        dy[VE] = -F / m->m_e;
    } else if (m->plant == TF_PLANT_MASS) {
        double f = tf_waveform_value(&m->input, t) + m->k_s * (m->v_0 * t - y[X]);
        dy[X] = y[V];
        dy[V] = (f - F) / m->m;
    }
}

tf_status tf_model_rhs(double t, const double *y, double *dy, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    int nm = nmech(m);
    double F = friction(m, t, y, dy + nm, 0);
    if (has_work(m)) heat_rates(m, t, y, F, dy);
    mechanical_rhs(m, t, y, F, dy);
    return TF_OK;
}

/* dv_r/dy for the mechanical states (prescribed motion: none). */
/* tf_model_rhs for the common case (lugre_constant_T). */
static tf_status rhs_lugre_constant_T(double t, const double *y, double *dy, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    int iz = m->plant == TF_PLANT_STICK_SLIP ? 4 : 2;
    double F = lugre_constant_T_friction(m, relative_velocity(m, t, y), y[iz], &dy[iz]);
    mechanical_rhs(m, t, y, F, dy);
    return TF_OK;
}

static void velocity_partials(const tf_model *m, double *dv_dy)
{
    memset(dv_dy, 0, sizeof(double) * TF_MAX_STATES);
    if (m->plant == TF_PLANT_STICK_SLIP) dv_dy[VE] = 1.0, dv_dy[VP] = -1.0;
    else if (m->plant == TF_PLANT_MASS) dv_dy[V] = 1.0;
}

/* The rows of the temperature and work states, and the temperature column of every row, of the
 * Jacobian. dF'/dT and dz'/dT come from a central difference in T: the laws are smooth and
 * most base models have no analytic parameter partials (h = 1e-3 K: truncation ~1e-8 relative
 * for the paper's laws, far below what Rodas4's Newton-free stages need). */
static void heat_jacobian(tf_model *m, double t, const double *y, const tf_friction_partials *d, double *J)
{
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    int iT = tf_model_temperature_index(m), iW = tf_model_work_index(m);
    double T = tf_model_temperature(m, t, y);
    double dz[TF_MAX_FRICTION_STATES], dzp[TF_MAX_FRICTION_STATES], dzm[TF_MAX_FRICTION_STATES];
    double F = friction_at(m, T, t, y, dz, 0, 0, 0), v = relative_velocity(m, t, y);
    double s = (F * v > 0.0) - (F * v < 0.0);
    double dv_dy[TF_MAX_STATES], dP[TF_MAX_STATES]; /* dP/dy, P = |F v| */
    velocity_partials(m, dv_dy);
    for (int k = 0; k < n; k++) dP[k] = s * (v * d->dF_dv + F) * dv_dy[k];
    for (int j = 0; j < nz; j++) dP[nm + j] += s * v * d->dF_dz[j];
    double dF_dT = 0.0, ddz_dT[TF_MAX_FRICTION_STATES] = {0};
    if (m->heat.on && m->thermal != TF_THERMAL_NONE) {
        const double h = 1e-3;
        double Fp = friction_at(m, T + h, t, y, dzp, 0, 0, 0), Fm = friction_at(m, T - h, t, y, dzm, 0, 0, 0);
        dF_dT = (Fp - Fm) / (2 * h);
        for (int j = 0; j < nz; j++) ddz_dT[j] = (dzp[j] - dzm[j]) / (2 * h);
    }
#define J_(i, j) J[(i) * n + (j)]
    if (m->heat.on) {
        dP[iT] = s * v * dF_dT;
        if (m->plant == TF_PLANT_STICK_SLIP) {
            J_(VP, iT) = dF_dT / m->m;
            J_(VE, iT) = -dF_dT / m->m_e;
        } else if (m->plant == TF_PLANT_MASS) {
            J_(V, iT) = -dF_dT / m->m;
        }
        for (int j = 0; j < nz; j++) J_(nm + j, iT) = ddz_dT[j];
        tf_heat_rate_jacobian(&m->heat, n, iT, dP, &J_(iT, 0));
    }
    for (int k = 0; k < n; k++) J_(iW, k) = dP[k];
#undef J_
}

/* The state Jacobian from the friction force's partials d (after the thermal model). */
static void jacobian_from(tf_model *m, double t, const double *y, const tf_friction_partials *d, double *J)
{
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    memset(J, 0, sizeof(double) * n * n);
#define J_(i, j) J[(i) * n + (j)]
    if (m->plant == TF_PLANT_STICK_SLIP) {
        J_(XP, VP) = 1.0;
        J_(VP, XP) = -m->k / m->m;
        J_(VP, VP) = (-m->c - d->dF_dv) / m->m;
        J_(VP, VE) = d->dF_dv / m->m;
        J_(XE, VE) = 1.0;
        J_(VE, VP) = d->dF_dv / m->m_e;
        J_(VE, VE) = -d->dF_dv / m->m_e;
        if (d->dF_dx != 0.0) { /* the ripple, in x_e - x_p */
            J_(VP, XE) += d->dF_dx / m->m, J_(VP, XP) -= d->dF_dx / m->m;
            J_(VE, XE) -= d->dF_dx / m->m_e, J_(VE, XP) += d->dF_dx / m->m_e;
        }
        for (int j = 0; j < nz; j++) {
            J_(VP, nm + j) = d->dF_dz[j] / m->m;
            J_(VE, nm + j) = -d->dF_dz[j] / m->m_e;
            J_(nm + j, VP) = -d->ddz_dv[j];
            J_(nm + j, VE) = d->ddz_dv[j];
        }
    } else if (m->plant == TF_PLANT_MASS) {
        J_(X, V) = 1.0;
        J_(V, X) = -m->k_s / m->m;
        J_(V, V) = -d->dF_dv / m->m;
        J_(V, X) -= d->dF_dx / m->m;
        for (int j = 0; j < nz; j++) {
            J_(V, nm + j) = -d->dF_dz[j] / m->m;
            J_(nm + j, V) = d->ddz_dv[j];
        }
    }
    for (int j = 0; j < nz; j++) J_(nm + j, nm + j) = d->ddz_dz[j];
#undef J_
    if (has_work(m)) heat_jacobian(m, t, y, d, J);
}

tf_status tf_model_jac(double t, const double *y, double *J, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double dz[TF_MAX_FRICTION_STATES];
    tf_friction_partials d;
    friction(m, t, y, dz, &d);
    jacobian_from(m, t, y, &d, J);
    return TF_OK;
}

/* d(rhs)/d(plant parameter) into column k of fp (stride np): only the mechanical rows depend on
 * these directly (the friction force and its power are functions of the state). */
static void plant_partials(const tf_model *m, double t, const double *y, const double *dy, int param,
                           double *fp, int np, int k)
{
    if (m->plant == TF_PLANT_STICK_SLIP) {
        double u = tf_waveform_value(&m->input, t);
        double d_m = -dy[VP] / m->m, d_c = -y[VP] / m->m, d_k = -y[XP] / m->m, d_T = u / m->m;
        double wn = sqrt(m->k / m->m), xi = m->c / (2.0 * wn * m->m), K = m->T_em / m->k;
        double vp = 0.0;
        switch (param) {
        case TF_PLANT_P_M: vp = d_m; break;
        case TF_PLANT_P_M_E: fp[VE * np + k] = -dy[VE] / m->m_e; return;
        case TF_PLANT_P_C: vp = d_c; break;
        case TF_PLANT_P_K: vp = d_k; break;
        case TF_PLANT_P_T_EM: vp = d_T; break;
        case TF_PLANT_P_XI: vp = d_c * 2.0 * wn * m->m; break;
        case TF_PLANT_P_WN: vp = (d_c * xi + d_k * wn + d_T * K * wn) * 2.0 * m->m; break;
        case TF_PLANT_P_GAIN: vp = d_T * m->k; break;
        case TF_PLANT_P_M_MODAL: vp = d_m + d_c * 2.0 * xi * wn + (d_k + d_T * K) * wn * wn; break;
        default: break;
        }
        fp[VP * np + k] = vp;
    } else if (m->plant == TF_PLANT_MASS) {
        if (param == TF_PLANT_P_M || param == TF_PLANT_P_M_MODAL) fp[V * np + k] = -dy[V] / m->m;
        else if (param == TF_PLANT_P_K_S) fp[V * np + k] = (m->v_0 * t - y[X]) / m->m;
    }
}

tf_status tf_model_derivatives(tf_model *m, double t, const double *y, double *dy, double *J,
                               const tf_target *targets, int np, double *fp)
{
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    int iT = tf_model_temperature_index(m), iW = tf_model_work_index(m);
    int fast = lugre_constant_T(m);
    if (!np) {
        if (fast) rhs_lugre_constant_T(t, y, dy, m);
        else tf_model_rhs(t, y, dy, m);
        if (J) tf_model_jac(t, y, J, m);
        return TF_OK;
    }
    if (!fast) tf_model_rhs(t, y, dy, m); /* else from the one friction evaluation below */
    tf_friction_param_partials dp;
    tf_friction_partials d; /* the state and the parameter partials from one evaluation */
    double dz[TF_MAX_FRICTION_STATES], Fb, lambda, dF_offset;
    double T = tf_model_temperature(m, t, y);
    tf_model_params_cached(m, T, &lambda, &dF_offset);
    double F = friction_at(m, T, t, y, dz, J ? &d : 0, &dp, &Fb);
    if (fast) { /* the same equations as rhs_lugre_constant_T, with the partials' evaluation */
        dy[nm] = dz[0];
        mechanical_rhs(m, t, y, F, dy);
    }
    if (J) jacobian_from(m, t, y, &d, J);
    if (m->fs_follows_fc) { /* one parameter moves both */
        dp.dF_dp[TF_P_FC] += dp.dF_dp[TF_P_FS];
        for (int j = 0; j < nz; j++) dp.ddz_dp[j][TF_P_FC] += dp.ddz_dp[j][TF_P_FS];
    }
    double Fref = reference_force(m);
    double v = relative_velocity(m, t, y);
    double s = (F * v > 0.0) - (F * v < 0.0); /* d|F v|/dF = s v */
    memset(fp, 0, sizeof(double) * (size_t)(n * np));
    for (int k = 0; k < np; k++) {
        const tf_target *tg = &targets[k];
        double dF = 0.0, chain = 1.0; /* dF'/dtheta and d(param)/dtheta */
        int i = tg->param;
        if (tg->kind == TF_TARGET_PLANT) {
            plant_partials(m, t, y, dy, i, fp, np, k);
            continue;
        }
        if (tg->kind == TF_TARGET_HEAT) { /* only the heat balance depends on these */
            if (m->heat.on) fp[iT * np + k] = tf_heat_param_partial(&m->heat, i, y[iT], fabs(F * v), dy[iT]);
            continue;
        }
        if (tg->kind == TF_TARGET_DF) {
            dF = tf_thermal_df_coef_partial(m->dF_form, &m->dF, tg->coef, T, Fb, Fref, v, m->cache_p[TF_P_VSMOOTH]);
        } else {
            if (tg->kind == TF_TARGET_LAW) chain = tf_law_coef_derivative(&m->law[i], tg->coef, T);
            dF = tf_thermal_param_partial(m->thermal, m->dF_form, lambda, Fref, i, chain * dp.dF_dp[i], Fb);
        }
        if (m->plant == TF_PLANT_STICK_SLIP) {
            fp[VP * np + k] = dF / m->m;
            fp[VE * np + k] = -dF / m->m_e;
        } else if (m->plant == TF_PLANT_MASS) {
            fp[V * np + k] = -dF / m->m;
        }
        if (tg->kind != TF_TARGET_DF)
            for (int j = 0; j < nz; j++) fp[(nm + j) * np + k] = chain * dp.ddz_dp[j][i];
        double dP = s * v * dF; /* of the friction power |F' v| */
        if (iT >= 0) fp[iT * np + k] = tf_heat_rate_dP(&m->heat, dP);
        if (iW >= 0) fp[iW * np + k] = dP;
    }
    return TF_OK;
}

double tf_model_next_corner(double t, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double c = tf_waveform_next_corner(&m->input, t);
    if (m->plant == TF_PLANT_PRESCRIBED) c = fmin(c, tf_waveform_next_reversal(&m->input, t));
    if (m->heat.on) {
        if (m->heat.P_ext.kind != TF_WAVE_ZERO) c = fmin(c, tf_waveform_next_corner(&m->heat.P_ext, t));
    } else if (m->T_n > 0) {
        c = fmin(c, tf_pwl_next_knot(m->T_n, m->T_t, t));
    }
    return c;
}

int tf_model_nevent(const tf_model *model) { return tf_friction_nevent(model->friction, &model->gms); }

void tf_model_events(double t, const double *y, double *g, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double lambda, dF;
    const double *p = tf_model_params_cached(m, tf_model_temperature(m, t, y), &lambda, &dF);
    tf_friction_events(m->friction, p, &m->gms, relative_velocity(m, t, y), y + nmech(m), g);
}

void tf_model_on_restart(double t, const double *y, void *ctx)
{
    tf_model *m = (tf_model *)ctx;
    double lambda, dF;
    const double *p = tf_model_params_cached(m, tf_model_temperature(m, t, y), &lambda, &dF);
    double v = relative_velocity(m, t, y);
    if (m->plant == TF_PLANT_PRESCRIBED) {
        /* a prescribed motion keeps one direction between restarts (corners and reversals), but
         * at a sine's extremum v(t) is rounding noise: take the direction from inside the segment */
        double tc = tf_model_next_corner(t, m);
        if (isfinite(tc)) v = copysign(fabs(v), tf_waveform_slope(&m->input, 0.5 * (t + tc)));
    }
    tf_friction_update_modes(m->friction, p, &m->gms, v, y + nmech(m));
}

/* dv/dy . w: the relative velocity is linear in the state (zero under prescribed motion). */
static double velocity_along(const tf_model *m, const double *w)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return w[VE] - w[VP];
    case TF_PLANT_MASS: return w[V];
    default: return 0.0;
    }
}

void tf_model_sensitivity_restart(tf_model *m, double t, double *Y, const tf_target *targets, int np)
{
    if (m->friction != TF_FRICTION_GMS) return;
    int n = tf_model_nstate(m), nm = nmech(m), ne = m->gms.n;
    int old[TF_MAX_FRICTION_STATES];
    double fm[TF_MAX_STATES], fpl[TF_MAX_STATES];
    memcpy(old, m->gms.mode, sizeof(int) * (size_t)ne);
    tf_model_rhs(t, Y, fm, m);
    tf_model_on_restart(t, Y, m);
    int changed = 0;
    for (int i = 0; i < ne; i++) changed |= old[i] != m->gms.mode[i];
    if (!changed || !np) return;
    tf_model_rhs(t, Y, fpl, m);
    double lambda, dF;
    const double *p = tf_model_params_cached(m, tf_model_temperature(m, t, Y), &lambda, &dF);
    double v = relative_velocity(m, t, Y), dg_dv, dg_p[TF_NPARAM];
    tf_stribeck(p, v, &dg_dv);
    tf_stribeck_param_partials(p, v, dg_p);
    if (m->fs_follows_fc) dg_p[TF_P_FC] += dg_p[TF_P_FS];
    /* the negative capacity -w_i g_-(v) (direction-dependent levels: friction.h, tf_friction_side) */
    double q[TF_NPARAM], dgn_dv, dgn_p[TF_NPARAM];
    const double *pn = tf_friction_side(p, -1.0, q);
    tf_stribeck(pn, v, &dgn_dv);
    tf_stribeck_param_partials(pn, v, dgn_p);
    tf_friction_side_partials(p, -1.0, dgn_p);
    if (m->fs_follows_fc) dgn_p[TF_P_FC] += dgn_p[TF_P_FS];
    /* dv/dt along the trajectory before the switch; under prescribed motion v(t) is the input's
       slope, whose change is left out (it moves an event only through the Stribeck curve's slope) */
    double vdot = velocity_along(m, fm);
    double *S = Y + n;
    for (int i = 0; i < ne; i++) {
        int a = old[i], b = m->gms.mode[i], row = nm + i;
        if (a == b) continue;
        double jump = fm[row] - fpl[row], w = m->gms.w[i];
        const double *dgs_p = a == 0 && b < 0 ? dgn_p : dg_p; /* the capacity of the side it broke loose to */
        double dgs_dv = a == 0 && b < 0 ? dgn_dv : dg_dv;
        /* the event function that fired: a stuck element reaching its capacity, b z_i - w_i g(v);
           a slipping one whose motion reversed, -a v */
        double rate = a == 0 ? b * fm[row] - w * dgs_dv * vdot : -a * vdot;
        if (!(fabs(rate) > 0.0) || jump == 0.0) continue;
        for (int k = 0; k < np; k++) {
            const tf_target *tg = &targets[k];
            double col[TF_MAX_STATES], num; /* column k of S (row-major n x np) */
            for (int r = 0; r < n; r++) col[r] = S[r * np + k];
            double dv = velocity_along(m, col);
            if (a == 0) {
                double dcap = 0.0; /* d(capacity g)/dtheta, directly */
                if (tg->kind == TF_TARGET_PARAM) dcap = dgs_p[tg->param];
                else if (tg->kind == TF_TARGET_LAW) dcap = tf_law_coef_derivative(&m->law[tg->param], tg->coef,
                                                                                  tf_model_temperature(m, t, Y)) *
                                                           dgs_p[tg->param];
                num = b * col[row] - w * (dcap + dgs_dv * dv);
            } else {
                num = -a * dv;
            }
            S[row * np + k] -= jump * num / rate;
        }
    }
}

static void model_restart(double t, double *y, void *ctx) { tf_model_on_restart(t, y, ctx); }

tf_ode tf_model_ode(tf_model *model)
{
    tf_ode ode = {tf_model_nstate(model), model, lugre_constant_T(model) ? rhs_lugre_constant_T : tf_model_rhs,
                  tf_model_jac, tf_model_next_corner, tf_model_nevent(model), tf_model_events, model_restart,
                  0.0, 0, -1};
    if (!ode.nevent) ode.events = 0, ode.on_restart = 0;
    if ((model->plant == TF_PLANT_STICK_SLIP || model->plant == TF_PLANT_MASS) && !ode.nevent) {
        /* the friction's relative velocity (relative_velocity), at the scale its tolerance is rtol times;
         * not for GMS, whose elements' switches between sticking and sliding are events (a restart each) */
        double scale[TF_MAX_STATES];
        tf_model_state_scale(model, scale);
        int stick_slip = model->plant == TF_PLANT_STICK_SLIP;
        ode.kink_plus = stick_slip ? VE : V;
        ode.kink_minus = stick_slip ? VP : -1;
        ode.kink_scale = scale[ode.kink_plus];
    }
    return ode;
}

void tf_model_outputs_strided(const tf_model *model, double t, const double *y, double *out, long stride)
{
    const int fast = lugre_constant_T(model); /* LuGre: one state, no work state */
    int nm = nmech(model), nz = fast ? 1 : nfric(model);
    double u = tf_waveform_value(&model->input, t);
    double xp = 0.0, vp = 0.0, x, v;
    switch (model->plant) {
    case TF_PLANT_STICK_SLIP: xp = y[XP]; vp = y[VP]; x = y[XE]; v = y[VE]; break;
    case TF_PLANT_MASS: x = y[X]; v = y[V]; break;
    default: x = u; v = tf_waveform_slope(&model->input, t);
    }
    out[TF_OUT_TIME * stride] = t;
    out[TF_OUT_INPUT * stride] = u;
    out[TF_OUT_STAGE_DISPLACEMENT * stride] = xp;
    out[TF_OUT_STAGE_VELOCITY * stride] = vp;
    out[TF_OUT_DISPLACEMENT * stride] = x;
    out[TF_OUT_VELOCITY * stride] = v;
    out[TF_OUT_RELATIVE_DISPLACEMENT * stride] = x - xp;
    out[TF_OUT_RELATIVE_VELOCITY * stride] = v - vp;
    if (fast) { /* the common case, as its right-hand side computes it */
        double dz;
        out[TF_OUT_FRICTION_FORCE * stride] = lugre_constant_T_friction((tf_model *)model, v - vp, y[nm], &dz);
        out[TF_OUT_TEMPERATURE * stride] = model->T_const;
    } else {
        out[TF_OUT_FRICTION_FORCE * stride] = tf_model_friction(model, t, y);
        out[TF_OUT_TEMPERATURE * stride] = tf_model_temperature(model, t, y);
    }
    for (int j = 0; j < nz; j++) out[(TF_OUT_NFIXED + j) * stride] = y[nm + j];
    if (!fast && has_work(model)) out[(TF_OUT_NFIXED + nz) * stride] = y[tf_model_work_index(model)];
}

void tf_model_outputs(const tf_model *model, double t, const double *y, double *out)
{
    tf_model_outputs_strided(model, t, y, out, 1);
}
