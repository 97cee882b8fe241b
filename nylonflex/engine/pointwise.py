"""The compiled pointwise evaluator: every design variable of scattered designs.

:func:`evaluate` is what calibration, uncertainty, optimisation and the explorer call: the
designs' five variables (and the base thickness) broadcast together NumPy-style, and every
numeric field of the material sets may be an array that broadcasts against them (Ogden
``mu``/``alpha`` with the terms on the last axis, the coil-index table's columns likewise),
so 10,000 samples of uncertain materials are one call. The loop is compiled with Numba and
runs in parallel over the designs; its body is the one the pure-Python reference
:func:`nylonflex.physics.design_limits` runs.
"""

from __future__ import annotations

import math
import threading
from bisect import bisect_right
from collections.abc import Mapping
from functools import lru_cache

import numpy as np

from ..kernels.records import CoilTable, Muscle, Nodes, Ogden, Options, PointDesigns, PointOut
from ..kernels.rows import DESIGN_ROWS, FLAG_ROWS, N_FLAGS, N_FLOAT_DESIGN
from ..kernels.scratch import node_scratch
from ..materials import (NYLON_PARAMETERS, NYLON_TABLES, SILICONE_PARAMETERS, Nylon, Silicone,
                         check_nylon, check_silicone, cooling_parameters, nylon_parameters,
                         silicone_kind, silicone_parameters)
from ..physics import (check_input, check_section, check_wrap_angle, float_in_range,
                       input_range)
from ..physics.bending import quadrature_nodes
from ..physics.chamber import P_ATM
from ..physics.limits import MODELS  # the model variants (docs/model.md s. 16)
from ..physics.nylon import check_stroke_shape
from ..physics.sealed import sealed_coefficients
from ..physics.thermal import check_supply_rise, coil_resistance, convection_loss_per_length
from ..units import short
from ..variables import AXES, DESIGN
from .results import to_dataset
from .threads import run_chunks

__all__ = ["MODELS", "design_limits", "evaluate"]

#: Designs below which the kernel runs in the calling thread (threads cost more than they save).
_PARALLEL_FROM = 64

_MUSCLE_FIELDS = ("t_amb", "t_max", "gamma", "beta", "t_g", "sigma_g", "resistance_per_length",
                  "heat_capacity_per_length", "heat_loss_per_length",
                  "thermal_force_coefficient")
_SILICONE_FIELDS = ("mu", "alpha")


