"""Closed-loop simulation in time: the paper's figures 9 and 10 (docs/model.md section 10).

The plant is the thermal ODE of eq. (3) driving the muscle temperature T; the stroke s(T),
the chamber pressure p(s) and the bend angle theta(p) follow quasi-statically. A pressure
sensor (optionally noisy) feeds an estimator, the model's angle-pressure curve held as a
small table built once per design, and a bang-bang controller switches the supply
(optionally with a hysteresis band). Several actuators may share one supply, as in the
gripper of figure 10: the switched-on muscles are in parallel on it, and its terminal
voltage sags over its internal resistance.

A config (YAML) is validated by :mod:`nylonflex.config.simulate` before any kernel runs (its
names are re-exported here); every refusal is one :class:`~nylonflex.units.InputError` line
naming the field. :func:`run_simulation` returns an :class:`xarray.Dataset` in SI with
``units`` and ``long_name`` on every variable, and the run's metrics, from which
:mod:`nylonflex.cli.simulate` writes the lines the ``nylonflex simulate`` command prints
(:func:`settled_errors` gives the settled errors it quotes).

Overheating [choice]: the temperature is not clamped. Above T_max the stroke keeps
following the same eq. (2) shape (a little past s_max(C)); the run records the highest
temperature, the time spent above T_max and the peak load in the muscle against its
breaking force, and the summary warns.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import yaml

from .. import __version__
from ..config.simulate import (  # noqa: F401 - the config layer's names, importable from here too
    DEFAULTS,
    ActuatorSpec,
    Reference,
    SimConfig,
    actuator_muscle_length,
    load_sim_config,
    parse_sim_config,
    top_temperature,
)
from ..kernels.records import AngleTables, Control, Muscles, Ogden, SimOut, Supply
from ..kernels.scratch import node_scratch
from ..physics.bending import NEWTON_RTOL, quadrature_nodes
from ..physics.chamber import P_ATM, chamber_pressure
from ..physics.nylon import nylon_force_limit, stroke, stroke_scale
from ..physics.thermal import coil_resistance_per_length
from ..physics.wrap import nylon_force
from ..files.atomic import refuse_special, replacing
from ..units import InputError

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
    "step_metrics",
    "write_simulation",
]

#: Points of the plant's angle-pressure table (cubic Hermite on exact values and slopes):
#: below 1e-11 relative to the curvature solve for the default design (tests).
PLANT_TABLE_POINTS = 513

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
# running
# ---------------------------------------------------------------------------------------

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
    from ..kernels.control import angle_table

    mu, alpha = a.silicone.arrays()
    nodes = quadrature_nodes()
    geom = (a.radius, a.wall_thickness, a.base_thickness, a.length, Ogden(mu, alpha), nodes,
            NEWTON_RTOL, node_scratch(nodes))
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

    from ..kernels.control import closed_loop, loop_state

    n, m = len(cfg.actuators), cfg.n_steps
    t = np.arange(m) * cfg.step
    per = {k: [] for k in ("lm", "r", "c", "loss", "tamb", "t0", "scale", "gamma", "beta",
                           "tg", "sg", "dpp", "dpe", "band", "keep", "gain", "istep")}
    plants, slopes, ests, refs, noises, reach = [], [], [], [], [], []
    for a in cfg.actuators:
        ny = a.nylon
        lm = actuator_muscle_length(a)
        top = top_temperature(cfg, a)
        scale = float(stroke_scale(a.coil_index, np.asarray(ny.coil_index_table),
                                   np.asarray(ny.stroke_max_table), ny.t_amb, ny.t_max,
                                   ny.gamma, ny.beta, ny.t_g, ny.sigma_g))
        s_top = float(stroke(top, a.coil_index, ny))
        p_top = float(chamber_pressure(s_top)) * (1.0 + 1e-9)
        dpp, plant, slope, dpe, est = _tables(a, max(p_top, 1.0))
        reach.append(plant[-1])
        for key, val in (("lm", lm), ("r", float(coil_resistance_per_length(a.coil_index, ny))),
                         ("c", ny.heat_capacity_per_length), ("loss", ny.heat_loss_per_length),
                         ("tamb", ny.t_amb), ("t0", a.initial_temperature), ("scale", scale),
                         ("gamma", ny.gamma), ("beta", ny.beta), ("tg", ny.t_g),
                         ("sg", ny.sigma_g), ("dpp", dpp), ("dpe", dpe),
                         ("band", 0.5 * a.hysteresis),
                         ("keep", math.exp(-cfg.step / a.filter_time_constant)
                          if a.filter_time_constant > 0 else 0.0),
                         ("gain", 1.0 / a.proportional_band),
                         ("istep", cfg.step / a.integral_time)):
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
    supply = Supply(cfg.step, cfg.supply_voltage, cfg.internal_resistance, P_ATM)
    muscles = Muscles(arr["lm"], arr["r"], arr["c"], arr["loss"], arr["tamb"], arr["t0"],
                      arr["scale"], arr["gamma"], arr["beta"], arr["tg"], arr["sg"])
    tables = AngleTables(arr["dpp"], _pad(plants, 0.0), _pad(slopes, 0.0), arr["dpe"],
                         _pad(ests, 0.0))
    kind = np.array([int(a.controller == "pi") for a in cfg.actuators], dtype=np.int64)
    control = Control(arr["band"], arr["keep"], reference, noise, kind, arr["gain"],
                      arr["istep"])
    out = SimOut(outs["temperature"], outs["stroke"], outs["pressure"], outs["bend_angle"],
                 outs["bend_angle_estimate"], outs["voltage"], outs["current"], outs["power"])
    tic = time.perf_counter()
    closed_loop(supply, muscles, tables, control, loop_state(arr["t0"]), out)
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
             "model": "docs/model.md section 10: exact step of eq. (3), quasi-static s, p, theta; "
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


def write_simulation(ds, path, inputs=()) -> Path:
    """Write a simulation Dataset to NetCDF4/HDF5 (h5netcdf engine) at ``path``.

    Atomic: written to a new temporary file beside it, fsynced, then renamed
    (:func:`nylonflex.files.atomic.replacing`). Only an earlier simulation is replaced; anything
    else at ``path`` (a cube, a config, a link, a special file, one of ``inputs``) is
    refused with an InputError.
    """
    path = Path(path)
    refuse_special(path, "--out", inputs)
    if path.exists() and not _is_simulation(path):
        raise InputError(f"--out: {path} exists and is not a nylonflex simulation; it is not "
                         "replaced: choose another --out or move it")
    with replacing(path, "--out", inputs) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return path


def _is_simulation(path) -> bool:
    import h5py

    try:
        with h5py.File(path, "r") as f:
            title = f.attrs.get("title", b"")
    except (OSError, ValueError):
        return False
    title = title.decode() if isinstance(title, bytes) else str(title)
    return title.startswith("nylonflex closed-loop simulation")


# ---------------------------------------------------------------------------------------
# metrics the command line quotes
# ---------------------------------------------------------------------------------------

def settled_errors(time, angle, reference) -> np.ndarray:
    """|angle - reference| [rad] at the end of each level of a piecewise-constant reference
    (the last sample before it changes, and the last of the run): how close the loop got
    before the next command. ``time`` [s], ``angle`` and ``reference`` [rad]."""
    reference = np.asarray(reference, float)
    ends = np.flatnonzero(np.diff(reference) != 0)
    ends = np.append(ends[ends > 0], len(reference) - 1)
    return np.abs(np.asarray(angle, float)[ends] - reference[ends])
