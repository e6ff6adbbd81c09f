/* Online contact-temperature estimator (see estimator.h): an extended Kalman filter on the lumped heat
 * path, driven by the friction power of the caller's tf_rt_friction stepped at the estimate. Every input
 * is checked; a refused call changes nothing. */
#include "thermofriction/estimator.h"

#include <math.h>
#include <string.h>

/* The temperature step [K] of the forward difference of the friction step over Tc: its truncation error,
 * d/2 of a law's curvature over its slope (0.159 / K for Li et al.'s exp laws: 8e-6 relative), and its
 * round-off, 1e-16 F / d, both far below what a temperature estimate resolves. One-sided: two friction
 * steps per estimator step, not three (a third of the cost). */
#define TF_ESTIMATOR_DT 1e-4
/* The gate on the friction update: skipped where h^2 P_cc < GATE r_F (it would move Tc by less than
 * GATE of the way to the measurement's temperature). */
#define TF_ESTIMATOR_GATE 1e-9

static tf_status est_done(tf_error *err, tf_status status, const char *what)
{
    return tf_error_set(err, status, status ? "estimator" : 0, status ? what : 0, NAN, -1);
}

static int pos(double x) { return isfinite(x) && x > 0.0; }
static int nonneg(double x) { return isfinite(x) && x >= 0.0; }

/* Why a configuration is refused, or NULL. */
static const char *config_problem(const tf_temperature_config *c)
{
    if (!c) return "config (NULL)";
    if (!pos(c->C_th)) return "config.C_th (finite, > 0)";
    if (!pos(c->R_th)) return "config.R_th (finite, > 0)";
    if (!(nonneg(c->eta) && c->eta <= 1.0)) return "config.eta (0 to 1)";
    if (!nonneg(c->C_2)) return "config.C_2 (finite, >= 0; 0: no housing node)";
    int housing = c->C_2 > 0.0;
    if (housing && !pos(c->R_2)) return "config.R_2 (finite, > 0 with a housing node)";
    if (c->proxy < TF_PROXY_NONE || c->proxy > TF_PROXY_HOUSING) return "config.proxy (kind)";
    if (c->proxy == TF_PROXY_HOUSING && !housing) return "config.proxy (housing proxy without a housing node)";
    int proxy = c->proxy != TF_PROXY_NONE;
    if (proxy && !pos(c->tau_p)) return "config.tau_p (finite, > 0 with a proxy)";
    if (!nonneg(c->q[0])) return "config.q[0] (finite, >= 0)";
    if (housing && !nonneg(c->q[1])) return "config.q[1] (finite, >= 0)";
    if (proxy && !nonneg(c->q[2])) return "config.q[2] (finite, >= 0)";
    if (!pos(c->r_F)) return "config.r_F (finite, > 0)";
    if (proxy && !pos(c->r_p)) return "config.r_p (finite, > 0 with a proxy)";
    if (!nonneg(c->v_min)) return "config.v_min (finite, >= 0)";
    return 0;
}

tf_status tf_temperature_init(tf_temperature_estimator *e, const tf_temperature_config *c, double T0, double var0,
                              tf_error *err)
{
    if (!e) return est_done(err, TF_ERR_BAD_ARGUMENT, "e (NULL)");
    const char *bad = config_problem(c);
    if (bad) return est_done(err, TF_ERR_BAD_ARGUMENT, bad);
    if (!isfinite(T0)) return est_done(err, TF_ERR_BAD_ARGUMENT, "T0 (not finite)");
    if (!pos(var0)) return est_done(err, TF_ERR_BAD_ARGUMENT, "var0 (finite, > 0)");
    memset(e, 0, sizeof *e);
    e->c = *c;
    e->n = 1;
    e->i_housing = c->C_2 > 0.0 ? e->n++ : -1;
    e->i_proxy = c->proxy != TF_PROXY_NONE ? e->n++ : -1;
    e->g_dt = NAN;
    for (int i = 0; i < e->n; i++) {
        e->x[i] = T0;
        e->P[i][i] = var0;
    }
    return est_done(err, TF_OK, 0);
}

