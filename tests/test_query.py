"""``nylonflex query``: grid points, interpolation, filters, formats and refusals.

Expected numbers come from docs/model.md section 8 (the paper's worked examples, 1.20 N and
0.150 N) and from :func:`nylonflex.design_limits` (the exact value at any design).
"""

import contextlib
import csv
import io
import json
import re

import h5py
import numpy as np
import pytest
from conftest import DEG, EXAMPLE_1, EXAMPLE_2
from helpers import write_cube

import nylonflex as nf
from nylonflex import query
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.storage import open_cube
from nylonflex.sweep.conductor import run_sweep
from nylonflex.units import InputError

AT_2 = "radius=7.5mm,wall_thickness=2mm,length=70mm,coil_index=1.7,wrap_angle=8deg"

SMALL = {
    "name": "small",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},  # 2.5 mm steps
        "wall_thickness": {"values": [2, 4, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 11},
               "pressure": {"start": 0, "stop": 40, "num": 9, "units": "kPa"}},
}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("query"), SMALL)


@pytest.fixture(scope="module")
def ds(cube):
    ds = open_cube(cube)
    yield ds
    ds.close()


def run(capsys, *argv):
    rc = main(["query", *map(str, argv)])
    out, err = capsys.readouterr()
    return rc, out, err


# ---------------------------------------------------------------------------- --at
def test_paper_example_2_prints_0150_newton(cube, capsys):
    # docs/model.md s. 8: (7.5 mm, 2 mm, 70 mm, C 1.7, psi 8 deg) gives 0.150 N, stroke-limited
    rc, out, _ = run(capsys, cube, "--at", AT_2)
    assert rc == 0
    assert "grid point" in out
    assert "tip_force_max    0.150 N" in out
    assert "stroke-limited" in out


def test_paper_example_1_bare_numbers_mean_mm_and_deg(cube, capsys):
    # docs/model.md s. 8: (20 mm, 6 mm, 90 mm, C 1.1) gives 1.20 N with a full range of motion
    rc, out, _ = run(capsys, cube, "--at",
                     "radius=20,wall_thickness=6,length=90,coil_index=1.1,wrap_angle=8")
    assert rc == 0
    assert "1.20 N" in out and "full range of motion" in out


def test_grid_point_is_the_stored_value(ds):
    res = query.query_cube(ds, at=EXAMPLE_2)
    assert res.point == "grid point" and res.interpolated == [] and len(res) == 1
    stored = ds["tip_force_max"].sel(EXAMPLE_2, method="nearest").item()
    assert res.data["tip_force_max"][0] == stored


def test_interpolated_radius_within_1_percent_of_design_limits(tmp_path):
    # the radius spacing of configs/fig12.yaml (0.5 mm) around the paper's example 2
    fine = dict(SMALL, grid={"radius": {"start": 5, "stop": 10, "num": 11, "units": "mm"},
                             "wall_thickness": {"values": [2], "units": "mm"},
                             "length": {"values": [70], "units": "mm"},
                             "coil_index": {"values": [1.7]},
                             "wrap_angle": {"values": [8], "units": "deg"}})
    ds = run_sweep(parse_config(fine), out=tmp_path / "fine.h5")
    at = dict(EXAMPLE_2, radius=7.8e-3)  # between the 7.5 and 8 mm grid radii
    res = query.query_cube(ds, at=at, interpolate=True)
    ds.close()
    assert res.point == "interpolated" and res.interpolated == ["radius"]
    exact = nf.design_limits(**at)
    for name in ("tip_force_max", "torque_max", "bend_angle_max", "pressure_max"):
        assert res.data[name][0] == pytest.approx(exact[name], rel=0.01), name
    assert res.data["limit"][0] == exact["limit"] == 0


def test_length_interpolation_is_exact(ds):
    # F* = M*/L and theta* = kappa L (docs/model.md s. 8): exact along L, whatever the spacing
    at = dict(EXAMPLE_1, length=77e-3)
    res = query.query_cube(ds, at=at, interpolate=True)
    exact = nf.design_limits(**at)
    for name in ("tip_force_max", "bend_angle_max", "torque_max"):
        assert res.data[name][0] == pytest.approx(exact[name], rel=1e-9), name


def test_limit_between_disagreeing_grid_points_is_unknown(ds):
    lim = ds["limit"].sel(wall_thickness=2e-3, length=70e-3, coil_index=1.7,
                          wrap_angle=20 * DEG).values
    i = int(np.argmax(lim[1:] != lim[:-1]))  # last radius before the limit flips
    a = ds["radius"].values
    at = dict(EXAMPLE_2, wrap_angle=20 * DEG, radius=0.5 * (a[i] + a[i + 1]))
    # the slab reader leaves it unknown; the query then takes it from the exact model
    at_loc = {n: query.locate(ds, n, v) for n, v in at.items()}
    assert np.isnan(query.slab_rows(ds, at_loc, i, i + 2)["limit"][0])
    res = query.query_cube(ds, at=at, interpolate=True)
    assert res.data["limit"][0] == nf.design_limits(**at)["limit"]
    assert "boundary" not in query.format_table(res)


