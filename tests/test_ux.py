"""Issue 15's conveniences: dry run, compile notice, init, list (small grids, no timing)."""

import pytest
import yaml
from conftest import write_cube  # noqa: F401

from nylonflex.cli import main
from nylonflex.config import parse_config

TINY = {
    "name": "tiny",
    "grid": {
        "radius": {"start": 5, "stop": 15, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [2, 4], "units": "mm"},
        "length": {"values": [70], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 30, "num": 6, "units": "kPa"}},
}


def run(capsys, *argv):
    rc = main([*map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


def test_dry_run_prints_size_memory_time_and_writes_nothing(tmp_path, capsys):
    config = tmp_path / "tiny.yaml"
    config.write_text(yaml.safe_dump(TINY))
    out = tmp_path / "runs" / "cube.h5"
    rc, text, _ = run(capsys, "sweep", config, "--out", out, "--dry-run")
    assert rc == 0
    assert "20 designs = 5 radius x 2 wall_thickness x 1 length x 2 coil_index" in text
    for word in ("on disk", "uncompressed", "memory", "time", "designs/s measured"):
        assert word in text, word
    assert not (tmp_path / "runs").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tiny.yaml"]


def test_estimate_sizes_match_the_written_cube(tmp_path):
    from nylonflex.sweep import estimate

    cfg = parse_config(TINY)
    e = estimate(cfg)
    assert e["designs"] == 20 and e["slabs"] >= 1 and e["sample_designs"] == 20
    path = write_cube(tmp_path, TINY)
    # the uncompressed size is exact arithmetic (float64 and int8 arrays); the file adds
    # HDF5 headers and attributes, so it is only compared loosely
    assert 0 < e["compression_ratio"] <= 1.2
    assert e["disk_bytes"] < path.stat().st_size + e["raw_bytes"]


def test_warm_up_reports_and_notices_only_when_slow():
    from nylonflex.engine import warmup

    seen = []
    assert warmup._timed(lambda: None, seen.append, after=60.0) == 0.0
    assert seen == []  # a quick call: no notice
    import threading

    gate = threading.Event()
    # a call that outlasts the notice delay: wait until the notice has come
    seconds = warmup._timed(lambda: gate.wait(60), lambda m: (seen.append(m), gate.set()),
                            after=0.01)
    assert seen == [warmup.COMPILE_NOTICE] and seconds > 0
    assert warmup.warm_up_grid(parse_config(TINY)) >= 0.0
    assert warmup.warm_up_points() >= 0.0


# ---------------------------------------------------------------------------- init, list
EXAMPLE_NAMES = ("fig12", "control", "step", "gripper")


def test_init_writes_the_examples_and_never_overwrites(tmp_path, capsys):
    from pathlib import Path

    from nylonflex.config import load_config
    from nylonflex.simconfig import load_sim_config

    rc, out, _ = run(capsys, "init", tmp_path / "mine")
    assert rc == 0 and len(out.strip().splitlines()) == 4
    repo = Path(__file__).resolve().parents[1] / "configs"
    for name in EXAMPLE_NAMES:  # the packaged files are the repository's configs
        written = (tmp_path / "mine" / f"{name}.yaml").read_text()
        assert written == (repo / f"{name}.yaml").read_text(), name
    assert load_config(tmp_path / "mine" / "fig12.yaml").n_designs == 41 * 6 * 3 * 4 * 4
    for name in ("control", "step", "gripper"):
        load_sim_config(tmp_path / "mine" / f"{name}.yaml")
    edited = tmp_path / "mine" / "step.yaml"
    edited.write_text("# mine\n")
    rc, _, err = run(capsys, "init", tmp_path / "mine")
    assert rc == 2 and "already exist" in err and "nothing written" in err
    assert edited.read_text() == "# mine\n"
    rc, _, _ = run(capsys, "init", tmp_path / "other", "--example", "fig12")
    assert rc == 0 and [p.name for p in (tmp_path / "other").iterdir()] == ["fig12.yaml"]


def test_list_materials_charts_variables(capsys):
    rc, out, _ = run(capsys, "list", "materials")
    assert rc == 0 and "tc5005" in out and "mu [Pa]" in out and "56190, 10490" in out
    assert "tensile_strength_table [Pa]" in out and "silver_nylon66" in out
    rc, out, _ = run(capsys, "list", "charts")
    from nylonflex.charts import CHARTS

    assert rc == 0 and all(name in out for name in CHARTS)
    rc, out, _ = run(capsys, "list", "variables")
    assert rc == 0 and "tip_force_max" in out and "[N m], shown in N mm" in out


def test_help_names_the_accepted_values(capsys):
    from nylonflex.charts import CHARTS

    for command, names in (("chart", list(CHARTS)), ("query", ["tip_force_max", "radius"])):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        out = " ".join(capsys.readouterr().out.split())
        for name in names:
            assert name in out, (command, name)
