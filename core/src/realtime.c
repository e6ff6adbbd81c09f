/* Real-time friction models (see realtime.h): exponential-Euler steps of the core's own
 * friction equations, allocation-free, every input checked (a refused call changes nothing). */
#include "thermofriction/realtime.h"

#include <math.h>
#include <string.h>

/* The outcome of a call: TF_OK, or a refusal of an argument (where "realtime"). */
static tf_status rt_done(tf_error *err, tf_status status, const char *what)
{
    return tf_error_set(err, status, status ? "realtime" : 0, status ? what : 0, NAN, -1);
}

/* tf_model_check's rules on the model as it now is: its structure, and its parameters where they
 * are known (without a thermal extension always; with one at the last temperature stepped at). A
 * refusal names the field (where "model"). */
static tf_status rt_check(const tf_rt_friction *f, int T_known, double T, double L, tf_error *err)
{
    return tf_model_check_friction(&f->model, T_known ? T : NAN, T_known ? L : NAN, err);
}

static int valid_kind(int kind, const tf_gms_elements *gms)
{
    if (tf_friction_nstate(kind, 1) < 0) return 0;
    return kind != TF_FRICTION_GMS || (gms && gms->n >= 1 && gms->n <= TF_MAX_FRICTION_STATES);
}

tf_status tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    memset(f, 0, sizeof *f);
    if (!p) return rt_done(err, TF_ERR_BAD_ARGUMENT, "p (NULL)");
    if (tf_friction_nstate(kind, 1) < 0) return rt_done(err, TF_ERR_BAD_ARGUMENT, "kind");
    if (kind == TF_FRICTION_GMS && !gms) return rt_done(err, TF_ERR_BAD_ARGUMENT, "gms (NULL)");
    tf_model *m = &f->model;
    m->plant = TF_PLANT_PRESCRIBED;
    m->friction = kind;
    memcpy(m->p, p, sizeof m->p);
    m->fs_follows_fc = !isfinite(p[TF_P_FS]);
    if (kind == TF_FRICTION_GMS) m->gms = *gms;
    tf_status bad = rt_check(f, 0, NAN, NAN, err);
    if (bad) { /* leave a model that every step refuses, not a half-checked one */
        memset(m, 0, sizeof *m);
        return bad;
    }
    tf_model_data_init(&f->data, m);
    return tf_rt_reset(f, err);
}

/* The run's data of f, pointing to f's model (the struct may have been copied since the last call). */
static tf_model_data *rt_data(tf_rt_friction *f)
{
    f->data.model = &f->model;
    return &f->data;
}

/* The last temperature and load stepped at, for checking a change there (the cache holds them; the load
 * NaN where the model read none). */
static int last_T(const tf_rt_friction *f, double *T, double *L)
{
    *T = f->data.cache.T;
    *L = f->data.cache.L;
    return f->data.cache.valid && f->model.thermal != TF_THERMAL_NONE;
}

/* After a setter: a refusal restored the model (the cache still holds); an accepted change
 * refills the cache at the last temperature, where it was checked, so the next change is checked
 * there too. */
static tf_status set_done(tf_rt_friction *f, tf_status bad, int known, double T, double L)
{
    if (!bad) {
        double l, d;
        tf_model_data_changed(rt_data(f));
        if (known) tf_model_params_cached(rt_data(f), T, L, &l, &d);
    }
    return bad;
}

tf_status tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM) return rt_done(err, TF_ERR_BAD_ARGUMENT, "param (index)");
    if (!law) return rt_done(err, TF_ERR_BAD_ARGUMENT, "law (NULL)");
    if (m->thermal == TF_THERMAL_MODEL_II) return rt_done(err, TF_ERR_BAD_ARGUMENT, "thermal (Model II is set)");
    double T, L;
    int known = last_T(f, &T, &L);
    int thermal = m->thermal;
    tf_law old = m->law[param];
    m->thermal = TF_THERMAL_MODEL_I;
    m->law[param] = *law;
    tf_status bad = rt_check(f, known, T, L, err);
    if (bad) m->thermal = thermal, m->law[param] = old;
    return set_done(f, bad, known, T, L);
}

tf_status tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    tf_model *m = &f->model;
    if (!dF) return rt_done(err, TF_ERR_BAD_ARGUMENT, "dF (NULL)");
    if (m->thermal == TF_THERMAL_MODEL_I) return rt_done(err, TF_ERR_BAD_ARGUMENT, "thermal (Model I is set)");
    double T, L;
    int known = last_T(f, &T, &L);
    int thermal = m->thermal, old_form = m->dF_form;
    tf_law old = m->dF;
    m->thermal = TF_THERMAL_MODEL_II;
    m->dF = *dF;
    m->dF_form = form;
    tf_status bad = rt_check(f, known, T, L, err);
    if (bad) m->thermal = thermal, m->dF = old, m->dF_form = old_form;
    return set_done(f, bad, known, T, L);
}