def test_partial_at_lists_every_value_of_the_free_axes(ds):
    res = query.query_cube(ds, at={"radius": 7.5e-3, "coil_index": 1.7})
    assert len(res) == 3 * 2 * 3  # wall x length x wrap angle
    assert np.all(res.data["radius"] == pytest.approx(7.5e-3))
    assert set(np.round(res.data["wrap_angle"] / DEG, 6)) == {5.0, 8.0, 20.0}


@pytest.mark.parametrize("at, match", [
    ("radius=30mm", r"radius=30 mm is outside the cube's grid; radius takes 5 \.\. 25 mm"),
    ("coil_index=2", r"coil_index=2 is outside .* 1\.1, 1\.7"),
    ("wrap_angle=1deg", r"wrap_angle=1 deg is outside"),
    ("radius=7.5kPa", r"--at radius: unit 'kPa' is not a length"),
    ("radius", r"expected NAME=VALUE"),
    ("size=3", r"unknown axis 'size'"),
    ("radius=7.5,radius=8", r"radius given twice"),
])
def test_at_refusals(cube, capsys, at, match):
    import re

    rc, out, err = run(capsys, cube, "--at", at)
    assert rc == 2 and out == ""
    assert re.search(match, err), err
    assert len(err.strip().splitlines()) == 1


# ---------------------------------------------------------------------------- --where
def _brute(ds, mask):
    """Designs meeting ``mask`` (a boolean DataArray over the axes), as a set of tuples."""
    d = ds[["tip_force_max"]].load().where(mask).to_dataframe().dropna()
    return {tuple(np.round(k, 9)) for k in d.index}


def test_where_matches_a_brute_force_filter(ds):
    res = query.query_cube(ds, where=["tip_force_max >= 0.5 N", "radius <= 15 mm"])
    got = {tuple(np.round([res.data[a][i] for a in query.AXES], 9)) for i in range(len(res))}
    load = ds.load()
    expect = _brute(load, (load["tip_force_max"] >= 0.5) & (load["radius"] <= 15e-3))
    assert got == expect and res.matched == len(expect) > 0


def test_where_units_are_converted(ds):
    in_n = query.query_cube(ds, where=["tip_force_max >= 0.5 N"])
    in_mn = query.query_cube(ds, where=["tip_force_max>=500mN"])
    assert in_n.matched == in_mn.matched
    deg = query.query_cube(ds, where=["wrap_angle == 8 deg"])
    bare = query.query_cube(ds, where=["wrap_angle == 8"])  # bare: the display unit, deg
    assert deg.matched == bare.matched == 9 * 3 * 2 * 2


def test_where_limit_words_and_range_fraction(ds):
    words = query.query_cube(ds, where=["limit == strength"])
    numbers = query.query_cube(ds, where=["limit == 1"])
    full = query.query_cube(ds, where=["range_fraction == 1"])
    n = int(np.prod([ds.sizes[a] for a in query.AXES]))
    assert words.matched == numbers.matched > 0
    assert full.matched + words.matched == n  # full range exactly when stroke-limited


def test_smallest_designs_giving_half_a_newton(cube, capsys):
    rc, out, _ = run(capsys, cube, "--where", "tip_force_max >= 0.5 N", "--sort", "radius",
                     "--limit", "5")
    assert rc == 0
    lines = out.strip().splitlines()
    assert lines[0].split()[:2] == ["radius", "wall_thickness"] and "[mm]" in lines[1]
    rows = [line.split() for line in lines[2:7]]
    assert len(rows) == 5 and lines[7].startswith("5 designs shown of")
    force = lines[0].split().index("tip_force_max")  # after the axes: the asked-for column
    assert force == 5
    assert all(float(r[force]) >= 0.5 for r in rows)
    radii = [float(r[0]) for r in rows]
    assert radii == sorted(radii)
    with open_cube(cube) as ds:
        smallest = float(ds["radius"].where(ds["tip_force_max"] >= 0.5).min()) * 1e3
    assert radii[0] == pytest.approx(smallest)


@pytest.mark.parametrize("where, match", [
    ("tip_force_max >= 0.5 kPa", r"--where tip_force_max: unit 'kPa' is not a force"),
    ("grip >= 1 N", r"unknown name 'grip'; accepted: radius"),
    ("tip_force_max about 1", r"expected 'NAME OP VALUE"),
    ("radius <= big", r"--where radius: expected a number"),
])
def test_where_refusals(cube, capsys, where, match):
    import re

    rc, _, err = run(capsys, cube, "--where", where)
    assert rc == 2 and re.search(match, err), err


# ---------------------------------------------------------------------------- --sort
def test_sort_descending_and_ties_in_grid_order(ds):
    res = query.query_cube(ds, sort="-tip_force_max", limit=4)
    assert list(res.data["tip_force_max"]) == sorted(res.data["tip_force_max"], reverse=True)
    assert res.data["tip_force_max"][0] == float(ds["tip_force_max"].max())
    same = query.query_cube(ds, sort="tip_force_max:desc", limit=4)
    assert np.array_equal(same.data["tip_force_max"], res.data["tip_force_max"])
    ties = query.query_cube(ds, sort="coil_index", limit=3)  # all C = 1.1: grid order
    assert list(ties.data["radius"]) == [5e-3] * 3
    assert list(ties.data["wrap_angle"]) == pytest.approx([5 * DEG, 8 * DEG, 20 * DEG])


