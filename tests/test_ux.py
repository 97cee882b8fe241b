"""Issue 15's conveniences: dry run, compile notice, init, list (small grids, no timing)."""

import pytest
import yaml
from helpers import TINY, run, write_cube  # noqa: F401

from nylonflex.cli import main
from nylonflex.config import parse_config


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
    from nylonflex.sweep.conductor import estimate

    cfg = parse_config(TINY)
    e = estimate(cfg)
    assert e["designs"] == 20 and e["slabs"] >= 1 and e["sample_designs"] == 20
    path = write_cube(tmp_path, TINY)
    # the uncompressed size is exact arithmetic (float64 and int8 arrays); the file adds
    # HDF5 headers and attributes, so it is only compared loosely
    assert 0 < e["compression_ratio"] <= 1.2
    assert e["disk_bytes"] < path.stat().st_size + e["raw_bytes"]


def test_a_dry_run_of_a_sampled_sweep_estimates_its_quantile_variables(tmp_path, capsys):
    # the estimate sizes each variable's chunks from the cube's coordinates: a sampled
    # sweep's <variable>_quantile lie over quantile (a KeyError before, exit 1)
    from nylonflex.sweep.conductor import estimate

    raw = {**TINY, "uncertainty": {"samples": 8, "seed": 1,
                                   "parameters": {"silicone.mu": {"rel_sd": 0.1}}}}
    config = tmp_path / "sampled.yaml"
    config.write_text(yaml.safe_dump(raw))
    rc, text, _ = run(capsys, "sweep", config, "--out", tmp_path / "cube.h5", "--dry-run")
    assert rc == 0 and "on disk" in text and not (tmp_path / "cube.h5").exists()
    e = estimate(parse_config(raw))
    assert e["raw_bytes"] > estimate(parse_config(TINY))["raw_bytes"]  # the quantiles too


def test_warm_up_notices_only_when_numba_compiles(monkeypatch):
    # a warm cache: however long the call takes, nothing compiles and nothing is said
    import time

    from nylonflex.engine import warmup

    seen = []
    assert warmup.warm_up_grid(parse_config(TINY)) >= 0.0
    assert warmup.warm_up_points() >= 0.0
    assert warmup.warm_up_grid(parse_config(TINY), notice=seen.append) == 0.0
    assert warmup.timed(lambda: time.sleep(0.3), seen.append) == 0.0  # slow, not compiling
    assert seen == []


# ---------------------------------------------------------------------------- init, list
def test_init_writes_the_examples_and_never_overwrites(tmp_path, capsys):
    from pathlib import Path

    from nylonflex.config import load_config
    from nylonflex.design import load_spec
    from nylonflex.examples import EXAMPLES
    from nylonflex.config.simulate import load_sim_config

    rc, out, _ = run(capsys, "init", tmp_path / "mine")
    repo = Path(__file__).resolve().parents[1]
    # every config of the repository's configs/ (the README's examples), the fitted
    # material they read and the fit's bench data
    assert sorted(EXAMPLES) == sorted(p.stem for p in (repo / "configs").glob("*.yaml"))
    assert rc == 0 and len(out.strip().splitlines()) == len(EXAMPLES) + 3
    mine = tmp_path / "mine"
    for name in EXAMPLES:  # the packaged files are the repository's configs
        written = (mine / "configs" / f"{name}.yaml").read_text()
        assert written == (repo / "configs" / f"{name}.yaml").read_text(), name
    fit = "fits/ecoflex_0050_ogden2.yaml"
    assert (mine / "configs" / fit).read_text() == (repo / "configs" / fit).read_text()
    assert (mine / "data" / "ecoflex_0050.csv").read_bytes() == \
        (repo / "tests" / "data" / "ecoflex_0050.csv").read_bytes()
    assert "ODbL" in (mine / "data" / "README.md").read_text()
    assert load_config(mine / "configs" / "fig12.yaml").n_designs == 41 * 6 * 3 * 4 * 4
    assert load_config(mine / "configs" / "fig12_fitted.yaml").silicone.mu[0] > 0
    load_config(mine / "configs" / "fig12_uncertain.yaml")
    for name in ("control", "step", "gripper"):
        load_sim_config(mine / "configs" / f"{name}.yaml")
    for name in ("design_force", "design_front"):
        load_spec(mine / "configs" / f"{name}.yaml")
    edited = mine / "configs" / "step.yaml"
    edited.write_text("# mine\n")
    rc, _, err = run(capsys, "init", mine)
    assert rc == 2 and "already exist" in err and "nothing written" in err
    assert edited.read_text() == "# mine\n"
    rc, _, _ = run(capsys, "init", tmp_path / "other", "--example", "fig12_fitted")
    assert rc == 0 and sorted(str(p.relative_to(tmp_path / "other"))
                              for p in (tmp_path / "other").rglob("*.yaml")) == \
        ["configs/fig12_fitted.yaml", "configs/fits/ecoflex_0050_ogden2.yaml"]


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


