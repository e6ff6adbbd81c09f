/* PID, friction compensation and the closed-loop stage simulation (see control.h). Every input is
 * checked; a refused call changes nothing. */
#include "thermofriction/control.h"

#include <math.h>
#include <string.h>

#include "thermofriction/integrator.h" /* status codes */

static int gains_ok(double kp, double ki, double kd, double tau_d)
{
    return isfinite(kp) && isfinite(ki) && isfinite(kd) && isfinite(tau_d) && tau_d >= 0.0;
}

int tf_pid_init(tf_pid *c, double kp, double ki, double kd, double tau_d)
{
    if (!c || !gains_ok(kp, ki, kd, tau_d)) return TF_ERR_BAD_ARGUMENT;
    c->kp = kp, c->ki = ki, c->kd = kd, c->tau_d = tau_d;
    c->integral = c->d_filtered = c->e_prev = 0.0;
    c->started = 0;
    return TF_OK;
}

int tf_pid_step_status(tf_pid *c, double e, double dt, double *u)
{
    if (u) *u = NAN;
    if (!c || !u || !isfinite(e) || !(isfinite(dt) && dt > 0.0) || !gains_ok(c->kp, c->ki, c->kd, c->tau_d))
        return TF_ERR_BAD_ARGUMENT;
    double e_prev = c->started ? c->e_prev : e;
    double de = (e - e_prev) / dt;
    /* first-order filter on the derivative, discretised exactly (stable for any dt) */
    double a = c->tau_d > 0.0 ? -expm1(-dt / c->tau_d) : 1.0;
    double d_filtered = c->d_filtered + a * (de - c->d_filtered);
    double integral = c->integral + e * dt;
    double out = c->kp * e + c->ki * integral + c->kd * d_filtered;
    if (!isfinite(out) || !isfinite(d_filtered) || !isfinite(integral)) return TF_ERR_NONFINITE;
    c->d_filtered = d_filtered, c->integral = integral, c->e_prev = e, c->started = 1;
    *u = out;
    return TF_OK;
}

double tf_pid_step(tf_pid *c, double e, double dt)
{
    double u;
    tf_pid_step_status(c, e, dt, &u);
    return u;
}

static int observed(int kind)
{
    return kind == TF_FRICTION_LUGRE || kind == TF_FRICTION_DAHL || kind == TF_FRICTION_ELASTOPLASTIC;
}

static int refuse(tf_rt_friction *f, int status, const char *what)
{
    f->status = status;
    f->what = what;
    return status;
}

int tf_observer_step_status(tf_rt_friction *f, double v, double e, double k, double T, double dt, double *F)
{
    if (F) *F = NAN;
    if (!f) return TF_ERR_BAD_ARGUMENT;
    tf_model *m = &f->model;
    if (!F) return refuse(f, TF_ERR_BAD_ARGUMENT, "F (NULL)");
    /* one state: extra (below) is one double, as tf_rt_advance reads extra[j] for every state */
    if (!observed(m->friction))
        return refuse(f, TF_ERR_BAD_ARGUMENT, "model (the observer needs a LuGre, Dahl or elasto-plastic model)");
    if (!isfinite(v)) return refuse(f, TF_ERR_BAD_ARGUMENT, "v (not finite)");
    if (!isfinite(e)) return refuse(f, TF_ERR_BAD_ARGUMENT, "e (not finite)");
    if (!(isfinite(k) && k >= 0.0)) return refuse(f, TF_ERR_BAD_ARGUMENT, "k (observer gain: finite, >= 0)");
    if (!isfinite(dt)) return refuse(f, TF_ERR_BAD_ARGUMENT, "dt (not finite)");
    double p[TF_NPARAM], lambda, dF, dz[1];
    int status = tf_rt_params_at(f, T, p, &lambda, &dF); /* checks T and the parameters there */
    if (status) return status;
    double extra[1] = {-k * e}, z[1] = {f->z[0]};
    double Fh = tf_rt_advance(m->friction, p, &m->gms, z, v, dt, extra, dz);
    /* the observer's own z^' in the damping term: F^ = sigma0 z^ + sigma1 z^' + sigma2 v */
    if (m->friction != TF_FRICTION_DAHL) Fh += tf_sigma1(p, v, 0, 0, 0) * extra[0];
    Fh = tf_rt_thermal_force(Fh, v, p, lambda, dF);
    if (!isfinite(Fh) || !isfinite(z[0]))
        return refuse(f, TF_ERR_NONFINITE, "force or state not finite (v, e, k or dt too large)");
    f->z[0] = z[0];
    *F = Fh;
    return refuse(f, TF_OK, 0);
}

double tf_observer_step(tf_rt_friction *f, double v, double e, double k, double T, double dt)
{
    double F;
    tf_observer_step_status(f, v, e, k, T, dt, &F);
    return F;
}

static int stop(tf_loop *L, int status, const char *where, const char *what, long period)
{
    L->where = where, L->what = what, L->period = period;
    return status;
}

