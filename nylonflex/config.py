"""YAML sweep configs: schema, units and ranges, validated before any work.

The schema is a set of pydantic models (structure, types, unknown and missing keys);
:func:`resolve` then turns the typed config into SI arrays and checks every range. Every
error is an :class:`~nylonflex.units.InputError` of one line that names the field (as a
dotted path) and what it accepts.
"""

from __future__ import annotations

import copy
import math
import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Union, get_args, get_origin

import numpy as np
import yaml
from pydantic import BaseModel, BeforeValidator, ConfigDict, Tag, ValidationError, \
    field_validator, model_validator

from .materials import Nylon, Silicone, nylon_parameters, silicone_parameters
from .requirements import parse_requirements
from .safe_yaml import YAML_MAX_DEPTH, load_yaml, read_yaml
from .units import InputError, from_si, parse_quantity, short, to_si
from .variables import AXES, INPUTS, VARIABLES

__all__ = ["CHARTS", "LIMITS", "SweepConfig", "apply_overrides", "check_range", "cube_bytes",
           "load_config", "load_yaml", "parse_config", "range_error"]

#: Figures a sweep config may name under ``charts``.
CHARTS = ("fig12a", "fig12b", "fig12c", "fig4", "fig6", "fig7", "design_map",
          "feasibility_map", "compare")



def _no_bool(value):
    if isinstance(value, bool):  # YAML's true/false/yes/no are not numbers
        raise ValueError(f"must be a number, got {str(value).lower()}")
    return value


Number = Annotated[Union[float, str], BeforeValidator(_no_bool)]
Count = Annotated[int, BeforeValidator(_no_bool)]

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


class Distribution(_Strict):
    """One uncertain parameter: ``sd`` (with ``units``) or ``rel_sd``, or ``from_fit``."""

    distribution: Literal["normal", "uniform"] = "normal"
    sd: Number | None = None
    rel_sd: float | None = None
    units: str | None = None
    from_fit: bool = False


class Uncertainty(_Strict):
    """The ``uncertainty:`` section (docs/uncertainty.md)."""

    samples: int = 256
    seed: int = 0
    quantiles: list[float] = [0.05, 0.5, 0.95]
    parameters: dict[str, Distribution] = {}


class Supply(_Strict):
    """A steady supply across the muscle: ``voltage`` with ``units`` (V by default)."""

    voltage: Number
    units: str | None = "V"


class Limits(_Strict):
    """The budget of one sweep: at most ``designs`` designs and a cube of ``gigabytes``."""

    designs: Annotated[float, BeforeValidator(_no_bool)] = LIMITS["designs"]
    gigabytes: Annotated[float, BeforeValidator(_no_bool)] = LIMITS["gigabytes"]


class SweepConfig(_Strict):
    """The sweep config of INTERFACE.md, as typed (not yet resolved to SI)."""

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

    _name = field_validator("name")(classmethod(lambda cls, name: check_run_name(name)))


def check_run_name(name):
    """A run name (pydantic validator body): refused unless :func:`valid_name`."""
    if not valid_name(name):
        raise ValueError("letters, digits, '-', '_' and '.' only")
    return name


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
    if cfg.uncertainty is not None:  # only then: plain sweeps keep their hash
        doc["uncertainty"] = cfg.uncertainty.to_dict()
    if cfg.requirements:
        doc["requirements"] = list(cfg.requirements)
    # only when asked for: the default config hashes as it always did
    if cfg.models != ("paper",):
        doc["model"] = list(cfg.models)
    if cfg.supply_voltage is not None:
        doc["supply_voltage"] = cfg.supply_voltage
    return yaml.safe_dump(doc, sort_keys=True, default_flow_style=None, width=100)