# ---------------------------------------------------------------------------- charts
ODD = {
    "name": "odd",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [1.5, 2, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.25, 1.4, 1.55, 1.7]},
        "wrap_angle": {"values": [3, 5, 8, 10, 14, 18, 25, 30], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 30, "num": 6, "units": "kPa"}},
}


@pytest.fixture(scope="module")
def odd_cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("odd"), ODD)


@pytest.fixture(scope="module")
def odd(odd_cube):
    from nylonflex.storage import open_cube

    ds = open_cube(odd_cube)
    yield ds
    ds.close()


def _texts(fig):
    texts = [t.get_text() for t in fig.texts]
    for ax in fig.axes:
        texts += [ax.get_title()] + [t.get_text() for t in ax.texts]
    return texts


def test_design_map_draws_every_coil_index(odd):
    import matplotlib.pyplot as plt

    from nylonflex import charts

    fig = charts.design_map(odd)
    titles = [ax.get_title() for ax in fig.axes if ax.get_visible() and ax.get_title()]
    assert titles == ["C = 1.1", "C = 1.25", "C = 1.4", "C = 1.55", "C = 1.7"]
    plt.close(fig)


def test_examples_only_where_the_slice_holds_them_with_true_values(odd):
    import matplotlib.pyplot as plt

    from nylonflex import charts
    from nylonflex.variables import to_display

    # example 2 (7.5 mm, 2 mm, 70 mm, C 1.7) is off this radius grid: no star anywhere;
    # example 1 (20 mm, 6 mm, 90 mm, C 1.1, 8 deg) is on it: marked at L = 90 mm only
    fig = charts.fig12c(odd, length=90e-3)
    notes = [t for t in _texts(fig) if t.startswith("paper example")]
    assert len(notes) == 1 and "a = 20 mm, C = 1.1" in notes[0]
    truth = float(to_display("bend_angle_max", odd["bend_angle_max"].sel(
        radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
        wrap_angle=odd["wrap_angle"].values[2])))
    assert f"{truth:.3g} deg" in notes[0]
    plt.close(fig)
    fig = charts.fig12c(odd, length=70e-3)
    assert not [t for t in _texts(fig) if t.startswith("paper example")]
    plt.close(fig)
    fig = charts.fig12b(odd, coil_index=[1.25, 1.7])  # C 1.1 not drawn: no example 1
    assert not [t for t in _texts(fig) if t.startswith("paper example")]
    plt.close(fig)


def test_many_wrap_angles_are_thinned_and_say_so(odd):
    import matplotlib.pyplot as plt

    from nylonflex import charts

    fig = charts.fig12b(odd)
    legend = fig.legends[0]
    labels = [t.get_text() for t in legend.get_texts()]
    assert sum(label.startswith("\u03c8 =") for label in labels) == 6
    assert "the other 2 wrap angles" in labels
    assert "6 of 8 labelled" in legend.get_title().get_text()
    # no in-plot labels that would overprint: the legend names them
    assert not [t for ax in fig.axes for t in ax.texts if t.get_text().startswith("\u03c8")]
    plt.close(fig)


def test_fig6_subtitle_from_the_data(odd):
    import matplotlib.pyplot as plt

    from nylonflex import charts

    fig = charts.fig6(odd)
    title = fig._suptitle.get_text()
    # 6-14 mm holds 10 mm only, 1-4 mm the walls 1.5 and 2 mm: fewer than three, so the
    # whole axes are drawn, and the subtitle names what is drawn (not the paper's spans)
    assert "radius 5-25 mm" in title and "wall thickness 1.5-6 mm" in title, title
    plt.close(fig)


