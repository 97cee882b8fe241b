"""The design cube on disk: netCDF-4/HDF5 written through h5py, read with xarray.

- :mod:`.cube`: the cube file, written slab by slab with its chunks compressed once;
- :mod:`.netcdf4`: the netCDF-4 layout (dimensions, coordinates, attributes) in h5py;
- :mod:`.journal`: the journal of finished slabs and the one-writer lock;
- :mod:`.run`: a sweep into a file (the journaled sink of the engine's slab loop, resume);
- :mod:`.reader`: :func:`open_cube` and friends.
"""

from ..engine.provenance import CUBE_FORMAT, VOLATILE_ATTRS
from .cube import CubeFile
from .journal import Journal, exclusive
from .reader import check_cube, cube_attrs, cube_summary, open_cube
from .run import CubeSink, DiskFull, Interrupted, sweep_to_file

__all__ = ["CUBE_FORMAT", "VOLATILE_ATTRS", "CubeFile", "CubeSink", "DiskFull", "Interrupted", "Journal",
           "check_cube", "cube_attrs", "cube_summary", "exclusive", "open_cube", "sweep_to_file"]
