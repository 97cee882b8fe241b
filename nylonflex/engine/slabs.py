"""The one slab loop: an executor computes slabs, a sink stores them.

:func:`run_slabs` drives every sweep, in memory or to a cube file, local or on Dask:

- an *executor* yields ``(k, arrays)`` for the slab indices it is given, as they finish:
  :class:`LocalExecutor` (the engine's threads, the next slab computed while the last is stored)
  or :class:`nylonflex.engine.cluster.DaskExecutor`;
- a *sink* stores them: ``sink.put(k, i0, i1, arrays)``. :class:`MemorySink` fills an
  in-memory :class:`xarray.Dataset`; :class:`nylonflex.sweep.run.CubeSink` journals each slab
  and writes the HDF5 cube.

Ctrl-C or SIGTERM stops the loop after the slab being stored; what was stored stays, so an
interrupted run loses at most the slabs in flight. The handlers only record the signal (a
raise from a handler can land anywhere, even in a weakref callback that swallows it, or in
cleanup code where it prints a traceback); the loop checks the record after each slab. A
second signal while a slab is still computing stops at once.
"""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from ..config import ResolvedConfig
from ..variables import COOLING, COORDS, MODEL, slab_done_attrs
from . import threads
from .grid import ArrayPool, compute_slab, coords, cube_variables, global_arrays

__all__ = ["LocalExecutor", "MemorySink", "RunStats", "deferred_signals", "run_slabs",
           "set_workers"]


@dataclass
class RunStats:
    """What a run did: slabs stored, designs computed (not restored) and its wall time."""

    done: set
    computed: int
    seconds: float
    stopped: bool


class _Stop(Exception):
    """Raised by the SIGTERM handler to stop a sweep like Ctrl-C does."""


#: The signal record of the outermost :func:`deferred_signals` scope, and the second-signal
#: action of each open scope (innermost last); None outside any scope.
_SCOPE: dict | None = None

#: The first signal any scope recorded in this process (its number), or None: the exit
#: status of a stopped command is 128 + it (130 for Ctrl-C, 143 for SIGTERM).
_FIRST_SIGNAL: list = []


def stopping_signal() -> int | None:
    """The number of the first SIGINT or SIGTERM a :func:`deferred_signals` scope recorded
    in this process, or None."""
    return _FIRST_SIGNAL[0] if _FIRST_SIGNAL else None


