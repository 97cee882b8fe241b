"""Compile the kernels before the work that needs them, with a notice when they compile.

The first run after installing (or after the model's sources change) compiles the Numba
kernels, seconds to minutes that would otherwise be counted as compute and leave the user
looking at a silent terminal. :func:`warm_up_grid` and :func:`warm_up_points` call the
kernels once on a one-design problem; a later run loads them from Numba's cache in a
fraction of a second. Whether they compile is Numba's own signal (its ``numba:compile``
event, :mod:`nylonflex.kernels.compiling`), never a timer: a warm run on a busy machine
prints nothing, a cold one names each kernel it compiles with a measured estimate. The
notice is a callback: the engine never prints.
"""

from __future__ import annotations

import dataclasses
import os
import signal
import sys
import threading
import time
from contextlib import nullcontext

import numpy as np

from ..config import ResolvedConfig, parse_config
from ..kernels import cache
from .grid import compute_slab
from .model_slab import paper_kernel
from .pointwise import evaluate

__all__ = ["COMPILE_NOTICE", "KERNELS", "grid_families", "timed", "warm_up_aside",
           "warm_up_codec", "warm_up_grid", "warm_up_kernels", "warm_up_points"]

#: How every compile notice begins (the rest names the kernel and its estimate).
COMPILE_NOTICE = "compiling "


def timed(call, notice):
    """Run ``call()`` with the compile notices going to ``notice`` (None: a
    :class:`~nylonflex.kernels.compiling.CompileWarning`).

    Returns the seconds ``call`` took when a kernel compiled in it, else 0.0 (a warm
    cache).
    """
    from ..kernels.compiling import compile_seconds, notices_to

    before = sum(compile_seconds().values())
    t0 = time.perf_counter()
    with notices_to(notice) if notice is not None else nullcontext():
        call()
    seconds = time.perf_counter() - t0
    return seconds if sum(compile_seconds().values()) > before else 0.0


def warm_up_grid(cfg: ResolvedConfig, *, parallel: bool = True, notice=None) -> float:
    """Compile (or load from cache) the grid kernel ``cfg`` will run, on one design.

    Parameters
    ----------
    cfg : ResolvedConfig
        The sweep's config; a one-design copy of it is computed.
    parallel : bool
        Run the warm-up on the engine's threads or in this one (the same compiled kernel).
    notice : callable, optional
        Receives one line per kernel family that really compiles (Numba's signal), with
        an estimate; None: a :class:`~nylonflex.kernels.compiling.CompileWarning`.

    Returns
    -------
    float
        Seconds [s] the warm-up took when a kernel compiled, else 0.0 (a warm cache).
    """
    tiny = dataclasses.replace(
        cfg, axes={k: v[:1] for k, v in cfg.axes.items()},
        curves={k: v[:2] for k, v in cfg.curves.items()})
    return timed(lambda: compute_slab(tiny, 0, 1, parallel=parallel), notice)


def grid_families(cfg: ResolvedConfig) -> set:
    """The kernel families (:data:`~nylonflex.kernels.compiling.FAMILIES`) that
    :func:`warm_up_grid` of ``cfg`` compiles or loads."""
    names = {"grid" if paper_kernel(cfg) else "grid_variants"}
    if cfg.tracking is not None:
        names.add("tracking")
    return names


