/* The C core's own tests: analytic solutions and finite-difference checks, no Python.
 * Prints one line per failed check and a closing "N passed, N failed" line. */
#include "thermofriction.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "../src/friction_private.h" /* tf_friction_affine_set: the exact stepping's, tested here */

/* ---- generic ODE harness: records the emitted grid ---- */
typedef struct { long n; int dim; double *y; } record;
static void emit_record(long i, double t, const double *y, void *ctx)
{
    record *r = (record *)ctx;
    (void)t;
    memcpy(r->y + i * r->dim, y, sizeof(double) * r->dim);
}

static void emit_none(long i, double t, const double *y, void *ctx);
static void paper_like(tf_model *m, double T);

/* The error record of the last call (status.h), and the force or control of a step as a number (NaN
 * when the step is refused: E says why). */
static tf_error E;
static double rt_force(tf_rt_friction *f, double v, double T, double dt)
{
    double F;
    tf_rt_step(f, v, T, NAN, dt, &F, &E);
    return F;
}
static double observer_force(tf_rt_friction *f, double v, double e, double k, double T, double dt)
{
    double F;
    tf_observer_step(f, v, e, k, T, NAN, dt, &F, &E);
    return F;
}
static double pid_u(tf_pid *c, double e, double dt)
{
    double u;
    tf_pid_step(c, e, dt, &u, &E);
    return u;
}

/* harmonic oscillator x'' = -w^2 x */
static tf_status osc_rhs(double t, const double *y, double *dy, void *ctx)
{
    double w = *(double *)ctx;
    dy[0] = y[1];
    dy[1] = -w * w * y[0];
    return 0;
}
static tf_status osc_jac(double t, const double *y, double *J, void *ctx)
{
    double w = *(double *)ctx;
    J[0] = 0; J[1] = 1; J[2] = -w * w; J[3] = 0;
    return 0;
}

/* Prothero-Robinson: y' = -L (y - sin t) + cos t, exact y = sin t; stiff for large L. */
static tf_status pr_rhs(double t, const double *y, double *dy, void *ctx)
{
    double L = *(double *)ctx;
    dy[0] = -L * (y[0] - sin(t)) + cos(t);
    return 0;
}
static tf_status pr_jac(double t, const double *y, double *J, void *ctx)
{
    J[0] = -*(double *)ctx;
    return 0;
}

static void test_oscillator_dense_output(int method)
{
    double w = 2.0 * 3.14159265358979;
    tf_ode ode = {2, &w, osc_rhs, osc_jac, 0};
    double atol[2] = {1e-10, 1e-10};
    tf_solver_options opt = {method, 1e-8, atol, 0, 0, 1000000};
    long n = 1001;
    double *t = malloc(sizeof(double) * n), *buf = malloc(sizeof(double) * 2 * n);
    for (long i = 0; i < n; i++) t[i] = 3.0 * i / (n - 1);
    double y0[2] = {1.0, 0.0};
    record r = {n, 2, buf};
    tf_solver_stats st;
    int status = tf_solve(&ode, &opt, t, n, y0, emit_record, &r, &st, &E);
    CHECK(status == TF_OK, "oscillator method %d status %d", method, status);
    double worst = 0;
    for (long i = 0; i < n; i++) worst = fmax(worst, fabs(buf[2 * i] - cos(w * t[i])));
    /* dense output between steps must be as good as the steps themselves */
    CHECK(worst < 1e-6, "oscillator method %d dense output error %g", method, worst);
    CHECK(st.steps < 2000, "oscillator method %d took %ld steps", method, st.steps);
    free(t); free(buf);
}

/* The interrupt poll (tf_solver_options.interrupt): a long integration stops within TF_POLL_STEPS
 * steps of the poll's answer, with TF_ERR_INTERRUPTED and the state where it stopped (the oscillator's
 * energy, conserved by the exact solution, tells that it is a real state of the run). */
static int polls_left(void *ctx) { return --*(int *)ctx <= 0; }
static void test_interrupt_poll_stops_a_long_integration(int method)
{
    double w = 2.0 * 3.14159265358979;
    tf_ode ode = {2, &w, osc_rhs, osc_jac, 0};
    double atol[2] = {1e-10, 1e-10}, t[2] = {0.0, 1e6}, y[2] = {1.0, 0.0};
    int polls = 5;
    tf_solver_options opt = {.method = method, .rtol = 1e-8, .atol = atol, .max_steps = 1000000000L,
                             .interrupt = polls_left, .interrupt_ctx = &polls};
    tf_solver_stats st;
    int status = tf_solve(&ode, &opt, t, 2, y, emit_none, 0, &st, &E);
    CHECK(status == TF_ERR_INTERRUPTED && E.code == TF_ERR_INTERRUPTED && polls == 0,
          "interrupt (method %d): status %d after %d polls", method, status, 5 - polls);
    CHECK(st.steps + st.rejected <= 5 * TF_POLL_STEPS && st.steps + st.rejected > 4 * TF_POLL_STEPS &&
              E.t > 0.0 && E.t < 1e6,
          "interrupt (method %d): stopped after %ld steps at t = %g", method, st.steps + st.rejected, E.t);
    double energy = y[0] * y[0] + y[1] * y[1] / (w * w);
    CHECK(fabs(energy - 1.0) < 1e-5, "interrupt (method %d): the state at the stop is the run's (energy %g)",
          method, energy);
    polls = 1 << 30; /* a poll that never fires changes nothing */
    double y2[2] = {1.0, 0.0}, t2[2] = {0.0, 3.0}, y3[2] = {1.0, 0.0};
    tf_solve(&ode, &opt, t2, 2, y2, emit_none, 0, &st, &E);
    opt.interrupt = 0;
    tf_solve(&ode, &opt, t2, 2, y3, emit_none, 0, &st, &E);
    CHECK(y2[0] == y3[0] && y2[1] == y3[1], "interrupt (method %d): a silent poll changes no result", method);
}

/* One error record from every entry point (status.h): the code returned, what and where named on a
 * failure, empty on success; the time and the output sample where an integration failed; NULL
 * accepted for the record everywhere. */
static void test_one_error_record_from_every_entry_point(void)
{
    double w = 1.0;
    tf_ode ode = {2, &w, osc_rhs, osc_jac, 0};
    double atol[2] = {1e-9, 1e-9}, y[2] = {1.0, 0.0}, t[4] = {0.0, 0.5, 0.4, 1.0};
    tf_solver_options opt = {.method = TF_METHOD_DOPRI5, .rtol = 1e-8, .atol = atol, .max_steps = 1000};
    tf_solver_stats st;
    tf_status s = tf_solve(&ode, &opt, t, 4, y, emit_none, 0, &st, &E);
    CHECK(s == TF_ERR_BAD_ARGUMENT && E.code == s && !strcmp(E.where, "solver") && strstr(E.what, "t_out") &&
              E.index == 2 && E.t == 0.4,
          "solve: a decreasing grid named at its sample (%s / %s / %ld)", E.where, E.what, E.index);
    t[2] = 0.7;
    opt.max_steps = 3;
    s = tf_solve(&ode, &opt, t, 4, y, emit_none, 0, &st, &E);
    CHECK(s == TF_ERR_MAX_STEPS && E.code == s && !strcmp(E.what, tf_status_message(s)) && E.t > 0.0 && E.t < 1.0,
          "solve: max_steps with the time it stopped at (%g)", E.t);
    opt.max_steps = 100000, y[0] = 1.0, y[1] = 0.0;
    s = tf_solve(&ode, &opt, t, 4, y, emit_none, 0, NULL, &E);
    CHECK(s == TF_OK && E.code == TF_OK && !E.what[0] && !E.where[0] && E.index == -1 && isnan(E.t),
          "solve: TF_OK leaves an empty record (stats may be NULL)");
    CHECK(tf_solve(&ode, &opt, t, 4, y, emit_none, 0, &st, NULL) == TF_OK, "solve: NULL record");

    static tf_model m;
    paper_like(&m, 30.0);
    m.p[TF_P_FC] = -1.0;
    CHECK(tf_model_check(&m, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "fc") && !strcmp(E.where, "model"),
          "model check: fc named (%s / %s)", E.where, E.what);
    CHECK(tf_model_check(&m, NULL) == TF_ERR_BAD_ARGUMENT && tf_model_check(NULL, &E) == TF_ERR_BAD_ARGUMENT,
          "model check: NULL record, NULL model");

    double A[4] = {1.0, 2.0, 2.0, 4.0};
    int piv[2];
    CHECK(tf_lu_factor(A, 2, piv) == TF_ERR_SINGULAR, "lu: a singular matrix has its status");

    tf_pid c;
    CHECK(tf_pid_init(&c, NAN, 0, 0, 0, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.where, "pid") &&
              strstr(E.what, "gains"),
          "pid: the gains named");
    char big[200];
    memset(big, 'x', sizeof big - 1);
    big[sizeof big - 1] = 0;
    CHECK(tf_error_set(&E, TF_ERR_NONFINITE, big, big, 1.0, 7) == TF_ERR_NONFINITE &&
              strlen(E.what) == TF_ERROR_WHAT - 1 && strlen(E.where) == TF_ERROR_WHERE - 1 && E.index == 7,
          "tf_error_set truncates what and where to the record");
}

static void test_stiff_prothero_robinson(void)
{
    double L = 1e7;
    tf_ode ode = {1, &L, pr_rhs, pr_jac, 0};
    double atol[1] = {1e-9};
    double t[2] = {0.0, 10.0};
    double y[1] = {0.0}, out[2];
    record r = {2, 1, out};
    tf_solver_stats st;
    tf_solver_options opt = {TF_METHOD_RODAS4, 1e-6, atol, 0, 0, 100000};
    int status = tf_solve(&ode, &opt, t, 2, y, emit_record, &r, &st, &E);
    CHECK(status == TF_OK && fabs(out[1] - sin(10.0)) < 1e-5, "Rodas4 stiff: status %d err %g",
          status, fabs(out[1] - sin(10.0)));
    CHECK(st.steps < 500, "Rodas4 stiff took %ld steps (should step over the stiff mode)", st.steps);

    /* AUTO starts explicit, detects stiffness and switches */
    y[0] = 0.0;
    opt.method = TF_METHOD_AUTO;
    status = tf_solve(&ode, &opt, t, 2, y, emit_record, &r, &st, &E);
    CHECK(status == TF_OK && st.switch_time >= 0 && st.method_used == TF_METHOD_RODAS4,
          "AUTO did not switch: status %d switch %g", status, st.switch_time);
    CHECK(fabs(out[1] - sin(10.0)) < 1e-5, "AUTO stiff error %g", fabs(out[1] - sin(10.0)));

    /* explicit alone runs out of steps and says it suspected stiffness */
    y[0] = 0.0;
    opt.method = TF_METHOD_DOPRI5;
    opt.max_steps = 5000;
    status = tf_solve(&ode, &opt, t, 2, y, emit_record, &r, &st, &E);
    CHECK(status == TF_ERR_MAX_STEPS && st.stiff_suspected, "DOPRI5 on stiff: status %d suspected %d",
          status, st.stiff_suspected);
}

