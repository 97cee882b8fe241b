"""The design-grid kernel: every design variable and curve of a slab of radii.

Private compiled loops that write into ``out`` arrays and check nothing (numbagg's habit);
:mod:`nylonflex.sweep.conductor` validates and shapes. The loops follow the model's
structure so that nothing is computed twice that a design axis does not change:

- per (a, t): the section's quadrature node table (heights and weights, no trigonometry),
  then the bend-angle curve over pressure, each solve started from the quintic Hermite
  extrapolation of the two before it (values, dkappa/dp and d2kappa/dp2), independent of
  C, psi and L;
- per (a, t, C): the curvature at the full stroke p(s_max(C)), started from the solved
  curve interpolated at p(s_max);
- per stroke: p(s) and S_theta(s), shared by every design's nylon-force curve;
- per (a, t, C, psi): the stroke limit and, only for strength-limited designs, one more
  curvature solve (started from the solved curve interpolated at p*, else from the
  full-stroke one); the nylon-force curve;
- per L: a multiply (theta = kappa L, F = M/L).

:func:`_design_points` evaluates scattered designs (the pointwise evaluator behind
``nylonflex.evaluate``), each with its own materials if asked.
"""

from __future__ import annotations

import math

import numpy as np

from ..physics.bending import (NEWTON_RTOL, _curvature_rates, _curvature_solve,
                               _curvature_start, _pressure_moment, _section_nodes)
from ..physics.chamber import _gauge_pressure, _solid_fraction
from ..physics.limits import (CAUCHY_MOMENT, INCOMPRESSIBLE_WALL, PAPER, PAPER_EQ10,
                              SEALED_CHAMBER, _blocked_moment, _curve_factor, _curve_squeeze,
                              _design_state_nodes,
                              _design_values, _dynamic_values, _length_factor, _model_moment,
                              _model_state_nodes, _nylon_force_model, _paper_force, _reach,
                              _stroke_limit_model, _stroke_state_nodes, _thermal_values,
                              _thermal_values_at, _validity, _working_temperatures)
from ..physics.nylon import _stroke_shape
from ..physics.records import (CoilRow, Cycle, Drive, NodeTable, Ogden, Section,
                                SolvedCurve, StrokeShape)
from ..physics.silicone import _equibiaxial_stress_and_slope, _stress_and_slope
from ..physics.thermal import _cooling_time
from ..physics.wrap import _outer_perimeter, _pitch, _wrap_force
from ._compile import compiled_entry, jit_kernel
from .records import GridScratch
from .rows import (ROW_BEND_ANGLE_MAX, ROW_COOLING_TIME, ROW_CYCLE_RATE, ROW_CYCLE_TIME,
                   ROW_EFFICIENCY, ROW_HEATING_ENERGY, ROW_HEATING_POWER, ROW_HEATING_TIME,
                   ROW_HEATING_VOLTAGE, ROW_LIMIT, ROW_MECHANICAL_WORK, ROW_MUSCLE_LENGTH,
                   ROW_NYLON_FORCE_MAX, ROW_NYLON_USE, ROW_PRESSURE_MAX, ROW_RANGE_FRACTION,
                   ROW_RESISTANCE, ROW_TIP_FORCE_MAX, ROW_TORQUE_MAX, ROW_USABLE_STROKE,
                   ROW_VALIDITY)
from .scratch import node_scratch
from .specialise import specialised


