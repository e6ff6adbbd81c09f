/* Coverage-guided fuzz target (libFuzzer) for the C core's entry points that take user data:
 * a whole model (plant, friction model with any parameters, Model I laws and Model II term,
 * input waveform, sampled temperature) decoded from the fuzzer's bytes, simulated by tf_solve
 * with either method, plus the waveform and law evaluators on their own.
 *
 * Contract checked (abort() on a violation, so the fuzzer reports it):
 * - tf_model_check accepts the model or refuses it naming a field; only accepted models are
 *   simulated (a controller embedding the core must check what users give it the same way);
 * - any parameter value (NaN, +-inf, negative, zero, subnormal, huge) is allowed: nothing may
 *   crash, read or write out of bounds (run under AddressSanitizer), hit undefined behaviour
 *   (UndefinedBehaviorSanitizer) or hang (max_steps bounds the work; libFuzzer's -timeout);
 * - on an accepted model, tf_solve returns one of the documented statuses; on TF_OK it has emitted every output
 *   sample exactly once, in order, and every emitted state is finite (no silent garbage; the
 *   output channels are computed too, but a model given finite yet absurd magnitudes, such as
 *   a 1e165 m amplitude, may overflow them: the Python package rejects non-finite outputs);
 * - a waveform's next corner or reversal lies strictly after t (else the driver could stall).
 * The structural preconditions the header documents are respected by construction: sampled
 * times and law knots strictly increasing, 1..64 GMS elements, an output grid that does not
 * decrease. Everything else is arbitrary.
 *
 * Build: cmake -S core -B build-fuzz -DCMAKE_C_COMPILER=clang -DTF_BUILD_FUZZERS=ON
 * Run:   build-fuzz/fuzz_simulate -max_total_time=60 core/fuzz/corpus   (see docs/hardening.md) */
#include "thermofriction.h"
#include "fuzz_reader.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const tf_model *current;

/* A broken contract: say which, and the model, then abort so that the fuzzer keeps the input. */
#define FAIL(why) fail_(why, __LINE__)
static void fail_(const char *why, int line)
{
    const tf_model *m = current;
    fprintf(stderr, "fuzz_simulate.c:%d: %s\n", line, why);
    if (m) {
        fprintf(stderr, "  plant %d (m %g c %g k %g T_em %g m_e %g k_s %g v_0 %g) friction %d thermal %d form %d "
                "input kind %d (A %g f %g rise %g off %g slew %g t0 %g) T %g T_n %d\n  p:",
                m->plant, m->m, m->c, m->k, m->T_em, m->m_e, m->k_s, m->v_0, m->friction, m->thermal, m->dF_form,
                m->input.kind, m->input.amplitude, m->input.frequency, m->input.rise, m->input.offset,
                m->input.slew, m->input.t0, m->T_const, m->T_n);
        for (int i = 0; i < TF_NPARAM; i++) fprintf(stderr, " %g", m->p[i]);
        fprintf(stderr, "\n");
    }
    abort();
}

/* A number: mostly a signed power of ten between 1e-9 and 1e7 (where the models live), sometimes
 * the raw bits of a double (NaN, infinities, subnormals, anything). */
static double number(reader *r)
{
    uint8_t sel = byte(r);
    if (sel < 40) {
        double d = 0.0;
        uint8_t b[8];
        for (int i = 0; i < 8; i++) b[i] = byte(r);
        memcpy(&d, b, sizeof d);
        return d;
    }
    if (sel < 48) return 0.0;
    double mant = 1.0 + byte(r) / 32.0;
    double e = (double)(byte(r) % 17) - 9.0;
    return (sel & 1 ? -1.0 : 1.0) * mant * pow(10.0, e);
}

/* Strictly increasing knots: a start and positive gaps. */
static int knots(reader *r, double *x, double *y, int nmax)
{
    int n = 2 + byte(r) % (nmax - 1);
    double start = number(r);
    if (!isfinite(start)) start = 0.0;
    x[0] = start;
    for (int i = 1; i < n; i++) {
        double gap = fabs(number(r));
        if (!(gap > 0) || !isfinite(gap)) gap = 1.0;
        x[i] = x[i - 1] + gap;
        if (!(x[i] > x[i - 1]) || !isfinite(x[i])) { n = i; break; }
    }
    for (int i = 0; i < n; i++) y[i] = number(r);
    return n < 2 ? 0 : n;
}