static void test_waveforms(void)
{
    tf_waveform saw = {TF_WAVE_SAWTOOTH, 30.0, 5.0, 0.99, 0.0, 1.0, 0, 0, 0, 0, 0};
    CHECK(fabs(tf_waveform_value(&saw, 0.198) - 30.0) < 1e-9, "sawtooth peak %g", tf_waveform_value(&saw, 0.198));
    CHECK(fabs(tf_waveform_value(&saw, 0.199) - 15.0) < 1e-9, "sawtooth mid-fall %g", tf_waveform_value(&saw, 0.199));
    CHECK(fabs(tf_waveform_next_corner(&saw, 0.0) - 0.198) < 1e-15, "first corner %g", tf_waveform_next_corner(&saw, 0.0));
    CHECK(fabs(tf_waveform_next_corner(&saw, 0.198) - 0.2) < 1e-15, "second corner");
    CHECK(fabs(tf_waveform_slope(&saw, 0.1) - 30.0 / 0.198) < 1e-9, "rising slope");
    tf_waveform back = saw;
    back.direction = -1.0;
    CHECK(fabs(tf_waveform_value(&back, 0.002) - 30.0) < 1e-9, "mirrored sawtooth peaks at (1-rise)/f");
    CHECK(fabs(tf_waveform_next_corner(&back, 0.0) - 0.002) < 1e-15, "mirrored corner");
    double v = 0;
    for (int i = 0; i < 1000; i++) { /* continuity at every corner */
        double tc = tf_waveform_next_corner(&saw, v);
        double jump = fabs(tf_waveform_value(&saw, tc + 1e-12) - tf_waveform_value(&saw, tc - 1e-12));
        if (jump > 1e-6) { CHECK(0, "sawtooth jumps %g at %g", jump, tc); break; }
        v = tc;
    }
    CHECK(fabs(v - 100.0) < 1e-9, "1000 corners of a 5 Hz sawtooth end at 100 s, got %.15g", v);
    double ts[3] = {0.0, 1.0, 3.0}, vs[3] = {0.0, 2.0, 0.0};
    tf_waveform smp = {TF_WAVE_SAMPLED, 0, 0, 0, 0, 0, 0, 0, ts, vs, 3};
    CHECK(fabs(tf_waveform_value(&smp, 2.0) - 1.0) < 1e-15 && tf_waveform_next_corner(&smp, 0.5) == 1.0,
          "sampled waveform");
}

static void test_laws(void)
{
    double x[5] = {30, 32, 35, 38.4, 41.5}, y[5] = {1.0, 0.9, 0.85, 0.5, 0.1}, d[5];
    tf_pchip_slopes(5, x, y, d);
    tf_law table = {TF_LAW_TABLE, 0, 0, 5, x, y, d};
    double prev = INFINITY, worst = 0;
    for (int i = 0; i <= 1150; i++) {
        double T = 30.0 + i * 0.01, dv;
        double v = tf_law_eval(&table, T, &dv);
        if (v > prev + 1e-15) { CHECK(0, "PCHIP not monotone at %g", T); break; }
        prev = v;
        double h = 1e-6;
        double fd = (tf_law_eval(&table, T + h, 0) - tf_law_eval(&table, T - h, 0)) / (2 * h);
        if (fabs(T - 32) > 2e-6 && fabs(T - 35) > 2e-6 && fabs(T - 38.4) > 2e-6) worst = fmax(worst, fabs(fd - dv));
    }
    CHECK(worst < 1e-6, "PCHIP derivative vs finite difference %g", worst);
    for (int i = 0; i < 5; i++) CHECK(fabs(tf_law_eval(&table, x[i], 0) - y[i]) < 1e-14, "PCHIP interpolates");
    double c[3] = {1.0, -2.0, 0.5};
    tf_law poly = {TF_LAW_POLY, 0, 0, 3, 0, c, 0};
    double dv, v = tf_law_eval(&poly, 3.0, &dv);
    CHECK(fabs(v - (1 - 6 + 4.5)) < 1e-14 && fabs(dv - (-2 + 3.0)) < 1e-14, "poly value %g slope %g", v, dv);
    tf_law e = {TF_LAW_EXP, 115072.0, -0.136, 0, 0, 0, 0};
    CHECK(fabs(tf_law_eval(&e, 35.0, 0) - 115072.0 * exp(-0.136 * 35.0)) < 1e-9, "exp law (Eq. 9)");
}

static void paper_like(tf_model *m, double T)
{
    memset(m, 0, sizeof *m);
    m->plant = TF_PLANT_STICK_SLIP;
    m->m = 0.05; m->m_e = 0.02;
    double wn = 6685.5, xi = 0.2488, K = 0.096e-6;
    m->k = m->m * wn * wn; m->c = 2 * xi * wn * m->m; m->T_em = K * m->k;
    m->friction = TF_FRICTION_LUGRE;
    m->p[TF_P_SIGMA0] = 1.15072e8 * exp(-0.136 * T);
    m->p[TF_P_SIGMA1] = -0.138 * T + 6.445;
    m->p[TF_P_FC] = m->p[TF_P_FS] = 106.04 * exp(-0.159 * T);
    m->p[TF_P_VS] = 1e-3; m->p[TF_P_DELTA] = 2; m->p[TF_P_VSMOOTH] = 1e-6;
    m->input = (tf_waveform){TF_WAVE_SAWTOOTH, 30.0, 5.0, 0.999, 0.0, 1.0, 0, 0, 0, 0, 0};
    m->T_const = T;
}

static void test_lugre_steady_sliding(void)
{
    /* analytic: z* = g(v) sgn(v) / sigma0, F = g(v) sgn(v) + sigma2 v */
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5; p[TF_P_SIGMA1] = 316; p[TF_P_SIGMA2] = 0.4;
    p[TF_P_FC] = 1.0; p[TF_P_FS] = 1.5; p[TF_P_VS] = 1e-3; p[TF_P_DELTA] = 2.0; p[TF_P_VD] = 2e-3;
    double vs[4] = {-0.01, -1e-3, 5e-4, 0.02};
    for (int i = 0; i < 4; i++) {
        double v = vs[i], g = tf_stribeck(p, v, 0);
        double z = (v > 0 ? g : -g) / p[TF_P_SIGMA0], dz;
        double F = tf_friction_eval(TF_FRICTION_LUGRE, p, 0, v, &z, &dz, 0, 0);
        CHECK(fabs(dz) < 1e-12 && fabs(F - ((v > 0 ? g : -g) + 0.4 * v)) < 1e-12, "LuGre steady sliding at v=%g", v);
    }
}

static void test_jacobian_vs_finite_differences(void)
{
    tf_model m;
    tf_model_data md;
    paper_like(&m, 35.0);
    m.p[TF_P_FS] = 1.5 * m.p[TF_P_FC];
    m.p[TF_P_SIGMA2] = 0.3;
    m.p[TF_P_VD] = 2e-3;
    for (int form = 0; form < 3; form++) {
        double dFx[2] = {30.0, 41.5}, dFy[2] = {0.0, -0.2};
        if (form > 0) {
            m.thermal = TF_THERMAL_MODEL_II;
            m.dF = (tf_law){TF_LAW_PWL, 0, 0, 2, dFx, dFy, 0};
            m.dF_form = form == 1 ? TF_DF_SCALE : TF_DF_OFFSET;
        }
        tf_model_data_init(&md, &m);
        double y[5] = {1e-7, 2e-3, 3e-7, -1e-3, 2e-7}, J[25], f0[5], f1[5], f2[5];
        tf_model_jac(0.01, y, J, &md);
        tf_model_rhs(0.01, y, f0, &md);
        double worst = 0;
        for (int j = 0; j < 5; j++) {
            double yp[5], ym[5];
            memcpy(yp, y, sizeof y); memcpy(ym, y, sizeof y);
            double h = 1e-7 * fmax(fabs(y[j]), 1e-9);
            yp[j] += h; ym[j] -= h;
            tf_model_rhs(0.01, yp, f1, &md);
            tf_model_rhs(0.01, ym, f2, &md);
            for (int i = 0; i < 5; i++) {
                double fd = (f1[i] - f2[i]) / (2 * h);
                double scale = fabs(fd) + fabs(J[i * 5 + j]) + 1e-300;
                if (fabs(fd - J[i * 5 + j]) > 1e-5 * scale + 1e-12 * (fabs(f0[i]) / fmax(fabs(y[j]), 1e-12)))
                    worst = fmax(worst, fabs(fd - J[i * 5 + j]) / scale);
            }
        }
        CHECK(worst == 0, "Jacobian vs finite differences (thermal form %d): worst relative error %g", form, worst);
    }
}

static void emit_stage(long i, double t, const double *y, void *ctx) { ((double *)ctx)[i] = y[0]; }

static void test_frictionless_step_response(void)
{
    /* friction removed: the stage is an exact damped second-order system under a unit step */
    tf_model m;
    tf_model_data md;
    paper_like(&m, 35.0);
    m.p[TF_P_SIGMA0] = m.p[TF_P_SIGMA1] = 0.0;
    m.p[TF_P_FC] = m.p[TF_P_FS] = 1.0;
    m.input = (tf_waveform){TF_WAVE_STEP, 10.0, 0, 0, 0, 0, 0.0, 1e-3, 0, 0, 0};
    tf_model_data_init(&md, &m);
    int n = tf_model_nstate(&m);
    double atol[5], y[5];
    tf_model_state_scale(&m, atol);
    for (int i = 0; i < n; i++) atol[i] *= 1e-8;
    tf_model_initial_state(&m, y);
    tf_ode ode = tf_model_ode(&md);
    long N = 201;
    double t[201], xp[201];
    for (int i = 0; i < N; i++) t[i] = 5e-3 * i / (N - 1);
    for (int method = 1; method <= 2; method++) {
        tf_solver_options opt = {method, 1e-8, atol, 0, 0, 100000};
        tf_solver_stats st;
        tf_model_initial_state(&m, y);
        int status = tf_solve(&ode, &opt, t, N, y, emit_stage, xp, &st, &E);
        double wn = 6685.5, xi = 0.2488, K = 0.096e-6, wd = wn * sqrt(1 - xi * xi), worst = 0;
        for (int i = 0; i < N; i++) {
            double tau = t[i] - 1e-3, exact = 0;
            if (tau > 0) exact = 10.0 * K * (1 - exp(-xi * wn * tau) * (cos(wd * tau) + xi / sqrt(1 - xi * xi) * sin(wd * tau)));
            worst = fmax(worst, fabs(xp[i] - exact));
        }
        CHECK(status == TF_OK && worst < 1e-6 * 10.0 * K, "step response method %d: status %d error %g m", method, status, worst);
    }
}