def range_error(field: str, lo, hi, display_unit: str, got, lo_open: bool = False,
                hi_open: bool = False) -> InputError:
    """The one-line refusal of a value outside its range, shown in display units.

    Parameters
    ----------
    field : str
        The dotted field, e.g. ``grid.radius.stop``.
    lo, hi : float or int or None
        Accepted range, SI [unit of the quantity]; None: unbounded on that side.
    display_unit : str
        Unit to show the range and the value in (``"1"``: none shown).
    got : float or int
        The refused value, SI [unit of the quantity].
    lo_open, hi_open : bool
        Whether the bound itself is refused.

    Returns
    -------
    InputError
        ``grid.radius.stop: must be in [0.5, 200] mm, got 900 mm``.
    """
    def show(x):
        if isinstance(x, (int, np.integer)) and not isinstance(x, bool):
            return str(int(x))  # counts and seeds: every digit
        return f"{from_si(x, display_unit):g}"

    unit = "" if display_unit in ("1", "", None) else f" {display_unit}"
    if lo is not None and hi is not None:
        rng = f"in {'(' if lo_open else '['}{show(lo)}, {show(hi)}{')' if hi_open else ']'}"
    elif lo is not None:
        rng = f"{'>' if lo_open else '>='} {show(lo)}"
    elif hi is not None:
        rng = f"{'<' if hi_open else '<='} {show(hi)}"
    else:
        return InputError(f"{field}: must be finite, got {show(got)}{unit}")
    return InputError(f"{field}: must be {rng}{unit}, got {show(got)}{unit}")


def check_range(raw, field: str, kind: str, unit: str, lo=None, hi=None,
                display_unit: str | None = None, *, lo_open: bool = False,
                hi_open: bool = False, slack: float = 0.0) -> float:
    """Parse a quantity (``"7.5 mm"`` or a bare number in ``unit``) to SI and check its range.

    Parameters
    ----------
    raw : str or float
        The value as the user typed it [``unit`` when bare].
    field : str
        The dotted field, for messages.
    kind : str
        The quantity's kind (``"length"``, ``"angle"``, ...).
    unit : str
        Unit of a bare number.
    lo, hi : float or None
        Accepted range, SI [unit of the quantity]; None: unbounded on that side.
    display_unit : str or None
        Unit of the message; ``unit`` when None.
    lo_open, hi_open : bool
        Whether the bound itself is refused.
    slack : float
        Tolerance on a closed bound, SI; a value within it is clamped onto the bound.

    Returns
    -------
    float
        The value in SI, within [lo, hi].

    Raises
    ------
    InputError
        Not a number, a unit of another kind, or out of range: one line naming ``field``.
    """
    value = float(parse_quantity(raw, field, kind, unit))
    ok = math.isfinite(value)
    if lo is not None:
        ok = ok and (value > lo if lo_open else value >= lo - slack)
    if hi is not None:
        ok = ok and (value < hi if hi_open else value <= hi + slack)
    if not ok:
        raise range_error(field, lo, hi, display_unit or unit, value, lo_open, hi_open)
    if lo is not None and not lo_open:
        value = max(value, lo)
    if hi is not None and not hi_open:
        value = min(value, hi)
    return value


def _strip(tp):
    """A type without its Annotated metadata and without None in a union."""
    while get_origin(tp) is Annotated:
        tp = get_args(tp)[0]
    if get_origin(tp) in (Union, type(int | None)):
        args = [a for a in get_args(tp) if a is not type(None)]
        if len(args) == 1:
            return _strip(args[0])
    return tp


def _union_member(tp, tag):
    """The member of a union that pydantic's location ``tag`` names, or None."""
    for member in get_args(tp):
        meta = get_args(member)[1:] if get_origin(member) is Annotated else ()
        base = _strip(member)
        tags = {m.tag for m in meta if isinstance(m, Tag)}
        if isinstance(base, type) and issubclass(base, BaseModel):
            tags.add(base.__name__)
            kind = base.model_fields.get("kind")
            if kind is not None and get_origin(kind.annotation) is Literal:
                tags.update(get_args(kind.annotation))
        if tag in tags:
            return base
    return None


