"""The material arguments of :func:`~nylonflex.engine.pointwise.evaluate`, checked and
made into the kernel's arrays: a set name, a material object or a mapping whose numeric
fields may be arrays that broadcast against the designs; named sets prepared once a
process (:func:`_named_materials`)."""

from __future__ import annotations

from collections.abc import Mapping
from functools import lru_cache

import numpy as np

from ..materials import (NYLON_PARAMETERS, NYLON_TABLES, SILICONE_PARAMETERS, Nylon, Silicone,
                         check_nylon, check_silicone, nylon_parameters, silicone_kind,
                         silicone_parameters)
from ..physics.nylon import check_stroke_shape
from ..units import short

_MUSCLE_FIELDS = ("t_amb", "t_max", "gamma", "beta", "t_g", "sigma_g", "resistance_per_length",
                  "heat_capacity_per_length", "heat_loss_per_length",
                  "thermal_force_coefficient")
_SILICONE_FIELDS = ("mu", "alpha")


def _flat(x, shape, n):
    """``x`` broadcast to ``shape``, as a read-only contiguous 1-D float array of ``n``.

    A scalar (the common single-design case) is filled directly, 2 us instead of the
    broadcast's 10; either way the same values and the same array type (read-only, C), so
    the kernel is the one compiled body.
    """
    if isinstance(x, float) or (isinstance(x, np.ndarray) and x.ndim == 0):
        out = np.full(n, x, dtype=float)
        out.flags.writeable = False
        return out
    return np.ascontiguousarray(np.broadcast_to(x, shape), float).reshape(-1)


def _materials(silicone, nylon):
    """``(ogden, stretch_max, nylon arrays)`` of the material arguments, checked.

    Named sets (strings, the usual case) are prepared once a process
    (:func:`_named_materials`): a single design spent 0.6 ms here on every call. The
    cached nylon arrays are read-only; the Ogden arrays are copied (the kernel's record
    takes them writable, one compiled type).
    """
    if isinstance(silicone, str) and isinstance(nylon, str):
        (mu, alpha), stretch_max, ny = _named_materials(silicone, nylon)
        return (mu.copy(), alpha.copy()), stretch_max, dict(ny)
    ogden = _silicone_arrays(silicone)
    stretch_max = _stretch_max(silicone)
    ny = _nylon_arrays(nylon)
    check_stroke_shape(*(ny[k] for k in ("t_max", "t_amb", "gamma", "beta", "t_g",
                                          "sigma_g")))
    return ogden, stretch_max, ny


@lru_cache(maxsize=64)
def _named_materials(silicone: str, nylon: str):
    """:func:`_materials` of two set names (the registry's sets do not change)."""
    ogden = _silicone_arrays(silicone)
    stretch_max = _stretch_max(silicone)
    ny = _nylon_arrays(nylon)
    check_stroke_shape(*(ny[k] for k in ("t_max", "t_amb", "gamma", "beta", "t_g",
                                          "sigma_g")))
    for value in ny.values():
        value.flags.writeable = False
    return ogden, stretch_max, ny


def _batch_shapes(ogden, ny) -> list:
    """The shapes the material arrays add to the designs' broadcast (tables: columns off)."""
    return [ogden[0].shape[:-1], ogden[1].shape[:-1], ny["coil_index_table"].shape[:-1],
            ny["stroke_max_table"].shape[:-1], ny["tensile_strength_table"].shape[:-1],
            *(np.shape(v) for k, v in ny.items() if k not in NYLON_TABLES)]


@lru_cache(maxsize=64)
def _named_batch(silicone: str, nylon: str) -> list:
    """:func:`_batch_shapes` of two named sets (all scalars: every shape ``()``)."""
    ogden, _, ny = _named_materials(silicone, nylon)
    return _batch_shapes(ogden, ny)


@lru_cache(maxsize=16)
def _single_muscle(nylon: str) -> tuple:
    """The muscle record's arrays of one design of a named nylon set (read-only, cached),
    as ``_flat`` makes them."""
    ny = _nylon_arrays(nylon)
    return tuple(_flat(ny[k], (), 1) for k in _MUSCLE_FIELDS)


def _stretch_max(silicone) -> float:
    """Top of the silicone set's fitted stretch range [-] (inf when it records none)."""
    base = silicone
    if isinstance(silicone, Mapping):
        base = {k: v for k, v in silicone.items() if np.ndim(v) <= 1 or k == "stretch_range"}
        base = {k: v for k, v in base.items() if k not in _SILICONE_FIELDS}
    return float(silicone_parameters(base).stretch_range[1])


# --------------------------------------------------------------------------- materials

def _short(value, n=40):
    return short(value, n)