tf_status tf_rt_set_param(tf_rt_friction *f, int param, double value, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM) return rt_done(err, TF_ERR_BAD_ARGUMENT, "param (index)");
    double T, L;
    int known = last_T(f, &T, &L);
    double old = m->p[param];
    tf_law old_law = m->law[param];
    int old_follows = m->fs_follows_fc;
    m->p[param] = value;
    m->law[param].kind = TF_LAW_NONE;
    if (param == TF_P_FS) m->fs_follows_fc = !isfinite(value);
    tf_status bad = rt_check(f, known, T, L, err);
    if (bad) m->p[param] = old, m->law[param] = old_law, m->fs_follows_fc = old_follows;
    return set_done(f, bad, known, T, L);
}

tf_status tf_rt_reset(tf_rt_friction *f, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    memset(f->z, 0, sizeof f->z);
    int n = f->model.gms.n;
    for (int i = 0; i < n && i < TF_MAX_FRICTION_STATES; i++) f->data.gms.mode[i] = 0;
    return rt_done(err, TF_OK, 0);
}

static int same(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

/* Parameters at (T, L), checked with tf_model_check's rules whenever T or L is new (a constant temperature
 * and load cost two comparisons); NULL, with *err filled, when T, L or the parameters there are refused.
 * A refused temperature or load leaves the cache invalid, so that it is refused again next time. */
static const double *rt_params(tf_rt_friction *f, double T, double L, double *lambda, double *dF, tf_error *err)
{
    const tf_model *m = &f->model;
    tf_params_cache *c = &f->data.cache;
    if (m->thermal == TF_THERMAL_NONE) {
        T = NAN; /* ignored: any value hits the cache */
    } else if (!isfinite(T)) {
        rt_done(err, TF_ERR_BAD_ARGUMENT, "T (not finite)");
        return 0;
    }
    if (!(c->valid ? c->loads : tf_thermal_load_mask(m->thermal, m->law))) {
        L = NAN; /* a model without a law of the load ignores it, NaN included */
    } else if (!isfinite(L)) {
        rt_done(err, TF_ERR_BAD_ARGUMENT, "load (not finite: the model has a law of the load)");
        return 0;
    }
    if (c->valid && same(c->T, T) && same(c->L, L)) {
        *lambda = c->lambda;
        *dF = c->dF;
        return c->p;
    }
    const double *p = tf_model_params_cached(rt_data(f), T, L, lambda, dF);
    if (tf_model_check_params(m, p, *lambda, *dF, err)) {
        c->valid = 0;
        return 0;
    }
    return p;
}

tf_status tf_rt_params_at(tf_rt_friction *f, double T, double load, double *p, double *lambda, double *dF_offset,
                          tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    double l, d;
    const double *q = rt_params(f, T, load, &l, &d, err);
    if (!q) return TF_ERR_BAD_ARGUMENT;
    if (p) memcpy(p, q, sizeof(double) * TF_NPARAM);
    if (lambda) *lambda = l;
    if (dF_offset) *dF_offset = d;
    return rt_done(err, TF_OK, 0);
}

tf_status tf_rt_thermal_force(double F_base, double v, const double *p, double lambda, double dF_offset, double *F,
                              tf_error *err)
{
    if (F) *F = NAN;
    if (!p || !F) return rt_done(err, TF_ERR_BAD_ARGUMENT, "p or F (NULL)");
    *F = tf_thermal_force(F_base, v, p[TF_P_VSMOOTH], lambda, dF_offset, 0, 0);
    return rt_done(err, TF_OK, 0);
}

static double advance(int kind, int nz, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                      const double *extra, double *dz)
{
    if (nz > 0 && dt > 0.0) {
        tf_friction_partials d;
        tf_friction_eval(kind, p, gms, v, z, dz, &d, 0);
        for (int j = 0; j < nz; j++) {
            double rate = dz[j] + (extra ? extra[j] : 0.0);
            double b = -d.ddz_dz[j], x = b * dt;
            /* (1 - exp(-b dt)) / b, its limit dt as b -> 0 */
            double phi = fabs(x) < 1e-12 ? dt : -expm1(-x) / b;
            z[j] += rate * phi;
        }
        if (kind == TF_FRICTION_GMS) tf_friction_update_modes(kind, p, gms, v, z);
    }
    double F = tf_friction_eval(kind, p, gms, v, z, dz, 0, 0);
    if (extra)
        for (int j = 0; j < nz; j++) dz[j] += extra[j];
    return F;
}

tf_status tf_rt_advance(int kind, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                        const double *extra, double *dz, double *F, tf_error *err)
{
    if (F) *F = NAN;
    if (!p || !z || !dz || !F) return rt_done(err, TF_ERR_BAD_ARGUMENT, "p, z, dz or F (NULL)");
    if (!valid_kind(kind, gms)) return rt_done(err, TF_ERR_BAD_ARGUMENT, "kind or gms");
    *F = advance(kind, tf_friction_nstate(kind, gms ? gms->n : 0), p, gms, z, v, dt, extra, dz);
    return rt_done(err, TF_OK, 0);
}

/* Internal states of a checked model (tf_friction_nstate without the call: it is on every step). */
static inline int nstate(const tf_model *m)
{
    int n = tf_friction_states(m->friction);
    return n == TF_STATES_PER_ELEMENT ? m->gms.n : n;
}

/* One checked step: the states advance in place from a backup, restored unless the force F' (and
 * so every state) is finite. The per-step cost of the checks: three isfinite, the cache test (a
 * model without a thermal extension skips even that) and the backup of the states. */
static tf_status rt_step(tf_rt_friction *f, double v, double T, double load, double dt, double *F_out,
                         tf_error *err)
{
    if (!isfinite(v)) return rt_done(err, TF_ERR_BAD_ARGUMENT, "v (not finite)");
    if (!isfinite(dt)) return rt_done(err, TF_ERR_BAD_ARGUMENT, "dt (not finite)");
    const tf_model *m = &f->model;
    tf_gms_elements *gms_data = &f->data.gms;
    const tf_params_cache *c = &f->data.cache;
    double lambda, dF, dz[TF_MAX_FRICTION_STATES], z0[TF_MAX_FRICTION_STATES];
    int mode0[TF_MAX_FRICTION_STATES];
    const double *p;
    if (m->thermal == TF_THERMAL_NONE && c->valid) {
        p = c->p, lambda = c->lambda, dF = c->dF;
    } else if (!(p = rt_params(f, T, load, &lambda, &dF, err))) {
        return TF_ERR_BAD_ARGUMENT;
    }
    int nz = nstate(m), gms = m->friction == TF_FRICTION_GMS;
    for (int j = 0; j < nz; j++) z0[j] = f->z[j];
    if (gms)
        for (int j = 0; j < nz; j++) mode0[j] = gms_data->mode[j];
    double F = advance(m->friction, nz, p, gms_data, f->z, v, dt, 0, dz);
    double x = dt > 0.0 ? f->x + v * dt : f->x;
    if (p[TF_P_RIPPLE_PERIOD] > 0.0) F += tf_friction_ripple(p, x, 0, 0);
    F = tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 0, 0);
    /* F' is finite only if every state is: each model's force sums its states with positive
       weights (sigma0 z, the GMS element forces), and lambda > 0 */
    if (!isfinite(F)) {
        for (int j = 0; j < nz; j++) f->z[j] = z0[j];
        if (gms)
            for (int j = 0; j < nz; j++) gms_data->mode[j] = mode0[j];
        return rt_done(err, TF_ERR_NONFINITE, "force or state not finite (v or dt too large)");
    }
    f->x = x;
    *F_out = F;
    return err ? rt_done(err, TF_OK, 0) : TF_OK;
}

