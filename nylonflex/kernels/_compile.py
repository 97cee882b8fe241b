"""Compile options, and how the kernels call the physics layer's formulas.

The physics modules mark their small pure functions with ``@formula`` and never import
Numba. This module registers every formula with Numba's own mechanism for calling plain
Python functions from jitted code (``numba.extending.register_jitable``): a kernel calls the
physics function by its ordinary name and Numba compiles that very function into it. One
formula, one place; both layers run the same source lines. The two ``@primitive`` functions
(the bits of a float and back, :mod:`nylonflex.physics.elementary`) are the exception: plain
Python cannot express a bit cast that Numba compiles, so they get a compiled form here, one
LLVM ``bitcast`` each, with the same result.

Numba's cache checks only the timestamp of the file that holds a kernel, not of the
formulas it compiles in from other files, so the cache folder is keyed on a digest of every
physics and kernel source (:mod:`.cache`): an edited formula can never run stale machine
code. That folder is set only while a kernel is decorated (:func:`_kernel_cache_dir`); the
process's own Numba setting is left as it was.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import pkgutil
import sys
import types
from contextlib import contextmanager
from pathlib import Path

import numba
from llvmlite import ir
from numba.core import types as nb_types
from numba.extending import intrinsic, overload, register_jitable

from .. import physics
from ..physics import elementary
from .cache import cache_dir, caching


def _import_numba_arraymath():
    """Import Numba's NumPy implementations without the scipy.linalg import of its BLAS probe.

    Numba imports ``numba.np.arraymath`` the first time it compiles *or loads a cached
    kernel*, and that module imports ``scipy.linalg`` at once only to learn whether BLAS is
    there (``_HAVE_BLAS``, which chooses how ``np.convolve`` and ``np.correlate`` multiply).
    scipy.linalg costs 0.1-0.3 s of every command that loads a kernel, and no kernel calls
    BLAS. While arraymath is imported, the probe (``numba.np.linalg.ensure_blas``) asks
    whether scipy's BLAS module is installed (a file test) instead of importing it; then
    Numba's own probe is put back, so np.dot and np.linalg still import scipy.linalg (and
    check its integer width) when something that uses them is compiled. Where scipy.linalg
    or arraymath is imported already, nothing is done.
    """
    if "numba.np.arraymath" in sys.modules or "scipy.linalg" in sys.modules:
        return
    from numba.np import linalg

    numbas = linalg.ensure_blas
    linalg.ensure_blas = _blas_probe
    try:
        from numba.np import arraymath
    finally:
        linalg.ensure_blas = numbas
    if getattr(arraymath, "ensure_blas", None) is _blas_probe:
        arraymath.ensure_blas = numbas


def _blas_probe():
    """Numba's ``ensure_blas`` at arraymath's import: ImportError when scipy's BLAS module
    is not installed (found on disk, not imported)."""
    if not _scipy_blas_installed():
        raise ImportError("scipy 0.16+ is required for linear algebra")


def _scipy_blas_installed() -> bool:
    """Whether ``scipy.linalg.cython_blas`` is installed (found on disk, not imported)."""
    spec = importlib.util.find_spec("scipy")
    for folder in (spec.submodule_search_locations or []) if spec else []:
        if any(Path(folder, "linalg").glob("cython_blas*")):
            return True
    return False


_import_numba_arraymath()

#: Options of every kernel. ``cache`` writes compiled code to a folder keyed on the model
#: sources so a second run starts warm; ``fastmath`` stays off: the kernels must match the
#: physics to 1e-9 and the sweep must be bit-reproducible.
JIT_OPTIONS = {"cache": caching(), "nogil": True,
               "error_model": "numpy", "fastmath": False}

#: Options of what a kernel calls: every formula, and a kernel's own body where
#: ``jit_kernel(callee_body=True)``. Numba compiles a callee once per set of the *caller's*
#: flags, and a kernel's flags (a Python wrapper, the GIL released) differ from any
#: callee's, so a formula called both from a kernel and from another formula compiled
#: twice: 16 of the grid kernel's 78 compiles. With the kernel's body a callee too, every
#: call of a formula has one set of flags.
CALLEE_OPTIONS = {"nogil": True, "error_model": "numpy", "fastmath": False}


@contextmanager
def _kernel_cache_dir():
    """Numba's cache folder set to :func:`cache_dir` while a kernel is decorated, then put
    back: Numba fixes a dispatcher's cache path when it is made, so the kernels cache under
    the digest of their sources while the process's own setting (another library's kernels,
    a notebook's) is left as it was. An unwritable folder makes Numba fall back to its
    usual __pycache__ locations."""
    saved = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = cache_dir()
    try:
        yield
    finally:
        numba.config.CACHE_DIR = saved


def is_formula(obj) -> bool:
    """True for a function marked with the physics layer's ``@formula``."""
    return isinstance(obj, types.FunctionType) and getattr(obj, "__nylonflex_formula__", False)


def _register_formulas():
    """Make every physics ``@formula`` callable from jitted code, by its own name."""
    for info in pkgutil.iter_modules(physics.__path__):
        module = importlib.import_module(f"{physics.__name__}.{info.name}")
        for obj in vars(module).values():
            if is_formula(obj) and obj.__module__ == module.__name__ \
                    and not getattr(obj, "__nylonflex_registered__", False):
                register_jitable(**CALLEE_OPTIONS)(obj)
                obj.__nylonflex_registered__ = True


