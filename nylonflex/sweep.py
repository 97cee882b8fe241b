"""Config + grid -> kernels -> cube. The only caller of the design kernels.

The design space is cut into slabs of consecutive radii, each of bounded memory
(``slab_megabytes`` in the config). A slab is computed by the compiled kernel, journaled and
written to the cube (see :mod:`nylonflex.storage`), so memory stays bounded by the slab
size, whatever the grid, and an interrupted sweep loses at most the slab in progress.
"""

from __future__ import annotations

import datetime as _dt
import os
import platform
import signal
import sys
import time
from pathlib import Path

import numpy as np

from . import __version__
from .config import ResolvedConfig, load_config
from .physics.bending import NEWTON_RTOL, QUADRATURE_ORDERS, quadrature_nodes
from .physics.chamber import P_ATM, chamber_pressure
from .physics.limits import DESIGN_VARIABLES, STROKE_RTOL
from .physics.nylon import nylon_force_limit, stroke_max
from .physics.wrap import muscle_width
from .storage import CubeFile, Journal, cube_attrs, exclusive, slab_done_attrs
from .units import InputError
from .variables import CURVES, DESIGN

__all__ = ["compute_slab", "default_output", "plan_slabs", "run_sweep"]

_FLOAT_DESIGN = [n for n in DESIGN_VARIABLES if n != "limit"]


def default_output(cfg: ResolvedConfig) -> Path:
    """``sweeps/<name>/cube.h5`` under the current directory."""
    return Path("sweeps") / cfg.name / "cube.h5"


def _bytes_per_radius(cfg: ResolvedConfig) -> int:
    nt, nl, nc, npsi = cfg.shape[1:]
    ns, npr = len(cfg.curves["stroke"]), len(cfg.curves["pressure"])
    design = nt * nl * nc * npsi * (8 * len(_FLOAT_DESIGN) + 1)
    return design + 8 * nt * nc * npsi * ns + 2 * 8 * nt * nl * npr


