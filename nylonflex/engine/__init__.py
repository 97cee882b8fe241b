"""The engine: one fast model for every caller.

- :func:`evaluate` (:mod:`.pointwise`): every design variable of scattered designs, with
  materials that may vary design by design; :func:`design_limits` is its scalar face.
- :mod:`.grid`: the design-grid kernel on a slab of radii, and the slab plan.
- :mod:`.slabs`: the one slab loop, given an executor (local threads, or Dask) and a sink
  (an in-memory Dataset here; the journaled HDF5 cube in :mod:`nylonflex.storage`).

Imports point down: the engine imports the kernels, the physics, the registry, the
materials and the config, never storage, charts, query or the CLI.
"""

from ..physics.limits import model_bend_angle as bend_angle
from .pointwise import MODELS, design_limits, evaluate

__all__ = ["MODELS", "bend_angle", "design_limits", "evaluate"]
