/* The plant's derivatives (plant.h): the state Jacobian (tf_model_jac), the right-hand side's partials
 * with respect to the targets of a sensitivity (tf_model_derivatives) and the sensitivities' jump where a
 * GMS element switches (tf_model_sensitivity_restart). The equations they differentiate are plant.c's. */
#include "plant_private.h"

static void velocity_partials(const tf_model *m, double *dv_dy)
{
    memset(dv_dy, 0, sizeof(double) * TF_MAX_STATES);
    if (m->plant == TF_PLANT_STICK_SLIP) dv_dy[VE] = 1.0, dv_dy[VP] = -1.0;
    else if (m->plant == TF_PLANT_MASS) dv_dy[V] = 1.0;
}

/* The rows of the temperature and work states, and the temperature column of every row, of the
 * Jacobian. dF'/dT and dz'/dT come from a central difference in T: the laws are smooth and
 * most base models have no analytic parameter partials (h = 1e-3 K: truncation ~1e-8 relative
 * for the paper's laws, far below what Rodas4's Newton-free stages need). */
static void heat_jacobian(tf_model_data *md, double t, const double *y, const tf_friction_partials *d, double *J)
{
    const tf_model *m = md->model;
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    int iT = tf_model_temperature_index(m), iW = tf_model_work_index(m);
    double T = tf_model_temperature(m, t, y), L = model_load(md, t);
    double dz[TF_MAX_FRICTION_STATES], dzp[TF_MAX_FRICTION_STATES], dzm[TF_MAX_FRICTION_STATES];
    double F = tf_plant_friction_at(md, T, L, t, y, dz, 0, 0, 0), v = relative_velocity(m, t, y);
    double s = (F * v > 0.0) - (F * v < 0.0);
    double dv_dy[TF_MAX_STATES], dP[TF_MAX_STATES]; /* dP/dy, P = |F v| */
    velocity_partials(m, dv_dy);
    for (int k = 0; k < n; k++) dP[k] = s * (v * d->dF_dv + F) * dv_dy[k];
    for (int j = 0; j < nz; j++) dP[nm + j] += s * v * d->dF_dz[j];
    double dF_dT = 0.0, ddz_dT[TF_MAX_FRICTION_STATES] = {0};
    if (m->heat.on && m->thermal != TF_THERMAL_NONE) {
        const double h = 1e-3;
        double Fp = tf_plant_friction_at(md, T + h, L, t, y, dzp, 0, 0, 0);
        double Fm = tf_plant_friction_at(md, T - h, L, t, y, dzm, 0, 0, 0);
        dF_dT = (Fp - Fm) / (2 * h);
        for (int j = 0; j < nz; j++) ddz_dT[j] = (dzp[j] - dzm[j]) / (2 * h);
    }
#define J_(i, j) J[(i) * n + (j)]
    if (m->heat.on) {
        dP[iT] = s * v * dF_dT;
        if (m->plant == TF_PLANT_STICK_SLIP) {
            J_(VP, iT) = dF_dT / m->m;
            J_(VE, iT) = -dF_dT / m->m_e;
        } else if (m->plant == TF_PLANT_MASS) {
            J_(V, iT) = -dF_dT / m->m;
        }
        for (int j = 0; j < nz; j++) J_(nm + j, iT) = ddz_dT[j];
        tf_heat_rate_jacobian(&m->heat, n, iT, dP, &J_(iT, 0));
    }
    for (int k = 0; k < n; k++) J_(iW, k) = dP[k];
#undef J_
}

