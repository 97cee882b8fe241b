"""``nylonflex explore``: the slices the page shows, the offline file and the refusals.

Expected values are the cube's own grid values (``ds.sel``): the explorer never
interpolates. The browser tests are in ``test_explore_browser.py``.
"""

import math
import re

import numpy as np
import pytest
from helpers import write_cube

from nylonflex import explore
from nylonflex.cli import main
from nylonflex.storage import open_cube
from nylonflex.units import InputError
from nylonflex.variables import AXES

DEG = math.pi / 180

SMALL = {
    "name": "small",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
        "wall_thickness": {"values": [2, 4, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 11},
               "pressure": {"start": 0, "stop": 40, "num": 9, "units": "kPa"}},
}
AT = {"radius": 15e-3, "wall_thickness": 2e-3, "length": 90e-3, "coil_index": 1.7,
      "wrap_angle": 8 * DEG}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("explore"), SMALL)


@pytest.fixture(scope="module")
def ds(cube):
    ds = open_cube(cube)
    yield ds
    ds.close()


def synthetic(ds):
    """The cube with a ``model`` dimension on the design variables and a ``validity`` flag
    variable (CF flag_masks), as other work adds them."""
    import xarray as xr

    out = ds[[*explore.design_variables(ds), "nylon_force", "nylon_force_limit",
              "chamber_pressure", "bend_angle", "tip_force"]].load()
    models = xr.DataArray(["paper", "coupled_muscle"], dims="model")
    for name in explore.design_variables(ds):
        if name != "limit":
            out[name] = xr.concat([out[name], 2 * out[name]], dim=models)
    bits = (out["radius"] > 20e-3).astype(np.int8) + 4 * (out["wall_thickness"] < 3e-3)
    out["validity"] = bits.broadcast_like(out["limit"]).astype(np.int8)
    out["validity"].attrs = {"flag_masks": np.array([1, 2, 4, 8], np.int8),
                             "flag_meanings": "self_contact stretch_beyond_fit "
                                              "under_one_turn chamber_closes",
                             "units": "1", "long_name": "validity flags"}
    out.attrs = dict(ds.attrs)
    return out


def test_snap_names_the_grid_point_and_says_when_between(ds):
    exact = explore.snap(ds, "radius", 15e-3)
    assert exact.exact and exact.value == pytest.approx(15e-3)
    between = explore.snap(ds, "radius", 16e-3)
    assert not between.exact and between.value == pytest.approx(15e-3)
    assert "between grid points" in between.note(ds) and "15 mm" in between.note(ds)
    with pytest.raises(InputError, match="not an axis"):
        explore.snap(ds, "colour", 1.0)


def _grid(p, name):
    """A payload's array of ``name`` as the cube's grid (model first where there is one)."""
    shape = ([len(p["models"])] if p["models"] else []) + p["sizes"]
    return np.asarray(p["data"][p["variables"].index(name)]).reshape(shape)


def test_the_page_carries_the_cube_in_display_units(ds):
    from nylonflex.explore.page import build_payload

    p = build_payload(ds)  # the numbers update.js draws every view from
    assert p["sizes"] == [ds.sizes[a] for a in AXES]  # a small cube: every design
    cube = ds.transpose(*AXES, ...)
    np.testing.assert_allclose(_grid(p, "tip_force_max"), cube["tip_force_max"].values,
                               rtol=1e-6)  # float32 on the page
    np.testing.assert_allclose(_grid(p, "pressure_max"), cube["pressure_max"].values / 1e3,
                               rtol=1e-6)  # kPa
    np.testing.assert_allclose(_grid(p, "bend_angle_max"),
                               np.degrees(cube["bend_angle_max"].values), rtol=1e-6)
    bend = p["curves"]["bend_angle"]
    assert bend["dims"] == ["radius", "wall_thickness", "length"]
    np.testing.assert_allclose(np.asarray(bend["values"]).reshape(9, 3, 2, 9),
                               np.degrees(ds["bend_angle"].transpose(
                                   "radius", "wall_thickness", "length", "pressure").values),
                               rtol=1e-6)
    np.testing.assert_allclose(bend["x"], ds["pressure"].values / 1e3)  # kPa
    np.testing.assert_array_equal(np.asarray(p["limit"]).reshape(p["sizes"]),
                                  cube["limit"].values)
    assert p["labels"]["wrap_angle"] == ["5 deg", "8 deg", "20 deg"]


