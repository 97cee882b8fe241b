"""One slab of one model through the grid kernel: its inputs from a config, its rows by name.

:func:`model_slab` is what the grid (:mod:`.grid`, a cube's slabs) and the sampled path
(:mod:`.sampled`, every sample a grid of its own) call: the config's axes and materials as
the kernel's records (:mod:`nylonflex.kernels.records`), one call of
:func:`nylonflex.kernels.design.design_slab` split over the engine's threads, and the
kernel's output rows named by the registry (:mod:`nylonflex.kernels.rows`).
"""

from __future__ import annotations

import numpy as np

from ..config import ResolvedConfig
from ..kernels.records import CoilTable, GridAxes, GridOut, Muscle, Nodes, Ogden, Options
from ..kernels.rows import DESIGN_ROWS, FLAG_ROWS, N_FLAGS, N_FLOAT_DESIGN
from ..physics.bending import quadrature_nodes
from ..physics.chamber import P_ATM
from ..physics.nylon import nylon_force_limit, stroke_max
from ..physics.records import SealedCoefficients
from ..physics.sealed import anchored_coefficients, sealed_coefficients
from ..physics.thermal import coil_heat_loss_per_length, coil_resistance_per_length
from ..physics.wrap import muscle_width
from ..variables import CURVES, DESIGN
from .threads import run_chunks

__all__ = ["coil_table", "grid_axes", "grid_out", "kernel_inputs", "model_slab", "muscle_record",
           "named_rows", "paper_kernel", "run_grid"]


def coil_table(cfg: ResolvedConfig):
    """The kernels' per-coil-index table (:class:`~nylonflex.kernels.records.CoilTable`) of
    ``cfg``'s coil-index axis: s_max [-], force limit [N], muscle width [m], r' [ohm/m] and
    heat loss per length [W/(K m)], one contiguous float64 column each."""
    c = cfg.axes["coil_index"]
    column = lambda x: np.ascontiguousarray(x, dtype=float).reshape(-1)  # noqa: E731
    return CoilTable(column(stroke_max(c, cfg.nylon)), column(nylon_force_limit(c, cfg.nylon)),
                     column(muscle_width(c, cfg.nylon)),
                     column(coil_resistance_per_length(c, cfg.nylon)),
                     column(coil_heat_loss_per_length(c, cfg.nylon, cfg.cooling)))


def muscle_record(cfg: ResolvedConfig) -> Muscle:
    """The muscle's constants as the kernels' :class:`~nylonflex.kernels.records.Muscle` of
    one entry (SI: K, 1/K, ohm/m, J/(K m), W/(K m), N/K)."""
    ny = cfg.nylon
    one = lambda x: np.array([float(x)])  # noqa: E731
    return Muscle(one(ny.t_amb), one(ny.t_max), one(ny.gamma), one(ny.beta), one(ny.t_g),
                  one(ny.sigma_g), one(ny.resistance_per_length),
                  one(ny.heat_capacity_per_length), one(ny.heat_loss_per_length),
                  one(ny.thermal_force_coefficient))


def grid_axes(cfg: ResolvedConfig, i0: int, i1: int) -> GridAxes:
    """The kernel's :class:`~nylonflex.kernels.records.GridAxes` of the radii [i0, i1) of
    ``cfg`` (every other axis whole) [SI]."""
    ax, cv = cfg.axes, cfg.curves
    return GridAxes(radius=_array(ax["radius"][i0:i1]), wall=_array(ax["wall_thickness"]),
                    length=_array(ax["length"]), wrap=_array(ax["wrap_angle"]),
                    base_thickness=-1.0 if cfg.base_thickness is None
                    else float(cfg.base_thickness),
                    stroke=_array(cv["stroke"]), pressure=_array(cv["pressure"]), p_atm=P_ATM)


def _array(x) -> np.ndarray:
    """``x`` as a contiguous, writeable float64 array (a copy where it is not): the one
    array type the compiled kernel was made for. A read-only view (a frozen config's axis)
    is another type to Numba, which would compile the kernel again for it."""
    return np.require(x, dtype=float, requirements=["C", "W"])


def kernel_inputs(cfg: ResolvedConfig, model: int) -> tuple:
    """The grid kernel's arguments after the axes, for one model (index into
    :data:`~nylonflex.physics.limits.MODELS`): the coil table, the silicone's
    :class:`~nylonflex.kernels.records.Ogden`, the quadrature's nodes, the muscle and the
    :class:`~nylonflex.kernels.records.Options`."""
    voltage = -1.0 if cfg.supply_voltage is None else float(cfg.supply_voltage)
    options = Options(model, voltage, float(cfg.silicone.stretch_range[1]),
                      chamber_coefficients(cfg))
    return (coil_table(cfg), Ogden(*cfg.silicone.arrays()), Nodes(*quadrature_nodes()),
            muscle_record(cfg), options)


