"""Compile the kernels before the work that needs them, with a notice while that takes time.

The first run after installing (or after the model's sources change) compiles the Numba
kernels, several seconds that would otherwise be counted as compute and leave the user
looking at a silent terminal. :func:`warm_up_grid` and :func:`warm_up_points` call the
kernels once on a one-design problem; a later run loads them from Numba's cache in a
fraction of a second. The notice is a callback: the engine never prints.
"""

from __future__ import annotations

import dataclasses
import threading
import time

from ..config import ResolvedConfig

__all__ = ["COMPILE_NOTICE", "warm_up_grid", "warm_up_points"]

#: The line a caller shows while the kernels compile.
COMPILE_NOTICE = ("compiling the model's kernels (first run, or the model changed; cached "
                  "for later runs: a few seconds, not counted in the timings)...")


def _timed(call, notice, after):
    """Run ``call()``; if it is still running after ``after`` [s], call ``notice`` once.

    Returns the seconds ``call`` took, or 0.0 when no notice was due (a warm cache).
    """
    timer = None
    if notice is not None:
        timer = threading.Timer(after, notice, args=(COMPILE_NOTICE,))
        timer.daemon = True
        timer.start()
    t0 = time.perf_counter()
    try:
        call()
    finally:
        if timer is not None:
            timer.cancel()
    seconds = time.perf_counter() - t0
    return seconds if seconds >= after else 0.0


def warm_up_grid(cfg: ResolvedConfig, *, parallel: bool = True, notice=None,
                 after: float = 1.0) -> float:
    """Compile (or load from cache) the grid kernel ``cfg`` will run, on one design.

    Parameters
    ----------
    cfg : ResolvedConfig
        The sweep's config; a one-design copy of it is computed.
    parallel : bool
        Warm the threaded kernel (local runs) or the serial one.
    notice : callable, optional
        Receives :data:`COMPILE_NOTICE` once if the warm-up lasts over ``after`` seconds.
    after : float
        Seconds [s] before the notice.

    Returns
    -------
    float
        Seconds [s] spent compiling (0.0 when the kernels were ready within ``after``).
    """
    from .grid import compute_slab

    tiny = dataclasses.replace(
        cfg, axes={k: v[:1] for k, v in cfg.axes.items()},
        curves={k: v[:2] for k, v in cfg.curves.items()})
    return _timed(lambda: compute_slab(tiny, 0, 1, parallel=parallel), notice, after)


def warm_up_points(settings=None, *, notice=None, after: float = 1.0) -> float:
    """Compile (or load from cache) the pointwise kernels of :func:`nylonflex.evaluate`.

    Parameters
    ----------
    settings : dict, optional
        Keyword arguments of :func:`~nylonflex.engine.pointwise.evaluate` (materials).
    notice : callable, optional
        Receives :data:`COMPILE_NOTICE` once if the warm-up lasts over ``after`` seconds.
    after : float
        Seconds [s] before the notice.

    Returns
    -------
    float
        Seconds [s] spent compiling (0.0 when the kernels were ready within ``after``).
    """
    import numpy as np

    from .pointwise import _PARALLEL_FROM, evaluate

    kw = dict(settings or {})

    def call():
        for n in (1, _PARALLEL_FROM):  # the serial and the threaded loop
            evaluate(np.full(n, 10e-3), 2e-3, 90e-3, 1.3, 0.14, **kw)

    return _timed(call, notice, after)
