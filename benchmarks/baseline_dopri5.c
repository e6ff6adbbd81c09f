/* The near-limit baseline of benchmarks/bench_simulate.py: a plain explicit Dormand-Prince 5(4)
 * (Hairer's DOPRI5: FSAL, PI step control, 4th-order continuous extension) with the right-hand
 * side of one case written inline -- LuGre with constant parameters (sigma1 constant, fs = fc) on
 * the stick-slip actuator driven by a sawtooth voltage. It restarts at the sawtooth's corners (the
 * only thing it knows of the problem besides the equations) and writes the five states on the
 * caller's output grid. No checks, no events, no stiffness detection, no Jacobian: what a person
 * writes by hand for this one case, to measure how close the library's general integrators come.
 *
 * Built by the benchmark with the system C compiler (cc -O3 -shared -fPIC) and called through
 * ctypes; not part of the package. */
#include <math.h>
#include <string.h>

typedef struct {
    double m, c, k, T_em, m_e;        /* stick-slip actuator, physical form */
    double sigma0, sigma1, sigma2, fc; /* LuGre at the run's temperature, fs = fc: g(v) = fc */
    double amplitude, frequency, rise, offset; /* sawtooth voltage */
} baseline_params;

typedef struct {
    long steps, rejected, rhs_evals;
} baseline_stats;

enum { N = 5 }; /* x_p, v_p, x_e, v_e, z */

static inline double sawtooth(const baseline_params *p, double t)
{
    double x = t * p->frequency, ph = x - floor(x);
    return p->offset + p->amplitude * (ph < p->rise ? ph / p->rise : (1.0 - ph) / (1.0 - p->rise));
}

static inline void rhs(const baseline_params *p, double t, const double *y, double *dy)
{
    double v = y[3] - y[1];
    double zd = v - p->sigma0 * fabs(v) * y[4] / p->fc;
    double F = p->sigma0 * y[4] + p->sigma1 * zd + p->sigma2 * v;
    dy[0] = y[1];
    dy[1] = (-p->c * y[1] - p->k * y[0] + p->T_em * sawtooth(p, t) + F) / p->m;
    dy[2] = y[3];
    dy[3] = -F / p->m_e;
    dy[4] = zd;
}

static const double
    c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9,
    a21 = 1.0 / 5, a31 = 3.0 / 40, a32 = 9.0 / 40,
    a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9,
    a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561, a54 = -212.0 / 729,
    a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247, a64 = 49.0 / 176, a65 = -5103.0 / 18656,
    a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192, a75 = -2187.0 / 6784, a76 = 11.0 / 84,
    e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920, e5 = -17253.0 / 339200, e6 = 22.0 / 525,
    e7 = -1.0 / 40,
    d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
    d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
    d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;

/* The next sawtooth corner (period start or end of the rise) after t. */
static double next_corner(const baseline_params *p, double t)
{
    double tt = t + 1e-12 * fmax(1.0, fabs(t)), f = p->frequency, k = floor(tt * f);
    double a = (k + p->rise) / f, b = (k + 1.0) / f;
    return a > tt ? a : b;
}

/* Integrates from rest at t_out[0] through t_out[n_out - 1]; writes the states at t_out into
 * out (n_out x 5, row-major). Returns 0, or 1 when max_steps is reached. */
