/* Private header of friction.c: its checks (tf_model_check, plant.h). Each returns NULL when the
 * thing is valid, else a static string naming the field refused. */
#ifndef THERMOFRICTION_FRICTION_PRIVATE_H
#define THERMOFRICTION_FRICTION_PRIVATE_H

#include "thermofriction/friction.h"

/* The friction model's kind and GMS elements. */
const char *tf_friction_structure_problem(int kind, const tf_gms_elements *gms);
/* The parameters the friction model uses, at one temperature (offset_form: Model II's offset form,
 * which needs v_smooth), by the rules of friction_domains.h. */
const char *tf_friction_params_problem(int kind, const double *p, int offset_form);

#endif
