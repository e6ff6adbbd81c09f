/* PID, friction compensation and the closed-loop stage simulation (see control.h). Every input is
 * checked; a refused call changes nothing. */
#include "thermofriction/control.h"

#include <math.h>
#include <string.h>


static int gains_ok(double kp, double ki, double kd, double tau_d)
{
    return isfinite(kp) && isfinite(ki) && isfinite(kd) && isfinite(tau_d) && tau_d >= 0.0;
}

/* The outcome of a call: TF_OK, or a refusal by `where` naming `what` (at control period `period`). */
static tf_status done(tf_error *err, tf_status status, const char *where, const char *what, long period)
{
    return tf_error_set(err, status, status ? where : 0, status ? what : 0, NAN, status ? period : -1);
}

tf_status tf_pid_init(tf_pid *c, double kp, double ki, double kd, double tau_d, tf_error *err)
{
    if (!c) return done(err, TF_ERR_BAD_ARGUMENT, "pid", "c (NULL)", -1);
    if (!gains_ok(kp, ki, kd, tau_d)) return done(err, TF_ERR_BAD_ARGUMENT, "pid", "gains (finite; tau_d >= 0)", -1);
    c->kp = kp, c->ki = ki, c->kd = kd, c->tau_d = tau_d;
    c->integral = c->d_filtered = c->e_prev = 0.0;
    c->started = 0;
    return done(err, TF_OK, 0, 0, -1);
}

/* Why a PID step is refused, or NULL. */
static const char *pid_problem(const tf_pid *c, double e, double dt, const double *u)
{
    if (!c || !u) return "c or u (NULL)";
    if (!isfinite(e)) return "e (not finite)";
    if (!(isfinite(dt) && dt > 0.0)) return "dt (finite, > 0)";
    if (!gains_ok(c->kp, c->ki, c->kd, c->tau_d)) return "gains (finite; tau_d >= 0)";
    return 0;
}

tf_status tf_pid_step(tf_pid *c, double e, double dt, double *u, tf_error *err)
{
    if (u) *u = NAN;
    const char *bad = pid_problem(c, e, dt, u);
    if (bad) return done(err, TF_ERR_BAD_ARGUMENT, "pid", bad, -1);
    double e_prev = c->started ? c->e_prev : e;
    double de = (e - e_prev) / dt;
    /* first-order filter on the derivative, discretised exactly (stable for any dt) */
    double a = c->tau_d > 0.0 ? -expm1(-dt / c->tau_d) : 1.0;
    double d_filtered = c->d_filtered + a * (de - c->d_filtered);
    double integral = c->integral + e * dt;
    double out = c->kp * e + c->ki * integral + c->kd * d_filtered;
    if (!isfinite(out) || !isfinite(d_filtered) || !isfinite(integral))
        return done(err, TF_ERR_NONFINITE, "pid", "u (not finite)", -1);
    c->d_filtered = d_filtered, c->integral = integral, c->e_prev = e, c->started = 1;
    *u = out;
    return done(err, TF_OK, 0, 0, -1);
}

static int observed(int kind)
{
    return kind == TF_FRICTION_LUGRE || kind == TF_FRICTION_DAHL || kind == TF_FRICTION_ELASTOPLASTIC;
}

/* Why an observer step is refused, or NULL (T and the parameters there: tf_rt_params_at). */
static const char *observer_problem(const tf_rt_friction *f, double v, double e, double k, double dt, const double *F)
{
    if (!f || !F) return "f or F (NULL)";
    /* one state: extra (below) is one double, as tf_rt_advance reads extra[j] for every state */
    if (!observed(f->model.friction)) return "model (the observer needs a LuGre, Dahl or elasto-plastic model)";
    if (!isfinite(v)) return "v (not finite)";
    if (!isfinite(e)) return "e (not finite)";
    if (!(isfinite(k) && k >= 0.0)) return "k (observer gain: finite, >= 0)";
    if (!isfinite(dt)) return "dt (not finite)";
    return 0;
}

