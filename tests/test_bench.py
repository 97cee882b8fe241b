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
                  "one design", "GFlop/s", "light commands", "cold compile",
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
