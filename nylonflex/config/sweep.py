"""YAML sweep configs: schema, units and ranges, validated before any work.

(The shared machinery is in :mod:`.base`, the ``uncertainty:`` section in
:mod:`.uncertainty`.)

The schema is a set of pydantic models (structure, types, unknown and missing keys);
:func:`resolve` then turns the typed config into SI arrays and checks every range. Every
error is an :class:`~nylonflex.units.InputError` of one line that names the field (as a
dotted path) and what it accepts.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
import yaml
from pydantic import BeforeValidator, Field, ValidationError, field_validator, model_validator

from ..materials import Cooling, Nylon, Silicone, nylon_parameters, silicone_parameters
from ..conditions import parse_requirements
from ..files.material_files import anchor_material_files, read_chamber_file
from ..files.safe_yaml import YAML_MAX_DEPTH, load_yaml, read_yaml
from ..units import (InputError, bare_number, decimal_to_si, from_si, parse_decimal,
                     plainly_degrees, short, to_si)
from ..variables import CURVES, DESIGN, INPUTS, MODELS, VARIABLES
from .charts import CHART_REGISTRY
from .base import (
    Count,
    Number,
    _no_bool,
    _pydantic_message,
    _Strict,
    check_range,
    check_run_name,
    range_error,
    resolve_cooling,
)
from .tracking import Tracking, TrackingSpec, resolve_tracking
from .uncertainty import Uncertainty, UncertaintySpec, resolve_uncertainty

__all__ = ["CHARTS", "LIMITS", "SweepConfig", "apply_overrides", "check_range", "cube_bytes",
           "load_config", "load_yaml", "parse_config", "range_error"]

#: Figures a sweep config may name under ``charts`` (the chart registry's names).
CHARTS = tuple(CHART_REGISTRY)



#: Default budget of one sweep (config key ``limits``): designs in the grid, and gigabytes
#: of the cube before compression. Checked before any file is created.
LIMITS = {"designs": 1_000_000_000, "gigabytes": 200.0}

#: quantity -> (kind, default unit, accepted SI range lo, hi, display unit for messages),
#: read off the registry (nylonflex.variables), for sweeps and simulations alike; the coil
#: index's range is the muscle table's
DESIGN_RANGES = {
    name: (v.kind, v.display, v.lo, v.hi, v.display)
    for name, v in {**VARIABLES, **INPUTS}.items()
    if name in ("radius", "wall_thickness", "length", "coil_index", "wrap_angle", "stroke",
                "pressure", "base_thickness")
}
_MAX_POINTS = 100_000
#: Most cooling sets of one sweep (``cooling:`` a list; 10,000 once ran past 90 s before
#: its first slab).
MAX_COOLING_SETS = 64
#: Neighbouring values of an axis lie at least this fraction of its accepted range apart
#: (0.1 Pa of pressure, 0.2 um of radius): ``stop: 1e-308 kPa`` is no curve.
AXIS_RESOLUTION = 1e-6


class Axis(_Strict):
    """One grid axis: ``start``/``stop``/``num`` (linear) or ``values``, with ``units``."""

    start: Number | None = None
    stop: Number | None = None
    num: Count | None = None
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


class Supply(_Strict):
    """A steady supply across the muscle: ``voltage`` with ``units`` (V by default)."""

    voltage: Number
    units: str | None = "V"


class Limits(_Strict):
    """The budget of one sweep: at most ``designs`` designs and a cube of ``gigabytes``."""

    designs: Annotated[float, BeforeValidator(_no_bool)] = LIMITS["designs"]
    gigabytes: Annotated[float, BeforeValidator(_no_bool)] = LIMITS["gigabytes"]


class Spread(_Strict):
    """``fidelity: {spread: [variant, ...]}``: the model variants whose range the cube
    stores beside each headline value (docs/model.md s. 23)."""

    # checked by _spread (one line naming the entry); the schema lists the variants
    spread: list[str] = Field(json_schema_extra={"items": {"enum": list(MODELS)},
                                                 "minItems": 2, "uniqueItems": True})


class ChamberFile(_Strict):
    """``chamber: {file: fits/chamber.yaml}``: a ``nylonflex fit chamber`` file
    (``sealed_chamber``, docs/bench.md)."""

    file: str


class SweepConfig(_Strict):
    """The sweep config of docs/interface.md, as typed (not yet resolved to SI)."""

    name: str
    silicone: Union[str, dict[str, Any]] = "tc5005"
    nylon: Union[str, dict[str, Any]] = "silver_nylon66"
    grid: Grid
    base_thickness: Union[Literal["wall"], FixedThickness] = "wall"
    curves: Curves
    charts: list[Literal[CHARTS]] = []  # type: ignore[valid-type]
    slab_megabytes: Annotated[float, BeforeValidator(_no_bool)] = 16.0
    limits: Limits = Limits()
    compression: Literal["gzip", "zstd", "lz4", "none"] = "gzip"
    uncertainty: Uncertainty | None = None
    requirements: list[str] = []
    model: Union[str, list[str]] = "paper"
    supply: Supply | None = None
    tracking: Tracking | None = None
    cooling: Union[str, dict[str, Any], list[Union[str, dict[str, Any]]], None] = None
    # "spread": the range over every variant (or over model's list); {spread: [...]}: over
    # those (docs/model.md s. 23)
    fidelity: Union[Literal["spread"], Spread, None] = None
    chamber: ChamberFile | None = None

    _name = field_validator("name")(classmethod(lambda cls, name: check_run_name(name)))

    @field_validator("fidelity", mode="before")
    @classmethod
    def _fidelity_form(cls, value):
        """One line for a fidelity of neither form (a union's first branch would name only
        ``'spread'``)."""
        if isinstance(value, dict) and set(value) - {"spread"}:
            extra = sorted(str(k) for k in set(value) - {"spread"})[0]
            raise ValueError(f"unknown key {short(extra)}; accepted: spread")
        if value is None or value == "spread" or (
                isinstance(value, dict) and isinstance(value.get("spread"), list)):
            return value
        raise ValueError("must be 'spread' or {spread: [variant, ...]} with at least two of "
                         f"{', '.join(MODELS)}")


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
    compression: str = "gzip"  # the cube's codec: not part of the design space or its hash
    uncertainty: "UncertaintySpec | None" = None
    requirements: tuple[str, ...] = ()
    models: tuple[str, ...] = ("paper",)
    supply_voltage: float | None = None
    tracking: "TrackingSpec | None" = None
    cooling: Cooling | None = None  # None: the nylon set's own heat loss (docs/model.md s. 9)
    # several cooling sets: the cube's string ``cooling`` dimension (then ``cooling`` is None)
    coolings: tuple[Cooling, ...] = ()
    # ``fidelity: spread``: the model variants the cube's <var>_model_lo/_hi range over;
    # () without a spread (docs/model.md s. 23)
    spread: tuple[str, ...] = ()
    # a chamber file's measured values (``sealed_chamber``; docs/bench.md), SI, with the
    # file's path: the kernels' coefficients are anchored on them (engine.model_slab)
    chamber: dict | None = None

    @property
    def cooling_names(self) -> tuple[str, ...]:
        """The labels of the cube's ``cooling`` coordinate; () for one cooling set or none."""
        return tuple(c.label for c in self.coolings)

    def with_cooling(self, cooling: Cooling | None) -> "ResolvedConfig":
        """This config under one cooling set (a slice of a cube of several)."""
        return dataclasses.replace(self, cooling=cooling, coolings=())

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def n_designs(self) -> int:
        return int(np.prod(self.shape))

    # made once: a sweep asks for the hash about eight times, and the YAML dump costs 7 ms
    # (the config is frozen, its arrays are never written)
    @cached_property
    def text(self) -> str:
        return canonical_yaml(self)

    @cached_property
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
    if cfg.uncertainty is not None:  # only then: plain sweeps keep their hash
        doc["uncertainty"] = cfg.uncertainty.to_dict()
    if cfg.requirements:
        doc["requirements"] = list(cfg.requirements)
    # only when asked for: the default config hashes as it always did
    if cfg.models != ("paper",):
        doc["model"] = list(cfg.models)
    if cfg.supply_voltage is not None:
        doc["supply_voltage"] = cfg.supply_voltage
    if cfg.tracking is not None:  # only then: cubes without tracking keep their hash
        doc["tracking"] = cfg.tracking.to_dict()
    if cfg.cooling is not None:
        doc["cooling"] = cfg.cooling.to_dict()
    if cfg.coolings:
        doc["cooling"] = [c.to_dict() for c in cfg.coolings]
    if cfg.spread:  # only then: cubes without a model spread keep their hash
        doc["fidelity"] = {"spread": list(cfg.spread)}
    if cfg.chamber is not None:  # only then: other cubes keep their hash
        doc["chamber"] = dict(cfg.chamber)
    return yaml.safe_dump(doc, sort_keys=True, default_flow_style=None, width=100)


