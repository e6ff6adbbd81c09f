/* Plants (docs/models.md#plants) with friction and thermal extension, as one ODE system: the right-hand side,
 * the outputs, the corners and events, the scales; its Jacobian and partials are in plant_derivatives.c. */
#include "thermofriction/plant.h"
#include "plant_private.h"

#include <math.h>
#include <string.h>

void tf_model_data_init(tf_model_data *data, const tf_model *model)
{
    memset(data, 0, sizeof *data);
    data->model = model;
    data->gms = model->gms;
}

void tf_model_data_changed(tf_model_data *data) { data->cache.valid = 0; }

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
 * run's, and tf_model_ode gives it a right-hand side (tf_plant_rhs_fast) that dispatches on
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

int tf_plant_fast(const tf_model *m)
{
    return m->friction == TF_FRICTION_LUGRE && m->T_n == 0 && m->load.kind == TF_WAVE_ZERO && !has_work(m) &&
           (m->plant == TF_PLANT_STICK_SLIP || m->plant == TF_PLANT_MASS) && !sided_or_ripple(m);
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

double tf_model_load(const tf_model *model, double t)
{
    return model->load.kind == TF_WAVE_ZERO ? model->load_const : tf_waveform_value(&model->load, t);
}

int tf_model_reads_load(const tf_model *model) { return tf_thermal_load_mask(model->thermal, model->law) != 0; }

void tf_model_params_at(const tf_model *model, double T, double L, double *p)
{
    tf_thermal_params(model->thermal, model->p, model->law, model->fs_follows_fc, T, L, p);
}

double tf_model_lambda(const tf_model *model, double T)
{
    return tf_thermal_lambda(model->thermal, model->dF_form, &model->dF, reference_force(model), T);
}

static int same(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

/* Parameters, scale factor and offset force at temperature T and load L, cached per (T, L). */
const double *tf_model_params_cached(tf_model_data *d, double T, double L, double *lambda, double *dF)
{
    const tf_model *m = d->model;
    tf_params_cache *c = &d->cache;
    /* after a change the laws may have changed: the masks are retaken when the cache is refilled */
    unsigned long loads = c->valid ? c->loads : tf_thermal_load_mask(m->thermal, m->law);
    if (!loads) L = NAN; /* a model that reads no load: any L hits the cache */
    /* (a model without a thermal part runs at T = NaN, which must hit the cache too) */
    if (!c->valid || !same(c->T, T) || !same(c->L, L)) {
        if (!c->valid) c->laws = tf_thermal_law_mask(m->law), c->loads = loads;
        tf_thermal_params_masked(m->thermal, m->p, m->law, c->laws, m->fs_follows_fc, T, L, c->p);
        c->lambda = tf_model_lambda(m, T);
        c->dF = tf_thermal_offset(m->thermal, m->dF_form, &m->dF, T);
        c->plain = !tf_friction_asymmetric(c->p) && !(c->p[TF_P_RIPPLE_PERIOD] > 0.0);
        c->T = T;
        c->L = L;
        c->valid = 1;
    }
    *lambda = c->lambda;
    *dF = c->dF;
    return c->p;
}

/* F' at temperature T and load L and, when jac is given, its partials (overwriting the base model's
 * partials). The base model's parameter partials go to dp, untouched by Model II (the caller
 * applies it: tf_thermal_param_partial). */
double tf_plant_friction_at(tf_model_data *d, double T, double L, double t, const double *y, double *dz,
                            tf_friction_partials *jac, tf_friction_param_partials *dp, double *F_base)
{
    const tf_model *m = d->model;
    double lambda, dF;
    const double *p = tf_model_params_cached(d, T, L, &lambda, &dF);
    double v = relative_velocity(m, t, y);
    int nz = nfric(m);
    double F;
    if (d->cache.plain) { /* symmetric, no ripple (cached with p): the models' equations alone */
        F = tf_friction_eval_side(m->friction, p, &d->gms, v, y + nmech(m), dz, jac, dp);
    } else {
        F = tf_friction_eval(m->friction, p, &d->gms, v, y + nmech(m), dz, jac, dp);
        if (p[TF_P_RIPPLE_PERIOD] > 0.0) /* on the base force: Model II scales it with the rest */
            F += tf_friction_ripple(p, relative_position(m, t, y), jac ? &jac->dF_dx : 0, dp ? dp->dF_dp : 0);
    }
    if (F_base) *F_base = F;
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, nz, jac);
}

/* F' and z' of the common case (tf_plant_fast): the same equations as tf_plant_friction_at, with the
 * run's parameters (its temperature and load constant). */
TF_SIZED double lugre_constant_T_friction(tf_model_data *d, double v, double z, double *zd)
{
    const tf_model *m = d->model;
    const tf_params_cache *c = &d->cache;
    double lambda = c->lambda, dF = c->dF;
    const double *p = c->p;
    if (!c->valid || !same(c->T, m->T_const) || (c->loads && !same(c->L, m->load_const)))
        p = tf_model_params_cached(d, m->T_const, m->load_const, &lambda, &dF);
    double g = p[TF_P_FS] == p[TF_P_FC] ? p[TF_P_FC] : tf_stribeck(p, v, 0);
    double F = tf_lugre_value(p, v, z, g, tf_sigma1(p, v, 0, 0, 0), zd);
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 1, 0);
}

