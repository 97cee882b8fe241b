"""Copies of a formula or a kernel body with some of their globals fixed, for Numba.

Numba compiles a function's globals as constants and prunes the branches that a constant
decides before typing, so a copy that serves one case compiles none of the formulas of the
others: the grid kernel of the paper's model (``_PAPER_ONLY`` fixed) and, inside it, the
paper's stroke limit (the paper's nylon force in place of the variants'),
:mod:`.design`. This is compiler machinery, so it lives here, not in the physics layer,
whose formulas stay the one plain source both layers run.
"""

from __future__ import annotations

import types

from numba.extending import register_jitable

from ._compile import CALLEE_OPTIONS, is_formula

__all__ = ["specialised"]


def specialised(func, name, **names):
    """A copy of ``func`` named ``name`` (same code, module and docstring) in which the
    global ``names`` are the values given: a compile-time constant (``_PAPER_ONLY=True``) or
    another formula to call (``_nylon_force_model=_paper_force``).

    In Python the copy runs the same lines. Its globals are those of ``func``'s module when
    the copy is made, so it is made after everything it calls. A copy of a physics
    ``@formula`` is one too, and is made callable from jitted code by its own object
    (as :mod:`._compile` does for the formulas of the physics modules), so a specialised
    caller can call it.
    """
    scope = {**func.__globals__, **names}
    copy = types.FunctionType(func.__code__.replace(co_name=name, co_qualname=name), scope,
                              name, func.__defaults__)
    copy.__module__, copy.__qualname__, copy.__doc__ = func.__module__, name, func.__doc__
    if is_formula(func):
        copy.__nylonflex_formula__ = True
        register_jitable(**CALLEE_OPTIONS)(copy)
        copy.__nylonflex_registered__ = True
    return copy