def test_sort_refusals(ds):
    with pytest.raises(InputError, match="--sort: unknown name 'size'"):
        query.query_cube(ds, sort="size")
    with pytest.raises(InputError, match="order must be 'asc' or 'desc'"):
        query.query_cube(ds, sort="radius:up")
    with pytest.raises(InputError, match="--limit"):
        query.query_cube(ds, limit=-1)


def test_slabs_give_the_same_answer(ds, monkeypatch):
    whole = query.query_cube(ds, where=["tip_force_max >= 0.3 N"], sort="-nylon_use",
                             limit=7)
    monkeypatch.setattr(query.scan, "_SLAB_VALUES", 50)  # one radius per slab
    cut = query.query_cube(ds, where=["tip_force_max >= 0.3 N"], sort="-nylon_use", limit=7)
    for name in query.COLUMNS:
        np.testing.assert_array_equal(whole.data[name], cut.data[name])
    assert whole.matched == cut.matched
    first = query.query_cube(ds, where=["tip_force_max >= 0.3 N"], limit=2)
    assert len(first) == 2 and first.matched == whole.matched  # first two, all counted
    every = query.query_cube(ds, where=["tip_force_max >= 0.3 N"])
    for name in query.COLUMNS:  # the first two in grid order
        np.testing.assert_array_equal(first.data[name], every.data[name][:2])


# ---------------------------------------------------------------------------- formats
def test_json_one_object_in_si_with_units(cube, capsys):
    # docs/interface.md: {"designs": [...], "units": {...}, "matching": N, "shown": M}
    rc, out, _ = run(capsys, cube, "--at", AT_2, "--format", "json")
    doc = json.loads(out)
    assert rc == 0 and isinstance(doc, dict)
    assert doc["matching"] == doc["shown"] == len(doc["designs"]) == 1
    one = doc["designs"][0]
    assert one["point"] == doc["point"] == "grid point" and one["limit"] == 0
    assert one["validity"] == 0 and isinstance(one["validity"], int)
    assert one["radius"] == pytest.approx(7.5e-3)
    assert one["tip_force_max"] == pytest.approx(0.150, abs=5e-4)  # docs/model.md s. 8
    assert doc["units"]["tip_force_max"] == "N" and doc["units"]["wrap_angle"] == "rad"
    assert doc["flags"]["validity"]["1"] == "self_contact"


def test_json_many_is_one_object_with_the_units_once_and_the_count(cube, capsys):
    rc, out, err = run(capsys, cube, "--where", "radius == 5 mm", "--limit", "3",
                       "--format", "json")
    doc = json.loads(out)
    n = 3 * 2 * 2 * 3  # every design of radius 5 mm in SMALL
    assert rc == 0 and isinstance(doc, dict) and len(doc["designs"]) == doc["shown"] == 3
    assert doc["matching"] == n and "held back" not in err
    assert doc["units"]["radius"] == "m"
    assert all(d["radius"] == 5e-3 and "units" not in d for d in doc["designs"])
    assert all(isinstance(d["limit"], int) and isinstance(d["validity"], int)
               for d in doc["designs"])


def test_csv_in_si(cube, capsys):
    rc, out, _ = run(capsys, cube, "--at", "radius=8.6mm,coil_index=1.7,length=70",
                     "--format", "csv")
    rows = list(csv.reader(io.StringIO(out)))
    assert rc == 0 and rows[0][:3] == ["point", "radius [m]", "wall_thickness [m]"]
    assert len(rows) == 1 + 3 * 3
    assert {r[0] for r in rows[1:]} == {"exact model"}
    assert float(rows[1][1]) == pytest.approx(8.6e-3)


# ---------------------------------------------------------------------------- the file
def test_not_a_cube_and_missing_file(tmp_path, capsys):
    bad = tmp_path / "bad.h5"
    bad.write_text("not hdf5")
    rc, _, err = run(capsys, bad)
    assert rc == 2 and "not a nylonflex cube" in err
    rc, _, err = run(capsys, tmp_path / "none.h5")
    assert rc == 2 and "no such cube" in err


def test_incomplete_cube_is_queried_where_complete(cube, tmp_path, capsys):
    part = tmp_path / "part.h5"
    part.write_bytes(cube.read_bytes())
    with h5py.File(part, "r+") as f:  # as a sweep stopped after the first 3 radii leaves it
        f.attrs["complete"] = "false"
        f["slab_done"][3:] = 0
    rc, out, err = run(capsys, part, "--where", "tip_force_max >= 0 N", "--limit", "all")
    assert rc == 0 and "incomplete" in err and "warning" in err
    assert out.strip().splitlines()[-1] == f"{3 * 3 * 2 * 2 * 3} designs"
    rc, out, err = run(capsys, part, "--at", AT_2)  # radius 7.5 mm: computed
    assert rc == 0 and "0.150 N" in out
    rc, out, err = run(capsys, part, "--at", AT_2.replace("7.5mm", "20mm"))
    assert rc == 2 and "not in the cube yet" in err


