"""``nylonflex verify --drive stroke``: the whole chain at each sampled design's full stroke.

Where the pressure drive (:mod:`.verify`) loads the FE twin with each model's p*, this one
drives it as the actuator is built: the sealed, stroke-driven twin (:func:`.fe_stroke`)
at the design's usable stroke s* (the paper model's, :func:`nylonflex.evaluate`), and every
model of the cube is held against what the twin reaches there: its sealed chamber pressure
(``pressure_max``), its bend (``bend_angle_max``) and, with ``blocked``, its held tip's
force (``tip_force_max``). Model over twin is 1 where the model is exact.

The runs are journaled by :func:`.runs.journaled_runs` in ``<cube>.fidelity_stroke.parts/``
(a plan of ``drive: stroke``; a folder of the pressure drive there is refused), the dataset
is ``<stem>.fidelity_stroke.nc`` and its map ``<stem>.fidelity_stroke_map.png`` beside the
cube, so that the two drives' results stand side by side.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import __version__
from . import fe_stroke, require_felupe
from .paths import stroke_map_path, stroke_path
from .runs import check_drive, journaled_runs, plan_material, plan_silicone
from .verify import AXES, check_arguments, check_outputs, sample_designs, write_fidelity

__all__ = ["DRIVES", "STROKE_RATIOS", "check_stroke_outputs", "model_values",
           "open_stroke_fidelity", "run_verify_stroke", "stroke_dataset", "stroke_map_path",
           "stroke_parts", "stroke_path", "stroke_summary"]

#: The drives of ``nylonflex verify``: the FE twin loaded by each model's pressure, or
#: driven by the muscle's stroke.
DRIVES = ("pressure", "stroke")
#: The stroke-driven ratios: (dataset variable, the model's cube variable, the twin's
#: variable, what it is).
STROKE_RATIOS = (("stroke_pressure_ratio", "pressure_max", "stroke_fe_pressure", "pressure"),
                 ("stroke_bend_ratio", "bend_angle_max", "stroke_fe_bend_angle",
                  "bend angle"),
                 ("stroke_force_ratio", "tip_force_max", "stroke_fe_tip_force",
                  "blocked tip force"))
#: What a stroke run file holds, free; and blocked besides.
FREE_KEYS = ("pressure", "bend_angle", "discretisation_error", "coarser_pressure",
             "coarser_bend_angle")
BLOCKED_KEYS = ("blocked_pressure", "tip_force", "blocked_discretisation_error")




def stroke_parts(cube) -> Path:
    """The stroke drive's run folder: ``<cube>.fidelity_stroke.parts``."""
    cube = Path(cube)
    return cube.with_name(cube.name + ".fidelity_stroke.parts")


def open_stroke_fidelity(cube):
    """The stroke-driven fidelity dataset beside ``cube``, loaded (None where there is
    none; OSError or ValueError where it cannot be read)."""
    path = stroke_path(cube)
    if not path.is_file():
        return None
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as fid:
        return fid.load()


def check_stroke_outputs(cube, overwrite=False):
    """:func:`.verify.check_outputs` for the stroke drive's dataset and map."""
    return check_outputs(cube, overwrite, (stroke_path(cube), stroke_map_path(cube)))


def _settings(attrs):
    """The cube's models and the evaluate keyword arguments of each."""
    from ..engine.provenance import cube_settings

    s = cube_settings(attrs)
    models = list(dict.fromkeys(s.models + tuple(s.spread)))
    cooling = s.coolings[0] if s.coolings else None
    return models, {m: s.evaluate_kwargs(model=m, cooling=cooling) for m in models}


