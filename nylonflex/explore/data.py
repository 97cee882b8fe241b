"""The explorer's data: what ``nylonflex explore`` says about a cube besides its numbers.

Display units (from the variable registry; a variable the registry does not know keeps the
units the cube gives it; the labels are :func:`nylonflex.variables.label`'s), the design
variables, ``validity`` by flag name, the note on stand-in materials, the grid point
nearest a value (:func:`snap`; the explorer never interpolates) and "copy as config". The
views themselves are drawn in the browser by ``update.js`` from the numbers
:func:`nylonflex.explore.page.build_payload` puts in a page.

The page itself is built by :func:`nylonflex.explore.page.build_document`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import yaml

from ..engine.provenance import chamber_spec, cube_settings
from ..materials import NYLON_PARAMETERS, SILICONE_PARAMETERS
from ..units import InputError
from ..variables import AXES, VARIABLES, to_display

__all__ = ["PAPER_EXAMPLES", "Snapped", "axis_text", "design_config", "design_variables",
           "display_unit", "first_design", "flag_meanings", "snap", "stand_in_note", "to_display_any",
           "validity_names"]


# ---------------------------------------------------------------------------- units
def display_unit(ds, name: str) -> str:
    """The unit ``name`` is shown in: the registry's display unit, else the cube's units."""
    if name in VARIABLES:
        return VARIABLES[name].display
    return str(ds[name].attrs.get("units", "1")) if name in ds.variables else "1"


def to_display_any(ds, name: str, si):
    """SI values of ``name`` in :func:`display_unit` (registry names converted)."""
    if name in VARIABLES:
        return to_display(name, si)
    return np.asarray(si, dtype=float)


def axis_text(ds, name: str, si) -> str:
    """``"7.5 mm"``, ``"8 deg"``, ``"1.7"``: one value of an axis or variable for a label."""
    value = float(to_display_any(ds, name, si))
    unit = display_unit(ds, name)
    return f"{value:.4g}" if unit == "1" else f"{value:.4g} {unit}"


# ---------------------------------------------------------------------------- the cube's parts
def design_variables(ds) -> list[str]:
    """The cube's design variables: those over every design axis, registry order first.

    ``validity`` and ``validity_model_any`` (flag sets) are left out; ``limit`` is included (0 stroke-, 1 strength-
    limited).
    """
    names = [n for n in ds.data_vars
             if set(AXES) <= set(ds[n].dims) and set(ds[n].dims) <= {*AXES, "model"}
             and n not in ("validity", "validity_model_any")]
    order = list(VARIABLES)
    return sorted(names, key=lambda n: (order.index(n) if n in order else len(order), n))


def flag_meanings(ds, name: str = "validity") -> list[tuple[int, str]]:
    """The (mask, meaning) pairs of a CF flag variable (``flag_masks``/``flag_meanings``)."""
    if name not in ds.variables:
        return []
    attrs = ds[name].attrs
    masks = np.atleast_1d(attrs.get("flag_masks", attrs.get("flag_values", [])))
    meanings = str(attrs.get("flag_meanings", "")).split()
    return [(int(m), s) for m, s in zip(masks, meanings) if int(m) != 0]


def validity_names(ds, bits) -> str:
    """A design's ``validity`` as its flag names: ``"valid"`` for 0, ``"self contact,
    stretch beyond fit"`` for the bits set, ``"unknown"`` for NaN (docs/model.md s. 17)."""
    if bits is None or not np.isfinite(bits):
        return "unknown"
    names = [m.replace("_", " ") for mask, m in flag_meanings(ds) if int(bits) & mask]
    return ", ".join(names) if names else "valid"


def stand_in_note(ds) -> str:
    """One sentence naming the cube's material sets whose values include proposals or
    stand-ins (source tag P, or a description saying "stand-in"), "" when none do."""
    parts = []
    for kind in ("silicone", "nylon"):
        try:
            doc = yaml.safe_load(str(ds.attrs.get(f"{kind}_parameters", ""))) or {}
        except yaml.YAMLError:
            continue
        if not isinstance(doc, dict):
            continue
        sources = doc.get("sources") or {}
        proposed = sorted(k for k, v in sources.items() if "P" in str(v).split(":")[0])
        stand_in = "stand-in" in str(doc.get("description", ""))
        if proposed or stand_in:
            name = doc.get("name", ds.attrs.get(kind, kind))
            what = f"{len(proposed)} of its {len(sources)} values are proposals (tag P)" \
                if proposed else "a stand-in"
            parts.append(f"{kind} {name}: {'a stand-in; ' if stand_in and proposed else ''}"
                         f"{what}")
    if not parts:
        return ""
    return ("Stand-in materials: " + "; ".join(parts) + " (docs/model.md s. 9; fit your "
            "own with nylonflex fit). The numbers are the model's with these sets, not "
            "measurements.")