def _axis_values(name: str, axis: Axis, path: str, nylon: Nylon) -> np.ndarray:
    kind, unit, lo, hi, shown = DESIGN_RANGES[name]
    units = axis.units or unit
    to_si(1.0, units, f"{path}.units", kind)
    if name == "coil_index":
        lo, hi = nylon.coil_index_range

    # a bare angle is degrees when the axis says so, or when one of its values is plainly
    # degrees (beyond the largest angle, read as radians): [5, 8, 12] (units.plainly_degrees)
    typed = axis.values if axis.values is not None else (axis.start, axis.stop)
    stated = axis.units is not None or (kind == "angle" and any(
        (b := bare_number(t)) is not None and b != 0.0 and plainly_degrees(b, hi)
        for t in typed))

    def value(text, field):
        return check_range(text, field, kind, units, lo, hi, shown, slack=1e-12,
                           unit_stated=stated)

    if axis.values is not None:
        if len(axis.values) == 0:
            raise InputError(f"{path}.values: needs at least one value")
        if len(axis.values) > _MAX_POINTS:
            raise InputError(f"{path}.values: at most {_MAX_POINTS:,} values, got "
                             f"{len(axis.values):,}")
        vals = np.array([value(v, f"{path}.values[{i}]") for i, v in enumerate(axis.values)])
    else:
        if not 1 <= axis.num <= _MAX_POINTS:
            raise range_error(f"{path}.num", 1, _MAX_POINTS, "1", axis.num)
        start, stop = value(axis.start, f"{path}.start"), value(axis.stop, f"{path}.stop")
        vals = _decimal_linspace(axis, units, kind, path, start, stop)
    if len(vals) > 1 and np.any(np.diff(vals) <= 0):
        raise InputError(f"{path}: values must be strictly increasing")
    if len(vals) > 1 and lo is not None and hi is not None and \
            np.min(np.diff(vals)) < AXIS_RESOLUTION * (hi - lo):
        least = from_si(AXIS_RESOLUTION * (hi - lo), shown)
        raise InputError(f"{path}: neighbouring values must be at least {least:.3g} "
                         f"{shown} apart (a millionth of the accepted range)")
    return vals


