/* The FMU's model and step logic around the C core (docs/fmu.md), shared by the FMI 2.0 and FMI 3.0
 * co-simulation wrappers (fmi2_cs.c, fmi3_cs.c): one binary for every model. Messages name the FMI 2
 * functions; an FMI 3 instance's logger shows the FMI 3 names (fmu_callbacks.names).
 *
 * The model is not compiled in: the instantiation reads it from resources/model.tfm, a text file the
 * Python exporter writes (thermofriction/fmu.py). That file gives the structure (plant, friction
 * model, thermal extension, the laws' kinds and sizes) and, for every tunable parameter, its value
 * reference, its role in a tf_model and its start value. So one prebuilt shared object serves any
 * model and no compiler is needed where the FMU is made.
 *
 * Between two communication points the model is integrated by tf_solve (the adaptive
 * Dormand-Prince / Rodas4 switch of integrator.h), the inputs being held (or, after
 * fmi2SetRealInputDerivatives (FMI 2 only), followed along their first derivative) through the step. The drive
 * and the temperature reach the core as two-point sampled signals over the step, so the core's own
 * corner handling and parameter cache apply unchanged.
 *
 * Never a crash on bad input: non-finite inputs or parameters, parameters out of their domain at
 * the temperature, a failed integration give FMU_ERROR with a logged message and leave the state as
 * it was before the call; a temperature outside the laws' calibrated range gives FMU_WARNING. */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_common.h"
#include "thermofriction.h"

#define FMU_FORMAT 2 /* 2: the "guid" line */
#define MAX_VR 2048     /* value references 0 .. MAX_VR-1 */
#define MAX_POINTS 256  /* points (or coefficients) of one law */
#define NLAW (TF_NPARAM + 1) /* the parameters' laws, then Model II's dF */
/* The work of one communication step is bounded (a fuzzer builds with smaller bounds): */
#ifndef MAX_FIXED_STEPS
#define MAX_FIXED_STEPS 100000000L /* fixed steps (~10 s of work): more is refused */
#endif
#ifndef MAX_ADAPTIVE_STEPS
#define MAX_ADAPTIVE_STEPS 10000000L /* the adaptive integrator's steps: more fails */
#endif
#define T_MIN (-100.0)  /* [degC] the temperatures a sensor on an actuator can read: the package's range */
#define T_MAX 300.0     /* (thermofriction.plausible.TEMPERATURE_RANGE); outside it an input is refused */
#define TIME_LIMIT 1e12 /* [s] the core's time limit (integrator.h: beyond it a double resolves time poorly) */

/* Fixed value references of the inputs and outputs; parameters come from the resource file. */
enum {
    VR_DRIVE = 0,          /* input: voltage, force or displacement */
    VR_TEMPERATURE = 1,    /* input: temperature (the ambient temperature with a heat model) [degC] */
    VR_DISPLACEMENT = 2,
    VR_VELOCITY = 3,
    VR_FRICTION_FORCE = 4,
    VR_TEMPERATURE_OUT = 5,
    VR_STAGE_DISPLACEMENT = 6,
    /* the temperature estimator (estimator.h), with an "estimator" line in the resources: */
    VR_TEMPERATURE_ESTIMATE = 7, /* outputs: the contact temperature estimate [degC] */
    VR_TEMPERATURE_VARIANCE = 8, /* and its variance [K^2] */
    VR_MEASURED_FORCE = 9,       /* inputs: the measured friction force [N] (NaN: none) */
    VR_PROXY_TEMPERATURE = 10,   /* the proxy temperature [degC] (NaN: none), with a proxy */
    VR_AMBIENT = 11,             /* the ambient temperature [degC], without a heat model (with one: VR_TEMPERATURE) */
    VR_LOAD = 12,                /* input: the load [N or N m] a law of the load reads, with a "load_input" line */
    VR_FIRST_PARAMETER = 16
};

/* What a parameter's value reference sets in the tf_model. */
typedef enum {
    ROLE_NONE = 0, ROLE_M, ROLE_M_E, ROLE_C, ROLE_K, ROLE_T_EM, ROLE_XI, ROLE_WN, ROLE_GAIN, ROLE_K_S, ROLE_V_0,
    ROLE_PARAM, ROLE_LAW_A, ROLE_LAW_B, ROLE_LAW_X, ROLE_LAW_Y, ROLE_GMS_K, ROLE_GMS_W,
    ROLE_C_TH, ROLE_R_TH, ROLE_ETA, ROLE_T_0, ROLE_STEP, ROLE_ESTIMATOR, ROLE_LOAD_K, ROLE_LOAD_S, ROLE_LOAD_C
} role_kind;

static const char *const ROLE_NAMES[] = {"", "m", "m_e", "c", "k", "T_em", "xi", "wn", "K", "k_s", "v_0",
                                         "p", "law_a", "law_b", "law_x", "law_y", "gms_k", "gms_w",
                                         "C_th", "R_th", "eta", "T_0", "step", "estimator",
                                         "load_k", "load_sat", "load_c"};

/* The estimator's parameters (role "estimator", index i): tf_temperature_config's numbers, then its start. */
enum { EST_C_TH, EST_R_TH, EST_ETA, EST_C_2, EST_R_2, EST_TAU_P, EST_Q_CONTACT, EST_Q_HOUSING, EST_Q_PROXY, EST_R_F,
       EST_R_P, EST_V_MIN, EST_T_0, EST_VAR_0, EST_NPARAM };

typedef struct {
    unsigned char role, fixed; /* fixed: settable before initialisation only (law breakpoints, T_0) */
    short i, j;                /* parameter / law index, element or point index */
} role_t;

typedef struct {
    int kind, n;
    double x[MAX_POINTS], y[MAX_POINTS], d[MAX_POINTS];
    tf_load_term load; /* the law's load term ("load_law" line; k, saturation and c from their parameters) */
} law_store;

struct fmu_instance {
    fmu_callbacks cb;
    char *name;
    int logging;
    enum { S_INSTANTIATED = FMU_IN_INSTANTIATED, S_INIT = FMU_IN_INITIALIZATION, S_STEP = FMU_IN_STEP,
           S_TERMINATED = FMU_IN_TERMINATED } mode;
    int stop_defined;        /* the experiment's stop time (fmi2SetupExperiment): no step ends past it */
    double stop;

    /* structure (resources) */
    int plant, modal, friction, n_gms, thermal, df_form, fs_follows_fc, heat, temperature_input;
    double range_lo, range_hi; /* the laws' calibrated range; NaN: none */
    int load_input;          /* the model reads the load: the input VR_LOAD */
    double load_lo, load_hi; /* the calibrated range of |load| (the load terms' ranges in common); NaN: none */
    tf_waveform p_ext;
    law_store law[NLAW];
    role_t role[MAX_VR];
    int max_vr;
    char guid[64];           /* the model description's GUID (resources: "guid" line) */

    /* values: parameters and inputs by value reference, their start values for fmi2Reset */
    double r[MAX_VR], r_start[MAX_VR];
    double du, dT, dL;       /* input derivatives for the next step (0: held) */
    int du_set;              /* du given for the next step */
    double u_prev;           /* prescribed motion: where the last step left the motion */
    double last_du;          /* prescribed motion: its slope over the last step (the velocity reported after it) */

    /* the model, its run's data (plant.h: the parameter cache and the GMS modes, which are state) and its state */
    tf_model model;
    tf_model_data data;
    double wave_t[2], wave_v[2], temp_t[2], temp_v[2], load_t[2], load_v[2];
    double t, y[TF_MAX_STATES];
    double rtol;
    double fixed_step;       /* > 0: the fixed-step real-time integrator at this step [s]; 0: adaptive */
    int out_of_range;        /* the last temperature was outside the range (warn once per excursion) */
    int load_out_of_range;   /* the last load was outside its range (the same) */