/* The state Jacobian from the friction force's partials d (after the thermal model). */
static void jacobian_from(tf_model_data *md, double t, const double *y, const tf_friction_partials *d, double *J)
{
    const tf_model *m = md->model;
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    memset(J, 0, sizeof(double) * n * n);
#define J_(i, j) J[(i) * n + (j)]
    if (m->plant == TF_PLANT_STICK_SLIP) {
        J_(XP, VP) = 1.0;
        J_(VP, XP) = -m->k / m->m;
        J_(VP, VP) = (-m->c - d->dF_dv) / m->m;
        J_(VP, VE) = d->dF_dv / m->m;
        J_(XE, VE) = 1.0;
        J_(VE, VP) = d->dF_dv / m->m_e;
        J_(VE, VE) = -d->dF_dv / m->m_e;
        if (d->dF_dx != 0.0) { /* the ripple, in x_e - x_p */
            J_(VP, XE) += d->dF_dx / m->m, J_(VP, XP) -= d->dF_dx / m->m;
            J_(VE, XE) -= d->dF_dx / m->m_e, J_(VE, XP) += d->dF_dx / m->m_e;
        }
        for (int j = 0; j < nz; j++) {
            J_(VP, nm + j) = d->dF_dz[j] / m->m;
            J_(VE, nm + j) = -d->dF_dz[j] / m->m_e;
            J_(nm + j, VP) = -d->ddz_dv[j];
            J_(nm + j, VE) = d->ddz_dv[j];
        }
    } else if (m->plant == TF_PLANT_MASS) {
        J_(X, V) = 1.0;
        J_(V, X) = -m->k_s / m->m;
        J_(V, V) = -d->dF_dv / m->m;
        J_(V, X) -= d->dF_dx / m->m;
        for (int j = 0; j < nz; j++) {
            J_(V, nm + j) = -d->dF_dz[j] / m->m;
            J_(nm + j, V) = d->ddz_dv[j];
        }
    }
    for (int j = 0; j < nz; j++) J_(nm + j, nm + j) = d->ddz_dz[j];
#undef J_
    if (has_work(m)) heat_jacobian(md, t, y, d, J);
}

tf_status tf_model_jac(double t, const double *y, double *J, void *ctx)
{
    tf_model_data *md = (tf_model_data *)ctx;
    double dz[TF_MAX_FRICTION_STATES];
    tf_friction_partials d;
    tf_plant_friction(md, t, y, dz, &d);
    jacobian_from(md, t, y, &d, J);
    return TF_OK;
}

/* d(rhs)/d(plant parameter) into column k of fp (stride np): only the mechanical rows depend on
 * these directly (the friction force and its power are functions of the state). */
static void plant_partials(const tf_model *m, double t, const double *y, const double *dy, int param,
                           double *fp, int np, int k)
{
    if (m->plant == TF_PLANT_STICK_SLIP) {
        double u = tf_waveform_value(&m->input, t);
        double d_m = -dy[VP] / m->m, d_c = -y[VP] / m->m, d_k = -y[XP] / m->m, d_T = u / m->m;
        double wn = sqrt(m->k / m->m), xi = m->c / (2.0 * wn * m->m), K = m->T_em / m->k;
        double vp = 0.0;
        switch (param) {
        case TF_PLANT_P_M: vp = d_m; break;
        case TF_PLANT_P_M_E: fp[VE * np + k] = -dy[VE] / m->m_e; return;
        case TF_PLANT_P_C: vp = d_c; break;
        case TF_PLANT_P_K: vp = d_k; break;
        case TF_PLANT_P_T_EM: vp = d_T; break;
        case TF_PLANT_P_XI: vp = d_c * 2.0 * wn * m->m; break;
        case TF_PLANT_P_WN: vp = (d_c * xi + d_k * wn + d_T * K * wn) * 2.0 * m->m; break;
        case TF_PLANT_P_GAIN: vp = d_T * m->k; break;
        case TF_PLANT_P_M_MODAL: vp = d_m + d_c * 2.0 * xi * wn + (d_k + d_T * K) * wn * wn; break;
        default: break;
        }
        fp[VP * np + k] = vp;
    } else if (m->plant == TF_PLANT_MASS) {
        if (param == TF_PLANT_P_M || param == TF_PLANT_P_M_MODAL) fp[V * np + k] = -dy[V] / m->m;
        else if (param == TF_PLANT_P_K_S) fp[V * np + k] = (m->v_0 * t - y[X]) / m->m;
    }
}

