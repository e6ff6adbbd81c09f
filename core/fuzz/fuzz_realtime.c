/* Coverage-guided fuzz target (libFuzzer) for the real-time and control APIs (realtime.h,
 * control.h): the fuzzer's bytes are a program of up to 64 calls on two friction objects, a PID
 * and a closed loop -- init, from_model, set_model_i / _ii, set_param, reset, params_at, bursts of
 * steps and observer steps, advance, pid_init / pid_step, loop_run -- with arbitrary arguments:
 * NULL pointers wherever the API takes one, unknown kinds and indices, laws with any number of
 * breakpoints in any order (duplicates, NaN), and values that are mostly powers of ten from 1e-9
 * to 1e7 and otherwise NaN, +-inf, +-1e308, subnormals or raw bits.
 *
 * Contract checked (abort() on a violation, so that the fuzzer keeps the input):
 * - nothing crashes, reads or writes out of bounds (ASan), hits undefined behaviour (UBSan) or hangs
 *   (the work per input is bounded: libFuzzer's -timeout catches a loop that is not);
 * - every call returns TF_OK, TF_ERR_BAD_ARGUMENT or TF_ERR_NONFINITE, and its error record (status.h)
 *   agrees: the same code, `what` and `where` empty exactly on TF_OK; a loop names a period in the run;
 * - a refused call changes nothing: the object (states, GMS modes, parameters, laws) or the PID is
 *   byte for byte what it was; a refused loop writes no output;
 * - a step on TF_OK gives a finite force and finite states; a refused one writes NaN to the force (or
 *   the PID's u) exactly then; the internal states are finite at all times.
 * The one precondition kept by construction: a law's arrays hold the n values it claims and are
 * not changed while an object may use them (each decoded law has its own storage).
 *
 * Build: cmake -S core -B build-fuzz -DCMAKE_C_COMPILER=clang -DTF_BUILD_FUZZERS=ON
 * Run:   build-fuzz/fuzz_realtime -max_total_time=60 core/fuzz/corpus_realtime   (docs/hardening.md) */
#include "thermofriction.h"
#include "fuzz_reader.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define FAIL(why) fail_(why, __LINE__)
static void fail_(const char *why, int line)
{
    fprintf(stderr, "fuzz_realtime.c:%d: %s\n", line, why);
    abort();
}

/* A number: mostly a signed power of ten between 1e-9 and 1e7, sometimes a special value (NaN,
 * infinities, the extremes, a subnormal) or the raw bits of a double. */
static double number(reader *r)
{
    static const double special[] = {NAN, INFINITY, -INFINITY, 0.0, -0.0, DBL_MAX, -DBL_MAX, 1e300, -1e300,
                                     4.9e-324, DBL_MIN, 1.0};
    uint8_t sel = byte(r);
    if (sel < 24) {
        double d = 0.0;
        uint8_t b[8];
        for (int i = 0; i < 8; i++) b[i] = byte(r);
        memcpy(&d, b, sizeof d);
        return d;
    }
    if (sel < 36) return special[sel - 24];
    if (sel < 40) return 0.0;
    double mant = 1.0 + byte(r) / 32.0;
    double e = (double)(byte(r) % 17) - 9.0;
    return (sel & 1 ? -1.0 : 1.0) * mant * pow(10.0, e);
}

enum { MAXK = 8, NLAWS = 48, NOPS = 64, MAXN = 48 };

/* Storage for the laws' arrays: one slot per decoded law, never reused within an input. */
static struct {
    double x[MAXK], y[MAXK], d[MAXK];
} pool[NLAWS];
static int used;

/* A law of any kind (known or not) with n = 0..MAXK breakpoints in any order, or NULL arrays; half of them with a
 * load term of any kind, combination and numbers (law.h: tf_load_term). */
