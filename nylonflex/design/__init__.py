"""Design from a specification: the best design or the Pareto set, refined off the grid.

>>> import nylonflex as nf
>>> res = nf.run_design("configs/design_force.yaml")       # doctest: +SKIP
>>> res.designs[0]["tip_force_max"], res.designs[0]["source"]  # doctest: +SKIP

Stages: (1) the grid: the cube's feasible designs and the best of them (one objective) or
their non-dominated set (several); (2) with ``refine``, continuous optimisation over the
axes with the exact model (:mod:`.refine`); (3) every reported design re-evaluated exactly
and dropped if it violates a constraint; (4) with a ``resolution``, every design snapped to
it and re-checked exactly, and designs equal in every objective merged into one row
(:mod:`.resolution`, a step of its own after refinement).
"""

from __future__ import annotations

import functools
import html
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import parse_config
from ..engine.provenance import cube_settings
from ..query import COLUMNS, HEADLINE as _HEADLINE
from ..query.frames import html_table, rows_frame
from ..storage import open_cube
from ..sweep.conductor import run_sweep
from ..units import InputError
from ..variables import AXES, DESIGN
from .refine import Model, _bounds, evaluate_rows, meets, refine
from .resolution import (check_fixed, check_steps, lattice_search, merge_equal, same_intervals,
                         snap)
from .search import CUBE_ONLY, GridScan, nondominated, scan_grid
from .spec import DesignSpec, Objective, load_spec, parse_spec

__all__ = ["DesignResult", "DesignSpec", "Objective", "load_spec", "nondominated",
           "parse_spec", "run_design"]


@dataclass
class DesignResult:
    """The answer to a spec.

    Attributes
    ----------
    spec : DesignSpec
    designs : list of dict
        The reported designs, each with every axis and design variable [SI] (exactly
        re-evaluated) and ``source`` (``"grid"`` or ``"refined"``). One objective: the best
        design (refined, when refinement beat the grid) and the best grid point. Several:
        the front (refined when ``refine``, else the grid's), ordered by the first objective.
    grid_front : dict of str to numpy.ndarray
        The grid's best rows (one objective) or non-dominated set (several), exact values.
    refined_front : dict of str to numpy.ndarray
        Several objectives with ``refine``: the non-dominated set of the grid front and the
        refined designs; else empty.
    scan : GridScan
        Totals, the feasible cloud and, when infeasible, the reasons.
    evaluations : int
        Exact model evaluations.
    dropped : int
        Reported candidates dropped because exact re-evaluation broke a constraint.
    snapped : dict
        With a ``resolution``: ``steps`` {axis: SI step}, ``candidates`` (on-resolution
        designs that met every constraint exactly) and ``lost`` (designs none of whose
        on-resolution neighbours did); with several objectives or a resolution, ``merged``
        (rows equal in every objective merged into one, see ``alternatives``).
    """

    spec: DesignSpec
    designs: list
    grid_front: dict
    refined_front: dict
    scan: GridScan
    evaluations: int
    dropped: int = 0
    improvement: dict = field(default_factory=dict)
    snapped: dict = field(default_factory=dict)
    #: The model variant the designs were scanned, re-checked and refined under.
    model: str = "paper"

    def reported_rows(self) -> dict:
        """The designs reported, one row each, as the table, JSON and CSV list them and
        the chart draws and counts them (one count everywhere): ``{column: array}`` [SI]."""
        keys = [k for k in (self.designs[0] if self.designs else dict.fromkeys(COLUMNS))
                if k not in ("source", "alternatives")]
        return {k: np.array([float(d[k]) for d in self.designs], dtype=float) for k in keys}

    @property
    def feasible(self) -> bool:
        return bool(self.designs)

    def _columns(self):
        names = [n for n in (*AXES, *DESIGN) if self.designs and n in self.designs[0]]
        columns = {n: np.array([d[n] for d in self.designs], dtype=float) for n in names}
        return names, columns, {"source": [d.get("source", "") for d in self.designs]}

    def to_dataframe(self):
        """The reported designs as a pandas DataFrame, one row each: ``source`` (grid or
        refined), every axis and design variable in SI (``df.attrs["units"]``)."""
        names, columns, extra = self._columns()
        return rows_frame(columns, names, extra)

    def _repr_html_(self) -> str:
        """The reported designs as an HTML table in display units, or why none is."""
        if not self.designs:
            items = "".join(f"<li>{html.escape(r)}</li>" for r in self.reasons)
            return f"<p>no design meets the spec:</p><ul>{items}</ul>"
        names, columns, extra = self._columns()
        shown = [n for n in names if n in AXES or n in _HEADLINE]
        caption = (f"{len(self.designs)} design(s) under model {self.model}; "
                   f"{self.evaluations} exact evaluations")
        return html_table(columns, shown, len(self.designs), caption, extra)

    @property
    def reasons(self) -> list:
        if self.designs or self.scan.reasons or not self.scan.feasible:
            return self.scan.reasons
        # the grid met the spec, but every candidate broke a constraint when evaluated
        # exactly: it sits on a constraint's boundary, within the cube's last bits
        return [f"the {self.dropped} best grid design(s) meeting the constraints in the cube "
                "break one when evaluated exactly (they sit on a constraint's bound, within "
                "the cube's rounding); loosen that bound slightly"]


