"""The second-order stage's response, x'' + 2 xi wn x' + wn^2 x = K wn^2 u(t), computed exactly for a sampled
input (no ODE solver): the state-space model discretised with the matrix exponential, with a first-order hold
(``hold="foh"``, exact for an input that is linear between samples: ramps, sawtooths, steps with a slew) or a
zero-order hold (``hold="zoh"``, exact for an input that is constant between samples: ideal steps at a sample
instant). The stage starts at rest at zero, as in ``tf.simulate``."""

from __future__ import annotations

import math

import numpy as np

from .._lazy import lazy
from ..errors import InputError

linalg, signal = (lazy(f"scipy.{name}") for name in ("linalg", "signal"))
#: relative spread of the sampling intervals treated as uniform sampling
UNIFORM_TOLERANCE = 1e-6


def step_response(time, xi, wn, K, amplitude, t_step=0.0):
    """Exact response of the stage, at rest at zero, to a step of ``amplitude`` volts at ``t_step``:
    underdamped (xi < 1), critically damped or overdamped.

    Parameters
    ----------
    time : array_like
        The times [s].
    xi : float
        The damping ratio [-].
    wn : float
        The natural frequency [rad/s].
    K : float
        The static gain [m/V].
    amplitude : float
        The step [V].
    t_step : float, default 0.0
        When the step happens [s].

    Returns
    -------
    numpy.ndarray
        The stage displacement [m] at ``time``.

    Raises
    ------
    None
        Nothing is checked (NumPy's errors for values that are not numbers).
    """
    tau = np.clip(np.asarray(time, float) - t_step, 0.0, None)
    if xi < 1:
        r = math.sqrt(1 - xi ** 2)
        wd = wn * r
        g = 1 - np.exp(-xi * wn * tau) * (np.cos(wd * tau) + xi / r * np.sin(wd * tau))
    elif xi == 1:
        g = 1 - np.exp(-wn * tau) * (1 + wn * tau)
    else:
        s = math.sqrt(xi ** 2 - 1)
        p1, p2 = -wn * (xi - s), -wn * (xi + s)
        g = 1 + (p2 * np.exp(p1 * tau) - p1 * np.exp(p2 * tau)) / (p1 - p2)
    return K * amplitude * g


def _phi2(z):
    """e^z - 1 - z, accurate for small |z| (complex)."""
    if abs(z) > 0.5:
        return np.exp(z) - 1 - z
    term, total = z * z / 2, 0j
    for k in range(3, 40):
        total += term
        if abs(term) <= 1e-18 * abs(total):
            break
        term *= z / k
    return total


def _discretisation_expm(xi, wn, h):
    A = np.array([[0.0, 1.0], [-wn * wn, -2 * xi * wn]])
    B = np.array([0.0, wn * wn])
    M = np.zeros((4, 4))
    M[:2, :2] = A * h
    M[:2, 2] = B * h
    M[2, 3] = 1.0
    E = linalg.expm(M)
    return E[:2, :2], E[:2, 2], E[:2, 3]


def _discretisation(xi, wn, h):
    """Phi, Gamma0 (held part) and Gamma1 (ramp part) of the sampled system:
    x[k+1] = Phi x[k] + Gamma0 u[k] + Gamma1 (u[k+1] - u[k]), with Phi = e^{Ah},
    Gamma0 = A^-1 (Phi - I) B and Gamma1 = A^-2 (Phi - I - A h) B / h. e^{Ah} by Sylvester's formula
    over the two poles, with Phi - I and Phi - I - Ah formed from expm1-like functions so that
    oversampled records (wn h << 1) lose no digits; near a double pole, the matrix exponential."""
    A = np.array([[0.0, 1.0], [-wn * wn, -2 * xi * wn]])
    B = np.array([0.0, wn * wn])
    disc = complex(xi * xi - 1) ** 0.5
    p1, p2 = wn * (-xi + disc), wn * (-xi - disc)
    if abs(p1 - p2) < 1e-3 * wn:  # Sylvester loses |p|/|p1 - p2| digits; 1e3 eps is fine
        return _discretisation_expm(xi, wn, h)
    I = np.eye(2)
    d = p1 - p2
    A1, A2 = (A - p2 * I) / d, (A - p1 * I) / d   # e^{At} = A1 e^{p1 t} - A2 e^{p2 t}
    Pm1 = (A1 * np.expm1(p1 * h) - A2 * np.expm1(p2 * h)).real          # Phi - I
    Pm2 = (A1 * _phi2(p1 * h) - A2 * _phi2(p2 * h)).real                # Phi - I - A h
    Ainv = np.array([[-2 * xi / wn, -1.0 / (wn * wn)], [1.0, 0.0]])
    G0 = Ainv @ (Pm1 @ B)
    G1 = Ainv @ (Ainv @ (Pm2 @ B)) / h
    return I + Pm1, G0, G1


