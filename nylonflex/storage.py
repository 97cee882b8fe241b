"""The design cube on disk: NetCDF4/HDF5 written through h5netcdf, read with xarray.

Durability: a sweep journals every finished slab of radii as its own ``.npz`` file in
``<cube>.parts/`` (written to a temporary name, then renamed, so a slab file is whole or
absent; it holds the slab's compressed chunks, see :meth:`CubeFile.encode`) and writes the
same slab into ``<cube>.building``. Only a finished run renames
the building file to ``<cube>``: a killed run never leaves a file that reads as complete.
``--resume`` keeps the journal's slabs (if the config hash matches) and computes the rest.
A run stopped by Ctrl-C or SIGTERM also leaves ``<cube>`` with ``complete = "false"`` and a
``slab_done`` mask, so the part already done can be queried.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import shutil
import warnings
import zlib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from .units import InputError
from .variables import AXES, COORDS, CURVES, DESIGN

__all__ = ["CUBE_FORMAT", "VOLATILE_ATTRS", "CubeFile", "Journal", "cube_summary",
           "open_cube"]

#: Value of the ``nylonflex_cube`` attribute that marks a file as a cube of this format.
CUBE_FORMAT = "1"
#: Attributes that differ between two runs of the same config (timing, host, when).
VOLATILE_ATTRS = ("created", "run_seconds", "designs_per_second", "scheduler", "workers",
                  "resumed_slabs", "python_version", "hostname")

_COMPRESSION = {"compression": "gzip", "compression_opts": 1, "shuffle": True}


def _chunks(dims, sizes, radius_chunk):
    shape = [sizes[d] for d in dims]
    if dims and dims[0] == "radius":
        shape[0] = min(radius_chunk, shape[0])
    # keep chunks near or under 2 MB of float64 by halving the largest trailing dims
    while np.prod(shape) > 2**18 and max(shape[1:] or [1]) > 1:
        j = 1 + int(np.argmax(shape[1:]))
        shape[j] = (shape[j] + 1) // 2
    return tuple(int(x) for x in shape)


def slab_done_attrs() -> dict:
    """Attributes of the ``slab_done`` mask, in-memory and on-disk cubes alike."""
    return {"units": "1", "long_name": "radius computed",
            "description": "1 where this radius's slab is in the cube",
            "flag_values": np.array([0, 1], np.int8), "flag_meanings": "missing done"}


class CubeFile:
    """Writes one cube file slab by slab (h5netcdf; gzip level 1 with shuffle)."""

    def __init__(self, path, coords: dict, attrs: dict, radius_chunk: int):
        import h5netcdf

        self.path = Path(path)
        self.f = h5netcdf.File(self.path, "w")
        sizes = {name: len(values) for name, values in coords.items()}
        self.f.dimensions = sizes
        for name, values in coords.items():
            v = self.f.create_variable(name, (name,), "f8", data=np.asarray(values, float))
            v.attrs.update(COORDS[name].attrs())
        for var in (*DESIGN.values(), *CURVES.values()):
            fill = None if var.dtype == "int8" else np.nan
            v = self.f.create_variable(var.name, var.dims, var.dtype, fillvalue=fill,
                                       chunks=_chunks(var.dims, sizes, radius_chunk),
                                       **_COMPRESSION)
            v.attrs.update(var.attrs())
        done = self.f.create_variable("slab_done", ("radius",), "i1", fillvalue=None)
        done.attrs.update(slab_done_attrs())
        self.f.attrs.update(attrs)
        self._pool = ThreadPoolExecutor(2, thread_name_prefix="nylonflex-deflate")

    def write(self, i0: int, i1: int, arrays: dict):
        """Write the variables of radii [i0, i1) (and those without a radius dim)."""
        self.write_encoded(i0, i1, self.encode(i0, arrays))

    def encode(self, i0: int, arrays: dict) -> dict:
        """The slab of radii from ``i0`` as it will be stored: a flat dict of arrays.

        Chunks that lie wholly inside the slab are shuffled and deflated here, by a small
        thread pool (zlib releases the GIL; HDF5 would compress them one by one in the
        writing thread), as ``NAME:offsets``, ``NAME:sizes`` and ``NAME:bytes``; anything
        else stays a plain array under its name. The journal keeps exactly this, so a slab
        is compressed once and its journal file is as small as its share of the cube.
        """
        out, jobs = {}, []
        for name, data in arrays.items():
            var = self.f.variables[name]
            dset = var._h5ds
            i1 = i0 + (np.shape(data)[0] if var.dimensions else 0)
            if var.dimensions and var.dimensions[0] == "radius" and \
                    self._aligned(dset, i0, i1):
                jobs.append((name, list(self._compress(dset, i0, data))))
            else:
                out[name] = np.asarray(data)
        for name, chunks in jobs:
            blobs = [future.result() for _, future in chunks]
            out[f"{name}:offsets"] = np.array([off for off, _ in chunks], dtype=np.int64)
            out[f"{name}:sizes"] = np.array([len(b) for b in blobs], dtype=np.int64)
            out[f"{name}:bytes"] = np.frombuffer(b"".join(blobs), dtype=np.uint8)
        return out

    def write_encoded(self, i0: int, i1: int, encoded: dict):
        """Store what :meth:`encode` made for the radii [i0, i1)."""
        for key, value in encoded.items():
            name, _, part = key.partition(":")
            var = self.f.variables[name]
            if part == "offsets":
                sizes = encoded[f"{name}:sizes"]
                blob = encoded[f"{name}:bytes"]
                ends = np.cumsum(sizes)
                for offset, end, size in zip(value, ends, sizes):
                    var._h5ds.id.write_direct_chunk(tuple(int(x) for x in offset),
                                                    blob[end - size:end].tobytes())
            elif part:
                continue  # sizes and bytes go with their offsets
            elif var.dimensions and var.dimensions[0] == "radius":
                var[i0:i1] = value
            else:
                var[...] = value
        self.f.variables["slab_done"][i0:i1] = 1

    @staticmethod
    def _aligned(dset, i0, i1):
        rc = dset.chunks[0]
        return i0 % rc == 0 and (i1 % rc == 0 or i1 == dset.shape[0])

    def _compress(self, dset, i0, data):
        """Yield ``(chunk offset, future of its filtered bytes)`` for a slab's chunks."""
        chunks, shape = dset.chunks, dset.shape
        data = np.ascontiguousarray(data, dtype=dset.dtype)
        starts = [range(0, data.shape[0], chunks[0])] + \
            [range(0, n, c) for n, c in zip(shape[1:], chunks[1:])]
        for corner in itertools.product(*starts):
            block = data[tuple(slice(c, c + n) for c, n in zip(corner, chunks))]
            offset = (i0 + corner[0], *corner[1:])
            yield offset, self._pool.submit(_shuffle_deflate, block, chunks)

    def close(self, attrs: dict | None = None):
        self._pool.shutdown()
        if attrs:
            self.f.attrs.update(attrs)
        self.f.close()