def _design_slab(grid, coil, silicone, nodes, muscle, options, out, scratch, k0, k1):
    """Fill ``out`` (a :class:`~.records.GridOut`) for the radii ``grid.radius``: the
    (radius, wall) pairs k0 <= k < k1, k = radius index x walls + wall index (a thread's
    chunk, :func:`nylonflex.engine.threads.run_chunks`).

    ``grid`` is a :class:`~.records.GridAxes` (all other axes whole), ``coil`` a
    :class:`~.records.CoilTable` with one entry a coil index of the axis, ``silicone`` an
    :class:`~.records.Ogden` of 1-D arrays, ``nodes`` the quadrature's
    :class:`~.records.Nodes`, ``muscle`` a :class:`~.records.Muscle` of one entry and
    ``options`` the :class:`~.records.Options` (model code, supply, fitted stretch);
    ``scratch`` its working arrays (a :class:`~.records.GridScratch`, :func:`grid_scratch`).
    ``out.design[ROW_<NAME>]`` holds each float variable, ``out.flags`` ``limit`` and
    ``validity`` (the rows of :mod:`.rows`); shapes (na, nt, nl, nc, npsi), curves as the
    registry says.

    The paper's model without a supply runs the loops it always ran (the stroke state once
    per (a, t, C, psi)); a variant or a supply runs :func:`_model_state_nodes`, per length
    when the supply makes the reachable stroke depend on the muscle's length, its curvature
    solves started from the bend-angle curve, which is the model's own kappa(p).
    """
    radius, wall, length, wrap = grid.radius, grid.wall, grid.length, grid.wrap
    stroke, pressure, p_atm = grid.stroke, grid.pressure, grid.p_atm
    mu, alpha = silicone.mu, silicone.alpha
    x_base, w_base, phi_trig, w_phi = nodes.x_base, nodes.w_base, nodes.phi_trig, nodes.w_phi
    out_design, out_flags, out_force, out_angle, out_tip = out
    coil_s_max, coil_force_limit, coil_width, coil_r, coil_loss = coil
    model, voltage, stretch_max, chamber = options
    t_amb = muscle.t_amb[0]
    t_max = muscle.t_max[0]
    gamma = muscle.gamma[0]
    beta = muscle.beta[0]
    t_g = muscle.t_g[0]
    sigma_g = muscle.sigma_g[0]
    c_per_len = muscle.c_per_len[0]
    force_coeff = muscle.force_coeff[0]
    shape = StrokeShape(t_amb, t_max, gamma, beta, t_g, sigma_g)
    ogden = Ogden(mu, alpha)
    # _PAPER_ONLY is a compile-time constant: design_slab_paper runs only the paper's
    # model without a supply, and Numba prunes every branch below that tests it, with the
    # variants' formulas it would call, before typing (a shorter first compile)
    default = _PAPER_ONLY or (model == PAPER and voltage <= 0.0)
    cauchy = model == CAUCHY_MOMENT
    top = _stroke_shape(t_max, t_amb, gamma, beta, t_g, sigma_g)
    b_fixed = grid.base_thickness
    nt = wall.shape[0]
    nl = length.shape[0]
    nc = coil_s_max.shape[0]
    npsi = wrap.shape[0]
    ns = stroke.shape[0]
    npr = pressure.shape[0]
    # p(s) and S_theta(s) depend on the stroke only: once per stroke, not per design
    stroke_pressure = scratch.stroke_pressure
    stroke_hoop = scratch.stroke_hoop
    for js in range(ns):
        stroke_pressure[js] = _gauge_pressure(stroke[js], p_atm)
        if not _PAPER_ONLY and model == PAPER_EQ10:
            stroke_hoop[js] = _equibiaxial_stress_and_slope(1.0 - stroke[js], mu, alpha)[0]
        else:
            stroke_hoop[js] = _stress_and_slope(1.0 - stroke[js], mu, alpha)[0]
    y_nodes, wy_nodes, wyy_nodes, work = scratch.y, scratch.wy, scratch.wyy, scratch.work
    kappa_curve, rate_curve, rate2_curve = scratch.kappa, scratch.rate, scratch.rate2
    for k in range(k0, k1):
        ia = k // nt
        it = k % nt
        a = radius[ia]
        t = wall[it]
        b = t if b_fixed <= 0.0 else b_fixed
        _section_nodes(a, t, b, x_base, w_base, phi_trig, w_phi, y_nodes, wy_nodes, wyy_nodes)
        section = Section(a, t, b)
        table = NodeTable(y_nodes, wy_nodes, wyy_nodes, work)
        perimeter = _outer_perimeter(a, t, b)
        # the bend-angle curve first, with dkappa/dp and d2kappa/dp2: each solve starts from
        # the previous ones, and they start the coil loop's solves
        # dM/dp: linear in p in every model (the paper's: M_P itself, bit for bit)
        lever_p = _pressure_moment(1.0, a, b) if _PAPER_ONLY else \
            _model_moment(model, 1.0, a, t, b)
        for jp in range(npr):
            moment = _pressure_moment(pressure[jp], a, b) if _PAPER_ONLY else \
                _model_moment(model, pressure[jp], a, t, b)
            kappa, dm, d2m = _curvature_solve(
                moment, y_nodes, wy_nodes, wyy_nodes, work, mu, alpha,
                _curvature_start(pressure[jp], pressure, kappa_curve, rate_curve, rate2_curve,
                                 jp), NEWTON_RTOL, cauchy)
            kappa_curve[jp] = kappa
            rate_curve[jp], rate2_curve[jp] = _curvature_rates(lever_p, dm, d2m)
            # sealed_chamber's squeeze at the stroke that holds this pressure (else 0)
            if not _PAPER_ONLY:
                k_sq, m_sq = _curve_squeeze(model, pressure[jp], section, ogden, table, p_atm,
                                            chamber)
                kappa += k_sq
                moment += m_sq
            for il in range(nl):
                factor = 1.0 if _PAPER_ONLY else _curve_factor(
                    model, pressure[jp], a, t, length[il], mu, alpha)
                out_angle[ia, it, il, jp] = kappa * length[il] * factor
                out_tip[ia, it, il, jp] = moment / length[il]
        curve = SolvedCurve(pressure, kappa_curve, rate_curve, rate2_curve)
        # the paper's solves (nominal stress) may start from it (not the Cauchy variant's)
        n_curve = npr if not cauchy else 0
        solid = _solid_fraction(a, t, b) if not _PAPER_ONLY and \
            model == INCOMPRESSIBLE_WALL else 0.0
        for ic in range(nc):
            s_max = coil_s_max[ic]
            f_lim = coil_force_limit[ic]
            # r' and lambda' depend on the coil index (docs/model.md s. 9)
            r_per_len = coil_r[ic]
            loss_per_len = coil_loss[ic]
            tau = c_per_len / loss_per_len
            scale = s_max / top
            coil_row = CoilRow(f_lim, s_max, scale, r_per_len, c_per_len, loss_per_len,
                               force_coeff)
            kappa_full = 0.0
            if default:
                p_full = _gauge_pressure(s_max, p_atm)
                kappa_full = _curvature_solve(
                    _pressure_moment(p_full, a, b), y_nodes, wy_nodes, wyy_nodes, work, mu,
                    alpha, _curvature_start(p_full, pressure, kappa_curve, rate_curve,
                                            rate2_curve, n_curve), NEWTON_RTOL, False)[0]
                # the working temperatures of a stroke-limited design (s* = s_max) depend
                # on the coil index only: once per C, not per wrap angle
                temps_full = _working_temperatures(model, s_max, t_max, scale, shape)
            else:
                temps_full = (0.0, 0.0, 0.0)
            for ip in range(npsi):
                pitch = _pitch(a, t, b, wrap[ip], coil_width[ic])
                cos_wrap = math.cos(wrap[ip])
                lever = pitch / cos_wrap
                if default:
                    st = _stroke_state_nodes(section, lever, coil_row, kappa_full, ogden,
                                             table, p_atm, curve, n_curve)
                    closes = False
                    if st[1] == 0:
                        temps = temps_full
                    else:
                        temps = _working_temperatures(model, st[0], t_max, scale, shape)
                else:
                    st = (0.0, 0, 0.0, 0.0, 0.0, 0.0, 0.0)
                    closes = False
                    temps = (0.0, 0.0, 0.0)
                # the cooling time does not depend on the length: once for all lengths
                # while the working temperatures stay
                cooling = _cooling_time(temps[0], temps[1], t_amb, tau)
                for il in range(nl):
                    if not _PAPER_ONLY and not default and (il == 0 or voltage > 0.0):
                        reach = _reach(coil_row, Drive(voltage, length[il], wrap[ip], pitch),
                                       section, shape)
                        ms = _model_state_nodes(model, section, lever, coil_row, reach, ogden,
                                                table, p_atm, chamber, curve, npr)
                        st = (ms[0], ms[1], ms[2], ms[3], ms[4], ms[5], ms[6])
                        closes = ms[7]
                        temps = _working_temperatures(model, ms[0], reach.temperature, scale,
                                                      shape)
                        cooling = _cooling_time(temps[0], temps[1], t_amb, tau)
                    # fe_calibrated's curvatures depend on the length: scaled here, as
                    # the model state above is length-free
                    lf = 1.0 if _PAPER_ONLY else _length_factor(model, a, length[il])
                    # and sealed_chamber's blocked moment, its pressure held straight
                    m_star = st[3] if _PAPER_ONLY else _blocked_moment(
                        model, st[0], st[2], st[3], section, length[il], chamber)
                    (usable_stroke, limit, pressure_max, torque_max, tip_force_max,
                     bend_angle_max, range_fraction, nylon_force_max,
                     nylon_use) = _design_values(st[0], st[1], st[2], m_star, st[4] * lf,
                                                 st[5], st[6] * lf, f_lim, length[il])
                    out_design[ROW_USABLE_STROKE, ia, it, il, ic, ip] = usable_stroke
                    out_flags[ROW_LIMIT, ia, it, il, ic, ip] = limit
                    out_design[ROW_PRESSURE_MAX, ia, it, il, ic, ip] = pressure_max
                    out_design[ROW_TORQUE_MAX, ia, it, il, ic, ip] = torque_max
                    out_design[ROW_TIP_FORCE_MAX, ia, it, il, ic, ip] = tip_force_max
                    out_design[ROW_BEND_ANGLE_MAX, ia, it, il, ic, ip] = bend_angle_max
                    out_design[ROW_RANGE_FRACTION, ia, it, il, ic, ip] = range_fraction
                    out_design[ROW_NYLON_FORCE_MAX, ia, it, il, ic, ip] = nylon_force_max
                    out_design[ROW_NYLON_USE, ia, it, il, ic, ip] = nylon_use
                    thermal = _thermal_values_at(length[il], pitch, perimeter, cos_wrap,
                                                 voltage, temps, t_amb, coil_row, tau, cooling)
                    (muscle_length, resistance, heating_power, heating_voltage, cooling_time,
                     heating_time) = thermal
                    out_design[ROW_MUSCLE_LENGTH, ia, it, il, ic, ip] = muscle_length
                    out_design[ROW_RESISTANCE, ia, it, il, ic, ip] = resistance
                    out_design[ROW_HEATING_POWER, ia, it, il, ic, ip] = heating_power
                    out_design[ROW_HEATING_VOLTAGE, ia, it, il, ic, ip] = heating_voltage
                    out_design[ROW_COOLING_TIME, ia, it, il, ic, ip] = cooling_time
                    out_design[ROW_HEATING_TIME, ia, it, il, ic, ip] = heating_time
                    if _PAPER_ONLY:  # no supply: NaN, as _dynamic_values gives
                        cycle_time = cycle_rate = heating_energy = math.nan
                        mechanical_work = efficiency = math.nan
                    else:
                        (cycle_time, cycle_rate, heating_energy, mechanical_work,
                         efficiency) = _dynamic_values(
                            model, usable_stroke, section, lever, solid, ogden, p_atm, chamber,
                            Cycle(voltage, thermal, temps, t_amb, tau))
                    out_design[ROW_CYCLE_TIME, ia, it, il, ic, ip] = cycle_time
                    out_design[ROW_CYCLE_RATE, ia, it, il, ic, ip] = cycle_rate
                    out_design[ROW_HEATING_ENERGY, ia, it, il, ic, ip] = heating_energy
                    out_design[ROW_MECHANICAL_WORK, ia, it, il, ic, ip] = mechanical_work
                    out_design[ROW_EFFICIENCY, ia, it, il, ic, ip] = efficiency
                    out_flags[ROW_VALIDITY, ia, it, il, ic, ip] = _validity(
                        bend_angle_max, st[4] * lf, section, stretch_max, length[il] / pitch,
                        closes, efficiency)
                for js in range(ns):
                    if not _PAPER_ONLY and (model == INCOMPRESSIBLE_WALL or
                                            model == SEALED_CHAMBER):
                        f = _nylon_force_model(model, stroke[js], a, t, lever, solid, mu,
                                               alpha, p_atm, chamber)[0]
                        out_force[ia, it, ic, ip, js] = f if f < math.inf else math.nan
                    else:
                        out_force[ia, it, ic, ip, js] = _wrap_force(
                            stroke_pressure[js], stroke_hoop[js], a, t, lever)


