/* Thermal extensions: Model I, Model II and the lumped heat balance (see thermal.h). */
#include "thermofriction/thermal.h"
#include "domain_tests.h"
#include "law_private.h"
#include "thermal_private.h"
#include "waveform_private.h" /* the heat input P_ext */

#include <math.h>
#include <string.h>

void tf_thermal_params(int thermal, const double *p_base, const tf_law *laws, int fs_follows_fc, double T,
                       double L, double *p)
{
    memcpy(p, p_base, sizeof(double) * TF_NPARAM);
    if (fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
    if (thermal != TF_THERMAL_MODEL_I) return;
    for (int i = 0; i < TF_NPARAM; i++)
        if (laws[i].kind != TF_LAW_NONE) p[i] = tf_law_eval_load(&laws[i], T, L, 0, 0);
    if (fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
}

unsigned long tf_thermal_law_mask(const tf_law *laws)
{
    unsigned long mask = 0;
    for (int i = 0; i < TF_NPARAM; i++)
        if (laws[i].kind != TF_LAW_NONE) mask |= 1UL << i;
    return mask;
}

unsigned long tf_thermal_load_mask(int thermal, const tf_law *laws)
{
    unsigned long mask = 0;
    if (thermal != TF_THERMAL_MODEL_I) return 0;
    for (int i = 0; i < TF_NPARAM; i++)
        if (laws[i].kind != TF_LAW_NONE && laws[i].load.kind != TF_LOAD_NONE) mask |= 1UL << i;
    return mask;
}

void tf_thermal_params_masked(int thermal, const double *p_base, const tf_law *laws, unsigned long mask,
                              int fs_follows_fc, double T, double L, double *p)
{
    memcpy(p, p_base, sizeof(double) * TF_NPARAM);
    if (thermal == TF_THERMAL_MODEL_I)
        for (int i = 0; mask; i++, mask >>= 1)
            if (mask & 1UL) p[i] = tf_law_eval_load(&laws[i], T, L, 0, 0);
    if (fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
}

double tf_thermal_df_coef_partial(int form, const tf_law *dF, int coef, double T, double F_base, double F_ref,
                                  double v, double v_smooth)
{
    double dlaw = tf_law_coef_derivative(dF, coef, T, 0.0);
    return form == TF_DF_SCALE ? F_base / F_ref * dlaw : dlaw * tanh(v / v_smooth);
}

double tf_heat_rate(const tf_heat *h, double t, double T, double P)
{
    double P_ext = h->P_ext.kind == TF_WAVE_ZERO ? 0.0 : tf_waveform_value(&h->P_ext, t);
    return (h->eta * P - (T - h->T_amb) / h->R_th + P_ext) / h->C_th;
}

void tf_heat_rate_jacobian(const tf_heat *h, int n, int iT, const double *dP_dy, double *row)
{
    for (int k = 0; k < n; k++) row[k] = tf_heat_rate_dP(h, dP_dy[k]);
    row[iT] -= 1.0 / (h->R_th * h->C_th);
}

double tf_heat_param_partial(const tf_heat *h, int param, double T, double P, double rate)
{
    switch (param) {
    case TF_HEAT_C_TH: return -rate / h->C_th;
    case TF_HEAT_R_TH: return (T - h->T_amb) / (h->R_th * h->R_th * h->C_th);
    case TF_HEAT_ETA: return P / h->C_th;
    case TF_HEAT_T_AMB: return 1.0 / (h->R_th * h->C_th);
    default: return 0.0; /* T_0: through the initial state only */
    }
}

/* ---- checks (tf_model_check, plant.h) ---- */

/* The thermal extension's kind, Model I's laws, Model II's law and form. */
const char *tf_thermal_structure_problem(int thermal, const tf_law *laws, const tf_law *dF, int dF_form)
{
    if (thermal < TF_THERMAL_NONE || thermal > TF_THERMAL_MODEL_II) return "thermal";
    if (thermal == TF_THERMAL_MODEL_I)
        for (int i = 0; i < TF_NPARAM; i++)
            if (!tf_law_ok(&laws[i])) return "law";
    if (thermal == TF_THERMAL_MODEL_II) {
        if (dF->kind == TF_LAW_NONE || !tf_law_ok(dF)) return "dF";
        if (dF->load.kind != TF_LOAD_NONE) return "dF (a load term: Model I laws only)";
        if (dF_form != TF_DF_SCALE && dF_form != TF_DF_OFFSET) return "dF form";
    }
    return 0;
}

const char *tf_thermal_lambda_problem(int thermal, int dF_form, double lambda, double dF_offset)
{
    if (thermal != TF_THERMAL_MODEL_II) return 0;
    int offset = dF_form == TF_DF_OFFSET;
    if (offset ? !isfinite(dF_offset) : !isfinite(lambda)) return "dF";
    if (!offset && !(lambda > 0.0)) return "dF (lambda <= 0 or not finite)";
    return 0;
}

const char *tf_heat_problem(const tf_heat *h)
{
    if (!tf_pos(h->C_th)) return "heat.C_th";
    if (!tf_pos(h->R_th)) return "heat.R_th";
    if (!(tf_nonneg(h->eta) && h->eta <= 1.0)) return "heat.eta (0 to 1)";
    if (!isfinite(h->T_amb)) return "heat.T_amb";
    if (!isfinite(h->T_0)) return "heat.T_0";
    if (tf_waveform_problem(&h->P_ext, 0)) return "heat.P_ext";
    return 0;
}
