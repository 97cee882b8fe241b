"""``nylonflex verify``: the sample, the journal and resume, the fidelity dataset and map.

The FE runs themselves are replaced here by a stand-in with known angles (the FE twin is
tested in tests/test_fe.py); one real, coarse verify that is killed and resumed is
slow-marked.
"""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest
import xarray as xr

import nylonflex.fe.verify as verify
from helpers import write_cube
from nylonflex.units import InputError

pytest.importorskip("felupe")

GRID = {
    "name": "fid",
    "grid": {"radius": {"values": [7.5, 12, 20], "units": "mm"},
             "wall_thickness": {"values": [2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}},
}


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("fid"), GRID)


def _fake(calls):
    def solve(task):
        d, sil, mesh = task
        calls.append(d["radius"])
        # an FE angle 1.5 times the paper's: every ratio of paper is 1/1.5
        import nylonflex as nf

        ang = nf.bend_angle(d["pressures"], d["radius"], d["wall_thickness"], d["length"])
        # both meshes alike: their Richardson extrapolation is that angle too
        return {"bend_angle": list(1.5 * np.asarray(ang)),
                "coarser_bend_angle": list(1.5 * np.asarray(ang)),
                "discretisation_error": [0.01] * 2}
    return solve


def test_the_sample_holds_the_paper_examples_and_fills_the_axes(cube):
    ds = xr.open_dataset(cube, engine="h5netcdf")
    designs = verify.sample_designs(ds, 12, seed=3)
    assert len(designs) == 12
    assert designs[0]["radius"] == 20e-3 and designs[1]["radius"] == 7.5e-3
    for axis in verify.AXES:
        values = [d[axis] for d in designs]
        assert float(ds[axis].min()) - 1e-12 <= min(values)
        assert max(values) <= float(ds[axis].max()) + 1e-12
    ds.close()


def test_verify_writes_ratios_and_resumes_only_what_is_missing(cube, monkeypatch):
    calls = []
    monkeypatch.setattr(verify, "_solve", _fake(calls))
    path = verify.run_verify(cube, 5, mesh="coarse")
    assert len(calls) == 5
    fid = xr.open_dataset(path, engine="h5netcdf").load()
    np.testing.assert_allclose(fid["ratio"].sel(model="paper").values, 1 / 1.5, rtol=1e-9)
    assert (fid["ratio"].sel(model="lateral_pressure").values > 1 / 1.5).all()
    assert fid["pressure"].attrs["units"] == "Pa" and fid.attrs["fe_mesh"] == "coarse"
    # a killed run: two journaled designs gone; only they are solved again
    parts = cube.with_name(cube.name + ".fidelity.parts")
    (parts / "design-0001.json").unlink()
    (parts / "design-0003.json").unlink()
    calls.clear()
    messages = []
    verify.run_verify(cube, 5, mesh="coarse", log=messages.append)
    assert len(calls) == 2 and "resuming: 3 of 5" in messages[0]
    # another sample in the same folder is refused, not mixed
    with pytest.raises(InputError, match="holds the runs of another verify"):
        verify.run_verify(cube, 6, mesh="coarse")
    # and so are the runs of another version of the FE model (its constants in the plan)
    import nylonflex.fe.model as fe_model

    assert fid.attrs["fe_model"] == json.dumps(fe_model.model_settings(), sort_keys=True)
    monkeypatch.setattr(fe_model, "COMPRESSION_RATIO", 1.0)
    with pytest.raises(InputError, match="holds the runs of another verify"):
        verify.run_verify(cube, 5, mesh="coarse")


def test_fidelity_map_and_info(cube, monkeypatch, tmp_path):
    from nylonflex.charts.fidelity import fidelity_map
    from nylonflex.cli import main

    monkeypatch.setattr(verify, "_solve", _fake([]))
    path = verify.run_verify(cube, 5, mesh="coarse")
    fig = fidelity_map(xr.open_dataset(path, engine="h5netcdf").load())
    assert len(fig.axes) == 5  # four models and the colour bar
    fig.savefig(tmp_path / "map.png")
    assert main(["info", str(cube)]) == 0


@pytest.mark.parametrize("kw,match", [({"designs": 0}, r"--designs: must be an integer in"),
                                      ({"designs": 10**6}, r"--designs"),
                                      ({"mesh": "huge"}, r"--mesh: must be one of"),
                                      ({"workers": 0}, r"--workers")])