tf_status tf_temperature_configure(tf_temperature_estimator *e, const tf_temperature_config *c, tf_error *err)
{
    if (!e) return est_done(err, TF_ERR_BAD_ARGUMENT, "e (NULL)");
    const char *bad = config_problem(c);
    if (bad) return est_done(err, TF_ERR_BAD_ARGUMENT, bad);
    if ((c->C_2 > 0.0) != (e->i_housing >= 0)) return est_done(err, TF_ERR_BAD_ARGUMENT, "config.C_2 (nodes as at init)");
    if (c->proxy != e->c.proxy) return est_done(err, TF_ERR_BAD_ARGUMENT, "config.proxy (as at init)");
    e->c = *c;
    e->g_dt = NAN;
    return est_done(err, TF_OK, 0);
}

double tf_temperature_estimate(const tf_temperature_estimator *e) { return e ? e->x[0] : NAN; }
double tf_temperature_variance(const tf_temperature_estimator *e) { return e ? e->P[0][0] : NAN; }

/* f's run state (internal states, GMS modes, position), saved and restored around trial steps. */
typedef struct {
    double z[TF_MAX_FRICTION_STATES];
    int mode[TF_MAX_FRICTION_STATES];
    double x;
} rt_backup;

static int friction_nstate(const tf_rt_friction *f)
{
    int n = tf_friction_nstate(f->model.friction, f->model.gms.n);
    return n < 0 ? 0 : n;
}

static void save(const tf_rt_friction *f, int nz, rt_backup *b)
{
    memcpy(b->z, f->z, sizeof(double) * nz);
    memcpy(b->mode, f->data.gms.mode, sizeof(int) * nz);
    b->x = f->x;
}

static void restore(tf_rt_friction *f, int nz, const rt_backup *b)
{
    memcpy(f->z, b->z, sizeof(double) * nz);
    memcpy(f->data.gms.mode, b->mode, sizeof(int) * nz);
    f->x = b->x;
}

/* A trial step from z0 + d s at Tc + d: its force, and its states into z (f restored). */
static tf_status trial(tf_rt_friction *f, int nz, const rt_backup *b, const double *s, double v, double load,
                       double Tc, double dt, double *F, double *z)
{
    for (int j = 0; j < nz; j++) f->z[j] = b->z[j] + TF_ESTIMATOR_DT * s[j];
    tf_status st = tf_rt_step(f, v, Tc + TF_ESTIMATOR_DT, load, dt, F, 0);
    memcpy(z, f->z, sizeof(double) * nz);
    restore(f, nz, b);
    return st;
}

/* Step 1: f advanced at Tc and the load (tf_rt_step), its force into *F; h = dF/dTc and the new s into s_new (the
 * directional forward difference along (s, 1): z follows Tc). A refused trial step (a law's domain
 * edge within TF_ESTIMATOR_DT): h = 0 and s kept. */
static tf_status friction_step(const tf_temperature_estimator *e, tf_rt_friction *f, int nz, const rt_backup *b,
                               double v, double load, double dt, double *F, double *h, double *s_new,
                               tf_error *err)
{
    double Fp, zp[TF_MAX_FRICTION_STATES];
    double Tc = e->x[0];
    int ok = trial(f, nz, b, e->s, v, load, Tc, dt, &Fp, zp) == TF_OK;
    tf_status st = tf_rt_step(f, v, Tc, load, dt, F, err);
    if (st) return st;
    *h = ok ? (Fp - *F) / TF_ESTIMATOR_DT : 0.0;
    for (int j = 0; j < nz; j++) s_new[j] = ok ? (zp[j] - f->z[j]) / TF_ESTIMATOR_DT : e->s[j];
    return TF_OK;
}

/* The step's decay factors g = 1 - exp(-a dt) of the contact, housing and proxy (a: their rates) into g:
 * e's, kept for the last dt (a constant control period computes them once; tf_temperature_configure
 * forgets them), or computed (the step keeps them when it succeeds). */
