"""Independent truths for the warm-up fit (issue 45 item 1): a joint with Stribeck friction whose fc and fs follow
linear laws of the contact temperature, heated by its own friction power through a two-node heat path (contact and
housing), integrated by scipy's solve_ivp from the equations written here (not the package's simulate), driven by
a duty cycle at two speeds with pauses; each run's sensor re-zeroed (its own offset), AR(1) noise on the torque,
a housing (or contact) sensor as a lagging proxy, quantised. Soak runs: short runs held at known temperatures."""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy.integrate import solve_ivp

import thermofriction as tf
from thermofriction.data.force import ForceExperiment
from thermofriction.data.motion import motion_waveform


@dataclasses.dataclass(frozen=True)
class Truth:
    """The joint's friction laws (a T + b), constants, heat path (eta, C1, R1, C2, R2) and proxy lag."""

    fc_a: float = -0.006
    fc_b: float = 1.05
    fs_a: float = -0.009
    fs_b: float = 1.525
    vs: float = 0.08
    sigma2: float = 0.25
    v_smooth: float = 1e-3
    eta: float = 0.8
    C1: float = 1.6          # J/K
    R1: float = 7.5          # K/W
    C2: float = 32.0         # J/K
    R2: float = 15.0         # K/W
    tau_p: float = 40.0      # s
    proxy_node: int = 1      # the housing
    ambient: float = 25.0

    def friction(self, v, T):
        fc, fs = self.fc_a * T + self.fc_b, self.fs_a * T + self.fs_b
        g = fc + (fs - fc) * np.exp(-(np.abs(v) / self.vs) ** 2)
        return g * np.tanh(v / self.v_smooth) + self.sigma2 * v

    def per_eta(self):
        """What force data determine: C/eta and eta R."""
        return {"C_th": self.C1 / self.eta, "R_th": self.eta * self.R1, "C_2": self.C2 / self.eta,
                "R_2": self.eta * self.R2}


def duty_velocity(t, speeds=(1.0, 2.5), on=40.0, off=20.0, freq=0.25):
    """A duty cycle: sinusoidal motion at each speed in turn for ``on`` seconds, then a pause of ``off``."""
    period = on + off
    phase = np.mod(t, period)
    k = np.floor_divide(t, period).astype(int) % len(speeds)
    amp = np.asarray(speeds, float)[k]
    return np.where(phase < on, amp * np.sin(2 * np.pi * freq * phase), 0.0)


def warm_up(truth: Truth, duration=1500.0, rate=20.0, x0=None, t_start=0.0, two_nodes=True):
    """(t, v, x, T_contact, T_housing, T_proxy, end state) of a warm-up from ``x0`` (default soaked at ambient),
    integrated by solve_ivp (RK45, steps of at most a tenth of the duty cycle's motion period)."""
    t = np.arange(0.0, duration, 1.0 / rate)
    x0 = np.full(3, truth.ambient) if x0 is None else np.asarray(x0, float)

    def rhs(s, y):
        v = duty_velocity(s + t_start)
        P = truth.eta * abs(truth.friction(v, y[0]) * v)
        if two_nodes:
            d1 = (P - (y[0] - y[1]) / truth.R1) / truth.C1
            d2 = ((y[0] - y[1]) / truth.R1 - (y[1] - truth.ambient) / truth.R2) / truth.C2
        else:
            d1 = (P - (y[0] - truth.ambient) / (truth.R1 + truth.R2)) / truth.C1
            d2 = 0.0
        dp = (y[truth.proxy_node] - y[2]) / truth.tau_p
        return [d1, d2, dp]
    sol = solve_ivp(rhs, (0.0, t[-1]), x0, t_eval=t, max_step=0.1, rtol=1e-8, atol=1e-8)
    v = duty_velocity(t + t_start)
    dt = 1.0 / rate
    x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * dt)])
    return t, v, x, sol.y[0], sol.y[1], sol.y[2], sol.y[:, -1]


def ar1(rng, n, sigma, rho=0.7):
    """AR(1) noise of standard deviation ``sigma`` and lag-1 correlation ``rho``."""
    e = rng.normal(0.0, sigma * np.sqrt(1 - rho ** 2), n)
    out = np.empty(n)
    out[0] = rng.normal(0.0, sigma)
    for i in range(1, n):
        out[i] = rho * out[i - 1] + e[i]
    return out


def experiment(label, t, v, x, force, *, temperature=None, ambient=None, proxy=None, continues=None):
    """A force experiment in memory, as the loader makes it."""
    return ForceExperiment(file=label, time=t, voltage=None, displacement=x,
                           temperature=float(np.mean(ambient)) if temperature is None else float(temperature),
                           force=force, velocity=v, rotary=True, input=motion_waveform(t, v, x[0]),
                           ambient_temperature=None if ambient is None else np.full(t.size, ambient, float),
                           proxy_temperature=proxy, continues=continues)


def measured(truth, rng, t, v, T, offset, sigma=0.01):
    """The torque record: the truth's friction at T plus the run's offset and AR(1) noise."""
    return truth.friction(v, T) + offset + ar1(rng, t.size, sigma)


def soak_runs(truth, rng, temperatures=(25.0, 35.0, 45.0, 55.0), duration=60.0, rate=20.0):
    """Runs at known, held contact temperatures (the duty cycle's two speeds), each with its own offset."""
    out = []
    for k, T in enumerate(temperatures):
        t = np.arange(0.0, duration, 1.0 / rate)
        v = duty_velocity(t, on=duration / 2, off=0.0)
        x = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) / rate)])
        out.append(experiment(f"soak-{T:g}C.csv", t, v, x, measured(truth, rng, t, v, np.full(t.size, T),
                                                                     0.02 * (k - 1.5)), temperature=T))
    return out


def proxy_record(rng, T, sigma=0.05, step=0.1):
    """A proxy sensor's record: the truth's lagging temperature with AR(1) noise, quantised."""
    return np.round((T + ar1(rng, T.size, sigma)) / step) * step


def initial_model(truth: Truth, off=1.2):
    """A Model I start for the fit: the truth's laws and constants ``off`` times theirs (intercepts kept near)."""
    laws = {"fc": tf.Linear(a=truth.fc_a * off, b=truth.fc_b / off ** 0.5, range=(0.0, 120.0)),
            "fs": tf.Linear(a=truth.fs_a * off, b=truth.fs_b / off ** 0.5, range=(0.0, 120.0))}
    return tf.Model(plant=tf.PrescribedMotion(motion="rotary"),
                    friction=tf.Stribeck(fc=None, fs=None, vs=truth.vs * off, sigma2=truth.sigma2 / off,
                                         v_smooth=truth.v_smooth),
                    thermal=tf.ModelI(laws=laws))
