"""``nylonflex.run_sweep``: a config's design space, in memory or into a cube file.

Both go through the engine's one slab loop (:func:`nylonflex.engine.slabs.run_slabs`): in
memory with :class:`~nylonflex.engine.slabs.MemorySink`, to a file with the journaled
:class:`~nylonflex.sweep.run.CubeSink`; locally or on a Dask cluster.
"""

from __future__ import annotations

import itertools
import time
from pathlib import Path

import numpy as np

from ..config import ResolvedConfig
from ..engine.grid import (bytes_per_radius, check_physics, compute_slab, coords,
                           cube_variables, global_arrays, plan_slabs)
from ..engine.provenance import provenance, typed_info
from ..engine.slabs import LocalExecutor, MemorySink, deferred_signals, run_slabs, set_workers
from ..engine.warmup import grid_families, warm_up_aside, warm_up_codec, warm_up_grid
from ..storage.codec import CODECS, chunk_shape, encode_chunk, compiled_shuffle
from ..storage.reader import open_cube
from .run import sweep_to_file

__all__ = ["default_output", "estimate", "prepare", "run_sweep", "sweep_file"]


def default_output(cfg: ResolvedConfig) -> Path:
    """``sweeps/<name>/cube.h5`` under the current directory."""
    return Path("sweeps") / cfg.name / "cube.h5"


def run_sweep(cfg: ResolvedConfig, out=None, *, resume: bool = False, workers=None,
              scheduler=None, progress=None, log=None, overwrite: bool = False):
    """Evaluate the config's design space.

    Parameters
    ----------
    cfg : ResolvedConfig
        From :func:`nylonflex.load_config`.
    out : path, optional
        Cube file to write. Without it the cube is built in memory (mind its size).
    resume : bool
        Finish an interrupted run of the same config at ``out``; refuse a changed config.
    overwrite : bool
        Replace a cube already at ``out`` (atomically: until the new one is complete, the
        old one stays). Without it an existing cube of the same config is up to date and
        left alone, and anything else at ``out`` is refused.
    workers : int, optional
        Local threads (default: all cores).
    scheduler : str or dask cluster, optional
        A Dask distributed scheduler, ``tcp://host:port``: slabs run there.
    progress : callable, optional
        Called with the number of designs each finished slab adds.
    log : callable, optional
        Receives one-line messages for the user.

    Returns
    -------
    xarray.Dataset
        The cube (opened lazily from ``out`` when given).

    Raises
    ------
    nylonflex.sweep.run.Interrupted
        Ctrl-C or SIGTERM stopped a run to a file; finish it with ``resume=True``.
    """
    check_physics(cfg)
    if out is None:
        from ..storage.accessor import CubeAccessor  # noqa: F401 - registers ds.nf

        with deferred_signals(on_second=_interrupt):
            _warm_up(cfg, workers, scheduler, log)
            return _in_memory(cfg, workers, scheduler, progress)

    sweep_file(cfg, out, resume=resume, workers=workers, scheduler=scheduler,
               progress=progress, log=log, overwrite=overwrite)
    return open_cube(out)


def sweep_file(cfg: ResolvedConfig, out, *, resume: bool = False, workers=None,
               scheduler=None, progress=None, log=None, overwrite: bool = False,
               command=None) -> Path:
    """:func:`run_sweep` into the cube file ``out``, without opening the cube afterwards.

    The parameters and exceptions are :func:`run_sweep`'s; returns ``out`` as a Path. The
    command line uses it: a sweep without charts never imports xarray. ``command``: the
    command line, recorded in the cube's ``history``.
    """
    check_physics(cfg)  # before any file
    # from here on Ctrl-C and SIGTERM are recorded, never raised inside a finaliser (where
    # Python would print and drop them): the slab loop stops on them, before or after a slab
    with deferred_signals(on_second=_interrupt):
        _warm_up(cfg, workers, scheduler, log)
        return sweep_to_file(cfg, out, resume=resume, workers=workers,
                             scheduler=scheduler, progress=progress, log=log,
                             overwrite=overwrite, command=command)


