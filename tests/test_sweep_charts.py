"""The charts a sweep draws beside its cube (drawn by the sweep's own process, after the
sweep), and the sweep command's start."""

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
