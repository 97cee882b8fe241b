"""``nylonflex verify --drive stroke``: every model of a cube at each sampled design's full
stroke against the sealed, stroke-driven FE twin.

One real, coarse design checks the dataset's ratios against nylonflex.evaluate and
nylonflex.fe_stroke called here; the journal, the drives' folders, the map and info run on
a stand-in twin with known values; a killed and resumed real verify is slow-marked.
"""

import json
import os
import shutil
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

import nylonflex as nf
import nylonflex.fe.verify as verify
import nylonflex.fe.verify_stroke as vs
from helpers import write_cube
from nylonflex.units import InputError

pytest.importorskip("felupe")

GRID = {
    "name": "fids",
    "grid": {"radius": {"values": [7.5, 12, 20], "units": "mm"},
             "wall_thickness": {"values": [2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}},
}
#: The stand-in twin: its pressure, bend and force these multiples of the paper model's.
TWIN = {"pressure": 2.0, "bend_angle": 0.5, "tip_force": 4.0}


@pytest.fixture()
def cube(tmp_path):
    return write_cube(tmp_path, GRID)


def _fake(calls):
    def solve(task):
        d, sil, mesh, blocked = task
        calls.append(d["radius"])
        r = nf.evaluate(d["radius"], d["wall_thickness"], d["length"], d["coil_index"],
                        d["wrap_angle"])
        # the paper's s* is the plan's stroke
        assert float(r["usable_stroke"]) == pytest.approx(d["strokes"][0], rel=1e-12)
        p = TWIN["pressure"] * float(r["pressure_max"])
        out = {"pressure": [p], "bend_angle": [TWIN["bend_angle"] * float(r["bend_angle_max"])],
               "discretisation_error": [0.02], "coarser_pressure": [p],
               "coarser_bend_angle": [0.1]}
        if blocked:
            out.update({"blocked_pressure": [p], "blocked_discretisation_error": [0.03],
                        "tip_force": [TWIN["tip_force"] * float(r["tip_force_max"])]})
        return out
    return solve


def _load(path):
    with xr.open_dataset(path, engine="h5netcdf") as fid:
        return fid.load()


def test_ratios_are_model_over_the_real_twin_at_full_stroke(cube):
    """One design (the paper's example 1, the first sampled) on the coarse mesh: each ratio
    is the model's value over nf.fe_stroke's at nf.evaluate's usable stroke."""
    fid = _load(vs.run_verify_stroke(cube, 1, mesh="coarse"))
    a, t, L, C, psi = 20e-3, 6e-3, 90e-3, 1.1, np.radians(8.0)
    assert float(fid["radius"][0]) == a and float(fid["wall_thickness"][0]) == t
    s_star = float(nf.evaluate(a, t, L, C, psi)["usable_stroke"])
    twin = nf.fe_stroke(a, t, L, [s_star], mesh="coarse")
    assert float(fid["stroke"][0]) == pytest.approx(s_star, rel=1e-12)
    assert float(fid["stroke_fe_pressure"][0]) == pytest.approx(twin["pressure"][0], rel=1e-9)
    for model in fid["model"].values:
        m = nf.evaluate(a, t, L, C, psi, model=str(model))
        np.testing.assert_allclose(fid["stroke_pressure_ratio"].sel(model=model).values,
                                   float(m["pressure_max"]) / twin["pressure"][0], rtol=1e-9)
        np.testing.assert_allclose(fid["stroke_bend_ratio"].sel(model=model).values,
                                   float(m["bend_angle_max"]) / twin["bend_angle"][0],
                                   rtol=1e-9)
    assert float(fid["stroke_fe_discretisation_error"][0]) == pytest.approx(
        twin["discretisation_error"][0], rel=1e-9)
    assert "stroke_force_ratio" not in fid  # not blocked


def test_stand_in_twin_ratios_units_map_and_info(cube, monkeypatch, tmp_path, capsys):
    from nylonflex.charts.fidelity import fidelity_map
    from nylonflex.cli import main

    calls = []
    monkeypatch.setattr(vs, "_solve_stroke", _fake(calls))
    fid = _load(vs.run_verify_stroke(cube, 4, mesh="coarse", blocked=True))
    assert len(calls) == 4
    for ratio, var in (("stroke_pressure_ratio", "pressure"),
                       ("stroke_bend_ratio", "bend_angle"), ("stroke_force_ratio", "tip_force")):
        np.testing.assert_allclose(fid[ratio].sel(model="paper").values, 1 / TWIN[var],
                                   rtol=1e-9)
        assert fid[ratio].attrs["units"] == "1" and "s*" in fid[ratio].attrs["long_name"]
    assert fid["stroke_fe_pressure"].attrs["units"] == "Pa"
    assert fid["stroke_fe_tip_force"].attrs["units"] == "N"
    assert fid["stroke_fe_bend_angle"].attrs["units"] == "rad"
    assert fid.attrs["drive"] == "stroke" and fid.attrs["blocked"] == 1
    fig = fidelity_map(fid)
    assert [ax.get_title() for ax in fig.axes] == [
        "pressure_max / twin at s*", "bend_angle_max / twin at s*", "tip_force_max / twin at s*"]
    fig.savefig(tmp_path / "map.png")
    assert main(["info", str(cube)]) == 0
    out = capsys.readouterr().out
    assert "drive stroke, blocked" in out and "within 15 %" in out
    # a resume solves nothing again and writes the same numbers
    calls.clear()
    again = _load(vs.run_verify_stroke(cube, 4, mesh="coarse", blocked=True))
    assert calls == [] and again.equals(fid)


def test_the_pressure_drive_is_unchanged(cube, monkeypatch):
    """No drive in its plan or dataset, the same variables as before the stroke drive."""
    from test_verify import _fake as pressure_fake

    monkeypatch.setattr(verify, "_solve", pressure_fake([]))
    fid = _load(verify.run_verify(cube, 3, mesh="coarse"))
    assert sorted(fid.variables) == sorted(
        ["design", "level", "model", "radius", "wall_thickness", "length", "coil_index",
         "wrap_angle", "pressure", "fe_bend_angle", "fe_mesh_bend_angle",
         "discretisation_error", "paper_bend_angle", "cauchy_moment_bend_angle",
         "lateral_pressure_bend_angle", "fe_calibrated_bend_angle", "ratio"])
    assert "drive" not in fid.attrs
    plan = json.loads((cube.with_name(cube.name + ".fidelity.parts") / "plan.json").read_text())
    assert "drive" not in plan and "strokes" not in plan["designs"][0]
    assert not vs.stroke_path(cube).exists()


def test_a_folder_of_the_other_drive_is_refused(cube, monkeypatch, capsys):
    from nylonflex.cli import main
    from test_verify import _fake as pressure_fake

    monkeypatch.setattr(verify, "_solve", pressure_fake([]))
    monkeypatch.setattr(vs, "_solve_stroke", _fake([]))
    verify.run_verify(cube, 2, mesh="coarse")
    pressure_parts = cube.with_name(cube.name + ".fidelity.parts")
    shutil.copytree(pressure_parts, vs.stroke_parts(cube))
    with pytest.raises(InputError, match="holds the runs of a pressure-driven verify, not "
                                         "of --drive stroke"):
        vs.run_verify_stroke(cube, 2, mesh="coarse")
    assert main(["verify", str(cube), "--designs", "2", "--drive", "stroke"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pressure-driven" in err[0]
    # and the other way round
    shutil.rmtree(vs.stroke_parts(cube))
    shutil.rmtree(pressure_parts)
    vs.run_verify_stroke(cube, 2, mesh="coarse")
    shutil.copytree(vs.stroke_parts(cube), pressure_parts)
    with pytest.raises(InputError, match="holds the runs of a stroke-driven verify, not "
                                         "of --drive pressure"):
        verify.run_verify(cube, 2, mesh="coarse")


@pytest.mark.parametrize("args, match", [
    (["--blocked"], "--blocked: only with --drive stroke"),
    (["--blocked", "--drive", "pressure"], "--blocked: only with --drive stroke"),
    (["--drive", "strain"], "--drive: must be pressure or stroke, got 'strain'"),
])
def test_bad_drive_flags_exit_2_with_one_line(cube, args, match, capsys):
    from nylonflex.cli import main

    assert main(["verify", str(cube), "--designs", "2", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0]


@pytest.mark.slow
def test_a_killed_stroke_verify_resumes_to_the_uninterrupted_dataset(tmp_path):
    """A real (coarse) stroke-driven verify of 2 designs killed after its first FE run is
    journaled, then run again: it solves only the other and writes the dataset an
    uninterrupted run writes."""
    grid = dict(GRID["grid"], radius={"values": [12, 15], "units": "mm"},
                wall_thickness={"values": [3, 4], "units": "mm"})
    cubes = [write_cube(tmp_path / name, dict(GRID, grid=grid)) for name in ("a", "b")]
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}

    def cmd(cube):
        return [sys.executable, "-m", "nylonflex", "verify", str(cube), "--designs", "2",
                "--mesh", "coarse", "--quiet", "--seed", "7", "--drive", "stroke"]

    parts = vs.stroke_parts(cubes[0])
    proc = subprocess.Popen(cmd(cubes[0]), env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE)
    deadline = time.monotonic() + 900
    while time.monotonic() < deadline and not list(parts.glob("design-*.json")):
        time.sleep(1)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert len(list(parts.glob("design-*.json"))) == 1
    out = subprocess.run(cmd(cubes[0]), env=env, capture_output=True, text=True,
                         timeout=1800)
    assert out.returncode == 0, out.stderr
    assert "resuming: 1 of 2" in out.stderr
    whole = subprocess.run(cmd(cubes[1]), env=env, capture_output=True, text=True,
                           timeout=1800)
    assert whole.returncode == 0, whole.stderr
    resumed, uninterrupted = (_load(vs.stroke_path(c)) for c in cubes)
    assert resumed.equals(uninterrupted)
    assert np.isfinite(resumed["stroke_fe_pressure"].values).all()


def test_each_model_is_held_against_the_twin_at_its_own_full_stroke(tmp_path, monkeypatch):
    """sealed_chamber's s* is longer where the paper's muscle breaks first (the 20/6 mm
    chamber at C 1.1 here): the twin is marched through both strokes and each model's ratio
    takes the twin at its own s*."""
    cube = write_cube(tmp_path, {**GRID, "model": ["paper", "sealed_chamber"]})

    def solve(task):  # a stand-in twin whose values are the stroke's multiples
        d = task[0]
        s = np.asarray(d["strokes"], dtype=float)
        return {"pressure": (1e5 * s).tolist(), "bend_angle": (10 * s).tolist(),
                "discretisation_error": [0.0] * len(s), "coarser_pressure": (1e5 * s).tolist(),
                "coarser_bend_angle": (10 * s).tolist()}

    monkeypatch.setattr(vs, "_solve_stroke", solve)
    fid = _load(vs.run_verify_stroke(cube, 12, mesh="coarse"))
    plan = json.loads((cube.with_name(cube.name + ".fidelity_stroke.parts")
                       / "plan.json").read_text())
    own = fid["stroke_model_stroke"]
    paper_s = fid["stroke"].values
    np.testing.assert_array_equal(own.sel(model="paper").values, paper_s)
    sealed_s = own.sel(model="sealed_chamber").values
    longer = sealed_s > paper_s * (1 + 1e-9)
    assert longer.any() and np.isfinite(sealed_s).all()
    for k in np.flatnonzero(longer):  # both strokes solved, the paper's first
        assert plan["designs"][k]["strokes"][0] == paper_s[k]
        assert sealed_s[k] in plan["designs"][k]["strokes"]
    for model, s in (("paper", paper_s), ("sealed_chamber", sealed_s)):
        np.testing.assert_allclose(fid["stroke_model_bend_angle_max"].sel(model=model).values
                                   / fid["stroke_bend_ratio"].sel(model=model).values,
                                   10 * s, rtol=1e-12)
