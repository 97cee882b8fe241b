"""Charts: every figure is drawn from a cube, labelled in display units, titled with its
slice, and written as PNG, PDF and SVG without a display."""

import ast
import math
from pathlib import Path

import pytest
from helpers import write_cube

from nylonflex import charts
from nylonflex.cli import main
from nylonflex.config import CHARTS, parse_config
from nylonflex.storage import open_cube
from nylonflex.sweep.conductor import run_sweep

DEG = math.pi / 180.0
SMALL = {
    "name": "small",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
        "wall_thickness": {"values": [1, 2, 4, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.5, 1.7]},
        "wrap_angle": {"values": [5, 8, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 11},
               "pressure": {"start": 0, "stop": 40, "num": 9, "units": "kPa"}},
    "charts": ["fig12b", "design_map"],
}

#: chart -> units its axes must show (the registry's display units).
UNITS = {"fig12a": ["[N]"], "fig12b": ["[mm]", "[N mm]"], "fig12c": ["[mm]", "[deg]", "[%]"],
         "fig4": ["[kPa]"], "fig6": ["[kPa]", "[deg]"], "fig7": ["[kPa]", "[N]"],
         "design_map": ["[mm]", "[N]"], "compare": ["[mm]", "[N]"]}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("charts"), SMALL)


@pytest.fixture(scope="module")
def ds(cube):
    ds = open_cube(cube)
    yield ds
    ds.close()


def test_chart_names_are_the_configs():
    assert tuple(charts.CHARTS) == CHARTS


def test_every_chart_function_is_the_registrys():
    # one registry (config/charts.py): the functions, what each needs, how it is drawn
    from nylonflex.config.charts import CHART_REGISTRY

    assert tuple(CHART_REGISTRY) == CHARTS
    for name, chart in CHART_REGISTRY.items():
        assert charts.CHARTS[name] is getattr(charts, name)
        assert chart.load() is charts.CHARTS[name]
        assert charts.NEEDS[name] == chart.needs
    # one figure holds every model in fig12b, fig12c and compare (docs/model.md s. 16)
    assert charts.ALL_MODELS == ("fig12b", "fig12c", "compare")


# charts of a plain cube; feasibility_map needs a sampled cube (tests/test_uncertainty.py),
# the dynamics charts a supply (tests/test_dynamics.py)
from nylonflex.config.charts import CHART_REGISTRY as _REGISTRY  # noqa: E402

CHART_VARIABLE = {n: c.variable for n, c in _REGISTRY.items()}
PLAIN_CHARTS = tuple(n for n in CHARTS if n != "feasibility_map"
                     and CHART_VARIABLE.get(n) is None)


@pytest.mark.parametrize("name", PLAIN_CHARTS)
def test_labels_carry_units_and_title_names_the_slice(ds, name):
    import matplotlib.pyplot as plt

    fig = charts.CHARTS[name](ds)
    try:
        labels = [ax.get_xlabel() + " " + ax.get_ylabel() for ax in fig.axes]
        labels += [ax.get_label() for ax in fig.axes]
        text = " ".join(labels)
        for unit in UNITS[name]:
            assert unit in text, (name, unit, labels)
        assert any(ax.get_xlabel() for ax in fig.axes) and any(ax.get_ylabel()
                                                               for ax in fig.axes)
        title = fig._suptitle.get_text()
        assert title and ("Figure" in title or "Design map" in title)
        slice_text = title + " ".join(ax.get_title() for ax in fig.axes)
        # each chart says which slice it shows: a fixed value with its unit
        assert any(s in slice_text for s in ("mm", "deg", "same for every design")), name
    finally:
        plt.close(fig)