def _materials(ds, spec):
    """The model with the materials, model variant (and supply) the cube was computed with,
    from its attributes; evaluations are remembered per cube config.

    The cube's own variant re-checks and refines its designs (a cube swept with
    ``model: fe_calibrated`` is answered under it, whatever the spec's default); a cube of
    several variants is refused, since its rows would mix them.
    """
    try:
        s = cube_settings(ds)
    except ValueError as err:
        raise InputError(str(err)) from None
    if len(s.models) != 1:
        raise InputError(f"cube: holds {len(s.models)} model variants ({', '.join(s.models)}); "
                         "design answers one: sweep the grid with one model, or give a "
                         "grid: spec with model: NAME")
    if s.coolings:
        raise InputError(f"cube: holds {len(s.coolings)} cooling sets ("
                         f"{', '.join(c.label for c in s.coolings)}); design answers one: sweep "
                         "the grid with one cooling set")
    return Model(s.silicone, s.nylon, s.base_thickness, s.models[0], _memo(s),
                 supply_voltage=s.supply_voltage, cooling=s.cooling, chamber=s.chamber)


@functools.lru_cache(maxsize=8)
def _memo(settings) -> dict:
    """The designs evaluated under one cube's settings (shared between runs on it)."""
    return {}


def _open(spec, cube):
    if cube is not None or spec.cube is not None:
        return open_cube(Path(cube if cube is not None else spec.cube), quiet=True)
    return run_sweep(parse_config(spec.sweep, "grid"))


def _rows(records) -> dict:
    keys = records[0].keys() if records else COLUMNS
    return {k: np.array([r[k] for r in records], dtype=float) for k in keys}


def _records(rows, source) -> list:
    n = len(rows["radius"])
    return [{**{k: float(v[i]) for k, v in rows.items()}, "source": source}
            for i in range(n)]


