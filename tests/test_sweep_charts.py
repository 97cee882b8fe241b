"""The charts a sweep draws beside its cube (drawn by the sweep's own process, after the
sweep), and the sweep command's start."""

import os
from pathlib import Path

import pytest

from nylonflex.cli import main

SMALL = {
    "name": "ahead",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 7, "units": "mm"},
        "wall_thickness": {"values": [2], "units": "mm"},
        "length": {"values": [90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 25, "num": 6, "units": "kPa"}},
}


def test_a_bad_config_is_refused_before_any_chart(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    import yaml

    grid = {**SMALL["grid"], "radius": {"values": [5], "units": "furlong"}}
    bad.write_text(yaml.safe_dump({**SMALL, "grid": grid, "charts": ["fig4"]}))
    assert main(["sweep", str(bad), "--quiet"]) == 2
    assert "furlong" in capsys.readouterr().err


def test_the_sweep_draws_its_charts_beside_the_cube(tmp_path, capsys):
    import yaml

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump({**SMALL, "charts": ["fig4", "design_map"]}))
    out = tmp_path / "run" / "cube.h5"
    assert main(["sweep", str(cfg), "--out", str(out), "--quiet"]) == 0
    captured = capsys.readouterr()
    assert str(out.parent / "fig4.png") in captured.out
    assert "design_map skipped" in captured.err  # printed by the command itself
    assert (out.parent / "fig4.png").stat().st_size > 10_000


def test_the_sweep_command_leaves_the_garbage_collector_running(tmp_path):
    # it pauses the collector while it starts (imports) and freezes what that made
    import gc

    import yaml

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump(SMALL))
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "cube.h5"), "--quiet",
                 "--no-charts"]) == 0
    assert gc.isenabled() and gc.get_freeze_count() > 0
    gc.unfreeze()


@pytest.mark.slow
def test_a_first_sweep_compiles_aside_and_makes_the_same_cube(tmp_path):
    # an empty cache: the kernel compiles in a forked child while the command imports the
    # chart libraries, then loads it; the cube is the one a warm process makes, bit for bit
    import subprocess
    import sys

    import xarray as xr
    import yaml

    cfg = tmp_path / "c.yaml"
    cfg.write_text(yaml.safe_dump({**SMALL, "charts": ["fig4"]}))
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "MPLBACKEND": "Agg"}
    env.pop("NYLONFLEX_NO_CACHE", None)
    cold = subprocess.run([sys.executable, "-m", "nylonflex", "sweep", str(cfg), "--out",
                           str(tmp_path / "cold" / "cube.h5")], env=env, capture_output=True,
                          text=True, timeout=600)
    assert cold.returncode == 0, cold.stderr
    assert cold.stderr.count("compiling the grid kernel") == 1  # by the child, once
    assert "compiled in" in cold.stderr and "in a second process" in cold.stderr and (tmp_path / "cold" / "fig4.png").exists()
    assert list(Path(env["NUMBA_CACHE_DIR"]).glob("*/grid.compiled"))
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "warm" / "cube.h5"), "--quiet",
                 "--no-charts"]) == 0
    with xr.open_dataset(tmp_path / "cold" / "cube.h5") as a, \
            xr.open_dataset(tmp_path / "warm" / "cube.h5") as b:
        for name in b.data_vars:
            assert a[name].equals(b[name]), name