    /* the temperature estimator: on with an "estimator" line (its proxy kind), stepped once per communication
       step after the plant, on its own real-time friction object (the model's friction at the estimate) */
    int estimator, est_proxy;
    double est_p[EST_NPARAM];
    tf_temperature_estimator est, est_trial; /* the trial: a step's result until the plant's step succeeded */
    tf_rt_friction est_rt, est_rt_trial;
};
typedef struct fmu_instance instance;

/* ---- logging ---- */

static void logv(instance *c, fmu_status status, const char *category, const char *fmt, va_list ap)
{
    if (!c || !c->cb.log) return;
    if (status == FMU_OK && !c->logging) return;
    char msg[512], esc[1024];
    vsnprintf(msg, sizeof msg, fmt, ap);
    const char *body = msg, *rename = "";
    for (const char *const *p = c->cb.names; p && p[0]; p += 2) { /* the standard's own function names */
        size_t n = strlen(p[0]);
        if (strncmp(msg, p[0], n) == 0 && msg[n] == ':') { body = msg + n, rename = p[1]; break; }
    }
    /* An FMI 2 logger takes a printf format; many importers (fmpy among them) show the format without
     * formatting it. So there the message itself is the format, its '%' doubled. */
    size_t k = strlen(rename) < sizeof esc / 2 ? strlen(rename) : 0;
    memcpy(esc, rename, k);
    for (const char *s = body; *s && k + 2 < sizeof esc; s++) {
        if (*s == '%' && c->cb.printf_format) esc[k++] = '%';
        esc[k++] = *s;
    }
    esc[k] = 0;
    c->cb.log(&c->cb, c->name ? c->name : "thermofriction", status, category, esc);
}

#if defined(__GNUC__)
#define PRINTF_LIKE __attribute__((format(printf, 2, 3)))
#else
#define PRINTF_LIKE
#endif

static void warn(instance *c, const char *fmt, ...) PRINTF_LIKE;
static void warn(instance *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    logv(c, FMU_WARNING, "logStatusWarning", fmt, ap);
    va_end(ap);
}

/* Logs an error and returns FMU_ERROR. */
fmu_status fmu_fail(instance *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    logv(c, FMU_ERROR, "logStatusError", fmt, ap);
    va_end(ap);
    return FMU_ERROR;
}

static const char *mode_name(int mode)
{
    switch (mode) {
    case S_INSTANTIATED: return "instantiated (not yet initialized)";
    case S_INIT: return "in initialization mode";
    case S_STEP: return "in step mode (initialized)";
    default: return "terminated";
    }
}

fmu_status fmu_require_mode(fmu_instance *c, const char *call, unsigned allowed)
{
    if (!c) return FMU_ERROR;
    if ((unsigned)c->mode & allowed) return FMU_OK;
    return fmu_fail(c, "%s: not allowed while the instance is %s (the FMI standard's state machine)", call,
                    mode_name(c->mode));
}

/* A temperature [degC] the package would take (thermofriction.plausible: -100 to 300 C). */
static int plausible_temperature(double T) { return T >= T_MIN && T <= T_MAX; }

/* ---- the resource file ---- */

/* file:///a/b%20c/resources -> /a/b c/resources (the forms FMI importers pass). */
static int uri_to_path(const char *uri, char *path, size_t size)
{
    const char *s = uri;
    if (strncmp(s, "file://", 7) == 0) {
        s += 7;
        if (strncmp(s, "localhost/", 10) == 0) s += 9;
    } else if (strncmp(s, "file:", 5) == 0) {
        s += 5;
    }
    size_t k = 0;
    for (; *s && k + 1 < size; s++) {
        if (s[0] == '%' && isxdigit((unsigned char)s[1]) && isxdigit((unsigned char)s[2])) {
            char hex[3] = {s[1], s[2], 0};
            path[k++] = (char)strtol(hex, 0, 16);
            s += 2;
        } else {
            path[k++] = *s;
        }
    }
    path[k] = 0;
#ifdef _WIN32
    if (path[0] == '/' && isalpha((unsigned char)path[1]) && path[2] == ':') memmove(path, path + 1, k); /* /C:/... */
#endif
    return *s == 0;
}

static int role_by_name(const char *name)
{
    for (int i = 1; i < (int)(sizeof ROLE_NAMES / sizeof *ROLE_NAMES); i++)
        if (strcmp(name, ROLE_NAMES[i]) == 0) return i;
    return -1;
}

/* Reads the model's structure and parameters from the folder dir (a file: URI if is_uri, FMI 2, else a
 * path, FMI 3); 0 on success, else logs the line and returns -1. */