def evaluate(radius, wall_thickness, length, coil_index, wrap_angle, *, base_thickness=None,
             silicone="tc5005", nylon="silver_nylon66", model="paper", supply_voltage=None,
             cooling=None, chamber=None, as_dataset=False):
    """Every design variable of designs that broadcast together (compiled, parallel).

    Parameters
    ----------
    radius : float or array
        Inner chamber radius a [m], 0.5-200 mm.
    wall_thickness : float or array
        Wall thickness t [m], 0.1-50 mm.
    length : float or array
        Actuator length L [m], 1-2000 mm.
    coil_index : float or array
        Coil index C [-], inside the muscle set's coil-index table.
    wrap_angle : float or array
        Helix angle psi of the wrap from the hoop direction [rad], 0.1-80 deg.
    base_thickness : float or array, optional
        Bottom layer thickness b [m]; b = t when None (docs/model.md s. 1 [choice]).
    silicone : str, dict or Silicone, default "tc5005"
        A set name, a :class:`~nylonflex.materials.Silicone`, or ``{"set": name, field:
        value}`` where ``mu`` [Pa] and ``alpha`` [-] may be arrays of shape (..., terms)
        whose leading axes broadcast against the designs.
    nylon : str, dict or Nylon, default "silver_nylon66"
        A set name, a :class:`~nylonflex.materials.Nylon`, or ``{"set": name, field:
        value}``; every numeric field may be an array broadcasting against the designs (the
        tables with their columns on the last axis).
    model : str, default "paper"
        Model variant, one of :data:`MODELS` (docs/model.md s. 16).
    supply_voltage : float, optional
        Steady supply voltage across the muscle [V], in (0, 1000]; None: no supply limit
        (docs/model.md s. 15).
    cooling : str, dict or Cooling, optional
        Cooling environment (``materials.COOLING_PARAMETERS``: ``still_air``,
        ``forced_air``, ``still_water``); None: the nylon set's ``heat_loss_per_length``
        (docs/model.md s. 9).
    chamber : dict or sequence, optional
        ``sealed_chamber``'s coefficients (k0, k1, g0, g1, c0, c1, cb) [-]; None: the
        shipped ones (docs/model.md s. 22).
    as_dataset : bool, default False
        Return an ``xarray.Dataset`` instead of a dict: the same arrays over dimensions
        ``design`` (1-D designs; ``design_0``, ``design_1``, ... for more axes; none for
        one design), each with ``units``, ``long_name`` and ``description`` attributes
        (CF flag attributes for ``limit`` and ``validity``), the five inputs and
        ``base_thickness`` as coordinates [m, rad, -], and ``model`` in its attributes.

    Returns
    -------
    dict of str to ndarray, or xarray.Dataset
        The design variables of :data:`nylonflex.variables.DESIGN` (the same names, units
        and values as :func:`nylonflex.design_limits`), each of the broadcast shape;
        ``limit`` and ``validity`` are int8; ``heating_time`` and the dynamics
        (``cycle_time``, ``cycle_rate``, ``heating_energy``, ``mechanical_work``,
        ``efficiency``; docs/model.md s. 20) are NaN without a supply.

    Raises
    ------
    ValueError
        One line naming the parameter and its accepted range.
    """
    if not as_dataset and cooling is None and isinstance(silicone, str) and \
            isinstance(nylon, str):
        out = _one_design((radius, wall_thickness, base_thickness, length, wrap_angle,
                           coil_index), silicone, nylon, model, supply_voltage, chamber)
        if out is not None:
            return _named_rows(out.design.reshape(N_FLOAT_DESIGN), out.flags.reshape(N_FLAGS))
    if model not in MODELS:
        raise ValueError(f"model: unknown model {_short(model)}; accepted: {', '.join(MODELS)}")
    voltage = -1.0 if supply_voltage is None else float(
        check_input("supply_voltage", supply_voltage))
    a, t, b = check_section(radius, wall_thickness, base_thickness)
    L = check_input("length", length)
    psi = check_wrap_angle(wrap_angle)
    ogden, stretch_max, ny = _materials(silicone, nylon)
    c = check_input("coil_index", coil_index, -np.inf, np.inf)
    table = ny["coil_index_table"]
    if c.ndim == 0 and table.ndim == 1:  # one coil index, one table: no array test
        bad = not table[0] <= float(c) <= table[-1]
    else:
        bad = (~np.isfinite(c) | (c < table[..., 0]) | (c > table[..., -1])).any()
    if bad:
        lo, hi = np.broadcast_arrays(table[..., 0], table[..., -1], c)[:2]
        bad = ~np.isfinite(c) | (c < table[..., 0]) | (c > table[..., -1])
        j = np.flatnonzero(np.broadcast_to(bad, np.broadcast(lo, c).shape))[0]
        raise ValueError(f"coil_index: must be in [{lo.flat[j]:g}, {hi.flat[j]:g}] (the "
                         f"nylon set's table), got {np.broadcast_to(c, lo.shape).flat[j]:g}")
    batch = _named_batch(silicone, nylon) if isinstance(silicone, str) and \
        isinstance(nylon, str) else _batch_shapes(ogden, ny)
    shapes = (a.shape, t.shape, b.shape, L.shape, c.shape, psi.shape, *batch)
    try:
        shape = np.broadcast_shapes(*shapes) if any(shapes) else ()
    except ValueError:
        raise ValueError("evaluate: the designs and material arrays do not broadcast "
                         f"together (shapes {[x.shape for x in (a, t, L, c, psi)]}, "
                         f"materials {batch})") from None
    n = math.prod(shape)
    if shape == () and isinstance(nylon, str) and cooling is None:
        designs, coil = _one_named_design((a, t, b, L, psi), float(c), ny)
        muscle = _single_muscle(nylon)
    else:
        designs, coil, muscle = _design_arrays((a, t, b, L, psi), c, ny, cooling, shape, n)
    options = (MODELS.index(model), voltage, stretch_max, sealed_coefficients(chamber))
    out = _run(shape, n, designs, coil, ogden, muscle, options)
    check_supply_rise(voltage, out["muscle_length"], coil[3].reshape(shape),
                      coil[4].reshape(shape), "supply_voltage")
    if as_dataset:
        inputs = dict(zip((*AXES, "base_thickness"), (a, t, L, c, psi, b)))
        extra = {} if supply_voltage is None else {"supply_voltage": voltage}
        return to_dataset(out, inputs, {"model": model, **extra})
    return out


