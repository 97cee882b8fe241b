"""Where the kernels' compiled code is cached, keyed on the model's sources.

Numba's cache checks only the timestamp of the file that holds a kernel, not of the
formulas it compiles in from other files, so the cache folder is keyed on a digest of every
physics and kernel source: an edited formula can never run stale machine code. This module
imports no Numba: the digest also names the model in a cube's provenance.
"""

from __future__ import annotations

import hashlib
import os
from functools import lru_cache
from pathlib import Path

from ..files.atomic import create_new

__all__ = ["cache_dir", "caching", "mark_compiled", "source_digest", "was_compiled",
           "writable"]


@lru_cache(maxsize=1)
def source_digest() -> str:
    """Digest of every physics and kernel source file, and of the physics' data (the
    ``fe_calibrated`` coefficients, compiled in as constants) (16 hex digits)."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for sub, pattern in (("physics", "*.py"), ("kernels", "*.py"), ("physics", "*.json")):
        for path in sorted((root / sub).glob(pattern)):
            digest.update(path.name.encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def caching() -> bool:
    """Whether the kernels keep their compiled code in :func:`cache_dir` (unless
    ``$NYLONFLEX_NO_CACHE`` is set, when each process compiles them again)."""
    return os.environ.get("NYLONFLEX_NO_CACHE") is None


def cache_dir() -> str:
    """The kernels' Numba cache folder: ``$NUMBA_CACHE_DIR`` (default
    ``~/.cache/nylonflex/numba``) / the :func:`source_digest` of the model sources."""
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "nylonflex", "numba")
    return os.path.join(base, source_digest())


def writable() -> bool:
    """Whether :func:`cache_dir` can be written (it is made if missing): where it cannot,
    Numba keeps compiled code elsewhere or nowhere, and no mark can be left."""
    try:
        os.makedirs(cache_dir(), exist_ok=True)
    except OSError:
        return False
    return os.access(cache_dir(), os.W_OK)


def _mark_path(family: str) -> str:
    return os.path.join(cache_dir(), f"{family}.compiled")


def mark_compiled(family: str) -> None:
    """Record that kernel ``family`` (:data:`~.compiling.FAMILIES`) compiled into this
    cache folder: an empty file beside Numba's, which goes when the folder goes. Nothing
    when the folder cannot be written (the kernel then compiles in each process anyway)."""
    try:
        os.makedirs(cache_dir(), exist_ok=True)
        os.close(create_new(_mark_path(family), 0o644))  # never through a link
    except OSError:  # marked already (FileExistsError), or an unwritable folder
        pass


def was_compiled(family: str) -> bool:
    """Whether kernel ``family`` compiled into this cache folder before (:func:`mark_compiled`),
    so that a process can expect to load it, not compile it. A hint: a cache emptied by hand
    or made on another CPU still compiles where the kernel is first called."""
    return os.path.exists(_mark_path(family))
