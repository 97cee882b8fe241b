"""The ``tracking:`` variables of a slab: the figure-9 closed loop of every design
(docs/model.md s. 19), through :mod:`nylonflex.kernels.tracking`.

Each design's loop is ``nylonflex simulate``'s for that design alone (one actuator, the
sweep's supply and ``cooling:``, no internal resistance): the same top pressure and
estimator table, the same sensor noise sequence (the seed's), controller and thermal step,
with r'(C) and lambda'(C) of the design's coil index (docs/model.md s. 9). Only the plant's
angle table differs in its grid: one curvature table per (radius, wall) of the slab, on
:data:`PLANT_POINTS` points up to the highest pressure of its designs, instead of 513
points up to each design's own (both within 1e-9 of the curvature solve).
"""

from __future__ import annotations

import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import numpy as np

from ..config import ResolvedConfig
from ..kernels.rows import N_TRACKING, TRACKING_ROWS
from ..kernels.scratch import node_scratch
from ..physics.bending import NEWTON_RTOL, quadrature_nodes
from ..physics.chamber import P_ATM, chamber_pressure
from ..physics.nylon import stroke, stroke_scale
from ..physics.records import Ogden
from ..physics.thermal import coil_heat_loss_per_length, coil_resistance_per_length, \
    steady_temperature
from ..physics.wrap import muscle_length
from ..variables import AXES, TRACKING
from . import threads
from .pointwise import evaluate
from .sampled import perturbed_configs, perturbed_inputs
from .threads import run_chunks

__all__ = ["PLANT_POINTS", "design_tracking", "sampled_tracking", "slab_tracking",
           "tracking_variables"]

#: Points of each (radius, wall)'s curvature table: four times the density of
#: ``nylonflex simulate``'s 513 over a design's own range.
PLANT_POINTS = 2049

#: Strokes from here on are refused by ``nylonflex simulate`` (Boyle and the wrap mean
#: nothing): such designs get NaN.
_STROKE_CAP = 0.5


def tracking_variables(cfg: ResolvedConfig) -> dict:
    """Registry entries of the variables ``cfg``'s ``tracking:`` adds (none without it);
    ``tracking_bandwidth`` only with ``tracking.bandwidth``."""
    spec = cfg.tracking
    if spec is None:
        return {}
    return {n: v for n, v in TRACKING.items()
            if n != "tracking_bandwidth" or spec.bandwidth is not None}


def sensor_noise(spec, samples: int) -> np.ndarray:
    """The pressure-sensor noise at each sample [Pa]: ``nylonflex simulate``'s sequence of
    the seed (a single actuator's), extended to ``samples``."""
    if spec.noise > 0:
        return np.random.default_rng(spec.seed).normal(0.0, spec.noise, samples)
    return np.zeros(samples)


def _longest_run(spec) -> int:
    """Samples of the longest run: the main one, or the bandwidth's at its lowest f."""
    m = spec.n_steps
    if spec.bandwidth is not None:
        b = spec.bandwidth
        m = max(m, int(math.floor((1.0 + b["periods"]) / b["low"] / spec.step + 1e-9)) + 1)
    return m


def top_pressure(cfg: ResolvedConfig, lm, coil_index) -> np.ndarray:
    """The highest gauge pressure each design reaches [Pa], the top of its estimator table:
    ``nylonflex simulate``'s, at T = max(T(0), T_ss(supply)) with lambda'(C) of the
    config's cooling set (the nylon set's own without one); NaN where that stroke is at
    least 0.5 (simulate refuses those). ``lm`` [m] and ``coil_index`` broadcast."""
    ny, spec = cfg.nylon, cfg.tracking
    t0 = ny.t_amb if spec.initial_temperature is None else spec.initial_temperature
    r = coil_resistance_per_length(coil_index, ny) * lm
    v = cfg.supply_voltage * r / (r + 0.0)  # simulate's terminal voltage, no source resistance
    top = np.maximum(t0, steady_temperature(v, lm, ny, coil_index=coil_index,
                                            cooling=cfg.cooling))
    s_top = np.asarray(stroke(top, coil_index, ny), float)
    p = np.asarray(chamber_pressure(np.minimum(s_top, _STROKE_CAP)), float) * (1.0 + 1e-9)
    return np.where(s_top < _STROKE_CAP, np.maximum(p, 1.0), np.nan)


