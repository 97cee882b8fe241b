"""Design specs: where to start, what to optimise, what to respect (validated before work).

A spec is a YAML mapping::

    name: force_at_20mm            # optional; names the run
    cube: sweeps/fig12/cube.h5     # a saved cube (relative to the current directory) ...
    # grid: {...}                  # ... or a sweep config's grid, with silicone, nylon,
    #                              #     base_thickness and model, computed in memory
    objectives:                    # one or more; any axis or design variable
      - max: tip_force_max
    constraints:                   # the query syntax, with units; ANDed
      - "range_fraction >= 1"
      - "radius <= 20 mm"
      - "coil_index == 1.1"
    refine: true                   # or {starts: 4, maxiter: 60}; false keeps grid points
    resolution:                    # optional: what can be built, per axis (with units;
      coil_index: 0.05             #   bare numbers in mm, deg): every reported design is
      wall_thickness: 0.5 mm       #   snapped to multiples of it and re-checked exactly

Every error is an :class:`~nylonflex.units.InputError` of one line naming the key.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..config import read_yaml
from ..query import COLUMNS, parse_constraint
from ..variables import TRACKING, VARIABLES
from ..units import InputError, parse_quantity
from ..variables import AXES

__all__ = ["DesignSpec", "Objective", "load_spec", "parse_spec"]

_KEYS = ("name", "cube", "grid", "silicone", "nylon", "base_thickness", "model",
         "objectives", "constraints", "refine", "resolution")
#: The model variants a ``grid:`` spec may name (a ``cube:`` spec uses the cube's own).
from ..variables import MODELS  # noqa: E402
#: Default refinement budget: multi-starts (one objective) or front seeds (several), and
#: SLSQP iterations per start.
DEFAULT_STARTS = {"single": 4, "multi": 40}
DEFAULT_MAXITER = 60
#: The most SLSQP iterations of one design run, starts x maxiter [-]: 8 times the default
#: budget of several objectives (40 x 60); the accepted maximum of each (1000 x 10,000) ran
#: past 120 s on a 128,000-design cube.
MAX_REFINE_ITERATIONS = 20_000
_OBJECTIVE_NAMES = tuple(n for n in COLUMNS if n != "limit") + tuple(TRACKING)


@dataclass(frozen=True)
class Objective:
    """One objective: ``sense`` ``"max"`` or ``"min"`` of ``name`` (an axis or variable)."""

    name: str
    sense: str

    @property
    def sign(self) -> float:
        """+1 to minimise, -1 to maximise: ``sign * value`` is always minimised."""
        return 1.0 if self.sense == "min" else -1.0

    def __str__(self):
        return f"{self.sense} {self.name}"


@dataclass(frozen=True)
class DesignSpec:
    """A validated design spec.

    Attributes
    ----------
    name : str
        Run name.
    cube : pathlib.Path or None
        The saved cube to start from; None with ``sweep``.
    sweep : dict or None
        A sweep config mapping (grid, materials) to compute in memory; None with ``cube``.
    objectives : tuple of Objective
    constraints : tuple of Condition
    refine : bool
    starts : int
        Refinement starts (one objective) or grid-front seeds refined (several).
    maxiter : int
        SLSQP iterations per start.
    model : str
        Model variant (``"paper"``).
    resolution : dict
        ``{axis: step}`` [SI]: the designs reported lie on multiples of ``step``
        (:mod:`nylonflex.design.resolution`); empty: any value.
    """

    name: str
    cube: Path | None
    sweep: dict | None
    objectives: tuple
    constraints: tuple
    refine: bool
    starts: int
    maxiter: int
    model: str = "paper"
    raw: dict = field(default_factory=dict, compare=False, repr=False)
    resolution: dict = field(default_factory=dict)


def _objective(item, i) -> Objective:
    where = f"objectives[{i}]"
    if isinstance(item, str) and len(item.split()) == 2:
        sense, name = item.split()
    elif isinstance(item, dict) and len(item) == 1:
        (sense, name), = item.items()
    else:
        raise InputError(f"{where}: expected {{max: NAME}} or {{min: NAME}}, got {item!r}")
    if sense not in ("max", "min"):
        raise InputError(f"{where}: sense must be 'max' or 'min', got {sense!r}")
    if name not in _OBJECTIVE_NAMES:
        raise InputError(f"{where}: unknown name {name!r}; accepted: "
                         f"{', '.join(_OBJECTIVE_NAMES)}")
    return Objective(str(name), str(sense))


def _refine(value, multi):
    kind = "multi" if multi else "single"
    if value is None or isinstance(value, bool):
        return bool(value if value is not None else True), DEFAULT_STARTS[kind], DEFAULT_MAXITER
    if not isinstance(value, dict):
        raise InputError(f"refine: expected true, false or {{starts: N, maxiter: N}}, "
                         f"got {value!r}")
    unknown = set(value) - {"starts", "maxiter"}
    if unknown:
        raise InputError(f"refine.{sorted(unknown)[0]}: unknown key; accepted: starts, maxiter")
    out = []
    for key, default, hi in (("starts", DEFAULT_STARTS[kind], 1000),
                             ("maxiter", DEFAULT_MAXITER, 10_000)):
        v = value.get(key, default)
        if isinstance(v, bool) or not isinstance(v, int) or not 1 <= v <= hi:
            raise InputError(f"refine.{key}: must be an integer in [1, {hi}], got {v!r}")
        out.append(v)
    if out[0] * out[1] > MAX_REFINE_ITERATIONS:  # checked before any work
        raise InputError(f"refine: starts x maxiter = {out[0]:,} x {out[1]:,} = "
                         f"{out[0] * out[1]:,} SLSQP iterations, over the "
                         f"{MAX_REFINE_ITERATIONS:,} one design run may take; lower "
                         "refine.starts or refine.maxiter")
    return True, out[0], out[1]


def _resolution(value) -> dict:
    """``{axis: step}`` [SI] from ``resolution: {coil_index: 0.05, wall_thickness: 0.5 mm}``."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise InputError("resolution: expected a mapping of axes to steps, e.g. "
                         "{coil_index: 0.05, wall_thickness: 0.5 mm}")
    out = {}
    for name, step in value.items():
        if name not in AXES:
            raise InputError(f"resolution.{name}: unknown axis; accepted: {', '.join(AXES)}")
        v = VARIABLES[name]
        if isinstance(step, bool) or not isinstance(step, (int, float, str)):
            raise InputError(f"resolution.{name}: expected a step like 0.5"
                             f"{'' if v.display == '1' else ' ' + v.display}, got {step!r}")
        si = parse_quantity(step, f"resolution.{name}", v.kind, v.display)
        if not si > 0 or not si < float("inf"):
            raise InputError(f"resolution.{name}: the step must be > 0, got {step!r}")
        out[str(name)] = float(si)
    return out


