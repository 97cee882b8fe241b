"""A cube described without xarray: ``nylonflex info``'s summary (dims, ranges, flags,
provenance, completeness) and the check of its chunks, read through h5py alone."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..variables import AXES, SPREAD_OF, VARIABLES, is_complete, to_display
from .codec import require_filters
from .decode import deflate_only, inflate
from .netcdf4 import STORED_DIMS, read_layout
from .reader import _attr, check_chunk_sizes, checked_attrs, cube_attrs

__all__ = ["check_cube", "cube_description", "cube_summary", "flag_histogram",
           "summary_lines"]


def _validity_counts(h5, dims, done) -> dict | None:
    """How many designs carry each validity bit (docs/model.md s. 17), per model.

    ``h5`` is the open cube (h5py), ``dims`` its variables' dimensions
    (:func:`~.netcdf4.read_layout`), ``done`` the radii computed (bool). Counted from a
    histogram of the flag bytes, radius slab by radius slab (one chunk row at a time): no
    copy of the flags wider than a byte, memory bounded by one slab. None without flags.
    """
    if "validity" not in dims:
        return None
    var = h5["validity"]
    counts = _byte_histogram(var, dims["validity"][:1] == ("radius",), done)
    meanings = str(var.attrs.get("flag_meanings", "")).split()
    bits = [int(x) for x in np.atleast_1d(var.attrs.get("flag_masks", []))]
    values = np.arange(256, dtype=np.uint8)  # each byte's value as the variable stores it
    values = (values.view(np.int8) if np.dtype(var.dtype).kind == "i" else values) \
        .astype(np.int64)
    return {"flagged": int(counts[values > 0].sum()), "values": int(counts.sum()),
            "over": [w for d, w in (("model", "model"), ("cooling", "cooling set"))
                     if d in dims["validity"]],
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
    with h5py.File(path, "r") as f:
        return _unreadable(f, path, full, progress)


def _unreadable(f, path, full, progress=None) -> list[str]:
    """:func:`check_cube`'s lines for the cube open in h5py as ``f`` (checked already)."""
    import h5py

    problems = []
    found = [(n, obj) for n, obj in f.items() if isinstance(obj, h5py.Dataset)]
    for k, (name, dset) in enumerate(found, 1):
        if dset.shape and dset.size:
            problems.extend(_check_dataset(path, name, dset, full))
        if progress is not None:
            progress(k, len(found))
    return problems


def _check_dataset(path, name, dset, full):
    """Lines for the chunks of ``dset`` that cannot be read."""
    if not full and dset.chunks is not None and deflate_only(dset):
        return _check_first_stored_chunk(path, name, dset)
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


def _check_first_stored_chunk(path, name, dset) -> list[str]:
    """The spot check of ``info``: the first stored chunk of a deflated ``dset``, its
    bytes read as stored and inflated (which checks the stream and its Adler-32, as HDF5's
    deflate filter does), to the chunk's size [bytes]; the shuffle, a permutation of the
    bytes, cannot fail. A quarter of decoding the chunk through HDF5 (a sweep's cube of 21
    variables: 25 ms against 98 ms). A chunk never written (a stopped sweep) is no problem.
    """
    if dset.id.get_num_chunks() == 0:
        return []
    info = dset.id.get_chunk_info(0)
    nbytes = int(np.prod(dset.chunks, dtype=np.int64)) * dset.dtype.itemsize
    try:
        mask, raw = dset.id.read_direct_chunk(info.chunk_offset)
        if mask:  # a filter skipped for this chunk: let HDF5 decode it
            dset[tuple(slice(o, o + c) for o, c in zip(info.chunk_offset, dset.chunks))]
        elif len(inflate(raw)) != nbytes:
            raise ValueError(f"inflates to the wrong size (expected {nbytes} bytes)")
    except Exception as exc:  # noqa: BLE001 - any decoder's error is a damaged chunk
        where = ", ".join(f"{o}:{min(o + c, n)}" for o, c, n in
                          zip(info.chunk_offset, dset.chunks, dset.shape))
        reason = " ".join(str(exc).split())[:120]
        return [f"{path}: variable {name} [{where}] cannot be read ({reason}); "
                "the cube is damaged: sweep it again with --overwrite"]
    return []


def _spread_lines(variants) -> list[str]:
    """``info``'s lines of a cube with a model spread: its variants and variables."""
    return [f"spread    over {len(variants)} model variants (fidelity: spread): "
            f"{', '.join(variants)}",
            f"          <var>_model_lo/_hi of {', '.join(SPREAD_OF)}; validity_model_any: "
            "their flags ORed"]


def cube_description(path) -> dict:
    """A cube described as data (``nylonflex info --format json``): dims, ranges (SI and
    the display unit), variables, flags, provenance and completeness.

    Read through h5py (the netCDF-4 layout from :func:`~.netcdf4.read_layout`; no
    h5netcdf, xarray, pandas or dask): the coordinates, the attributes, ``slab_done`` and
    the flag bytes (:func:`_validity_counts`).
    """
    import h5py

    a = checked_attrs(path)  # open_cube's refusals, in its words
    path = Path(path)
    d = {"cube": str(path), "name": str(a.get("name"))[:80],
         "config_sha256": str(a.get("config_sha256", ""))}
    complete = is_complete(a)
    with h5py.File(path, "r") as f:
        sizes, dims = read_layout(f)
        h5 = {name: f[name] for name in dims}  # each looked up once (about 0.1 ms a lookup)
        done_flags = np.asarray(h5["slab_done"][...]).astype(bool)
        # a spot check: the first chunk of each variable read ('info --check' reads all)
        d["damaged"] = _unreadable(f, path, full=False)
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
            d["validity"] = _validity_counts(h5, dims, done_flags if not complete else
                                             np.ones_like(done_flags))
        except (OSError, ValueError, RuntimeError):
            d["validity"] = "unreadable"
        d["axes"] = {}
        for name in (*AXES, "stroke", "pressure"):
            v = VARIABLES[name]
            vals = np.asarray(h5[name][...], dtype=float)
            d["axes"][name] = {"min": float(vals.min()), "max": float(vals.max()),
                               "count": len(vals), "units": v.units, "display": v.display,
                               "stored_over": dims[name][0]}
        d["variables"] = {}
        logical = {dim: name for name, dim in STORED_DIMS.items()}
        for name in _data_vars(h5, sizes, dims):
            if name == "slab_done":
                continue
            var = h5[name]
            d["variables"][name] = {
                "dims": [logical.get(x, x) for x in dims[name]],  # as open_cube has them
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


def _data_vars(h5, sizes, dims) -> list[str]:
    """The data variables of a netCDF-4 file open in h5py (``sizes`` and ``dims`` its
    :func:`~.netcdf4.read_layout`), in file order, as xarray names them: every variable
    that is neither a dimension's coordinate nor named in a variable's ``coordinates``
    attribute."""
    named = set()
    for name in dims:
        named.update(str(_attr(h5[name].attrs.get("coordinates", ""))).split())
    return [n for n in dims if n not in sizes and n not in named]
