/* Friction under a prescribed motion, stepped exactly segment by segment (prescribed.h); the
 * elasto-plastic bristle by prescribed_ep.c. */
#include "thermofriction/prescribed.h"
#include "thermofriction/thermal.h"
#include "friction_private.h"
#include "prescribed_ep.h"

#include <math.h>
#include <string.h>

#define NZ TF_MAX_FRICTION_STATES

/* The run's state: the friction states z, their sensitivities S (NZ x np), the GMS modes, and the
 * current segment's rates z' = a + b z with their parameter derivatives da, db (NZ x np); the
 * elasto-plastic model's segment instead (prescribed_ep.h). With sensitivities, a one-state model affine in z
 * (LuGre, Dahl: the flag affine) keeps its segment's evaluation aff and the force's partials dF/dp = dF0 + dF1 z (np). */
typedef struct {
    int kind, nz, np, follows; /* follows: fs = fc at every temperature, so fc moves both */
    int affine, delta; /* delta: the Stribeck exponent is one of the run's parameters */
    tf_friction_affine aff;
    double dF0[TF_NPARAM], dF1[TF_NPARAM];
    const int *params;
    double p[TF_NPARAM];
    tf_gms_elements gms;
    double v;
    double z[NZ], S[NZ][TF_NPARAM];
    double a[NZ], b[NZ], da[NZ][TF_NPARAM], db[NZ][TF_NPARAM];
    tf_ep_segment ep;
} run_state;

int tf_prescribed_applies(const tf_model *m)
{
    return m->plant == TF_PLANT_PRESCRIBED && m->input.kind == TF_WAVE_SAMPLED && m->input.n >= 2 &&
           !m->heat.on && m->T_n <= 1 && m->load.kind == TF_WAVE_ZERO && m->thermal != TF_THERMAL_MODEL_II &&
           tf_friction_nstate(m->friction, m->gms.n) >= 0;
}

/* A parameter derivative from the friction model's list d[TF_NPARAM]: fc's carries fs's where fs follows fc
 * (as the sensitivities of the integrator have it, plant.c). */
static double pd(const run_state *s, const double *d, int j)
{
    int q = s->params[j];
    return d[q] + (s->follows && q == TF_P_FC ? d[TF_P_FS] : 0.0);
}

/* The elasto-plastic segment's z_ss and z_ba at the current velocity, their derivatives in the run's
 * parameters. */
static void ep_coefficients(run_state *s)
{
    double dzss[TF_NPARAM], dzba[TF_NPARAM];
    tf_ep_segment_set(&s->ep, s->p, s->v, s->np ? dzss : 0, dzba);
    for (int j = 0; j < s->np; j++) {
        s->ep.dzss[j] = pd(s, dzss, j);
        s->ep.dzba[j] = pd(s, dzba, j);
    }
}

/* A model affine in z: the segment's coefficients and the force's partials in the run's parameters, from one
 * evaluation at the velocity (tf_friction_affine_set), not one per sample. */
static void affine_coefficients(run_state *s)
{
    const tf_friction_affine *a = &s->aff;
    tf_friction_affine_set(s->kind, s->p, s->v, s->delta, &s->aff);
    s->a[0] = a->a;
    s->b[0] = a->b;
    for (int j = 0; j < s->np; j++) {
        s->da[0][j] = pd(s, a->da, j);
        s->db[0][j] = pd(s, a->db, j);
        s->dF0[j] = pd(s, a->dF0, j);
        s->dF1[j] = pd(s, a->dF1, j);
    }
}

/* The rates' coefficients at the current velocity and modes, from the friction model's own evaluation
 * at z = 0 (a, da, and b = dz'/dz) and at z = 1 (db = the parameter derivative's slope in z). */
static void coefficients(run_state *s)
{
    static const double zero[NZ] = {0.0};
    double one[NZ], dz[NZ];
    tf_friction_partials jac;
    tf_friction_param_partials dp0, dp1;
    if (s->nz == 0) return;
    if (s->kind == TF_FRICTION_ELASTOPLASTIC) {
        ep_coefficients(s);
        return;
    }
    if (s->affine) {
        affine_coefficients(s);
        return;
    }
    tf_friction_eval(s->kind, s->p, &s->gms, s->v, zero, dz, &jac, s->np ? &dp0 : 0);
    for (int i = 0; i < s->nz; i++) {
        s->a[i] = dz[i];
        s->b[i] = jac.ddz_dz[i];
        one[i] = 1.0;
    }
    if (!s->np) return;
    tf_friction_eval(s->kind, s->p, &s->gms, s->v, one, dz, 0, &dp1);
    for (int i = 0; i < s->nz; i++)
        for (int j = 0; j < s->np; j++) {
            s->da[i][j] = pd(s, dp0.ddz_dp[i], j);
            s->db[i][j] = pd(s, dp1.ddz_dp[i], j) - s->da[i][j];
        }
}

