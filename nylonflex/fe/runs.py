"""FE runs journaled one file each, on local processes or a Dask cluster: the seam
``verify`` and ``fit fe`` share.

A plan (JSON) is written first into the run folder; each finished run is written whole as
``design-NNNN.json`` and renamed into place, so a killed command resumes with the runs
still to do, and a folder holding another plan's runs is refused.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..units import InputError, json_text
from .model import model_settings

__all__ = ["journaled_runs", "plan_material", "plan_silicone"]


def plan_material(sil) -> dict:
    """What a plan records of the material and the FE model: the silicone ``sil`` (its
    name and Ogden constants, read back by :func:`plan_silicone`) and the model's constants
    (:func:`~.model.model_settings`), so that runs of another silicone or another version
    of the model are never mixed in."""
    return {"silicone": {"name": getattr(sil, "name", "custom"),
                         "mu": [float(m) for m in sil.mu],
                         "alpha": [float(a) for a in sil.alpha]},
            "fe_model": model_settings()}


def plan_silicone(sil):
    """A plan's Ogden constants (``{"mu": [...], "alpha": [...]}``) as a silicone nylonflex
    accepts: a set with its fields replaced (only mu and alpha enter the FE and the angles)."""
    return {"set": "tc5005", "mu": list(sil["mu"]), "alpha": list(sil["alpha"])}


def _map(tasks, workers, scheduler, solve):
    """Yield (index, result) as the tasks finish: local processes, or a Dask cluster."""
    if scheduler:
        try:
            from distributed import Client, as_completed
        except ImportError:
            raise InputError("--scheduler: needs dask's distributed: pip install "
                             "'nylonflex[dask]'") from None
        with Client(scheduler, timeout=30, set_as_default=False) as client:
            futures = {client.submit(solve, t, pure=False): i for i, t in tasks}
            for fut in as_completed(futures):
                yield futures[fut], fut.result()
        return
    if workers <= 1:
        for i, t in tasks:
            yield i, solve(t)
        return
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    ex = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"))
    try:
        futures = {ex.submit(solve, t): i for i, t in tasks}
        for fut in as_completed(futures):
            yield futures[fut], fut.result()
    except BaseException:
        # Ctrl-C, SIGTERM or a failed run: the queued runs are cancelled and the running
        # ones stopped (what is journaled stays; a resume solves the rest). Leaving the
        # pool's context would instead wait for every queued run, minutes each.
        running = list((getattr(ex, "_processes", None) or {}).values())  # before
        ex.shutdown(wait=False, cancel_futures=True)  # shutdown forgets them
        for proc in running:
            proc.terminate()
        raise
    ex.shutdown(wait=True)


def journaled_runs(parts, plan, tasks, solve, *, workers=1, scheduler=None, progress=None,
                   log=None, what="verify") -> dict:
    """Run ``solve(task)`` for each of ``tasks`` not yet journaled in the folder ``parts``;
    returns {index: result} for all of them.

    ``plan`` (JSON-able) identifies the runs: a folder holding another plan is refused.
    ``solve`` must be importable (it runs in other processes); its result JSON-able.
    """
    from ..files.atomic import write_atomic

    parts = Path(parts)
    if parts.is_symlink():
        raise InputError(f"{parts}: is a symbolic link; nylonflex does not write through links")
    parts.mkdir(exist_ok=True)
    plan_file = parts / "plan.json"
    text = json.dumps(plan, sort_keys=True, indent=1)
    if plan_file.exists() and not plan_file.is_symlink():
        if plan_file.read_text() != text:
            raise InputError(f"{parts}: holds the runs of another {what} (other designs, "
                             f"mesh or settings); delete it to start again")
    else:
        write_atomic(plan_file, text.encode(), what=what)
    done = {}
    for k in range(len(tasks)):
        f = parts / f"design-{k:04d}.json"
        if f.is_file() and not f.is_symlink():
            try:
                done[k] = json.loads(f.read_text())
            except ValueError:
                pass  # a damaged run is solved again
    total = len(tasks)
    if done and log is not None:
        log(f"resuming: {len(done)} of {total} FE runs already done")
    todo = [(k, t) for k, t in enumerate(tasks) if k not in done]
    if progress is not None:
        progress(len(done), total)
    for k, res in _map(todo, workers, scheduler, solve):
        write_atomic(parts / f"design-{k:04d}.json", json_text(res).encode(), what=what)
        done[k] = res
        if progress is not None:
            progress(len(done), total)
    return done