def _design_arrays(section, c, ny, cooling, shape, n) -> tuple:
    """The kernel's design, coil-table and muscle arrays of designs of ``shape`` (``n``
    of them): ``section`` the checked (a, t, b, L, psi) [m, rad], ``c`` the coil index [-],
    ``ny`` the nylon arrays."""
    flat = lambda x: _flat(x, shape, n)  # noqa: E731
    if shape == ():  # one design: its six inputs as the rows of one read-only block
        block = np.array([*section, c], dtype=float).reshape(6, 1)
        block.flags.writeable = False
        designs = tuple(block[:5])
        c_flat = block[5]
    else:
        designs = tuple(flat(x) for x in section)
        c_flat = flat(c)
    table = ny["coil_index_table"]
    s_max = _interp(c_flat, _rows(table, shape), _rows(ny["stroke_max_table"], shape))
    strength = _interp(c_flat, _rows(table, shape), _rows(ny["tensile_strength_table"], shape))
    d_f = flat(ny["fibre_diameter"])
    force_limit = strength * (np.pi * d_f**2 / 4.0)
    width = d_f * (c_flat + 1.0)
    muscle = [flat(ny[k]) for k in _MUSCLE_FIELDS]
    r_per_len = _coil_resistances(flat(ny["resistance_per_length"]),
                                  flat(ny["resistance_coil_index"]), c_flat)
    loss_per_len = _heat_loss(cooling, d_f, flat(ny["t_max"]), flat(ny["t_amb"]), c_flat,
                              flat(ny["heat_loss_per_length"]))
    coil = (s_max, force_limit, width, r_per_len, loss_per_len)
    # a copy is writeable, a view read-only: all read-only, one array type (see _run)
    return (tuple(map(_frozen, designs)), tuple(map(_frozen, coil)),
            tuple(map(_frozen, muscle)))


def _one_named_design(section, c: float, ny: dict) -> tuple:
    """:func:`_design_arrays` of one design of a named nylon set without a cooling set,
    with scalar arithmetic (the same operations, the same bits): the design and coil-table
    arrays as the rows of one read-only block."""
    table = ny["coil_index_table"]
    s_max = np.interp(c, table, ny["stroke_max_table"])
    strength = np.interp(c, table, ny["tensile_strength_table"])
    d_f = float(ny["fibre_diameter"])
    force_limit = strength * (np.pi * d_f**2 / 4.0)
    width = d_f * (c + 1.0)
    r_per_len = coil_resistance(float(ny["resistance_per_length"]),
                                float(ny["resistance_coil_index"]), c)
    block = np.array([*section, s_max, force_limit, width, r_per_len,
                      ny["heat_loss_per_length"]], dtype=float).reshape(10, 1)
    block.flags.writeable = False
    return tuple(block[:5]), tuple(block[5:])


def _coil_resistances(r_ref, c_ref, c) -> np.ndarray:
    """r'(C) [ohm/m] of each design (:func:`~nylonflex.physics.thermal.coil_resistance`, the
    same bits), computed once per distinct coil index where the set's r'_ref and C_r are the
    same for every design (a batch or a sampled slab repeats a few coil indices: the
    Python-level formula once a design was a fifth of a sampled sweep's time)."""
    if c.size == 1:  # one design: the formula once, no search for distinct indices
        return np.array([coil_resistance(r_ref[0], c_ref[0], c[0])], dtype=float)
    if r_ref.size and np.all(r_ref == r_ref[0]) and np.all(c_ref == c_ref[0]):
        values, where = np.unique(c, return_inverse=True)
        one = np.array([coil_resistance(r_ref[0], c_ref[0], x) for x in values], dtype=float)
        return one[where.reshape(-1)]
    return np.vectorize(coil_resistance, otypes=[float])(r_ref, c_ref, c)