static void emit_none(long i, double t, const double *y, void *ctx) { (void)i; (void)t; (void)y; (void)ctx; }

static void test_grid_end_one_ulp_past_a_corner(void)
{
    /* the last output time can sit a rounding error past a corner: no spurious underflow */
    tf_model m;
    tf_model_data md;
    paper_like(&m, 35.0);
    m.input.rise = 0.999;
    tf_model_data_init(&md, &m);
    double atol[5], y[5];
    tf_model_state_scale(&m, atol);
    for (int i = 0; i < 5; i++) atol[i] *= 1e-6;
    tf_ode ode = tf_model_ode(&md);
    tf_solver_options opt = {TF_METHOD_DOPRI5, 1e-6, atol, 0, 0, 1000000};
    tf_solver_stats st;
    double corner = 3.0 / 5.0;
    double ends[3] = {nextafter(corner, 1.0), nextafter(nextafter(corner, 1.0), 1.0), nextafter(corner, 0.0)};
    for (int k = 0; k < 3; k++) {
        double t[2] = {0.0, ends[k]};
        tf_model_initial_state(&m, y);
        int status = tf_solve(&ode, &opt, t, 2, y, emit_none, 0, &st, &E);
        CHECK(status == TF_OK, "end %.17g next to the corner %.17g: status %d", ends[k], corner, status);
    }
}

static void test_parameter_derivatives_vs_finite_differences(void)
{
    /* df/dtheta of tf_model_derivatives against central differences of the right-hand side */
    double dFx[3] = {30.0, 38.4, 41.5}, dFy[3] = {0.0, -0.145, -0.4775};
    for (int form = 0; form < 3; form++) {
        tf_model m;
        tf_model_data md;
        paper_like(&m, 36.0);
        m.p[TF_P_FS] = 1.4 * m.p[TF_P_FC];
        m.p[TF_P_SIGMA2] = 0.3;
        m.p[TF_P_VD] = 2e-3;
        m.T_const = 36.0;
        tf_target tg[8] = {{TF_TARGET_PARAM, TF_P_SIGMA0, 0}, {TF_TARGET_PARAM, TF_P_SIGMA1, 0},
                           {TF_TARGET_PARAM, TF_P_FC, 0},     {TF_TARGET_PARAM, TF_P_FS, 0},
                           {TF_TARGET_PARAM, TF_P_VS, 0},     {TF_TARGET_PARAM, TF_P_VD, 0},
                           {TF_TARGET_PARAM, TF_P_SIGMA2, 0}, {TF_TARGET_DF, 0, 1}};
        int np = 7;
        if (form > 0) {
            m.thermal = TF_THERMAL_MODEL_II;
            m.dF = (tf_law){TF_LAW_PWL, 0, 0, 3, dFx, dFy, 0};
            m.dF_form = form == 1 ? TF_DF_SCALE : TF_DF_OFFSET;
            np = 8;
        }
        tf_model_data_init(&md, &m);
        double y[5] = {1e-7, 2e-3, 3e-7, -1e-3, 2e-7}, dy[5], fp[5 * 8], f1[5], f2[5];
        tf_model_derivatives(&md, 0.01, y, dy, 0, tg, np, fp);
        double worst = 0;
        for (int k = 0; k < np; k++) {
            double *slot = tg[k].kind == TF_TARGET_DF ? &dFy[tg[k].coef] : &m.p[tg[k].param];
            double save = *slot, h = 1e-6 * fabs(save);
            *slot = save + h; tf_model_data_init(&md, &m); tf_model_rhs(0.01, y, f1, &md);
            *slot = save - h; tf_model_data_init(&md, &m); tf_model_rhs(0.01, y, f2, &md);
            *slot = save; tf_model_data_init(&md, &m);
            for (int i = 0; i < 5; i++) {
                double fd = (f1[i] - f2[i]) / (2 * h), an = fp[i * np + k];
                double err = fabs(fd - an) / (fabs(fd) + fabs(an) + 1e-300);
                if (fabs(fd - an) > 1e-6 * (fabs(fd) + fabs(an)) + 1e-9 * fabs(dy[i]) / fabs(save)) {
                    worst = fmax(worst, err);
                    printf("  form %d target %d state %d: fd %g analytic %g\n", form, k, i, fd, an);
                }
            }
        }
        CHECK(worst == 0, "parameter derivatives (thermal form %d): worst relative error %g", form, worst);
    }
}

static void test_lu_solves_systems_that_need_pivoting_in_later_columns(void)
{
    /* pseudo-random 6x6 systems with a known solution; residual and solution error are checked
     * (a solve that mixes up where the interchanges happened fails the moment a pivot is taken
     * after the first column) */
    unsigned long seed = 12345;
    double worst = 0.0;
    int pivots_after_first = 0;
    for (int trial = 0; trial < 200; trial++) {
        int n = 6, piv[6];
        double A[36], LU[36], x[6], b[6];
        for (int i = 0; i < n * n; i++) {
            seed = seed * 6364136223846793005UL + 1442695040888963407UL;
            A[i] = ((double)(seed >> 11) / 9007199254740992.0) * 2.0 - 1.0;
        }
        for (int i = 0; i < n; i++) x[i] = i + 1.0;
        for (int i = 0; i < n; i++) { b[i] = 0; for (int j = 0; j < n; j++) b[i] += A[i * n + j] * x[j]; }
        memcpy(LU, A, sizeof A);
        if (tf_lu_factor(LU, n, piv)) continue;
        for (int k = 1; k < n; k++) pivots_after_first += piv[k] != k;
        tf_lu_solve(LU, n, piv, b);
        for (int i = 0; i < n; i++) worst = fmax(worst, fabs(b[i] - x[i]) / (i + 1.0));
    }
    CHECK(pivots_after_first > 50, "the test must exercise later pivots (%d)", pivots_after_first);
    CHECK(worst < 1e-8, "LU solve error %g", worst);
}

typedef struct { int dim; double *F; tf_model_data *m; } force_record;
static void emit_force(long i, double t, const double *y, void *ctx)
{
    force_record *r = (force_record *)ctx;
    r->F[i] = tf_model_friction(r->m, t, y);
}

/* One GMS element (k = 1e5 N/m, capacity fc = 2 N, C = 50 /s) under prescribed motion: the analytic case of the
 * two tests below. */
static void single_gms_element(tf_model *m)
{
    memset(m, 0, sizeof *m);
    m->plant = TF_PLANT_PRESCRIBED;
    m->friction = TF_FRICTION_GMS;
    m->p[TF_P_FC] = m->p[TF_P_FS] = 2.0;
    m->p[TF_P_VS] = 1e-3;
    m->p[TF_P_DELTA] = 2.0;
    m->p[TF_P_C] = 50.0;
    m->p[TF_P_VSMOOTH] = 1e-6;
    m->gms.n = 1;
    m->gms.k[0] = 1e5;
    m->gms.w[0] = 1.0;
}

static void test_gms_element_breaks_loose_exactly_at_its_capacity(void)
{
    /* One GMS element under prescribed motion x = v t: it sticks (F = k v t) until F reaches its
     * capacity w fc at t* = w fc / (k v), exactly: the switch is a located event, then it slips
     * (F -> w fc at rate C) and, when the motion reverses at the sawtooth's corner, sticks again
     * (F falls at k v' from where it was). Analytic solution, every method. */
    tf_model m;
    tf_model_data md;
    single_gms_element(&m);
    m.T_const = NAN;
    /* up at 1e-4 m/s for 0.6 s, down for 0.4 s (sawtooth, amplitude 6e-5 m, 1 Hz, rise 0.6) */
    m.input = (tf_waveform){TF_WAVE_SAWTOOTH, 6e-5, 1.0, 0.6, 0.0, 1.0, 0, 0, 0, 0, 0};
    tf_model_data_init(&md, &m);
    double v = 1e-4, k = 1e5, fc = 2.0, t_star = fc / (k * v); /* 0.2 s */
    double t[6] = {0.0, 0.1, t_star, 0.4, 0.6, 0.7};
    double exact[6];
    exact[0] = 0.0;
    exact[1] = k * v * 0.1;
    exact[2] = fc;
    exact[3] = fc; /* slipping at capacity: F' = C (1 - F / fc) = 0 */
    exact[4] = fc;
    double vdown = -6e-5 / 0.4;
    exact[5] = fc + k * vdown * 0.1; /* stuck again after the reversal */
    for (int method = 1; method <= 2; method++) {
        double y[1] = {0.0}, atol[1] = {1e-12}, F[6];
        force_record r = {1, F, &md};
        tf_ode ode = tf_model_ode(&md);
        tf_solver_options opt = {method, 1e-9, atol, 0, 0, 100000};
        tf_solver_stats st;
        memset(md.gms.mode, 0, sizeof md.gms.mode);
        int status = tf_solve(&ode, &opt, t, 6, y, emit_force, &r, &st, &E);
        double worst = 0.0;
        for (int i = 0; i < 6; i++) worst = fmax(worst, fabs(F[i] - exact[i]));
        CHECK(status == TF_OK && worst < 1e-6 * fc && st.events >= 2,
              "GMS single element, method %d: status %d, worst force error %g N, %ld events", method, status, worst,
              st.events);
    }
}

