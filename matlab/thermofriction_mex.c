/* The MATLAB/Octave gateway to the C core (docs/matlab.md): one source, built by MATLAB's `mex` and by
 * Octave's `mkoctfile --mex` (matlab/+thermofriction/build.m) together with the core's sources and the FMU's
 * model logic (core/fmu/fmu_common.c). No numerics of its own: a model is an FMU instance in this process
 * (its resources/model.tfm read by the FMU's one reader, fmu_common.c), a simulation is the FMU's
 * communication steps (fmu_do_step: tf_solve between samples, the inputs followed linearly between them),
 * and the friction loop is the real-time API (realtime.h: tf_rt_step; control.h: tf_observer_step) on the
 * instance's model. So a MATLAB result is bit for bit the FMU's in Simulink or fmpy.
 *
 *   h = thermofriction_mex('open', resources_folder, guid)   % a handle (a positive integer)
 *   Y = thermofriction_mex('simulate', h, t, drive, temperature, rtol)
 *       % N x 5: displacement, velocity, friction force, temperature, stage displacement (NaN: not an
 *       % output of this plant); temperature [] for a model without a temperature input
 *   F = thermofriction_mex('friction', h, v, T, dt[, load])       % tf_rt_step once per element of v
 *   F = thermofriction_mex('observer', h, v, e, k, T, dt[, load]) % tf_observer_step once per element of v
 *       % load [N or N m]: read by a law of the load (required by a model with one; without: NaN, ignored)
 *   thermofriction_mex('reset', h)                           % the friction loop's states to rest
 *   thermofriction_mex('close', h)
 *
 * Errors are MATLAB errors (identifier thermofriction:...) with the core's or the FMU logic's message;
 * a refused step leaves the loop's state as it was before the call's first refused step. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mex.h"

#include "fmu_common.h"
#include "thermofriction.h"

#define MAX_HANDLES 64
enum { VR_DRIVE = 0, VR_TEMPERATURE = 1, VR_FIRST_OUTPUT = 2, N_OUTPUTS = 5 }; /* fmu_common.c's value references */

typedef struct {
    fmu_instance *inst;
    tf_rt_friction rt; /* the friction loop's model and states */
} slot;

static slot *slots[MAX_HANDLES];
static char last_error[600], last_warning[600];

static void on_log(const fmu_callbacks *cb, const char *name, fmu_status status, const char *category,
                   const char *message)
{
    char *to = status >= FMU_DISCARD ? last_error : status == FMU_WARNING ? last_warning : NULL;
    if (to) snprintf(to, sizeof last_error, "%s", message);
}

static void fail(const char *id, const char *fmt, ...)
{
    char msg[800];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    mexErrMsgIdAndTxt(id, "%s", msg);
}

static void close_all(void)
{
    for (int i = 0; i < MAX_HANDLES; i++) {
        if (!slots[i]) continue;
        fmu_free_instance(slots[i]->inst);
        free(slots[i]);
        slots[i] = NULL;
    }
}

/* ---- arguments ---- */

static void text(const mxArray *a, const char *name, char *out, size_t size)
{
    if (!mxIsChar(a) || mxGetString(a, out, (mwSize)size) != 0)
        fail("thermofriction:argument", "%s must be a character vector (at most %d characters)", name, (int)size - 1);
}

static const double *reals(const mxArray *a, const char *name, size_t *n)
{
    if (!mxIsDouble(a) || mxIsComplex(a) || mxIsSparse(a))
        fail("thermofriction:argument", "%s must be real double values, got a %s", name, mxGetClassName(a));
    *n = mxGetNumberOfElements(a);
    return mxGetPr(a);
}

static double scalar(const mxArray *a, const char *name)
{
    size_t n;
    const double *x = reals(a, name, &n);
    if (n != 1) fail("thermofriction:argument", "%s must be one number, got %d values", name, (int)n);
    return x[0];
}

/* One value per sample: n values, or one (held). */
static const double *per_sample(const mxArray *a, const char *name, size_t n, int *stride)
{
    size_t m;
    const double *x = reals(a, name, &m);
    if (m != n && m != 1)
        fail("thermofriction:argument", "%s must have one value per sample (%d) or one, got %d", name, (int)n, (int)m);
    *stride = m == n;
    return x;
}

static slot *handle(const mxArray *a)
{
    double h = scalar(a, "the model handle");
    int i = (int)h - 1;
    if (h != floor(h) || i < 0 || i >= MAX_HANDLES || !slots[i])
        fail("thermofriction:handle", "%g is not an open model (thermofriction.load_model gives one)", h);
    return slots[i];
}

