/* The load as an input of the C core (issue 43): a law's load term (law.h) against its equations written out
 * here and against central differences; the real-time API's and the model check's statuses for the load
 * (a NaN load refused by a model with a law of the load, ignored by one without); a simulation whose
 * parameters follow a load ramp. Prints one line per failed check and a closing "N passed, N failed" line. */
#include "thermofriction.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "check.h"

static tf_error E;

static void emit_none(long i, double t, const double *y, void *ctx) { (void)i, (void)t, (void)y, (void)ctx; }

/* The load term's equations written out (law.h's comment), for a linear f(T) = a T + b. */
static double written_out(const tf_law *law, double T, double L)
{
    double f = law->a * T + law->b, S = law->load.saturation;
    double s = S > 0.0 ? S * tanh(fabs(L) / S) : fabs(L);
    double v = law->load.kind == TF_LOAD_PROPORTIONAL ? f * s
               : law->load.combine == TF_COMBINE_PRODUCT ? f * (1.0 + law->load.k * s)
                                                         : f + law->load.k * s;
    return law->load.interaction ? v + law->load.c * T * s : v;
}

static void test_load_term_values_partials_and_coefficients(void)
{
    /* every kind x combination x saturation x interaction; truths: the equations above (values), central
       differences (partials in T and L, derivatives in every coefficient) */
    const tf_load_term terms[] = {
        {TF_LOAD_PROPORTIONAL, TF_COMBINE_PRODUCT, 0.0, 0.0, 0, 0.0},
        {TF_LOAD_PROPORTIONAL, TF_COMBINE_PRODUCT, 0.0, 80.0, 1, -2e-5},
        {TF_LOAD_AFFINE, TF_COMBINE_PRODUCT, 4e-3, 0.0, 1, 3e-5},
        {TF_LOAD_AFFINE, TF_COMBINE_PRODUCT, -2e-3, 150.0, 0, 0.0},
        {TF_LOAD_AFFINE, TF_COMBINE_SUM, 6e-3, 0.0, 0, 0.0},
        {TF_LOAD_AFFINE, TF_COMBINE_SUM, 6e-3, 60.0, 1, 1e-4},
    };
    const double Ts[] = {-5.0, 22.0, 61.0}, Ls[] = {-140.0, 3.0, 47.5, 320.0};
    for (size_t i = 0; i < sizeof terms / sizeof *terms; i++) {
        tf_law law = {TF_LAW_LINEAR, -1.2e-3, 0.31, 0, 0, 0, 0, terms[i]};
        int nc = tf_law_ncoef(&law);
        CHECK(nc == 2 + (terms[i].kind == TF_LOAD_AFFINE) + terms[i].interaction, "term %zu: %d coefficients", i, nc);
        for (size_t a = 0; a < 3; a++)
            for (size_t b = 0; b < 4; b++) {
                double T = Ts[a], L = Ls[b], dT, dL;
                double v = tf_law_eval_load(&law, T, L, &dT, &dL), w = written_out(&law, T, L);
                CHECK(fabs(v - w) <= 1e-15 * fabs(w), "term %zu at (%g, %g): %.17g vs %.17g", i, T, L, v, w);
                double hT = 1e-3, hL = 1e-4 * fabs(L);
                double fT = (tf_law_eval_load(&law, T + hT, L, 0, 0) - tf_law_eval_load(&law, T - hT, L, 0, 0)) /
                            (2 * hT);
                double fL = (tf_law_eval_load(&law, T, L + hL, 0, 0) - tf_law_eval_load(&law, T, L - hL, 0, 0)) /
                            (2 * hL);
                double scale = fabs(v) + 1e-12;
                CHECK(fabs(dT - fT) <= 1e-8 * scale, "term %zu dT at (%g, %g): %g vs %g", i, T, L, dT, fT);
                CHECK(fabs(dL - fL) <= 1e-7 * fabs(fL) + 1e-12 * scale, "term %zu dL at (%g, %g): %g vs %g", i, T,
                      L, dL, fL);
                /* the coefficients in law.h's order: a, b, then k (affine), then c (interaction) */
                for (int k = 0; k < nc; k++) {
                    tf_law up = law, dn = law;
                    int is_k = k == 2 && terms[i].kind == TF_LOAD_AFFINE;
                    double *cu = k == 0 ? &up.a : k == 1 ? &up.b : is_k ? &up.load.k : &up.load.c;
                    double *cd = k == 0 ? &dn.a : k == 1 ? &dn.b : is_k ? &dn.load.k : &dn.load.c;
                    double h = 1e-6 * fmax(fabs(*cu), 1e-3);
                    *cu += h, *cd -= h;
                    double fd = (tf_law_eval_load(&up, T, L, 0, 0) - tf_law_eval_load(&dn, T, L, 0, 0)) / (2 * h);
                    double an = tf_law_coef_derivative(&law, k, T, L);
                    CHECK(fabs(an - fd) <= 1e-7 * fabs(fd) + 1e-12 * scale,
                          "term %zu coefficient %d at (%g, %g): %g vs %g", i, k, T, L, an, fd);
                }
            }
    }
    tf_law plain = {TF_LAW_LINEAR, -1.2e-3, 0.31, 0, 0, 0, 0, {0}};
    CHECK(tf_law_eval_load(&plain, 20.0, NAN, 0, 0) == tf_law_eval(&plain, 20.0, 0), "no load term: L not read");
    CHECK(tf_law_ncoef(&plain) == 2 && tf_law_coef_derivative(&plain, 0, 20.0, NAN) == 20.0, "no load term: base");
}

