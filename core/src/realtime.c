/* Real-time friction models (see realtime.h): exponential-Euler steps of the core's own
 * friction equations, allocation-free. */
#include "thermofriction/realtime.h"

#include <math.h>
#include <string.h>

#include "thermofriction/integrator.h" /* status codes */

int tf_rt_init(tf_rt_friction *f, int kind, const double *p, const tf_gms_elements *gms)
{
    memset(f, 0, sizeof *f);
    int n = kind == TF_FRICTION_GMS ? (gms ? gms->n : 0) : 0;
    if (tf_friction_nstate(kind, n) < 0 || (kind == TF_FRICTION_GMS && (n < 1 || n > TF_MAX_FRICTION_STATES)))
        return TF_ERR_BAD_ARGUMENT;
    tf_model *m = &f->model;
    m->plant = TF_PLANT_PRESCRIBED;
    m->friction = kind;
    memcpy(m->p, p, sizeof m->p);
    m->fs_follows_fc = !isfinite(p[TF_P_FS]);
    if (kind == TF_FRICTION_GMS) m->gms = *gms;
    tf_rt_reset(f);
    return TF_OK;
}

int tf_rt_set_model_i(tf_rt_friction *f, int param, const tf_law *law)
{
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM || !law || m->thermal == TF_THERMAL_MODEL_II) return TF_ERR_BAD_ARGUMENT;
    m->thermal = TF_THERMAL_MODEL_I;
    m->law[param] = *law;
    tf_model_prepare(m);
    return TF_OK;
}

int tf_rt_set_model_ii(tf_rt_friction *f, const tf_law *dF, int form)
{
    tf_model *m = &f->model;
    if (!dF || m->thermal == TF_THERMAL_MODEL_I || (form != TF_DF_SCALE && form != TF_DF_OFFSET))
        return TF_ERR_BAD_ARGUMENT;
    m->thermal = TF_THERMAL_MODEL_II;
    m->dF = *dF;
    m->dF_form = form;
    tf_model_prepare(m);
    return TF_OK;
}

int tf_rt_set_param(tf_rt_friction *f, int param, double value)
{
    tf_model *m = &f->model;
    if (param < 0 || param >= TF_NPARAM) return TF_ERR_BAD_ARGUMENT;
    m->p[param] = value;
    m->law[param].kind = TF_LAW_NONE;
    if (param == TF_P_FS) m->fs_follows_fc = !isfinite(value);
    tf_model_prepare(m);
    return TF_OK;
}

void tf_rt_reset(tf_rt_friction *f)
{
    memset(f->z, 0, sizeof f->z);
    for (int i = 0; i < f->model.gms.n; i++) f->model.gms.mode[i] = 0;
}

void tf_rt_params_at(tf_rt_friction *f, double T, double *p, double *lambda, double *dF_offset)
{
    double l, d;
    const double *q = tf_model_params_cached(&f->model, T, &l, &d);
    if (p) memcpy(p, q, sizeof(double) * TF_NPARAM);
    if (lambda) *lambda = l;
    if (dF_offset) *dF_offset = d;
}

double tf_rt_thermal_force(double F_base, double v, const double *p, double lambda, double dF_offset)
{
    return tf_thermal_force(F_base, v, p[TF_P_VSMOOTH], lambda, dF_offset, 0, 0);
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
    tf_model *m = &f->model;
    const double *p = tf_model_params_cached(m, T, &lambda, &dF);
    double F = tf_rt_advance(m->friction, p, &m->gms, f->z, v, dt, 0, dz);
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 0, 0);
}

int tf_rt_from_model(tf_rt_friction *f, const tf_model *m)
{
    if (m->friction == TF_FRICTION_GMS && (m->gms.n < 1 || m->gms.n > TF_MAX_FRICTION_STATES))
        return TF_ERR_BAD_ARGUMENT;
    if (tf_friction_nstate(m->friction, m->gms.n) < 0) return TF_ERR_BAD_ARGUMENT;
    f->model = *m;
    tf_model_prepare(&f->model);
    tf_rt_reset(f);
    return TF_OK;
}
