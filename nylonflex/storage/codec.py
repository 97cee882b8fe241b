"""The cube's codecs and the encoding of a slab into stored chunks: the bytes HDF5's filter
pipeline would write, made by a thread pool beside the file or on a Dask worker. The way
back, for the light reads, is :mod:`.decode`."""

from __future__ import annotations

import itertools
import threading
import zlib
from dataclasses import dataclass

import numpy as np

try:
    from isal import isal_zlib
except ImportError:  # pragma: no cover - isal is a dependency
    isal_zlib = None

#: CRC-32 of a buffer (zlib's polynomial): ISA-L's, about 4x zlib's speed, where present.
crc32 = isal_zlib.crc32 if isal_zlib is not None else zlib.crc32

__all__ = ["CODECS", "COMPILED_SHUFFLE_BYTES", "DEFAULT_CODEC", "ChunkPlan", "Codec",
           "EncodedSlab", "MissingPlugin", "SlabEncoder", "aligned", "chunk_shape",
           "compiled_shuffle", "crc32", "encode_chunk", "load_filter_plugins",
           "require_filters"]


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


def aligned(chunks, shape, i0: int, i1: int) -> bool:
    """Whether radii [i0, i1) cover whole chunks of ``chunks`` along radius, of a variable
    of ``shape`` (the last may end with the axis)."""
    rc = chunks[0]
    return i0 % rc == 0 and (i1 % rc == 0 or i1 == shape[0])


@dataclass(frozen=True)
class ChunkPlan:
    """How a cube variable is cut into stored chunks: its dimension names, chunk shape,
    shape and dtype (``numpy.dtype.str``); no HDF5 object, so it travels to a Dask
    worker."""

    dims: tuple
    chunks: tuple | None
    shape: tuple
    dtype: str


class EncodedSlab:
    """A slab already encoded where it was computed (a Dask worker): ``arrays`` is what
    :meth:`CubeFile.encode` gives, ready for :meth:`CubeFile.write_encoded`."""

    __slots__ = ("arrays",)

    def __init__(self, arrays: dict):
        self.arrays = arrays


class _Done:
    """A finished computation with a future's ``result()`` (:meth:`SlabEncoder.__call__`)."""

    __slots__ = ("value",)

    def __init__(self, value):
        self.value = value

    def result(self):
        return self.value


def _now(fn, *args):
    return _Done(fn(*args))


class SlabEncoder:
    """Encodes a slab as its cube stores it: each chunk that lies wholly inside the slab
    shuffled and compressed (``NAME:offsets``, ``NAME:sizes``, ``NAME:bytes``, and each
    chunk's CRC-32 in ``NAME:crcs``, which the journal keeps instead of the bytes),
    anything else a plain array under its name (:meth:`CubeFile.encode`).

    It holds plain data (each variable's :class:`ChunkPlan`, the codec's name, whether the
    shuffle is the compiled one), so it pickles: a Dask worker encodes the slab it
    computed with it (:meth:`__call__`, in its own thread), and the client only writes
    and journals the bytes (docs/distributed.md). The same object encodes for the cube
    file, so both give the same bytes.
    """

    def __init__(self, plans: dict, codec: str, compiled: bool):
        self.plans = plans
        self.codec = codec
        self.compiled = compiled

    def __call__(self, i0: int, arrays: dict) -> EncodedSlab:
        """The slab of radii from ``i0``, encoded in this thread; it shares no memory with
        ``arrays`` (what is not compressed is copied), so they may be reused at once."""
        return EncodedSlab(self.finish(self.start(i0, arrays, _now, copy=True)))

    def start(self, i0: int, arrays: dict, submit, copy: bool = False):
        """Hand each whole chunk of the slab to ``submit(fn, *args)`` (a thread pool's, or
        :func:`_now`); :meth:`finish` collects. What is not compressed is kept as it is,
        or copied with ``copy``."""
        codec = CODECS[self.codec]
        out, jobs = {}, []
        for name, data in arrays.items():
            plan = self.plans[name]
            i1 = i0 + (np.shape(data)[0] if plan.dims else 0)
            if plan.dims and plan.dims[0] == "radius" and codec.encode is not None and \
                    aligned(plan.chunks, plan.shape, i0, i1):
                jobs.append((name, list(self._compress(plan, codec, i0, data, submit))))
            else:
                out[name] = np.array(data) if copy else np.asarray(data)
        return out, jobs

    @staticmethod
    def finish(started) -> dict:
        """Wait for the chunks :meth:`start` handed out: the dict :meth:`CubeFile.encode`
        gives."""
        out, jobs = started
        for name, chunks in jobs:
            done = [future.result() for _, future in chunks]
            blobs, crcs = [b for b, _ in done], [c for _, c in done]
            out[f"{name}:offsets"] = np.array([off for off, _ in chunks], dtype=np.int64)
            out[f"{name}:sizes"] = np.array([len(b) for b in blobs], dtype=np.int64)
            out[f"{name}:crcs"] = np.array(crcs, dtype=np.uint32)
            out[f"{name}:bytes"] = np.frombuffer(b"".join(blobs), dtype=np.uint8)
        return out

    def _compress(self, plan, codec, i0, data, submit):
        """Yield ``(chunk offset, future of its filtered bytes)`` for a slab's chunks."""
        chunks, shape = plan.chunks, plan.shape
        data = np.ascontiguousarray(data, dtype=plan.dtype)
        starts = [range(0, data.shape[0], chunks[0])] + \
            [range(0, n, c) for n, c in zip(shape[1:], chunks[1:])]
        for corner in itertools.product(*starts):
            block = data[tuple(slice(c, c + n) for c, n in zip(corner, chunks))]
            offset = (i0 + corner[0], *corner[1:])
            yield offset, submit(_encode_checked, block, chunks, codec, self.compiled)


def _encode_checked(block, chunks, codec: Codec, compiled: bool):
    """:func:`encode_chunk`'s bytes and their CRC-32 (computed in the same worker thread;
    ISA-L's and zlib's release the GIL)."""
    blob = encode_chunk(block, chunks, codec, compiled)
    return blob, crc32(blob)


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
