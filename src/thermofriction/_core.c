/* Thin CPython binding of the C core: it unpacks a model description (a dict of numbers
 * and float64 arrays built by thermofriction.simulate) into a tf_model, and moves whole
 * arrays in and out (every argument through one set of buffer helpers, below). No numerics here:
 * what computes is the core's (default tolerances, the sensitivities' initial state and target check,
 * a waveform's corners). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <string.h>
#include <time.h>

#include "thermofriction.h"

static PyObject *SolverError;

/* ---- the buffers of one call, written once ----
 * Every function's array arguments and scratch memory go into one arena, released together at the end
 * of the call whatever happened: in_array (a float64 input), out_array (a float64 output of a known size),
 * in_int32, scratch (memory the call owns). Each sets the Python exception and returns NULL on a refusal. */
#define MAX_VIEWS 96
#define MAX_OWNED 32
typedef struct {
    Py_buffer views[MAX_VIEWS];
    int nviews;
    void *owned[MAX_OWNED];
    int nowned;
} arena;

static void arena_free(arena *a)
{
    for (int i = 0; i < a->nviews; i++) PyBuffer_Release(&a->views[i]);
    for (int i = 0; i < a->nowned; i++) PyMem_Free(a->owned[i]);
    a->nviews = a->nowned = 0;
}

/* A buffer of obj held until arena_free (flags: PyBUF_*); NULL with the exception set. */
static Py_buffer *view(arena *a, PyObject *obj, int flags)
{
    if (a->nviews >= MAX_VIEWS) { PyErr_SetString(PyExc_ValueError, "too many arrays"); return NULL; }
    Py_buffer *v = &a->views[a->nviews];
    if (PyObject_GetBuffer(obj, v, flags) < 0) return NULL;
    a->nviews++;
    return v;
}

static int is_float64(const Py_buffer *v) { return v->itemsize == 8 && v->format && strcmp(v->format, "d") == 0; }

/* A read-only contiguous float64 array; NULL (no error) for None. */
static const double *get_array(arena *a, PyObject *obj, Py_ssize_t *len, const char *what)
{
    *len = 0;
    if (obj == NULL || obj == Py_None) return NULL;
    Py_buffer *v = view(a, obj, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT);
    if (!v) return NULL;
    if (!is_float64(v)) {
        PyErr_Format(PyExc_TypeError, "%s must be a contiguous float64 array", what);
        return NULL;
    }
    *len = v->len / 8;
    return (const double *)v->buf;
}

/* A writable C-contiguous float64 array of exactly n values; else ValueError(what). */
static double *out_array(arena *a, PyObject *obj, Py_ssize_t n, const char *what)
{
    Py_buffer *v = view(a, obj, PyBUF_C_CONTIGUOUS | PyBUF_WRITABLE | PyBUF_FORMAT);
    if (!v) return NULL;
    if (!is_float64(v) || v->len != 8 * n) { PyErr_SetString(PyExc_ValueError, what); return NULL; }
    return (double *)v->buf;
}

/* A read-only contiguous int32 array of a multiple of `width` values (at least one row): its rows in *rows. */
static const int *in_int32(arena *a, PyObject *obj, int width, Py_ssize_t *rows, const char *what)
{
    Py_buffer *v = view(a, obj, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT);
    if (!v) return NULL;
    if (v->itemsize != 4 || v->len % (4 * width) != 0 || v->len == 0) {
        PyErr_SetString(PyExc_ValueError, what);
        return NULL;
    }
    *rows = v->len / (4 * width);
    return (const int *)v->buf;
}

/* Memory owned by the call (zeroed), freed by arena_free; NULL with MemoryError. */
static void *scratch(arena *a, size_t bytes)
{
    void *p = a->nowned < MAX_OWNED ? PyMem_Calloc(1, bytes ? bytes : 1) : NULL;
    if (!p) { PyErr_NoMemory(); return NULL; }
    a->owned[a->nowned++] = p;
    return p;
}

static int get_double(PyObject *dict, const char *key, double *out)
{
    PyObject *o = PyDict_GetItemString(dict, key);
    if (!o) { PyErr_Format(PyExc_KeyError, "model spec lacks '%s'", key); return -1; }
    *out = PyFloat_AsDouble(o);
    return PyErr_Occurred() ? -1 : 0;
}

static int get_int(PyObject *dict, const char *key, int *out)
{
    PyObject *o = PyDict_GetItemString(dict, key);
    if (!o) { PyErr_Format(PyExc_KeyError, "model spec lacks '%s'", key); return -1; }
    *out = (int)PyLong_AsLong(o);
    return PyErr_Occurred() ? -1 : 0;
}

/* law: None or (kind, a, b, x, y[, load]), load None or (kind, combine, k, saturation, interaction, c)
 * (law.h: tf_load_term) */
static int parse_law(arena *a, PyObject *obj, tf_law *law)
{
    memset(law, 0, sizeof *law);
    if (obj == NULL || obj == Py_None) return 0;
    PyObject *x = NULL, *y = NULL, *load = Py_None;
    if (!PyArg_ParseTuple(obj, "iddOO|O", &law->kind, &law->a, &law->b, &x, &y, &load)) return -1;
    tf_load_term *t = &law->load;
    if (load != Py_None &&
        !PyArg_ParseTuple(load, "iiddid", &t->kind, &t->combine, &t->k, &t->saturation, &t->interaction, &t->c))
        return -1;
    Py_ssize_t nx, ny;
    law->x = get_array(a, x, &nx, "law breakpoints");
    if (PyErr_Occurred()) return -1;
    law->y = get_array(a, y, &ny, "law values");
    if (PyErr_Occurred()) return -1;
    law->n = (int)ny;
    if (law->kind == TF_LAW_POLY && ny < 1) { PyErr_SetString(PyExc_ValueError, "poly law needs coefficients"); return -1; }
    if ((law->kind == TF_LAW_PWL || law->kind == TF_LAW_TABLE) && (nx != ny || ny < 1)) {
        PyErr_SetString(PyExc_ValueError, "pwl/table law needs as many breakpoints as values");
        return -1;
    }
    if (law->kind == TF_LAW_TABLE) {
        double *d = scratch(a, sizeof(double) * ny);
        if (!d) return -1;
        tf_pchip_slopes(law->n, law->x, law->y, d);
        law->d = d;
    }
    return 0;
}

/* waveform: (kind, amplitude, frequency, rise, offset, direction, slew, t0, t, v) */
static int parse_waveform(arena *a, PyObject *obj, tf_waveform *w)
{
    memset(w, 0, sizeof *w);
    PyObject *t = NULL, *v = NULL;
    if (!PyArg_ParseTuple(obj, "idddddddOO", &w->kind, &w->amplitude, &w->frequency, &w->rise, &w->offset,
                          &w->direction, &w->slew, &w->t0, &t, &v))
        return -1;
    Py_ssize_t nt, nv;
    w->t = get_array(a, t, &nt, "waveform times");
    if (PyErr_Occurred()) return -1;
    w->v = get_array(a, v, &nv, "waveform values");
    if (PyErr_Occurred()) return -1;
    if (nt != nv) { PyErr_SetString(PyExc_ValueError, "waveform times and values differ in length"); return -1; }
    w->n = (int)nt;
    return 0;
}