def warm_up_aside(warm, families, meanwhile) -> float:
    """Run ``meanwhile()`` here while ``warm()`` compiles kernels in a second process.

    A kernel compiles on one core for seconds, and nothing else in the process can use the
    other one: the compile holds the GIL half of its time, so a thread that imports beside it
    only slows it down. When some of ``families`` have not compiled into the cache folder
    yet (:func:`~nylonflex.kernels.cache.was_compiled`), this process forks; the child runs
    ``warm()``, which compiles them into Numba's cache, and exits, while this process runs
    ``meanwhile()`` (work the caller needs next: importing the chart libraries); then this
    process waits for the child, and its own warm-up loads the kernels from the cache. The
    same bits: the child compiles the very kernels this process would.

    Otherwise (every family compiled before, caching off or its folder unwritable, so that
    the parent would compile again, Windows or macOS, or other threads running, which a
    fork would not carry over) ``meanwhile()`` simply runs first.
    A child that fails leaves the kernels to this process's own warm-up, which compiles them
    and reports what went wrong.

    Parameters
    ----------
    warm : callable
        Compiles (or loads) the kernels; run in the child only.
    families : iterable of str
        The kernel families ``warm`` compiles.
    meanwhile : callable
        Run in this process, in either case.

    Returns
    -------
    float
        Seconds [s] from the fork until the child had compiled, else 0.0 (no child, or it
        failed).

    Raises
    ------
    KeyboardInterrupt
        The child was stopped by Ctrl-C or SIGTERM (the terminal stops both processes).
        Whatever ``meanwhile()`` raises is raised, after the child is stopped and reaped.
    """
    if all(cache.was_compiled(name) for name in families) or not _can_fork() or \
            not cache.caching() or not cache.writable():
        meanwhile()
        return 0.0
    # Numba and the kernels are imported before the fork: the child compiles with them and
    # this process loads the compiled code with them afterwards (0.3 s, not twice)
    from ..kernels import design  # noqa: F401

    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child (coverage does not follow a fork)
        _child(warm)
    try:
        meanwhile()
        _, status = os.waitpid(pid, 0)
    except BaseException:  # the caller stops here (a second Ctrl-C): so does the child
        os.kill(pid, signal.SIGTERM)
        os.waitpid(pid, 0)
        raise
    if os.WIFSIGNALED(status) and os.WTERMSIG(status) in (signal.SIGINT, signal.SIGTERM):
        raise KeyboardInterrupt
    compiled = os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0 and \
        all(cache.was_compiled(name) for name in families)
    return time.perf_counter() - t0 if compiled else 0.0


def _can_fork() -> bool:
    """Whether this process may fork now: Linux (fork is its own way; the charts fork too),
    and no other thread, whose locks a child would inherit held."""
    return sys.platform.startswith("linux") and hasattr(os, "fork") and \
        threading.active_count() == 1