def _decimal_linspace(axis: Axis, units: str, kind: str, path: str, start: float,
                      stop: float) -> np.ndarray:
    """The points of a ``start``/``stop``/``num`` axis, SI: each the float nearest its
    decimal value (``{start: 5, stop: 25, num: 41, units: mm}`` gives exactly the floats
    0.005, 0.0055, ..., 0.0105, ..., as typed; ``np.linspace`` in SI gave
    0.010499999999999999), so ``ds.sel(radius=10.5e-3)`` finds the grid point.

    ``start`` and ``stop`` [SI] are the checked (and clamped) ends; a start and stop typed
    in different units fall back to ``np.linspace`` between them.
    """
    if axis.num == 1:
        return np.array([start])
    (a, ua), (b, ub) = (parse_decimal(x, f"{path}.{k}", kind, units)
                        for k, x in (("start", axis.start), ("stop", axis.stop)))
    if ua != ub:
        return np.linspace(start, stop, axis.num)
    step = (b - a) / (axis.num - 1)
    vals = np.array([decimal_to_si(a + step * i, ua) for i in range(axis.num)])
    vals[0], vals[-1] = start, stop
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
        raise InputError(_pydantic_message(err, SweepConfig)) from None
    if not 1.0 <= cfg.slab_megabytes <= 4096.0:
        raise range_error("slab_megabytes", 1.0, 4096.0, "1", cfg.slab_megabytes)
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
    _check_budget(cfg.limits, axes, curves)
    if cfg.base_thickness == "wall":
        base = None
    else:
        kind, _, lo, hi, shown = DESIGN_RANGES["base_thickness"]
        base = check_range(cfg.base_thickness.value, "base_thickness.value", kind,
                           cfg.base_thickness.units or "mm", lo, hi, shown)
    requirements = tuple(r.text for r in parse_requirements(cfg.requirements))
    if (cfg.uncertainty is not None or requirements) and not isinstance(cfg.model, str) \
            and len(cfg.model) > 1:
        raise InputError("model: a sweep with uncertainty or requirements takes one model; "
                         "sweep each variant on its own")
    uncertainty = None if cfg.uncertainty is None else \
        resolve_uncertainty(cfg.uncertainty, silicone, nylon, raw)
    models, voltage = _models(cfg.model), _supply(cfg.supply)
    tracking = None if cfg.tracking is None else \
        resolve_tracking(cfg.tracking, voltage, models, nylon.t_amb, nylon.t_max)
    coolings = _coolings(cfg.cooling, nylon)
    if len(coolings) > 1 and (uncertainty is not None or requirements or
                              tracking is not None):
        raise InputError("cooling: a sweep with uncertainty, requirements or tracking takes "
                         "one cooling set; sweep each set on its own")
    chamber = None
    if cfg.chamber is not None:
        if "sealed_chamber" not in models:
            raise InputError("chamber: applies to model sealed_chamber only; add it to model: "
                             f"(got {', '.join(models)})")
        try:
            chamber = {**read_chamber_file(cfg.chamber.file), "file": cfg.chamber.file}
        except InputError as err:
            raise InputError(f"chamber.file: {err}") from None
    return ResolvedConfig(name=cfg.name, axes=axes, curves=curves, base_thickness=base,
                          silicone=silicone, nylon=nylon, charts=tuple(cfg.charts),
                          slab_megabytes=cfg.slab_megabytes, compression=cfg.compression,
                          raw=copy.deepcopy(raw), uncertainty=uncertainty,
                          requirements=requirements, models=models,
                          supply_voltage=voltage, tracking=tracking,
                          cooling=coolings[0] if len(coolings) == 1 else None,
                          coolings=coolings if len(coolings) > 1 else (),
                          spread=_spread(cfg.fidelity, models), chamber=chamber)


