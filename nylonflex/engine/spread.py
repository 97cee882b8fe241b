"""The model spread of a sweep with ``fidelity: spread`` (docs/model.md s. 22).

The cube's values are its own model's; beside the headline variables
(:data:`~nylonflex.variables.SPREAD_OF`) it stores their lowest and highest value over the
config's variants (``<var>_model_lo``, ``<var>_model_hi``) and the OR of the variants'
validity bits (``validity_model_any``). The range is taken from the per-model slabs the
grid already computes (:func:`nylonflex.engine.grid.compute_slab` runs the slab kernel
once a model): no second physics path. It is a function of a slab's per-model values
alone, so a resumed sweep (whose journal keeps whole slabs) stores the same range.

**[choice] Flagged designs enter the range.** A variant whose design carries a validity
bit (self contact, stretch beyond the silicone's fit, ...) still gives its number: the
flag marks where that model's own assumptions stop holding, so leaving it out would
narrow the range exactly where the models are least sure. ``validity_model_any`` says
where some variant is flagged. A variant without a value (NaN) is left out; NaN where
none has one.
"""

from __future__ import annotations

import numpy as np

from ..config import ResolvedConfig
from ..variables import SPREAD, SPREAD_OF, spread_name

__all__ = ["extra_models", "spread_arrays", "spread_variables"]


def spread_variables(cfg: ResolvedConfig) -> dict:
    """``{name: Variable}`` of the spread variables ``cfg``'s cube holds (none without
    ``fidelity: spread``)."""
    return dict(SPREAD) if cfg.spread else {}


def extra_models(cfg: ResolvedConfig) -> tuple[str, ...]:
    """The spread's variants the cube does not store (computed for the range only)."""
    return tuple(m for m in cfg.spread if m not in cfg.models)


def spread_arrays(cfg: ResolvedConfig, slabs: dict, dims: dict) -> dict:
    """The spread variables of one slab.

    Parameters
    ----------
    cfg : ResolvedConfig
        A config with ``spread``.
    slabs : dict
        ``{(model, k): arrays}``: each variant's named rows (:func:`~.model_slab.model_slab`)
        under each cooling set ``k`` (0 alone without a cooling list), for every variant of
        ``cfg.spread``.
    dims : dict
        ``{name: dims}`` of the spread variables in the cube (a last ``cooling`` dimension
        stacks the cooling sets, as the cube's own variables do).

    Returns
    -------
    dict
        ``{name: array}``, the slab's radii first; the range in SI (the variable's units).
    """
    out = {}
    for name in (*(spread_name(n, "lo") for n in SPREAD_OF), "validity_model_any"):
        base = name.removesuffix("_model_lo") if name != "validity_model_any" else "validity"
        by_cooling = "cooling" in dims[name]
        n_cool = 1 + max(k for _, k in slabs)
        stack = np.stack([np.stack([slabs[m, k][base] for k in range(n_cool)], axis=-1)
                          if by_cooling else slabs[m, 0][base] for m in cfg.spread])
        if base == "validity":
            out[name] = np.bitwise_or.reduce(stack, axis=0).astype(np.int8)
            continue
        # fmin/fmax skip NaN (a variant without a value), NaN where every one is
        out[name] = np.fmin.reduce(stack, axis=0)
        out[spread_name(base, "hi")] = np.fmax.reduce(stack, axis=0)
    return out
