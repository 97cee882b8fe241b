"""FE runs journaled one file each, on local processes or a Dask cluster: the seam
``verify`` and ``fit fe`` share.

A plan (JSON) is written first into the run folder; each finished run is written whole as
``design-NNNN.json`` (a new temporary, renamed into place) with its index, its plan
entry, the plan's digest, its values and a digest over all of them, so a killed command
resumes with the runs still to do. On a resume every run file is checked against the plan
of this command (the design, its pressures, the mesh, the silicone, the FE model's
settings, the seed: :func:`check_run`) and its digest; one that fails (malformed, edited,
swapped with another, of another plan) is solved again, never used. A folder holding
another plan's runs is refused in one line. The digest is a check against accidents (a
torn write, a copy from another folder), not against someone who recomputes it.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path

from ..units import InputError, json_text
from .model import model_settings

__all__ = ["RUN_FORMAT", "check_drive", "check_run", "journaled_runs", "plan_material",
           "plan_silicone", "run_record"]

#: The format of a run file (``format`` in it).
RUN_FORMAT = 1
#: Bytes a run file or a plan file may have when read back [B] (a run of a design at two
#: pressures is about 1 kB; a plan of 500 designs about 200 kB).
MAX_RUN_BYTES = 1 << 20
MAX_PLAN_BYTES = 16 << 20


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


def _canonical(obj) -> str:
    return json.dumps(obj, sort_keys=True, separators=(",", ":"), allow_nan=False)


def _digest(obj) -> str:
    return hashlib.sha256(_canonical(obj).encode()).hexdigest()


def run_record(index: int, entry: dict, plan_digest: str, result: dict) -> dict:
    """A run file's content: the run ``index``, its plan ``entry`` (design and pressures),
    the digest of the whole plan, the ``result`` (JSON: NaN as null) and a SHA-256 over
    all of these."""
    body = {"format": RUN_FORMAT, "index": int(index), "entry": entry, "plan": plan_digest,
            "result": json.loads(json_text(result))}
    return {**body, "digest": _digest(body)}


def _values_ok(values, n: int) -> bool:
    """A list of ``n`` numbers (finite floats or ints, or null for an angle not reached)."""
    return isinstance(values, list) and len(values) == n and all(
        v is None or (type(v) in (int, float) and math.isfinite(v)) for v in values)


def check_run(record, index: int, entry: dict, plan_digest: str, keys) -> str | None:
    """Why the run file's content ``record`` may not stand for run ``index`` of the plan
    whose digest is ``plan_digest`` and whose entry is ``entry`` (a short reason), or None
    when it may. ``keys``: the result's lists, one number a pressure of the entry."""
    if not isinstance(record, dict):
        return f"not a run record (a JSON {type(record).__name__})"
    if record.get("format") != RUN_FORMAT:
        return "not a run record of this version"
    body = {k: record.get(k) for k in ("format", "index", "entry", "plan", "result")}
    try:
        if record.get("digest") != _digest(body):
            return "its digest does not match its content (damaged or edited)"
    except (TypeError, ValueError):  # NaN or an infinity written by hand
        return "not valid JSON numbers"
    if record["index"] != index:
        return f"it holds run {str(record['index'])[:20]} (files swapped or renamed)"
    if record["plan"] != plan_digest or _canonical(record["entry"]) != _canonical(entry):
        return "it belongs to another plan (design, pressures or settings)"
    result = record["result"]
    n = len(entry.get("pressures", entry.get("strokes", ())))  # a stroke drive's strokes
    if not isinstance(result, dict) or not all(_values_ok(result.get(k), n) for k in keys):
        return f"its values are not {n} numbers each of {', '.join(keys)}"
    return None


def _map(tasks, workers, scheduler, solve):
    """Yield (index, result) as the tasks finish: local processes, or a Dask cluster."""
    if scheduler:
        from ..engine.cluster import WORKER_WAIT, connect_client

        client = connect_client(None, scheduler)
        try:
            from distributed import as_completed

            try:  # a scheduler without workers would leave the runs waiting forever
                client.wait_for_workers(1, timeout=WORKER_WAIT)
            except TimeoutError:
                raise RuntimeError(f"no Dask worker joined {scheduler} within "
                                   f"{WORKER_WAIT:g} s; start some with 'dask worker "
                                   f"{scheduler}'") from None
            futures = {client.submit(solve, t, pure=False): i for i, t in tasks}
            for fut in as_completed(futures):
                yield futures[fut], fut.result()
        finally:
            client.close()
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