static void lugre_params(double *p)
{
    memset(p, 0, sizeof(double) * TF_NPARAM);
    p[TF_P_SIGMA0] = 1e5, p[TF_P_SIGMA1] = 316.2, p[TF_P_SIGMA2] = 0.4, p[TF_P_FC] = 1.0, p[TF_P_FS] = 1.5;
    p[TF_P_VS] = 1e-3, p[TF_P_DELTA] = 2.0, p[TF_P_VSMOOTH] = 1e-6;
}

static void test_rt_step_reads_the_load_where_a_law_does(void)
{
    /* fc = mu(T) |N|, fs = 1.5 fc: the steady sliding force at v is g(v) + sigma2 v with g scaled by |N| --
       doubling N doubles the Coulomb and static levels (an analytic truth of the law and the LuGre model) */
    static tf_rt_friction f, g;
    double p[TF_NPARAM], F1 = 0.0, F2 = 0.0;
    lugre_params(p);
    tf_law mu = {TF_LAW_LINEAR, -1e-4, 0.012, 0, 0, 0, 0, {TF_LOAD_PROPORTIONAL, TF_COMBINE_PRODUCT, 0, 0, 0, 0}};
    tf_law mus = mu;
    mus.a *= 1.5, mus.b *= 1.5;
    CHECK(tf_rt_init(&f, TF_FRICTION_LUGRE, p, NULL, &E) == TF_OK, "init");
    CHECK(tf_rt_set_model_i(&f, TF_P_FC, &mu, &E) == TF_OK && tf_rt_set_model_i(&f, TF_P_FS, &mus, &E) == TF_OK,
          "a law of temperature and load set (%s)", E.what);
    g = f;
    for (int i = 0; i < 20000; i++) {
        tf_rt_step(&f, 0.02, 30.0, 100.0, 1e-4, &F1, &E);
        tf_rt_step(&g, 0.02, 30.0, 200.0, 1e-4, &F2, &E);
    }
    double s1 = 0.4 * 0.02, c1 = (0.012 - 30e-4) * 100.0; /* viscous part, Coulomb level at N = 100 */
    double gv = c1 + (1.5 * c1 - c1) * exp(-pow(0.02 / 1e-3, 2.0)); /* Stribeck at v >> vs: ~ c1 */
    CHECK(fabs(F1 - (gv + s1)) <= 1e-9 * F1, "steady sliding at N = 100: %.12g vs %.12g", F1, gv + s1);
    CHECK(fabs((F2 - s1) - 2.0 * (F1 - s1)) <= 1e-9 * F2, "the level doubles with N: %.12g vs %.12g", F2 - s1,
          2.0 * (F1 - s1));
    double before = f.z[0];
    CHECK(tf_rt_step(&f, 0.02, 30.0, NAN, 1e-4, &F1, &E) == TF_ERR_BAD_ARGUMENT && isnan(F1) && f.z[0] == before &&
              !strncmp(E.what, "load (not finite", 16),
          "NaN load refused by a law of the load, state kept (%s)", E.what);
    CHECK(tf_rt_step(&f, 0.02, 30.0, INFINITY, 1e-4, &F1, &E) == TF_ERR_BAD_ARGUMENT, "infinite load refused");
    CHECK(tf_rt_params_at(&f, 30.0, NAN, 0, 0, 0, &E) == TF_ERR_BAD_ARGUMENT, "params_at: NaN load refused");
    double q[TF_NPARAM];
    CHECK(tf_rt_params_at(&f, 30.0, -250.0, q, 0, 0, &E) == TF_OK && fabs(q[TF_P_FC] - 0.009 * 250.0) < 1e-14 * 3,
          "params_at: fc = mu(T) |N| at N = -250 (%g)", q[TF_P_FC]);
    /* a proportional law at zero load gives fc = 0: refused as the domain rule fc > 0 says */
    CHECK(tf_rt_step(&f, 0.02, 30.0, 0.0, 1e-4, &F1, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "fc"),
          "fc = 0 at zero load refused (%s)", E.what);

    /* a model without a law of the load ignores it, NaN included: the same force at any load */
    static tf_rt_friction a, b;
    tf_law lin = {TF_LAW_LINEAR, -1e-3, 1.2, 0, 0, 0, 0, {0}};
    tf_rt_init(&a, TF_FRICTION_LUGRE, p, NULL, &E);
    tf_rt_set_model_i(&a, TF_P_FC, &lin, &E);
    b = a;
    double Fa = 0.0, Fb = 0.0;
    int ok = 1;
    for (int i = 0; i < 100; i++) {
        ok &= tf_rt_step(&a, 0.01 * sin(i * 0.1), 30.0, NAN, 1e-4, &Fa, &E) == TF_OK;
        ok &= tf_rt_step(&b, 0.01 * sin(i * 0.1), 30.0, 1e3 * i, 1e-4, &Fb, &E) == TF_OK;
        ok &= Fa == Fb;
    }
    CHECK(ok, "a load-free model ignores the load (NaN or any number)");

    /* a load term on Model II's dF, a proportional sum, a table with a load term: refused as structure */
    static tf_rt_friction c;
    tf_rt_init(&c, TF_FRICTION_LUGRE, p, NULL, &E);
    tf_law dF = {TF_LAW_CONST, 0.1, 0, 0, 0, 0, 0, {TF_LOAD_AFFINE, TF_COMBINE_SUM, 1e-3, 0, 0, 0}};
    CHECK(tf_rt_set_model_ii(&c, &dF, TF_DF_SCALE, &E) == TF_ERR_BAD_ARGUMENT && !strncmp(E.what, "dF", 2),
          "Model II dF with a load term refused (%s)", E.what);
    tf_law bad = mu;
    bad.load.combine = TF_COMBINE_SUM;
    CHECK(tf_rt_set_model_i(&c, TF_P_FC, &bad, &E) == TF_ERR_BAD_ARGUMENT && !strcmp(E.what, "law"),
          "a proportional sum refused (%s)", E.what);
    bad = mu;
    bad.load.saturation = -1.0;
    CHECK(tf_rt_set_model_i(&c, TF_P_FC, &bad, &E) == TF_ERR_BAD_ARGUMENT, "a negative saturation refused");
}

