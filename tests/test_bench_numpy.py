"""The NumPy yardstick of ``nylonflex bench`` computes what the grid kernel computes."""

import numpy as np

from nylonflex.bench import QUICK, bench_config
from nylonflex.bench.yardstick import MECHANICAL, grid_numpy
from nylonflex.engine.grid import compute_slab


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