def _walk(model, loc):
    """The dotted path (``actuators[0].design.radius``) of a pydantic location, and the
    type it ends at (None when unknown); union members' tags are not part of the path."""
    path, tp = "", model
    for part in loc:
        tp = _strip(tp)
        if get_origin(tp) in (Union, type(int | None)):
            tp = _union_member(tp, part)  # a union's tag: not a key the user typed
            continue
        if isinstance(part, int):
            path += f"[{part}]"
            args = get_args(tp)
            tp = args[0] if get_origin(tp) in (list, tuple) and args else None
            continue
        path += f".{part}" if path else str(part)
        if isinstance(tp, type) and issubclass(tp, BaseModel) and part in tp.model_fields:
            tp = tp.model_fields[part].annotation
        elif get_origin(tp) is dict:
            tp = get_args(tp)[1]
        else:
            tp = None
    return path, _strip(tp) if tp is not None else None


_TYPE_MESSAGES = {
    "model_type": "must be a mapping of keys",
    "model_attributes_type": "must be a mapping of keys",
    "dict_type": "must be a mapping of keys",
    "list_type": "must be a list",
    "int_type": "must be an integer",
    "int_from_float": "must be an integer",
    "string_type": "must be a string",
}


def _pydantic_message(err: ValidationError, model: type[BaseModel]) -> str:
    """One line for the first error of a validation against ``model``: the dotted field and
    what it accepts."""
    e = err.errors()[0]
    path, tp = _walk(model, e["loc"])
    msg = e["msg"].removeprefix("Value error, ")
    got = e.get("input")
    tail = "" if isinstance(got, dict) else f", got {short(got)}"
    kind = e["type"]
    if kind == "extra_forbidden":
        parent = _walk(model, e["loc"][:-1])[1]
        keys = sorted(parent.model_fields) if isinstance(parent, type) and \
            issubclass(parent, BaseModel) else []
        msg, tail = "unknown key" + (f"; accepted: {', '.join(keys)}" if keys else ""), ""
    elif kind == "missing":
        msg, tail = "missing key", ""
    elif kind == "literal_error":
        msg = msg.replace("Input should be", "must be one of")
    elif kind in ("union_tag_invalid", "union_tag_not_found"):
        key = e["ctx"]["discriminator"].strip("'")
        path = f"{path}.{key}" if path else key
        tags = [t for m in get_args(tp) for t in get_args(_strip(m).model_fields[key].annotation)]
        msg = f"must be one of {', '.join(tags)}"
        tail = f", got {short(e['ctx']['tag'])}" if kind == "union_tag_invalid" else ""
        msg = msg if tail else f"missing key; accepted: {', '.join(tags)}"
    else:
        msg = _TYPE_MESSAGES.get(kind, msg)
    return f"{path or 'config'}: {msg}{tail}"


def _axis_values(name: str, axis: Axis, path: str, nylon: Nylon) -> np.ndarray:
    kind, unit, lo, hi, shown = DESIGN_RANGES[name]
    units = axis.units or unit
    to_si(1.0, units, f"{path}.units", kind)
    if name == "coil_index":
        lo, hi = nylon.coil_index_range

    def value(text, field):
        return check_range(text, field, kind, units, lo, hi, shown, slack=1e-12)

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
        _uncertainty(cfg.uncertainty, silicone, nylon, raw)
    return ResolvedConfig(name=cfg.name, axes=axes, curves=curves, base_thickness=base,
                          silicone=silicone, nylon=nylon, charts=tuple(cfg.charts),
                          slab_megabytes=cfg.slab_megabytes, compression=cfg.compression,
                          raw=copy.deepcopy(raw), uncertainty=uncertainty,
                          requirements=requirements, models=_models(cfg.model),
                          supply_voltage=_supply(cfg.supply))


def _models(model) -> tuple[str, ...]:
    """The model variants of a config's ``model`` (one name or a list), checked."""
    from .variables import MODELS

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


def _supply(supply) -> float | None:
    """The supply voltage [V] of a config's ``supply``, or None."""
    if supply is None:
        return None
    v = INPUTS["supply_voltage"]
    return check_range(supply.voltage, "supply.voltage", v.kind, supply.units or "V", v.lo,
                       v.hi, "V", lo_open=v.lo_open)


# --------------------------------------------------------------------------- uncertainty