static int read_resources(instance *c, const char *dir, int is_uri)
{
    char path[4096];
    if (is_uri ? !uri_to_path(dir, path, sizeof path - 16) : strlen(dir) >= sizeof path - 16)
        return (fmu_fail(c, "resource location too long"), -1);
    if (!is_uri) strcpy(path, dir);
    size_t len = strlen(path);
    while (len > 0 && (path[len - 1] == '/' || path[len - 1] == '\\')) path[--len] = 0;
    strcat(path, "/model.tfm");
    FILE *f = fopen(path, "r");
    if (!f) return (fmu_fail(c, "cannot open %s (the FMU's model description)", path), -1);
    char line[1024];
    int lineno = 0, ok = 1, have_header = 0;
    c->range_lo = c->range_hi = c->load_lo = c->load_hi = NAN;
    while (ok && fgets(line, sizeof line, f)) {
        lineno++;
        char key[32];
        int used = 0;
        if (line[0] == '#' || sscanf(line, "%31s%n", key, &used) != 1) continue;
        const char *rest = line + used;
        if (strcmp(key, "thermofriction-fmu") == 0) {
            int version;
            ok = sscanf(rest, "%d", &version) == 1 && version == FMU_FORMAT;
            have_header = ok;
        } else if (strcmp(key, "guid") == 0) {
            ok = sscanf(rest, "%63s", c->guid) == 1;
        } else if (strcmp(key, "plant") == 0) {
            ok = sscanf(rest, "%d %d", &c->plant, &c->modal) == 2;
        } else if (strcmp(key, "friction") == 0) {
            ok = sscanf(rest, "%d %d", &c->friction, &c->n_gms) == 2 && c->n_gms >= 0 &&
                 c->n_gms <= TF_MAX_FRICTION_STATES && tf_friction_nstate(c->friction, c->n_gms) >= 0;
        } else if (strcmp(key, "thermal") == 0) {
            ok = sscanf(rest, "%d %d %d", &c->thermal, &c->df_form, &c->fs_follows_fc) == 3;
        } else if (strcmp(key, "heat") == 0) {
            ok = sscanf(rest, "%d", &c->heat) == 1;
        } else if (strcmp(key, "temperature_input") == 0) {
            ok = sscanf(rest, "%d", &c->temperature_input) == 1;
        } else if (strcmp(key, "range") == 0) {
            ok = sscanf(rest, "%lf %lf", &c->range_lo, &c->range_hi) == 2;
        } else if (strcmp(key, "p_ext") == 0) { /* kind amplitude frequency rise offset direction slew t0 */
            tf_waveform *w = &c->p_ext;
            ok = sscanf(rest, "%d %lf %lf %lf %lf %lf %lf %lf", &w->kind, &w->amplitude, &w->frequency, &w->rise,
                        &w->offset, &w->direction, &w->slew, &w->t0) == 8 && w->kind != TF_WAVE_SAMPLED;
        } else if (strcmp(key, "law") == 0) { /* index (TF_NPARAM: dF) kind n */
            int i, kind, n;
            ok = sscanf(rest, "%d %d %d", &i, &kind, &n) == 3 && i >= 0 && i < NLAW && n >= 0 && n <= MAX_POINTS;
            if (ok) c->law[i].kind = kind, c->law[i].n = n;
        } else if (strcmp(key, "load_law") == 0) { /* index kind combine interaction (law.h: tf_load_term) */
            int i, kind, combine, interaction;
            ok = sscanf(rest, "%d %d %d %d", &i, &kind, &combine, &interaction) == 4 && i >= 0 && i < TF_NPARAM &&
                 kind >= TF_LOAD_PROPORTIONAL && kind <= TF_LOAD_AFFINE;
            if (ok) c->law[i].load.kind = kind, c->law[i].load.combine = combine, c->law[i].load.interaction = interaction;
        } else if (strcmp(key, "load_input") == 0) { /* the load input's start value [N or N m] */
            ok = sscanf(rest, "%lf", &c->r_start[VR_LOAD]) == 1 && isfinite(c->r_start[VR_LOAD]);
            c->load_input = ok;
            c->r[VR_LOAD] = c->r_start[VR_LOAD];
        } else if (strcmp(key, "load_range") == 0) {
            ok = sscanf(rest, "%lf %lf", &c->load_lo, &c->load_hi) == 2;
        } else if (strcmp(key, "var") == 0) { /* vr role i j fixed start */
            unsigned vr;
            char rname[16];
            int i, j, fixed;
            double start;
            ok = sscanf(rest, "%u %15s %d %d %d %lf", &vr, rname, &i, &j, &fixed, &start) == 6 &&
                 vr >= VR_FIRST_PARAMETER && vr < MAX_VR && role_by_name(rname) > 0 && isfinite(start);
            if (ok) {
                c->role[vr] = (role_t){(unsigned char)role_by_name(rname), (unsigned char)fixed, (short)i, (short)j};
                c->r[vr] = c->r_start[vr] = start;
                if ((int)vr > c->max_vr) c->max_vr = (int)vr;
            }
        } else if (strcmp(key, "integrator") == 0) { /* adaptive | realtime (its step: the "step" variable) */
            char kind[16];
            ok = sscanf(rest, "%15s", kind) == 1 && (strcmp(kind, "adaptive") == 0 || strcmp(kind, "realtime") == 0);
            if (ok) c->fixed_step = strcmp(kind, "realtime") == 0 ? NAN : 0.0; /* NaN until its variable is read */
        } else if (strcmp(key, "estimator") == 0) { /* the estimator's proxy kind (estimator.h) */
            double T_amb;
            ok = sscanf(rest, "%d %lf", &c->est_proxy, &T_amb) == 2 && c->est_proxy >= TF_PROXY_NONE &&
                 c->est_proxy <= TF_PROXY_HOUSING && plausible_temperature(T_amb);
            c->estimator = ok;
            c->r[VR_AMBIENT] = c->r_start[VR_AMBIENT] = T_amb; /* the measurements: none until given */
            c->r[VR_MEASURED_FORCE] = c->r_start[VR_MEASURED_FORCE] = NAN;
            c->r[VR_PROXY_TEMPERATURE] = c->r_start[VR_PROXY_TEMPERATURE] = NAN;
        } else if (strcmp(key, "input") == 0) { /* start values of the inputs */
            ok = sscanf(rest, "%lf %lf", &c->r_start[VR_DRIVE], &c->r_start[VR_TEMPERATURE]) == 2;
            c->r[VR_DRIVE] = c->r_start[VR_DRIVE];
            c->r[VR_TEMPERATURE] = c->r_start[VR_TEMPERATURE];
        } else {
            ok = 0;
        }
    }
    fclose(f);
    if (!ok) return (fmu_fail(c, "%s, line %d: not understood (an FMU made by another version?)", path, lineno), -1);
    if (!have_header) return (fmu_fail(c, "%s: not a thermofriction FMU model description", path), -1);
    if (!c->guid[0]) return (fmu_fail(c, "%s: no guid line (the model description's GUID)", path), -1);
    if (isnan(c->fixed_step)) {
        int has_step = 0;
        for (int vr = VR_FIRST_PARAMETER; vr <= c->max_vr; vr++) has_step |= c->role[vr].role == ROLE_STEP;
        if (!has_step) return (fmu_fail(c, "%s: the realtime integrator without its step variable", path), -1);
    }
    return 0;
}

/* ---- the model from the parameter values ---- */

/* Builds a model (c->model, or a trial copy) from the structure and the values; 0, or logs why not and
 * returns -1. */
static int build_model(instance *c, tf_model *m)
{
    memset(m, 0, sizeof *m);
    m->plant = c->plant;
    m->friction = c->friction;
    m->thermal = c->thermal;
    m->dF_form = c->df_form;
    m->fs_follows_fc = c->fs_follows_fc;
    m->gms.n = c->n_gms;
    m->m = 1.0;
    double xi = 0, wn = 0, gain = 0;
    for (int vr = VR_FIRST_PARAMETER; vr <= c->max_vr; vr++) {
        role_t r = c->role[vr];
        double v = c->r[vr];
        switch (r.role) {
        case ROLE_M: m->m = v; break;
        case ROLE_M_E: m->m_e = v; break;
        case ROLE_C: m->c = v; break;
        case ROLE_K: m->k = v; break;
        case ROLE_T_EM: m->T_em = v; break;
        case ROLE_XI: xi = v; break;
        case ROLE_WN: wn = v; break;
        case ROLE_GAIN: gain = v; break;
        case ROLE_K_S: m->k_s = v; break;
        case ROLE_V_0: m->v_0 = v; break;
        case ROLE_PARAM: if (r.i >= 0 && r.i < TF_NPARAM) m->p[r.i] = v; break;
        case ROLE_LAW_A: if (r.i >= 0 && r.i < NLAW) c->law[r.i].x[0] = v; break; /* a, b kept in x[0], y[0] */
        case ROLE_LAW_B: if (r.i >= 0 && r.i < NLAW) c->law[r.i].y[0] = v; break;
        case ROLE_LAW_X: if (r.i >= 0 && r.i < NLAW && r.j >= 0 && r.j < MAX_POINTS) c->law[r.i].x[r.j] = v; break;
        case ROLE_LAW_Y: if (r.i >= 0 && r.i < NLAW && r.j >= 0 && r.j < MAX_POINTS) c->law[r.i].y[r.j] = v; break;
        case ROLE_GMS_K: if (r.i >= 0 && r.i < TF_MAX_FRICTION_STATES) m->gms.k[r.i] = v; break;
        case ROLE_GMS_W: if (r.i >= 0 && r.i < TF_MAX_FRICTION_STATES) m->gms.w[r.i] = v; break;
        case ROLE_C_TH: m->heat.C_th = v; break;
        case ROLE_R_TH: m->heat.R_th = v; break;
        case ROLE_ETA: m->heat.eta = v; break;
        case ROLE_T_0: m->heat.T_0 = v; break;
        case ROLE_STEP:
            if (!(v > 0 && isfinite(v))) return (fmu_fail(c, "integrator.step = %g s: the fixed step must be positive", v), -1);
            c->fixed_step = v;
            break;
        case ROLE_ESTIMATOR: if (r.i >= 0 && r.i < EST_NPARAM) c->est_p[r.i] = v; break;
        case ROLE_LOAD_K: if (r.i >= 0 && r.i < TF_NPARAM) c->law[r.i].load.k = v; break;
        case ROLE_LOAD_S: if (r.i >= 0 && r.i < TF_NPARAM) c->law[r.i].load.saturation = v; break;
        case ROLE_LOAD_C: if (r.i >= 0 && r.i < TF_NPARAM) c->law[r.i].load.c = v; break;
        default: break;
        }
        if (r.role && !isfinite(v)) return (fmu_fail(c, "parameter (value reference %d) is not finite", vr), -1);
    }
    if (c->plant == TF_PLANT_STICK_SLIP && c->modal) { /* k = m wn^2, c = 2 xi wn m, T_em = K k */
        m->k = m->m * wn * wn;
        m->c = 2.0 * xi * wn * m->m;
        m->T_em = gain * m->k;
    }
    if (c->fs_follows_fc) m->p[TF_P_FS] = m->p[TF_P_FC];
    for (int i = 0; i < NLAW; i++) {
        law_store *s = &c->law[i];
        tf_law *law = i < TF_NPARAM ? &m->law[i] : &m->dF;
        if (s->kind == TF_LAW_NONE) continue;
        law->kind = s->kind;
        if (i < TF_NPARAM) law->load = s->load;
        if (s->kind == TF_LAW_CONST || s->kind == TF_LAW_LINEAR || s->kind == TF_LAW_EXP) {
            law->a = s->x[0];
            law->b = s->y[0];
        } else {
            law->n = s->n;
            law->x = s->x;
            law->y = s->y;
            if (s->kind == TF_LAW_TABLE) {
                for (int k = 1; k < s->n; k++)
                    if (!(s->x[k] > s->x[k - 1])) return (fmu_fail(c, "law breakpoints must increase strictly"), -1);
                tf_pchip_slopes(s->n, s->x, s->y, s->d);
                law->d = s->d;
            }
        }
    }
    if (c->heat) {
        m->heat.on = 1;
        m->heat.T_amb = c->r[VR_TEMPERATURE];
        m->heat.P_ext = c->p_ext;
    }
    m->input.kind = TF_WAVE_SAMPLED;
    m->input.n = 2;
    m->input.t = c->wave_t;
    m->input.v = c->wave_v;
    m->load_const = c->load_input ? c->r[VR_LOAD] : NAN;
    return 0;
}

