"""The finite-element twin of the actuator (the ``[fe]`` extra, built on FElupe).

``fe_bend`` builds the 3-D silicone body of a design (docs/fidelity.md: the chamber, its
wall and floor, the end caps of thickness t, the strain-limiting skin and the smeared hoop
wrap), loads the chamber with its pressure as a follower load and returns the bend angle
against pressure, with a Richardson estimate of the mesh's discretisation error.

FElupe (pip-only, kept, a small readable API for hyperelastic solids with u-p-J elements and
follower pressures) is imported only when a solve runs: everything else in nylonflex works
without the extra.
"""

from __future__ import annotations

import numpy as np

from ..units import InputError
from .stroke import air_heating_ratio, check_strokes, load_list

__all__ = ["FE_RANGES", "MESH_NAMES", "fe_bend", "fe_stroke", "require_felupe"]

#: The mesh levels a user may ask for, coarse to fine (:data:`.mesh.MESHES`).
MESH_NAMES = ("coarse", "default", "fine")
#: The level whose difference from each gives the Richardson estimate.
_COARSER = {"coarse": "rough", "default": "coarse", "fine": "default"}
#: Observed order of convergence of the bend angle in the mesh size (docs/fidelity.md).
ORDER = 2.0
#: Roache's safety factor for a two-mesh estimate whose order is not observed [-]
#: (:func:`pressure_error`).
SAFETY = 3.0

#: The shapes the FE twin accepts, beyond the registry's ranges of each dimension: the
#: mesh is sized for them (docs/fidelity.md).
FE_RANGES = {"wall_ratio": (0.02, 2.0), "base_ratio": (0.02, 2.0), "slenderness": (0.5, 40.0)}
#: At most this many pressures, each in [0, MAX_PRESSURE] Pa.
MAX_PRESSURES = 100
MAX_PRESSURE = 1e6

INSTALL_HINT = "the FE twin needs FElupe: pip install 'nylonflex[fe]'"


def require_felupe():
    """Import FElupe, or raise :class:`InputError` saying how to install it."""
    try:
        import felupe  # noqa: F401
    except ImportError:
        raise InputError(INSTALL_HINT) from None


def _design(radius, wall_thickness, length, base_thickness):
    from ..physics import check_input

    a = float(check_input("radius", radius))
    t = float(check_input("wall_thickness", wall_thickness))
    L = float(check_input("length", length))
    b = t if base_thickness is None else float(check_input("base_thickness", base_thickness))
    for name, value in (("wall_ratio", t / a), ("base_ratio", b / a),
                        ("slenderness", L / (a + t + b))):
        lo, hi = FE_RANGES[name]
        if not lo <= value <= hi:
            what = {"wall_ratio": "wall_thickness / radius", "base_ratio":
                    "base_thickness / radius", "slenderness":
                    "length / (radius + wall_thickness + base_thickness)"}[name]
            raise InputError(f"{what}: the FE twin accepts {lo:g} to {hi:g}, got {value:.4g}")
    return a, t, L, b


def _pressures(pressures):
    p = load_list(pressures, "pressures", "pressure", "Pa", MAX_PRESSURES)
    if not np.all(np.isfinite(p)) or np.any(p < 0) or np.any(p > MAX_PRESSURE):
        bad = p[~(np.isfinite(p) & (p >= 0) & (p <= MAX_PRESSURE))][0]
        raise InputError(f"pressures: each must be in [0, {MAX_PRESSURE:g}] Pa, got {bad:g}")
    return p


def _mesh_name(mesh):
    if not isinstance(mesh, str) or mesh not in MESH_NAMES:
        raise InputError(f"mesh: must be one of {', '.join(MESH_NAMES)}, got {mesh!r}")
    return mesh


def _silicone(silicone):
    from ..materials import silicone_parameters

    try:
        return silicone_parameters(silicone)
    except ValueError as exc:
        raise InputError(str(exc)) from None


#: The share of a two-mesh solve's work that the asked-for mesh takes (the rest: the
#: coarser mesh of the error estimate), for its progress report.
SHARE = 0.75


def _reporter(progress, loads):
    """``report(offset, weight)``: a solve's callback ``call(load, angle, iterations)``
    that tells ``progress(done, 1.0)`` the share done, ``offset + weight * load / top``
    over the loads (pressures [Pa] or strokes [-]) asked for."""
    top = float(loads.max()) if loads.max() > 0 else 1.0

    def report(offset, weight):
        def call(load, angle, iterations):
            if progress is not None:
                progress(offset + weight * load / top, 1.0)
        return call

    return report


