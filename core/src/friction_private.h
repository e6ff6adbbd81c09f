/* Private header of friction.c: its checks (tf_model_check, plant.h), each returning NULL when the thing is
 * valid, else a static string naming the field refused; and the one-state models at one velocity for the exact
 * stepping of a prescribed motion (prescribed.c). */
#ifndef THERMOFRICTION_FRICTION_PRIVATE_H
#define THERMOFRICTION_FRICTION_PRIVATE_H

#include "thermofriction/friction.h"

/* The friction model's kind and GMS elements. */
const char *tf_friction_structure_problem(int kind, const tf_gms_elements *gms);
/* The parameters the friction model uses, at one temperature (offset_form: Model II's offset form,
 * which needs v_smooth), by the rules of friction_domains.h. */
const char *tf_friction_params_problem(int kind, const double *p, int offset_form);

/* Whether model kind has one state and, at a fixed velocity, its rate, force and their parameter partials affine
 * in it (LuGre, Dahl): z' = a + b z, F = F(0) + dF_dz z, dz'/dp = da + db z, dF/dp = dF0 + dF1 z. */
int tf_friction_affine_in_z(int kind);

/* Such a model at one velocity (tf_friction_affine_set): its coefficients, every parameter's partials
 * (TF_NPARAM, on the parameters they came from: the negative side's where v < 0, as tf_friction_eval's), and
 * what its force at a state needs (tf_friction_affine_force). */
typedef struct {
    int kind, negative; /* negative: v < 0 on a direction-dependent model, q the side's values */
    double v, a, b, dF_dz;
    double g, s1; /* LuGre: g(v) and sigma1(v) */
    double q[TF_NPARAM];
    double da[TF_NPARAM], db[TF_NPARAM], dF0[TF_NPARAM], dF1[TF_NPARAM];
} tf_friction_affine;

/* The coefficients of model kind (tf_friction_affine_in_z) with parameters p at velocity v, from its own
 * evaluations at z = 0 and z = 1 sharing the velocity's work (g, sigma1 and their partials once). delta: whether
 * the Stribeck exponent's partials are wanted (a logarithm, the one cost of its own; else they are left zero). */
void tf_friction_affine_set(int kind, const double *p, double v, int delta, tf_friction_affine *a);
/* The force at state z, the same number as tf_friction_eval's at a's velocity (p: the parameters a was set with). */
double tf_friction_affine_force(const tf_friction_affine *a, const double *p, double z);

#endif
