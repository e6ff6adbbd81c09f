/* The domain of every friction model's parameters, one table (an X-macro, as MuJoCo's mjxmacro.h):
 * the C checks (tf_model_check, tf_model_check_friction, tf_rt_*: friction.c) walk it, and the Python
 * binding exports it (thermofriction._core.FRICTION_DOMAINS), so that both sides read one rule per
 * parameter. A model's rows are checked in their order, and the first refused names the parameter.
 *
 * X(model, parameter, rule, other, when): the friction model (TF_FRICTION_<model>, TF_FRICTION_MODELS below), the parameter
 * (TF_P_<parameter>), its rule (TF_DOMAIN_<rule>), the parameter the rule compares with (TF_P_<other>,
 * NONE: none), and where the rule applies (TF_DOMAIN_<when>). Every value is a parameter at one temperature
 * (laws evaluated), on each side of a direction-dependent model. */
#ifndef THERMOFRICTION_DOMAINS_H
#define THERMOFRICTION_DOMAINS_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TF_DOMAIN_POSITIVE = 0,        /* finite and > 0 */
    TF_DOMAIN_NON_NEGATIVE,        /* finite and >= 0 */
    TF_DOMAIN_AT_LEAST,            /* finite and >= the parameter `other` (fs >= fc) */
    TF_DOMAIN_BELOW_DEFLECTION,    /* finite, >= 0 and below `other` / sigma0 (z_ba < fc / sigma0) */
    TF_DOMAIN_POSITIVE_OR_ABSENT,  /* finite and > 0, or absent: 0 in C, None in Python (vd: sigma1 constant) */
    TF_DOMAIN_NRULE
} tf_domain_rule;

typedef enum {
    TF_DOMAIN_ALWAYS = 0,
    TF_DOMAIN_STRIBECK,            /* where fs != fc (a Stribeck effect) */
    TF_DOMAIN_OFFSET_FORM,         /* where Model II's offset form smooths the sign of v (v_smooth) */
    TF_DOMAIN_NWHEN
} tf_domain_when;

/* The parameter a rule compares with, where there is none. */
#define TF_P_NONE (-1)

/* The friction models, one line each: X(symbol, name in model files, states, equations). Their ids
 * (friction.h, tf_friction_kind: TF_FRICTION_<symbol>, in this order from 0), their number of states
 * (0: a static map; TF_STATES_PER_ELEMENT: one per element) and the Python binding's friction constants come from
 * this list; a new model is a line here, its rows below and its step in friction.c. */
#define TF_STATES_PER_ELEMENT (-1)
#define TF_FRICTION_MODELS(X)                                                                           \
    X(LUGRE, "lugre", 1, "z' = v - sigma0 |v| z / g(v); F = sigma0 z + sigma1(v) z' + sigma2 v")        \
    X(COULOMB, "coulomb", 0, "F = fc s(v) + sigma2 v; s = tanh(v / v_smooth)")                          \
    X(STRIBECK, "stribeck", 0, "F = g(v) s(v) + sigma2 v")                                              \
    X(DAHL, "dahl", 1, "z' = v - sigma0 |v| z / fc; F = sigma0 z")                                      \
    X(ELASTOPLASTIC, "elastoplastic", 1, "LuGre with alpha(z, v) on the relaxation term (Dupont et al. 2002)") \
    X(GMS, "gms", TF_STATES_PER_ELEMENT, "N Maxwell-slip elements, each stuck or slipping (Al-Bender et al. 2005)")

#define TF_FRICTION_DOMAINS(X)                                                                          \
    X(LUGRE, FC, POSITIVE, NONE, ALWAYS)                                                                \
    X(LUGRE, SIGMA2, NON_NEGATIVE, NONE, ALWAYS)                                                        \
    X(LUGRE, SIGMA0, POSITIVE, NONE, ALWAYS)                                                            \
    X(LUGRE, SIGMA1, NON_NEGATIVE, NONE, ALWAYS)                                                        \
    X(LUGRE, VD, POSITIVE_OR_ABSENT, NONE, ALWAYS)                                                      \
    X(LUGRE, FS, AT_LEAST, FC, ALWAYS)                                                                  \
    X(LUGRE, VS, POSITIVE, NONE, STRIBECK)                                                              \
    X(LUGRE, DELTA, POSITIVE, NONE, STRIBECK)                                                           \
    X(LUGRE, VSMOOTH, POSITIVE, NONE, OFFSET_FORM)                                                      \
    X(COULOMB, FC, POSITIVE, NONE, ALWAYS)                                                              \
    X(COULOMB, SIGMA2, NON_NEGATIVE, NONE, ALWAYS)                                                      \
    X(COULOMB, VSMOOTH, POSITIVE, NONE, ALWAYS)                                                         \
    X(STRIBECK, FC, POSITIVE, NONE, ALWAYS)                                                             \
    X(STRIBECK, SIGMA2, NON_NEGATIVE, NONE, ALWAYS)                                                     \
    X(STRIBECK, FS, AT_LEAST, FC, ALWAYS)                                                               \
    X(STRIBECK, VS, POSITIVE, NONE, STRIBECK)                                                           \
    X(STRIBECK, DELTA, POSITIVE, NONE, STRIBECK)                                                        \
    X(STRIBECK, VSMOOTH, POSITIVE, NONE, ALWAYS)                                                        \
    X(DAHL, FC, POSITIVE, NONE, ALWAYS)                                                                 \
    X(DAHL, SIGMA0, POSITIVE, NONE, ALWAYS)                                                             \
    X(DAHL, VSMOOTH, POSITIVE, NONE, OFFSET_FORM)                                                       \
    X(ELASTOPLASTIC, FC, POSITIVE, NONE, ALWAYS)                                                        \
    X(ELASTOPLASTIC, SIGMA2, NON_NEGATIVE, NONE, ALWAYS)                                                \
    X(ELASTOPLASTIC, SIGMA0, POSITIVE, NONE, ALWAYS)                                                    \
    X(ELASTOPLASTIC, SIGMA1, NON_NEGATIVE, NONE, ALWAYS)                                                \
    X(ELASTOPLASTIC, VD, POSITIVE_OR_ABSENT, NONE, ALWAYS)                                              \
    X(ELASTOPLASTIC, FS, AT_LEAST, FC, ALWAYS)                                                          \
    X(ELASTOPLASTIC, VS, POSITIVE, NONE, STRIBECK)                                                      \
    X(ELASTOPLASTIC, DELTA, POSITIVE, NONE, STRIBECK)                                                   \
    X(ELASTOPLASTIC, VSMOOTH, POSITIVE, NONE, OFFSET_FORM)                                              \
    X(ELASTOPLASTIC, ZBA, BELOW_DEFLECTION, FC, ALWAYS)                                                 \
    X(GMS, FC, POSITIVE, NONE, ALWAYS)                                                                  \
    X(GMS, SIGMA2, NON_NEGATIVE, NONE, ALWAYS)                                                          \
    X(GMS, FS, AT_LEAST, FC, ALWAYS)                                                                    \
    X(GMS, VS, POSITIVE, NONE, STRIBECK)                                                                \
    X(GMS, DELTA, POSITIVE, NONE, STRIBECK)                                                             \
    X(GMS, VSMOOTH, POSITIVE, NONE, OFFSET_FORM)                                                        \
    X(GMS, C, POSITIVE, NONE, ALWAYS)

#ifdef __cplusplus
}
#endif
#endif
