"""``nylonflex warmup``: compile every kernel once (a new install, CI, a Dask worker)."""

from __future__ import annotations

import sys
import time

HELP = "compile every kernel once, so that later runs start warm"
DESCRIPTION = """Compile (or load from the cache) every Numba kernel once, with a line per
kernel: the grid kernel (sweeps and sampled sweeps, on local threads and Dask workers), the
pointwise kernel (nylonflex.evaluate, design, query --at, propagate, sensitivity), the cube
codec, the tracking kernels (sweeps with tracking:) and the closed-loop kernels (simulate). Compiled code is cached per model version
(the Numba cache folder, NUMBA_CACHE_DIR), so this is done once per install: the README's
first sweep, CI runs and Dask workers then start warm. A warm cache makes this take about
a second."""


def add_arguments(w):
    w.add_argument("--quiet", action="store_true", help="print nothing but errors")


def _control(notice):
    """The closed-loop kernels: a 0.1 s simulation of the paper's example 2."""
    from ..engine.warmup import timed
    from ..sim import parse_sim_config, run_simulation

    cfg = parse_sim_config({
        "name": "warmup",
        "design": {"radius": "7.5 mm", "wall_thickness": "2 mm", "length": "70 mm",
                   "coil_index": 1.7, "wrap_angle": "8 deg"},
        "supply": {"voltage": "12 V"},
        "time": {"duration": "0.1 s", "step": "10 ms"},
        "reference": {"kind": "sine", "mean": "85 deg", "amplitude": "30 deg",
                      "frequency": "0.04 Hz"},
    })
    return timed(lambda: run_simulation(cfg), notice)


def run(args) -> int:
    from ..engine.warmup import KERNELS

    say = (lambda line: None) if args.quiet else (lambda line: print(line, flush=True))
    notice = (lambda line: None) if args.quiet else \
        (lambda line: print(f"  {line}", file=sys.stderr, flush=True))
    steps = [(name, what, warm) for name, what, warm in KERNELS]
    steps.append(("control", "simulate's closed loop", _control))
    t_all = time.perf_counter()
    width = max(len(name) for name, _, _ in steps)
    for k, (name, what, warm) in enumerate(steps, 1):
        t0, c0 = time.perf_counter(), time.process_time()
        compiled = warm(notice)
        seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
        state = (f"compiled in {compiled:.1f} s" if compiled else "cached in "
                 f"{seconds:.1f} s") + f" ({cpu:.1f} CPU-s)"
        say(f"[{k}/{len(steps)}] {name:<{width}} {state:<32} {what}")
    say(f"warm: every kernel compiled or loaded in {time.perf_counter() - t_all:.1f} s")
    return 0
