"""Sweeps on a Dask distributed cluster: slabs are tasks, the client is the single writer.

:func:`nylonflex.run_sweep` with ``scheduler=`` hands the slabs still to do to a
:class:`DaskExecutor`, the executor of the one slab loop (:mod:`.slabs`). Each task computes
one slab of radii with the design kernel in the worker's own thread
(:func:`nylonflex.engine.grid.compute_slab` with ``parallel=False``): the
cluster's worker processes and threads are the only level of parallelism, so the
kernels are never split over threads inside Dask's threads and never oversubscribe a
worker's cores.
Each worker encodes the slab it computed as the cube stores it (the sink's picklable
encoder, ``remote``: shuffled and compressed chunks, a fifth of the arrays' bytes), and the
results come back to the client as they finish; the client journals and writes each one, as
a local run does, so resume and the cube's format are the same.

Memory stays bounded by the slab size whatever the grid: at most :data:`IN_FLIGHT_PER_THREAD`
slabs per worker thread are submitted at a time, a finished slab stays on its worker until
the client fetches it, and the client holds three slabs at most: the one being written,
the one it hands over next, and one being fetched meanwhile.

Both paths run the same compiled loop body on the same slab boundaries, and every element
of a slab is computed by a deterministic sequence of floating-point operations that depends
on nothing but its own indices, so a cluster's cube is identical, bit for bit, to a local
one made with the same nylonflex, Numba and NumPy versions. Workers are checked for those
versions before any work (and each task checks again, for workers that join later).
"""

from __future__ import annotations

import logging
import os
import time
import uuid
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor

import numpy

from .. import __version__
from ..kernels import source_digest
from ..units import InputError
from .dask_connect import CONNECT_TIMEOUT, _normalise_address, connect_client
from .grid import ArrayPool, compute_slab

__all__ = ["CONNECT_TIMEOUT", "IN_FLIGHT_PER_THREAD", "STALL_TIMEOUT", "WORKER_WAIT",
           "DaskExecutor", "connect_client"]

#: Seconds to wait for the first worker to join a scheduler that has none.
WORKER_WAIT = 60.0
#: Seconds without a finished slab, while no worker is alive, before a run gives up
#: (``DaskExecutor(stall=...)``, or the environment variable ``NYLONFLEX_DASK_STALL``);
#: the journal keeps what was done for --resume.
STALL_TIMEOUT = 60.0
#: Slabs submitted per worker thread at a time: one computing, one queued behind it.
IN_FLIGHT_PER_THREAD = 2

def _versions() -> dict:
    """What decides a slab's bits: nylonflex's version and model sources, Numba, NumPy.

    ``model`` is the digest of the physics and kernel sources, so an edited formula on one
    side is caught even where the version number did not change.
    """
    from importlib.metadata import version

    return {"nylonflex": __version__, "model": source_digest(), "numba": version("numba"),
            "numpy": numpy.__version__}


def _mismatch(expected: dict, got: dict) -> str:
    return ", ".join(f"{k} {got.get(k)} (client {v})" for k, v in expected.items()
                     if got.get(k) != v)


def _quiet_dask_logs() -> dict:
    """Silence dask.distributed's loggers below CRITICAL (a lost scheduler makes them log
    reconnect tracebacks); returns the levels to restore with :func:`_restore_logs`."""
    names = ["distributed", *(n for n in logging.root.manager.loggerDict
                              if n.startswith("distributed."))]
    saved = {}
    for name in names:
        log = logging.getLogger(name)
        saved[name] = log.level
        log.setLevel(logging.CRITICAL)
    return saved


def _restore_logs(saved: dict):
    for name, level in saved.items():
        logging.getLogger(name).setLevel(level)


def _stall_seconds() -> float:
    """The stall timeout [s]: ``NYLONFLEX_DASK_STALL`` if set, else :data:`STALL_TIMEOUT`."""
    text = os.environ.get("NYLONFLEX_DASK_STALL", "").strip()
    if not text:
        return STALL_TIMEOUT
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0.0 < value < 1e7:
        raise InputError(f"NYLONFLEX_DASK_STALL: expected seconds in (0, 1e7), got "
                         f"{text[:40]!r}")
    return value