@intrinsic
def _bitcast_float_int(typingctx, x):
    """The IEEE 754 bits of a float64 as an int64: one LLVM ``bitcast``."""
    if not isinstance(x, nb_types.Float):
        return None

    def codegen(context, builder, signature, args):
        value = context.cast(builder, args[0], x, nb_types.float64)
        return builder.bitcast(value, ir.IntType(64))

    return nb_types.int64(x), codegen


@intrinsic
def _bitcast_int_float(typingctx, bits):
    """The float64 whose IEEE 754 bits are an int64: one LLVM ``bitcast``."""
    if not isinstance(bits, nb_types.Integer):
        return None

    def codegen(context, builder, signature, args):
        value = context.cast(builder, args[0], bits, nb_types.int64)
        return builder.bitcast(value, ir.DoubleType())

    return nb_types.float64(bits), codegen


def _register_primitives():
    """Compile the physics layer's ``@primitive`` functions (plain Python there) to bit casts."""
    def float_bits(x):
        return lambda x: _bitcast_float_int(x)

    def bits_float(bits):
        return lambda bits: _bitcast_int_float(bits)

    for func, impl in ((elementary._float_bits, float_bits),
                       (elementary._bits_float, bits_float)):
        if not getattr(func, "__nylonflex_registered__", False):
            overload(func)(impl)
            func.__nylonflex_registered__ = True


_register_primitives()
_register_formulas()


def jit_kernel(func=None, *, callee_body=False, borrows=False):
    """``njit`` a kernel (with :data:`JIT_OPTIONS`); it calls physics formulas by name.

    ``callee_body``: the compiled kernel is a one-line function of the same name, file and
    parameters that calls ``func`` compiled as a callee (:data:`CALLEE_OPTIONS`), so that a
    formula the kernel calls both itself and through other formulas compiles once, not
    twice (the grid and pointwise kernels: their cold compile is 0.6-0.7 s shorter). It
    costs one more optimisation of the whole body's machine code, so a small kernel, or one
    that other kernels call, is better without it. Serial: the engine splits a kernel's
    range over its own threads (:mod:`nylonflex.engine.threads`), so no kernel needs
    Numba's ``parallel`` form.

    ``borrows`` (with ``callee_body``): the body only borrows arrays (its arguments and
    views of them) and makes none, so it and every formula it calls compile without
    Numba's reference counting (``_nrt=False``; a callee takes its caller's setting). Each
    formula call that passes arrays otherwise counts them up and down on entry and exit,
    atomically: a fifth of the grid kernel's time. A formula that makes an array cannot
    compile there (Numba refuses it), so nothing is freed twice or leaked."""

    if borrows and not callee_body:
        raise TypeError("jit_kernel: borrows needs callee_body (the Python-facing wrapper "
                        "keeps the reference counts of the arrays it is given)")

    def wrap(f):
        with _kernel_cache_dir():
            return numba.njit(**JIT_OPTIONS)(_calling(f, borrows) if callee_body else f)

    return wrap if func is None else wrap(func)


def compiled_entry(kernel, args):
    """The machine-code entry that a call of ``kernel`` (a :func:`jit_kernel`) with
    ``args`` runs, for later calls with arguments of exactly those Numba types; the
    kernel itself where it has none (not compiled for them yet, or ``NUMBA_DISABLE_JIT``).

    Numba's dispatcher types every argument of every call before it picks the compiled
    code: for the pointwise kernel's records (about thirty arrays in seven named tuples)
    that took 15-20 us, more than the kernel's own one design. The entry skips that typing
    and checks nothing, so a caller passes only arguments made the way ``args`` were (the
    same record types, array dtypes, dimensions, layouts and flags): another type would be
    read as this one's.
    """
    overloads = getattr(kernel, "overloads", None)
    if overloads is None:
        return kernel
    compiled = overloads.get(tuple(numba.typeof(a) for a in args))
    return getattr(compiled, "entry_point", None) or kernel


def _calling(f, borrows=False):
    """A function like ``f`` (name, module, file, first line, parameters, docstring) whose
    body is ``return f(...)``, with ``f`` made a Numba callee (without reference counting
    where ``borrows``): what :func:`jit_kernel` compiles. Numba's cache files are named by
    the function's name and line, as before."""
    register_jitable(**CALLEE_OPTIONS, **({"_nrt": False} if borrows else {}))(f)
    code = f.__code__
    if f.__defaults__ or code.co_kwonlyargcount or code.co_posonlyargcount or \
            code.co_flags & (inspect.CO_VARARGS | inspect.CO_VARKEYWORDS):
        raise TypeError(f"kernel {f.__name__}: plain positional parameters only")
    args = ", ".join(code.co_varnames[:code.co_argcount])
    source = "\n" * (code.co_firstlineno - 1) + \
        f"def {f.__name__}({args}):\n    return _body({args})\n"
    scope = {"_body": f}
    exec(compile(source, code.co_filename, "exec"), scope)  # noqa: S102 - our own kernel
    outer = scope[f.__name__]
    outer.__module__, outer.__qualname__, outer.__doc__ = f.__module__, f.__qualname__, f.__doc__
    outer.__wrapped__ = f
    return outer


# Numba's compile events as a notice (before any kernel can compile): kernels/compiling.py
from . import compiling  # noqa: E402,F401
