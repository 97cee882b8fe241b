"""``nylonflex bench --quick`` as a smoke run: it runs and reports; no timing is asserted.

The suite is the checkout's benchmarks/suite.py, loaded as the command loads it.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import nylonflex
from nylonflex.cli.bench import benchmarks_folder, load_suite

ROOT = Path(__file__).resolve().parents[1]
run_bench = load_suite(benchmarks_folder(ROOT)).run_bench


def test_quick_bench_reports_every_figure():
    lines = []
    result = run_bench(quick=True, log=lines.append)
    text = "\n".join(lines)
    for words in ("designs/s", "angle solves/s", "speed-up per design", "peak memory",
                  "closed loop", "evaluations/s", "NumPy yardstick", "kernel vs NumPy",
                  "one design", "GFlop/s", "flop per design", "% of the matmul's", "light commands",
                  "cold compile", "kernel + encoding",
                  "us CPU per evaluation"):
        assert words in text
    assert result["designs"] == 12 * 6 * 4 * 3 * 4
    assert result["angle_solves"] >= 12 * 6 * (9 + 3)  # curve points + full-stroke solves
    assert all(result[k] > 0 for k in ("kernel_s", "sweep_s", "reference_s_per_design",
                                       "speedup", "peak_rss_mb", "numpy_s",
                                       "kernel_vs_numpy", "single_vs_batch",
                                       "matmul_gflops", "sampled_cpu_us_per_evaluation"))
    # every light command ran (exit 0) and was measured as a child process of its own
    assert set(result["light_commands"]) >= {"info", "query --where", "query --at", "list materials"}
    assert all(cpu > 0 and (mb is None or mb > 0)
               for cpu, mb in result["light_commands"].values())
    # issue 49's ratios, each of two things measured in this run, with its target
    # (S2, a sweep beyond its start-up, needs the full grid: not in --quick)
    assert set(result["ratios"]) == {"K1", "K2", "S1", "L1q", "L1i", "P1s", "P1b"}
    assert result["kernel_encode_cpu_s"] > 0 and result["kernel_cpu_s"] > 0
    assert all(v > 0 for v in result["ratios"].values())
    assert "ratios (issue 49" in text and "target <= 5600" in text


def test_the_flop_count_counts_each_operation_once_and_runs_the_kernels_own_numbers():
    # benchmarks/flops.py counts the kernel's work by running its source on counting floats:
    # p(s) = P_atm ((1 - s)^-2 - 1) is five operations; the counted run of the paper's grid
    # kernel on one (radius, wall) pair writes the compiled kernel's numbers, bit for bit
    # (the Python source is what ran); and the count is a few hundred to a few thousand
    # operations a design of the quick grid (about 1 kflop on the 2 M grid)
    import importlib

    import numpy as np

    from nylonflex.engine.model_slab import grid_axes, grid_out, kernel_inputs
    from nylonflex.kernels import design
    from nylonflex.physics.chamber import _gauge_pressure

    suite = load_suite(benchmarks_folder(ROOT))
    flops = importlib.import_module(suite.__package__ + ".flops")
    with flops.counting() as count:
        p = _gauge_pressure(flops.Flop(0.1), flops.Flop(101325.0))
        assert count() == 5 and isinstance(p, flops.Flop)

    cfg = suite.bench_config(suite.QUICK)
    n, counted = flops.counted_kernel(cfg, 3, 2)
    grid, inputs = grid_axes(cfg, 3, 4), kernel_inputs(cfg, 0)
    out = grid_out(cfg, 1)
    design.design_slab_paper(grid, *inputs, out, design.grid_scratch(grid, inputs[2]), 2, 3)
    for name, a, b in zip(out._fields, out, counted):
        pair = (slice(None), 0, 2) if name in ("design", "flags") else (0, 2)
        np.testing.assert_array_equal(b[pair].astype(a.dtype).view(np.uint8),
                                      a[pair].view(np.uint8), err_msg=name)
    per_design = n / np.prod(out.design.shape[3:])
    assert 300 < per_design < 20_000
    assert flops.kernel_flops_per_design(cfg, pairs=2) > 300


def test_the_command_finds_the_benchmarks_beside_the_package_of_a_checkout(tmp_path):
    # the editable install of the README runs this checkout's nylonflex/: its benchmarks/
    # is the folder beside it; a folder without the project's pyproject.toml is no checkout
    if Path(nylonflex.__file__).resolve().parents[1] != ROOT:
        pytest.skip("nylonflex is installed from elsewhere (not this checkout's editable)")
    assert benchmarks_folder() == ROOT / "benchmarks"
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks" / "suite.py").write_text("")
    assert benchmarks_folder(tmp_path) is None


def test_bench_from_an_installed_wheel_says_in_one_line_where_the_benchmarks_are(tmp_path):
    # a wheel installs nylonflex/ alone into site-packages: the package laid out so (a copy
    # of it, run as python -m nylonflex from there) finds no benchmarks/ beside it
    site = tmp_path / "site-packages"
    shutil.copytree(ROOT / "nylonflex", site / "nylonflex",
                    ignore=shutil.ignore_patterns("__pycache__"))
    done = subprocess.run([sys.executable, "-m", "nylonflex", "bench", "--quick"],
                          env={**os.environ, "PYTHONPATH": str(site)}, cwd=tmp_path,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 2, done.stderr
    assert done.stdout == ""
    (line,) = done.stderr.splitlines()
    assert line.startswith("nylonflex bench: the benchmarks come with a source checkout")
    assert f"({site / 'benchmarks'} is missing)" in line  # the copy ran, not this checkout