def _open_folder(parts: Path, plan_text: str, what: str):
    """Make the run folder ``parts`` or check the one there holds this plan."""
    from ..files.atomic import make_folder, read_bounded, refuse_link, write_atomic

    refuse_link(parts, f"{what}: the run folder")
    make_folder(parts, f"{what}: the run folder")
    plan_file = parts / "plan.json"
    try:
        old = read_bounded(plan_file, f"{what}: {parts}", MAX_PLAN_BYTES)
    except ValueError as exc:
        if isinstance(exc, InputError):
            raise
        old = b"(too large)"
    if old is None:
        write_atomic(plan_file, plan_text.encode(), what=what)
    elif old != plan_text.encode():
        raise InputError(f"{what}: {parts} holds the runs of another {what} (other designs, "
                         "mesh, seed or settings); delete it to start again")


def journaled_runs(parts, plan, tasks, solve, *, keys=("bend_angle", "coarser_bend_angle"),
                   workers=1, scheduler=None, progress=None, log=None,
                   what="verify") -> dict:
    """Run ``solve(task)`` for each of ``tasks`` not yet journaled in the folder ``parts``;
    returns {index: result} for all of them.

    ``plan`` (JSON-able) identifies the runs: a folder holding another plan is refused;
    ``plan["designs"][k]`` is run ``k``'s entry. ``solve`` must be importable (it runs in
    other processes); its result a dict holding ``keys``, each a list of one number a
    pressure of the entry. A run file that fails :func:`check_run` is solved again.
    """
    from ..files.atomic import read_json, refuse_special, write_atomic

    parts = Path(parts)
    text = json.dumps(plan, sort_keys=True, indent=1)
    _open_folder(parts, text, what)
    plan_digest = hashlib.sha256(text.encode()).hexdigest()
    entries = json.loads(json.dumps(plan["designs"]))
    done, redo = {}, []
    for k in range(len(tasks)):
        f = parts / f"design-{k:04d}.json"
        refuse_special(f, f"{what}: the run file")  # a link or fifo is never followed
        try:
            record = read_json(f, f"{what}: the run file", MAX_RUN_BYTES)
        except InputError:
            raise
        except ValueError as exc:
            redo.append((k, str(exc)))
            continue
        if record is None:
            continue
        why = check_run(record, k, entries[k], plan_digest, keys)
        if why is None:
            done[k] = record["result"]
        else:
            redo.append((k, why))
    total = len(tasks)
    if log is not None:
        for k, why in redo[:5]:
            log(f"run file design-{k:04d}.json: {why}; solving it again")
        if len(redo) > 5:
            log(f"... and {len(redo) - 5} more run files solved again")
        if done:
            log(f"resuming: {len(done)} of {total} FE runs already done")
    todo = [(k, t) for k, t in enumerate(tasks) if k not in done]
    if progress is not None:
        progress(len(done), total)
    for k, res in _map(todo, workers, scheduler, solve):
        record = run_record(k, entries[k], plan_digest, res)
        write_atomic(parts / f"design-{k:04d}.json", json_text(record, indent=None).encode(),
                     what=f"{what}: the run file")
        done[k] = record["result"]
        if progress is not None:
            progress(len(done), total)
    return done


def check_drive(parts, drive: str, what: str = "verify"):
    """Refuse (:class:`InputError`, one line) a run folder ``parts`` whose plan is of
    another drive than ``drive`` (a plan without ``drive`` is the pressure drive's)."""
    from ..files.atomic import read_bounded, refuse_link

    refuse_link(parts, f"{what}: the run folder")  # never read through a link
    try:
        text = read_bounded(Path(parts) / "plan.json", f"{what}: {parts}", MAX_PLAN_BYTES)
    except InputError:
        raise
    except ValueError:
        return  # too large: journaled_runs says it is another plan's
    if text is None:
        return
    try:
        old = json.loads(text)
    except ValueError:
        return  # journaled_runs refuses it as another plan's
    if not isinstance(old, dict):
        return  # likewise
    held = old.get("drive", "pressure")
    if held != drive:
        raise InputError(f"{what}: {parts} holds the runs of a {held}-driven verify, not of "
                         f"--drive {drive}; delete it to start again")
