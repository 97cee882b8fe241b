"""``nylonflex bench``: the kernels against the scipy reference, side by side in one run.

Timings on shared machines are noisy, so the figures that matter are the ratios measured in
the same process: the per-design speed-up over the adaptive-quadrature reference, and the
kernel's speed-up over a plain NumPy implementation of the same structure
(:mod:`.yardstick`).

The suite lives in the repository's ``benchmarks/``, outside the package: ``nylonflex
bench`` (nylonflex/cli/bench.py) finds this folder beside the package of a source checkout
and runs :func:`run_bench`. The scipy reference it times is the tests' own,
``tests/naive.py`` (:func:`naive`), so that the speed-up is over the very reference the
tests hold the model to, not over a copy of it that could drift.
"""

from __future__ import annotations

import importlib.util
import math
import resource
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from nylonflex.config import parse_config
from nylonflex.engine import evaluate
from nylonflex.engine.grid import compute_slab
from nylonflex.physics import design_limits as python_loop
from nylonflex.sim import parse_sim_config, run_simulation
from nylonflex.storage import open_cube
from nylonflex.sweep.conductor import run_sweep, sweep_file

from .first_use import cold_compiles, command_costs
from .flops import kernel_flops_per_design
from .kernel_cpu import kernel_encode_seconds, kernel_seconds
from .ratios import kernel_ratios, process_ratios, ratio_lines
from .yardstick import grid_numpy

#: The checkout's tests/naive.py, the slow reference of the tests.
NAIVE = Path(__file__).resolve().parents[1] / "tests" / "naive.py"


def naive():
    """``tests/naive.py`` of this checkout as a module (loaded by its path, once)."""
    name = "nylonflex_tests_naive"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(name, NAIVE)
        module = importlib.util.module_from_spec(spec)
        sys.modules[name] = module
        spec.loader.exec_module(module)
    return sys.modules[name]


#: The benchmark grid of issue 3: 100 x 40 x 10 x 5 x 10 = 2,000,000 designs with curves.
FULL = {"radius": 100, "wall_thickness": 40, "length": 10, "coil_index": 5, "wrap_angle": 10,
        "stroke": 51, "pressure": 41, "reference_designs": 6, "pointwise_designs": 20000}
QUICK = {"radius": 12, "wall_thickness": 6, "length": 4, "coil_index": 3, "wrap_angle": 4,
         "stroke": 11, "pressure": 9, "reference_designs": 2, "pointwise_designs": 500}


def bench_config(sizes: dict):
    """The benchmark's design space (the fig12 ranges, sizes from ``sizes``)."""
    return parse_config(bench_dict(sizes))


def bench_dict(sizes: dict) -> dict:
    """:func:`bench_config`'s config as the dict a YAML file would hold."""
    return {
        "name": "bench",
        "grid": {
            "radius": {"start": 5, "stop": 25, "num": sizes["radius"], "units": "mm"},
            "wall_thickness": {"start": 1, "stop": 6, "num": sizes["wall_thickness"],
                               "units": "mm"},
            "length": {"start": 40, "stop": 150, "num": sizes["length"], "units": "mm"},
            "coil_index": {"start": 1.1, "stop": 1.7, "num": sizes["coil_index"]},
            "wrap_angle": {"start": 2, "stop": 30, "num": sizes["wrap_angle"], "units": "deg"},
        },
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": sizes["stroke"]},
                   "pressure": {"start": 0, "stop": 40, "num": sizes["pressure"],
                                "units": "kPa"}},
    }


#: The sampled sweep of issue 12: the fig12 grid (41 x 6 x 3 x 4 x 4 = 11,808 designs) x
#: 256 samples, about 3 million evaluations; quick: the quick grid x 16 samples.
SAMPLED_FULL = {"grid": {"radius": {"start": 5, "stop": 25, "num": 41, "units": "mm"},
                         "wall_thickness": {"values": [1, 2, 3, 4, 5, 6], "units": "mm"},
                         "length": {"values": [70, 90, 120], "units": "mm"},
                         "coil_index": {"values": [1.1, 1.3, 1.5, 1.7]},
                         "wrap_angle": {"values": [5, 8, 12, 20], "units": "deg"}},
                "samples": 256}