def test_label_reads_the_attrs_and_shows_display_units():
    # issue 28: one label(da), after xarray's label_from_attrs
    import xarray as xr

    from nylonflex.variables import label, name_label

    radius = xr.DataArray([5e-3], dims="radius", name="radius",
                          attrs={"units": "m", "long_name": "chamber radius"})
    assert label(radius) == "chamber radius [mm]"  # the display unit, not the SI attrs
    assert label(radius.assign_attrs(long_name="inner radius")) == "inner radius [mm]"
    assert label(xr.DataArray(0.5, name="bend_angle_max")) == "maximum bend angle [deg]"
    assert label(xr.DataArray(0.3, name="usable_stroke",
                              attrs={"units": "1", "long_name": "usable stroke"})) \
        == "usable stroke"  # dimensionless: no brackets
    grip = xr.DataArray(1.0, name="grip", attrs={"units": "N m", "long_name": "grip torque"})
    assert label(grip) == "grip torque [N m]"  # not registered: its own units
    assert label(xr.DataArray(1.0, name="grip")) == "grip" == name_label("grip")
    assert label(xr.DataArray(0.0, name="stroke"), " [-]") == "muscle stroke [-]"
    assert name_label("tip_force_max") == "maximum tip force [N]"
    assert name_label("stroke", " [-]") == "muscle stroke [-]"


def test_a_long_name_edited_in_the_cube_shows_on_its_charts(ds):
    import matplotlib.pyplot as plt

    edited = ds.copy()
    edited["radius"].attrs["long_name"] = "inner radius"
    edited["tip_force_max"].attrs["long_name"] = "blocked force"
    edited["stroke"].attrs["long_name"] = "contraction"
    assert ds["radius"].attrs["long_name"] == "chamber radius"  # the fixture's cube as it was
    for name, want in (("design_map", ["inner radius [mm]", "blocked force [N]"]),
                       ("compare", ["inner radius [mm]", "blocked force [N]"]),
                       ("fig12b", ["inner radius [mm]"]), ("fig4", ["contraction [-]"])):
        fig = charts.CHARTS[name](edited)
        try:
            texts = [t for ax in fig.axes for t in (ax.get_xlabel(), ax.get_ylabel())]
            for text in want:
                assert text in texts, (name, text, texts)
            assert not any("chamber radius" in t for t in texts), (name, texts)
        finally:
            plt.close(fig)


def test_every_chart_is_written_as_png(ds, tmp_path):
    paths = charts.draw_charts(ds, None, tmp_path, "png")
    assert [p.name for p in paths] == [f"{n}.png" for n in PLAIN_CHARTS]
    for p in paths:
        assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 10_000


@pytest.mark.parametrize("fmt, magic", [("pdf", b"%PDF"), ("svg", b"<?xml")])
def test_pdf_and_svg(ds, tmp_path, fmt, magic):
    (path,) = charts.draw_charts(ds, ["fig12c"], tmp_path / "out", fmt)
    assert path == tmp_path / "out" / f"fig12c.{fmt}"
    assert path.read_bytes().startswith(magic)
    if fmt == "svg":  # text stays text: labels are searchable in the file
        assert "maximum bend angle [deg]" in path.read_text()


def test_slice_follows_the_paper(ds):
    import matplotlib.pyplot as plt

    fig = charts.fig12c(ds)
    assert "L = 90 mm" in fig._suptitle.get_text()
    assert {ax.get_title() for ax in fig.axes} >= {"wall thickness t = 2 mm",
                                                   "wall thickness t = 6 mm"}
    plt.close(fig)
    fig = charts.design_map(ds, length=70e-3, wrap_angle=20 * DEG, coil_index=1.5)
    assert "L = 70 mm, \u03c8 = 20 deg" in fig._suptitle.get_text()
    assert [ax.get_title() for ax in fig.axes if ax.get_title()] == ["C = 1.5"]
    plt.close(fig)


def test_chart_command_beside_the_cube(cube, capsys):
    rc = main(["chart", str(cube), "--figure", "fig4", "fig12a", "--format", "svg"])
    out = capsys.readouterr().out.split()
    assert rc == 0
    assert out == [str(cube.parent / "fig4.svg"), str(cube.parent / "fig12a.svg")]
    assert all(Path(p).is_file() for p in out)