def parse_spec(raw, source: str = "spec") -> DesignSpec:
    """Validate a spec mapping (as read from YAML).

    Parameters
    ----------
    raw : dict
        The spec; see the module docstring.
    source : str
        Names the spec in messages.

    Returns
    -------
    DesignSpec

    Raises
    ------
    InputError
        One line naming the key and what it accepts.
    """
    if not isinstance(raw, dict):
        raise InputError(f"{source}: must be a YAML mapping with objectives, constraints "
                         "and cube or grid")
    for key in raw:
        if key not in _KEYS:
            raise InputError(f"{key}: unknown key; accepted: {', '.join(_KEYS)}")
    if ("cube" in raw) == ("grid" in raw):
        raise InputError(f"{source}: give exactly one of 'cube' (a saved cube) or 'grid' "
                         "(a sweep grid)")
    name = str(raw.get("name", "design"))
    model = raw.get("model", "paper")
    if model not in MODELS:
        raise InputError(f"model: must be one of {', '.join(MODELS)}, got {model!r}")
    cube = sweep = None
    if "cube" in raw:
        for key in ("silicone", "nylon", "base_thickness", "model"):
            if key in raw:
                raise InputError(f"{key}: a cube carries its own materials and model; "
                                 "give it only with 'grid'")
        if not isinstance(raw["cube"], str) or not raw["cube"]:
            raise InputError(f"cube: expected a path to a saved cube, got {raw['cube']!r}")
        cube = Path(raw["cube"])
    else:
        sweep = {"name": "design",
                 "grid": raw["grid"],
                 # the design variables need no curves: one point each keeps the sweep cheap
                 "curves": {"stroke": {"values": [0.05]}, "pressure": {"values": [0]}}}
        for key in ("silicone", "nylon", "base_thickness"):
            if key in raw:
                sweep[key] = raw[key]
        if model != "paper":
            sweep["model"] = model
    objectives = raw.get("objectives")
    if isinstance(objectives, (str, dict)):
        objectives = [objectives]
    if not isinstance(objectives, list) or not objectives:
        raise InputError("objectives: expected a list of {max: NAME} or {min: NAME}, "
                         "at least one")
    objectives = tuple(_objective(o, i) for i, o in enumerate(objectives))
    names = [o.name for o in objectives]
    if len(set(names)) != len(names):
        raise InputError(f"objectives: each name once, got {', '.join(names)}")
    constraints = raw.get("constraints") or []
    if isinstance(constraints, str):
        constraints = [constraints]
    if not isinstance(constraints, list):
        raise InputError("constraints: expected a list of strings like \"radius <= 20 mm\"")
    constraints = tuple(parse_constraint(c, i) for i, c in enumerate(constraints))
    refine, starts, maxiter = _refine(raw.get("refine", True), len(objectives) > 1)
    loop = [n for n in (*names, *(c.name for c in constraints)) if n in TRACKING]
    if loop and (refine or raw.get("resolution")):
        raise InputError(f"refine: {loop[0]} comes from the closed loop of grid designs in "
                         "the cube (docs/model.md s. 19), not from the exact model that "
                         "refines and snaps; give refine: false and no resolution")
    return DesignSpec(name=name, cube=cube, sweep=sweep, objectives=objectives,
                      constraints=constraints, refine=refine, starts=starts, maxiter=maxiter,
                      model=model, raw=dict(raw),
                      resolution=_resolution(raw.get("resolution")))


def load_spec(path) -> DesignSpec:
    """Read and validate a spec file (YAML)."""
    try:
        raw = read_yaml(path)
    except InputError as err:
        raise InputError(str(err).replace("no such config file", "no such spec file")) from None
    return parse_spec(raw, str(path))


def fixed_axes(spec: DesignSpec) -> dict:
    """``{axis: SI value}`` of the axes an equality constraint fixes."""
    out = {}
    for c in spec.constraints:
        if c.op == "==" and c.name in AXES:
            if c.name in out and out[c.name] != c.value:
                out[c.name] = float("nan")  # two different values: no design meets both
            else:
                out[c.name] = c.value
    return out
