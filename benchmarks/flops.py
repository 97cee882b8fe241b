"""A software count of the grid kernel's floating-point operations per design.

These hosts expose no hardware performance counters (a container sees no PMU: ``perf
stat -e fp_arith_inst_retired...`` is not there), so ``nylonflex bench`` counts the
kernel's work instead: the grid kernel's own source (:func:`nylonflex.kernels.design.
_design_slab`, the paper's copy the main job runs, and every formula it calls) runs as
plain Python on a few (radius, wall) pairs of the bench grid, with every float a
:class:`Flop`, a float that counts each arithmetic operation it takes part in.

What counts as one operation: ``+ - * /``, ``**``, unary minus, and each call of the
``math`` module that returns a float (``cos``, ``sqrt``, ...: a lower bound for a libm
call, which is several). What does not count: comparisons, ``abs``, ``min``/``max``, and
the integer and bit operations of the branch-free log and exp (:mod:`nylonflex.physics.
elementary`), whose float arithmetic counts. The count is the work of the Python source,
which is what Numba compiles; LLVM may remove a little of it (common subexpressions), so
the compiled kernel does at most this many.
"""

from __future__ import annotations

import contextlib
import importlib
import math
import pkgutil
import types

import numpy as np

__all__ = ["Flop", "counting", "kernel_flops_per_design"]


class _Counter:
    n = 0


class Flop(float):
    """A float that adds one to the count for each arithmetic operation it takes part in
    (its result is a :class:`Flop` too)."""

    __slots__ = ()


def _binary(name):
    base = getattr(float, name)

    def op(self, other):
        out = base(self, other)
        if out is NotImplemented:
            return out
        _Counter.n += 1
        return Flop(out)

    op.__name__ = name
    return op


for _name in ("__add__", "__radd__", "__sub__", "__rsub__", "__mul__", "__rmul__",
              "__truediv__", "__rtruediv__", "__pow__", "__rpow__"):
    setattr(Flop, _name, _binary(_name))


def _neg(self):
    _Counter.n += 1
    return Flop(float.__neg__(self))


Flop.__neg__ = _neg
Flop.__abs__ = lambda self: Flop(float.__abs__(self))
Flop.__pos__ = lambda self: self


class _CountingMath(types.SimpleNamespace):
    """The ``math`` module for counted code: a function returning a float counts one and
    returns a :class:`Flop`; constants are Flops."""

    def __init__(self):
        super().__init__()
        for name in dir(math):
            if name.startswith("_"):
                continue
            value = getattr(math, name)
            if isinstance(value, float):
                setattr(self, name, Flop(value))
            elif callable(value):
                setattr(self, name, self._wrap(value))

    @staticmethod
    def _wrap(func):
        def call(*args):
            out = func(*args)
            if isinstance(out, float):
                _Counter.n += 1
                return Flop(out)
            return out

        return call


def _physics_modules():
    from nylonflex import physics

    return [importlib.import_module(f"{physics.__name__}.{info.name}")
            for info in pkgutil.iter_modules(physics.__path__)]


@contextlib.contextmanager
def counting(*functions):
    """While inside: every physics module (and the globals of ``functions``, such as the
    kernels' specialised copies of formulas) sees the counting ``math``, and the branch-free
    exp and log build Flops from their bits. Yields a callable giving the count so far."""
    from nylonflex.physics import elementary

    fake = _CountingMath()
    scopes = []
    for module in _physics_modules():
        scopes.append(vars(module))
        scopes += [f.__globals__ for f in vars(module).values()
                   if isinstance(f, types.FunctionType) and f.__globals__ is not vars(module)]
    scopes += [f.__globals__ for f in functions]
    saved = []
    for scope in {id(s): s for s in scopes}.values():
        if scope.get("math") is math:
            saved.append((scope, "math", math))
            scope["math"] = fake
    bits_float = elementary._bits_float
    saved.append((vars(elementary), "_bits_float", bits_float))
    vars(elementary)["_bits_float"] = lambda bits: Flop(bits_float(bits))
    _Counter.n = 0
    try:
        yield lambda: _Counter.n
    finally:
        for scope, name, value in saved:
            scope[name] = value


def _flops_of(x):
    """``x`` with every float a :class:`Flop` (float arrays become object arrays)."""
    if isinstance(x, tuple) and hasattr(x, "_fields"):
        return type(x)(*(_flops_of(v) for v in x))
    if isinstance(x, np.ndarray) and x.dtype.kind == "f":
        return np.array([Flop(v) for v in x.ravel()], dtype=object).reshape(x.shape)
    if isinstance(x, (float, np.floating)):
        return Flop(x)
    return x


def counted_kernel(cfg, ia: int, it: int) -> tuple[int, tuple]:
    """The paper's grid kernel run as Python on counting floats for the (radius, wall) pair
    (``ia``, ``it``) of ``cfg``, with all its lengths, coil indices and wrap angles (and its
    curves): the operations [flop] it did, and its outputs (a ``GridOut`` of object arrays
    of one radius, the pair's wall filled)."""
    from nylonflex.engine.model_slab import grid_axes, grid_out, kernel_inputs
    from nylonflex.kernels import design
    from nylonflex.kernels.specialise import specialised

    body = specialised(design._design_slab, "_design_slab_counted", **design.PAPER_ONLY_GLOBALS)
    grid, inputs = grid_axes(cfg, ia, ia + 1), kernel_inputs(cfg, 0)
    out = grid_out(cfg, 1)
    out = type(out)(*(np.empty(a.shape, dtype=object) for a in out))
    scratch = design.grid_scratch(grid, inputs[2])
    scratch = type(scratch)(*(np.empty(a.shape, dtype=object) for a in scratch))
    copies = [f for f in vars(design).values()  # the kernels' specialised formulas too
              if isinstance(f, types.FunctionType) and f.__globals__ is not vars(design)]
    with counting(body, *copies) as count:
        body(_flops_of(grid), *(_flops_of(v) for v in inputs), out, scratch, it, it + 1)
        return count(), out


def kernel_flops_per_design(cfg, pairs: int = 4) -> float:
    """Floating-point operations [flop] the paper's grid kernel does per design of ``cfg``
    (a sweep of the paper's model without a supply), counted on ``pairs`` (radius, wall)
    pairs spread over the grid (:func:`counted_kernel`)."""
    na, nt = len(cfg.axes["radius"]), len(cfg.axes["wall_thickness"])
    total, designs = 0, 0
    for j in range(pairs):
        ia = (na - 1) * j // max(pairs - 1, 1)
        it = (nt - 1) * (pairs - 1 - j) // max(pairs - 1, 1)
        n, out = counted_kernel(cfg, ia, it)
        total += n
        designs += int(np.prod(out.design.shape[3:]))  # (rows, 1, walls, L, C, psi)
    return total / designs