/* Everything tf_loop_run can refuse before it starts, so that a refusal writes nothing. */
static int loop_check(tf_loop *L, long n, const double *x_ref, const double *v_ref)
{
    const int B = TF_ERR_BAD_ARGUMENT;
    if (n < 1) return stop(L, B, "loop", "n (one period or more)", -1);
    if (!x_ref) return stop(L, B, "reference", "x_ref (NULL)", -1);
    if (L->compensation < TF_COMP_NONE || L->compensation > TF_COMP_OBSERVER)
        return stop(L, B, "loop", "compensation (kind)", -1);
    int ff = L->compensation == TF_COMP_FEEDFORWARD;
    if (ff && !v_ref) return stop(L, B, "reference", "v_ref (NULL)", -1);
    if (!(isfinite(L->mass) && L->mass > 0.0)) return stop(L, B, "loop", "mass (finite, > 0)", -1);
    if (!(isfinite(L->dt) && L->dt > 0.0)) return stop(L, B, "loop", "dt (finite, > 0)", -1);
    if (L->substeps < 1) return stop(L, B, "loop", "substeps (1 or more)", -1);
    if ((double)n * L->substeps > TF_LOOP_MAX_SUBSTEPS) /* the work of one call is bounded */
        return stop(L, B, "loop", "n x substeps (at most 1e8 plant substeps in one run)", -1);
    for (long i = 0; i < n; i++) {
        if (!isfinite(x_ref[i])) return stop(L, B, "reference", "x_ref (not finite)", i);
        if (ff && !isfinite(v_ref[i])) return stop(L, B, "reference", "v_ref (not finite)", i);
    }
    if (!gains_ok(L->pid.kp, L->pid.ki, L->pid.kd, L->pid.tau_d))
        return stop(L, B, "pid", "gains (finite; tau_d >= 0)", -1);
    if (!L->plant) return stop(L, B, "plant", "plant (NULL)", -1);
    /* the temperatures are constant over the run: a model valid there at the start stays so */
    if (tf_rt_params_at(L->plant, L->T_plant, 0, 0, 0)) return stop(L, B, "plant", L->plant->what, -1);
    if (L->compensation != TF_COMP_NONE) {
        if (!L->comp) return stop(L, B, "compensation", "comp (NULL)", -1);
        if (L->compensation == TF_COMP_OBSERVER) {
            if (!observed(L->comp->model.friction))
                return stop(L, B, "compensation", "model (the observer needs a LuGre, Dahl or elasto-plastic model)",
                            -1);
            if (!(isfinite(L->observer_gain) && L->observer_gain >= 0.0))
                return stop(L, B, "compensation", "observer_gain (finite, >= 0)", -1);
        }
        if (tf_rt_params_at(L->comp, L->T_comp, 0, 0, 0)) return stop(L, B, "compensation", L->comp->what, -1);
    }
    return TF_OK;
}

int tf_loop_run(tf_loop *L, long n, const double *x_ref, const double *v_ref, double *x_out, double *u_out,
                double *F_out)
{
    if (!L) return TF_ERR_BAD_ARGUMENT;
    int status = loop_check(L, n, x_ref, v_ref);
    if (status) return status;
    double x = x_ref[0], v = 0.0;
    double h = L->dt / L->substeps;
    for (long i = 0; i < n; i++) {
        double e = x_ref[i] - x, u, Fc = 0.0;
        if ((status = tf_pid_step_status(&L->pid, e, L->dt, &u))) return stop(L, status, "pid", "u (not finite: the loop is unstable)", i);
        if (L->compensation == TF_COMP_FEEDFORWARD) status = tf_rt_step_status(L->comp, v_ref[i], L->T_comp, L->dt, &Fc);
        else if (L->compensation == TF_COMP_OBSERVER)
            status = tf_observer_step_status(L->comp, v, -e, L->observer_gain, L->T_comp, L->dt, &Fc);
        if (status) return stop(L, status, "compensation", L->comp->what, i);
        u += Fc;
        if (!isfinite(u)) return stop(L, TF_ERR_NONFINITE, "loop", "u (not finite: the loop is unstable)", i);
        if (x_out) x_out[i] = x;
        if (u_out) u_out[i] = u;
        if (F_out) F_out[i] = Fc;
        for (int s = 0; s < L->substeps; s++) {
            double F;
            if ((status = tf_rt_step_status(L->plant, v, L->T_plant, h, &F)))
                return stop(L, status, "plant", L->plant->what, i);
            v += (u - F) / L->mass * h;
            x += v * h;
            /* here, not after the period: the next substep would refuse a non-finite v as an argument */
            if (!isfinite(x) || !isfinite(v))
                return stop(L, TF_ERR_NONFINITE, "loop", "position or velocity not finite (the loop is unstable)", i);
        }
    }
    return stop(L, TF_OK, 0, 0, -1);
}
