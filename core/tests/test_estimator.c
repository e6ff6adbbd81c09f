/* Tests of the online temperature estimator (estimator.h) against analytic solutions of its heat path
 * and of LuGre's steady sliding; its refusals. Prints one line per failed check and "N passed, N failed". */
#include "thermofriction.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

static tf_error E;

/* LuGre with fc(T) = 1 - 0.01 (T - 25) N when `law` (else fc = 1 N), fs = 1.5 N, vs = 1 mm/s. */
static tf_law fc_law = {TF_LAW_LINEAR, -0.01, 1.25, 0, 0, 0, 0};
static void lugre(tf_rt_friction *f, int law)
{
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA0] = 1e5, p[TF_P_SIGMA1] = 316.2, p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0, p[TF_P_VSMOOTH] = 1e-6;
    CHECK(tf_rt_init(f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_OK, "tf_rt_init");
    if (law) CHECK(tf_rt_set_model_i(f, TF_P_FC, &fc_law, &E) == TF_OK, "fc law");
}

static tf_temperature_config config(double C_2, int proxy)
{
    tf_temperature_config c = {10.0, 2.0, 1.0, C_2, 0.5, proxy, 5.0, {0.0, 0.0, 0.0}, 1e-4, 1e-2, 1e-4};
    return c;
}

static double step(tf_temperature_estimator *e, tf_rt_friction *f, double v, double Fm, double Tp, double Ta, double dt)
{
    double F;
    tf_temperature_step(e, f, v, NAN, Fm, Tp, Ta, dt, &F, &E);
    return F;
}

static void test_one_node_relaxes_exactly(void)
{
    /* Oracle (analytic): at rest (no friction power) and without measurements, Tc - T_amb and the
     * variance (q = 0) decay as exp(-t / (C_th R_th)) and exp(-2 t / (C_th R_th)); the exponential step
     * is exact for any dt. A friction measurement at v = 0 < v_min is gated. */
    static tf_rt_friction f;
    tf_temperature_estimator e;
    lugre(&f, 1);
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    CHECK(tf_temperature_init(&e, &c, 40.0, 4.0, &E) == TF_OK, "init: %s", E.what);
    double t = 0.0, dts[3] = {1e-3, 0.7, 13.0}, worst = 0.0, worst_var = 0.0;
    for (int k = 0; k < 300; k++) {
        double dt = dts[k % 3];
        step(&e, &f, 0.0, 0.3, NAN, 25.0, dt);
        t += dt;
        CHECK(E.code == TF_OK && e.gated, "step %d: %s, gated %d", k, E.what, e.gated);
        worst = fmax(worst, fabs(tf_temperature_estimate(&e) - (25.0 + 15.0 * exp(-t / 20.0))) / 15.0);
        worst_var = fmax(worst_var, fabs(tf_temperature_variance(&e) / (4.0 * exp(-2.0 * t / 20.0)) - 1.0));
    }
    CHECK(worst < 1e-12, "one node off the analytic decay by %g of the initial offset", worst);
    CHECK(worst_var < 1e-10, "variance off the analytic decay by %g (relative)", worst_var);
}

static void test_two_nodes_reach_the_analytic_steady_state(void)
{
    /* Oracle (analytic): sliding at constant v with a temperature-independent friction F = g(v) +
     * sigma2 v, the nodes settle at Th = T_amb + eta P R_2, Tc = Th + eta P R_th (P = F v); a proxy of
     * the housing settles at Th. */
    static tf_rt_friction f;
    tf_temperature_estimator e;
    lugre(&f, 0);
    tf_temperature_config c = config(30.0, TF_PROXY_HOUSING);
    c.eta = 0.8;
    CHECK(tf_temperature_init(&e, &c, 20.0, 1.0, &E) == TF_OK, "init: %s", E.what);
    double v = 0.5, F = 0.0;
    for (int k = 0; k < 20000; k++) F = step(&e, &f, v, NAN, NAN, 20.0, 0.1);
    double g = 1.0 + 0.5 * exp(-pow(v / 1e-3, 2)), Pw = (g + 0.4 * v) * v;
    CHECK(fabs(F - (g + 0.4 * v)) < 1e-12, "force %g vs %g", F, g + 0.4 * v);
    double Th = 20.0 + 0.8 * Pw * 0.5, Tc = Th + 0.8 * Pw * 2.0;
    CHECK(fabs(e.x[0] - Tc) < 1e-9 * (Tc - 20.0), "contact %.12g vs %.12g", e.x[0], Tc);
    CHECK(fabs(e.x[1] - Th) < 1e-9 * (Th - 20.0), "housing %.12g vs %.12g", e.x[1], Th);
    CHECK(fabs(e.x[2] - Th) < 1e-9 * (Th - 20.0), "proxy %.12g vs %.12g", e.x[2], Th);
    CHECK(e.h == 0.0, "no thermal model: h = %g", e.h);
}