def _plan(ds, attrs, n, seed, mesh, blocked):
    from ..engine import evaluate

    models, kwargs = _settings(attrs)
    paper = dict(kwargs[models[0]], model="paper")
    paper.pop("chamber", None)  # sealed_chamber's coefficients: not the paper model's
    designs = sample_designs(ds, n, seed)
    arr = [np.array([d[a] for d in designs]) for a in AXES]
    s_star = np.atleast_1d(evaluate(*arr, **paper)["usable_stroke"])
    # each model's own s* as well (sealed_chamber's is longer where the paper's muscle
    # breaks first): the twin is marched through all of them, the paper's first
    own = [np.atleast_1d(evaluate(*arr, **kwargs[m])["usable_stroke"]) for m in models]
    runs = [{**d, "strokes": _strokes(float(s_star[k]), [float(o[k]) for o in own]),
             "base_thickness": paper.get("base_thickness")} for k, d in enumerate(designs)]
    return {"drive": "stroke", "blocked": bool(blocked), "designs": runs, "mesh": mesh,
            "seed": int(seed), "models": models, **plan_material(paper["silicone"]),
            "cube_config_sha256": str(attrs.get("config_sha256", ""))}


def _strokes(paper, others) -> list:
    """The strokes [-] the twin is solved at for one design: the paper model's s* first,
    then every other model's own s* that differs from it (finite, in (0, 0.5))."""
    out = [paper]
    for s in sorted(others):
        if math.isfinite(s) and 0.0 < s < 0.5 and all(abs(s - o) > 1e-9 for o in out):
            out.append(s)
    return out


def _at_own_stroke(rows, done, key, strokes):
    """The twin's ``key`` at each design's stroke in ``strokes`` (per design; the nearest
    solved one, NaN where none is within 1e-9)."""
    out = np.full(len(rows), np.nan)
    for k, row in enumerate(rows):
        solved = np.asarray(row["strokes"], dtype=float)
        if not np.isfinite(strokes[k]):
            continue
        j = int(np.argmin(np.abs(solved - strokes[k])))
        if abs(solved[j] - strokes[k]) <= 1e-9 and key in done[k]:
            out[k] = done[k][key][j]
    return out


def _solve_stroke(task):
    """One stroke-driven FE run (a task of the executor): the free twin at s*, and the
    blocked one's pressure and tip force with ``blocked``."""
    d, sil, mesh, blocked = task
    kw = {"base_thickness": d["base_thickness"], "silicone": plan_silicone(sil), "mesh": mesh}
    free = fe_stroke(d["radius"], d["wall_thickness"], d["length"], d["strokes"], **kw)
    out = {k: np.asarray(free[k]).tolist() for k in FREE_KEYS}
    if blocked:
        held = fe_stroke(d["radius"], d["wall_thickness"], d["length"], d["strokes"],
                         blocked=True, **kw)
        out.update({"blocked_pressure": held["pressure"].tolist(),
                    "tip_force": held["tip_force"].tolist(),
                    "blocked_discretisation_error": held["discretisation_error"].tolist()})
    return out


def run_verify_stroke(cube, designs=24, *, blocked=False, workers=1, scheduler=None,
                      mesh="coarse", seed=0, progress=None, log=None,
                      overwrite=False) -> Path:
    """Verify a cube's models against the stroke-driven FE twin at each sampled design's
    full stroke; returns the dataset's path (:func:`stroke_path`).

    The designs are those of :func:`.verify.run_verify` with the same ``designs`` and
    ``seed``; ``workers``, ``scheduler``, ``mesh``, ``progress``, ``log`` and ``overwrite``
    as there. ``blocked``: also solve the held tip, for the force ratio. The twin's values
    compared are its own on ``mesh`` (not extrapolated); its discretisation error [1] is
    in the dataset.
    """

    check_arguments(designs, seed, workers, mesh)
    require_felupe()
    from ..storage import open_cube

    cube = Path(cube)
    ds = open_cube(cube)
    try:
        owned = check_stroke_outputs(cube, overwrite)
        plan = _plan(ds, ds.attrs, designs, seed, mesh, blocked)
        kwargs = _settings(ds.attrs)[1]
    finally:
        ds.close()
    parts = stroke_parts(cube)
    check_drive(parts, "stroke")
    tasks = [(d, plan["silicone"], mesh, bool(blocked)) for d in plan["designs"]]
    keys = FREE_KEYS + (BLOCKED_KEYS if blocked else ())
    done = journaled_runs(parts, plan, tasks, _solve_stroke, keys=keys, workers=workers,
                          scheduler=scheduler, progress=progress, log=log, what="verify")
    out = stroke_dataset(plan, done, cube.name, kwargs)
    path = stroke_path(cube)

    write_fidelity(out, path, inputs=(cube,))
    owned.record([path])
    return path


