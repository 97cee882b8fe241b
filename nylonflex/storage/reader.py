"""Reading cubes: open one lazily as an xarray Dataset, and its attributes (its summary
and chunk check: :mod:`.describe`)."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..units import InputError
from ..variables import AXES, CURVES, DESIGN, SPREAD, UNCERTAIN, is_complete, validate
from .codec import require_filters
from .netcdf4 import STORED_DIMS

__all__ = ["MASKED", "MAX_CHUNK_BYTES", "MAX_AXIS_VALUES", "check_chunk_sizes",
           "checked_attrs", "cube_attrs", "incomplete_warning", "logical_dims", "open_cube",
           "portable_encoding", "validated"]

#: The largest chunk of a cube read [bytes]: a chunk is decoded whole, and nylonflex writes
#: chunks of about 2 MB (a crafted 2^29-element chunk made ``info`` allocate 4 GiB).
MAX_CHUNK_BYTES = 64 * 2**20
#: The most values of a cube's coordinate (a grid axis) read [-].
MAX_AXIS_VALUES = 1_000_000


def cube_attrs(path) -> dict | None:
    """Global attributes of a nylonflex cube file, or None if it is not one."""
    import h5py

    path = Path(path)
    if not path.is_file() or not h5py.is_hdf5(path):
        return None
    try:
        with h5py.File(path, "r") as f:
            attrs = {k: _attr(v) for k, v in f.attrs.items()}
    except OSError:
        return None
    return attrs if attrs.get("nylonflex_cube") else None


def check_chunk_sizes(path):
    """Refuse a cube with a chunk over :data:`MAX_CHUNK_BYTES` or a coordinate over
    :data:`MAX_AXIS_VALUES` values, before anything is decoded (InputError naming the
    variable and its size)."""
    import h5py

    with h5py.File(path, "r") as f:
        for name, obj in f.items():
            if not isinstance(obj, h5py.Dataset):
                continue
            if obj.chunks is not None:
                nbytes = int(np.prod(obj.chunks, dtype=np.float64)) * obj.dtype.itemsize
                if nbytes > MAX_CHUNK_BYTES:
                    raise InputError(
                        f"{path}: variable {name[:80]} is stored in chunks of "
                        f"{nbytes / 2**20:,.0f} MiB ({' x '.join(map(str, obj.chunks))}), over "
                        f"the {MAX_CHUNK_BYTES // 2**20} MiB nylonflex decodes at once; not a "
                        "cube nylonflex wrote (its chunks are about 2 MB)")
            if obj.ndim == 1 and name in AXES and obj.size > MAX_AXIS_VALUES:
                raise InputError(f"{path}: axis {name} has {obj.size:,} values, over the "
                                 f"{MAX_AXIS_VALUES:,} nylonflex reads")


def _attr(v):
    if isinstance(v, bytes):
        return v.decode()
    if isinstance(v, np.ndarray) and v.size == 1:
        return v.item()
    return v


def checked_attrs(path) -> dict:
    """The global attributes of the cube at ``path`` (:func:`cube_attrs`), after the checks
    every reader of it makes before anything is decoded: the file is a nylonflex cube, no
    chunk or axis is too large to read (:func:`check_chunk_sizes`), and HDF5 can decompress
    its codec (:func:`~nylonflex.storage.codec.require_filters`). :func:`open_cube` and
    :func:`~nylonflex.storage.light.open_light` share it, so both refuse in the same words.

    Raises
    ------
    InputError
        The path is missing (naming an interrupted run's slabs where there are some), not
        HDF5, not a nylonflex cube, or holds a chunk or axis too large.
    MissingPlugin
        Its codec (zstd, lz4) needs a filter plugin that is not installed.
    """
    path = Path(path)
    if not path.exists():
        from .journal import Journal  # only here: its imports (zipfile, hashlib) are not light

        parts = Journal(path)
        extra = (f"; an interrupted run's slabs are in {parts.dir} (finish it with "
                 "'nylonflex sweep CONFIG --resume')") if parts.exists() else ""
        raise InputError(f"{path}: no such cube{extra}")
    attrs = cube_attrs(path)
    if attrs is None:
        raise InputError(f"{path}: not a nylonflex cube (expected a NetCDF4/HDF5 file "
                         "written by 'nylonflex sweep')")
    check_chunk_sizes(path)
    require_filters(attrs.get("compression"))  # zstd and lz4 need a filter plugin
    return attrs


#: The variables an incomplete cube reads as NaN at the radii not computed (those over
#: ``radius``): every design, curve, sampled and spread variable; a tracking one is not.
MASKED = frozenset({**DESIGN, **CURVES, **UNCERTAIN, **SPREAD})


def incomplete_warning(path, done) -> str:
    """The one line an incomplete cube opens with: how many of its radii are computed
    (``done``, bool over ``radius``)."""
    return (f"{path} is incomplete: {int(done.sum())} of {done.size} radii computed; the "
            "rest is masked")


def validated(cube, path):
    """``cube`` (an open Dataset, or :class:`~nylonflex.storage.light.LightCube`) after the
    registry's check of its dimensions, units and dtypes (metadata only); closed, and an
    InputError naming ``path``, where it disagrees."""
    try:
        validate(cube)
    except ValueError as err:
        cube.close()
        raise InputError(f"{path}: {err}") from None
    return cube


def open_cube(path, *, quiet: bool = False):
    """Open a cube written by ``nylonflex sweep`` as an :class:`xarray.Dataset` (lazy).

    An incomplete cube (a sweep stopped early) opens with a warning, its missing radii
    masked (NaN; ``limit`` then reads as float).

    Raises
    ------
    InputError
        The path is missing, not HDF5, or not a nylonflex cube.
    """
    import xarray as xr

    from .accessor import CubeAccessor  # noqa: F401 - registers ds.nf

    attrs = checked_attrs(path)
    path = Path(path)
    ds = logical_dims(xr.open_dataset(path, engine="h5netcdf"))
    for var in ds.variables.values():
        var.encoding = portable_encoding(var.encoding)
    validated(ds, path)
    if not is_complete(attrs):
        done = ds["slab_done"].values.astype(bool)
        if not quiet:
            warnings.warn(incomplete_warning(path, done), stacklevel=2)
        for name in [n for n in ds.data_vars if n in MASKED]:
            if "radius" in ds[name].dims:
                ds[name] = _masked(ds[name].variable, done)
    return ds


def logical_dims(ds):
    """``ds`` (a cube as xarray reads the file) with each axis of :data:`STORED_DIMS`
    its dimension again: ``bend_angle`` and ``tip_force`` over ``pressure``, as the
    registry has them, whatever the cube's format (format 3 stores them over
    ``pressure_point``; earlier formats over ``pressure`` itself)."""
    swap = {dim: name for name, dim in STORED_DIMS.items()
            if dim in ds.dims and name in ds.coords and ds[name].dims == (dim,)}
    return ds.swap_dims(swap) if swap else ds


#: Encoding keys of codecs only HDF5 filter plugins know: h5py's filter id and options, and
#: the netCDF4-style flags xarray reads them into (zstd; lz4 reads as blosc). Neither engine
#: writes them again without the plugin (h5netcdf: 'Compression filter "zstd" is
#: unavailable'; netcdf4: 'Unsupported value for compression kwarg').
_PLUGIN_KEYS = ("compression", "compression_opts", "zstd", "blosc", "szip", "bzip2")


def portable_encoding(encoding: dict) -> dict:
    """A variable's encoding as both xarray engines (h5netcdf, netcdf4) write it again.

    A chunk filter only a plugin decodes (zstd, lz4) becomes deflate level 1 with the
    shuffle filter, the default cube's codec, which every reader decompresses; deflate,
    chunking, dtype and fill value are kept as read.
    """
    out = dict(encoding)
    filters = [out.pop(key, None) for key in _PLUGIN_KEYS]
    if any(f not in (None, False, "gzip") for f in filters):
        out.update(zlib=True, complevel=1, shuffle=True)
    return out


def _masked(var, done):
    """``var`` with the radii not ``done`` read as NaN, lazily: nothing is loaded until
    indexed, and then only the part indexed (``where`` would load the whole variable)."""
    import xarray as xr
    from xarray.core import indexing

    dtype = np.result_type(var.dtype, np.float32)
    array = indexing.LazilyIndexedArray(_masked_array_class()(var, done, dtype))
    return xr.Variable(var.dims, array, var.attrs, var.encoding)


_MASKED = []


def _masked_array_class():
    """The lazy masked backend array class (made on first use: xarray is imported lazily)."""
    if _MASKED:
        return _MASKED[0]
    from xarray.backends import BackendArray
    from xarray.core import indexing

    class MaskedArray(BackendArray):
        """Reads through the lazily opened variable; masks the radii that are not done
        (the first axis)."""

        def __init__(self, var, done, dtype):
            self.var, self.done = var, done
            self.shape, self.dtype = var.shape, np.dtype(dtype)

        def __getitem__(self, key):
            return indexing.explicit_indexing_adapter(
                key, self.shape, indexing.IndexingSupport.OUTER, self._get)

        _get = _masked_get

    _MASKED.append(MaskedArray)
    return MaskedArray


def _masked_get(self, key):
        data = np.asarray(self.var[key].values, dtype=self.dtype)
        keep = self.done[key[0]]
        if np.ndim(keep) == 0:
            return data if keep else np.full_like(data, np.nan)
        index = [slice(None)] * data.ndim
        index[0] = ~np.asarray(keep, bool)
        data = np.array(data, copy=True) if not data.flags.writeable else data
        data[tuple(index)] = np.nan
        return data