enum { MAXK = 12, MAXOUT = 16 };

typedef struct {
    double xs[TF_NPARAM + 1][MAXK], ys[TF_NPARAM + 1][MAXK], ds[TF_NPARAM + 1][MAXK];
    double wt[MAXK], wv[MAXK], Tt[MAXK], Tv[MAXK];
} storage;

static void law(reader *r, tf_law *L, double *x, double *y, double *d)
{
    memset(L, 0, sizeof *L);
    L->kind = 1 + byte(r) % 6;
    L->a = number(r);
    L->b = number(r);
    if (L->kind == TF_LAW_POLY) {
        L->n = 1 + byte(r) % 5;
        for (int i = 0; i < L->n; i++) y[i] = number(r);
        L->y = y;
    } else if (L->kind == TF_LAW_PWL || L->kind == TF_LAW_TABLE) {
        L->n = knots(r, x, y, MAXK);
        if (L->n < 2) { L->kind = TF_LAW_CONST; return; }
        L->x = x;
        L->y = y;
        if (L->kind == TF_LAW_TABLE) {
            tf_pchip_slopes(L->n, x, y, d);
            L->d = d;
        }
    }
}

typedef struct {
    tf_model_data *m;
    long count;
    double last_t;
    int nonfinite, channel;
    double t_bad;
} sink;

static void emit(long i, double t, const double *y, void *ctx)
{
    sink *s = (sink *)ctx;
    if (i != s->count) FAIL("an output sample emitted twice or skipped");
    if (s->count && t < s->last_t) FAIL("output times decrease");
    s->count++;
    s->last_t = t;
    double out[TF_OUT_NFIXED + TF_MAX_FRICTION_STATES + 8];
    tf_model_outputs(s->m, t, y, out); /* computed (sanitisers watch it), not required finite:
                                          finite but absurd magnitudes (1e165 m) may overflow */
    for (int k = 0; k < tf_model_nstate(s->m->model); k++)
        if (!isfinite(y[k]) && !s->nonfinite) s->nonfinite = 1, s->channel = k, s->t_bad = t;
}

