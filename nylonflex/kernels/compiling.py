"""A notice when a kernel really compiles: Numba's own signal, with a measured estimate.

Numba raises its ``numba:compile`` event only when it compiles a dispatcher's signature:
a kernel loaded from the cache raises none (``Dispatcher.compile`` loads the cached
overload first and triggers the event only on a miss). A listener registered here turns
the first such event of each kernel family in a process into one line,

    compiling the grid kernel (sweeps) (first run here, or the model changed; cached for
    later runs): it took 26 s here last time...

whatever the load: no timer decides. The line goes to the sink a caller installs with
:func:`notices_to` (the CLI prints it on stderr), else it is a :class:`CompileWarning`,
so that ``nf.evaluate`` and ``nf.design_limits`` in a script say so too. Each family's
compile time is measured from the events and kept beside the cache
(``compile_seconds.json``): the next notice quotes what it took on this machine.
"""

from __future__ import annotations

import json
import os
import threading
import time
import warnings
from contextlib import contextmanager

from numba.core import event

from .cache import cache_dir, mark_compiled

__all__ = ["FAMILIES", "MEASURED", "CompileWarning", "compile_seconds", "family",
           "notice_text", "notices_to"]


class CompileWarning(UserWarning):
    """A nylonflex kernel is compiling (once per install or model change): seconds to
    minutes. Silence with ``warnings.simplefilter("ignore", nylonflex.CompileWarning)``."""


#: What each kernel family computes, as the notice names it.
FAMILIES = {
    "grid": "the grid kernel (sweeps of the paper's model)",
    "grid_variants": "the general grid kernel (sweeps of model variants, several models or a "
                     "supply)",
    "pointwise": "the pointwise kernel (nylonflex.evaluate, design_limits, design, query --at, "
                 "uncertainty propagate and sensitivity)",
    "control": "the closed-loop kernels (simulate)",
    "tracking": "the tracking kernels (sweeps with tracking:)",
    "codec": "the cube codec's byte shuffle",
}

#: Cold compile times [s] measured on the project's 2-core machine on 2026-12-03 with an
#: empty cache (``nylonflex warmup``, NUMBA_CACHE_DIR a new folder; ``nylonflex bench``
#: measures them again): CPU seconds, what an idle machine takes; the wall time is several
#: times that on a shared machine. Quoted until this machine has its own figure.
MEASURED = {"grid": 12.0, "grid_variants": 17.0, "pointwise": 8.0, "control": 4.0,
            "codec": 1.0, "tracking": 12.0}
# (the paper's grid kernel: 0.7x the general one's 17 s, from the two measured on
# 2026-12-06 on a faster host, 6.8-7.4 s against 9.7-10.6 s)

_KERNEL_MODULES = {"nylonflex.kernels.control": "control", "nylonflex.kernels.bytes": "codec",
                   "nylonflex.kernels.tracking": "tracking"}
_STATE = threading.local()
_LOCK = threading.Lock()
_SINK: list = []            # the installed notice callables, innermost last
_NOTICED: set = set()       # families noticed in this process
_SECONDS: dict = {}         # family -> seconds compiled in this process


def family(dispatcher) -> str | None:
    """The kernel family of a Numba dispatcher (None: not a nylonflex kernel)."""
    func = getattr(dispatcher, "py_func", None)
    name, module = getattr(func, "__name__", ""), getattr(func, "__module__", "")
    if name.startswith("_design_slab"):
        return "grid" if name.endswith("_paper") else "grid_variants"
    if name.startswith("_design_points"):
        return "pointwise"
    return _KERNEL_MODULES.get(module)


def _record_path() -> str:
    # beside the digest-keyed cache folders: a changed model keeps the machine's figures
    return os.path.join(os.path.dirname(cache_dir().rstrip(os.sep)),
                        "compile_seconds.json")


def _recorded() -> dict:
    try:
        with open(_record_path(), encoding="utf-8") as f:
            data = json.load(f)
        return {k: float(v) for k, v in data.items() if k in FAMILIES}
    except (OSError, ValueError, TypeError, AttributeError):
        return {}


def _record(name, seconds):
    data = _recorded()
    data[name] = round(float(seconds), 1)
    try:
        os.makedirs(os.path.dirname(_record_path()), exist_ok=True)
        tmp = _record_path() + f".{os.getpid()}.part"
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(data, f)
        os.replace(tmp, _record_path())
    except OSError:  # an unwritable cache: the estimate stays the measured default
        pass


def notice_text(name) -> str:
    """The notice of family ``name``, with its estimate: this machine's last compile time,
    or :data:`MEASURED`'s."""
    here = _recorded().get(name)
    if here is None:
        estimate = f"about {MEASURED[name]:.0f} s on an idle machine, minutes on a busy one"
    else:  # a short compile reads "under a second", not "0 s"
        took = "under a second" if here < 0.95 else f"{here:.0f} s"
        estimate = f"it took {took} here last time"
    return (f"compiling {FAMILIES[name]} (first run here, or the model changed; cached for "
            f"later runs): {estimate}...")


def _emit(text):
    sink = _SINK[-1] if _SINK else None
    if sink is None:
        warnings.warn(text, CompileWarning, stacklevel=2)
    else:
        sink(text)


class _Listener(event.Listener):
    """Numba's ``numba:compile`` events: the first top-level compile of a family notices;
    each one's duration adds to the family's seconds."""

    def on_start(self, ev):
        depth = getattr(_STATE, "depth", 0)
        _STATE.depth = depth + 1
        if depth:  # a kernel compiled from inside another: part of the outer one
            return
        name = family(ev.data.get("dispatcher") if isinstance(ev.data, dict) else None)
        _STATE.family, _STATE.t0 = name, time.perf_counter()
        if name is None:
            return
        with _LOCK:
            first = name not in _NOTICED
            _NOTICED.add(name)
        if first:
            _emit(notice_text(name))

    def on_end(self, ev):
        _STATE.depth = max(0, getattr(_STATE, "depth", 1) - 1)
        name = getattr(_STATE, "family", None)
        if _STATE.depth or name is None:
            return
        _STATE.family = None
        with _LOCK:
            _SECONDS[name] = _SECONDS.get(name, 0.0) + time.perf_counter() - _STATE.t0
            seconds = _SECONDS[name]
        _record(name, seconds)
        # marked even after a failure (Numba 0.68's Event.is_failed reads the wrong way
        # round): the next process then compiles the kernel itself, as it would unmarked
        mark_compiled(name)


def compile_seconds() -> dict:
    """Seconds [s] each family has compiled in this process so far (absent: none)."""
    with _LOCK:
        return dict(_SECONDS)


@contextmanager
def notices_to(sink):
    """Send compile notices to ``sink`` (a callable taking one line) inside the block,
    instead of a :class:`CompileWarning`; None keeps the warning."""
    _SINK.append(sink)
    try:
        yield
    finally:
        _SINK.remove(sink) if sink in _SINK else None


_LISTENER = _Listener()
event.register("numba:compile", _LISTENER)