def _curve_axis(name, si) -> dict:
    """A curve axis of a config in display units: start/stop/num when evenly spaced."""
    v = np.asarray(to_display(name, np.asarray(si, float)), float)
    unit = VARIABLES[name].display
    units = {} if unit == "1" else {"units": unit}
    if v.size > 2 and np.allclose(v, np.linspace(v[0], v[-1], v.size), rtol=0,
                                  atol=1e-9 * max(1.0, abs(v[-1]))):
        return {"start": float(f"{v[0]:.12g}"), "stop": float(f"{v[-1]:.12g}"),
                "num": int(v.size), **units}
    return {"values": [float(f"{x:.12g}") for x in v], **units}


def design_config(ds, at: dict, placeholders: bool = False) -> str:
    """The selected design as a runnable sweep config (YAML, display units): one grid value
    per axis, the cube's curves, its materials as ``{set: NAME, field: value, ...}`` with
    every field of the cube's resolved sets, its models, supply, cooling set and
    ``sealed_chamber``'s chamber file (docs/bench.md), so that ``nylonflex sweep`` of it
    gives this design's values of the cube ("copy as config"). With ``placeholders`` each grid
    value is ``'@AXIS@'``, for a page to fill in."""
    try:
        settings = cube_settings(ds)
    except ValueError as err:
        raise InputError(str(err)) from None
    name = str(ds.attrs.get("name", "design"))
    out = {"name": f"{name}_design"}
    for kind, table, default in (("silicone", SILICONE_PARAMETERS, "tc5005"),
                                 ("nylon", NYLON_PARAMETERS, "silver_nylon66")):
        m = getattr(settings, kind).to_dict()
        base = str(m.get("name", default)).split("+")[0]
        out[kind] = {"set": base if base in table else default,
                     **{k: v for k, v in sorted(m.items()) if k != "name"}}
    b = settings.base_thickness
    out["base_thickness"] = "wall" if b is None else \
        {"value": float(f"{float(to_display('wall_thickness', b)):.12g}"), "units": "mm"}
    models = list(settings.models)
    if models != ["paper"]:  # every model the cube holds, so each one's values come back
        out["model"] = models[0] if len(models) == 1 else models
    chamber = (yaml.safe_load(ds.attrs.get("config_yaml") or "null") or {}).get("chamber")
    warning = ""
    if isinstance(chamber, dict):  # sealed_chamber anchored on a bench fit (docs/bench.md)
        try:
            out["chamber"] = chamber_spec(chamber)
        except ValueError as err:  # the page still opens; the copy says what it cannot do
            out["chamber"] = {"file": str(chamber.get("file", ""))}
            warning = f"# warning: {err}: its sealed_chamber values will differ\n"
    if settings.supply_voltage is not None:
        out["supply"] = {"voltage": settings.supply_voltage, "units": "V"}
    if settings.cooling is not None:
        out["cooling"] = {"set": settings.cooling.name, "speed": settings.cooling.speed}
    grid = {}
    for axis in AXES:
        value = float(ds[axis].values[snap(ds, axis, float(at[axis])).index])
        unit = VARIABLES[axis].display
        shown = f"@{axis}@" if placeholders else float(f"{float(to_display(axis, value)):.12g}")
        grid[axis] = {"values": [shown],
                      **({} if unit == "1" else {"units": unit})}
    out["grid"] = grid
    out["curves"] = {c: _curve_axis(c, ds[c].values) for c in ("stroke", "pressure")}
    head = (f"# the design picked in the explorer of cube '{name}': "
            "nylonflex sweep THIS.yaml\n") + warning
    return head + yaml.safe_dump(out, sort_keys=False, default_flow_style=None, width=100)


@dataclass(frozen=True)
class Snapped:
    """A requested axis value and the grid point the cube holds for it."""

    axis: str
    index: int
    value: float          # the grid value [SI]
    requested: float      # the value asked for [SI]
    exact: bool           # the request was a grid value (to 1e-9 of the axis span)

    def note(self, ds) -> str:
        """One line for the page: the grid point, and whether the request fell between."""
        shown = axis_text(ds, self.axis, self.value)
        if self.exact:
            return f"{self.axis} {shown} (a grid point)"
        return (f"{self.axis} {axis_text(ds, self.axis, self.requested)} lies between grid "
                f"points: showing the nearest grid point {shown} (the cube holds no values "
                "between grid points)")


