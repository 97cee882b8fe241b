"""Issue 45: ``fidelity: spread``, the range of the headline variables over model variants
(docs/model.md s. 22).

The range is checked against separate one-model sweeps of the same grid (an independent
path: each runs the kernel on its own), the cube's own values against a sweep without a
spread (bit for bit), and the range through the cube file, a killed and resumed sweep,
query, info, the charts and the explorer.
"""

import copy
import json
import signal

import numpy as np
import pytest
import xarray as xr
from helpers import stable, write_config
from killing import kill_after_slabs

import nylonflex as nf
from nylonflex.cli import main
from nylonflex.config import load_config, parse_config
from nylonflex.query.format import cell_text
from nylonflex.storage import open_cube
from nylonflex.units import InputError
from nylonflex.variables import MODELS, SPREAD, SPREAD_OF, label, spread_name, validate

# incompressible_wall closes some chambers (validity bit 8): flags that differ by variant
VARIANTS = ["paper", "lateral_pressure", "incompressible_wall"]
SMALL = {
    "name": "spread",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [1, 2, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
}


def _with(**changes):
    raw = copy.deepcopy(SMALL)
    raw.update(changes)
    return raw


@pytest.fixture(scope="module")
def spread_cube():
    return nf.run_sweep(parse_config(_with(fidelity={"spread": VARIANTS})))


@pytest.fixture(scope="module")
def singles():
    return {m: nf.run_sweep(parse_config(_with(model=m))) for m in VARIANTS}


def test_the_range_is_min_and_max_over_one_model_sweeps(spread_cube, singles):
    for name in SPREAD_OF:
        stack = np.stack([singles[m][name].values for m in VARIANTS])
        np.testing.assert_array_equal(spread_cube[spread_name(name, "lo")].values,
                                      stack.min(axis=0), err_msg=name)
        np.testing.assert_array_equal(spread_cube[spread_name(name, "hi")].values,
                                      stack.max(axis=0), err_msg=name)
    ored = np.bitwise_or.reduce(np.stack([singles[m]["validity"].values for m in VARIANTS]))
    np.testing.assert_array_equal(spread_cube["validity_model_any"].values, ored)
    # the variants disagree somewhere, and incompressible_wall's flag (8) is in the OR only
    width = spread_cube["tip_force_max_model_hi"] - spread_cube["tip_force_max_model_lo"]
    assert float(width.max()) > 0
    assert (spread_cube["validity_model_any"].values & 8).any()
    assert not (spread_cube["validity"].values & 8).any()


def test_the_cube_keeps_its_own_models_values_bit_for_bit(spread_cube, singles):
    plain = singles["paper"]
    rest = spread_cube.drop_vars(list(SPREAD))
    assert set(rest.data_vars) == set(plain.data_vars)
    for name in plain.variables:
        assert rest[name].values.tobytes() == plain[name].values.tobytes(), name
    # a config without fidelity resolves, hashes and stores as before: no spread anywhere
    cfg = parse_config(SMALL)
    assert cfg.spread == () and "fidelity" not in cfg.text
    assert "model_spread" not in plain.attrs
    assert not set(SPREAD) & set(plain.variables)


def test_spread_over_a_model_list_and_over_every_variant():
    ds = nf.run_sweep(parse_config(_with(model=VARIANTS[:2], fidelity="spread")))
    assert list(ds["model"].values) == VARIANTS[:2]
    np.testing.assert_array_equal(ds["bend_angle_max_model_hi"].values,
                                  ds["bend_angle_max"].max("model").values)
    np.testing.assert_array_equal(ds["range_fraction_model_lo"].values,
                                  ds["range_fraction"].min("model").values)
    # one model and 'spread': every variant there is (docs/model.md s. 16)
    assert parse_config(_with(fidelity="spread")).spread == MODELS


def test_set_fidelity_on_the_command_line(tmp_path):
    path = write_config(tmp_path, SMALL)
    assert load_config(path, ["fidelity=spread"]).spread == MODELS
    cfg = load_config(path, ["fidelity.spread=[paper, fe_calibrated]"])
    assert cfg.spread == ("paper", "fe_calibrated")


def test_round_trip_through_the_cube_file_with_units(tmp_path, spread_cube):
    cfg = parse_config(_with(fidelity={"spread": VARIANTS}))
    disk = nf.run_sweep(cfg, tmp_path / "cube.h5")
    xr.testing.assert_equal(spread_cube, disk.load())
    validate(disk)
    assert disk.attrs["model_spread"] == " ".join(VARIANTS)
    for name in SPREAD_OF:
        base = disk[name].attrs["units"]
        for side in ("lo", "hi"):
            attrs = disk[spread_name(name, side)].attrs
            assert attrs["units"] == base and "docs/model.md s. 22" in attrs["description"]
    assert disk["validity_model_any"].attrs["flag_meanings"].split()[3] == "chamber_closes"
    assert label(disk["tip_force_max_model_lo"]) == "maximum tip force, lowest model [N]"
    assert label(disk["bend_angle_max_model_hi"]) == "maximum bend angle, highest model [deg]"
    # info --config rebuilds a config that sweeps to the same design space
    from nylonflex.engine.provenance import runnable_config

    again = parse_config(__import__("yaml").safe_load(runnable_config(disk.attrs)))
    assert again.spread == tuple(VARIANTS) and again.sha256 == cfg.sha256


@pytest.mark.parametrize("fidelity, match", [
    ({"spread": ["paper", "bogus"]}, r"^fidelity\.spread\[1\]: must be one of paper, "),
    ({"spread": ["paper"]}, r"^fidelity\.spread: needs at least two model variants"),
    ({"spread": ["paper", "paper"]}, r"^fidelity\.spread: each variant once"),
    ({"spread": ["lateral_pressure", "fe_calibrated"]},
     r"^fidelity\.spread: must hold the cube's model 'paper'"),
    ("wide", r"^fidelity: must be 'spread' or \{spread: \[variant, \.\.\.\]\}.*, got 'wide'"),
    ({"spread": "paper"}, r"^fidelity: must be 'spread' or \{spread: "),
    ({"spread": ["paper", "lateral_pressure"], "wide": 1}, r"^fidelity: unknown key 'wide'; accepted: spread"),
])
def test_bad_spreads_exit_2_with_one_line(tmp_path, capsys, fidelity, match):
    with pytest.raises(InputError, match=match):
        parse_config(_with(fidelity=fidelity))
    path = write_config(tmp_path, _with(fidelity=fidelity))
    assert main(["sweep", str(path), "--out", str(tmp_path / "c.h5"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "fidelity" in err, err
    assert not (tmp_path / "c.h5").exists()


# four slabs of four radii at 1 MB: a kill after two leaves a journal to resume
RESUMABLE = _with(name="spread_resume", slab_megabytes=1, fidelity={"spread": VARIANTS},
                  grid={"radius": {"start": 5, "stop": 25, "num": 16, "units": "mm"},
                        "wall_thickness": {"start": 1, "stop": 6, "num": 20, "units": "mm"},
                        "length": {"values": [60, 70, 90, 120], "units": "mm"},
                        "coil_index": {"values": [1.1, 1.7]},
                        "wrap_angle": {"values": [3, 5, 8, 10, 12, 15, 20, 25],
                                       "units": "deg"}})


@pytest.mark.slow
def test_a_killed_sweep_resumes_to_the_same_range(tmp_path):
    from nylonflex.engine.grid import plan_slabs

    assert len(plan_slabs(parse_config(RESUMABLE))[0]) == 4
    path = write_config(tmp_path, RESUMABLE)
    out = tmp_path / "run" / "cube.h5"
    cmd = ["sweep", str(path), "--out", str(out), "--quiet", "--no-charts"]
    assert kill_after_slabs(cmd, 2, signal.SIGKILL) != 0
    assert not out.exists()
    assert main([*cmd, "--resume"]) == 0
    resumed = open_cube(out)
    assert resumed.attrs["resumed_slabs"] == 2
    whole = nf.run_sweep(parse_config(RESUMABLE), tmp_path / "whole.h5")
    xr.testing.assert_identical(stable(resumed), stable(whole))
    assert float(resumed["tip_force_max_model_hi"].max()) > 0


@pytest.fixture(scope="module")
def spread_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("spread") / "cube.h5"
    nf.run_sweep(parse_config(_with(fidelity={"spread": VARIANTS})), path).close()
    return path


EX1 = "radius=20,wall_thickness=6,length=90,coil_index=1.1,wrap_angle=8"


def test_query_shows_the_range_beside_each_value(spread_file, capsys):
    assert main(["query", str(spread_file), "--at", EX1]) == 0
    out = capsys.readouterr().out
    with open_cube(spread_file) as ds:
        at = ds.sel(radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
                    wrap_angle=np.radians(8), method="nearest")
        lo, hi = float(at["tip_force_max_model_lo"]), float(at["tip_force_max_model_hi"])
    line = next(x for x in out.splitlines() if x.strip().startswith("tip_force_max"))
    shown = [cell_text(spread_name("tip_force_max", side), x) for side, x in
             (("lo", lo), ("hi", hi))]
    assert line.endswith(f"(models {shown[0]} .. {shown[1]} N)"), line
    assert lo < hi
    assert "validity" in out and "any model:" in out
    # JSON: the range in SI beside the value
    assert main(["query", str(spread_file), "--at", EX1, "--format", "json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["designs"][0]["tip_force_max_model_hi"] == pytest.approx(hi, rel=1e-12)
    assert doc["units"]["bend_angle_max_model_lo"] == "rad"
    # a table's default columns hold the range; --where tests it
    assert main(["query", str(spread_file), "--where", "tip_force_max_model_hi >= 1 N",
                 "--limit", "3"]) == 0
    assert "model_" in capsys.readouterr().out


def test_query_off_the_grid_takes_the_range_from_every_variant(spread_file, capsys):
    design = dict(radius=21e-3, wall_thickness=5e-3, length=80e-3, coil_index=1.3,
                  wrap_angle=np.radians(6.5))
    with open_cube(spread_file) as ds:
        res = nf.query.query_cube(ds, at=design)
    values = [nf.design_limits(**design, model=m) for m in VARIANTS]
    for name in SPREAD_OF:
        assert res.data[spread_name(name, "lo")][0] == pytest.approx(
            min(v[name] for v in values), rel=1e-9)
        assert res.data[spread_name(name, "hi")][0] == pytest.approx(
            max(v[name] for v in values), rel=1e-9)
    assert res.data["tip_force_max"][0] == pytest.approx(values[0]["tip_force_max"], rel=1e-9)


def test_a_cube_without_a_spread_says_how_to_get_one(tmp_path, capsys):
    path = tmp_path / "plain.h5"
    nf.run_sweep(parse_config(SMALL), path).close()
    assert main(["query", str(path), "--columns", "tip_force_max_model_lo"]) == 2
    err = capsys.readouterr().err
    assert "fidelity: spread" in err and len(err.strip().splitlines()) == 1


def test_info_names_the_spread_and_its_variants(spread_file, capsys):
    assert main(["info", str(spread_file)]) == 0
    out = capsys.readouterr().out
    line = next(x for x in out.splitlines() if x.startswith("spread"))
    assert "over 3 model variants" in line and ", ".join(VARIANTS) in line


def test_fig12_draws_the_range_and_names_the_examples(spread_cube):
    from matplotlib.collections import LineCollection
    from matplotlib.text import Text

    from nylonflex.charts.fig12 import fig12b, fig12c

    def bars(fig):
        return sum(isinstance(c, LineCollection) for ax in fig.axes for c in ax.collections)

    plain = spread_cube.drop_vars(list(SPREAD))
    for draw in (fig12b, fig12c):
        with_band, without = draw(spread_cube), draw(plain)
        assert bars(with_band) > bars(without), draw.__name__
        texts = " ".join(t.get_text() for t in with_band.findobj(Text))
        assert "over 3 model variants" in texts, draw.__name__
        assert "(models " in texts  # the paper's example names its range
        assert ", ".join(VARIANTS) in texts.replace("\n", " ")


def test_the_explorer_pairs_each_variable_with_its_range(spread_cube):
    from nylonflex.explore.model_spread import spread_args
    from nylonflex.explore.page import build_payload

    p = build_payload(spread_cube)
    names = p["variables"]
    assert "validity_model_any" not in names
    args = spread_args(spread_cube, names)
    j = names.index("tip_force_max")
    lo, hi = args["bands"][j]
    assert (names[lo], names[hi]) == ("tip_force_max_model_lo", "tip_force_max_model_hi")
    assert args["bands"][names.index("nylon_use")] is None
    assert ", ".join(VARIANTS) in args["spreadnote"]
    assert p["validity_any"] is not None and p["validity_any"].size == p["data"][j].size


def test_each_cooling_slice_of_the_range_is_its_own_sweep():
    # a supply puts the headline variables on the cooling dimension: so is their range
    raw = _with(fidelity={"spread": ["paper", "incompressible_wall"]},
                supply={"voltage": 12}, cooling=["still_air", "still_water"])
    ds = nf.run_sweep(parse_config(raw))
    for name in SPREAD:
        assert ds[name].dims[-1] == "cooling", name
    for label_, one_set in zip(["still_air", "still_water"], raw["cooling"]):
        one = nf.run_sweep(parse_config({**raw, "cooling": one_set}))
        for name in SPREAD:
            assert ds[name].sel(cooling=label_).values.tobytes() == \
                one[name].values.tobytes(), name


@pytest.mark.slow
def test_the_explorer_read_out_shows_the_range_in_a_browser(spread_file, tmp_path):
    import os

    if not os.path.exists("/usr/bin/chromium"):
        pytest.skip("no Chromium at /usr/bin/chromium (.ci/run installs it)")
    sync_api = pytest.importorskip("playwright.sync_api")
    pytest.importorskip("bokeh")
    from nylonflex.explore.page import DEFAULT_DESIGN
    from nylonflex.variables import to_display

    page_file = tmp_path / "page.html"
    assert main(["explore", str(spread_file), "--html", str(page_file)]) == 0
    with open_cube(spread_file) as ds:
        at = ds.sel(DEFAULT_DESIGN, method="nearest")
        want = [float(to_display("tip_force_max", at[spread_name("tip_force_max", s)]))
                for s in ("lo", "hi")]
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path="/usr/bin/chromium",
                                    args=["--headless", "--no-sandbox", "--disable-gpu"])
        try:
            page = browser.new_page(viewport={"width": 1300, "height": 1000})
            page.goto(page_file.as_uri())
            page.wait_for_selector("#nf-spread", timeout=60_000)
            shown = page.locator("#nf-spread")
            got = [float(shown.get_attribute(f"data-{s}")) for s in ("lo", "hi")]
            assert got == pytest.approx(want, rel=1e-6)  # float32 on the page
            assert ", ".join(VARIANTS) in shown.inner_text()
            assert page.locator("#nf-validity-any").count() == 1
        finally:
            browser.close()
