"""D1 of issue 49: a sweep on a loopback Dask cluster against the same sweep on local
threads, in total CPU seconds (benchmarks/README.md, "Ratios").

    python benchmarks/dask_cpu.py CONFIG.yaml [PAIRS]    # e.g. configs/big20m.yaml 3

A scheduler and two single-threaded workers (``dask worker --nthreads 1 --no-nanny``) are
started on this machine and left to warm up (one unmeasured sweep of each kind first: the
workers load the kernels, the page cache holds the files). Then, ``PAIRS`` times in turn,
the cluster sweep and the local sweep run as whole ``nylonflex sweep`` processes:

- the cluster's CPU is the client process's (user + system, from ``wait4``) plus what the
  scheduler and the workers used while it ran (their ``cpu_times`` before and after);
- the local sweep's is its whole process's.

Prints one line a pair and the median ratio ``cluster / local`` (the target: <= 1.3).
The cubes of both are compared value for value at the end.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def _cpu(command) -> float:
    """CPU seconds [s] (user + system) of one whole child process."""
    proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed: {proc.stderr.read()}")
    return usage.ru_utime + usage.ru_stime


def _tree_cpu(procs) -> float:
    """CPU seconds [s] used so far by ``procs`` (psutil processes) and their children."""
    import psutil

    total = 0.0
    for p in procs:
        for q in [p, *p.children(recursive=True)]:
            try:
                t = q.cpu_times()
            except psutil.NoSuchProcess:
                continue
            total += t.user + t.system
    return total


def _start_cluster(folder: Path):
    """A scheduler and two one-thread workers on loopback: (address, processes)."""
    import psutil

    file = folder / "scheduler.json"
    dask = [sys.executable, "-m", "distributed.cli.dask_scheduler"]
    procs = [subprocess.Popen(dask + ["--host", "127.0.0.1", "--port", "0",
                                      "--dashboard-address", ":0",
                                      "--scheduler-file", str(file)],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    deadline = time.monotonic() + 60
    while not file.exists() and time.monotonic() < deadline:
        time.sleep(0.2)
    address = json.loads(file.read_text())["address"]
    worker = [sys.executable, "-m", "distributed.cli.dask_worker", "--scheduler-file",
              str(file), "--nthreads", "1", "--no-nanny", "--dashboard-address", ":0",
              "--host", "127.0.0.1"]
    procs += [subprocess.Popen(worker, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
              for _ in range(2)]
    from distributed import Client

    with Client(address, timeout=30) as client:
        client.wait_for_workers(2, timeout=60)
    return address, procs, [psutil.Process(p.pid) for p in procs]


def _stop(procs):
    """Terminate ``procs``; kill whichever has not ended 10 s later."""
    for p in procs:
        p.terminate()
    for p in procs:
        try:
            p.wait(timeout=10)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def main(argv) -> int:
    if not 1 <= len(argv) <= 2:
        print("usage: python benchmarks/dask_cpu.py CONFIG.yaml [PAIRS]", file=sys.stderr)
        return 2
    config, pairs = argv[0], int(argv[1]) if len(argv) == 2 else 3
    with tempfile.TemporaryDirectory(prefix="nylonflex-dask-cpu-") as tmp:
        folder = Path(tmp)
        address, procs, watched = _start_cluster(folder)
        sweep = [sys.executable, "-m", "nylonflex", "sweep", config, "--overwrite", "--quiet",
                 "--no-charts"]
        on_cluster = sweep + ["--out", str(folder / "dask.h5"), "--scheduler", address]
        local = sweep + ["--out", str(folder / "local.h5")]
        try:
            _cpu(on_cluster), _cpu(local)  # unmeasured: the workers load the kernels
            ratios = []
            for _ in range(pairs):
                before = _tree_cpu(watched)
                client = _cpu(on_cluster)
                cluster = client + _tree_cpu(watched) - before
                alone = _cpu(local)
                ratios.append(cluster / alone)
                print(f"cluster {cluster:7.2f} CPU-s (client {client:.2f}, scheduler and "
                      f"workers {cluster - client:.2f})  local {alone:7.2f} CPU-s  "
                      f"ratio {ratios[-1]:.2f}", flush=True)
        finally:
            _stop(procs[::-1])  # the workers, then the scheduler
        print(f"D1 cluster / local, median of {pairs}: {statistics.median(ratios):.2f} "
              f"(range {min(ratios):.2f}-{max(ratios):.2f})")
        _same_cube(folder / "dask.h5", folder / "local.h5")
    return 0


def _same_cube(a, b):
    """Refuse to report a ratio of two runs that made different cubes."""
    import numpy as np

    import nylonflex as nf

    with nf.open_cube(a) as x, nf.open_cube(b) as y:
        for name in y.data_vars:
            np.testing.assert_array_equal(x[name].values, y[name].values, err_msg=name)
    print("the two cubes hold the same values")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
