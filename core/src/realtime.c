/* Real-time friction models (see realtime.h): exponential-Euler steps of the core's own
 * friction equations, allocation-free. */
#include "thermofriction/realtime.h"

#include <math.h>
#include <string.h>

#include "thermofriction/integrator.h" /* status codes */
#include "thermofriction/plant.h"

int tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms)
{
    memset(f, 0, sizeof *f);
    int n = kind == TF_FRICTION_GMS ? (gms ? gms->n : 0) : 0;
    if (tf_friction_nstate(kind, n) < 0 || (kind == TF_FRICTION_GMS && (n < 1 || n > TF_MAX_FRICTION_STATES)))
        return TF_ERR_BAD_ARGUMENT;
    f->kind = kind;
    memcpy(f->p, p, sizeof f->p);
    f->fs_follows_fc = !isfinite(p[TF_P_FS]);
    if (kind == TF_FRICTION_GMS) f->gms = *gms;
    tf_rt_reset(f);
    return TF_OK;
}

int tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law)
{
    if (param < 0 || param >= TF_NPARAM || !law || f->thermal == TF_THERMAL_MODEL_II) return TF_ERR_BAD_ARGUMENT;
    f->thermal = TF_THERMAL_MODEL_I;
    f->law[param] = *law;
    f->cache_valid = 0;
    return TF_OK;
}

int tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form)
{
    if (!dF || f->thermal == TF_THERMAL_MODEL_I || (form != TF_DF_SCALE && form != TF_DF_OFFSET))
        return TF_ERR_BAD_ARGUMENT;
    f->thermal = TF_THERMAL_MODEL_II;
    f->dF = *dF;
    f->dF_form = form;
    f->cache_valid = 0;
    return TF_OK;
}

int tf_rt_set_param(tf_rt_friction *f, int param, double value)
{
    if (param < 0 || param >= TF_NPARAM) return TF_ERR_BAD_ARGUMENT;
    f->p[param] = value;
    f->law[param].kind = TF_LAW_NONE;
    if (param == TF_P_FS) f->fs_follows_fc = !isfinite(value);
    f->cache_valid = 0;
    return TF_OK;
}

void tf_rt_reset(tf_rt_friction *f)
{
    memset(f->z, 0, sizeof f->z);
    for (int i = 0; i < f->gms.n; i++) f->gms.mode[i] = 0;
}

void tf_rt_params_at(tf_rt_friction *f, double T, double *p, double *lambda, double *dF_offset)
{
    if (!f->cache_valid || !(f->cache_T == T || (isnan(T) && isnan(f->cache_T)))) {
        double *q = f->cache_p;
        memcpy(q, f->p, sizeof f->p);
        if (f->thermal == TF_THERMAL_MODEL_I)
            for (int i = 0; i < TF_NPARAM; i++)
                if (f->law[i].kind != TF_LAW_NONE) q[i] = tf_law_eval(&f->law[i], T, 0);
        if (f->fs_follows_fc) q[TF_P_FS] = q[TF_P_FC];
        f->cache_lambda = 1.0;
        f->cache_dF = 0.0;
        if (f->thermal == TF_THERMAL_MODEL_II) {
            double dF = tf_law_eval(&f->dF, T, 0);
            if (f->dF_form == TF_DF_SCALE) f->cache_lambda = 1.0 + dF / tf_friction_reference_force(f->kind, f->p);
            else f->cache_dF = dF;
        }
        f->cache_T = T;
        f->cache_valid = 1;
    }
    if (p) memcpy(p, f->cache_p, sizeof f->cache_p);
    if (lambda) *lambda = f->cache_lambda;
    if (dF_offset) *dF_offset = f->cache_dF;
}

double tf_rt_advance(int kind, const double *p, tf_gms_elements *gms, double *z, double v, double dt,
                     const double *extra, double *dz)
{
    int nz = tf_friction_nstate(kind, gms->n);
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

double tf_rt_step(tf_rt_friction *f, double v, double T, double dt)
{
    double lambda, dF, dz[TF_MAX_FRICTION_STATES];
    tf_rt_params_at(f, T, 0, &lambda, &dF);
    double F = lambda * tf_rt_advance(f->kind, f->cache_p, &f->gms, f->z, v, dt, 0, dz);
    if (dF != 0.0) F += dF * tanh(v / f->cache_p[TF_P_VSMOOTH]);
    return F;
}

int tf_rt_from_model(tf_rt_friction *f, const tf_model *m)
{
    double p[TF_NPARAM];
    memcpy(p, m->p, sizeof p);
    if (m->fs_follows_fc) p[TF_P_FS] = NAN;
    int status = tf_rt_init(f, m->friction, p, m->friction == TF_FRICTION_GMS ? &m->gms : 0);
    if (status != TF_OK) return status;
    f->thermal = m->thermal;
    memcpy(f->law, m->law, sizeof f->law);
    f->dF = m->dF;
    f->dF_form = m->dF_form;
    return TF_OK;
}
