"""Closed-loop simulation in time: the paper's figures 9 and 10 (MODEL.md section 10).

The plant is the thermal ODE of eq. (3) driving the muscle temperature T; the stroke s(T),
the chamber pressure p(s) and the bend angle theta(p) follow quasi-statically. A pressure
sensor (optionally noisy) feeds an estimator, the model's angle-pressure curve held as a
small table built once per design, and a bang-bang controller switches the supply
(optionally with a hysteresis band). Several actuators may share one supply, as in the
gripper of figure 10: the switched-on muscles are in parallel on it, and its terminal
voltage sags over its internal resistance.

A config (YAML) is validated here before any kernel runs; every refusal is one
:class:`~nylonflex.units.InputError` line naming the field. :func:`run_simulation` returns
an :class:`xarray.Dataset` in SI with ``units`` and ``long_name`` on every variable;
:func:`simulate_command` is the ``nylonflex simulate`` entry point.

Overheating [choice]: the temperature is not clamped. Above T_max the stroke keeps
following the same eq. (2) shape (a little past s_max(C)); the run records the highest
temperature, the time spent above T_max and the peak load in the muscle against its
breaking force, and the summary warns.
"""

from __future__ import annotations

import copy
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from . import __version__
from .config import DESIGN_RANGES, read_yaml, valid_name
from .materials import Nylon, Silicone, nylon_parameters, silicone_parameters
from .physics.bending import NEWTON_RTOL, quadrature_nodes
from .physics.chamber import P_ATM, chamber_pressure
from .physics.nylon import _stroke_scale, nylon_force_limit, stroke
from .physics.thermal import muscle_resistance, steady_temperature
from .physics.wrap import muscle_length, nylon_force
from .units import InputError, from_si, parse_quantity

__all__ = [
    "PLANT_TABLE_POINTS",
    "SIM_VARIABLES",
    "ActuatorSpec",
    "Reference",
    "SimConfig",
    "load_sim_config",
    "parse_sim_config",
    "reference_signal",
    "run_simulation",
    "summary",
    "step_metrics",
    "write_simulation",
]

#: Points of the plant's angle-pressure table (cubic Hermite on exact values and slopes):
#: below 1e-11 relative to the curvature solve for the default design (tests).
PLANT_TABLE_POINTS = 513

#: Largest number of samples times actuators of one run (8 float64 series each).
_MAX_SAMPLES = 20_000_000

#: Output variables: name -> (units, long_name). Every time series has dims
#: (actuator, time), squeezed to (time,) for a single actuator.
SIM_VARIABLES: dict[str, tuple[str, str]] = {
    "temperature": ("K", "muscle temperature"),
    "stroke": ("1", "muscle contraction"),
    "pressure": ("Pa", "chamber gauge pressure"),
    "bend_angle": ("rad", "bend angle"),
    "bend_angle_estimate": ("rad", "estimated bend angle"),
    "bend_angle_reference": ("rad", "reference bend angle"),
    "voltage": ("V", "voltage on the muscle"),
    "current": ("A", "current in the muscle"),
    "power": ("W", "electric heating power"),
}

#: Per-actuator metrics (gripper runs store them as variables on ``actuator``, single runs
#: as global attributes): name -> (units, long_name).
SIM_METRICS: dict[str, tuple[str, str]] = {
    "rms_error": ("rad", "RMS tracking error"),
    "rms_error_fraction": ("1", "RMS tracking error over the reference span"),
    "rise_time": ("s", "10-90 % rise time of the step"),
    "overshoot": ("1", "overshoot of the step, fraction of the step"),
    "mean_power": ("W", "mean heating power"),
    "peak_power": ("W", "peak heating power"),
    "energy": ("J", "electric energy"),
    "temperature_max": ("K", "highest muscle temperature"),
    "time_above_t_max": ("s", "time above the muscle's highest safe temperature"),
    "nylon_use_max": ("1", "peak muscle load over its breaking force"),
    "reach": ("rad", "largest bend angle the muscle can reach: full heating alone, or its start"),
}

