/* Private header of thermal.c: its checks (tf_model_check, plant.h). Each returns NULL when the
 * thing is valid, else a static string naming the field refused. */
#ifndef THERMOFRICTION_THERMAL_PRIVATE_H
#define THERMOFRICTION_THERMAL_PRIVATE_H

#include "thermofriction/thermal.h"

/* The thermal extension's kind, laws and Model II form. */
const char *tf_thermal_structure_problem(int thermal, const tf_law *laws, const tf_law *dF, int dF_form);
/* Model II's factor (scale form) or offset (offset form) at one temperature. */
const char *tf_thermal_lambda_problem(int thermal, int dF_form, double lambda, double dF_offset);
/* The heat balance's parameters. */
const char *tf_heat_problem(const tf_heat *h);

#endif