def sampled_config(quick: bool = False):
    """The sampled-sweep benchmark: wall sd 0.1 mm, silicone mu and stroke 10 %/5 %."""
    sizes = QUICK
    grid = bench_config(sizes).raw["grid"] if quick else SAMPLED_FULL["grid"]
    return parse_config({
        "name": "bench_sampled", "grid": grid,
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 11},
                   "pressure": {"start": 0, "stop": 25, "num": 11, "units": "kPa"}},
        "uncertainty": {"samples": 16 if quick else SAMPLED_FULL["samples"], "seed": 0,
                        "parameters": {"wall_thickness": {"sd": 0.1, "units": "mm"},
                                       "silicone.mu": {"rel_sd": 0.1},
                                       "nylon.stroke_max": {"rel_sd": 0.05}}},
        "requirements": ["tip_force_max >= 0.5 N", "range_fraction >= 1"],
    })


def _sampled_seconds(quick: bool) -> tuple[float, float, int]:
    """Wall and CPU seconds [s] (every thread of this process) of a sampled sweep in
    memory, and its evaluations (designs x samples)."""
    cfg = sampled_config(quick)
    t0, c0 = time.perf_counter(), time.process_time()
    ds = run_sweep(cfg)
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    ds.close()
    return seconds, cpu, cfg.n_designs * cfg.uncertainty.samples


def _reference_design(cfg, a, t, c, psi):
    """One design's s*, kappa(s_max) and kappa* by scipy quadrature and brentq."""
    ref = naive()
    ny = cfg.nylon
    mu, alpha = cfg.silicone.arrays()
    s_max = ref.table_value(c, ny.coil_index_table, ny.stroke_max_table)
    force_limit = ref.force_limit(c, ny.coil_index_table, ny.tensile_strength_table,
                                  ny.fibre_diameter)
    s = ref.stroke_limit(force_limit, s_max, a, t, t, psi, c, mu, alpha, ny.fibre_diameter)
    k_full = ref.curvature(ref.gauge_pressure(s_max), a, t, t, mu, alpha)
    k = k_full if s == s_max else ref.curvature(ref.gauge_pressure(s), a, t, t, mu, alpha)
    return s, k_full, k