tf_status tf_model_derivatives(tf_model_data *md, double t, const double *y, double *dy, double *J,
                               const tf_target *targets, int np, double *fp)
{
    const tf_model *m = md->model;
    int n = tf_model_nstate(m), nm = nmech(m), nz = nfric(m);
    int iT = tf_model_temperature_index(m), iW = tf_model_work_index(m);
    int fast = tf_plant_fast(m);
    if (!np) {
        if (fast) tf_plant_rhs_fast(t, y, dy, md);
        else tf_model_rhs(t, y, dy, md);
        if (J) tf_model_jac(t, y, J, md);
        return TF_OK;
    }
    if (!fast) tf_model_rhs(t, y, dy, md); /* else from the one friction evaluation below */
    tf_friction_param_partials dp;
    tf_friction_partials d; /* the state and the parameter partials from one evaluation */
    double dz[TF_MAX_FRICTION_STATES], Fb, lambda, dF_offset;
    double T = tf_model_temperature(m, t, y);
    tf_model_params_cached(md, T, model_load(md, t), &lambda, &dF_offset);
    double L = md->cache.L; /* NaN where the model reads no load */
    double F = tf_plant_friction_at(md, T, L, t, y, dz, J ? &d : 0, &dp, &Fb);
    if (fast) { /* the same equations as tf_plant_rhs_fast, with the partials' evaluation */
        dy[nm] = dz[0];
        mechanical_rhs(m, t, y, F, dy);
    }
    if (J) jacobian_from(md, t, y, &d, J);
    if (m->fs_follows_fc) { /* one parameter moves both */
        dp.dF_dp[TF_P_FC] += dp.dF_dp[TF_P_FS];
        for (int j = 0; j < nz; j++) dp.ddz_dp[j][TF_P_FC] += dp.ddz_dp[j][TF_P_FS];
    }
    double Fref = reference_force(m);
    double v = relative_velocity(m, t, y);
    double s = (F * v > 0.0) - (F * v < 0.0); /* d|F v|/dF = s v */
    memset(fp, 0, sizeof(double) * (size_t)(n * np));
    for (int k = 0; k < np; k++) {
        const tf_target *tg = &targets[k];
        double dF = 0.0, chain = 1.0; /* dF'/dtheta and d(param)/dtheta */
        int i = tg->param;
        if (tg->kind == TF_TARGET_PLANT) {
            plant_partials(m, t, y, dy, i, fp, np, k);
            continue;
        }
        if (tg->kind == TF_TARGET_HEAT) { /* only the heat balance depends on these */
            if (m->heat.on) fp[iT * np + k] = tf_heat_param_partial(&m->heat, i, y[iT], fabs(F * v), dy[iT]);
            continue;
        }
        if (tg->kind == TF_TARGET_DF) {
            dF = tf_thermal_df_coef_partial(m->dF_form, &m->dF, tg->coef, T, Fb, Fref, v, md->cache.p[TF_P_VSMOOTH]);
        } else {
            if (tg->kind == TF_TARGET_LAW) chain = tf_law_coef_derivative(&m->law[i], tg->coef, T, L);
            dF = tf_thermal_param_partial(m->thermal, m->dF_form, lambda, Fref, i, chain * dp.dF_dp[i], Fb);
        }
        if (m->plant == TF_PLANT_STICK_SLIP) {
            fp[VP * np + k] = dF / m->m;
            fp[VE * np + k] = -dF / m->m_e;
        } else if (m->plant == TF_PLANT_MASS) {
            fp[V * np + k] = -dF / m->m;
        }
        if (tg->kind != TF_TARGET_DF)
            for (int j = 0; j < nz; j++) fp[(nm + j) * np + k] = chain * dp.ddz_dp[j][i];
        double dP = s * v * dF; /* of the friction power |F' v| */
        if (iT >= 0) fp[iT * np + k] = tf_heat_rate_dP(&m->heat, dP);
        if (iW >= 0) fp[iW * np + k] = dP;
    }
    return TF_OK;
}

