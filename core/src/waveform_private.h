/* Private header of waveform.c: its checks (tf_model_check, plant.h). Each returns NULL when the thing
 * is valid, else a static string naming the field refused. */
#ifndef THERMOFRICTION_WAVEFORM_PRIVATE_H
#define THERMOFRICTION_WAVEFORM_PRIVATE_H

#include "thermofriction/waveform.h"

/* n >= 2 points with finite values and strictly increasing finite times (knots): 1 if so. */
int tf_knots_ok(int n, const double *x, const double *y);
/* An input (prescribed: a motion, whose slopes must be finite). */
const char *tf_waveform_problem(const tf_waveform *w, int prescribed);

#endif
