"""Results as MATLAB files (docs/formats.md#results-in-matlab-files): a simulation's columns, and a fit's or a
validation's JSON document as MATLAB structs."""

from __future__ import annotations

import math
import re

import numpy as np

from .matlab import matlab_name, save_mat

def simulation_to_mat(result, path):
    """A simulation result as a MATLAB file: one column vector per CSV column
    (docs/formats.md#simulation-output), named as the header with its unit as a suffix
    (``time_s``, ``displacement_m``, ``velocity_m_per_s``); per-cycle ``step_sizes_m`` and
    ``cycle_times_s`` for periodic inputs."""
    variables = {matlab_name(h): np.asarray(v, float) for h, v in result.columns().items()}
    if getattr(result, "step_sizes", None) is not None and np.size(result.step_sizes):
        variables["step_sizes_m"] = np.asarray(result.step_sizes, float)
        variables["cycle_times_s"] = np.asarray(result.cycle_times, float)
    save_mat(path, variables)


_IDENTIFIER = re.compile(r"[A-Za-z][A-Za-z0-9_]{0,62}")
_NONFINITE = {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) or (isinstance(v, str) and v in _NONFINITE)


def results_to_mat(value, table=False):
    """A results document (what the JSON holds: docs/formats.md#results-json) as MATLAB values: objects
    become structs; a list of objects becomes a table-like struct of columns (one entry per row); an object
    whose keys are not MATLAB names (``sigma0.a``, file names) becomes a struct with a ``name`` cell array
    and one column per field; lists of numbers become double vectors (JSON's "nan"/"inf" strings as
    NaN/Inf), lists of text cell arrays; null an empty matrix. ``table`` makes an object a table by name
    even where its keys are MATLAB names (the fitted parameters: always ``parameters.name{k}``)."""
    if value is None:
        return np.zeros((0, 0))
    if isinstance(value, bool):
        return value
    if _number(value):
        return float(_NONFINITE.get(value, value)) if isinstance(value, str) else float(value)
    if isinstance(value, str):
        return value
    if isinstance(value, dict):
        if not table and all(_IDENTIFIER.fullmatch(str(k)) for k in value):
            return {str(k): results_to_mat(v) for k, v in value.items()}
        rows = list(value.values())
        table = {"name": np.array([str(k) for k in value], dtype=object)}
        if rows and all(isinstance(r, dict) for r in rows):
            table.update(results_to_mat(rows))
        else:
            table["value"] = results_to_mat(rows)
        return table
    if isinstance(value, (list, tuple)):
        items = list(value)
        if items and all(_number(v) for v in items):
            return np.array([results_to_mat(v) for v in items], float)
        if (items and all(isinstance(v, (list, tuple)) and v and all(_number(x) for x in v) for v in items)
                and len({len(v) for v in items}) == 1):  # a matrix (the correlations)
            return np.array([[results_to_mat(x) for x in v] for v in items], float)
        if items and all(isinstance(v, str) for v in items):
            return np.array(items, dtype=object)
        if items and all(isinstance(v, dict) for v in items):
            keys = list(dict.fromkeys(k for v in items for k in v))
            return {re.sub(r"\W", "_", str(k)): results_to_mat([v.get(k) for v in items]) for k in keys}
        cells = np.empty(len(items), dtype=object)
        for i, v in enumerate(items):
            cells[i] = results_to_mat(v)
        return cells
    return value


def save_results_mat(document: dict, path):
    """A results document (identify's or validate's JSON) written as a MATLAB file, one variable per
    top-level key (see :func:`results_to_mat`)."""
    save_mat(path, {re.sub(r"\W", "_", k): results_to_mat(v, table=k == "parameters") for k, v in document.items()})


__all__ = ["simulation_to_mat", "results_to_mat", "save_results_mat"]
