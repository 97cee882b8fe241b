"""Cooling as a sweep axis (issue 29): ``cooling: [set, set, ...]`` gives the cube a string
``cooling`` dimension on the variables the heat loss moves (docs/model.md s. 9, 15)."""

import copy

import numpy as np
import pytest

import nylonflex as nf
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.units import InputError
from nylonflex.variables import AXES, DESIGN, THERMAL

from helpers import write_config, write_cube

SMALL = {
    "name": "coolings",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 3, "units": "mm"},
        "wall_thickness": {"values": [1, 3], "units": "mm"},
        "length": {"values": [70], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 4},
               "pressure": {"start": 0, "stop": 40, "num": 3, "units": "kPa"}},
    "supply": {"voltage": 12},
    "cooling": ["still_air", {"set": "forced_air", "speed": 5}, "still_water"],
}
LABELS = ["still_air", "forced_air 5 m/s", "still_water"]


def _with(**changes):
    raw = copy.deepcopy(SMALL)
    for key, value in changes.items():
        if value is None:
            raw.pop(key, None)
        else:
            raw[key] = value
    return raw


@pytest.mark.parametrize("models", [["paper"], ["paper", "lateral_pressure"]])
def test_each_cooling_slice_is_its_own_sweep_bit_for_bit(models):
    ds = nf.run_sweep(parse_config(_with(model=models)))
    assert [str(c) for c in ds["cooling"].values] == LABELS
    for label, one_set in zip(LABELS, SMALL["cooling"]):
        one = nf.run_sweep(parse_config(_with(model=models, cooling=one_set)))
        assert "cooling" not in one.dims
        for name in one.data_vars:
            got = ds[name].sel(cooling=label) if "cooling" in ds[name].dims else ds[name]
            assert got.dims == one[name].dims, name
            assert got.values.tobytes() == one[name].values.tobytes(), name
    # water cools fastest: the cooling time falls from still air to forced air to water
    t = ds["cooling_time"].isel(model=0) if "model" in ds["cooling_time"].dims else \
        ds["cooling_time"]
    med = [float(t.sel(cooling=c).median()) for c in LABELS]
    assert med[0] > med[1] > med[2] > 0


def test_which_variables_gain_the_cooling_dimension():
    with_supply = nf.run_sweep(parse_config(SMALL))
    without = nf.run_sweep(parse_config(_with(supply=None)))
    for name, v in DESIGN.items():
        if not v.by_model:  # muscle_length, resistance: geometry and the thread alone
            assert "cooling" not in with_supply[name].dims, name
            continue
        assert with_supply[name].dims == (*AXES, "cooling"), name
        if name in without:
            assert ("cooling" in without[name].dims) == (name in THERMAL), name
    for name in ("nylon_force", "bend_angle", "tip_force", "stroke_max"):
        assert "cooling" not in with_supply[name].dims, name
    # without a supply the rest is the same for every set: one copy of it
    one = nf.run_sweep(parse_config(_with(supply=None, cooling="still_water")))
    assert without["tip_force_max"].values.tobytes() == one["tip_force_max"].values.tobytes()


@pytest.mark.parametrize("cooling, match", [
    ([], r"^cooling: needs at least one cooling set"),
    (["still_air", "still_air"], r"^cooling\[1\]: the same set as cooling\[0\] \(still_air\)"),
    (["still_air", "snow"], r"^cooling\[1\]: must be one of still_air"),
    (["still_air", {"set": "forced_air", "speed": -1}], r"^cooling\[1\]\.speed: must be"),
])
def test_bad_cooling_lists_are_refused_naming_the_entry(cooling, match):
    with pytest.raises(InputError, match=match):
        parse_config(_with(cooling=cooling))


def test_a_list_of_one_set_is_that_set():
    one = parse_config(_with(cooling=["still_water"]))
    assert one.coolings == () and one.cooling.name == "still_water"
    assert one.sha256 == parse_config(_with(cooling="still_water")).sha256


def test_several_sets_with_uncertainty_are_refused():
    raw = _with(uncertainty={"samples": 8, "seed": 1,
                             "parameters": {"silicone.mu": {"rel_sd": 0.1}}})
    with pytest.raises(InputError, match=r"^cooling: a sweep with uncertainty, requirements "
                                         r"or tracking takes one cooling set"):
        parse_config(raw)


