"""The NumPy yardstick of ``nylonflex bench`` (benchmarks/yardstick.py) computes what the
grid kernel computes."""

import importlib
from pathlib import Path

import numpy as np

from nylonflex.cli.bench import SUITE, benchmarks_folder, load_suite
from nylonflex.engine.grid import compute_slab

suite = load_suite(benchmarks_folder(Path(__file__).resolve().parents[1]))
QUICK, bench_config = suite.QUICK, suite.bench_config
yardstick = importlib.import_module(f"{SUITE}.yardstick")
MECHANICAL, grid_numpy = yardstick.MECHANICAL, yardstick.grid_numpy


def test_numpy_yardstick_matches_the_kernel_to_1e_9():
    cfg = bench_config(QUICK)
    kernel = compute_slab(cfg, 0, cfg.shape[0])
    numpy = grid_numpy(cfg)
    assert set(numpy) == set(MECHANICAL)
    assert (numpy["limit"] == 1).any() and (numpy["limit"] == 0).any()  # both branches
    for name in MECHANICAL:
        assert numpy[name].shape == kernel[name].shape, name
        if name == "limit":
            np.testing.assert_array_equal(numpy[name], kernel[name])
        else:
            np.testing.assert_allclose(numpy[name], kernel[name], rtol=1e-9, atol=0.0,
                                       err_msg=name)