def slab_tracking(cfg: ResolvedConfig, i0: int, i1: int, nominal: dict,
                  parallel: bool = True, table_top=None) -> dict:
    """The tracking variables of the radii [i0, i1), shape (radius, wall, length, coil,
    wrap) each.

    ``nominal`` is the slab's grid-kernel result (``bend_angle_max`` scales a reference
    relative to it). ``parallel=False`` (Dask workers) runs the serial kernels.
    ``table_top`` [Pa], shape (radius, wall), is the top of each (radius, wall)'s plant
    table; by default the highest pressure of the slab's designs (see
    :func:`design_tracking`, which runs one design as a whole grid would).
    """
    from ..kernels import tracking as kt

    spec, ny = cfg.tracking, cfg.nylon
    ax = cfg.axes
    a = np.ascontiguousarray(ax["radius"][i0:i1])
    t, L, C, psi = ax["wall_thickness"], ax["length"], ax["coil_index"], ax["wrap_angle"]
    grid = np.meshgrid(a, t, L, C, psi, indexing="ij", sparse=True)
    base = None if cfg.base_thickness is None else float(cfg.base_thickness)
    lm = np.ascontiguousarray(np.broadcast_to(
        muscle_length(grid[0], grid[1], grid[2], grid[4], grid[3], base, ny),
        (len(a), len(t), len(L), len(C), len(psi))), dtype=float)
    p_top = np.ascontiguousarray(top_pressure(cfg, lm, grid[3]))
    if table_top is not None:
        p_group = np.ascontiguousarray(np.reshape(table_top, (len(a), len(t))), dtype=float)
    else:
        with np.errstate(all="ignore"):
            p_group = np.ascontiguousarray(
                np.nanmax(p_top.reshape(len(a), len(t), -1), axis=2)
                if p_top.size else np.zeros((len(a), len(t))))
    scale = np.array([float(stroke_scale(c, np.asarray(ny.coil_index_table),
                                         np.asarray(ny.stroke_max_table), ny.t_amb,
                                         ny.t_max, ny.gamma, ny.beta, ny.t_g, ny.sigma_g))
                      for c in C])
    if spec.relative_to == "bend_angle_max":
        ref_scale = np.ascontiguousarray(nominal["bend_angle_max"], dtype=float)
    else:
        ref_scale = np.ones(lm.shape)
    mu, alpha = cfg.silicone.arrays()
    nodes = quadrature_nodes()
    kappa = np.empty((len(a), len(t), PLANT_POINTS))
    slope = np.empty_like(kappa)
    run_chunks(lambda q0, q1: kt.kappa_tables(
        p_group, a, t, -1.0 if base is None else base, Ogden(mu, alpha), nodes, NEWTON_RTOL,
        node_scratch(nodes), kappa, slope, q0, q1), len(a) * len(t), parallel=parallel)
    t0 = ny.t_amb if spec.initial_temperature is None else spec.initial_temperature
    muscle = (np.ascontiguousarray(np.atleast_1d(coil_resistance_per_length(C, ny)), float),
              ny.heat_capacity_per_length,
              np.ascontiguousarray(np.atleast_1d(coil_heat_loss_per_length(C, ny, cfg.cooling)),
                                   float),
              ny.t_amb, t0, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    keep = math.exp(-spec.step / spec.filter_time_constant) \
        if spec.filter_time_constant > 0 else 0.0
    settings = (spec.step, spec.n_steps, float(cfg.supply_voltage), P_ATM,
                spec.table_points, int(spec.controller == "pi"), 0.5 * spec.hysteresis,
                1.0 / spec.proportional_band, spec.step / spec.integral_time, keep)
    reference = (0 if spec.kind == "sine" else 1, spec.mean, spec.amplitude, spec.frequency,
                 spec.phase, spec.initial, spec.final, spec.at, spec.rms_from)
    b = spec.bandwidth
    bandwidth = (0, 0.0, 1.0, 1.0, 0, 1) if b is None else \
        (1, b["error"], b["low"], b["high"], b["iterations"], b["periods"])
    out = np.empty((N_TRACKING, lm.size))
    args = ((a, t, L, -1.0 if base is None else base), (lm, p_top, scale, ref_scale),
            (p_group, kappa, slope), muscle, Ogden(mu, alpha), nodes, NEWTON_RTOL,
            (settings, reference, bandwidth, sensor_noise(spec, _longest_run(spec))), out)
    run_chunks(lambda q0, q1: kt.track_slab(*args, kt.track_scratch(nodes, spec.table_points),
                                            q0, q1), lm.size, parallel=parallel)
    wanted = tracking_variables(cfg)
    return {name: out[row].reshape(lm.shape) for name, row in TRACKING_ROWS.items()
            if name in wanted}


def design_tracking(cfg: ResolvedConfig, design: dict, bend_angle_max: float | None = None,
                    parallel: bool = True) -> dict:
    """The tracking variables of one design, as a sweep of ``cfg``'s grid gives them.

    The design need not be a grid point (a perturbed wall, an ``--at`` value): its plant
    table spans the highest pressure of the grid designs of its radius and wall (the
    config's length, coil and wrap axes) and its own, as its slab's would; on a grid design
    the values are the cube's, bit for bit.

    Parameters
    ----------
    cfg : ResolvedConfig
        Materials, supply and ``tracking:`` (needed); its axes give the plant table's group.
    design : dict of str to float
        The five axes [SI].
    bend_angle_max : float, optional
        theta* [rad] of the design under ``cfg``'s materials, for a reference relative to
        it (``tracking.reference.relative_to: bend_angle_max``); unused otherwise.
    parallel : bool
        False: the serial kernels (one thread; callers that run designs in threads).

    Returns
    -------
    dict of str to float
        :func:`tracking_variables`' names.
    """
    one = {k: np.array([float(design[k])]) for k in AXES}
    ny, ax = cfg.nylon, cfg.axes
    base = None if cfg.base_thickness is None else float(cfg.base_thickness)
    group = [np.concatenate([ax[k], one[k]]) for k in ("length", "coil_index", "wrap_angle")]
    L, C, psi = np.meshgrid(*group, indexing="ij", sparse=True)
    lm = muscle_length(one["radius"][0], one["wall_thickness"][0], L, psi, C, base, ny)
    with np.errstate(all="ignore"):
        top = np.nanmax(top_pressure(cfg, np.broadcast_to(lm, np.broadcast(L, C, psi).shape),
                                     C))
    if cfg.tracking.relative_to == "bend_angle_max" and bend_angle_max is None:
        raise ValueError("bend_angle_max: needed for a reference relative to it")
    nominal = {"bend_angle_max": np.full((1,) * 5, np.nan if bend_angle_max is None
                                         else float(bend_angle_max))}
    out = slab_tracking(replace(cfg, axes=one), 0, 1, nominal, parallel=parallel,
                        table_top=np.full((1, 1), top))
    return {k: float(v.reshape(-1)[0]) for k, v in out.items()}


def sampled_tracking(cfg: ResolvedConfig, design: dict, z: np.ndarray, names=None,
                     bend_angle_max=None, parallel: bool = True) -> dict:
    """The tracking variables of one design under each sample of the uncertain parameters.

    Each sample is :func:`design_tracking` of the design under that sample's materials
    (and moved axes, :func:`~.sampled.perturbed_configs`): the value a sweep of a config
    with those materials would hold. A run takes about 8 ms (a plant table and the loop;
    ``tracking.bandwidth``'s search several runs more); the samples run in threads, one a
    Numba thread (the kernels release the GIL).

    Parameters
    ----------
    cfg : ResolvedConfig
        Materials, ``tracking:`` and ``uncertainty:``.
    design : dict of str to float
        The five axes [SI].
    z : ndarray
        Standard variables, shape (S, dims).
    names : sequence of str, optional
        The tracking variables wanted (default all of :func:`tracking_variables`); the
        bandwidth search runs only when ``tracking_bandwidth`` is among them.
    bend_angle_max : ndarray, optional
        theta* [rad] of each sample (S,), for a reference relative to it; computed by the
        evaluator when not given.
    parallel : bool
        False: one thread.

    Returns
    -------
    dict of str to ndarray
        ``names``, shape (S,) each.
    """

    names = tuple(tracking_variables(cfg) if names is None else names)
    pairs = perturbed_configs(cfg, design, z)
    if "tracking_bandwidth" not in names and cfg.tracking.bandwidth is not None:
        # the search is several runs a design: only when asked for (the main run's noise
        # is the same: the sequence of the seed, only shorter)
        quick = replace(cfg.tracking, bandwidth=None)
        pairs = [(d, replace(c, tracking=quick)) for d, c in pairs]
    if cfg.tracking.relative_to == "bend_angle_max" and bend_angle_max is None:
        one = {k: np.asarray(design[k], float) for k in design}
        bend_angle_max = np.asarray(evaluate(**perturbed_inputs(one, cfg, z))
                                    ["bend_angle_max"], float).reshape(-1)
    theta = [None] * len(pairs) if bend_angle_max is None else \
        np.broadcast_to(np.asarray(bend_angle_max, float).reshape(-1), (len(pairs),))

    def run(s):
        d, c = pairs[s]
        return design_tracking(c, d, None if theta[s] is None else float(theta[s]),
                               parallel=False)

    workers = threads.workers() if parallel else 1
    if workers > 1 and len(pairs) > 1:
        with ThreadPoolExecutor(workers, thread_name_prefix="nylonflex-track") as pool:
            rows = list(pool.map(run, range(len(pairs))))
    else:
        rows = [run(s) for s in range(len(pairs))]
    return {n: np.array([r[n] for r in rows]) for n in names}