static const double *decays(const tf_temperature_estimator *e, double dt, double *g)
{
    const tf_temperature_config *c = &e->c;
    if (dt == e->g_dt) return e->g;
    g[0] = -expm1(-dt / (c->C_th * c->R_th));
    g[1] = e->i_housing >= 0 ? -expm1(-dt * (1.0 / c->R_th + 1.0 / c->R_2) / c->C_2) : 0.0;
    g[2] = e->i_proxy >= 0 ? -expm1(-dt / c->tau_p) : 0.0;
    return g;
}

/* Step 2: the nodes' exponential-Euler step (x in place) and its Jacobian A, at friction power Pw and
 * dPw/dTc = dP, with decay factors g (decays): each node moves the share g of the way to the temperature
 * its neighbours and its heat input hold it at. */
static void heat_predict(const tf_temperature_config *c, int ih, int ip, const double *g, double *x, double A[3][3],
                         double Pw, double dP, double T_amb)
{
    double Tc = x[0], Th = ih >= 0 ? x[ih] : T_amb;
    /* phi = (1 - exp(-a dt)) / a: the contact's a = 1 / (C_th R_th) */
    double phi_c = g[0] * c->C_th * c->R_th;
    double rate_c = (c->eta * Pw - (Tc - Th) / c->R_th) / c->C_th;
    A[0][0] = 1.0 - g[0] + c->eta * dP / c->C_th * phi_c;
    x[0] = Tc + rate_c * phi_c;
    if (ih >= 0) {
        double phi_h = g[1] * c->C_2 / (1.0 / c->R_th + 1.0 / c->R_2);
        double rate_h = ((Tc - Th) / c->R_th - (Th - T_amb) / c->R_2) / c->C_2;
        A[0][ih] = g[0];
        A[ih][0] = phi_h / (c->C_2 * c->R_th);
        A[ih][ih] = 1.0 - g[1];
        x[ih] = Th + rate_h * phi_h;
    }
    if (ip >= 0) {
        int is = c->proxy == TF_PROXY_HOUSING ? ih : 0;
        double src = is == 0 ? Tc : Th;
        A[ip][is] = g[2];
        A[ip][ip] = 1.0 - g[2];
        x[ip] += (src - x[ip]) * g[2];
    }
}

/* P <- A P A' + diag(q) dt over n states. */
static void cov_predict(int n, double P[3][3], double A[3][3], const double *q, const int *qi, double dt)
{
    double AP[3][3] = {{0}};
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            for (int k = 0; k < n; k++) AP[i][j] += A[i][k] * P[k][j];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
            double s = 0.0;
            for (int k = 0; k < n; k++) s += AP[i][k] * A[j][k];
            P[i][j] = s;
        }
    for (int i = 0; i < n; i++) P[i][i] += q[qi[i]] * dt;
}

/* The scalar update with H = g e_m (a measurement y of g x[m], noise r) in Joseph form; returns the
 * change of x[0]. */
static double kalman_update(int n, double *x, double P[3][3], int m, double g, double y, double y_hat, double r)
{
    double PH[3] = {0}, K[3] = {0}, S = g * g * P[m][m] + r;
    for (int i = 0; i < n; i++) PH[i] = g * P[i][m];
    for (int i = 0; i < n; i++) K[i] = PH[i] / S;
    double innov = y - y_hat, dx0 = K[0] * innov;
    for (int i = 0; i < n; i++) x[i] += K[i] * innov;
    /* (I - K H) P (I - K H)' + K r K', with (I - K H) P = P - K (H P) */
    double M[3][3], Q[3][3];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) M[i][j] = P[i][j] - K[i] * PH[j];
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) Q[i][j] = M[i][j] - M[i][m] * g * K[j] + K[i] * r * K[j];
    for (int i = 0; i < n; i++)
        for (int j = 0; j <= i; j++) P[i][j] = P[j][i] = 0.5 * (Q[i][j] + Q[j][i]);
    return dx0;
}