int baseline_dopri5(const baseline_params *p, double rtol, const double *atol, const double *t_out, long n_out,
                    double *out, long max_steps, baseline_stats *st)
{
    double y[N] = {0}, y1[N], yt[N], k1[N], k2[N], k3[N], k4[N], k5[N], k6[N], k7[N], cont[5][N];
    double t = t_out[0], t_end = t_out[n_out - 1], h = 1e-6, facold = 1e-4;
    long next = 0;
    memset(st, 0, sizeof *st);
    while (next < n_out && t_out[next] <= t) memcpy(out + N * next++, y, sizeof y);
    while (t < t_end) {
        double seg_end = fmin(next_corner(p, t), t_end);
        rhs(p, t, y, k1);
        st->rhs_evals++;
        int reject = 0;
        while (t < seg_end) {
            if (st->steps + st->rejected >= max_steps) return 1;
            int last = 0;
            if (t + 1.01 * h >= seg_end) { h = seg_end - t; last = 1; }
            int i;
            for (i = 0; i < N; i++) yt[i] = y[i] + h * a21 * k1[i];
            rhs(p, t + c2 * h, yt, k2);
            for (i = 0; i < N; i++) yt[i] = y[i] + h * (a31 * k1[i] + a32 * k2[i]);
            rhs(p, t + c3 * h, yt, k3);
            for (i = 0; i < N; i++) yt[i] = y[i] + h * (a41 * k1[i] + a42 * k2[i] + a43 * k3[i]);
            rhs(p, t + c4 * h, yt, k4);
            for (i = 0; i < N; i++) yt[i] = y[i] + h * (a51 * k1[i] + a52 * k2[i] + a53 * k3[i] + a54 * k4[i]);
            rhs(p, t + c5 * h, yt, k5);
            for (i = 0; i < N; i++)
                yt[i] = y[i] + h * (a61 * k1[i] + a62 * k2[i] + a63 * k3[i] + a64 * k4[i] + a65 * k5[i]);
            rhs(p, t + h, yt, k6);
            for (i = 0; i < N; i++)
                y1[i] = y[i] + h * (a71 * k1[i] + a73 * k3[i] + a74 * k4[i] + a75 * k5[i] + a76 * k6[i]);
            rhs(p, t + h, y1, k7);
            st->rhs_evals += 6;
            double err = 0.0;
            for (i = 0; i < N; i++) {
                double e = h * (e1 * k1[i] + e3 * k3[i] + e4 * k4[i] + e5 * k5[i] + e6 * k6[i] + e7 * k7[i]);
                double sk = atol[i] + rtol * fmax(fabs(y[i]), fabs(y1[i]));
                err += (e / sk) * (e / sk);
            }
            err = sqrt(err / N);
            if (err <= 1.0) {
                double t_new = last ? seg_end : t + h;
                if (next < n_out && t_out[next] <= t_new) {
                    for (i = 0; i < N; i++) {
                        double dy = y1[i] - y[i], bspl = h * k1[i] - dy;
                        cont[0][i] = y[i];
                        cont[1][i] = dy;
                        cont[2][i] = bspl;
                        cont[3][i] = dy - h * k7[i] - bspl;
                        cont[4][i] = h * (d1 * k1[i] + d3 * k3[i] + d4 * k4[i] + d5 * k5[i] + d6 * k6[i] + d7 * k7[i]);
                    }
                    while (next < n_out && t_out[next] <= t_new) {
                        double s = (t_out[next] - t) / h, s1 = 1.0 - s, *o = out + N * next++;
                        for (i = 0; i < N; i++)
                            o[i] = cont[0][i] + s * (cont[1][i] + s1 * (cont[2][i] + s * (cont[3][i] + s1 * cont[4][i])));
                    }
                }
                st->steps++;
                double fac = pow(err, 0.17) / pow(facold, 0.04); /* PI control, Hairer's constants */
                fac = fmax(0.1, fmin(5.0, fac / 0.9));
                double hnew = h / fac;
                facold = fmax(err, 1e-4);
                if (reject) hnew = fmin(hnew, h);
                reject = 0;
                memcpy(y, y1, sizeof y);
                memcpy(k1, k7, sizeof y); /* FSAL */
                t = t_new;
                h = hnew;
            } else {
                st->rejected++;
                reject = 1;
                h /= fmin(5.0, pow(err, 0.17) / 0.9);
            }
        }
    }
    while (next < n_out) memcpy(out + N * next++, y, sizeof y);
    return 0;
}