@contextlib.contextmanager
def deferred_signals(on_second=None, earlier=()):
    """Record SIGINT and SIGTERM instead of acting on them; yields the list of signals seen.

    ``on_second`` (a callable) runs on the second signal (e.g. raise to stop at once);
    without it every signal is only recorded. Scopes nest: an inner one shares the outer
    one's record, so a Ctrl-C that came while a run was being set up (compiling, opening
    files) is seen by the slab loop, which then stops before it computes anything; while
    the inner scope is open its ``on_second`` applies. Outside the main thread it does
    nothing. ``earlier`` (signal numbers) are signals the caller saw before the outermost
    scope opened (the command line's own record, from its process's start): the scope begins
    with them, so a signal that came while modules were imported stops the run too, even
    where a finaliser dropped the exception it raised.
    """
    global _SCOPE
    if threading.current_thread() is not threading.main_thread():
        yield []
        return
    if _SCOPE is not None:  # nested: same record, this scope's second-signal action
        _SCOPE["actions"].append(on_second)
        try:
            yield _SCOPE["seen"]
        finally:
            _SCOPE["actions"].pop()
        return
    scope = _SCOPE = {"seen": [int(sig) for sig in earlier], "actions": [on_second]}
    if scope["seen"] and not _FIRST_SIGNAL:
        _FIRST_SIGNAL.append(scope["seen"][0])

    def handler(signum, frame):
        scope["seen"].append(signum)
        if not _FIRST_SIGNAL:
            _FIRST_SIGNAL.append(int(signum))
        action = scope["actions"][-1]
        if len(scope["seen"]) > 1 and action is not None:
            action()

    previous = {sig: signal.signal(sig, handler) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield scope["seen"]
    finally:
        _SCOPE = None
        for sig, old in previous.items():
            signal.signal(sig, old)


def set_workers(workers=None) -> int:
    """Set (or read) the number of threads a kernel is split over; ``workers`` in
    [1, cores] (:mod:`.threads`)."""
    return threads.set_workers(workers)


class LocalExecutor:
    """Slabs on this machine's cores: the kernel split over the engine's threads, one slab ahead.

    The kernel releases the GIL, so storing slab k (compression, journal) overlaps the
    arithmetic of slab k+1; at most two slabs are in memory.
    """

    def __init__(self, workers=None):
        self.workers = set_workers(workers)

    def info(self) -> dict:
        return {"scheduler": "local (threads)", "workers": str(self.workers)}

    def map_slabs(self, cfg, slabs, todo, prepare=None, remote=None):
        """Yield ``(k, arrays)`` as slabs finish; with ``prepare``, ``(k, prepare(i0,
        arrays))``, called in the computing thread (a sink's compression starts there).
        ``remote`` (a step for executors that compute elsewhere) is not used: ``prepare``
        runs in this process already.

        A slab's arrays are reused for a later slab once the caller asks for the next one
        (they come from an :class:`~nylonflex.engine.grid.ArrayPool`): store or copy them
        before that, as the sinks do.
        """
        buffers = ArrayPool()

        def job(i0, i1):
            arrays = compute_slab(cfg, i0, i1, pool=buffers)
            return arrays, (arrays if prepare is None else prepare(i0, arrays))

        with ThreadPoolExecutor(1, thread_name_prefix="nylonflex-slab") as pool:
            pending = None
            for k in [*todo, None]:
                future = None if k is None else pool.submit(job, *slabs[k])
                if pending is not None:
                    arrays, item = pending[1].result()
                    yield pending[0], item
                    buffers.give_back(arrays)  # stored: the next slabs may write them
                pending = (k, future)

    def close(self):
        pass


def run_slabs(cfg: ResolvedConfig, slabs, todo, executor, sink, progress=None) -> RunStats:
    """Compute the slabs ``todo`` with ``executor`` and store each in ``sink``.

    Parameters
    ----------
    cfg : ResolvedConfig
        The design space.
    slabs : list of (int, int)
        The slab plan: radius index ranges.
    todo : iterable of int
        Indices into ``slabs`` to compute.
    executor : LocalExecutor or DaskExecutor
        Yields ``(k, arrays)`` from ``map_slabs(cfg, slabs, todo)`` (with
        ``prepare=sink.prepare`` and ``remote=sink.remote`` when the sink has them).
    sink : object with ``put(k, i0, i1, arrays)``
        Stores a finished slab.
    progress : callable, optional
        Called with the number of designs each stored slab adds.

    Returns
    -------
    RunStats
        ``stopped`` is True when Ctrl-C or SIGTERM ended the loop early.
    """
    per_radius = cfg.n_designs // cfg.shape[0]
    stats = RunStats(done=set(), computed=0, seconds=0.0, stopped=False)

    def stop_now():
        raise _Stop()

    t0 = time.perf_counter()
    try:
        with deferred_signals(on_second=stop_now) as seen:
            if seen:  # Ctrl-C or SIGTERM while the run was set up: stop before computing
                raise _Stop()
            # a sink with a first step (CubeSink starts compressing) has the executor run it
            # as soon as a slab is computed
            first = {"prepare": sink.prepare} if hasattr(sink, "prepare") else {}
            if getattr(sink, "remote", None) is not None:  # a step a Dask worker can run
                first["remote"] = sink.remote
            finished = executor.map_slabs(cfg, slabs, todo, **first)
            try:
                for k, arrays in finished:
                    i0, i1 = slabs[k]
                    sink.put(k, i0, i1, arrays)
                    stats.done.add(k)
                    stats.computed += (i1 - i0) * per_radius
                    if progress is not None:
                        progress((i1 - i0) * per_radius)
                    if seen:
                        raise _Stop()
            finally:
                # an error of the sink (a full disk) would leave the executor's generator
                # suspended until it is collected: closed here, its slab in flight ends
                # before the error goes on
                close = getattr(finished, "close", None)
                if close is not None:
                    close()
    except (KeyboardInterrupt, _Stop):
        stats.stopped = True
    finally:
        stats.seconds = time.perf_counter() - t0
    return stats


class MemorySink:
    """Collects a sweep's slabs into arrays; :meth:`dataset` makes the cube."""

    def __init__(self, cfg: ResolvedConfig):
        self.cfg = cfg
        self.coords = coords(cfg)
        sizes = {k: len(v) for k, v in self.coords.items()}
        sizes["model"] = len(cfg.models)
        sizes["cooling"] = len(cfg.coolings)
        self.variables = cube_variables(cfg)
        self.data = {name: np.empty([sizes[d] for d in dims], dtype=v.dtype)
                     for name, (v, dims) in self.variables.items()}
        self.data.update(global_arrays(cfg))
        self.done = np.zeros(sizes["radius"], np.int8)

    def put(self, k, i0, i1, arrays):
        for name, arr in arrays.items():
            self.data[name][i0:i1] = arr
        self.done[i0:i1] = 1

    def dataset(self, attrs: dict):
        """The cube as an :class:`xarray.Dataset` (every variable with its registry attrs)."""
        import xarray as xr

        coords = {name: (name, values, COORDS[name].attrs())
                  for name, values in self.coords.items()}
        if len(self.cfg.models) > 1:
            coords["model"] = ("model", np.array(self.cfg.models, dtype=object),
                               MODEL.attrs())
        if self.cfg.coolings:
            coords["cooling"] = ("cooling", np.array(self.cfg.cooling_names, dtype=object),
                                 COOLING.attrs())
        ds = xr.Dataset(
            {name: (dims, self.data[name], v.attrs())
             for name, (v, dims) in self.variables.items()},
            coords=coords, attrs=attrs)
        ds["slab_done"] = ("radius", self.done, slab_done_attrs())
        return ds
