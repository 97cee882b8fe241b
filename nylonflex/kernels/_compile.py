"""Compile options, and the Numba compilation of the physics layer's formulas.

The physics modules mark their small pure functions with ``@formula`` and never import
Numba. :func:`jit_formula` compiles such a function *and every formula it calls*: it
rebuilds the function over a copy of its globals in which each called formula is replaced
by its compiled twin, then hands it to ``numba.njit``. One formula, one place; both layers
run the same source lines.
"""

from __future__ import annotations

import hashlib
import os
import types
from pathlib import Path

import numba

#: Options of every kernel. ``cache`` writes compiled code beside the sources so a second
#: run starts warm; ``fastmath`` stays off: the kernels must match the physics to 1e-9.
JIT_OPTIONS = {"cache": os.environ.get("NYLONFLEX_NO_CACHE") is None, "nogil": True,
               "error_model": "numpy", "fastmath": False}



def _source_digest() -> str:
    """Digest of every physics and kernel source file.

    Numba's cache checks only the timestamp of the file that holds the kernel, not of the
    formulas it inlines from other files, so an edited formula could run stale machine code.
    Keying the cache folder on all the sources the kernels are compiled from closes that hole.
    """
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
    return os.path.join(base, _source_digest())


# Set before any kernel is decorated: numba reads it when a dispatcher's cache is created.
# An unwritable folder makes numba fall back to its usual __pycache__ locations.
numba.config.CACHE_DIR = _cache_dir()

_COMPILED: dict[types.FunctionType, numba.core.registry.CPUDispatcher] = {}


def is_formula(obj) -> bool:
    """True for a function marked with the physics layer's ``@formula``."""
    return isinstance(obj, types.FunctionType) and getattr(obj, "__nylonflex_formula__", False)


def _with_compiled_formulas(func, qualname):
    """A copy of ``func`` whose global formulas are their compiled twins."""
    namespace = dict(func.__globals__)
    for name in func.__code__.co_names:
        if is_formula(namespace.get(name)):
            namespace[name] = jit_formula(namespace[name])
    clone = types.FunctionType(func.__code__, namespace, func.__name__, func.__defaults__,
                               func.__closure__)
    clone.__module__ = func.__module__
    clone.__qualname__ = qualname
    clone.__doc__ = func.__doc__
    return clone


def jit_formula(func):
    """The Numba-compiled twin of a physics ``@formula`` (memoised)."""
    if func not in _COMPILED:
        if not is_formula(func):
            raise TypeError(f"{func.__qualname__} is not a physics @formula")
        clone = _with_compiled_formulas(func, func.__qualname__)
        _COMPILED[func] = numba.njit(**JIT_OPTIONS)(clone)
    return _COMPILED[func]


def jit_kernel(func=None, *, parallel=False):
    """``njit`` a kernel whose body calls physics formulas by their module-level names.

    Formulas referenced as globals of ``func`` are swapped for their compiled twins the same
    way :func:`jit_formula` does, so a kernel module can simply import them from physics.
    """

    def wrap(f):
        clone = _with_compiled_formulas(f, f.__qualname__ + ("_parallel" if parallel else ""))
        return numba.njit(parallel=parallel, **JIT_OPTIONS)(clone)

    return wrap if func is None else wrap(func)
