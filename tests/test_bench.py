"""``nylonflex bench --quick`` as a smoke run: it runs and reports; no timing is asserted."""

from nylonflex.bench import run_bench


def test_quick_bench_reports_every_figure():
    lines = []
    result = run_bench(quick=True, log=lines.append)
    text = "\n".join(lines)
    for words in ("designs/s", "angle solves/s", "speed-up per design", "peak memory",
                  "closed loop", "evaluations/s", "NumPy yardstick", "kernel vs NumPy",
                  "one design", "GFlop/s"):
        assert words in text
    assert result["designs"] == 12 * 6 * 4 * 3 * 4
    assert result["angle_solves"] >= 12 * 6 * (9 + 3)  # curve points + full-stroke solves
    assert all(result[k] > 0 for k in ("kernel_s", "sweep_s", "reference_s_per_design",
                                       "speedup", "peak_rss_mb", "numpy_s",
                                       "kernel_vs_numpy", "single_vs_batch",
                                       "matmul_gflops"))
