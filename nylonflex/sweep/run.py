"""A sweep into a cube file: the journaled sink, and resume.

Durability: every finished slab of radii is written into ``<cube>.building``, made durable
there (``fsync``), and then journaled as its own ``.npz`` file in ``<cube>.parts/``
(written to a temporary name, then renamed, so a slab file is whole or absent). The slab
file records where the slab's compressed chunks lie in the building file and their CRC-32s,
not the chunks again (:mod:`nylonflex.storage.restore`). Only a finished run renames the
building file to ``<cube>``: a killed run never leaves a file that reads as complete.
``--resume`` moves the interrupted building file into the journal, keeps the journal's
slabs (if the config hash, the nylonflex version and the model digest match, the slab plan
and codec are ones the config implies, each slab file passes its own verification, which
covers the codec it decodes with, and its chunks are found, unchanged, in that file or in
the incomplete cube; a slab that fails is recomputed) and computes the rest. A run
stopped by Ctrl-C or SIGTERM also leaves ``<cube>`` with ``complete`` 0 and a ``slab_done`` mask, so the part
already done can be queried.
"""

from __future__ import annotations

import errno
import os
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from .. import __version__
from ..config import ResolvedConfig
from ..engine.grid import (bytes_per_radius, coords, cube_variables, global_arrays, plan_is_implied,
                           plan_slabs)
from ..engine.provenance import is_complete, provenance, run_attrs
from ..engine.slabs import LocalExecutor, deferred_signals, run_slabs
from ..kernels import source_digest
from ..units import InputError
from ..storage.codec import CODECS, EncodedSlab
from ..storage.cube import CubeFile
from ..storage.journal import JOURNAL_FORMAT, Journal, SlabInvalid, manifest_digest, publish, \
    refuse_special
from ..storage.locks import check_building, exclusive, renew_building, share_building
from ..storage.restore import ChunkSources, journal_record
from ..storage.reader import cube_attrs

__all__ = ["CubeSink", "DiskFull", "Interrupted", "sweep_to_file"]


class Interrupted(KeyboardInterrupt):
    """A sweep stopped early (Ctrl-C or SIGTERM); its slabs are journaled for --resume."""


class DiskFull(RuntimeError):
    """The disk filled up during a sweep; the journal keeps what was done for --resume."""


class CubeSink:
    """Writes each slab into the building cube file and journals where it lies.

    :meth:`prepare` starts a slab's compression as soon as it is computed (the executor
    calls it from the computing thread; a Dask worker encodes it instead, with
    :attr:`remote`); :meth:`put` writes it into the cube, then journals it in a second
    thread: the cube file is made durable (``fsync``) first, then the slab's record (where
    its chunks lie, their sizes and CRC-32s) is written. ``put`` returns once the slab is
    in the cube and the *previous* slab's journal file is on disk; :meth:`close` waits for
    the last one (and raises its error, a full disk). The fsync and the journal's write so
    overlap the next slab instead of holding up the loop; a killed run loses at most the
    slabs in flight, never a slab whose journal file exists.
    """

    def __init__(self, cube: CubeFile, journal: Journal, config_sha: str = ""):
        self.cube = cube
        self.journal = journal
        self.config_sha = config_sha
        self.decoding = cube.decoding()  # what each slab's digest covers besides its bytes
        self._journaling = ThreadPoolExecutor(1, thread_name_prefix="nylonflex-journal")
        self._saving = None  # the last slab's journal save, not yet waited for

    def prepare(self, i0, arrays):
        """Start compressing the slab of radii from ``i0`` (returns what :meth:`put` takes)."""
        return _Started(self.cube.encode_start(i0, arrays))

    @property
    def remote(self):
        """What an executor that computes slabs elsewhere (Dask) runs there on each slab
        instead of :meth:`prepare` here: the cube's encoder (its result is an
        :class:`~nylonflex.storage.codec.EncodedSlab`), or None (HDF5 compresses: lz4)."""
        return self.cube.remote_encoder()

    def put(self, k, i0, i1, arrays):
        if isinstance(arrays, EncodedSlab):  # encoded where it was computed
            encoded = arrays.arrays
        elif isinstance(arrays, _Started):
            encoded = self.cube.encode_finish(arrays.started)
        else:
            encoded = self.cube.encode(i0, arrays)
        previous, self._saving = self._saving, None
        try:
            record = journal_record(encoded, self.cube.write_encoded(i0, i1, encoded))
            self._saving = self._journaling.submit(self._save, k, record, (i0, i1))
        finally:
            if previous is not None:  # its error (a full disk) first, if both failed
                previous.result()

    def _save(self, k, record, slab):
        """The cube made durable, then slab ``k``'s record journaled (the journal thread)."""
        self.cube.sync()
        self.journal.save(k, record, slab=slab, config_sha=self.config_sha,
                          decoding=self.decoding)

    def flush(self):
        """Wait until every slab put so far is on disk in the journal (raising the error
        of a save that failed: a full disk)."""
        saving, self._saving = self._saving, None
        if saving is not None:
            saving.result()

    def close(self):
        """:meth:`flush`, then stop the journal's thread."""
        try:
            self.flush()
        finally:
            self._journaling.shutdown()