def _uniform_response(u, xi, wn, h, hold):
    """Unit-gain response on a uniform grid of step h, the stage at rest at zero at the first sample."""
    Phi, G0, G1 = _discretisation(xi, wn, h)
    C = np.array([1.0, 0.0])
    if hold == "zoh":
        num, den = signal.ss2tf(Phi, G0[:, None], C[None, :], np.zeros((1, 1)))
        return signal.lfilter(num[0], den, u)
    # first-order hold. With w[k] = x[k] - G1 u[k] the recursion is the ordinary discrete system
    # w[k+1] = Phi w[k] + Bt u[k], y[k] = C w[k] + C G1 u[k]: one lfilter call, plus the free
    # response of w[0] = -G1 u[0] (x[0] = 0).
    Bt = Phi @ G1 + G0 - G1
    num, den = signal.ss2tf(Phi, Bt[:, None], C[None, :], np.array([[C @ G1]]))
    if u[0] == 0:
        return signal.lfilter(num[0], den, u)
    # f[k] = C Phi^k w0 is a zero-input response of the filter (Cayley-Hamilton): start the filter
    # in the state that produces it. No eigenvectors, so a double pole (xi = 1) is fine.
    w0 = -G1 * u[0]
    f0, f1 = C @ w0, C @ (Phi @ w0)
    return signal.lfilter(num[0], den, u, zi=np.array([f0, f1 + den[1] * f0]))[0]


def unit_gain_response(time, voltage, xi, wn, hold="foh"):
    """Response with K = 1 to the recorded voltage, the stage at rest at zero at the first sample:
    exact for an input linear between samples (``hold="foh"``) or constant between samples
    (``"zoh"``). Sampling that is not uniform (within 1e-6) is simulated on a uniform grid at the
    median interval and interpolated back (second-order accurate)."""
    t = np.asarray(time, float)
    u = np.asarray(voltage, float)
    if hold not in ("foh", "zoh"):
        raise InputError(f"hold must be 'foh' or 'zoh', got {hold!r}")
    n = t.size
    h = (t[-1] - t[0]) / (n - 1)
    dt = np.diff(t)
    if np.max(np.abs(dt - h)) <= UNIFORM_TOLERANCE * h:
        return _uniform_response(u, xi, wn, h, hold)
    hm = float(np.median(dt))
    grid = t[0] + hm * np.arange(int(math.ceil((t[-1] - t[0]) / hm - 1e-9)) + 1)
    if hold == "zoh":
        ug = u[np.clip(np.searchsorted(t, grid, side="right") - 1, 0, n - 1)]
    else:
        ug = np.interp(grid, t, u)
    return np.interp(t, grid, _uniform_response(ug, xi, wn, hm, hold))


def is_uniform(t):
    h = (t[-1] - t[0]) / (t.size - 1)
    return bool(np.max(np.abs(np.diff(t) - h)) <= UNIFORM_TOLERANCE * h)



__all__ = ["step_response", "unit_gain_response", "is_uniform", "UNIFORM_TOLERANCE"]