static void test_prescribed_exact_stepping_gms_and_its_record(void)
{
    /* tf_prescribed_force on the analytic GMS case above, the motion as a sampled position (up at 1e-4 m/s
     * for 0.6 s, down at -1.5e-4 m/s for 0.4 s): F = k v t until the capacity fc at t* = 0.2 s, then fc, then
     * fc + k v' (t - 0.6) after the reversal; dF/dfc = 0 before t* and 1 after (the capacity w g = fc moves
     * the force once the element has slipped), dF/dC = 0 throughout (it slips at its fixed point). Then the
     * one error record: a decreasing grid, a model it does not apply to. */
    tf_model m;
    single_gms_element(&m);
    m.fs_follows_fc = 1;
    m.T_const = 25.0;
    static const double kt[3] = {0.0, 0.6, 1.0}, kx[3] = {0.0, 6e-5, 0.0};
    m.input = (tf_waveform){TF_WAVE_SAMPLED, 0, 0, 0, 0, 1.0, 0, 0, kt, kx, 3};
    double k = 1e5, fc = 2.0, v = 1e-4, vdown = -1.5e-4;
    double t[6] = {0.0, 0.1, 0.25, 0.4, 0.6, 0.7}, F[6], dF[12];
    double exact[6] = {0.0, k * v * 0.1, fc, fc, fc, fc + k * vdown * 0.1};
    double dfc[6] = {0, 0, 1, 1, 1, 1};
    int params[2] = {TF_P_FC, TF_P_C};
    tf_status s = tf_prescribed_force(&m, 6, t, F, 2, params, dF, &E);
    double worst = 0.0, worst_d = 0.0;
    for (int i = 0; i < 6; i++) {
        worst = fmax(worst, fabs(F[i] - exact[i]));
        worst_d = fmax(worst_d, fmax(fabs(dF[2 * i] - dfc[i]), fabs(dF[2 * i + 1])));
    }
    CHECK(s == TF_OK && E.code == TF_OK && worst < 1e-12 * fc && worst_d < 1e-12,
          "prescribed GMS: status %d, worst force error %g N, worst derivative error %g", s, worst, worst_d);
    t[3] = 0.2;
    s = tf_prescribed_force(&m, 6, t, F, 0, NULL, NULL, &E);
    CHECK(s == TF_ERR_BAD_ARGUMENT && E.code == s && !strcmp(E.where, "prescribed") && strstr(E.what, "t_out") &&
              E.index == 3, "prescribed: a decreasing grid named at its sample (%s / %s / %ld)", E.where, E.what, E.index);
    t[3] = 0.4;
    m.thermal = TF_THERMAL_MODEL_II;
    CHECK(!tf_prescribed_applies(&m) && tf_prescribed_force(&m, 6, t, F, 0, NULL, NULL, &E) == TF_ERR_BAD_ARGUMENT &&
              strstr(E.what, "model"), "prescribed: Model II is refused (%s)", E.what);
}

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The elasto-plastic transition's rate per unit displacement, dy/dx = 1 - alpha(y) y / z_ss with the half
 * sine alpha = 1/2 + sin(pi (y - (z_ss + z_ba) / 2) / (z_ss - z_ba)) / 2 (docs/models.md). */
static double ep_rate(double y, double zss, double zba)
{
    double alpha = 0.5 + 0.5 * sin(M_PI * (y - 0.5 * (zss + zba)) / (zss - zba));
    return 1.0 - alpha * y / zss;
}

/* The largest change of a sine motion's velocity A w cos(w t) within [t, t + h] (sampled at 200 points), in units
 * of the larger of |v(t)| and vs. */
static double sine_velocity_change(double A, double w, double t, double h, double vs)
{
    double v0 = A * w * cos(w * t), dv = 0.0;
    for (int k = 1; k <= 200; k++) dv = fmax(dv, fabs(A * w * cos(w * (t + k * h / 200.0)) - v0));
    return dv / fmax(fabs(v0), vs);
}

static void test_prescribed_sine_step_limit(void)
{
    /* A prescribed motion's velocity is no state, so that no error estimate sees it: tf_model_max_step holds every
     * step to a change of the velocity of at most half the larger of |v| at its start and the Stribeck velocity
     * (analytic: the sine's velocity, sampled within each step), and no tighter than that near a reversal, where
     * the acceleration peaks (the change reaches 0.45 of vs); the narrower band where the two sides' differ; no limit for a piecewise-linear motion (constant velocity between corners) or without a Stribeck effect. */
    tf_model m;
    memset(&m, 0, sizeof m);
    m.plant = TF_PLANT_PRESCRIBED;
    m.friction = TF_FRICTION_LUGRE;
    m.p[TF_P_SIGMA0] = 1e5, m.p[TF_P_SIGMA1] = 316.0, m.p[TF_P_FC] = 1.0, m.p[TF_P_FS] = 1.5;
    m.p[TF_P_VS] = 1e-3, m.p[TF_P_DELTA] = 2.0;
    m.T_const = 25.0;
    const double A = 2e-3, w = 2.0 * M_PI, vs = 1e-3;
    m.input = (tf_waveform){TF_WAVE_SINE, A, 1.0, 0, 0, 0, 0, 0, 0, 0, 0};
    tf_model_data md;
    tf_model_data_init(&md, &m);
    tf_ode ode = tf_model_ode(&md);
    CHECK(ode.max_step == tf_model_max_step, "a prescribed motion's ODE limits its steps");
    double y[1] = {0.0}, worst = 0.0, near_reversal = 0.0;
    for (int i = 0; i < 1000; i++) {
        double t = 1e-3 * i, h = tf_model_max_step(t, y, &md), r = sine_velocity_change(A, w, t, h, vs);
        worst = fmax(worst, r);
        if (fabs(A * w * cos(w * t)) < vs) near_reversal = fmax(near_reversal, r);
    }
    CHECK(worst <= 0.5 * (1.0 + 1e-12) && near_reversal > 0.45,
          "sine step limit: velocity change %g of max(|v|, vs) (at most 0.5), %g near a reversal", worst, near_reversal);
    m.p[TF_P_VS_NEG] = 2e-4, m.p[TF_P_FS_NEG] = 1.3; /* the negative side: a narrower band */
    tf_model_data_changed(&md);
    double h_neg = tf_model_max_step(0.75, y, &md);
    CHECK(fabs(h_neg - 0.5 * 2e-4 / (A * w * w)) < 1e-9 * h_neg, "the narrower side's band: %g s", h_neg);
    m.p[TF_P_VS_NEG] = m.p[TF_P_FS_NEG] = 0.0, m.p[TF_P_FS] = m.p[TF_P_FC];
    tf_model_data_changed(&md);
    CHECK(isinf(tf_model_max_step(0.75, y, &md)), "no Stribeck effect: no limit");
    m.p[TF_P_FS] = 1.5;
    m.input = (tf_waveform){TF_WAVE_SAWTOOTH, A, 1.0, 0.5, 0.0, 1.0, 0, 0, 0, 0, 0};
    tf_model_data_changed(&md);
    CHECK(isinf(tf_model_max_step(0.2, y, &md)), "a piecewise-linear motion: no limit");
}

static void test_prescribed_exact_stepping_elastoplastic(void)
{
    /* tf_prescribed_force on the elasto-plastic bristle from rest at a constant velocity v (sigma1 = sigma2 = 0,
     * fs = fc: F = sigma0 z, z_ss = fc / sigma0). Analytic: z = v t up to z_ba (elastic), then the time at which
     * z reaches y in the band is t_ba + (1/v) integral_{z_ba}^{y} dy / (1 - alpha y / z_ss), a quadrature
     * (composite Simpson, 200,000 panels) independent of the stepping; one sample far into the steady state
     * (where F = fc to rounding). Both directions of motion. */
    tf_model m;
    memset(&m, 0, sizeof m);
    m.plant = TF_PLANT_PRESCRIBED;
    m.friction = TF_FRICTION_ELASTOPLASTIC;
    double s0 = 2e4, fc = 1.5, zss = fc / s0, zba = 0.3 * zss, v = 2e-3;
    m.p[TF_P_SIGMA0] = s0;
    m.p[TF_P_FC] = m.p[TF_P_FS] = fc;
    m.p[TF_P_VS] = 1e-3;
    m.p[TF_P_DELTA] = 2.0;
    m.p[TF_P_ZBA] = zba;
    m.p[TF_P_VSMOOTH] = 1e-6;
    m.fs_follows_fc = 1;
    m.T_const = 25.0;
    double ys[5] = {0.5 * zba, zba + 0.25 * (zss - zba), zba + 0.75 * (zss - zba), zss - 1e-4 * (zss - zba), 0.0};
    double t[6] = {0.0}, F[6];
    for (int k = 0; k < 4; k++) {
        double y0 = k == 0 ? 0.0 : zba, y1 = ys[k], sum = 0.0;
        int n = 200000;
        if (k == 0) {
            t[k + 1] = ys[0] / v;
            continue;
        }
        double hq = (y1 - y0) / n;
        for (int i = 0; i <= n; i++) {
            double wgt = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
            sum += wgt / ep_rate(y0 + i * hq, zss, zba);
        }
        t[k + 1] = zba / v + sum * hq / 3.0 / v;
    }
    t[5] = t[4] + 60.0 * zss / v;
    ys[4] = zss;
    for (int dir = 1; dir >= -1; dir -= 2) {
        static double kt[2] = {0.0, 10.0}, kx[2];
        kx[1] = dir * v * 10.0;
        m.input = (tf_waveform){TF_WAVE_SAMPLED, 0, 0, 0, 0, 1.0, 0, 0, kt, kx, 2};
        tf_status s = tf_prescribed_force(&m, 6, t, F, 0, NULL, NULL, &E);
        double worst = fabs(F[0]);
        for (int k = 0; k < 5; k++) worst = fmax(worst, fabs(F[k + 1] - dir * s0 * ys[k]));
        CHECK(s == TF_OK && tf_prescribed_applies(&m) && worst < 1e-9 * fc,
              "prescribed elasto-plastic, direction %d: status %d, worst force error %g N", dir, s, worst);
    }
}

