"""``nylonflex verify``: the FE twin on a space-filling sample of a cube's designs.

For each sampled design the FE twin solves the body at the pressures the design reaches
(half and all of its p*, from the cube's own model and materials) and every variant's
analytic angle is set beside it. Each FE run is journaled as its own file in
``<cube>.fidelity.parts/`` (written whole, then renamed), so a killed verify resumes with
the runs still to do; the result is a fidelity dataset ``<cube stem>.fidelity.nc`` beside the
cube: per design and pressure, the FE angle, its discretisation error and each variant's
ratio to FE, with provenance.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import __version__
from ..units import InputError
from . import MESH_NAMES, extrapolated, fe_bend, require_felupe
from .paths import fidelity_map_path, fidelity_path
from .runs import check_drive, journaled_runs, plan_material, plan_silicone

__all__ = ["ANGLE_MODELS", "MAX_DESIGNS", "PAPER_EXAMPLES", "check_arguments", "check_outputs",
           "fidelity_map_path", "fidelity_path",
           "fidelity_stats", "fidelity_summary", "open_fidelity", "run_verify", "sample_designs",
           "write_fidelity"]

#: The variants whose bend angle at a given pressure differs (the others change the
#: muscle's side only): the ones the fidelity dataset compares.
ANGLE_MODELS = ("paper", "cauchy_moment", "lateral_pressure", "fe_calibrated")
#: The paper's worked examples (docs/model.md s. 8), included when the cube's axes hold them.
PAPER_EXAMPLES = ({"radius": 20e-3, "wall_thickness": 6e-3, "length": 90e-3,
                   "coil_index": 1.1, "wrap_angle": np.radians(8.0)},
                  {"radius": 7.5e-3, "wall_thickness": 2e-3, "length": 70e-3,
                   "coil_index": 1.7, "wrap_angle": np.radians(8.0)})
#: Accepted --designs.
MAX_DESIGNS = 500
#: Fractions of each design's p* the FE is solved at.
FRACTIONS = (0.5, 1.0)

AXES = ("radius", "wall_thickness", "length", "coil_index", "wrap_angle")
#: What a verify run file holds: one number a pressure each.
RUN_KEYS = ("bend_angle", "coarser_bend_angle", "discretisation_error")


def check_outputs(cube, overwrite: bool = False, paths=None):
    """Refuse, before any FE run, what verify would write over: a link, fifo, device or
    folder at the fidelity dataset or its map (``paths``; by default the pressure drive's,
    :func:`fidelity_path` and :func:`fidelity_map_path`), and, unless ``overwrite``, a file
    there that nylonflex did not write for this cube (the chart manifest beside it says
    which, as for charts: :class:`~nylonflex.files.atomic.OwnedFiles`). Returns that
    manifest."""
    from ..files.atomic import OwnedFiles, refuse_special

    cube = Path(cube)
    owned = OwnedFiles(cube.parent, str(cube.resolve()))
    for path in paths or (fidelity_path(cube), fidelity_map_path(cube)):
        refuse_special(path, "verify", inputs=(cube,))
        why = owned.foreign(path)
        if why and not overwrite:
            raise InputError(f"{why}; it is not replaced: move it away or give "
                             "--overwrite")
    return owned


def open_fidelity(cube):
    """The fidelity dataset beside ``cube``, loaded (None where there is none; OSError or
    ValueError where it cannot be read)."""
    path = fidelity_path(cube)
    if not path.is_file():
        return None  # before xarray is imported: info stays light without one
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as fid:
        return fid.load()


def _parts(cube) -> Path:
    cube = Path(cube)
    return cube.with_name(cube.name + ".fidelity.parts")


def sample_designs(ds, n, seed=0) -> list[dict]:
    """``n`` designs filling the cube's axes (a scrambled Latin hypercube, scipy), the
    paper's examples first where the axes hold them; each a dict of the five axes [SI]."""
    from scipy.stats import qmc

    lo = {a: float(ds[a].min()) for a in AXES}
    hi = {a: float(ds[a].max()) for a in AXES}
    out = [dict(e) for e in PAPER_EXAMPLES
           if all(lo[a] * (1 - 1e-9) <= e[a] <= hi[a] * (1 + 1e-9) for a in AXES)][:n]
    rest = n - len(out)
    if rest > 0:
        u = qmc.LatinHypercube(d=len(AXES), seed=seed).random(rest)
        for row in u:
            out.append({a: lo[a] + row[k] * (hi[a] - lo[a]) for k, a in enumerate(AXES)})
    return out