static void check_waveform(const tf_waveform *w, double t)
{
    (void)tf_waveform_value(w, t);
    (void)tf_waveform_slope(w, t);
    if (!isfinite(t)) return;
    double c = tf_waveform_next_corner(w, t);
    if (c <= t) FAIL("next corner not after t");
    double rv = tf_waveform_next_reversal(w, t);
    if (rv <= t) FAIL("next reversal not after t");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    static storage st;
    static tf_model m;
    memset(&st, 0, sizeof st);
    memset(&m, 0, sizeof m);
    current = &m;

    m.plant = byte(&r) % 3;
    m.m = number(&r);
    m.c = number(&r);
    m.k = number(&r);
    m.T_em = number(&r);
    m.m_e = number(&r);
    if (byte(&r) & 1) { m.k_s = number(&r); m.v_0 = number(&r); }
    m.friction = byte(&r) % 6;
    for (int i = 0; i < TF_NPARAM; i++) m.p[i] = number(&r);
    m.fs_follows_fc = byte(&r) & 1;
    if (m.friction == TF_FRICTION_GMS) {
        m.gms.n = 1 + byte(&r) % TF_MAX_FRICTION_STATES;
        for (int i = 0; i < m.gms.n; i++) { m.gms.k[i] = number(&r); m.gms.w[i] = number(&r); }
    }

    m.thermal = byte(&r) % 3;
    if (m.thermal == TF_THERMAL_MODEL_I) {
        for (int i = 0; i < TF_NPARAM; i++)
            if (byte(&r) < 64) law(&r, &m.law[i], st.xs[i], st.ys[i], st.ds[i]);
    } else if (m.thermal == TF_THERMAL_MODEL_II) {
        law(&r, &m.dF, st.xs[TF_NPARAM], st.ys[TF_NPARAM], st.ds[TF_NPARAM]);
        m.dF_form = byte(&r) & 1;
    }

    tf_waveform *w = &m.input;
    w->kind = byte(&r) % 6;
    w->amplitude = number(&r);
    w->frequency = number(&r);
    w->rise = number(&r);
    w->offset = number(&r);
    w->direction = byte(&r) & 1 ? 1.0 : -1.0;
    w->slew = number(&r);
    w->t0 = number(&r);
    if (w->kind == TF_WAVE_SAMPLED) {
        w->n = knots(&r, st.wt, st.wv, MAXK);
        if (w->n < 2) w->kind = TF_WAVE_ZERO;
        w->t = st.wt;
        w->v = st.wv;
    }

    m.T_const = number(&r);
    if (byte(&r) & 1) {
        m.T_n = knots(&r, st.Tt, st.Tv, MAXK);
        m.T_t = st.Tt;
        m.T_v = st.Tv;
    }
    static tf_model_data md;
    tf_model_data_init(&md, &m);

    /* user data goes through tf_model_check first; what it refuses is not simulated */
    tf_error e;
    tf_status checked = tf_model_check(&m, &e);
    int valid = checked == TF_OK;
    if (e.code != checked) FAIL("the error record's code is not the status returned");
    if (!valid && (checked != TF_ERR_BAD_ARGUMENT || !e.what[0] || strcmp(e.where, "model") != 0))
        FAIL("refused without naming a field");
    if (valid && (e.what[0] || e.where[0])) FAIL("accepted but named a field");

    /* the waveform and laws on their own, at an arbitrary time/temperature */
    double probe = number(&r);
    check_waveform(w, probe);
    for (int i = 0; i < TF_NPARAM; i++)
        if (m.law[i].kind) (void)tf_law_eval(&m.law[i], probe, 0);

    /* an output grid that does not decrease (arbitrary otherwise: NaN, inf, repeats) */
    int n_out = 1 + byte(&r) % MAXOUT;
    double t_out[MAXOUT];
    t_out[0] = fabs(number(&r));
    if (!isfinite(t_out[0])) t_out[0] = 0.0;
    for (int i = 1; i < n_out; i++) {
        double gap = fabs(number(&r));
        t_out[i] = t_out[i - 1] + (isfinite(gap) ? gap : 1.0);
    }

    if (!valid) return 0;
    int n = tf_model_nstate(&m);
    if (n < 0 || n > TF_MAX_STATES) FAIL("state count out of range");
    double y[TF_MAX_STATES], atol[TF_MAX_STATES];
    tf_model_initial_state(&m, y);
    tf_model_state_scale(&m, atol);
    double rtol = pow(10.0, -(double)(2 + byte(&r) % 9));
    for (int i = 0; i < n; i++) atol[i] = isfinite(atol[i]) && atol[i] > 0 ? rtol * atol[i] : rtol;
    tf_solver_options opt = {.method = byte(&r) % 3, .rtol = rtol, .atol = atol, .max_steps = 400};
    tf_ode ode = tf_model_ode(&md);
    tf_solver_stats stats;
    sink s = {&md, 0, 0.0, 0, 0, 0.0};
    tf_status status = tf_solve(&ode, &opt, t_out, n_out, y, emit, &s, &stats, &e);
    if (status != TF_OK && status != TF_ERR_NONFINITE && status != TF_ERR_STEP_UNDERFLOW &&
        status != TF_ERR_MAX_STEPS && status != TF_ERR_BAD_ARGUMENT)
        FAIL("unknown status");
    if (e.code != status || (status != TF_OK && (strcmp(e.where, "solver") != 0 || !e.what[0])))
        FAIL("the error record does not match the status");
    if (status == TF_OK && s.count != n_out) FAIL("TF_OK but not every sample emitted");
    if (status == TF_OK && s.nonfinite) {
        fprintf(stderr, "state %d at t = %g\n", s.channel, s.t_bad);
        FAIL("TF_OK with a non-finite state");
    }
    return 0;
}

#ifdef TF_FUZZ_REPLAY
#include "replay_main.h"
#endif