# ---------------------------------------------------------------------------------------
# config
# ---------------------------------------------------------------------------------------

#: MODEL.md section 10: the default design, supply and timing.
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

_TOP_KEYS = {"name", "silicone", "nylon", "design", "supply", "time", "initial_temperature",
             "sensor", "estimator", "controller", "reference", "metrics", "actuators",
             "description"}
_ACTUATOR_KEYS = {"name", "silicone", "nylon", "design", "initial_temperature", "sensor",
                  "estimator", "controller", "reference", "metrics"}
_SECTION_KEYS = {
    "design": {"radius", "wall_thickness", "length", "coil_index", "wrap_angle",
               "base_thickness"},
    "supply": {"voltage", "internal_resistance"},
    "time": {"duration", "step"},
    "sensor": {"noise", "seed"},
    "estimator": {"table_points", "filter_time_constant"},
    "controller": {"hysteresis"},
    "metrics": {"rms_from"},
}
_REFERENCE_KEYS = {
    "sine": {"kind", "mean", "amplitude", "frequency", "phase"},
    "step": {"kind", "initial", "final", "at"},
    "schedule": {"kind", "times", "angles", "interpolation"},
}

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
    """One actuator of a simulation, SI: design, materials, loop settings and reference."""

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
            "initial_temperature": a.initial_temperature,
            "sensor": {"noise": a.noise, "seed": a.seed},
            "estimator": {"table_points": a.table_points,
                          "filter_time_constant": a.filter_time_constant},
            "controller": {"hysteresis": a.hysteresis},
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


def _mapping(value, path) -> dict:
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError(f"{path}: must be a mapping of keys, got {value!r}")
    return value


def _known(d: dict, allowed, path):
    for key in d:
        if key not in allowed:
            raise InputError(f"{path}.{key}: unknown key; accepted: "
                             f"{', '.join(sorted(allowed))}" if path else
                             f"{key}: unknown key; accepted: {', '.join(sorted(allowed))}")


def _quantity(raw, path, kind, unit, lo=None, hi=None, *, lo_open=False, show=None) -> float:
    """Parse ``"7.5 mm"``, a bare number (in ``unit``) or ``{value, units}`` to SI, in range."""
    if isinstance(raw, dict):
        _known(raw, {"value", "units"}, path)
        if "value" not in raw:
            raise InputError(f"{path}.value: missing key")
        raw = f"{raw['value']} {raw.get('units', unit)}"
    if isinstance(raw, bool) or raw is None or isinstance(raw, (list, dict)):
        raise InputError(f"{path}: expected a number with an optional unit ({unit}), "
                         f"got {raw!r}")
    value = float(parse_quantity(raw, path, kind, unit))
    show = show or unit
    bad = not math.isfinite(value)
    if lo is not None:
        bad |= value <= lo if lo_open else value < lo
    if hi is not None:
        bad |= value > hi
    if bad:
        lo_s = "" if lo is None else f"{from_si(lo, show):g}"
        hi_s = "" if hi is None else f"{from_si(hi, show):g}"
        if lo is not None and hi is not None:
            rng = f"in {'(' if lo_open else '['}{lo_s}, {hi_s}] {show}"
        elif lo is not None:
            rng = f"{'>' if lo_open else '>='} {lo_s} {show}"
        else:
            rng = f"<= {hi_s} {show}"
        raise InputError(f"{path}: must be {rng}, got {raw!r}")
    return value


def _integer(raw, path, lo, hi) -> int:
    if isinstance(raw, bool) or not isinstance(raw, int) or not lo <= raw <= hi:
        raise InputError(f"{path}: must be an integer in [{lo}, {hi}], got {raw!r}")
    return raw


def _angle_list(raw, path, kind, unit):
    if not isinstance(raw, list) or len(raw) == 0:
        raise InputError(f"{path}: must be a non-empty list, got {raw!r}")
    return [_quantity(v, f"{path}[{i}]", kind, unit) for i, v in enumerate(raw)]