def _slab_task(cfg, i0: int, i1: int, expected: dict, remote=None):
    """Runs on a worker: one slab with the serial kernel (one level of parallelism), then
    ``remote(i0, arrays)`` when given (the sink's encoding: the client receives the
    compressed chunks, not the arrays)."""
    bad = _mismatch(expected, _versions())
    if bad:
        raise RuntimeError(f"this Dask worker runs {bad}; install the client's versions so "
                           "that the cube is reproducible")

    if remote is None:
        return compute_slab(cfg, i0, i1, parallel=False)
    # the step keeps none of the arrays (what it sends is new: compressed chunks, copies),
    # so they go back to this worker's pool for its next slab, as a local sweep's do:
    # fresh arrays cost the kernel the zeroing of every page it writes
    arrays = compute_slab(cfg, i0, i1, parallel=False, pool=_WORKER_POOL)
    try:
        return remote(i0, arrays)
    finally:
        _WORKER_POOL.give_back(arrays)


#: Each worker process's output arrays, handed back after a slab is encoded (``_slab_task``).
_WORKER_POOL = ArrayPool()


class DaskExecutor:
    """Runs slabs as tasks on a Dask distributed scheduler.

    Parameters
    ----------
    address : str or cluster
        ``tcp://HOST:PORT`` (``HOST:PORT`` means tcp), or a dask cluster object such as
        ``LocalCluster`` or dask-jobqueue's ``SLURMCluster`` (its ``scheduler_address``).
    timeout : float
        Seconds to wait for the scheduler to answer [s].
    worker_wait : float
        Seconds to wait for at least one worker to join [s].
    stall : float, optional
        Seconds without a finished slab while no worker is alive before the run stops with
        a RuntimeError (resumable) [s]; default ``NYLONFLEX_DASK_STALL`` or 60.

    Raises
    ------
    InputError
        The address is malformed, or no scheduler answers there within ``timeout``.
    RuntimeError
        No worker joins within ``worker_wait``, or a worker runs other nylonflex, Numba or
        NumPy versions than the client.
    """

    def __init__(self, address, *, timeout: float = CONNECT_TIMEOUT,
                 worker_wait: float = WORKER_WAIT, stall: float | None = None):
        self.address = _normalise_address(address)
        self.stall = _stall_seconds() if stall is None else float(stall)
        self.client = connect_client(None, self.address, timeout)
        self._quiet = _quiet_dask_logs()  # its reconnect tracebacks on scheduler loss
        self._pending: set = set()
        self._used: set[str] = set()
        self._fetcher = ThreadPoolExecutor(1, thread_name_prefix="nylonflex-fetch")
        try:
            self._check_workers(worker_wait)
        except BaseException:
            self.client.close()
            _restore_logs(self._quiet)
            raise

    def _check_workers(self, worker_wait):
        try:
            self.client.wait_for_workers(1, timeout=worker_wait)
        except TimeoutError:
            raise RuntimeError(f"no Dask worker joined {self.address} within "
                               f"{worker_wait:g} s; start some with 'dask worker "
                               f"{self.address} --nthreads 1'") from None
        expected = _versions()
        for worker, got in self.client.run(_versions).items():
            bad = _mismatch(expected, got)
            if bad:
                raise RuntimeError(f"Dask worker {worker} runs {bad}; install the client's "
                                   "versions on every worker so that the cube is "
                                   "reproducible")
        self._threads = self.client.nthreads()

    def info(self) -> dict:
        """Provenance for the cube: the scheduler and the number of workers.

        ``workers`` counts the workers connected at the start or, if more took part
        (workers that joined later), those that computed slabs.
        """
        n = max(len(self._threads), len(self._used))
        return {"scheduler": self.address, "workers": str(n)}

    def _capacity(self) -> int:
        try:
            self._threads = self.client.nthreads()
        except (OSError, TimeoutError):
            pass
        return IN_FLIGHT_PER_THREAD * max(1, sum(self._threads.values()))

    def map_slabs(self, cfg, slabs: list[tuple[int, int]], todo: Iterable[int],
                  prepare=None, remote=None) -> Iterator[tuple[int, dict]]:
        """Yield ``(k, arrays)`` for each slab index in ``todo``, as they finish.

        ``arrays`` is what ``compute_slab(cfg, *slabs[k], parallel=False)`` returns,
        computed on a worker; with ``remote`` (a picklable step, the sink's encoder), what
        ``remote(i0, arrays)`` returns on the worker, so that only its result travels;
        else ``prepare(i0, arrays)`` when given (a sink's first step, run here once the
        slab is fetched). At most :data:`IN_FLIGHT_PER_THREAD` slabs per
        worker thread are submitted at once; a slab is released from the cluster once
        yielded.
        """
        from distributed import as_completed

        expected = _versions()
        token = uuid.uuid4().hex[:8]
        queue = iter(todo)
        done = as_completed(loop=self.client.loop, with_results=False)

        def submit() -> bool:
            k = next(queue, None)
            if k is None:
                return False
            i0, i1 = slabs[k]
            fut = self.client.submit(_slab_task, cfg, i0, i1, expected, remote, pure=False,
                                     key=f"nylonflex-slab-{token}-{k:06d}")
            fut.slab = k
            self._pending.add(fut)
            done.add(fut)
            return True

        def top_up():
            capacity = self._capacity()
            while len(self._pending) < capacity and submit():
                pass

        def finish(fut, fetch):
            # a slab whose worker died while it was fetched is recomputed: that wait too
            # gives up when no worker is left (the watchdog)
            self._wait_until(fetch.done)
            try:
                arrays = fetch.result()
            except Exception as exc:  # noqa: BLE001 - a lost scheduler is one line
                raise self._lost(exc) from None
            self._used.update(self._who_ran(fut))
            self._pending.discard(fut)
            fut.release()
            top_up()
            if prepare is not None and remote is None:
                arrays = prepare(slabs[fut.slab][0], arrays)
            return fut.slab, arrays

        # While the caller writes one slab, the next finished one is fetched in a thread.
        top_up()
        fetching = None
        while fetching is not None or not done.is_empty():
            if fetching is not None and not done.has_ready():
                yield finish(*fetching)  # nothing else finished: don't wait for it
                fetching = None
                continue
            self._wait_until(done.has_ready)
            fut = next(done)
            started = (fut, self._fetcher.submit(fut.result))
            if fetching is not None:
                yield finish(*fetching)
            fetching = started

    def _wait_until(self, ready):
        """Wait until ``ready()``; give up after ``stall`` seconds with no live worker
        (every worker died, or the scheduler is gone)."""
        last_alive = time.monotonic()
        while not ready():
            time.sleep(0.2)
            try:
                alive = bool(self.client.scheduler_info().get("workers"))
            except Exception:  # noqa: BLE001 - a lost scheduler counts as no workers
                alive = False
            if alive and self.client.status == "running":
                last_alive = time.monotonic()
            elif time.monotonic() - last_alive > self.stall:
                raise RuntimeError(
                    f"no slab finished for {self.stall:g} s and no Dask worker is alive at "
                    f"{self.address}; the finished slabs are journaled: start workers (or "
                    "the scheduler) and run again with --resume")

    def _lost(self, exc):
        """The error to raise for ``exc`` from a slab: the scheduler's loss in one line
        with what to do, anything else (a worker's error) as it is."""
        import asyncio

        gone = self.client.status not in ("running", "connecting") or isinstance(
            exc, (asyncio.CancelledError, OSError, TimeoutError)) or \
            "scheduler-connection-lost" in str(exc) or "CommClosed" in type(exc).__name__
        if not gone and type(exc).__name__ not in ("FuturesCancelledError",
                                                   "CancelledError"):
            return exc
        return RuntimeError(
            f"lost the Dask scheduler at {self.address} ({type(exc).__name__}); the "
            "finished slabs are journaled: start the scheduler and workers and run again "
            "with --resume")

    def _who_ran(self, fut) -> set[str]:
        # the worker that holds the result ran the task (results are not replicated)
        try:
            return set(self.client.who_has([fut]).get(fut.key, ()))
        except Exception:  # noqa: BLE001 - a lost scheduler cancels the future: nobody
            return set()

    def close(self):
        """Cancel what is still queued and disconnect; the cluster itself keeps running."""
        client = getattr(self, "client", None)
        if client is None:
            return
        try:
            if self._pending and client.status == "running":
                client.cancel(list(self._pending), force=True)
            self._pending.clear()
        except Exception:  # noqa: BLE001 - the scheduler is gone: nothing to cancel
            pass
        finally:
            try:
                client.close(timeout=5)
            except Exception:  # noqa: BLE001
                pass
            self._fetcher.shutdown(wait=False, cancel_futures=True)
            _restore_logs(getattr(self, "_quiet", {}))
