/* Thermal extensions: Model I, Model II and the lumped heat balance (see thermal.h). */
#include "thermofriction/thermal.h"

#include <math.h>
#include <string.h>

void tf_thermal_params(int thermal, const double *p_base, const tf_law *laws, int fs_follows_fc, double T,
                       double *p)
{
    memcpy(p, p_base, sizeof(double) * TF_NPARAM);
    if (fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
    if (thermal != TF_THERMAL_MODEL_I) return;
    for (int i = 0; i < TF_NPARAM; i++)
        if (laws[i].kind != TF_LAW_NONE) p[i] = tf_law_eval(&laws[i], T, 0);
    if (fs_follows_fc) p[TF_P_FS] = p[TF_P_FC];
}

double tf_thermal_df_coef_partial(int form, const tf_law *dF, int coef, double T, double F_base, double F_ref,
                                  double v, double v_smooth)
{
    double dlaw = tf_law_coef_derivative(dF, coef, T);
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