class _Started:
    """A slab whose compression :meth:`CubeSink.prepare` started."""

    __slots__ = ("started",)

    def __init__(self, started):
        self.started = started


def _versions() -> dict:
    return {"format": JOURNAL_FORMAT, "nylonflex_version": __version__,
            "model_digest": source_digest()}


def _check_existing(cfg, out, attrs, resume, overwrite, log):
    """What an existing cube at ``out`` allows: None (nothing to do) or whether this run
    replaces a finished cube (only with --overwrite)."""
    if attrs is None:
        return False
    same = attrs.get("config_sha256") == cfg.sha256
    complete = is_complete(attrs)
    if resume and not same and not overwrite:
        raise InputError(f"--resume: {out} was made from another config "
                         f"(sha256 {str(attrs.get('config_sha256', '?'))[:12]} vs "
                         f"{cfg.sha256[:12]}); add --overwrite (without --resume) to "
                         "replace it")
    if complete and same and not overwrite:
        log(f"{out} is already complete and up to date (same config); nothing to do")
        return None
    if not overwrite and not (resume and same):
        state = "finished" if complete else "incomplete"
        whose = "this" if same else "another"
        raise InputError(f"--out: {out} holds a {state} cube of {whose} config "
                         f"('{_short(attrs.get('name'))}'); it is not replaced: add "
                         "--overwrite to replace it, or choose another --out")
    return complete


def _short(value, n=40) -> str:
    text = str(value)
    return text if len(text) <= n else text[:n] + "..."