def snap(ds, axis: str, value: float) -> Snapped:
    """The grid point of ``axis`` nearest ``value`` [SI].

    Raises
    ------
    InputError
        ``axis`` is not a coordinate of the cube.
    """
    if axis not in ds.coords:
        raise InputError(f"{axis}: not an axis of this cube; accepted: "
                         f"{', '.join(str(c) for c in ds.coords)}")
    grid = np.asarray(ds[axis].values, dtype=float)
    i = int(np.argmin(np.abs(grid - value)))
    span = float(np.ptp(grid)) or 1.0
    return Snapped(axis, i, float(grid[i]), float(value),
                   bool(abs(grid[i] - value) <= 1e-9 * span))


#: The paper's worked examples (section 4; docs/model.md s. 8), SI, psi = 8 deg; the
#: second first: the explorer opens on it where the cube holds it.
PAPER_EXAMPLES = (
    ("the paper's second worked example", {"radius": 7.5e-3, "wall_thickness": 2e-3,
                                           "length": 70e-3, "coil_index": 1.7,
                                           "wrap_angle": float(np.radians(8.0))}),
    ("the paper's first worked example", {"radius": 20e-3, "wall_thickness": 6e-3,
                                          "length": 90e-3, "coil_index": 1.1,
                                          "wrap_angle": float(np.radians(8.0))}))


def _valid_at(ds, index) -> bool:
    """Whether the grid design at ``index`` ({axis: grid index}) has no validity flag (the
    first model of a cube of several) and a finite ``limit``."""
    one = ds.isel(model=0) if "model" in ds.dims else ds
    if "validity" in one:
        v = float(one["validity"].isel(index).values)
        if not (np.isfinite(v) and v == 0):
            return False
    if "limit" in one:
        return bool(np.isfinite(float(one["limit"].isel(index).values)))
    return True


def first_design(ds, keep=None) -> tuple[dict, str]:
    """The design the explorer opens on: ``({axis: grid index}, its name)``.

    The paper's second worked example (then the first) where every one of its values is a
    grid value of the cube (among the ``keep`` indices, {axis: [grid index]}, a page
    carries) and it carries no validity flag; else the valid design nearest the second
    example (by grid steps), named by its values. Never a flagged design, unless every
    design of the cube is flagged (then the one nearest the example, so named).
    """
    keep = keep or {a: list(range(ds.sizes[a])) for a in AXES}
    for name, at in PAPER_EXAMPLES:
        snapped = {a: snap(ds, a, at[a]) for a in AXES}
        index = {a: s.index for a, s in snapped.items()}
        if all(s.exact for s in snapped.values()) and \
                all(index[a] in keep[a] for a in AXES) and _valid_at(ds, index):
            values = ", ".join(f"{_SYMBOL[a]} {axis_text(ds, a, at[a])}" for a in AXES)
            return index, f"{name} ({values})"
    target = PAPER_EXAMPLES[0][1]
    centre = {a: keep[a].index(min(keep[a], key=lambda i: abs(float(ds[a].values[i])
                                                               - target[a]))) for a in AXES}
    one = ds.isel(model=0) if "model" in ds.dims else ds
    kept = one.isel({a: keep[a] for a in AXES})
    ok = np.ones(tuple(len(keep[a]) for a in AXES), bool)
    if "validity" in kept:
        v = kept["validity"].transpose(*AXES).values.astype(float)
        ok &= np.isfinite(v) & (v == 0)
    if "limit" in kept:
        ok &= np.isfinite(kept["limit"].transpose(*AXES).values.astype(float))
    grids = np.meshgrid(*[np.arange(len(keep[a])) for a in AXES], indexing="ij")
    dist = sum((g - centre[a]) ** 2 for g, a in zip(grids, AXES)).astype(float)
    any_ok = ok.any()
    flat = int(np.argmin(np.where(ok, dist, np.inf))) if any_ok else int(np.argmin(dist))
    j = np.unravel_index(flat, ok.shape)
    index = {a: keep[a][int(k)] for a, k in zip(AXES, j)}
    values = ", ".join(f"{_SYMBOL[a]} {axis_text(ds, a, ds[a].values[index[a]])}"
                       for a in AXES)
    what = "a valid design" if any_ok else "a flagged design (every design is flagged)"
    return index, f"{what}: {values} (the cube does not hold the paper's examples)"


_SYMBOL = {"radius": "a", "wall_thickness": "t", "length": "L", "coil_index": "C",
           "wrap_angle": "\u03c8"}
