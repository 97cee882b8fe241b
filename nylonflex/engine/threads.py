"""The engine's threads: one compiled kernel body, split over Python threads.

Every kernel releases the GIL (``nogil``) and takes the range of items it computes, so a
slab of the grid or a batch of designs runs as contiguous chunks on :func:`workers`
threads, and a serial run (a Dask worker's slab, a thread that is already one of several)
is the same compiled body called once. Numba's ``parallel=True`` would
compile each kernel a second time for its threaded form, about as long again as the first
on a cold cache (benchmarks/README.md), for no gain here: the chunks are independent and
write disjoint parts of the output, so the numbers do not depend on how they are split.
"""

from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

from ..units import InputError

__all__ = ["cores", "run_chunks", "set_workers", "workers"]

_STATE = {"workers": None}


def cores() -> int:
    """The cores this process may run on (its CPU affinity) [1]."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def set_workers(n=None) -> int:
    """Set (or, with None, read) the number of threads a kernel is split over; ``n`` in
    [1, cores]."""
    if n is None:
        return workers()
    if isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= cores():
        raise InputError(f"--workers: must be in [1, {cores()}], got {n}")
    _STATE["workers"] = n
    return n


def workers() -> int:
    """The number of threads a kernel is split over (default: every core) [1]."""
    return _STATE["workers"] or cores()


def run_chunks(call, n: int, *, parallel: bool = True) -> None:
    """``call(k0, k1)`` on contiguous chunks of ``range(n)``: one chunk a thread of
    :func:`workers` when ``parallel`` (the calling thread takes the first), else one call.
    An exception in any chunk is raised here once every chunk has ended."""
    threads = min(workers(), n) if parallel else 1
    if threads <= 1:
        call(0, n)
        return
    bounds = [n * j // threads for j in range(threads + 1)]
    error = None
    # a pool of this call's own: its threads end with it (a pool kept for the process
    # left a segfault in the interpreter's last collection after a failed sweep)
    with ThreadPoolExecutor(threads - 1, thread_name_prefix="nylonflex-kernel") as pool:
        futures = [pool.submit(call, bounds[j], bounds[j + 1]) for j in range(1, threads)]
        try:
            call(bounds[0], bounds[1])
        except BaseException as exc:  # noqa: BLE001 - raised below, after the other chunks
            error = exc
        for f in futures:
            try:
                f.result()
            except BaseException as exc:  # noqa: BLE001
                error = error or exc
    if error is not None:
        raise error
