"""YAML sweep configs: schema, units and ranges, validated before any work.

The schema is a set of pydantic models (structure, types, unknown and missing keys);
:func:`resolve` then turns the typed config into SI arrays and checks every range. Every
error is an :class:`~nylonflex.units.InputError` of one line that names the field (as a
dotted path) and what it accepts.
"""

from __future__ import annotations

import copy
import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, Union

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, ValidationError, model_validator

from .materials import Nylon, Silicone, nylon_parameters, silicone_parameters
from .units import InputError, from_si, parse_quantity, to_si

__all__ = ["CHARTS", "SweepConfig", "apply_overrides", "load_config", "parse_config"]

#: Figures a sweep config may name under ``charts``.
CHARTS = ("fig12a", "fig12b", "fig12c", "fig4", "fig6", "fig7", "design_map")

Number = Union[float, str]

#: quantity -> (kind, default unit, accepted SI range lo, hi, display unit for messages);
#: the design's plausible range (MODEL.md section 1), for sweeps and simulations alike
DESIGN_RANGES = {
    "radius": ("length", "mm", 0.5e-3, 0.2, "mm"),
    "wall_thickness": ("length", "mm", 0.1e-3, 0.05, "mm"),
    "length": ("length", "mm", 1e-3, 2.0, "mm"),
    "coil_index": ("dimensionless", "1", None, None, "1"),  # the nylon table decides
    "wrap_angle": ("angle", "deg", math.radians(0.1), math.radians(80.0), "deg"),
    "stroke": ("dimensionless", "1", 0.0, 0.5, "1"),
    "pressure": ("pressure", "kPa", 0.0, 100e3, "kPa"),
    "base_thickness": ("length", "mm", 0.1e-3, 0.05, "mm"),
}
_MAX_POINTS = 100_000


def valid_name(name) -> bool:
    """A run name usable as a folder under sweeps/: letters, digits, '-', '_', '.'."""
    return isinstance(name, str) and bool(name) and not name.startswith(".") and \
        all(ch.isalnum() or ch in "-_." for ch in name)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Axis(_Strict):
    """One grid axis: ``start``/``stop``/``num`` (linear) or ``values``, with ``units``."""

    start: Number | None = None
    stop: Number | None = None
    num: int | None = None
    values: list[Number] | None = None
    units: str | None = None

    @model_validator(mode="after")
    def _one_form(self):
        linear = (self.start, self.stop, self.num)
        if self.values is not None and any(x is not None for x in linear):
            raise ValueError("give start/stop/num or values, not both")
        if self.values is None and any(x is None for x in linear):
            raise ValueError("needs start, stop and num, or values")
        return self


class Grid(_Strict):
    radius: Axis
    wall_thickness: Axis
    length: Axis
    coil_index: Axis
    wrap_angle: Axis


class Curves(_Strict):
    stroke: Axis
    pressure: Axis


class FixedThickness(_Strict):
    value: Number
    units: str | None = "mm"


class SweepConfig(_Strict):
    """The sweep config of INTERFACE.md, as typed (not yet resolved to SI)."""

    name: str
    silicone: Union[str, dict[str, Any]] = "tc5005"
    nylon: Union[str, dict[str, Any]] = "silver_nylon66"
    grid: Grid
    base_thickness: Union[Literal["wall"], FixedThickness] = "wall"
    curves: Curves
    charts: list[Literal[CHARTS]] = []  # type: ignore[valid-type]
    slab_megabytes: float = 16.0

    @model_validator(mode="after")
    def _name(self):
        if not valid_name(self.name):
            raise ValueError("name: letters, digits, '-', '_' and '.' only")
        if not 1.0 <= self.slab_megabytes <= 4096.0:
            raise ValueError("slab_megabytes: must be in [1, 4096]")
        return self


@dataclass(frozen=True)
class ResolvedConfig:
    """A validated config in SI: axes as float64 arrays, materials as objects.

    ``text`` is the canonical YAML of everything that determines the cube, and ``sha256``
    its hash: two configs that resolve to the same design space hash the same.
    """

    name: str
    axes: dict[str, np.ndarray]
    curves: dict[str, np.ndarray]
    base_thickness: float | None
    silicone: Silicone
    nylon: Nylon
    charts: tuple[str, ...]
    slab_megabytes: float
    raw: dict = field(compare=False, repr=False)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def n_designs(self) -> int:
        return int(np.prod(self.shape))

    @property
    def text(self) -> str:
        return canonical_yaml(self)

    @property
    def sha256(self) -> str:
        return hashlib.sha256(self.text.encode()).hexdigest()


def canonical_yaml(cfg: ResolvedConfig) -> str:
    """YAML of the resolved config: SI values, materials in full, sorted keys."""
    doc = {
        "name": cfg.name,
        "grid": {k: [float(x) for x in v] for k, v in cfg.axes.items()},
        "curves": {k: [float(x) for x in v] for k, v in cfg.curves.items()},
        "base_thickness": "wall" if cfg.base_thickness is None else cfg.base_thickness,
        "silicone": cfg.silicone.to_dict(),
        "nylon": cfg.nylon.to_dict(),
        "units": "SI (m, rad, Pa; stroke and coil_index dimensionless)",
    }
    return yaml.safe_dump(doc, sort_keys=True, default_flow_style=None, width=100)


