"""YAML simulation configs: schema, defaults, units and ranges, validated before any work.

The same machinery as the sweep configs (:mod:`.sweep`): pydantic models (on the
``_Strict`` base of :mod:`.base`) check the structure (keys, nesting, types, the
``actuators:`` list of a gripper), and its ``_pydantic_message`` words their errors;
:func:`parse_sim_config` then merges defaults, top-level sections and each actuator's own
sections key by key, parses units and checks every range with :func:`.base.check_range`.
Every refusal is one :class:`~nylonflex.units.InputError` line naming the dotted field and what
it accepts.

The one physical check, that the supply cannot heat a muscle past a stroke of 0.5, needs
the muscle's length, resistance and steady temperature: those come from the physics layer.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal, Union

import numpy as np
import yaml
from pydantic import (
    AfterValidator,
    BeforeValidator,
    Discriminator,
    Field,
    PlainValidator,
    StrictInt,
    Tag,
    ValidationError,
    field_validator,
)

from ..materials import Cooling, Nylon, Silicone, nylon_parameters, silicone_parameters
from ..physics.nylon import stroke
from ..physics.thermal import cooled_nylon, muscle_resistance, steady_temperature
from ..physics.wrap import muscle_length
from ..units import InputError, bare_number, from_si, plainly_degrees
from .base import _no_bool, _pydantic_message, _Strict, check_range, check_run_name, \
    range_error, resolve_cooling
from ..files.material_files import anchor_material_files
from ..files.safe_yaml import read_yaml
from .sweep import DESIGN_RANGES

__all__ = [
    "DEFAULTS",
    "ActuatorSpec",
    "Reference",
    "SimConfig",
    "SimConfigModel",
    "actuator_muscle_length",
    "load_sim_config",
    "parse_sim_config",
    "top_temperature",
]

#: Largest number of samples times actuators of one run (8 float64 series each).
_MAX_SAMPLES = 20_000_000

#: Most actuators on one supply.
_MAX_ACTUATORS = 64

#: docs/model.md section 10: the default design, supply and timing.
DEFAULTS: dict[str, Any] = {
    "silicone": "tc5005",
    "nylon": "silver_nylon66",
    "design": {"radius": "7.5 mm", "wall_thickness": "2 mm", "length": "70 mm",
               "coil_index": 1.7, "wrap_angle": "8 deg", "base_thickness": "wall"},
    "supply": {"voltage": "12 V", "internal_resistance": "0 ohm"},
    "time": {"duration": "120 s", "step": "10 ms"},
    "sensor": {"noise": "0 kPa", "seed": 0},
    "estimator": {"table_points": 65, "filter_time_constant": "0 s"},
    "controller": {"hysteresis": "0 deg"},
}

# ---------------------------------------------------------------------------------------
# schema: structure and types only; units and ranges are resolved after
# ---------------------------------------------------------------------------------------


def _scalar(value):
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ValueError("expected a number with an optional unit")
    return value


class _ValueUnits(_Strict):
    """``{value: 2, units: mm}``: the long form of a quantity."""

    value: Annotated[Any, PlainValidator(_scalar)]
    units: str | None = None


def _flatten(q):
    if isinstance(q, _ValueUnits):
        return q.value if q.units is None else f"{q.value} {q.units}"
    return q


#: A quantity as typed: ``"7.5 mm"``, a bare number (in the field's unit) or
#: ``{value, units}``; flattened to the first two forms.
Quantity = Annotated[
    Union[Annotated[_ValueUnits, Tag("value_units")],
          Annotated[Any, PlainValidator(_scalar), Tag("scalar")]],
    Discriminator(lambda v: "value_units" if isinstance(v, (dict, _ValueUnits)) else "scalar"),
    AfterValidator(_flatten),
]


class Design(_Strict):
    radius: Quantity = None
    wall_thickness: Quantity = None
    length: Quantity = None
    coil_index: Quantity = None
    wrap_angle: Quantity = None
    base_thickness: Quantity = None  # "wall" (b = t) or a length


class Supply(_Strict):
    voltage: Quantity = None
    internal_resistance: Quantity = None


class Time(_Strict):
    duration: Quantity = None
    step: Quantity = None


class Sensor(_Strict):
    noise: Quantity = None
    seed: StrictInt = None


class Estimator(_Strict):
    table_points: StrictInt = None
    filter_time_constant: Quantity = None


class Controller(_Strict):
    kind: Literal["bang_bang", "pi"] = None
    hysteresis: Quantity = None
    proportional_band: Quantity = None   # PI: the error that drives the duty 0 -> 1
    integral_time: Quantity = None       # PI: T_i


class Metrics(_Strict):
    rms_from: Quantity = None


class SineReference(_Strict):
    kind: Literal["sine"]
    mean: Quantity
    amplitude: Quantity
    frequency: Quantity
    phase: Quantity = 0.0


class StepReference(_Strict):
    kind: Literal["step"]
    initial: Quantity = 0.0
    final: Quantity
    at: Quantity = 0.0


class ScheduleReference(_Strict):
    kind: Literal["schedule"]
    times: list[Quantity]
    angles: list[Quantity]
    interpolation: Literal["hold", "linear"] = "hold"


ReferenceModel = Annotated[Union[SineReference, StepReference, ScheduleReference],
                           Field(discriminator="kind")]

Material = Union[str, dict[str, Any]]


class _Loop(_Strict):
    """What the top level and each actuator may set: materials, design, loop, reference."""

    silicone: Material = None
    nylon: Material = None
    cooling: Material | None = None  # a cooling set (docs/model.md s. 9); None: the set's own
    design: Design | None = None
    initial_temperature: Quantity | None = None
    sensor: Sensor | None = None
    estimator: Estimator | None = None
    controller: Controller | None = None
    reference: ReferenceModel | None = None
    metrics: Metrics | None = None


class ActuatorModel(_Loop):
    """One actuator of a gripper; unset sections and keys come from the top level."""

    name: str | None = None


class SimLimits(_Strict):
    """The budget of one simulation: at most ``samples`` time samples x actuators."""

    samples: Annotated[float, BeforeValidator(_no_bool)] = _MAX_SAMPLES


class SimConfigModel(_Loop):
    """The simulation config (``configs/control.yaml``), as typed (not yet in SI)."""

    name: str
    description: Any = None
    supply: Supply | None = None
    time: Time | None = None
    actuators: list[ActuatorModel] | None = None
    limits: SimLimits | None = None

    _name = field_validator("name")(classmethod(lambda cls, name: check_run_name(name)))


# ---------------------------------------------------------------------------------------
# the resolved config, SI
# ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Reference:
    """A reference angle schedule, SI.

    Attributes
    ----------
    kind : str
        ``"sine"``, ``"step"`` or ``"schedule"``.
    params : dict
        sine: ``mean``, ``amplitude`` [rad], ``frequency`` [Hz], ``phase`` [rad];
        step: ``initial``, ``final`` [rad], ``at`` [s];
        schedule: ``times`` [s], ``angles`` [rad], ``interpolation`` (hold or linear).
    """

    kind: str
    params: dict

    @property
    def span(self) -> float:
        """The reference's size [rad]: sine amplitude, step height or schedule range."""
        p = self.params
        if self.kind == "sine":
            return p["amplitude"]
        if self.kind == "step":
            return abs(p["final"] - p["initial"])
        return float(np.ptp(p["angles"]))


