"""A sweep into a cube file: the journaled sink, and resume.

Durability: every finished slab of radii is journaled as its own ``.npz`` file in
``<cube>.parts/`` (written to a temporary name, then renamed, so a slab file is whole or
absent; it holds the slab's compressed chunks, see :meth:`CubeFile.encode`) and written
into ``<cube>.building``. Only a finished run renames the building file to ``<cube>``: a
killed run never leaves a file that reads as complete. ``--resume`` keeps the journal's
slabs (if the config hash matches) and computes the rest. A run stopped by Ctrl-C or SIGTERM
also leaves ``<cube>`` with ``complete = "false"`` and a ``slab_done`` mask, so the part
already done can be queried.
"""

from __future__ import annotations

import datetime as _dt
import os
import platform
from pathlib import Path

from .. import __version__
from ..config import ResolvedConfig
from ..engine.grid import coords, cube_variables, global_arrays, plan_slabs
from ..engine.provenance import provenance
from ..engine.slabs import LocalExecutor, run_slabs
from ..units import InputError
from .cube import CubeFile
from .journal import Journal, exclusive
from .reader import cube_attrs

__all__ = ["CubeSink", "Interrupted", "sweep_to_file"]


class Interrupted(KeyboardInterrupt):
    """A sweep stopped early (Ctrl-C or SIGTERM); its slabs are journaled for --resume."""


class CubeSink:
    """Journals each slab, then writes it into the building cube file."""

    def __init__(self, cube: CubeFile, journal: Journal):
        self.cube = cube
        self.journal = journal

    def put(self, k, i0, i1, arrays):
        encoded = self.cube.encode(i0, arrays)
        self.journal.save(k, encoded)
        self.cube.write_encoded(i0, i1, encoded)


def _check_resume(cfg, out, journal, resume, log):
    """Decide what to keep: ``None`` (nothing to do), or the journal's slab plan, its chunk
    length along radius, the indices of its finished slabs (an empty plan: start afresh)
    and the codec of the journaled chunks."""
    manifest = journal.read_manifest() if journal.exists() else None
    if manifest is not None and not resume:
        raise InputError(f"{out}: an interrupted run of '{manifest.get('name')}' is in "
                         f"{journal.dir}; add --resume to finish it, or delete that folder")
    if not resume:
        return [], None, set(), cfg.compression
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
        return [], None, set(), cfg.compression
    if manifest.get("config_sha256") != cfg.sha256:
        raise InputError(f"--resume: the config changed since the interrupted run "
                         f"(sha256 {manifest.get('config_sha256', '?')[:12]} vs "
                         f"{cfg.sha256[:12]}); delete {journal.dir} to start over")
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
    codec = manifest.get("compression", "gzip")  # journaled chunks are in this codec
    if codec != cfg.compression:
        log(f"resuming with the journal's compression, {codec} (the config now says "
            f"{cfg.compression})")
    return slabs, chunk, journal.done() & set(range(len(slabs))), codec


def sweep_to_file(cfg: ResolvedConfig, out, *, resume=False, workers=None, scheduler=None,
                  progress=None, log=None) -> Path:
    """Sweep ``cfg`` into the cube file ``out`` (one writer: a second run is refused).

    Parameters are those of :func:`nylonflex.run_sweep`; ``progress`` receives the designs
    each stored slab adds, ``log`` one-line messages.

    Raises
    ------
    Interrupted
        Ctrl-C or SIGTERM stopped the run; ``out`` is marked incomplete and the journal
        keeps every finished slab for ``--resume``.
    """
    log = log or (lambda msg: None)
    out = Path(out)
    with exclusive(out):
        journal = Journal(out)
        decision = _check_resume(cfg, out, journal, resume, log)
        if decision is None:
            return out
        slabs, chunk, keep, codec = decision
        if slabs:
            log(f"resuming: {len(keep)} of {len(slabs)} slabs already done")
        else:
            slabs, chunk = plan_slabs(cfg)
        # connect (and fail) before anything is written
        if scheduler is None:
            executor = LocalExecutor(workers)
        else:
            from ..engine.cluster import DaskExecutor

            executor = DaskExecutor(scheduler)
        try:
            if not keep:
                journal.start({"name": cfg.name, "config_sha256": cfg.sha256,
                               "slabs": [list(s) for s in slabs], "radius_chunk": chunk,
                               "compression": codec, "nylonflex_version": __version__})
            _write(cfg, out, journal, slabs, keep, chunk, codec, executor, progress, log)
        finally:
            executor.close()
    return out


def _write(cfg, out, journal, slabs, keep, chunk, codec, executor, progress, log):
    """Restore the journaled slabs, compute the rest; finish or mark the cube incomplete."""
    building = out.with_name(out.name + ".building")
    cube = CubeFile(building, coords(cfg), provenance(cfg), chunk, codec, cube_variables(cfg),
                    cfg.models)
    per_radius = cfg.n_designs // cfg.shape[0]
    cube.write(0, 0, global_arrays(cfg))
    for k in sorted(keep):
        i0, i1 = slabs[k]
        cube.write_encoded(i0, i1, journal.load(k))
        if progress is not None:
            progress((i1 - i0) * per_radius)
    todo = [k for k in range(len(slabs)) if k not in keep]
    stats = run_slabs(cfg, slabs, todo, executor, CubeSink(cube, journal), progress)
    done = len(keep) + len(stats.done)
    complete = not stats.stopped and done == len(slabs)
    seconds = stats.seconds
    final = {
        **executor.info(),
        "complete": "true" if complete else "false",
        "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "run_seconds": f"{seconds:.3f}",
        "designs_per_second": f"{stats.computed / seconds:.0f}" if seconds > 0 else "nan",
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
    log(f"stopped: {done} of {len(slabs)} slabs saved in {journal.dir}; "
        f"{out} is marked incomplete. Finish with --resume.")
    raise Interrupted