def test_query_names_each_rows_cooling_set(tmp_path, capsys):
    cube = write_cube(tmp_path, _with(model=["paper", "lateral_pressure"]))
    at = "radius=15mm,wall_thickness=1mm,length=70mm,coil_index=1.1,wrap_angle=5deg"
    assert main(["query", str(cube), "--at", at, "--columns", "cycle_rate"]) == 0
    out = capsys.readouterr().out
    lines = [ln for ln in out.splitlines() if ln.startswith(("paper", "lateral"))]
    assert len(lines) == 6 and all(c in out for c in LABELS)
    assert main(["query", str(cube), "--where", "cooling == forced_air 5 m/s",
                 "--where", "model == paper", "--where", "cycle_rate >= 0 Hz",
                 "--format", "json", "--columns", "cycle_rate", "--limit", "all"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    assert doc["matching"] == 3 * 2 * 1 * 2 * 2  # one model, one cooling set
    ds = nf.open_cube(cube)
    want = ds["cycle_rate"].sel(model="paper", cooling="forced_air 5 m/s").values.reshape(-1)
    got = [row["cycle_rate"] for row in doc["designs"]]
    np.testing.assert_array_equal(np.sort(got), np.sort(want))
    assert main(["query", str(cube), "--where", "cooling == water"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--where cooling: this cube has still_air" in err[0]
    assert main(["query", str(cube), "--at", at.replace("15mm", "16mm")]) == 2
    assert "several" in capsys.readouterr().err


def test_charts_are_drawn_once_a_cooling_set(tmp_path):
    cube = write_cube(tmp_path, SMALL)
    out = tmp_path / "charts"
    assert main(["chart", str(cube), "--figure", "cycle_rate_map", "--out", str(out),
                 "--quiet"]) == 0
    assert sorted(p.name for p in out.glob("*.png")) == [
        "cycle_rate_map_forced_air_5mps.png", "cycle_rate_map_still_air.png",
        "cycle_rate_map_still_water.png"]


def test_info_lists_the_cooling_sets(tmp_path, capsys):
    cube = write_cube(tmp_path, SMALL)
    assert main(["info", str(cube)]) == 0
    out = capsys.readouterr().out
    assert "cooling   still_air, forced_air 5 m/s, still_water" in out
    assert "(counted over every cooling set)" in out


def test_design_and_explore_ask_for_one_cooling_set(tmp_path, capsys):
    cube = write_cube(tmp_path, SMALL)
    spec = write_config(tmp_path, {"name": "d", "cube": str(cube),
                                   "objectives": [{"max": "tip_force_max"}]}, "spec.yaml")
    assert main(["design", str(spec)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "holds 3 cooling sets" in err[0]
    pytest.importorskip("bokeh")
    page = tmp_path / "p.html"
    assert main(["explore", str(cube), "--html", str(page)]) == 2
    assert "--cooling: this cube holds 3 cooling sets" in capsys.readouterr().err
    assert main(["explore", str(cube), "--html", str(page), "--cooling", "still_water"]) == 0
    assert "(cooling: still_water)" in page.read_text()


def test_a_speed_typed_with_its_unit_is_read_as_m_per_s():
    # configs take units (docs/interface.md): "5 m/s" is 5, a wrong unit names the field
    typed = parse_config(_with(cooling=["still_air", {"set": "forced_air", "speed": "5 m/s"}]))
    assert [c.label for c in typed.coolings] == ["still_air", "forced_air 5 m/s"]
    bare = parse_config(_with(cooling=["still_air", {"set": "forced_air", "speed": 5}]))
    assert typed.sha256 == bare.sha256
    one = parse_config(_with(cooling={"set": "forced_air", "speed": "5 m/s"}))
    assert one.cooling.speed == 5.0
    with pytest.raises(InputError, match=r"^cooling\[1\]\.speed: unknown unit 'km'"):
        parse_config(_with(cooling=["still_air", {"set": "forced_air", "speed": "5 km"}]))
    from nylonflex.sim import parse_sim_config
    from nylonflex.files.safe_yaml import read_yaml

    sim = parse_sim_config({**read_yaml("configs/control.yaml"),
                            "cooling": {"set": "forced_air", "speed": "5 m/s"}})
    assert sim.actuators[0].cooling.speed == 5.0