static int parse_model(arena *a, PyObject *spec, tf_model *m)
{
    memset(m, 0, sizeof *m);
    if (!PyDict_Check(spec)) { PyErr_SetString(PyExc_TypeError, "model spec must be a dict"); return -1; }
    if (get_int(spec, "plant", &m->plant) || get_double(spec, "m", &m->m) || get_double(spec, "c", &m->c) ||
        get_double(spec, "k", &m->k) || get_double(spec, "T_em", &m->T_em) || get_double(spec, "m_e", &m->m_e) ||
        get_int(spec, "friction", &m->friction) || get_int(spec, "thermal", &m->thermal) ||
        get_int(spec, "dF_form", &m->dF_form) || get_double(spec, "T_const", &m->T_const) ||
        get_int(spec, "fs_follows_fc", &m->fs_follows_fc))
        return -1;
    PyObject *gk = PyDict_GetItemString(spec, "gms_k"), *gw = PyDict_GetItemString(spec, "gms_w");
    if (gk && gk != Py_None) {
        Py_ssize_t nk, nw;
        const double *k = get_array(a, gk, &nk, "gms_k");
        if (PyErr_Occurred()) return -1;
        const double *w = get_array(a, gw, &nw, "gms_w");
        if (PyErr_Occurred()) return -1;
        if (nk != nw || nk < 1 || nk > TF_MAX_FRICTION_STATES) {
            PyErr_Format(PyExc_ValueError, "gms_k and gms_w must have the same length, 1..%d", TF_MAX_FRICTION_STATES);
            return -1;
        }
        m->gms.n = (int)nk;
        memcpy(m->gms.k, k, sizeof(double) * nk);
        memcpy(m->gms.w, w, sizeof(double) * nk);
        PyObject *gm = PyDict_GetItemString(spec, "gms_mode"); /* optional: tests set the modes */
        if (gm && gm != Py_None) {
            Py_ssize_t nm;
            const double *mode = get_array(a, gm, &nm, "gms_mode");
            if (PyErr_Occurred()) return -1;
            if (nm != nk) { PyErr_SetString(PyExc_ValueError, "gms_mode must have one value per element"); return -1; }
            for (Py_ssize_t i = 0; i < nk; i++) m->gms.mode[i] = (mode[i] > 0) - (mode[i] < 0);
        }
    }
    if (get_double(spec, "k_s", &m->k_s) || get_double(spec, "v_0", &m->v_0)) return -1;
    if (tf_friction_nstate(m->friction, m->gms.n) < 0) {
        PyErr_SetString(PyExc_ValueError, "unknown friction model");
        return -1;
    }
    Py_ssize_t np;
    const double *p = get_array(a, PyDict_GetItemString(spec, "params"), &np, "params");
    if (PyErr_Occurred()) return -1;
    if (np != TF_NPARAM) { PyErr_Format(PyExc_ValueError, "params must have %d values", TF_NPARAM); return -1; }
    memcpy(m->p, p, sizeof(double) * TF_NPARAM);
    PyObject *laws = PyDict_GetItemString(spec, "laws");
    if (laws && laws != Py_None) {
        if (!PyList_Check(laws) || PyList_GET_SIZE(laws) != TF_NPARAM) {
            PyErr_Format(PyExc_ValueError, "laws must be a list of %d entries", TF_NPARAM);
            return -1;
        }
        for (int i = 0; i < TF_NPARAM; i++)
            if (parse_law(a, PyList_GET_ITEM(laws, i), &m->law[i])) return -1;
    }
    if (parse_law(a, PyDict_GetItemString(spec, "dF"), &m->dF)) return -1;
    PyObject *input = PyDict_GetItemString(spec, "input");
    if (!input) { PyErr_SetString(PyExc_KeyError, "model spec lacks 'input'"); return -1; }
    if (parse_waveform(a, input, &m->input)) return -1;
    Py_ssize_t nt, nv;
    m->T_t = get_array(a, PyDict_GetItemString(spec, "T_t"), &nt, "temperature times");
    if (PyErr_Occurred()) return -1;
    m->T_v = get_array(a, PyDict_GetItemString(spec, "T_v"), &nv, "temperature values");
    if (PyErr_Occurred()) return -1;
    if (nt != nv) { PyErr_SetString(PyExc_ValueError, "temperature times and values differ in length"); return -1; }
    m->T_n = (int)nt;
    /* optional: load = a waveform or None, load_const = a number (absent: NaN, no load) */
    PyObject *load = PyDict_GetItemString(spec, "load"), *load_const = PyDict_GetItemString(spec, "load_const");
    m->load_const = NAN;
    if (load && load != Py_None && parse_waveform(a, load, &m->load)) return -1;
    if (load_const && load_const != Py_None && get_double(spec, "load_const", &m->load_const)) return -1;
    /* optional: heat = (C_th, R_th, eta, T_amb, T_0, P_ext waveform or None); work = 0/1 */
    PyObject *heat = PyDict_GetItemString(spec, "heat");
    if (heat && heat != Py_None) {
        PyObject *P_ext = NULL;
        tf_heat *h = &m->heat;
        if (!PyArg_ParseTuple(heat, "dddddO", &h->C_th, &h->R_th, &h->eta, &h->T_amb, &h->T_0, &P_ext)) return -1;
        h->on = 1;
        if (P_ext != Py_None && parse_waveform(a, P_ext, &h->P_ext)) return -1;
    }
    PyObject *work = PyDict_GetItemString(spec, "work");
    if (work && work != Py_None) {
        m->work = PyObject_IsTrue(work);
        if (m->work < 0) return -1;
    }
    return 0;
}

/* ---- Ctrl-C during a long integration ----
 * tf_solve runs with the GIL released, so Python's signal handlers (KeyboardInterrupt, the command
 * line's SIGTERM handler) cannot run until it returns. The solver polls interrupt_poll every
 * TF_POLL_STEPS steps; at most every POLL_SECONDS it takes the GIL back and runs the pending handlers
 * (PyErr_CheckSignals). A handler that raises stops the integration (TF_ERR_INTERRUPTED) and its
 * exception is what the call raises. Only in the main thread: Python runs signal handlers there
 * only, and other threads need not wait for the GIL. */
#define POLL_SECONDS 0.05
static unsigned long main_thread_ident;

typedef struct {
    PyThreadState *ts; /* the released thread state, NULL when not polling */
    double last;       /* when the handlers last ran [s, monotonic] */
    int raised;        /* a handler raised: the exception is set */
} signal_poll;

static double monotonic_seconds(void)
{
#ifdef CLOCK_MONOTONIC
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0) return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return (double)clock() / CLOCKS_PER_SEC;
}

static int interrupt_poll(void *ctx)
{
    signal_poll *p = (signal_poll *)ctx;
    double now = monotonic_seconds();
    if (now - p->last < POLL_SECONDS) return 0;
    p->last = now;
    PyEval_RestoreThread(p->ts);
    p->raised = PyErr_CheckSignals() != 0;
    p->ts = PyEval_SaveThread();
    return p->raised;
}

/* tf_solve without the GIL, polled for signals in the main thread. */
static tf_status solve_released(const tf_ode *ode, tf_solver_options *opt, const double *t_out, long n_out,
                                double *y, tf_emit_fn emit, void *ctx, tf_solver_stats *st, tf_error *err,
                                int *raised)
{
    signal_poll poll = {NULL, monotonic_seconds(), 0};
    if (PyThread_get_thread_ident() == main_thread_ident) {
        opt->interrupt = interrupt_poll;
        opt->interrupt_ctx = &poll;
    }
    poll.ts = PyEval_SaveThread();
    tf_status status = tf_solve(ode, opt, t_out, n_out, y, emit, ctx, st, err);
    PyEval_RestoreThread(poll.ts);
    *raised = poll.raised;
    return status;
}

/* SolverError(message, status, t_fail, h_fail, state, stiff_suspected): the message is the error
 * record's what (status.h: the status's sentence, or the argument refused) */
static void raise_solver_error(const tf_error *err, const tf_solver_stats *st, const double *y, int n)
{
    PyObject *state = PyTuple_New(n);
    for (int i = 0; i < n && state; i++) PyTuple_SET_ITEM(state, i, PyFloat_FromDouble(y[i]));
    PyObject *exc_args = Py_BuildValue("(siddNi)", err->what, (int)err->code, err->t, st->h_fail,
                                       state, st->stiff_suspected);
    if (exc_args) { PyErr_SetObject(SolverError, exc_args); Py_DECREF(exc_args); }
}

/* The C core's own model check, after Python's: a refusal here means the two disagree (a bug),
 * reported as a SolverError with TF_ERR_BAD_ARGUMENT naming the field. */