def _coolings(cooling, nylon: Nylon) -> tuple[Cooling, ...]:
    """The cooling sets of a config's ``cooling``: () without one, one set, or a list of
    sets (a sweep axis), each named by a label of its own."""
    if not isinstance(cooling, list):
        env = resolve_cooling(cooling, nylon)
        return () if env is None else (env,)
    if not cooling:
        raise InputError("cooling: needs at least one cooling set, got []")
    if len(cooling) > MAX_COOLING_SETS:  # each set is a slice of the cube: a sweep each
        raise InputError(f"cooling: at most {MAX_COOLING_SETS} cooling sets, got "
                         f"{len(cooling):,}")
    out = []
    for i, item in enumerate(cooling):
        env = resolve_cooling(item, nylon, f"cooling[{i}]")
        if env is None:
            raise InputError(f"cooling[{i}]: must be a cooling set, got null")
        labels = [c.label for c in out]
        if env.label in labels:
            raise InputError(f"cooling[{i}]: the same set as cooling[{labels.index(env.label)}] "
                             f"({env.label}); give each set once")
        out.append(env)
    return tuple(out)


def _models(model) -> tuple[str, ...]:
    """The model variants of a config's ``model`` (one name or a list), checked."""
    names = [model] if isinstance(model, str) else list(model)
    if not names:
        raise InputError(f"model: needs at least one of {', '.join(MODELS)}")
    for i, name in enumerate(names):
        field_name = "model" if isinstance(model, str) else f"model[{i}]"
        if name not in MODELS:
            raise InputError(f"{field_name}: must be one of {', '.join(MODELS)}, got {name!r}")
    if len(set(names)) != len(names):
        raise InputError(f"model: each variant once, got {', '.join(names)}")
    return tuple(names)