def _heat_loss(cooling, d_f, t_max, t_amb, c, own):
    """lambda' [W/(K m)] of each design: the set's own without ``cooling``, else the
    cooling set's correlation at d_f (C + 1) and T_s = t_max, once per distinct design
    (docs/model.md s. 9)."""
    if cooling is None:
        return own

    env = cooling_parameters(cooling)
    keys, inverse = np.unique(np.stack([d_f, t_max, t_amb, c]), axis=1, return_inverse=True)
    values = np.array([convection_loss_per_length(k[0] * (k[3] + 1.0), k[1], k[2], env.fluid,
                                                  env.speed) for k in keys.T])
    return np.ascontiguousarray(values[inverse.reshape(-1)])


def _flat(x, shape, n):
    """``x`` broadcast to ``shape``, as a read-only contiguous 1-D float array of ``n``.

    A scalar (the common single-design case) is filled directly, 2 us instead of the
    broadcast's 10; either way the same values and the same array type (read-only, C), so
    the kernel is the one compiled body.
    """
    if isinstance(x, float) or (isinstance(x, np.ndarray) and x.ndim == 0):
        out = np.full(n, x, dtype=float)
        out.flags.writeable = False
        return out
    return np.ascontiguousarray(np.broadcast_to(x, shape), float).reshape(-1)


def _materials(silicone, nylon):
    """``(ogden, stretch_max, nylon arrays)`` of the material arguments, checked.

    Named sets (strings, the usual case) are prepared once a process
    (:func:`_named_materials`): a single design spent 0.6 ms here on every call. The
    cached nylon arrays are read-only; the Ogden arrays are copied (the kernel's record
    takes them writable, one compiled type).
    """
    if isinstance(silicone, str) and isinstance(nylon, str):
        (mu, alpha), stretch_max, ny = _named_materials(silicone, nylon)
        return (mu.copy(), alpha.copy()), stretch_max, dict(ny)
    ogden = _silicone_arrays(silicone)
    stretch_max = _stretch_max(silicone)
    ny = _nylon_arrays(nylon)
    check_stroke_shape(*(ny[k] for k in ("t_max", "t_amb", "gamma", "beta", "t_g",
                                          "sigma_g")))
    return ogden, stretch_max, ny


@lru_cache(maxsize=64)
def _named_materials(silicone: str, nylon: str):
    """:func:`_materials` of two set names (the registry's sets do not change)."""
    ogden = _silicone_arrays(silicone)
    stretch_max = _stretch_max(silicone)
    ny = _nylon_arrays(nylon)
    check_stroke_shape(*(ny[k] for k in ("t_max", "t_amb", "gamma", "beta", "t_g",
                                          "sigma_g")))
    for value in ny.values():
        value.flags.writeable = False
    return ogden, stretch_max, ny


def _batch_shapes(ogden, ny) -> list:
    """The shapes the material arrays add to the designs' broadcast (tables: columns off)."""
    return [ogden[0].shape[:-1], ogden[1].shape[:-1], ny["coil_index_table"].shape[:-1],
            ny["stroke_max_table"].shape[:-1], ny["tensile_strength_table"].shape[:-1],
            *(np.shape(v) for k, v in ny.items() if k not in NYLON_TABLES)]


@lru_cache(maxsize=64)
def _named_batch(silicone: str, nylon: str) -> list:
    """:func:`_batch_shapes` of two named sets (all scalars: every shape ``()``)."""
    ogden, _, ny = _named_materials(silicone, nylon)
    return _batch_shapes(ogden, ny)


@lru_cache(maxsize=16)
def _single_muscle(nylon: str) -> tuple:
    """The muscle record's arrays of one design of a named nylon set (read-only, cached),
    as ``_flat`` makes them."""
    ny = _nylon_arrays(nylon)
    return tuple(_flat(ny[k], (), 1) for k in _MUSCLE_FIELDS)