tf_status tf_rt_set_position(tf_rt_friction *f, double x, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    if (!isfinite(x)) return rt_done(err, TF_ERR_BAD_ARGUMENT, "x (not finite)");
    f->x = x;
    return rt_done(err, TF_OK, 0);
}

tf_status tf_rt_step(tf_rt_friction *f, double v, double T, double load, double dt, double *F, tf_error *err)
{
    if (F) *F = NAN;
    if (!f || !F) return rt_done(err, TF_ERR_BAD_ARGUMENT, f ? "F (NULL)" : "f (NULL)");
    return rt_step(f, v, T, load, dt, F, err);
}

tf_status tf_rt_from_model(tf_rt_friction *f, const tf_model *m, tf_error *err)
{
    if (!f) return rt_done(err, TF_ERR_BAD_ARGUMENT, "f (NULL)");
    if (!m) return rt_done(err, TF_ERR_BAD_ARGUMENT, "model (NULL)");
    if (tf_model_check_friction(m, NAN, NAN, err)) return TF_ERR_BAD_ARGUMENT;
    memset(f, 0, sizeof *f); /* every field from a known state: the position (the ripple's argument) at 0 */
    f->model = *m;
    tf_model_data_init(&f->data, &f->model);
    return tf_rt_reset(f, err);
}