def _design_points(designs, coil, silicone, nodes, muscle, options, p_atm, out, table, i0,
                   i1):
    """Every design variable of the scattered designs i0 <= i < i1 (a thread's chunk).

    ``designs`` is a :class:`~.records.PointDesigns`, ``coil`` a
    :class:`~.records.CoilTable` and ``muscle`` a :class:`~.records.Muscle`, one entry a
    design. ``silicone`` holds 2-D arrays (row, term) with one row for all designs or one
    row a design. ``table`` is the thread's node table and scratch
    (:func:`.scratch.node_scratch`).
    The loop body is the one :func:`nylonflex.physics.design_limits` runs, so both give the
    same numbers.
    """
    radius, wall, base, length, wrap = designs
    s_max_all, f_lim_all, width_all, r_all, loss_all = coil
    mu_all, alpha_all = silicone
    out_design, out_flags = out
    model, voltage, stretch_max, chamber = options
    t_amb_all, t_max_all, gamma_all, beta_all, t_g_all, sigma_g_all = \
        muscle.t_amb, muscle.t_max, muscle.gamma, muscle.beta, muscle.t_g, muscle.sigma_g
    c_all, coeff_all = muscle.c_per_len, muscle.force_coeff
    step = 0 if mu_all.shape[0] == 1 else 1  # one row for all, or one a design
    for i in range(i0, i1):
        row = i * step
        ogden = Ogden(mu_all[row], alpha_all[row])
        a = radius[i]
        t = wall[i]
        b = base[i]
        psi = wrap[i]
        f_lim = f_lim_all[i]
        s_max = s_max_all[i]
        t_amb = t_amb_all[i]
        t_max = t_max_all[i]
        shape = StrokeShape(t_amb, t_max, gamma_all[i], beta_all[i], t_g_all[i],
                            sigma_g_all[i])
        scale = s_max / _stroke_shape(t_max, t_amb, gamma_all[i], beta_all[i], t_g_all[i],
                                      sigma_g_all[i])
        coil_row = CoilRow(f_lim, s_max, scale, r_all[i], c_all[i], loss_all[i], coeff_all[i])
        section = Section(a, t, b)
        pitch = _pitch(a, t, b, psi, width_all[i])
        lever = pitch / math.cos(psi)
        st = _design_state_nodes(model, Drive(voltage, length[i], psi, pitch), section, lever,
                                 coil_row, shape, ogden, nodes, table, p_atm, chamber)
        (usable_stroke, limit, pressure_max, torque_max, tip_force_max, bend_angle_max,
         range_fraction, nylon_force_max, nylon_use) = _design_values(
            st[0], st[1], st[2], st[3], st[4], st[5], st[6], f_lim, length[i])
        out_design[ROW_USABLE_STROKE, i] = usable_stroke
        out_flags[ROW_LIMIT, i] = limit
        out_design[ROW_PRESSURE_MAX, i] = pressure_max
        out_design[ROW_TORQUE_MAX, i] = torque_max
        out_design[ROW_TIP_FORCE_MAX, i] = tip_force_max
        out_design[ROW_BEND_ANGLE_MAX, i] = bend_angle_max
        out_design[ROW_RANGE_FRACTION, i] = range_fraction
        out_design[ROW_NYLON_FORCE_MAX, i] = nylon_force_max
        out_design[ROW_NYLON_USE, i] = nylon_use
        temps = _working_temperatures(model, usable_stroke, st[8], scale, shape)
        thermal = _thermal_values(length[i], pitch, section, psi, voltage, temps, t_amb,
                                  coil_row)
        (muscle_length, resistance, heating_power, heating_voltage, cooling_time,
         heating_time) = thermal
        out_design[ROW_MUSCLE_LENGTH, i] = muscle_length
        out_design[ROW_RESISTANCE, i] = resistance
        out_design[ROW_HEATING_POWER, i] = heating_power
        out_design[ROW_HEATING_VOLTAGE, i] = heating_voltage
        out_design[ROW_COOLING_TIME, i] = cooling_time
        out_design[ROW_HEATING_TIME, i] = heating_time
        solid = _solid_fraction(a, t, b) if model == INCOMPRESSIBLE_WALL else 0.0
        (cycle_time, cycle_rate, heating_energy, mechanical_work,
         efficiency) = _dynamic_values(model, usable_stroke, section, lever, solid, ogden,
                                       p_atm, chamber, Cycle(voltage, thermal, temps, t_amb,
                                                             c_all[i] / loss_all[i]))
        out_design[ROW_CYCLE_TIME, i] = cycle_time
        out_design[ROW_CYCLE_RATE, i] = cycle_rate
        out_design[ROW_HEATING_ENERGY, i] = heating_energy
        out_design[ROW_MECHANICAL_WORK, i] = mechanical_work
        out_design[ROW_EFFICIENCY, i] = efficiency
        out_flags[ROW_VALIDITY, i] = _validity(bend_angle_max, st[4], section, stretch_max,
                                               length[i] / pitch, st[7], efficiency)


