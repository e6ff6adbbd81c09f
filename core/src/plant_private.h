/* Private header of plant.c, shared with plant_derivatives.c (the Jacobian and the partials): the
 * state layout, the relative motion, the friction force at a temperature, the plant's mechanical rows. */
#ifndef THERMOFRICTION_PLANT_PRIVATE_H
#define THERMOFRICTION_PLANT_PRIVATE_H

#include "thermofriction/plant.h"
#include "inline.h" /* TF_SIZED */

#include <math.h>
#include <string.h>

/* State indices: stick-slip x_p, v_p, x_e, v_e; mass x, v (X, V); prescribed none. */
enum { XP = 0, VP, XE, VE };
enum { X = 0, V };

static inline int nmech(const tf_model *m)
{
    return m->plant == TF_PLANT_STICK_SLIP ? 4 : m->plant == TF_PLANT_MASS ? 2 : 0;
}

static inline int nfric(const tf_model *m) { return tf_friction_nstate(m->friction, m->gms.n); }

static inline int has_work(const tf_model *m) { return m->heat.on || m->work; }

/* Relative sliding velocity v_r of the driven body on its driving surface. */
static inline double relative_velocity(const tf_model *m, double t, const double *y)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return y[VE] - y[VP];
    case TF_PLANT_MASS: return y[V];
    default: return tf_waveform_slope(&m->input, t);
    }
}

/* Model II's F_ref: from the base parameters, the same at every temperature. */
static inline double reference_force(const tf_model *m) { return tf_friction_reference_force(m->friction, m->p); }

/* LuGre on the stick-slip actuator or the mass at one constant temperature (plant.c: the common case, with
 * its own right-hand side tf_plant_rhs_fast). */
int tf_plant_fast(const tf_model *m);
tf_status tf_plant_rhs_fast(double t, const double *y, double *dy, void *ctx);

/* F' at temperature T and load L and, when jac is given, its partials (overwriting the base model's
 * partials). The base model's parameter partials go to dp, untouched by Model II (the caller
 * applies it: tf_thermal_param_partial); the base model's force (with the ripple) to *F_base. */
double tf_plant_friction_at(tf_model_data *d, double T, double L, double t, const double *y, double *dz,
                            tf_friction_partials *jac, tf_friction_param_partials *dp, double *F_base);

/* The load at t for the parameters (tf_model_load), NaN without reading the waveform where the cache
 * already knows that the model's laws read none. */
static inline double model_load(const tf_model_data *d, double t)
{
    return d->cache.valid && !d->cache.loads ? NAN : tf_model_load(d->model, t);
}

/* F' at (t, y), at the model's temperature and load there. */
static inline double tf_plant_friction(tf_model_data *d, double t, const double *y, double *dz,
                                       tf_friction_partials *jac)
{
    return tf_plant_friction_at(d, tf_model_temperature(d->model, t, y), model_load(d, t), t, y, dz, jac, 0, 0);
}

/* The plant's mechanical rows under the friction force F (a prescribed motion has none): the one
 * statement of the plant equations, for every right-hand side. */
TF_SIZED void mechanical_rhs(const tf_model *m, double t, const double *y, double F, double *dy)
{
    if (m->plant == TF_PLANT_STICK_SLIP) {
        double u = tf_waveform_value(&m->input, t);
        dy[XP] = y[VP];
        dy[VP] = (-m->c * y[VP] - m->k * y[XP] + m->T_em * u + F) / m->m;
        dy[XE] = y[VE];
        dy[VE] = -F / m->m_e;
    } else if (m->plant == TF_PLANT_MASS) {
        double f = tf_waveform_value(&m->input, t) + m->k_s * (m->v_0 * t - y[X]);
        dy[X] = y[V];
        dy[V] = (f - F) / m->m;
    }
}

#endif
