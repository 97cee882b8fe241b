"""Issue 10's charts and query for a cube of several models: fig12b and fig12c draw every
model in one figure, flagged designs are greyed with a legend naming the flags, compare
draws a chosen variable, and query prints the model in every row."""

import csv
import io
import json

import pytest
from helpers import write_cube

from nylonflex import charts
from nylonflex.cli import main
from nylonflex.query import format_csv, format_json, format_table, query_cube
from nylonflex.storage import open_cube
from nylonflex.units import InputError

MODELS = ["paper", "coupled_muscle", "incompressible_wall"]
SMALL = {
    "name": "models",
    "model": MODELS,
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [2, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [8, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 5},
               "pressure": {"start": 0, "stop": 20, "num": 5, "units": "kPa"}},
}
#: The paper's first worked example (docs/model.md s. 8), on this grid.
EXAMPLE = "radius=20mm,wall_thickness=6mm,length=90mm,coil_index=1.1,wrap_angle=8deg"


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("models"), SMALL)


@pytest.fixture(scope="module")
def ds(cube):
    ds = open_cube(cube)
    yield ds
    ds.close()


def _texts(fig):
    out = [t.get_text() for t in fig.texts]
    for ax in fig.axes:
        out += [ax.get_title(), ax.get_ylabel()]
    for legend in fig.legends + [ax.get_legend() for ax in fig.axes if ax.get_legend()]:
        out += [t.get_text() for t in legend.get_texts()]
    return "\n".join(out)


@pytest.mark.parametrize("name, rows", [("fig12b", 2), ("fig12c", 4)])
def test_fig12bc_draw_every_model_in_one_figure(ds, name, rows):
    import matplotlib.pyplot as plt

    fig = charts.CHARTS[name](ds)
    try:
        visible = [ax for ax in fig.axes if ax.get_visible()]
        assert len(visible) == rows * len(MODELS)  # a column per model, rows per wall
        titles = [ax.get_title() for ax in visible]
        for m in MODELS:
            assert sum(t.startswith(m + "\n") for t in titles) == 2  # one per wall
        text = _texts(fig)
        # coupled_muscle's designs are load-limited: drawn, and said so in the legend
        assert "load-limited" in text
        # one scale along a row: the models compare directly
        row = visible[:len(MODELS)]
        assert len({ax.get_ylim() for ax in row}) == 1 and row[0].get_ylim()[0] == 0
    finally:
        plt.close(fig)


def test_flagged_designs_are_named_in_the_legend(ds):
    import matplotlib.pyplot as plt

    # incompressible_wall closes the chamber of thin-walled small designs (bit 8) and some
    # bend past 360 deg (bit 1): the map greys them and the legend names the bits
    flags = ds["validity"].sel(model="incompressible_wall", length=0.09,
                               wrap_angle=ds["wrap_angle"].values[0])
    assert int(flags.max()) > 0
    one = ds.sel(model="incompressible_wall", drop=True)
    fig = charts.design_map(one)
    try:
        text = _texts(fig)
        assert "flagged design:" in text
        named = text.split("flagged design:")[1].splitlines()[0]
        present = {int(b) for b in (1, 2, 4, 8) if (flags.values.astype(int) & b).any()}
        for bit, meaning in zip((1, 2, 4, 8), ds["validity"].attrs["flag_meanings"].split()):
            assert (f"{bit} {meaning}" in named) == (bit in present)
    finally:
        plt.close(fig)


def test_draw_charts_writes_fig12bc_once_and_the_rest_per_model(ds, tmp_path):
    paths = charts.draw_charts(ds, ["fig12b", "compare", "design_map"], tmp_path)
    names = sorted(p.name for p in paths)
    assert names == sorted(["fig12b.png", "compare.png"] +
                           [f"design_map_{m}.png" for m in MODELS])


def test_compare_draws_the_chosen_variable(cube, tmp_path, capsys):
    rc = main(["chart", str(cube), "--figure", "compare", "--variable", "bend_angle_max",
               "--out", str(tmp_path), "--quiet"])
    assert rc == 0 and (tmp_path / "compare.png").is_file()
    with pytest.raises(InputError, match=r"--variable: compare draws one of .*tip_force_max"):
        charts.draw_charts(open_cube(cube), ["compare"], tmp_path, variable="pressure")
    rc = main(["chart", str(cube), "--figure", "fig4", "--variable", "torque_max",
               "--out", str(tmp_path), "--quiet"])
    assert rc == 2 and "only --figure compare" in capsys.readouterr().err


def test_compare_default_is_tip_force_max(ds):
    import matplotlib.pyplot as plt

    fig = charts.compare(ds)
    try:
        ax = fig.axes[0]
        assert ax.get_ylabel().startswith("maximum tip force")
        assert [t.get_text() for t in ax.get_legend().get_texts()][:3] == MODELS
    finally:
        plt.close(fig)


def test_query_prints_the_model_in_every_row(ds):
    res = query_cube(ds, at=EXAMPLE)
    assert res.columns[0] == "model" and list(res.data["model"]) == MODELS
    # the paper's first example: 1.20 N with a full range of motion (docs/model.md s. 8)
    assert res.data["tip_force_max"][0] == pytest.approx(1.20, abs=0.005)
    table = format_table(res).splitlines()
    # the header (long names wrap over lines above it to fit 120 columns), units, rows
    head = next(i for i, line in enumerate(table) if line.split()[:1] == ["model"])
    assert [line.split()[0] for line in table[head + 2:head + 5]] == MODELS
    records = json.loads(format_json(res))["designs"]
    assert [r["model"] for r in records] == MODELS
    rows = list(csv.reader(io.StringIO(format_csv(res))))
    assert rows[0][:2] == ["point", "model"] and [r[1] for r in rows[1:]] == MODELS


def test_query_counts_every_model_and_sorts_across_them(ds):
    res = query_cube(ds, sort="-tip_force_max", limit=3)
    assert res.matched == ds["tip_force_max"].size
    best = float(ds["tip_force_max"].max())
    assert res.data["tip_force_max"][0] == pytest.approx(best)
    assert set(res.data["model"]) <= set(MODELS)


def test_where_model_still_filters(ds, cube, capsys):
    res = query_cube(ds, at=EXAMPLE, where=["model == coupled_muscle"])
    assert "model" not in res.columns and len(res) == 1
    assert res.data["limit"][0] == 3  # load-limited (docs/model.md s. 16)
    rc = main(["query", str(cube), "--where", "model == paper_eq10", "--quiet"])
    assert rc == 2 and "this cube has paper, coupled_muscle" in capsys.readouterr().err
