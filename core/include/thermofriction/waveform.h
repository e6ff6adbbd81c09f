/* Input waveforms (docs/formats.md#inputs): value, slope and corner times.
 * A corner is a time where the waveform or its slope jumps; integrators stop there. */
#ifndef THERMOFRICTION_WAVEFORM_H
#define THERMOFRICTION_WAVEFORM_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TF_WAVE_ZERO = 0,
    TF_WAVE_SAWTOOTH = 1, /* amplitude, frequency, rise, offset, direction */
    TF_WAVE_SINE = 2,     /* amplitude, frequency, offset: offset + A sin(2 pi f t) */
    TF_WAVE_SQUARE = 3,   /* amplitude, frequency, slew, offset, duty (= rise) */
    TF_WAVE_STEP = 4,     /* amplitude at time t0, ramped over slew, from offset */
    TF_WAVE_SAMPLED = 5   /* linear interpolation through (t[i], v[i]); held beyond the ends */
} tf_waveform_kind;

typedef struct {
    int kind;
    double amplitude;
    double frequency; /* Hz */
    double rise;      /* sawtooth: rising fraction of the period; square: duty cycle */
    double offset;
    double direction; /* sawtooth: +1 slow rise / fast fall, -1 mirrored in time */
    double slew;      /* square, step: transition time [s] */
    double t0;        /* step time [s] */
    const double *t;  /* sampled: strictly increasing times */
    const double *v;  /* sampled: values */
    int n;            /* sampled: number of points */
} tf_waveform;

double tf_waveform_value(const tf_waveform *w, double t);
/* Right-hand slope d/dt at t (the slope of the segment that starts at or contains t). */
double tf_waveform_slope(const tf_waveform *w, double t);
/* The largest |d^2/dt^2| at any time (a prescribed motion's peak acceleration; the sine's A (2 pi f)^2): 0 for
 * the piecewise-linear waveforms, whose slope changes only at corners. */
double tf_waveform_peak_slope_rate(const tf_waveform *w);
/* Smallest corner strictly later than t (by more than a rounding margin); INFINITY if none. */
double tf_waveform_next_corner(const tf_waveform *w, double t);
/* The corners in [a, b] (a corner within 1e-12, relative, before a counts as at a), in order: the first
 * min(count, cap) into out (may be NULL with cap 0); returns their count (at most 1e6). */
long tf_waveform_corners(const tf_waveform *w, double a, double b, double *out, long cap);
/* First time > t (by more than the corner margin) at which a smooth waveform's slope changes
 * sign (the sine's extrema); INFINITY for the piecewise-linear ones, whose slope changes sign
 * only at corners. A prescribed motion restarts the integration there: v(t) is then no state
 * the error control could follow, and a step must not carry a reversal inside it. */
double tf_waveform_next_reversal(const tf_waveform *w, double t);

/* Piecewise-linear signal helpers shared by sampled waveforms and sampled temperatures. */
double tf_pwl_value(int n, const double *x, const double *y, double t);
double tf_pwl_slope(int n, const double *x, const double *y, double t);
double tf_pwl_next_knot(int n, const double *x, double t);

#ifdef __cplusplus
}
#endif
#endif