def fe_bend(radius, wall_thickness, length, pressures, *, base_thickness=None,
            silicone="tc5005", mesh="default", blocked=False, progress=None):
    """Bend angle of a design against chamber pressure by the FE twin.

    Parameters
    ----------
    radius, wall_thickness, length : float
        a, t, L [m] (the registry's ranges; with t/a and b/a in [0.02, 2] and
        L/(a + t + b) in [0.5, 40]).
    pressures : float or sequence of float
        Chamber gauge pressures [Pa], each in [0, 1e6], at most 100.
    base_thickness : float, optional
        b [m]; the wall thickness when None.
    silicone : str, dict or Silicone
        Any silicone set nylonflex knows (named, a fitted file ``{"file": ...}``, or with
        fields overridden).
    mesh : {"coarse", "default", "fine"}
        Mesh level (docs/fidelity.md: the default's discretisation error is under 3 %).
    blocked : bool
        Hold the tip straight (its cap's outer face clamped, the paper's force test) and
        return the moment it takes.
    progress : callable, optional
        ``progress(done, total)`` in solved increments of both meshes (an estimate).

    Returns
    -------
    dict
        ``pressure`` [Pa], ``bend_angle`` [rad] and ``discretisation_error`` [1] (the
        Richardson estimate |theta_h - theta_2h| / (r^p - 1) / |theta_h| against the next
        coarser mesh, r = 1.5, p = 2; 0 at zero pressure), arrays in the order given; NaN
        where the solve could not reach the pressure (it stalls at large bends:
        docs/fidelity.md); ``coarser_bend_angle`` [rad], the next coarser mesh's angles the
        estimate is taken from. With ``blocked``: ``tip_moment`` [N m] (the moment the
        body exerts on the tip's holder about the x-axis through the skin, y = 0),
        ``tip_force`` [N] = tip_moment / length (the paper's eq. 16), their coarser
        mesh's ``coarser_tip_moment``, and ``discretisation_error`` that of the moment.

    Raises
    ------
    InputError
        A design outside the accepted range, no or negative pressures, an unknown mesh,
        or FElupe not installed.
    """
    from .mesh import body_mesh
    from .solve import solve_bend

    mesh = _mesh_name(mesh)
    a, t, L, b = _design(radius, wall_thickness, length, base_thickness)
    p = _pressures(pressures)
    sil = _silicone(silicone)
    require_felupe()
    mu, alpha = sil.arrays()
    report = _reporter(progress, p)

    if blocked:
        from .solve import solve_pressures

        fine, coarse = (solve_pressures(body_mesh(a, t, L, base_thickness=b, mesh=level), mu,
                                        alpha, p, progress=report(*part), partial=True,
                                        blocked=True)
                        for level, part in ((mesh, (0.0, SHARE)),
                                            (_COARSER[mesh], (SHARE, 1.0 - SHARE))))
        return {"pressure": p, "bend_angle": fine["bend_angle"],
                "tip_moment": fine["tip_moment"], "tip_force": fine["tip_moment"] / L,
                "discretisation_error": richardson(fine["tip_moment"], coarse["tip_moment"]),
                "mesh": mesh, "coarser_bend_angle": coarse["bend_angle"],
                "coarser_tip_moment": coarse["tip_moment"]}
    angles = solve_bend(body_mesh(a, t, L, base_thickness=b, mesh=mesh), mu, alpha, p,
                        progress=report(0.0, SHARE), partial=True)
    coarser = solve_bend(body_mesh(a, t, L, base_thickness=b, mesh=_COARSER[mesh]), mu,
                         alpha, p, progress=report(SHARE, 1.0 - SHARE), partial=True)
    return {"pressure": p, "bend_angle": angles,
            "discretisation_error": richardson(angles, coarser), "mesh": mesh,
            "coarser_bend_angle": coarser}


def richardson(fine, coarse):
    """The Richardson estimate |f_h - f_2h| / (r^p - 1) / |f_h| [1] of values ``fine`` on a
    mesh against ``coarse`` on the next coarser one (r = :data:`.mesh.REFINEMENT`, p =
    :data:`ORDER`); 0 where the value is 0, NaN where either is."""
    from .mesh import REFINEMENT

    fine, coarse = np.asarray(fine, dtype=float), np.asarray(coarse, dtype=float)
    factor = REFINEMENT ** ORDER - 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        err = np.where(fine != 0, np.abs(fine - coarse) / factor / np.abs(fine), 0.0)
    err[np.isnan(fine) | np.isnan(coarse)] = np.nan
    return err


def extrapolated(fine, coarse):
    """Richardson's extrapolation of two mesh levels' values (ratio
    :data:`.mesh.REFINEMENT`, order :data:`ORDER`), in their unit (the angles: [rad])."""
    from .mesh import REFINEMENT

    fine = np.asarray(fine, float)
    coarse = np.asarray(coarse, float)
    return fine + (fine - coarse) / (REFINEMENT ** ORDER - 1.0)


