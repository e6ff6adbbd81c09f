/* Forward sensitivity equations of a model (see sensitivity.h). */
#include "thermofriction/sensitivity.h"

#include <string.h>

int tf_sensitivity_rhs(double t, const double *Y, double *dY, void *ctx)
{
    tf_sensitivity_system *s = (tf_sensitivity_system *)ctx;
    if (!s->n) s->n = tf_model_nstate(s->model);
    int n = s->n, np = s->np;
    double J[TF_MAX_STATES * TF_MAX_STATES];
    double *fp = dY + n; /* df/dtheta lands where dS goes, then J S is added */
    tf_model_derivatives(s->model, t, Y, dY, J, s->targets, np, fp);
    const double *S = Y + n;
    for (int r = 0; r < n; r++) {
        const double *Jr = J + r * n;
        for (int c = 0; c < n; c++) {
            double a = Jr[c];
            if (a == 0.0) continue; /* J is sparse: most products vanish */
            for (int k = 0; k < np; k++) fp[r * np + k] += a * S[c * np + k];
        }
    }
    return 0;
}

double tf_sensitivity_next_corner(double t, void *ctx)
{
    return tf_model_next_corner(t, ((tf_sensitivity_system *)ctx)->model);
}

/* Discrete modes (GMS): the model's events on the state part, and at each restart its modes set
 * and the sensitivities' jump applied where a mode switched (tf_model_sensitivity_restart). */
static void sensitivity_events(double t, const double *Y, double *g, void *ctx)
{
    tf_model_events(t, Y, g, ((tf_sensitivity_system *)ctx)->model);
}

static void sensitivity_restart(double t, double *Y, void *ctx)
{
    tf_sensitivity_system *s = (tf_sensitivity_system *)ctx;
    tf_model_sensitivity_restart(s->model, t, Y, s->targets, s->np);
}

tf_ode tf_sensitivity_ode(tf_sensitivity_system *s)
{
    tf_ode ode = {.n = tf_model_nstate(s->model) * (1 + s->np), .ctx = s, .rhs = tf_sensitivity_rhs,
                  .next_corner = tf_sensitivity_next_corner, .nevent = tf_model_nevent(s->model)};
    if (ode.nevent) ode.events = sensitivity_events, ode.on_restart = sensitivity_restart;
    return ode;
}
