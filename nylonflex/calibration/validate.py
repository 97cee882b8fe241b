"""Check one actuator design against its measurements (the paper's figures 4, 6 and 7).

The design comes from a config with a ``design:`` section as ``nylonflex simulate`` reads
(radius, wall_thickness, length, base_thickness; coil_index and wrap_angle are read but not
needed here) and the config's ``silicone`` and ``nylon`` sets (names or fitted files). The
data file (plain CSV, units in the header) holds any of:

- ``stroke`` and ``pressure``: chamber pressure against muscle stroke (figure 4), model
  :func:`~nylonflex.physics.chamber_pressure`;
- ``pressure`` and ``bend_angle``: bend angle against pressure (figure 6), model
  :func:`~nylonflex.physics.bend_angle`;
- ``pressure`` and ``tip_force``: tip force against pressure (figure 7), model
  :func:`~nylonflex.physics.tip_force`.

The error is reported as the paper does, the largest model-minus-data difference over the
largest measured value, in percent (its "maximum displacement error", "pressure error" and
"maximum force error"), beside the RMSE. A model 5 % above the data reports 5 %.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import DESIGN_RANGES, read_yaml
from ..materials import nylon_parameters, silicone_parameters
from ..physics import bend_angle, chamber_pressure, tip_force
from ..units import InputError, parse_quantity
from .data import Table, column, read_table
from ..files.material_files import anchor_material_files
from ..variables import VARIABLES

__all__ = ["Comparison", "validate_design", "design_from_config"]

#: The highest pressure compared [Pa]: the model's (the ``pressure`` axis, docs/model.md s. 3).
_PRESSURE_MAX = VARIABLES["pressure"].hi

#: measured quantity -> (x name, error name as the paper reports it, unit)
CHECKS = {
    "pressure": ("stroke", "pressure_error", "Pa"),
    "bend_angle": ("pressure", "maximum_displacement_error", "rad"),
    "tip_force": ("pressure", "maximum_force_error", "N"),
}


@dataclass
class Comparison:
    """Model against data for one measured quantity (SI)."""

    quantity: str
    x_name: str
    x: np.ndarray
    data: np.ndarray
    model: np.ndarray
    error_name: str
    error_percent: float
    rmse: float
    unit: str

    def to_json(self) -> dict:
        return {"quantity": self.quantity, "against": self.x_name,
                self.error_name: self.error_percent, "error_percent": self.error_percent,
                "rmse": self.rmse, "units": self.unit, "n_points": int(self.x.size)}


def design_from_config(path) -> dict:
    """The design and material sets of a config with a ``design:`` section (SI).

    Raises
    ------
    InputError
        No ``design`` section, or a field out of its range; the message names the field.
    """
    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    if not isinstance(raw, dict) or not isinstance(raw.get("design"), dict):
        raise InputError(f"{path}: needs a 'design:' section (radius, wall_thickness, length, "
                         "base_thickness), as configs/control.yaml has")
    try:
        sil = silicone_parameters(raw.get("silicone", "tc5005"))
        ny = nylon_parameters(raw.get("nylon", "silver_nylon66"))
    except InputError:
        raise
    except ValueError as exc:
        raise InputError(str(exc)) from None
    d = raw["design"]
    out = {"silicone": sil, "nylon": ny}
    for key in ("radius", "wall_thickness", "length"):
        if key not in d:
            raise InputError(f"design.{key}: missing key")
        kind, unit, lo, hi, _ = DESIGN_RANGES[key]
        v = parse_quantity(d[key], f"design.{key}", kind, unit)
        if not lo <= v <= hi:
            raise InputError(f"design.{key}: out of range [{lo:g}, {hi:g}] m")
        out[key] = v
    b = d.get("base_thickness", "wall")
    out["base_thickness"] = None if b == "wall" else parse_quantity(
        b, "design.base_thickness", "length", "mm")
    return out


def validate_design(config, data) -> list[Comparison]:
    """Compare the model of a config's design with measurements.

    Parameters
    ----------
    config : str, Path or dict
        A config file with a ``design`` section, or :func:`design_from_config`'s dict.
    data : str, Path or Table
        Measurements (see the module docstring).

    Returns
    -------
    list of Comparison
        One per measured quantity found.

    Raises
    ------
    InputError
        No known pair of columns, or values outside the model's range.
    """
    design = config if isinstance(config, dict) else design_from_config(config)
    table = data if isinstance(data, Table) else read_table(data)
    a, t, L, b = (design[k] for k in ("radius", "wall_thickness", "length", "base_thickness"))
    found = []
    if table.has("pressure"):  # the model's range (docs/model.md s. 3): 1e300 kPa gave inf
        _, p = column(table, ["pressure"], "pressure", "pressure")
        _check_range(table.path, "pressure", p, 0.0, _PRESSURE_MAX, closed=True)
    if table.has("stroke", "pressure"):
        _, s = column(table, ["stroke"], "stroke", "dimensionless")
        _, p = column(table, ["pressure"], "pressure", "pressure")
        _check_range(table.path, "stroke", s, 0.0, 1.0)
        found.append(("pressure", s, p, np.asarray(chamber_pressure(s), float)))
    for q in ("bend_angle", "tip_force"):
        if table.has("pressure", q):
            _, p = column(table, ["pressure"], "pressure", "pressure")
            _, y = column(table, [q], q, "angle" if q == "bend_angle" else "force")
            _check_range(table.path, "pressure", p, 0.0, np.inf)
            if q == "bend_angle":
                m = bend_angle(p, a, t, L, b, silicone=design["silicone"])
            else:
                m = tip_force(p, a, L, t if b is None else b)  # b = t: 'wall'
            found.append((q, p, y, np.asarray(m, float)))
    if not found:
        raise InputError(f"{table.path}: needs columns stroke and pressure, pressure and "
                         "bend_angle, or pressure and tip_force (with units)")
    out = []
    for q, x, y, m in found:
        x_name, err_name, unit = CHECKS[q]
        scale = float(np.max(np.abs(y)))
        if not scale > 0:
            raise InputError(f"{table.path}: the measured {q} is zero everywhere")
        err = 100.0 * float(np.max(np.abs(m - y))) / scale
        rmse = float(np.sqrt(np.mean((m - y) ** 2)))
        out.append(Comparison(q, x_name, x, y, m, err_name, err, rmse, unit))
    return out


def _check_range(path, name, v, lo, hi, closed=False):
    bad = ~np.isfinite(v) | (v < lo) | ((v > hi) if closed else (v >= hi))
    if np.any(bad):
        if name == "pressure":
            raise InputError(f"{path}: column 'pressure' must be in [{lo / 1e3:g}, "
                             f"{hi / 1e3:g}] kPa (the model's range), got "
                             f"{v[bad][0] / 1e3:g} kPa")
        raise InputError(f"{path}: column {name!r} must be in [{lo:g}, {hi:g}"
                         f"{']' if closed else ')'}")