/* Real-time API (realtime.h, control.h). */
static void rt_lugre(tf_rt_friction *f)
{
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5, p[TF_P_SIGMA1] = 316.2, p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0, p[TF_P_VSMOOTH] = 1e-6;
    CHECK(tf_rt_init(f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_OK, "tf_rt_init");
}

static void test_rt_exact_for_constant_velocity_and_stable_at_large_steps(void)
{
    /* Oracle (analytic): at constant v, z(t) = z_ss (1 - exp(-sigma0 |v| t / g(v))), z_ss = g/sigma0:
     * the exponential step is exact for any dt, and F -> g(v) + sigma2 v in sliding. */
    static tf_rt_friction f;
    double v = 2e-3, g = 1.0 + 0.5 * exp(-4.0), zss = g / 1e5;
    double dts[] = {1e-6, 1e-4, 1e-2};
    for (int k = 0; k < 3; k++) {
        rt_lugre(&f);
        double t = 0.0, worst = 0.0, F = 0.0;
        for (int i = 0; i < 2000; i++) {
            F = rt_force(&f, v, NAN, dts[k]);
            t += dts[k];
            worst = fmax(worst, fabs(f.z[0] - zss * -expm1(-1e5 * v * t / g)) / zss);
        }
        CHECK(worst < 1e-12, "rt LuGre at dt %g: z off the exact solution by %g", dts[k], worst);
        if (dts[k] >= 1e-4) CHECK(fabs(F - (g + 0.4 * v)) < 1e-9, "rt LuGre sliding force %g at dt %g", F, dts[k]);
    }
}

static void test_rt_observer_converges(void)
{
    /* Oracle (analytic): with e = 0 the observer error z^ - z of LuGre at constant v decays as
     * exp(-sigma0 |v| t / g(v)); from z^(0) = -z_ss it is below 1e-9 z_ss after 25 time constants. */
    static tf_rt_friction plant, obs;
    rt_lugre(&plant);
    rt_lugre(&obs);
    double v = 2e-3, g = 1.0 + 0.5 * exp(-4.0), tau = g / (1e5 * v), dt = 1e-5;
    obs.z[0] = -g / 1e5;
    double F = 0.0, Fh = 0.0;
    for (int i = 0; i < (int)(25 * tau / dt); i++) {
        F = rt_force(&plant, v, NAN, dt);
        Fh = observer_force(&obs, v, 0.0, 100.0, NAN, dt);
    }
    CHECK(fabs(obs.z[0] - plant.z[0]) < 1e-9 * g / 1e5, "observer error %g", obs.z[0] - plant.z[0]);
    CHECK(fabs(Fh - F) < 1e-8, "observer force %g vs %g", Fh, F);
}

static void test_rt_parameter_update_and_reset(void)
{
    /* Oracle (analytic): in steady sliding F = g(v) + sigma2 v, so raising sigma2 by 1 N s/m at run
     * time raises F by v at once; reset returns the state to rest (F = sigma2 v + sigma1 v at z = 0). */
    static tf_rt_friction f;
    rt_lugre(&f);
    double v = 0.1, F0 = 0.0, F1;
    for (int i = 0; i < 100; i++) F0 = rt_force(&f, v, NAN, 1e-3);
    CHECK(tf_rt_set_param(&f, TF_P_SIGMA2, 1.4, &E) == TF_OK, "set_param");
    F1 = rt_force(&f, v, NAN, 1e-3);
    CHECK(fabs(F1 - F0 - v) < 1e-12, "sigma2 update: %g -> %g", F0, F1);
    CHECK(tf_rt_set_param(&f, TF_NPARAM, 1.0, &E) == TF_ERR_BAD_ARGUMENT, "bad parameter index accepted");
    tf_rt_reset(&f, &E);
    CHECK(f.z[0] == 0.0 && fabs(rt_force(&f, v, NAN, 0.0) - (1.4 + 316.2) * v) < 1e-12, "reset to rest");
}

/* The shared helpers of friction.h and thermal.h against central differences: sigma1(v) in v,
 * sigma1 and vd; Model II's force in v (offset form); the heat balance in T and its parameters. */
static void test_sigma1_thermal_force_and_heat_rate_partials(void)
{
    double p[TF_NPARAM] = {0}, q[TF_NPARAM];
    p[TF_P_SIGMA1] = 3.0; p[TF_P_VD] = 2e-3;
    double v = 1.3e-3, d_dv, d_ds1, d_dvd;
    double s1 = tf_sigma1(p, v, &d_dv, &d_ds1, &d_dvd);
    CHECK(fabs(s1 - 3.0 * exp(-(v / 2e-3) * (v / 2e-3))) < 1e-15, "sigma1(v)");
    double h = 1e-9;
    CHECK(fabs(d_dv - (tf_sigma1(p, v + h, 0, 0, 0) - tf_sigma1(p, v - h, 0, 0, 0)) / (2 * h)) < 1e-6 * fabs(d_dv),
          "dsigma1/dv");
    memcpy(q, p, sizeof q); q[TF_P_SIGMA1] += 1e-6;
    CHECK(fabs(d_ds1 - (tf_sigma1(q, v, 0, 0, 0) - s1) / 1e-6) < 1e-8, "dsigma1/dsigma1");
    memcpy(q, p, sizeof q); q[TF_P_VD] += 1e-10;
    double fd = tf_sigma1(q, v, 0, 0, 0);
    q[TF_P_VD] -= 2e-10;
    fd = (fd - tf_sigma1(q, v, 0, 0, 0)) / 2e-10;
    CHECK(fabs(d_dvd - fd) < 1e-6 * fabs(d_dvd), "dsigma1/dvd");
    p[TF_P_VD] = 0.0;
    CHECK(tf_sigma1(p, v, &d_dv, &d_ds1, &d_dvd) == 3.0 && d_dv == 0.0 && d_ds1 == 1.0 && d_dvd == 0.0,
          "sigma1 constant for vd <= 0");

    tf_friction_partials jac;
    memset(&jac, 0, sizeof jac);
    jac.dF_dv = 2.0; jac.dF_dz[0] = 5.0;
    double vs = 1e-4, lambda = 0.8, off = 0.3, Fb = 1.5;
    double F = tf_thermal_force(Fb, v, vs, lambda, off, 1, &jac);
    CHECK(F == lambda * Fb + off * tanh(v / vs), "Model II force");
    double dv = 1e-9, Fp = tf_thermal_force(Fb + 2.0 * dv, v + dv, vs, lambda, off, 0, 0),
           Fm = tf_thermal_force(Fb - 2.0 * dv, v - dv, vs, lambda, off, 0, 0);
    CHECK(fabs(jac.dF_dv - (Fp - Fm) / (2 * dv)) < 1e-6 * fabs(jac.dF_dv) && jac.dF_dz[0] == 5.0 * lambda,
          "Model II force partials");

    tf_heat heat;
    memset(&heat, 0, sizeof heat);
    heat.on = 1; heat.C_th = 0.01; heat.R_th = 200.0; heat.eta = 0.8; heat.T_amb = 25.0;
    double T = 31.0, P = 0.02, rate = tf_heat_rate(&heat, 0.0, T, P);
    CHECK(fabs(rate - (0.8 * P - (T - 25.0) / 200.0) / 0.01) < 1e-12, "heat rate");
    double row[3], dP[3] = {0.0, 0.5, 0.0};
    tf_heat_rate_jacobian(&heat, 3, 2, dP, row);
    CHECK(fabs(row[1] - 0.8 * 0.5 / 0.01) < 1e-12 && fabs(row[2] + 1.0 / (200.0 * 0.01)) < 1e-12, "heat Jacobian row");
    double *field[] = {&heat.C_th, &heat.R_th, &heat.eta, &heat.T_amb};
    for (int k = 0; k < 4; k++) {
        double x = *field[k], e = 1e-7 * fabs(x);
        *field[k] = x + e; double rp = tf_heat_rate(&heat, 0.0, T, P);
        *field[k] = x - e; double rm = tf_heat_rate(&heat, 0.0, T, P);
        *field[k] = x;
        double d = tf_heat_param_partial(&heat, k, T, P, rate);
        CHECK(fabs(d - (rp - rm) / (2 * e)) < 1e-6 * fabs(d), "heat parameter partial %d", k);
    }
    CHECK(tf_heat_param_partial(&heat, TF_HEAT_T_0, T, P, rate) == 0.0, "T_0 enters through the initial state");
}

/* ---- Checks of the real-time and control APIs (issue 17): every refusal leaves the object as it
 * was, so the oracle of "as it was" is a twin that never saw the bad call. ---- */

#define B TF_ERR_BAD_ARGUMENT

static void rt_gms(tf_rt_friction *f)
{
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5, p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0;
    p[TF_P_C] = 20.0;
    static tf_gms_elements g = {3, {5e4, 3e4, 2e4}, {0.3, 0.3, 0.4}, {0}};
    CHECK(tf_rt_init(f, TF_FRICTION_GMS, p, &g, &E) == TF_OK, "tf_rt_init GMS: %s", E.what);
}

static void test_rt_init_and_setters_refuse_bad_arguments(void)
{
    static tf_rt_friction f;
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5, p[TF_P_SIGMA1] = 316.2, p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0, p[TF_P_VSMOOTH] = 1e-6;
    CHECK(tf_rt_init(NULL, TF_FRICTION_LUGRE, p, NULL, &E) == B, "init: NULL f");
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, NULL, NULL, &E) == B && E.code == B && !strcmp(E.what, "p (NULL)"),
          "init: NULL p");
    CHECK(tf_rt_init(&f, 99, p, NULL, &E) == B, "init: unknown kind");
    CHECK(tf_rt_init(&f, TF_FRICTION_GMS, p, NULL, &E) == B, "init: GMS without elements");
    tf_gms_elements g = {0};
    CHECK(tf_rt_init(&f, TF_FRICTION_GMS, p, &g, &E) == B, "init: GMS with 0 elements");
    g.n = TF_MAX_FRICTION_STATES + 1;
    CHECK(tf_rt_init(&f, TF_FRICTION_GMS, p, &g, &E) == B, "init: GMS with 65 elements");
    p[TF_P_SIGMA0] = -1e5; /* the simulator's rules: sigma0 > 0 */
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == B && !strcmp(E.what, "sigma0"), "init: sigma0 < 0");
    CHECK(isnan(rt_force(&f, 1e-3, NAN, 1e-4)), "a refused init leaves a model that every step refuses");
    p[TF_P_SIGMA0] = 1e5;
    p[TF_P_FS] = 0.5;
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == B && !strcmp(E.what, "fs"), "init: fs < fc");
    p[TF_P_FS] = 1.5;

    rt_lugre(&f);
    double x2[2] = {20.0, 20.0}, y2[2] = {1.0, 2.0};
    tf_law pwl0 = {TF_LAW_PWL, 0, 0, 0, x2, y2, 0};
    tf_law table_null = {TF_LAW_TABLE, 0, 0, 2, NULL, NULL, NULL};
    tf_law duplicate = {TF_LAW_PWL, 0, 0, 2, x2, y2, 0};
    tf_law table_no_slopes = {TF_LAW_TABLE, 0, 0, 2, x2, y2, NULL};
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &pwl0, &E) == B, "PWL law with n = 0");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &table_null, &E) == B, "TABLE law with NULL data");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &duplicate, &E) == B, "duplicate breakpoints");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &table_no_slopes, &E) == B, "TABLE law without slopes");
    CHECK(tf_rt_set_model_i(&f, -1, &pwl0, &E) == B && tf_rt_set_model_i(&f, TF_NPARAM, &pwl0, &E) == B,
          "Model I: bad index");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, NULL, &E) == B && tf_rt_set_model_i(NULL, TF_P_FC, &pwl0, &E) == B,
          "Model I: NULL law or model");
    CHECK(f.model.thermal == TF_THERMAL_NONE && f.model.law[TF_P_FC].kind == TF_LAW_NONE,
          "a refused law leaves the model without it");
    CHECK(tf_rt_set_model_ii(&f, NULL, TF_DF_SCALE, &E) == B && tf_rt_set_model_ii(NULL, &pwl0, TF_DF_SCALE, &E) == B,
          "Model II: NULL");
    tf_law lin = {TF_LAW_LINEAR, -0.02, 0.6, 0, 0, 0, 0};
    CHECK(tf_rt_set_model_ii(&f, &lin, 7, &E) == B && f.model.thermal == TF_THERMAL_NONE, "Model II: bad form");
    CHECK(tf_rt_set_param(NULL, TF_P_FC, 1.0, &E) == B, "set_param: NULL");
    CHECK(tf_rt_set_param(&f, TF_P_SIGMA0, -1.0, &E) == B && f.model.p[TF_P_SIGMA0] == 1e5 && !strcmp(E.what, "sigma0"),
          "set_param: sigma0 < 0 refused, the old value kept");
    CHECK(tf_rt_set_param(&f, TF_P_FC, NAN, &E) == B && f.model.p[TF_P_FC] == 1.0, "set_param: NaN fc");
    CHECK(tf_rt_set_param(&f, TF_P_FS, NAN, &E) == TF_OK && f.model.fs_follows_fc, "set_param: NaN fs = no Stribeck");
    CHECK(tf_rt_reset(NULL, &E) == B && tf_rt_params_at(NULL, 30.0, NAN, p, 0, 0, &E) == B, "reset, params_at: NULL");
    CHECK(tf_rt_from_model(NULL, &f.model, &E) == B && tf_rt_from_model(&f, NULL, &E) == B, "from_model: NULL");
    tf_model bad = f.model;
    bad.p[TF_P_SIGMA0] = -1.0;
    CHECK(tf_rt_from_model(&f, &bad, &E) == B && f.model.p[TF_P_SIGMA0] == 1e5, "from_model: sigma0 < 0");
    double z[1] = {0}, dz[1], Fa = 0.0;
    CHECK(tf_rt_advance(TF_FRICTION_LUGRE, NULL, NULL, z, 1e-3, 1e-4, 0, dz, &Fa, &E) == B && isnan(Fa) &&
              tf_rt_advance(TF_FRICTION_GMS, f.model.p, NULL, z, 1e-3, 1e-4, 0, dz, &Fa, &E) == B &&
              tf_rt_advance(42, f.model.p, NULL, z, 1e-3, 1e-4, 0, dz, &Fa, &E) == B && isnan(Fa) && z[0] == 0.0 &&
              tf_rt_advance(TF_FRICTION_LUGRE, f.model.p, NULL, z, 1e-3, 1e-4, 0, dz, NULL, &E) == B,
          "advance: NULL p, GMS without elements, unknown kind, NULL F");
    p[TF_P_FS] = 1.5;
    CHECK(tf_rt_advance(TF_FRICTION_LUGRE, p, NULL, z, 1e-3, 1e-4, 0, dz, &Fa, &E) == TF_OK && isfinite(Fa) &&
              E.code == TF_OK && !E.what[0] && !E.where[0],
          "advance: LuGre needs no GMS elements");
    CHECK(tf_rt_thermal_force(1.0, 1e-3, NULL, 1.0, 0.0, &Fa, &E) == B && isnan(Fa) && !strcmp(E.where, "realtime"),
          "thermal_force: NULL p");
}