@dataclass(frozen=True)
class ActuatorSpec:
    """One actuator of a simulation, SI: design, materials, loop settings and reference.

    With a ``cooling`` set, ``nylon`` is the muscle set with that environment's lambda'(C)
    at this actuator's coil index as its ``heat_loss_per_length``
    (:func:`~nylonflex.physics.thermal.cooled_nylon`): the whole loop uses it.
    """

    name: str
    radius: float
    wall_thickness: float
    length: float
    coil_index: float
    wrap_angle: float
    base_thickness: float
    silicone: Silicone
    nylon: Nylon
    initial_temperature: float
    noise: float
    seed: int
    table_points: int
    filter_time_constant: float
    hysteresis: float
    reference: Reference
    rms_from: float
    controller: str = "bang_bang"  # or "pi" (docs/model.md s. 19)
    proportional_band: float = math.inf  # PI [rad]
    integral_time: float = math.inf  # PI [s]
    cooling: Cooling | None = None  # None: the nylon set's own heat loss (docs/model.md s. 9)


@dataclass(frozen=True)
class SimConfig:
    """A validated simulation config: the supply, the time grid and the actuators (SI).

    ``text`` is the resolved config as YAML (SI), written into the output file.
    """

    name: str
    supply_voltage: float
    internal_resistance: float
    duration: float
    step: float
    actuators: tuple[ActuatorSpec, ...]
    gripper: bool
    raw: dict = field(compare=False, repr=False)

    @property
    def n_steps(self) -> int:
        """Number of samples, t = 0, dt, ..., up to the duration [-]."""
        return int(math.floor(self.duration / self.step + 1e-9)) + 1

    @property
    def text(self) -> str:
        return yaml.safe_dump(_resolved_doc(self), sort_keys=False, width=100)


