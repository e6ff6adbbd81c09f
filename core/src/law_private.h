/* Private header of law.c: its check (tf_model_check, plant.h). */
#ifndef THERMOFRICTION_LAW_PRIVATE_H
#define THERMOFRICTION_LAW_PRIVATE_H

#include "thermofriction/law.h"

/* A law's kind and breakpoints: 1 if valid. */
int tf_law_ok(const tf_law *L);
/* A load term's kind, combination and numbers, for a law of kind law_kind: 1 if valid. */
int tf_load_term_ok(const tf_load_term *t, int law_kind);

#endif