/* Why a step's own arguments are refused, or NULL. */
static const char *step_problem(const tf_temperature_estimator *e, const tf_rt_friction *f, double v, double F_meas,
                                double T_proxy, double T_amb, double dt, const double *F_hat)
{
    if (!e || !f || !F_hat) return "e, f or F_hat (NULL)";
    if (!isfinite(v)) return "v (not finite)";
    if (isinf(F_meas)) return "F_measured (infinite; NaN: none)";
    if (isinf(T_proxy)) return "T_proxy (infinite; NaN: none)";
    if (!isnan(T_proxy) && e->i_proxy < 0) return "T_proxy (given, but the configuration has no proxy)";
    if (!isfinite(T_amb)) return "T_amb (not finite)";
    if (!(isfinite(dt) && dt > 0.0)) return "dt (finite, > 0)";
    return 0;
}

static int all_finite(const tf_temperature_estimator *e, const double *x, double P[3][3], double F)
{
    int ok = isfinite(F);
    for (int i = 0; i < e->n; i++)
        for (int j = 0; j < e->n; j++) ok = ok && isfinite(P[i][j]);
    for (int i = 0; i < e->n; i++) ok = ok && isfinite(x[i]);
    return ok;
}

tf_status tf_temperature_step(tf_temperature_estimator *e, tf_rt_friction *f, double v, double load,
                              double F_measured, double T_proxy, double T_amb, double dt, double *F_hat, tf_error *err)
{
    if (F_hat) *F_hat = NAN;
    const char *bad = step_problem(e, f, v, F_measured, T_proxy, T_amb, dt, F_hat);
    if (bad) return est_done(err, TF_ERR_BAD_ARGUMENT, bad);
    const tf_temperature_config *c = &e->c;
    int n = e->n, nz = friction_nstate(f);
    rt_backup b;
    save(f, nz, &b);
    double F, h, s[TF_MAX_FRICTION_STATES];
    tf_status st = friction_step(e, f, nz, &b, v, load, dt, &F, &h, s, err);
    if (st) return st;
    /* 2. predict: P = |F v|, dP/dTc = sgn(F v) v h */
    double x[3] = {e->x[0], e->x[1], e->x[2]}, P[3][3], A[3][3] = {{0}};
    memcpy(P, e->P, sizeof P);
    double Fv = F * v, dP = (Fv > 0.0 ? 1.0 : Fv < 0.0 ? -1.0 : 0.0) * v * h;
    double g_new[3];
    const double *g = decays(e, dt, g_new);
    heat_predict(c, e->i_housing, e->i_proxy, g, x, A, fabs(Fv), dP, T_amb);
    int qi[3] = {0, 1, 2};
    if (e->i_housing < 0 && e->i_proxy >= 0) qi[1] = 2;
    cov_predict(n, P, A, c->q, qi, dt);
    /* 3. update */
    double dTc = 0.0;
    int gated = 0;
    if (!isnan(F_measured)) {
        gated = fabs(v) < c->v_min || h * h * P[0][0] < TF_ESTIMATOR_GATE * c->r_F;
        if (!gated) dTc += kalman_update(n, x, P, 0, h, F_measured, F, c->r_F);
    }
    if (!isnan(T_proxy)) dTc += kalman_update(n, x, P, e->i_proxy, 1.0, T_proxy, x[e->i_proxy], c->r_p);
    F += h * dTc;
    for (int j = 0; j < nz; j++) f->z[j] += s[j] * dTc;
    if (!all_finite(e, x, P, F)) {
        restore(f, nz, &b);
        return est_done(err, TF_ERR_NONFINITE, "estimate, covariance or force not finite");
    }
    memcpy(e->x, x, sizeof x);
    memcpy(e->P, P, sizeof P);
    memcpy(e->s, s, sizeof(double) * nz);
    e->h = h, e->gated = gated;
    if (g == g_new) memcpy(e->g, g_new, sizeof g_new), e->g_dt = dt;
    *F_hat = F;
    return est_done(err, TF_OK, 0);
}