def stroke_dataset(plan, done, cube_name, kwargs=None):
    """The stroke-driven fidelity dataset of a plan and its journaled runs ``done``
    (``kwargs``: :func:`model_values`'s)."""
    import xarray as xr


    rows = plan["designs"]
    n = len(rows)
    models = plan["models"]
    data = {a: ("design", np.array([r[a] for r in rows])) for a in AXES}
    data["stroke"] = ("design", np.array([r["strokes"][0] for r in rows]))

    def fe(key):
        return np.array([done[k][key][0] for k in range(n)], dtype=float)

    data["stroke_fe_pressure"] = ("design", fe("pressure"))
    data["stroke_fe_bend_angle"] = ("design", fe("bend_angle"))
    data["stroke_fe_discretisation_error"] = ("design", fe("discretisation_error"))
    data["stroke_fe_coarser_pressure"] = ("design", fe("coarser_pressure"))
    data["stroke_fe_coarser_bend_angle"] = ("design", fe("coarser_bend_angle"))
    if plan["blocked"]:
        data["stroke_fe_blocked_pressure"] = ("design", fe("blocked_pressure"))
        data["stroke_fe_tip_force"] = ("design", fe("tip_force"))
        data["stroke_fe_blocked_discretisation_error"] = \
            ("design", fe("blocked_discretisation_error"))
    vals = model_values(plan, kwargs)
    # each model against the twin at its own s* (a run made before the twin was solved at
    # every model's stroke has the paper's alone: the others' ratios are NaN there)
    own = {model: _model_strokes(rows, vals[model]["usable_stroke"]) for model in models}
    data["stroke_model_stroke"] = (("model", "design"), np.array([own[m] for m in models]))
    keys = {"stroke_fe_pressure": "pressure", "stroke_fe_bend_angle": "bend_angle",
            "stroke_fe_tip_force": "tip_force"}
    for ratio, var, twin, _ in STROKE_RATIOS:
        if twin not in data:
            continue
        m = np.array([vals[model][var] for model in models])
        fe_own = np.array([_at_own_stroke(rows, done, keys[twin], own[model])
                           for model in models])
        data[f"stroke_model_{var}"] = (("model", "design"), m)
        with np.errstate(invalid="ignore", divide="ignore"):
            data[ratio] = (("model", "design"), np.where(fe_own > 0, m / fe_own, np.nan))
    out = xr.Dataset(data, coords={"design": np.arange(n), "model": np.array(models)})
    _attrs(out, plan, cube_name)
    return out


def _model_strokes(rows, usable) -> np.ndarray:
    """A model's s* per design [-]: its own ``usable`` stroke where the twin was solved
    there, else the paper's (the run's first), which a run of the paper's alone holds."""
    out = np.array([r["strokes"][0] for r in rows], dtype=float)
    for k, row in enumerate(rows):
        if any(abs(s - usable[k]) <= 1e-9 for s in row["strokes"]):
            out[k] = usable[k]
        elif not abs(usable[k] - out[k]) <= 1e-9:
            out[k] = np.nan  # solved at other strokes only (or none of its own): no ratio
    return out


