"""Numba kernels of the per-design closed loop of a ``tracking:`` sweep (docs/model.md s. 19).

The loop of each design is ``nylonflex simulate``'s (:func:`.control.closed_loop`, one
actuator, no internal resistance): the same stroke, pressure, estimator table, controller
(:func:`.control._duty`) and exact thermal step, sample by sample in the same order; only
the time series are not kept, the metrics are summed as the loop goes. Private, unchecked
(:mod:`nylonflex.engine.tracking` validates and shapes):

- :func:`kappa_tables` tabulates the curvature kappa(p) and its slope once per (radius,
  wall) of a slab (the angle is kappa L, so every length shares it), up to the highest
  pressure any of its designs reaches;
- :func:`track_slab` runs every design's loop, and its bandwidth search, one design per
  iteration (a chunk of the designs a call: the engine's threads split a slab).
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.chamber import _gauge_pressure
from ..physics.nylon import _stroke_shape
from ..physics.thermal import _temperature_step
from ._compile import jit_kernel
from .control import _duty, angle_table, estimate_angle, plant_angle
from .records import (Estimator, LoopControl, LoopMuscle, LoopPlant, LoopReference, Section,
                      TableSpec)
from .rows import (ROW_TRACKING_BANDWIDTH, ROW_TRACKING_ENERGY, ROW_TRACKING_MAX_TEMPERATURE,
                   ROW_TRACKING_RMS_ERROR)
from .scratch import node_scratch

__all__ = ["kappa_tables", "run_loop", "track_scratch", "track_slab"]

def _kappa_tables(p_max, radius, wall, base, silicone, nodes, rtol, table, out_kappa,
                  out_slope, q0, q1):
    """kappa(k dp) [1/m] and d kappa/dp [1/(m Pa)], dp = p_max[i, j] / (points - 1), of
    the (radius i, wall j) pairs q0 <= q = i nt + j < q1 (a thread's chunk); ``base`` <= 0
    means b = t; ``silicone`` an :class:`~.records.Ogden`, ``nodes`` the quadrature
    (:class:`~.records.Nodes`). NaN rows where p_max is NaN. ``table`` is the thread's node
    table and scratch (:func:`.scratch.node_scratch`)."""
    na, nt = p_max.shape
    points = out_kappa.shape[2]
    for q in range(q0, q1):
        i = q // nt
        j = q % nt
        b = wall[j] if base <= 0.0 else base
        if p_max[i, j] > 0.0:
            angle_table(p_max[i, j] / (points - 1), radius[i], wall[j], b, 1.0, silicone,
                        nodes, rtol, table, out_kappa[i, j], out_slope[i, j])
        else:
            out_kappa[i, j, :] = np.nan
            out_slope[i, j, :] = np.nan


kappa_tables = jit_kernel(_kappa_tables, callee_body=True, borrows=True)


@jit_kernel
def run_loop(dt, m, noise, muscle, plant, estimator, control, reference):
    """One design's closed loop over ``m`` samples of ``dt`` [s]: (rms error [rad],
    highest sampled temperature [K], electric energy [J]).

    The records: ``muscle`` a :class:`~.records.LoopMuscle`, ``plant`` a
    :class:`~.records.LoopPlant`, ``estimator`` an :class:`~.records.Estimator`,
    ``control`` a :class:`~.records.LoopControl`, ``reference`` a
    :class:`~.records.LoopReference`. The sample order is :func:`.control.closed_loop`'s:
    read the pressure, estimate, switch, record, then step eq. (3) at the held voltage. The
    RMS is over the samples t_k >= rms_from (NaN when none); ``noise`` (m,) [Pa] is added
    to each pressure reading.
    """
    temperature = muscle.t_start
    estimate = 0.0
    on = False
    integral = 0.0
    resistance = muscle.r_per_len * muscle.length
    sq = 0.0
    count = 0
    t_top = -math.inf
    energy = 0.0
    for k in range(m):
        t_k = k * dt
        s = muscle.stroke_scale * _stroke_shape(temperature, muscle.t_amb, muscle.gamma,
                                                muscle.beta, muscle.t_g, muscle.sigma_g)
        p = _gauge_pressure(s, muscle.p_atm)
        raw = estimate_angle(p + noise[k], estimator.step, estimator.angles)
        if k == 0:
            estimate = raw
        else:
            estimate = raw + control.filter_keep * (estimate - raw)
        if reference.kind == 0:
            ref = reference.mean + reference.amplitude * math.sin(
                2.0 * np.pi * reference.frequency * t_k + reference.phase)
        else:
            ref = reference.final if t_k >= reference.at else reference.initial
        duty, on, integral = _duty(control.kind, on, integral, estimate, ref,
                                   control.half_band, control.gain, control.integral_step)
        if temperature > t_top:
            t_top = temperature
        if t_k >= reference.rms_from - 1e-12:
            err = plant.length * plant_angle(p, plant.step, plant.kappa, plant.slope) - ref
            sq += err * err
            count += 1
        v = muscle.voltage * math.sqrt(duty) if on else 0.0
        energy += v * v / resistance
        temperature = _temperature_step(temperature, v, dt, muscle.length, muscle.t_amb,
                                        muscle.r_per_len, muscle.c_per_len,
                                        muscle.loss_per_len)
    rms = math.sqrt(sq / count) if count > 0 else math.nan
    return rms, t_top, energy * dt


@jit_kernel
def _bandwidth(dt, noise, muscle, plant, estimator, control, mean, amplitude, search):
    """Highest sine frequency [Hz] whose RMS error (after the first period, over
    ``periods`` more) is at most ``error`` [rad]: bisection in log frequency between
    ``low`` and ``high``, ``iterations`` halvings; 0 when ``low`` fails, ``high`` when it
    passes. A run at f lasts (1 + periods)/f. ``search`` is (enabled, error, low, high,
    iterations, periods); the sine's ``mean`` and ``amplitude`` [rad]; the other records
    as :func:`run_loop`'s."""
    _, error, low, high, iterations, periods = search
    lo = low
    hi = high
    for trial in range(iterations + 2):
        if trial == 0:
            f = low
        elif trial == 1:
            f = high
        else:
            f = math.sqrt(lo * hi)
        m = int(math.floor((1.0 + periods) / f / dt + 1e-9)) + 1
        if m > noise.shape[0]:
            m = noise.shape[0]
        sine = LoopReference(0, mean, amplitude, f, 0.0, 0.0, 0.0, 0.0, 1.0 / f)
        rms, _, _ = run_loop(dt, m, noise, muscle, plant, estimator, control, sine)
        ok = rms <= error  # NaN fails
        if trial == 0:
            if not ok:
                return 0.0
        elif trial == 1:
            if ok:
                return high
        elif ok:
            lo = f
        else:
            hi = f
    return lo