def _resolved_doc(cfg: SimConfig) -> dict:
    acts = []
    for a in cfg.actuators:
        acts.append({
            "name": a.name,
            "design": {k: getattr(a, k) for k in ("radius", "wall_thickness", "length",
                                                  "coil_index", "wrap_angle",
                                                  "base_thickness")},
            "silicone": a.silicone.to_dict(),
            "nylon": a.nylon.to_dict(),
            **({} if a.cooling is None else {"cooling": a.cooling.to_dict()}),
            "initial_temperature": a.initial_temperature,
            "sensor": {"noise": a.noise, "seed": a.seed},
            "estimator": {"table_points": a.table_points,
                          "filter_time_constant": a.filter_time_constant},
            "controller": {"hysteresis": a.hysteresis} if a.controller == "bang_bang" else
            {"kind": "pi", "hysteresis": a.hysteresis,
             "proportional_band": a.proportional_band, "integral_time": a.integral_time},
            "reference": {"kind": a.reference.kind,
                          **{k: (list(map(float, v)) if isinstance(v, (list, tuple,
                                                                      np.ndarray)) else v)
                             for k, v in a.reference.params.items()}},
            "metrics": {"rms_from": a.rms_from},
        })
    return {"name": cfg.name,
            "supply": {"voltage": cfg.supply_voltage,
                       "internal_resistance": cfg.internal_resistance},
            "time": {"duration": cfg.duration, "step": cfg.step},
            "actuators": acts,
            "units": "SI (m, rad, s, K, Pa, V, ohm)"}


def actuator_muscle_length(a: ActuatorSpec) -> float:
    """Length of the actuator's wrapped muscle [m]."""
    return float(muscle_length(a.radius, a.wall_thickness, a.length, a.wrap_angle,
                               a.coil_index, a.base_thickness, a.nylon))


def top_temperature(cfg: SimConfig, a: ActuatorSpec) -> float:
    """Highest temperature the muscle can reach: its start or full supply alone [K].

    The exact step is a convex combination of T and T_ss, so T never leaves
    [T_amb, max(T(0), T_ss(E))] (with others on, the supply only sags).
    """
    lm = actuator_muscle_length(a)
    r = float(muscle_resistance(lm, a.nylon, coil_index=a.coil_index))
    v = cfg.supply_voltage * r / (r + cfg.internal_resistance)
    return max(a.initial_temperature,
               float(steady_temperature(v, lm, a.nylon, coil_index=a.coil_index)))


# ---------------------------------------------------------------------------------------
# resolving: defaults, merging, units and ranges
# ---------------------------------------------------------------------------------------

_FULL_TURN = math.radians(360.0)


def _own_or_top(own: _Loop, top: _Loop, key: str, default=None):
    """The actuator's own value where it sets the key, else the top level's, else default."""
    for src in (own, top):
        if key in src.model_fields_set:
            return getattr(src, key)
    return default


def _section(key: str, *sources: _Strict) -> dict:
    """Defaults, then each source's section (the top level, the actuator's own): key by key."""
    merged = dict(DEFAULTS.get(key, {}))
    for src in sources:
        sec = getattr(src, key)
        if sec is not None:
            merged.update(sec.model_dump(exclude_unset=True))
    return merged


def _integer(value: int, path: str, lo: int, hi: int) -> int:
    if not lo <= value <= hi:
        raise range_error(path, lo, hi, "1", value)
    return value