def run_design(spec, cube=None, progress=None) -> DesignResult:
    """Answer a design spec.

    Parameters
    ----------
    spec : DesignSpec, dict or path
        The spec, its mapping or its YAML file.
    cube : path or xarray.Dataset, optional
        Overrides the spec's start (a cube file or an opened cube).
    progress : callable, optional
        Called as ``progress(done, total)`` [refinement starts] as refinement goes.

    Returns
    -------
    DesignResult

    Raises
    ------
    InputError
        A malformed spec or a missing cube.
    """
    if isinstance(spec, (str, Path)):
        spec = load_spec(spec)
    elif isinstance(spec, dict):
        spec = parse_spec(spec)
    own = not hasattr(cube, "data_vars")
    ds = _open(spec, cube) if own else cube
    try:
        model = _materials(ds, spec)
        check_steps(spec.resolution, {a: (float(ds[a].min()), float(ds[a].max()))
                                      for a in spec.resolution})
        multi = len(spec.objectives) > 1
        scan = scan_grid(ds, spec, keep=1 if multi else max(1, spec.starts))
    finally:
        if own:
            ds.close()
    refined = refine(model, spec, scan, progress) if spec.refine and scan.feasible else []

    # every reported design, exactly, once more; drop any that breaks a constraint
    grid = evaluate_rows(model, scan.best)
    # the cube-only columns (tracking_*) of grid designs come from the cube
    grid.update({k: v for k, v in scan.best.items() if k in CUBE_ONLY})
    ok = meets(spec, grid, scan.fixed)
    dropped = int((~ok).sum())
    grid = {k: v[ok] for k, v in grid.items()}
    new = evaluate_rows(model, _rows(refined)) if refined else {k: np.empty(0) for k in grid}
    ok = meets(spec, new, scan.fixed)
    dropped += int((~ok).sum())
    new = {k: v[ok] for k, v in new.items()}
    snapped = {}
    if spec.resolution:  # a separate step after refinement (nylonflex.design.resolution)
        grid, new, snapped = _on_resolution(model, spec, scan, grid, new)

    signs = np.array([o.sign for o in spec.objectives])

    def F(rows):
        return np.column_stack([rows[o.name] for o in spec.objectives]) * signs

    improvement = {}
    refined_front = {k: np.empty(0) for k in grid}
    if not multi:
        grid = {k: v[:1] for k, v in grid.items()}
        designs = _records(grid, "grid")
        if len(new["radius"]):
            k = int(np.argmin(F(new)[:, 0]))
            if not len(grid["radius"]) or F(new)[k, 0] < F(grid)[0, 0]:
                designs = _records({n: v[k:k + 1] for n, v in new.items()}, "refined") + designs
        if spec.refine and designs:
            name = spec.objectives[0].name
            g, b = designs[-1][name], designs[0][name]
            improvement = {name: (g, b, (b - g) / abs(g) if g else np.nan)}
    else:
        order = np.lexsort(F(grid).T[::-1]) if len(grid["radius"]) else []
        grid = {k: v[order] for k, v in grid.items()}
        designs = _records(grid, "grid")
        if spec.refine or len(new["radius"]):  # new: refined, or grid designs snapped
            both = {k: np.concatenate([new[k], grid[k]]) for k in grid}
            source = ["refined"] * len(new["radius"]) + ["grid"] * len(grid["radius"])
            keep = nondominated(F(both)) if len(source) else np.zeros(0, bool)
            idx = np.flatnonzero(keep)
            idx = idx[np.lexsort(F(both)[idx].T[::-1])] if len(idx) else idx
            refined_front = {k: v[idx] for k, v in both.items()}
            designs = [{**{k: float(both[k][i]) for k in both}, "source": source[i]}
                       for i in idx]
            improvement = _front_gain(F(grid), F(refined_front), spec)
    if multi or spec.resolution:
        designs, snapped["merged"] = merge_equal(designs, spec.objectives)
    if spec.resolution and designs:
        designs = same_intervals(model, spec, designs, _bounds(spec, scan.ranges, scan.fixed),
                                 scan.fixed)
    return DesignResult(spec, designs, grid, refined_front, scan, model.evaluations,
                        dropped, improvement, snapped, model=model.model)


def _on_resolution(model, spec, scan, grid, new):
    """The grid's and the refinement's designs snapped to the spec's resolution, each
    re-checked exactly; grid designs that had to move join the refined ones."""
    check_fixed(spec.resolution, scan.fixed)
    g, g_moved, g_lost = snap(model, spec, grid, scan.ranges, keep_bits=True)
    r, _, r_lost = snap(model, spec, new, scan.ranges)
    keep = {k: g[k][~g_moved] for k in g}
    moved = {k: np.concatenate([r[k], g[k][g_moved]]) for k in g}
    info = {"steps": dict(spec.resolution), "lost": g_lost + r_lost,
            "candidates": len(g["radius"]) + len(r["radius"])}
    # the designs that would be reported, each moved to the best buildable design near it
    # on the lattice (a rounded continuous optimum can be a step or two off it)
    both = {k: np.concatenate([keep[k], moved[k]]) for k in g}
    if len(both["radius"]):
        signs = np.array([o.sign for o in spec.objectives])
        F = np.column_stack([both[o.name] for o in spec.objectives]) * signs
        if len(spec.objectives) > 1:
            pick = np.flatnonzero(nondominated(F))
        else:
            pick = np.argsort(F[:, 0], kind="stable")[:3]
        found, went = lattice_search(model, spec, {k: v[pick] for k, v in both.items()},
                                     _bounds(spec, scan.ranges, scan.fixed), scan.fixed)
        info["lattice_moves"] = int(went.sum())
        moved = {k: np.concatenate([moved[k], found[k][went]]) for k in g}
    return keep, moved, info


def _front_gain(g, r, spec):
    """Two objectives: the area each front dominates (hypervolume) from the grid's nadir."""
    if len(spec.objectives) != 2 or len(g) == 0:
        return {}
    ref = g.max(axis=0)

    def area(F):
        F = F[np.lexsort(F.T[::-1])]
        total, best_y = 0.0, ref[1]
        for x, y in F:
            if y < best_y:
                total += (ref[0] - x) * (best_y - y)
                best_y = y
        return total

    a_g, a_r = area(g), area(r)
    return {"hypervolume": (a_g, a_r, (a_r - a_g) / a_g if a_g else np.nan)}
