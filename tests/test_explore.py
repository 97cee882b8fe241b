"""``nylonflex explore``: the slices the page shows, the offline file and the refusals.

Expected values are the cube's own grid values (``ds.sel``): the explorer never
interpolates. The browser tests are in ``test_explore_browser.py``.
"""

import math
import re

import numpy as np
import pytest
from conftest import write_cube

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


def test_map_slice_is_the_cube_in_display_units(ds):
    m = explore.map_slice(ds, "tip_force_max", "radius", "wall_thickness", AT)
    want = ds["tip_force_max"].sel(length=AT["length"], coil_index=AT["coil_index"],
                                   wrap_angle=AT["wrap_angle"], method="nearest")
    np.testing.assert_allclose(m["z"], want.transpose("wall_thickness", "radius").values)
    np.testing.assert_allclose(m["x"], ds["radius"].values * 1e3)  # mm
    assert m["limit"].shape == m["z"].shape == m["validity"].shape  # cubes carry validity
    b = explore.map_slice(ds, "bend_angle_max", "coil_index", "wrap_angle", AT)
    assert b["z"].shape == (3, 2)
    np.testing.assert_allclose(b["y"], [5, 8, 20])  # deg
    with pytest.raises(InputError, match="two different"):
        explore.map_slice(ds, "tip_force_max", "radius", "radius", AT)


def test_design_table_and_curves_of_one_grid_design(ds):
    rows = {r["name"]: r for r in explore.design_table(ds, AT)}
    point = ds.sel(AT, method="nearest")
    assert rows["tip_force_max"]["value"] == pytest.approx(float(point["tip_force_max"]))
    assert rows["pressure_max"]["value"] == pytest.approx(float(point["pressure_max"]) / 1e3)
    assert rows["pressure_max"]["unit"] == "kPa"
    assert rows["bend_angle_max"]["value"] == pytest.approx(
        math.degrees(float(point["bend_angle_max"])))
    curves = explore.design_curves(ds, AT)
    np.testing.assert_allclose(curves["tip_force"][1], point["tip_force"].values)
    np.testing.assert_allclose(curves["bend_angle"][0], ds["pressure"].values / 1e3)
    assert curves["nylon_force_limit"] == pytest.approx(float(point["nylon_force_limit"]))


def test_fig12_lines_mark_strength_limited_designs(ds):
    lines = explore.fig12_lines(ds, "torque_max", AT)
    assert set(lines["lines"]) == {1.1, 1.7}
    values, strong = lines["lines"][1.7]
    cut = ds[["torque_max", "limit"]].sel(wall_thickness=AT["wall_thickness"],
                                          length=AT["length"], coil_index=1.7,
                                          wrap_angle=AT["wrap_angle"], method="nearest")
    np.testing.assert_allclose(values, cut["torque_max"].values * 1e3)  # N mm
    np.testing.assert_array_equal(strong, cut["limit"].values == 1)


def test_model_dimension_and_validity_flags_are_handled(ds):
    syn = synthetic(ds)
    assert explore.flag_meanings(syn)[0] == (1, "self_contact")
    at = {**AT, "model": "coupled_muscle"}
    m = explore.map_slice(syn, "tip_force_max", "radius", "wall_thickness", at)
    base = explore.map_slice(ds, "tip_force_max", "radius", "wall_thickness", AT)
    np.testing.assert_allclose(m["z"], 2 * base["z"])
    assert m["validity"][0].tolist() == [4] * 7 + [5] * 2  # wall 2 mm; radius > 20 mm
    rows = {r["name"]: r["value"] for r in explore.design_table(syn, at)}
    assert rows["tip_force_max"] == pytest.approx(
        2 * float(ds["tip_force_max"].sel(AT, method="nearest")))
    with pytest.raises(InputError, match="model: 'nope'"):
        explore.design_table(syn, {**AT, "model": "nope"})


def test_served_page_builds_with_model_and_flags(ds):
    pytest.importorskip("panel")
    from nylonflex.explore_page import build_page

    page, states = build_page(synthetic(ds))
    assert states == {}
    text = str(page)
    assert "model variant" in text


def test_html_is_offline_and_holds_the_cube(ds, tmp_path):
    pytest.importorskip("bokeh")
    from nylonflex.explore_html import build_html

    text = build_html(synthetic(ds), source="cube.h5")
    assert not re.search(r"<script[^>]+src=|<link[^>]+href=\"?https?:", text)
    assert "every design of the cube" in text and "outlined in orange" in text


def test_html_subset_is_bounded(ds, monkeypatch):
    from nylonflex import explore_html

    monkeypatch.setattr(explore_html, "MAX_DESIGNS", 100)
    keep = explore_html._subset(ds)
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
def test_validity_by_flag_name_in_the_served_readout(ds):
    pytest.importorskip("panel")
    from nylonflex.explore_page import _readout_html

    syn = synthetic(ds)  # bits: 1 where radius > 20 mm, 4 where wall < 3 mm
    assert explore.validity_names(syn, 5) == "self contact, under one turn"
    assert explore.validity_names(syn, 0) == "valid"
    assert explore.validity_names(syn, float("nan")) == "unknown"
    text = _readout_html(syn, "tip_force_max", {**AT, "model": "paper"}, [])
    assert 'id="nf-validity" data-value="4"' in text and "under one turn" in text
    clean = _readout_html(syn, "tip_force_max", {**AT, "wall_thickness": 4e-3,
                                                 "model": "paper"}, [])
    assert "validity: <b>valid</b>" in clean


def test_colour_scale_is_set_by_the_clean_designs():
    z = np.array([[1.0, 2.0, 50.0], [3.0, np.nan, 4.0]])
    bits = np.array([[0, 0, 1], [0, 0, 0]])
    assert explore.colour_range(z, bits) == (1.0, 4.0)  # the flagged 50 does not set it
    assert explore.colour_range(z) == (1.0, 50.0)
    assert explore.colour_range(z, np.ones_like(bits)) == (1.0, 50.0)  # none clean: all


def test_offline_file_names_its_hover_colour_bar_and_validity(ds):
    pytest.importorskip("bokeh")
    from nylonflex.explore_html import build_html

    text = build_html(synthetic(ds), source="cube.h5")
    # the hover names the variable (it said "value", and "???" over the star marker)
    assert '"tooltips":[["maximum tip force [N]","@z{0.000}"]]' in text
    assert '["value","@z' not in text
    assert '"title":"maximum tip force [N]"' in text  # the colour bar
    assert 'nf-validity' in text and "flagtext" in text
    assert "colour scale is set by the unflagged designs" in text


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


def test_both_pages_offer_the_config(ds):
    pytest.importorskip("bokeh")
    pytest.importorskip("panel")
    from nylonflex.explore_html import build_html
    from nylonflex.explore_page import _readout_html

    assert 'id="nf-config"' in _readout_html(ds, "tip_force_max", AT, [])
    text = build_html(ds, source="cube.h5")
    assert "copy as config" in text and "@radius@" in text