static void check(fmu_status s, const char *what)
{
    if (s >= FMU_DISCARD) fail("thermofriction:failed", "%s: %s", what, last_error[0] ? last_error : "refused");
}

/* ---- commands ---- */

static void cmd_open(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
    char folder[4096], guid[128];
    if (nrhs != 3) fail("thermofriction:argument", "open takes a resources folder and a GUID");
    text(prhs[1], "the resources folder", folder, sizeof folder);
    text(prhs[2], "the GUID", guid, sizeof guid);
    int i = 0;
    while (i < MAX_HANDLES && slots[i]) i++;
    if (i == MAX_HANDLES) fail("thermofriction:handle", "%d models are open: close some (thermofriction.close_model)", i);
    fmu_callbacks cb = {.log = on_log, .allocateMemory = calloc, .freeMemory = free};
    last_error[0] = 0;
    fmu_instance *inst = fmu_instantiate("thermofriction", guid, folder, 0, &cb, 0);
    if (!inst) fail("thermofriction:model", "%s", last_error[0] ? last_error : "the model could not be read");
    slot *s = calloc(1, sizeof *s);
    tf_error e;
    if (!s || tf_rt_from_model(&s->rt, (const tf_model *)fmu_model(inst), &e) != TF_OK) {
        char why[TF_ERROR_WHAT + 16];
        snprintf(why, sizeof why, "%s", s ? e.what : "out of memory");
        fmu_free_instance(inst);
        free(s);
        fail("thermofriction:model", "the real-time friction model refused the model ('%s')", why);
    }
    s->inst = inst;
    slots[i] = s;
    plhs[0] = mxCreateDoubleScalar(i + 1);
}

/* The FMU's communication steps through the samples t, the inputs linear between them. */
static void cmd_simulate(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
    if (nrhs != 6) fail("thermofriction:argument", "simulate takes a handle, t, drive, temperature and rtol");
    fmu_instance *c = handle(prhs[1])->inst;
    size_t n;
    const double *t = reals(prhs[2], "t", &n);
    if (n < 2) fail("thermofriction:argument", "t must have at least two samples");
    int su, sT = 0;
    const double *u = per_sample(prhs[3], "drive", n, &su), *T = NULL;
    if (mxGetNumberOfElements(prhs[4]) > 0) T = per_sample(prhs[4], "temperature", n, &sT);
    double rtol = scalar(prhs[5], "rtol");
    const fmu_vr vr_u = VR_DRIVE, vr_T = VR_TEMPERATURE;
    const int order = 1;
    last_error[0] = last_warning[0] = 0;
    check(fmu_reset(c), "simulate");
    check(fmu_setup_experiment(c, 1, rtol, t[0], 1, t[n - 1]), "simulate");
    check(fmu_enter_initialization(c), "simulate");
    check(fmu_set_real(c, &vr_u, 1, &u[0]), "simulate: the drive at the start");
    if (T) check(fmu_set_real(c, &vr_T, 1, &T[0]), "simulate: the temperature at the start");
    check(fmu_exit_initialization(c), "simulate: the start");
    mxArray *Y = mxCreateDoubleMatrix((mwSize)n, N_OUTPUTS, mxREAL);
    double *y = mxGetPr(Y);
    int declared[N_OUTPUTS];
    for (int j = 0; j < N_OUTPUTS; j++) { /* the outputs this plant has (the others NaN) */
        fmu_vr vr = (fmu_vr)(VR_FIRST_OUTPUT + j);
        double x;
        declared[j] = fmu_get_real(c, &vr, 1, &x) == FMU_OK;
    }
    last_error[0] = 0;
    for (size_t k = 0; k < n; k++) {
        if (k > 0) {
            double h = t[k] - t[k - 1];
            if (!(h > 0)) {
                mxDestroyArray(Y);
                fail("thermofriction:argument", "t must increase strictly: t(%d) = %g after t(%d) = %g", (int)k + 1,
                     t[k], (int)k, t[k - 1]);
            }
            double du = (u[k * su] - u[(k - 1) * su]) / h;
            fmu_status s = fmu_set_real(c, &vr_u, 1, &u[(k - 1) * su]);
            if (s == FMU_OK) s = fmu_set_input_derivatives(c, &vr_u, 1, &order, &du);
            if (s == FMU_OK && T) {
                double dT = (T[k * sT] - T[(k - 1) * sT]) / h;
                s = fmu_set_real(c, &vr_T, 1, &T[(k - 1) * sT]);
                if (s == FMU_OK) s = fmu_set_input_derivatives(c, &vr_T, 1, &order, &dT);
            }
            if (s == FMU_OK) s = fmu_do_step(c, t[k - 1], h, 1);
            if (s >= FMU_DISCARD) {
                mxDestroyArray(Y);
                check(s, "simulate");
            }
        }
        for (int j = 0; j < N_OUTPUTS; j++) {
            fmu_vr vr = (fmu_vr)(VR_FIRST_OUTPUT + j);
            y[k + j * n] = NAN;
            if (declared[j]) fmu_get_real(c, &vr, 1, &y[k + j * n]);
        }
    }
    fmu_terminate(c);
    if (last_warning[0]) mexWarnMsgIdAndTxt("thermofriction:warning", "%s", last_warning);
    plhs[0] = Y;
}

