"""Numba kernels of the closed-loop simulation (docs/model.md section 10, paper figures 8-10).

Private, unchecked kernels (the caller, :mod:`nylonflex.sim`, validates and shapes
everything):

- :func:`angle_table` tabulates the model's bend angle and its slope against pressure on a
  uniform grid, once per design, by the physics curvature solve.
- :func:`plant_angle` reads the plant's quasi-static angle from that table (cubic Hermite,
  as accurate as the solve and a hundred times cheaper than a Newton solve per step);
  :func:`estimate_angle` is the controller's estimator: a small table, linear interpolation.
- :func:`closed_loop` steps one supply and several actuators through time. The thermal ODE
  (eq. 3) is stepped by its exact exponential solution at the voltage held over the step
  (zero-order hold), and the stroke, pressure and angle follow quasi-statically.

Every piece of physics is a physics-layer ``@formula`` (compiled here by ``jit_kernel``); no
formula is written twice.
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.bending import (_curvature_nodes, _pressure_moment, _section_moment,
                               _section_nodes)
from ..physics.chamber import _gauge_pressure
from ..physics.nylon import _stroke_shape
from ..physics.thermal import _temperature_step
from ._compile import jit_kernel

__all__ = ["angle_table", "closed_loop", "estimate_angle", "loop_state", "plant_angle"]


def _angle_table(pressure_step, radius, wall_thickness, base_thickness, length, silicone,
                 nodes, rtol, table, out_angle, out_slope):
    """Bend angle theta(p_k) = kappa(p_k) L and its slope at p_k = k dp [rad], [rad/Pa].

    Parameters
    ----------
    pressure_step : float
        Grid spacing dp [Pa].
    radius, wall_thickness, base_thickness, length : float
        a, t, b, L [m].
    silicone : Ogden
        The Ogden constants ``mu`` [Pa] and ``alpha`` [-] (arrays of one entry a term).
    nodes : Nodes
        Gauss-Legendre nodes and weights (``physics.bending.quadrature_nodes()``).
    rtol : float
        Tolerance of the curvature solve [-] (``physics.bending.NEWTON_RTOL``).
    table : NodeTable
        The section's node table and scratch, overwritten
        (:func:`nylonflex.kernels.scratch.node_scratch` of the same nodes).
    out_angle, out_slope : ndarray, shape (points,)
        Written with theta(p_k) [rad] and d theta/dp [rad/Pa].

    Notes
    -----
    d theta/dp = L (dM_P/dp) / (dM_S/dkappa), from the moment balance M_S(kappa) = M_P(p).
    The section's node table is filled once a table (physics' ``_curvature`` and
    ``_material_moment`` make one a call: two a point, the same numbers); each point's
    curvature is solved in it, warm-started from the previous point's, and its stiffness
    evaluated there.
    """
    mu, alpha = silicone
    x_base, w_base, phi_trig, w_phi = nodes
    y, wy, wyy, work = table.y, table.wy, table.wyy, table.work
    _section_nodes(radius, wall_thickness, base_thickness, x_base, w_base, phi_trig, w_phi, y,
                   wy, wyy)
    kappa = 0.0
    lever = _pressure_moment(1.0, radius, base_thickness)  # dM_P/dp: M_P is linear in p
    for k in range(out_angle.shape[0]):
        # warm start from the previous grid point: a few Halley steps each
        kappa = _curvature_nodes(lever * (k * pressure_step), y, wy, wyy, work, mu, alpha,
                                 kappa, rtol, False)
        stiffness = _section_moment(kappa, y, wy, wyy, work, mu, alpha, False)[1]
        out_angle[k] = kappa * length
        out_slope[k] = length * lever / stiffness


#: The angle table, from Python (``nylonflex simulate``) and from the tracking kernels; it
#: makes no array (the caller's node table), so it borrows (``jit_kernel``).
angle_table = jit_kernel(_angle_table, callee_body=True, borrows=True)


@jit_kernel
def plant_angle(pressure, pressure_step, angle, slope):
    """theta(p) by cubic Hermite interpolation of a uniform table of values and slopes [rad].

    The plant's quasi-static angle: with the exact slopes the interpolation error is of
    order dp^4 (below 1e-9 relative for the default 1025 points, see the tests), at a
    fraction of the cost of a Newton solve per step.

    Parameters
    ----------
    pressure : float
        Gauge pressure p [Pa], inside the table (clamped to it otherwise).
    pressure_step : float
        Table spacing dp [Pa].
    angle, slope : ndarray
        theta(k dp) [rad] and d theta/dp [rad/Pa] from :func:`angle_table`.
    """
    last = angle.shape[0] - 1
    x = pressure / pressure_step
    if not x > 0.0:
        return angle[0]
    if x >= last:
        return angle[last]
    i = int(x)
    u = x - i
    u2 = u * u
    u3 = u2 * u
    return ((2.0 * u3 - 3.0 * u2 + 1.0) * angle[i]
            + (u3 - 2.0 * u2 + u) * pressure_step * slope[i]
            + (-2.0 * u3 + 3.0 * u2) * angle[i + 1]
            + (u3 - u2) * pressure_step * slope[i + 1])


@jit_kernel
def estimate_angle(pressure, pressure_step, table):
    """theta_hat(p) by linear interpolation in a uniform table, clamped at its ends [rad].

    Parameters
    ----------
    pressure : float
        Measured gauge pressure [Pa]; below 0 reads as 0, above the table as its last point.
    pressure_step : float
        Table spacing dp [Pa].
    table : ndarray
        Angles at p_k = k dp [rad].
    """
    x = pressure / pressure_step
    if not x > 0.0:  # also catches NaN
        return table[0]
    last = table.shape[0] - 1
    if x >= last:
        return table[last]
    i = int(x)
    f = x - i
    return table[i] + f * (table[i + 1] - table[i])


@jit_kernel
def _switch(on, estimate, reference, half_band):
    """Bang-bang with a hysteresis band of half-width ``half_band`` [rad].

    On below ``reference - half_band``, off at or above ``reference + half_band``, and in
    between the previous state holds. With no band: on exactly when estimate < reference.
    """
    if estimate < reference - half_band:
        return True
    if estimate >= reference + half_band:
        return False
    return on


@jit_kernel
def _duty(kind, on, integral, estimate, reference, half_band, gain, integral_step):
    """The controller: the fraction of the step the supply is on [-], and its new state.

    Parameters
    ----------
    kind : int
        0 bang-bang with hysteresis (:func:`_switch`), 1 PI.
    on : bool
        The bang-bang state of the last sample.
    integral : float
        The PI's integral term, (1/T_i) times the integrated error [rad].
    estimate, reference : float
        Estimated and reference angle [rad].
    half_band : float
        Half the bang-bang hysteresis band [rad].
    gain : float
        PI: 1 / proportional band [1/rad]: the duty is gain (e + integral), clipped to
        [0, 1].
    integral_step : float
        PI: dt / T_i [-].

    Returns
    -------
    duty, on, integral : float, bool, float
        Bang-bang: duty 1.0 or 0.0. PI: the clipped duty; the integral only integrates
        while the duty is not saturated in the error's direction (conditional
        integration, against windup).

    Notes
    -----
    docs/model.md s. 19: a duty u over the step is PWM faster than the step (and far faster
    than the muscle's time constant): the mean power u V^2/R, held as the voltage
    sqrt(u) V in the exact step of eq. (3).
    """
    if kind == 0:
        on = _switch(on, estimate, reference, half_band)
        return (1.0 if on else 0.0), on, integral
    error = reference - estimate
    u = gain * (error + integral)
    if u >= 1.0:
        duty = 1.0
        if error < 0.0:
            integral += integral_step * error
    elif u <= 0.0:
        duty = 0.0
        if error > 0.0:
            integral += integral_step * error
    else:
        duty = u
        integral += integral_step * error
    return duty, duty > 0.0, integral


def _closed_loop(supply, muscles, tables_, control, state, out):
    """Step the closed loop of ``n`` actuators on one supply through ``m`` samples.

    At sample k each actuator's chamber pressure is read (plus ``noise``), turned into an
    angle estimate by its table (optionally low-pass filtered) and compared with the
    reference; the switched-on muscles share the supply, whose terminal voltage sags over
    its internal resistance; that voltage is held over [t_k, t_k + dt] while eq. (3) is
    stepped by its exact solution.

    Parameters
    ----------
    supply : :class:`~.records.Supply`
        ``dt`` sample time [s], ``voltage`` open-circuit voltage E [V],
        ``internal_resistance`` [ohm], ``p_atm`` initial absolute chamber pressure [Pa].
    muscles : :class:`~.records.Muscles`, arrays (n,)
        ``length`` l_m [m], ``r_per_len`` r' [ohm/m], ``c_per_len`` c' [J/(K m)],
        ``loss_per_len`` lambda' [W/(K m)], ``t_amb`` [K], ``t_start`` T(0) [K],
        ``stroke_scale`` s_max(C)/s_ref [-] and the eq. (2) shape ``gamma`` [1/K], ``beta``
        [-], ``t_g`` [K], ``sigma_g`` [K].
    tables_ : :class:`~.records.AngleTables`
        ``plant_step`` (n,) [Pa] and ``plant_angles``, ``plant_slopes`` (n, points): the
        model's theta(k dp) [rad] and d theta/dp [rad/Pa] (:func:`angle_table`);
        ``table_step`` (n,) [Pa] and ``tables`` (n, points): the estimators' theta(k dp).
    control : :class:`~.records.Control`
        ``half_band`` (n,) half the hysteresis band [rad]; ``filter_keep`` (n,)
        exp(-dt/tau_f) of the estimate's first-order filter, 0 for none [-]; ``reference``
        (n, m) [rad] and ``noise`` (n, m) additive pressure-sensor noise [Pa] at each sample;
        ``kind`` (n,) int64, 0 bang-bang, 1 PI; ``gain`` (n,) [1/rad] and ``integral_step``
        (n,) dt/T_i [-] of a PI (:func:`_duty`).
    state : tuple
        The loop's state, arrays (n,), as :func:`loop_state` starts it (overwritten):
        temperature [K], estimate [rad], on (bool), duty [-], the PI's integral [rad].
    out : :class:`~.records.SimOut`, arrays (n, m)
        Written: temperature [K], stroke [-], pressure [Pa], angle [rad], estimate [rad],
        voltage [V], current [A] and electric power [W] at each sample; the voltage is the
        one held from that sample to the next.
    """
    dt, supply_voltage, internal_resistance, p_atm = supply
    (muscle_length, r_per_len, c_per_len, loss_per_len, t_amb, t_start, stroke_scale, gamma,
     beta, t_g, sigma_g) = muscles
    plant_step, plant_angles, plant_slopes, table_step, tables = tables_
    half_band, filter_keep, reference, noise, kind, gain, integral_step = control
    (out_temperature, out_stroke, out_pressure, out_angle, out_estimate, out_voltage,
     out_current, out_power) = out
    temperature, estimate, on, duty, integral = state
    n = muscle_length.shape[0]
    m = reference.shape[1]
    for k in range(m):
        conductance = 0.0
        for j in range(n):
            t_j = temperature[j]
            s = stroke_scale[j] * _stroke_shape(t_j, t_amb[j], gamma[j], beta[j], t_g[j],
                                                sigma_g[j])
            p = _gauge_pressure(s, p_atm)
            raw = estimate_angle(p + noise[j, k], table_step[j], tables[j])
            if k == 0:
                estimate[j] = raw
            else:
                estimate[j] = raw + filter_keep[j] * (estimate[j] - raw)
            duty[j], on[j], integral[j] = _duty(kind[j], on[j], integral[j], estimate[j],
                                                reference[j, k], half_band[j], gain[j],
                                                integral_step[j])
            if on[j]:
                conductance += duty[j] / (r_per_len[j] * muscle_length[j])
            out_temperature[j, k] = t_j
            out_stroke[j, k] = s
            out_pressure[j, k] = p
            out_angle[j, k] = plant_angle(p, plant_step[j], plant_angles[j], plant_slopes[j])
            out_estimate[j, k] = estimate[j]
        # the switched-on muscles are in parallel on the supply
        terminal = supply_voltage / (1.0 + internal_resistance * conductance)
        for j in range(n):
            v = terminal * math.sqrt(duty[j]) if on[j] else 0.0
            resistance = r_per_len[j] * muscle_length[j]
            out_voltage[j, k] = v
            out_current[j, k] = v / resistance
            out_power[j, k] = v * v / resistance
            temperature[j] = _temperature_step(temperature[j], v, dt, muscle_length[j],
                                               t_amb[j], r_per_len[j], c_per_len[j],
                                               loss_per_len[j])


#: The closed loop; its state comes from the caller (:func:`loop_state`), so it makes no
#: array and borrows (``jit_kernel``).
closed_loop = jit_kernel(_closed_loop, callee_body=True, borrows=True)


def loop_state(t_start) -> tuple:
    """The state :data:`closed_loop` starts from, for the actuators' initial temperatures
    ``t_start`` (n,) [K]: temperature (a copy), estimate 0 [rad], off, duty 0 [-],
    integral 0 [rad]."""
    n = len(t_start)
    return (np.array(t_start, dtype=float), np.zeros(n), np.zeros(n, dtype=np.bool_),
            np.zeros(n), np.zeros(n))