def _shuffle_deflate(block, chunks):
    """HDF5's shuffle then deflate filters on one chunk (padded to the full chunk shape)."""
    if block.shape != tuple(chunks):
        full = np.zeros(chunks, dtype=block.dtype)
        full[tuple(slice(0, n) for n in block.shape)] = block
        block = full
    raw = np.ascontiguousarray(block).view(np.uint8)
    size = block.dtype.itemsize
    if size > 1:  # byte k of every element together, as H5Z_FILTER_SHUFFLE does
        raw = raw.reshape(-1, size).T
    return zlib.compress(np.ascontiguousarray(raw).tobytes(), _COMPRESSION["compression_opts"])


class Journal:
    """The ``<cube>.parts`` folder: a manifest and one ``.npz`` per finished slab."""

    def __init__(self, cube_path):
        self.dir = Path(str(cube_path) + ".parts")
        self.manifest = self.dir / "manifest.json"

    def exists(self) -> bool:
        return self.manifest.is_file()

    def read_manifest(self) -> dict:
        try:
            return json.loads(self.manifest.read_text())
        except (OSError, ValueError):
            return {}

    def start(self, manifest: dict):
        if self.dir.exists():
            shutil.rmtree(self.dir)
        self.dir.mkdir(parents=True)
        _atomic_write(self.manifest, json.dumps(manifest, indent=1).encode())

    def _slab_path(self, k):
        return self.dir / f"slab-{k:06d}.npz"

    def done(self) -> set[int]:
        out = set()
        for p in self.dir.glob("slab-*.npz"):
            with contextlib.suppress(ValueError):
                out.add(int(p.stem.split("-")[1]))
        return out

    def save(self, k: int, arrays: dict):
        tmp = self._slab_path(k).with_suffix(".tmp")
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
        os.replace(tmp, self._slab_path(k))

    def load(self, k: int) -> dict:
        with np.load(self._slab_path(k)) as z:
            return {name: z[name] for name in z.files}

    def remove(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def _atomic_write(path: Path, data: bytes):
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


@contextlib.contextmanager
def exclusive(cube_path):
    """Hold ``<cube>.lock`` for a run; a second run on the same output is refused."""
    import fcntl

    lock = Path(str(cube_path) + ".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    fh = open(lock, "a+")
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise RuntimeError(f"another sweep is writing {cube_path} (lock {lock}); "
                           "wait for it or stop it first") from None
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            lock.unlink()
        fcntl.flock(fh, fcntl.LOCK_UN)
        fh.close()


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
    ds = xr.open_dataset(path, engine="h5netcdf")
    if attrs.get("complete") != "true":
        done = ds["slab_done"].values.astype(bool)
        if not quiet:
            warnings.warn(f"{path} is incomplete: {int(done.sum())} of {done.size} radii "
                          "computed; the rest is masked", stacklevel=2)
        mask = xr.DataArray(done, dims=("radius",), coords={"radius": ds["radius"]})
        for name in list(DESIGN) + list(CURVES):
            if "radius" in ds[name].dims:
                ds[name] = ds[name].where(mask)
    return ds


def cube_summary(path) -> list[str]:
    """Lines that describe a cube: dims, ranges, variables, provenance, completeness."""
    from .variables import VARIABLES, to_display

    path = Path(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = open_cube(path, quiet=True)
    a = ds.attrs
    out = []
    complete = a.get("complete") == "true"
    done = int(ds["slab_done"].sum())
    out.append(f"cube      {path}")
    out.append(f"name      {a.get('name')}   config sha256 {a.get('config_sha256', '')[:16]}")
    out.append(f"status    {'complete' if complete else 'INCOMPLETE'} "
               f"({done}/{ds.sizes['radius']} radii)")
    n = int(np.prod([ds.sizes[d] for d in AXES]))
    out.append(f"designs   {n:,} = " + " x ".join(f"{ds.sizes[d]} {d}" for d in AXES))
    out.append("axes")
    for name in (*AXES, "stroke", "pressure"):
        v = VARIABLES[name]
        vals = to_display(name, ds[name].values)
        unit = "" if v.display == "1" else f" {v.display}"
        out.append(f"  {name:<15} {vals.min():g} .. {vals.max():g}{unit} ({len(vals)})")
    out.append("variables")
    for name in ds.data_vars:
        if name == "slab_done":
            continue
        out.append(f"  {name:<18} ({', '.join(ds[name].dims)}) [{ds[name].attrs.get('units')}] "
                   f"{ds[name].attrs.get('long_name')}")
    out.append("provenance")
    for key in ("nylonflex_version", "numba_version", "numpy_version", "silicone", "nylon",
                "quadrature", "created", "run_seconds", "designs_per_second", "workers",
                "scheduler"):
        if key in a:
            out.append(f"  {key:<18} {a[key]}")
    ds.close()
    return out