static void test_h_is_the_steady_sliding_slope(void)
{
    /* Oracle (analytic): in LuGre's steady sliding F = fc(T) + (fs - fc(T)) exp(-(v/vs)^2) + sigma2 v,
     * so dF/dT = fc'(T) (1 - exp(-(v/vs)^2)); the estimator's h (the bristle state following T, not held:
     * held, sigma0 z carries no T and h would be ~0) must reach it. eta = 0: the estimate stays put. */
    static tf_rt_friction f;
    tf_temperature_estimator e;
    lugre(&f, 1);
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    c.eta = 0.0;
    CHECK(tf_temperature_init(&e, &c, 30.0, 1.0, &E) == TF_OK, "init: %s", E.what);
    double v = 1.5e-3;
    for (int k = 0; k < 2000; k++) step(&e, &f, v, NAN, NAN, 30.0, 1e-4);
    double slope = -0.01 * (1.0 - exp(-pow(v / 1e-3, 2)));
    /* (a linear law: the forward difference is exact up to round-off, 1e-16 F / 1e-4 K) */
    CHECK(fabs(e.h - slope) < 1e-6 * fabs(slope), "h %.10g vs dF/dT %.10g", e.h, slope);
}

static void test_h_follows_the_load(void)
{
    /* Oracle (analytic): fc(T, L) = fc0(T) (1 + k |L|) + c T |L| (law.h's affine product with an interaction),
     * fc0 = 1.25 - 0.01 T, k = 0.02 / N, c = -1e-4 / (C N): in steady sliding dF/dT = (-0.01 (1 + k |L|) + c |L|)
     * (1 - exp(-(v/vs)^2)), at each load the estimator is told (the load switched from 5 to 20 N mid-run);
     * F_hat is the force of a plain tf_rt_step stepped alongside at the same (v, T, L); a NaN load is refused
     * naming it, the estimator unchanged. */
    static tf_rt_friction f, g;
    tf_temperature_estimator e;
    lugre(&f, 0);
    tf_law law = fc_law;
    law.load.kind = TF_LOAD_AFFINE, law.load.combine = TF_COMBINE_PRODUCT, law.load.k = 0.02;
    law.load.interaction = 1, law.load.c = -1e-4;
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &law, &E) == TF_OK, "a law of the load: %s", E.what);
    g = f;
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    c.eta = 0.0;
    CHECK(tf_temperature_init(&e, &c, 30.0, 1.0, &E) == TF_OK, "init: %s", E.what);
    double v = 1.5e-3, L[2] = {5.0, 20.0};
    for (int j = 0; j < 2; j++) {
        double F = NAN, G = NAN;
        int ok = 1;
        for (int k = 0; k < 2000; k++) {
            ok = ok && tf_temperature_step(&e, &f, v, L[j], NAN, NAN, 30.0, 1e-4, &F, &E) == TF_OK;
            tf_rt_step(&g, v, 30.0, L[j], 1e-4, &G, 0);
        }
        CHECK(ok, "steps at load %g: %s", L[j], E.what);
        double slope = (-0.01 * (1.0 + 0.02 * L[j]) - 1e-4 * L[j]) * (1.0 - exp(-pow(v / 1e-3, 2)));
        CHECK(fabs(e.h - slope) < 1e-6 * fabs(slope), "h %.10g vs dF/dT %.10g at %g N", e.h, slope, L[j]);
        CHECK(F == G, "F_hat %.17g vs tf_rt_step %.17g at %g N", F, G, L[j]);
    }
    tf_temperature_estimator e0 = e;
    double F = 0.0;
    CHECK(tf_temperature_step(&e, &f, v, NAN, NAN, NAN, 30.0, 1e-4, &F, &E) == TF_ERR_BAD_ARGUMENT && isnan(F) &&
              !strncmp(E.what, "load (not finite", 16) && e.x[0] == e0.x[0] && e.P[0][0] == e0.P[0][0],
          "a NaN load refused by a law of the load: %s", E.what);
}

