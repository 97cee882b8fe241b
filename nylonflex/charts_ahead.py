"""A sweep's charts drawn by a process started before the sweep.

Drawing needs matplotlib and xarray, about a second of imports on a small machine, and the
sweep before it keeps one core busy with its own start (Numba, the config, HDF5). So
``nylonflex sweep`` forks a process *before* it sweeps: that process imports what the
charts need while the sweep runs, then waits; once the cube is complete it opens it and
draws (:func:`nylonflex.charts.draw_charts`, on one forked process a core), and sends back
what the parent reports: each skipped chart's reason, progress, the files, or the error.

Where fork is not the platform's way (macOS, Windows) the charts are drawn in this process
after the sweep, as before. The files are the same either way. The process ahead never
outlives its parent: it exits when the parent closes its end of the pipe, and Linux sends
it SIGTERM if the parent dies.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

__all__ = ["ChartsAhead"]


def _can_fork() -> bool:
    return sys.platform.startswith("linux") and hasattr(os, "fork")


class ChartsAhead:
    """Charts of a cube not yet made, drawn by a process forked now.

    Use as a context manager around the sweep; call :meth:`draw` once the cube is complete.
    Leaving the block without drawing (the sweep failed or was stopped) ends the process.

    Parameters
    ----------
    fork : bool, optional
        Start the process ahead [-]; default where the platform forks. False draws in this
        process, after the sweep.
    """

    def __init__(self, fork: bool | None = None):
        self._conn = None
        self._pid = None
        if fork is None:
            fork = _can_fork()
        if fork:
            self._start()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _start(self):
        from multiprocessing import Pipe

        parent, child = Pipe()
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:  # the process ahead: it never returns into the caller's code
            status = 0
            try:
                parent.close()
                _serve(child)
            except BaseException:  # noqa: BLE001 - nothing of the parent's may run here
                status = 1
            finally:
                os._exit(status)
        child.close()
        self._conn, self._pid = parent, pid

    def draw(self, cube, names, out_dir, fmt="png", *, on_skip=None, progress=None,
             refuse_foreign=True) -> list[Path]:
        """Draw charts of the complete cube file ``cube``: :func:`nylonflex.charts.draw_charts`.

        The parameters, return value and exceptions are those of ``draw_charts`` (after
        ``nylonflex.open_cube(cube)``). Callbacks run in this process. If the process
        ahead has gone (killed), the charts are drawn here.
        """
        request = {"cube": str(cube), "names": list(names), "out_dir": str(out_dir),
                   "fmt": fmt, "refuse_foreign": refuse_foreign}
        if self._conn is not None:
            conn, self._conn = self._conn, None  # asked to draw: close() lets it finish
            try:
                conn.send(request)
                while True:
                    kind, *value = conn.recv()
                    if kind == "skip":
                        (on_skip or _warn)(value[0])
                    elif kind == "progress":
                        if progress is not None:
                            progress(*value)
                    elif kind == "error":
                        raise value[0]
                    else:
                        return value[0]
            except (EOFError, BrokenPipeError, ConnectionResetError):
                pass  # the process ahead is gone: draw here
            finally:
                conn.close()
                self.close()
        return _draw(request, on_skip, progress)

    def close(self):
        """End the process ahead and reap it: at once when it was not asked to draw (it
        may still be importing), after its last message when it was."""
        import contextlib
        import signal

        if self._conn is not None:
            self._conn.close()
            self._conn = None
            if self._pid is not None:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(self._pid, signal.SIGKILL)
        if self._pid is not None:
            with contextlib.suppress(ChildProcessError):
                os.waitpid(self._pid, 0)
            self._pid = None


def _warn(message):
    import warnings

    warnings.warn(message, stacklevel=3)


def _draw(request, on_skip, progress) -> list[Path]:
    from .charts import draw_charts
    from .storage import open_cube

    ds = open_cube(request["cube"])
    try:
        return draw_charts(ds, request["names"], request["out_dir"], request["fmt"],
                           on_skip=on_skip or _warn, progress=progress,
                           refuse_foreign=request["refuse_foreign"])
    finally:
        ds.close()


def _serve(conn):
    """The process ahead: import, wait for the cube, draw, report; any error is sent back."""
    import signal

    _die_with_parent(signal.SIGTERM)
    # a Ctrl-C reaches the whole process group: the parent reports it, this one just ends
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    error = None
    try:
        import h5netcdf  # noqa: F401 - open_cube's engine

        from .charts import warm_up

        warm_up()
    except Exception as exc:  # noqa: BLE001 - reported when the charts are asked for
        error = exc
    try:
        request = conn.recv()
    except EOFError:  # the sweep failed or was stopped: nothing to draw
        return
    try:
        if error is not None:
            raise error
        paths = _draw(request, lambda msg: conn.send(("skip", msg)),
                      lambda done, total: conn.send(("progress", done, total)))
        conn.send(("done", paths))
    except Exception as exc:  # noqa: BLE001 - the parent raises it as its own
        conn.send(("error", _picklable(exc)))


def _picklable(exc: Exception) -> Exception:
    import pickle

    try:
        pickle.loads(pickle.dumps(exc))
        return exc
    except Exception:  # noqa: BLE001
        return RuntimeError(f"{type(exc).__name__}: {exc}")


def _die_with_parent(sig):
    """Have Linux send ``sig`` to this process when its parent dies (prctl)."""
    import contextlib
    import ctypes

    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(sig))  # PR_SET_PDEATHSIG
        if os.getppid() == 1:  # the parent died before prctl took effect
            os._exit(1)
