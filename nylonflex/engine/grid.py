"""The design grid: slab plan, one slab through the grid kernel, the arrays without radius.

The design space is cut into slabs of consecutive radii, each of bounded memory
(``slab_megabytes`` in the config); every other axis is whole in a slab. A slab is what an
executor computes and a sink stores (:mod:`.slabs`).
"""

from __future__ import annotations

import threading
import weakref

import numpy as np

from ..config import ResolvedConfig
from ..kernels.rows import FLOAT_DESIGN
from ..physics.chamber import chamber_pressure
from ..physics.limits import MODELS
from ..physics.nylon import check_stroke_shape, nylon_force_limit, stroke_max
from ..physics.thermal import (check_supply_rise, coil_heat_loss_per_length,
                               coil_resistance_per_length)
from ..physics.wrap import muscle_width, outer_perimeter
from ..variables import COORDS, CURVES, DESIGN, SUPPLY_ONLY
from .model_slab import coil_table, model_slab
from .sampled import slab_statistics, uncertain_variables
from .spread import extra_models, spread_arrays, spread_variables
from .tracking import slab_tracking, tracking_variables

__all__ = ["FLOAT_DESIGN", "bytes_per_radius", "coil_table", "compute_slab", "coords",
           "cube_variables", "global_arrays", "plan_slabs", "slab_variables"]

# FLOAT_DESIGN (exported): the float design variables in the registry's order, the rows of
# the kernel's ``out.design`` (nylonflex.kernels.rows, the table the kernels write by)


def cube_variables(cfg: ResolvedConfig) -> dict:
    """``{name: (Variable, dims)}`` of every variable ``cfg``'s cube holds, in order.

    With several models, the variables that depend on the model gain a ``model``
    dimension, and with several cooling sets those that depend on the heat loss a last
    ``cooling`` one (:meth:`~nylonflex.variables.Variable.by_cooling`); ``heating_time`` is
    there only with a supply (docs/model.md s. 15-16); the quantiles and feasibility only
    with ``uncertainty``/``requirements``.
    """
    supply = cfg.supply_voltage is not None
    out = {n: (v, v.dims_for(cfg.models, cfg.cooling_names, supply))
           for n, v in {**DESIGN, **CURVES}.items() if supply or n not in SUPPLY_ONLY}
    # a sampled sweep's quantiles and feasibility (docs/uncertainty.md)
    out.update({n: (v, v.dims) for n, v in uncertain_variables(cfg).items()})
    # the closed loop of every design (docs/model.md s. 19)
    out.update({n: (v, v.dims) for n, v in tracking_variables(cfg).items()})
    # the range over a model spread, on its variable's cooling dimension (docs/model.md s. 22)
    out.update({n: (v, v.dims_for((), cfg.cooling_names, supply))
                for n, v in spread_variables(cfg).items()})
    return out


def slab_variables() -> dict:
    """Registry entries of every variable with a radius dimension (what a slab holds)."""
    return {n: v for n, v in {**DESIGN, **CURVES}.items() if v.dims[0] == "radius"}


def coords(cfg: ResolvedConfig) -> dict:
    """Every coordinate of the cube: the five axes and the two curve axes, SI arrays (and
    the probability levels ``quantile`` of a sweep with ``uncertainty``)."""
    out = {**cfg.axes, **cfg.curves}
    if cfg.uncertainty is not None:
        out["quantile"] = np.asarray(cfg.uncertainty.quantiles, float)
    return out


def bytes_per_radius(cfg: ResolvedConfig) -> int:
    """Bytes [B] that one radius of ``cfg``'s cube holds uncompressed: every variable that
    runs along ``radius``, over the other dimensions (the size of a slab per radius)."""
    sizes = {k: len(v) for k, v in coords(cfg).items()}
    sizes["model"] = len(cfg.models)
    sizes["cooling"] = len(cfg.coolings)
    return sum(int(np.prod([sizes[d] for d in dims[1:]])) * np.dtype(v.dtype).itemsize
               for v, dims in cube_variables(cfg).values() if dims[0] == "radius")