tf_status tf_observer_step(tf_rt_friction *f, double v, double e, double k, double T, double load, double dt,
                           double *F, tf_error *err)
{
    if (F) *F = NAN;
    const char *bad = observer_problem(f, v, e, k, dt, F);
    if (bad) return done(err, TF_ERR_BAD_ARGUMENT, "observer", bad, -1);
    tf_model *m = &f->model;
    double p[TF_NPARAM], lambda, dF, dz[1], Fh;
    tf_status status = tf_rt_params_at(f, T, load, p, &lambda, &dF, err); /* checks T, load and the parameters */
    if (status) return status;
    double extra[1] = {-k * e}, z[1] = {f->z[0]};
    tf_rt_advance(m->friction, p, &f->data.gms, z, v, dt, extra, dz, &Fh, 0); /* its arguments are valid here */
    /* the observer's own z^' in the damping term: F^ = sigma0 z^ + sigma1 z^' + sigma2 v */
    if (m->friction != TF_FRICTION_DAHL) Fh += tf_sigma1(p, v, 0, 0, 0) * extra[0];
    tf_rt_thermal_force(Fh, v, p, lambda, dF, &Fh, 0);
    if (!isfinite(Fh) || !isfinite(z[0]))
        return done(err, TF_ERR_NONFINITE, "observer", "force or state not finite (v, e, k or dt too large)", -1);
    f->z[0] = z[0];
    *F = Fh;
    return done(err, TF_OK, 0, 0, -1);
}

/* A stop of the loop: the part, the argument, the period. */
static tf_status stop(tf_error *err, tf_status status, const char *where, const char *what, long period)
{
    return tf_error_set(err, status, where, what, NAN, period);
}

/* A refusal from a part (the PID, a friction object): its status and what, the loop's part and period. */
static tf_status stop_in(tf_error *err, tf_status status, const char *where, long period)
{
    if (err) {
        char what[TF_ERROR_WHAT];
        memcpy(what, err->what, sizeof what);
        tf_error_set(err, status, where, what, NAN, period);
    }
    return status;
}

/* Two inputs differ (two NaNs do not: a model without a law of the load reads none). */
static int differ(double a, double b) { return a != b && !(isnan(a) && isnan(b)); }

/* A part's per-period inputs, the temperature and the load: each a series (every sample finite; NULL: the
 * constant) and, where the pair changes, the model valid there (f not NULL). */
static tf_status inputs_check(tf_rt_friction *f, const double *Ts, double T, const double *Ls, double L, long n,
                              const char *where, const char *T_what, const char *L_what, tf_error *err)
{
    long periods = Ts || Ls ? n : 1;
    for (long i = 0; i < periods; i++) {
        double Ti = Ts ? Ts[i] : T, Li = Ls ? Ls[i] : L;
        if (Ts && !isfinite(Ti)) return stop(err, TF_ERR_BAD_ARGUMENT, where, T_what, i);
        if (Ls && !isfinite(Li)) return stop(err, TF_ERR_BAD_ARGUMENT, where, L_what, i);
        if (f && (i == 0 || differ(Ti, Ts ? Ts[i - 1] : T) || differ(Li, Ls ? Ls[i - 1] : L)) &&
            tf_rt_params_at(f, Ti, Li, 0, 0, 0, err))
            return stop_in(err, TF_ERR_BAD_ARGUMENT, where, Ts || Ls ? i : -1);
    }
    return TF_OK;
}

/* The temperatures' and loads' inputs: the series, the estimator's (its own checks are per step), the noise. */
static tf_status temperature_check(tf_loop *L, long n, tf_error *err)
{
    const int B = TF_ERR_BAD_ARGUMENT;
    tf_rt_friction *comp = L->compensation != TF_COMP_NONE ? L->comp : 0;
    tf_status status;
    if ((status = inputs_check(L->plant, L->T_plant_series, L->T_plant, L->load_plant_series, L->load_plant, n,
                               "plant", "T_plant_series (not finite)", "load_plant_series (not finite)", err)))
        return status;
    for (long i = 0; L->position_noise && i < n; i++)
        if (!isfinite(L->position_noise[i])) return stop(err, B, "loop", "position_noise (not finite)", i);
    if (!(isfinite(L->dob_tau) && L->dob_tau >= 0.0)) return stop(err, B, "loop", "dob_tau (finite, >= 0)", -1);
    if (L->estimator) {
        if (!L->est_friction) return stop(err, B, "estimator", "est_friction (NULL)", -1);
        if (!isfinite(L->T_amb)) return stop(err, B, "estimator", "T_amb (not finite)", -1);
        for (long i = 0; L->T_proxy && i < n; i++) /* NaN: not measured in that period */
            if (isinf(L->T_proxy[i])) return stop(err, B, "estimator", "T_proxy (infinite)", i);
        for (long i = 0; L->load_comp_series && i < n; i++)
            if (!isfinite(L->load_comp_series[i])) return stop(err, B, "compensation", "load_comp_series (not finite)", i);
        return TF_OK;
    }
    return inputs_check(comp, L->T_comp_series, L->T_comp, L->load_comp_series, L->load_comp, n, "compensation",
                        "T_comp_series (not finite)", "load_comp_series (not finite)", err);
}

