"""``fe_stroke``: the FE twin driven as the actuator is built (docs/fidelity.md, "Driven as
built: the sealed, stroke-driven twin").

The muscle's stroke shortens the wrap; the sealed chamber's air follows Boyle's law with
the deformed cavity's volume (:mod:`.sealed`). Where the paper's eq. (8) takes the chamber
to shrink at fixed shape and length, V1/V2 = (1 - s)^-2, the twin lets the D-section round
out and the wall lengthen above the strain-limiting skin.
"""

from __future__ import annotations

import numpy as np

from ..units import InputError

__all__ = ["MAX_AIR_HEATING", "MAX_STROKE", "MAX_STROKES", "fe_stroke"]

#: At most this many strokes, each in [0, MAX_STROKE) [-].
MAX_STROKES = 100
MAX_STROKE = 0.5
#: The air's temperature rise is at most this [K].
MAX_AIR_HEATING = 200.0


def _strokes(strokes):
    try:
        s = np.atleast_1d(np.asarray(strokes, dtype=float))
    except (TypeError, ValueError):
        raise InputError("strokes: must be numbers [-]") from None
    if s.ndim != 1 or s.size == 0:
        raise InputError("strokes: need at least one stroke [-]")
    if s.size > MAX_STROKES:
        raise InputError(f"strokes: at most {MAX_STROKES}, got {s.size}")
    ok = np.isfinite(s) & (s >= 0) & (s < MAX_STROKE)
    if not np.all(ok):
        raise InputError(f"strokes: each must be in [0, {MAX_STROKE:g}) [-], got {s[~ok][0]:g}")
    return s


def _heating(air_heating):
    """(T0 + dT)/T0 [-] of a temperature rise dT [K] (None: 1), T0 the nylon set's
    ambient."""
    from ..materials import nylon_parameters

    if air_heating is None:
        return 1.0
    try:
        dT = float(air_heating)
    except (TypeError, ValueError):
        raise InputError("air_heating: must be a temperature rise [K]") from None
    if not 0.0 <= dT <= MAX_AIR_HEATING:
        raise InputError(f"air_heating: must be in [0, {MAX_AIR_HEATING:g}] K, got {dT:g}")
    t0 = float(nylon_parameters().t_amb)
    return (t0 + dT) / t0


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
        paper's eq. 16). ``discretisation_error`` [1]: the larger of the Richardson
        estimates (as :func:`.fe_bend`'s) of the pressure and of the bend angle (of the
        tip moment when ``blocked``), against the next coarser mesh, whose values are
        ``coarser_<name>``. NaN where the solve could not reach the stroke. ``mesh``,
        and ``air_heating`` [K].

    Raises
    ------
    InputError
        A design outside the accepted range, strokes outside [0, 0.5), a negative or
        too large air heating, an unknown mesh, or FElupe not installed.
    """
    from ..physics.chamber import P_ATM
    from . import _COARSER, _design, _mesh_name, _silicone, require_felupe, richardson
    from .mesh import body_mesh
    from .sealed import solve_stroke

    mesh = _mesh_name(mesh)
    a, t, L, b = _design(radius, wall_thickness, length, base_thickness)
    s = _strokes(strokes)
    heating = _heating(air_heating)
    sil = _silicone(silicone)
    require_felupe()
    mu, alpha = sil.arrays()
    span = float(s.max()) if s.max() > 0 else 1.0
    share = 0.75  # of the work: the asked-for mesh; the rest the coarser one

    def report(offset, weight):
        def call(stroke, angle, iterations):
            if progress is not None:
                progress(offset + weight * stroke / span, 1.0)
        return call

    fine, coarse = (solve_stroke(body_mesh(a, t, L, base_thickness=b, mesh=level), mu, alpha,
                                 s, p_atm=P_ATM, heating=heating, blocked=bool(blocked),
                                 progress=report(*part), partial=True)
                    for level, part in ((mesh, (0.0, share)),
                                        (_COARSER[mesh], (share, 1.0 - share))))
    main = "tip_moment" if blocked else "bend_angle"
    err = np.fmax(richardson(fine["pressure"], coarse["pressure"]),
                  richardson(fine[main], coarse[main]))
    err[np.isnan(fine[main]) | np.isnan(coarse[main])] = np.nan
    out = {"stroke": s, **fine}
    if blocked:
        out["tip_force"] = fine["tip_moment"] / L
    out["discretisation_error"] = err
    out.update({f"coarser_{k}": v for k, v in coarse.items()})
    out["mesh"] = mesh
    out["air_heating"] = 0.0 if air_heating is None else float(air_heating)
    return out
