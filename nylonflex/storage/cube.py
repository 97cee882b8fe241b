"""Writing the cube file: netCDF-4/HDF5 through h5py, slab by slab, chunks compressed once
(:mod:`.codec`)."""

from __future__ import annotations

import contextlib
import json
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..variables import COOLING, COORDS, CURVES, DESIGN, MODEL, slab_done_attrs
from .codec import (CODECS, DEFAULT_CODEC, ZSTD_EXTRA, ChunkPlan, SlabEncoder, aligned,
                    chunk_shape, compiled_shuffle, load_filter_plugins)
from .netcdf4 import STORED_DIMS, NetCDF4File, stored_dims

__all__ = ["CubeFile"]


@dataclass(frozen=True)
class _Layout:
    """A cube variable's HDF5 dataset, its dimension names, chunk shape, shape and dtype."""

    dset: object
    dims: tuple
    chunks: tuple | None
    shape: tuple
    dtype: np.dtype

    def aligned(self, i0: int, i1: int) -> bool:
        """Whether radii [i0, i1) cover whole chunks (the last may end with the axis)."""
        return aligned(self.chunks, self.shape, i0, i1)




class CubeFile:
    """Writes one cube file slab by slab (netCDF-4 through h5py, :mod:`.netcdf4`; the codec
    of :data:`CODECS` it is given, deflate (gzip) by default, with the shuffle filter where the codec
    has it)."""

    def __init__(self, path, coords: dict, attrs: dict, radius_chunk: int,
                 codec: str = DEFAULT_CODEC, variables: dict | None = None,
                 models=("paper",), coolings=()):
        import h5py

        self.codec = CODECS[codec]
        if self.codec.plugin and not load_filter_plugins():
            raise RuntimeError(f"compression: {codec}: {ZSTD_EXTRA}")
        self.path = Path(path)
        # the caller holds the writer's lock on this file (storage.journal.exclusive), so
        # HDF5's own lock, which would conflict with it, is off
        self.f = NetCDF4File(self.path)
        sizes = {STORED_DIMS.get(name, name): len(values) for name, values in coords.items()}
        for name, values in coords.items():
            if name in STORED_DIMS:  # an auxiliary coordinate over a dimension of its own
                self.f.dimension(STORED_DIMS[name], len(values))
                self.f.variable(name, (STORED_DIMS[name],), "f8", COORDS[name].attrs(),
                                data=np.asarray(values, float))
            else:
                self.f.coordinate(name, np.asarray(values, float), COORDS[name].attrs())
        if len(models) > 1:  # the string dimension of a cube of several model variants
            sizes["model"] = len(models)
            self.f.coordinate("model", np.array(models, dtype=object), MODEL.attrs(),
                              dtype=h5py.string_dtype())
        if len(coolings) > 1:  # the string dimension of a cube of several cooling sets
            sizes["cooling"] = len(coolings)
            self.f.coordinate("cooling", np.array(coolings, dtype=object), COOLING.attrs(),
                              dtype=h5py.string_dtype())
        # the variables the config asks for, {name: (registry entry, dims)}; a plain
        # sweep's by default
        if variables is None:
            variables = {n: (v, v.dims) for n, v in {**DESIGN, **CURVES}.items()}
        for var, dims in variables.values():
            fill = None if var.dtype == "int8" else np.nan
            dims, var_attrs = stored_dims(dims), var.attrs()
            aux = [name for name, dim in STORED_DIMS.items() if dim in dims]
            if aux:
                var_attrs["coordinates"] = " ".join(aux)
            self.f.variable(var.name, dims, var.dtype, var_attrs, fillvalue=fill,
                            chunks=chunk_shape(dims, sizes, radius_chunk),
                            **self.codec.filters)
        self.f.variable("slab_done", ("radius",), "i1", slab_done_attrs())
        self.f.set_attrs({**attrs, "compression": self.codec.name})
        # each variable's dataset and layout, looked up once (an h5py lookup costs about
        # 0.1 ms with the GIL held, several a variable a slab)
        self._layout = {name: _Layout(ds, self.f.dims[name], ds.chunks, ds.shape, ds.dtype)
                        for name, ds in self.f.datasets.items()}
        self.encoder = SlabEncoder(
            {name: ChunkPlan(lay.dims, lay.chunks, lay.shape, lay.dtype.str)
             for name, lay in self._layout.items()}, self.codec.name,
            compiled_shuffle(sum(lay.dset.size * lay.dtype.itemsize
                                 for lay in self._layout.values())))
        self._pool = ThreadPoolExecutor(2, thread_name_prefix="nylonflex-deflate")

    def decoding(self) -> str:
        """How this file's stored chunks decode: the codec, its filters and each variable's
        dtype and chunk shape (what a journaled slab's digest covers, so that a journal
        whose codec was edited is recomputed, never trusted) [-]."""
        return json.dumps({"codec": self.codec.name, "filters": self.codec.filters,
                           "shuffle": self.codec.shuffle,
                           "chunks": {name: [list(lay.chunks or ()), lay.dtype.str]
                                      for name, lay in self._layout.items()}},
                          sort_keys=True, default=str)

    def write(self, i0: int, i1: int, arrays: dict):
        """Write the variables of radii [i0, i1) (and those without a radius dim)."""
        self.write_encoded(i0, i1, self.encode(i0, arrays))

    def encode(self, i0: int, arrays: dict) -> dict:
        """The slab of radii from ``i0`` as it will be stored: a flat dict of arrays.

        Chunks that lie wholly inside the slab are shuffled and compressed here, by a small
        thread pool (zlib, zstd and the compiled shuffle release the GIL; HDF5 would
        compress them one by one in the writing thread), as ``NAME:offsets``,
        ``NAME:sizes`` and ``NAME:bytes``; anything else stays a plain array under its
        name. The journal keeps exactly this, so a slab is compressed once and its journal
        file is as small as its share of the cube.
        """
        return self.encode_finish(self.encode_start(i0, arrays))

    def encode_start(self, i0: int, arrays: dict):
        """Submit a slab's chunks to the compression pool; :meth:`encode_finish` collects.

        Called from the thread that computed the slab, so its compression overlaps the
        storing of the previous slab (and the computing of the next).
        """
        return self.encoder.start(i0, arrays, self._pool.submit)

    @staticmethod
    def encode_finish(started) -> dict:
        """Wait for the chunks :meth:`encode_start` submitted: the dict :meth:`encode` gives."""
        return SlabEncoder.finish(started)

    def remote_encoder(self) -> SlabEncoder | None:
        """What encodes this cube's slabs away from the file (a Dask worker), or None when
        HDF5 compresses them itself (lz4: the chunks are written as plain arrays)."""
        return self.encoder if self.codec.encode is not None else None

    def write_encoded(self, i0: int, i1: int, encoded: dict) -> dict:
        """Store what :meth:`encode` made for the radii [i0, i1); return where each
        compressed chunk now lies in the file: ``{NAME:addresses: byte offsets [B]}``, in
        the order of ``NAME:offsets`` (HDF5 writes a chunk given whole at once, with
        ``pwrite``, at an address it never moves: what the journal records,
        :func:`nylonflex.storage.restore.journal_record`)."""
        addresses = {}
        for key, value in encoded.items():
            name, _, part = key.partition(":")
            layout = self._layout[name]
            if part == "offsets":
                addresses[f"{name}:addresses"] = self._write_chunks(
                    layout.dset.id, value, encoded[f"{name}:sizes"], encoded[f"{name}:bytes"])
            elif part:
                continue  # sizes, CRCs and bytes go with their offsets
            elif layout.dims and layout.dims[0] == "radius":
                layout.dset[i0:i1] = value
            else:
                layout.dset[...] = value
        self._layout["slab_done"].dset[i0:i1] = 1
        return addresses

    @staticmethod
    def _write_chunks(dsid, offsets, sizes, data) -> np.ndarray:
        """Write chunks (``offsets`` [-], ``sizes`` [B], their bytes one after another in
        ``data``); their byte offsets in the file [B]."""
        blob, end, where = memoryview(data), 0, []
        for offset, size in zip(offsets.tolist(), sizes.tolist()):
            dsid.write_direct_chunk(tuple(offset), blob[end:end + size])  # a view: no copy
            where.append(dsid.get_chunk_info_by_coord(tuple(offset)).byte_offset)
            end += size
        return np.array(where, dtype=np.int64)

    def sync(self):
        """Make what was written to the file so far durable (``fsync`` of its descriptor;
        the chunks a journal record points to, before that record is written)."""
        os.fsync(self.f.fd)

    def abandon(self):
        """Close after a failure (a full disk, an error) without raising, and without
        writing anything more to the disk.

        A failed run's file is never published, but its chunks are what the journal's
        records point to (``--resume`` reads them back), so its bytes stay; its
        descriptor is pointed at a memory file first (:func:`_divert`): whatever HDF5
        still flushes as it closes (chunk caches, metadata) then goes there and cannot
        fail, nor write over what is on disk. A close that failed partway left HDF5 ids
        half closed, and a second close freed them again: a segfault on a full disk (exit
        139 when the disk filled while the finished cube was being closed). A file whose
        close already failed is therefore never closed again (:meth:`NetCDF4File.close`).
        """
        self._pool.shutdown(cancel_futures=True)
        with contextlib.suppress(OSError):  # the descriptor read at open: no HDF5 call
            _divert(self.f.fd)  # what HDF5 still writes, now or at exit, goes to memory
        if self.f.close_failed:
            return  # its objects are parked: freeing them again is what crashed
        with contextlib.suppress(Exception):
            self.f.h5.close()

    def close(self, attrs: dict | None = None):
        """Write the final root attributes ``attrs`` and close the file."""
        self._pool.shutdown()
        if attrs:
            self.f.set_attrs(attrs)
        self.f.close()


def _divert(fd: int):
    """Point the descriptor ``fd`` at a new empty memory file (Linux ``memfd_create``):
    writes to it then succeed whatever the disk, and the disk file keeps what it held.
    Does nothing where there is no memory file."""
    if not hasattr(os, "memfd_create"):  # pragma: no cover - not Linux
        return
    mem = os.memfd_create("nylonflex-abandoned", getattr(os, "MFD_CLOEXEC", 0))
    try:
        os.dup2(mem, fd, inheritable=False)
    finally:
        os.close(mem)


