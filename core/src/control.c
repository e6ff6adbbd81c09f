/* PID, friction compensation and the closed-loop stage simulation (see control.h). */
#include "thermofriction/control.h"

#include <math.h>

#include "thermofriction/integrator.h" /* status codes */

void tf_pid_init(tf_pid *c, double kp, double ki, double kd, double tau_d)
{
    c->kp = kp, c->ki = ki, c->kd = kd, c->tau_d = tau_d;
    c->integral = c->d_filtered = c->e_prev = 0.0;
    c->started = 0;
}

double tf_pid_step(tf_pid *c, double e, double dt)
{
    if (!c->started) c->e_prev = e, c->started = 1;
    double de = (e - c->e_prev) / dt;
    /* first-order filter on the derivative, discretised exactly (stable for any dt) */
    double a = c->tau_d > 0.0 ? -expm1(-dt / c->tau_d) : 1.0;
    c->d_filtered += a * (de - c->d_filtered);
    c->integral += e * dt;
    c->e_prev = e;
    return c->kp * e + c->ki * c->integral + c->kd * c->d_filtered;
}

double tf_observer_step(tf_rt_friction *f, double v, double e, double k, double T, double dt)
{
    double lambda, dF, dz[TF_MAX_FRICTION_STATES];
    tf_model *m = &f->model;
    const double *p = tf_model_params_cached(m, T, &lambda, &dF);
    double extra = -k * e;
    double F = tf_rt_advance(m->friction, p, &m->gms, f->z, v, dt, &extra, dz);
    /* the observer's own z^' in the damping term: F^ = sigma0 z^ + sigma1 z^' + sigma2 v */
    if (m->friction == TF_FRICTION_LUGRE || m->friction == TF_FRICTION_ELASTOPLASTIC) {
        F += tf_sigma1(p, v, 0, 0, 0) * extra;
    }
    return tf_thermal_force(F, v, p[TF_P_VSMOOTH], lambda, dF, 0, 0);
}

int tf_loop_run(tf_loop *L, long n, const double *x_ref, const double *v_ref, double *x_out, double *u_out,
                double *F_out)
{
    double x = x_ref[0], v = 0.0;
    double h = L->dt / (L->substeps > 0 ? L->substeps : 1);
    for (long i = 0; i < n; i++) {
        double e = x_ref[i] - x;
        double u = tf_pid_step(&L->pid, e, L->dt), Fc = 0.0;
        if (L->compensation == TF_COMP_FEEDFORWARD) Fc = tf_rt_step(L->comp, v_ref[i], L->T_comp, L->dt);
        else if (L->compensation == TF_COMP_OBSERVER)
            Fc = tf_observer_step(L->comp, v, -e, L->observer_gain, L->T_comp, L->dt);
        u += Fc;
        if (x_out) x_out[i] = x;
        if (u_out) u_out[i] = u;
        if (F_out) F_out[i] = Fc;
        for (int s = 0; s < (L->substeps > 0 ? L->substeps : 1); s++) {
            double F = tf_rt_step(L->plant, v, L->T_plant, h);
            v += (u - F) / L->mass * h;
            x += v * h;
        }
        if (!isfinite(x) || !isfinite(v)) return TF_ERR_NONFINITE;
    }
    return TF_OK;
}
