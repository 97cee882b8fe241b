"""Issue 46, item 7: the papercuts a designer acts on."""

import re
from pathlib import Path

import numpy as np

DATA = Path(__file__).parent / "data" / "ecoflex_0050.csv"


def test_a_wide_silicone_interval_beside_a_high_r2_is_explained():
    # the default fit: mu0 in [0, 48 kPa] at R^2 0.997 read like a failed fit
    from nylonflex.calibration import fit_silicone

    res = fit_silicone(str(DATA))
    note = next(n for n in res.notes if n.startswith("intervals allow"))
    m = re.search(r"lag-1 correlation ([0-9.]+) .* R\^2 ([0-9.]+) says the curve is fitted "
                  r"well.* the (\d+) points weigh like about ([0-9.]+) independent ones; an "
                  r"interval ending at 0 is cut at the bound", note)
    assert m, note
    rho, r2, n, n_eff = float(m[1]), float(m[2]), int(m[3]), float(m[4])
    assert n == res.n_points and abs(r2 - res.r2) < 1e-4
    # the variance of the mean of n AR(1) errors is s^2/n^2 sum_ij rho^|i-j| (closed form):
    # it equals that of n_eff independent ones
    lag = np.abs(np.subtract.outer(np.arange(n), np.arange(n)))
    exact = n * n / np.sum(float(rho) ** lag)
    assert n_eff == float(f"{exact:.2g}") or abs(n_eff - exact) / exact < 0.05
    assert 1.0 <= n_eff < 3.0  # the whole pull weighs about like one point
