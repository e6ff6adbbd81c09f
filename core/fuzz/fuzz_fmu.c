/* Coverage-guided fuzz target (libFuzzer) for the FMI 2.0 co-simulation wrapper (core/fmu/fmi2_cs.c
 * around fmu_common.c, the logic the FMI 3.0 wrapper shares):
 * its resource file and every entry point. The fuzzer's bytes are
 *   - the model description the FMU loads (resources/model.tfm: a two-byte length, then that much text;
 *     the seeds are files the Python exporter wrote), written to a temporary folder, and
 *   - a program of up to 48 FMI calls on the instance: fmi2SetupExperiment, Enter/ExitInitializationMode,
 *     fmi2SetReal / fmi2GetReal (declared, undeclared and huge value references; NULL arrays),
 *     fmi2SetRealInputDerivatives (NULL arrays, orders 0-2), fmi2DoStep (at the FMU's time or another,
 *     steps from 1e-9 s to 1e300 s, NaN), FMU states (get, set, free), reset, terminate, logging, the
 *     integer / boolean / string accessors and the functions the FMU does not provide;
 *     the instantiation itself with the right GUID, a wrong one or NULL.
 * Values are mostly signed powers of ten (1e-9 .. 1e7), sometimes NaN, +-inf, +-1e300, subnormals or raw
 * bits.
 *
 * Contract checked (abort() on a violation, so that the fuzzer keeps the input):
 * - nothing crashes, reads or writes out of bounds (ASan), hits undefined behaviour (UBSan, with
 *   float-cast-overflow in the tests) or hangs (the work per call is bounded: this target builds the
 *   wrapper with at most MAX_FIXED_STEPS fixed steps and MAX_ADAPTIVE_STEPS adaptive ones per step);
 * - every call returns fmi2OK, fmi2Warning or fmi2Error, and an fmi2Error (or a failed instantiation)
 *   comes with a logged error message;
 * - a step answered fmi2OK / fmi2Warning moved the FMU's time (fmi2LastSuccessfulTime) by exactly h and
 *   left finite outputs; a refused one moved neither the time nor any output (bit for bit);
 * - a refused fmi2SetReal or fmi2SetRealInputDerivatives changed no variable;
 * - the undeclared value references are never read or written with fmi2OK: 13-15 always, 7-11 without an
 *   "estimator" line in the resources, 12 without a "load_input" line;
 * - the calls follow the standard's state machine (this target keeps its own model of the modes, moved by
 *   the calls answered OK; fmi2SetFMUstate moves none): fmi2EnterInitializationMode only when instantiated,
 *   fmi2ExitInitializationMode only in initialization mode, fmi2DoStep and fmi2Terminate only in step mode,
 *   no fmi2SetReal of a variable once terminated, fmi2GetRealStatus only once initialized (issue 41);
 * - no step answered OK ends past a stop time the last fmi2SetupExperiment defined (1e-9 relative, the
 *   FMU's rounding) (issue 41).
 *
 * Build: cmake -S core -B build-fuzz -DCMAKE_C_COMPILER=clang -DTF_BUILD_FUZZERS=ON
 * Run:   build-fuzz/fuzz_fmu -max_total_time=600 core/fuzz/corpus_fmu   (docs/hardening.md) */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include "fmi2Functions.h"
#include "fuzz_reader.h"

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#define FAIL(why) fail_(why, __LINE__)
static void fail_(const char *why, int line)
{
    fprintf(stderr, "fuzz_fmu.c:%d: %s\n", line, why);
    abort();
}

static double number(reader *r)
{
    static const double special[] = {NAN, INFINITY, -INFINITY, 0.0, -0.0, DBL_MAX, -DBL_MAX, 1e300, -1e300,
                                     4.9e-324, DBL_MIN, 1.0};
    uint8_t sel = byte(r);
    if (sel < 16) {
        double d = 0.0;
        uint8_t b[8];
        for (int i = 0; i < 8; i++) b[i] = byte(r);
        memcpy(&d, b, sizeof d);
        return d;
    }
    if (sel < 28) return special[sel - 16];
    if (sel < 32) return 0.0;
    double mant = 1.0 + byte(r) / 32.0;
    double e = (double)(byte(r) % 17) - 9.0;
    return (sel & 1 ? -1.0 : 1.0) * mant * pow(10.0, e);
}

