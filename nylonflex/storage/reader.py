"""Reading cubes: open one lazily as an xarray Dataset, its attributes, a summary."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..units import InputError
from ..variables import (AXES, CURVES, DESIGN, SPREAD, SPREAD_OF, UNCERTAIN, VARIABLES,
                         is_complete, to_display, validate)
from .cube import STORED_DIMS, require_filters
from .journal import Journal

__all__ = ["MAX_CHUNK_BYTES", "MAX_AXIS_VALUES", "check_cube", "check_chunk_sizes",
           "cube_attrs", "cube_description", "cube_summary", "logical_dims", "open_cube",
           "summary_lines"]

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

    path = Path(path)
    if not path.exists():
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
    ds = logical_dims(xr.open_dataset(path, engine="h5netcdf"))
    for var in ds.variables.values():
        var.encoding = portable_encoding(var.encoding)
    try:
        validate(ds)  # the registry's dimensions, units and dtypes (metadata only)
    except ValueError as err:
        ds.close()
        raise InputError(f"{path}: {err}") from None
    if not is_complete(attrs):
        done = ds["slab_done"].values.astype(bool)
        if not quiet:
            warnings.warn(f"{path} is incomplete: {int(done.sum())} of {done.size} radii "
                          "computed; the rest is masked", stacklevel=2)
        for name in [n for n in ds.data_vars
                     if n in {**DESIGN, **CURVES, **UNCERTAIN, **SPREAD}]:
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


def _validity_counts(f, h5, done) -> dict | None:
    """How many designs carry each validity bit (docs/model.md s. 17), per model.

    ``f`` is the open cube (h5netcdf), ``h5`` the same file in h5py (its data reads
    fast), ``done`` the radii computed (bool). Counted from a
    histogram of the flag bytes, radius slab by radius slab (one chunk row at a time): no
    copy of the flags wider than a byte, memory bounded by one slab. None without flags.
    """
    if "validity" not in f.variables:
        return None
    var = f.variables["validity"]
    counts = _byte_histogram(h5["validity"], var.dimensions[:1] == ("radius",), done)
    meanings = str(var.attrs.get("flag_meanings", "")).split()
    bits = [int(x) for x in np.atleast_1d(var.attrs.get("flag_masks", []))]
    values = np.arange(256, dtype=np.uint8)  # each byte's value as the variable stores it
    values = (values.view(np.int8) if np.dtype(var.dtype).kind == "i" else values) \
        .astype(np.int64)
    return {"flagged": int(counts[values > 0].sum()), "values": int(counts.sum()),
            "over": [w for d, w in (("model", "model"), ("cooling", "cooling set"))
                     if d in var.dimensions],
            "by_flag": {name: int(counts[(values & bit) > 0].sum())
                        for bit, name in zip(bits, meanings)}}


def _validity_line(v) -> str:
    per = f" (counted over every {' and '.join(v['over'])})" if v["over"] else ""
    return (f"flagged   {v['flagged']:,} of {v['values']:,} design values "
            f"({100 * v['flagged'] / (v['values'] or 1):.1f} %){per}: "
            + ", ".join(f"{name} {n:,}" for name, n in v["by_flag"].items()))


def flag_histogram(flags, piece: int = 1 << 18) -> np.ndarray:
    """How many of ``flags`` (an array of one-byte integers) hold each byte value [-].

    Returns 256 counts, index ``b`` the unsigned byte ``b`` (an int8 -1 counts at 255):
    ``np.bincount`` over a ``uint8`` view, a piece of ``piece`` bytes at a time (bincount
    takes its input as intp: a piece's copy is 8 bytes a flag, never the whole array's).
    """
    flags = np.ascontiguousarray(flags)
    if flags.dtype.itemsize != 1:
        raise ValueError(f"flags: one-byte integers expected, not {flags.dtype}")
    raw = flags.view(np.uint8).reshape(-1)
    counts = np.zeros(256, dtype=np.int64)
    for start in range(0, raw.size, piece):
        counts += np.bincount(raw[start:start + piece], minlength=256)
    return counts


def _byte_histogram(dset, radial, done) -> np.ndarray:
    """:func:`flag_histogram` of a one-byte h5py dataset, over the radii ``done`` when its
    first axis is the radius (``radial``), read a few MB of whole chunk rows at a time."""
    counts = np.zeros(256, dtype=np.int64)
    if not dset.shape or not dset.size:
        return counts
    row = max(1, dset.size // dset.shape[0])
    chunk = dset.chunks[0] if dset.chunks else 1
    step = chunk * max(1, (4 << 20) // (row * chunk))
    for start in range(0, dset.shape[0], step):
        stop = min(start + step, dset.shape[0])
        keep = done[start:stop] if radial else np.ones(stop - start, dtype=bool)
        if not keep.any():
            continue
        block = dset[start:stop]
        counts += flag_histogram(block if keep.all() else block[keep])
    return counts


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


def check_cube(path, *, full: bool = True, progress=None) -> list[str]:
    """Read a cube's stored chunks and say which cannot be read, one line each.

    Each variable is read chunk by chunk (memory bounded by one chunk), so that a cube
    marked complete whose bytes are damaged is found (its compressed chunks fail to
    decode). Chunks a stopped sweep never wrote read as fill and are not problems. A cube
    written without compression (``compression: none``) has no redundancy to check: a
    damaged chunk of it reads as wrong numbers, not as an error.

    Parameters
    ----------
    path : path
        A nylonflex cube [-].
    full : bool
        Read every chunk (True) or only the first chunk of each variable (False) [-].
    progress : callable, optional
        Called as ``progress(done, total)`` [variables] after each variable.

    Returns
    -------
    list of str
        One line per unreadable chunk (variable, its index range, the error); empty when
        every chunk read.
    """
    import h5py

    check_chunk_sizes(path)
    require_filters((cube_attrs(path) or {}).get("compression"))
    problems = []
    with h5py.File(path, "r") as f:
        names = [n for n, obj in f.items() if isinstance(obj, h5py.Dataset)]
        for k, name in enumerate(names, 1):
            dset = f[name]
            if dset.shape and dset.size:
                problems.extend(_check_dataset(path, name, dset, full))
            if progress is not None:
                progress(k, len(names))
    return problems


def _check_dataset(path, name, dset, full):
    """Lines for the chunks of ``dset`` that cannot be read."""
    if dset.chunks is None:  # contiguous (small): read in blocks of the first axis
        step = max(1, (1 << 24) // max(1, dset.dtype.itemsize * (dset.size // dset.shape[0])))
        blocks = [(slice(i, min(i + step, dset.shape[0])),) for i in
                  range(0, dset.shape[0], step)]
    else:
        blocks = dset.iter_chunks()
    out = []
    for sel in blocks:
        try:
            dset[sel]
        except (OSError, ValueError, RuntimeError) as exc:
            where = ", ".join(f"{s.start}:{s.stop}" for s in sel)
            reason = " ".join(str(exc).split())[:120]
            out.append(f"{path}: variable {name} [{where}] cannot be read ({reason}); "
                       "the cube is damaged: sweep it again with --overwrite")
        if not full:
            break
    return out


def _spread_lines(variants) -> list[str]:
    """``info``'s lines of a cube with a model spread: its variants and variables."""
    return [f"spread    over {len(variants)} model variants (fidelity: spread): "
            f"{', '.join(variants)}",
            f"          <var>_model_lo/_hi of {', '.join(SPREAD_OF)}; validity_model_any: "
            "their flags ORed"]