def _spread(fidelity, models: tuple[str, ...]) -> tuple[str, ...]:
    """The model variants of a config's ``fidelity`` spread, checked: () without one;
    ``"spread"``: the config's ``model`` list, or every variant when it names one; a list:
    those, at least two, each once, holding every variant of ``model`` (the band is around
    the cube's own values)."""
    if fidelity is None:
        return ()
    if fidelity == "spread":
        return tuple(models) if len(models) > 1 else tuple(MODELS)
    names = list(fidelity.spread)
    for i, name in enumerate(names):
        if name not in MODELS:
            raise InputError(f"fidelity.spread[{i}]: must be one of {', '.join(MODELS)}, "
                             f"got {name!r}")
    if len(set(names)) != len(names):
        raise InputError(f"fidelity.spread: each variant once, got {', '.join(names)}")
    if len(names) < 2:
        raise InputError(f"fidelity.spread: needs at least two model variants (of "
                         f"{', '.join(MODELS)}), got {len(names)}; a spread of one model "
                         "is its value")
    missing = [m for m in models if m not in names]
    if missing:
        raise InputError(f"fidelity.spread: must hold the cube's model {missing[0]!r} "
                         f"(model:), the value the band is around; got {', '.join(names)}")
    return tuple(names)


def _supply(supply) -> float | None:
    """The supply voltage [V] of a config's ``supply``, or None."""
    if supply is None:
        return None
    v = INPUTS["supply_voltage"]
    return check_range(supply.voltage, "supply.voltage", v.kind, supply.units or "V", v.lo,
                       v.hi, "V", lo_open=v.lo_open)


def cube_bytes(axes: dict, curves: dict) -> int:
    """Bytes of a cube's variables before compression, from the registry's dims and dtypes."""
    sizes = {k: len(v) for k, v in {**axes, **curves}.items()}
    return sum(int(np.prod([sizes[d] for d in v.dims], dtype=float)) *
               np.dtype(v.dtype).itemsize for v in (*DESIGN.values(), *CURVES.values()))


def _check_budget(limits: Limits, axes: dict, curves: dict):
    """Refuse a design space over the budget, before anything is computed or written."""
    for key in ("designs", "gigabytes"):
        value = getattr(limits, key)
        if not (math.isfinite(value) and value > 0):
            raise range_error(f"limits.{key}", 0, None, "1", value, lo_open=True)
    n = math.prod(len(v) for v in axes.values())
    size = cube_bytes(axes, curves) / 1e9
    if n > limits.designs or size > limits.gigabytes:
        raise InputError(
            f"grid: {n:,} designs, a cube of {size:,.3g} GB before compression, is over the "
            f"budget of {limits.designs:,.0f} designs and {limits.gigabytes:g} GB; shrink the "
            "grid, or raise the budget with the config key 'limits: {designs: N, gigabytes: "
            "G}' (or --set limits.designs=N --set limits.gigabytes=G)")


def apply_overrides(raw: dict, overrides) -> dict:
    """Apply ``KEY=VALUE`` strings (dotted keys, YAML values) to a copy of ``raw``."""
    out = copy.deepcopy(raw)
    for item in overrides or ():
        key, sep, value = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"--set {short(item)}: expected KEY=VALUE, e.g. "
                             "grid.radius.num=81")
        parts = key.strip().split(".")
        if len(parts) > YAML_MAX_DEPTH:
            raise InputError(f"--set {short(key)}: nested deeper than {YAML_MAX_DEPTH} levels")
        node = out
        for i, part in enumerate(parts[:-1]):
            nxt = node.get(part) if isinstance(node, dict) else None
            if nxt is None:
                nxt = node[part] = {}
            if i == 0 and part in ("silicone", "nylon") and isinstance(nxt, str):
                # a named set: a field override keeps it ({set: tc5005, mu: [...]})
                nxt = node[part] = {"set": nxt}
            if not isinstance(nxt, dict):
                where = '.'.join(parts[:i + 1])
                raise InputError(f"--set {short(key)}: {short(where)} is {short(nxt)}, not a "
                                 f"mapping with fields; set it whole instead, e.g. --set "
                                 f"{short(where)}=VALUE")
            node = nxt
        try:
            parsed = load_yaml(value, f"--set {short(key)}")
        except InputError as err:
            if "not valid YAML" not in str(err):
                raise
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


def load_config(path, overrides=()) -> ResolvedConfig:
    """Read, override (``KEY=VALUE`` strings) and validate a sweep config file."""
    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    return parse_config(apply_overrides(raw, overrides), str(path))
