"""One design of :func:`~nylonflex.engine.pointwise.evaluate` and
:func:`~nylonflex.engine.pointwise.design_limits` (issue 49): float inputs, two named sets,
no cooling set. The general path's checks in its order as float comparisons, the sets'
records made once a process, a thread's own design arrays rewritten each call, and the
pointwise kernel called through its compiled entry, without Numba's typing of its seven
records (benchmarks/README.md, "One design"). Also the kernel's rows by name, which both
paths return."""

from __future__ import annotations

import math
import threading
from bisect import bisect_right
from functools import lru_cache

import numpy as np

from ..kernels.records import CoilTable, Muscle, Nodes, Ogden, Options, PointDesigns, PointOut
from ..kernels.rows import DESIGN_ROWS, FLAG_ROWS, N_FLAGS, N_FLOAT_DESIGN
from ..kernels.scratch import node_scratch
from ..physics import float_in_range, input_range
from ..physics.bending import quadrature_nodes
from ..physics.chamber import P_ATM
from ..physics.limits import MODELS  # the model variants (docs/model.md s. 16)
from ..physics.sealed import sealed_coefficients
from ..physics.thermal import check_supply_rise, coil_resistance
from ..variables import DESIGN
from .point_sets import _named_materials, _single_muscle

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


@lru_cache(maxsize=1)
def _kernels():
    """The pointwise kernels' module and records, imported on first use (Numba)."""
    from ..kernels import design as kernels

    return kernels, (CoilTable, Muscle, Nodes, Ogden, Options, PointDesigns, PointOut)


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