def _reference(ref, path: str, duration: float) -> Reference:
    if ref is None:
        raise InputError(f"{path}: missing; give kind: sine, step or schedule")

    def angle(raw, key, lo=0.0, hi=_FULL_TURN, stated=False):
        return check_range(raw, f"{path}.{key}", "angle", "deg", lo, hi, unit_stated=stated)

    if ref.kind == "sine":
        p = {"mean": angle(ref.mean, "mean"),
             "amplitude": angle(ref.amplitude, "amplitude"),
             "frequency": check_range(ref.frequency, f"{path}.frequency", "frequency", "Hz",
                                      0.0, 100.0, lo_open=True),
             "phase": angle(ref.phase, "phase", -_FULL_TURN, _FULL_TURN)}
        if p["amplitude"] > p["mean"]:
            raise InputError(f"{path}.amplitude: must be <= mean so the angle stays >= 0 deg, "
                             f"got {from_si(p['amplitude'], 'deg'):g} deg > "
                             f"{from_si(p['mean'], 'deg'):g} deg")
        return Reference("sine", p)
    if ref.kind == "step":
        p = {"initial": angle(ref.initial, "initial"), "final": angle(ref.final, "final"),
             "at": check_range(ref.at, f"{path}.at", "time", "s", 0.0, duration)}
        if p["final"] == p["initial"]:
            raise InputError(f"{path}.final: must differ from initial, got "
                             f"{from_si(p['final'], 'deg'):g} deg")
        return Reference("step", p)
    for key in ("times", "angles"):
        if len(getattr(ref, key)) == 0:
            raise InputError(f"{path}.{key}: must be a non-empty list, got []")
    times = [check_range(v, f"{path}.times[{i}]", "time", "s")
             for i, v in enumerate(ref.times)]
    # a schedule of bare angles is degrees when one of them is plainly degrees: [0, 40, 0]
    plain = any((b := bare_number(v)) is not None and b != 0.0 and
                plainly_degrees(b, _FULL_TURN) for v in ref.angles)
    angles = [angle(v, f"angles[{i}]", stated=plain) for i, v in enumerate(ref.angles)]
    if len(times) != len(angles):
        raise InputError(f"{path}.angles: needs one angle per time ({len(times)}), "
                         f"got {len(angles)}")
    if any(b <= a for a, b in zip(times, times[1:])) or times[0] < 0.0:
        raise InputError(f"{path}.times: must be >= 0 s and strictly increasing, "
                         f"got {list(ref.times)!r}")
    return Reference("schedule", {"times": times, "angles": angles,
                                  "interpolation": ref.interpolation})


def _actuator(top: SimConfigModel, own: _Loop, path: str, duration: float, index: int,
              name: str) -> ActuatorSpec:
    pre = f"{path}." if path else ""
    try:
        sil = silicone_parameters(_own_or_top(own, top, "silicone", DEFAULTS["silicone"]))
        ny = nylon_parameters(_own_or_top(own, top, "nylon", DEFAULTS["nylon"]))
    except ValueError as exc:  # the material sets name their own field
        raise InputError(f"{pre}{exc}") from None
    cooling = resolve_cooling(_own_or_top(own, top, "cooling"), ny, f"{pre}cooling")
    d = _section("design", top, own)
    vals = {}
    for key in ("radius", "wall_thickness", "length", "wrap_angle"):
        kind, unit, lo, hi, shown = DESIGN_RANGES[key]
        vals[key] = check_range(d[key], f"{pre}design.{key}", kind, unit, lo, hi, shown)
    lo, hi = ny.coil_index_range
    vals["coil_index"] = check_range(d["coil_index"], f"{pre}design.coil_index",
                                     "dimensionless", "1", lo, hi)
    if d["base_thickness"] == "wall":
        vals["base_thickness"] = vals["wall_thickness"]
    else:
        kind, unit, lo, hi, shown = DESIGN_RANGES["base_thickness"]
        vals["base_thickness"] = check_range(d["base_thickness"], f"{pre}design.base_thickness",
                                             kind, unit, lo, hi, shown)
    if cooling is not None:  # lambda'(C) of this muscle in place of the set's own
        try:
            ny = cooled_nylon(ny, cooling, vals["coil_index"])
        except ValueError as exc:  # the fluid's property table does not reach the muscle
            raise InputError(f"{pre}cooling: {exc}") from None
    t0_raw = _own_or_top(own, top, "initial_temperature")
    t0 = ny.t_amb if t0_raw is None else check_range(
        t0_raw, f"{pre}initial_temperature", "temperature", "degC", ny.t_amb, ny.t_max)
    sensor = _section("sensor", top, own)
    est = _section("estimator", top, own)
    ctl = _section("controller", top, own)
    met = _section("metrics", top, own)
    ref = _reference(_own_or_top(own, top, "reference"), f"{pre}reference", duration)
    if "rms_from" in met:
        rms_from = check_range(met["rms_from"], f"{pre}metrics.rms_from", "time", "s", 0.0,
                               duration)
    else:  # the sine's first period is the warm-up from ambient (docs/model.md section 10)
        rms_from = min(1.0 / ref.params["frequency"], duration) if ref.kind == "sine" else 0.0
    pi = {}
    if ctl.get("kind") == "pi":
        for key, kind, unit, what in (("proportional_band", "angle", "deg", "e.g. 10 deg"),
                                      ("integral_time", "time", "s", "e.g. 20 s")):
            if ctl.get(key) is None:
                raise InputError(f"{pre}controller.{key}: missing for kind: pi; give {what}")
            pi[key] = check_range(ctl[key], f"{pre}controller.{key}", kind, unit, 0.0,
                                  _FULL_TURN if kind == "angle" else 1e6, lo_open=True)
        pi["controller"] = "pi"
    elif ctl.get("proportional_band") is not None or ctl.get("integral_time") is not None:
        raise InputError(f"{pre}controller: proportional_band and integral_time are for "
                         "kind: pi")
    return ActuatorSpec(
        name=name, **pi, silicone=sil, nylon=ny, cooling=cooling, initial_temperature=t0,
        reference=ref,
        noise=check_range(sensor["noise"], f"{pre}sensor.noise", "pressure", "kPa", 0.0,
                          100e3),
        seed=_integer(sensor["seed"], f"{pre}sensor.seed", 0, 2**32 - 1) + index,
        table_points=_integer(est["table_points"], f"{pre}estimator.table_points", 2,
                              100_000),
        filter_time_constant=check_range(est["filter_time_constant"],
                                         f"{pre}estimator.filter_time_constant", "time", "s",
                                         0.0, 3600.0),
        hysteresis=check_range(ctl["hysteresis"], f"{pre}controller.hysteresis", "angle",
                               "deg", 0.0, math.radians(90.0)),
        rms_from=rms_from, **vals)