def _check_resume(cfg, out, journal, resume, log, overwrite=False):
    """Decide what to keep: ``None`` (nothing to do), or the journal's slab plan, its chunk
    length along radius, the indices of its finished slabs (an empty plan: start afresh)
    whether the run replaces a finished cube at ``out`` and the codec of the journaled
    chunks."""
    refuse_special(out, "--out")
    attrs = cube_attrs(out) if out.exists() else None
    if out.exists() and attrs is None:
        raise InputError(f"--out: {out} exists and is not a nylonflex cube; it is not "
                         "replaced: choose another --out or move it")
    journal.refuse_links()
    if journal.foreign():
        raise InputError(f"{journal.dir} exists and was not written by nylonflex; it is "
                         "not deleted: move it or choose another --out")
    manifest = journal.read_manifest() if journal.exists() else None
    if manifest is not None and not resume and not overwrite:
        raise InputError(f"{out}: an interrupted run of '{_short(manifest.get('name'))}' is "
                         f"in {journal.dir}; add --resume to finish it, --overwrite to start "
                         "afresh, or delete that folder")
    if manifest is None or not resume:
        replaces = _check_existing(cfg, out, attrs, resume, overwrite, log)
        if replaces is None:
            return None
        if resume:
            log("nothing to resume; starting the sweep")
        return [], None, set(), replaces, cfg.compression
    damaged = InputError(f"--resume: {journal.manifest} is damaged or was edited; delete "
                         f"{journal.dir} to start over")
    if not isinstance(manifest.get("config_sha256"), str):  # not JSON, or not a manifest
        raise damaged
    if manifest.get("config_sha256") != cfg.sha256:
        raise InputError(f"--resume: the config changed since the interrupted run "
                         f"(sha256 {str(manifest.get('config_sha256', '?'))[:12]} vs "
                         f"{cfg.sha256[:12]}); delete {journal.dir} to start over")
    # the journal's own slab plan and chunking: slab_megabytes may differ now (it is not in
    # the hash), and journaled slabs hold compressed chunks of the recorded shape. The plan
    # must be one the config implies (for some slab_megabytes), the codec one nylonflex
    # has: a manifest's digest of itself is no seal (an edit can recompute it), and each
    # slab's digest covers the codec and chunking it is decoded with
    try:
        slabs = [tuple(int(i) for i in s) for s in manifest.get("slabs", [])]
    except (TypeError, ValueError):
        slabs = []
    chunk = manifest.get("radius_chunk")
    if any(len(s) != 2 for s in slabs) or not plan_is_implied(cfg, slabs, chunk) or \
            manifest.get("compression", "gzip") not in CODECS or \
            manifest.get("digest") != manifest_digest(manifest):
        raise damaged
    now = _versions()
    differs = [f"{key} {_short(manifest.get(key))} (now {value})" for key, value in now.items()
               if manifest.get(key) != value]
    if differs:
        raise InputError(f"--resume: the journal in {journal.dir} was written with "
                         f"{'; '.join(differs)}; its slabs would mix two models: delete "
                         f"{journal.dir} and run again without --resume")
    # what the cube at out implies, not what the manifest says: a finished cube there is
    # kept until this run completes
    replaces = is_complete(attrs)
    codec = manifest.get("compression", "gzip")  # journaled chunks are in this codec
    if codec != cfg.compression:
        log(f"resuming with the journal's compression, {codec} (the config now says "
            f"{cfg.compression})")
    return slabs, chunk, journal.done() & set(range(len(slabs))), replaces, codec


def _needed_gigabytes(cfg) -> float:
    return 2 * bytes_per_radius(cfg) * cfg.shape[0] / 1e9


def _disk_full(exc) -> bool:
    return getattr(exc, "errno", None) in (errno.ENOSPC, errno.EDQUOT) or \
        "No space left" in str(exc) or "errno = 28" in str(exc)


def sweep_to_file(cfg: ResolvedConfig, out, *, resume=False, workers=None, scheduler=None,
                  progress=None, log=None, overwrite=False, command=None) -> Path:
    """Sweep ``cfg`` into the cube file ``out`` (one writer: a second run is refused).

    Parameters are those of :func:`nylonflex.run_sweep`; ``progress`` receives the designs
    each stored slab adds, ``log`` one-line messages. A finished cube at ``out`` is
    replaced only with ``overwrite`` (atomically: an interrupted replacement leaves it in
    place); with the same config it is up to date and left alone. Anything at ``out`` that
    is not a nylonflex cube is refused, never replaced. ``command`` (the command line that
    ran it, a str) goes into the cube's ``history`` line.

    Raises
    ------
    Interrupted
        Ctrl-C or SIGTERM stopped the run; ``out`` is marked incomplete (or, when it held a
        finished cube, left as it was) and the journal keeps every finished slab for
        ``--resume``.
    DiskFull
        The disk filled up; the journal keeps what was done for ``--resume``.
    """
    log = log or (lambda msg: None)
    out = Path(out)
    refuse_special(out, "--out")
    with exclusive(out) as building:
        journal = Journal(out)
        decision = _check_resume(cfg, out, journal, resume, log, overwrite)
        if decision is None:
            return out
        slabs, chunk, keep, replaces, codec = decision
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
                               "compression": codec, **_versions(),
                               "replaces": bool(replaces)})
            _write(cfg, out, building, journal, slabs, keep, chunk, codec, executor,
                   progress, log, replaces=replaces, command=command)
        except (OSError, RuntimeError) as exc:  # h5py's failed flush is a RuntimeError
            if not _disk_full(exc):
                raise
            raise DiskFull(f"the disk of {out.parent} is full; this run needs up to "
                           f"{_needed_gigabytes(cfg):.3g} GB (the cube, and during a "
                           "resume the interrupted run's file beside it, before "
                           f"compression); the finished slabs are kept in {journal.dir}: "
                           "free some space and run again with --resume") from None
        finally:
            executor.close()
    return out