def _stretch_max(silicone) -> float:
    """Top of the silicone set's fitted stretch range [-] (inf when it records none)."""
    base = silicone
    if isinstance(silicone, Mapping):
        base = {k: v for k, v in silicone.items() if np.ndim(v) <= 1 or k == "stretch_range"}
        base = {k: v for k, v in base.items() if k not in _SILICONE_FIELDS}
    return float(silicone_parameters(base).stretch_range[1])


def _run(shape, n, design_arrays, coil_arrays, ogden, muscle, options):
    kernels, (CoilTable, Muscle, Nodes, Ogden, Options, PointDesigns, PointOut) = _kernels()

    # the Ogden rows writeable, every other record field read-only (_design_arrays): one
    # array type per field whatever path made the array, as Numba compiles the kernel once
    # for every new type
    mu, alpha = (np.require(x.reshape(-1, x.shape[-1]), float, ["C", "W"]) for x in
                 _silicone_rows(ogden, shape))
    out = PointOut(np.empty((N_FLOAT_DESIGN, n)), np.empty((N_FLAGS, n), dtype=np.int8))
    nodes = Nodes(*quadrature_nodes())
    args = (PointDesigns(*design_arrays), CoilTable(*coil_arrays), Ogden(mu, alpha), nodes,
            Muscle(*muscle), Options(*options), P_ATM, out)
    run_chunks(lambda i0, i1: kernels.design_points(*args, node_scratch(nodes), i0, i1), n,
               parallel=n >= _PARALLEL_FROM)
    return _named_rows(out.design.reshape(N_FLOAT_DESIGN, *shape),
                       out.flags.reshape(N_FLAGS, *shape))


#: ``(name, is_flag, index)`` of each design variable in the registry's order: its row of
#: the kernel's ``design`` or ``flags`` (kernels.rows, the one table both sides read).
_ROWS = tuple((name, name in FLAG_ROWS, (FLAG_ROWS[name] if name in FLAG_ROWS
                                         else DESIGN_ROWS[name], Ellipsis)) for name in DESIGN)


def _named_rows(design, flags) -> dict:
    """The kernel's output rows by name, in the registry's order (views)."""
    return {name: flags[index] if flag else design[index] for name, flag, index in _ROWS}


def _named_numbers(out) -> dict:
    """:func:`_named_rows` of one design's output as Python floats and ints (the numbers
    that ``float()`` and ``int()`` of its 0-d arrays give)."""
    design, flags = out.design[:, 0].tolist(), out.flags[:, 0].tolist()
    return {name: flags[index[0]] if flag else design[index[0]] for name, flag, index in _ROWS}


def _frozen(x: np.ndarray) -> np.ndarray:
    """``x`` (a contiguous float64 array, made here) marked read-only: the one type the
    pointwise kernel's 1-D record fields are compiled for."""
    x.flags.writeable = False
    return x


@lru_cache(maxsize=1)
def _kernels():
    """The pointwise kernels' module and records, imported on first use (Numba)."""
    from ..kernels import design as kernels

    return kernels, (CoilTable, Muscle, Nodes, Ogden, Options, PointDesigns, PointOut)


def design_limits(radius, wall_thickness, length, coil_index, wrap_angle, base_thickness=None,
                  silicone="tc5005", nylon="silver_nylon66", model="paper",
                  supply_voltage=None, cooling=None):
    """Every design variable of the cube for one design or broadcastable arrays of them.

    The compiled :func:`evaluate` with docs/interface.md's positional signature: floats (and an
    int ``limit``) for scalar input, arrays of the broadcast shape otherwise. Arguments,
    units and errors as :func:`evaluate`; docs/model.md s. 8.
    """
    if cooling is None and isinstance(silicone, str) and isinstance(nylon, str):
        one = _one_design((radius, wall_thickness, base_thickness, length, wrap_angle,
                           coil_index), silicone, nylon, model, supply_voltage, None)
        if one is not None:
            return _named_numbers(one)
    out = evaluate(radius, wall_thickness, length, coil_index, wrap_angle,
                   base_thickness=base_thickness, silicone=silicone, nylon=nylon, model=model,
                   supply_voltage=supply_voltage, cooling=cooling)
    if out["limit"].ndim:
        return out
    return {name: int(v) if name in ("limit", "validity") else float(v)
            for name, v in out.items()}