static void test_rt_step_refuses_bad_samples_and_keeps_its_state(void)
{
    static tf_rt_friction f, twin;
    double F;
    CHECK(isnan(rt_force(NULL, 1e-3, NAN, 1e-4)), "step(NULL) is NaN");
    CHECK(tf_rt_step(NULL, 1e-3, NAN, NAN, 1e-4, &F, &E) == B && isnan(F), "step_status(NULL)");
    rt_lugre(&f);
    CHECK(tf_rt_step(&f, 1e-3, NAN, NAN, 1e-4, NULL, &E) == B, "step_status: NULL F");
    rt_lugre(&twin);
    for (int i = 0; i < 10; i++) rt_force(&f, 1e-3, NAN, 1e-4), rt_force(&twin, 1e-3, NAN, 1e-4);
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        CHECK(isnan(rt_force(&f, bad[k], NAN, 1e-4)) && E.code == B && !strcmp(E.what, "v (not finite)"),
              "v = %g refused", bad[k]);
        CHECK(tf_rt_step(&f, 1e-3, NAN, NAN, bad[k], &F, &E) == B && isnan(F), "dt = %g refused", bad[k]);
    }
    CHECK(rt_force(&f, 1e-3, INFINITY, 1e-4) == rt_force(&twin, 1e-3, 35.0, 1e-4) && f.z[0] == twin.z[0],
          "without a thermal model T is ignored (NaN, inf), and the refused samples left the state as it was");
    /* an overflow: sigma1 |v| at v = 1e308 is infinite; the step is refused, the state kept */
    CHECK(tf_rt_step(&f, 1e308, NAN, NAN, 1e-4, &F, &E) == TF_ERR_NONFINITE && isnan(F) && f.z[0] == twin.z[0],
          "overflowing step: status %d, z %g vs %g", E.code, f.z[0], twin.z[0]);
    CHECK(rt_force(&f, 1e-3, NAN, 1e-4) == rt_force(&twin, 1e-3, NAN, 1e-4) && E.code == TF_OK && !E.what[0],
          "the next good sample continues as if the bad ones had not come");

    /* Model I: fc = 2.5 - 0.05 T turns negative above 50 C (the issue: F = -1.6e17 N at 60 C) */
    rt_lugre(&f);
    rt_lugre(&twin);
    tf_law fc = {TF_LAW_LINEAR, -0.05, 2.5, 0, 0, 0, 0};
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &fc, &E) == TF_OK && tf_rt_set_model_i(&twin, TF_P_FC, &fc, &E) == TF_OK, "law");
    CHECK(tf_rt_set_model_i(&f, TF_P_FS, &fc, &E) == TF_OK && tf_rt_set_model_i(&twin, TF_P_FS, &fc, &E) == TF_OK, "law");
    for (int i = 0; i < 10; i++) rt_force(&f, 1e-3, 35.0, 1e-4), rt_force(&twin, 1e-3, 35.0, 1e-4);
    CHECK(isnan(rt_force(&f, 1e-3, 60.0, 1e-4)) && E.code == B && !strcmp(E.what, "fc"),
          "Model I: fc < 0 at 60 C refused (%s)", E.what);
    CHECK(isnan(rt_force(&f, 1e-3, 60.0, 1e-4)), "and refused again at the same temperature");
    CHECK(tf_rt_params_at(&f, 60.0, NAN, 0, 0, 0, &E) == B, "params_at 60 C refused");
    CHECK(isnan(rt_force(&f, 1e-3, NAN, 1e-4)) && !strcmp(E.what, "T (not finite)"), "NaN T with a thermal model");
    CHECK(isnan(rt_force(&f, 1e-3, INFINITY, 1e-4)) && !strcmp(E.what, "T (not finite)"), "inf T refused");
    CHECK(rt_force(&f, 1e-3, 35.0, 1e-4) == rt_force(&twin, 1e-3, 35.0, 1e-4) && f.z[0] == twin.z[0],
          "back at 35 C as if 60 C had not come");
    CHECK(tf_rt_set_param(&f, TF_P_SIGMA0, -5.0, &E) == B && !strcmp(E.what, "sigma0"),
          "set_param with Model I: checked at the last temperature");
    tf_law neg = {TF_LAW_CONST, -1.0, 0, 0, 0, 0, 0};
    CHECK(tf_rt_set_model_i(&f, TF_P_SIGMA0, &neg, &E) == B && f.model.law[TF_P_SIGMA0].kind == TF_LAW_NONE,
          "a law negative at the last temperature refused");

    /* Model II: lambda = 1 + dF / fc <= 0 reverses friction: refused at that step */
    rt_lugre(&f);
    tf_law dF = {TF_LAW_LINEAR, -0.1, 0.6, 0, 0, 0, 0}; /* lambda = 1.6 - 0.1 T <= 0 from 16 C */
    CHECK(tf_rt_set_model_ii(&f, &dF, TF_DF_SCALE, &E) == TF_OK, "Model II");
    CHECK(isfinite(rt_force(&f, 1e-3, 5.0, 1e-4)) && rt_force(&f, 1e-3, 5.0, 1e-4) > 0.0, "lambda > 0 at 5 C");
    CHECK(isnan(rt_force(&f, 1e-3, 35.0, 1e-4)) && E.code == B && !strncmp(E.what, "dF", 2),
          "Model II: lambda < 0 at 35 C refused");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &fc, &E) == B, "Model I on a Model II model refused");
}