def _interrupt():
    """The second Ctrl-C while a run is set up: stop at once."""
    raise KeyboardInterrupt


def prepare(cfg: ResolvedConfig, *, workers=None, scheduler=None, log=None, meanwhile=None):
    """Import and load (or compile) what a sweep of ``cfg`` runs: the kernel.

    :func:`sweep_file` and :func:`run_sweep` do it themselves; a caller may do it first to
    keep the start apart (the command line does, with the garbage collector paused).
    Parameters as :func:`run_sweep`'s; ``meanwhile`` (a callable), the caller's next work
    that needs no kernel, runs while the kernel compiles in a second process when it has
    to compile (:func:`~nylonflex.engine.warmup.warm_up_aside`), else first: the command
    line imports the chart libraries so.
    """
    check_physics(cfg)
    _warm_up(cfg, workers, scheduler, log, meanwhile)


#: The (config hash, workers) whose kernel this process has warmed up: :func:`prepare`
#: followed by :func:`sweep_file` warms once.
_WARMED: set = set()


def _warm_up(cfg, workers, scheduler, log, meanwhile=None):
    """Compile (or load) the local kernel first, so that the run's timings exclude it;
    ``meanwhile`` as :func:`prepare`'s."""
    if scheduler is not None or (cfg.sha256, workers) in _WARMED:
        if meanwhile is not None:
            meanwhile()
        return

    set_workers(workers)
    aside = 0.0
    if meanwhile is not None:
        aside = warm_up_aside(lambda: warm_up_grid(cfg, notice=log), grid_families(cfg),
                              meanwhile)
    compiled = warm_up_grid(cfg, notice=log)
    _WARMED.add((cfg.sha256, workers))
    if (compiled or aside) and log is not None:
        where = "" if compiled else " in a second process"
        log(f"kernels compiled in {compiled or aside:.1f} s{where} (not counted below)")


def _in_memory(cfg, workers, scheduler, progress):
    if scheduler is None:
        executor = LocalExecutor(workers)
    else:
        from ..engine.cluster import DaskExecutor

        executor = DaskExecutor(scheduler)
    slabs, _ = plan_slabs(cfg)
    sink = MemorySink(cfg)
    try:
        stats = run_slabs(cfg, slabs, range(len(slabs)), executor, sink, progress)
    finally:
        executor.close()
    if stats.stopped:
        raise KeyboardInterrupt

    return sink.dataset({**provenance(cfg), **typed_info(executor.info()),
                         "complete": np.int8(1)})


def _resident_bytes() -> int:
    """This process's resident memory now [B] (Python, the libraries, the kernels)."""
    import psutil

    return int(psutil.Process().memory_info().rss)


def _packed_bytes(value, chunks, codec, compiled: bool) -> int:
    """Bytes of ``value`` stored in ``chunks`` with the cube's codec (name), shuffled by the
    compiled loop or by NumPy (``compiled``), as the cube will be."""
    codec = CODECS[codec]
    if codec.encode is None:  # lz4: HDF5 compresses; zstd's size is close enough here
        codec = CODECS["zstd"]

    chunks = tuple(min(c, n) for c, n in zip(chunks, value.shape))
    starts = [range(0, n, c) for n, c in zip(value.shape, chunks)]
    total = 0
    for corner in itertools.product(*starts):
        block = value[tuple(slice(i, i + c) for i, c in zip(corner, chunks))]
        total += len(encode_chunk(block, chunks, codec, compiled))
    return total


#: Designs the dry run computes to measure the rate and the compression (at least one radius).
_SAMPLE_DESIGNS = 20_000