# ------------------------------------------------------------------------- one design

#: The registry ranges of the inputs the one-design path tests as floats, in
#: :func:`evaluate`'s order of checks (what :func:`~nylonflex.physics.check_input` tests).
_V_RANGE, _A_RANGE, _T_RANGE, _B_RANGE, _L_RANGE, _PSI_RANGE = (
    input_range(name) for name in ("supply_voltage", "radius", "wall_thickness",
                                   "base_thickness", "length", "wrap_angle"))


def _one_design(inputs, silicone: str, nylon: str, model, supply_voltage, chamber):
    """The kernel's output (a :class:`~nylonflex.kernels.records.PointOut` of one column)
    of one design of two named sets without a cooling set: :func:`evaluate`'s general path
    (its checks in its order, as float comparisons; the records of the sets made once a
    process; the same numbers into the same compiled kernel), a quarter of its time.

    ``inputs`` holds radius, wall_thickness, base_thickness, length, wrap_angle and
    coil_index. None where one of them is not a float in its range, or the model or the
    supply voltage is not accepted: the general path checks those, and refuses with its
    message. A set's refusal, the chamber's and the supply's (rise) are raised here, as the
    general path raises them at the same point of its checks.
    """
    a, t, b, length, psi, c = inputs
    if not (model in MODELS
            and (supply_voltage is None or float_in_range(supply_voltage, *_V_RANGE))
            and float_in_range(a, *_A_RANGE) and float_in_range(t, *_T_RANGE)
            and (b is None or float_in_range(b, *_B_RANGE))
            and float_in_range(length, *_L_RANGE) and float_in_range(psi, *_PSI_RANGE)):
        return None
    sets = _one_design_sets(silicone, nylon)
    if not (isinstance(c, float) and math.isfinite(c) and sets.c_lo <= c <= sets.c_hi):
        return None
    voltage = -1.0 if supply_voltage is None else float(supply_voltage)
    options = sets.options[MODELS.index(model)] if voltage < 0.0 and chamber is None else \
        Options(MODELS.index(model), voltage, sets.stretch_max, sealed_coefficients(chamber))
    c = float(c)
    arrays = _one_arrays()  # _one_named_design's values, its operations
    arrays.values[:] = (a, t, t if b is None else b, length, psi,
                        _table_value(c, sets.coil_index, sets.stroke_max),
                        _table_value(c, sets.coil_index, sets.strength) * sets.fibre_area,
                        sets.fibre_diameter * (c + 1.0),
                        coil_resistance(sets.r_ref, sets.c_ref, c), sets.loss_per_len)
    out = PointOut(np.empty((N_FLOAT_DESIGN, 1)), np.empty((N_FLAGS, 1), dtype=np.int8))
    _point_call((arrays.designs, arrays.coil, sets.ogden, arrays.nodes, sets.muscle, options,
                 P_ATM, out, arrays.table, 0, 1))
    if voltage > 0.0:  # check_supply_rise checks nothing without a supply
        check_supply_rise(voltage, out.design[DESIGN_ROWS["muscle_length"], 0],
                          arrays.values[8], arrays.values[9], "supply_voltage")
    return out


class _OneSets:
    """What the one-design path reads of two named sets (:func:`_one_design_sets`)."""

    def __init__(self, silicone: str, nylon: str):
        (mu, alpha), stretch_max, ny = _named_materials(silicone, nylon)
        self.stretch_max = stretch_max
        # the general path's records of one design: the Ogden rows a writable copy, every
        # muscle field a read-only array of one (_run, _single_muscle)
        self.ogden = Ogden(mu.copy().reshape(1, -1), alpha.copy().reshape(1, -1))
        self.muscle = Muscle(*_single_muscle(nylon))
        self.options = tuple(Options(i, -1.0, stretch_max, sealed_coefficients(None))
                             for i in range(len(MODELS)))
        # _one_named_design's constants (floats, the same operations; the tables as
        # tuples of floats for _table_value)
        self.coil_index, self.stroke_max, self.strength = (
            tuple(ny[k].tolist()) for k in ("coil_index_table", "stroke_max_table",
                                             "tensile_strength_table"))
        self.c_lo, self.c_hi = self.coil_index[0], self.coil_index[-1]
        self.fibre_diameter = float(ny["fibre_diameter"])
        self.fibre_area = np.pi * self.fibre_diameter**2 / 4.0
        self.r_ref = float(ny["resistance_per_length"])
        self.c_ref = float(ny["resistance_coil_index"])
        self.loss_per_len = float(ny["heat_loss_per_length"])


