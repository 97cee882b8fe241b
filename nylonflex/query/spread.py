"""A query's model spread (``fidelity: spread``, docs/model.md s. 22): its columns between
grid points.

On the grid the cube's ``<var>_model_lo``/``_hi`` and ``validity_model_any`` are read like
any column. Between grid points the exact model gives them as the sweep did: every variant
of the cube's ``model_spread`` evaluated at the design, their lowest and highest value, the
OR of their flags (:func:`exact_spread`); ``--interpolate`` interpolates them, the tip
forces and angles through their length-free parts (:data:`TIMES_LENGTH`,
:data:`PER_LENGTH`), as it does the headline values.
"""

from __future__ import annotations

import numpy as np

from ..variables import AXES, SPREAD, SPREAD_OF, spread_name

__all__ = ["PER_LENGTH", "TIMES_LENGTH", "exact_spread", "spread_variants"]

#: Columns proportional to 1/L at a fixed length-free state (F* = M*/L, docs/model.md s. 8).
TIMES_LENGTH = ("tip_force_max", spread_name("tip_force_max", "lo"),
                spread_name("tip_force_max", "hi"))
#: Columns proportional to L (theta* = kappa* L).
PER_LENGTH = ("bend_angle_max", spread_name("bend_angle_max", "lo"),
              spread_name("bend_angle_max", "hi"))


def exact_spread(rows: dict, settings: dict, evaluate, variants) -> dict:
    """The spread columns of ``rows`` (SI arrays by column, the five axes given) from the
    exact model ``evaluate`` under each of ``variants`` with the cube's ``settings``
    (:meth:`~nylonflex.engine.provenance.CubeSettings.evaluate_kwargs`)."""
    n = len(rows[AXES[0]])
    if not n or not variants:
        return {name: np.full(n, np.nan) for name in SPREAD}
    outs = [evaluate(*(rows[name] for name in AXES), **{**settings, "model": m})
            for m in variants]
    got = {}
    for name in SPREAD_OF:
        stack = np.stack([np.asarray(o[name], dtype=float).reshape(-1) for o in outs])
        got[spread_name(name, "lo")] = np.fmin.reduce(stack, axis=0)
        got[spread_name(name, "hi")] = np.fmax.reduce(stack, axis=0)
    bits = np.stack([np.asarray(o["validity"], dtype=float).reshape(-1) for o in outs])
    known = np.isfinite(bits).all(axis=0)
    ored = np.bitwise_or.reduce(np.nan_to_num(bits).astype(np.int64), axis=0)
    got["validity_model_any"] = np.where(known, ored.astype(float), np.nan)
    return got


def spread_variants(ds) -> tuple[str, ...]:
    """The variants of a cube's model spread (its ``model_spread`` attribute), () without
    one."""
    from ..engine.provenance import cube_settings

    if not any(n in ds for n in SPREAD):
        return ()
    try:
        return cube_settings(ds).spread
    except ValueError:
        return ()