def _pydantic_message(err: ValidationError) -> str:
    e = err.errors()[0]
    loc = ".".join(str(x) for x in e["loc"] if not str(x).startswith(("function-after",
                                                                       "literal[", "str")))
    msg = e["msg"].removeprefix("Value error, ")
    if e["type"] == "extra_forbidden":
        msg = "unknown key"
    elif e["type"] == "missing":
        msg = "missing key"
    elif e["type"] == "literal_error":
        msg = msg.replace("Input should be", "must be one of")
    got = e.get("input")
    tail = "" if e["type"] == "missing" or isinstance(got, dict) else f", got {got!r}"
    return f"{loc or 'config'}: {msg}{tail}"


def _axis_values(name: str, axis: Axis, path: str, nylon: Nylon) -> np.ndarray:
    kind, unit, lo, hi, shown = DESIGN_RANGES[name]
    units = axis.units or unit
    to_si(1.0, units, f"{path}.units", kind)
    if name == "coil_index":
        lo, hi = nylon.coil_index_range

    def value(text, field):
        v = parse_quantity(text, field, kind, units)
        if not (np.isfinite(v) and lo - 1e-12 <= v <= hi + 1e-12):
            rng = f"[{from_si(lo, shown):g}, {from_si(hi, shown):g}]"
            unit_txt = "" if shown == "1" else f" {shown}"
            raise InputError(f"{field}: must be in {rng}{unit_txt}, got "
                             f"{from_si(v, shown):g}{unit_txt}")
        return min(max(v, lo), hi)

    if axis.values is not None:
        if len(axis.values) == 0:
            raise InputError(f"{path}.values: needs at least one value")
        vals = np.array([value(v, f"{path}.values[{i}]") for i, v in enumerate(axis.values)])
    else:
        if not 1 <= axis.num <= _MAX_POINTS:
            raise InputError(f"{path}.num: must be in [1, {_MAX_POINTS}], got {axis.num}")
        start, stop = value(axis.start, f"{path}.start"), value(axis.stop, f"{path}.stop")
        vals = np.linspace(start, stop, axis.num) if axis.num > 1 else np.array([start])
    if len(vals) > 1 and np.any(np.diff(vals) <= 0):
        raise InputError(f"{path}: values must be strictly increasing")
    return vals


def parse_config(raw: dict, source: str = "config") -> ResolvedConfig:
    """Validate a config mapping (as read from YAML) and resolve it to SI.

    Raises
    ------
    InputError
        One line: the dotted field, what it accepts, and the bad value.
    """
    if not isinstance(raw, dict):
        raise InputError(f"{source}: must be a YAML mapping of keys (name, grid, curves, ...)")
    try:
        cfg = SweepConfig.model_validate(raw)
    except ValidationError as err:
        raise InputError(_pydantic_message(err)) from None
    try:
        silicone = silicone_parameters(cfg.silicone)
        nylon = nylon_parameters(cfg.nylon)
    except InputError:
        raise
    except ValueError as err:
        raise InputError(str(err)) from None
    axes = {name: _axis_values(name, getattr(cfg.grid, name), f"grid.{name}", nylon)
            for name in Grid.model_fields}
    curves = {name: _axis_values(name, getattr(cfg.curves, name), f"curves.{name}", nylon)
              for name in Curves.model_fields}
    if cfg.base_thickness == "wall":
        base = None
    else:
        units = cfg.base_thickness.units or "mm"
        _, _, lo, hi, _ = DESIGN_RANGES["base_thickness"]
        base = parse_quantity(cfg.base_thickness.value, "base_thickness.value", "length", units)
        if not lo <= base <= hi:
            raise InputError(f"base_thickness.value: must be in [{lo * 1e3:g}, {hi * 1e3:g}] "
                             f"mm, got {base * 1e3:g} mm")
    return ResolvedConfig(name=cfg.name, axes=axes, curves=curves, base_thickness=base,
                          silicone=silicone, nylon=nylon, charts=tuple(cfg.charts),
                          slab_megabytes=cfg.slab_megabytes, raw=copy.deepcopy(raw))


def apply_overrides(raw: dict, overrides) -> dict:
    """Apply ``KEY=VALUE`` strings (dotted keys, YAML values) to a copy of ``raw``."""
    out = copy.deepcopy(raw)
    for item in overrides or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"--set {item!r}: expected KEY=VALUE, e.g. grid.radius.num=81")
        parts = key.strip().split(".")
        node = out
        for i, part in enumerate(parts[:-1]):
            nxt = node.get(part) if isinstance(node, dict) else None
            if nxt is None:
                nxt = node[part] = {}
            if not isinstance(nxt, dict):
                raise InputError(f"--set {key}: {'.'.join(parts[:i + 1])} is not a mapping")
            node = nxt
        try:
            parsed = yaml.safe_load(value)
        except yaml.YAMLError:
            parsed = value
        node[parts[-1]] = parsed
        # switching an axis between forms: drop the other form
        if len(parts) >= 3 and parts[0] in ("grid", "curves"):
            if parts[-1] in ("start", "stop", "num"):
                node.pop("values", None)
            elif parts[-1] == "values":
                for k in ("start", "stop", "num"):
                    node.pop(k, None)
    return out


def read_yaml(path) -> dict:
    """Read a YAML file; a missing file or bad YAML is an InputError naming it."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such config file")
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.YAMLError as err:
        mark = getattr(err, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark else ""
        raise InputError(f"{path}: not valid YAML{where}") from None
    return data


def load_config(path, overrides=()) -> ResolvedConfig:
    """Read, override (``KEY=VALUE`` strings) and validate a sweep config file."""
    from .calibration.files import anchor_material_files

    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    return parse_config(apply_overrides(raw, overrides), str(path))