/* dv/dy . w: the relative velocity is linear in the state (zero under prescribed motion). */
static double velocity_along(const tf_model *m, const double *w)
{
    switch (m->plant) {
    case TF_PLANT_STICK_SLIP: return w[VE] - w[VP];
    case TF_PLANT_MASS: return w[V];
    default: return 0.0;
    }
}

void tf_model_sensitivity_restart(tf_model_data *md, double t, double *Y, const tf_target *targets, int np)
{
    const tf_model *m = md->model;
    if (m->friction != TF_FRICTION_GMS) return;
    int n = tf_model_nstate(m), nm = nmech(m), ne = m->gms.n;
    int old[TF_MAX_FRICTION_STATES];
    double fm[TF_MAX_STATES], fpl[TF_MAX_STATES];
    memcpy(old, md->gms.mode, sizeof(int) * (size_t)ne);
    tf_model_rhs(t, Y, fm, md);
    tf_model_on_restart(t, Y, md);
    int changed = 0;
    for (int i = 0; i < ne; i++) changed |= old[i] != md->gms.mode[i];
    if (!changed || !np) return;
    tf_model_rhs(t, Y, fpl, md);
    double lambda, dF;
    const double *p = tf_model_params_cached(md, tf_model_temperature(m, t, Y), model_load(md, t), &lambda, &dF);
    double L = md->cache.L, v = relative_velocity(m, t, Y), dg_dv, dg_p[TF_NPARAM];
    tf_stribeck(p, v, &dg_dv);
    tf_stribeck_param_partials(p, v, dg_p);
    if (m->fs_follows_fc) dg_p[TF_P_FC] += dg_p[TF_P_FS];
    /* the negative capacity -w_i g_-(v) (direction-dependent levels: friction.h, tf_friction_side) */
    double q[TF_NPARAM], dgn_dv, dgn_p[TF_NPARAM];
    const double *pn = tf_friction_side(p, -1.0, q);
    tf_stribeck(pn, v, &dgn_dv);
    tf_stribeck_param_partials(pn, v, dgn_p);
    tf_friction_side_partials(p, -1.0, dgn_p);
    if (m->fs_follows_fc) dgn_p[TF_P_FC] += dgn_p[TF_P_FS];
    /* dv/dt along the trajectory before the switch; under prescribed motion v(t) is the input's
       slope, whose change is left out (it moves an event only through the Stribeck curve's slope) */
    double vdot = velocity_along(m, fm);
    double *S = Y + n;
    for (int i = 0; i < ne; i++) {
        int a = old[i], b = md->gms.mode[i], row = nm + i;
        if (a == b) continue;
        double jump = fm[row] - fpl[row], w = md->gms.w[i];
        const double *dgs_p = a == 0 && b < 0 ? dgn_p : dg_p; /* the capacity of the side it broke loose to */
        double dgs_dv = a == 0 && b < 0 ? dgn_dv : dg_dv;
        /* the event function that fired: a stuck element reaching its capacity, b z_i - w_i g(v);
           a slipping one whose motion reversed, -a v */
        double rate = a == 0 ? b * fm[row] - w * dgs_dv * vdot : -a * vdot;
        if (!(fabs(rate) > 0.0) || jump == 0.0) continue;
        for (int k = 0; k < np; k++) {
            const tf_target *tg = &targets[k];
            double col[TF_MAX_STATES], num; /* column k of S (row-major n x np) */
            for (int r = 0; r < n; r++) col[r] = S[r * np + k];
            double dv = velocity_along(m, col);
            if (a == 0) {
                double dcap = 0.0; /* d(capacity g)/dtheta, directly */
                if (tg->kind == TF_TARGET_PARAM) dcap = dgs_p[tg->param];
                else if (tg->kind == TF_TARGET_LAW) dcap = tf_law_coef_derivative(&m->law[tg->param], tg->coef,
                                                                                  tf_model_temperature(m, t, Y), L) *
                                                           dgs_p[tg->param];
                num = b * col[row] - w * (dcap + dgs_dv * dv);
            } else {
                num = -a * dv;
            }
            S[row * np + k] -= jump * num / rate;
        }
    }
}