def test_bad_input_is_refused(cube, kw, match):
    args = {"designs": 3, **kw}
    with pytest.raises(InputError, match=match):
        verify.run_verify(cube, args.pop("designs"), **args)


@pytest.mark.slow
def test_a_killed_verify_resumes(tmp_path):
    """A real (coarse) verify of 2 designs, killed after its first FE run is journaled,
    then run again: it solves only the other one and writes the dataset."""
    # away from the paper's examples (the FE stalls before the second's 214 deg at p*), and
    # at C 1.1 alone: p* = 11.9 kPa, half of C 1.7's, so the two solves take half the steps
    grid = dict(GRID["grid"], radius={"values": [12, 15], "units": "mm"},
                wall_thickness={"values": [3, 4], "units": "mm"},
                coil_index={"values": [1.1]})
    cube = write_cube(tmp_path, dict(GRID, grid=grid))
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    cmd = [sys.executable, "-m", "nylonflex", "verify", str(cube), "--designs", "2",
           "--mesh", "coarse", "--quiet", "--seed", "7"]
    parts = cube.with_name(cube.name + ".fidelity.parts")
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 900
    while time.monotonic() < deadline and not list(parts.glob("design-*.json")):
        time.sleep(1)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    done = list(parts.glob("design-*.json"))
    assert len(done) == 1
    out = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=1800)
    assert out.returncode == 0, out.stderr
    assert "resuming: 1 of 2" in out.stderr
    fid = xr.open_dataset(verify.fidelity_path(cube), engine="h5netcdf")
    # every design solved at half its p* (at p* a large bend may stall the FE: NaN)
    assert np.isfinite(fid["fe_bend_angle"].sel(level=0.5).values).all()
    # the FE angle is the Richardson extrapolation of the mesh's: a little further
    half = fid.sel(level=0.5)
    assert (half["fe_bend_angle"] >= half["fe_mesh_bend_angle"]).all()
    json.loads((parts / "plan.json").read_text())


@pytest.mark.parametrize("flag", ["--designs", "--workers", "--seed"])
def test_a_non_integer_flag_is_one_line_naming_it(flag, capsys, tmp_path):
    from nylonflex.cli import main

    with pytest.raises(SystemExit) as stop:  # argparse's own exit, status 2
        main(["verify", str(tmp_path / "c.h5"), flag, "abc"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and f"argument {flag}: must be an integer, got 'abc'" in err[0]


_INTERRUPTED_POOL = """
import signal, sys, time
sys.path.insert(0, sys.argv[1])


def stop(signum, frame):  # what the command line does with SIGTERM (and Ctrl-C)
    raise KeyboardInterrupt


signal.signal(signal.SIGTERM, stop)
from nylonflex.fe.runs import journaled_runs
import slowsolve

tasks = [{"k": k} for k in range(6)]
start = time.monotonic()
try:
    journaled_runs(sys.argv[2], {"designs": tasks}, tasks, slowsolve.solve, workers=2)
except KeyboardInterrupt:
    print("stopped after", round(time.monotonic() - start, 1), flush=True)
"""


def test_an_interrupted_pool_stops_its_runs_at_once(tmp_path):
    # a stop of the parent (SIGTERM here: a background job ignores SIGINT) ends the queued
    # and running FE runs instead of waiting for them (minutes each); the journaled stay
    (tmp_path / "slowsolve.py").write_text(
        "import time\n"
        "def solve(task):\n"
        "    time.sleep(0.5 if task['k'] == 0 else 60)\n"
        "    return {'k': task['k']}\n")
    parts = tmp_path / "runs.parts"
    proc = subprocess.Popen([sys.executable, "-c", _INTERRUPTED_POOL, str(tmp_path),
                             str(parts)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and not (parts / "design-0000.json").exists():
        time.sleep(0.2)
    assert (parts / "design-0000.json").exists()
    proc.send_signal(signal.SIGTERM)
    out, err = proc.communicate(timeout=30)  # not the 60 s of the runs still going
    assert "stopped after" in out, err
    assert sorted(p.name for p in parts.glob("design-*.json")) == ["design-0000.json"]