#: Whether the grid kernel's body runs the paper's model without a supply only: a constant
#: Numba compiles in (False here; True in :data:`design_slab_paper`'s copy of the body).
_PAPER_ONLY = False


#: The paper's stroke limit: :func:`~nylonflex.physics.limits._stroke_limit_model` whose
#: calls of ``_nylon_force_model`` call the paper's F_n
#: (:func:`~nylonflex.physics.limits._paper_force`), the branch it takes for the model code
#: PAPER: the same lines and numbers, none of the variants' forces to compile.
_stroke_limit_paper = specialised(_stroke_limit_model, "_stroke_limit_paper",
                                  _nylon_force_model=_paper_force)

#: The paper's stroke state: :func:`~nylonflex.physics.limits._stroke_state_nodes` calling
#: :data:`_stroke_limit_paper`, so that the paper's grid kernel compiles no variant force.
_stroke_state_paper = specialised(_stroke_state_nodes, "_stroke_state_nodes_paper",
                                  _stroke_limit_model=_stroke_limit_paper)

#: The globals that :data:`design_slab_paper`'s copy of the grid kernel's body fixes
#: (:func:`~.specialise.specialised`): ``_PAPER_ONLY`` and the paper's stroke state.
PAPER_ONLY_GLOBALS = {"_PAPER_ONLY": True, "_stroke_state_nodes": _stroke_state_paper}