/* Everything tf_loop_run can refuse before it starts, so that a refusal writes nothing. */
static tf_status loop_check(tf_loop *L, long n, const double *x_ref, const double *v_ref, tf_error *err)
{
    const int B = TF_ERR_BAD_ARGUMENT;
    if (n < 1) return stop(err, B, "loop", "n (one period or more)", -1);
    if (!x_ref) return stop(err, B, "reference", "x_ref (NULL)", -1);
    if (L->compensation < TF_COMP_NONE || L->compensation > TF_COMP_OBSERVER)
        return stop(err, B, "loop", "compensation (kind)", -1);
    int ff = L->compensation == TF_COMP_FEEDFORWARD || L->inertia_feedforward;
    if (ff && !v_ref) return stop(err, B, "reference", "v_ref (NULL)", -1);
    if (!(isfinite(L->mass) && L->mass > 0.0)) return stop(err, B, "loop", "mass (finite, > 0)", -1);
    if (!(isfinite(L->dt) && L->dt > 0.0)) return stop(err, B, "loop", "dt (finite, > 0)", -1);
    if (L->substeps < 1) return stop(err, B, "loop", "substeps (1 or more)", -1);
    if ((double)n * L->substeps > TF_LOOP_MAX_SUBSTEPS) /* the work of one call is bounded */
        return stop(err, B, "loop", "n x substeps (at most 1e8 plant substeps in one run)", -1);
    for (long i = 0; i < n; i++) {
        if (!isfinite(x_ref[i])) return stop(err, B, "reference", "x_ref (not finite)", i);
        if (ff && !isfinite(v_ref[i])) return stop(err, B, "reference", "v_ref (not finite)", i);
    }
    if (!gains_ok(L->pid.kp, L->pid.ki, L->pid.kd, L->pid.tau_d))
        return stop(err, B, "pid", "gains (finite; tau_d >= 0)", -1);
    if (!L->plant) return stop(err, B, "plant", "plant (NULL)", -1);
    if (L->compensation != TF_COMP_NONE) {
        if (!L->comp) return stop(err, B, "compensation", "comp (NULL)", -1);
        if (L->compensation == TF_COMP_OBSERVER) {
            if (!observed(L->comp->model.friction))
                return stop(err, B, "compensation", "model (the observer needs a LuGre, Dahl or elasto-plastic model)",
                            -1);
            if (!(isfinite(L->observer_gain) && L->observer_gain >= 0.0))
                return stop(err, B, "compensation", "observer_gain (finite, >= 0)", -1);
        }
    }
    /* a model valid at each given temperature before the start stays so; the estimator's is checked per step */
    return temperature_check(L, n, err);
}

/* The disturbance observer's memory: the last two encoder positions and controls, the filtered force. */
typedef struct {
    double x1, x2, u1, u2, F;
} dob_memory;

/* The compensation's temperature in period i (and its variance, the measured friction), from the
 * estimator stepped on the disturbance observer's friction at the compensation's load, a sensor's series or the
 * constant. */