static const tf_law *law(reader *r, tf_law *L)
{
    uint8_t sel = byte(r);
    if (sel < 8 || used >= NLAWS) return NULL;
    memset(L, 0, sizeof *L);
    L->kind = byte(r) % 8; /* 7: unknown */
    L->a = number(r);
    L->b = number(r);
    int slot = used++;
    L->n = byte(r) % (MAXK + 1);
    uint8_t shape = byte(r);
    double x = number(r);
    for (int i = 0; i < L->n; i++) {
        pool[slot].x[i] = x;
        /* mostly increasing, sometimes a repeat or a step back */
        double gap = shape & 1 ? fabs(number(r)) : (byte(r) % 4 ? 1.0 + byte(r) : 0.0);
        x += (shape & 2) && i == 1 ? -gap : gap;
        pool[slot].y[i] = number(r);
    }
    if (L->kind == TF_LAW_TABLE && L->n >= 1 && L->n <= MAXK && !(shape & 4))
        tf_pchip_slopes(L->n, pool[slot].x, pool[slot].y, pool[slot].d);
    L->x = shape & 8 ? NULL : pool[slot].x;
    L->y = shape & 16 ? NULL : pool[slot].y;
    L->d = shape & 4 ? NULL : pool[slot].d;
    if (sel >= 128) {
        L->load.kind = byte(r) % 4; /* 3: unknown */
        L->load.combine = byte(r) % 3;
        L->load.k = number(r);
        L->load.saturation = number(r);
        L->load.interaction = byte(r) & 1;
        L->load.c = number(r);
    }
    return L;
}

/* A step's load: NaN (none) or any number. */
static double load_of(reader *r) { return byte(r) & 1 ? NAN : number(r); }

static tf_rt_friction obj[2];
static tf_gms_elements gms;
static tf_pid pid;

static tf_rt_friction *pick(reader *r)
{
    uint8_t b = byte(r);
    return b < 16 ? NULL : &obj[b & 1];
}

#define SAME(a, b) (memcmp(&(a), &(b), sizeof(a)) == 0) /* bit for bit: NaN equals NaN */

static int same_law(const tf_law *a, const tf_law *b)
{
    const tf_load_term *s = &a->load, *t = &b->load;
    return SAME(a->kind, b->kind) && SAME(a->a, b->a) && SAME(a->b, b->b) && SAME(a->n, b->n) && a->x == b->x &&
           a->y == b->y && a->d == b->d && s->kind == t->kind && s->combine == t->combine && SAME(s->k, t->k) &&
           SAME(s->saturation, t->saturation) && s->interaction == t->interaction && SAME(s->c, t->c);
}

/* The object as it was: states, model, laws, GMS elements and modes (not its status or cache). */
static int same_object(const tf_rt_friction *f, const tf_rt_friction *g)
{
    const tf_model *a = &f->model, *b = &g->model;
    if (!SAME(f->z, g->z) || !SAME(a->p, b->p) || a->friction != b->friction || a->thermal != b->thermal ||
        a->dF_form != b->dF_form || a->fs_follows_fc != b->fs_follows_fc || !same_law(&a->dF, &b->dF) ||
        a->gms.n != b->gms.n || !SAME(a->gms.k, b->gms.k) || !SAME(a->gms.w, b->gms.w) ||
        !SAME(f->data.gms.mode, g->data.gms.mode))
        return 0;
    for (int i = 0; i < TF_NPARAM; i++)
        if (!same_law(&a->law[i], &b->law[i])) return 0;
    return 1;
}

/* The error record of every call (status.h). */
static tf_error err;

static void check_record(tf_status status)
{
    if (status != TF_OK && status != TF_ERR_BAD_ARGUMENT && status != TF_ERR_NONFINITE) FAIL("unknown status");
    if (err.code != status) FAIL("the error record's code is not the status returned");
    if ((status == TF_OK) != (err.what[0] == 0) || (status == TF_OK) != (err.where[0] == 0))
        FAIL("what and where are not empty exactly on TF_OK");
}

static void check_object(const tf_rt_friction *f, tf_status status, const tf_rt_friction *before)
{
    check_record(status);
    if (f && status != TF_OK && before && !same_object(f, before)) FAIL("a refused call changed the object");
}