def cube_description(path) -> dict:
    """A cube described as data (``nylonflex info --format json``): dims, ranges (SI and
    the display unit), variables, flags, provenance and completeness.

    Read through h5netcdf (the netCDF-4 layout, no xarray, pandas or dask): the
    coordinates, the attributes, ``slab_done`` and the flag bytes (:func:`_validity_counts`).
    """
    import h5netcdf
    import h5py

    path = Path(path)
    a = cube_attrs(path)
    if a is None:
        if not path.exists():
            open_cube(path)  # the missing-cube message, with a journal's hint
        raise InputError(f"{path}: not a nylonflex cube (expected a NetCDF4/HDF5 file "
                         "written by 'nylonflex sweep')")
    check_chunk_sizes(path)
    require_filters(a.get("compression"))
    d = {"cube": str(path), "name": str(a.get("name"))[:80],
         "config_sha256": str(a.get("config_sha256", ""))}
    complete = is_complete(a)
    with h5py.File(path, "r") as h5, h5netcdf.File(h5, "r") as f:
        sizes = {name: int(size) for name, size in
                 ((n, f.dimensions[n].size) for n in f.dimensions)}
        done_flags = np.asarray(h5["slab_done"][...]).astype(bool)
        # a spot check: the first chunk of each variable read ('info --check' reads all)
        d["damaged"] = check_cube(path, full=False)
        d["status"] = "DAMAGED" if d["damaged"] else "complete" if complete else "INCOMPLETE"
        d["radii_done"], d["radii"] = int(np.sum(done_flags, dtype=np.int64)), sizes["radius"]
        d["shape"] = {ax: sizes[ax] for ax in AXES}
        d["designs"] = int(np.prod(list(d["shape"].values())))
        for cat in ("model", "cooling"):
            if cat in sizes:
                d[cat] = [_text(m) for m in np.asarray(h5[cat][...]).reshape(-1)]
        if "model_spread" in a:  # fidelity: spread (docs/model.md s. 23)
            d["model_spread"] = _text(a["model_spread"]).split()
        supply = a.get("supply_voltage", "none")  # [V] float64; text before cube format 2
        if supply != "none":
            d["supply_voltage"] = supply
        try:
            d["validity"] = _validity_counts(f, h5, done_flags if not complete else
                                             np.ones_like(done_flags))
        except (OSError, ValueError, RuntimeError):
            d["validity"] = "unreadable"
        d["axes"] = {}
        for name in (*AXES, "stroke", "pressure"):
            v = VARIABLES[name]
            vals = np.asarray(h5[name][...], dtype=float)
            d["axes"][name] = {"min": float(vals.min()), "max": float(vals.max()),
                               "count": len(vals), "units": v.units, "display": v.display,
                               "stored_over": f.variables[name].dimensions[0]}
        d["variables"] = {}
        logical = {dim: name for name, dim in STORED_DIMS.items()}
        for name in _data_vars(f):
            if name == "slab_done":
                continue
            var = f.variables[name]
            d["variables"][name] = {
                "dims": [logical.get(x, x) for x in var.dimensions],  # as open_cube has them
                "units": _attr(var.attrs.get("units")),
                "long_name": _attr(var.attrs.get("long_name"))}
    d["provenance"] = {key: a[key] for key in (
        "nylonflex_version", "numba_version", "numpy_version", "silicone", "nylon",
        "quadrature", "created", "run_seconds", "designs_per_second", "workers",
        "scheduler") if key in a}
    return d


