"""One registry of every cube variable and coordinate: name, dims, units, long_name.

The sweep writes from it, storage checks against it, charts take their labels from it and
the CLI converts units with it (after sgkit's ``variables.py``). ``display`` is the unit a
designer reads on charts and types on the command line; the cube stays SI.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["AXES", "COORDS", "CURVES", "DESIGN", "VARIABLES", "Variable", "display_label",
           "to_display"]

AXES = ("radius", "wall_thickness", "length", "coil_index", "wrap_angle")


@dataclass(frozen=True)
class Variable:
    """A cube coordinate or variable.

    Attributes
    ----------
    name : str
        snake_case name, the same in code, configs, the CLI and the cube.
    dims : tuple of str
        Dimensions, in order.
    units : str
        SI unit stored in the cube (``attrs["units"]``), "1" for dimensionless.
    long_name : str
        Human label (``attrs["long_name"]``).
    description : str
        What it is, with the MODEL.md section.
    display : str
        Unit shown on charts and accepted bare on the command line.
    kind : str
        Kind of quantity, for unit parsing (see :mod:`nylonflex.units`).
    dtype : str
        Stored dtype.
    """

    name: str
    dims: tuple[str, ...]
    units: str
    long_name: str
    description: str
    display: str
    kind: str
    dtype: str = "float64"

    def attrs(self) -> dict:
        """The attributes written to the cube."""
        out = {"units": self.units, "long_name": self.long_name,
               "description": self.description}
        if self.name == "limit":
            out["flag_values"] = np.array([0, 1], dtype=np.int8)
            out["flag_meanings"] = "stroke_limited strength_limited"
        return out


def _v(name, dims, units, long_name, description, display, kind, dtype="float64"):
    return Variable(name, tuple(dims), units, long_name, description, display, kind, dtype)


COORDS = {v.name: v for v in [
    _v("radius", ["radius"], "m", "chamber radius", "inner radius a of the half-cylindrical "
       "chamber (MODEL.md s. 1)", "mm", "length"),
    _v("wall_thickness", ["wall_thickness"], "m", "wall thickness",
       "thickness t of the half-cylindrical silicone wall (MODEL.md s. 1)", "mm", "length"),
    _v("length", ["length"], "m", "actuator length", "actuator length L (MODEL.md s. 1)",
       "mm", "length"),
    _v("coil_index", ["coil_index"], "1", "coil index",
       "spring index C = D/d of the coiled muscle (MODEL.md s. 2)", "1", "dimensionless"),
    _v("wrap_angle", ["wrap_angle"], "rad", "wrap angle",
       "helix angle psi of the wrap from the hoop direction (MODEL.md s. 4)", "deg", "angle"),
    _v("stroke", ["stroke"], "1", "muscle stroke",
       "muscle contraction s, a fraction of its ambient length (MODEL.md s. 2)", "1",
       "dimensionless"),
    _v("pressure", ["pressure"], "Pa", "chamber pressure", "gauge pressure p of the chamber "
       "(MODEL.md s. 3)", "kPa", "pressure"),
]}

DESIGN = {v.name: v for v in [
    _v("usable_stroke", AXES, "1", "usable stroke",
       "s* = min(s_max(C), s_lim), the stroke the muscle can use (MODEL.md s. 8)", "1",
       "dimensionless"),
    _v("limit", AXES, "1", "limiting factor",
       "0 stroke-limited (full range of motion), 1 strength-limited (MODEL.md s. 8)", "1",
       "dimensionless", "int8"),
    _v("pressure_max", AXES, "Pa", "maximum pressure", "p* = p(s*) (MODEL.md s. 8)", "kPa",
       "pressure"),
    _v("torque_max", AXES, "N m", "maximum torque", "M* = M_P(p*) (MODEL.md s. 8)", "N mm",
       "torque"),
    _v("tip_force_max", AXES, "N", "maximum tip force", "F* = M*/L, blocked (MODEL.md s. 7-8)",
       "N", "force"),
    _v("bend_angle_max", AXES, "rad", "maximum bend angle",
       "theta* = kappa(p*) L, free bending (MODEL.md s. 6, 8)", "deg", "angle"),
    _v("range_fraction", AXES, "1", "range of motion fraction",
       "theta*/theta(s_max); 1 means a full range of motion (MODEL.md s. 8)", "1",
       "dimensionless"),
    _v("nylon_force_max", AXES, "N", "nylon force at usable stroke", "F_n(s*) (MODEL.md s. 4)",
       "N", "force"),
    _v("nylon_use", AXES, "1", "nylon strength use", "F_n(s*)/F_lim(C) (MODEL.md s. 4, 8)",
       "1", "dimensionless"),
]}

CURVES = {v.name: v for v in [
    _v("nylon_force", ["radius", "wall_thickness", "coil_index", "wrap_angle", "stroke"], "N",
       "nylon force", "tension F_n(s) in the wrap (MODEL.md s. 4)", "N", "force"),
    _v("nylon_force_limit", ["coil_index"], "N", "nylon force limit",
       "breaking force F_lim(C) = sigma_u(C) A_f (MODEL.md s. 2)", "N", "force"),
    _v("chamber_pressure", ["stroke"], "Pa", "chamber pressure",
       "gauge pressure p(s), Boyle (MODEL.md s. 3)", "kPa", "pressure"),
    _v("bend_angle", ["radius", "wall_thickness", "length", "pressure"], "rad", "bend angle",
       "free bending angle theta(p) = kappa(p) L (MODEL.md s. 6)", "deg", "angle"),
    _v("tip_force", ["radius", "wall_thickness", "length", "pressure"], "N", "tip force",
       "blocked tip force M_P(p)/L (MODEL.md s. 7)", "N", "force"),
]}

VARIABLES = {**COORDS, **DESIGN, **CURVES}


def to_display(name: str, si):
    """SI values of a registered name in its display unit (mm, deg, kPa, ...)."""
    from .units import from_si

    return from_si(np.asarray(si, dtype=float), VARIABLES[name].display)


def display_label(name: str) -> str:
    """Axis label ``"long name [display unit]"`` of a registered name."""
    v = VARIABLES[name]
    unit = "" if v.display == "1" else f" [{v.display}]"
    return f"{v.long_name}{unit}"