static void test_model_check_and_a_simulated_load_ramp(void)
{
    /* prescribed sliding at a constant v = 0.05 m/s under a load ramp N(t) = 50 + 100 t, fc = fs = mu |N| (no
       Stribeck effect): LuGre's force follows g(t) = mu N(t) quasi-steadily. Truth (analytic, first order in
       the ramp): z' = g'/sigma0, sigma0 z = g (1 - g'/(sigma0 v)), so F = g (1 - g'/(sigma0 v)) + sigma1
       g'/sigma0 + sigma2 v; the next order is 4e-4 of these corrections (~3e-6 N on 4 N) */
    tf_model m;
    memset(&m, 0, sizeof m);
    m.plant = TF_PLANT_PRESCRIBED;
    m.friction = TF_FRICTION_LUGRE;
    lugre_params(m.p);
    m.fs_follows_fc = 1;
    m.thermal = TF_THERMAL_MODEL_I;
    m.T_const = 25.0;
    tf_law mu = {TF_LAW_CONST, 0.02, 0, 0, 0, 0, 0, {TF_LOAD_PROPORTIONAL, TF_COMBINE_PRODUCT, 0, 0, 0, 0}};
    m.law[TF_P_FC] = mu;
    static const double ut[2] = {0.0, 2.0}, ux[2] = {0.0, 0.1}, lt[2] = {0.0, 2.0}, lv[2] = {50.0, 250.0};
    m.input = (tf_waveform){TF_WAVE_SAMPLED, 0, 0, 0, 0, 1, 0, 0, ut, ux, 2};
    m.load_const = NAN;
    CHECK(tf_model_check(&m, &E) == TF_ERR_BAD_ARGUMENT && !strncmp(E.what, "load", 4),
          "a law of the load and no load: refused (%s)", E.what);
    m.load = (tf_waveform){TF_WAVE_SAMPLED, 0, 0, 0, 0, 1, 0, 0, lt, lv, 2};
    CHECK(tf_model_check(&m, &E) == TF_OK, "with a load ramp: accepted (%s)", E.what);
    CHECK(!tf_prescribed_applies(&m), "the exact prescribed stepping is for a constant load only");
    tf_model_data d;
    tf_model_data_init(&d, &m);
    tf_ode ode = tf_model_ode(&d);
    tf_solver_options opt;
    memset(&opt, 0, sizeof opt);
    opt.method = TF_METHOD_RODAS4;
    opt.rtol = 1e-8;
    double atol[TF_MAX_STATES];
    tf_model_default_atol(&m, opt.rtol, atol);
    opt.atol = atol;
    opt.max_steps = 1000000;
    double t_out[4] = {0.0, 0.5, 1.0, 1.5}, y[TF_MAX_STATES];
    tf_solver_stats st;
    tf_model_initial_state(&m, y);
    tf_status s = tf_solve(&ode, &opt, t_out, 4, y, emit_none, 0, &st, &E);
    CHECK(s == TF_OK, "the ramp simulates (%d, %s)", s, E.what);
    double out[TF_OUT_NFIXED + 1];
    tf_model_outputs(&d, 1.5, y, out); /* (inside the motion: its slope after 2 s is 0) */
    double g = 0.02 * 200.0, gd = 0.02 * 100.0, v = 0.05;
    double truth = g * (1.0 - gd / (1e5 * v)) + 316.2 * gd / 1e5 + 0.4 * v;
    CHECK(fabs(out[TF_OUT_FRICTION_FORCE] - truth) <= 2e-5, "F at 1.5 s: %.9g vs %.9g",
          out[TF_OUT_FRICTION_FORCE], truth);
    CHECK(fabs(out[TF_OUT_FRICTION_FORCE] - (g + 0.4 * v)) > 1e-3, "(the ramp's first-order terms are seen)");
}

int main(void)
{
    test_load_term_values_partials_and_coefficients();
    test_rt_step_reads_the_load_where_a_law_does();
    test_model_check_and_a_simulated_load_ramp();
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
