/* Temperature laws (docs/models.md#model-i, docs/formats.md#model-files): a parameter, or Model II's
 * dF, as a function of T [degC]; a Model I parameter's law may add a load term, making it a law of
 * (T, L) with L the load (a normal force [N] or a load torque [N m]; docs/models.md#laws-of-temperature-and-load).
 * The thermal models that use them are in thermal.h. */
#ifndef THERMOFRICTION_LAW_H
#define THERMOFRICTION_LAW_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TF_LAW_NONE = 0,   /* no law: the parameter keeps its constant value */
    TF_LAW_CONST = 1,  /* a */
    TF_LAW_LINEAR = 2, /* a T + b */
    TF_LAW_EXP = 3,    /* a exp(b T) */
    TF_LAW_POLY = 4,   /* sum y[i] T^i, i < n */
    TF_LAW_PWL = 5,    /* linear through (x[i], y[i]); linear extrapolation with the end segments */
    TF_LAW_TABLE = 6   /* monotone cubic (PCHIP) through (x[i], y[i]) with slopes d[i];
                          linear extrapolation with the end slopes */
} tf_law_kind;

/* A law's load term (models/load_laws.py holds the same equations for Python). With s = |L|, or
 * s = S tanh(|L| / S) with a saturation S > 0, and f(T) the temperature law:
 *   proportional (a product):  p = f(T) s             + c T s
 *   affine, product:           p = f(T) (1 + k s)     + c T s
 *   affine, sum:               p = f(T) + k s         + c T s
 * c T s only where `interaction` is set. */
typedef enum {
    TF_LOAD_NONE = 0,          /* a law of temperature only */
    TF_LOAD_PROPORTIONAL = 1,  /* f(T) s */
    TF_LOAD_AFFINE = 2         /* f(T) (1 + k s), or f(T) + k s */
} tf_load_kind;

typedef enum {
    TF_COMBINE_PRODUCT = 0,
    TF_COMBINE_SUM = 1         /* affine only */
} tf_load_combine;

typedef struct {
    int kind;          /* tf_load_kind */
    int combine;       /* tf_load_combine */
    double k;          /* the affine gain [1/N] in a product, [parameter unit / N] in a sum */
    double saturation; /* S > 0; 0: none (s = |L|) */
    int interaction;   /* 1: the term c T s is there (and c a coefficient) */
    double c;          /* the interaction coefficient */
} tf_load_term;

typedef struct {
    int kind;
    double a, b;
    int n;
    const double *x;
    const double *y;
    const double *d; /* TABLE only: node slopes from tf_pchip_slopes */
    tf_load_term load; /* Model I only; zero (TF_LOAD_NONE): none. Not with a TABLE law */
} tf_law;

/* Value of the temperature law f(T) (the load term, if any, not applied); its derivative with
 * respect to T in *dvalue_dT when not NULL. */
double tf_law_eval(const tf_law *law, double T, double *dvalue_dT);
/* Value of the law at temperature T and load L (the load term applied: tf_law_eval for a law without
 * one, whatever L); its partials in T and L in *dT, *dL when not NULL (d|L|/dL taken as sign(L), 0 at 0). */
double tf_law_eval_load(const tf_law *law, double T, double L, double *dT, double *dL);

/* Derivative of the law's value at (T, L) with respect to its coefficient number `coef`: the temperature
 * law's coefficients first -- const: value; linear, exp: a (0), b (1); poly: c[coef]; pwl: values[coef] --
 * each times the load term's multiplier (s; 1 + k s; 1), then the load term's k (affine) and c
 * (interaction), the order of models/load_laws.py's coefficient_names. NAN for table laws (their slopes
 * depend on the values nonlinearly) and bad indices. L is not read for a law without a load term. */
double tf_law_coef_derivative(const tf_law *law, int coef, double T, double L);
/* Number of coefficients tf_law_coef_derivative takes (the load term's included). */
int tf_law_ncoef(const tf_law *law);

/* Node slopes of the shape-preserving cubic through (x, y) (Fritsch-Carlson with the
 * weighted harmonic mean of Fritsch and Butland; the end slopes by the three-point
 * rule, limited to keep the shape). Written once at set-up, read by tf_law_eval. */
void tf_pchip_slopes(int n, const double *x, const double *y, double *d);

#ifdef __cplusplus
}
#endif
#endif