def _pointwise_seconds(n: int) -> tuple[float, float, int]:
    """Per-design time [s] of ``nf.evaluate`` on ``n`` random designs, and of the uncompiled
    python loop (:func:`nylonflex.physics.design_limits`) on a 50th of them, same run."""
    d = naive().random_designs(n)
    evaluate(**{k: v[:64] for k, v in d.items()})  # compile or load the cache
    t0 = time.perf_counter()
    evaluate(**d)
    t_point = (time.perf_counter() - t0) / n
    m = max(10, n // 50)
    t0 = time.perf_counter()
    python_loop(*(v[:m] for v in d.values()))
    return t_point, (time.perf_counter() - t0) / m, n


def _single_vs_batch_cpu(n: int = 20_000, calls: int = 2000) -> tuple[float, float]:
    """CPU seconds [s] of ``nf.evaluate`` for one design, and per design of an ``n``-design
    batch, measured back to back in this process (issue 27: at most 20x; issue 49: 5x)."""
    d = naive().random_designs(n, seed=27)
    one = {k: float(v[0]) for k, v in d.items()}
    evaluate(**d), evaluate(**one)  # compile or load the cache: both loops
    t0 = time.process_time()
    for _ in range(3):
        evaluate(**d)
    batch = (time.process_time() - t0) / 3 / n
    t0 = time.process_time()
    for _ in range(calls):
        evaluate(**one)
    return (time.process_time() - t0) / calls, batch


def _matmul_gflops(n: int = 1024) -> tuple[float, float]:
    """The machine's practical floating-point peak: NumPy's matmul of two n x n float64
    matrices (2 n^3 flops), best of 3, on the BLAS threads it has: [GFlop/s] of wall time
    and [GFlop per CPU-s] (a core's peak, whatever the number of BLAS threads)."""
    a = np.random.default_rng(0).random((n, n))
    a @ a
    best, best_cpu = math.inf, math.inf
    for _ in range(3):
        t0, c0 = time.perf_counter(), time.process_time()
        a @ a
        best = min(best, time.perf_counter() - t0)
        best_cpu = min(best_cpu, time.process_time() - c0)
    return 2.0 * n**3 / best / 1e9, 2.0 * n**3 / best_cpu / 1e9


def _closed_loop_seconds(duration: float) -> tuple[float, float]:
    """Loop time [s] of the figure-9 closed loop over ``duration`` [s] at 10 ms, and the
    whole run's (tables and output included), once compiled."""
    cfg = parse_sim_config({
        "name": "bench",
        "design": {"radius": "7.5 mm", "wall_thickness": "2 mm", "length": "70 mm",
                   "coil_index": 1.7, "wrap_angle": "8 deg"},
        "supply": {"voltage": "12 V"},
        "time": {"duration": f"{duration} s", "step": "10 ms"},
        "reference": {"kind": "sine", "mean": "85 deg", "amplitude": "30 deg",
                      "frequency": "0.04 Hz"},
    })
    run_simulation(cfg)  # compile or load the cache
    t0 = time.perf_counter()
    ds = run_simulation(cfg)
    return float(ds.attrs["loop_time"]), time.perf_counter() - t0


def _solve_count(ds) -> int:
    """Angle solves the kernel makes: curve points, full-stroke and strength-limited ones."""
    na, nt, nc = ds.sizes["radius"], ds.sizes["wall_thickness"], ds.sizes["coil_index"]
    strength = int((ds["limit"].isel(length=0) == 1).sum())
    return na * nt * (ds.sizes["pressure"] + nc) + strength


def _numpy_yardstick(cfg) -> tuple[float, float]:
    """Seconds of the NumPy yardstick (:mod:`.yardstick`) on ``cfg``'s whole grid
    and of the threaded kernel on the same grid in one slab, back to back (after the
    sweep, so that its memory does not count in the sweep's peak)."""
    t0 = time.perf_counter()
    grid_numpy(cfg)
    t_numpy = time.perf_counter() - t0
    t0 = time.perf_counter()
    compute_slab(cfg, 0, cfg.shape[0])
    return t_numpy, time.perf_counter() - t0


def run_bench(quick: bool = False, log=None) -> dict:
    """Time compile, kernels, the end-to-end sweep and the reference.

    ``log`` receives each line of the report as it is measured; the figures are returned.
    """
    sizes = QUICK if quick else FULL
    cfg = bench_config(sizes)
    say = log or (lambda msg: None)
    say(f"nylonflex bench{' --quick' if quick else ''}: {cfg.n_designs:,} designs "
        f"({' x '.join(str(n) for n in cfg.shape)}), curves {sizes['stroke']} strokes x "
        f"{sizes['pressure']} pressures")

    t0 = time.perf_counter()
    compute_slab(cfg, 0, 1)
    t_compile = time.perf_counter() - t0
    say(f"  compile or load cache      {t_compile:8.2f} s")

    cpu_kernel, t_kernel = kernel_seconds(cfg)
    flops = kernel_flops_per_design(cfg, pairs=2 if quick else 4)
    kernel_gflops = flops * cfg.n_designs / cpu_kernel / 1e9

    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        sweep_file(cfg, Path(tmp) / "cube.h5")  # the sweep and its file, not the reopening
        t_total = time.perf_counter() - t0
        ds = open_cube(Path(tmp) / "cube.h5")
        solves = _solve_count(ds)
        size_mb = (Path(tmp) / "cube.h5").stat().st_size / 2**20
        ds.close()
        light = command_costs(Path(tmp) / "cube.h5")
        # S2 (the sweep beyond its start-up over its kernel and encoding): not in --quick,
        # whose 3,456 designs cost less than the noise of two process start-ups
        encode_cpu, _ = kernel_encode_seconds(cfg, tmp)
        whole = process_ratios(Path(tmp) / "cube.h5", pairs=1 if quick else 5,
                               sweep=None if quick else bench_dict(sizes),
                               encode_cpu=encode_cpu)
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t_numpy, t_kernel_whole = _numpy_yardstick(cfg)

    rng = np.random.default_rng(12)
    n_ref = sizes["reference_designs"]
    designs = [(rng.uniform(5e-3, 25e-3), rng.uniform(1e-3, 6e-3), rng.uniform(1.1, 1.7),
                math.radians(rng.uniform(2, 30))) for _ in range(n_ref)]
    t0 = time.perf_counter()
    for d in designs:
        _reference_design(cfg, *d)
    t_ref = (time.perf_counter() - t0) / n_ref
    t_point, t_loop_py, n_point = _pointwise_seconds(sizes["pointwise_designs"])
    cpu_single, cpu_batch = _single_vs_batch_cpu(2000 if quick else 20_000,
                                                 200 if quick else 2000)
    gflops, gflops_cpu = _matmul_gflops(256 if quick else 1024)

    sim_duration = 60.0 if quick else 3600.0
    t_loop, t_sim = _closed_loop_seconds(sim_duration)

    t_sampled, cpu_sampled, n_sampled = _sampled_seconds(quick)
    cold = None if quick else cold_compiles()  # a minute of CPU: not in the smoke run

    per_design = t_total / cfg.n_designs
    result = {
        "designs": cfg.n_designs,
        "compile_s": t_compile,
        "kernel_s": t_kernel,
        "kernel_designs_per_s": cfg.n_designs / t_kernel,
        "sweep_s": t_total,
        "sweep_designs_per_s": cfg.n_designs / t_total,
        "angle_solves": solves,
        "angle_solves_per_s": solves / t_kernel,
        "reference_s_per_design": t_ref,
        "speedup": t_ref / per_design,
        "pointwise_s_per_design": t_point,
        "python_loop_s_per_design": t_loop_py,
        "pointwise_vs_reference": t_ref / t_point,
        "pointwise_vs_python_loop": t_loop_py / t_point,
        "closed_loop_s": t_loop,
        "closed_loop_run_s": t_sim,
        "numpy_s": t_numpy,
        "numpy_designs_per_s": cfg.n_designs / t_numpy,
        "kernel_whole_grid_s": t_kernel_whole,
        "kernel_vs_numpy": t_numpy / t_kernel_whole,
        "peak_rss_mb": peak_mb,
        "cube_mb": size_mb,
        "single_design_cpu_s": cpu_single,
        "batch_design_cpu_s": cpu_batch,
        "single_vs_batch": cpu_single / cpu_batch,
        "matmul_gflops": gflops,
        "matmul_gflops_per_cpu_s": gflops_cpu,
        "kernel_cpu_s": cpu_kernel,
        "kernel_encode_cpu_s": encode_cpu,
        "kernel_flops_per_design": flops,
        "kernel_gflops_per_cpu_s": kernel_gflops,
        "kernel_peak_fraction": kernel_gflops / gflops_cpu,
        "sampled_s": t_sampled,
        "sampled_evaluations": n_sampled,
        "sampled_evaluations_per_s": n_sampled / t_sampled,
        "sampled_cpu_us_per_evaluation": cpu_sampled / n_sampled * 1e6,
        "light_commands": light,
        "cold_compile": cold,
    }
    result["ratios"] = {**kernel_ratios(result), **whole}
    say(f"  kernels only               {t_kernel:8.2f} s  {result['kernel_designs_per_s']:>12,.0f}"
        f" designs/s  {result['angle_solves_per_s']:>10,.0f} angle solves/s")
    say(f"  sweep end to end (+ HDF5)  {t_total:8.2f} s  {result['sweep_designs_per_s']:>12,.0f}"
        f" designs/s  cube {size_mb:.0f} MB")
    say(f"  NumPy yardstick            {t_numpy:8.2f} s  {result['numpy_designs_per_s']:>12,.0f}"
        f" designs/s  (same structure vectorised over designs, mechanics only)")
    say(f"  kernel vs NumPy            {result['kernel_vs_numpy']:>12.1f} x  (kernel "
        f"{t_kernel_whole:.2f} s on the same grid, same run; benchmarks/yardstick.py)")
    say(f"  scipy reference            {t_ref:8.3f} s per design ({n_ref} designs)")
    say(f"  speed-up per design        {result['speedup']:>12,.0f} x  (reference / sweep, "
        "same run)")
    say(f"  nf.evaluate, scattered      {t_point * 1e6:8.1f} us per design ({n_point:,} random "
        f"designs over the accepted ranges)")
    say(f"  python-loop design_limits  {t_loop_py * 1e6:8.1f} us per design "
        f"(physics.design_limits, the same formulas uncompiled)")
    say(f"  evaluate speed-up          {result['pointwise_vs_reference']:>12,.0f} x the scipy "
        f"reference, {result['pointwise_vs_python_loop']:,.0f} x the python loop (same run)")
    say(f"  nf.evaluate, one design    {cpu_single * 1e6:8.1f} us CPU, "
        f"{result['single_vs_batch']:.1f} x a design of a batch ({cpu_batch * 1e6:.2f} us CPU"
        f" each, same run)")
    say(f"  NumPy matmul (peak)        {gflops:8.1f} GFlop/s (float64, the BLAS threads of "
        f"this process: one under the nylonflex command), {gflops_cpu:.1f} GFlop per CPU-s")
    say(f"  kernel flops               {flops:8.0f} flop per design (counted in its own "
        f"source, benchmarks/flops.py), {kernel_gflops:.2f} GFlop per CPU-s: "
        f"{100 * result['kernel_peak_fraction']:.1f} % of the matmul's (same run; "
        f"{cpu_kernel:.2f} CPU-s for the kernels)")
    say(f"  kernel + encoding          {encode_cpu:8.2f} CPU-s over the grid (pooled output "
        f"arrays, the cube's codec, nothing written: kernel {cpu_kernel:.2f} CPU-s of it)")
    say(f"  closed loop {sim_duration / 60:g} min @ 10 ms  {t_loop * 1e3:8.1f} ms loop, "
        f"{t_sim * 1e3:.0f} ms with tables and output")
    say(f"  sampled sweep (uncertainty) {t_sampled:7.2f} s  "
        f"{result['sampled_evaluations_per_s']:>12,.0f} evaluations/s ({n_sampled:,} = "
        f"designs x samples{', quick grid x 16' if quick else ', fig12 grid x 256'})")
    say(f"  sampled, CPU               {result['sampled_cpu_us_per_evaluation']:8.2f} us CPU "
        "per evaluation")
    say(f"  peak memory (RSS)          {peak_mb:8.0f} MB")
    say("  light commands, whole process (CPU s, peak MB; warm cache, the sweep's cube): " +
        ", ".join(f"{k} {c:.2f} s" + ("" if m is None else f" {m:.0f} MB")
                  for k, (c, m) in light.items()))
    if cold is None:
        say("  cold compile               not measured in --quick (nylonflex warmup, empty cache)")
    else:
        say("  cold compile, empty cache  " + ", ".join(
            f"{k} {w:.1f} s ({c:.1f} CPU-s)" for k, (w, c) in cold["kernels"].items()) +
            f"; nylonflex warmup's whole process {cold['process_cpu_s']:.1f} CPU-s")
    for line in ratio_lines(result["ratios"]):
        say(line)
    return result