def _plan(ds, attrs, n, seed, mesh):
    from ..engine import evaluate
    from ..engine.provenance import cube_settings

    s = cube_settings(attrs)
    # a cube of several models (cooling sets): its first one's peak pressures
    settings = s.evaluate_kwargs(model=s.models[0],
                                 cooling=s.coolings[0] if s.coolings else None)
    designs = sample_designs(ds, n, seed)
    arr = {a: np.array([d[a] for d in designs]) for a in AXES}
    res = evaluate(arr["radius"], arr["wall_thickness"], arr["length"], arr["coil_index"],
                   arr["wrap_angle"], **settings)
    runs = []
    for k, d in enumerate(designs):
        p_star = float(res["pressure_max"][k])
        runs.append({**d, "pressures": [f * p_star for f in FRACTIONS],
                     "base_thickness": settings.get("base_thickness")})
    sil = settings["silicone"]
    return {"designs": runs, "mesh": mesh, "seed": int(seed), "model": settings["model"],
            **plan_material(sil),
            "cube_config_sha256": str(attrs.get("config_sha256", ""))}


def _solve(task):
    """One FE run (a task of the executor): the design's angles and error estimates."""
    d, sil, mesh = task
    silicone = plan_silicone(sil)
    res = fe_bend(d["radius"], d["wall_thickness"], d["length"], d["pressures"],
                  base_thickness=d["base_thickness"], silicone=silicone, mesh=mesh)
    return {"bend_angle": res["bend_angle"].tolist(),
            "coarser_bend_angle": res["coarser_bend_angle"].tolist(),
            "discretisation_error": res["discretisation_error"].tolist()}


#: The mesh verify solves on by default: with its next coarser partner's Richardson
#: extrapolation (the FE angle verify compares against), within 0.6 % of the fine mesh on
#: example 1 and 1.4-9.5 % below it on the slender example 2 as its bend grows from 17 to
#: 80 deg, at about a quarter of the default mesh's cost (docs/fidelity.md, Convergence).
DEFAULT_MESH = "coarse"


def check_arguments(designs, seed, workers, mesh):
    """Refuse, in one line naming the flag, a verify's ``--designs``, ``--seed``,
    ``--workers`` or ``--mesh`` outside its range (both drives)."""
    if not isinstance(designs, int) or not 1 <= designs <= MAX_DESIGNS:
        raise InputError(f"--designs: must be an integer in [1, {MAX_DESIGNS}], "
                         f"got {designs!r}")
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < 2**32:
        raise InputError(f"--seed: must be an integer in [0, 2^32), got {seed!r}")
    if not isinstance(workers, int) or not 1 <= workers <= 64:
        raise InputError(f"--workers: must be an integer in [1, 64], got {workers!r}")
    if mesh not in MESH_NAMES:
        raise InputError(f"--mesh: must be one of {', '.join(MESH_NAMES)}, got {mesh!r}")