def model_values(plan, kwargs=None) -> dict:
    """{model: {"pressure_max" [Pa], "bend_angle_max" [rad], "tip_force_max" [N]}} of the
    plan's designs, each model under the cube's settings (``kwargs``: {model: evaluate
    keyword arguments}; None: the paper's defaults with the plan's silicone and base)."""
    from ..engine import evaluate

    rows = plan["designs"]
    arr = [np.array([r[a] for r in rows]) for a in AXES]
    out = {}
    for model in plan["models"]:
        kw = dict(kwargs[model]) if kwargs else {
            "model": model, "silicone": plan_silicone(plan["silicone"]),
            "base_thickness": rows[0]["base_thickness"] if rows else None}
        res = evaluate(*arr, **kw)
        out[model] = {v: np.atleast_1d(np.asarray(res[v], dtype=float))
                      for v in ("pressure_max", "bend_angle_max", "tip_force_max",
                                "usable_stroke")}
    return out


def _attrs(out, plan, cube_name):
    units = {"radius": "m", "wall_thickness": "m", "length": "m", "coil_index": "1",
             "wrap_angle": "rad", "stroke": "1"}
    for name in out.variables:
        if name in units:
            out[name].attrs["units"] = units[name]
        elif name.endswith("_ratio") or name.endswith("discretisation_error"):
            out[name].attrs["units"] = "1"
        elif "pressure" in name:
            out[name].attrs["units"] = "Pa"
        elif "bend_angle" in name:
            out[name].attrs["units"] = "rad"
        elif "force" in name:
            out[name].attrs["units"] = "N"
    long = {"stroke": "the design's usable stroke s* (paper model), the twin's drive",
            "stroke_model_stroke": "the model's own s*, where its ratios are taken",
            "stroke_fe_pressure": "sealed twin's chamber pressure at s* (free)",
            "stroke_fe_bend_angle": "sealed twin's bend angle at s* (free)",
            "stroke_fe_discretisation_error": "twin's Richardson error estimate at s* (free)",
            "stroke_fe_coarser_pressure": "twin's pressure on the next coarser mesh",
            "stroke_fe_coarser_bend_angle": "twin's bend angle on the next coarser mesh",
            "stroke_fe_blocked_pressure": "sealed twin's chamber pressure at s*, tip held",
            "stroke_fe_tip_force": "sealed twin's blocked tip force at s* (moment / length)",
            "stroke_fe_blocked_discretisation_error":
                "twin's Richardson error estimate at s* (tip held)"}
    for ratio, var, twin, what in STROKE_RATIOS:
        long[ratio] = f"model {var} / stroke-driven twin's {what}, both at the model's s*"
        long[f"stroke_model_{var}"] = f"model's {var} (its own s*)"
    for name, text in long.items():
        if name in out.variables:
            out[name].attrs["long_name"] = text
    out.attrs.update({"title": "nylonflex fidelity: the stroke-driven FE twin against the "
                      "models at full stroke", "drive": "stroke",
                      "blocked": int(plan["blocked"]),
                      "nylonflex_version": __version__, "fe_mesh": plan["mesh"],
                      "seed": plan["seed"], "cube": cube_name,
                      "cube_config_sha256": plan["cube_config_sha256"],
                      "models": " ".join(plan["models"]),
                      "silicone": json.dumps(plan["silicone"]),
                      "fe_model": json.dumps(plan["fe_model"], sort_keys=True),
                      "Conventions": "CF-1.8"})


def stroke_summary(fid) -> list[str]:
    """One line a model and stroke-driven quantity: model/twin median and range over the
    designs, and how many within 15 %."""
    from ..charts.fidelity import ratio_stats

    lines = []
    for ratio, var, _, what in STROKE_RATIOS:
        if ratio not in fid:
            continue
        for model in fid["model"].values:
            st = ratio_stats(fid[ratio].sel(model=model).values)
            if st is None:
                continue
            within = int(np.sum(np.abs(fid[ratio].sel(model=model).values - 1) <= 0.15))
            lines.append(f"{str(model):<17} {what:<17} model/twin at s* median "
                         f"{st['median']:.3f}, range {st['min']:.3f}-{st['max']:.3f}, "
                         f"within 15 %: {100 * within / st['n']:.0f} % ({st['n']} designs)")
    return lines