static void test_h_of_a_static_model_ii(void)
{
    /* Oracle (analytic): Stribeck (no internal state) with Model II in the scale form, F' = (1 + dF(T)/fc) F_base,
     * dF(T) = 0.02 (T - 30) N: dF'/dT = 0.02 / fc F_base = 0.02 / fc F' / lambda(T), whatever v. */
    static tf_rt_friction f;
    tf_temperature_estimator e;
    double p[TF_NPARAM] = {0};
    p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5, p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0;
    p[TF_P_VSMOOTH] = 1e-5;
    tf_law dF = {TF_LAW_LINEAR, 0.02, -0.6, 0, 0, 0, 0};
    CHECK(tf_rt_init(&f, TF_FRICTION_STRIBECK, p, NULL, &E) == TF_OK, "stribeck");
    CHECK(tf_rt_set_model_ii(&f, &dF, TF_DF_SCALE, &E) == TF_OK, "Model II");
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    c.eta = 0.0;
    CHECK(tf_temperature_init(&e, &c, 45.0, 1.0, &E) == TF_OK, "init: %s", E.what);
    double vs[3] = {-2e-3, 7e-4, 0.3};
    for (int k = 0; k < 3; k++) {
        double F = step(&e, &f, vs[k], NAN, NAN, 45.0, 1e-3), lambda = 1.0 + 0.02 * 15.0;
        double want = 0.02 / 1.0 * F / lambda;
        CHECK(fabs(e.h - want) < 1e-8 * fabs(want), "v = %g: h %.12g vs %.12g", vs[k], e.h, want);
    }
}

static void test_converges_from_five_kelvin_off(void)
{
    /* Oracle: a truth made by a second friction object stepped at a known constant T = 40 C (the ambient,
     * no heating: eta = 0), the estimator started at 35 C with noise-free force measurements: the
     * estimate reaches 40 C within 1 mK of sliding back and forth (1 N at +-5 mm/s, r_F = 1e-4 N^2). */
    static tf_rt_friction truth, f;
    tf_temperature_estimator e;
    lugre(&truth, 1);
    lugre(&f, 1);
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    c.eta = 0.0, c.q[0] = 1e-4;
    CHECK(tf_temperature_init(&e, &c, 35.0, 25.0, &E) == TF_OK, "init: %s", E.what);
    double dt = 1e-3;
    for (int k = 0; k < 4000; k++) {
        double v = 5e-3 * sin(6.283185307179586 * k * dt), Fm;
        tf_rt_step(&truth, v, 40.0, NAN, dt, &Fm, &E);
        step(&e, &f, v, Fm, NAN, 40.0, dt);
    }
    CHECK(fabs(e.x[0] - 40.0) < 1e-3, "estimate %g after 4 s", e.x[0]);
    /* the continuous filter's steady variance sqrt(q r_F dt) / |h| = 3.2e-4 K^2 (|h| <= 0.01 N/K) */
    CHECK(e.P[0][0] > 3e-4 && e.P[0][0] < 1e-3, "variance %g after 4 s", e.P[0][0]);
}