def estimate(cfg: ResolvedConfig, *, workers=None, notice=None) -> dict:
    """What a sweep of ``cfg`` will cost, measured on a small sample; writes nothing.

    A few radii spread over the grid are computed with the kernel a local run uses (after
    compiling it, which is not counted), and their arrays compressed as the cube is
    (with the config's codec), so the rate and the compression ratio are this machine's and this
    design space's.

    Parameters
    ----------
    cfg : ResolvedConfig
        The sweep's config.
    workers : int, optional
        Local threads (default: all cores).
    notice : callable, optional
        Receives a one-line notice while the kernels compile.

    Returns
    -------
    dict
        ``shape`` (axis -> size), ``designs``, ``slabs``, ``slab_bytes`` [B] (largest
        slab in memory), ``memory_bytes`` [B] (this process now, plus two slabs and their
        compressed copies, the most a local run holds), ``raw_bytes`` [B] (the cube uncompressed),
        ``disk_bytes`` [B] (on disk, at the sample's compression ratio),
        ``compression_ratio`` [-], ``sample_designs``, ``designs_per_second`` [1/s]
        (compute), ``compress_seconds`` [s] and ``seconds`` [s] (estimated wall time,
        compute plus compression; they partly overlap, so a bound), ``compile_seconds`` [s].
    """
    check_physics(cfg)  # what a sweep would refuse, a dry run refuses

    set_workers(workers)
    compiled = warm_up_grid(cfg, notice=notice)
    slabs, radius_chunk = plan_slabs(cfg)
    n_radius = cfg.shape[0]
    per_radius = cfg.n_designs // n_radius
    k = int(min(n_radius, max(4, -(-_SAMPLE_DESIGNS // per_radius))))
    # up to four blocks of consecutive radii spread over the axis, each one kernel call
    groups = 1 if k >= n_radius else min(4, k)
    size = -(-k // groups)
    starts = np.unique(np.linspace(0, n_radius - size, groups).round().astype(int))
    # as the cube file has them: with several models or cooling sets, their dimensions too
    sizes = {name: len(v) for name, v in coords(cfg).items()}
    sizes.update(model=len(cfg.models), cooling=len(cfg.cooling_names))
    dims = {name: d for name, (_, d) in cube_variables(cfg).items()}
    globals_bytes = sum(v.nbytes for v in global_arrays(cfg).values())
    axes_bytes = 8 * sum(len(v) for v in (*cfg.axes.values(), *cfg.curves.values()))
    raw_total = n_radius * bytes_per_radius(cfg) + globals_bytes + axes_bytes
    # the sample is shuffled as the cube will be, and a compiled shuffle is compiled before
    # the timing, as the kernel is
    shuffle_compiled = compiled_shuffle(raw_total)
    if shuffle_compiled:
        compiled += warm_up_codec(notice=notice)
    compute = compress = 0.0
    raw = packed = 0
    for i in starts:
        t0 = time.perf_counter()
        arrays = compute_slab(cfg, int(i), int(i) + size)
        compute += time.perf_counter() - t0
        t0 = time.perf_counter()
        for name, value in arrays.items():
            raw += value.nbytes
            packed += _packed_bytes(value, chunk_shape(dims[name], sizes,
                                                   min(radius_chunk, size)), cfg.compression,
                                  shuffle_compiled)
        compress += time.perf_counter() - t0
    picks = range(len(starts) * size)
    sample = len(picks) * per_radius
    ratio = packed / raw if raw else 1.0
    per_slab = max(i1 - i0 for i0, i1 in slabs) * bytes_per_radius(cfg)
    rate = sample / compute if compute > 0 else float("inf")
    compress_seconds = compress * cfg.n_designs / sample
    return {
        "shape": {name: len(v) for name, v in cfg.axes.items()},
        "designs": cfg.n_designs,
        "slabs": len(slabs),
        "slab_bytes": per_slab,
        "memory_bytes": int(_resident_bytes() + 2 * per_slab * (1 + ratio)),
        "raw_bytes": int(raw_total),
        "disk_bytes": int(raw_total * ratio),
        "compression_ratio": ratio,
        "sample_designs": int(sample),
        "designs_per_second": rate,
        "compress_seconds": compress_seconds,
        "seconds": cfg.n_designs / rate + compress_seconds,
        "compile_seconds": compiled,
    }