static int same_pid(const tf_pid *a, const tf_pid *b)
{
    return SAME(a->kp, b->kp) && SAME(a->ki, b->ki) && SAME(a->kd, b->kd) && SAME(a->tau_d, b->tau_d) &&
           SAME(a->integral, b->integral) && SAME(a->d_filtered, b->d_filtered) && SAME(a->e_prev, b->e_prev) &&
           a->started == b->started;
}

static void check_states(void)
{
    for (int k = 0; k < 2; k++)
        for (int j = 0; j < TF_MAX_FRICTION_STATES; j++)
            if (!isfinite(obj[k].z[j])) FAIL("a non-finite internal state");
}

static void params(reader *r, double *p)
{
    for (int i = 0; i < TF_NPARAM; i++) p[i] = number(r);
}

static void decode_gms(reader *r)
{
    memset(&gms, 0, sizeof gms);
    gms.n = byte(r) % (TF_MAX_FRICTION_STATES + 8); /* 0 and 65..71: refused */
    int m = gms.n < TF_MAX_FRICTION_STATES ? gms.n : TF_MAX_FRICTION_STATES;
    double wsum = 0.0;
    for (int i = 0; i < m; i++) {
        gms.k[i] = number(r);
        gms.w[i] = 1.0 + byte(r) % 4;
        wsum += gms.w[i];
    }
    if (byte(r) & 1) /* mostly weights that sum to one, as a valid model needs */
        for (int i = 0; i < m; i++) gms.w[i] /= wsum;
}