#: The compiled loops: one body each, for threaded runs (chunks on the engine's threads,
#: :mod:`nylonflex.engine.threads`) and serial ones (Dask workers) alike.
design_slab = jit_kernel(_design_slab, callee_body=True, borrows=True)
design_points = jit_kernel(_design_points, callee_body=True, borrows=True)
#: The grid kernel of the paper's model without a supply (the main job, figure 12): the
#: same source as :data:`design_slab`, the same numbers bit for bit, about 30 % less to
#: compile (:func:`grid_kernel` chooses).
design_slab_paper = jit_kernel(specialised(_design_slab, "_design_slab_paper",
                                           **PAPER_ONLY_GLOBALS),
                               callee_body=True, borrows=True)


def points_entry(args):
    """:data:`design_points`'s compiled entry for arguments made the way ``args`` (one
    call's) were (:func:`._compile.compiled_entry`): what ``nylonflex.evaluate``'s
    one-design path calls, without the dispatcher's typing of its seven records."""
    return compiled_entry(design_points, args)


def grid_scratch(grid, nodes):
    """The grid kernel's working arrays for a call on ``grid`` (a :class:`~.records.GridAxes`)
    with the quadrature ``nodes`` (a :class:`~.records.Nodes`): a
    :class:`~.records.GridScratch`, one a thread (each call fills what it reads): the
    section's node table (:func:`.scratch.node_scratch`) and the curves."""
    npr, ns = len(grid.pressure), len(grid.stroke)
    return GridScratch(*node_scratch(nodes), np.empty(npr), np.empty(npr), np.empty(npr),
                       np.empty(ns), np.empty(ns))


def grid_kernel(model: int, voltage: float):
    """The grid kernel for a model code and supply voltage [V] (<= 0: none):
    :data:`design_slab_paper` for the paper's model without a supply, else
    :data:`design_slab`."""
    return design_slab_paper if model == PAPER and voltage <= 0.0 else design_slab