# ---------------------------------------------------------------------------- issue 15
def test_at_between_grid_points_is_the_exact_model(ds, cube, capsys):
    # wall 3 mm lies between the 2 and 4 mm grid walls: the answer is design_limits there,
    # with the cube's materials (tc5005, silver_nylon66, b = t), not an interpolation
    at = dict(EXAMPLE_2, wall_thickness=3e-3)
    res = query.query_cube(ds, at=at)
    exact = nf.design_limits(**at)
    assert res.point == query.EXACT and res.interpolated == ["wall_thickness"]
    for name in query.DESIGN:  # heating_time: NaN without a supply, on both sides
        assert res.data[name][0] == exact[name] or \
            (np.isnan(res.data[name][0]) and np.isnan(exact[name])), name
    linear = query.query_cube(ds, at=at, interpolate=True)
    assert linear.point == query.INTERPOLATED
    assert linear.data["bend_angle_max"][0] != pytest.approx(exact["bend_angle_max"],
                                                           rel=1e-3)
    rc, out, _ = run(capsys, cube, "--at", AT_2.replace("2mm", "3mm"))
    assert rc == 0 and "exact model at this design" in out
    rc, out, _ = run(capsys, cube, "--at", AT_2.replace("2mm", "3mm"), "--interpolate")
    assert rc == 0 and "interpolated linearly in wall_thickness" in out


def test_exact_model_uses_the_cubes_own_materials(tmp_path):
    # a cube of another silicone and a fixed base: the exact answer must use them too
    raw = dict(SMALL, name="other", silicone="ecoflex_00_30",
               base_thickness={"value": 3, "units": "mm"},
               grid=dict(SMALL["grid"], radius={"values": [7, 9], "units": "mm"}))
    path = write_cube(tmp_path, raw)
    with open_cube(path) as ds:
        res = query.query_cube(ds, at=dict(EXAMPLE_2, radius=8e-3))
    exact = nf.design_limits(**dict(EXAMPLE_2, radius=8e-3), base_thickness=3e-3,
                             silicone="ecoflex_00_30")
    assert res.data["tip_force_max"][0] == exact["tip_force_max"]
    assert res.data["tip_force_max"][0] != nf.design_limits(
        **dict(EXAMPLE_2, radius=8e-3))["tip_force_max"]


def test_exact_slice_between_grid_points(ds):
    # a partial --at off the grid: every free-axis grid value, each by the exact model
    res = query.query_cube(ds, at={"radius": 8.6e-3, "coil_index": 1.7})
    assert res.point == query.EXACT and len(res) == 3 * 2 * 3
    i = 4
    one = nf.design_limits(**{n: res.data[n][i] for n in query.AXES})
    assert res.data["tip_force_max"][i] == one["tip_force_max"]


def test_repeated_at_merges_or_refuses(cube, capsys):
    rc, out, _ = run(capsys, cube, "--at", "radius=7.5mm,wall_thickness=2mm",
                     "--at", "length=70mm,coil_index=1.7,wrap_angle=8deg")
    assert rc == 0 and "0.150 N" in out
    rc, _, err = run(capsys, cube, "--at", "radius=7.5mm", "--at", "radius=10mm")
    assert rc == 2 and "radius given twice" in err and "merged" in err


def test_default_limit_holds_back_and_says_so(cube, capsys):
    rc, out, _ = run(capsys, cube)
    n = 9 * 3 * 2 * 2 * 3
    lines = out.strip().splitlines()
    assert rc == 0 and len(lines) == 2 + 20 + 1
    assert f"20 designs shown of {n} matching; {n - 20} held back" in out
    rc, out, _ = run(capsys, cube, "--limit", "all")
    assert out.strip().splitlines()[-1] == f"{n} designs"
    rc, out, err = run(capsys, cube, "--format", "csv")
    assert len(out.strip().splitlines()) == 21 and f"{n - 20} held back" in err
    with pytest.raises(SystemExit) as exit_:  # argparse: a usage error, exit 2
        run(capsys, cube, "--limit", "lots")
    assert exit_.value.code == 2 and "'all'" in capsys.readouterr().err


def test_query_progress_callback(ds):
    seen = []
    query.query_cube(ds, progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1][0] == seen[-1][1]