/* The loop: references, outputs with a sentinel to show a refusal wrote nothing. */
static void run_loop(reader *r)
{
    static double x_ref[MAXN], v_ref[MAXN], out[3][MAXN];
    tf_loop L;
    memset(&L, 0, sizeof L);
    L.mass = number(r);
    L.plant = pick(r);
    L.T_plant = number(r);
    L.pid = pid;
    if (byte(r) & 1) tf_pid_init(&L.pid, 1e3 * (1 + byte(r)), 1e4 * byte(r), byte(r), 1e-4 * byte(r), NULL);
    L.compensation = byte(r) % 4; /* 3: unknown */
    L.comp = pick(r);
    L.T_comp = number(r);
    L.observer_gain = number(r);
    L.dt = byte(r) & 1 ? 1e-4 : number(r);
    L.substeps = (int)(byte(r) % 5) - 1;
    long n = (long)(byte(r) % (MAXN + 1)) - (byte(r) == 255);
    double A = number(r);
    for (int i = 0; i < MAXN; i++) {
        x_ref[i] = A * sin(0.1 * i);
        v_ref[i] = A * cos(0.1 * i);
        out[0][i] = out[1][i] = out[2][i] = -12345.0;
    }
    if (n > 0 && byte(r) < 32) x_ref[byte(r) % n] = number(r);
    if (n > 0 && byte(r) < 32) v_ref[byte(r) % n] = number(r);
    uint8_t nulls = byte(r);
    tf_status status = tf_loop_run(byte(r) < 4 ? NULL : &L, n, nulls & 1 ? NULL : x_ref, nulls & 2 ? NULL : v_ref,
                                   nulls & 4 ? NULL : out[0], nulls & 8 ? NULL : out[1], nulls & 16 ? NULL : out[2],
                                   &err);
    check_record(status);
    if (status != TF_OK && !(err.index >= -1 && err.index < (n > 0 ? n : 1))) FAIL("loop: a period outside the run");
    if (status == TF_ERR_BAD_ARGUMENT)
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < MAXN; i++)
                if (out[k][i] != -12345.0) FAIL("a refused loop wrote an output");
    if (status == TF_OK)
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < n; i++)
                if (!(nulls & (4 << k)) && !isfinite(out[k][i])) FAIL("loop: TF_OK with a non-finite output");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    static tf_rt_friction before;
    memset(obj, 0, sizeof obj);
    memset(&pid, 0, sizeof pid);
    used = 0;
    for (int op = 0; op < NOPS && r.n; op++) {
        tf_rt_friction *f = pick(&r);
        if (f) before = *f;
        tf_status status = TF_OK;
        tf_law L;
        double p[TF_NPARAM], F;
        switch (byte(&r) % 12) {
        case 0: { /* init */
            int kind = byte(&r) % 8;
            params(&r, p);
            if (kind == TF_FRICTION_GMS || byte(&r) < 16) decode_gms(&r);
            uint8_t nulls = byte(&r);
            status = tf_rt_init(f, kind, nulls & 1 ? NULL : p, nulls & 2 ? NULL : &gms, &err);
            check_object(f, status, NULL);
            break;
        }
        case 1: { /* from_model: a simulation model's friction part */
            static tf_model m;
            memset(&m, 0, sizeof m);
            m.friction = byte(&r) % 8;
            params(&r, m.p);
            m.fs_follows_fc = byte(&r) & 1;
            if (m.friction == TF_FRICTION_GMS) decode_gms(&r), m.gms = gms;
            m.thermal = byte(&r) % 4;
            if (m.thermal == TF_THERMAL_MODEL_I) {
                for (int k = byte(&r) % 3; k > 0; k--) {
                    int i = byte(&r) % TF_NPARAM;
                    const tf_law *l = law(&r, &L);
                    if (l) m.law[i] = *l;
                }
            } else if (m.thermal == TF_THERMAL_MODEL_II) {
                const tf_law *l = law(&r, &L);
                if (l) m.dF = *l;
                m.dF_form = byte(&r) % 3;
            }
            status = tf_rt_from_model(f, byte(&r) < 8 ? NULL : &m, &err);
            check_object(f, status, f ? &before : NULL);
            break;
        }
        case 2: { /* Model I */
            int param = (int)(byte(&r) % (TF_NPARAM + 2)) - 1;
            status = tf_rt_set_model_i(f, param, law(&r, &L), &err);
            check_object(f, status, f ? &before : NULL);
            break;
        }
        case 3: { /* Model II */
            const tf_law *l = law(&r, &L);
            status = tf_rt_set_model_ii(f, l, byte(&r) % 3, &err);
            check_object(f, status, f ? &before : NULL);
            break;
        }
        case 4: { /* set_param */
            int param = (int)(byte(&r) % (TF_NPARAM + 2)) - 1;
            status = tf_rt_set_param(f, param, number(&r), &err);
            check_object(f, status, f ? &before : NULL);
            break;
        }
        case 5:
            status = tf_rt_reset(f, &err);
            check_object(f, status, NULL);
            break;
        case 6: { /* params_at */
            double T = number(&r), Lo = load_of(&r), lambda = -1.0, dF = -1.0;
            uint8_t nulls = byte(&r);
            for (int i = 0; i < TF_NPARAM; i++) p[i] = -7.0;
            status = tf_rt_params_at(f, T, Lo, nulls & 1 ? NULL : p, nulls & 2 ? NULL : &lambda, nulls & 4 ? NULL : &dF,
                                     &err);
            check_object(f, status, f ? &before : NULL);
            if (status != TF_OK && (p[0] != -7.0 || lambda != -1.0 || dF != -1.0)) FAIL("a refused params_at wrote");
            break;
        }
        case 7: { /* a burst of steps at one temperature, one of them perhaps a bad sample */
            int k = 1 + byte(&r) % 32, bad = byte(&r) % 40;
            double v = number(&r), T = number(&r), dt = byte(&r) & 1 ? 1e-4 : number(&r), w = number(&r);
            double Lo = load_of(&r);
            for (int i = 0; i < k; i++) {
                double vi = i == bad ? number(&r) : v * sin(w * i);
                if (f) before = *f;
                int null_F = (byte(&r) & 1) && byte(&r) < 4; /* (the bytes of the former two variants) */
                F = 0.0;
                status = tf_rt_step(f, vi, T, Lo, dt, null_F ? NULL : &F, &err);
                check_object(f, status, f ? &before : NULL);
                if (status == TF_OK && !isfinite(F)) FAIL("step: TF_OK with a non-finite force");
                if (!null_F && (status != TF_OK) != isnan(F)) FAIL("tf_rt_step: *F NaN not exactly on a refusal");
            }
            break;
        }
        case 8: { /* observer steps */
            int k = 1 + byte(&r) % 16;
            double v = number(&r), e = number(&r), gain = number(&r), T = number(&r), Lo = load_of(&r);
            double dt = byte(&r) & 1 ? 1e-4 : number(&r);
            for (int i = 0; i < k; i++) {
                if (f) before = *f;
                int null_F = (byte(&r) & 1) && byte(&r) < 4;
                F = 0.0;
                status = tf_observer_step(f, v, e * i, gain, T, Lo, dt, null_F ? NULL : &F, &err);
                check_object(f, status, f ? &before : NULL);
                if (status == TF_OK && !isfinite(F)) FAIL("observer: TF_OK with a non-finite force");
                if (!null_F && (status != TF_OK) != isnan(F)) FAIL("tf_observer_step: *F NaN not exactly on a refusal");
            }
            break;
        }
        case 9: { /* advance on its own, with arbitrary (unchecked) parameters: memory safety only */
            double z[TF_MAX_FRICTION_STATES] = {0}, dz[TF_MAX_FRICTION_STATES], extra[TF_MAX_FRICTION_STATES];
            int kind = byte(&r) % 8;
            params(&r, p);
            for (int i = 0; i < TF_MAX_FRICTION_STATES; i++) extra[i] = 1e-3 * i;
            uint8_t nulls = byte(&r);
            if (kind == TF_FRICTION_GMS || nulls & 32) decode_gms(&r);
            status = tf_rt_advance(kind, nulls & 1 ? NULL : p, nulls & 2 ? NULL : &gms, nulls & 4 ? NULL : z,
                                   number(&r), number(&r), nulls & 8 ? NULL : extra, nulls & 16 ? NULL : dz, &F, &err);
            if (status != TF_OK && status != TF_ERR_BAD_ARGUMENT) FAIL("advance: unknown status");
            if (err.code != status || (status != TF_OK && !isnan(F))) FAIL("advance: record or *F wrong");
            status = tf_rt_thermal_force(number(&r), number(&r), nulls & 64 ? NULL : p, number(&r), number(&r), &F,
                                         &err);
            if (err.code != status || (status != TF_OK && !isnan(F))) FAIL("thermal_force: record or *F wrong");
            status = TF_OK;
            break;
        }
        case 10: { /* PID */
            tf_pid *c = byte(&r) < 16 ? NULL : &pid;
            if (byte(&r) & 1) {
                double kp = number(&r), ki = number(&r), kd = number(&r), tau = number(&r);
                tf_pid keep = pid;
                status = tf_pid_init(c, kp, ki, kd, tau, &err);
                if (status != TF_OK && status != TF_ERR_BAD_ARGUMENT) FAIL("pid_init: unknown status");
                check_record(status);
                if (status != TF_OK && !same_pid(&keep, &pid)) FAIL("a refused pid_init changed the PID");
            }
            int k = 1 + byte(&r) % 16;
            double e = number(&r), dt = byte(&r) & 1 ? 1e-4 : number(&r);
            for (int i = 0; i < k; i++) {
                tf_pid keep = pid;
                double u = 0.0;
                int null_u = (byte(&r) & 1) && byte(&r) < 4;
                status = tf_pid_step(c, e * i, dt, null_u ? NULL : &u, &err);
                check_record(status);
                int refused = status != TF_OK;
                if (!null_u && refused != isnan(u)) FAIL("pid: *u NaN not exactly on a refusal");
                if (refused && !same_pid(&keep, &pid)) FAIL("a refused pid step changed the PID");
                if (!refused && !isfinite(u)) FAIL("pid: an accepted step with a non-finite u");
            }
            break;
        }
        default:
            run_loop(&r);
        }
        check_states();
    }
    return 0;
}

#ifdef TF_FUZZ_REPLAY
#include "replay_main.h"
#endif