/* The run's data for c->model as now built: its cache refilled at the next use, the GMS modes kept (they
 * are state, across a rebuild). */
static void data_for_model(instance *c)
{
    int modes[TF_MAX_FRICTION_STATES];
    memcpy(modes, c->data.gms.mode, sizeof modes);
    tf_model_data_init(&c->data, &c->model);
    memcpy(c->data.gms.mode, modes, sizeof modes);
}

/* c->model rebuilt from the values, and its data (build_model, data_for_model). */
static int rebuild(instance *c)
{
    if (build_model(c, &c->model) != 0) return -1;
    data_for_model(c);
    return 0;
}

/* The drive and temperature of model m over [t, t + h]: lines from their values at t along their
 * derivatives (h = 0: at t only). */
static void set_signals(instance *c, tf_model *m, double t, double h)
{
    double u = c->r[VR_DRIVE], du = c->du;
    if (c->plant == TF_PLANT_PRESCRIBED && !c->du_set) { /* no derivative: the motion ramps to u over the step */
        du = h > 0 ? (u - c->u_prev) / h : 0.0;
        u = c->u_prev;
    }
    double dT = c->dT, dL = c->dL;
    if (!(h > 0)) { /* at a communication point: the values at t; a prescribed motion's velocity that of the last step */
        h = 1.0, dT = dL = 0.0;
        du = c->plant == TF_PLANT_PRESCRIBED ? c->last_du : 0.0;
        u = c->plant == TF_PLANT_PRESCRIBED ? c->u_prev : c->r[VR_DRIVE];
        c->wave_t[0] = t - h, c->wave_t[1] = t + h; /* a segment through (t, u) with slope du */
        c->wave_v[0] = u - du * h, c->wave_v[1] = u + du * h;
        goto temperature;
    }
    c->wave_t[0] = t, c->wave_t[1] = t + h;
    c->wave_v[0] = u, c->wave_v[1] = u + du * h;
temperature:
    m->input.kind = TF_WAVE_SAMPLED;
    m->input.n = 2;
    m->input.t = c->wave_t;
    m->input.v = c->wave_v;
    if (c->heat) {
        m->heat.T_amb = c->r[VR_TEMPERATURE];
    } else if (c->temperature_input) {
        c->temp_t[0] = t, c->temp_t[1] = t + h;
        c->temp_v[0] = c->r[VR_TEMPERATURE], c->temp_v[1] = c->r[VR_TEMPERATURE] + dT * h;
        m->T_n = 2;
        m->T_t = c->temp_t;
        m->T_v = c->temp_v;
    } else {
        m->T_const = NAN;
    }
    if (c->load_input) { /* as the temperature input: a line from its value at t along its derivative */
        c->load_t[0] = t, c->load_t[1] = t + h;
        c->load_v[0] = c->r[VR_LOAD], c->load_v[1] = c->r[VR_LOAD] + dL * h;
        memset(&m->load, 0, sizeof m->load);
        m->load.kind = TF_WAVE_SAMPLED;
        m->load.n = 2;
        m->load.t = c->load_t;
        m->load.v = c->load_v;
    }
}

static int check_model(instance *c, const tf_model *m)
{
    tf_error e;
    if (tf_model_check(m, &e) == TF_OK) return 0;
    if (c->load_input)
        fmu_fail(c, "at time %g s, temperature %g C, load %g: the model is outside its domain ('%s')", c->t,
                 c->r[VR_TEMPERATURE], c->r[VR_LOAD], e.what);
    else if (c->temperature_input || c->heat)
        fmu_fail(c, "at time %g s, temperature %g C: the model is outside its domain ('%s')", c->t,
             c->r[VR_TEMPERATURE], e.what);
    else
        fmu_fail(c, "at time %g s: the model is outside its domain ('%s')", c->t, e.what);
    return -1;
}

/* FMU_WARNING (logged) when temperature T leaves the laws' calibrated range, once per excursion. */
static fmu_status check_range(instance *c, double T)
{
    if (isnan(c->range_lo)) return FMU_OK;
    int out = !(T >= c->range_lo - 1e-9 && T <= c->range_hi + 1e-9);
    fmu_status s = FMU_OK;
    if (out && !c->out_of_range) {
        warn(c, "at time %g s the temperature %g C is outside the laws' calibrated range [%g, %g] C: extrapolated",
              c->t, T, c->range_lo, c->range_hi);
        s = FMU_WARNING;
    }
    c->out_of_range = out;
    return s;
}

/* FMU_WARNING (logged) when the load's magnitude leaves the load terms' calibrated range, once per excursion
 * (the range's tolerance: models/load_laws.py, LOAD_RANGE_TOLERANCE of its span). */
static fmu_status check_load_range(instance *c, double L)
{
    if (!c->load_input || isnan(c->load_lo)) return FMU_OK;
    double tol = 0.02 * (c->load_hi - c->load_lo), a = fabs(L);
    int out = !(a >= c->load_lo - tol && a <= c->load_hi + tol);
    fmu_status s = FMU_OK;
    if (out && !c->load_out_of_range) {
        warn(c, "at time %g s the load %g is outside the load laws' calibrated range of |load| [%g, %g]: extrapolated",
             c->t, L, c->load_lo, c->load_hi);
        s = FMU_WARNING;
    }
    c->load_out_of_range = out;
    return s;
}

/* ---- the temperature estimator (estimator.h) ---- */

static tf_temperature_config est_config(const instance *c)
{
    const double *p = c->est_p;
    tf_temperature_config k = {p[EST_C_TH], p[EST_R_TH], p[EST_ETA], p[EST_C_2], p[EST_R_2], c->est_proxy,
                               p[EST_TAU_P], {p[EST_Q_CONTACT], p[EST_Q_HOUSING], p[EST_Q_PROXY]}, p[EST_R_F],
                               p[EST_R_P], p[EST_V_MIN]};
    return k;
}

/* The estimator from its parameters and start, on the model's friction at rest: at the initialization. */
static int est_start(instance *c)
{
    if (!c->estimator) return 0;
    tf_error e;
    tf_temperature_config k = est_config(c);
    if (tf_rt_from_model(&c->est_rt, &c->model, &e) != TF_OK)
        return (fmu_fail(c, "the estimator's friction model was refused ('%s')", e.what), -1);
    if (tf_temperature_init(&c->est, &k, c->est_p[EST_T_0], c->est_p[EST_VAR_0], &e) != TF_OK)
        return (fmu_fail(c, "fmi2ExitInitializationMode: the estimator refuses its parameters: '%s'", e.what), -1);
    return 0;
}

