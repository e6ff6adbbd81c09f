/* Private to the checks (friction.c, thermal.c, waveform.c, model_check.c): the two tests of a number
 * that most domains are (the friction parameters' rules: domains.h), 1 where the value passes. */
#ifndef THERMOFRICTION_DOMAIN_TESTS_H
#define THERMOFRICTION_DOMAIN_TESTS_H

#include <math.h>

static inline int tf_pos(double x) { return isfinite(x) && x > 0.0; }
static inline int tf_nonneg(double x) { return isfinite(x) && x >= 0.0; }

#endif