static void test_observer_pid_and_loop_refuse_bad_arguments(void)
{
    static tf_rt_friction f, twin, plant, comp;
    double F;
    /* the stack buffer overflow: one `extra` for every GMS element; now a clear refusal */
    rt_gms(&f);
    double z0[3] = {f.z[0], f.z[1], f.z[2]};
    CHECK(isnan(observer_force(&f, 1e-3, 1e-6, 100.0, NAN, 1e-4)) && E.code == B &&
              f.z[0] == z0[0] && f.z[1] == z0[1] && f.z[2] == z0[2],
          "observer on GMS refused");
    double p[TF_NPARAM] = {0};
    p[TF_P_FC] = 1.0, p[TF_P_SIGMA2] = 0.4, p[TF_P_VSMOOTH] = 1e-4;
    CHECK(tf_rt_init(&f, TF_FRICTION_COULOMB, p, NULL, &E) == TF_OK &&
              tf_observer_step(&f, 1e-3, 0.0, 100.0, NAN, NAN, 1e-4, &F, &E) == B,
          "observer on Coulomb refused (no state)");
    CHECK(isnan(observer_force(NULL, 1e-3, 0, 100, NAN, 1e-4)), "observer(NULL)");
    rt_lugre(&f);
    rt_lugre(&twin);
    CHECK(tf_observer_step(&f, 1e-3, 0.0, 100.0, NAN, NAN, 1e-4, NULL, &E) == B, "observer: NULL F");
    const double bad[] = {NAN, INFINITY};
    for (int k = 0; k < 2; k++) {
        CHECK(tf_observer_step(&f, bad[k], 0.0, 100.0, NAN, NAN, 1e-4, &F, &E) == B && isnan(F), "observer v");
        CHECK(tf_observer_step(&f, 1e-3, bad[k], 100.0, NAN, NAN, 1e-4, &F, &E) == B, "observer e");
        CHECK(tf_observer_step(&f, 1e-3, 0.0, bad[k], NAN, NAN, 1e-4, &F, &E) == B, "observer k");
        CHECK(tf_observer_step(&f, 1e-3, 0.0, 100.0, NAN, NAN, bad[k], &F, &E) == B, "observer dt");
    }
    CHECK(tf_observer_step(&f, 1e-3, 0.0, -1.0, NAN, NAN, 1e-4, &F, &E) == B, "observer: negative gain");
    CHECK(observer_force(&f, 1e-3, 1e-7, 100.0, NAN, 1e-4) == observer_force(&twin, 1e-3, 1e-7, 100.0, NAN, 1e-4) &&
              f.z[0] == twin.z[0],
          "observer state untouched by the refusals");

    tf_pid c, ctwin;
    CHECK(tf_pid_init(NULL, 1, 1, 1, 0, &E) == B && tf_pid_init(&c, NAN, 1, 1, 0, &E) == B &&
              tf_pid_init(&c, 1, INFINITY, 1, 0, &E) == B && tf_pid_init(&c, 1, 1, 1, -1e-3, &E) == B,
          "pid_init: NULL, non-finite gains, tau_d < 0");
    CHECK(tf_pid_init(&c, 4e4, 4e5, 280.0, 2e-4, &E) == TF_OK && tf_pid_init(&ctwin, 4e4, 4e5, 280.0, 2e-4, &E) == TF_OK,
          "pid_init");
    double u;
    pid_u(&c, 1e-6, 1e-4), pid_u(&ctwin, 1e-6, 1e-4);
    CHECK(isnan(pid_u(&c, 2e-6, 0.0)) && tf_pid_step(&c, 2e-6, 0.0, &u, &E) == B && isnan(u),
          "pid: dt = 0 refused (it gave NaN forever)");
    CHECK(tf_pid_step(&c, 2e-6, -1e-4, &u, &E) == B && tf_pid_step(&c, NAN, 1e-4, &u, &E) == B &&
              tf_pid_step(&c, 2e-6, NAN, &u, &E) == B && tf_pid_step(NULL, 0, 1e-4, &u, &E) == B &&
              tf_pid_step(&c, 0, 1e-4, NULL, &E) == B,
          "pid: negative or NaN dt, NaN e, NULL");
    CHECK(tf_pid_step(&c, 1e305, 1e-4, &u, &E) == TF_ERR_NONFINITE, "pid: an overflowing u");
    CHECK(pid_u(&c, 2e-6, 1e-4) == pid_u(&ctwin, 2e-6, 1e-4), "pid state untouched by the refusals");

    enum { N = 200 };
    static double x_ref[N], v_ref[N], x[N];
    for (int i = 0; i < N; i++) x_ref[i] = 1e-6 * i, v_ref[i] = 1e-2, x[i] = -7.0;
    rt_lugre(&plant);
    rt_lugre(&comp);
    tf_loop L = {1.0, &plant, 30.0, {0}, TF_COMP_FEEDFORWARD, &comp, 30.0, 100.0, 1e-4, 10};
    tf_pid_init(&L.pid, 4e4, 4e5, 280.0, 2e-4, &E);
    CHECK(tf_loop_run(NULL, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop(NULL)");
    CHECK(tf_loop_run(&L, 0, NULL, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "loop"), "loop: n = 0, x_ref NULL");
    CHECK(tf_loop_run(&L, N, NULL, v_ref, x, 0, 0, &E) == B && !strcmp(E.what, "x_ref (NULL)"), "loop: x_ref NULL");
    CHECK(tf_loop_run(&L, N, x_ref, NULL, x, 0, 0, &E) == B && !strcmp(E.what, "v_ref (NULL)"),
          "loop: feed-forward without v_ref");
    x_ref[150] = NAN;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && E.index == 150 && x[0] == -7.0,
          "loop: a NaN reference sample refused before anything is written");
    x_ref[150] = 150e-6;
    double *fields[] = {&L.mass, &L.dt};
    for (int k = 0; k < 2; k++) {
        double keep = *fields[k];
        *fields[k] = 0.0;
        CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: %s = 0", k ? "dt" : "mass");
        *fields[k] = NAN;
        CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: %s = NaN", k ? "dt" : "mass");
        *fields[k] = keep;
    }
    L.substeps = 0;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: substeps = 0");
    /* issue 32: substeps = INT_MAX ran 200 x 2^31 plant steps (a hang); the work is bounded */
    L.substeps = 2147483647;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "loop") &&
              strstr(E.what, "substeps") && x[0] == -7.0,
          "loop: n x substeps beyond TF_LOOP_MAX_SUBSTEPS refused before anything is written");
    L.substeps = (int)(TF_LOOP_MAX_SUBSTEPS / N) + 1;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && strstr(E.what, "substeps"),
          "loop: one substep per run beyond the bound refused");
    L.substeps = 10, L.compensation = 9;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: unknown compensation");
    L.compensation = TF_COMP_OBSERVER, L.comp = NULL;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: compensation NULL");
    rt_gms(&comp);
    L.comp = &comp;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "compensation"),
          "loop: observer on GMS (the issue's overflow, through the loop)");
    rt_lugre(&comp);
    L.observer_gain = -1.0;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: negative observer gain");
    L.observer_gain = 100.0, L.pid.kd = NAN;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "pid"), "loop: NaN gain");
    L.pid.kd = 280.0, L.plant = NULL;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: plant NULL");
    L.plant = &plant;
    tf_law fc = {TF_LAW_LINEAR, -0.05, 2.5, 0, 0, 0, 0};
    tf_rt_set_model_i(&plant, TF_P_FC, &fc, &E);
    tf_rt_set_model_i(&plant, TF_P_FS, &fc, &E);
    L.T_plant = 60.0;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "plant") && !strcmp(E.what, "fc") &&
              x[0] == -7.0,
          "loop: the plant's Model I invalid at 60 C, refused before the first period");
    L.T_plant = NAN;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B, "loop: NaN plant temperature");
    L.T_plant = 35.0;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == TF_OK && isfinite(x[N - 1]) && x[0] == 0.0, "loop runs");
    L.pid.kp = -1e12; /* positive feedback */
    tf_rt_reset(&plant, &E), tf_rt_reset(&comp, &E);
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == TF_ERR_NONFINITE && E.index >= 0,
          "loop: unstable gains stop the run (at period %ld: %s)", E.index, E.what);

    /* temperatures that change over the run (issue 45): every period's checked before anything is written */
    L.pid.kp = 4e4;
    static double T_series[N], T_told[N], F_plant[N];
    for (int i = 0; i < N; i++) T_series[i] = 30.0 + 0.05 * i, T_told[i] = 30.0, x[i] = -7.0;
    T_series[120] = 60.0; /* fc of the law above is negative there */
    L.T_plant_series = T_series;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "plant") && E.index == 120 &&
              x[0] == -7.0,
          "loop: a plant series invalid at one period refused before anything is written (%s, %ld)", E.where,
          E.index);
    T_series[120] = NAN;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && E.index == 120, "loop: a NaN in the plant series");
    T_series[120] = 36.0;
    T_told[50] = 60.0;
    L.T_comp_series = T_told;
    tf_rt_set_model_i(&comp, TF_P_FC, &fc, &E);
    tf_rt_set_model_i(&comp, TF_P_FS, &fc, &E);
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "compensation") && E.index == 50,
          "loop: a compensation series invalid at one period refused");
    T_told[50] = 30.0;
    L.dob_tau = -1.0;
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && strstr(E.what, "dob_tau"), "loop: dob_tau < 0");
    L.dob_tau = 0.0;
    tf_temperature_estimator est;
    L.estimator = &est; /* without its friction model */
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == B && !strcmp(E.where, "estimator"),
          "loop: an estimator without est_friction");
    L.estimator = NULL;
    L.trace.F_plant = F_plant;
    tf_rt_reset(&plant, &E), tf_rt_reset(&comp, &E), tf_pid_init(&L.pid, 4e4, 4e5, 280.0, 2e-4, &E);
    CHECK(tf_loop_run(&L, N, x_ref, v_ref, x, 0, 0, &E) == TF_OK && isfinite(F_plant[N - 1]) && F_plant[N - 1] > 0.0,
          "loop: runs with both series and writes the plant's friction");
    L.T_plant_series = L.T_comp_series = NULL, L.trace.F_plant = NULL;
}
#undef B

/* Parameter partials of every friction model (tf_friction_eval's dp) against central differences
 * of tf_friction_eval itself, at states and velocities that visit each branch: both signs of v,
 * the elasto-plastic transition band (alpha between 0 and 1) and full sliding, GMS elements stuck
 * and slipping either way, velocities inside and beyond the Stribeck band. */
static void test_friction_affine_equals_the_evaluation(void)
{
    /* tf_friction_affine_set (the exact stepping's one evaluation per velocity of LuGre and Dahl) against
     * tf_friction_eval at each state: the rate's coefficients and the force the same numbers, the partials
     * da + db z and dF0 + dF1 z equal to the evaluation's within 1e-13 of each entry's scale, on both sides of
     * direction-dependent parameters (fs_neg following fc_neg too), with and without a Stribeck effect, at rest;
     * the Stribeck exponent's partials zero when not wanted, every other entry unchanged. */
    enum { NSETS = 4 };
    double sets[NSETS][TF_NPARAM] = {{0}};
    for (int k = 0; k < NSETS; k++) {
        double *p = sets[k];
        p[TF_P_SIGMA0] = 3000.0; p[TF_P_SIGMA1] = 0.3; p[TF_P_SIGMA2] = 0.35; p[TF_P_FC] = 0.9; p[TF_P_FS] = 1.4;
        p[TF_P_VS] = 0.3; p[TF_P_DELTA] = k == 1 ? 1.6 : 2.0; p[TF_P_VD] = k == 0 ? 0.2 : 0.0;
    }
    sets[1][TF_P_FC_NEG] = 0.7, sets[1][TF_P_FS_NEG] = 1.1, sets[1][TF_P_VS_NEG] = 0.2, sets[1][TF_P_SIGMA2_NEG] = 0.3;
    sets[2][TF_P_FS] = sets[2][TF_P_FC], sets[2][TF_P_FC_NEG] = 0.75; /* no Stribeck effect; fs_neg follows fc_neg */
    sets[3][TF_P_VS] = 0.0, sets[3][TF_P_FC_NEG] = 0.8;                /* no Stribeck velocity */
    const int kinds[2] = {TF_FRICTION_LUGRE, TF_FRICTION_DAHL};
    const double vs[] = {-1.7, -0.25, -1e-3, 0.0, 2e-4, 0.3, 4.0}, zs[] = {-3e-4, 0.0, 1.2e-4, 5e-4};
    double worst = 0.0;
    int same = 1, delta_ok = 1, count = 0;
    for (int m = 0; m < 2; m++)
        for (int k = 0; k < NSETS; k++)
            for (size_t a = 0; a < sizeof vs / sizeof vs[0]; a++) {
                const double *p = sets[k], v = vs[a];
                tf_friction_affine af, nodelta;
                tf_friction_affine_set(kinds[m], p, v, 1, &af);
                tf_friction_affine_set(kinds[m], p, v, 0, &nodelta);
                for (int i = 0; i < TF_NPARAM; i++) {
                    int d = i == TF_P_DELTA;
                    delta_ok &= d ? nodelta.da[i] == 0.0 && nodelta.db[i] == 0.0 && nodelta.dF0[i] == 0.0 &&
                                        nodelta.dF1[i] == 0.0
                                  : nodelta.da[i] == af.da[i] && nodelta.db[i] == af.db[i] &&
                                        nodelta.dF0[i] == af.dF0[i] && nodelta.dF1[i] == af.dF1[i];
                }
                for (size_t b = 0; b < sizeof zs / sizeof zs[0]; b++) {
                    double z = zs[b], dz, dz0;
                    tf_friction_partials jac;
                    tf_friction_param_partials dp;
                    double F = tf_friction_eval(kinds[m], p, 0, v, &z, &dz, &jac, &dp);
                    tf_friction_eval(kinds[m], p, 0, v, &zs[1], &dz0, 0, 0);
                    same &= tf_friction_affine_force(&af, p, z) == F && af.a == dz0 && af.b == jac.ddz_dz[0] &&
                            af.dF_dz == jac.dF_dz[0];
                    for (int i = 0; i < TF_NPARAM; i++) {
                        double r = af.da[i] + af.db[i] * z, f = af.dF0[i] + af.dF1[i] * z;
                        double sr = fabs(af.da[i]) + fabs(af.db[i] * z) + 1e-300;
                        double sf = fabs(af.dF0[i]) + fabs(af.dF1[i] * z) + 1e-300;
                        worst = fmax(worst, fmax(fabs(r - dp.ddz_dp[0][i]) / sr, fabs(f - dp.dF_dp[i]) / sf));
                        count += dp.dF_dp[i] != 0.0;
                    }
                }
            }
    CHECK(same && delta_ok && worst < 1e-13 && count > 500,
          "tf_friction_affine_set: coefficients and force the evaluation's (%d), delta's partials only when wanted "
          "(%d), partials' worst relative difference %g (%d nonzero)", same, delta_ok, worst, count);
}