def test_chart_command_slices_and_refuses_off_grid(odd_cube, tmp_path, capsys):
    rc, out, _ = run(capsys, "chart", odd_cube, "--figure", "design_map", "fig12c",
                     "--at", "length=70mm,wrap_angle=8deg", "--coil-index", "1.1,1.7",
                     "--out", tmp_path)
    assert rc == 0 and len(out.split()) == 2
    rc, _, err = run(capsys, "chart", odd_cube, "--at", "length=75mm", "--out", tmp_path)
    assert rc == 2 and "length=75 mm is not a grid value of the cube; it has 70, 90 mm" in err
    rc, _, err = run(capsys, "chart", odd_cube, "--coil-index", "1.3", "--out", tmp_path)
    assert rc == 2 and "--coil-index: coil_index=1.3 is not a grid value" in err


def test_chart_slice_reaches_each_chart_and_progress(odd, tmp_path):
    import matplotlib.pyplot as plt

    from nylonflex import charts

    chosen = charts.chart_slice(odd, {"length": 70e-3, "wrap_angle": 8 * 3.141592653589793
                                      / 180}, [1.1, 1.7])
    fig = charts.design_map(odd, **charts._slice_kwargs(charts.design_map, chosen))
    assert "L = 70 mm, \u03c8 = 8 deg" in fig._suptitle.get_text()
    assert [ax.get_title() for ax in fig.axes if ax.get_title()] == ["C = 1.1", "C = 1.7"]
    plt.close(fig)
    seen = []
    charts.draw_charts(odd, ["fig4", "fig6"], tmp_path, progress=lambda d, n: seen.append(d))
    assert seen[-1] == 2


def test_the_console_script_exits_fast_with_the_status_output_and_exit_handlers(tmp_path):
    # run() ends the process with os._exit after main(): the status, the buffered output
    # (a pipe here) and the atexit handlers must all survive it
    import subprocess
    import sys

    code = ("import atexit, sys\n"
            "atexit.register(lambda: print('exit handler ran'))\n"
            "sys.argv = ['nylonflex', *sys.argv[1:]]\n"
            "from nylonflex.cli import run\n"
            "run()\n")
    bad = subprocess.run([sys.executable, "-c", code, "sweep", "missing.yaml"],
                         capture_output=True, text=True, cwd=tmp_path)
    assert bad.returncode == 2, bad.stderr
    assert "no such config file" in bad.stderr
    assert "exit handler ran" in bad.stdout
    ok = subprocess.run([sys.executable, "-m", "nylonflex", "--version"],
                        capture_output=True, text=True, cwd=tmp_path)
    assert ok.returncode == 0 and ok.stdout.startswith("nylonflex "), ok


def test_the_console_script_waits_for_a_thread_left_running(tmp_path):
    # a non-daemon thread still running: the usual exit, which waits for it
    import subprocess
    import sys

    code = ("import sys, threading, time\n"
            "threading.Thread(target=lambda: (time.sleep(0.3), print('thread done'))).start()\n"
            "sys.argv = ['nylonflex', '--version']\n"
            "from nylonflex.cli import run\n"
            "run()\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       cwd=tmp_path)
    assert r.returncode == 0 and "thread done" in r.stdout, r


# ------------------------------------------------------------------- schema (issue 24)
SCHEMA_EXAMPLES = {"sweep": ("fig12", "fig12_uncertain", "fig12_fitted", "big20m",
                             "fig12_tracking"),
                   "simulate": ("control", "step", "gripper"),
                   "design": ("design_force", "design_front", "design_tracking")}


@pytest.mark.parametrize("kind", list(SCHEMA_EXAMPLES))
def test_schema_prints_json_schema_every_example_meets(capsys, kind):
    # the JSON Schema an editor's YAML language server reads: every example config of
    # that kind validates, and an unknown key (which nylonflex refuses) is flagged too
    import json
    from pathlib import Path

    import yaml

    jsonschema = pytest.importorskip("jsonschema")
    rc, out, _ = run(capsys, "schema", kind)
    schema = json.loads(out)
    assert rc == 0 and schema["$schema"].endswith("2020-12/schema")
    jsonschema.Draft202012Validator.check_schema(schema)
    validator = jsonschema.Draft202012Validator(schema)
    configs = Path(__file__).resolve().parents[1] / "configs"
    for name in SCHEMA_EXAMPLES[kind]:
        doc = yaml.safe_load((configs / f"{name}.yaml").read_text())
        assert not list(validator.iter_errors(doc)), name
        assert list(validator.iter_errors({**doc, "colour": "red"})), name
