"""Several charts drawn at once: one forked process a core, each chart whole in one.

Matplotlib lays out and rasterises in Python, under the GIL, so threads would not help.
Forked processes start with the modules already imported and the cube's data shared
copy-on-write; each draws whole charts and writes its own files, and the parent only
collects the paths. Where fork is not the platform's way (macOS, Windows), or for a single
chart, the charts are drawn one by one in this process.
"""

from __future__ import annotations

import sys
from concurrent.futures import as_completed

from ..engine.threads import cores

#: What the forked workers inherit: the drawing function and the cube (set before the
#: pool forks, never pickled).
_INHERITED: dict = {}


def _draw_inherited(job):
    return _INHERITED["draw"](_INHERITED["ds"], *job)


def draw_all(draw, ds, jobs, processes=None, on_done=None) -> list:
    """``[draw(ds, *job) for job in jobs]``, on up to ``processes`` forked processes.

    Parameters
    ----------
    draw : callable
        ``draw(ds, *job)`` draws one chart and returns its path.
    ds : xarray.Dataset
        The cube, inherited by the workers.
    jobs : list of tuple
        The arguments of each chart (picklable).
    processes : int, optional
        Processes to draw in [1, ...]; default one a core. 1 draws here, one by one.
    on_done : callable, optional
        ``on_done(done, total, result)`` after each chart, as it is finished.

    Returns
    -------
    list
        What ``draw`` returned, in the order of ``jobs``.
    """
    n = min(len(jobs), processes or cores())
    if n <= 1 or not sys.platform.startswith("linux"):
        out = []
        for k, job in enumerate(jobs, 1):
            out.append(draw(ds, *job))
            if on_done is not None:
                on_done(k, len(jobs), out[-1])
        return out
    import multiprocessing
    from concurrent.futures.process import ProcessPoolExecutor

    _INHERITED.update(draw=draw, ds=ds)
    try:
        with ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("fork")) as pool:
            futures = {pool.submit(_draw_inherited, job): i for i, job in enumerate(jobs)}
            out = [None] * len(jobs)
            for k, future in enumerate(as_completed(futures), 1):
                out[futures[future]] = future.result()
                if on_done is not None:
                    on_done(k, len(jobs), out[futures[future]])
        return out
    finally:
        _INHERITED.clear()
