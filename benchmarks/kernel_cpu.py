"""The grid kernel's own CPU seconds over a config's whole grid: what a whole sweep of it
costs beyond the kernel is measured against this (issue 27: at most 2x on the 2 M bench
grid, 1.2x on the 20 M cube).

    python benchmarks/kernel_cpu.py CONFIG.yaml     # prints "kernel_cpu_s wall_s designs"

The kernel is compiled (or loaded) first, then every slab of the sweep's plan is computed
in this process on the engine's threads, into pooled output arrays, as a local sweep
computes it, with nothing written; CPU seconds are the process's (user + system, every thread) over that loop.
"""

from __future__ import annotations

import sys
import time


def kernel_seconds(cfg) -> tuple[float, float]:
    """CPU [s] and wall [s] seconds of the grid kernel over ``cfg``'s whole grid.

    The output arrays come from an :class:`~nylonflex.engine.grid.ArrayPool` and go back
    to it after each slab, as a local sweep runs the kernel (``engine/slabs.py``): fresh
    arrays cost the kernel the zeroing of every page it writes, which made this reference
    1.39 times slower than the sweep's own kernel time (issue 49), and every sweep / kernel
    ratio read too good by that much.
    """
    return _pooled_seconds(cfg)


def kernel_encode_seconds(cfg, folder) -> tuple[float, float]:
    """CPU [s] and wall [s] seconds of the grid kernel and the encoding of its output over
    ``cfg``'s whole grid: what a local sweep cannot do without (issue 49, S2).

    Each slab is computed into pooled arrays as :func:`kernel_seconds` does, then shuffled
    and compressed chunk by chunk into what the sweep stores
    (:meth:`~nylonflex.storage.cube.CubeFile.encode`, its thread pool included), with
    nothing written to the cube (a scratch file in ``folder``, dropped) or the journal.
    """
    from pathlib import Path

    from nylonflex.engine.grid import coords, cube_variables, plan_slabs
    from nylonflex.engine.provenance import provenance
    from nylonflex.storage.cube import CubeFile

    _, chunk = plan_slabs(cfg)
    cube = CubeFile(Path(folder) / "encode-only.h5", coords(cfg), provenance(cfg), chunk,
                    cfg.compression, cube_variables(cfg), cfg.models, cfg.cooling_names)
    try:
        return _pooled_seconds(cfg, cube.encode)
    finally:
        cube.abandon()


def _pooled_seconds(cfg, then=None) -> tuple[float, float]:
    """CPU [s] and wall [s] seconds of every slab of ``cfg`` computed into pooled arrays,
    each followed by ``then(i0, arrays)`` when given; the first slab, which compiles or
    loads the kernel and fills the pool, is run once before and not counted."""
    from nylonflex.engine.grid import ArrayPool, compute_slab, plan_slabs

    slabs, _ = plan_slabs(cfg)
    pool = ArrayPool()

    def one(i0, i1):
        arrays = compute_slab(cfg, i0, i1, pool=pool)
        if then is not None:
            then(i0, arrays)
        pool.give_back(arrays)

    one(*slabs[0])
    t0, c0 = time.perf_counter(), time.process_time()
    for i0, i1 in slabs:
        one(i0, i1)
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