@pytest.mark.parametrize("at, where", [
    (None, ["tip_force_max >= 0.3 N", "limit == strength"]),
    (None, ["wall_thickness <= 3 mm", "nylon_use > 0.5", "bend_angle_max < 200 deg"]),
    ("coil_index=1.7", ["range_fraction < 1", "radius >= 10 mm"]),
    (None, ["tip_force_max > 1e9 N"]),  # nothing matches: the scan stops at the first read
])
def test_where_reads_variable_by_variable_and_finds_what_a_full_read_finds(ds, at, where):
    # the reference: every column of every slab read, then all conditions tested
    at_loc = {n: query.locate(ds, n, v) for n, v in (query.parse_at(at) if at
                                                            else {}).items()}
    full = query.slab_rows(ds, at_loc, 0, ds.sizes["radius"])
    keep = np.ones(len(full["radius"]), dtype=bool)
    for c in query.parse_where(where):
        keep &= c.mask(full[c.name])
    res = query.query_cube(ds, at=at, where=where, limit=None)
    assert res.matched == int(keep.sum())
    assert (res.matched > 0) == ("1e9" not in where[0])
    for name in query.COLUMNS:
        np.testing.assert_array_equal(res.data[name], full[name][keep], err_msg=name)
    few = query.query_cube(ds, at=at, where=where, limit=3)  # the rest only for kept rows
    assert few.matched == res.matched
    for name in query.COLUMNS:
        np.testing.assert_array_equal(few.data[name], full[name][keep][:3], err_msg=name)


# ---------------------------------------------------------------------------- issue 25
SLIM = "tip_force_max >= 0.5 N"


def test_default_table_shows_axes_asked_and_headline_in_120_columns(cube, capsys):
    rc, out, _ = run(capsys, cube, "--where", SLIM, "--limit", "5")
    lines = out.splitlines()
    assert rc == 0 and max(len(line) for line in lines) <= 120
    assert lines[0].split() == [*query.AXES, "tip_force_max", "limit", "bend_angle_max",
                                "validity"]
    # sorted by another variable: that one joins the table after the asked-for one
    rc, out, _ = run(capsys, cube, "--where", SLIM, "--sort=-nylon_use", "--limit", "5")
    assert out.splitlines()[0].split()[5:7] == ["tip_force_max", "nylon_use"]


def _header_names(out, n):
    """The column names of a table of ``n`` rows, its header lines joined again (names
    broken after an underscore over lines; blocks of columns, each with a '#' line)."""
    lines = [x for x in out.splitlines() if "designs shown" not in x and
             not x.startswith("at ")]
    heads = []
    if any(x.split()[:1] == ["#"] for x in lines):
        start = 0
        while start < len(lines):
            i = next(k for k in range(start, len(lines)) if lines[k].split()[:1] == ["#"])
            heads.append(lines[start:i + 1])
            start = i + 2 + n + 1  # the unit line, the rows, a blank line
    else:
        heads.append(lines[:len(lines) - n - 1])
    names = []
    for head in heads:
        width = max(map(len, head))
        used = [any(len(h) > k and h[k] != " " for h in head) for k in range(width)]
        k = 0
        while k < width:
            e = k
            while e < width and used[e]:
                e += 1
            if e > k:
                names.append("".join(h[k:e].strip() for h in head))
            k = e + 1
    return [x for x in names if x != "#"]


TWO_FLAGS = {  # a 1 mm wall, 120 mm long: self contact and stretch beyond the fit (fig12)
    "name": "two_flags",
    "grid": {"radius": {"values": [15.5, 16], "units": "mm"},
             "wall_thickness": {"values": [1], "units": "mm"},
             "length": {"values": [120], "units": "mm"},
             "coil_index": {"values": [1.7]},
             "wrap_angle": {"values": [5, 8], "units": "deg"}},
    "curves": SMALL["curves"],
}


def test_every_table_fits_in_120_columns(tmp_path, capsys):
    # issue 25: --where ... --sort on the fig12 cube's designs with two validity flags
    # printed 126 columns; now long names break after an underscore, and a table that is
    # still too wide goes in blocks of columns, each led by the row number
    two = write_cube(tmp_path, TWO_FLAGS)
    for extra in ([], ["--sort=-bend_angle_max"], ["--columns", "all"]):
        rc, out, _ = run(capsys, two, "--where", SLIM, "--limit", "5", *extra)
        assert rc == 0 and "self_contact+stretch_beyond_fit" in out
        assert max(map(len, out.splitlines())) <= 120, out
    assert _header_names(out, 4) == list(query.shown_columns(
        query.query_cube(open_cube(two), where=[SLIM], columns="all"), "table"))
    # every flag set and every column: blocks, each line within 120 columns
    from nylonflex.query.format import _columns_text

    heads = [*query.COLUMNS]
    cells = [[query.flag_names(15) if h == "validity" else "123.456" for h in heads]] * 3
    lines = _columns_text(heads, cells)
    assert max(map(len, lines)) <= 120 and sum(line.lstrip().startswith("#")
                                               for line in lines) >= 2
    assert _header_names("\n".join(lines), 3) == heads


def test_columns_option_picks_and_refuses(cube, capsys):
    rc, out, _ = run(capsys, cube, "--where", SLIM, "--limit", "2",
                     "--columns", "radius,validity,heating_time")
    assert rc == 0 and out.splitlines()[0].split() == ["radius", "validity", "heating_time"]
    assert out.splitlines()[2].split()[2] == "nan"  # named: kept although all NaN
    rc, out, _ = run(capsys, cube, "--limit", "1", "--columns", "all")
    names = _header_names(out, 1)  # 17 columns: wrapped to fit in 120 columns
    assert "heating_time" not in names  # no supply: no value in any row
    assert "usable_stroke" in names and max(map(len, out.splitlines())) <= 120
    rc, out, _ = run(capsys, cube, "--limit", "2", "--format", "csv", "--columns",
                     "radius,limit")
    assert rc == 0 and out.splitlines()[0] == "radius [m],limit [1]"
    for bad, match in (("radius,grip", r"--columns: unknown name 'grip'"),
                       ("radius,radius", r"--columns: radius given twice"),
                       ("feasibility", r"--columns: the cube has no feasibility")):
        rc, _, err = run(capsys, cube, "--columns", bad)
        assert rc == 2 and re.search(match, err), err