def _write(cfg, out, building, journal, slabs, keep, chunk, codec, executor, progress, log, *,
           replaces=False, command=None):
    """Restore the journaled slabs, compute the rest; finish or mark the cube incomplete."""
    if keep and os.path.getsize(building) > 0:
        # the interrupted run's chunks lie in it: kept (in the journal) until restored
        renew_building(building, journal.aside_path())
    cube = CubeFile(building, coords(cfg), provenance(cfg), chunk, codec, cube_variables(cfg),
                    cfg.models, cfg.cooling_names)
    try:
        check_building(building)  # HDF5 opened it by name: still the file this run locked
        _fill(cfg, out, building, journal, slabs, keep, cube, executor, progress, log,
              replaces, command)
    except BaseException:
        cube.abandon()
        raise


def _restore(cfg, out, journal, slabs, keep, cube, progress, log) -> set:
    """Write the journal's slabs ``keep`` into the new cube from the files that hold their
    chunks; journal where they now lie; return the slabs restored (the others failed
    their checks and are recomputed)."""
    per_radius = cfg.n_designs // cfg.shape[0]
    decoding = cube.decoding()
    moved = {}  # slab -> its record, pointing into the new cube
    with ChunkSources([*journal.asides(), out]) as sources:
        for k in sorted(keep):
            i0, i1 = slabs[k]
            try:
                record = journal.load(k, slab=(i0, i1), config_sha=cfg.sha256,
                                      decoding=decoding)
                encoded = sources.slab(record, f"slab {k}")
            except SlabInvalid as why:
                log(f"journal: {why}; recomputing that slab")
                journal.discard(k)
                continue
            moved[k] = journal_record(encoded, cube.write_encoded(i0, i1, encoded))
            if progress is not None:
                progress((i1 - i0) * per_radius)
    if moved:  # the records point into the new cube once its chunks are durable
        cube.sync()
        for k, record in moved.items():
            journal.save(k, record, slab=slabs[k], config_sha=cfg.sha256, decoding=decoding)
    journal.drop_asides()
    return set(moved)


def _fill(cfg, out, building, journal, slabs, keep, cube, executor, progress, log,
          replaces, command=None):
    cube.write(0, 0, global_arrays(cfg))
    keep = _restore(cfg, out, journal, slabs, keep, cube, progress, log)
    todo = [k for k in range(len(slabs)) if k not in keep]
    sink = CubeSink(cube, journal, cfg.sha256)
    try:
        stats = run_slabs(cfg, slabs, todo, executor, sink, progress)
    finally:
        sink.close()
    done = len(keep) + len(stats.done)
    complete = not stats.stopped and done == len(slabs)
    seconds = stats.seconds
    final = run_attrs(executor.info(), complete=complete, seconds=seconds,
                      computed=stats.computed, resumed=len(keep), command=command)
    with deferred_signals():  # the publishing steps run to their end
        cube.close(final)
        if complete or not replaces:
            # readers open the published cube with a shared lock: this run's lock is made
            # shared first (docs/reliability.md), so that no reader meets it
            share_building(building)
            refuse_special(out, "--out")
            publish(building, out)
        if complete:
            journal.remove()
    if complete:
        log(f"wrote {out}: {cfg.n_designs:,} designs in {seconds:.2f} s "
            f"({final['designs_per_second']:.0f} designs/s computed)")
        return
    where = (f"{out} (the finished cube) is kept until this run completes"
             if replaces else f"{out} is marked incomplete")
    log(f"stopped: {done} of {len(slabs)} slabs saved in {journal.dir}; {where}. "
        "Finish with --resume.")
    raise Interrupted
