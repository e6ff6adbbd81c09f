/* Real-time friction models (see realtime.h): exponential-Euler steps of the core's own
 * friction equations, allocation-free, every input checked (a refused call changes nothing). */
#include "thermofriction/realtime.h"

#include <math.h>
#include <string.h>

#include "thermofriction/integrator.h" /* status codes */

static int rt_done(tf_rt_friction *f, int status, const char *what)
{
    f->status = status;
    f->what = status ? what : 0;
    return status;
}

/* tf_model_check's rules on the model as it now is: its structure, and its parameters where they
 * are known (without a thermal extension always; with one at the last temperature stepped at). */
static const char *rt_check(const tf_rt_friction *f, int T_known, double T)
{
    const char *what;
    tf_model_check_friction(&f->model, T_known ? T : NAN, &what);
    return what;
}

static int valid_kind(int kind, const tf_gms_elements *gms)
{
    if (tf_friction_nstate(kind, 1) < 0) return 0;
    return kind != TF_FRICTION_GMS || (gms && gms->n >= 1 && gms->n <= TF_MAX_FRICTION_STATES);
}

int tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    memset(f, 0, sizeof *f);
    if (!p) return rt_done(f, TF_ERR_BAD_ARGUMENT, "p (NULL)");
    if (tf_friction_nstate(kind, 1) < 0) return rt_done(f, TF_ERR_BAD_ARGUMENT, "kind");
    if (kind == TF_FRICTION_GMS && !gms) return rt_done(f, TF_ERR_BAD_ARGUMENT, "gms (NULL)");
    tf_model *m = &f->model;
    m->plant = TF_PLANT_PRESCRIBED;
    m->friction = kind;
    memcpy(m->p, p, sizeof m->p);
    m->fs_follows_fc = !isfinite(p[TF_P_FS]);
    if (kind == TF_FRICTION_GMS) m->gms = *gms;
    const char *bad = rt_check(f, 0, NAN);
    if (bad) { /* leave a model that every step refuses, not a half-checked one */
        memset(m, 0, sizeof *m);
        return rt_done(f, TF_ERR_BAD_ARGUMENT, bad);
    }
    tf_rt_reset(f);
    return rt_done(f, TF_OK, 0);
}

/* The last temperature stepped at, for checking a change there (the cache holds it). */
static int last_T(const tf_rt_friction *f, double *T)
{
    *T = f->model.cache_T;
    return f->model.cache_valid && f->model.thermal != TF_THERMAL_NONE;
}

/* After a setter: a refusal restored the model (the cache still holds); an accepted change
 * refills the cache at the last temperature, where it was checked, so the next change is checked
 * there too. */
static int set_done(tf_rt_friction *f, const char *bad, int known, double T)
{
    if (!bad) {
        double l, d;
        tf_model_prepare(&f->model);
        if (known) tf_model_params_cached(&f->model, T, &l, &d);
    }
    return rt_done(f, bad ? TF_ERR_BAD_ARGUMENT : TF_OK, bad);
}

int tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM) return rt_done(f, TF_ERR_BAD_ARGUMENT, "param (index)");
    if (!law) return rt_done(f, TF_ERR_BAD_ARGUMENT, "law (NULL)");
    if (m->thermal == TF_THERMAL_MODEL_II) return rt_done(f, TF_ERR_BAD_ARGUMENT, "thermal (Model II is set)");
    double T;
    int known = last_T(f, &T);
    int thermal = m->thermal;
    tf_law old = m->law[param];
    m->thermal = TF_THERMAL_MODEL_I;
    m->law[param] = *law;
    const char *bad = rt_check(f, known, T);
    if (bad) m->thermal = thermal, m->law[param] = old;
    return set_done(f, bad, known, T);
}

int tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    tf_model *m = &f->model;
    if (!dF) return rt_done(f, TF_ERR_BAD_ARGUMENT, "dF (NULL)");
    if (m->thermal == TF_THERMAL_MODEL_I) return rt_done(f, TF_ERR_BAD_ARGUMENT, "thermal (Model I is set)");
    double T;
    int known = last_T(f, &T);
    int thermal = m->thermal, old_form = m->dF_form;
    tf_law old = m->dF;
    m->thermal = TF_THERMAL_MODEL_II;
    m->dF = *dF;
    m->dF_form = form;
    const char *bad = rt_check(f, known, T);
    if (bad) m->thermal = thermal, m->dF = old, m->dF_form = old_form;
    return set_done(f, bad, known, T);
}

int tf_rt_set_param(tf_rt_friction *f, int param, double value)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM) return rt_done(f, TF_ERR_BAD_ARGUMENT, "param (index)");
    double T;
    int known = last_T(f, &T);
    double old = m->p[param];
    tf_law old_law = m->law[param];
    int old_follows = m->fs_follows_fc;
    m->p[param] = value;
    m->law[param].kind = TF_LAW_NONE;
    if (param == TF_P_FS) m->fs_follows_fc = !isfinite(value);
    const char *bad = rt_check(f, known, T);
    if (bad) m->p[param] = old, m->law[param] = old_law, m->fs_follows_fc = old_follows;
    return set_done(f, bad, known, T);
}

int tf_rt_reset(tf_rt_friction *f)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    memset(f->z, 0, sizeof f->z);
    int n = f->model.gms.n;
    for (int i = 0; i < n && i < TF_MAX_FRICTION_STATES; i++) f->model.gms.mode[i] = 0;
    return rt_done(f, TF_OK, 0);
}

