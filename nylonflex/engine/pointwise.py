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

import numpy as np

from ..kernels.rows import N_FLAGS, N_FLOAT_DESIGN
from ..kernels.scratch import node_scratch
from ..materials import cooling_parameters
from ..physics import check_input, check_section, check_wrap_angle
from ..physics.bending import quadrature_nodes
from ..physics.chamber import P_ATM
from ..physics.limits import MODELS  # the model variants (docs/model.md s. 16)
from ..physics.sealed import sealed_coefficients
from ..physics.thermal import check_supply_rise, coil_resistance, convection_loss_per_length
from ..variables import AXES
from .one_design import _kernels, _named_numbers, _named_rows, _one_design
from .point_sets import (_MUSCLE_FIELDS, _batch_shapes, _flat, _interp, _materials,
                         _named_batch, _rows, _short, _silicone_rows, _single_muscle)
from .results import to_dataset
from .threads import run_chunks

__all__ = ["MODELS", "design_limits", "evaluate"]

#: Designs below which the kernel runs in the calling thread (threads cost more than they save).
_PARALLEL_FROM = 64


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


def _frozen(x: np.ndarray) -> np.ndarray:
    """``x`` (a contiguous float64 array, made here) marked read-only: the one type the
    pointwise kernel's 1-D record fields are compiled for."""
    x.flags.writeable = False
    return x


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