def _reference(raw, path, duration) -> Reference:
    raw = _mapping(raw, path)
    if not raw:
        raise InputError(f"{path}: missing; give kind: sine, step or schedule")
    kind = raw.get("kind")
    if kind not in _REFERENCE_KEYS:
        raise InputError(f"{path}.kind: must be one of sine, step, schedule, got {kind!r}")
    _known(raw, _REFERENCE_KEYS[kind], path)
    big = math.radians(360.0)
    if kind == "sine":
        for key in ("mean", "amplitude", "frequency"):
            if key not in raw:
                raise InputError(f"{path}.{key}: missing key")
        p = {"mean": _quantity(raw["mean"], f"{path}.mean", "angle", "deg", 0.0, big),
             "amplitude": _quantity(raw["amplitude"], f"{path}.amplitude", "angle", "deg",
                                    0.0, big),
             "frequency": _quantity(raw["frequency"], f"{path}.frequency", "frequency",
                                    "Hz", 0.0, 100.0, lo_open=True),
             "phase": _quantity(raw.get("phase", 0.0), f"{path}.phase", "angle", "deg",
                                -big, big)}
        if p["amplitude"] > p["mean"]:
            raise InputError(f"{path}.amplitude: must be <= mean so the angle stays >= 0 deg, "
                             f"got {raw['amplitude']!r}")
        return Reference("sine", p)
    if kind == "step":
        if "final" not in raw:
            raise InputError(f"{path}.final: missing key")
        p = {"initial": _quantity(raw.get("initial", 0.0), f"{path}.initial", "angle", "deg",
                                  0.0, big),
             "final": _quantity(raw["final"], f"{path}.final", "angle", "deg", 0.0, big),
             "at": _quantity(raw.get("at", 0.0), f"{path}.at", "time", "s", 0.0, duration)}
        if p["final"] == p["initial"]:
            raise InputError(f"{path}.final: must differ from initial, got {raw['final']!r}")
        return Reference("step", p)
    for key in ("times", "angles"):
        if key not in raw:
            raise InputError(f"{path}.{key}: missing key")
    times = _angle_list(raw["times"], f"{path}.times", "time", "s")
    angles = _angle_list(raw["angles"], f"{path}.angles", "angle", "deg")
    if len(times) != len(angles):
        raise InputError(f"{path}.angles: needs one angle per time ({len(times)}), "
                         f"got {len(angles)}")
    if any(b <= a for a, b in zip(times, times[1:])) or times[0] < 0.0:
        raise InputError(f"{path}.times: must be >= 0 s and strictly increasing, "
                         f"got {raw['times']!r}")
    for i, a in enumerate(angles):
        if not 0.0 <= a <= big:
            raise InputError(f"{path}.angles[{i}]: must be in [0, 360] deg, "
                             f"got {raw['angles'][i]!r}")
    interp = raw.get("interpolation", "hold")
    if interp not in ("hold", "linear"):
        raise InputError(f"{path}.interpolation: must be one of hold, linear, got {interp!r}")
    return Reference("schedule", {"times": times, "angles": angles, "interpolation": interp})


def _section(top: dict, own: dict, key: str, path: str) -> dict:
    """Defaults, then the top-level section, then the actuator's own: key by key."""
    merged = dict(DEFAULTS.get(key, {}))
    for src, where in ((top, key), (own, path)):
        sec = _mapping(src.get(key), where)
        _known(sec, _SECTION_KEYS[key], where)
        merged.update(sec)
    return merged