/* Parameters at T, checked with tf_model_check's rules whenever T is new (a constant temperature
 * costs one comparison); NULL, with the status set, when T or the parameters there are refused.
 * A refused temperature leaves the cache invalid, so that it is refused again next time. */
static const double *rt_params(tf_rt_friction *f, double T, double *lambda, double *dF)
{
    tf_model *m = &f->model;
    if (m->thermal == TF_THERMAL_NONE) {
        T = NAN; /* ignored: any value hits the cache */
    } else if (!isfinite(T)) {
        rt_done(f, TF_ERR_BAD_ARGUMENT, "T (not finite)");
        return 0;
    }
    if (m->cache_valid && (m->cache_T == T || (isnan(T) && isnan(m->cache_T)))) {
        *lambda = m->cache_lambda;
        *dF = m->cache_dF;
        return m->cache_p;
    }
    const double *p = tf_model_params_cached(m, T, lambda, dF);
    const char *bad;
    if (tf_model_check_params(m, p, *lambda, *dF, &bad)) {
        m->cache_valid = 0;
        rt_done(f, TF_ERR_BAD_ARGUMENT, bad);
        return 0;
    }
    return p;
}

int tf_rt_params_at(tf_rt_friction *f, double T, double *p, double *lambda, double *dF_offset)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    double l, d;
    const double *q = rt_params(f, T, &l, &d);
    if (!q) return f->status;
    if (p) memcpy(p, q, sizeof(double) * TF_NPARAM);
    if (lambda) *lambda = l;
    if (dF_offset) *dF_offset = d;
    return rt_done(f, TF_OK, 0);
}

double tf_rt_thermal_force(double F_base, double v, const double *p, double lambda, double dF_offset)
{
    if (!p) return NAN;
    return tf_thermal_force(F_base, v, p[TF_P_VSMOOTH], lambda, dF_offset, 0, 0);
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

double tf_rt_advance(int kind, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                     const double *extra, double *dz)
{
    if (!p || !z || !dz || !valid_kind(kind, gms)) return NAN;
    return advance(kind, tf_friction_nstate(kind, gms ? gms->n : 0), p, gms, z, v, dt, extra, dz);
}

/* Internal states of a checked model (tf_friction_nstate without the call: it is on every step). */
static inline int nstate(const tf_model *m)
{
    switch (m->friction) {
    case TF_FRICTION_COULOMB: case TF_FRICTION_STRIBECK: return 0;
    case TF_FRICTION_GMS: return m->gms.n;
    default: return 1;
    }
}

/* One checked step: the states advance in place from a backup, restored unless the force F' (and
 * so every state) is finite. The per-step cost of the checks: three isfinite, the cache test (a
 * model without a thermal extension skips even that) and the backup of the states. */
static int rt_step(tf_rt_friction *f, double v, double T, double dt, double *F_out)
{
    if (!isfinite(v)) return rt_done(f, TF_ERR_BAD_ARGUMENT, "v (not finite)");
    if (!isfinite(dt)) return rt_done(f, TF_ERR_BAD_ARGUMENT, "dt (not finite)");
    tf_model *m = &f->model;
    double lambda, dF, dz[TF_MAX_FRICTION_STATES], z0[TF_MAX_FRICTION_STATES];
    int mode0[TF_MAX_FRICTION_STATES];
    const double *p;
    if (m->thermal == TF_THERMAL_NONE && m->cache_valid) {
        p = m->cache_p, lambda = m->cache_lambda, dF = m->cache_dF;
    } else if (!(p = rt_params(f, T, &lambda, &dF))) {
        return f->status;
    }
    int nz = nstate(m), gms = m->friction == TF_FRICTION_GMS;
    for (int j = 0; j < nz; j++) z0[j] = f->z[j];
    if (gms)
        for (int j = 0; j < nz; j++) mode0[j] = m->gms.mode[j];
    double F = advance(m->friction, nz, p, &m->gms, f->z, v, dt, 0, dz);
    F = tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 0, 0);
    /* F' is finite only if every state is: each model's force sums its states with positive
       weights (sigma0 z, the GMS element forces), and lambda > 0 */
    if (!isfinite(F)) {
        for (int j = 0; j < nz; j++) f->z[j] = z0[j];
        if (gms)
            for (int j = 0; j < nz; j++) m->gms.mode[j] = mode0[j];
        return rt_done(f, TF_ERR_NONFINITE, "force or state not finite (v or dt too large)");
    }
    *F_out = F;
    f->status = TF_OK, f->what = 0;
    return TF_OK;
}

int tf_rt_step_status(tf_rt_friction *f, double v, double T, double dt, double *F)
{
    if (F) *F = NAN;
    if (!f) return TF_ERR_BAD_ARGUMENT;
    if (!F) return rt_done(f, TF_ERR_BAD_ARGUMENT, "F (NULL)");
    return rt_step(f, v, T, dt, F);
}

double tf_rt_step(tf_rt_friction *f, double v, double T, double dt)
{
    double F = NAN;
    if (f) rt_step(f, v, T, dt, &F);
    return F;
}

int tf_rt_from_model(tf_rt_friction *f, const tf_model *m)
{
    if (!f) return TF_ERR_BAD_ARGUMENT;
    if (!m) return rt_done(f, TF_ERR_BAD_ARGUMENT, "model (NULL)");
    const char *bad;
    if (tf_model_check_friction(m, NAN, &bad)) return rt_done(f, TF_ERR_BAD_ARGUMENT, bad);
    f->model = *m;
    tf_model_prepare(&f->model);
    tf_rt_reset(f);
    return rt_done(f, TF_OK, 0);
}
