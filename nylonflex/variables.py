"""One registry of every quantity: name, dims, units, long_name, accepted range, display unit.

Everything that needs to know about a quantity reads it here (after sgkit's
``variables.py``): the physics' input checks and the pointwise evaluator (accepted ranges),
config validation (ranges and the unit a bare number means), the engine (the order of the
design variables, written once: :data:`DESIGN`), cube attributes, the labels of every chart
and of the explorer (:func:`label`, from a variable's attributes) and query units.
``display`` is the unit a designer reads on charts and types in configs and on the command
line; the code and the cube stay SI.

This module is the bottom layer with :mod:`nylonflex.units` and :mod:`nylonflex.materials`:
it imports nothing else of nylonflex at module level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .units import from_si

__all__ = ["AXES", "CATEGORIES", "COORDS", "CURVES", "DESIGN", "INPUTS", "MODELS", "SPREAD",
           "SPREAD_OF", "SUPPLY_ONLY", "THERMAL", "TRACKING", "UNCERTAIN", "VARIABLES",
           "Variable", "incomplete_text", "label", "name_label", "quantile_name",
           "range_text", "slab_done_attrs", "spread_name", "to_display", "validate"]

#: Model variants, in the order of their integer codes in the kernels (docs/model.md
#: s. 16); ``paper`` is the default. What each adds, where it holds and when to use it:
#: :data:`nylonflex.variants.VARIANTS` (``nylonflex list models``), one record a name.
MODELS = ("paper", "coupled_muscle", "paper_eq10", "incompressible_wall", "cauchy_moment",
          "lateral_pressure", "fe_calibrated", "sealed_chamber")

#: The design axes, in the cube's order.
AXES = ("radius", "wall_thickness", "length", "coil_index", "wrap_angle")


@dataclass(frozen=True)
class Variable:
    """A cube coordinate or variable.

    Attributes
    ----------
    name : str
        snake_case name, the same in code, configs, the CLI and the cube.
    dims : tuple of str
        Dimensions, in order.
    units : str
        SI unit stored in the cube (``attrs["units"]``), "1" for dimensionless.
    long_name : str
        Human label (``attrs["long_name"]``).
    description : str
        What it is, with the docs/model.md section.
    display : str
        Unit shown on charts and accepted bare on the command line.
    kind : str
        Kind of quantity, for unit parsing (see :mod:`nylonflex.units`).
    dtype : str
        Stored dtype.
    lo, hi : float or None
        Accepted range of an input in SI ``units`` (None: unbounded on that side, or set
        elsewhere, like the coil index by the muscle's table).
    lo_open, hi_open : bool
        The bound itself is excluded.
    """

    name: str
    dims: tuple[str, ...]
    units: str
    long_name: str
    description: str
    display: str
    kind: str
    dtype: str = "float64"
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    by_model: bool = False

    def attrs(self) -> dict:
        """The attributes written to the cube (CF flags for flag variables)."""
        out = {"units": self.units, "long_name": self.long_name,
               "description": self.description}
        if self.name in STANDARD_NAMES:
            out["standard_name"] = STANDARD_NAMES[self.name]
        if self.name in _FLAGS:
            values, meanings = _FLAGS[self.name]
            out["flag_values"] = np.array(values, dtype=np.int8)
            out["flag_meanings"] = meanings
        if self.name in _MASKS:
            values, meanings = _MASKS[self.name]
            out["flag_masks"] = np.array(values, dtype=np.int8)
            out["flag_meanings"] = meanings
        return out

    def dims_for(self, models, coolings=(), supply: bool = False) -> tuple[str, ...]:
        """Dimensions in a cube of ``models`` and ``coolings`` (their names): a string
        ``model`` dimension when there are several models and this variable depends on the
        model, then a string ``cooling`` dimension when there are several cooling sets and
        it depends on the heat loss (:meth:`by_cooling`)."""
        dims = self.dims + ("model",) if self.by_model and len(models) > 1 else self.dims
        if len(coolings) > 1 and self.by_cooling(supply):
            dims = dims + ("cooling",)
        return dims

    def by_cooling(self, supply: bool) -> bool:
        """Whether this design variable depends on the cooling set: the heat loss sets the
        holding power, its voltage and the cooling time (:data:`THERMAL`); with a
        ``supply`` it also caps the temperature, T_ss = T_amb + V^2/(r' lambda' l_m^2), and
        so the usable stroke and all that follows from it (docs/model.md s. 9, 15)."""
        return self.by_model and self.dims == AXES and (supply or self.name in THERMAL)


#: CF flag values and meanings of the flag variables.
_FLAGS = {"limit": ((0, 1, 2, 3),
                    "stroke_limited strength_limited supply_limited load_limited"),
          "slab_done": ((0, 1), "missing done")}

#: CF flag masks and meanings of the bit-field variables (docs/model.md s. 17).
_MASKS = {"validity": ((1, 2, 4, 8, 16),
                       "self_contact stretch_beyond_fit under_one_turn chamber_closes "
                       "efficiency_beyond_bound")}
_MASKS["validity_model_any"] = _MASKS["validity"]  # the same bits, OR over a model spread

#: Variables that are in a cube only when its config gives a supply.
SUPPLY_ONLY = ("heating_time", "cycle_time", "cycle_rate", "heating_energy", "mechanical_work",
               "efficiency")

#: Design variables that depend on the cooling set even without a supply (docs/model.md
#: s. 15): lambda' l_m (T* - T_amb), its voltage, and the time constant c'/lambda'.
THERMAL = ("heating_power", "heating_voltage", "cooling_time")

#: The string dimensions of a cube, in the order they follow the others: several model
#: variants (docs/model.md s. 16), several cooling sets (s. 9).
CATEGORIES = ("model", "cooling")

#: CF standard names (CF standard name table) where CF has one for a cube variable: the
#: two flag variables say the status and the quality of each design's values. The design
#: quantities themselves (radius, tip force, bend angle, ...) have no CF name: CF names
#: geophysical quantities.
STANDARD_NAMES = {"limit": "status_flag", "validity": "quality_flag"}


def _v(name, dims, units, long_name, description, display, kind, dtype="float64", **rng):
    return Variable(name, tuple(dims), units, long_name, description, display, kind, dtype,
                    **rng)


def _m(*args, **kw):
    """A variable that depends on the model variant."""
    return _v(*args, by_model=True, **kw)


_DEG = np.pi / 180.0


COORDS = {v.name: v for v in [
    _v("radius", ["radius"], "m", "chamber radius", "inner radius a of the half-cylindrical "
       "chamber (docs/model.md s. 1)", "mm", "length", lo=0.5e-3, hi=0.2),
    _v("wall_thickness", ["wall_thickness"], "m", "wall thickness",
       "thickness t of the half-cylindrical silicone wall (docs/model.md s. 1)", "mm", "length",
       lo=0.1e-3, hi=0.05),
    _v("length", ["length"], "m", "actuator length", "actuator length L (docs/model.md s. 1)",
       "mm", "length", lo=1e-3, hi=2.0),
    _v("coil_index", ["coil_index"], "1", "coil index",
       "spring index C = D/d of the coiled muscle (docs/model.md s. 2)", "1", "dimensionless"),
    _v("wrap_angle", ["wrap_angle"], "rad", "wrap angle",
       "helix angle psi of the wrap from the hoop direction (docs/model.md s. 4)", "deg", "angle",
       lo=0.1 * _DEG, hi=80.0 * _DEG),
    _v("stroke", ["stroke"], "1", "muscle stroke",
       "muscle contraction s, a fraction of its ambient length (docs/model.md s. 2)", "1",
       "dimensionless", lo=0.0, hi=0.5),
    _v("pressure", ["pressure"], "Pa", "chamber pressure", "gauge pressure p of the chamber "
       "(docs/model.md s. 3)", "kPa", "pressure", lo=0.0, hi=100e3),
    _v("quantile", ["quantile"], "1", "probability level",
       "probability level of the <variable>_quantile variables (the config's "
       "uncertainty.quantiles; docs/uncertainty.md)", "1", "dimensionless", lo=0.0, hi=1.0),
]}

#: Inputs that are neither axes nor stored variables.
INPUTS = {v.name: v for v in [
    _v("base_thickness", [], "m", "base thickness", "thickness b of the bottom layer below "
       "the chamber floor; b = t unless given (docs/model.md s. 1)", "mm", "length",
       lo=0.1e-3, hi=0.05),
    _v("supply_voltage", [], "V", "supply voltage", "steady voltage across the muscle; caps "
       "its temperature at T_ss (docs/model.md s. 15)", "V", "voltage", lo=0.0, hi=1000.0,
       lo_open=True),
]}

DESIGN = {v.name: v for v in [
    _m("usable_stroke", AXES, "1", "usable stroke",
       "s* = min(s_max(C), s_lim), the stroke the muscle can use (docs/model.md s. 8)", "1",
       "dimensionless"),
    _m("limit", AXES, "1", "limiting factor",
       "0 stroke-limited (full range of motion), 1 strength-limited, 2 supply-limited, "
       "3 load-limited (docs/model.md s. 8, 15, 16)", "1",
       "dimensionless", "int8"),
    _m("pressure_max", AXES, "Pa", "maximum pressure", "p* = p(s*) (docs/model.md s. 8)", "kPa",
       "pressure"),
    _m("torque_max", AXES, "N m", "maximum torque", "M* = M_P(p*) (docs/model.md s. 8)", "N mm",
       "torque"),
    _m("tip_force_max", AXES, "N", "maximum tip force", "F* = M*/L, blocked (docs/model.md s. 7-8)",
       "N", "force"),
    _m("bend_angle_max", AXES, "rad", "maximum bend angle",
       "theta* = kappa(p*) L, free bending (docs/model.md s. 6, 8)", "deg", "angle"),
    _m("range_fraction", AXES, "1", "range of motion fraction",
       "theta*/theta(s_max); 1 means a full range of motion (docs/model.md s. 8)", "1",
       "dimensionless"),
    _m("nylon_force_max", AXES, "N", "nylon force at usable stroke", "F_n(s*) (docs/model.md s. 4)",
       "N", "force"),
    _m("nylon_use", AXES, "1", "nylon strength use", "F_n(s*)/F_lim(C) (docs/model.md s. 4, 8)",
       "1", "dimensionless"),
    _v("muscle_length", AXES, "m", "muscle length", "length of muscle in the wrap "
       "l_m = n P_out / cos psi (docs/model.md s. 15)", "mm", "length"),
    _v("resistance", AXES, "ohm", "muscle resistance", "R = r' l_m (docs/model.md s. 15)",
       "ohm", "resistance"),
    _m("heating_power", AXES, "W", "heating power", "lambda' l_m (T* - T_amb), the steady "
       "power that holds the muscle at its working temperature T* (docs/model.md s. 15)", "W",
       "power"),
    _m("heating_voltage", AXES, "V", "heating voltage", "sqrt(R P), the steady supply that "
       "holds the muscle at T* (docs/model.md s. 15)", "V", "voltage"),
    _m("cooling_time", AXES, "s", "cooling time", "time from T* until the free stroke is 5 % "
       "of its value at T*, eq. (3) with V = 0 (docs/model.md s. 15)", "s", "time"),
    _m("heating_time", AXES, "s", "heating time", "time at the supply voltage from ambient "
       "until the free stroke is 95 % of its value at T* (docs/model.md s. 15)", "s", "time"),
    # per-design dynamics with a supply (issue 29; docs/model.md s. 20)
    _m("cycle_time", AXES, "s", "cycle time", "heating at the supply from ambient to 95 % of "
       "the working stroke, then cooling to 5 % of it, eq. (3) (docs/model.md s. 20)", "s",
       "time"),
    _m("cycle_rate", AXES, "Hz", "cycle rate", "1 / cycle_time, full strokes a second "
       "(docs/model.md s. 20)", "Hz", "frequency"),
    _m("heating_energy", AXES, "J", "heating energy", "electrical energy of one stroke, "
       "V^2/R times the heating time (docs/model.md s. 20)", "J", "energy"),
    _m("mechanical_work", AXES, "J", "mechanical work", "work of the muscle on the chamber "
       "over the usable stroke, l_m int_0^s* F_n ds (docs/model.md s. 20)", "mJ", "energy"),
    _m("efficiency", AXES, "1", "efficiency", "mechanical_work / heating_energy; validity "
       "bit 16 above 1.32 %, the best measured for coiled polymer muscles (docs/model.md "
       "s. 20)", "1", "dimensionless"),
    _m("validity", AXES, "1", "validity flags", "bits: 1 self_contact, 2 stretch_beyond_fit, "
       "4 under_one_turn, 8 chamber_closes, 16 efficiency_beyond_bound; 0 a clean design "
       "(docs/model.md s. 17, 19)", "1",
       "dimensionless", "int8"),
]}
assert tuple(DESIGN)[-1] == "validity"

CURVES = {v.name: v for v in [
    _m("nylon_force", ["radius", "wall_thickness", "coil_index", "wrap_angle", "stroke"], "N",
       "nylon force", "tension F_n(s) in the wrap (docs/model.md s. 4)", "N", "force"),
    _v("nylon_force_limit", ["coil_index"], "N", "nylon force limit",
       "breaking force F_lim(C) = sigma_u(C) A_f (docs/model.md s. 2)", "N", "force"),
    _v("stroke_max", ["coil_index"], "1", "maximum stroke",
       "free stroke s_max(C) of the muscle at its highest safe temperature (docs/model.md s. 2)",
       "1", "dimensionless"),
    _v("chamber_pressure", ["stroke"], "Pa", "chamber pressure",
       "gauge pressure p(s), Boyle (docs/model.md s. 3)", "kPa", "pressure"),
    _m("bend_angle", ["radius", "wall_thickness", "length", "pressure"], "rad", "bend angle",
       "free bending angle theta(p) = kappa(p) L (docs/model.md s. 6)", "deg", "angle"),
    _m("tip_force", ["radius", "wall_thickness", "length", "pressure"], "N", "tip force",
       "blocked tip force M(p)/L, the model's moment (docs/model.md s. 7, 18)", "N", "force"),
]}


def quantile_name(name: str) -> str:
    """``tip_force_max_quantile``: the cube variable of a design variable's quantiles."""
    return f"{name}_quantile"


def _quantile_variable(v: Variable) -> Variable:
    return Variable(quantile_name(v.name), (*AXES, "quantile"), v.units,
                    f"{v.long_name} (quantile)", f"quantiles of {v.name} over the sampled "
                    f"uncertain parameters (docs/uncertainty.md); {v.description}", v.display,
                    v.kind)


#: Variables of a sweep with ``uncertainty`` (quantiles of every float design variable) or
#: ``requirements`` (``feasibility``); the cube holds them only then (docs/uncertainty.md).
UNCERTAIN = {v.name: v for v in [
    *(_quantile_variable(v) for v in DESIGN.values() if v.dtype != "int8"),
    _v("feasibility", AXES, "1", "probability of meeting the requirements",
       "P(every requirement holds) over the sampled uncertain parameters; 0 or 1 at the "
       "nominal design without uncertainty (docs/uncertainty.md)", "1", "dimensionless",
       lo=0.0, hi=1.0),
]}

#: Variables of a sweep with ``tracking:``: the figure-9 closed loop of every design against
#: the config's reference (docs/model.md s. 19); the cube holds them only then.
TRACKING = {v.name: v for v in [
    _v("tracking_rms_error", AXES, "rad", "RMS tracking error",
       "RMS of bend angle minus reference from tracking.rms_from on, the closed loop of "
       "nylonflex simulate (docs/model.md s. 10, 19)", "deg", "angle"),
    _v("tracking_max_temperature", AXES, "K", "highest muscle temperature while tracking",
       "largest sampled muscle temperature of the closed loop (docs/model.md s. 19)", "degC",
       "temperature"),
    _v("tracking_energy", AXES, "J", "electric energy while tracking",
       "electric energy the supply puts into the muscle over the run (docs/model.md s. 19)",
       "J", "energy"),
    _v("tracking_bandwidth", AXES, "Hz", "tracking bandwidth",
       "highest sine frequency whose RMS error stays within tracking.bandwidth.error, by a "
       "bracketed search; 0 when the lowest fails, the highest when it passes (docs/model.md "
       "s. 19)", "Hz", "frequency"),
]}

#: The headline design variables whose range over model variants a sweep with
#: ``fidelity: spread`` stores (docs/model.md s. 23): the torque of figure 12(b), the tip
#: force, the bend angle and the range of motion of figure 12(c).
SPREAD_OF = ("torque_max", "tip_force_max", "bend_angle_max", "range_fraction")


def spread_name(name: str, side: str) -> str:
    """``tip_force_max_model_lo``: the cube variable of the lowest (``side`` "lo") or
    highest ("hi") value of a design variable over a sweep's model spread."""
    if side not in ("lo", "hi"):
        raise ValueError(f"side: must be 'lo' or 'hi', got {side!r}")
    return f"{name}_model_{side}"


def _spread_variable(v: Variable, side: str) -> Variable:
    word = "lowest" if side == "lo" else "highest"
    return Variable(spread_name(v.name, side), AXES, v.units, f"{v.long_name}, {word} model",
                    f"the {word} {v.name} over the model variants of fidelity.spread (the "
                    "cube attribute model_spread), flagged designs included (docs/model.md "
                    f"s. 23); {v.description}", v.display, v.kind, by_model=True)


#: Variables of a sweep with ``fidelity: spread`` (docs/model.md s. 23): the range of each
#: of :data:`SPREAD_OF` over the named model variants, and the OR of their validity bits;
#: the cube holds them only then. Never a ``model`` dimension of their own (they summarise
#: it); ``by_model`` lets them follow their variable onto a ``cooling`` dimension.
SPREAD = {v.name: v for v in [
    *(_spread_variable(DESIGN[n], side) for n in SPREAD_OF for side in ("lo", "hi")),
    _m("validity_model_any", AXES, "1", "validity flags of any model",
       "validity bits set by at least one model variant of fidelity.spread (the OR of "
       "their validity); 0 where every variant's design is clean (docs/model.md s. 17, 22)",
       "1", "dimensionless", "int8"),
]}

#: The string coordinate of a cube of several model variants (docs/model.md s. 16).
MODEL = _v("model", ["model"], "1", "model variant", "the model variant of each slice "
           "(docs/model.md s. 16)", "1", "dimensionless", "str")

#: The string coordinate of a cube of several cooling sets (docs/model.md s. 9).
COOLING = _v("cooling", ["cooling"], "1", "cooling environment", "the cooling set of each "
             "slice: its name, and its speed where it is not the set's own (docs/model.md "
             "s. 9)", "1", "dimensionless", "str")

#: The mask of the radii a sweep has stored (1) or not yet (0).
SLAB_DONE = _v("slab_done", ["radius"], "1", "radius computed",
               "1 where this radius's slab is in the cube", "1", "dimensionless", "int8")

VARIABLES = {**COORDS, **DESIGN, **CURVES, **UNCERTAIN, **TRACKING, **SPREAD}


def is_complete(attrs) -> bool:
    """Whether a cube's attributes mark it complete: ``complete`` 1 (an int8, as written
    since issue 24), or the string ``"true"`` of earlier cubes."""
    value = attrs.get("complete") if attrs is not None else None
    if isinstance(value, (bytes, str)):
        return (value.decode() if isinstance(value, bytes) else value) == "true"
    try:
        return int(np.asarray(value).reshape(-1)[0]) == 1
    except (TypeError, ValueError, IndexError):
        return False


def incomplete_text(ds) -> str:
    """``"incomplete: 5 of 9 slabs (radii) computed"`` for a cube whose sweep was interrupted (as
    ``nylonflex info`` reports it: the ``slab_done`` radii of a cube not marked complete),
    ``""`` for a complete one. ``ds``: an :class:`xarray.Dataset` (or a mapping with
    ``attrs`` and ``slab_done``)."""
    if is_complete(ds.attrs):
        return ""
    if "slab_done" in ds:
        done = np.asarray(ds["slab_done"].values).astype(bool)
        return f"incomplete: {int(done.sum())} of {done.size} slabs (radii) computed"
    return "incomplete: the sweep did not finish"


def slab_done_attrs() -> dict:
    """Attributes of the ``slab_done`` mask, in-memory and on-disk cubes alike."""
    return SLAB_DONE.attrs()


def range_text(name: str, lo=None, hi=None, unit: str | None = None) -> str:
    """``"in [0.5, 200] mm"``: the accepted range of a registered input, in ``unit``.

    ``lo``/``hi`` [SI] replace the registry's bounds (the coil index's come from the
    muscle's table); ``unit`` defaults to the display unit.
    """
    v = {**VARIABLES, **INPUTS}[name]
    lo = v.lo if lo is None else lo
    hi = v.hi if hi is None else hi
    unit = v.display if unit is None else unit
    shown = "" if unit == "1" else f" {unit}"
    return (f"in {'(' if v.lo_open else '['}{from_si(lo, unit):g}, {from_si(hi, unit):g}"
            f"{')' if v.hi_open else ']'}{shown}")


def to_display(name: str, si):
    """SI values of a registered name in its display unit (mm, deg, kPa, ...)."""
    return from_si(np.asarray(si, dtype=float), VARIABLES[name].display)


class _Named:
    """A stand-in for a DataArray of a name and no attrs (:func:`name_label`)."""

    __slots__ = ("name", "attrs")

    def __init__(self, name):
        self.name, self.attrs = name, {}


def label(da, unit_note: str = "") -> str:
    """``"chamber radius [mm]"``: the label of a quantity, read from its attributes (after
    xarray's ``label_from_attrs``); every chart and the explorer label with it.

    The long name is ``da.attrs["long_name"]`` (so a name a user edited in the cube
    shows), else the registry's, else ``da.name``. The unit is the registry's display unit
    for a registered name (the cube stores SI; charts show mm, deg, kPa), else
    ``da.attrs["units"]``; a dimensionless quantity (``"1"``) shows no brackets.

    Parameters
    ----------
    da : xarray.DataArray
        A cube variable or coordinate (anything with ``name`` and ``attrs``).
    unit_note : str, optional
        Text appended as it is, e.g. ``" [-]"`` for a fraction shown without a unit.

    Returns
    -------
    str

    Examples
    --------
    >>> import xarray as xr
    >>> radius = xr.DataArray([5e-3], dims="radius", name="radius",
    ...                       attrs={"units": "m", "long_name": "chamber radius"})
    >>> label(radius)
    'chamber radius [mm]'
    >>> label(radius.assign_attrs(long_name="inner radius"))
    'inner radius [mm]'
    >>> label(xr.DataArray(0.3, name="muscle_share", attrs={"units": "1"}))
    'muscle_share'
    >>> label(xr.DataArray(0.0, name="stroke"), " [-]")
    'muscle stroke [-]'
    """
    name = getattr(da, "name", None)
    attrs = getattr(da, "attrs", None) or {}
    v = VARIABLES.get(name) if isinstance(name, str) else None
    long_name = attrs.get("long_name") or (v.long_name if v is not None else
                                          "" if name is None else name)
    unit = v.display if v is not None else attrs.get("units", "1")
    shown = "" if str(unit) in ("1", "") else f" [{unit}]"
    return f"{long_name}{shown}{unit_note}"


def name_label(name: str, unit_note: str = "") -> str:
    """:func:`label` of a name with no DataArray in scope (a sensitivity output, a design
    objective): the registry's long name and display unit; an unknown name is itself.

    >>> name_label("tip_force_max")
    'maximum tip force [N]'
    """
    return label(_Named(name), unit_note)


def validate(ds) -> None:
    """Check a cube against the registry (after sgkit's ``variables.validate``): every
    variable or coordinate with a registered name has the registry's dimensions (a
    model-dependent one may add ``model``, one the heat loss moves ``cooling``, in that
    order), its SI units and its kind of dtype.

    Parameters
    ----------
    ds : xarray.Dataset
        A cube (in memory or opened).

    Raises
    ------
    ValueError
        One line naming the first variable that disagrees and what the registry says.
    """
    kinds = {"float64": "f", "int8": "i", "str": "OSU"}
    for name, var in ds.variables.items():
        v = VARIABLES.get(name) or {"model": MODEL, "cooling": COOLING}.get(name)
        if v is None:
            continue
        dims = tuple(var.dims)
        extra = dims[len(v.dims):]
        if dims[:len(v.dims)] != v.dims or list(extra) != [c for c in CATEGORIES if c in extra] \
                or (extra and not v.by_model):
            raise ValueError(f"cube: {name} has dimensions {dims}; the registry's are "
                             f"{v.dims}{' (and model, cooling)' if v.by_model else ''}")
        units = var.attrs.get("units")
        if units is not None and str(units) != v.units:
            raise ValueError(f"cube: {name} is in {units!r}; the registry's unit is "
                             f"{v.units!r}")
        # an incomplete cube's masked flags read as float (NaN where not computed)
        allowed = kinds.get(v.dtype, "") + ("f" if v.dtype == "int8" else "")
        if allowed and var.dtype.kind not in allowed:
            raise ValueError(f"cube: {name} is stored as {var.dtype}; the registry's dtype "
                             f"is {v.dtype}")