/* tf_rt_step (k NULL) or tf_observer_step once per velocity sample, at the optional trailing load (one value
 * or one per sample; absent: NaN, which a model without a law of the load ignores and one with refuses). */
static void cmd_friction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[], int observer)
{
    int base = observer ? 7 : 5;
    if (nrhs != base && nrhs != base + 1)
        fail("thermofriction:argument", observer ? "observer takes a handle, v, e, k, T, dt and optionally the load"
                                                 : "friction takes a handle, v, T, dt and optionally the load");
    slot *s = handle(prhs[1]);
    size_t n;
    const double *v = reals(prhs[2], "v", &n);
    int se = 0, sk = 0, sT, sd, sL = 0;
    const double none = NAN;
    const double *e = observer ? per_sample(prhs[3], "e", n, &se) : NULL;
    const double *k = observer ? per_sample(prhs[4], "k", n, &sk) : NULL;
    const double *T = per_sample(prhs[observer ? 5 : 3], "T", n, &sT);
    const double *dt = per_sample(prhs[observer ? 6 : 4], "dt", n, &sd);
    const double *L = nrhs > base ? per_sample(prhs[base], "load", n, &sL) : &none;
    mxArray *out = mxCreateDoubleMatrix(mxGetM(prhs[2]), mxGetN(prhs[2]), mxREAL);
    double *F = mxGetPr(out);
    for (size_t i = 0; i < n; i++) {
        tf_error err;
        tf_status st = observer ? tf_observer_step(&s->rt, v[i], e[i * se], k[i * sk], T[i * sT], L[i * sL],
                                                   dt[i * sd], &F[i], &err)
                                : tf_rt_step(&s->rt, v[i], T[i * sT], L[i * sL], dt[i * sd], &F[i], &err);
        if (st != TF_OK) {
            mxDestroyArray(out);
            fail("thermofriction:refused", "%s: step %d (v = %g m/s, T = %g C, load = %g, dt = %g s) refused: %s "
                 "(%s: '%s'); the steps before it were taken", observer ? "observer" : "friction", (int)i + 1, v[i],
                 T[i * sT], L[i * sL], dt[i * sd], tf_status_message(st), err.where, err.what);
        }
    }
    plhs[0] = out;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
    char cmd[16];
    mexAtExit(close_all);
    if (nrhs < 1) fail("thermofriction:argument", "thermofriction_mex: give a command (see thermofriction_mex.c)");
    text(prhs[0], "the command", cmd, sizeof cmd);
    if (strcmp(cmd, "open") == 0) {
        cmd_open(nlhs, plhs, nrhs, prhs);
    } else if (strcmp(cmd, "simulate") == 0) {
        cmd_simulate(nlhs, plhs, nrhs, prhs);
    } else if (strcmp(cmd, "friction") == 0 || strcmp(cmd, "observer") == 0) {
        cmd_friction(nlhs, plhs, nrhs, prhs, cmd[0] == 'o');
    } else if (strcmp(cmd, "reset") == 0 || strcmp(cmd, "close") == 0) {
        if (nrhs != 2) fail("thermofriction:argument", "%s takes a handle", cmd);
        slot *s = handle(prhs[1]);
        tf_error e;
        if (cmd[0] == 'r') {
            tf_rt_reset(&s->rt, &e);
            return;
        }
        int i = (int)mxGetScalar(prhs[1]) - 1;
        fmu_free_instance(s->inst);
        free(s);
        slots[i] = NULL;
    } else {
        fail("thermofriction:argument", "unknown command '%s' (open, simulate, friction, observer, reset, close)", cmd);
    }
}