static void test_refusals_name_the_argument_and_change_nothing(void)
{
    const int B = TF_ERR_BAD_ARGUMENT;
    static tf_rt_friction f, f0;
    tf_temperature_estimator e, e0;
    lugre(&f, 1);
    tf_temperature_config c = config(0.0, TF_PROXY_NONE);
    CHECK(tf_temperature_init(NULL, &c, 25, 1, &E) == B && strstr(E.what, "e (NULL)"), "init NULL e");
    CHECK(tf_temperature_init(&e, NULL, 25, 1, &E) == B && strstr(E.what, "config"), "init NULL config");
    const char *fields[] = {"C_th", "R_th", "eta", "C_2", "R_2", "proxy", "tau_p", "q[0]", "r_F", "r_p", "v_min"};
    for (int k = 0; k < 11; k++) {
        tf_temperature_config bad = config(5.0, TF_PROXY_CONTACT);
        double *field[] = {&bad.C_th, &bad.R_th, &bad.eta, &bad.C_2, &bad.R_2, 0, &bad.tau_p, &bad.q[0], &bad.r_F,
                           &bad.r_p, &bad.v_min};
        if (field[k]) *field[k] = -1.0;
        else bad.proxy = 7;
        CHECK(tf_temperature_init(&e, &bad, 25, 1, &E) == B && strstr(E.what, fields[k]) &&
              !strcmp(E.where, "estimator"), "config.%s refused and named: %s", fields[k], E.what);
    }
    c.proxy = TF_PROXY_HOUSING;
    CHECK(tf_temperature_init(&e, &c, 25, 1, &E) == B && strstr(E.what, "housing"), "housing proxy, one node");
    c.proxy = TF_PROXY_NONE;
    CHECK(tf_temperature_init(&e, &c, NAN, 1, &E) == B && strstr(E.what, "T0"), "T0 NaN");
    CHECK(tf_temperature_init(&e, &c, 25, 0.0, &E) == B && strstr(E.what, "var0"), "var0 0");
    CHECK(tf_temperature_init(&e, &c, 25, 1, &E) == TF_OK, "init");
    step(&e, &f, 1e-2, NAN, NAN, 25.0, 1e-3);
    memcpy(&e0, &e, sizeof e);
    memcpy(&f0, &f, sizeof f);
    double F = 0.0;
    CHECK(tf_temperature_step(NULL, &f, 0, NAN, NAN, NAN, 25, 1e-3, &F, &E) == B && isnan(F), "step NULL e");
    CHECK(tf_temperature_step(&e, NULL, 0, NAN, NAN, NAN, 25, 1e-3, &F, &E) == B, "step NULL f");
    CHECK(tf_temperature_step(&e, &f, 0, NAN, NAN, NAN, 25, 1e-3, NULL, &E) == B, "step NULL F_hat");
    struct { double v, Fm, Tp, Ta, dt; const char *what; } bad[] = {
        {NAN, NAN, NAN, 25, 1e-3, "v"}, {0, INFINITY, NAN, 25, 1e-3, "F_measured"},
        {0, NAN, -INFINITY, 25, 1e-3, "T_proxy"}, {0, NAN, 30.0, 25, 1e-3, "T_proxy (given"},
        {0, NAN, NAN, NAN, 1e-3, "T_amb"}, {0, NAN, NAN, 25, 0.0, "dt"}, {0, NAN, NAN, 25, -1.0, "dt"},
        {0, NAN, NAN, 25, INFINITY, "dt"}};
    for (int k = 0; k < 8; k++) {
        F = 0.0;
        CHECK(tf_temperature_step(&e, &f, bad[k].v, NAN, bad[k].Fm, bad[k].Tp, bad[k].Ta, bad[k].dt, &F, &E) == B &&
              isnan(F) && strstr(E.what, bad[k].what) == E.what, "step refuses %s: %s", bad[k].what, E.what);
    }
    /* the friction model refused at the estimate (fc(T) <= 0 beyond 125 C), and an overflow */
    e.x[0] = 200.0;
    CHECK(tf_temperature_step(&e, &f, 1e-2, NAN, NAN, NAN, 25, 1e-3, &F, &E) == B && isnan(F), "fc <= 0 at 200 C");
    e.x[0] = e0.x[0];
    CHECK(tf_temperature_step(&e, &f, 1e308, NAN, NAN, NAN, 25, 1e-3, &F, &E) == TF_ERR_NONFINITE, "overflow: %d",
          E.code);
    /* (field by field: the struct's padding, copied from the caller's config, is not a value) */
    CHECK(!memcmp(e.x, e0.x, sizeof e.x) && !memcmp(e.P, e0.P, sizeof e.P) && !memcmp(e.s, e0.s, sizeof e.s) &&
          e.h == e0.h && e.gated == e0.gated && !memcmp(e.g, e0.g, sizeof e.g) && e.g_dt == e0.g_dt &&
          !memcmp(f.z, f0.z, sizeof f.z) && f.x == f0.x, "refusals changed nothing");
    tf_temperature_config c2 = config(5.0, TF_PROXY_NONE);
    CHECK(tf_temperature_configure(&e, &c2, &E) == B && strstr(E.what, "C_2"), "configure: other nodes");
    c2 = config(0.0, TF_PROXY_NONE);
    c2.r_F = 2.0;
    CHECK(tf_temperature_configure(&e, &c2, &E) == TF_OK && e.c.r_F == 2.0 && e.x[0] == e0.x[0], "configure");
    CHECK(isnan(tf_temperature_estimate(NULL)) && isnan(tf_temperature_variance(NULL)), "accessors of NULL");
}

int main(void)
{
    test_one_node_relaxes_exactly();
    test_two_nodes_reach_the_analytic_steady_state();
    test_h_is_the_steady_sliding_slope();
    test_h_follows_the_load();
    test_h_of_a_static_model_ii();
    test_converges_from_five_kelvin_off();
    test_refusals_name_the_argument_and_change_nothing();
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