/* A tunable estimator parameter changed (in step mode): the configuration checked and taken, or refused. */
static int est_configure(instance *c)
{
    if (!c->estimator || c->mode != S_STEP) return 0;
    tf_error e;
    tf_temperature_config k = est_config(c);
    if (tf_temperature_configure(&c->est, &k, &e) != TF_OK)
        return (fmu_fail(c, "fmi2SetReal: the estimator refuses its parameters: '%s'", e.what), -1);
    return 0;
}

/* The estimator's friction object on c->model as now built (its laws in the instance's stores), its states kept. */
static void est_sync_model(instance *c)
{
    if (!c->estimator) return;
    int modes[TF_MAX_FRICTION_STATES];
    memcpy(modes, c->est_rt.data.gms.mode, sizeof modes);
    c->est_rt.model = c->model;
    tf_model_data_init(&c->est_rt.data, &c->est_rt.model);
    memcpy(c->est_rt.data.gms.mode, modes, sizeof modes);
}

/* One estimator step over the communication step h at the sliding velocity v and the load of its start, into the trial
 * copies (est_commit takes them once the plant's step succeeded): 0, or logs why not and returns -1. */
static int est_step(instance *c, double v, double h)
{
    if (!c->estimator) return 0;
    c->est_trial = c->est;
    c->est_rt_trial = c->est_rt;
    double T_amb = c->heat ? c->r[VR_TEMPERATURE] : c->r[VR_AMBIENT], F;
    double T_proxy = c->est_proxy != TF_PROXY_NONE ? c->r[VR_PROXY_TEMPERATURE] : NAN;
    tf_error e;
    double load = c->load_input ? c->r[VR_LOAD] : NAN; /* the friction's load input, at the step's start as v */
    tf_status s = tf_temperature_step(&c->est_trial, &c->est_rt_trial, v, load, c->r[VR_MEASURED_FORCE], T_proxy,
                                      T_amb, h, &F, &e);
    if (s != TF_OK)
        return (fmu_fail(c, "the temperature estimator's step at %g s (estimate %g C) was refused: %s ('%s')", c->t,
                         c->est.x[0], tf_status_message(s), e.what), -1);
    return 0;
}

static fmu_status est_commit(instance *c, fmu_status status)
{
    if (c->estimator && status <= FMU_WARNING) c->est = c->est_trial, c->est_rt = c->est_rt_trial;
    return status;
}

/* ---- outputs ---- */

static double output(instance *c, int vr)
{
    double out[TF_OUT_NFIXED + TF_MAX_FRICTION_STATES + 2];
    set_signals(c, &c->model, c->t, 0.0);
    tf_model_outputs(&c->data, c->t, c->y, out);
    switch (vr) {
    case VR_DISPLACEMENT: return out[TF_OUT_DISPLACEMENT];
    case VR_VELOCITY: return out[TF_OUT_VELOCITY];
    case VR_FRICTION_FORCE: return out[TF_OUT_FRICTION_FORCE];
    case VR_TEMPERATURE_OUT: return out[TF_OUT_TEMPERATURE];
    case VR_STAGE_DISPLACEMENT: return out[TF_OUT_STAGE_DISPLACEMENT];
    default: return NAN;
    }
}

/* ---- the FMI functions ---- */

fmu_status fmu_set_debug_logging(fmu_instance *c, int on)
{
    if (!c) return FMU_ERROR;
    c->logging = on;
    return FMU_OK;
}

fmu_instance *fmu_instantiate(const char *name, const char *guid, const char *resources, int resources_is_uri,
                              const fmu_callbacks *cb, int logging)
{
    if (!cb || !cb->allocateMemory || !cb->freeMemory) return NULL;
    instance *c = cb->allocateMemory(1, sizeof *c);
    if (!c) return NULL;
    memset(c, 0, sizeof *c);
    c->cb = *cb;
    c->logging = logging;
    size_t len = strlen(name ? name : "") + 1;
    c->name = cb->allocateMemory(len, 1);
    if (c->name) memcpy(c->name, name ? name : "", len);
    c->rtol = 1e-6;
    int bad_guid = 0;
    if (!resources || read_resources(c, resources, resources_is_uri) != 0 ||
        (bad_guid = !guid || strcmp(guid, c->guid) != 0) || rebuild(c) != 0) {
        if (!resources) fmu_fail(c, "no resource location given");
        if (bad_guid)
            fmu_fail(c, "fmi2Instantiate: GUID %s is not this FMU's %s (a model description of another FMU?)",
                 guid ? guid : "(NULL)", c->guid);
        if (c->name) cb->freeMemory(c->name);
        cb->freeMemory(c);
        return NULL;
    }
    c->mode = S_INSTANTIATED;
    return c;
}

void fmu_free_instance(fmu_instance *c)
{
    if (!c) return;
    void (*freeMemory)(void *) = c->cb.freeMemory;
    if (c->name) freeMemory(c->name);
    freeMemory(c);
}

fmu_status fmu_setup_experiment(fmu_instance *c, int tol_defined, double tol, double start,
                               int stop_defined, double stop)
{
    if (!c) return FMU_ERROR;
    if (c->mode != S_INSTANTIATED) return fmu_fail(c, "fmi2SetupExperiment: only after fmi2Instantiate");
    /* all checked before anything is taken: a refusal changes nothing */
    if (tol_defined && !(tol > 0 && tol < 1))
        return fmu_fail(c, "fmi2SetupExperiment: tolerance %g must be between 0 and 1", tol);
    if (!(fabs(start) <= TIME_LIMIT))
        return fmu_fail(c, "fmi2SetupExperiment: start time %g s: must be finite and within +-%g s (the integrator's "
                    "time limit)", start, TIME_LIMIT);
    if (stop_defined && !(stop >= start))
        return fmu_fail(c, "fmi2SetupExperiment: stop time %g s: must be a time not before the start time %g s", stop,
                        start);
    if (tol_defined) c->rtol = tol;
    c->t = start;
    c->stop_defined = stop_defined != 0;
    c->stop = stop_defined ? stop : 0.0;
    return FMU_OK;
}

fmu_status fmu_enter_initialization(fmu_instance *c)
{
    if (!c) return FMU_ERROR;
    if (c->mode != S_INSTANTIATED) return fmu_fail(c, "fmi2EnterInitializationMode: only after fmi2Instantiate");
    c->mode = S_INIT;
    return FMU_OK;
}

fmu_status fmu_exit_initialization(fmu_instance *c)
{
    if (!c) return FMU_ERROR;
    if (c->mode != S_INIT) return fmu_fail(c, "fmi2ExitInitializationMode: only in initialization mode");
    if (!isfinite(c->r[VR_DRIVE]) || !isfinite(c->r[VR_TEMPERATURE]))
        return fmu_fail(c, "the inputs at the start are not finite (drive %g, temperature %g)", c->r[VR_DRIVE],
                     c->r[VR_TEMPERATURE]);
    if ((c->temperature_input || c->heat) && !plausible_temperature(c->r[VR_TEMPERATURE]))
        return fmu_fail(c, "the temperature at the start %g C is not a plausible temperature (expected %g to %g C)",
                    c->r[VR_TEMPERATURE], T_MIN, T_MAX);
    if (c->load_input && !isfinite(c->r[VR_LOAD]))
        return fmu_fail(c, "the load input at the start is not finite (%g)", c->r[VR_LOAD]);
    if (rebuild(c) != 0) return FMU_ERROR;
    c->u_prev = c->r[VR_DRIVE];
    set_signals(c, &c->model, c->t, 0.0);
    if (check_model(c, &c->model) != 0) return FMU_ERROR;
    tf_model_initial_state(&c->model, c->y);
    tf_model_on_restart(c->t, c->y, &c->data); /* GMS modes consistent with the start */
    if (est_start(c) != 0) return FMU_ERROR;
    c->mode = S_STEP;
    fmu_status status = check_load_range(c, c->r[VR_LOAD]);
    if (c->temperature_input || c->heat) {
        fmu_status r = check_range(c, output(c, VR_TEMPERATURE_OUT));
        if (r > status) status = r;
    }
    return status;
}