/* ---- the logger: counts error messages, checks that each says something ---- */
static int errors_logged;
static void logger(fmi2ComponentEnvironment env, fmi2String name, fmi2Status status, fmi2String category,
                   fmi2String message, ...)
{
    if (!message || !message[0] || !category) FAIL("a log message without text or category");
    if (status == fmi2Error || status == fmi2Fatal) errors_logged++;
}

static void check_status(fmi2Status s, int errors_before)
{
    if (s != fmi2OK && s != fmi2Warning && s != fmi2Error) FAIL("a status other than OK, Warning or Error");
    if (s == fmi2Error && errors_logged == errors_before) FAIL("fmi2Error without a logged message");
}

/* ---- the resource file ---- */
static char dir[64], uri[128];
static void write_resources(const char *text, size_t len)
{
    if (!dir[0]) {
        snprintf(dir, sizeof dir, "/tmp/tf-fuzz-fmu-XXXXXX");
        if (!mkdtemp(dir)) FAIL("mkdtemp");
    }
    char path[128];
    snprintf(path, sizeof path, "%s/model.tfm", dir);
    FILE *f = fopen(path, "wb");
    if (!f) FAIL("cannot write the resource file");
    fwrite(text, 1, len, f);
    fclose(f);
}

/* Value references the resource file names ("var VR role ..."), and the guid it gives. */
enum { MAXV = 64 };
static unsigned vars[MAXV];
static int nvars, step_vr;
static int has_estimator, has_load; /* an "estimator" line (value references 7-11), a "load_input" line (12) */
static char guid[80];
static void scan_resources(const char *text)
{
    nvars = 0, step_vr = -1, guid[0] = 0, has_estimator = 0, has_load = 0;
    for (const char *line = text; line && *line; line = strchr(line, '\n'), line = line ? line + 1 : 0) {
        unsigned vr;
        char role[16];
        if (sscanf(line, "var %u %15s", &vr, role) == 2 && nvars < MAXV) {
            vars[nvars++] = vr;
            if (strcmp(role, "step") == 0) step_vr = (int)vr;
        }
        sscanf(line, "guid %79s", guid);
        char key[32];
        if (line[0] != '#' && sscanf(line, "%31s", key) == 1) { /* the key as fmu_common.c reads it */
            if (strcmp(key, "estimator") == 0) has_estimator = 1;
            if (strcmp(key, "load_input") == 0) has_load = 1;
        }
    }
}

/* Whether a fixed value reference below 16 may be read or written with fmi2OK: 0-6 by the model, 7-11 only with
 * the estimator, 12 only with the load input, 13-15 never (fmu_common.c's declared()). */
static int may_be_declared(unsigned vr)
{
    if (vr < 7) return 1;
    if (vr < 12) return has_estimator;
    return vr == 12 && has_load;
}

static fmi2ValueReference pick_vr(reader *r)
{
    uint8_t b = byte(r);
    if (b < 96) return b % 16;                               /* inputs, outputs, 7-15 (declared or not) */
    if (b < 224 && nvars) return vars[b % nvars];            /* a parameter */
    if (b < 240) return 16 + byte(r) * 9;                    /* another parameter number */
    return b & 1 ? 0xFFFFFFFFu : 2048u + byte(r);            /* beyond every table */
}

enum { OUTPUTS = 5 };
static const fmi2ValueReference OUT_VR[OUTPUTS] = {2, 3, 4, 5, 6};

/* What the FMU shows: its time and every variable it declares (undeclared ones read as NaN). */
typedef struct {
    double t;
    double v[16 + MAXV];
    int ok[16 + MAXV];
} view;

/* The mode the standard's state machine is in, as the calls answered OK moved it, and the experiment's
 * stop time. */
static enum { M_INSTANTIATED, M_INIT, M_STEP, M_TERMINATED } mode;
static int have_stop;
static double stop_time;

static void look(fmi2Component c, view *w)
{
    memset(w, 0, sizeof *w);
    int errors = errors_logged;
    fmi2Status st = fmi2GetRealStatus(c, fmi2LastSuccessfulTime, &w->t);
    check_status(st, errors);
    if ((st == fmi2OK) != (mode == M_STEP || mode == M_TERMINATED))
        FAIL("fmi2LastSuccessfulTime refused once initialized, or answered before");
    if (st != fmi2OK) w->t = NAN;
    for (int k = 0; k < 16 + nvars; k++) {
        fmi2ValueReference vr = k < 16 ? (fmi2ValueReference)k : vars[k - 16];
        int before = errors_logged;
        fmi2Status s = fmi2GetReal(c, &vr, 1, &w->v[k]);
        check_status(s, before);
        w->ok[k] = s == fmi2OK;
        if (k < 16 && w->ok[k] && !may_be_declared((unsigned)k))
            FAIL("an undeclared value reference (7-15: no estimator, no load input, or 13-15) read with fmi2OK");
        if (!w->ok[k]) w->v[k] = NAN;
    }
}