def test_where_marks_the_designs_the_query_finds(ds):
    from nylonflex.explore.page import build_payload
    from nylonflex.query import parse_where, query_cube

    text = ["tip_force_max >= 0.5 N", "wall_thickness <= 4 mm"]
    p = build_payload(ds, parse_where(text))
    res = query_cube(ds, where=text, limit=1)
    assert p["rows"]["matching"] == int(p["match"].sum()) == res.matched > 0
    rows = p["rows"]["data"]
    assert min(rows["tip_force_max"]) >= 0.5 and max(rows["wall_thickness"]) <= 4
    assert p["rows"]["columns"][:5] == list(AXES) and "validity" in p["rows"]["columns"]
    # each row's grid indices (what a click on the row picks) name its own design
    i = {a: rows[f"i_{a}"][0] for a in AXES}
    assert rows["tip_force_max"][0] == pytest.approx(
        float(ds["tip_force_max"].isel(i)), rel=1e-6)
    with pytest.raises(InputError, match="unknown name 'colour'"):
        build_payload(ds, parse_where(["colour > 1"]))


def test_cli_where_is_parsed_by_the_query_parser(cube, tmp_path, capsys):
    out = tmp_path / "page.html"
    assert main(["explore", str(cube), "--html", str(out), "--where", "tip_force_max >= x"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--where" in err and not out.exists()
    assert main(["explore", str(cube), "--html", str(out), "--where",
                 "tip_force_max >= 0.5 N"]) == 0
    assert "designs of this page meet --where tip_force_max" in out.read_text()


def test_model_dimension_and_validity_flags_are_handled(ds):
    from nylonflex.explore.page import build_payload

    syn = synthetic(ds)
    assert explore.flag_meanings(syn)[0] == (1, "self_contact")
    p, base = build_payload(syn), build_payload(ds)
    assert p["models"] == ["paper", "coupled_muscle"]
    np.testing.assert_allclose(_grid(p, "tip_force_max")[1], 2 * _grid(base, "tip_force_max"))
    v = np.asarray(p["validity"]).reshape(2, *p["sizes"])
    assert v[0, :, 0, 0, 0, 0].tolist() == [4] * 7 + [5] * 2  # wall 2 mm; radius > 20 mm
    assert np.asarray(p["curves"]["tip_force"]["values"]).size == 2 * base["curves"][
        "tip_force"]["values"].size  # curves without a model dimension repeat per model
    with pytest.raises(InputError, match="model == nope"):
        build_payload(syn, ["model == nope"])


def test_one_document_for_the_served_page_and_the_file(ds):
    pytest.importorskip("bokeh")
    from bokeh.embed import file_html

    from nylonflex.explore.page import build_document, build_html

    served = file_html(build_document(synthetic(ds), served=True), "inline")
    saved = build_html(synthetic(ds))
    for text in (served, saved):  # one script, update.js, draws both from one state
        assert "model variant" in text and "const st = {v: Number(variable.value)" in text
    assert "Served page" in served and "Exported page" in saved


def test_a_long_name_edited_in_the_cube_shows_on_the_page(ds):
    # the page's labels are read from the variables' attrs (issue 28)
    pytest.importorskip("bokeh")
    from bokeh.models import Select

    from nylonflex.explore.page import build_document

    edited = ds.copy()
    edited["radius"].attrs["long_name"] = "inner radius"
    edited["tip_force_max"].attrs["long_name"] = "blocked force"
    doc = build_document(edited)
    fig = doc.select_one({"name": "nf-map-figure"})
    assert fig.xaxis[0].axis_label == "inner radius [mm]"
    assert ("radius", "inner radius [mm]") in doc.select_one({"name": "nf-map-x"}).options
    variable = doc.select_one({"type": Select, "name": "nf-variable"})
    assert any(text == "blocked force [N]" for _, text in variable.options)
    assert doc.select_one({"name": "nf-slider-radius"}).title == "inner radius"
    assert ds["radius"].attrs["long_name"] == "chamber radius"


def test_html_is_offline_and_holds_the_cube(ds, tmp_path):
    pytest.importorskip("bokeh")
    from nylonflex.explore.page import build_html

    text = build_html(synthetic(ds), source="cube.h5")
    assert not re.search(r"<script[^>]+src=|<link[^>]+href=\"?https?:", text)
    assert "every design of the cube" in text and "Grey cells hatched / are flagged" in text


def test_html_subset_is_bounded(ds, monkeypatch):
    from nylonflex.explore import page

    monkeypatch.setattr(page, "MAX_DESIGNS", 100)
    keep = page._subset(ds)
    assert math.prod(len(v) for v in keep.values()) <= 100
    assert all(len(keep[a]) >= 1 for a in AXES) and len(keep["radius"]) >= 3


def test_cli_html_writes_once_then_needs_overwrite(cube, tmp_path, capsys):
    out = tmp_path / "page.html"
    assert main(["explore", str(cube), "--html", str(out)]) == 0
    assert out.stat().st_size > 100_000
    out.write_text("mine")
    assert main(["explore", str(cube), "--html", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--overwrite" in err
    assert out.read_text() == "mine"
    assert main(["explore", str(cube), "--html", str(out), "--overwrite"]) == 0
    assert out.stat().st_size > 100_000


def test_cli_refuses_a_file_that_is_not_a_cube(tmp_path, capsys):
    bad = tmp_path / "notes.h5"
    bad.write_text("not hdf5")
    assert main(["explore", str(bad), "--html", str(tmp_path / "x.html")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a nylonflex cube" in err


def test_cli_refuses_a_port_in_use(cube, capsys):
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["explore", str(cube), "--port", str(port), "--no-browser"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"--port {port}: already in use" in err


# ---------------------------------------------------------------------------- issue 25
def test_validity_by_flag_name(ds):
    # the page names the flags the same way (update.js's flagtext; the browser test)
    syn = synthetic(ds)  # bits: 1 where radius > 20 mm, 4 where wall < 3 mm
    assert explore.validity_names(syn, 5) == "self contact, under one turn"
    assert explore.validity_names(syn, 0) == "valid"
    assert explore.validity_names(syn, float("nan")) == "unknown"


def test_offline_file_names_its_hover_colour_bar_and_validity(ds):
    pytest.importorskip("bokeh")
    from nylonflex.explore.page import build_html

    text = build_html(synthetic(ds), source="cube.h5")
    # the hover names the variable (it said "value", and "???" over the star marker)
    assert '"tooltips":[["maximum tip force [N]","@z{0.000}"]]' in text
    assert '["value","@z' not in text
    assert '"title":"maximum tip force [N]"' in text  # the colour bar
    assert 'nf-validity' in text and "flagtext" in text
    assert "colour scale and the panels' ranges are set by the unflagged designs" in text


def test_stand_in_materials_are_named(ds):
    note = explore.stand_in_note(ds)  # tc5005 and silver_nylon66: the default sets
    assert note.startswith("Stand-in materials: silicone tc5005: a stand-in")
    assert "nylon silver_nylon66:" in note and "proposals (tag P)" in note
    other = ds.copy()
    other.attrs = {k: v for k, v in ds.attrs.items()
                   if k not in ("silicone_parameters", "nylon_parameters")}
    assert explore.stand_in_note(other) == ""


def test_copy_as_config_sweeps_to_the_selected_designs_values(ds):
    import yaml

    import nylonflex as nf
    from nylonflex.config import parse_config

    at = {**AT, "radius": 12.5e-3, "wrap_angle": 20 * DEG}
    text = explore.design_config(ds, at)
    one = nf.run_sweep(parse_config(yaml.safe_load(text)))
    for name in ("tip_force_max", "bend_angle_max", "limit", "validity"):
        assert float(one[name].squeeze()) == float(ds[name].sel(at, method="nearest")), name
    assert "values: ['@radius@']" in explore.design_config(ds, at, placeholders=True)


def test_the_page_offers_the_config(ds):
    pytest.importorskip("bokeh")
    from nylonflex.explore.page import build_html

    text = build_html(ds, source="cube.h5")
    assert "copy as config" in text and "@radius@" in text


def _fidelity_beside(cube_path, ds):
    """A fidelity dataset as ``nylonflex verify`` writes it, for two designs of the cube."""
    import xarray as xr

    from nylonflex.fe.verify import fidelity_path

    n, levels = 2, [0.5, 1.0]
    fid = xr.Dataset(
        {"radius": ("design", [15e-3, 20e-3]), "wall_thickness": ("design", [2e-3, 6e-3]),
         "length": ("design", [90e-3, 90e-3]), "coil_index": ("design", [1.7, 1.1]),
         "wrap_angle": ("design", [8 * DEG, 8 * DEG]),
         "pressure": (("design", "level"), [[2e3, 4e3], [5e3, 10e3]]),
         "fe_bend_angle": (("design", "level"), [[0.3, 0.6], [0.4, np.nan]]),
         "ratio": (("model", "design", "level"), [[[0.61, 0.62], [0.63, np.nan]],
                                                  [[1.071, 1.072], [0.973, np.nan]]])},
        coords={"design": np.arange(n), "level": levels,
                "model": ["paper", "fe_calibrated"]}, attrs={"fe_mesh": "coarse"})
    path = fidelity_path(cube_path)
    fid.to_netcdf(path, engine="h5netcdf")
    return path


def test_the_page_lists_the_verified_designs_with_their_ratios(cube, ds, tmp_path):
    import shutil

    from nylonflex.explore.fidelity import fidelity_rows

    here = tmp_path / "cube.h5"
    shutil.copy(cube, here)
    path = _fidelity_beside(here, ds)
    out = tmp_path / "page.html"
    assert main(["explore", str(here), "--html", str(out)]) == 0
    text = out.read_text()
    assert "FE fidelity" in text and path.name in text
    # the summary line: per model, over the finite angles (3 of 4)
    assert "median 0.620 (0.610-0.630), 0 of 3 within 10 %" in text
    assert "median 1.071 (0.973-1.072), 3 of 3 within 10 %" in text
    import xarray as xr

    with xr.open_dataset(path, engine="h5netcdf") as fid:
        rows = fidelity_rows(ds, fid.load())
    assert rows["radius"] == [15.0, 15.0, 20.0, 20.0]  # mm, a row a design and level
    assert rows["pressure"] == [2.0, 4.0, 5.0, 10.0]  # kPa
    assert rows["ratio_fe_calibrated"][:3] == [1.071, 1.072, 0.973]
    assert math.isnan(rows["ratio_fe_calibrated"][3])


def test_a_page_without_a_fidelity_dataset_has_no_fidelity_part(cube, tmp_path):
    out = tmp_path / "page.html"
    assert main(["explore", str(cube), "--html", str(out)]) == 0
    assert "FE fidelity" not in out.read_text()


# ---------------------------------------------------------------------------- issue 46
def test_the_page_opens_on_a_valid_design_named_right(ds):
    # it opened on a flagged self-contacting design (15/2/90 mm, 443 deg) that it called
    # the paper's second worked example (7.5/2/70 mm, C 1.7, 8 deg; docs/model.md s. 8)
    from nylonflex.explore import first_design

    index, name = first_design(ds)
    point = ds.isel(index)
    assert name.startswith("the paper's second worked example (a 7.5 mm, t 2 mm, L 70 mm, "
                           "C 1.7")
    assert float(point["radius"]) == pytest.approx(7.5e-3)
    assert float(point["length"]) == pytest.approx(70e-3)
    assert float(point["validity"]) == 0
    # flagged there: never opened on; the first example instead (20/6/90 mm, C 1.1)
    flagged = ds.copy()
    v = flagged["validity"].load().copy()
    v[index] = 1
    flagged["validity"] = v
    index, name = first_design(flagged)
    assert name.startswith("the paper's first worked example") and \
        float(flagged["validity"].isel(index)) == 0
    # a cube without either example: a valid design, described by its values
    other = ds.isel(radius=[0, 2, 4, 6, 8])  # 5, 10, 15, 20, 25 mm
    other = other.isel(wall_thickness=[0, 1])  # 2, 4 mm: not the first example's 6 mm
    other = other.sel(radius=[5e-3, 10e-3, 15e-3, 25e-3], method="nearest")
    index, name = first_design(other)
    assert name.startswith("a valid design: a ") and "does not hold the paper's examples" \
        in name
    assert float(other["validity"].isel(index)) == 0


def test_the_page_of_an_incomplete_cube_says_so(ds):
    pytest.importorskip("bokeh")
    from nylonflex.explore.page import build_html

    part = ds.copy()
    part.attrs = {**ds.attrs, "complete": 0}
    done = part["slab_done"].load().copy()
    done[5:] = 0
    part["slab_done"] = done
    text = build_html(part, source="cube.h5")
    assert "incomplete: 5 of 9 slabs" in text and "nf-incomplete" in text
    assert "nf-incomplete" not in build_html(ds, source="cube.h5")