def test_table_drops_the_all_nan_heating_time_but_json_keeps_every_column(cube, capsys):
    rc, out, _ = run(capsys, cube, "--at", AT_2)
    assert rc == 0 and "heating_time" not in out and "validity         valid" in out
    rc, out, _ = run(capsys, cube, "--at", AT_2, "--format", "json")
    assert json.loads(out)["designs"][0]["heating_time"] is None


def test_validity_prints_as_flag_names_and_integers(ds):
    res = query.query_cube(ds, where=["validity == 1"], limit=1)
    assert res.matched == int((ds["validity"] == 1).sum()) > 0
    assert "self_contact" in query.format_table(res).splitlines()[2]
    rows = list(csv.reader(io.StringIO(query.format_csv(res))))
    assert rows[1][rows[0].index("validity [1]")] == "1"
    assert rows[1][rows[0].index("limit [1]")] in ("0", "1")
    assert query.flag_names(0) == "valid" and query.flag_names(3) == \
        "self_contact+stretch_beyond_fit" and query.flag_names(np.nan) == "unknown"


#: SMALL at wall 2 mm, L 90 mm, C 1.7, 8 deg: validity 0 at radius 10 mm, 1 (self_contact)
#: at 12.5 mm (read from the cube), so 11 mm lies between grid points that disagree.
FLIP = dict(wall_thickness=2e-3, length=90e-3, coil_index=1.7, wrap_angle=8 * DEG)


def test_interpolate_takes_the_flags_from_the_exact_model(ds, cube, capsys):
    assert [int(ds["validity"].sel(dict(FLIP, radius=r)).item()) for r in (10e-3, 12.5e-3)] == [0, 1]
    at = dict(FLIP, radius=11e-3)
    res = query.query_cube(ds, at=at, interpolate=True)
    exact = nf.design_limits(**at)
    assert res.point == query.INTERPOLATED and res.flags == query.EXACT
    assert res.data["validity"][0] == exact["validity"]  # not 0.44, the linear blend
    assert res.data["limit"][0] == exact["limit"]
    rc, out, _ = run(capsys, cube, "--at", "radius=11mm,wall_thickness=2mm,length=90mm,"
                     "coil_index=1.7,wrap_angle=8deg", "--interpolate")
    assert rc == 0 and "limit and validity: exact model" in out
    assert f"validity         {query.flag_names(exact['validity'])}" in out


def test_interpolated_flags_without_the_exact_model_are_unknown_where_corners_disagree(ds):
    # the slab reader itself (what a cube of several models gets): never a blend
    at = dict(FLIP, radius=11e-3)
    at_loc = {n: query.locate(ds, n, v) for n, v in at.items()}
    rows = query.slab_rows(ds, at_loc, at_loc["radius"][0], at_loc["radius"][1] + 1)
    assert np.isnan(rows["validity"][0])
    at_loc = {n: query.locate(ds, n, v) for n, v in dict(at, radius=6e-3).items()}
    rows = query.slab_rows(ds, at_loc, at_loc["radius"][0], at_loc["radius"][1] + 1)
    assert rows["validity"][0] == 0  # both corners clean