double tf_model_friction(tf_model_data *data, double t, const double *y)
{
    const tf_model *model = data->model;
    double dz[TF_MAX_FRICTION_STATES];
    if (tf_plant_fast(model))
        return lugre_constant_T_friction(data, relative_velocity(model, t, y), y[nmech(model)], dz);
    return tf_plant_friction(data, t, y, dz, 0);
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
    tf_model_params_at(model, model->heat.on ? model->heat.T_0 : tf_model_temperature(model, 0.0, 0),
                       tf_model_load(model, 0.0), p);
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
    int static_map = tf_friction_states(model->friction) == 0;
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

void tf_model_default_atol(const tf_model *model, double rtol, double *atol)
{
    tf_model_state_scale(model, atol);
    int n = tf_model_nstate(model);
    for (int i = 0; i < n; i++) atol[i] *= rtol;
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

tf_status tf_model_rhs(double t, const double *y, double *dy, void *ctx)
{
    tf_model_data *d = (tf_model_data *)ctx;
    const tf_model *m = d->model;
    int nm = nmech(m);
    double F = tf_plant_friction(d, t, y, dy + nm, 0);
    if (has_work(m)) heat_rates(m, t, y, F, dy);
    mechanical_rhs(m, t, y, F, dy);
    return TF_OK;
}

/* tf_model_rhs for the common case (tf_plant_fast). */
tf_status tf_plant_rhs_fast(double t, const double *y, double *dy, void *ctx)
{
    tf_model_data *d = (tf_model_data *)ctx;
    const tf_model *m = d->model;
    int iz = m->plant == TF_PLANT_STICK_SLIP ? 4 : 2;
    double F = lugre_constant_T_friction(d, relative_velocity(m, t, y), y[iz], &dy[iz]);
    mechanical_rhs(m, t, y, F, dy);
    return TF_OK;
}

double tf_model_next_corner(double t, void *ctx)
{
    const tf_model *m = ((const tf_model_data *)ctx)->model;
    double c = tf_waveform_next_corner(&m->input, t);
    if (m->plant == TF_PLANT_PRESCRIBED) c = fmin(c, tf_waveform_next_reversal(&m->input, t));
    if (m->heat.on) {
        if (m->heat.P_ext.kind != TF_WAVE_ZERO) c = fmin(c, tf_waveform_next_corner(&m->heat.P_ext, t));
    } else if (m->T_n > 0) {
        c = fmin(c, tf_pwl_next_knot(m->T_n, m->T_t, t));
    }
    if (m->load.kind != TF_WAVE_ZERO) c = fmin(c, tf_waveform_next_corner(&m->load, t));
    return c;
}

/* The Stribeck band: the smaller Stribeck velocity of the two sides where fs differs from fc (INFINITY if
 * neither side has a Stribeck effect). */
static double stribeck_band(const double *p)
{
    double q[TF_NPARAM], band = INFINITY;
    for (int side = 0; side < 2; side++) {
        const double *s = side ? tf_friction_side(p, -1.0, q) : p;
        if (isfinite(s[TF_P_FS]) && s[TF_P_FS] != s[TF_P_FC] && s[TF_P_VS] > 0.0) band = fmin(band, s[TF_P_VS]);
    }
    return band;
}

/* Under a prescribed motion the velocity is the input's, no state, so no error estimate sees how it
 * changes within a step -- only what it does to the friction states (the sine's reversals are corners for
 * the same reason). Across the Stribeck band before a reversal the bristles' relaxation rate
 * sigma0 |v| / g(v) falls by orders of magnitude within ~10 ms; Rodas4, whose Jacobian is the step's
 * start's, took one step across it with z frozen at fc/sigma0 and a small error estimate: 3-9 % of the
 * force's range at every rtol (docs/limits.md). So a step may change the velocity by at most
 * PRESCRIBED_STEP_FRACTION of the larger of |v| at its start and the band, bounded with the waveform's peak
 * acceleration: the friction's coefficients then change little within it. The whole of it (1.0) still
 * left 1.5 % on a 20 mm, 1 Hz sine; the steps this adds per quarter period grow with log(v_peak / vs). */
static const double PRESCRIBED_STEP_FRACTION = 0.5;

double tf_model_max_step(double t, const double *y, void *ctx)
{
    tf_model_data *d = (tf_model_data *)ctx;
    const tf_model *m = d->model;
    double a = tf_waveform_peak_slope_rate(&m->input); /* a bound on the whole step's acceleration */
    if (!(a > 0.0)) return INFINITY; /* piecewise linear: constant velocity between corners */
    double lambda, dF;
    const double *p = tf_model_params_cached(d, tf_model_temperature(m, t, y), model_load(d, t), &lambda, &dF);
    double band = stribeck_band(p);
    if (!isfinite(band)) return INFINITY;
    return PRESCRIBED_STEP_FRACTION * fmax(fabs(tf_waveform_slope(&m->input, t)), band) / a;
}

int tf_model_nevent(const tf_model *model) { return tf_friction_nevent(model->friction, &model->gms); }

void tf_model_events(double t, const double *y, double *g, void *ctx)
{
    tf_model_data *d = (tf_model_data *)ctx;
    const tf_model *m = d->model;
    double lambda, dF;
    const double *p = tf_model_params_cached(d, tf_model_temperature(m, t, y), model_load(d, t), &lambda, &dF);
    tf_friction_events(m->friction, p, &d->gms, relative_velocity(m, t, y), y + nmech(m), g);
}

void tf_model_on_restart(double t, const double *y, void *ctx)
{
    tf_model_data *d = (tf_model_data *)ctx;
    const tf_model *m = d->model;
    double lambda, dF;
    const double *p = tf_model_params_cached(d, tf_model_temperature(m, t, y), model_load(d, t), &lambda, &dF);
    double v = relative_velocity(m, t, y);
    if (m->plant == TF_PLANT_PRESCRIBED) {
        /* a prescribed motion keeps one direction between restarts (corners and reversals), but
         * at a sine's extremum v(t) is rounding noise: take the direction from inside the segment */
        double tc = tf_model_next_corner(t, d);
        if (isfinite(tc)) v = copysign(fabs(v), tf_waveform_slope(&m->input, 0.5 * (t + tc)));
    }
    tf_friction_update_modes(m->friction, p, &d->gms, v, y + nmech(m));
}

static void model_restart(double t, double *y, void *ctx) { tf_model_on_restart(t, y, ctx); }

tf_ode tf_model_ode(tf_model_data *data)
{
    const tf_model *model = data->model;
    tf_ode ode = {tf_model_nstate(model), data, tf_plant_fast(model) ? tf_plant_rhs_fast : tf_model_rhs,
                  tf_model_jac, tf_model_next_corner, tf_model_nevent(model), tf_model_events, model_restart,
                  0.0, 0, -1, model->plant == TF_PLANT_PRESCRIBED ? tf_model_max_step : 0};
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

void tf_model_outputs_strided(tf_model_data *data, double t, const double *y, double *out, long stride)
{
    const tf_model *model = data->model;
    const int fast = tf_plant_fast(model); /* LuGre: one state, no work state */
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
        out[TF_OUT_FRICTION_FORCE * stride] = lugre_constant_T_friction(data, v - vp, y[nm], &dz);
        out[TF_OUT_TEMPERATURE * stride] = model->T_const;
    } else {
        out[TF_OUT_FRICTION_FORCE * stride] = tf_model_friction(data, t, y);
        out[TF_OUT_TEMPERATURE * stride] = tf_model_temperature(model, t, y);
    }
    for (int j = 0; j < nz; j++) out[(TF_OUT_NFIXED + j) * stride] = y[nm + j];
    if (!fast && has_work(model)) out[(TF_OUT_NFIXED + nz) * stride] = y[tf_model_work_index(model)];
}

void tf_model_outputs(tf_model_data *data, double t, const double *y, double *out)
{
    tf_model_outputs_strided(data, t, y, out, 1);
}