static tf_status told_temperature(tf_loop *L, long i, double x, double load, dob_memory *d, double *T, double *var,
                                  double *Fm, tf_error *err)
{
    double xe = x + (L->position_noise ? L->position_noise[i] : 0.0), dt = L->dt;
    *var = 0.0, *Fm = NAN;
    if (!L->estimator) {
        *T = L->T_comp_series ? L->T_comp_series[i] : L->T_comp;
        return TF_OK;
    }
    double vc = i == 0 ? 0.0 : (xe - d->x1) / dt, F_hat;
    if (i >= 2) {
        double Fd = 0.5 * (d->u1 + d->u2) - L->mass * (xe - 2.0 * d->x1 + d->x2) / (dt * dt);
        double a = L->dob_tau > 0.0 ? -expm1(-dt / L->dob_tau) : 1.0;
        *Fm = d->F = i == 2 ? Fd : d->F + a * (Fd - d->F);
        vc = (xe - d->x2) / (2.0 * dt);
    }
    double Tp = L->T_proxy ? L->T_proxy[i] : NAN;
    tf_status status = tf_temperature_step(L->estimator, L->est_friction, vc, load, *Fm, Tp, L->T_amb, dt, &F_hat, err);
    if (status) return stop_in(err, status, "estimator", i);
    d->x2 = d->x1, d->x1 = xe;
    *T = tf_temperature_estimate(L->estimator);
    *var = tf_temperature_variance(L->estimator);
    return TF_OK;
}

/* Writes one period's value to an output array, if asked for. */
static void put(double *out, long i, double value)
{
    if (out) out[i] = value;
}

tf_status tf_loop_run(tf_loop *L, long n, const double *x_ref, const double *v_ref, double *x_out, double *u_out,
                      double *F_out, tf_error *err)
{
    if (!L) return stop(err, TF_ERR_BAD_ARGUMENT, "loop", "loop (NULL)", -1);
    tf_status status = loop_check(L, n, x_ref, v_ref, err);
    if (status) return status;
    double x = x_ref[0], v = 0.0;
    double h = L->dt / L->substeps;
    dob_memory d = {x, x, 0.0, 0.0, 0.0};
    const tf_loop_trace *tr = &L->trace;
    for (long i = 0; i < n; i++) {
        double e = x_ref[i] - x, u, Fc = 0.0, Tc, var, Fm;
        double T_plant = L->T_plant_series ? L->T_plant_series[i] : L->T_plant;
        double L_plant = L->load_plant_series ? L->load_plant_series[i] : L->load_plant;
        double L_comp = L->load_comp_series ? L->load_comp_series[i] : L->load_comp;
        if ((status = told_temperature(L, i, x, L_comp, &d, &Tc, &var, &Fm, err))) return status;
        if ((status = tf_pid_step(&L->pid, e, L->dt, &u, 0)))
            return stop(err, status, "pid", "u (not finite: the loop is unstable)", i);
        if (L->compensation == TF_COMP_FEEDFORWARD)
            status = tf_rt_step(L->comp, v_ref[i], Tc, L_comp, L->dt, &Fc, err);
        else if (L->compensation == TF_COMP_OBSERVER)
            status = tf_observer_step(L->comp, v, -e, L->observer_gain, Tc, L_comp, L->dt, &Fc, err);
        if (status) return stop_in(err, status, "compensation", i);
        u += Fc;
        if (L->inertia_feedforward && i + 1 < n) u += L->mass * (v_ref[i + 1] - v_ref[i]) / L->dt;
        if (!isfinite(u)) return stop(err, TF_ERR_NONFINITE, "loop", "u (not finite: the loop is unstable)", i);
        d.u2 = d.u1, d.u1 = u;
        put(x_out, i, x), put(u_out, i, u), put(F_out, i, Fc);
        put(tr->T_comp, i, Tc), put(tr->T_variance, i, var), put(tr->F_measured, i, Fm);
        double F_sum = 0.0;
        for (int s = 0; s < L->substeps; s++) {
            double F;
            if ((status = tf_rt_step(L->plant, v, T_plant, L_plant, h, &F, err)))
                return stop_in(err, status, "plant", i);
            v += (u - F) / L->mass * h;
            x += v * h;
            F_sum += F;
            /* here, not after the period: the next substep would refuse a non-finite v as an argument */
            if (!isfinite(x) || !isfinite(v))
                return stop(err, TF_ERR_NONFINITE, "loop", "position or velocity not finite (the loop is unstable)", i);
        }
        put(tr->F_plant, i, F_sum / L->substeps);
    }
    return stop(err, TF_OK, 0, 0, -1);
}