def plan_slabs(cfg: ResolvedConfig) -> tuple[list[tuple[int, int]], int]:
    """Slabs ``[(i0, i1), ...]`` of radius indices, and the HDF5 chunk length along radius.

    A slab holds as many radii as fit in ``cfg.slab_megabytes`` (at least one), a multiple
    of the chunk length so that slabs write whole chunks.
    """
    per = _bytes_per_radius(cfg)
    na = cfg.shape[0]
    per_slab = min(na, max(1, int(cfg.slab_megabytes * 2**20) // per))
    # chunks of about 2 MB of one variable, never longer than a slab
    chunk = max(1, min(per_slab, (2 * 2**20) // max(1, per // 9)))
    per_slab = (per_slab // chunk) * chunk
    return [(i, min(na, i + per_slab)) for i in range(0, na, per_slab)], chunk


def _material_arrays(cfg: ResolvedConfig):
    c = cfg.axes["coil_index"]
    return (np.ascontiguousarray(stroke_max(c, cfg.nylon), dtype=float).reshape(-1),
            np.ascontiguousarray(nylon_force_limit(c, cfg.nylon), dtype=float).reshape(-1),
            np.ascontiguousarray(muscle_width(c, cfg.nylon), dtype=float).reshape(-1))


def compute_slab(cfg: ResolvedConfig, i0: int, i1: int, parallel: bool = True) -> dict:
    """Every radius-dependent variable of the radii [i0, i1), as a dict of arrays.

    ``parallel`` picks the Numba-threaded kernel; the serial one is for Dask workers.
    """
    from .kernels import design

    kernel = design.design_slab_parallel if parallel else design.design_slab_serial
    radius = np.ascontiguousarray(cfg.axes["radius"][i0:i1])
    wall, length = cfg.axes["wall_thickness"], cfg.axes["length"]
    wrap = cfg.axes["wrap_angle"]
    s_max, f_lim, width = _material_arrays(cfg)
    stroke, pressure = cfg.curves["stroke"], cfg.curves["pressure"]
    mu, alpha = cfg.silicone.arrays()
    na, nt, nl, nc, npsi = len(radius), len(wall), len(length), len(s_max), len(wrap)
    out_design = np.empty((len(_FLOAT_DESIGN), na, nt, nl, nc, npsi))
    out_limit = np.empty((na, nt, nl, nc, npsi), dtype=np.int8)
    out_force = np.empty((na, nt, nc, npsi, len(stroke)))
    out_angle = np.empty((na, nt, nl, len(pressure)))
    out_tip = np.empty((na, nt, nl, len(pressure)))
    base = -1.0 if cfg.base_thickness is None else float(cfg.base_thickness)
    kernel(radius, wall, length, s_max, f_lim, width, wrap, base, stroke, pressure, mu, alpha,
           *quadrature_nodes(), P_ATM, out_design, out_limit, out_force, out_angle, out_tip)
    arrays = {name: out_design[j] for j, name in enumerate(_FLOAT_DESIGN)}
    arrays.update(limit=out_limit, nylon_force=out_force, bend_angle=out_angle,
                  tip_force=out_tip)
    return arrays


def _global_arrays(cfg: ResolvedConfig) -> dict:
    """Variables without a radius dimension."""
    return {"nylon_force_limit": np.asarray(nylon_force_limit(cfg.axes["coil_index"],
                                                              cfg.nylon), float).reshape(-1),
            "chamber_pressure": np.asarray(chamber_pressure(cfg.curves["stroke"]),
                                           float).reshape(-1)}


def _coords(cfg: ResolvedConfig) -> dict:
    return {**cfg.axes, **cfg.curves}


def provenance(cfg: ResolvedConfig) -> dict:
    """Global attributes that describe how the cube was made (the stable part)."""
    import h5py
    import numba
    import xarray
    import yaml

    from .kernels._compile import _source_digest

    def material(m):
        d = {**m.to_dict(), "description": m.description, "sources": dict(m.sources)}
        return yaml.safe_dump(d, sort_keys=False, width=100)

    return {
        "nylonflex_cube": "1",
        "title": f"nylonflex design cube '{cfg.name}'",
        "Conventions": "CF-1.10",
        "name": cfg.name,
        "config_yaml": cfg.text,
        "config_sha256": cfg.sha256,
        "nylonflex_version": __version__,
        "model_sources_sha256": _source_digest(),
        "numba_version": numba.__version__,
        "numpy_version": np.__version__,
        "xarray_version": xarray.__version__,
        "h5py_version": h5py.__version__,
        "silicone": cfg.silicone.name,
        "silicone_parameters": material(cfg.silicone),
        "nylon": cfg.nylon.name,
        "nylon_parameters": material(cfg.nylon),
        "base_thickness": "wall" if cfg.base_thickness is None else
        f"{cfg.base_thickness} m",
        "quadrature": (f"Gauss-Legendre phi={QUADRATURE_ORDERS['phi']} "
                       f"base={QUADRATURE_ORDERS['base']}; Newton rtol curvature "
                       f"{NEWTON_RTOL:g}, stroke {STROKE_RTOL:g}"),
        "model": "MODEL.md (nylonflex), after the paper and Polygerinos et al. 2015",
        "complete": "false",
    }


class _Stop(Exception):
    """Raised by the SIGTERM handler to stop a sweep like Ctrl-C does."""


def _progress(total, quiet):
    from tqdm import tqdm

    disable = quiet or not sys.stderr.isatty()
    return tqdm(total=total, unit="design", unit_scale=True, disable=disable,
                desc="sweep", smoothing=0.1, dynamic_ncols=True)


def _set_workers(workers):
    import numba

    if workers is None:
        return numba.get_num_threads()
    if not 1 <= workers <= numba.config.NUMBA_NUM_THREADS:
        raise InputError(f"--workers: must be in [1, {numba.config.NUMBA_NUM_THREADS}], "
                         f"got {workers}")
    numba.set_num_threads(workers)
    return workers


def run_sweep(cfg: ResolvedConfig, out=None, *, resume: bool = False, workers=None,
              scheduler=None, quiet: bool = True, log=None):
    """Evaluate the config's design space.

    Parameters
    ----------
    cfg : ResolvedConfig
        From :func:`nylonflex.load_config`.
    out : path, optional
        Cube file to write. Without it the cube is built in memory (mind its size).
    resume : bool
        Finish an interrupted run of the same config at ``out``; refuse a changed config.
    workers : int, optional
        Threads (local) or, with ``scheduler``, nothing (the cluster decides).
    scheduler : str, optional
        Address of a Dask distributed scheduler, ``tcp://host:port``.
    quiet : bool
        No progress bar.
    log : callable, optional
        Receives one-line messages for the user.

    Returns
    -------
    xarray.Dataset
        The cube (opened from ``out`` when given).
    """
    log = log or (lambda msg: None)
    if out is None:
        return _sweep_in_memory(cfg, workers, quiet)
    out = Path(out)
    with exclusive(out):
        _sweep_to_file(cfg, out, resume, workers, scheduler, quiet, log)
    from .storage import open_cube

    return open_cube(out)


def _sweep_in_memory(cfg, workers, quiet):
    import xarray as xr

    from .variables import COORDS

    _set_workers(workers)
    slabs, _ = plan_slabs(cfg)
    coords = _coords(cfg)
    sizes = {k: len(v) for k, v in coords.items()}
    data = {name: np.empty([sizes[d] for d in v.dims], dtype=v.dtype)
            for name, v in {**DESIGN, **CURVES}.items()}
    data.update(_global_arrays(cfg))
    with _progress(cfg.n_designs, quiet) as bar:
        for i0, i1 in slabs:
            for name, arr in compute_slab(cfg, i0, i1).items():
                data[name][i0:i1] = arr
            bar.update((i1 - i0) * cfg.n_designs // cfg.shape[0])
    ds = xr.Dataset(
        {name: (v.dims, data[name], v.attrs()) for name, v in {**DESIGN, **CURVES}.items()},
        coords={name: (name, values, COORDS[name].attrs()) for name, values in coords.items()},
        attrs={**provenance(cfg), "complete": "true"})
    ds["slab_done"] = ("radius", np.ones(sizes["radius"], np.int8), slab_done_attrs())
    return ds


def _check_resume(cfg, out, journal, resume, log):
    """Decide what to keep: ``None`` (nothing to do), or the journal's slab plan, its chunk
    length along radius and the indices of its finished slabs (an empty plan: start
    afresh)."""
    manifest = journal.read_manifest() if journal.exists() else None
    if manifest is not None and not resume:
        raise InputError(f"{out}: an interrupted run of '{manifest.get('name')}' is in "
                         f"{journal.dir}; add --resume to finish it, or delete that folder")
    if not resume:
        return [], None, set()
    if manifest is None:
        attrs = cube_attrs(out)
        if attrs and attrs.get("config_sha256") != cfg.sha256:
            raise InputError(f"--resume: {out} was made from another config "
                             f"(sha256 {attrs.get('config_sha256', '?')[:12]} vs "
                             f"{cfg.sha256[:12]}); drop --resume to overwrite it")
        if attrs and attrs.get("complete") == "true":
            log(f"{out} is already complete; nothing to resume")
            return None
        log("nothing to resume; starting the sweep")
        return [], None, set()
    if manifest.get("config_sha256") != cfg.sha256:
        raise InputError(f"--resume: the config changed since the interrupted run "
                         f"(sha256 {manifest.get('config_sha256', '?')[:12]} vs "
                         f"{cfg.sha256[:12]}); delete {journal.dir} to start over")
    # the journal's own slab plan: slab_megabytes may differ now (it is not in the hash)
    # the journal's own slab plan and chunking: slab_megabytes may differ now (it is not in
    # the hash), and journaled slabs hold compressed chunks of the recorded shape
    slabs = [tuple(int(i) for i in s) for s in manifest.get("slabs", [])]
    edges = [i for s in slabs for i in s]
    chunk = manifest.get("radius_chunk")
    if not slabs or edges[0] != 0 or edges[-1] != cfg.shape[0] or \
            any(a != b for a, b in zip(edges[1:-1:2], edges[2::2])) or \
            not isinstance(chunk, int) or chunk < 1:
        raise InputError(f"--resume: {journal.manifest} is damaged; delete {journal.dir} "
                         "to start over")
    return slabs, chunk, journal.done() & set(range(len(slabs)))


def _sweep_to_file(cfg, out, resume, workers, scheduler, quiet, log):
    journal = Journal(out)
    decision = _check_resume(cfg, out, journal, resume, log)
    if decision is None:
        return
    slabs, chunk, keep = decision
    if slabs:
        log(f"resuming: {len(keep)} of {len(slabs)} slabs already done")
    else:
        slabs, chunk = plan_slabs(cfg)
    # connect (and fail) before anything is written
    runner = None
    if scheduler is None:
        runner_info = {"scheduler": "local (numba threads)",
                       "workers": str(_set_workers(workers))}
    else:
        from .distributed import DaskRunner

        runner = DaskRunner(scheduler)
        runner_info = runner.info()
    try:
        if not keep:
            journal.start({"name": cfg.name, "config_sha256": cfg.sha256,
                           "slabs": [list(s) for s in slabs], "radius_chunk": chunk,
                           "nylonflex_version": __version__})
        _write_slabs(cfg, out, journal, slabs, keep, chunk, runner, runner_info, quiet, log)
    finally:
        if runner is not None:
            runner.close()


def _write_slabs(cfg, out, journal, slabs, keep, chunk, runner, runner_info, quiet, log):
    """Journal and write every slab not in ``keep``; finish or mark the cube incomplete."""
    building = out.with_name(out.name + ".building")
    attrs = provenance(cfg)
    cube = CubeFile(building, _coords(cfg), attrs, chunk)
    per_radius = cfg.n_designs // cfg.shape[0]
    t0 = time.perf_counter()
    stopped = None
    previous = signal.getsignal(signal.SIGTERM)

    term = []

    def on_term(signum, frame):
        term.append(signum)  # a raise that lands in a weakref callback is swallowed;
        raise _Stop()        # the loop below then stops after the slab it is writing

    in_main = _is_main_thread()
    if in_main:
        signal.signal(signal.SIGTERM, on_term)
    computed = 0
    done_slabs = set()
    try:
        cube.write(0, 0, _global_arrays(cfg))
        with _progress(cfg.n_designs, quiet) as bar:
            for k in sorted(keep):
                i0, i1 = slabs[k]
                cube.write_encoded(i0, i1, journal.load(k))
                done_slabs.add(k)
                bar.update((i1 - i0) * per_radius)
            todo = [k for k in range(len(slabs)) if k not in keep]
            if runner is None:
                results = _local_results(cfg, slabs, todo)
            else:
                results = runner.map_slabs(cfg, slabs, todo)
            for k, arrays in results:
                i0, i1 = slabs[k]
                encoded = cube.encode(i0, arrays)
                journal.save(k, encoded)
                cube.write_encoded(i0, i1, encoded)
                done_slabs.add(k)
                computed += (i1 - i0) * per_radius
                bar.update((i1 - i0) * per_radius)
                if term:
                    raise _Stop()
    except (KeyboardInterrupt, _Stop) as exc:
        stopped = exc
    finally:
        if in_main:
            signal.signal(signal.SIGTERM, previous)
        if runner is not None:
            runner_info = runner.info()  # counts workers that joined during the run
    seconds = time.perf_counter() - t0
    complete = stopped is None and len(done_slabs) == len(slabs)
    final = {
        **runner_info,
        "complete": "true" if complete else "false",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "run_seconds": f"{seconds:.3f}",
        "designs_per_second": f"{computed / seconds:.0f}" if seconds > 0 else "nan",
        "resumed_slabs": str(len(keep)),
        "python_version": platform.python_version(),
        "hostname": platform.node(),
    }
    cube.close(final)
    os.replace(building, out)
    if complete:
        journal.remove()
        log(f"wrote {out}: {cfg.n_designs:,} designs in {seconds:.2f} s "
            f"({final['designs_per_second']} designs/s computed)")
        return
    log(f"stopped: {len(done_slabs)} of {len(slabs)} slabs saved in {journal.dir}; "
        f"{out} is marked incomplete. Finish with --resume.")
    raise KeyboardInterrupt


def _local_results(cfg, slabs, todo):
    """Yield ``(k, arrays)`` slab by slab, computing slab k+1 while the caller writes k.

    The kernel releases the GIL, so compression and journaling overlap the next slab's
    arithmetic; at most two slabs are in memory.
    """
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(1, thread_name_prefix="nylonflex-slab") as pool:
        pending = None
        for k in todo:
            future = pool.submit(compute_slab, cfg, *slabs[k])
            if pending is not None:
                yield pending[0], pending[1].result()
            pending = (k, future)
        if pending is not None:
            yield pending[0], pending[1].result()


def _is_main_thread():
    import threading

    return threading.current_thread() is threading.main_thread()
