/* Private to the core's sources: the checks of tf_model_check (plant.h), each in the file of what it
 * checks. Each returns NULL when the thing is valid, else a static string naming the field refused. */
#ifndef THERMOFRICTION_CHECKS_H
#define THERMOFRICTION_CHECKS_H

#include <math.h>

#include "thermofriction/friction.h"
#include "thermofriction/law.h"
#include "thermofriction/thermal.h"
#include "thermofriction/waveform.h"

static inline int tf_pos(double x) { return isfinite(x) && x > 0.0; }
static inline int tf_nonneg(double x) { return isfinite(x) && x >= 0.0; }

/* waveform.c: n >= 2 points with finite values and strictly increasing finite times (knots): 1 if so. */
int tf_knots_ok(int n, const double *x, const double *y);
/* waveform.c: an input (prescribed: a motion, whose slopes must be finite). */
const char *tf_waveform_problem(const tf_waveform *w, int prescribed);
/* law.c: a law's kind and breakpoints: 1 if valid. */
int tf_law_ok(const tf_law *L);
/* friction.c: the friction model's kind and GMS elements. */
const char *tf_friction_structure_problem(int kind, const tf_gms_elements *gms);
/* friction.c: the parameters the friction model uses, at one temperature (offset_form: Model II's
 * offset form, which needs v_smooth). */
const char *tf_friction_params_problem(int kind, const double *p, int offset_form);
/* thermal.c: the thermal extension's kind, laws and Model II form. */
const char *tf_thermal_structure_problem(int thermal, const tf_law *laws, const tf_law *dF, int dF_form);
/* thermal.c: Model II's factor (scale form) or offset (offset form) at one temperature. */
const char *tf_thermal_lambda_problem(int thermal, int dF_form, double lambda, double dF_offset);
/* thermal.c: the heat balance's parameters. */
const char *tf_heat_problem(const tf_heat *h);

#endif
