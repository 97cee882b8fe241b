"""Compile options, and how the kernels call the physics layer's formulas.

The physics modules mark their small pure functions with ``@formula`` and never import
Numba. This module registers every formula with Numba's own mechanism for calling plain
Python functions from jitted code (``numba.extending.register_jitable``): a kernel calls the
physics function by its ordinary name and Numba compiles that very function into it. One
formula, one place; both layers run the same source lines.

Numba's cache checks only the timestamp of the file that holds a kernel, not of the
formulas it compiles in from other files, so the cache folder is keyed on a digest of every
physics and kernel source: an edited formula can never run stale machine code.
"""

from __future__ import annotations

import hashlib
import importlib
import os
import pkgutil
import types
from functools import lru_cache
from pathlib import Path

import numba
from numba.extending import register_jitable

#: Options of every kernel. ``cache`` writes compiled code to a folder keyed on the model
#: sources so a second run starts warm; ``fastmath`` stays off: the kernels must match the
#: physics to 1e-9 and the sweep must be bit-reproducible.
JIT_OPTIONS = {"cache": os.environ.get("NYLONFLEX_NO_CACHE") is None, "nogil": True,
               "error_model": "numpy", "fastmath": False}


@lru_cache(maxsize=1)
def source_digest() -> str:
    """Digest of every physics and kernel source file (16 hex digits)."""
    root = Path(__file__).resolve().parents[1]
    digest = hashlib.sha256()
    for sub in ("physics", "kernels"):
        for path in sorted((root / sub).glob("*.py")):
            digest.update(path.name.encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def _cache_dir() -> str:
    base = os.environ.get("NUMBA_CACHE_DIR") or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache"),
        "nylonflex", "numba")
    return os.path.join(base, source_digest())


# Set before any kernel is decorated: numba reads it when a dispatcher's cache is created.
# An unwritable folder makes numba fall back to its usual __pycache__ locations.
numba.config.CACHE_DIR = _cache_dir()


def is_formula(obj) -> bool:
    """True for a function marked with the physics layer's ``@formula``."""
    return isinstance(obj, types.FunctionType) and getattr(obj, "__nylonflex_formula__", False)


def _register_formulas():
    """Make every physics ``@formula`` callable from jitted code, by its own name."""
    from .. import physics

    for info in pkgutil.iter_modules(physics.__path__):
        module = importlib.import_module(f"{physics.__name__}.{info.name}")
        for obj in vars(module).values():
            if is_formula(obj) and obj.__module__ == module.__name__ \
                    and not getattr(obj, "__nylonflex_registered__", False):
                register_jitable(obj)
                obj.__nylonflex_registered__ = True


_register_formulas()


def jit_kernel(func=None, *, parallel=False):
    """``njit`` a kernel (with :data:`JIT_OPTIONS`); it calls physics formulas by name."""

    def wrap(f):
        if parallel:  # a second dispatcher of the same Python function, cached apart
            f = types.FunctionType(f.__code__, f.__globals__, f.__name__, f.__defaults__,
                                   f.__closure__)
            f.__qualname__ = f.__qualname__ + "_parallel"
        return numba.njit(parallel=parallel, **JIT_OPTIONS)(f)

    return wrap if func is None else wrap(func)
