"""Numba kernels over design grids. Only :mod:`nylonflex.sweep.conductor` (and the simulator)
call them.

:func:`source_digest` (of the physics and kernel sources) names the compiled model in a
cube's provenance and keys :func:`cache_dir`, the kernels' own Numba cache folder; neither
imports Numba.
"""

from .cache import cache_dir, source_digest

__all__ = ["cache_dir", "source_digest"]
