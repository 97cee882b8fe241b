"""Issue 49's ratios for ``nylonflex bench``: each a quotient of two things measured in the
same run, so that it holds on any host (benchmarks/README.md, "Ratios").

The whole-process figures (S1, L1) are CPU seconds (user + system) of child processes,
medians of ``pairs`` interleaved runs: the command, then its floor, then the command again,
after one unmeasured run of each (a warm page cache and Numba cache). The children run as a
user's would, with their bytecode cached: without ``PYTHONDONTWRITEBYTECODE`` (set on some
build hosts, this one included), under which nylonflex's own modules were compiled from
source on every start (about 0.1 CPU-s of ``info``) while NumPy's and h5py's, compiled at
install, were not: the floor and the command did not start alike.
The in-process ones (K1, K2, P1) come from :func:`.suite.run_bench`'s result.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

__all__ = ["TARGETS", "floor_cpu", "kernel_ratios", "process_ratios", "ratio_lines"]

#: (name, what, target, the direction that meets it): issue 49's "done when".
TARGETS = (
    ("K1", "kernel CPU-ns per design x matmul GFlop per CPU-s", 5600.0, "<="),
    ("K2", "kernel over the NumPy yardstick (speed-up)", 10.0, ">="),
    ("S1", "500-design sweep / import numpy, h5py, numba (CPU)", 1.15, "<="),
    ("S2", "(bench sweep - 500-design sweep) / its pooled kernel + encode (CPU)", 1.15, "<="),
    ("L1q", "query --where / import numpy, h5py (CPU)", 3.0, "<="),
    ("L1i", "info / import numpy, h5py (CPU)", 1.3, "<="),
    ("P1s", "nf.evaluate of one design / a batch design (CPU)", 5.0, "<="),
    ("P1b", "a batch design / a grid design (CPU)", 15.0, "<="),
)


def child_env() -> dict:
    """The environment of a measured child: this one, with bytecode written and read, and
    OpenBLAS's pool at one thread, which every nylonflex command sets for itself
    (``cli._lighten_process``): left to start its threads, the pool cost the bare
    ``import numpy, h5py`` floor 0.11 CPU-s more (0.41 against 0.30, 7 interleaved pairs),
    so that a command read 1.12x the floor instead of 1.53x."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["OPENBLAS_NUM_THREADS"] = "1"
    return env


def _cpu(command, cwd) -> float:
    """CPU seconds [s] (user + system) of one whole child process."""
    proc = subprocess.Popen(command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, cwd=cwd, env=child_env())
    _, status, usage = os.wait4(proc.pid, 0)
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{' '.join(map(str, command))} failed")
    return usage.ru_utime + usage.ru_stime


def floor_cpu(modules: str, cwd) -> float:
    """CPU seconds [s] of ``python -c "import MODULES"``, the floor a command is held to."""
    return _cpu([sys.executable, "-c", f"import {modules}"], cwd)


def _paired(command, floor, pairs, cwd) -> float:
    """Median over ``pairs`` of command CPU / floor CPU, run in turn, after one unmeasured
    run of each."""
    _cpu(command, cwd), floor_cpu(floor, cwd)
    out = []
    for _ in range(pairs):
        out.append(_cpu(command, cwd) / floor_cpu(floor, cwd))
    return statistics.median(out)


def _sweep_500(folder: Path) -> list:
    """``nylonflex sweep`` of a 500-design config into ``folder`` (no charts)."""
    cfg = folder / "s500.yaml"
    cfg.write_text(
        "name: s500\n"
        "grid:\n"
        "  radius: {start: 5, stop: 25, num: 5, units: mm}\n"
        "  wall_thickness: {values: [1, 2, 3, 4, 6], units: mm}\n"
        "  length: {values: [70, 90, 120, 150], units: mm}\n"
        "  coil_index: {start: 1.1, stop: 1.7, num: 5}\n"
        "  wrap_angle: {values: [8], units: deg}\n"
        "curves:\n"
        "  stroke: {start: 0, stop: 0.1, num: 11}\n"
        "  pressure: {start: 0, stop: 25, num: 11, units: kPa}\n"
        "charts: []\n")
    return [sys.executable, "-m", "nylonflex", "sweep", str(cfg), "--out",
            str(folder / "s500.h5"), "--overwrite", "--quiet"]


def _sweep_of(config: dict, folder: Path) -> list:
    """``nylonflex sweep`` of the config ``config`` (a dict, written as YAML) into
    ``folder`` (no charts)."""
    import yaml

    path = folder / f"{config['name']}.yaml"
    path.write_text(yaml.safe_dump({**config, "charts": []}, sort_keys=False))
    return [sys.executable, "-m", "nylonflex", "sweep", str(path), "--out",
            str(folder / f"{config['name']}.h5"), "--overwrite", "--quiet"]


def _sweep_beyond_start(big, small, encode_cpu, pairs, cwd) -> float:
    """S2: median over ``pairs`` of (CPU of the sweep ``big`` - CPU of the 500-design sweep
    ``small``) / ``encode_cpu``, the big grid's pooled kernel and encoding [CPU-s], run in
    turn after one unmeasured run of each."""
    _cpu(big, cwd), _cpu(small, cwd)
    return statistics.median((_cpu(big, cwd) - _cpu(small, cwd)) / encode_cpu
                             for _ in range(pairs))


def process_ratios(cube: Path, pairs: int = 3, sweep: dict | None = None,
                   encode_cpu: float | None = None) -> dict:
    """S1, L1 and, given ``sweep`` (the bench grid's config, a dict) and ``encode_cpu``
    (its pooled kernel and encoding [CPU-s], ``kernel_cpu.kernel_encode_seconds``), S2 of
    :data:`TARGETS` ({name: value}), on ``cube`` (the bench sweep's file, for the light
    commands)."""
    nf = [sys.executable, "-m", "nylonflex"]
    with tempfile.TemporaryDirectory(prefix="nylonflex-ratios-") as tmp:
        small = _sweep_500(Path(tmp))
        out = {"S1": _paired(small, "numpy, h5py, numba", pairs, tmp)}
        if sweep is not None:
            out["S2"] = _sweep_beyond_start(_sweep_of(sweep, Path(tmp)), small, encode_cpu,
                                            pairs, tmp)
        out["L1q"] = _paired(nf + ["query", str(cube), "--where", "tip_force_max >= 0.5 N",
                                   "--limit", "5"], "numpy, h5py", pairs, tmp)
        out["L1i"] = _paired(nf + ["info", str(cube)], "numpy, h5py", pairs, tmp)
        return out


def kernel_ratios(result: dict) -> dict:
    """K1, K2 and P1 of :data:`TARGETS` ({name: value}) from a bench ``result``."""
    grid_cpu = result["kernel_cpu_s"] / result["designs"]  # [CPU-s] a grid design
    return {"K1": grid_cpu * 1e9 * result["matmul_gflops_per_cpu_s"],
            "K2": result["kernel_vs_numpy"],
            "P1s": result["single_vs_batch"],
            "P1b": result["batch_design_cpu_s"] / grid_cpu}


def ratio_lines(values: dict) -> list:
    """The report's lines: each ratio, its target and whether it meets it."""
    lines = ["  ratios (issue 49; same run, medians of whole-process pairs where a command):"]
    for name, what, target, sense in TARGETS:
        if name not in values:
            continue
        v = values[name]
        met = v <= target if sense == "<=" else v >= target
        lines.append(f"    {name:4s} {v:10.2f}  target {sense} {target:g}  "
                     f"{'met' if met else 'not met'}  ({what})")
    return lines
