"""The input checks of ``fe_stroke``, the FE twin driven as the actuator is built
(docs/fidelity.md, "Driven as built: the sealed, stroke-driven twin").

The muscle's stroke shortens the wrap; the sealed chamber's air follows Boyle's law with
the deformed cavity's volume (:mod:`.sealed`). Where the paper's eq. (8) takes the chamber
to shrink at fixed shape and length, V1/V2 = (1 - s)^-2, the twin lets the D-section round
out and the wall lengthen above the strain-limiting skin.
"""

from __future__ import annotations

import numpy as np

from ..units import InputError

__all__ = ["MAX_AIR_HEATING", "MAX_STROKE", "MAX_STROKES", "air_heating_ratio", "check_strokes",
           "load_list"]

#: At most this many strokes, each in [0, MAX_STROKE) [-].
MAX_STROKES = 100
MAX_STROKE = 0.5
#: The air's temperature rise is at most this [K].
MAX_AIR_HEATING = 200.0


def load_list(values, field: str, noun: str, unit: str, most: int):
    """``values`` as a 1-D float array of 1 to ``most`` entries, or :class:`InputError`
    naming ``field`` (the FE twin's pressures [Pa] or strokes [-]; their ranges are the
    caller's)."""
    try:
        out = np.atleast_1d(np.asarray(values, dtype=float))
    except (TypeError, ValueError):
        raise InputError(f"{field}: must be numbers [{unit}]") from None
    if out.ndim != 1 or out.size == 0:
        raise InputError(f"{field}: need at least one {noun} [{unit}]")
    if out.size > most:
        raise InputError(f"{field}: at most {most}, got {out.size}")
    return out


def check_strokes(strokes):
    """``strokes`` as an array [-], or :class:`InputError`."""
    s = load_list(strokes, "strokes", "stroke", "-", MAX_STROKES)
    ok = np.isfinite(s) & (s >= 0) & (s < MAX_STROKE)
    if not np.all(ok):
        raise InputError(f"strokes: each must be in [0, {MAX_STROKE:g}) [-], got {s[~ok][0]:g}")
    return s


def air_heating_ratio(air_heating):
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