# ---------------------------------------------------------------------------- issue 49
# A --where query on the grid of a one-model cube reads it through h5py alone
# (nylonflex.storage.light): the same rows, bit for bit, as through xarray.
SPREAD_GRID = {
    "name": "spread",
    "fidelity": {"spread": ["paper", "lateral_pressure"]},
    "grid": {
        "radius": {"values": [5, 10, 15, 20], "units": "mm"},
        "wall_thickness": {"values": [1, 2, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 8], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
}


def _incomplete(cube, folder):
    """A copy of ``cube`` as a sweep stopped after its first 3 radii leaves it."""
    part = folder / "part.h5"
    part.write_bytes(cube.read_bytes())
    with h5py.File(part, "r+") as f:
        f.attrs["complete"] = "false"
        f["slab_done"][3:] = 0
    return part


@pytest.fixture(scope="module")
def cubes(cube, tmp_path_factory):
    """The complete cube, an incomplete copy, and a cube with a model spread (OPTIONAL
    columns)."""
    folder = tmp_path_factory.mktemp("light")
    spread = folder / "spread.h5"
    run_sweep(parse_config(SPREAD_GRID), out=spread).close()
    return {"complete": cube, "incomplete": _incomplete(cube, folder), "spread": spread}


@contextlib.contextmanager
def _views(cubes, which):
    """The cube ``which`` of :func:`cubes` through h5py alone and through xarray (each
    with the incomplete cube's warning)."""
    from nylonflex.storage import open_light

    views = []
    try:
        for opener in (open_light, open_cube):
            with pytest.warns(UserWarning, match="is incomplete") if which == "incomplete" \
                    else contextlib.nullcontext():
                views.append(opener(cubes[which]))
        yield views
    finally:
        for view in views:
            view.close()


@pytest.mark.parametrize("which", ["complete", "incomplete", "spread"])
def test_the_h5py_view_reads_what_xarray_reads(cubes, which):
    with _views(cubes, which) as (light, ds):
        assert type(light).__name__ == "LightCube" and light.sizes == dict(ds.sizes)
        assert set(light.dims) == set(ds.dims) and set(light.variables) == set(ds.variables)
        assert set(light.attrs) == set(ds.attrs)
        for key, value in ds.attrs.items():  # a one-element array: its number here
            assert np.array_equal(np.ravel(light.attrs[key]), np.ravel(value)), key
        for name, var in ds.variables.items():
            mine = light[name]
            assert mine.dims == var.dims and mine.dtype.kind == var.dtype.kind, name
            want = np.asarray(var.values, dtype=float)
            assert np.array_equal(mine.values, want, equal_nan=True), name
            index = {"radius": slice(1, 4)} if "radius" in var.dims else {}
            box = np.asarray(var.isel(index).values, dtype=float)
            assert np.array_equal(light.read(name, index), box, equal_nan=True), name
        assert np.isnan(light.read("tip_force_max")).any() == (which == "incomplete")


def _same(a, b):
    assert a.matched == b.matched and a.columns == b.columns and a.point == b.point
    for name in a.columns:
        x, y = a.data[name], b.data[name]
        assert x.dtype == y.dtype and x.shape == y.shape, name
        assert x.tobytes() == y.tobytes(), name  # bit for bit, NaN included


@pytest.mark.parametrize("which", ["complete", "incomplete", "spread"])
@pytest.mark.parametrize("at, where, sort, limit", [
    (None, ["tip_force_max >= 0.3 N"], None, None),
    (None, ["tip_force_max >= 0.3 N"], None, 0),
    (None, ["tip_force_max >= 0.3 N"], None, 3),
    (None, ["wall_thickness <= 3 mm", "nylon_use > 0.5", "bend_angle_max < 200 deg"],
     "-tip_force_max", 5),
    (None, ["limit == strength", "radius >= 10 mm"], "nylon_use", None),
    ("coil_index=1.7", ["range_fraction < 1"], None, None),
    (AT_2.replace("7.5mm", "10mm"), ["tip_force_max >= 0 N"], None, None),
    (None, ["tip_force_max > 1e9 N"], None, None),
    (None, ["model == paper", "validity == 0"], "-bend_angle_max", 4),
])
def test_the_h5py_view_answers_as_xarray_does(cubes, which, at, where, sort, limit):
    with _views(cubes, which) as (light, ds):
        assert query.by_variable(light, at, where, False)
        _same(query.query_cube(light, at=at, where=where, sort=sort, limit=limit),
              query.query_cube(ds, at=at, where=where, sort=sort, limit=limit))


def test_spread_columns_are_tested_and_kept_through_the_h5py_view(cubes):
    with _views(cubes, "spread") as (light, ds):
        where = ["tip_force_max_model_hi >= 0.3 N", "validity_model_any == 0"]
        res = query.query_cube(light, where=where, sort="-tip_force_max_model_lo")
        _same(res, query.query_cube(ds, where=where, sort="-tip_force_max_model_lo"))
        assert res.matched > 0 and "validity_model_any" in res.columns
        assert np.all(res.data["tip_force_max_model_hi"] >= 0.3)


def _both(monkeypatch, capsys, *argv):
    """``nylonflex query ARGV`` as it runs (the view it opens, its rc, stdout, stderr), and
    again with the h5py view turned off (xarray's reader)."""
    import nylonflex.storage
    from nylonflex.cli import query as cli_query

    opened = []
    real = cli_query.open_cube_for

    def spy(*args, **kwargs):
        opened.append(real(*args, **kwargs))
        return opened[-1]

    monkeypatch.setattr(cli_query, "open_cube_for", spy)
    first = run(capsys, *argv)
    nylonflex.storage.open_light  # loaded, so that it can be replaced
    monkeypatch.setattr(nylonflex.storage, "open_light", lambda path, **kw: None)
    second = run(capsys, *argv)
    monkeypatch.undo()
    return [type(ds).__name__ for ds in opened], first, second


#: Options of ``nylonflex query`` answered through the h5py view.
LIGHT_QUERIES = [
    ["--where", "tip_force_max >= 0.5 N"],
    ["--where", "tip_force_max >= 0.3 N", "--limit", "0"],
    ["--where", "tip_force_max >= 0.3 N", "--limit", "all", "--format", "csv"],
    ["--where", "tip_force_max >= 0.3 N", "--limit", "3", "--format", "csv"],
    ["--where", "bend_angle_max >= 90 deg", "--sort", "-tip_force_max", "--format", "json",
     "--limit", "4"],
    ["--where", "radius <= 10 mm", "--where", "limit == stroke", "--columns", "all"],
    ["--where", "bend_angle_max >= 100000"],  # nothing: a note on the bare number's unit
    ["--where", "radius <= 0.01"],
    ["--at", "wrap_angle=8deg", "--where", "tip_force_max >= 0.3 N", "--format", "json"],
]


@pytest.mark.parametrize("which, extra", [
    *(("complete", extra) for extra in LIGHT_QUERIES),
    *((which, LIGHT_QUERIES[k]) for which in ("incomplete", "spread") for k in (2, 4, 6, 8)),
])
def test_the_command_prints_the_same_through_h5py_and_xarray(cubes, monkeypatch, capsys,
                                                             which, extra):
    opened, light, full = _both(monkeypatch, capsys, cubes[which], *extra)
    assert opened == ["LightCube", "Dataset"]
    assert light == full and light[0] == 0
    assert ("incomplete" in light[2]) == (which == "incomplete")
    assert light[2].count("warning") == (which == "incomplete")


@pytest.mark.parametrize("extra", [
    ["--limit", "3"],  # no --where: the slab reader
    ["--at", "radius=7.3mm", "--where", "tip_force_max >= 0.1 N"],  # off the grid
    ["--at", "radius=7.5mm", "--where", "tip_force_max >= 0.1 N", "--interpolate"],
    ["--where", "model == paper"],
    ["--at", "radius=99mm", "--where", "tip_force_max >= 0.1 N"],  # refused, as before
])
def test_other_queries_keep_xarray(cube, monkeypatch, capsys, extra):
    opened, light, full = _both(monkeypatch, capsys, cube, *extra)
    assert light == full and opened == ["Dataset", "Dataset"]


def test_a_cube_of_several_models_and_cooling_sets_keeps_xarray(tmp_path, monkeypatch,
                                                                capsys):
    from nylonflex.storage import open_light

    raw = dict(SMALL, model=["paper", "lateral_pressure"], supply={"voltage": 12},
               cooling=["still_air", "still_water"])
    path = write_cube(tmp_path, raw)
    assert open_light(path) is None  # string dimensions: xarray's reader
    opened, light, full = _both(monkeypatch, capsys, path, "--where",
                                "tip_force_max >= 0.5 N", "--format", "json")
    assert opened == ["Dataset", "Dataset"] and light == full and light[0] == 0
    doc = json.loads(light[1])
    with open_cube(path) as ds:
        want = int((ds["tip_force_max"] >= 0.5).sum())
        assert doc["matching"] == want > 0
        assert {row["model"] for row in doc["designs"]} <= {"paper", "lateral_pressure"}
        opened, light, _ = _both(monkeypatch, capsys, path, "--where", "model == paper",
                                 "--where", "cooling == still_air", "--where",
                                 "tip_force_max >= 0.5 N", "--format", "json", "--limit",
                                 "all")
        doc = json.loads(light[1])
        sub = ds["tip_force_max"].sel(model="paper", cooling="still_air") \
            if "cooling" in ds["tip_force_max"].dims else ds["tip_force_max"].sel(model="paper")
        assert doc["matching"] == int((sub >= 0.5).sum()) > 0


def test_the_h5py_view_refuses_in_open_cubes_words(tmp_path, cube):
    from nylonflex.storage import open_light

    bad = tmp_path / "bad.h5"
    bad.write_text("not hdf5")
    for path in (bad, tmp_path / "none.h5"):
        with pytest.raises(InputError) as light:
            open_light(path)
        with pytest.raises(InputError) as full:
            open_cube(path)
        assert str(light.value) == str(full.value)
    odd = tmp_path / "odd.h5"
    odd.write_bytes(cube.read_bytes())
    with h5py.File(odd, "r+") as f:
        f["tip_force_max"].attrs["units"] = "kN"
    with pytest.raises(InputError) as light:
        open_light(odd)
    with pytest.raises(InputError) as full:
        open_cube(odd)
    assert str(light.value) == str(full.value) and "registry" in str(light.value)
    packed = tmp_path / "packed.h5"  # a packed variable: for xarray to decode
    packed.write_bytes(cube.read_bytes())
    with h5py.File(packed, "r+") as f:
        f["tip_force_max"].attrs["scale_factor"] = 2.0
    assert open_light(packed) is None


def test_a_where_query_imports_neither_xarray_nor_pandas(cube):
    # issue 49: python -m nylonflex query CUBE --where ..., in its own process, from this
    # checkout
    import subprocess
    import sys
    from pathlib import Path

    probe = ("import atexit, runpy, sys\n"
             "atexit.register(lambda: print('LOADED', [m for m in ('xarray', 'pandas', "
             "'h5netcdf', 'h5py') if m in sys.modules]))\n"
             f"sys.argv = ['nylonflex', 'query', {str(cube)!r}, '--where', "
             "'tip_force_max >= 0.5 N']\n"
             "runpy.run_module('nylonflex', run_name='__main__')\n")
    done = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          cwd=Path(__file__).resolve().parents[1], timeout=600)
    assert done.returncode == 0, done.stderr
    assert "designs shown of" in done.stdout
    assert done.stdout.splitlines()[-1] == "LOADED ['h5py']"