@jit_kernel
def _one_design(dt, m, noise, muscle, spec, plant, control, reference, search, scratch):
    """(rms error, highest temperature, energy, bandwidth) of one design; NaN when its
    ``spec.p_top`` is NaN. Its estimator table is ``nylonflex simulate``'s: ``spec.points``
    angles on p_top / (points - 1), from the same curvature solve of its section
    (:func:`.control.angle_table`), written into the thread's ``scratch`` (the table, its
    slopes and the node table: :func:`track_scratch`). ``spec`` a
    :class:`~.records.TableSpec`; ``search`` the bandwidth search (enabled first); the
    other records as :func:`run_loop`'s."""
    if not spec.p_top > 0.0:
        return math.nan, math.nan, math.nan, math.nan
    est, est_slope, table = scratch
    est_step = spec.p_top / (spec.points - 1)
    section = spec.section
    angle_table(est_step, section.radius, section.wall, section.base, plant.length,
                spec.silicone, spec.nodes, spec.rtol, table, est, est_slope)
    estimator = Estimator(est_step, est)
    rms, t_top, energy = run_loop(dt, m, noise, muscle, plant, estimator, control, reference)
    bandwidth = math.nan
    if search[0]:
        bandwidth = _bandwidth(dt, noise, muscle, plant, estimator, control, reference.mean,
                               reference.amplitude, search)
    return rms, t_top, energy, bandwidth


