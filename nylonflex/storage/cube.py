"""Writing the cube file: netCDF-4/HDF5 through h5py, slab by slab, chunks compressed once."""

from __future__ import annotations

import contextlib
import itertools
import json
import os
import threading
import zlib
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from pathlib import Path

import numpy as np

try:
    from isal import isal_zlib
except ImportError:  # pragma: no cover - isal is a dependency
    isal_zlib = None

from ..variables import COOLING, COORDS, CURVES, DESIGN, MODEL, slab_done_attrs
from .netcdf4 import NetCDF4File

__all__ = ["CODECS", "DEFAULT_CODEC", "STORED_DIMS", "Codec", "CubeFile", "MissingPlugin",
           "chunk_shape", "compiled_shuffle", "encode_chunk", "require_filters",
           "stored_dims"]

#: Axes a cube stores as an auxiliary coordinate over a dimension of another name (cube
#: format 3): {axis: its dimension in the file}. compliance-checker (cf:1.8, s. 5.1) asks a
#: dimension *named* ``pressure`` for ``standard_name = air_pressure``, which the chamber's
#: gauge pressure is not (CF's air_pressure is the absolute pressure of the air). So the
#: curves ``bend_angle`` and ``tip_force`` lie over ``pressure_point`` in the file, with
#: ``coordinates = "pressure"``: every reader still finds the variable ``pressure`` [Pa],
#: and :func:`nylonflex.open_cube` makes it the dimension again (``ds.sel(pressure=...)``).
STORED_DIMS = {"pressure": "pressure_point"}


def stored_dims(dims) -> tuple:
    """A variable's dimensions as the file names them (:data:`STORED_DIMS`)."""
    return tuple(STORED_DIMS.get(d, d) for d in dims)


@dataclass(frozen=True)
class Codec:
    """How the cube's chunks are compressed.

    ``filters`` are the HDF5 dataset options; ``encode(raw_bytes)`` compresses a chunk the
    way that filter pipeline would (after the shuffle when ``shuffle``), so slabs can be
    compressed by a thread pool and written directly; None lets HDF5 compress instead.
    ``plugin``: readers need the hdf5plugin package (``import hdf5plugin``) to open it.
    """

    name: str
    filters: dict
    encode: object
    shuffle: bool
    plugin: bool
    readers: str


#: zstd's level: -1 (the first of its fast levels) stores the cube's shuffled floats in the
#: same bytes as level 1 (70.1 MB for the 2 M-design perf grid, within 0.3 %) at about 1.3x
#: the speed; the level does not matter to a reader.
ZSTD_LEVEL = -1

#: ISA-L's deflate level for the default codec: 0, its fastest. On the shuffled chunks of
#: the 2 M-design bench cube it encodes at zstd -1's speed (0.34 CPU s for 320 MB) into
#: 96.8 MB against zstd's 76.2 MB; its level 1 is slower and larger (113 MB), zlib level 1
#: 8x slower (78.3 MB), libdeflate level 1 3.3x slower and holds the GIL (78.9 MB).
ISAL_LEVEL = 0

#: Uncompressed bytes [B] of a cube from which its chunks are shuffled by the compiled loop
#: (:mod:`nylonflex.kernels.bytes`, about 10 GB/s) instead of NumPy's strided copy (about
#: 2 GB/s): below it, NumPy's extra time (under 30 ms) is less than the compiled loop's
#: first compile (0.4-0.6 s with an empty cache), which the README's main job (3.5 MB)
#: would otherwise pay. Both give the same bytes (:func:`compiled_shuffle` decides, for the
#: cube and for the dry run's sample alike).
COMPILED_SHUFFLE_BYTES = 64 * 2**20


def compiled_shuffle(raw_bytes: int) -> bool:
    """Whether a cube of ``raw_bytes`` [B] uncompressed is shuffled by the compiled loop
    (else by NumPy, the same bytes): :data:`COMPILED_SHUFFLE_BYTES`."""
    return raw_bytes >= COMPILED_SHUFFLE_BYTES

#: Each compression thread's own zstd compressor and shuffle buffer.
_per_thread = threading.local()


def _zstd(raw: bytes) -> bytes:
    """zstd frame of ``raw``, by this thread's own compressor (a context is not shared
    between threads, and making one a chunk costs about 8 % of the compression)."""
    compressor = getattr(_per_thread, "zstd", None)
    if compressor is None:
        try:
            import zstandard
        except ImportError:
            raise MissingPlugin(ZSTD_EXTRA) from None
        compressor = _per_thread.zstd = zstandard.ZstdCompressor(level=ZSTD_LEVEL)
    return compressor.compress(raw)


