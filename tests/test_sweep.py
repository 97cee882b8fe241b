"""The sweep end to end: config -> cube file, round trip, resume, refusals, CLI."""

import signal

import h5py
import numpy as np
import pytest
from killing import kill_after_slabs
import xarray as xr
import yaml
from helpers import stable, write_config

from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.storage import Journal, exclusive, open_cube
from nylonflex.engine.grid import bytes_per_radius, plan_slabs
from nylonflex.sweep.conductor import run_sweep
from nylonflex.variables import VARIABLES

SMALL = {
    "name": "small",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
        "wall_thickness": {"values": [1, 3, 6], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
    "slab_megabytes": 1,
}




def test_round_trip_file_equals_memory(tmp_path):
    cfg = parse_config(SMALL)
    mem = run_sweep(cfg)
    disk = run_sweep(cfg, tmp_path / "cube.h5")
    assert disk.attrs["complete"] == 1  # int8 (issue 24)
    xr.testing.assert_equal(mem, disk.load())
    for name in disk.variables:
        assert disk[name].attrs["units"] and disk[name].attrs["long_name"], name
        if name in VARIABLES:
            assert disk[name].attrs["units"] == VARIABLES[name].units


def test_cube_is_readable_by_h5py_and_netcdf4_with_units_and_provenance(tmp_path):
    netCDF4 = pytest.importorskip("netCDF4")
    # the default codec (issue 24): deflate with the shuffle filter, no plugin needed
    assert parse_config(SMALL).compression == "gzip"
    cfg = parse_config(SMALL)
    path = tmp_path / "cube.h5"
    run_sweep(cfg, path).close()
    with netCDF4.Dataset(path) as nc:
        for name, var in nc.variables.items():
            assert var.units, name
        assert nc.variables["tip_force_max"].units == "N"
        assert nc.variables["limit"].flag_meanings == \
            "stroke_limited strength_limited supply_limited load_limited"  # issue 10
    with h5py.File(path, "r") as f:
        assert f["tip_force_max"].compression == "gzip"
        assert f["tip_force_max"].chunks is not None
        attrs = dict(f.attrs)
    for key in ("config_yaml", "config_sha256", "nylonflex_version", "numba_version",
                "numpy_version", "silicone_parameters", "nylon_parameters", "quadrature",
                "run_seconds", "designs_per_second"):
        assert key in attrs, key
    assert yaml.safe_load(attrs["config_yaml"])["grid"]["radius"][0] == 0.005
    assert "Marechal" in attrs["silicone_parameters"]


def test_slabs_bound_memory():
    cfg = parse_config({**SMALL, "slab_megabytes": 1})
    slabs, chunk = plan_slabs(cfg)
    assert slabs[0][0] == 0 and slabs[-1][1] == 9
    big = parse_config({**SMALL, "grid": {**SMALL["grid"],
                                          "radius": {"start": 5, "stop": 25, "num": 4000}}})
    slabs, chunk = plan_slabs(big)
    per_radius = bytes_per_radius(big)
    assert len(slabs) > 1 and slabs[-1][1] == 4000
    assert all((i1 - i0) * per_radius <= 2**20 for i0, i1 in slabs)
    assert all((i1 - i0) % chunk == 0 for i0, i1 in slabs[:-1])


def _journaled(out):
    return len(Journal(out).done())


def _kill_halfway(cmd, out, sig, at_least=3):
    return kill_after_slabs(cmd, at_least, sig)


BIGGER = {**SMALL, "name": "bigger",
          "grid": {**SMALL["grid"], "radius": {"start": 5, "stop": 25, "num": 160},
                   "wall_thickness": {"start": 1, "stop": 6, "num": 30},
                   "wrap_angle": {"values": [3, 5, 8, 12, 20, 30]}}}


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_killed_sweep_resumes_to_an_identical_cube(tmp_path, sig):
    cfg_path = write_config(tmp_path, BIGGER)
    out = tmp_path / "run" / "cube.h5"
    cmd = ["sweep", str(cfg_path), "--out", str(out), "--quiet", "--no-charts"]
    rc = _kill_halfway(cmd, out, sig)
    assert rc != 0
    done = _journaled(out)
    assert done == 3
    if sig == signal.SIGKILL:
        # a killed run never leaves a file that reads as complete
        assert not out.exists()
        with pytest.raises(ValueError, match="--resume"):
            open_cube(out)
    else:
        # a stopped run leaves an incomplete cube that can be read where it is done
        with pytest.warns(UserWarning, match="incomplete"):
            part = open_cube(out)
        assert part.attrs["complete"] == 0
        assert 0 < int(part["slab_done"].sum()) < 160
        part.close()
    # without --resume the journal is protected
    assert main(["sweep", str(cfg_path), "--out", str(out), "--quiet"]) == 2
    assert main(["sweep", str(cfg_path), "--out", str(out), "--quiet", "--resume",
                 "--no-charts"]) == 0
    resumed = open_cube(out)
    assert resumed.attrs["resumed_slabs"] == done  # typed (issue 24)
    whole = run_sweep(parse_config(BIGGER), tmp_path / "whole.h5")
    xr.testing.assert_identical(stable(resumed), stable(whole))
    assert not Journal(out).dir.exists()


@pytest.mark.slow
def test_a_killed_resume_of_a_killed_sweep_resumes_to_an_identical_cube(tmp_path):
    # journal format 5: the chunks of the first run lie in its building file, which the
    # resume moves into the journal (aside-000001.h5), restores from, points the records
    # at its own building file and drops; killed in its turn, it leaves that building
    # file, which the third run moves aside and restores from
    cfg_path = write_config(tmp_path, BIGGER)
    out = tmp_path / "run" / "cube.h5"
    cmd = ["sweep", str(cfg_path), "--out", str(out), "--quiet", "--no-charts"]
    assert kill_after_slabs(cmd, 3, signal.SIGKILL) != 0
    assert kill_after_slabs([*cmd, "--resume"], 2, signal.SIGKILL) != 0
    assert _journaled(out) == 5 and not Journal(out).asides()
    assert main([*cmd, "--resume"]) == 0
    resumed = open_cube(out)
    assert resumed.attrs["resumed_slabs"] == 5
    whole = run_sweep(parse_config(BIGGER), tmp_path / "whole.h5")
    xr.testing.assert_identical(stable(resumed), stable(whole))
    assert not Journal(out).dir.exists()


def test_resume_refuses_a_changed_config(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    cfg = parse_config(SMALL)
    Journal(out).start({"name": "small", "config_sha256": "0" * 64, "slabs": []})
    path = write_config(tmp_path, SMALL)
    assert main(["sweep", str(path), "--out", str(out), "--resume", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "config changed" in err and err.count("\n") == 1
    assert cfg.sha256[:12] in err


def test_second_sweep_on_the_same_output_is_refused(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    path = write_config(tmp_path, SMALL)
    with exclusive(out):
        assert main(["sweep", str(path), "--out", str(out), "--quiet"]) == 1
    assert "another sweep is writing" in capsys.readouterr().err
    assert not out.exists()


def test_resume_of_a_complete_cube_does_nothing(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    path = write_config(tmp_path, SMALL)
    assert main(["sweep", str(path), "--out", str(out), "--no-charts"]) == 0
    before = out.stat().st_mtime_ns
    assert main(["sweep", str(path), "--out", str(out), "--resume", "--no-charts"]) == 0
    assert out.stat().st_mtime_ns == before
    assert "already complete" in capsys.readouterr().err


def _mutate(raw, path, value):
    import copy

    raw = copy.deepcopy(raw)
    node = raw
    for key in path[:-1]:
        node = node[key]
    if value is KeyError:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return raw


@pytest.mark.parametrize("path,value,match", [
    (("grid", "radius", "colour"), "red", r"grid.radius.colour: unknown key"),
    (("grid", "wall_thickness"), KeyError, r"grid.wall_thickness: missing key"),
    (("grid", "radius", "units"), "kPa", r"grid.radius.units: unit 'kPa' is not a length"),
    (("grid", "radius", "units"), "furlong", r"grid.radius.units: unknown unit 'furlong'"),
    (("grid", "radius", "start"), "five", r"grid.radius.start: expected a number"),
    (("grid", "radius", "stop"), 900, r"grid.radius.stop: must be in \[0.5, 200\] mm, got 900 mm"),
    (("grid", "coil_index", "values"), [1.1, 2.5], r"grid.coil_index.values\[1\]: must be in \[1.1, 1.7\], got 2.5"),
    (("grid", "wrap_angle", "values"), [], r"grid.wrap_angle.values: needs at least one"),
    (("grid", "length", "values"), [90, 70], r"grid.length: values must be strictly incr"),
    (("curves", "pressure", "stop"), 500, r"curves.pressure.stop: must be in \[0, 100\] kPa, got 500 kPa"),
    (("curves", "stroke", "stop"), 1.2, r"curves.stroke.stop: must be in \[0, 0.5\], got 1.2"),
    (("silicone",), "jelly", r"silicone: unknown set 'jelly'"),
    (("nylon",), {"set": "silver_nylon66", "colour": 1}, r"nylon.colour: unknown field"),
    (("name",), "../x", r"name: letters, digits"),
    (("charts",), ["fig99"], r"charts\[0\]: must be one of"),
])
def test_bad_config_exits_2_with_one_line_and_no_file(tmp_path, capsys, path, value, match):
    import re

    cfg_path = write_config(tmp_path, _mutate(SMALL, path, value))
    out = tmp_path / "cube.h5"
    assert main(["sweep", str(cfg_path), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert re.search(match, err), err
    assert not out.exists() and not Journal(out).dir.exists()


def test_config_file_errors(tmp_path, capsys):
    assert main(["sweep", str(tmp_path / "nope.yaml")]) == 2
    assert "no such config file" in capsys.readouterr().err
    bad = tmp_path / "bad.yaml"
    bad.write_text("name: [unclosed\n")
    assert main(["sweep", str(bad)]) == 2
    assert "not valid YAML" in capsys.readouterr().err
    assert main(["sweep", str(write_config(tmp_path, SMALL)), "--set", "grid.radius.num"]) == 2
    assert "expected KEY=VALUE" in capsys.readouterr().err


def test_set_overrides_a_config_key(tmp_path):
    path = write_config(tmp_path, SMALL)
    out = tmp_path / "cube.h5"
    assert main(["sweep", str(path), "--out", str(out), "--quiet", "--no-charts",
                 "--set", "grid.radius.num=3", "--set", "grid.length.values=[80mm]",
                 "--workers", "1"]) == 0
    ds = open_cube(out)
    assert ds.sizes["radius"] == 3 and ds["length"].values.tolist() == [0.08]
    assert ds.attrs["workers"] == 1  # typed (issue 24)


def test_default_output_under_sweeps(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    path = write_config(tmp_path, SMALL)
    assert main(["sweep", str(path), "--quiet", "--no-charts"]) == 0
    assert (tmp_path / "sweeps" / "small" / "cube.h5").is_file()


def test_info_describes_a_cube(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    run_sweep(parse_config(SMALL), out).close()
    assert main(["info", str(out)]) == 0
    text = capsys.readouterr().out
    assert "complete" in text and "radius" in text and "5 .. 25 mm" in text
    assert "nylonflex_version" in text


@pytest.mark.parametrize("content", [b"", b"not a cube at all", None])
def test_a_file_that_is_not_a_cube_is_refused(tmp_path, capsys, content):
    path = tmp_path / "x.h5"
    if content is None:
        with h5py.File(path, "w") as f:
            f["a"] = np.arange(3)
    else:
        path.write_bytes(content)
    assert main(["info", str(path)]) == 2
    assert "not a nylonflex cube" in capsys.readouterr().err


def test_workers_out_of_range(tmp_path, capsys):
    path = write_config(tmp_path, SMALL)
    assert main(["sweep", str(path), "--out", str(tmp_path / "c.h5"), "--workers", "0"]) == 2
    assert "--workers: must be in [1," in capsys.readouterr().err

@pytest.mark.slow

def test_resume_keeps_the_journal_slab_plan_when_slab_size_changes(tmp_path):
    # slab_megabytes is not part of the config hash: a resume must use the journal's plan
    cfg_path = write_config(tmp_path, BIGGER)
    out = tmp_path / "run" / "cube.h5"
    cmd = ["sweep", str(cfg_path), "--out", str(out), "--quiet", "--no-charts"]
    assert _kill_halfway(cmd, out, signal.SIGKILL) != 0
    assert _journaled(out) == 3
    assert main(["sweep", str(cfg_path), "--out", str(out), "--quiet", "--resume",
                 "--no-charts", "--set", "slab_megabytes=7"]) == 0
    whole = run_sweep(parse_config(BIGGER), tmp_path / "whole.h5")
    xr.testing.assert_identical(stable(open_cube(out)), stable(whole))


def test_a_damaged_journal_is_refused(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    cfg = parse_config(SMALL)
    Journal(out).start({"name": "small", "config_sha256": cfg.sha256, "slabs": [[0, 4]]})
    path = write_config(tmp_path, SMALL)
    assert main(["sweep", str(path), "--out", str(out), "--resume", "--quiet"]) == 2
    assert "damaged" in capsys.readouterr().err


@pytest.mark.parametrize("argv", [["sweep"], ["frobnicate"], ["query", "x", "--format", "xml"],
                                  ["sweep", "c.yaml", "--workers", "two"]])
def test_command_line_usage_errors_are_one_line_exit_2(argv, capsys):
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "error:" in err and "--help" in err


def test_version_and_help(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and "nylonflex 0." in capsys.readouterr().out
    assert main([]) == 0 and "sweep" in capsys.readouterr().out


# ------------------------------------------------- coordinates at their decimals (issue 24)
def test_grid_points_are_the_floats_nearest_their_decimal_values():
    # {start: 5, stop: 25, num: 41, units: mm}: point i is the decimal 5 + 0.5 i mm, and its
    # SI float is the one Python reads from that decimal in metres (float('0.0105')), not
    # np.linspace's 0.010499999999999999; a values axis likewise (1.3 mm * 1e-3 is an ulp
    # off 0.0013); degrees are math.radians' product, as np.radians gives
    from fractions import Fraction

    raw = {**SMALL, "grid": {**SMALL["grid"],
                             "radius": {"start": 5, "stop": 25, "num": 41, "units": "mm"},
                             "wall_thickness": {"values": [1.3, 2.1, 4.2], "units": "mm"},
                             "wrap_angle": {"start": 2, "stop": 30, "num": 15,
                                            "units": "deg"}},
           "curves": {**SMALL["curves"], "stroke": {"start": 0, "stop": 0.1, "num": 51}}}
    cfg = parse_config(raw)
    assert cfg.axes["radius"].tolist() == [float((5 + Fraction(1, 2) * i) / 1000)
                                           for i in range(41)]
    assert 0.0105 in cfg.axes["radius"].tolist()  # np.linspace: 0.010499999999999999
    assert cfg.axes["wall_thickness"].tolist() == [0.0013, 0.0021, 0.0042]
    assert cfg.axes["wrap_angle"].tolist() == np.radians(np.arange(2, 31, 2)).tolist()
    assert cfg.curves["stroke"].tolist() == [float(Fraction(i, 500)) for i in range(51)]


def test_sel_finds_grid_points_typed_in_si_or_with_units():
    ds = run_sweep(parse_config({**SMALL, "grid": {
        **SMALL["grid"], "radius": {"start": 5, "stop": 25, "num": 41, "units": "mm"}}}))
    for mm in np.arange(5, 25.01, 0.5):  # every grid point by its decimal, no 'nearest'
        ds.sel(radius=float(f"{mm / 1000:.4g}"))
    one = ds.nf.sel(radius="10.5 mm", wall_thickness=0.003, wrap_angle="20deg")  # bare: SI
    assert float(one["radius"]) == 0.0105 and float(one["wall_thickness"]) == 0.003
    # the display-unit copy for plots: values and units attrs converted, SI cube untouched
    shown = one["torque_max"].nf.display()
    assert shown.attrs["units"] == VARIABLES["torque_max"].display == "N mm"
    np.testing.assert_allclose(shown.values, one["torque_max"].values * 1e3, rtol=1e-15)
    assert shown["length"].attrs["units"] == "mm" and ds["radius"].attrs["units"] == "m"
    from nylonflex.units import InputError

    with pytest.raises(InputError, match="stroke_max: not an axis"):
        ds.nf.sel(stroke_max=1)
    # issue 46: a bare number is SI; a miss names how it was read and the nearest values
    with pytest.raises(KeyError, match=r"radius=7\.5 \(read in SI 7\.5 m\) is not a grid "
                       r"value; nearest: 0\.0245 m \(24\.5 mm\), 0\.025 m \(25 mm\); a bare "
                       r"number is SI \(m\): write '7\.5mm'"):
        ds.nf.sel(radius=7.5)
    with pytest.raises(InputError, match=r"read as 0\.0103 m\) is not a grid value; "
                       r"nearest: 0\.01 m \(10 mm\), 0\.0105 m"):
        ds.nf.sel(radius="10.3mm")
    assert float(ds.nf.sel(radius=0.0075)["radius"]) == 0.0075