def _table_value(x: float, xs: tuple, ys: tuple) -> float:
    """``np.interp(x, xs, ys)`` of one ``x`` in [xs[0], xs[-1]] (a named set's table, its
    nodes increasing) in float arithmetic, 2 us less: NumPy's operations, so its bits
    (tests/test_one_design.py; :func:`_interp` repeats them too). The last node at or below
    x; at a node its value, else the slope times the offset plus the left value (from the
    right where that is NaN, the value where both are)."""
    j = bisect_right(xs, x) - 1
    if j == len(xs) - 1 or xs[j] == x:
        return ys[j]
    slope = (ys[j + 1] - ys[j]) / (xs[j + 1] - xs[j])
    y = slope * (x - xs[j]) + ys[j]
    if math.isnan(y):
        y = slope * (x - xs[j + 1]) + ys[j + 1]
        if math.isnan(y) and ys[j] == ys[j + 1]:
            y = ys[j]
    return y


@lru_cache(maxsize=64)
def _one_design_sets(silicone: str, nylon: str) -> _OneSets:
    """:class:`_OneSets` of two set names, made once a process (the registry's sets do not
    change; the kernel only reads them)."""
    return _OneSets(silicone, nylon)


class _OneArrays:
    """A thread's arrays of the one-design path (its own: the kernel runs without the GIL).

    ``values`` holds the design's radius, wall, base, length, wrap and its coil table's
    s_max, force limit, width, r' and lambda', rewritten on each call; ``designs`` and
    ``coil`` are the kernel's records of them, one read-only row each as the general
    path's (the one compiled type). ``nodes`` is the quadrature of
    :data:`~nylonflex.physics.bending.QUADRATURE_ORDERS` (constants, read once a thread)
    and ``table`` the node table the kernel fills.
    """

    def __init__(self):
        block = np.zeros((10, 1))
        rows = list(block)
        for row in rows:
            row.flags.writeable = False
        self.values = block.reshape(10)
        self.designs = PointDesigns(*rows[:5])
        self.coil = CoilTable(*rows[5:])
        self.nodes = Nodes(*quadrature_nodes())
        self.table = node_scratch(self.nodes)


_THREAD = threading.local()


def _one_arrays() -> _OneArrays:
    """This thread's :class:`_OneArrays`, made on its first one-design call."""
    try:
        return _THREAD.arrays
    except AttributeError:
        _THREAD.arrays = _OneArrays()
        return _THREAD.arrays


#: The pointwise kernel's compiled entry for the one-design path's arguments, found on its
#: first call (:func:`nylonflex.kernels.design.points_entry`).
_ENTRY = {}


def _point_call(args) -> None:
    """The pointwise kernel on the one-design path's ``args``: the first call through
    Numba's dispatcher (which compiles or loads it, with its notice), the later ones
    straight into the compiled code it ran (the same records, the same types)."""
    entry = _ENTRY.get("one")
    if entry is not None:
        entry(*args)
        return
    kernels = _kernels()[0]
    kernels.design_points(*args)
    _ENTRY["one"] = kernels.points_entry(args)


# --------------------------------------------------------------------------- materials

def _short(value, n=40):
    return short(value, n)


def _split(kind, value, table, fields):
    """(base set object, {field: array override}) of a material argument."""
    if isinstance(value, (Silicone, Nylon)) or isinstance(value, str):
        return value, {}
    if not isinstance(value, Mapping):
        raise ValueError(f"{kind}: must be a set name, a mapping with 'set' or a material "
                         f"object, got {_short(value)}")
    arrays = {k: v for k, v in value.items() if k != "set" and k in fields and np.ndim(v) > 1}
    scalar = {k: v for k, v in value.items() if k not in arrays}
    return scalar, arrays


