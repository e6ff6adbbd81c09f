/* Thermal extensions of a friction model (docs/models.md#thermal-extensions). */
#ifndef THERMOFRICTION_THERMAL_H
#define THERMOFRICTION_THERMAL_H

#include "law.h"

#ifdef __cplusplus
extern "C" {
#endif

/* How Model II applies its thermal-induced friction dF(T) (docs/models.md#model-ii). */
typedef enum {
    TF_THERMAL_NONE = 0,
    TF_THERMAL_MODEL_I = 1,  /* parameters follow laws of T */
    TF_THERMAL_MODEL_II = 2  /* base model plus dF(T) */
} tf_thermal_kind;

typedef enum {
    TF_DF_SCALE = 0,  /* F' = (1 + dF(T) / F_ref) F_base */
    TF_DF_OFFSET = 1  /* F' = F_base + dF(T) s(v) */
} tf_df_form;

#ifdef __cplusplus
}
#endif
#endif
