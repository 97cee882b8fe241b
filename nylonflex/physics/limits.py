"""Design limits of an actuator (paper section 4, figure 12; docs/model.md section 8).

For a design (a, t, L, C, psi): the muscle contracts at most s_max(C) and breaks at
F_lim(C). s* = min(s_max, s_lim) with F_n(s_lim) = F_lim. Then p* = p(s*), M* = M_P(p*),
F* = M*/L, theta* = kappa(p*) L, and [choice] the range fraction theta*/theta(s_max): 1 for a
stroke-limited design, a *full range of motion*.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import nylon_parameters, silicone_parameters
from ._formula import (check, check_input, check_section, check_wrap_angle, formula,
                       scalar_or_array)
from .bending import (NEWTON_RTOL, _curvature_nodes, _curvature_rates, _curvature_solve,
                      _curvature_start, _lateral_lever, _node_table, _pressure_moment,
                      _section_moment, _section_nodes, _taylor_start, quadrature_nodes)
from .calibrated import _length_correction, _section_correction
from .chamber import (P_ATM, _gauge_pressure, _gauge_pressure_slope, _gauge_pressure_wall,
                      _solid_fraction)
from .nylon import _free_stroke, _stroke_shape, _temperature_for_stroke, check_stroke_shape
from .records import (CoilRow, Cycle, Drive, NodeTable, Nodes, Ogden, Reach, Section,
                      SolvedCurve, StrokeShape)
from .sealed import COEFFICIENTS as _SEALED, _blocked_ratio, _sealed_pressure, \
    _sealed_stroke, _squeeze_curvature, sealed_coefficients
from .silicone import _equibiaxial_stress_and_slope, _stress_and_slope
from .thermal import _cooling_time, _heating_power, _heating_time, \
    _steady_temperature, check_supply_rise, coil_heat_loss_per_length, coil_resistance
from .wrap import _muscle_length, _muscle_length_at, _nylon_force_and_slope, \
    _outer_perimeter, _pitch, _wrap_force

__all__ = ["DESIGN_VARIABLES", "EFFICIENCY_BOUND", "MODELS", "VALIDITY_FLAGS", "design_limits",
           "model_bend_angle", "stroke_limit"]

from ..variables import DESIGN, MODELS  # noqa: E402  (the registry holds the names)
PAPER, COUPLED_MUSCLE, PAPER_EQ10, INCOMPRESSIBLE_WALL, CAUCHY_MOMENT, LATERAL_PRESSURE, \
    FE_CALIBRATED, SEALED_CHAMBER = range(8)

#: Bits of the ``validity`` flag (docs/model.md s. 17).
VALIDITY_FLAGS = {"self_contact": 1, "stretch_beyond_fit": 2, "under_one_turn": 4,
                  "chamber_closes": 8, "efficiency_beyond_bound": 16}

#: The highest efficiency measured for coiled polymer muscles, mechanical work over the
#: energy put in: 1.32 % (polyethylene; 1.08 % for nylon 6,6), Haines et al., Science
#: 343:868, 2014. ``efficiency`` above it sets the ``efficiency_beyond_bound`` bit
#: (docs/model.md s. 20).
EFFICIENCY_BOUND = 0.0132

#: 8-point Gauss-Legendre nodes and weights on [-1, 1] (Abramowitz & Stegun, Table 25.4):
#: the work integral of the nylon force over the stroke (docs/model.md s. 20).
_WORK_X = (-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
           -0.1834346424956498, 0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
           0.9602898564975363)
_WORK_W = (0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
           0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763)

#: Fraction of the free stroke that counts as reached (heating) or let go (cooling) [-].
HEATED_FRACTION = 0.95
COOLED_FRACTION = 0.05

#: Relative shortfall below the free stroke that counts as load-limited [-].
LOAD_RTOL = 1e-9

#: The names :func:`design_limits` returns, in the cube's order (docs/interface.md): the
#: registry's, read from it (the kernels' output rows come from the same order).
DESIGN_VARIABLES = tuple(DESIGN)

#: Relative Newton step below which s_lim counts as converged [-].
STROKE_RTOL = 1e-10


@formula
def _nylon_force_model(model, stroke, radius, wall_thickness, lever, solid, mu, alpha, p_atm,
                       chamber):
    """F_n(s) and dF_n/ds [N] of a model variant (``solid`` = A_s/A_out, wall variant only;
    ``chamber`` the :class:`~.records.SealedCoefficients`, ``sealed_chamber`` only).

    ``paper_eq10`` takes the hoop stress of the paper's eqs. (10)-(12),
    ``incompressible_wall`` the chamber pressure with a conserved wall area,
    ``sealed_chamber`` the sealed, compliant chamber's (:mod:`.sealed`); the others are the
    paper's F_n (docs/model.md s. 4, 15, 22).
    """
    if model == PAPER_EQ10:
        p = _gauge_pressure(stroke, p_atm)
        dp = _gauge_pressure_slope(stroke, p_atm)
        s_theta, ds_dlam = _equibiaxial_stress_and_slope(1.0 - stroke, mu, alpha)
    elif model == INCOMPRESSIBLE_WALL:
        p, dp = _gauge_pressure_wall(stroke, p_atm, solid)
        s_theta, ds_dlam = _stress_and_slope(1.0 - stroke, mu, alpha)
    elif model == SEALED_CHAMBER:
        p, dp = _sealed_pressure(stroke, radius, wall_thickness, mu, alpha, p_atm, 1.0, chamber)
        s_theta, ds_dlam = _stress_and_slope(1.0 - stroke, mu, alpha)
    else:
        return _nylon_force_and_slope(stroke, radius, wall_thickness, lever, mu, alpha, p_atm)
    sign = 1.0 if s_theta >= 0.0 else -1.0
    force = _wrap_force(p, s_theta, radius, wall_thickness, lever)
    return force, (dp * radius - sign * ds_dlam * wall_thickness) * lever


@formula
def _stroke_limit_model(model, force_limit, s_max, radius, wall_thickness, lever, solid, mu,
                        alpha, p_atm, chamber, rtol):
    """Usable stroke s*, the limit flag (0 stroke, 1 strength) and F_n(s*) [N] of a model
    variant's F_n (``solid`` = A_s/A_out, wall variant only), below the stroke ``s_max``.

    s_lim solves F_n(s) = F_lim on (0, s_max) by Newton from s_max, safeguarded by
    bisection; F_n is increasing with F_n(0) = 0.
    """
    f, df = _nylon_force_model(model, s_max, radius, wall_thickness, lever, solid, mu, alpha,
                               p_atm, chamber)
    if f <= force_limit:
        return s_max, 0, f
    lo = 0.0
    hi = s_max
    s = s_max
    for _ in range(200):
        if f > force_limit:
            hi = s
        else:
            lo = s
        step = (f - force_limit) / df
        s_new = s - step
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        elif abs(step) <= rtol * s:
            s = s_new
            break
        s = s_new
        f, df = _nylon_force_model(model, s, radius, wall_thickness, lever, solid, mu, alpha,
                                   p_atm, chamber)
    f, df = _nylon_force_model(model, s, radius, wall_thickness, lever, solid, mu, alpha,
                               p_atm, chamber)
    return s, 1, f


@formula
def _paper_force(model, stroke, radius, wall_thickness, lever, solid, mu, alpha, p_atm, chamber):
    """:func:`_nylon_force_model` of the paper's model: F_n(s) and dF_n/ds [N] (``model``,
    ``solid`` and ``chamber`` unused), in its signature: what the paper's grid kernel calls
    in its place (:mod:`nylonflex.kernels.design`)."""
    return _nylon_force_and_slope(stroke, radius, wall_thickness, lever, mu, alpha, p_atm)


@formula
def _coupled_stroke(force_blocked, s_free, radius, wall_thickness, lever, mu, alpha, p_atm,
                    rtol):
    """Stroke where the wrap's load meets the muscle's line, F_n(s) = F_b (1 - s/s_free) [-].

    ``coupled_muscle`` (docs/model.md s. 16): g(s) = F_n(s)/F_b - (1 - s/s_free) rises from
    -1 at s = 0 to F_n(s_free)/F_b >= 0, so the root in [0, s_free] is unique; safeguarded
    Newton from the linearised root. Written over F_b so an infinitely strong muscle
    (F_b -> inf) gives s_free.
    """
    if force_blocked <= 0.0:
        return 0.0
    f_top = _nylon_force_and_slope(s_free, radius, wall_thickness, lever, mu, alpha, p_atm)[0]
    lo = 0.0
    hi = s_free
    s = s_free / (1.0 + f_top / force_blocked)
    for _ in range(200):
        f, df = _nylon_force_and_slope(s, radius, wall_thickness, lever, mu, alpha, p_atm)
        g = f / force_blocked - (1.0 - s / s_free)
        if g == 0.0:
            return s
        if g > 0.0:
            hi = s
        else:
            lo = s
        step = g / (df / force_blocked + 1.0 / s_free)
        s_new = s - step
        if not (lo < s_new < hi):
            s_new = 0.5 * (lo + hi)
        elif abs(step) <= rtol * s:
            return s_new
        if hi - lo <= rtol * s:
            return s_new
        s = s_new
    return s


@formula
def _model_moment(model, pressure, radius, wall_thickness, base_thickness):
    """The moment that bends the section at chamber pressure p [N m] in a model variant.

    The paper's end-cap moment M_P (eq. 16; every variant but ``lateral_pressure``, bit for
    bit); ``lateral_pressure`` (and ``fe_calibrated``, which corrects its curvature, and
    ``sealed_chamber``, which adds the squeeze) adds the pressure on the wall and floor, p
    times :func:`~.bending._lateral_lever` (docs/model.md s. 18). Linear in p in every
    model: ``_model_moment(model, 1, ...)`` is dM/dp.
    """
    m = _pressure_moment(pressure, radius, base_thickness)
    if model == LATERAL_PRESSURE or model == FE_CALIBRATED or model == SEALED_CHAMBER:
        m += pressure * _lateral_lever(radius, wall_thickness, base_thickness)
    return m


@formula
def _model_state_nodes(model, section, lever, coil, reach, ogden, table, p_atm, chamber, curve,
                       n):
    """The length-free design limits of a model variant, with a reachable free stroke.

    ``section`` a :class:`~.records.Section`, ``lever`` the wrap's pitch over cos psi [m],
    ``coil`` the :class:`~.records.CoilRow` (F_lim, s_max), ``ogden`` the silicone's
    :class:`~.records.Ogden`, ``table`` the section's node table and scratch (a
    :class:`~.records.NodeTable`, :func:`~.bending._section_nodes`), ``p_atm`` the initial
    chamber pressure [Pa], ``chamber`` the :class:`~.records.SealedCoefficients`
    (``sealed_chamber``). ``reach`` is the muscle at its reachable temperature (a
    :class:`~.records.Reach`, :func:`_reach`): its free stroke ``s_free`` [-] (s_max
    without a supply), blocked force ``force_blocked`` F_b = c (T - T_amb) [N]
    (``coupled_muscle``) and ``limited``, whether the supply keeps the muscle below
    T_max. ``n`` solved points of the model's kappa(p) in ``curve`` (a
    :class:`~.records.SolvedCurve`) start the curvature solves (:func:`_stroke_state_nodes`;
    none: ``n`` = 0, the full-stroke solve from its own start and the strength-limited one
    from a second-order Taylor of it).

    Returns (s*, limit, p*, M*, kappa*, F_n(s*), kappa_full, closes): limit 0 stroke, 1
    strength, 2 supply, 3 load (docs/model.md s. 8, 15, 16); ``closes``
    (``incompressible_wall``) when the chamber would close before s_max, and then kappa_full
    is inf (range fraction 0).
    """
    radius, wall_thickness, base_thickness = section.radius, section.wall, section.base
    force_limit, s_max = coil.force_limit, coil.s_max
    mu, alpha = ogden.mu, ogden.alpha
    y, wy, wyy, work = table.y, table.wy, table.wyy, table.work
    pressures, kappas, rates, rates2 = curve.pressure, curve.kappa, curve.rate, curve.rate2
    s_free, force_blocked, supply_limited = reach.s_free, reach.force_blocked, reach.limited
    cauchy = model == CAUCHY_MOMENT
    solid = 0.0
    closes = False
    s_top = s_free
    if model == INCOMPRESSIBLE_WALL:
        solid = _solid_fraction(radius, wall_thickness, base_thickness)
        s_close = 1.0 - math.sqrt(solid)
        if s_close <= s_max:
            closes = True
            if s_top > s_close * (1.0 - 1e-9):
                s_top = s_close * (1.0 - 1e-9)
    rate_full = 0.0
    rate2_full = 0.0
    if closes:
        kappa_full = math.inf
        p_full = math.inf
    else:
        p_full = _nylon_pressure(model, s_max, p_atm, solid, radius, wall_thickness, mu, alpha,
                                 chamber)
        kappa_full, dm, d2m = _curvature_solve(
            _model_moment(model, p_full, radius, wall_thickness, base_thickness), y, wy, wyy,
            work, mu, alpha, _curvature_start(p_full, pressures, kappas, rates, rates2, n),
            NEWTON_RTOL, cauchy)
        rate_full, rate2_full = _curvature_rates(
            _model_moment(model, 1.0, radius, wall_thickness, base_thickness), dm, d2m)
    if model == COUPLED_MUSCLE:
        s_eq = _coupled_stroke(force_blocked, s_free, radius, wall_thickness, lever, mu, alpha,
                               p_atm, STROKE_RTOL)
    else:
        s_eq = s_top
    s, strength, force = _stroke_limit_model(model, force_limit, s_eq, radius,
                                             wall_thickness, lever, solid, mu, alpha, p_atm,
                                             chamber, STROKE_RTOL)
    if strength == 1:
        limit = 1
    elif supply_limited:
        limit = 2
    elif model == COUPLED_MUSCLE and s_eq < s_free * (1.0 - LOAD_RTOL):
        limit = 3
    else:
        limit = 0
    p = _nylon_pressure(model, s, p_atm, solid, radius, wall_thickness, mu, alpha, chamber)
    moment = _model_moment(model, p, radius, wall_thickness, base_thickness)
    if limit == 0:
        kappa = kappa_full
    else:
        guess = _curvature_start(p, pressures, kappas, rates, rates2, n)
        if guess <= 0.0 and p_full < math.inf:  # second-order Taylor from the full stroke
            guess = _taylor_start(p, p_full, kappa_full, rate_full, rate2_full)
        kappa = _curvature_nodes(moment, y, wy, wyy, work, mu, alpha, guess, NEWTON_RTOL,
                                 cauchy)
    if model == FE_CALIBRATED:  # the balance's curvatures, corrected (:mod:`.calibrated`)
        kappa *= _section_correction(p, radius, wall_thickness, mu, alpha)
        kappa_full *= _section_correction(p_full, radius, wall_thickness, mu, alpha)
    elif model == SEALED_CHAMBER:  # the squeeze's curvature and blocked moment (:mod:`.sealed`)
        kappa_full += _squeeze_curvature(s_max, radius, wall_thickness, base_thickness, chamber)
        k_sq, m_sq = _squeeze_state(s, section, ogden, table, chamber)
        kappa += k_sq
        moment += m_sq
    return s, limit, p, moment, kappa, force, kappa_full, closes


@formula
def _squeeze_state(stroke, section, ogden, table, chamber):
    """``sealed_chamber``'s squeeze at stroke s [-]: its curvature kappa_sq [1/m] and the
    blocked moment c_b M_S(kappa_sq) [N m] that holds it straight (docs/model.md s. 22), in
    the section's node table ``table`` (its ``work`` overwritten), with the coefficients
    ``chamber`` (a :class:`~.records.SealedCoefficients`)."""
    k_sq = _squeeze_curvature(stroke, section.radius, section.wall, section.base, chamber)
    m_sq = _section_moment(k_sq, table.y, table.wy, table.wyy, table.work, ogden.mu,
                           ogden.alpha, False)[0]
    return k_sq, chamber[6] * m_sq


@formula
def _curve_squeeze(model, pressure, section, ogden, table, p_atm, chamber):
    """What a model adds at chamber pressure p [Pa] to the balance's curvature [1/m] and
    moment [N m] on the bend-angle and tip-force curves: ``sealed_chamber``'s squeeze at the
    stroke that holds p (:func:`~.sealed._sealed_stroke`), else (0, 0)."""
    if model != SEALED_CHAMBER:
        return 0.0, 0.0
    s = _sealed_stroke(pressure, section.radius, section.wall, ogden.mu, ogden.alpha, p_atm,
                       1.0, chamber)
    return _squeeze_state(s, section, ogden, table, chamber)


@formula
def _design_state(model, drive, section, lever, coil, shape, ogden, nodes, p_atm, chamber):
    """The stroke state of one design in any model, with or without a supply.

    ``drive`` the supply V [V] (<= 0: none), length L [m], wrap angle psi [rad] and wrap
    pitch [m] (a :class:`~.records.Drive`), ``section`` a :class:`~.records.Section`,
    ``lever`` the wrap's pitch over cos psi [m], ``coil`` the :class:`~.records.CoilRow` of
    its coil index, ``shape`` the muscle's :class:`~.records.StrokeShape`, ``ogden`` the
    silicone's :class:`~.records.Ogden`, ``nodes`` the quadrature's
    :class:`~.records.Nodes`, ``p_atm`` the initial chamber pressure [Pa], ``chamber`` the
    :class:`~.records.SealedCoefficients` (``sealed_chamber``).

    Returns (s*, limit, p*, M*, kappa*, F_n(s*), kappa_full, closes, T_reach): the paper's
    model without a supply is :func:`_stroke_state_nodes` itself; otherwise
    :func:`_model_state_nodes` at the reachable temperature (:func:`_reach`). It makes the
    section's node table and runs :func:`_design_state_nodes` in it.
    """
    y, wy, wyy, work = _node_table(section.radius, section.wall, section.base, nodes.x_base,
                                   nodes.w_base, nodes.phi_trig, nodes.w_phi)
    return _design_state_nodes(model, drive, section, lever, coil, shape, ogden, nodes,
                               NodeTable(y, wy, wyy, work), p_atm, chamber)


@formula
def _design_state_nodes(model, drive, section, lever, coil, shape, ogden, nodes, table, p_atm,
                        chamber):
    """:func:`_design_state` in a node table and scratch ``table`` (a
    :class:`~.records.NodeTable` of :func:`~.bending._node_count` nodes, overwritten: the
    section's nodes from the quadrature's ``nodes``), which it makes no array for: what the
    pointwise kernel calls, with one table a thread."""
    y, wy, wyy = table.y, table.wy, table.wyy
    _section_nodes(section.radius, section.wall, section.base, nodes.x_base, nodes.w_base,
                   nodes.phi_trig, nodes.w_phi, y, wy, wyy)
    unsolved = SolvedCurve(y, y, y, y)
    if model == PAPER and drive.voltage <= 0.0:
        st = _stroke_state_nodes(section, lever, coil, 0.0, ogden, table, p_atm, unsolved, 0)
        return st[0], st[1], st[2], st[3], st[4], st[5], st[6], False, shape.t_max
    reach = _reach(coil, drive, section, shape)
    ms = _model_state_nodes(model, section, lever, coil, reach, ogden, table, p_atm, chamber,
                            unsolved, 0)
    lf = _length_factor(model, section.radius, drive.length)
    moment = _blocked_moment(model, ms[0], ms[2], ms[3], section, drive.length, chamber)
    return ms[0], ms[1], ms[2], moment, ms[4] * lf, ms[5], ms[6] * lf, ms[7], reach.temperature


@formula
def _blocked_moment(model, stroke, pressure, moment, section, length, chamber):
    """The blocked moment M* [N m] of a design of length L [m] from its length-free state's
    (s*, p* [Pa], M* [N m]): ``sealed_chamber``'s pressure moment taken at the chamber's
    pressure held straight, c_a rho M_lateral(p) (M_lateral is linear in p;
    :func:`~.sealed._blocked_ratio`), its squeeze's moment kept; the others' M* as it is."""
    if model != SEALED_CHAMBER:
        return moment
    m_p = _model_moment(model, pressure, section.radius, section.wall, section.base)
    rho = _blocked_ratio(stroke, section.radius, section.wall, length, chamber)
    return moment + (chamber[7] * rho - 1.0) * m_p


@formula
def _length_factor(model, radius, length):
    """The factor a model applies to the curvature of a design of length L [-]: 1 but for
    ``fe_calibrated`` (:func:`~.calibrated._length_correction`)."""
    if model == FE_CALIBRATED:
        return _length_correction(radius, length)
    return 1.0


@formula
def _curve_factor(model, pressure, radius, wall_thickness, length, mu, alpha):
    """The factor a model applies to the balance's curvature kappa(p) of a design of length
    L [-]: 1 but for ``fe_calibrated`` (:mod:`.calibrated`)."""
    if model == FE_CALIBRATED:
        return _section_correction(pressure, radius, wall_thickness, mu, alpha) * \
            _length_correction(radius, length)
    return 1.0


@formula
def _nylon_pressure(model, stroke, p_atm, solid, radius, wall_thickness, mu, alpha, chamber):
    """Chamber gauge pressure p(s) of a model variant [Pa]."""
    if model == INCOMPRESSIBLE_WALL:
        return _gauge_pressure_wall(stroke, p_atm, solid)[0]
    if model == SEALED_CHAMBER:
        return _sealed_pressure(stroke, radius, wall_thickness, mu, alpha, p_atm, 1.0,
                                chamber)[0]
    return _gauge_pressure(stroke, p_atm)


@formula
def _reach(coil, drive, section, shape):
    """The muscle at its reachable temperature min(T_max, T_ss), a :class:`~.records.Reach`:
    the temperature [K], its free stroke [-], the blocked force c (T - T_amb) [N] there,
    and whether the supply limits it.

    ``coil`` a :class:`~.records.CoilRow`, ``drive`` the supply V [V], length L [m], wrap
    angle psi [rad] and pitch [m] (a :class:`~.records.Drive`), ``section`` a
    :class:`~.records.Section`, ``shape`` the :class:`~.records.StrokeShape`. V <= 0: no
    supply, T_max and s_max itself (docs/model.md s. 15, 16).
    """
    if drive.voltage > 0.0:
        l_m = _muscle_length(drive.length, drive.pitch, section.radius, section.wall,
                             section.base, drive.wrap_angle)
        t_ss = _steady_temperature(drive.voltage, l_m, shape.t_amb, coil.r_per_len,
                                   coil.loss_per_len)
        if t_ss < shape.t_max:
            return Reach(t_ss, _free_stroke(t_ss, coil.scale, shape.t_amb, shape.gamma,
                                            shape.beta, shape.t_g, shape.sigma_g),
                         coil.force_coeff * (t_ss - shape.t_amb), True)
    return Reach(shape.t_max, coil.s_max, coil.force_coeff * (shape.t_max - shape.t_amb), False)


@formula
def _working_temperatures(model, s_star, t_reach, coil_scale, shape):
    """T* [K], and the temperatures where the free stroke is 5 % and 95 % of s(T*) [K].

    T* is the temperature whose free stroke (eq. 2, ``coil_scale`` [-] times the
    :class:`~.records.StrokeShape` ``shape``) is s* (in ``coupled_muscle``: the reachable
    temperature ``t_reach`` [K] it is heated to; docs/model.md s. 15). Returns
    (T*, T_5, T_95), the ``temps`` of :func:`_thermal_values` and :func:`_dynamic_values`.
    """
    t_amb, t_max, gamma, beta, t_g, sigma_g = shape
    if model == COUPLED_MUSCLE:
        t_work = t_reach
    else:
        t_work = _temperature_for_stroke(s_star, coil_scale, t_amb, t_max, gamma, beta, t_g,
                                         sigma_g)
    s_work = _free_stroke(t_work, coil_scale, t_amb, gamma, beta, t_g, sigma_g)
    t_cool = _temperature_for_stroke(COOLED_FRACTION * s_work, coil_scale, t_amb, t_max,
                                     gamma, beta, t_g, sigma_g)
    t_hot = _temperature_for_stroke(HEATED_FRACTION * s_work, coil_scale, t_amb, t_max,
                                    gamma, beta, t_g, sigma_g)
    return t_work, t_cool, t_hot


@formula
def _thermal_values(length, pitch, section, wrap_angle, voltage, temps, t_amb, coil):
    """muscle_length, resistance, heating_power, heating_voltage, cooling_time, heating_time.

    Of a design of length L and wrap ``pitch`` [m], ``section`` (a
    :class:`~.records.Section`), wrap angle psi [rad] and supply ``voltage`` [V], at the
    working temperatures ``temps`` (T*, T_5, T_95) [K] of :func:`_working_temperatures`,
    ambient ``t_amb`` [K] and the coil index's r', c', lambda' (``coil``, a
    :class:`~.records.CoilRow`); heating_time is NaN without a supply (``voltage`` <= 0;
    docs/model.md s. 15).
    """
    t_work, t_cool = temps[0], temps[1]
    tau = coil.c_per_len / coil.loss_per_len
    return _thermal_values_at(length, pitch, _outer_perimeter(section.radius, section.wall,
                                                              section.base),
                              math.cos(wrap_angle), voltage, temps, t_amb, coil, tau,
                              _cooling_time(t_work, t_cool, t_amb, tau))


@formula
def _thermal_values_at(length, pitch, perimeter, cos_wrap, voltage, temps, t_amb, coil, tau,
                       cooling):
    """:func:`_thermal_values` from the parts that do not depend on the length: the outer
    perimeter [m], cos psi [-], the time constant tau = c'/lambda' [s] and the cooling time
    [s]. The grid kernel computes them once for all lengths (the same operations, the same
    bits)."""
    t_work, t_hot = temps[0], temps[2]
    r_per_len, loss_per_len = coil.r_per_len, coil.loss_per_len
    l_m = _muscle_length_at(length, pitch, perimeter, cos_wrap)
    r = r_per_len * l_m
    power = _heating_power(t_work, l_m, t_amb, loss_per_len)
    heating = math.nan
    if voltage > 0.0:
        heating = _heating_time(t_hot, _steady_temperature(voltage, l_m, t_amb, r_per_len,
                                                           loss_per_len), t_amb, tau)
    return l_m, r, power, math.sqrt(r * power), cooling, heating


@formula
def _stroke_work(model, stroke, radius, wall_thickness, lever, solid, mu, alpha, p_atm,
                 chamber):
    """Integral of the nylon force over the stroke, int_0^s F_n(s') ds' [N].

    8-point Gauss-Legendre on [0, s] (F_n is smooth there: Boyle's pressure and the Ogden
    hoop stress; docs/model.md s. 20); times the muscle length, the work [J].
    """
    half = 0.5 * stroke
    total = 0.0
    for j in range(8):
        total += _WORK_W[j] * _nylon_force_model(model, half * (1.0 + _WORK_X[j]), radius,
                                                 wall_thickness, lever, solid, mu, alpha,
                                                 p_atm, chamber)[0]
    return total * half


@formula
def _dynamic_values(model, s_star, section, lever, solid, ogden, p_atm, chamber, cycle):
    """cycle_time [s], cycle_rate [Hz], heating_energy [J], mechanical_work [J], efficiency.

    Of a design with usable stroke ``s_star`` [-], ``section`` (a
    :class:`~.records.Section`), ``lever`` [m], solid fraction ``solid`` [-]
    (``incompressible_wall``, else 0), silicone ``ogden`` (an :class:`~.records.Ogden`),
    initial chamber pressure ``p_atm`` [Pa], ``chamber`` (``sealed_chamber``'s
    :class:`~.records.SealedCoefficients`) and heating cycle ``cycle`` (a
    :class:`~.records.Cycle`: the supply V [V], the six ``thermal`` values of
    :func:`_thermal_values`, the working temperatures ``temps`` (T*, T_5, T_95) [K], ambient
    ``t_amb`` [K] and time constant ``tau`` = c'/lambda' [s]).

    With a supply V (``cycle.voltage`` > 0; NaN without): the cycle heats at V from ambient
    to 95 % of the working stroke (``heating``, the heating time to T_95) and cools from
    there to 5 % of it, tau ln((T_95 - T_amb)/(T_5 - T_amb)); the heating energy is V^2/R
    times the heating time; the work l_m int_0^s* F_n ds; the efficiency their ratio
    (docs/model.md s. 20).
    """
    voltage, thermal, temps = cycle.voltage, cycle.thermal, cycle.temps
    if not voltage > 0.0:
        return math.nan, math.nan, math.nan, math.nan, math.nan
    muscle_length, resistance, heating = thermal[0], thermal[1], thermal[5]
    cycle_time = heating + _cooling_time(temps[2], temps[1], cycle.t_amb, cycle.tau)
    energy = voltage * voltage / resistance * heating
    work = muscle_length * _stroke_work(model, s_star, section.radius, section.wall, lever,
                                        solid, ogden.mu, ogden.alpha, p_atm, chamber)
    return cycle_time, 1.0 / cycle_time, energy, work, work / energy


@formula
def _validity(bend_angle, kappa, section, stretch_max, turns, closes, efficiency):
    """The ``validity`` bits (docs/model.md s. 17) of a design with bend angle theta* [rad],
    curvature kappa* [1/m], ``section`` (a :class:`~.records.Section`), the silicone's
    fitted ``stretch_max`` [-], wrap ``turns`` [-], ``closes`` and ``efficiency`` [-]: 1
    self contact (theta* > 2 pi), 2 the
    largest axial stretch 1 + kappa* (b + a + t) beyond the silicone's fitted range, 4 fewer
    than one turn of wrap, 8 the chamber closes (``incompressible_wall``), 16 the efficiency
    above :data:`EFFICIENCY_BOUND` (NaN without a supply: never set)."""
    flags = 0
    if efficiency > EFFICIENCY_BOUND:
        flags += 16
    if bend_angle > 2.0 * math.pi:
        flags += 1
    if 1.0 + kappa * (section.base + section.radius + section.wall) > stretch_max:
        flags += 2
    if turns < 1.0:
        flags += 4
    if closes:
        flags += 8
    return flags


@formula
def _stroke_state_nodes(section, lever, coil, kappa_full, ogden, table, p_atm, curve, n):
    """The length-free part of the design limits of the paper's model.

    ``section`` a :class:`~.records.Section`, ``lever`` [m], ``coil`` the
    :class:`~.records.CoilRow` (F_lim, s_max), ``ogden`` the silicone's
    :class:`~.records.Ogden`, ``table`` the section's node table and scratch (a
    :class:`~.records.NodeTable`; :func:`~.bending._section_moment`), ``p_atm`` [Pa].
    ``kappa_full`` is the curvature at p(s_max) [1/m] (<= 0: computed here). ``n`` solved
    points of kappa(p) and its first two derivatives in p (``curve``, a
    :class:`~.records.SolvedCurve` whose first ``n`` entries count,
    :func:`~.bending._curvature_start`) start the curvature solves (none: ``n`` = 0).
    Returns (s*, limit, p*, M*, kappa*, F_n(s*), kappa_full).
    """
    radius, wall_thickness, base_thickness = section.radius, section.wall, section.base
    force_limit, s_max = coil.force_limit, coil.s_max
    mu, alpha = ogden.mu, ogden.alpha
    y, wy, wyy, work = table.y, table.wy, table.wyy, table.work
    pressures, kappas, rates, rates2 = curve.pressure, curve.kappa, curve.rate, curve.rate2
    p_full = _gauge_pressure(s_max, p_atm)
    solved = kappa_full <= 0.0
    rate_full = 0.0
    rate2_full = 0.0
    if solved:
        kappa_full, dm, d2m = _curvature_solve(
            _pressure_moment(p_full, radius, base_thickness), y, wy, wyy, work, mu, alpha,
            _curvature_start(p_full, pressures, kappas, rates, rates2, n), NEWTON_RTOL, False)
        rate_full, rate2_full = _curvature_rates(_pressure_moment(1.0, radius, base_thickness),
                                                 dm, d2m)
    s, limit, force = _stroke_limit_model(PAPER, force_limit, s_max, radius, wall_thickness,
                                          lever, 0.0, mu, alpha, p_atm, _SEALED, STROKE_RTOL)
    p = _gauge_pressure(s, p_atm)
    moment = _pressure_moment(p, radius, base_thickness)
    if limit == 0:
        kappa = kappa_full
    else:
        # p* < p(s_max): start from the solved curve around p*, else from the full-stroke
        # solve (second-order Taylor when it was made here, else scaled by the pressure)
        guess = _curvature_start(p, pressures, kappas, rates, rates2, n)
        if guess <= 0.0 and solved:
            guess = _taylor_start(p, p_full, kappa_full, rate_full, rate2_full)
        if not guess > 0.0:
            guess = kappa_full * p / p_full
        kappa = _curvature_solve(moment, y, wy, wyy, work, mu, alpha, guess, NEWTON_RTOL,
                                 False)[0]
    return s, limit, p, moment, kappa, force, kappa_full


@formula
def _design_values(s, limit, p, moment, kappa, force, kappa_full, force_limit, length):
    """The nine design variables (order of DESIGN_VARIABLES) of a design of length L [m].

    ``nylon_use`` F_n(s*)/F_lim is at most 1 by construction: s* is either a stroke where
    F_n <= F_lim or the root of F_n = F_lim, whose solver stops within a relative stroke
    tolerance, so the ratio is clipped to 1 (it came out 1 + 6e-15, or 1 + 1e-8 for a
    very weak muscle).
    """
    fraction = 1.0 if limit == 0 else kappa / kappa_full
    use = force / force_limit
    if use > 1.0:
        use = 1.0
    return (s, limit, p, moment, moment / length, kappa * length, fraction, force, use)


def _inputs(radius, wall_thickness, length, coil_index, wrap_angle, base_thickness, ny):
    lo, hi = ny.coil_index_range
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    L = check_input("length", length)
    c = check_input("coil_index", coil_index, lo, hi)
    return a, t, L, c, check_wrap_angle(wrap_angle), b


def stroke_limit(radius, wall_thickness, coil_index, wrap_angle, base_thickness=None,
                 silicone="tc5005", nylon="silver_nylon66"):
    """Usable stroke s* = min(s_max(C), s_lim) of a design [-] (docs/model.md section 8).

    Parameters
    ----------
    radius, wall_thickness : float or array
        a, t [m], > 0.
    coil_index : float or array
        C [-], inside the coil-index table.
    wrap_angle : float or array
        psi [rad], in (0, pi/2).
    base_thickness : float or array, optional
        b [m]; b = t when None.
    silicone, nylon : str, dict or material object
        Material sets.
    """
    return design_limits(radius, wall_thickness, 1.0, coil_index, wrap_angle, base_thickness,
                         silicone, nylon)["usable_stroke"]


def design_limits(radius, wall_thickness, length, coil_index, wrap_angle, base_thickness=None,
                  silicone="tc5005", nylon="silver_nylon66", model="paper", supply_voltage=None,
                  cooling=None, chamber=None):
    """Every design variable of the cube for one design or broadcastable arrays of them.

    The slow, obviously-right pure-Python loop the compiled engine is tested against.

    Parameters
    ----------
    radius : float or array
        Inner chamber radius a [m], > 0.
    wall_thickness : float or array
        Wall thickness t [m], > 0.
    length : float or array
        Actuator length L [m], > 0.
    coil_index : float or array
        Coil index C [-], inside the coil-index table (1.1-1.7 for the default set).
    wrap_angle : float or array
        Helix angle psi of the wrap from the hoop direction [rad], in (0, pi/2).
    base_thickness : float or array, optional
        Bottom layer thickness b [m], > 0; b = t when None (docs/model.md section 1 [choice]).
    silicone : str, dict or Silicone, default "tc5005"
        Silicone set (its ``stretch_range`` sets the ``stretch_beyond_fit`` bit).
    nylon : str, dict or Nylon, default "silver_nylon66"
        Muscle set.
    model : str, default "paper"
        Model variant, one of :data:`MODELS` (docs/model.md s. 16).
    supply_voltage : float, optional
        Steady supply voltage V [V], > 0; None: no supply limit (docs/model.md s. 15).
    cooling : str, dict or Cooling, optional
        Cooling environment (``materials.COOLING_PARAMETERS``); None: the muscle set's
        ``heat_loss_per_length`` (docs/model.md s. 9).
    chamber : dict or sequence, optional
        ``sealed_chamber``'s coefficients (k0, k1, g0, g1, c0, c1, cb) [-]; None: the
        shipped ones (docs/model.md s. 22).

    Returns
    -------
    dict
        ``usable_stroke`` s* [-], ``limit`` (0 stroke, 1 strength, 2 supply, 3 load),
        ``pressure_max`` p* [Pa], ``torque_max`` M* [N m], ``tip_force_max`` F* [N],
        ``bend_angle_max`` theta* [rad], ``range_fraction`` theta*/theta(s_max) [-],
        ``nylon_force_max`` F_n(s*) [N], ``nylon_use`` F_n(s*)/F_lim [-],
        ``muscle_length`` [m], ``resistance`` [ohm], ``heating_power`` [W],
        ``heating_voltage`` [V], ``cooling_time`` [s], ``heating_time`` [s], ``cycle_time``
        [s], ``cycle_rate`` [Hz], ``heating_energy`` [J], ``mechanical_work`` [J],
        ``efficiency`` [-] (the last six NaN without a supply) and ``validity`` (bits of :data:`VALIDITY_FLAGS`). Floats (ints for the
        flags) for scalar input, arrays of the broadcast shape otherwise.

    Raises
    ------
    ValueError
        Naming the parameter and its accepted range.

    References
    ----------
    Paper section 4 and figure 12; docs/model.md sections 8, 15-17.
    """
    if model not in MODELS:
        raise ValueError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    code = MODELS.index(model)
    coef = sealed_coefficients(chamber)
    voltage = 0.0 if supply_voltage is None else float(
        check_input("supply_voltage", supply_voltage))
    ny = nylon_parameters(nylon)
    check_stroke_shape(ny.t_max, ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    sil = silicone_parameters(silicone)
    mu, alpha = sil.arrays()
    stretch_max = float(sil.stretch_range[1])
    a, t, L, c, psi, b = _inputs(radius, wall_thickness, length, coil_index, wrap_angle,
                                 base_thickness, ny)
    a, t, L, c, psi, b = np.broadcast_arrays(a, t, L, c, psi, b)
    ogden = Ogden(mu, alpha)
    nodes = Nodes(*quadrature_nodes())
    c_tab = np.asarray(ny.coil_index_table)
    shape = StrokeShape(ny.t_amb, ny.t_max, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    top = _stroke_shape(shape.t_max, shape.t_amb, shape.gamma, shape.beta, shape.t_g,
                        shape.sigma_g)
    out = {name: np.empty(a.shape, dtype=np.int8 if name in ("limit", "validity") else float)
           for name in DESIGN_VARIABLES}
    r_all, loss_all = np.empty(a.shape), np.empty(a.shape)
    for idx in np.ndindex(a.shape):
        ai, ti, bi, Li, ci, pi = (float(x[idx]) for x in (a, t, b, L, c, psi))
        force_limit = float(np.interp(ci, c_tab, ny.tensile_strength_table)) * ny.fibre_area
        r_per_len = coil_resistance(ny.resistance_per_length, ny.resistance_coil_index, ci)
        loss_per_len = ny.heat_loss_per_length if cooling is None else \
            coil_heat_loss_per_length(ci, ny, cooling)
        s_max = float(np.interp(ci, c_tab, ny.stroke_max_table))
        pitch = _pitch(ai, ti, bi, pi, ny.fibre_diameter * (ci + 1.0))
        lever = pitch / math.cos(pi)
        section = Section(ai, ti, bi)
        coil = CoilRow(force_limit, s_max, s_max / top, r_per_len,
                       ny.heat_capacity_per_length, loss_per_len, ny.thermal_force_coefficient)
        *state, closes, t_reach = _design_state(code, Drive(voltage, Li, pi, pitch), section,
                                                lever, coil, shape, ogden, nodes, P_ATM, coef)
        values = _design_values(*state, force_limit, Li)
        temps = _working_temperatures(code, values[0], t_reach, coil.scale, shape)
        thermal = _thermal_values(Li, pitch, section, pi, voltage, temps, shape.t_amb, coil)
        solid = _solid_fraction(ai, ti, bi) if code == INCOMPRESSIBLE_WALL else 0.0
        dynamic = _dynamic_values(code, values[0], section, lever, solid, ogden, P_ATM, coef,
                                  Cycle(voltage, thermal, temps, shape.t_amb,
                                        coil.c_per_len / coil.loss_per_len))
        flags = _validity(values[5], state[4], section, stretch_max, Li / pitch, closes,
                          dynamic[4])
        r_all[idx], loss_all[idx] = r_per_len, loss_per_len
        for name, v in zip(DESIGN_VARIABLES, (*values, *thermal, *dynamic, flags)):
            out[name][idx] = v
    check_supply_rise(voltage, out["muscle_length"], r_all, loss_all, "supply_voltage")
    return {name: (int(v) if name in ("limit", "validity") and v.ndim == 0
                   else scalar_or_array(v)) for name, v in out.items()}


def model_bend_angle(pressure, radius, wall_thickness, length, base_thickness=None,
                     silicone="tc5005", model="paper", chamber=None):
    """Free bend angle theta(p) = kappa(p) L of a model variant at a chamber pressure [rad].

    The variants differ here by the moment that bends the section (``lateral_pressure``:
    :func:`_model_moment`) or the stress it is balanced by
    (``cauchy_moment``); ``coupled_muscle``, ``paper_eq10`` and ``incompressible_wall``
    change the muscle's side only and give the paper's angle (docs/model.md s. 16, 18);
    ``sealed_chamber`` adds the squeeze of the stroke that holds p (s. 22).

    Parameters
    ----------
    pressure : float or array
        Chamber gauge pressure p [Pa], >= 0.
    radius, wall_thickness, length : float or array
        a, t, L [m], > 0.
    base_thickness : float or array, optional
        b [m], > 0; b = t when None.
    silicone : str, dict or Silicone
        Material set.
    model : str
        One of :data:`MODELS`.
    chamber : dict or sequence, optional
        ``sealed_chamber``'s coefficients; None: the shipped ones (docs/model.md s. 22).

    Returns
    -------
    float or array
        theta [rad], of the broadcast shape of the inputs.
    """
    if model not in MODELS:
        raise ValueError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    code = MODELS.index(model)
    coef = sealed_coefficients(chamber)
    p = check("pressure", pressure, 0.0, unit="Pa")
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    L = check_input("length", length)
    sil = silicone_parameters(silicone)
    mu, alpha = sil.arrays()
    nodes = quadrature_nodes()
    cauchy = code == CAUCHY_MOMENT

    def one(p_, a_, t_, b_, l_):
        y, wy, wyy, work = _node_table(a_, t_, b_, *nodes)
        moment = _model_moment(code, p_, a_, t_, b_)
        kappa = _curvature_nodes(moment, y, wy, wyy, work, mu, alpha, 0.0, NEWTON_RTOL, cauchy)
        kappa += _curve_squeeze(code, p_, Section(a_, t_, b_), Ogden(mu, alpha),
                                NodeTable(y, wy, wyy, work), P_ATM, coef)[0]
        return kappa * l_ * _curve_factor(code, p_, a_, t_, l_, mu, alpha)

    return scalar_or_array(np.vectorize(one, otypes=[float])(p, a, t, b, L))
