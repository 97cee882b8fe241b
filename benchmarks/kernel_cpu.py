"""The grid kernel's own CPU seconds over a config's whole grid: what a whole sweep of it
costs beyond the kernel is measured against this (issue 27: at most 2x on the 2 M bench
grid, 1.2x on the 20 M cube).

    python benchmarks/kernel_cpu.py CONFIG.yaml     # prints "kernel_cpu_s wall_s designs"

The kernel is compiled (or loaded) first, then every slab of the sweep's plan is computed
in this process on the engine's threads, as a local sweep computes it, with nothing
written; CPU seconds are the process's (user + system, every thread) over that loop.
"""

from __future__ import annotations

import sys
import time


def kernel_seconds(cfg) -> tuple[float, float]:
    """CPU [s] and wall [s] seconds of the grid kernel over ``cfg``'s whole grid."""
    from nylonflex.engine.grid import compute_slab, plan_slabs

    compute_slab(cfg, 0, 1)  # compile or load the kernel, not counted
    slabs, _ = plan_slabs(cfg)
    t0, c0 = time.perf_counter(), time.process_time()
    for i0, i1 in slabs:
        compute_slab(cfg, i0, i1)
    return time.process_time() - c0, time.perf_counter() - t0


def main(argv) -> int:
    if len(argv) != 1:
        print("usage: python benchmarks/kernel_cpu.py CONFIG.yaml", file=sys.stderr)
        return 2
    from nylonflex.config import load_config

    cfg = load_config(argv[0])
    cpu, wall = kernel_seconds(cfg)
    print(f"{cpu:.3f} {wall:.3f} {cfg.n_designs}")
    return 0

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