def pressure_error(fine, coarse):
    """The sealed chamber's pressure error estimate [1]: Roache's grid convergence index for
    two meshes, F_s |p_h - p_2h| / (r^p - 1) / |p_h|, with the safety factor F_s =
    :data:`SAFETY` and first order (p = 1), not :func:`richardson`'s second.

    The pressure is not yet in its asymptotic range on these meshes (docs/fidelity.md,
    "Driven as built": example 1's coarse, default and fine pressures 873, 868 and 852 Pa
    differ more the finer the mesh), so the second-order estimate (0.5 and 2.3 % on the
    examples) fell short of the default mesh's measured gap to the fine one (1.9 and 2.9 %);
    this one gives 3.5 and 17 %. 0 where the value is 0, NaN where either is."""
    from .mesh import REFINEMENT

    return richardson(fine, coarse) * SAFETY * (REFINEMENT ** ORDER - 1.0) / (REFINEMENT - 1.0)


def fe_stroke(radius, wall_thickness, length, strokes, *, base_thickness=None,
              silicone="tc5005", blocked=False, air_heating=None, mesh="default",
              progress=None):
    """The sealed actuator against the muscle's stroke by the FE twin.

    The wrap's rest length is 1 - s (bonded to the silicone: it does not slide); the
    chamber holds its air, (p0 + p) V = p0 V0 (T0 + dT)/T0 (docs/fidelity.md).

    Parameters
    ----------
    radius, wall_thickness, length : float
        a, t, L [m] (the ranges of :func:`.fe_bend`).
    strokes : float or sequence of float
        Muscle strokes s [-], each in [0, 0.5), at most 100.
    base_thickness : float, optional
        b [m]; the wall thickness when None.
    silicone : str, dict or Silicone
        Any silicone set nylonflex knows.
    blocked : bool
        Hold the tip straight (its cap's outer face clamped: the paper's force test).
    air_heating : float, optional
        Temperature rise dT of the chamber's air over the ambient T0 [K], in [0, 200]
        (T0: the nylon set's ambient, 298.15 K); the air is warmed at zero stroke, sealed,
        then the wrap contracts. None: isothermal (dT = 0).
    mesh : {"coarse", "default", "fine"}
        Mesh level.
    progress : callable, optional
        ``progress(done, total)``, the solved share of the work (an estimate).

    Returns
    -------
    dict
        Arrays in the order of ``strokes``: ``stroke`` [-], ``pressure`` (chamber gauge)
        [Pa], ``volume_ratio`` V/V0 [-], ``bend_angle`` [rad]; with ``blocked``
        ``tip_moment`` [N m] (the moment the body exerts on the tip's holder about the
        x-axis through the skin, y = 0) and ``tip_force`` [N] = tip_moment / length (the
        paper's eq. 16). ``discretisation_error`` [1]: the Richardson estimate (as
        :func:`.fe_bend`'s) of the bend angle (of the tip moment when ``blocked``) against
        the next coarser mesh, whose values are ``coarser_<name>``; ``pressure_error`` [1]
        the pressure's (:func:`pressure_error`: first order, safety factor 3, as the
        pressure is not yet in its asymptotic range). NaN where the solve could not reach
        the stroke. ``mesh``, and ``air_heating`` [K].

    Raises
    ------
    InputError
        A design outside the accepted range, strokes outside [0, 0.5), a negative or
        too large air heating, an unknown mesh, or FElupe not installed.
    """
    from ..physics.chamber import P_ATM
    from .mesh import body_mesh
    from .sealed import solve_stroke

    mesh = _mesh_name(mesh)
    a, t, L, b = _design(radius, wall_thickness, length, base_thickness)
    s = check_strokes(strokes)
    heating = air_heating_ratio(air_heating)
    sil = _silicone(silicone)
    require_felupe()
    mu, alpha = sil.arrays()
    report = _reporter(progress, s)

    fine, coarse = (solve_stroke(body_mesh(a, t, L, base_thickness=b, mesh=level), mu, alpha,
                                 s, p_atm=P_ATM, heating=heating, blocked=bool(blocked),
                                 progress=report(*part), partial=True)
                    for level, part in ((mesh, (0.0, SHARE)),
                                        (_COARSER[mesh], (SHARE, 1.0 - SHARE))))
    main = "tip_moment" if blocked else "bend_angle"
    err = richardson(fine[main], coarse[main])
    out = {"stroke": s, **fine}
    if blocked:
        out["tip_force"] = fine["tip_moment"] / L
    out["discretisation_error"] = err
    out["pressure_error"] = pressure_error(fine["pressure"], coarse["pressure"])
    out.update({f"coarser_{k}": v for k, v in coarse.items()})
    out["mesh"] = mesh
    out["air_heating"] = 0.0 if air_heating is None else float(air_heating)
    return out