def parse_sim_config(raw, source: str = "config") -> SimConfig:
    """Validate a simulation config (a mapping from YAML) into a :class:`SimConfig` (SI).

    Parameters
    ----------
    raw : dict
        The config as read from YAML (see ``configs/control.yaml``).
    source : str
        What to call the config in messages.

    Raises
    ------
    InputError
        One line: the field as a dotted path, what it accepts and what it got.
    """
    if not isinstance(raw, dict):
        raise InputError(f"{source}: must be a YAML mapping of keys (name, design, reference, "
                         f"...)")
    try:
        top = SimConfigModel.model_validate(raw)
    except ValidationError as err:
        raise InputError(_pydantic_message(err, SimConfigModel)) from None
    supply = _section("supply", top)
    voltage = check_range(supply["voltage"], "supply.voltage", "voltage", "V", 0.0, 1000.0,
                          lo_open=True)
    r_int = check_range(supply["internal_resistance"], "supply.internal_resistance",
                        "resistance", "ohm", 0.0, 1e4)
    tm = _section("time", top)
    duration = check_range(tm["duration"], "time.duration", "time", "s", 0.0, 10 * 86400.0,
                           lo_open=True)
    dt = check_range(tm["step"], "time.step", "time", "s", 0.0, duration, "ms", lo_open=True)
    if top.actuators is None:
        specs = (_actuator(top, _Loop(), "", duration, 0, "actuator"),)
    else:
        if not 1 <= len(top.actuators) <= _MAX_ACTUATORS:
            raise InputError(f"actuators: must be a list of 1 to {_MAX_ACTUATORS} actuators, "
                             f"got {len(top.actuators)}")
        specs, names = [], set()
        for i, item in enumerate(top.actuators):
            path = f"actuators[{i}]"
            nm = f"actuator_{i}" if item.name is None else item.name
            if not nm.isidentifier() or nm in names:
                raise InputError(f"{path}.name: a unique name of letters, digits and '_', "
                                 f"got {nm!r}")
            names.add(nm)
            specs.append(_actuator(top, item, path, duration, i, nm))
        specs = tuple(specs)
    cfg = SimConfig(name=top.name, supply_voltage=voltage, internal_resistance=r_int,
                    duration=duration, step=dt, actuators=specs,
                    gripper=top.actuators is not None, raw=copy.deepcopy(raw))
    cap = top.limits.samples if top.limits is not None else _MAX_SAMPLES
    if not 0 < cap < float("inf"):
        raise range_error("limits.samples", 0, None, "1", cap, lo_open=True)
    total = cfg.n_steps * len(specs)
    if total > cap:
        raise InputError(
            f"time.step: {cfg.n_steps:,} samples x {len(specs)} actuators = {total:,} "
            f"(about {total * 64 / 1e9:.3g} GB of series) is more than the budget of "
            f"{cap:,.0f}; use a longer step or a shorter duration, or raise the budget with "
            "the config key 'limits: {samples: N}'")
    for a in specs:
        hot = top_temperature(cfg, a)
        s_top = float(stroke(hot, a.coil_index, a.nylon))
        if s_top >= 0.5:  # Boyle and the wrap model mean nothing this far
            raise InputError(f"supply.voltage: must keep every muscle's stroke below 0.5, "
                             f"but heats {a.name} to {hot - 273.15:.0f} degC (stroke "
                             f"{s_top:.2f}), got {voltage:g} V")
    return cfg


def load_sim_config(path) -> SimConfig:
    """Read and validate a simulation config file (YAML); material files are read relative
    to its folder."""
    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    return parse_sim_config(raw, str(path))
