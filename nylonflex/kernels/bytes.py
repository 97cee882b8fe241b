"""Byte-level loops of the storage layer: HDF5's shuffle filter, compiled.

NumPy's strided copy of the transpose (``np.copyto(out, src.T)``) does the shuffle at
about 2 GB/s, about deflate's own speed. These loops release the GIL, so the compression
threads shuffle in parallel: the byte-by-byte loop runs at 2.5-3.3 GB/s; for 8-byte
elements (every float variable of the cube) the word loop transposes 8 x 8-byte blocks in
registers at 9-14 GB/s on a chunk in cache. They are compiled the first time a large cube
is written (:data:`nylonflex.storage.codec.COMPILED_SHUFFLE_BYTES`); a small one is
shuffled by NumPy, with the same bytes.
"""

from __future__ import annotations

import numpy as np

from ._compile import jit_kernel


def _shuffle_bytes(src, out):
    """``out[k, i] = src[i, k]``: byte k of every element together (H5Z_FILTER_SHUFFLE).

    ``src`` is (elements, itemsize) uint8, ``out`` (itemsize, elements) uint8.
    """
    n = src.shape[0]
    size = src.shape[1]
    for i in range(n):
        for k in range(size):
            out[k, i] = src[i, k]


def _shuffle_words8(src, out):
    """The shuffle of 8-byte elements, 8 at a time: ``src`` (n,) uint64, ``out`` (8, n/8)
    uint64 (n a multiple of 8), as little-endian words.

    Eight elements are an 8 x 8 matrix of bytes (a row a word); its transpose, in three
    steps that swap the off-diagonal 4 x 4, 2 x 2 and 1 x 1 blocks with shifts and masks
    (Warren, Hacker's Delight, s. 7-3), puts byte k of the eight elements into word k.
    """
    m32 = np.uint64(0x00000000FFFFFFFF)
    m16 = np.uint64(0x0000FFFF0000FFFF)
    m8 = np.uint64(0x00FF00FF00FF00FF)
    s32 = np.uint64(32)
    s16 = np.uint64(16)
    s8 = np.uint64(8)
    for j in range(src.shape[0] // 8):
        b = 8 * j
        w0, w1, w2, w3 = src[b], src[b + 1], src[b + 2], src[b + 3]
        w4, w5, w6, w7 = src[b + 4], src[b + 5], src[b + 6], src[b + 7]
        t = ((w0 >> s32) ^ w4) & m32
        w4 ^= t
        w0 ^= t << s32
        t = ((w1 >> s32) ^ w5) & m32
        w5 ^= t
        w1 ^= t << s32
        t = ((w2 >> s32) ^ w6) & m32
        w6 ^= t
        w2 ^= t << s32
        t = ((w3 >> s32) ^ w7) & m32
        w7 ^= t
        w3 ^= t << s32
        t = ((w0 >> s16) ^ w2) & m16
        w2 ^= t
        w0 ^= t << s16
        t = ((w1 >> s16) ^ w3) & m16
        w3 ^= t
        w1 ^= t << s16
        t = ((w4 >> s16) ^ w6) & m16
        w6 ^= t
        w4 ^= t << s16
        t = ((w5 >> s16) ^ w7) & m16
        w7 ^= t
        w5 ^= t << s16
        t = ((w0 >> s8) ^ w1) & m8
        w1 ^= t
        w0 ^= t << s8
        t = ((w2 >> s8) ^ w3) & m8
        w3 ^= t
        w2 ^= t << s8
        t = ((w4 >> s8) ^ w5) & m8
        w5 ^= t
        w4 ^= t << s8
        t = ((w6 >> s8) ^ w7) & m8
        w7 ^= t
        w6 ^= t << s8
        out[0, j], out[1, j], out[2, j], out[3, j] = w0, w1, w2, w3
        out[4, j], out[5, j], out[6, j], out[7, j] = w4, w5, w6, w7


_shuffle_bytes_jit = jit_kernel(_shuffle_bytes)
_shuffle_words8_jit = jit_kernel(_shuffle_words8)


def shuffle_bytes(src, out):
    """HDF5's shuffle of ``src`` (elements, itemsize) uint8 into ``out`` (itemsize,
    elements) uint8: ``out[k, i] = src[i, k]``. Both C-contiguous."""
    n, size = src.shape
    if size == 8 and n % 8 == 0 and src.flags.c_contiguous and out.flags.c_contiguous \
            and src.ctypes.data % 8 == 0 and out.ctypes.data % 8 == 0 \
            and np.little_endian:
        _shuffle_words8_jit(src.reshape(-1).view(np.uint64),
                            out.reshape(-1).view(np.uint64).reshape(8, n // 8))
    else:
        _shuffle_bytes_jit(src, out)
