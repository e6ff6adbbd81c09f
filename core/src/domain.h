/* Private to the checks (friction.c, thermal.c, waveform.c, model_check.c): the domain rules of a
 * number, each returning 1 where the value is in the domain. */
#ifndef THERMOFRICTION_DOMAIN_H
#define THERMOFRICTION_DOMAIN_H

#include <math.h>

static inline int tf_pos(double x) { return isfinite(x) && x > 0.0; }
static inline int tf_nonneg(double x) { return isfinite(x) && x >= 0.0; }

#endif