/* E = e^{bh}, phi = (E - 1) / b and psi = (h E - phi) / b, with their limits where b h is small. */
static void phis(double b, double h, double *E, double *phi, double *psi)
{
    double x = b * h;
    *E = exp(x);
    if (fabs(x) < 1e-2) { /* Taylor series: the first omitted terms are below 2e-13 relative */
        *phi = h * (1.0 + x * (0.5 + x * (1.0 / 6.0 + x * (1.0 / 24.0 + x / 120.0))));
        *psi = h * h * (0.5 + x * (1.0 / 3.0 + x * (1.0 / 8.0 + x * (1.0 / 30.0 + x / 144.0))));
    } else { /* E - 1 loses at most 2e-14 relative here (|x| >= 1e-2): one exponential, not two */
        *phi = (*E - 1.0) / b;
        *psi = (h * *E - *phi) / b;
    }
}

/* Every state over h at the current coefficients: z(h) = z0 + (a + b z0) phi and
 * S(h) = E S0 + da phi + db (z0 h E + a psi), the exact solutions of z' = a + b z and
 * S' = b S + da + db z(t). */
static void advance(run_state *s, double h)
{
    if (!(h > 0.0)) return;
    if (s->kind == TF_FRICTION_ELASTOPLASTIC) {
        tf_ep_advance(&s->ep, s->v, &s->z[0], s->S[0], s->np, h);
        return;
    }
    for (int i = 0; i < s->nz; i++) {
        double E, phi, psi, z0 = s->z[i];
        phis(s->b[i], h, &E, &phi, &psi);
        s->z[i] = z0 + (s->a[i] + s->b[i] * z0) * phi;
        double w = z0 * h * E + s->a[i] * psi;
        for (int j = 0; j < s->np; j++) s->S[i][j] = E * s->S[i][j] + s->da[i][j] * phi + s->db[i][j] * w;
    }
}

/* GMS: the time until the first stuck element reaches its capacity in the direction of motion (its
 * event function, tf_friction_events, rises through zero at the rate a = k v), INFINITY if none; its
 * index in *which. */
static double next_break(run_state *s, int *which)
{
    double ev[2 * NZ], best = INFINITY;
    *which = -1;
    if (s->kind != TF_FRICTION_GMS || s->v == 0.0) return best;
    tf_friction_events(s->kind, s->p, &s->gms, s->v, s->z, ev);
    for (int i = 0; i < s->nz; i++) {
        if (s->gms.mode[i] != 0) continue;
        double e = s->v > 0.0 ? ev[2 * i] : ev[2 * i + 1]; /* F_i - cap or -F_i - cap */
        double tau = fmax(-e / fabs(s->a[i]), 0.0);
        if (tau < best) { best = tau; *which = i; }
    }
    return best;
}

/* A segment of constant velocity v from its start: the modes set as at a restart of the integrator,
 * the coefficients for them. */
static void start_segment(run_state *s, double v)
{
    int before[NZ];
    memcpy(before, s->gms.mode, sizeof(int) * (size_t)s->gms.n);
    int changed = v != s->v;
    s->v = v;
    tf_friction_update_modes(s->kind, s->p, &s->gms, v, s->z);
    for (int i = 0; i < s->gms.n && s->kind == TF_FRICTION_GMS; i++) changed |= before[i] != s->gms.mode[i];
    if (changed) coefficients(s);
}

/* Advances from t to t1 within one segment, stopping at each element that breaks loose: it slips on
 * from its capacity, the fixed point of its slipping rate, where its sensitivity is the fixed point of
 * the sensitivity's (what the jump S+ = S- + (f- - f+) dtau/dtheta at the event gives). */
static void within_segment(run_state *s, double t, double t1)
{
    for (;;) {
        int i;
        double tau = next_break(s, &i);
        if (!(t + tau < t1)) break;
        advance(s, tau);
        t += tau;
        s->gms.mode[i] = s->v > 0.0 ? 1 : -1;
        coefficients(s);
        if (s->b[i] < 0.0) {
            s->z[i] = -s->a[i] / s->b[i];
            for (int j = 0; j < s->np; j++) s->S[i][j] = -(s->da[i][j] + s->db[i][j] * s->z[i]) / s->b[i];
        }
    }
    advance(s, t1 - t);
}

/* The position ripple at the prescribed position x, added to the friction as the plant adds it (plant.c:
 * friction_at; it has no state); its amplitudes' partials added into dp[TF_NPARAM] when not NULL. */
static double ripple(const run_state *s, double x, double *dp)
{
    return s->p[TF_P_RIPPLE_PERIOD] > 0.0 ? tf_friction_ripple(s->p, x, 0, dp) : 0.0;
}

