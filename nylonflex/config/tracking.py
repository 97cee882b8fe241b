"""The ``tracking:`` section of a sweep config: the figure-9 closed loop of every design
(docs/model.md s. 19), its schema and its resolution to SI.

The loop is the one of ``nylonflex simulate`` (docs/model.md s. 10): the same sensor,
estimator table, controller (bang-bang with hysteresis, or PI) and exact thermal step, one
actuator per design on the sweep's ``supply`` (no internal resistance). The reference's
angles are in degrees, or fractions of each design's range ``bend_angle_max`` with
``relative_to: bend_angle_max``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from ..units import InputError, from_si
from .base import Count, Number, _Strict, check_range, range_error

__all__ = ["Tracking", "TrackingSpec", "resolve_tracking", "tracking_section"]

#: Most samples of one design's run (duration / step): 1e6 is 10,000 s at 10 ms.
_MAX_SAMPLES = 1_000_000
_FULL_TURN = 2.0 * math.pi


class _Reference(_Strict):
    kind: Literal["sine", "step"]
    relative_to: Literal["absolute", "bend_angle_max"] = "absolute"
    mean: Number | None = None
    amplitude: Number | None = None
    frequency: Number | None = None
    phase: Number = 0.0
    initial: Number = 0.0
    final: Number | None = None
    at: Number = 0.0


class _Controller(_Strict):
    kind: Literal["bang_bang", "pi"] = "bang_bang"
    hysteresis: Number = 0.0
    proportional_band: Number | None = None
    integral_time: Number | None = None


class _Sensor(_Strict):
    noise: Number = 0.0
    seed: Count = 0


class _Estimator(_Strict):
    table_points: Count = 65
    filter_time_constant: Number = 0.0


class _Bandwidth(_Strict):
    error: Number
    low: Number = 0.01
    high: Number = 1.0
    iterations: Count = 8
    periods: Count = 3


class Tracking(_Strict):
    """The ``tracking:`` section, as typed (units not yet resolved)."""

    duration: Number = "125 s"
    step: Number = "10 ms"
    initial_temperature: Number | None = None
    reference: _Reference
    controller: _Controller = _Controller()
    sensor: _Sensor = _Sensor()
    estimator: _Estimator = _Estimator()
    rms_from: Number | None = None
    bandwidth: _Bandwidth | None = None


@dataclass(frozen=True)
class TrackingSpec:
    """The resolved ``tracking:`` section, SI.

    Attributes
    ----------
    duration, step : float
        Run length and sample time [s].
    initial_temperature : float or None
        T(0) [K]; None: the muscle's ambient.
    kind : str
        ``"sine"`` or ``"step"``.
    relative_to : str
        ``"absolute"``: the angles below are [rad]; ``"bend_angle_max"``: fractions [-] of
        each design's theta*.
    mean, amplitude, frequency, phase : float
        Sine: [rad or -], [rad or -], [Hz], [rad].
    initial, final, at : float
        Step: [rad or -], [rad or -], [s].
    controller : str
        ``"bang_bang"`` or ``"pi"``.
    hysteresis : float
        Bang-bang band [rad].
    proportional_band, integral_time : float
        PI: the error that drives the duty from 0 to 1 [rad], and T_i [s].
    noise : float
        Pressure-sensor noise, standard deviation [Pa]; ``seed`` its generator's seed.
    table_points : int
        Points of the estimator's angle-pressure table [-].
    filter_time_constant : float
        First-order filter of the estimate [s]; 0: none.
    rms_from : float
        Start of the RMS window [s].
    bandwidth : dict or None
        ``error`` [rad], ``low``, ``high`` [Hz], ``iterations``, ``periods`` [-].
    """

    duration: float
    step: float
    initial_temperature: float | None
    kind: str
    relative_to: str
    mean: float
    amplitude: float
    frequency: float
    phase: float
    initial: float
    final: float
    at: float
    controller: str
    hysteresis: float
    proportional_band: float
    integral_time: float
    noise: float
    seed: int
    table_points: int
    filter_time_constant: float
    rms_from: float
    bandwidth: dict | None

    @property
    def n_steps(self) -> int:
        """Samples t = 0, dt, ..., up to the duration (as ``nylonflex simulate``) [-]."""
        return int(math.floor(self.duration / self.step + 1e-9)) + 1

    def to_dict(self) -> dict:
        """The spec as plain SI values (for the config's canonical YAML and its hash)."""
        d = {k: getattr(self, k) for k in self.__dataclass_fields__ if k != "bandwidth"}
        if self.bandwidth is not None:
            d["bandwidth"] = dict(self.bandwidth)
        return {k: (float(v) if isinstance(v, float) else v) for k, v in d.items()}


def _angle(raw, field, relative, lo=0.0, hi=_FULL_TURN):
    if relative:
        return check_range(raw, field, "dimensionless", "1", 0.0, 10.0)
    return check_range(raw, field, "angle", "deg", lo, hi)


def _needed(value, field, what):
    if value is None:
        raise InputError(f"{field}: missing; give {what}")
    return value


def resolve_tracking(t: Tracking, supply_voltage, models, t_amb: float,
                     t_max: float) -> TrackingSpec:
    """Check a typed ``tracking:`` section and resolve it to SI.

    Parameters
    ----------
    t : Tracking
        The typed section.
    supply_voltage : float or None
        The sweep's supply [V]; tracking needs one.
    models : tuple of str
        The sweep's model variants; the closed loop is the ``paper`` model's.
    t_amb, t_max : float
        The muscle's ambient and highest safe temperature [K] (bounds of T(0)).

    Raises
    ------
    InputError
        One line naming the field and what it accepts.
    """
    if supply_voltage is None:
        raise InputError("tracking: needs a supply, e.g. supply: {voltage: 12, units: V}")
    if tuple(models) != ("paper",):
        raise InputError("tracking: the closed loop is the paper model's (nylonflex "
                         f"simulate); give model: paper, got {', '.join(models)}")
    duration = check_range(t.duration, "tracking.duration", "time", "s", 0.0, 86400.0,
                           lo_open=True)
    step = check_range(t.step, "tracking.step", "time", "s", 0.0, duration, "ms",
                       lo_open=True)
    ratio = duration / step  # inf for a step of 1e-308 ms: compared before int()
    if not ratio + 1 <= _MAX_SAMPLES:
        shown = f"{ratio + 1:,.0f}" if math.isfinite(ratio) else "more"
        raise InputError(f"tracking.step: {shown} samples a design is more than "
                         f"{_MAX_SAMPLES:,}; use a longer step or a shorter duration")
    t0 = None if t.initial_temperature is None else check_range(
        t.initial_temperature, "tracking.initial_temperature", "temperature", "degC", t_amb,
        t_max)
    r = t.reference
    rel = r.relative_to != "absolute"
    p = "tracking.reference"
    ref = {"mean": 0.0, "amplitude": 0.0, "frequency": 0.0, "phase": 0.0, "initial": 0.0,
           "final": 0.0, "at": 0.0}
    if r.kind == "sine":
        for key, what in (("mean", "the sine's mean angle"), ("amplitude", "its amplitude"),
                          ("frequency", "its frequency")):
            _needed(getattr(r, key), f"{p}.{key}", what)
        ref["mean"] = _angle(r.mean, f"{p}.mean", rel)
        ref["amplitude"] = _angle(r.amplitude, f"{p}.amplitude", rel)
        ref["frequency"] = check_range(r.frequency, f"{p}.frequency", "frequency", "Hz", 0.0,
                                       100.0, lo_open=True)
        ref["phase"] = check_range(r.phase, f"{p}.phase", "angle", "deg", -_FULL_TURN,
                                   _FULL_TURN)
        if ref["amplitude"] > ref["mean"]:
            shown = (lambda x: f"{x:g}") if rel else (lambda x: f"{from_si(x, 'deg'):g} deg")
            raise InputError(f"{p}.amplitude: must be <= mean so the angle stays >= 0, got "
                             f"{shown(ref['amplitude'])} > {shown(ref['mean'])}")
    else:
        ref["initial"] = _angle(r.initial, f"{p}.initial", rel)
        ref["final"] = _angle(_needed(r.final, f"{p}.final", "the step's final angle"),
                              f"{p}.final", rel)
        ref["at"] = check_range(r.at, f"{p}.at", "time", "s", 0.0, duration)
        if ref["final"] == ref["initial"]:
            raise InputError(f"{p}.final: must differ from initial, got {r.final}")
    c = t.controller
    hysteresis = check_range(c.hysteresis, "tracking.controller.hysteresis", "angle", "deg",
                             0.0, math.radians(90.0))
    band, ti = math.inf, math.inf
    if c.kind == "pi":
        band = check_range(_needed(c.proportional_band, "tracking.controller.proportional_band",
                                   "the error that drives the duty from 0 to 1, e.g. 10 deg"),
                           "tracking.controller.proportional_band", "angle", "deg", 0.0,
                           _FULL_TURN, lo_open=True)
        ti = check_range(_needed(c.integral_time, "tracking.controller.integral_time",
                                 "the integral time T_i, e.g. 20 s"),
                         "tracking.controller.integral_time", "time", "s", 0.0, 1e6,
                         lo_open=True)
    elif c.proportional_band is not None or c.integral_time is not None:
        raise InputError("tracking.controller: proportional_band and integral_time are for "
                         "kind: pi")
    noise = check_range(t.sensor.noise, "tracking.sensor.noise", "pressure", "kPa", 0.0,
                        100e3)
    if not 0 <= t.sensor.seed <= 2**32 - 1:
        raise range_error("tracking.sensor.seed", 0, 2**32 - 1, "1", t.sensor.seed)
    if not 2 <= t.estimator.table_points <= 100_000:
        raise range_error("tracking.estimator.table_points", 2, 100_000, "1",
                          t.estimator.table_points)
    tau = check_range(t.estimator.filter_time_constant, "tracking.estimator."
                      "filter_time_constant", "time", "s", 0.0, 3600.0)
    if t.rms_from is not None:
        rms_from = check_range(t.rms_from, "tracking.rms_from", "time", "s", 0.0, duration)
    else:  # as nylonflex simulate: a sine's first period is the warm-up from ambient
        rms_from = min(1.0 / ref["frequency"], duration) if r.kind == "sine" else 0.0
    bw = None
    if t.bandwidth is not None:
        b = t.bandwidth
        if r.kind != "sine":
            raise InputError("tracking.bandwidth: needs a sine reference (its mean and "
                             "amplitude at each trial frequency)")
        pb = "tracking.bandwidth"
        bw = {"error": check_range(b.error, f"{pb}.error", "angle", "deg", 0.0, _FULL_TURN,
                                   lo_open=True),
              "low": check_range(b.low, f"{pb}.low", "frequency", "Hz", 0.0, 100.0,
                                 lo_open=True)}
        bw["high"] = check_range(b.high, f"{pb}.high", "frequency", "Hz", bw["low"], 100.0,
                                 lo_open=True)
        if not 0 <= b.iterations <= 40:
            raise range_error(f"{pb}.iterations", 0, 40, "1", b.iterations)
        if not 1 <= b.periods <= 100:
            raise range_error(f"{pb}.periods", 1, 100, "1", b.periods)
        longest = (1 + b.periods) / bw["low"] / step
        if longest > _MAX_SAMPLES:
            raise InputError(f"{pb}.low: a run of {1 + b.periods} periods at {b.low} takes "
                             f"{longest:,.0f} samples, more than {_MAX_SAMPLES:,}; raise "
                             "low or tracking.step")
        bw.update(iterations=int(b.iterations), periods=int(b.periods))
    return TrackingSpec(duration=duration, step=step, initial_temperature=t0, kind=r.kind,
                        relative_to=r.relative_to, controller=c.kind, hysteresis=hysteresis,
                        proportional_band=band, integral_time=ti, noise=noise,
                        seed=int(t.sensor.seed), table_points=int(t.estimator.table_points),
                        filter_time_constant=tau, rms_from=rms_from, bandwidth=bw, **ref)


def tracking_section(d: dict) -> dict:
    """A ``tracking:`` section (typed, SI units spelled out) that resolves to the SI spec
    ``d`` (:meth:`TrackingSpec.to_dict`) exactly: ``nylonflex info CUBE --config``."""
    q = lambda x, unit: f"{float(x)!r} {unit}"  # noqa: E731 - factor 1: the same float
    rel = d["relative_to"] != "absolute"
    ang = (lambda x: float(x)) if rel else (lambda x: q(x, "rad"))
    if d["kind"] == "sine":
        ref = {"kind": "sine", "mean": ang(d["mean"]), "amplitude": ang(d["amplitude"]),
               "frequency": q(d["frequency"], "Hz"), "phase": q(d["phase"], "rad")}
    else:
        ref = {"kind": "step", "initial": ang(d["initial"]), "final": ang(d["final"]),
               "at": q(d["at"], "s")}
    if rel:
        ref["relative_to"] = d["relative_to"]
    ctl = {"kind": d["controller"], "hysteresis": q(d["hysteresis"], "rad")}
    if d["controller"] == "pi":
        ctl.update(proportional_band=q(d["proportional_band"], "rad"),
                   integral_time=q(d["integral_time"], "s"))
    out = {"duration": q(d["duration"], "s"), "step": q(d["step"], "s"), "reference": ref,
           "controller": ctl, "sensor": {"noise": q(d["noise"], "Pa"), "seed": d["seed"]},
           "estimator": {"table_points": d["table_points"],
                         "filter_time_constant": q(d["filter_time_constant"], "s")},
           "rms_from": q(d["rms_from"], "s")}
    if d.get("initial_temperature") is not None:
        out["initial_temperature"] = q(d["initial_temperature"], "K")
    b = d.get("bandwidth")
    if b is not None:
        out["bandwidth"] = {"error": q(b["error"], "rad"), "low": q(b["low"], "Hz"),
                            "high": q(b["high"], "Hz"), "iterations": b["iterations"],
                            "periods": b["periods"]}
    return out