_MAX_SAMPLES = 65536
#: Aliases of material table fields in ``uncertainty.parameters``.
_FIELD_ALIASES = {"stroke_max": "stroke_max_table", "tensile_strength": "tensile_strength_table",
                  "coil_index": "coil_index_table"}


@dataclass(frozen=True)
class UncertainParameter:
    """One uncertain input, resolved: what it perturbs and by how much (SI).

    ``target`` is an axis name (``wall_thickness``) or ``silicone.mu`` /
    ``nylon.stroke_max_table`` (a material field; a table or the Ogden terms move together
    by one standard variable). With ``from_fit``, ``target`` is ``silicone`` or ``nylon``,
    ``fields`` names each dimension (``mu_1``) and ``covariance`` is theirs, SI.
    """

    name: str
    target: str
    distribution: str
    sd: float | None = None
    rel_sd: float | None = None
    fields: tuple[str, ...] = ()
    covariance: tuple[tuple[float, ...], ...] = ()

    @property
    def dims(self) -> int:
        """Standard variables this parameter takes (1, or the fit's parameter count)."""
        return len(self.fields) if self.fields else 1

    def to_dict(self) -> dict:
        d = {"target": self.target, "distribution": self.distribution}
        if self.sd is not None:
            d["sd"] = float(self.sd)
        if self.rel_sd is not None:
            d["rel_sd"] = float(self.rel_sd)
        if self.fields:
            d.update(fields=list(self.fields),
                     covariance=[[float(x) for x in row] for row in self.covariance])
        return d


@dataclass(frozen=True)
class UncertaintySpec:
    """The resolved ``uncertainty:`` section: scrambled Sobol' samples of the parameters."""

    samples: int
    seed: int
    quantiles: tuple[float, ...]
    parameters: tuple[UncertainParameter, ...]

    def to_dict(self) -> dict:
        return {"samples": self.samples, "seed": self.seed,
                "quantiles": [float(q) for q in self.quantiles],
                "parameters": {p.name: p.to_dict() for p in self.parameters}}


def _material_numeric(kind, material) -> dict:
    return {k: v for k, v in material.to_dict().items()
            if k != "name" and isinstance(v, (int, float, list, tuple))}


def _fit_parameter(name, dist, path, raw_material, material):
    from .material_files import read_material_file

    if not (isinstance(raw_material, dict) and isinstance(raw_material.get("file"), str)):
        raise InputError(f"{path}.from_fit: {name} must come from a fitted material file "
                         f"({name}: {{file: fits/....yaml}})")
    doc = read_material_file(raw_material["file"])
    order, cov = doc.get("parameter_order"), doc.get("covariance")
    try:
        cov = np.asarray(cov, dtype=float)
    except (TypeError, ValueError):
        cov = None
    if not isinstance(order, list) or cov is None or cov.shape != (len(order), len(order)):
        raise InputError(f"{path}.from_fit: {raw_material['file']} has no 'covariance' of "
                         "its 'parameter_order'")
    numeric = _material_numeric(name, material)
    for p in order:
        field_name, _, idx = str(p).rpartition("_")
        ok = (field_name in numeric and idx.isdigit() and isinstance(numeric[field_name], list)
              and 1 <= int(idx) <= len(numeric[field_name])) or \
            (p in numeric and not isinstance(numeric[p], list))
        if not ok:
            raise InputError(f"{path}.from_fit: the fitted parameter {p!r} of "
                             f"{raw_material['file']} is not a field of the {name} set")
    if not np.allclose(cov, cov.T) or np.any(np.linalg.eigvalsh(cov) < -1e-12 *
                                             np.abs(cov).max()):
        raise InputError(f"{path}.from_fit: the covariance of {raw_material['file']} is not "
                         "symmetric positive semi-definite")
    if dist.distribution != "normal" or dist.sd is not None or dist.rel_sd is not None:
        raise InputError(f"{path}: from_fit takes the fit's multivariate normal; give no "
                         "sd, rel_sd or distribution")
    return UncertainParameter(name, name, "normal", fields=tuple(str(p) for p in order),
                              covariance=tuple(tuple(float(x) for x in row) for row in cov))