def _track_slab(axes, designs, plant_tables, muscle, silicone, nodes, rtol, loop, out,
                scratch, q0, q1):
    """Every design's tracking metrics into ``out`` (4, n), designs in C order of the
    slab's (radius, wall, length, coil, wrap).

    Parameters
    ----------
    axes : tuple
        (radius, wall, length) arrays [m] and the base thickness [m] (<= 0: b = t).
    designs : tuple
        (lm, p_top, scale, ref_scale): ``lm``, ``p_top``, ``ref_scale`` arrays of shape
        (na, nt, nl, nc, nw): muscle length [m]; the highest pressure the design reaches
        [Pa] (its estimator table's top; NaN: no tracking); the factor of the reference
        angles (1, or theta* [rad] for angles relative to it); ``scale`` (nc,) the stroke
        scale s_max(C)/s_ref(T_max) [-].
    plant_tables : tuple
        (p_group, kappa, kappa_slope): the top of each (radius, wall)'s curvature table
        [Pa], (na, nt); :func:`kappa_tables` on the spacing p_group / (points - 1), (na,
        nt, points).
    muscle : tuple
        r'(C) [ohm/m] (an array over the coil indices, docs/model.md s. 9), c' [J/(K m)],
        lambda'(C) [W/(K m)] (an array over the coil indices: the cooling set's, or the
        nylon set's own at every C), T_amb, T(0) [K], gamma [1/K], beta [-], T_g,
        sigma_g [K].
    silicone, nodes : Ogden, Nodes
        Ogden (mu [Pa], alpha [-]); the quadrature nodes and weights.
    rtol : float
        Tolerance of the curvature solve [-].
    loop : tuple
        (settings, reference, bandwidth, noise). ``settings``: dt [s], samples, supply [V],
        p_atm [Pa], estimator points, controller kind (0 bang-bang, 1 PI), half band
        [rad], PI gain [1/rad], dt/T_i [-], filter factor [-]. ``reference``: kind (0 sine,
        1 step), mean, amplitude [rad or -], frequency [Hz], phase [rad], initial, final
        [rad or -], at, rms_from [s]. ``bandwidth``: enabled (0/1), error [rad], low, high
        [Hz], iterations, periods. ``noise``: sensor noise at each sample [Pa], as long as
        the longest run.
    out : ndarray (4, n)
        Written, in the rows of :mod:`.rows` (``ROW_TRACKING_*``, the registry's
        ``TRACKING`` order): rms error [rad], highest temperature [K], energy [J],
        bandwidth [Hz].
    scratch : tuple
        The thread's estimator table, its slopes and node table (:func:`track_scratch`).
    q0, q1 : int
        The designs q0 <= q < q1 of that C order are computed (a thread's chunk).
    """
    radius, wall, length, base = axes
    lm, p_top, scale, ref_scale = designs
    p_group, kappa, kappa_slope = plant_tables
    r_per_len, c_per_len, loss_per_len, t_amb, t_start, gamma, beta, t_g, sigma_g = muscle
    settings, reference, search, noise = loop
    (dt, m, voltage, p_atm, points, kind, half_band, gain, integral_step,
     filter_keep) = settings
    ref_kind, mean, amplitude, frequency, phase, initial, final, at, rms_from = reference
    control = LoopControl(kind, half_band, gain, integral_step, filter_keep)
    na, nt, nl, nc, nw = lm.shape
    plant_points = kappa.shape[2]
    for q in range(q0, q1):
        i = q // (nt * nl * nc * nw)
        j = (q // (nl * nc * nw)) % nt
        li = (q // (nc * nw)) % nl
        ci = (q // nw) % nc
        wi = q % nw
        b = wall[j] if base <= 0.0 else base
        g = ref_scale[i, j, li, ci, wi]
        design_muscle = LoopMuscle(voltage, p_atm, lm[i, j, li, ci, wi], r_per_len[ci],
                                   c_per_len, loss_per_len[ci], t_amb, t_start, scale[ci],
                                   gamma, beta, t_g, sigma_g)
        plant = LoopPlant(length[li], p_group[i, j] / (plant_points - 1), kappa[i, j],
                          kappa_slope[i, j])
        design_reference = LoopReference(ref_kind, g * mean, g * amplitude, frequency, phase,
                                         g * initial, g * final, at, rms_from)
        (tracking_rms_error, tracking_max_temperature, tracking_energy,
         tracking_bandwidth) = _one_design(
            dt, m, noise, design_muscle,
            TableSpec(Section(radius[i], wall[j], b), p_top[i, j, li, ci, wi], points,
                      silicone, nodes, rtol), plant, control, design_reference, search,
            scratch)
        out[ROW_TRACKING_RMS_ERROR, q] = tracking_rms_error
        out[ROW_TRACKING_MAX_TEMPERATURE, q] = tracking_max_temperature
        out[ROW_TRACKING_ENERGY, q] = tracking_energy
        out[ROW_TRACKING_BANDWIDTH, q] = tracking_bandwidth


#: The compiled loop, for threaded runs (chunks on the engine's threads) and serial ones.
track_slab = jit_kernel(_track_slab, callee_body=True, borrows=True)


def track_scratch(nodes, points: int) -> tuple:
    """A thread's working arrays for :data:`track_slab`: the estimator table and its slopes
    (``points`` entries each) and a node table for the quadrature ``nodes``
    (:func:`.scratch.node_scratch`)."""
    return np.empty(points), np.empty(points), node_scratch(nodes)