static int check_model(const tf_model *m)
{
    tf_error e;
    if (tf_model_check(m, &e) == TF_OK) return 0;
    char message[160];
    snprintf(message, sizeof message, "the C core's model check refused '%s'", e.what);
    PyObject *exc_args = Py_BuildValue("(siddNi)", message, TF_ERR_BAD_ARGUMENT, 0.0, 0.0, PyTuple_New(0), 0);
    if (exc_args) { PyErr_SetObject(SolverError, exc_args); Py_DECREF(exc_args); }
    return -1;
}

typedef struct {
    tf_model_data *data;
    double *out;
    int nch;
    long n_out; /* > 0: out is column-major (Fortran order), a column per output channel */
} emit_ctx;

static void emit_outputs(long i, double t, const double *y, void *ctx)
{
    emit_ctx *e = (emit_ctx *)ctx;
    if (!e->n_out) {
        tf_model_outputs(e->data, t, y, e->out + (size_t)i * e->nch);
        return;
    }
    tf_model_outputs_strided(e->data, t, y, e->out + i, e->n_out);
}

/* simulate(spec, t_out, out, method, rtol, atol|None, h0, hmax, max_steps) -> stats dict */
static PyObject *py_simulate(PyObject *self, PyObject *args)
{
    PyObject *spec, *t_obj, *out_obj, *atol_obj;
    int method;
    double rtol, h0, hmax;
    long max_steps;
    if (!PyArg_ParseTuple(args, "OOOidOddl", &spec, &t_obj, &out_obj, &method, &rtol, &atol_obj, &h0, &hmax,
                          &max_steps))
        return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (parse_model(&a, spec, &m)) goto done;
    Py_ssize_t n_out, n_atol;
    const double *t_out = get_array(&a, t_obj, &n_out, "t_out");
    if (PyErr_Occurred()) goto done;
    if (n_out < 1) { PyErr_SetString(PyExc_ValueError, "t_out is empty"); goto done; }
    int n = tf_model_nstate(&m), nch = tf_model_noutput(&m);
    /* out: (n_out, nch), C order (a row per sample) or Fortran order (a contiguous column per channel,
     * which the package reads as views without copying) */
    Py_buffer *outv = view(&a, out_obj, PyBUF_STRIDES | PyBUF_WRITABLE | PyBUF_FORMAT);
    if (!outv) goto done;
    int rows = PyBuffer_IsContiguous(outv, 'C'), columns = !rows && PyBuffer_IsContiguous(outv, 'F');
    if (!is_float64(outv) || outv->ndim != 2 || outv->shape[0] != n_out || outv->shape[1] != nch ||
        !(rows || columns)) {
        PyErr_Format(PyExc_ValueError, "out must be a contiguous float64 array of shape (%zd, %d)", n_out, nch);
        goto done;
    }
    double atol[TF_MAX_STATES];
    const double *atol_in = get_array(&a, atol_obj, &n_atol, "atol");
    if (PyErr_Occurred()) goto done;
    if (atol_in) {
        if (n_atol != n) { PyErr_Format(PyExc_ValueError, "atol must have %d values", n); goto done; }
        memcpy(atol, atol_in, sizeof(double) * n);
    } else {
        tf_model_default_atol(&m, rtol, atol);
    }
    if (check_model(&m)) goto done;
    double y[TF_MAX_STATES];
    tf_model_initial_state(&m, y);
    tf_model_data md; /* the run's mutable part: parameter cache, GMS modes */
    tf_model_data_init(&md, &m);
    tf_ode ode = tf_model_ode(&md);
    double rtol_w[TF_MAX_STATES];
    tf_model_rtol_weights(&m, rtol_w);
    tf_solver_options opt = {.method = method, .rtol = rtol, .atol = atol, .h0 = h0, .hmax = hmax,
                             .max_steps = max_steps, .rtol_weight = rtol_w};
    tf_solver_stats st;
    emit_ctx ec = {&md, (double *)outv->buf, nch, columns ? (long)n_out : 0};
    int raised;
    tf_error e;
    tf_status status = solve_released(&ode, &opt, t_out, n_out, y, emit_outputs, &ec, &st, &e, &raised);
    if (status != TF_OK) {
        if (!raised) raise_solver_error(&e, &st, y, n);
        goto done;
    }
    result = Py_BuildValue("{s:l,s:l,s:l,s:l,s:l,s:i,s:d,s:l}", "steps", st.steps, "rejected", st.rejected,
                           "rhs_evals", st.rhs_evals, "jac_evals", st.jac_evals, "decompositions",
                           st.decompositions, "method", st.method_used, "switch_time", st.switch_time,
                           "events", st.events);
done:
    arena_free(&a);
    return result;
}

typedef struct {
    tf_model_data *data;
    double *out, *sens;
    int nch, n, np;
} sens_emit_ctx;

static void emit_sensitivities(long i, double t, const double *Y, void *ctx)
{
    sens_emit_ctx *e = (sens_emit_ctx *)ctx;
    tf_model_outputs(e->data, t, Y, e->out + (size_t)i * e->nch);
    memcpy(e->sens + (size_t)i * e->n * e->np, Y + e->n, sizeof(double) * e->n * e->np);
}

/* simulate_sensitivities(spec, targets, t_out, out, sens, rtol, atol|None, h0, hmax, max_steps)
 * targets: int32 array (np, 3) of (kind, param, coef); sens: float64 (n_out, n, np). */
static PyObject *py_simulate_sensitivities(PyObject *self, PyObject *args)
{
    PyObject *spec, *tg_obj, *t_obj, *out_obj, *sens_obj, *atol_obj;
    double rtol, h0, hmax;
    long max_steps;
    if (!PyArg_ParseTuple(args, "OOOOOdOddl", &spec, &tg_obj, &t_obj, &out_obj, &sens_obj, &rtol, &atol_obj, &h0,
                          &hmax, &max_steps))
        return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (parse_model(&a, spec, &m)) goto done;
    if (check_model(&m)) goto done; /* a fit must never integrate a model the simulator would refuse */
    Py_ssize_t np_rows;
    const int *ti = in_int32(&a, tg_obj, 3, &np_rows, "targets must be an int32 array of shape (np, 3)");
    if (!ti) goto done;
    if (np_rows > TF_MAX_TARGETS) { PyErr_Format(PyExc_ValueError, "at most %d targets", TF_MAX_TARGETS); goto done; }
    int np = (int)np_rows;
    tf_target targets[TF_MAX_TARGETS];
    for (int k = 0; k < np; k++) targets[k] = (tf_target){ti[3 * k], ti[3 * k + 1], ti[3 * k + 2]};
    tf_model_data md;
    tf_model_data_init(&md, &m);
    tf_sensitivity_system sys = {&md, np, targets};
    tf_error e;
    if (tf_sensitivity_check(&sys, &e)) {
        PyErr_Format(PyExc_ValueError, "target %ld is not valid for this model", e.index);
        goto done;
    }
    Py_ssize_t n_out, n_atol;
    const double *t_out = get_array(&a, t_obj, &n_out, "t_out");
    if (PyErr_Occurred()) goto done;
    if (n_out < 1) { PyErr_SetString(PyExc_ValueError, "t_out is empty"); goto done; }
    int n = tf_model_nstate(&m), nch = tf_model_noutput(&m), N = n * (1 + np);
    double *out = out_array(&a, out_obj, n_out * nch, "out or sens has the wrong size");
    double *sens = out ? out_array(&a, sens_obj, n_out * n * np, "out or sens has the wrong size") : NULL;
    double *atol = sens ? scratch(&a, sizeof(double) * N) : NULL, *Y = atol ? scratch(&a, sizeof(double) * N) : NULL;
    if (!Y) goto done;
    const double *atol_in = get_array(&a, atol_obj, &n_atol, "atol");
    if (PyErr_Occurred()) goto done;
    if (!atol_in || n_atol != N) { PyErr_Format(PyExc_ValueError, "atol must have %d values", N); goto done; }
    memcpy(atol, atol_in, sizeof(double) * N);
    tf_sensitivity_initial_state(&sys, Y);
    tf_ode ode = tf_sensitivity_ode(&sys);
    tf_solver_options opt = {.method = TF_METHOD_DOPRI5, .rtol = rtol, .atol = atol, .h0 = h0, .hmax = hmax,
                             .max_steps = max_steps};
    tf_solver_stats st;
    sens_emit_ctx ec = {&md, out, sens, nch, n, np};
    int raised;
    tf_status status = solve_released(&ode, &opt, t_out, n_out, Y, emit_sensitivities, &ec, &st, &e, &raised);
    if (status != TF_OK) {
        if (!raised) raise_solver_error(&e, &st, Y, n);
        goto done;
    }
    result = Py_BuildValue("{s:l,s:l,s:l}", "steps", st.steps, "rejected", st.rejected, "rhs_evals", st.rhs_evals);
done:
    arena_free(&a);
    return result;
}