fmu_status fmu_terminate(fmu_instance *c)
{
    fmu_status s = fmu_require_mode(c, "fmi2Terminate", FMU_IN_STEP); /* FMI 2 and 3: once initialized, once */
    if (s == FMU_OK) c->mode = S_TERMINATED;
    return s;
}

fmu_status fmu_reset(fmu_instance *c)
{
    if (!c) return FMU_ERROR;
    memcpy(c->r, c->r_start, sizeof c->r);
    c->du = c->dT = c->dL = 0;
    c->du_set = 0;
    c->t = 0;
    c->out_of_range = c->load_out_of_range = 0;
    c->stop_defined = 0, c->stop = 0.0; /* as instantiated: no experiment yet */
    memset(c->y, 0, sizeof c->y);
    memset(c->data.gms.mode, 0, sizeof c->data.gms.mode);
    c->mode = S_INSTANTIATED;
    return rebuild(c) == 0 ? FMU_OK : FMU_ERROR;
}

static int is_output(fmu_vr vr)
{
    return vr >= VR_DISPLACEMENT && vr <= VR_TEMPERATURE_VARIANCE;
}

/* The value references the model description declares (fmu.py's _variables): the drive, the
 * temperature input with a thermal extension or a heat model, the outputs of this plant, and the
 * parameters the resource file gives a role. Every other one is refused. */
static int declared(const instance *c, fmu_vr vr)
{
    switch (vr) {
    case VR_DRIVE: case VR_DISPLACEMENT: case VR_VELOCITY: case VR_FRICTION_FORCE: return 1;
    case VR_TEMPERATURE: return c->temperature_input || c->heat;
    case VR_TEMPERATURE_OUT: return c->heat;
    case VR_STAGE_DISPLACEMENT: return c->plant == TF_PLANT_STICK_SLIP;
    case VR_TEMPERATURE_ESTIMATE: case VR_TEMPERATURE_VARIANCE: case VR_MEASURED_FORCE: return c->estimator;
    case VR_PROXY_TEMPERATURE: return c->estimator && c->est_proxy != TF_PROXY_NONE;
    case VR_AMBIENT: return c->estimator && !c->heat;
    case VR_LOAD: return c->load_input;
    default: return vr >= VR_FIRST_PARAMETER && vr < MAX_VR && c->role[vr].role != ROLE_NONE;
    }
}

fmu_status fmu_get_real(fmu_instance *c, const fmu_vr vr[], size_t n, double value[])
{
    if (!c) return FMU_ERROR;
    if (n > 0 && (!vr || !value)) return fmu_fail(c, "fmi2GetReal: NULL argument");
    for (size_t k = 0; k < n; k++) {
        if (!declared(c, vr[k])) return fmu_fail(c, "fmi2GetReal: value reference %u is not a variable of this FMU", vr[k]);
        value[k] = vr[k] == VR_TEMPERATURE_ESTIMATE ? c->est.x[0]
                   : vr[k] == VR_TEMPERATURE_VARIANCE ? c->est.P[0][0]
                   : is_output(vr[k]) ? output(c, (int)vr[k]) : c->r[vr[k]];
    }
    return FMU_OK;
}

fmu_status fmu_set_real(fmu_instance *c, const fmu_vr vr[], size_t n, const double value[])
{
    if (!c) return FMU_ERROR;
    if (n > 0 && (!vr || !value)) return fmu_fail(c, "fmi2SetReal: NULL argument");
    if (c->mode == S_TERMINATED) return fmu_fail(c, "fmi2SetReal: the instance is terminated");
    int changed = 0;
    double before[MAX_VR];
    memcpy(before, c->r, sizeof before);
    for (size_t k = 0; k < n; k++) {
        fmu_vr v = vr[k];
        if (!declared(c, v) || is_output(v)) {
            memcpy(c->r, before, sizeof before);
            return fmu_fail(c, "fmi2SetReal: value reference %u cannot be set", v);
        }
        int measurement = v == VR_MEASURED_FORCE || v == VR_PROXY_TEMPERATURE; /* NaN: not measured */
        if (!isfinite(value[k]) && !(measurement && isnan(value[k]))) {
            memcpy(c->r, before, sizeof before);
            return fmu_fail(c, "fmi2SetReal: %s (value reference %u) is not finite (%g): refused",
                         v == VR_DRIVE ? "the drive input" : v == VR_TEMPERATURE ? "the temperature input"
                         : v == VR_LOAD ? "the load input"
                         : measurement ? "a measurement input (NaN: none)" : v == VR_AMBIENT ? "the ambient temperature"
                                       : "a parameter", v, value[k]);
        }
        int start_T = c->role[v].role == ROLE_T_0 || (c->role[v].role == ROLE_ESTIMATOR && c->role[v].i == EST_T_0);
        if ((v == VR_TEMPERATURE || v == VR_AMBIENT || v == VR_PROXY_TEMPERATURE || start_T) && !isnan(value[k]) &&
            !plausible_temperature(value[k])) {
            memcpy(c->r, before, sizeof before);
            return fmu_fail(c, "fmi2SetReal: %s %g C is not a plausible temperature (expected %g to %g C): refused",
                        v == VR_TEMPERATURE ? (c->heat ? "the ambient temperature" : "the temperature input")
                        : v == VR_AMBIENT ? "the ambient temperature" : v == VR_PROXY_TEMPERATURE ? "the proxy temperature"
                                          : "the start temperature", value[k], T_MIN, T_MAX);
        }
        if (v >= VR_FIRST_PARAMETER && c->role[v].role == ROLE_STEP && !(value[k] > 0)) {
            memcpy(c->r, before, sizeof before);
            return fmu_fail(c, "fmi2SetReal: integrator.step = %g s refused: the fixed step must be positive", value[k]);
        }
        if (v >= VR_FIRST_PARAMETER) {
            if (c->mode == S_STEP && c->role[v].fixed) {
                memcpy(c->r, before, sizeof before);
                return fmu_fail(c, "fmi2SetReal: parameter %u is fixed: set it before initialization", v);
            }
            changed = 1;
        }
        if (v == VR_DRIVE) c->du_set = 0, c->du = 0.0; /* a new value without a derivative is held */
        if (v == VR_TEMPERATURE) c->dT = 0.0;
        if (v == VR_LOAD) c->dL = 0.0;
        c->r[v] = value[k];
    }
    if (changed && c->mode == S_STEP) { /* a tunable parameter: the model must stay valid */
        tf_model m = c->model;
        int bad = build_model(c, &m) != 0;
        if (!bad) set_signals(c, &m, c->t, 0.0);
        if (bad || check_model(c, &m) != 0 || est_configure(c) != 0) {
            memcpy(c->r, before, sizeof before);
            rebuild(c); /* the laws' stores (and the estimator's parameters) back to the old values */
            return FMU_ERROR;
        }
        c->model = m;
        data_for_model(c);
        est_sync_model(c);
    }
    return FMU_OK;
}

