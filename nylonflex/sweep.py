"""``nylonflex.run_sweep``: a config's design space, in memory or into a cube file.

Both go through the engine's one slab loop (:func:`nylonflex.engine.slabs.run_slabs`): in
memory with :class:`~nylonflex.engine.slabs.MemorySink`, to a file with the journaled
:class:`~nylonflex.storage.CubeSink`; locally or on a Dask cluster.
"""

from __future__ import annotations

from pathlib import Path

from .config import ResolvedConfig

__all__ = ["default_output", "run_sweep"]


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
    nylonflex.storage.Interrupted
        Ctrl-C or SIGTERM stopped a run to a file; finish it with ``resume=True``.
    """
    if out is None:
        return _in_memory(cfg, workers, scheduler, progress)
    from .storage import open_cube, sweep_to_file

    sweep_to_file(cfg, out, resume=resume, workers=workers, scheduler=scheduler,
                  progress=progress, log=log, overwrite=overwrite)
    return open_cube(out)


def _in_memory(cfg, workers, scheduler, progress):
    from .engine.grid import plan_slabs
    from .engine.provenance import provenance
    from .engine.slabs import LocalExecutor, MemorySink, run_slabs

    if scheduler is None:
        executor = LocalExecutor(workers)
    else:
        from .engine.cluster import DaskExecutor

        executor = DaskExecutor(scheduler)
    slabs, _ = plan_slabs(cfg)
    sink = MemorySink(cfg)
    try:
        stats = run_slabs(cfg, slabs, range(len(slabs)), executor, sink, progress)
    finally:
        executor.close()
    if stats.stopped:
        raise KeyboardInterrupt
    return sink.dataset({**provenance(cfg), **executor.info(), "complete": "true"})
