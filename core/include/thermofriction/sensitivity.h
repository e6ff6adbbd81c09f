/* Forward sensitivities: the state y and S = dy/dtheta integrated together,
 *   y' = f(t, y),   S' = (df/dy) S + df/dtheta,
 * so that an identification gets the exact Jacobian of its residuals (to solver tolerance)
 * from one integration instead of one per parameter. */
#ifndef THERMOFRICTION_SENSITIVITY_H
#define THERMOFRICTION_SENSITIVITY_H

#include "integrator.h"
#include "plant.h"

#ifdef __cplusplus
extern "C" {
#endif

#define TF_MAX_TARGETS 32

typedef struct {
    tf_model_data *data; /* the model's run (plant.h): tf_model_data_init before */
    int np;
    const tf_target *targets;
    int n; /* the model's states: set on the first evaluation (0 before) */
} tf_sensitivity_system;

/* Refuses (TF_ERR_BAD_ARGUMENT, err->index the target) a target that the model has not: a kind, parameter
 * or coefficient out of range (where "sensitivity"). */
tf_status tf_sensitivity_check(const tf_sensitivity_system *system, tf_error *err);
/* The augmented initial state: the model's (tf_model_initial_state) and S(0) = 0, except the initial
 * temperature's column (a heat model's T_0 target), which is 1 in the temperature's row. */
void tf_sensitivity_initial_state(const tf_sensitivity_system *system, double *Y);
/* Augmented right-hand side: Y = [y (n), S (n x np, row-major)]. */
tf_status tf_sensitivity_rhs(double t, const double *Y, double *dY, void *system);
double tf_sensitivity_next_corner(double t, void *system);
/* An ODE over the augmented state, for tf_solve with the explicit method (no Jacobian). */
tf_ode tf_sensitivity_ode(tf_sensitivity_system *system);

#ifdef __cplusplus
}
#endif
#endif