def test_chart_command_refusals(cube, tmp_path, capsys):
    assert main(["chart", str(cube), "--figure", "fig99"]) == 2
    assert "unknown chart 'fig99'; accepted: fig12a" in capsys.readouterr().err
    bad = tmp_path / "x.h5"
    bad.write_bytes(b"nope")
    assert main(["chart", str(bad)]) == 2
    assert "not a nylonflex cube" in capsys.readouterr().err
    afile = tmp_path / "file.txt"
    afile.write_text("")
    assert main(["chart", str(cube), "--out", str(afile)]) == 2


def test_sweep_draws_the_configs_charts(tmp_path, capsys, monkeypatch):
    import yaml

    cfg = tmp_path / "small.yaml"
    cfg.write_text(yaml.safe_dump(SMALL))
    rc = main(["sweep", str(cfg), "--out", str(tmp_path / "s" / "cube.h5"), "--quiet"])
    out = capsys.readouterr().out
    assert rc == 0
    for name in SMALL["charts"]:
        assert (tmp_path / "s" / f"{name}.png").is_file() and f"{name}.png" in out


def test_charts_read_the_dataset_only():
    # layers (STYLE.md): charts never compute physics; matplotlib is imported lazily
    for path in sorted(Path(charts.__file__).parent.glob("*.py")):
        tree = ast.parse(path.read_text())
        imported = {(n.module or "") for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)}
        imported |= {a.name for n in ast.walk(tree) if isinstance(n, ast.Import)
                     for a in n.names}
        assert not any("physics" in m or "kernels" in m or "sweep" in m for m in imported), path
        top = {a.name for n in tree.body if isinstance(n, ast.Import) for a in n.names}
        top |= {n.module for n in tree.body if isinstance(n, ast.ImportFrom)}
        assert not any(m and m.startswith("matplotlib") for m in top), path


def test_incomplete_cube_draws_with_a_warning(cube, tmp_path, capsys):
    import h5py

    part = tmp_path / "part.h5"
    part.write_bytes(cube.read_bytes())
    with h5py.File(part, "r+") as f:
        f.attrs["complete"] = "false"
        f["slab_done"][5:] = 0
    rc = main(["chart", str(part), "--figure", "fig12b", "design_map"])
    captured = capsys.readouterr()
    assert rc == 0 and "incomplete" in captured.err
    assert (tmp_path / "design_map.png").is_file()


def test_a_cube_with_single_value_axes_skips_what_it_cannot_draw(tmp_path, capsys):
    from nylonflex.cli import main

    raw = {"name": "one",
           "grid": {"radius": {"values": [10], "units": "mm"},
                    "wall_thickness": {"values": [2, 3], "units": "mm"},
                    "length": {"values": [90], "units": "mm"},
                    "coil_index": {"values": [1.3]},
                    "wrap_angle": {"values": [8], "units": "deg"}},
           "curves": {"stroke": {"values": [0.0, 0.05]},
                      "pressure": {"values": [10], "units": "kPa"}}}
    out = tmp_path / "cube.h5"
    run_sweep(parse_config(raw), out).close()
    assert main(["chart", str(out)]) == 0
    captured = capsys.readouterr()
    assert "design_map skipped: it needs at least 2 values of radius" in captured.err
    assert "fig6 skipped" in captured.err and "fig12b skipped" in captured.err
    assert (tmp_path / "fig4.png").is_file() and (tmp_path / "fig12a.png").is_file()
    assert not (tmp_path / "design_map.png").exists()


def test_files_come_back_in_the_order_asked_though_drawn_longest_first(ds, tmp_path):
    names = ["fig4", "fig12b", "design_map"]  # drawn design_map, fig12b, fig4
    assert [charts.COST[n] for n in names] == sorted(charts.COST[n] for n in names)
    paths = charts.draw_charts(ds, names, tmp_path, "png", processes=2)
    assert [p.name for p in paths] == ["fig4.png", "fig12b.png", "design_map.png"]