fmu_status fmu_set_input_derivatives(fmu_instance *c, const fmu_vr vr[], size_t n,
                                       const int order[], const double value[])
{
    if (!c) return FMU_ERROR;
    if (n > 0 && (!vr || !order || !value)) return fmu_fail(c, "fmi2SetRealInputDerivatives: NULL argument");
    if (c->mode == S_TERMINATED)
        return fmu_fail(c, "fmi2SetRealInputDerivatives: the instance is terminated");
    double du = c->du, dT = c->dT, dL = c->dL; /* a refusal changes nothing */
    int du_set = c->du_set;
    for (size_t k = 0; k < n; k++) {
        if (order[k] != 1) return fmu_fail(c, "fmi2SetRealInputDerivatives: only first derivatives (order 1)");
        if (!isfinite(value[k])) return fmu_fail(c, "fmi2SetRealInputDerivatives: derivative is not finite (%g)", value[k]);
        if (vr[k] == VR_DRIVE) du = value[k], du_set = 1;
        else if (vr[k] == VR_TEMPERATURE && c->temperature_input) dT = value[k];
        else if (vr[k] == VR_LOAD && c->load_input) dL = value[k];
        else return fmu_fail(c, "fmi2SetRealInputDerivatives: value reference %u is no continuous input", vr[k]);
    }
    c->du = du, c->dT = dT, c->dL = dL, c->du_set = du_set;
    return FMU_OK;
}

static void no_emit(long i, double t, const double *y, void *ctx) {}
static fmu_status step_done(instance *c, double h, const double *y, int n, fmu_status status,
                             const tf_gms_elements *modes);

/* Relative sliding velocity at (t, y): the friction's input (plant.c's states: x_p, v_p, x_e, v_e
 * for the stick-slip actuator, x, v for a mass; prescribed motion: the input's slope). */
static double sliding_velocity(const tf_model *m, double t, const double *y)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return y[3] - y[1];
    case TF_PLANT_MASS: return y[1];
    default: return tf_waveform_slope(&m->input, t);
    }
}

/* The fixed-step real-time integrator over [c->t, c->t + h] into y: as many steps of c->fixed_step
 * as fit, the last one shortened to end on the communication point (docs/fmu.md). Each step:
 * the friction states by the core's real-time step (realtime.h: exponential Euler at the sliding
 * velocity held over the step), then the plant by semi-implicit Euler with that force (velocities,
 * then positions with the new velocities, as tf_loop_run does), the heat balance and frictional
 * work by explicit Euler; the drive and temperature held at their values at the step's start.
 * The plant's equations are the simulator's own (tf_model_rhs). 0, or logs why not and returns -1
 * (y and the run's GMS modes may then be changed: the caller restores them). */
static int realtime_steps(instance *c, double h, double *y)
{
    tf_model *m = &c->model;
    tf_rt_friction rt;
    tf_error e;
    if (tf_rt_from_model(&rt, m, &e) != TF_OK)
        return (fmu_fail(c, "the real-time friction model refused the model ('%s')", e.what), -1);
    int n = tf_model_nstate(m);
    int nz = tf_friction_nstate(m->friction, m->gms.n);
    int nm = m->plant == TF_PLANT_STICK_SLIP ? 4 : m->plant == TF_PLANT_MASS ? 2 : 0;
    memcpy(rt.z, y + nm, sizeof(double) * nz);
    memcpy(rt.data.gms.mode, c->data.gms.mode, sizeof c->data.gms.mode);
    double dt = c->fixed_step;
    /* whole steps, a communication step within 1e-9 of a whole number of steps counting as one */
    double ratio = h / dt;
    if (!(ratio <= MAX_FIXED_STEPS)) /* (long)floor(ratio) would overflow, or the step would not end */
        return (fmu_fail(c, "fmi2DoStep: a communication step of %g s is %.3g fixed steps of integrator.step = %g s; "
                     "at most %ld are taken in one communication step: refused", h, ratio, dt, MAX_FIXED_STEPS), -1);
    long whole = (long)floor(ratio * (1.0 + 1e-9));
    double last = h - whole * dt;
    if (last <= 1e-9 * dt) last = 0.0;
    long steps = whole + (last > 0.0);
    double dy[TF_MAX_STATES];
    for (long s = 0; s < steps; s++) {
        double ts = c->t + s * dt, hs = s < whole ? dt : last;
        if (s == whole - 1 && last == 0.0) hs = h - s * dt; /* end exactly on the communication point */
        double v = sliding_velocity(m, ts, y), T = tf_model_temperature(m, ts, y), F;
        tf_status st = tf_rt_step(&rt, v, T, tf_model_load(m, ts), hs, &F, &e);
        if (st != TF_OK)
            return (fmu_fail(c, "the fixed step at %g s (temperature %g C) was refused: %s ('%s')", ts, T,
                         tf_status_message(st), e.what), -1);
        memcpy(y + nm, rt.z, sizeof(double) * nz);
        memcpy(c->data.gms.mode, rt.data.gms.mode, sizeof c->data.gms.mode);
        tf_model_rhs(ts, y, dy, &c->data); /* at the new friction states: the force the real-time step gave */
        for (int i = 1; i < nm; i += 2) y[i] += dy[i] * hs;
        for (int i = 0; i < nm; i += 2) y[i] += y[i + 1] * hs;
        for (int i = nm + nz; i < n; i++) y[i] += dy[i] * hs;
        for (int i = 0; i < n; i++)
            if (!isfinite(y[i]))
                return (fmu_fail(c, "the fixed step of %g s diverged at %g s (the state is not finite): lower "
                             "integrator.step below the plant's and the friction's time constants", dt, ts), -1);
    }
    return 0;
}

