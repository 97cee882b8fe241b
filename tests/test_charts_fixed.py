"""Figure 12(b, c) honour a fixed wrap angle (issue 25): no solid segment, and no band, runs
past the threshold where that wrap angle's strength limit cuts in.

The thresholds are known from the cube itself: for each coil index the last radius whose
design at the wrap angle is stroke-limited (``limit == 0``, docs/model.md s. 8).
"""

import matplotlib
import numpy as np
import pytest

import nylonflex as nf
from nylonflex.charts import fig12b, fig12c
from nylonflex.charts._common import _COLOURS
from nylonflex.config import parse_config

matplotlib.use("Agg")
DEG = np.pi / 180
GRID = {
    "name": "thresholds",
    "grid": {"radius": {"start": 5, "stop": 25, "num": 21, "units": "mm"},  # 1 mm steps
             "wall_thickness": {"values": [2], "units": "mm"},
             "length": {"values": [90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [5, 8, 20], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
               "pressure": {"start": 0, "stop": 25, "num": 5, "units": "kPa"}},
}


@pytest.fixture(scope="module")
def ds():
    return nf.run_sweep(parse_config(GRID))


@pytest.fixture(scope="module")
def sampled():
    raw = dict(GRID, uncertainty={"samples": 8, "seed": 0, "parameters": {
        "silicone.mu": {"rel_sd": 0.05}}})
    return nf.run_sweep(parse_config(raw))


def threshold(ds, coil, psi, valid=False):
    """Radius [mm] of the last stroke-limited design at (coil, psi), from the cube (with
    ``valid``: of the last one without a validity flag, docs/model.md s. 17)."""
    at = dict(wall_thickness=2e-3, length=90e-3, coil_index=coil, wrap_angle=psi)
    ok = ds["limit"].sel(at).values == 0
    if valid:
        ok &= ds["validity"].sel(at).values == 0
    return 1e3 * float(ds["radius"].values[np.flatnonzero(ok)[-1]])


def solid_end(ax, k, coil):
    """Largest radius [mm] the solid line of the k-th coil index reaches on ``ax``: its
    coloured line, and its grey stretch of flagged designs (issue 46)."""
    ends = [np.nanmax(np.where(np.isfinite(line.get_ydata()), line.get_xdata(), np.nan))
            for line in ax.get_lines() if (line.get_linewidth() == 2.0
                                           and line.get_color() == _COLOURS[k]
                                           or line.get_label() == f"_flagged C = {coil:g}")
            and line.get_linestyle() == "-"]
    assert 1 <= len(ends) <= 2
    return max(ends)


@pytest.mark.parametrize("chart", [fig12b, fig12c])
def test_solid_curve_ends_at_the_fixed_wrap_angles_threshold(ds, chart):
    import matplotlib.pyplot as plt

    cut = threshold(ds, 1.7, 8 * DEG)
    # the grid is one where 8 deg cuts in well before 5 deg (the C = 1.7 case)
    assert threshold(ds, 1.7, 5 * DEG) > cut + 1
    fixed = chart(ds, wrap_angle=8 * DEG)
    every = chart(ds)
    try:
        for k, coil in enumerate((1.1, 1.7)):
            assert solid_end(fixed.axes[0], k, coil) == \
                pytest.approx(threshold(ds, coil, 8 * DEG))
        # every wrap angle: the solid line runs to the largest wrap angle's reach
        assert solid_end(every.axes[0], 1, 1.7) == pytest.approx(threshold(ds, 1.7, 5 * DEG))
    finally:
        plt.close(fixed)
        plt.close(every)


@pytest.mark.parametrize("chart", [fig12b, fig12c])
def test_bands_follow_their_curves(sampled, chart):
    import matplotlib.pyplot as plt

    fig = chart(sampled, wrap_angle=8 * DEG)
    try:
        bands = [c for c in fig.axes[0].collections if c.get_paths()]
        assert len(bands) == 2  # one per coil index
        for k, coil in enumerate((1.1, 1.7)):
            right = max(p.vertices[:, 0].max() for p in bands[k].get_paths())
            # a band stops where its curve turns grey (a flagged design): no colour there
            assert right == pytest.approx(threshold(sampled, coil, 8 * DEG, valid=True))
    finally:
        plt.close(fig)