def _deflate_encoder():
    """A zlib stream (RFC 1950, what HDF5's deflate filter reads) of a chunk: ISA-L's
    level 0 where the ``isal`` package is installed (a base dependency; it releases the
    GIL, so both compression threads run), else the standard library's zlib level 1
    (the same stream format, 8x the CPU, 20 % smaller)."""
    if isal_zlib is None:  # pragma: no cover - isal is a dependency
        return lambda raw: zlib.compress(raw, 1)
    return lambda raw: isal_zlib.compress(raw, ISAL_LEVEL)


#: What a zstd or lz4 cube needs: the one line a writer or reader without it prints.
ZSTD_EXTRA = ("this cube's codec (zstd or lz4) needs the HDF5 filter plugins: "
              "pip install 'nylonflex[zstd]' (hdf5plugin and zstandard); outside Python set "
              "HDF5_PLUGIN_PATH to hdf5plugin's plugin folder, or write the cube with "
              "compression: gzip")


#: The codecs a config may choose (``compression:``). ``gzip`` is the default: deflate
#: with HDF5's shuffle filter, which every HDF5 and netCDF-4 reader decompresses with no
#: plugin (h5py, xarray, netCDF-C's ncdump, h5dump, HDFView, MATLAB); encoded by ISA-L at
#: about zstd's speed, 1.27x its size. ``zstd`` (smaller) and ``lz4`` are opt-in: they need
#: the ``zstd`` extra to write and every reader needs the HDF5 filter plugin to read.
CODECS = {
    "gzip": Codec("gzip", {"compression": "gzip", "compression_opts": 1, "shuffle": True},
                  _deflate_encoder(), True, False,
                  "any HDF5/netCDF4 reader (h5py, netCDF4, xarray, ncdump, h5dump, HDFView, "
                  "MATLAB)"),
    "zstd": Codec("zstd", {"compression": 32015, "compression_opts": (ZSTD_LEVEL % 2**32,),
                           "shuffle": True},
                  _zstd, True, True,
                  "nylonflex and h5py/xarray with the zstd extra (hdf5plugin); HDF5 tools "
                  "with HDF5_PLUGIN_PATH set to hdf5plugin's plugin folder"),
    "lz4": Codec("lz4", {"compression": 32004, "compression_opts": (0,), "shuffle": True},
                 None, True, True,
                 "as zstd, with the LZ4 filter plugin"),
    "none": Codec("none", {}, lambda raw: raw, False, False, "any HDF5/netCDF4 reader"),
}
DEFAULT_CODEC = "gzip"


def load_filter_plugins():
    """Register the hdf5plugin filters (zstd, lz4) with HDF5; False if it is not installed."""
    try:
        import hdf5plugin  # noqa: F401
    except ImportError:
        return False
    return True


class MissingPlugin(RuntimeError):
    """A zstd or lz4 cube, and no HDF5 filter plugin to decompress it."""


def require_filters(codec_name) -> None:
    """Make sure HDF5 can decompress a cube written with ``codec_name`` (its
    ``compression`` attribute): registers hdf5plugin's filters for zstd and lz4.

    Raises
    ------
    MissingPlugin
        One line saying what to install, when the codec needs a plugin that neither
        hdf5plugin nor ``HDF5_PLUGIN_PATH`` provides.
    """
    codec = CODECS.get(str(codec_name))
    if codec is None or not codec.plugin or load_filter_plugins():
        return
    import h5py

    if not h5py.h5z.filter_avail(codec.filters["compression"]):  # HDF5_PLUGIN_PATH's
        raise MissingPlugin(ZSTD_EXTRA)


