"""The design cube on disk: netCDF-4/HDF5 written through h5py, read with xarray.

- :mod:`.cube`: the cube file, written slab by slab with its chunks compressed once
  (:mod:`.codec`; read back by :mod:`.decode`);
- :mod:`.netcdf4`: the netCDF-4 layout (dimensions, coordinates, attributes) in h5py;
- :mod:`.journal`: the journal of finished slabs;
- :mod:`.locks`: the one-writer lock on a cube being written;
- :mod:`.restore`: a journal's record of a slab, and the slab restored from it;
- :mod:`.reader`: :func:`open_cube` and friends;
- :mod:`.describe`: a cube's summary (``nylonflex info``) and the check of its chunks,
  with h5py alone;
- :mod:`.light`: :func:`open_light`, a cube read through h5py alone (no xarray), for the
  variable-by-variable scan of ``nylonflex query --where``.

The names below are imported from their modules on first use (PEP 562), so that reading a
cube (``nylonflex info``) does not import the engine that writes one, nor Numba.
"""

from __future__ import annotations

import importlib

#: Each public name -> the module of this package (or the engine's) that defines it.
_WHERE = {
    "CUBE_FORMAT": "..engine.provenance", "VOLATILE_ATTRS": "..engine.provenance",
    "CubeFile": ".cube",
    "Journal": ".journal", "exclusive": ".locks",
    "check_cube": ".describe", "cube_attrs": ".reader", "cube_summary": ".describe",
    "cube_description": ".describe",
    "open_cube": ".reader",
    "LightCube": ".light", "open_light": ".light",
}

__all__ = sorted(_WHERE)


def __getattr__(name):
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name], __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_WHERE))