def run_verify(cube, designs=24, *, workers=1, scheduler=None, mesh=DEFAULT_MESH, seed=0,
               progress=None, log=None, overwrite=False) -> Path:
    """Verify a cube against the FE twin; returns the fidelity dataset's path.

    Parameters
    ----------
    cube : path
        A finished cube (``nylonflex sweep``).
    designs : int
        Designs to sample, 1 to :data:`MAX_DESIGNS` (the paper's examples among them where
        the cube holds them).
    workers : int
        Local processes (each FE run is one process; FElupe holds the GIL).
    scheduler : str, optional
        A Dask scheduler's address: the runs go to its workers instead.
    mesh : str
        The FE mesh level (:data:`nylonflex.fe.MESH_NAMES`); the FE angle is the Richardson
        extrapolation of it and the next coarser level (order 2), the angle each model is
        compared against.
    progress : callable, optional
        ``progress(done, total)`` after each FE run.
    log : callable, optional
        One-line messages (resumed runs).
    overwrite : bool
        Replace a fidelity dataset or map that nylonflex did not write for this cube
        (:func:`check_outputs`; refused otherwise, before any FE run).
    """
    import xarray as xr

    from ..engine import bend_angle
    from ..storage import open_cube

    check_arguments(designs, seed, workers, mesh)
    require_felupe()
    cube = Path(cube)
    ds = open_cube(cube)
    try:
        owned = check_outputs(cube, overwrite)
    except BaseException:
        ds.close()
        raise
    try:
        plan = _plan(ds, ds.attrs, designs, seed, mesh)
    finally:
        ds.close()
    parts = _parts(cube)

    check_drive(parts, "pressure")
    tasks = [(d, plan["silicone"], mesh) for d in plan["designs"]]
    done = journaled_runs(parts, plan, tasks, _solve, keys=RUN_KEYS, workers=workers,
                          scheduler=scheduler, progress=progress, log=log, what="verify")
    sil = plan["silicone"]
    total = len(plan["designs"])
    # the dataset: design x level (the fractions of p*)
    n = total
    rows = plan["designs"]
    coords = {"design": np.arange(n), "level": np.array(FRACTIONS)}
    data = {a: ("design", np.array([r[a] for r in rows])) for a in AXES}
    pressure = np.array([r["pressures"] for r in rows])
    # null (JSON) where the FE could not reach a pressure: NaN
    on_mesh = np.array([done[k]["bend_angle"] for k in range(n)], dtype=float)
    coarser = np.array([done[k]["coarser_bend_angle"] for k in range(n)], dtype=float)
    fe = np.where(on_mesh == 0.0, 0.0, extrapolated(on_mesh, coarser))
    err = np.array([done[k]["discretisation_error"] for k in range(n)], dtype=float)
    data["pressure"] = (("design", "level"), pressure)
    data["fe_bend_angle"] = (("design", "level"), fe)
    data["fe_mesh_bend_angle"] = (("design", "level"), on_mesh)
    data["discretisation_error"] = (("design", "level"), err)
    ratios = []
    for model in ANGLE_MODELS:
        ang = np.array([np.atleast_1d(bend_angle(pressure[k], r["radius"], r["wall_thickness"],
                                                 r["length"], base_thickness=r["base_thickness"],
                                                 silicone=plan_silicone(sil), model=model)) for k, r in enumerate(rows)])
        data[f"{model}_bend_angle"] = (("design", "level"), ang)
        with np.errstate(invalid="ignore", divide="ignore"):
            ratios.append(np.where(fe > 0, ang / fe, np.nan))
    coords["model"] = np.array(ANGLE_MODELS)
    data["ratio"] = (("model", "design", "level"), np.array(ratios))
    out = xr.Dataset(data, coords=coords)
    units = {"radius": "m", "wall_thickness": "m", "length": "m", "coil_index": "1",
             "wrap_angle": "rad", "pressure": "Pa", "fe_bend_angle": "rad",
             "discretisation_error": "1", "ratio": "1", "level": "1"}
    for name in out.variables:
        if name in units:
            out[name].attrs["units"] = units[name]
        elif name.endswith("_bend_angle"):
            out[name].attrs["units"] = "rad"
    out["ratio"].attrs["long_name"] = "analytic bend angle / FE bend angle"
    out["level"].attrs["long_name"] = "fraction of the design's pressure_max"
    out["fe_bend_angle"].attrs["long_name"] = \
        "FE bend angle (Richardson extrapolation of the mesh and the next coarser one)"
    out["fe_mesh_bend_angle"].attrs["long_name"] = "FE bend angle on the mesh itself"
    out.attrs.update({"title": "nylonflex fidelity: the FE twin against the analytic models",
                      "nylonflex_version": __version__, "fe_mesh": mesh, "seed": seed,
                      "cube": cube.name, "cube_config_sha256": plan["cube_config_sha256"],
                      "model_of_cube": plan["model"], "silicone": json.dumps(sil),
                      "fe_model": json.dumps(plan["fe_model"], sort_keys=True),
                      "Conventions": "CF-1.8"})
    path = fidelity_path(cube)
    write_fidelity(out, path, inputs=(cube,))
    owned.record([path])
    return path


def write_fidelity(fid, path, inputs=()) -> Path:
    """Write the fidelity dataset ``fid`` to ``path`` (netCDF-4): made whole in memory
    (at most :data:`MAX_DESIGNS` designs, under a megabyte), then written through
    :func:`~nylonflex.files.atomic.write_atomic`.

    HDF5 never writes to the disk here: on a full disk h5netcdf's close failed partway and
    HDF5 freed its ids a second time (a segfault, exit -11); a plain write fails with an
    ``OSError`` instead, and ``path`` is left as it was.
    """
    from ..files.atomic import write_atomic

    return write_atomic(path, bytes(fid.to_netcdf(engine="h5netcdf")), what="verify",
                        inputs=inputs)


def fidelity_stats(fid, level=None) -> list[dict]:
    """Per model of a fidelity dataset, model/FE where the FE reached it, over every design
    at ``level`` (a fraction of p*; None: every level): ``model``, ``median``, ``min``,
    ``max`` [1], ``within`` (how many within 10 %) and ``n``; models with no finite ratio
    are left out. The numbers of :func:`nylonflex.charts.fidelity.ratio_stats`, which the
    map's titles use too."""
    from ..charts.fidelity import ratio_stats

    out = []
    for model in fid["model"].values:
        r = fid["ratio"].sel(model=model)
        if level is not None:
            r = r.sel(level=level, method="nearest")
        st = ratio_stats(r.values)
        if st is not None:
            out.append({"model": str(model), **st})
    return out


def fidelity_summary(fid) -> list[str]:
    """One line a model and pressure level of a fidelity dataset (at p*, the map's level,
    the same numbers as the map's titles), then over every level."""
    levels = sorted((float(x) for x in fid["level"].values), reverse=True)
    lines = []
    for lv in levels + ([None] if len(levels) > 1 else []):
        at = "every level" if lv is None else "at p*" if lv == 1.0 else f"at {lv:g} p*"
        lines += [f"{s['model']:<17} {at:<11} model/FE median {s['median']:.3f}, range "
                  f"{s['min']:.3f}-{s['max']:.3f}, within 10 %: "
                  f"{100 * s['within'] / s['n']:.0f} % ({s['n']} FE angles)"
                  for s in fidelity_stats(fid, lv)]
    return lines
