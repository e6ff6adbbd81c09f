/* The model check (plant.h: tf_model_check, tf_model_check_friction, tf_model_check_params): the C side
 * of the Python package's parameter checks. The plant's own fields are checked here; the input's,
 * the friction model's and the thermal extension's in their files (their private headers). */
#include "thermofriction/plant.h"
#include "domain_tests.h"
#include "friction_private.h"
#include "thermal_private.h"
#include "waveform_private.h"

#include <math.h>

/* NULL, or the field refused: the rules of tf_model_check_params. */
static const char *params_problem(const tf_model *m, const double *p, double lambda, double dF_offset)
{
    int offset = m->thermal == TF_THERMAL_MODEL_II && m->dF_form == TF_DF_OFFSET;
    const char *bad = tf_friction_params_problem(m->friction, p, offset);
    return bad ? bad : tf_thermal_lambda_problem(m->thermal, m->dF_form, lambda, dF_offset);
}

/* The outcome of a check: TF_OK, or TF_ERR_BAD_ARGUMENT naming the field (where "model"). */
static tf_status checked(const char *bad, tf_error *err)
{
    return tf_error_set(err, bad ? TF_ERR_BAD_ARGUMENT : TF_OK, bad ? "model" : 0, bad, NAN, -1);
}

tf_status tf_model_check_params(const tf_model *m, const double *p, double lambda, double dF_offset, tf_error *err)
{
    if (!m || !p) return checked("model or p (NULL)", err);
    return checked(params_problem(m, p, lambda, dF_offset), err);
}

static const char *check_TL(const tf_model *m, double T, double L)
{
    double p[TF_NPARAM];
    tf_model_params_at(m, T, L, p);
    return params_problem(m, p, tf_model_lambda(m, T), tf_thermal_offset(m->thermal, m->dF_form, &m->dF, T));
}

/* The load's magnitudes a run reaches, lo..hi (a law is linear in s, monotone in |L|: its checks hold
 * between if at both ends): the constant; the samples of a sampled load; a periodic or step load on a
 * fine grid of its first period. "load" if any is not finite. */
static const char *load_range(const tf_model *m, double *lo, double *hi)
{
    const tf_waveform *w = &m->load;
    *lo = INFINITY, *hi = -INFINITY;
    if (w->kind == TF_WAVE_ZERO) {
        *lo = *hi = fabs(m->load_const);
    } else if (w->kind == TF_WAVE_SAMPLED) {
        for (int i = 0; i < w->n; i++) *lo = fmin(*lo, fabs(w->v[i])), *hi = fmax(*hi, fabs(w->v[i]));
    } else {
        double span = w->kind == TF_WAVE_STEP ? w->t0 + w->slew + 1.0 : 1.0 / w->frequency;
        for (int j = 0; j <= 256; j++) {
            double a = fabs(tf_waveform_value(w, span * j / 256.0));
            *lo = fmin(*lo, a), *hi = fmax(*hi, a);
        }
        if (w->kind == TF_WAVE_SINE || w->kind == TF_WAVE_SAWTOOTH || w->kind == TF_WAVE_SQUARE) {
            double e[2] = {w->offset + w->amplitude, w->offset - w->amplitude}; /* the extremes between samples */
            for (int j = 0; j < 2; j++) *hi = fmax(*hi, fabs(e[j]));
        }
    }
    return isfinite(*lo) && isfinite(*hi) ? 0 : "load (not finite, or none given to a law of the load)";
}

/* The parameters at temperature T, over the load's range for a model that reads it. */
static const char *check_at(const tf_model *m, double T)
{
    if (!tf_model_reads_load(m)) return check_TL(m, T, NAN);
    double lo, hi;
    const char *bad = load_range(m, &lo, &hi);
    if (!bad) bad = check_TL(m, T, lo);
    return bad ? bad : check_TL(m, T, hi);
}

/* The friction model and its thermal extension, apart from the parameters' values. */
static const char *check_friction_structure(const tf_model *m)
{
    const char *bad = tf_friction_structure_problem(m->friction, &m->gms);
    return bad ? bad : tf_thermal_structure_problem(m->thermal, m->law, &m->dF, m->dF_form);
}

tf_status tf_model_check_friction(const tf_model *m, double T, double L, tf_error *err)
{
    if (!m) return checked("model (NULL)", err);
    const char *bad = check_friction_structure(m);
    int reads = !bad && tf_model_reads_load(m);
    if (!bad && (m->thermal == TF_THERMAL_NONE || isfinite(T)) && (!reads || isfinite(L)))
        bad = check_TL(m, m->thermal ? T : NAN, reads ? L : NAN);
    return checked(bad, err);
}

tf_status tf_model_check(const tf_model *m, tf_error *err)
{
    if (!m) return checked("model (NULL)", err);
    const char *bad = 0;
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP:
        if (!tf_pos(m->m)) bad = "m";
        else if (!tf_nonneg(m->c)) bad = "c";
        else if (!tf_pos(m->k)) bad = "k";
        else if (!isfinite(m->T_em)) bad = "T_em";
        else if (!tf_pos(m->m_e)) bad = "m_e";
        break;
    case TF_PLANT_MASS:
        if (!tf_pos(m->m)) bad = "m";
        else if (!tf_nonneg(m->k_s)) bad = "k_s";
        else if (!isfinite(m->v_0)) bad = "v_0";
        break;
    case TF_PLANT_PRESCRIBED:
        if (m->input.kind == TF_WAVE_ZERO) bad = "input (prescribed motion needs one)";
        break;
    default:
        bad = "plant";
    }
    if (!bad) bad = check_friction_structure(m);
    if (!bad) bad = tf_waveform_problem(&m->input, m->plant == TF_PLANT_PRESCRIBED);
    if (!bad && m->load.kind != TF_WAVE_ZERO && tf_waveform_problem(&m->load, 0)) bad = "load (its waveform)";
    if (!bad && m->heat.on) bad = tf_heat_problem(&m->heat);
    if (!bad && m->T_n > 0 && !tf_knots_ok(m->T_n, m->T_t, m->T_v))
        bad = "temperature (sampled: two or more finite points, times increasing)";
    if (!bad && m->thermal != TF_THERMAL_NONE) {
        if (m->heat.on) { /* the temperature is a state: where it starts and where it tends */
            bad = check_at(m, m->heat.T_0);
            if (!bad) bad = check_at(m, m->heat.T_amb);
        } else if (m->T_n > 0) {
            /* the temperature sweeps [min, max] of its samples: the knots and a fine grid */
            double lo = INFINITY, hi = -INFINITY;
            for (int i = 0; !bad && i < m->T_n; i++) {
                lo = fmin(lo, m->T_v[i]);
                hi = fmax(hi, m->T_v[i]);
                bad = check_at(m, m->T_v[i]);
            }
            for (int j = 0; !bad && j <= 64; j++) bad = check_at(m, lo + (hi - lo) * j / 64.0);
        } else if (!isfinite(m->T_const)) {
            bad = "temperature";
        } else {
            bad = check_at(m, m->T_const);
        }
    } else if (!bad) {
        bad = check_at(m, NAN);
    }
    return checked(bad, err);
}
