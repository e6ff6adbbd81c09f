/* Temperature laws (docs/models.md#model-i, docs/formats.md#model-files): a parameter, or Model II's
 * dF, as a function of T [degC]. The thermal models that use them are in thermal.h. */
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

typedef struct {
    int kind;
    double a, b;
    int n;
    const double *x;
    const double *y;
    const double *d; /* TABLE only: node slopes from tf_pchip_slopes */
} tf_law;

/* Value of the law at T; its derivative with respect to T in *dvalue_dT when not NULL. */
double tf_law_eval(const tf_law *law, double T, double *dvalue_dT);

/* Derivative of the law's value at T with respect to its coefficient number `coef`:
 * const: value; linear, exp: a (0), b (1); poly: c[coef]; pwl: values[coef].
 * NAN for table laws (their slopes depend on the values nonlinearly) and bad indices. */
double tf_law_coef_derivative(const tf_law *law, int coef, double T);
/* Number of coefficients tf_law_coef_derivative takes. */
int tf_law_ncoef(const tf_law *law);

/* Node slopes of the shape-preserving cubic through (x, y) (Fritsch-Carlson with the
 * weighted harmonic mean of Fritsch and Butland; the end slopes by the three-point
 * rule, limited to keep the shape). Written once at set-up, read by tf_law_eval. */
void tf_pchip_slopes(int n, const double *x, const double *y, double *d);

#ifdef __cplusplus
}
#endif
#endif