fmu_status fmu_do_step(fmu_instance *c, double t, double h, int no_prior)
{
    if (fmu_require_mode(c, "fmi2DoStep", FMU_IN_STEP) != FMU_OK) return FMU_ERROR; /* initialized, not terminated */
    if (!(h > 0) || !isfinite(h) || !isfinite(t)) return fmu_fail(c, "fmi2DoStep: bad step (t = %g, h = %g)", t, h);
    if (fabs(t - c->t) > 1e-9 * fmax(1.0, fabs(t))) /* the importer's clock and ours must agree */
        return fmu_fail(c, "fmi2DoStep: communication point %.17g s is not the FMU's time %.17g s", t, c->t);
    /* FMI 2 and 3: computing past a defined stop time is an error; within 1e-9 of it relative to the times
     * (the rounding of an importer's grid, fmpy's isclose) it is the stop time */
    if (c->stop_defined && c->t + h > c->stop + 1e-9 * fmax(fabs(c->stop), fabs(c->t) + h))
        return fmu_fail(c, "fmi2DoStep: the step from %.17g s over %g s ends at %.17g s, past the experiment's stop "
                        "time %.17g s: refused", c->t, h, c->t + h, c->stop);
    if (!isfinite(c->r[VR_DRIVE]) || !isfinite(c->r[VR_TEMPERATURE]))
        return fmu_fail(c, "at time %g s the inputs are not finite (drive %g, temperature %g)", t, c->r[VR_DRIVE],
                     c->r[VR_TEMPERATURE]);
    if (c->load_input && !(isfinite(c->r[VR_LOAD]) && isfinite(c->r[VR_LOAD] + c->dL * h)))
        return fmu_fail(c, "at time %g s the load input is not finite over the step (%g, derivative %g)", t,
                        c->r[VR_LOAD], c->dL);
    if (!(fabs(t + h) <= TIME_LIMIT))
        return fmu_fail(c, "fmi2DoStep: the step ends at %g s, beyond +-%g s (the integrator's time limit)", t + h,
                    TIME_LIMIT);
    if (c->temperature_input || c->heat) {
        double T0 = c->r[VR_TEMPERATURE], T1 = T0 + (c->heat ? 0.0 : c->dT * h);
        if (!plausible_temperature(T0) || !plausible_temperature(T1))
            return fmu_fail(c, "fmi2DoStep: the %s reaches %g C over the step, not a plausible temperature (expected "
                        "%g to %g C)", c->heat ? "ambient temperature" : "temperature input",
                        plausible_temperature(T0) ? T1 : T0, T_MIN, T_MAX);
    }
    fmu_status status = FMU_OK;
    if (c->temperature_input && !c->heat) {
        status = check_range(c, c->r[VR_TEMPERATURE]);
        double T1 = c->r[VR_TEMPERATURE] + c->dT * h;
        if (status == FMU_OK && c->dT != 0.0) status = check_range(c, T1);
    }
    if (c->load_input) {
        fmu_status r = check_load_range(c, c->r[VR_LOAD]);
        if (r == FMU_OK && c->dL != 0.0) r = check_load_range(c, c->r[VR_LOAD] + c->dL * h);
        if (r > status) status = r;
    }
    set_signals(c, &c->model, c->t, h);
    if (check_model(c, &c->model) != 0) return FMU_ERROR;
    if (est_step(c, sliding_velocity(&c->model, c->t, c->y), h) != 0) return FMU_ERROR;

    int n = tf_model_nstate(&c->model);
    double y[TF_MAX_STATES], atol[TF_MAX_STATES];
    memcpy(y, c->y, sizeof(double) * n);
    tf_gms_elements modes = c->data.gms;
    if (c->fixed_step > 0) {
        if (realtime_steps(c, h, y) != 0) {
            c->data.gms = modes;
            tf_model_data_changed(&c->data);
            return FMU_ERROR;
        }
        return est_commit(c, step_done(c, h, y, n, status, &modes));
    }
    tf_model_state_scale(&c->model, atol);
    for (int i = 0; i < n; i++) atol[i] *= c->rtol;
    tf_ode ode = tf_model_ode(&c->data);
    double rtol_w[TF_MAX_STATES];
    tf_model_rtol_weights(&c->model, rtol_w);
    tf_solver_options opt = {.method = TF_METHOD_AUTO, .rtol = c->rtol, .atol = atol, .max_steps = MAX_ADAPTIVE_STEPS,
                             .rtol_weight = rtol_w};
    double t_out[2] = {c->t, c->t + h};
    tf_solver_stats st;
    tf_error e;
    tf_status s = tf_solve(&ode, &opt, t_out, 2, y, no_emit, 0, &st, &e);
    for (int i = 0; s == TF_OK && i < n; i++)
        if (!isfinite(y[i])) s = TF_ERR_NONFINITE, e.t = c->t + h, snprintf(e.what, sizeof e.what, "%s", "state");
    if (s != TF_OK) {
        c->data.gms = modes;
        return fmu_fail(c, "the integration from %g s over %g s failed at %g s: %s (%s)", c->t, h, e.t,
                    tf_status_message(s), e.what);
    }
    return est_commit(c, step_done(c, h, y, n, status, &modes));
}

/* After a successful step of h: the new state and time, the inputs advanced along their derivatives; refused,
 * with nothing moved, where an output would not be finite (a finite state can still give an infinite velocity
 * or force: the fuzzer found one that fmi2DoStep had answered OK). */
static fmu_status step_done(instance *c, double h, const double *y, int n, fmu_status status,
                             const tf_gms_elements *modes)
{
    double y_before[TF_MAX_STATES];
    memcpy(y_before, c->y, sizeof(double) * n);
    double t = c->t, u_prev = c->u_prev, last_du = c->last_du, drive = c->r[VR_DRIVE], T = c->r[VR_TEMPERATURE];
    double du = c->du, dT = c->dT, L = c->r[VR_LOAD], dL = c->dL;
    int du_set = c->du_set;
    memcpy(c->y, y, sizeof(double) * n);
    c->t += h;
    c->u_prev = c->wave_v[1];
    c->last_du = (c->wave_v[1] - c->wave_v[0]) / h;
    if (c->temperature_input && !c->heat) c->r[VR_TEMPERATURE] += c->dT * h;
    if (c->load_input) c->r[VR_LOAD] += c->dL * h;
    if (c->du_set || c->plant != TF_PLANT_PRESCRIBED) c->r[VR_DRIVE] = c->wave_v[1];
    c->du = c->dT = c->dL = 0.0; /* derivatives hold for one step */
    c->du_set = 0;
    for (int vr = VR_DISPLACEMENT; vr <= VR_STAGE_DISPLACEMENT; vr++) {
        double v = declared(c, (fmu_vr)vr) ? output(c, vr) : 0.0;
        if (isfinite(v)) continue;
        memcpy(c->y, y_before, sizeof(double) * n);
        c->t = t, c->u_prev = u_prev, c->last_du = last_du, c->r[VR_DRIVE] = drive, c->r[VR_TEMPERATURE] = T;
        c->du = du, c->dT = dT, c->du_set = du_set, c->r[VR_LOAD] = L, c->dL = dL;
        c->data.gms = *modes;
        return fmu_fail(c, "the step from %g s over %g s gives a non-finite output (value reference %d: %g)", t, h,
                        vr, v);
    }
    if (c->heat) {
        fmu_status r = check_range(c, output(c, VR_TEMPERATURE_OUT));
        if (r > status) status = r;
    }
    return status;
}

/* ---- FMU state: a copy of the instance (its laws' pointers are rebuilt on restore) ---- */

fmu_status fmu_get_state(fmu_instance *c, void **state)
{
    if (!c) return FMU_ERROR;
    if (!state) return fmu_fail(c, "fmi2GetFMUstate: NULL argument");
    instance *s = *state ? *state : c->cb.allocateMemory(1, sizeof *s);
    if (!s) return fmu_fail(c, "fmi2GetFMUstate: out of memory");
    memcpy(s, c, sizeof *s);
    *state = s;
    return FMU_OK;
}

/* The state machine's mode and the experiment's stop time are the importer's, not the FMU state's:
 * fmi2SetFMUstate is no transition of the standards' state machines, so the instance keeps its mode (a
 * state taken in step mode restored once terminated leaves it terminated). A state taken on the other
 * side of the initialization (its time and model states meaningless there) or of another FMU is refused. */
fmu_status fmu_set_state(fmu_instance *c, void *state)
{
    if (!c) return FMU_ERROR;
    if (!state) return fmu_fail(c, "fmi2SetFMUstate: NULL argument");
    const instance *from = state;
    if (strncmp(from->guid, c->guid, sizeof c->guid) != 0)
        return fmu_fail(c, "fmi2SetFMUstate: the state is of another FMU (GUID %.63s, this one %s): refused",
                        from->guid, c->guid);
    int initialized = (c->mode & (S_STEP | S_TERMINATED)) != 0, was = (from->mode & (S_STEP | S_TERMINATED)) != 0;
    if (initialized != was)
        return fmu_fail(c, "fmi2SetFMUstate: the state was taken %s initialization and the instance is %s: a state "
                        "is restored on the side of the initialization it was taken on: refused",
                        was ? "after" : "before", mode_name(c->mode));
    char *name = c->name;
    fmu_callbacks cb = c->cb;
    int logging = c->logging, mode = c->mode, stop_defined = c->stop_defined;
    double stop = c->stop;
    memcpy(c, state, sizeof *c);
    c->name = name, c->cb = cb, c->logging = logging;
    c->mode = mode, c->stop_defined = stop_defined, c->stop = stop;
    if (rebuild(c) != 0) return FMU_ERROR; /* the laws' pointers and the data's, the modes as saved */
    est_sync_model(c);
    return FMU_OK;
}

fmu_status fmu_free_state(fmu_instance *c, void **state)
{
    if (!c) return FMU_ERROR;
    if (!state) return fmu_fail(c, "fmi2FreeFMUstate: NULL argument");
    if (*state) c->cb.freeMemory(*state);
    *state = NULL;
    return FMU_OK;
}

/* The FMU's time: the last successful communication point. */
double fmu_time(const fmu_instance *c) { return c->t; }

/* The instance's tf_model (fmu_common.h). */
const void *fmu_model(const fmu_instance *c) { return c ? &c->model : NULL; }
