"""The way back from :mod:`.codec` for the light reads: the default codec's stored chunks
inflated (ISA-L where installed) and unshuffled here, h5py's read for anything else."""

from __future__ import annotations

import itertools
import zlib

import numpy as np

try:
    from isal import isal_zlib
except ImportError:  # pragma: no cover - isal is a dependency
    isal_zlib = None

__all__ = ["decode_chunk", "deflate_only", "inflate", "read_box"]

#: A zlib stream (RFC 1950) inflated: ISA-L's, about twice zlib's speed (what HDF5's
#: deflate filter uses), to the same bytes; else the standard library's.
inflate = isal_zlib.decompress if isal_zlib is not None else zlib.decompress


def decode_chunk(raw: bytes, chunks, dtype, shuffle: bool, out=None) -> np.ndarray:
    """The inverse of :func:`~.codec.encode_chunk` for the default codec: one stored chunk's bytes
    (a zlib stream, of shuffled bytes when ``shuffle``) as an array of the chunk's shape
    ``chunks`` (padding included) and ``dtype``, written into ``out`` when given (a
    C-contiguous array of that shape and dtype). Inflated by ISA-L where installed, about
    twice zlib's speed (what HDF5's deflate filter uses), to the same bytes."""
    dtype = np.dtype(dtype)
    data = np.frombuffer(inflate(raw), dtype=np.uint8)
    if out is None:
        out = np.empty(chunks, dtype=dtype)
    flat = out.reshape(-1).view(np.uint8)
    if shuffle and dtype.itemsize > 1:
        # byte plane k back into byte k of every element: one strided row a plane, 2.4x
        # NumPy's transposed copy of the (itemsize, n) planes
        planes, bytes_of = data.reshape(dtype.itemsize, -1), flat.reshape(-1, dtype.itemsize)
        for k in range(dtype.itemsize):
            bytes_of[:, k] = planes[k]
    else:
        flat[...] = data
    return out


def read_box(dset, key, deflate: bool | None = None) -> np.ndarray:
    """``dset[key]`` (an h5py dataset of a cube, ``key`` a tuple of an int or a slice of
    step 1 per dimension), its chunks inflated here (:func:`decode_chunk`) when they are
    deflate with or without the shuffle and nothing else, as nylonflex writes the default
    codec: h5py would inflate them with zlib, about half the speed; anything else (another
    codec, a chunk not written, a chunk whose filters were skipped, a chunk that does not
    inflate, whose read then raises HDF5's OSError naming it) is h5py's read.
    ``deflate``: :func:`deflate_only` of ``dset``, when the caller knows it (it reads the
    dataset's creation properties, about 50 us)."""
    box = _box(dset, key)
    if box is None or not (deflate_only(dset) if deflate is None else deflate):
        return dset[key]
    starts, stops = box
    chunks = dset.chunks
    out = np.empty([b - a for a, b in zip(starts, stops)], dtype=dset.dtype)
    ranges = [range(a // c * c, b, c) for a, b, c in zip(starts, stops, chunks)]
    read = dset.id.read_direct_chunk
    for corner in itertools.product(*ranges):
        try:
            mask, raw = read(corner)
        except (KeyError, OSError, RuntimeError, ValueError):  # not written: h5py fills
            return dset[key]
        if mask:  # a filter was skipped for this chunk
            return dset[key]
        lo = [max(a, c) for a, c in zip(starts, corner)]
        hi = [min(b, c + n) for b, c, n in zip(stops, corner, chunks)]
        region = out[tuple(slice(x - a, y - a) for x, y, a in zip(lo, hi, starts))]
        straight = region.shape == tuple(chunks) and region.flags.c_contiguous
        try:
            block = decode_chunk(raw, chunks, dset.dtype, dset.shuffle,
                                 out=region if straight else None)
        except (*_INFLATE_ERRORS, ValueError):  # a damaged chunk: HDF5 says which (OSError)
            return dset[key]
        if not straight:
            region[...] = block[tuple(slice(x - c, y - c) for x, y, c in zip(lo, hi, corner))]
    return out[tuple(0 if isinstance(k, (int, np.integer)) else slice(None) for k in key)]


#: What inflating a damaged chunk raises (ISA-L's error, zlib's).
_INFLATE_ERRORS = (zlib.error,) if isal_zlib is None else (isal_zlib.error, zlib.error)


def _box(dset, key):
    """``(starts, stops)`` of ``key`` over ``dset`` (chunked), or None when it is not a
    box of ints and step-1 slices."""
    if dset.chunks is None or len(key) != dset.ndim:
        return None
    starts, stops = [], []
    for k, n in zip(key, dset.shape):
        if isinstance(k, (int, np.integer)):
            k = int(k) + n if k < 0 else int(k)
            if not 0 <= k < n:
                return None
            starts.append(k), stops.append(k + 1)
        elif isinstance(k, slice) and k.step in (None, 1):
            a, b, _ = k.indices(n)
            if b <= a:
                return None
            starts.append(a), stops.append(b)
        else:
            return None
    return starts, stops


def deflate_only(dset) -> bool:
    """Whether ``dset``'s filter pipeline is deflate, after the shuffle or alone."""
    import h5py

    plist = dset.id.get_create_plist()
    filters = [plist.get_filter(i)[0] for i in range(plist.get_nfilters())]
    return filters in ([h5py.h5z.FILTER_SHUFFLE, h5py.h5z.FILTER_DEFLATE],
                       [h5py.h5z.FILTER_DEFLATE])