def chunk_shape(dims, sizes, radius_chunk):
    shape = [sizes[d] for d in dims]
    if dims and dims[0] == "radius":
        shape[0] = min(radius_chunk, shape[0])
    # keep chunks near or under 2 MB of float64 by halving the largest trailing dims
    while np.prod(shape) > 2**18 and max(shape[1:] or [1]) > 1:
        j = 1 + int(np.argmax(shape[1:]))
        shape[j] = (shape[j] + 1) // 2
    return tuple(int(x) for x in shape)


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
        rc = self.chunks[0]
        return i0 % rc == 0 and (i1 % rc == 0 or i1 == self.shape[0])


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
        self._compiled_shuffle = compiled_shuffle(
            sum(lay.dset.size * lay.dtype.itemsize for lay in self._layout.values()))
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
        out, jobs = {}, []
        for name, data in arrays.items():
            layout = self._layout[name]
            i1 = i0 + (np.shape(data)[0] if layout.dims else 0)
            if layout.dims and layout.dims[0] == "radius" and \
                    self.codec.encode is not None and layout.aligned(i0, i1):
                jobs.append((name, list(self._compress(layout, i0, data))))
            else:
                out[name] = np.asarray(data)
        return out, jobs

    @staticmethod
    def encode_finish(started) -> dict:
        """Wait for the chunks :meth:`encode_start` submitted: the dict :meth:`encode` gives."""
        out, jobs = started
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
            layout = self._layout[name]
            if part == "offsets":
                sizes = encoded[f"{name}:sizes"]
                blob = memoryview(encoded[f"{name}:bytes"])
                write_chunk = layout.dset.id.write_direct_chunk
                end = 0
                for offset, size in zip(value.tolist(), sizes.tolist()):
                    write_chunk(tuple(offset), blob[end:end + size])  # a view: no copy
                    end += size
            elif part:
                continue  # sizes and bytes go with their offsets
            elif layout.dims and layout.dims[0] == "radius":
                layout.dset[i0:i1] = value
            else:
                layout.dset[...] = value
        self._layout["slab_done"].dset[i0:i1] = 1

    def _compress(self, layout, i0, data):
        """Yield ``(chunk offset, future of its filtered bytes)`` for a slab's chunks."""
        chunks, shape = layout.chunks, layout.shape
        data = np.ascontiguousarray(data, dtype=layout.dtype)
        starts = [range(0, data.shape[0], chunks[0])] + \
            [range(0, n, c) for n, c in zip(shape[1:], chunks[1:])]
        for corner in itertools.product(*starts):
            block = data[tuple(slice(c, c + n) for c, n in zip(corner, chunks))]
            offset = (i0 + corner[0], *corner[1:])
            yield offset, self._pool.submit(encode_chunk, block, chunks, self.codec,
                                            self._compiled_shuffle)

    def abandon(self):
        """Close after a failure (a full disk, an error) without raising, and without
        writing anything more to the disk.

        A failed run's file is never published (``--resume`` rebuilds it from the journal),
        so its bytes are dropped and its descriptor is pointed at a memory file first
        (:func:`_divert`): whatever HDF5 still flushes as it closes (chunk caches, metadata)
        then cannot fail. A close that failed partway left HDF5 ids half closed, and a
        second close freed them again: a segfault on a full disk (exit 139 when the disk
        filled while the finished cube was being closed). A file whose close already
        failed is therefore never closed again (:meth:`NetCDF4File.close`).
        """
        self._pool.shutdown(cancel_futures=True)
        with contextlib.suppress(OSError):  # the descriptor read at open: no HDF5 call
            os.ftruncate(self.f.fd, 0)
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
    writes to it then succeed whatever the disk, and the disk file's own blocks are freed
    with its last descriptor. Does nothing where there is no memory file."""
    if not hasattr(os, "memfd_create"):  # pragma: no cover - not Linux
        return
    mem = os.memfd_create("nylonflex-abandoned", getattr(os, "MFD_CLOEXEC", 0))
    try:
        os.dup2(mem, fd, inheritable=False)
    finally:
        os.close(mem)


def encode_chunk(block, chunks, codec: Codec, compiled: bool = False):
    """One chunk as the codec's HDF5 filter pipeline stores it (padded to the chunk shape),
    shuffled by the compiled loop (``compiled``, a large cube) or by NumPy (the same bytes,
    nothing to compile; :data:`COMPILED_SHUFFLE_BYTES`)."""
    if block.shape != tuple(chunks):
        full = np.zeros(chunks, dtype=block.dtype)
        full[tuple(slice(0, n) for n in block.shape)] = block
        block = full
    raw = np.ascontiguousarray(block).reshape(-1).view(np.uint8)
    size = block.dtype.itemsize
    if codec.shuffle and size > 1:  # byte k of every element together, as H5Z_FILTER_SHUFFLE
        src = raw.reshape(-1, size)
        raw = _shuffle_buffer(raw.size).reshape(size, src.shape[0])
        if compiled:
            from ..kernels.bytes import shuffle_bytes

            shuffle_bytes(src, raw)
        else:
            np.copyto(raw, src.T)
    # a 1-D byte view (no copy); every codec returns new bytes, so the buffer is free after
    return codec.encode(raw.reshape(-1).data)


def _shuffle_buffer(nbytes: int) -> np.ndarray:
    """This thread's shuffle buffer, ``nbytes`` long: a fresh 2 MB array a chunk cost the
    zeroing of its pages every time (the arenas hand freed memory back)."""
    buf = getattr(_per_thread, "shuffle", None)
    if buf is None or buf.size < nbytes:
        buf = _per_thread.shuffle = np.empty(nbytes, dtype=np.uint8)
    return buf[:nbytes]


def _shuffle_deflate(block, chunks):
    """HDF5's shuffle then deflate filters on one chunk (padded to the full chunk shape)."""
    return encode_chunk(block, chunks, CODECS["gzip"])