static void test_friction_parameter_partials_vs_finite_differences(void)
{
    const int kinds[6] = {TF_FRICTION_LUGRE, TF_FRICTION_COULOMB, TF_FRICTION_STRIBECK, TF_FRICTION_DAHL,
                          TF_FRICTION_ELASTOPLASTIC, TF_FRICTION_GMS};
    const char *names[6] = {"lugre", "coulomb", "stribeck", "dahl", "elastoplastic", "gms"};
    /* which parameters each model reads (the ones whose partials must be nonzero somewhere) */
    const int reads[6][TF_NPARAM] = {
        [0] = {[TF_P_SIGMA0] = 1, [TF_P_SIGMA1] = 1, [TF_P_SIGMA2] = 1, [TF_P_FC] = 1, [TF_P_FS] = 1, [TF_P_VS] = 1,
               [TF_P_DELTA] = 1, [TF_P_VD] = 1},
        [1] = {[TF_P_FC] = 1, [TF_P_SIGMA2] = 1, [TF_P_VSMOOTH] = 1},
        [2] = {[TF_P_FC] = 1, [TF_P_FS] = 1, [TF_P_VS] = 1, [TF_P_DELTA] = 1, [TF_P_SIGMA2] = 1, [TF_P_VSMOOTH] = 1},
        [3] = {[TF_P_SIGMA0] = 1, [TF_P_FC] = 1},
        [4] = {[TF_P_SIGMA0] = 1, [TF_P_SIGMA1] = 1, [TF_P_SIGMA2] = 1, [TF_P_FC] = 1, [TF_P_FS] = 1, [TF_P_VS] = 1,
               [TF_P_DELTA] = 1, [TF_P_VD] = 1, [TF_P_ZBA] = 1},
        [5] = {[TF_P_C] = 1, [TF_P_FC] = 1, [TF_P_FS] = 1, [TF_P_VS] = 1, [TF_P_DELTA] = 1, [TF_P_SIGMA2] = 1}};
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5; p[TF_P_SIGMA1] = 300.0; p[TF_P_SIGMA2] = 0.4; p[TF_P_FC] = 1.0; p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3; p[TF_P_DELTA] = 1.7; p[TF_P_VD] = 2e-3; p[TF_P_VSMOOTH] = 2e-4; p[TF_P_ZBA] = 4e-6;
    p[TF_P_C] = 50.0;
    tf_gms_elements el = {3, {1e4, 3e4, 6e4}, {0.3, 0.3, 0.4}, {0, 1, -1}};
    /* (v, z): z in the elasto-plastic band [z_ba, g/sigma0] = [4, ~10..15] um, beyond it, opposing v */
    const double vz[][2] = {{7e-4, 8e-6}, {-1.3e-3, -9e-6}, {2.5e-3, 1.2e-5}, {5e-3, 2e-5}, {4e-4, -3e-6},
                            {-3e-4, -5e-6}, {1e-4, 2e-6}};
    const int nvz = (int)(sizeof vz / sizeof vz[0]);
    for (int m = 0; m < 6; m++) {
        int seen[TF_NPARAM] = {0};
        double worst = 0.0;
        for (int c = 0; c < nvz; c++) {
            double v = vz[c][0], z[3] = {vz[c][1], 0.25 * v / fabs(v), -0.3}, dz[3], dz1[3], dz2[3];
            if (kinds[m] == TF_FRICTION_GMS) z[0] = 0.1, z[1] = 0.2 * (v > 0 ? 1 : -1) , z[2] = -0.35;
            tf_friction_param_partials dp;
            tf_friction_eval(kinds[m], p, &el, v, z, dz, 0, &dp);
            int nz = tf_friction_nstate(kinds[m], el.n);
            for (int i = 0; i < TF_NPARAM; i++) {
                double q[TF_NPARAM];
                memcpy(q, p, sizeof q);
                double h = 1e-6 * fabs(p[i]);
                q[i] = p[i] + h; double F1 = tf_friction_eval(kinds[m], q, &el, v, z, dz1, 0, 0);
                q[i] = p[i] - h; double F2 = tf_friction_eval(kinds[m], q, &el, v, z, dz2, 0, 0);
                double fd = (F1 - F2) / (2 * h), an = dp.dF_dp[i];
                double err = fabs(fd - an) / (1e-3 * fabs(p[TF_P_FC] / p[i]) + fabs(fd));
                if (an != 0.0) seen[i] = 1;
                if (!reads[m][i] && an != 0.0) err = 1.0;
                worst = fmax(worst, err);
                if (err > 1e-5) printf("  %s dF/dp[%d] at v=%g: fd %g analytic %g\n", names[m], i, v, fd, an);
                for (int j = 0; j < nz; j++) {
                    double fdz = (dz1[j] - dz2[j]) / (2 * h), anz = dp.ddz_dp[j][i];
                    double scale = kinds[m] == TF_FRICTION_GMS ? p[TF_P_C] : fabs(v); /* of z' */
                    double e = fabs(fdz - anz) / (1e-3 * scale / p[i] + fabs(fdz));
                    if (anz != 0.0) seen[i] = 1;
                    if (!reads[m][i] && anz != 0.0) e = 1.0;
                    worst = fmax(worst, e);
                    if (e > 1e-5) printf("  %s dz%d'/dp[%d] at v=%g: fd %g analytic %g\n", names[m], j, i, v, fdz, anz);
                }
            }
        }
        int missing = 0;
        for (int i = 0; i < TF_NPARAM; i++) missing += reads[m][i] && !seen[i];
        CHECK(worst < 1e-5 && !missing, "%s parameter partials: worst relative error %g, %d read parameters never "
              "moved", names[m], worst, missing);
    }
}

/* The friction models' domain table (domains.h): every model has rows, every row names a parameter of the
 * list, and the checks follow it: vd = 0 is "none" (sigma1 constant), a negative vd is refused, the other
 * rules by the name of the first parameter refused. */
static void test_friction_domain_table_drives_the_checks(void)
{
    int rows[TF_FRICTION_GMS + 1] = {0}, bad_rows = 0;
#define ROW(model, param, rule, other, when)                                                              \
    rows[TF_FRICTION_##model]++;                                                                            \
    bad_rows += TF_P_##param < 0 || TF_P_##param >= TF_NPARAM || TF_DOMAIN_##rule >= TF_DOMAIN_NRULE ||     \
                TF_P_##other >= TF_NPARAM || TF_DOMAIN_##when >= TF_DOMAIN_NWHEN;
    TF_FRICTION_DOMAINS(ROW)
#undef ROW
    for (int k = 0; k <= TF_FRICTION_GMS; k++) CHECK(rows[k] >= 3, "domain table: model %d has %d rows", k, rows[k]);
    CHECK(bad_rows == 0, "domain table: %d rows name no parameter, rule or condition", bad_rows);
    static tf_rt_friction f;
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5, p[TF_P_SIGMA1] = 316.2, p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0, p[TF_P_ZBA] = 1e-6;
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_OK, "vd = 0: none (sigma1 constant)");
    p[TF_P_VD] = 1e-3;
    CHECK(tf_rt_init(&f, TF_FRICTION_ELASTOPLASTIC, p, NULL, &E) == TF_OK, "vd > 0");
    p[TF_P_VD] = -1e-3;
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "vd"), "vd < 0 refused");
    p[TF_P_VD] = INFINITY;
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "vd"), "vd = inf refused");
    p[TF_P_VD] = 0.0, p[TF_P_ZBA] = 2e-5; /* at or above fc / sigma0 = 1e-5 */
    CHECK(tf_rt_init(&f, TF_FRICTION_ELASTOPLASTIC, p, NULL, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "z_ba"), "z_ba");
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_OK, "z_ba: the elasto-plastic model's only");
    p[TF_P_FS] = 1.0, p[TF_P_VS] = -1.0;
    CHECK(tf_rt_init(&f, TF_FRICTION_STRIBECK, p, NULL, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "v_smooth"),
          "vs unchecked without a Stribeck effect; v_smooth always for a static map");
    p[TF_P_FS] = 1.2;
    CHECK(tf_rt_init(&f, TF_FRICTION_DAHL, p, NULL, &E) == TF_OK, "Dahl: no Stribeck curve");
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "vs"), "vs where fs != fc");
}

int main(void)
{
    test_friction_domain_table_drives_the_checks();
    test_rt_init_and_setters_refuse_bad_arguments();
    test_rt_step_refuses_bad_samples_and_keeps_its_state();
    test_observer_pid_and_loop_refuse_bad_arguments();
    test_sigma1_thermal_force_and_heat_rate_partials();
    test_rt_parameter_update_and_reset();
    test_rt_exact_for_constant_velocity_and_stable_at_large_steps();
    test_rt_observer_converges();
    test_lu_solves_systems_that_need_pivoting_in_later_columns();
    test_parameter_derivatives_vs_finite_differences();
    test_friction_parameter_partials_vs_finite_differences();
    test_friction_affine_equals_the_evaluation();
    test_grid_end_one_ulp_past_a_corner();
    test_oscillator_dense_output(TF_METHOD_DOPRI5);
    test_oscillator_dense_output(TF_METHOD_RODAS4);
    test_stiff_prothero_robinson();
    test_one_error_record_from_every_entry_point();
    test_interrupt_poll_stops_a_long_integration(TF_METHOD_DOPRI5);
    test_interrupt_poll_stops_a_long_integration(TF_METHOD_RODAS4);
    test_waveforms();
    test_laws();
    test_lugre_steady_sliding();
    test_jacobian_vs_finite_differences();
    test_frictionless_step_response();
    test_gms_element_breaks_loose_exactly_at_its_capacity();
    test_prescribed_exact_stepping_gms_and_its_record();
    test_prescribed_exact_stepping_elastoplastic();
    test_prescribed_sine_step_limit();
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
