/* Forward sensitivity equations of a model (see sensitivity.h). */
#include "thermofriction/sensitivity.h"

#include <math.h>
#include <string.h>

#include "inline.h" /* TF_SIZED */

/* fp += J S (J n x n, S n x np, both row-major). Inlined with np a constant for the usual few
 * parameters, so that the row of np products compiles to straight-line code. */
TF_SIZED void add_jacobian_times(const double *J, const double *S, double *fp, int n, const int np)
{
    for (int r = 0; r < n; r++) {
        const double *Jr = J + r * n;
        double *fr = fp + r * np;
        for (int c = 0; c < n; c++) {
            double a = Jr[c];
            if (a == 0.0) continue; /* J is sparse: most products vanish */
            const double *Sc = S + c * np;
            for (int k = 0; k < np; k++) fr[k] += a * Sc[k];
        }
    }
}

tf_status tf_sensitivity_rhs(double t, const double *Y, double *dY, void *ctx)
{
    tf_sensitivity_system *s = (tf_sensitivity_system *)ctx;
    if (!s->n) s->n = tf_model_nstate(s->data->model);
    int n = s->n, np = s->np;
    double J[TF_MAX_STATES * TF_MAX_STATES];
    double *fp = dY + n; /* df/dtheta lands where dS goes, then J S is added */
    tf_model_derivatives(s->data, t, Y, dY, J, s->targets, np, fp);
    const double *S = Y + n;
    switch (np) {
    case 1: add_jacobian_times(J, S, fp, n, 1); break;
    case 2: add_jacobian_times(J, S, fp, n, 2); break;
    case 3: add_jacobian_times(J, S, fp, n, 3); break;
    case 4: add_jacobian_times(J, S, fp, n, 4); break;
    case 5: add_jacobian_times(J, S, fp, n, 5); break;
    case 6: add_jacobian_times(J, S, fp, n, 6); break;
    default: add_jacobian_times(J, S, fp, n, np); break;
    }
    return TF_OK;
}

double tf_sensitivity_next_corner(double t, void *ctx)
{
    return tf_model_next_corner(t, ((tf_sensitivity_system *)ctx)->data);
}

/* Discrete modes (GMS): the model's events on the state part, and at each restart its modes set
 * and the sensitivities' jump applied where a mode switched (tf_model_sensitivity_restart). */
static void sensitivity_events(double t, const double *Y, double *g, void *ctx)
{
    tf_model_events(t, Y, g, ((tf_sensitivity_system *)ctx)->data);
}

static void sensitivity_restart(double t, double *Y, void *ctx)
{
    tf_sensitivity_system *s = (tf_sensitivity_system *)ctx;
    tf_model_sensitivity_restart(s->data, t, Y, s->targets, s->np);
}

tf_ode tf_sensitivity_ode(tf_sensitivity_system *s)
{
    tf_ode ode = {.n = tf_model_nstate(s->data->model) * (1 + s->np), .ctx = s, .rhs = tf_sensitivity_rhs,
                  .next_corner = tf_sensitivity_next_corner, .nevent = tf_model_nevent(s->data->model)};
    if (ode.nevent) ode.events = sensitivity_events, ode.on_restart = sensitivity_restart;
    return ode;
}

tf_status tf_sensitivity_check(const tf_sensitivity_system *s, tf_error *err)
{
    if (!s || !s->data || !s->data->model || (s->np > 0 && !s->targets) || s->np < 0 || s->np > TF_MAX_TARGETS)
        return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "sensitivity", "system (NULL, or 0 to 32 targets)", NAN, -1);
    const tf_model *m = s->data->model;
    for (int k = 0; k < s->np; k++) {
        const tf_target *tg = &s->targets[k];
        const tf_law *law = tg->kind == TF_TARGET_DF                                                   ? &m->dF
                            : tg->kind == TF_TARGET_LAW && tg->param >= 0 && tg->param < TF_NPARAM ? &m->law[tg->param]
                                                                                                   : NULL;
        int bad = tg->kind < 0 || tg->kind > TF_TARGET_PLANT || tg->param < 0 ||
                  tg->param >= (tg->kind == TF_TARGET_HEAT    ? TF_HEAT_NPARAM
                                : tg->kind == TF_TARGET_PLANT ? TF_PLANT_NPARAM
                                                              : TF_NPARAM);
        if (!bad && law && (tg->coef < 0 || tg->coef >= tf_law_ncoef(law))) bad = 1;
        if (bad) return tf_error_set(err, TF_ERR_BAD_ARGUMENT, "sensitivity", "target", NAN, k);
    }
    return tf_error_set(err, TF_OK, 0, 0, NAN, -1);
}

void tf_sensitivity_initial_state(const tf_sensitivity_system *s, double *Y)
{
    const tf_model *m = s->data->model;
    int n = tf_model_nstate(m), np = s->np;
    memset(Y, 0, sizeof(double) * (size_t)n * (size_t)(1 + np));
    tf_model_initial_state(m, Y); /* and S(0) = 0: the initial state does not depend on theta, */
    for (int k = 0; k < np; k++)  /* except on the initial temperature */
        if (s->targets[k].kind == TF_TARGET_HEAT && s->targets[k].param == TF_HEAT_T_0 && m->heat.on)
            Y[n + tf_model_temperature_index(m) * np + k] = 1.0;
}