def _split(kind, value, table, fields):
    """(base set object, {field: array override}) of a material argument."""
    if isinstance(value, (Silicone, Nylon)) or isinstance(value, str):
        return value, {}
    if not isinstance(value, Mapping):
        raise ValueError(f"{kind}: must be a set name, a mapping with 'set' or a material "
                         f"object, got {_short(value)}")
    arrays = {k: v for k, v in value.items() if k != "set" and k in fields and np.ndim(v) > 1}
    scalar = {k: v for k, v in value.items() if k not in arrays}
    return scalar, arrays


def _as_array(kind, key, value):
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{kind}.{key}: must be numbers, got {_short(value)}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{kind}.{key}: must be finite, got {arr[~np.isfinite(arr)].flat[0]:g}")
    return arr


def _silicone_arrays(silicone):
    """``(mu, alpha)`` arrays of shape (..., terms) of a silicone argument, checked."""
    base, arrays = _split("silicone", silicone, SILICONE_PARAMETERS, _SILICONE_FIELDS)
    if not arrays:
        s = silicone_parameters(base)
        return np.asarray(s.mu, float), np.asarray(s.alpha, float)
    s = silicone_parameters({k: v for k, v in base.items()})  # the set and scalar fields
    mu = _as_array("silicone", "mu", arrays.get("mu", s.mu))
    alpha = _as_array("silicone", "alpha", arrays.get("alpha", s.alpha))
    if mu.shape[-1] != alpha.shape[-1]:
        raise ValueError("silicone.mu/alpha: need the same number (1 to 6) of terms on the "
                         f"last axis, got shapes {mu.shape} and {alpha.shape}")
    name = base.get("set") if isinstance(base, Mapping) else None
    check_silicone(mu, alpha, kind=silicone_kind(base),
                   name=name if isinstance(name, str) else None)
    return mu, alpha


def _silicone_rows(ogden, shape):
    mu, alpha = ogden
    if mu.ndim == 1 and alpha.ndim == 1:
        return mu.reshape(1, -1), alpha.reshape(1, -1)
    k = mu.shape[-1]
    return (np.broadcast_to(mu, (*shape, k)), np.broadcast_to(alpha, (*shape, k)))


def _nylon_arrays(nylon) -> dict:
    """Every numeric field of a nylon argument as an array (tables: columns last), checked."""
    base, arrays = _split("nylon", nylon, NYLON_PARAMETERS, NYLON_TABLES)
    numeric = {k: v for k, v in (base.items() if isinstance(base, Mapping) else ())
               if k != "set" and np.ndim(v) > 0 and k not in NYLON_TABLES}
    scalar_base = {k: v for k, v in base.items() if k not in numeric} \
        if isinstance(base, Mapping) else base
    ny = nylon_parameters(scalar_base)
    out = {k: np.asarray(v, float) for k, v in ny.to_dict().items() if k != "name"}
    # to_dict leaves a resistance_coil_index of 0 out (the set's hash); the kernel needs it
    out.setdefault("resistance_coil_index", np.asarray(ny.resistance_coil_index, float))
    for key, value in {**numeric, **arrays}.items():
        out[key] = _as_array("nylon", key, value)
    if not numeric and not arrays:
        return out
    check_nylon(out)  # the named sets' own validator, on the arrays
    return out


def _rows(table, shape):
    """A table as (m,) when shared by every design, else (n, m) one row a design."""
    if table.ndim == 1:
        return table
    return np.ascontiguousarray(np.broadcast_to(table, (*shape, table.shape[-1]))).reshape(
        -1, table.shape[-1])


def _interp(x, xp, fp):
    """``np.interp`` of each design's coil index in its own table (rows of ``xp``, ``fp``).

    With 1-D tables this is ``np.interp`` itself; with per-design tables it repeats
    NumPy's arithmetic (slope times offset plus the left value; a node returns its value)
    so both give the same bits.
    """
    if xp.ndim == 1 and fp.ndim == 1:
        return np.interp(x, xp, fp)
    xp, fp = np.broadcast_arrays(np.atleast_2d(xp), np.atleast_2d(fp))
    xp = np.broadcast_to(xp, (x.size, xp.shape[-1]))
    fp = np.broadcast_to(fp, (x.size, fp.shape[-1]))
    m = xp.shape[-1]
    if m == 1:
        return fp[:, 0].copy()
    j = np.clip(np.sum(xp[:, 1:] <= x[:, None], axis=1), 0, m - 2)
    rows = np.arange(x.size)
    x0, x1, y0, y1 = xp[rows, j], xp[rows, j + 1], fp[rows, j], fp[rows, j + 1]
    slope = (y1 - y0) / (x1 - x0)
    out = slope * (x - x0) + y0
    out = np.where(x == x0, y0, out)
    return np.where(x == xp[:, -1], fp[:, -1], out)