def _uncertainty(unc: Uncertainty, silicone, nylon, raw) -> UncertaintySpec:
    """Resolve the ``uncertainty:`` section; InputError naming the field otherwise."""
    if not 2 <= unc.samples <= _MAX_SAMPLES:
        raise range_error("uncertainty.samples", 2, _MAX_SAMPLES, "1", unc.samples)
    if not 0 <= unc.seed < 2**32:
        raise range_error("uncertainty.seed", 0, 2**32 - 1, "1", unc.seed)
    if not unc.quantiles or any(not 0 < q < 1 for q in unc.quantiles) or \
            np.any(np.diff(unc.quantiles) <= 0):
        raise InputError(f"uncertainty.quantiles: must be increasing probabilities in (0, 1), "
                         f"got {unc.quantiles}")
    params = []
    # sorted by name: the Sobol' column of each parameter, like the config hash (sorted
    # YAML), must not depend on the order the keys were written in
    for name, dist in sorted(unc.parameters.items()):
        path = f"uncertainty.parameters.{name}"
        kind, _, fld = name.partition(".")
        if dist.from_fit:
            if fld or kind not in ("silicone", "nylon"):
                raise InputError(f"{path}.from_fit: only 'silicone' or 'nylon' take a fit's "
                                 "covariance")
            params.append(_fit_parameter(kind, dist, path, raw.get(kind),
                                         silicone if kind == "silicone" else nylon))
            continue
        if (dist.sd is None) == (dist.rel_sd is None):
            raise InputError(f"{path}: give one of sd (with units) or rel_sd")
        if dist.rel_sd is not None and not 0 < dist.rel_sd <= 1:
            raise range_error(f"{path}.rel_sd", 0, 1, "1", dist.rel_sd, lo_open=True)
        if name in AXES:
            target = name
            v = VARIABLES[name]
            sd = None if dist.sd is None else float(parse_quantity(
                dist.sd, f"{path}.sd", v.kind, dist.units or v.display))
        elif kind in ("silicone", "nylon") and fld:
            fld = _FIELD_ALIASES.get(fld, fld) if kind == "nylon" else fld
            numeric = _material_numeric(kind, silicone if kind == "silicone" else nylon)
            if fld not in numeric:
                raise InputError(f"{path}: unknown {kind} field; accepted: "
                                 f"{', '.join(sorted(numeric))}")
            target = f"{kind}.{fld}"
            if dist.units is not None and dist.sd is None:
                raise InputError(f"{path}.units: only with sd")
            sd = None if dist.sd is None else float(parse_quantity(
                dist.sd, f"{path}.sd", "dimensionless", "1") if dist.units is None else
                to_si(float(dist.sd), dist.units, f"{path}.units"))
        else:
            raise InputError(f"{path}: unknown parameter; accepted: {', '.join(AXES)}, "
                             "silicone.FIELD, nylon.FIELD, or silicone/nylon with from_fit")
        if sd is not None and not (math.isfinite(sd) and sd > 0):
            raise InputError(f"{path}.sd: must be > 0, got {dist.sd!r}")
        params.append(UncertainParameter(name, target, dist.distribution, sd=sd,
                                         rel_sd=dist.rel_sd))
    targets = [p.target for p in params]
    for p in params:
        if p.fields and any(t.startswith(p.target + ".") for t in targets):
            raise InputError(f"uncertainty.parameters.{p.name}: from_fit and a field of "
                             f"{p.target} at once; keep one")
    if len(set(targets)) != len(targets):
        raise InputError("uncertainty.parameters: a parameter is given twice")
    return UncertaintySpec(unc.samples, unc.seed, tuple(float(q) for q in unc.quantiles),
                           tuple(params))


def cube_bytes(axes: dict, curves: dict) -> int:
    """Bytes of a cube's variables before compression, from the registry's dims and dtypes."""
    from .variables import CURVES, DESIGN

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
            if not isinstance(nxt, dict):
                raise InputError(f"--set {short(key)}: {short('.'.join(parts[:i + 1]))} is "
                                 "not a mapping")
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
    from .material_files import anchor_material_files

    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    return parse_config(apply_overrides(raw, overrides), str(path))
