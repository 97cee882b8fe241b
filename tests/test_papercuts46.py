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


def _fidelity():
    import xarray as xr

    deg = np.pi / 180
    return xr.Dataset(
        {"radius": ("design", [15e-3, 20e-3, 10e-3]),
         "wall_thickness": ("design", [2e-3, 6e-3, 3e-3]),
         "length": ("design", [90e-3, 90e-3, 70e-3]), "coil_index": ("design", [1.7, 1.1, 1.3]),
         "wrap_angle": ("design", [8 * deg] * 3),
         "ratio": (("model", "design", "level"),
                   [[[0.95, 0.62], [0.97, 0.8], [1.2, 1.05]],
                    [[1.0, 1.5], [1.02, np.nan], [0.99, 0.7]]])},
        coords={"design": np.arange(3), "level": [0.5, 1.0],
                "model": ["paper", "fe_calibrated"]}, attrs={"fe_mesh": "coarse"})


def test_verify_map_and_summary_share_one_computation():
    # the map (at p*) said 33 % where the command line (both pressures) said 29 %
    from nylonflex.charts.fidelity import fidelity_map
    from nylonflex.fe.verify import fidelity_summary

    fid = _fidelity()
    titles = [ax.get_title() for ax in fidelity_map(fid).axes[:2]]
    lines = fidelity_summary(fid)
    # paper at p*: 0.62, 0.8, 1.05 -> median 0.80, 1 of 3 within 10 %
    assert "median 0.80, 33 % within 10 %" in titles[0]
    assert any(line.startswith("paper             at p*       model/FE median 0.800, range "
                               "0.620-1.050, within 10 %: 33 % (3 FE angles)")
               for line in lines), lines
    # fe_calibrated at p*: 1.5 and 0.7 (one stalled): 0 of 2
    assert "median 1.10, 0 % within 10 %" in titles[1]
    assert any("fe_calibrated     at p*" in x and "0 % (2 FE angles)" in x for x in lines)
    # and over both levels, said as such
    assert any("paper             every level" in x and "(6 FE angles)" in x for x in lines)


def test_progress_off_a_terminal_is_a_line_with_the_count_and_time(capsys):
    import time

    from nylonflex.cli._common import progress_bar

    err = ""
    with progress_bar("verify", unit="design", every=0.05) as bar:
        bar(3, 8)
        for _ in range(200):  # the timer's line, whenever it comes (no timing asserted)
            err += capsys.readouterr().err
            if "3 of 8" in err:
                break
            time.sleep(0.05)
    assert re.search(r"^nylonflex verify: 3 of 8 designs \(38 %\), \d+ s elapsed, "
                     r"about \d+ s left$", err, re.M), err
    capsys.readouterr()  # a tick between the last read and the block's end
    with progress_bar("sweep", quiet=True, every=0.01) as bar:
        bar(1, 2)
        time.sleep(0.1)
    assert capsys.readouterr().err == ""  # --quiet: nothing


def test_no_progress_line_comes_after_the_block_ends(capsys, monkeypatch):
    # the timer is joined when the block ends: a line it is printing lands inside the
    # block, and none after it (a stale line under the command's last output). A slow
    # line() holds the timer mid-print while the block ends.
    import time

    from nylonflex.cli._common import progress_bar

    def slow_line(self):
        time.sleep(0.1)
        return "tick"

    monkeypatch.setattr(progress_bar, "line", slow_line)
    with progress_bar("verify", unit="design", every=0.001) as bar:
        bar(3, 8)
        time.sleep(0.02)  # the timer is inside line() now
    capsys.readouterr()
    time.sleep(0.3)
    assert capsys.readouterr().err == ""


def test_the_control_chart_says_amplitude_not_span():
    # rms_error_fraction is of the reference's size: a sine's amplitude (config.simulate)
    from nylonflex.charts.sim import figure9
    from nylonflex.config.simulate import parse_sim_config
    from nylonflex.sim import run_simulation

    raw = {"name": "t", "time": {"duration": "20 s", "step": "10 ms"},
           "reference": {"kind": "sine", "mean": "60 deg", "amplitude": "20 deg",
                         "frequency": "0.04 Hz"}}
    ds = run_simulation(parse_sim_config(raw))
    title = figure9(ds).axes[0].get_title()
    assert "% of the 20 deg amplitude)" in title and "span" not in title