def cube_summary(path) -> list[str]:
    """Lines that describe a cube (``nylonflex info``): :func:`cube_description` as text."""
    return summary_lines(cube_description(path))


def summary_lines(d: dict) -> list[str]:
    """The text of a :func:`cube_description`, in display units."""
    out = [f"cube      {d['cube']}",
           f"name      {d['name']}   config sha256 {d['config_sha256'][:16]}",
           f"status    {d['status']} ({d['radii_done']}/{d['radii']} radii)"]
    out.extend(f"damaged   {line}" for line in d["damaged"])
    out.append(f"designs   {d['designs']:,} = " + " x ".join(f"{n} {ax}"
                                                           for ax, n in d["shape"].items()))
    if "model" in d:
        out.append("models    " + ", ".join(d["model"]))
    if "model_spread" in d:
        out.extend(_spread_lines(d["model_spread"]))
    if "cooling" in d:
        out.append("cooling   " + ", ".join(d["cooling"]))
    if "supply_voltage" in d:
        supply = d["supply_voltage"]
        out.append(f"supply    {supply if isinstance(supply, str) else f'{supply:g} V'}")
    if d["validity"] == "unreadable":
        out.append("flagged   (the validity flags cannot be read)")
    elif d["validity"] is not None:
        out.append(_validity_line(d["validity"]))
    out.append("axes")
    for name, ax in d["axes"].items():
        unit = "" if ax["display"] == "1" else f" {ax['display']}"
        where = f"; in the file over the dimension {ax['stored_over']}" \
            if ax["stored_over"] != name else ""
        out.append(f"  {name:<15} {to_display(name, ax['min']):g} .. "
                   f"{to_display(name, ax['max']):g}{unit} ({ax['count']}{where})")
    out.append("variables")
    for name, var in d["variables"].items():
        out.append(f"  {name:<18} ({', '.join(var['dims'])}) [{var['units']}] "
                   f"{var['long_name']}")
    out.append("provenance")
    out.extend(f"  {key:<18} {str(value)[:200]}" for key, value in d["provenance"].items())
    return out


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _data_vars(f) -> list[str]:
    """The data variables of an open netCDF-4 file, in file order, as xarray names them:
    every variable that is neither a dimension's coordinate nor named in a variable's
    ``coordinates`` attribute."""
    named = set()
    for var in f.variables.values():
        named.update(str(_attr(var.attrs.get("coordinates", ""))).split())
    return [n for n in f.variables if n not in f.dimensions and n not in named]