def _actuator(top: dict, own: dict, path: str, duration: float, dt: float, index: int,
              name: str) -> ActuatorSpec:
    pre = f"{path}." if path else ""
    try:
        sil = silicone_parameters(own.get("silicone", top.get("silicone",
                                                               DEFAULTS["silicone"])))
        ny = nylon_parameters(own.get("nylon", top.get("nylon", DEFAULTS["nylon"])))
    except ValueError as exc:  # the material sets name their own field
        raise InputError(f"{pre}{exc}") from None
    d = _section(top, own, "design", f"{pre}design")
    vals = {}
    for key in ("radius", "wall_thickness", "length", "wrap_angle"):
        kind, unit, lo, hi, _ = DESIGN_RANGES[key]
        vals[key] = _quantity(d[key], f"{pre}design.{key}", kind, unit, lo, hi)
    lo, hi = ny.coil_index_range
    vals["coil_index"] = _quantity(d["coil_index"], f"{pre}design.coil_index",
                                   "dimensionless", "1", lo, hi)
    b = d["base_thickness"]
    if b == "wall":
        vals["base_thickness"] = vals["wall_thickness"]
    else:
        kind, unit, lo, hi, _ = DESIGN_RANGES["base_thickness"]
        vals["base_thickness"] = _quantity(b, f"{pre}design.base_thickness", kind, unit, lo,
                                           hi)
    t0_raw = own.get("initial_temperature", top.get("initial_temperature"))
    t0 = ny.t_amb if t0_raw is None else _quantity(
        t0_raw, f"{pre}initial_temperature", "temperature", "degC", ny.t_amb, ny.t_max,
        show="degC")
    sensor = _section(top, own, "sensor", f"{pre}sensor")
    est = _section(top, own, "estimator", f"{pre}estimator")
    ctl = _section(top, own, "controller", f"{pre}controller")
    met = _section(top, own, "metrics", f"{pre}metrics")
    ref = _reference(own.get("reference", top.get("reference")), f"{pre}reference",
                     duration)
    if "rms_from" in met:
        rms_from = _quantity(met["rms_from"], f"{pre}metrics.rms_from", "time", "s", 0.0,
                             duration)
    else:  # the sine's first period is the warm-up from ambient (MODEL.md section 10)
        rms_from = min(1.0 / ref.params["frequency"], duration) if ref.kind == "sine" else 0.0
    return ActuatorSpec(
        name=name, silicone=sil, nylon=ny, initial_temperature=t0, reference=ref,
        noise=_quantity(sensor["noise"], f"{pre}sensor.noise", "pressure", "kPa", 0.0, 100e3),
        seed=_integer(sensor["seed"], f"{pre}sensor.seed", 0, 2**32 - 1) + index,
        table_points=_integer(est["table_points"], f"{pre}estimator.table_points", 2,
                              100_000),
        filter_time_constant=_quantity(est["filter_time_constant"],
                                       f"{pre}estimator.filter_time_constant", "time", "s",
                                       0.0, 3600.0),
        hysteresis=_quantity(ctl["hysteresis"], f"{pre}controller.hysteresis", "angle", "deg",
                             0.0, math.radians(90.0)),
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
    _known(raw, _TOP_KEYS, "")
    name = raw.get("name")
    if not valid_name(name):
        raise InputError(f"name: letters, digits, '-', '_' and '.' only, got {name!r}")
    supply = _section(raw, {}, "supply", "supply")
    voltage = _quantity(supply["voltage"], "supply.voltage", "voltage", "V", 0.0, 1000.0,
                        lo_open=True)
    r_int = _quantity(supply["internal_resistance"], "supply.internal_resistance", "resistance",
                      "ohm", 0.0, 1e4)
    tm = _section(raw, {}, "time", "time")
    duration = _quantity(tm["duration"], "time.duration", "time", "s", 0.0, 10 * 86400.0,
                         lo_open=True)
    dt = _quantity(tm["step"], "time.step", "time", "s", 0.0, duration, lo_open=True,
                   show="ms")
    acts_raw = raw.get("actuators")
    if acts_raw is None:
        specs = (_actuator(raw, {}, "", duration, dt, 0, "actuator"),)
        gripper = False
    else:
        if not isinstance(acts_raw, list) or not 1 <= len(acts_raw) <= 64:
            raise InputError(f"actuators: must be a list of 1 to 64 actuators, got {acts_raw!r}")
        specs, names = [], set()
        for i, item in enumerate(acts_raw):
            path = f"actuators[{i}]"
            item = _mapping(item, path)
            _known(item, _ACTUATOR_KEYS, path)
            nm = item.get("name", f"actuator_{i}")
            if not isinstance(nm, str) or not nm.isidentifier() or nm in names:
                raise InputError(f"{path}.name: a unique name of letters, digits and '_', "
                                 f"got {nm!r}")
            names.add(nm)
            specs.append(_actuator(raw, item, path, duration, dt, i, nm))
        specs = tuple(specs)
        gripper = True
    cfg = SimConfig(name=name, supply_voltage=voltage, internal_resistance=r_int,
                    duration=duration, step=dt, actuators=specs, gripper=gripper,
                    raw=copy.deepcopy(raw))
    if cfg.n_steps * len(specs) > _MAX_SAMPLES:
        raise InputError(f"time.step: {cfg.n_steps} samples x {len(specs)} actuators is more "
                         f"than {_MAX_SAMPLES}; use a longer step or a shorter duration")
    for a in specs:
        top = _top_temperature(cfg, a)
        s_top = float(stroke(top, a.coil_index, a.nylon))
        if s_top >= 0.5:  # Boyle and the wrap model mean nothing this far
            raise InputError(f"supply.voltage: must keep every muscle's stroke below 0.5, "
                             f"but heats {a.name} to {top - 273.15:.0f} degC (stroke "
                             f"{s_top:.2f}), got {voltage:g} V")
    return cfg


def load_sim_config(path) -> SimConfig:
    """Read and validate a simulation config file (YAML)."""
    from .calibration.files import anchor_material_files

    raw = anchor_material_files(read_yaml(path), Path(path).parent)
    return parse_sim_config(raw, str(path))


# ---------------------------------------------------------------------------------------
# running
# ---------------------------------------------------------------------------------------

def _muscle_length(a: ActuatorSpec) -> float:
    return float(muscle_length(a.radius, a.wall_thickness, a.length, a.wrap_angle,
                               a.coil_index, a.base_thickness, a.nylon))


def _top_temperature(cfg: SimConfig, a: ActuatorSpec) -> float:
    """Highest temperature the muscle can reach: its start or full supply alone [K].

    The exact step is a convex combination of T and T_ss, so T never leaves
    [T_amb, max(T(0), T_ss(E))] (with others on, the supply only sags).
    """
    lm = _muscle_length(a)
    r = float(muscle_resistance(lm, a.nylon))
    v = cfg.supply_voltage * r / (r + cfg.internal_resistance)
    return max(a.initial_temperature, float(steady_temperature(v, lm, a.nylon)))


def reference_signal(ref: Reference, t):
    """The reference angle at times ``t`` [rad].

    Parameters
    ----------
    ref : Reference
        The schedule.
    t : ndarray
        Times [s].

    Notes
    -----
    A step switches at ``at`` (inclusive); a ``hold`` schedule keeps each angle until the
    next time and its first angle before the first time.
    """
    t = np.asarray(t, dtype=float)
    p = ref.params
    if ref.kind == "sine":
        return p["mean"] + p["amplitude"] * np.sin(2.0 * np.pi * p["frequency"] * t
                                                   + p["phase"])
    if ref.kind == "step":
        return np.where(t >= p["at"], p["final"], p["initial"])
    times = np.asarray(p["times"])
    angles = np.asarray(p["angles"])
    if p["interpolation"] == "linear":
        return np.interp(t, times, angles)
    idx = np.searchsorted(times, t, side="right") - 1
    return angles[np.clip(idx, 0, None)]


def step_metrics(t, angle, ref: Reference):
    """Rise time (10 to 90 % of the step) [s] and overshoot (fraction of the step) [-].

    Parameters
    ----------
    t : ndarray
        Times [s].
    angle : ndarray
        Bend angle [rad].
    ref : Reference
        A ``step`` reference.

    Returns
    -------
    rise_time, overshoot : float
        NaN rise time when the angle never gets to 90 % of the step; overshoot is the
        largest excursion past the final value after the step, 0 when there is none.
    """
    p = ref.params
    after = t >= p["at"]
    y = (angle[after] - p["initial"]) / (p["final"] - p["initial"])
    ta = t[after]

    def crossing(level):
        i = np.flatnonzero(y >= level)
        if i.size == 0:
            return math.nan
        i = i[0]
        if i == 0:
            return ta[0]
        # linear interpolation between the samples around the crossing
        return ta[i - 1] + (level - y[i - 1]) / (y[i] - y[i - 1]) * (ta[i] - ta[i - 1])

    rise = crossing(0.9) - crossing(0.1)
    overshoot = max(0.0, float(np.max(y)) - 1.0) if y.size else math.nan
    return float(rise), overshoot


def _tables(a: ActuatorSpec, p_top: float):
    from .kernels.control import angle_table

    mu, alpha = a.silicone.arrays()
    nodes = quadrature_nodes()
    geom = (a.radius, a.wall_thickness, a.base_thickness, a.length, mu, alpha, *nodes,
            NEWTON_RTOL)
    dp_plant = p_top / (PLANT_TABLE_POINTS - 1)
    plant = np.empty(PLANT_TABLE_POINTS)
    slope = np.empty(PLANT_TABLE_POINTS)
    angle_table(dp_plant, *geom, plant, slope)
    dp_est = p_top / (a.table_points - 1)
    est = np.empty(a.table_points)
    angle_table(dp_est, *geom, est, np.empty(a.table_points))
    return dp_plant, plant, slope, dp_est, est


def _pad(rows, fill):
    width = max(len(r) for r in rows)
    out = np.full((len(rows), width), fill, dtype=float)
    for i, r in enumerate(rows):
        out[i, :len(r)] = r
    return out


def run_simulation(cfg: SimConfig):
    """Simulate the closed loop of a validated config.

    Parameters
    ----------
    cfg : SimConfig
        From :func:`parse_sim_config` or :func:`load_sim_config`.

    Returns
    -------
    xarray.Dataset
        Time series of :data:`SIM_VARIABLES` on ``time`` [s] (and ``actuator`` for a
        gripper), SI, with ``units`` and ``long_name``; the metrics of :data:`SIM_METRICS`
        as global attributes (single actuator) or variables on ``actuator``; the resolved
        config as YAML in ``attrs["config"]``; the loop's wall time in ``attrs["loop_time"]``.
    """
    import xarray as xr

    from .kernels.control import closed_loop

    n, m = len(cfg.actuators), cfg.n_steps
    t = np.arange(m) * cfg.step
    per = {k: [] for k in ("lm", "r", "c", "loss", "tamb", "t0", "scale", "gamma", "beta",
                           "tg", "sg", "dpp", "dpe", "band", "keep")}
    plants, slopes, ests, refs, noises, reach = [], [], [], [], [], []
    for a in cfg.actuators:
        ny = a.nylon
        lm = _muscle_length(a)
        top = _top_temperature(cfg, a)
        scale = float(_stroke_scale(a.coil_index, np.asarray(ny.coil_index_table),
                                    np.asarray(ny.stroke_max_table), ny.t_amb, ny.t_max,
                                    ny.gamma, ny.beta, ny.t_g, ny.sigma_g))
        s_top = float(stroke(top, a.coil_index, ny))
        p_top = float(chamber_pressure(s_top)) * (1.0 + 1e-9)
        dpp, plant, slope, dpe, est = _tables(a, max(p_top, 1.0))
        reach.append(plant[-1])
        for key, val in (("lm", lm), ("r", ny.resistance_per_length),
                         ("c", ny.heat_capacity_per_length), ("loss", ny.heat_loss_per_length),
                         ("tamb", ny.t_amb), ("t0", a.initial_temperature), ("scale", scale),
                         ("gamma", ny.gamma), ("beta", ny.beta), ("tg", ny.t_g),
                         ("sg", ny.sigma_g), ("dpp", dpp), ("dpe", dpe),
                         ("band", 0.5 * a.hysteresis),
                         ("keep", math.exp(-cfg.step / a.filter_time_constant)
                          if a.filter_time_constant > 0 else 0.0)):
            per[key].append(val)
        plants.append(plant)
        slopes.append(slope)
        ests.append(est)
        refs.append(reference_signal(a.reference, t))
        rng = np.random.default_rng(a.seed)
        noises.append(rng.normal(0.0, a.noise, m) if a.noise > 0 else np.zeros(m))
    arr = {k: np.asarray(v, dtype=float) for k, v in per.items()}
    reference = np.ascontiguousarray(np.array(refs))
    noise = np.ascontiguousarray(np.array(noises))
    outs = {k: np.empty((n, m)) for k in SIM_VARIABLES if k != "bend_angle_reference"}
    args = (cfg.step, cfg.supply_voltage, cfg.internal_resistance, P_ATM,
            arr["lm"], arr["r"], arr["c"], arr["loss"], arr["tamb"], arr["t0"],
            arr["scale"], arr["gamma"], arr["beta"], arr["tg"], arr["sg"],
            arr["dpp"], _pad(plants, 0.0), _pad(slopes, 0.0), arr["dpe"], _pad(ests, 0.0),
            arr["band"], arr["keep"], reference, noise,
            outs["temperature"], outs["stroke"], outs["pressure"], outs["bend_angle"],
            outs["bend_angle_estimate"], outs["voltage"], outs["current"], outs["power"])
    tic = time.perf_counter()
    closed_loop(*args)
    loop_time = time.perf_counter() - tic
    outs["bend_angle_reference"] = reference

    metrics = {k: [] for k in SIM_METRICS}
    for j, a in enumerate(cfg.actuators):
        ny = a.nylon
        sel = t >= a.rms_from - 1e-12
        err = outs["bend_angle"][j, sel] - reference[j, sel]
        rms = float(np.sqrt(np.mean(err * err))) if err.size else math.nan
        span = a.reference.span
        if a.reference.kind == "step":
            rise, over = step_metrics(t, outs["bend_angle"][j], a.reference)
        else:
            rise, over = math.nan, math.nan
        temp = outs["temperature"][j]
        s_peak = float(np.max(outs["stroke"][j]))
        use = float(nylon_force(max(s_peak, 0.0), a.radius, a.wall_thickness, a.wrap_angle,
                                a.coil_index, a.base_thickness, a.silicone, ny)
                    / nylon_force_limit(a.coil_index, ny))
        power = outs["power"][j]
        for key, val in (("rms_error", rms),
                         ("rms_error_fraction", rms / span if span > 0 else math.nan),
                         ("rise_time", rise), ("overshoot", over),
                         ("mean_power", float(power.mean())),
                         ("peak_power", float(power.max())),
                         ("energy", float(power.sum() * cfg.step)),
                         ("temperature_max", float(temp.max())),
                         ("time_above_t_max", float(np.count_nonzero(temp > ny.t_max)
                                                    * cfg.step)),
                         ("nylon_use_max", use), ("reach", float(reach[j]))):
            metrics[key].append(val)

    dims = ("actuator", "time") if cfg.gripper else ("time",)
    data = {}
    for key, (units, long_name) in SIM_VARIABLES.items():
        values = outs[key] if cfg.gripper else outs[key][0]
        data[key] = xr.Variable(dims, values, {"units": units, "long_name": long_name})
    coords = {"time": ("time", t, {"units": "s", "long_name": "time"})}
    attrs = {"title": f"nylonflex closed-loop simulation {cfg.name}",
             "nylonflex_version": __version__, "config": cfg.text,
             "supply_voltage": cfg.supply_voltage,
             "internal_resistance": cfg.internal_resistance, "time_step": cfg.step,
             "loop_time": loop_time,
             "model": "MODEL.md section 10: exact step of eq. (3), quasi-static s, p, theta; "
                      "bang-bang on the pressure-based angle estimate"}
    if cfg.gripper:
        coords["actuator"] = ("actuator", [a.name for a in cfg.actuators],
                              {"long_name": "actuator"})
        for key, (units, long_name) in SIM_METRICS.items():
            data[key] = xr.Variable(("actuator",), np.asarray(metrics[key]),
                                    {"units": units, "long_name": long_name})
        total = outs["current"].sum(axis=0)
        data["supply_current"] = xr.Variable(("time",), total, {
            "units": "A", "long_name": "current drawn from the supply"})
        attrs["supply_current_max"] = float(total.max())
    else:
        for key in SIM_METRICS:
            attrs[key] = metrics[key][0]
    attrs["metric_units"] = yaml.safe_dump({k: u for k, (u, _) in SIM_METRICS.items()},
                                           sort_keys=False).strip()
    return xr.Dataset(data, coords=coords, attrs=attrs)


def write_simulation(ds, path) -> Path:
    """Write a simulation Dataset to NetCDF4/HDF5 (h5netcdf engine) at ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    ds.to_netcdf(path, engine="h5netcdf")
    return path


# ---------------------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------------------

def _deg(x):
    return math.degrees(x)


def summary(cfg: SimConfig, ds) -> list[str]:
    """Lines of the run's summary: tracking, step response, power and warnings."""
    lines = [f"{cfg.name}: {len(cfg.actuators)} actuator(s) on {cfg.supply_voltage:g} V, "
             f"{cfg.duration:g} s at {cfg.step * 1e3:g} ms ({cfg.n_steps} steps), loop "
             f"{ds.attrs['loop_time'] * 1e3:.1f} ms"]
    for j, a in enumerate(cfg.actuators):
        get = (lambda k: float(ds[k].values[j])) if cfg.gripper else \
            (lambda k: float(ds.attrs[k]))
        tag = f"  {a.name}: " if cfg.gripper else "  "
        span = a.reference.span
        what = {"sine": "amplitude", "step": "step", "schedule": "range"}[a.reference.kind]
        lines.append(f"{tag}RMS error {_deg(get('rms_error')):.2f} deg = "
                     f"{100 * get('rms_error_fraction'):.1f} % of the {_deg(span):.0f} deg "
                     f"{what} (from t = {a.rms_from:g} s)")
        if a.reference.kind == "step":
            rise = get("rise_time")
            rise_s = "never reaches 90 %" if math.isnan(rise) else f"{rise:.2f} s"
            lines.append(f"{tag}rise time (10-90 %) {rise_s}, overshoot "
                         f"{100 * get('overshoot'):.2f} %")
        lines.append(f"{tag}power mean {get('mean_power'):.2f} W, peak "
                     f"{get('peak_power'):.2f} W, energy {get('energy'):.1f} J; "
                     f"max temperature {get('temperature_max') - 273.15:.0f} degC")
        ref_max = float(np.max(reference_signal(a.reference, ds["time"].values)))
        if ref_max > get("reach") + 1e-9:
            lines.append(f"{tag}warning: the reference reaches {_deg(ref_max):.0f} deg, "
                         f"beyond the {_deg(get('reach')):.0f} deg the design settles at "
                         f"with full heating")
        if get("time_above_t_max") > 0:
            lines.append(f"{tag}warning: the muscle spent {get('time_above_t_max'):.1f} s "
                         f"above its highest safe temperature "
                         f"{a.nylon.t_max - 273.15:.0f} degC")
        if get("nylon_use_max") > 1.0:
            lines.append(f"{tag}warning: the muscle load reached "
                         f"{100 * get('nylon_use_max'):.0f} % of its breaking force")
    if cfg.gripper:
        lines.append(f"  supply current peak {1e3 * ds.attrs['supply_current_max']:.0f} mA")
    return lines