def plan_slabs(cfg: ResolvedConfig) -> tuple[list[tuple[int, int]], int]:
    """Slabs ``[(i0, i1), ...]`` of radius indices, and the HDF5 chunk length along radius.

    A slab holds as many radii as fit in ``cfg.slab_megabytes`` (at least one), a multiple
    of the chunk length so that slabs write whole chunks.
    """
    per = bytes_per_radius(cfg)
    na = cfg.shape[0]
    per_slab = min(na, max(1, int(cfg.slab_megabytes * 2**20) // per))
    # chunks of about 2 MB of one variable, never longer than a slab
    chunk = min(per_slab, _chunk_cap(per))
    per_slab = (per_slab // chunk) * chunk
    return _uniform_slabs(na, per_slab), chunk


def check_physics(cfg: ResolvedConfig):
    """Cross-checks of an accepted config that its fields' ranges cannot make: the muscle's
    stroke shape rises to T_max (:func:`~nylonflex.physics.nylon.check_stroke_shape`), and
    the supply heats the grid's longest muscle at least
    :data:`~nylonflex.physics.thermal.MIN_SUPPLY_RISE` above ambient. Checked before any
    file is made or kernel run (ValueError, one line).

    The longest muscle: l_m = L P_out / (pitch cos psi) with pitch = max(P_out tan psi,
    w / cos psi) is L min(1 / sin psi, P_out / w), and psi is independent of P_out and w, so
    its largest value over the grid is L_max min(1 / sin psi_min, P_max / w_min).
    """
    ny = cfg.nylon
    check_stroke_shape(ny.t_max, ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    if cfg.supply_voltage is None:
        return
    for cooling in cfg.coolings:  # a cube of several cooling sets: each must heat
        check_physics(cfg.with_cooling(cooling))
    if cfg.coolings:
        return
    ax = cfg.axes
    p_max = float(outer_perimeter(ax["radius"][-1], ax["wall_thickness"][-1],
                                  cfg.base_thickness))
    w_min = float(np.min(muscle_width(ax["coil_index"], ny)))
    l_max = ax["length"][-1] * min(1.0 / np.sin(ax["wrap_angle"][0]), p_max / w_min)
    # r' and lambda' per coil index: the largest product gives the least rise (a bound)
    c = ax["coil_index"]
    product = np.atleast_1d(coil_resistance_per_length(c, ny)) * \
        np.atleast_1d(coil_heat_loss_per_length(c, ny, cfg.cooling))
    j = int(np.argmax(product))
    check_supply_rise(cfg.supply_voltage, l_max,
                      np.atleast_1d(coil_resistance_per_length(c, ny))[j],
                      np.atleast_1d(coil_heat_loss_per_length(c, ny, cfg.cooling))[j])


def _chunk_cap(per_radius: int) -> int:
    """The longest chunk along radius [radii]: about 2 MB of one variable."""
    return max(1, (2 * 2**20) // max(1, per_radius // 9))


def _uniform_slabs(na: int, per_slab: int) -> list[tuple[int, int]]:
    return [(i, min(na, i + per_slab)) for i in range(0, na, per_slab)]


def plan_is_implied(cfg: ResolvedConfig, slabs, chunk) -> bool:
    """Whether ``(slabs, chunk)`` is a plan :func:`plan_slabs` gives this config for some
    ``slab_megabytes`` (which may change between a run and its resume): slabs of one length
    ``n`` from radius 0 to the last, and a chunk length of ``min(n, cap)``."""
    na = cfg.shape[0]
    try:
        slabs = [(int(a), int(b)) for a, b in slabs]
    except (TypeError, ValueError):
        return False
    if not slabs or not isinstance(chunk, int) or isinstance(chunk, bool):
        return False
    n = slabs[0][1] - slabs[0][0]
    if not 1 <= n <= na:
        return False
    return slabs == _uniform_slabs(na, n) and \
        chunk == min(n, _chunk_cap(bytes_per_radius(cfg))) and n % chunk == 0


class ArrayPool:
    """Output arrays handed back once a slab is stored, and handed out again.

    A sweep's slabs have the same shapes, and a fresh array costs the kernel the zeroing of
    every page it writes (a quarter of a second a 20 M-design sweep). :meth:`empty` gives a
    handed-back array of the shape and dtype when there is one; :meth:`give_back` takes the
    arrays of a stored slab (views of the pool's arrays count as those arrays).
    """

    def __init__(self):
        self._free: dict = {}
        self._made: dict = {}  # id -> weak reference of each array the pool made
        self._lock = threading.Lock()

    def empty(self, shape, dtype=float) -> np.ndarray:
        key = (tuple(int(n) for n in shape), np.dtype(dtype).str)
        with self._lock:
            free = self._free.get(key)
            if free:
                return free.pop()
            out = np.empty(key[0], dtype=dtype)
            self._made[id(out)] = weakref.ref(out, lambda _, i=id(out): self._made.pop(i, None))
        return out

    def give_back(self, arrays):
        """Return the pool's arrays behind ``arrays`` (a dict or iterable of arrays)."""
        values = arrays.values() if isinstance(arrays, dict) else arrays
        bases = {}
        for a in values:
            base = a if getattr(a, "base", None) is None else a.base
            ref = self._made.get(id(base))
            if ref is not None and ref() is base:
                bases[id(base)] = base
        with self._lock:
            for base in bases.values():
                self._free.setdefault((base.shape, base.dtype.str), []).append(base)


def compute_slab(cfg: ResolvedConfig, i0: int, i1: int, parallel: bool = True,
                 pool: ArrayPool | None = None) -> dict:
    """Every radius-dependent variable of the radii [i0, i1), as a dict of arrays.

    ``parallel`` splits the kernel over the engine's threads (:mod:`.threads`); False runs it
    in this thread (Dask workers). With
    several models (cooling sets) the kernel runs once a model (and cooling set) and the
    variables that depend on them are stacked along last axes, model then cooling
    (docs/model.md s. 9, 16). ``pool``: the kernel's output arrays
    come from it (and go back to it when the caller is done with the slab).
    """
    coolings = [cfg.with_cooling(c) for c in cfg.coolings] or [cfg]
    slabs = {(m, k): _compute_model_slab(one, i0, i1, parallel, MODELS.index(m), pool)
             for m in cfg.models for k, one in enumerate(coolings)}
    # a model spread's other variants: the kernel's rows alone, for the range
    # (docs/model.md s. 22)
    extra = {(m, k): model_slab(one, i0, i1, parallel, MODELS.index(m), pool)
             for m in extra_models(cfg) for k, one in enumerate(coolings)}
    variables = cube_variables(cfg)
    spread = spread_variables(cfg)
    arrays = {}
    if spread:
        arrays.update(spread_arrays(cfg, {**slabs, **extra},
                                    {n: variables[n][1] for n in spread}))
        if pool is not None:  # the range is taken: their arrays may serve the next slab
            for rows in extra.values():
                pool.give_back(rows)
    for name, (v, dims) in variables.items():
        if dims[0] != "radius" or name in spread:
            continue
        by_model, by_cooling = "model" in dims, "cooling" in dims
        ks = range(len(coolings))
        per_model = [np.stack([slabs[m, k][name] for k in ks], axis=-1) if by_cooling
                     else slabs[m, 0][name]
                     for m in (cfg.models if by_model else cfg.models[:1])]
        arrays[name] = np.stack(per_model, axis=-2 if by_cooling else -1) if by_model \
            else per_model[0]
    return arrays


def _compute_model_slab(cfg, i0, i1, parallel, model, pool=None):
    arrays = model_slab(cfg, i0, i1, parallel, model, pool)
    if cfg.uncertainty is not None or cfg.requirements:  # docs/uncertainty.md
        arrays.update(slab_statistics(cfg, i0, i1, arrays, model, parallel=parallel))
    if cfg.tracking is not None:  # docs/model.md s. 19
        arrays.update(slab_tracking(cfg, i0, i1, arrays, parallel=parallel))
    return arrays


def global_arrays(cfg: ResolvedConfig) -> dict:
    """Variables without a radius dimension: per coil index and per stroke."""
    c = cfg.axes["coil_index"]
    column = lambda x: np.asarray(x, float).reshape(-1)  # noqa: E731
    return {"nylon_force_limit": column(nylon_force_limit(c, cfg.nylon)),
            "stroke_max": column(stroke_max(c, cfg.nylon)),
            "chamber_pressure": column(chamber_pressure(cfg.curves["stroke"]))}


def _check_registry():
    # every variable of the registry is either a slab variable or a global one
    assert set(slab_variables()) | {"nylon_force_limit", "stroke_max", "chamber_pressure"} \
        == set(DESIGN) | set(CURVES), "variables.py and engine.grid disagree"
    assert all(n in COORDS for v in {**DESIGN, **CURVES}.values() for n in v.dims)


_check_registry()