def chamber_coefficients(cfg) -> SealedCoefficients:
    """``sealed_chamber``'s coefficients for a sweep: the shipped ones, or those anchored on
    its ``chamber:`` file's measured actuator (``physics.sealed.anchored_coefficients``,
    with that actuator's silicone's mu0: the sweep's own silicone then scales K by its mu0,
    sample by sample in a sampled sweep)."""
    chamber = getattr(cfg, "chamber", None)
    if chamber is None:
        return sealed_coefficients()
    return anchored_coefficients(chamber, chamber["initial_shear_modulus"])


def paper_kernel(cfg: ResolvedConfig) -> bool:
    """Whether ``cfg``'s sweep runs the grid kernel of the paper's model without a supply
    (:data:`~nylonflex.kernels.design.design_slab_paper`, a shorter first compile): one
    model, ``paper``, and no supply. A sweep of several models runs the general kernel for
    each, so that its first run compiles one grid kernel, not two."""
    return tuple(cfg.models) == ("paper",) and cfg.supply_voltage is None


def run_grid(grid: GridAxes, inputs: tuple, out: GridOut, parallel: bool, *,
             paper: bool = False) -> None:
    """The grid kernel on ``grid`` with ``inputs`` (:func:`kernel_inputs`) into ``out``,
    split over the engine's threads by (radius, wall) pair when ``parallel``; ``paper``
    (:func:`paper_kernel`) runs the paper's kernel where the slab's model and supply allow
    it (the same bits)."""
    from ..kernels import design

    args = (grid, *inputs, out)
    options = inputs[-1]
    kernel = design.grid_kernel(options.model, options.voltage) if paper else \
        design.design_slab
    nodes = inputs[2]
    run_chunks(lambda k0, k1: kernel(*args, design.grid_scratch(grid, nodes), k0, k1),
               len(grid.radius) * len(grid.wall), parallel=parallel)


def named_rows(out: GridOut) -> dict:
    """The kernel's output rows and curves by the registry's names (views of ``out``)."""
    # the kernel's rows by name (kernels.rows, the one table both sides read)
    arrays = {name: out.design[row] for name, row in DESIGN_ROWS.items()}
    arrays.update({name: out.flags[row] for name, row in FLAG_ROWS.items()})
    arrays.update(nylon_force=out.nylon_force, bend_angle=out.bend_angle,
                  tip_force=out.tip_force)
    return arrays


def model_slab(cfg: ResolvedConfig, i0: int, i1: int, parallel: bool, model: int,
               pool=None) -> dict:
    """Every radius-dependent variable of one model (index into
    :data:`~nylonflex.physics.limits.MODELS`) for the radii [i0, i1) of ``cfg``.

    ``parallel`` splits the kernel over the engine's threads; False runs it in this thread.
    ``pool`` (an :class:`~.grid.ArrayPool`) hands out the output arrays. Returns the
    registry's names of the kernel's rows and curves (views of the output).
    """
    out = grid_out(cfg, i1 - i0, pool)
    run_grid(grid_axes(cfg, i0, i1), kernel_inputs(cfg, model), out, parallel,
             paper=paper_kernel(cfg))
    return named_rows(out)


def grid_out(cfg: ResolvedConfig, n_radii: int, pool=None) -> GridOut:
    """The kernel's output arrays (:class:`~nylonflex.kernels.records.GridOut`) of
    ``n_radii`` radii of ``cfg``, from ``pool`` where given."""
    sizes = {k: len(v) for k, v in {**cfg.axes, **cfg.curves}.items()}
    sizes["radius"] = n_radii
    shape = lambda name: [sizes[d] for d in CURVES[name].dims]  # noqa: E731
    design_shape = [sizes[d] for d in DESIGN["limit"].dims]
    empty = np.empty if pool is None else pool.empty
    return GridOut(design=empty((N_FLOAT_DESIGN, *design_shape)),
                   flags=empty((N_FLAGS, *design_shape), dtype=np.int8),
                   nylon_force=empty(shape("nylon_force")),
                   bend_angle=empty(shape("bend_angle")),
                   tip_force=empty(shape("tip_force")))