def _as_array(kind, key, value):
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{kind}.{key}: must be numbers, got {_short(value)}") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{kind}.{key}: must be finite, got {arr[~np.isfinite(arr)].flat[0]:g}")
    return arr


def _silicone_arrays(silicone):
    """``(mu, alpha)`` arrays of shape (..., terms) of a silicone argument, checked."""
    base, arrays = _split("silicone", silicone, SILICONE_PARAMETERS, _SILICONE_FIELDS)
    if not arrays:
        s = silicone_parameters(base)
        return np.asarray(s.mu, float), np.asarray(s.alpha, float)
    s = silicone_parameters({k: v for k, v in base.items()})  # the set and scalar fields
    mu = _as_array("silicone", "mu", arrays.get("mu", s.mu))
    alpha = _as_array("silicone", "alpha", arrays.get("alpha", s.alpha))
    if mu.shape[-1] != alpha.shape[-1]:
        raise ValueError("silicone.mu/alpha: need the same number (1 to 6) of terms on the "
                         f"last axis, got shapes {mu.shape} and {alpha.shape}")
    name = base.get("set") if isinstance(base, Mapping) else None
    check_silicone(mu, alpha, kind=silicone_kind(base),
                   name=name if isinstance(name, str) else None)
    return mu, alpha


def _silicone_rows(ogden, shape):
    mu, alpha = ogden
    if mu.ndim == 1 and alpha.ndim == 1:
        return mu.reshape(1, -1), alpha.reshape(1, -1)
    k = mu.shape[-1]
    return (np.broadcast_to(mu, (*shape, k)), np.broadcast_to(alpha, (*shape, k)))


def _nylon_arrays(nylon) -> dict:
    """Every numeric field of a nylon argument as an array (tables: columns last), checked."""
    base, arrays = _split("nylon", nylon, NYLON_PARAMETERS, NYLON_TABLES)
    numeric = {k: v for k, v in (base.items() if isinstance(base, Mapping) else ())
               if k != "set" and np.ndim(v) > 0 and k not in NYLON_TABLES}
    scalar_base = {k: v for k, v in base.items() if k not in numeric} \
        if isinstance(base, Mapping) else base
    ny = nylon_parameters(scalar_base)
    out = {k: np.asarray(v, float) for k, v in ny.to_dict().items() if k != "name"}
    # to_dict leaves a resistance_coil_index of 0 out (the set's hash); the kernel needs it
    out.setdefault("resistance_coil_index", np.asarray(ny.resistance_coil_index, float))
    for key, value in {**numeric, **arrays}.items():
        out[key] = _as_array("nylon", key, value)
    if not numeric and not arrays:
        return out
    check_nylon(out)  # the named sets' own validator, on the arrays
    return out


def _rows(table, shape):
    """A table as (m,) when shared by every design, else (n, m) one row a design."""
    if table.ndim == 1:
        return table
    return np.ascontiguousarray(np.broadcast_to(table, (*shape, table.shape[-1]))).reshape(
        -1, table.shape[-1])


def _interp(x, xp, fp):
    """``np.interp`` of each design's coil index in its own table (rows of ``xp``, ``fp``).

    With 1-D tables this is ``np.interp`` itself; with per-design tables it repeats
    NumPy's arithmetic (slope times offset plus the left value; a node returns its value)
    so both give the same bits.
    """
    if xp.ndim == 1 and fp.ndim == 1:
        return np.interp(x, xp, fp)
    xp, fp = np.broadcast_arrays(np.atleast_2d(xp), np.atleast_2d(fp))
    xp = np.broadcast_to(xp, (x.size, xp.shape[-1]))
    fp = np.broadcast_to(fp, (x.size, fp.shape[-1]))
    m = xp.shape[-1]
    if m == 1:
        return fp[:, 0].copy()
    j = np.clip(np.sum(xp[:, 1:] <= x[:, None], axis=1), 0, m - 2)
    rows = np.arange(x.size)
    x0, x1, y0, y1 = xp[rows, j], xp[rows, j + 1], fp[rows, j], fp[rows, j + 1]
    slope = (y1 - y0) / (x1 - x0)
    out = slope * (x - x0) + y0
    out = np.where(x == x0, y0, out)
    return np.where(x == xp[:, -1], fp[:, -1], out)