static int same_view(const view *a, const view *b)
{
    return memcmp(&a->t, &b->t, sizeof a->t) == 0 && memcmp(a->v, b->v, sizeof a->v) == 0;
}

static void *alloc(size_t n, size_t size) { return calloc(n, size); }

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    reader r = {data, size};
    size_t len = byte(&r);
    len |= (size_t)byte(&r) << 8;
    if (len > r.n) len = r.n;
    static char text[1 << 16];
    memcpy(text, r.p, len);
    text[len] = 0;
    r.p += len, r.n -= len;
    write_resources(text, len);
    scan_resources(text);
    snprintf(uri, sizeof uri, "file://%s", dir);

    fmi2CallbackFunctions cb = {logger, alloc, free, NULL, NULL};
    uint8_t how = byte(&r);
    const char *g = how % 8 == 0 ? NULL : how % 8 == 1 ? "{wrong}" : guid;
    const char *res = how & 8 ? dir : uri; /* a plain path or a file: URI */
    int before = errors_logged;
    fmi2Component c = fmi2Instantiate(how & 16 ? NULL : "fuzz", fmi2CoSimulation, g, res, &cb, 0, how & 32);
    if (!c) {
        if (errors_logged == before) FAIL("a failed instantiation without a logged message");
        return 0;
    }
    fmi2FMUstate state = NULL;
    view a, b;
    mode = M_INSTANTIATED, have_stop = 0, stop_time = 0.0;
    for (int op = 0; op < 48 && r.n; op++) {
        before = errors_logged;
        fmi2Status s = fmi2OK;
        int call = byte(&r) % 14;
        switch (call) {
        case 0: {
            uint8_t f = byte(&r);
            double tol = number(&r), start = f & 2 ? number(&r) : 0.0, stop = number(&r);
            s = fmi2SetupExperiment(c, f & 1, tol, start, f & 4, stop);
            if (s != fmi2Error) have_stop = (f & 4) != 0, stop_time = stop;
            break;
        }
        case 1:
            s = fmi2EnterInitializationMode(c);
            if (s != fmi2Error && mode != M_INSTANTIATED) FAIL("fmi2EnterInitializationMode answered OK once initialized");
            if (s != fmi2Error) mode = M_INIT;
            break;
        case 2:
            s = fmi2ExitInitializationMode(c);
            if (s != fmi2Error && mode != M_INIT) FAIL("fmi2ExitInitializationMode answered OK outside initialization mode");
            if (s != fmi2Error) mode = M_STEP;
            break;
        case 3: { /* SetReal: a refusal changes nothing */
            fmi2ValueReference vr[3];
            double v[3];
            size_t n = byte(&r) % 4;
            for (size_t k = 0; k < n; k++) vr[k] = pick_vr(&r), v[k] = number(&r);
            uint8_t nulls = byte(&r);
            look(c, &a);
            s = fmi2SetReal(c, nulls == 1 ? NULL : vr, n, nulls == 2 ? NULL : v);
            look(c, &b);
            if (s == fmi2Error && !same_view(&a, &b)) FAIL("a refused fmi2SetReal changed a variable or the time");
            if (s != fmi2Error && n && mode == M_TERMINATED) FAIL("fmi2SetReal answered OK once terminated");
            if (s != fmi2Error && n)
                for (size_t k = 0; k < n; k++)
                    if (vr[k] < 16 && !may_be_declared(vr[k]))
                        FAIL("an undeclared value reference (7-15: no estimator, no load input, or 13-15) set with "
                             "fmi2OK");
            break;
        }
        case 4: {
            fmi2ValueReference vr[3];
            double v[3];
            size_t n = byte(&r) % 4;
            for (size_t k = 0; k < n; k++) vr[k] = pick_vr(&r);
            uint8_t nulls = byte(&r);
            s = fmi2GetReal(c, nulls == 1 ? NULL : vr, n, nulls == 2 ? NULL : v);
            break;
        }
        case 5: {
            fmi2ValueReference vr[2];
            fmi2Integer order[2];
            double v[2];
            size_t n = byte(&r) % 3;
            for (size_t k = 0; k < n; k++) vr[k] = byte(&r) % 3, order[k] = byte(&r) % 8 ? 1 : byte(&r) % 3,
                                           v[k] = number(&r);
            uint8_t nulls = byte(&r);
            s = fmi2SetRealInputDerivatives(c, nulls == 1 ? NULL : vr, n, nulls == 2 ? NULL : order,
                                            nulls == 3 ? NULL : v);
            break;
        }
        case 6: { /* DoStep: OK moves the time by exactly h with finite outputs; a refusal moves nothing */
            look(c, &a);
            uint8_t f = byte(&r);
            double h = f & 1 ? number(&r) : (1 + byte(&r) % 10) * pow(10.0, -(double)(3 + byte(&r) % 4));
            double t = f & 2 ? number(&r) : a.t;
            s = fmi2DoStep(c, t, h, fmi2True);
            look(c, &b);
            if (s == fmi2Error && !same_view(&a, &b)) FAIL("a refused fmi2DoStep moved the time or an output");
            if (s != fmi2Error) {
                if (mode != M_STEP) FAIL("fmi2DoStep answered OK outside step mode");
                if (have_stop && a.t + h > stop_time + 1e-9 * fmax(fabs(stop_time), fabs(a.t) + h))
                    FAIL("fmi2DoStep answered OK for a step past the stop time");
                if (!(b.t == a.t + h)) FAIL("fmi2DoStep answered OK without moving the time by h");
                for (int k = 0; k < OUTPUTS; k++)
                    if (b.ok[OUT_VR[k]] && !isfinite(b.v[OUT_VR[k]])) FAIL("fmi2DoStep answered OK with a non-finite output");
            }
            break;
        }
        case 7:
            if (byte(&r) & 1 || !state) s = fmi2GetFMUstate(c, &state);
            else s = fmi2SetFMUstate(c, state);
            break;
        case 8: s = fmi2FreeFMUstate(c, &state); break;
        case 9:
            s = fmi2Reset(c);
            if (s != fmi2Error) mode = M_INSTANTIATED, have_stop = 0;
            break;
        case 10:
            s = fmi2Terminate(c);
            if (s != fmi2Error && mode != M_STEP) FAIL("fmi2Terminate answered OK outside step mode");
            if (s != fmi2Error) mode = M_TERMINATED;
            break;
        case 11: s = fmi2SetDebugLogging(c, byte(&r) & 1, 0, NULL); break;
        case 12: { /* the types this FMU has none of */
            fmi2ValueReference vr = pick_vr(&r);
            fmi2Integer i = 0;
            fmi2Boolean bo = 0;
            fmi2String str = "";
            size_t n = byte(&r) % 2;
            switch (byte(&r) % 6) {
            case 0: s = fmi2GetInteger(c, &vr, n, &i); break;
            case 1: s = fmi2SetInteger(c, &vr, n, &i); break;
            case 2: s = fmi2GetBoolean(c, &vr, n, &bo); break;
            case 3: s = fmi2SetBoolean(c, &vr, n, &bo); break;
            case 4: s = fmi2GetString(c, &vr, n, &str); break;
            default: s = fmi2SetString(c, &vr, n, &str); break;
            }
            break;
        }
        default: { /* what the FMU does not provide: fmi2Error with a message, never a crash */
            fmi2Real x = 0.0;
            fmi2Status st;
            switch (byte(&r) % 4) {
            case 0: s = fmi2CancelStep(c); break;
            case 1: s = fmi2GetStatus(c, fmi2DoStepStatus, &st); break;
            case 2: s = fmi2GetRealStatus(c, (fmi2StatusKind)(byte(&r) % 4), &x); break;
            default: s = fmi2GetDirectionalDerivative(c, NULL, 0, NULL, 0, NULL, NULL); break;
            }
        }
        }
        check_status(s, before);
#ifdef TF_FUZZ_TRACE /* which calls an input makes, and their statuses */
        fprintf(stderr, "call %d: status %d\n", call, (int)s);
#endif
    }
    if (state) fmi2FreeFMUstate(c, &state);
    fmi2FreeInstance(c);
    return 0;
}

#ifdef TF_FUZZ_REPLAY
#include "replay_main.h"
#endif