def _child(warm):  # pragma: no cover - runs in the forked child only
    """The forked child: ``warm()``, then exit at once (no atexit handlers, no buffers of
    the parent flushed twice); Ctrl-C and SIGTERM stop it at once."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    status = 1
    try:
        warm()
        status = 0
    except BaseException:  # noqa: BLE001 - the parent's own warm-up reports it
        pass
    finally:
        sys.stderr.flush()
        os._exit(status)


def warm_up_points(settings=None, *, notice=None) -> float:
    """Compile (or load from cache) the pointwise kernel of :func:`nylonflex.evaluate` (one
    compiled loop for every batch size, threaded or not).

    Parameters
    ----------
    settings : dict, optional
        Keyword arguments of :func:`~nylonflex.engine.pointwise.evaluate` (materials).
    notice : callable, optional
        Receives one line per kernel family that really compiles (Numba's signal), with
        an estimate; None: a :class:`~nylonflex.kernels.compiling.CompileWarning`.

    Returns
    -------
    float
        Seconds [s] the warm-up took when a kernel compiled, else 0.0 (a warm cache).
    """
    kw = dict(settings or {})

    def call():
        evaluate(np.full(2, 10e-3), 2e-3, 90e-3, 1.3, 0.14, **kw)

    return timed(call, notice)


def warm_up_codec(*, notice=None) -> float:
    """Compile (or load from cache) the cube codec's byte shuffles (both loops), on a few
    bytes. Returns the seconds [s] it took when a kernel compiled, else 0.0."""
    from ..kernels.bytes import shuffle_bytes

    def call():
        for size, n in ((8, 16), (3, 5)):  # the 8-byte word loop and the byte loop
            src = np.zeros((n, size), dtype=np.uint8)
            shuffle_bytes(src, np.empty((size, n), dtype=np.uint8))

    return timed(call, notice)


def _tiny_config():
    """A one-radius, one-design-a-axis sweep config (fig12's materials and model)."""
    return parse_config(_TINY)


_TINY = {
    "name": "warmup",
    "grid": {"radius": {"values": [10], "units": "mm"},
             "wall_thickness": {"values": [2], "units": "mm"},
             "length": {"values": [90], "units": "mm"},
             "coil_index": {"values": [1.3]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 2},
               "pressure": {"start": 0, "stop": 25, "num": 2, "units": "kPa"}},
}


def _tiny_variant_config():
    """:func:`_tiny_config` with a 12 V supply: the general grid kernel, which every model
    variant and every supply runs (the paper's model without a supply has its own)."""
    return parse_config({**_TINY, "name": "warmup_variants",
                         "supply": {"voltage": 12, "units": "V"}})


def _tiny_tracking_config():
    """:func:`_tiny_config` with a 12 V supply and a short closed loop to track (a
    bang-bang controller and the bandwidth search: every tracking kernel)."""
    return parse_config({
        **_TINY, "name": "warmup_tracking", "supply": {"voltage": 12, "units": "V"},
        "tracking": {"duration": "0.5 s", "step": "10 ms",
                     "reference": {"kind": "sine", "mean": "20 deg", "amplitude": "5 deg",
                                   "frequency": "1 Hz"},
                     "controller": {"kind": "bang_bang", "hysteresis": "0 deg"},
                     "bandwidth": {"error": "2 deg"}},
    })


#: The kernels :func:`warm_up_kernels` compiles, in order: (name, what runs it, warm-up
#: taking ``notice``). The closed-loop kernels (``simulate``) sit above the engine and are
#: warmed by ``nylonflex warmup`` itself.
KERNELS = (
    ("grid", "sweeps and sampled sweeps of the paper's model alone, without a supply",
     lambda notice: warm_up_grid(_tiny_config(), parallel=True, notice=notice)),
    ("grid_variants", "sweeps of the model variants, several models or a supply",
     lambda notice: warm_up_grid(_tiny_variant_config(), parallel=True, notice=notice)),
    ("pointwise", "nylonflex.evaluate, design, query --at, propagate, sensitivity",
     lambda notice: warm_up_points(notice=notice)),
    ("codec", "the cube writer's byte shuffle", lambda notice: warm_up_codec(notice=notice)),
    ("tracking", "sweeps with tracking: (each design's closed loop, its bandwidth)",
     lambda notice: warm_up_grid(_tiny_tracking_config(), parallel=True, notice=notice)),
)


def warm_up_kernels(names=None, *, notice=None, progress=None) -> dict:
    """Compile (or load from Numba's cache) every engine kernel once.

    What a new install, a CI run or a Dask worker calls before the work, so that the
    first sweep, ``query --at`` or sampled sweep does not compile (a Dask worker:
    ``client.register_worker_callbacks(nylonflex.engine.warmup.warm_up_kernels)`` or
    ``client.run(...)``; ``nylonflex warmup`` also warms the closed-loop kernels).

    Parameters
    ----------
    names : iterable of str, optional
        Names of :data:`KERNELS` to warm; None: all.
    notice : callable, optional
        Receives one line per kernel family that really compiles; None: a
        :class:`~nylonflex.kernels.compiling.CompileWarning`.
    progress : callable, optional
        Called as ``progress(done, total, name)`` [kernels] after each kernel.

    Returns
    -------
    dict of str to float
        Seconds [s] each kernel's warm-up took when it compiled, else 0.0 (cached).
    """
    chosen = [k for k in KERNELS if names is None or k[0] in set(names)]
    out = {}
    for done, (name, _, warm) in enumerate(chosen, 1):
        out[name] = warm(notice)
        if progress is not None:
            progress(done, len(chosen), name)
    return out