/* output() for a model affine in z: the force and its partials at the state from the segment's evaluation
 * (the force the same number as tf_friction_eval's, so as the run's without sensitivities). */
static double affine_output(run_state *s, double x, double *dF)
{
    double z = s->z[0], F = tf_friction_affine_force(&s->aff, s->p, z);
    for (int j = 0; j < s->np; j++) dF[j] = s->dF0[j] + z * s->dF1[j] + s->aff.dF_dz * s->S[0][j];
    if (s->p[TF_P_RIPPLE_PERIOD] > 0.0) {
        double dR[TF_NPARAM] = {0.0};
        F += ripple(s, x, dR);
        for (int j = 0; j < s->np; j++) dF[j] += pd(s, dR, j);
    }
    return F;
}

/* The force and its parameter derivatives at the current state (dF: np values), with the position ripple at
 * the prescribed position x. */
static double output(run_state *s, double x, double *dF)
{
    if (s->affine) return affine_output(s, x, dF);
    double dz[NZ];
    tf_friction_partials jac;
    tf_friction_param_partials dp;
    double F = tf_friction_eval(s->kind, s->p, &s->gms, s->v, s->z, dz, s->np ? &jac : 0, s->np ? &dp : 0);
    if (s->p[TF_P_RIPPLE_PERIOD] > 0.0) /* its amplitudes' partials added to dp's (tf_friction_ripple adds) */
        F += ripple(s, x, s->np ? dp.dF_dp : 0);
    for (int j = 0; j < s->np; j++) {
        double d = pd(s, dp.dF_dp, j);
        for (int i = 0; i < s->nz; i++) d += jac.dF_dz[i] * s->S[i][j];
        dF[j] = d;
    }
    return F;
}

/* The sampled position's slope on the segment after its k-th knot (k knots at or before the time), zero
 * before the first knot and after the last (where tf_waveform_slope holds it): the segment is known, no search. */
static double slope_after(const tf_waveform *w, int k)
{
    if (k <= 0 || k >= w->n) return 0.0;
    return (w->v[k] - w->v[k - 1]) / (w->t[k] - w->t[k - 1]);
}

tf_status tf_prescribed_force(const tf_model *m, long n_out, const double *t_out, double *F, int np,
                              const int *params, double *dF, tf_error *err)
{
    static run_state zero_state;
    if (!m || !tf_prescribed_applies(m))
        return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "prescribed", "model (not a prescribed motion at a constant "
                            "temperature and load with a sampled position)", NAN, -1);
    if (n_out < 1 || !t_out || !F || np < 0 || np > TF_NPARAM || (np > 0 && (!params || !dF)))
        return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "prescribed", "arguments", NAN, -1);
    int delta = 0;
    for (int j = 0; j < np; j++) {
        if (params[j] < 0 || params[j] >= TF_NPARAM)
            return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "prescribed", "params (not a tf_param index)", NAN, j);
        delta |= params[j] == TF_P_DELTA;
    }
    for (long i = 0; i < n_out; i++)
        if (!isfinite(t_out[i]) || (i > 0 && t_out[i] < t_out[i - 1]))
            return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "prescribed", "t_out (not finite or decreasing)", NAN, i);
    run_state s_mem = zero_state, *s = &s_mem; /* on the stack: no allocation */
    s->kind = m->friction;
    s->nz = tf_friction_nstate(m->friction, m->gms.n);
    s->np = np;
    s->affine = np > 0 && tf_friction_affine_in_z(m->friction);
    s->delta = delta;
    s->params = params;
    s->follows = m->fs_follows_fc;
    s->gms = m->gms;
    tf_thermal_params(m->thermal, m->p, m->law, m->fs_follows_fc, m->T_const, m->load_const, s->p);
    const tf_waveform *w = &m->input;
    int k = 0; /* knots at or before t */
    double t = t_out[0];
    while (k < w->n && w->t[k] <= t) k++;
    s->v = NAN; /* forces the first segment's coefficients */
    start_segment(s, slope_after(w, k));
    for (long i = 0; i < n_out; i++) {
        while (t < t_out[i]) {
            double end = k < w->n ? w->t[k] : INFINITY;
            double t1 = fmin(t_out[i], end);
            within_segment(s, t, t1);
            t = t1;
            if (t == end) {
                k++;
                start_segment(s, slope_after(w, k));
            }
        }
        double *d = np ? dF + (size_t)i * (size_t)np : 0;
        F[i] = output(s, tf_waveform_value(w, t_out[i]), d);
        int finite = isfinite(F[i]);
        for (int j = 0; j < np; j++) finite &= isfinite(d[j]) != 0;
        if (!finite) return tf_error_set(err, TF_ERR_NONFINITE, "prescribed", "friction force", t, i);
    }
    return tf_error_set(err, TF_OK, 0, 0, NAN, -1);
}