/* rhs_jac(spec, t, y, dy_out, J_out|None): one evaluation, for differential tests */
static PyObject *py_rhs_jac(PyObject *self, PyObject *args)
{
    PyObject *spec, *y_obj, *dy_obj, *J_obj;
    double t;
    if (!PyArg_ParseTuple(args, "OdOOO", &spec, &t, &y_obj, &dy_obj, &J_obj)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (parse_model(&a, spec, &m)) goto done;
    int n = tf_model_nstate(&m);
    Py_ssize_t ny;
    const double *y = get_array(&a, y_obj, &ny, "y");
    if (PyErr_Occurred()) goto done;
    if (ny != n) { PyErr_Format(PyExc_ValueError, "y must have %d values", n); goto done; }
    double *dy = out_array(&a, dy_obj, n, "dy has the wrong size");
    double *J = J_obj == Py_None || !dy ? NULL : out_array(&a, J_obj, (Py_ssize_t)n * n, "J has the wrong size");
    if (!dy || (J_obj != Py_None && !J)) goto done;
    tf_model_data md;
    tf_model_data_init(&md, &m);
    tf_model_rhs(t, y, dy, &md);
    if (J) tf_model_jac(t, y, J, &md);
    result = PyFloat_FromDouble(tf_model_friction(&md, t, y));
done:
    arena_free(&a);
    return result;
}

/* time_rhs(spec, t, y, n_evals) -> seconds per right-hand-side evaluation, timed in C (benchmarks) */
static PyObject *py_time_rhs(PyObject *self, PyObject *args)
{
    PyObject *spec, *y_obj;
    double t;
    long n_evals;
    if (!PyArg_ParseTuple(args, "OdOl", &spec, &t, &y_obj, &n_evals)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (parse_model(&a, spec, &m)) goto done;
    int n = tf_model_nstate(&m);
    Py_ssize_t ny;
    const double *y = get_array(&a, y_obj, &ny, "y");
    if (PyErr_Occurred()) goto done;
    if (ny != n || n_evals < 1) { PyErr_Format(PyExc_ValueError, "y must have %d values, n_evals >= 1", n); goto done; }
    double dy[TF_MAX_STATES], sink = 0.0;
    tf_model_data md;
    tf_model_data_init(&md, &m);
    struct timespec t0, t1;
    Py_BEGIN_ALLOW_THREADS
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (long i = 0; i < n_evals; i++) {
        tf_model_rhs(t + 1e-12 * (double)(i & 1023), y, dy, &md);
        sink += dy[n - 1];
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    Py_END_ALLOW_THREADS
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    result = Py_BuildValue("(dd)", secs / (double)n_evals, sink);
done:
    arena_free(&a);
    return result;
}

/* law_eval(law, T, value_out, slope_out) */
static PyObject *py_law_eval(PyObject *self, PyObject *args)
{
    PyObject *law_obj, *T_obj, *v_obj, *d_obj;
    if (!PyArg_ParseTuple(args, "OOOO", &law_obj, &T_obj, &v_obj, &d_obj)) return NULL;
    arena a = {0};
    tf_law law;
    PyObject *result = NULL;
    Py_ssize_t nT;
    if (parse_law(&a, law_obj, &law)) goto done;
    const double *T = get_array(&a, T_obj, &nT, "T");
    if (PyErr_Occurred()) goto done;
    double *value = out_array(&a, v_obj, nT, "output sizes differ from T");
    double *slope = value ? out_array(&a, d_obj, nT, "output sizes differ from T") : NULL;
    if (!slope) goto done;
    for (Py_ssize_t i = 0; i < nT; i++) value[i] = tf_law_eval(&law, T[i], slope + i);
    result = Py_NewRef(Py_None);
done:
    arena_free(&a);
    return result;
}

/* law_eval_load(law, T, L, value_out, dT_out, dL_out, coef_out): the law at (T[i], L[i]) (tf_law_eval_load),
 * its partials, and its derivatives in every coefficient (tf_law_coef_derivative) into coef_out (n x ncoef,
 * row-major); returns ncoef */
static PyObject *py_law_eval_load(PyObject *self, PyObject *args)
{
    PyObject *law_obj, *T_obj, *L_obj, *v_obj, *dT_obj, *dL_obj, *c_obj;
    if (!PyArg_ParseTuple(args, "OOOOOOO", &law_obj, &T_obj, &L_obj, &v_obj, &dT_obj, &dL_obj, &c_obj)) return NULL;
    arena a = {0};
    tf_law law;
    PyObject *result = NULL;
    Py_ssize_t nT, nL;
    if (parse_law(&a, law_obj, &law)) goto done;
    const double *T = get_array(&a, T_obj, &nT, "T");
    if (PyErr_Occurred()) goto done;
    const double *L = get_array(&a, L_obj, &nL, "L");
    if (PyErr_Occurred()) goto done;
    if (nL != nT) { PyErr_SetString(PyExc_ValueError, "T and L differ in length"); goto done; }
    int nc = tf_law_ncoef(&law);
    double *value = out_array(&a, v_obj, nT, "output sizes differ from T");
    double *dT = value ? out_array(&a, dT_obj, nT, "output sizes differ from T") : NULL;
    double *dL = dT ? out_array(&a, dL_obj, nT, "output sizes differ from T") : NULL;
    double *dc = dL ? out_array(&a, c_obj, nT * nc, "coef_out: n x ncoef values") : NULL;
    if (!dc) goto done;
    for (Py_ssize_t i = 0; i < nT; i++) {
        value[i] = tf_law_eval_load(&law, T[i], L[i], dT + i, dL + i);
        for (int k = 0; k < nc; k++) dc[i * nc + k] = tf_law_coef_derivative(&law, k, T[i], L[i]);
    }
    result = PyLong_FromLong(nc);
done:
    arena_free(&a);
    return result;
}

/* waveform_eval(wave, t, value_out) -> list of corners in [t[0], t[-1]] */
static PyObject *py_waveform_eval(PyObject *self, PyObject *args)
{
    PyObject *w_obj, *t_obj, *v_obj;
    if (!PyArg_ParseTuple(args, "OOO", &w_obj, &t_obj, &v_obj)) return NULL;
    arena a = {0};
    tf_waveform w;
    PyObject *result = NULL;
    Py_ssize_t nt;
    if (parse_waveform(&a, w_obj, &w)) goto done;
    const double *t = get_array(&a, t_obj, &nt, "t");
    if (PyErr_Occurred()) goto done;
    double *value = out_array(&a, v_obj, nt, "output size differs from t");
    if (!value) goto done;
    for (Py_ssize_t i = 0; i < nt; i++) value[i] = tf_waveform_value(&w, t[i]);
    long nc = nt > 0 ? tf_waveform_corners(&w, t[0], t[nt - 1], NULL, 0) : 0;
    double *corners = scratch(&a, sizeof(double) * (size_t)nc);
    if (!corners) goto done;
    if (nc) tf_waveform_corners(&w, t[0], t[nt - 1], corners, nc);
    result = PyList_New(nc);
    for (long i = 0; i < nc && result; i++) {
        PyObject *f = PyFloat_FromDouble(corners[i]);
        if (!f) { Py_CLEAR(result); break; }
        PyList_SET_ITEM(result, i, f);
    }
done:
    arena_free(&a);
    return result;
}

/* state_scale(spec) -> tuple: each state's characteristic magnitude (default tolerances) */
static PyObject *py_state_scale(PyObject *self, PyObject *args)
{
    PyObject *spec;
    if (!PyArg_ParseTuple(args, "O", &spec)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (parse_model(&a, spec, &m) == 0) {
        double scale[TF_MAX_STATES];
        int n = tf_model_nstate(&m);
        tf_model_state_scale(&m, scale);
        result = PyTuple_New(n);
        for (int i = 0; i < n && result; i++) PyTuple_SET_ITEM(result, i, PyFloat_FromDouble(scale[i]));
    }
    arena_free(&a);
    return result;
}

/* An optional per-period input of the loop: None (NULL), or n float64 values. */
static const double *loop_series(arena *a, PyObject *obj, Py_ssize_t n, const char *what)
{
    Py_ssize_t len;
    const double *s = get_array(a, obj, &len, what);
    if (s && len != n) PyErr_Format(PyExc_ValueError, "%s: one value per period (%zd), got %zd", what, n, len);
    return PyErr_Occurred() ? NULL : s;
}

/* The loop's estimator, from (est_spec, config, T0, var0, T_amb, T_proxy|None, position_noise|None, dob_tau):
 * its friction model in *f, the estimator initialised in *est; 0, or -1 with a Python error set. config is
 * the tuple of temperature_estimate. */
static int loop_estimator(arena *a, PyObject *obj, Py_ssize_t n, tf_loop *L, tf_temperature_estimator *est,
                          tf_rt_friction *f)
{
    PyObject *spec, *proxy, *noise;
    tf_temperature_config c;
    double T0, var0;
    tf_model m;
    tf_error e;
    if (!PyArg_ParseTuple(obj, "O(dddddiddddddd)dddOOd", &spec, &c.C_th, &c.R_th, &c.eta, &c.C_2, &c.R_2,
                          &c.proxy, &c.tau_p, &c.q[0], &c.q[1], &c.q[2], &c.r_F, &c.r_p, &c.v_min, &T0, &var0,
                          &L->T_amb, &proxy, &noise, &L->dob_tau))
        return -1;
    if (parse_model(a, spec, &m)) return -1;
    if (tf_rt_from_model(f, &m, &e)) return PyErr_Format(PyExc_ValueError, "estimator friction model: %s", e.what), -1;
    if (tf_temperature_init(est, &c, T0, var0, &e)) return PyErr_Format(PyExc_ValueError, "estimator: %s", e.what), -1;
    L->estimator = est, L->est_friction = f;
    L->T_proxy = loop_series(a, proxy, n, "T_proxy");
    if (!PyErr_Occurred()) L->position_noise = loop_series(a, noise, n, "position_noise");
    return PyErr_Occurred() ? -1 : 0;
}

/* loop(plant_spec, T_plant, T_plant_series|None, comp_spec|None, T_comp, T_comp_series|None, compensation,
 *      observer_gain, mass, (kp, ki, kd, tau_d), dt, substeps, x_ref, v_ref, estimator|None,
 *      (x, u, F_comp, F_plant, T_comp, T_variance, F_measured), inertia_feedforward[, load_plant, load_comp,
 *      load_plant_series|None, load_comp_series|None]): the closed loop of control.h; the outputs are float64
 *      arrays of n values (the last four may be None); the loads NaN (none) when not given. */
static PyObject *py_loop(PyObject *self, PyObject *args)
{
    PyObject *plant_spec, *comp_spec, *xr_obj, *vr_obj, *Tp_obj, *Tc_obj, *est_obj, *outs[7];
    PyObject *Lp_obj = Py_None, *Lc_obj = Py_None;
    tf_loop L;
    memset(&L, 0, sizeof L);
    L.load_plant = L.load_comp = NAN;
    double kp, ki, kd, tau_d;
    long substeps_in;
    if (!PyArg_ParseTuple(args, "OdOOdOidd(dddd)dlOOO(OOOOOOO)p|ddOO", &plant_spec, &L.T_plant, &Tp_obj, &comp_spec,
                          &L.T_comp, &Tc_obj, &L.compensation, &L.observer_gain, &L.mass, &kp, &ki, &kd, &tau_d, &L.dt,
                          &substeps_in, &xr_obj, &vr_obj, &est_obj, &outs[0], &outs[1], &outs[2], &outs[3], &outs[4],
                          &outs[5], &outs[6], &L.inertia_feedforward, &L.load_plant, &L.load_comp, &Lp_obj,
                          &Lc_obj))
        return NULL;
    if (substeps_in > TF_LOOP_MAX_SUBSTEPS) { /* beyond an int: the core's own bound, in its words */
        PyErr_SetString(PyExc_ValueError, "loop: n x substeps (at most 1e8 plant substeps in one run)");
        return NULL;
    }
    L.substeps = (int)(substeps_in < 0 ? 0 : substeps_in);
    /* the PID at rest, as tf_pid_init leaves it (bad gains: tf_loop_run refuses them) */
    L.pid.kp = kp, L.pid.ki = ki, L.pid.kd = kd, L.pid.tau_d = tau_d;
    arena a = {0}, b = {0}, c = {0};
    tf_model pm, cm;
    tf_rt_friction *rt = scratch(&a, 3 * sizeof(tf_rt_friction)); /* ~5 kB each: not on the stack */
    tf_temperature_estimator est;
    PyObject *result = NULL;
    if (!rt) goto done;
    if (parse_model(&a, plant_spec, &pm)) goto done;
    if (comp_spec != Py_None && parse_model(&b, comp_spec, &cm)) goto done;
    Py_ssize_t n, nv;
    const double *x_ref = get_array(&a, xr_obj, &n, "x_ref");
    if (PyErr_Occurred()) goto done;
    const double *v_ref = get_array(&a, vr_obj, &nv, "v_ref");
    if (PyErr_Occurred()) goto done;
    if (n < 1 || nv != n) { PyErr_SetString(PyExc_ValueError, "x_ref and v_ref: same length, >= 1"); goto done; }
    double *out[7] = {0};
    for (int k = 0; k < 7; k++)
        if ((k < 3 || outs[k] != Py_None) && !(out[k] = out_array(&a, outs[k], n, "outputs: one float64 per period")))
            goto done;
    L.trace = (tf_loop_trace){out[3], out[4], out[5], out[6]};
    if (!(L.T_plant_series = loop_series(&a, Tp_obj, n, "T_plant_series")) && PyErr_Occurred()) goto done;
    if (!(L.T_comp_series = loop_series(&a, Tc_obj, n, "T_comp_series")) && PyErr_Occurred()) goto done;
    if (!(L.load_plant_series = loop_series(&a, Lp_obj, n, "load_plant_series")) && PyErr_Occurred()) goto done;
    if (!(L.load_comp_series = loop_series(&a, Lc_obj, n, "load_comp_series")) && PyErr_Occurred()) goto done;
    if (est_obj != Py_None && loop_estimator(&c, est_obj, n, &L, &est, &rt[2])) goto done;
    tf_error e;
    int plant_bad = 0;
    if ((plant_bad = tf_rt_from_model(&rt[0], &pm, &e) != TF_OK) ||
        (comp_spec != Py_None && tf_rt_from_model(&rt[1], &cm, &e))) {
        PyErr_Format(PyExc_ValueError, "%s friction model: %s", plant_bad ? "plant" : "compensation", e.what);
        goto done;
    }
    L.plant = &rt[0], L.comp = &rt[1];
    if (comp_spec == Py_None) L.compensation = TF_COMP_NONE;
    tf_status status;
    Py_BEGIN_ALLOW_THREADS
    status = tf_loop_run(&L, (long)n, x_ref, v_ref, out[0], out[1], out[2], &e);
    Py_END_ALLOW_THREADS
    /* a refusal (ValueError) names the part, the argument and the period; other statuses are returned */
    if (status == TF_ERR_BAD_ARGUMENT && e.index >= 0)
        PyErr_Format(PyExc_ValueError, "%s: %s (period %ld)", e.where, e.what, e.index);
    else if (status == TF_ERR_BAD_ARGUMENT)
        PyErr_Format(PyExc_ValueError, "%s: %s", e.where, e.what);
    else
        result = PyLong_FromLong(status);
done:
    arena_free(&a);
    arena_free(&b);
    arena_free(&c);
    return result;
}

/* A per-step input of rt_steps: a float (into *c, NULL returned) or n float64 values. */
static const double *per_step(arena *a, PyObject *obj, Py_ssize_t n, const char *what, double *c)
{
    *c = NAN;
    if (PyFloat_Check(obj)) {
        *c = PyFloat_AsDouble(obj);
        return NULL;
    }
    Py_ssize_t len;
    const double *s = get_array(a, obj, &len, what);
    if (!PyErr_Occurred() && len != n) PyErr_Format(PyExc_ValueError, "%s: a number or one per velocity", what);
    return PyErr_Occurred() ? NULL : s;
}

/* rt_steps(spec, T, v, dt, F_out[, load]) -> seconds: tf_rt_step over the velocities v (one per step) at
 * temperature T and load (each a number, or an array with one per step; the load NaN when not given), the
 * forces into F_out, timed in C */
static PyObject *py_rt_steps(PyObject *self, PyObject *args)
{
    PyObject *spec, *v_obj, *F_obj, *T_obj, *L_obj = NULL;
    double dt;
    if (!PyArg_ParseTuple(args, "OOOdO|O", &spec, &T_obj, &v_obj, &dt, &F_obj, &L_obj)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    tf_rt_friction *f = scratch(&a, sizeof *f);
    if (!f) goto done;
    if (parse_model(&a, spec, &m)) goto done;
    Py_ssize_t n;
    const double *v = get_array(&a, v_obj, &n, "v");
    if (PyErr_Occurred()) goto done;
    double *F = out_array(&a, F_obj, n, "F_out: one float64 per velocity");
    if (!F) goto done;
    double T_const, L_const = NAN;
    const double *T = per_step(&a, T_obj, n, "T", &T_const), *L = NULL;
    if (PyErr_Occurred()) goto done;
    if (L_obj && L_obj != Py_None) L = per_step(&a, L_obj, n, "load", &L_const);
    if (PyErr_Occurred()) goto done;
    tf_error e;
    if (tf_rt_from_model(f, &m, &e)) { PyErr_Format(PyExc_ValueError, "friction model: %s", e.what); goto done; }
    struct timespec t0, t1;
    Py_ssize_t i = 0;
    Py_BEGIN_ALLOW_THREADS
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (; i < n; i++) /* no record while timing: a refused step changes nothing, so it is repeated for it */
        if (tf_rt_step(f, v[i], T ? T[i] : T_const, L ? L[i] : L_const, dt, &F[i], NULL)) break;
    clock_gettime(CLOCK_MONOTONIC, &t1);
    Py_END_ALLOW_THREADS
    /* a refused step: ValueError (an argument or parameter), FloatingPointError (an overflow) */
    if (i < n && tf_rt_step(f, v[i], T ? T[i] : T_const, L ? L[i] : L_const, dt, &F[i], &e) != TF_OK)
        PyErr_Format(e.code == TF_ERR_NONFINITE ? PyExc_FloatingPointError : PyExc_ValueError, "step %zd: %s",
                     i, e.what);
    else
        result = PyFloat_FromDouble((double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
done:
    arena_free(&a);
    return result;
}

/* temperature_estimate(spec, config, T0, var0, v, load|None, F_measured, T_proxy|None, T_amb, dt, T_out, var_out,
 * F_out) -> seconds: the estimator of estimator.h over n samples (v, F_measured, T_amb: n each; NaN in
 * F_measured: none; load: None (NaN: none) or n values; T_proxy: None or n values, NaN: none) with the friction
 * model of spec from rest; writes the contact temperature estimate, its variance and the friction estimate per
 * sample; the loop timed in C.
 * config: (C_th, R_th, eta, C_2, R_2, proxy, tau_p, q_contact, q_housing, q_proxy, r_F, r_p, v_min). */
static PyObject *py_temperature_estimate(PyObject *self, PyObject *args)
{
    PyObject *spec, *objs[5], *outs[3];
    tf_temperature_config c;
    double T0, var0, dt;
    if (!PyArg_ParseTuple(args, "O(dddddiddddddd)ddOOOOOdOOO", &spec, &c.C_th, &c.R_th, &c.eta, &c.C_2, &c.R_2,
                          &c.proxy, &c.tau_p, &c.q[0], &c.q[1], &c.q[2], &c.r_F, &c.r_p, &c.v_min, &T0, &var0,
                          &objs[0], &objs[1], &objs[2], &objs[3], &objs[4], &dt, &outs[0], &outs[1], &outs[2]))
        return NULL;
    static const char *names[5] = {"v", "load", "F_measured", "T_proxy", "T_amb"};
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    tf_rt_friction *f = scratch(&a, sizeof *f);
    if (!f || parse_model(&a, spec, &m)) goto done;
    const double *in[5];
    Py_ssize_t n = -1, len;
    for (int k = 0; k < 5; k++) {
        in[k] = get_array(&a, objs[k], &len, names[k]);
        if (PyErr_Occurred()) goto done;
        if (k == 0) n = len;
        if ((in[k] || (k != 1 && k != 3)) && len != n) {
            PyErr_Format(PyExc_ValueError, "%s: one value per sample (%zd), got %zd", names[k], n, len);
            goto done;
        }
    }
    double *out[3];
    for (int k = 0; k < 3; k++)
        if (!(out[k] = out_array(&a, outs[k], n, "outputs: one float64 per sample"))) goto done;
    tf_error e;
    tf_temperature_estimator est;
    if (tf_rt_from_model(f, &m, &e)) { PyErr_Format(PyExc_ValueError, "friction model: %s", e.what); goto done; }
    if (tf_temperature_init(&est, &c, T0, var0, &e)) { PyErr_Format(PyExc_ValueError, "%s", e.what); goto done; }
    struct timespec t0, t1;
    Py_ssize_t i = 0;
    tf_status status = TF_OK;
    Py_BEGIN_ALLOW_THREADS
    clock_gettime(CLOCK_MONOTONIC, &t0);
    for (; i < n; i++) {
        status = tf_temperature_step(&est, f, in[0][i], in[1] ? in[1][i] : NAN, in[2][i], in[3] ? in[3][i] : NAN,
                                     in[4][i], dt, &out[2][i], &e);
        if (status) break;
        out[0][i] = est.x[0];
        out[1][i] = est.P[0][0];
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    Py_END_ALLOW_THREADS
    /* a refused step: ValueError (an argument or parameter), FloatingPointError (an overflow) */
    if (status)
        PyErr_Format(status == TF_ERR_NONFINITE ? PyExc_FloatingPointError : PyExc_ValueError, "sample %zd: %s", i,
                     e.what);
    else
        result = PyFloat_FromDouble((double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
done:
    arena_free(&a);
    return result;
}

/* The contract with Python, from one source: every enum constant of the core's headers with the
 * name Python uses for it, grouped. thermofriction._bridge reads these; tests/test_bridge.py parses
 * the headers and fails if a header constant is missing here or a name here is not in a header. */
typedef struct {
    const char *group, *name, *c_name;
    long value;
} tf_constant;

#define C(group, name, sym) {group, name, #sym, (long)(sym)}
static const tf_constant constants[] = {
#define PARAMETER(symbol, name, unit, meaning) C("parameter", name, TF_P_##symbol),
    TF_PARAMETERS(PARAMETER)
#undef PARAMETER
    C("plant", "stick-slip", TF_PLANT_STICK_SLIP), C("plant", "mass", TF_PLANT_MASS),
    C("plant", "prescribed", TF_PLANT_PRESCRIBED),
#define FRICTION(symbol, name, states, equations) C("friction", name, TF_FRICTION_##symbol),
    TF_FRICTION_MODELS(FRICTION)
#undef FRICTION
    C("law", "none", TF_LAW_NONE), C("law", "const", TF_LAW_CONST), C("law", "linear", TF_LAW_LINEAR),
    C("law", "exp", TF_LAW_EXP), C("law", "poly", TF_LAW_POLY), C("law", "pwl", TF_LAW_PWL),
    C("law", "table", TF_LAW_TABLE),
    C("load_kind", "none", TF_LOAD_NONE), C("load_kind", "proportional", TF_LOAD_PROPORTIONAL),
    C("load_kind", "affine", TF_LOAD_AFFINE),
    C("load_combine", "product", TF_COMBINE_PRODUCT), C("load_combine", "sum", TF_COMBINE_SUM),
    C("thermal", "none", TF_THERMAL_NONE), C("thermal", "model-i", TF_THERMAL_MODEL_I),
    C("thermal", "model-ii", TF_THERMAL_MODEL_II),
    C("df_form", "scale", TF_DF_SCALE), C("df_form", "offset", TF_DF_OFFSET),
    C("waveform", "zero", TF_WAVE_ZERO), C("waveform", "sawtooth", TF_WAVE_SAWTOOTH),
    C("waveform", "sine", TF_WAVE_SINE), C("waveform", "square", TF_WAVE_SQUARE), C("waveform", "step", TF_WAVE_STEP),
    C("waveform", "sampled", TF_WAVE_SAMPLED),
    C("method", "auto", TF_METHOD_AUTO), C("method", "dopri5", TF_METHOD_DOPRI5), C("method", "rodas4", TF_METHOD_RODAS4),
    C("status", "ok", TF_OK), C("status", "nonfinite", TF_ERR_NONFINITE),
    C("status", "step_underflow", TF_ERR_STEP_UNDERFLOW), C("status", "max_steps", TF_ERR_MAX_STEPS),
    C("status", "bad_argument", TF_ERR_BAD_ARGUMENT), C("status", "no_memory", TF_ERR_NO_MEMORY),
    C("status", "interrupted", TF_ERR_INTERRUPTED), C("status", "singular", TF_ERR_SINGULAR),
    C("output", "time", TF_OUT_TIME), C("output", "input", TF_OUT_INPUT),
    C("output", "stage_displacement", TF_OUT_STAGE_DISPLACEMENT), C("output", "stage_velocity", TF_OUT_STAGE_VELOCITY),
    C("output", "displacement", TF_OUT_DISPLACEMENT), C("output", "velocity", TF_OUT_VELOCITY),
    C("output", "relative_displacement", TF_OUT_RELATIVE_DISPLACEMENT),
    C("output", "relative_velocity", TF_OUT_RELATIVE_VELOCITY), C("output", "friction_force", TF_OUT_FRICTION_FORCE),
    C("output", "temperature", TF_OUT_TEMPERATURE),
    C("target", "param", TF_TARGET_PARAM), C("target", "law", TF_TARGET_LAW), C("target", "dF", TF_TARGET_DF),
    C("target", "heat", TF_TARGET_HEAT), C("target", "plant", TF_TARGET_PLANT),
    C("plant_parameter", "m", TF_PLANT_P_M), C("plant_parameter", "m_e", TF_PLANT_P_M_E),
    C("plant_parameter", "c", TF_PLANT_P_C), C("plant_parameter", "k", TF_PLANT_P_K),
    C("plant_parameter", "T_em", TF_PLANT_P_T_EM), C("plant_parameter", "xi", TF_PLANT_P_XI),
    C("plant_parameter", "wn", TF_PLANT_P_WN), C("plant_parameter", "K", TF_PLANT_P_GAIN),
    C("plant_parameter", "m (modal)", TF_PLANT_P_M_MODAL), C("plant_parameter", "k_s", TF_PLANT_P_K_S),
    C("heat_parameter", "C_th", TF_HEAT_C_TH), C("heat_parameter", "R_th", TF_HEAT_R_TH),
    C("heat_parameter", "eta", TF_HEAT_ETA), C("heat_parameter", "T_amb", TF_HEAT_T_AMB),
    C("heat_parameter", "T_0", TF_HEAT_T_0),
    C("domain_rule", "positive", TF_DOMAIN_POSITIVE), C("domain_rule", "non-negative", TF_DOMAIN_NON_NEGATIVE),
    C("domain_rule", "at-least", TF_DOMAIN_AT_LEAST), C("domain_rule", "below-deflection", TF_DOMAIN_BELOW_DEFLECTION),
    C("domain_rule", "positive-or-absent", TF_DOMAIN_POSITIVE_OR_ABSENT),
    C("domain_when", "always", TF_DOMAIN_ALWAYS), C("domain_when", "stribeck", TF_DOMAIN_STRIBECK),
    C("domain_when", "offset-form", TF_DOMAIN_OFFSET_FORM),
    C("compensation", "none", TF_COMP_NONE), C("compensation", "feedforward", TF_COMP_FEEDFORWARD),
    C("compensation", "observer", TF_COMP_OBSERVER),
    C("proxy", "none", TF_PROXY_NONE), C("proxy", "contact", TF_PROXY_CONTACT), C("proxy", "housing", TF_PROXY_HOUSING),
    /* counts and capacities */
    C("limit", "parameters", TF_NPARAM), C("limit", "friction_models", TF_NFRICTION),
    C("limit", "fixed_outputs", TF_OUT_NFIXED),
    C("limit", "heat_parameters", TF_HEAT_NPARAM), C("limit", "plant_parameters", TF_PLANT_NPARAM), C("limit", "friction_states", TF_MAX_FRICTION_STATES),
    C("limit", "states", TF_MAX_STATES), C("limit", "targets", TF_MAX_TARGETS),
    C("limit", "domain_rules", TF_DOMAIN_NRULE), C("limit", "domain_conditions", TF_DOMAIN_NWHEN),
};
#undef C

/* The name of the constant of a group with a value (NULL if none). */
static const char *constant_name(const char *group, long value)
{
    for (size_t i = 0; i < sizeof constants / sizeof constants[0]; i++)
        if (constants[i].value == value && strcmp(constants[i].group, group) == 0) return constants[i].name;
    return NULL;
}

/* FRICTION_DOMAINS: {model: ((parameter, rule, other or None, when), ...)}, domains.h's table in its order
 * (the order the C checks follow), every code by its name in CONSTANTS. */
typedef struct {
    int model, param, rule, other, when;
} domain_row;
#define DOMAIN_ROW(model, param, rule, other, when) \
    {TF_FRICTION_##model, TF_P_##param, TF_DOMAIN_##rule, TF_P_##other, TF_DOMAIN_##when},
static const domain_row domain_rows[] = {TF_FRICTION_DOMAINS(DOMAIN_ROW)};
#undef DOMAIN_ROW

static PyObject *friction_domains(void)
{
    PyObject *lists = PyDict_New(), *result = NULL, *key, *list;
    if (!lists) return NULL;
    for (size_t i = 0; i < sizeof domain_rows / sizeof domain_rows[0]; i++) {
        const domain_row *r = &domain_rows[i];
        const char *model = constant_name("friction", r->model);
        list = PyDict_GetItemString(lists, model); /* borrowed */
        if (!list) {
            list = PyList_New(0);
            if (!list || PyDict_SetItemString(lists, model, list) < 0) { Py_XDECREF(list); goto done; }
            Py_DECREF(list); /* the dict holds it */
        }
        PyObject *other = r->other < 0 ? Py_NewRef(Py_None) : PyUnicode_FromString(constant_name("parameter", r->other));
        PyObject *row = other ? Py_BuildValue("(ssNs)", constant_name("parameter", r->param),
                                              constant_name("domain_rule", r->rule), other,
                                              constant_name("domain_when", r->when))
                              : NULL;
        int bad = !row || PyList_Append(list, row) < 0;
        Py_XDECREF(row);
        if (bad) goto done;
    }
    result = PyDict_New();
    Py_ssize_t pos = 0;
    while (result && PyDict_Next(lists, &pos, &key, &list)) {
        PyObject *rows = PyList_AsTuple(list);
        if (!rows || PyDict_SetItem(result, key, rows) < 0) Py_CLEAR(result);
        Py_XDECREF(rows);
    }
done:
    Py_DECREF(lists);
    return result;
}

/* CONSTANTS: {group: {name: value}}; C_NAMES: {C symbol: value} (for the contract test). */
static int add_constants(PyObject *mod)
{
    PyObject *groups = PyDict_New(), *c_names = PyDict_New();
    if (!groups || !c_names) goto fail;
    for (size_t i = 0; i < sizeof constants / sizeof constants[0]; i++) {
        const tf_constant *c = &constants[i];
        PyObject *group = PyDict_GetItemString(groups, c->group); /* borrowed */
        if (!group) {
            group = PyDict_New();
            if (!group || PyDict_SetItemString(groups, c->group, group) < 0) { Py_XDECREF(group); goto fail; }
            Py_DECREF(group); /* the dict holds it */
        }
        PyObject *v = PyLong_FromLong(c->value);
        if (!v) goto fail;
        int bad = PyDict_SetItemString(group, c->name, v) < 0 || PyDict_SetItemString(c_names, c->c_name, v) < 0;
        Py_DECREF(v);
        if (bad) goto fail;
    }
    /* PARAMETER_UNITS: {name: unit}, from the same list as the indices */
    PyObject *units = Py_BuildValue("{" 
#define UNIT_FORMAT(symbol, name, unit, meaning) "s:s"
                                    TF_PARAMETERS(UNIT_FORMAT)
#undef UNIT_FORMAT
                                    "}"
#define UNIT_ARGS(symbol, name, unit, meaning) , name, unit
                                    TF_PARAMETERS(UNIT_ARGS)
#undef UNIT_ARGS
    );
    if (!units || PyModule_AddObject(mod, "PARAMETER_UNITS", units) < 0) { Py_XDECREF(units); goto fail; }
    PyObject *domains = friction_domains();
    if (!domains || PyModule_AddObject(mod, "FRICTION_DOMAINS", domains) < 0) { Py_XDECREF(domains); goto fail; }
    if (PyModule_AddObject(mod, "CONSTANTS", groups) < 0) goto fail;
    groups = NULL;
    if (PyModule_AddObject(mod, "C_NAMES", c_names) < 0) goto fail;
    return 0;
fail:
    Py_XDECREF(groups);
    Py_XDECREF(c_names);
    return -1;
}

/* prescribed_force(spec, t_out, F_out, params, dF_out|None): the friction force under a prescribed
 * motion stepped exactly (prescribed.h) into F_out (n_out float64), its derivatives with respect to
 * the parameters `params` (a tuple of tf_param indices) into dF_out (n_out x np, C order). Raises
 * SolverError with the core's status and record. */
static PyObject *py_prescribed_force(PyObject *self, PyObject *args)
{
    PyObject *spec, *t_obj, *F_obj, *p_obj, *dF_obj;
    if (!PyArg_ParseTuple(args, "OOOOO", &spec, &t_obj, &F_obj, &p_obj, &dF_obj)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    int params[TF_NPARAM];
    if (parse_model(&a, spec, &m)) goto done;
    Py_ssize_t n_out;
    const double *t_out = get_array(&a, t_obj, &n_out, "t_out");
    if (PyErr_Occurred()) goto done;
    if (!PyTuple_Check(p_obj) || PyTuple_GET_SIZE(p_obj) > TF_NPARAM) {
        PyErr_SetString(PyExc_ValueError, "params must be a tuple of at most TF_NPARAM indices");
        goto done;
    }
    int np = (int)PyTuple_GET_SIZE(p_obj);
    for (int j = 0; j < np; j++) {
        params[j] = (int)PyLong_AsLong(PyTuple_GET_ITEM(p_obj, j));
        if (PyErr_Occurred()) goto done;
    }
    double *F = out_array(&a, F_obj, n_out, "F_out: one float64 per output time"), *dF = NULL;
    if (!F) goto done;
    if (np > 0 && !(dF = out_array(&a, dF_obj, n_out * np, "dF_out: a C-ordered float64 array of shape (n_out, np)")))
        goto done;
    if (check_model(&m)) goto done;
    tf_error e;
    tf_status status;
    Py_BEGIN_ALLOW_THREADS
    status = tf_prescribed_force(&m, (long)n_out, t_out, F, np, params, dF, &e);
    Py_END_ALLOW_THREADS
    if (status != TF_OK) {
        PyObject *exc_args = Py_BuildValue("(siddNi)", e.what, (int)e.code, e.t, 0.0, PyTuple_New(0), 0);
        if (exc_args) { PyErr_SetObject(SolverError, exc_args); Py_DECREF(exc_args); }
        goto done;
    }
    result = Py_BuildValue("i", tf_prescribed_applies(&m));
done:
    arena_free(&a);
    return result;
}

/* prescribed_applies(spec): whether prescribed_force applies to the model (tf_prescribed_applies). */
static PyObject *py_prescribed_applies(PyObject *self, PyObject *args)
{
    PyObject *spec;
    if (!PyArg_ParseTuple(args, "O", &spec)) return NULL;
    arena a = {0};
    tf_model m;
    PyObject *result = NULL;
    if (!parse_model(&a, spec, &m)) result = PyBool_FromLong(tf_prescribed_applies(&m));
    arena_free(&a);
    return result;
}

static PyMethodDef methods[] = {
    {"prescribed_force", py_prescribed_force, METH_VARARGS,
     "Friction force (and parameter derivatives) under a prescribed motion, stepped exactly."},
    {"prescribed_applies", py_prescribed_applies, METH_VARARGS, "Whether prescribed_force applies to a model."},
    {"rt_steps", py_rt_steps, METH_VARARGS, "tf_rt_step over an array of velocities; returns seconds (timed in C)."},
    {"temperature_estimate", py_temperature_estimate, METH_VARARGS,
     "The temperature estimator of estimator.h over arrays of samples; returns seconds (timed in C)."},
    {"loop", py_loop, METH_VARARGS, "The closed-loop stage simulation of control.h (fixed step)."},
    {"simulate", py_simulate, METH_VARARGS, "Integrate a model on an output grid (see thermofriction.simulate)."},
    {"simulate_sensitivities", py_simulate_sensitivities, METH_VARARGS,
     "Integrate a model and its forward sensitivities to the given targets."},
    {"rhs_jac", py_rhs_jac, METH_VARARGS, "Right-hand side and Jacobian at one state; returns the friction force."},
    {"time_rhs", py_time_rhs, METH_VARARGS, "Seconds per right-hand-side evaluation, timed in C (benchmarks)."},
    {"law_eval", py_law_eval, METH_VARARGS, "Evaluate a temperature law and its slope on an array of T."},
    {"law_eval_load", py_law_eval_load, METH_VARARGS,
     "Evaluate a law at (T, load) with its partials and coefficient derivatives; returns the coefficients' count."},
    {"waveform_eval", py_waveform_eval, METH_VARARGS, "Evaluate a waveform on an array of t; returns its corners."},
    {"state_scale", py_state_scale, METH_VARARGS, "Characteristic magnitude of each state."},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "_core", "thermofriction C core binding", -1, methods};

PyMODINIT_FUNC PyInit__core(void)
{
    PyObject *mod = PyModule_Create(&module);
    if (!mod) return NULL;
    SolverError = PyErr_NewException("thermofriction._core.SolverError", NULL, NULL);
    if (PyModule_AddObject(mod, "SolverError", SolverError) < 0) return NULL;
    Py_INCREF(SolverError);
    if (add_constants(mod) < 0) return NULL;
    main_thread_ident = PyThread_get_thread_ident(); /* Python imports extension modules ... */
    PyObject *threading = PyImport_ImportModule("threading"); /* ... but ask, in case this is not the main thread */
    PyObject *main = threading ? PyObject_CallMethod(threading, "main_thread", NULL) : NULL;
    PyObject *ident = main ? PyObject_GetAttrString(main, "ident") : NULL;
    if (ident && PyLong_Check(ident)) main_thread_ident = PyLong_AsUnsignedLong(ident);
    Py_XDECREF(ident);
    Py_XDECREF(main);
    Py_XDECREF(threading);
    PyErr_Clear(); /* no answer: the importing thread it is */
    return mod;
}
