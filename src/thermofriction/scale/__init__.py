"""Scale-out: many simulations and identifications on this machine's cores or on Dask's distributed
scheduler (docs/scale.md).

- :func:`sweep`: a design map, one simulation per grid point, summary metrics per point;
- :func:`identify_fleet`: one identification per dataset of a production batch, with a fleet summary;
- :func:`propagate`: a fit's uncertainty carried into predictions at new temperatures (bands).

With no ``scheduler`` the work runs in chunks on threads in this process (the C core releases the
GIL); ``scheduler="processes"`` on an embedded local Dask cluster of worker processes;
``scheduler="tcp://HOST:8786"`` (or a ``distributed.Client``) on an existing cluster;
``scheduler="sequential"`` in this process, in order. Dask is imported only when a cluster is used.
"""

from __future__ import annotations

from .cluster import SEQUENTIAL, Runner
from .fleet import FleetResult, fleet_datasets, identify_fleet
from .propagate import PropagationResult, draw_parameters, propagate
from .sweep import METRICS, SweepResult, parse_axis, sweep

__all__ = ["sweep", "SweepResult", "METRICS", "parse_axis", "identify_fleet", "FleetResult", "fleet_datasets",
           "propagate", "PropagationResult", "draw_parameters", "Runner", "SEQUENTIAL"]
