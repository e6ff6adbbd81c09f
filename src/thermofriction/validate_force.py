"""Validation on force data (docs/force-data.md#validation): the model, driven by each experiment's measured
motion, predicts the measured friction force (torque) plus the sensor offset of its ``[plant]``, which is used
as it is (fitted once, on the fit experiments; never re-fitted on held-out ones)."""

from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np

from .drive import drive
from .errors import InputError, TemperatureRangeWarning, ThermofrictionError
from .identify.quality import fit_quality
from .simulate import StepSizeController, simulate
from .validate import Failure, ValidationResult


@dataclasses.dataclass
class ForcePrediction:
    """One force experiment: measured and predicted force [N or N m], the motion, and the metrics."""

    file: str
    temperature: float
    role: str
    time: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray
    rmse: float
    nrmse: float
    max_error_pct: float
    bias: float
    unit: str
    fit_quality: dict | None = None

    def metrics(self) -> dict:
        return {"file": self.file, "temperature": self.temperature, "role": self.role, "rmse": self.rmse,
                "nrmse": self.nrmse, "max_error_pct": self.max_error_pct, "bias": self.bias, "unit": self.unit,
                "fit_quality": self.fit_quality}


def predict_force(model, exp, rtol=1e-8) -> ForcePrediction:
    """Simulates one force experiment on its own samples and compares the force."""
    if model.plant.type != "prescribed":
        raise InputError(f"force data are predicted with a prescribed-motion model ([plant] type = \"prescribed\"); "
                         f"this model's plant is '{model.plant.type}'")
    if model.plant.rotary != exp.rotary:
        raise InputError(f"{exp.file}: the data are {'rotary' if exp.rotary else 'linear'} but the model's motion is "
                         f"{model.plant.motion}")
    d = drive(exp, model, start="model")
    res = simulate(d.model(model), t_eval=exp.time, temperature=d.temperature, input=d.waveform,
                   controller=StepSizeController(rtol=rtol))
    pred = res.friction_force + model.plant.sensor_offset
    meas = np.asarray(exp.force, float)
    err = pred - meas
    span = float(np.ptp(meas))
    quality = fit_quality(err, meas)
    rmse = float(np.sqrt(np.mean(err ** 2)))
    return ForcePrediction(exp.file, float(exp.temperature), getattr(exp, "role", "fit"), np.asarray(exp.time),
                           np.asarray(exp.displacement), np.asarray(exp.drive_velocity), meas, pred, rmse,
                           rmse / span if span > 0 else math.nan,
                           100 * float(np.max(np.abs(err))) / span if span > 0 else math.nan, float(np.mean(err)),
                           exp.force_unit, quality)


class ForceValidationResult(ValidationResult):
    """As :class:`~thermofriction.validate.ValidationResult`, in force units (``rmse`` in N or N m)."""

    @property
    def _COLUMNS(self):  # noqa: N802 - the base class's table layout, with the unit in the headers
        return (("file", "file", "{}"), ("T [C]", "temperature", "{:.4g}"), ("role", "role", "{}"),
                (f"RMSE [{self.unit}]", "rmse", "{:.4g}"), ("NRMSE", "nrmse", "{:.3g}"),
                ("max error [%]", "max_error_pct", "{:.3g}"), (f"mean error [{self.unit}]", "bias", "{:+.3g}"))

    @property
    def unit(self) -> str:
        return self.predictions[0].unit if self.predictions else "N"

    def rows(self):
        for m in self.experiments:
            yield [fmt.format(m[key]) for _, key, fmt in self._COLUMNS]

    def summary(self) -> dict:
        out = {}
        for role in ("fit", "validate"):
            ps = [p for p in self.predictions if p.role == role]
            if ps:
                pcts = [p.max_error_pct for p in ps if not math.isnan(p.max_error_pct)]
                out[role] = {"max_error_pct": max(pcts) if pcts else math.nan,
                             "rmse": float(np.sqrt(np.mean([p.rmse ** 2 for p in ps]))), "unit": ps[0].unit,
                             "n": len(ps)}
        return out

    def to_dict(self) -> dict:
        d = super().to_dict()
        d["sensor_offset"] = self.model.plant.sensor_offset
        d["unit"] = self.unit
        return d


def validate_force(model, experiments) -> ForceValidationResult:
    """Predicts every force experiment with ``model`` (see :func:`thermofriction.validate.validate`)."""
    caught, preds, failures = [], [], []
    for exp in experiments:
        with warnings.catch_warnings(record=True) as w:
            warnings.simplefilter("always", TemperatureRangeWarning)
            try:
                preds.append(predict_force(model, exp))
            except InputError:
                raise
            except ThermofrictionError as e:
                failures.append(Failure(exp.file, float(exp.temperature), getattr(exp, "role", "fit"), str(e)))
        caught += [f"{exp.file}: {x.message}" for x in w if issubclass(x.category, TemperatureRangeWarning)]
    return ForceValidationResult(model, preds, caught, failures)


__all__ = ["ForcePrediction", "ForceValidationResult", "predict_force", "validate_force"]


def steady_state_curve(model, velocities, temperature=None) -> np.ndarray:
    """The model's friction force in steady sliding at each of ``velocities`` [m/s or rad/s], by simulation
    (any friction model, any thermal form): a constant velocity held over thirty presliding lengths (g/stiffness),
    where the bristles have long settled. Without the sensor offset."""
    from .waveforms import Sampled
    p = model.parameters_at(temperature if temperature is not None else 25.0)
    stiffness = p.get("sigma0") or (sum(p["k"]) if p.get("k") is not None else None)
    level = max(p.get("fc") or 0.0, p.get("fs") or 0.0)
    distance = 30.0 * level / stiffness if stiffness else 1e-9
    out = []
    for v in np.asarray(velocities, float):
        if v == 0:
            out.append(0.0)
            continue
        T = distance / abs(v)
        res = simulate(model, t_eval=np.array([0.0, T]), temperature=temperature,
                       input=Sampled(np.array([0.0, 2 * T]), np.array([0.0, 2 * T * v])),
                       controller=StepSizeController(rtol=1e-8))
        out.append(float(res.friction_force[-1]))
    return np.array(out)


__all__ += ["steady_state_curve"]
