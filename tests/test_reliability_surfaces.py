"""Reliability of the newer surfaces (issue 48): verify and fit fe run folders, the
fidelity outputs, init, bounds, hangs and the explorer's server.

A full disk is a real one: a small tmpfs mounted in a user namespace (``unshare -rm``),
each run in its own process, so that a segfault is seen as exit 139, not as a lost test.
"""

import os
import subprocess
import sys
from pathlib import Path

import pytest
from helpers import write_config

from nylonflex.cli import main

#: The sweep of tests/test_reliability.py's MULTI: 64,800 designs in 6 slabs, 3.4 MB.
BIG = {
    "name": "big",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 18, "units": "mm"},
        "wall_thickness": {"start": 1, "stop": 6, "num": 30, "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"start": 3, "stop": 30, "num": 30, "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
    "slab_megabytes": 1,
}


def _env():
    return {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}


def on_tiny_disk(mount, kib, command, timeout=300):
    """Run the shell ``command`` with a ``kib`` KiB tmpfs mounted at ``mount`` (a user
    namespace of its own); (exit status, stderr). A segfault of Python is status 139."""
    script = f"mount -t tmpfs -o size={kib}k tmpfs {mount} && cd {mount} && {command}"
    proc = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True,
                          text=True, timeout=timeout, env=_env())
    return proc.returncode, proc.stderr


@pytest.fixture
def mount(tmp_path):
    """An empty folder a tmpfs can be mounted on; skipped where no namespace allows it."""
    where = tmp_path / "mnt"
    where.mkdir()
    probe = subprocess.run(["unshare", "-rm", "sh", "-c",
                            f"mount -t tmpfs -o size=1m tmpfs {where} && echo ok"],
                           capture_output=True, text=True)
    if probe.stdout.strip() != "ok":
        pytest.skip("no unprivileged tmpfs mount here")
    return where


# --------------------------------------------------------------------------- 1. full disks

@pytest.mark.slow
def test_a_disk_that_fills_anywhere_in_a_sweep_never_crashes_it(tmp_path, mount):
    # The disk is sized to fill at 30 points of the sweep's last 120 KiB (the publishing
    # close): before the fix 13 of these 30 runs segfaulted (exit 139) in CubeFile.abandon,
    # HDF5 freeing the ids of a close that had failed partway.
    cfg = write_config(tmp_path, BIG, "big.yaml")
    whole = tmp_path / "whole" / "cube.h5"
    assert main(["sweep", str(cfg), "--out", str(whole), "--quiet", "--no-charts"]) == 0
    # the peak is the cube and the journal's records (journal format 5 keeps where the
    # chunks lie, not the chunks): this sweep needed the cube and 221-232 KiB on a
    # tmpfs. The 30 sizes go from the cube and 164 KiB to the cube and 280 KiB, so about
    # half of the runs meet a full disk, at the publishing close among other points
    need = whole.stat().st_size // 1024 + 280
    sweep = (f"{sys.executable} -X faulthandler -m nylonflex sweep {cfg} --out "
             f"{mount}/cube.h5 --quiet --no-charts")
    outcomes = [(kib, *on_tiny_disk(mount, kib, sweep)) for kib in range(need, need - 120, -4)]
    # a full disk is the environment's problem: exit 2 and one line (issue 46)
    crashed = [(kib, rc, err[-300:]) for kib, rc, err in outcomes if rc not in (0, 2)]
    assert not crashed, crashed
    full = [err for _, rc, err in outcomes if rc == 2]
    assert full and all("Traceback" not in e and "--resume" in e for e in full)


_FIDELITY = """
import sys
import numpy as np, xarray as xr
from nylonflex.fe.verify import write_fidelity
n = 500
fid = xr.Dataset({f"v{i}": (("design", "level"), np.random.rand(n, 2)) for i in range(12)},
                 coords={"design": np.arange(n), "level": [0.5, 1.0]})
write_fidelity(fid, sys.argv[1])
"""


@pytest.mark.slow
def test_verify_writing_its_dataset_on_a_full_disk_never_crashes(tmp_path, mount):
    # before the fix all 18 runs under 150 KiB segfaulted (h5netcdf's close on a full disk)
    script = tmp_path / "fidelity.py"
    script.write_text(_FIDELITY)
    runs = [(kib, *on_tiny_disk(mount, kib, f"{sys.executable} {script} {mount}/c.nc",
                                timeout=120)) for kib in range(8, 248, 8)]
    assert not [(kib, rc) for kib, rc, _ in runs if rc not in (0, 1)], runs
    failed = [err for _, rc, err in runs if rc == 1]
    assert failed and all("No space left" in e for e in failed)
    assert [rc for _, rc, _ in runs][-1] == 0  # the largest disk holds it


def test_init_on_a_full_disk_leaves_no_truncated_file(mount):
    # 12-40 KiB: the disk fills inside one of init's files (45 KB in all)
    for kib in (12, 24, 40):
        rc, err = on_tiny_disk(mount, kib, f"{sys.executable} -m nylonflex init x; "
                                           "s=$?; find . | wc -l >&2; exit $s")
        assert rc == 2 and "no space left" in err.lower(), (kib, err)
        assert err.split()[-1] == "1", (kib, err)  # only the mount itself is left
    rc, err = on_tiny_disk(mount, 40, f"{sys.executable} -m nylonflex init x "
                                      "--example fig12 && test -s x/configs/fig12.yaml")
    assert rc == 0, err


def test_init_leaves_nothing_when_a_file_cannot_be_written(tmp_path, monkeypatch, capsys):
    import errno

    import nylonflex.files.atomic as files

    real, calls = files._link_new, []

    def fail_third(tmp, path):
        calls.append(path)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        real(tmp, path)

    monkeypatch.setattr(files, "_link_new", fail_third)
    assert main(["init", str(tmp_path / "x")]) == 2  # the environment's problem (issue 46)
    assert "no space left" in capsys.readouterr().err.lower()
    assert not (tmp_path / "x").exists()  # files, temporaries and the folders it made


@pytest.mark.parametrize("target", ["a file", "a dangling link", "a file where a folder goes",
                                    "/proc/self"])
def test_init_at_a_path_that_is_no_folder_is_one_line(tmp_path, capsys, target):
    path = {"a file": tmp_path / "f", "a dangling link": tmp_path / "l",
            "a file where a folder goes": tmp_path / "d", "/proc/self": Path("/proc/self")}
    (tmp_path / "f").write_text("mine")
    (tmp_path / "l").symlink_to(tmp_path / "nowhere")
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "configs").write_text("mine")
    assert main(["init", str(path[target])]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "init" in err and "Traceback" not in err
    assert (tmp_path / "f").read_text() == "mine"
    assert (tmp_path / "d" / "configs").read_text() == "mine"


# --------------------------------------------------------------------------- 2. run folders

def _plan(seed=0):
    designs = [{"radius": 0.01 * (k + 1), "pressures": [1e3 * (k + 1), 2e3 * (k + 1)]}
               for k in range(4)]
    return {"designs": designs, "mesh": "coarse", "seed": seed}


def _solver(calls):
    def solve(task):
        calls.append(task["radius"])
        return {"bend_angle": [task["radius"] * p for p in task["pressures"]],
                "coarser_bend_angle": [0.5, None]}
    return solve


def _runs(parts, calls, plan=None, log=None):
    from nylonflex.fe.runs import journaled_runs

    plan = plan or _plan()
    return journaled_runs(parts, plan, plan["designs"], _solver(calls), log=log)


def _swap(parts):
    a, b = parts / "design-0001.json", parts / "design-0002.json"
    ta, tb = a.read_bytes(), b.read_bytes()
    a.write_bytes(tb)
    b.write_bytes(ta)


def _one_digit(parts):
    f = parts / "design-0001.json"
    text = f.read_text()
    i = text.index('"bend_angle": [') + len('"bend_angle": [')
    assert text[i].isdigit()
    f.write_text(text[:i] + ("7" if text[i] != "7" else "8") + text[i + 1:])


CORRUPTIONS = {
    "an empty mapping": lambda p: (p / "design-0001.json").write_text("{}"),
    "a list": lambda p: (p / "design-0001.json").write_text("[1, 2]"),
    "a bare number": lambda p: (p / "design-0001.json").write_text("3.5"),
    "a string": lambda p: (p / "design-0001.json").write_text('"bend_angle"'),
    "deep nesting": lambda p: (p / "design-0001.json").write_text("[" * 100000 + "]" * 100000),
    "not JSON": lambda p: (p / "design-0001.json").write_bytes(b"\xff\x00{"),
    "short arrays": lambda p: (p / "design-0001.json").write_text(json_swap_short(p)),
    "one digit changed": _one_digit,
    "two runs swapped": _swap,
    "a huge file": lambda p: (p / "design-0001.json").write_text(" " * (2 << 20) + "{}"),
}


def json_swap_short(parts):
    import json

    record = json.loads((parts / "design-0001.json").read_text())
    record["result"]["bend_angle"] = record["result"]["bend_angle"][:1]
    return json.dumps(record)


@pytest.mark.parametrize("corruption", CORRUPTIONS)
def test_a_damaged_run_file_is_solved_again(tmp_path, corruption):
    parts, calls = tmp_path / "runs.parts", []
    first = _runs(parts, calls)
    assert len(calls) == 4
    CORRUPTIONS[corruption](parts)
    calls.clear()
    messages = []
    again = _runs(parts, calls, log=messages.append)
    redone = {0.02, 0.03} if corruption == "two runs swapped" else {0.02}
    assert set(calls) == redone, messages
    assert again == first
    assert any("solving it again" in m for m in messages)
    calls.clear()
    assert _runs(parts, calls) == first and not calls  # and it is whole now


def test_a_run_folder_of_another_plan_is_refused(tmp_path):
    from nylonflex.units import InputError

    parts = tmp_path / "runs.parts"
    _runs(parts, [])
    with pytest.raises(InputError, match="holds the runs of another"):
        _runs(parts, [], plan=_plan(seed=1))
    # a run file of another plan copied in is solved again, never used
    other = tmp_path / "other.parts"
    plan = _plan()
    plan["designs"][1]["pressures"][0] = 1234.0
    _runs(other, [], plan=plan)
    (parts / "design-0001.json").write_bytes((other / "design-0001.json").read_bytes())
    calls = []
    _runs(parts, calls)
    assert calls == [0.02]


@pytest.mark.parametrize("what", ["a file", "a dangling link", "a fifo run file",
                                  "a linked run file", "a fifo plan"])
def test_a_run_folder_that_is_no_folder_is_one_line(tmp_path, what):
    from nylonflex.units import InputError

    parts = tmp_path / "runs.parts"
    if what == "a file":
        parts.write_text("mine")
    elif what == "a dangling link":
        parts.symlink_to(tmp_path / "nowhere")
    else:
        _runs(parts, [])
        target = parts / ("plan.json" if what == "a fifo plan" else "design-0002.json")
        target.unlink()
        if what == "a linked run file":
            target.symlink_to(tmp_path / "elsewhere.json")
        else:
            os.mkfifo(target)
    with pytest.raises(InputError) as err:  # at once: a fifo is never opened to wait
        _runs(parts, [])
    assert "\n" not in str(err.value) and str(parts) in str(err.value)
    if what == "a file":
        assert parts.read_text() == "mine"


# --------------------------------------------------------------------------- 3. verify's files

FID_GRID = {
    "name": "fid",
    "grid": {"radius": {"values": [7.5, 20], "units": "mm"},
             "wall_thickness": {"values": [2, 6], "units": "mm"},
             "length": {"values": [70, 90], "units": "mm"},
             "coil_index": {"values": [1.1, 1.7]},
             "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 20, "num": 3, "units": "kPa"}},
}


@pytest.fixture
def fid_cube(tmp_path, monkeypatch):
    """A small cube, and verify's FE runs replaced by a stand-in (their count in .calls)."""
    pytest.importorskip("felupe")
    from helpers import write_cube

    import nylonflex.fe.verify as verify

    calls = []

    def solve(task):
        d = task[0]
        calls.append(d["radius"])
        return {k: [0.1, 0.2] for k in verify.RUN_KEYS}

    monkeypatch.setattr(verify, "_solve", solve)
    return write_cube(tmp_path, FID_GRID), calls


def _verify(cube, *extra):
    return main(["verify", str(cube), "--designs", "2", "--quiet", *extra])


def test_verify_replaces_only_its_own_outputs(fid_cube, capsys):
    fid_cube, calls = fid_cube
    nc = fid_cube.with_name("cube.fidelity.nc")
    png = fid_cube.with_name("cube.fidelity_map.png")
    assert _verify(fid_cube) == 0 and nc.is_file() and png.is_file()
    assert _verify(fid_cube) == 0  # its own: replaced
    for mine in (nc, png):
        mine.write_bytes(b"the user's own file")
        capsys.readouterr()
        calls.clear()
        assert _verify(fid_cube) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and str(mine) in err and "--overwrite" in err
        assert mine.read_bytes() == b"the user's own file" and not calls
        assert _verify(fid_cube, "--overwrite") == 0
        assert mine.read_bytes() != b"the user's own file"


@pytest.mark.parametrize("what", ["a link at the dataset", "a fifo at the map",
                                  "a link at the run folder", "a file at the run folder"])
def test_verify_refuses_special_outputs_before_work(fid_cube, capsys, what):
    fid_cube, calls = fid_cube
    nc = fid_cube.with_name("cube.fidelity.nc")
    png = fid_cube.with_name("cube.fidelity_map.png")
    parts = fid_cube.with_name("cube.h5.fidelity.parts")
    elsewhere = fid_cube.with_name("elsewhere")
    {"a link at the dataset": lambda: nc.symlink_to(elsewhere),
     "a fifo at the map": lambda: os.mkfifo(png),
     "a link at the run folder": lambda: parts.symlink_to(elsewhere),
     "a file at the run folder": lambda: parts.write_text("mine")}[what]()
    capsys.readouterr()
    assert _verify(fid_cube, "--overwrite") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not calls and not elsewhere.exists()


# --------------------------------------------------------------------------- 4. bounds, hangs

SMALL = {**BIG, "name": "small", "grid": {**BIG["grid"],
                                          "radius": {"values": [5, 10], "units": "mm"},
                                          "wall_thickness": {"values": [1, 2], "units": "mm"}}}


def _curve(stop=None, step=None):
    raw = {**SMALL, "curves": dict(SMALL["curves"])}
    if stop is not None:
        raw["curves"]["pressure"] = {"start": 0, "stop": stop, "num": 5, "units": "kPa"}
    return raw


@pytest.mark.parametrize("raw,field", [
    (_curve(stop=1e308), "curves.pressure.stop"),
    (_curve(stop=1e-308), "curves.pressure"),
    ({**SMALL, "cooling": [["still_air"]]}, "cooling"),
    ({**SMALL, "cooling": [{"set": {"still_air": 1}}]}, "cooling[0].set"),
    ({**SMALL, "cooling": {"set": ["still_air"]}}, "cooling.set"),
    ({**SMALL, "cooling": [{"set": "forced_air", "speed": 1 + i / 100} for i in range(10_000)]},
     "cooling"),
])
def test_bad_numbers_in_a_sweep_config_are_one_line(tmp_path, capsys, raw, field):
    cfg = write_config(tmp_path, raw)
    assert main(["sweep", str(cfg), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"error: {field}" in err, err


@pytest.mark.parametrize("step,words", [("1e-308 ms", "samples"), ("1e308 ms", "must be in")])
def test_a_tracking_step_out_of_any_range_is_one_line(tmp_path, capsys, step, words):
    import yaml

    from nylonflex.examples import example_text

    raw = yaml.safe_load(example_text("fig12_tracking"))
    raw["tracking"]["step"] = step
    assert main(["sweep", str(write_config(tmp_path, raw)), "--dry-run"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "tracking.step" in err and words in err


@pytest.mark.parametrize("step", ["1e308 mm", "1e-308 mm", "100 mm", "0.001 mm"])
def test_a_design_resolution_out_of_its_axis_is_refused(tmp_path, capsys, step):
    from helpers import write_cube

    cube = write_cube(tmp_path, SMALL)  # radius 5-10 mm: steps 0.005-5 mm
    spec = write_config(tmp_path, {"name": "d", "cube": str(cube),
                                   "objectives": [{"max": "tip_force_max"}],
                                   "resolution": {"radius": step}}, "spec.yaml")
    capsys.readouterr()
    assert main(["design", str(spec)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "resolution.radius: must be in [0.005, 5] mm" in err


@pytest.mark.parametrize("pressure", ["1e308", "1e-308", "0:10:1e-308", "0:1e308:1"])
def test_fe_pressures_out_of_any_range_are_one_line(capsys, pressure):
    pytest.importorskip("felupe")
    assert main(["fe", "--at", "radius=20mm,wall_thickness=6mm,length=90mm",
                 "--pressure", pressure]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--pressure" in err


def test_fit_fe_with_too_few_designs_is_refused_before_any_run(tmp_path, capsys,
                                                               monkeypatch):
    pytest.importorskip("felupe")
    import nylonflex.fe.calibrate as calibrate

    monkeypatch.setattr(calibrate, "training_plan", lambda *a: pytest.fail("planned"))
    assert main(["fit", "fe", "--designs", "3", "--out", str(tmp_path / "f.json")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--designs: must be in [6, 500]" in err


def test_verify_at_a_scheduler_that_never_answers_ends_in_one_line(tmp_path):
    # a loopback listener that accepts and never replies (no other address is used)
    import socket
    import time

    from helpers import write_cube

    pytest.importorskip("felupe")
    pytest.importorskip("distributed")
    cube = write_cube(tmp_path, SMALL)
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    port = srv.getsockname()[1]
    try:
        start = time.monotonic()
        proc = subprocess.run([sys.executable, "-m", "nylonflex", "verify", str(cube),
                               "--designs", "2", "--quiet", "--scheduler",
                               f"tcp://127.0.0.1:{port}"], capture_output=True, text=True,
                              timeout=120, env=_env())
        took = time.monotonic() - start
    finally:
        srv.close()
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("\n") == 1 and "--scheduler" in proc.stderr
    assert took < 60, took  # its deadline is 5 s; the rest is the process's start


# --------------------------------------------------------------------------- 5. explorer

_MALFORMED = [
    b"GARBAGE\r\n\r\n",
    b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: abc\r\n\r\n",
    b"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\nConnection: Upgrade"
    b"\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
    b"Origin: http://127.0.0.1:{port}\r\n\r\n",  # no Bokeh subprotocol
    b"GET /ws?bokeh-session-id=zzz HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket"
    b"\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
    b"Sec-WebSocket-Version: 13\r\nOrigin: http://127.0.0.1:{port}\r\n"
    b"Sec-WebSocket-Protocol: bokeh, garbage\r\n\r\n",  # a token that is no token
    b"GET /autoload.js?bokeh-autoload-element=\xff HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
    b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\nX: " + b"a" * 100_000 + b"\r\n\r\n",
    b"POST / HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Length: 10\r\n\r\nabc",  # slow: stops
    b"GET /static/../../etc/passwd HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n",
]


def test_the_explorer_answers_malformed_requests_without_a_traceback(tmp_path):
    pytest.importorskip("bokeh")
    import socket
    import threading
    import time

    from helpers import write_cube

    cube = write_cube(tmp_path, SMALL)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    err = tmp_path / "server.err"
    with open(err, "wb") as fh:
        proc = subprocess.Popen([sys.executable, "-m", "nylonflex", "explore", str(cube),
                                 "--no-browser", "--port", str(port)],
                                stdout=subprocess.PIPE, stderr=fh, text=True, env=_env())
    try:
        assert "serving" in proc.stdout.readline()
        answers = {}

        def ask(i, raw):
            try:
                with socket.create_connection(("127.0.0.1", port), timeout=10) as c:
                    c.sendall(raw.replace(b"{port}", str(port).encode()))
                    answers[i] = c.recv(64)
            except OSError as exc:  # the slow request: no answer while it waits
                answers[i] = exc

        threads = [threading.Thread(target=ask, args=(i, raw))
                   for i, raw in enumerate(_MALFORMED * 2)]
        for t in threads:
            t.start()
        for t in threads:
            t.join(30)
        with socket.create_connection(("127.0.0.1", port), timeout=30) as c:
            c.sendall(b"GET / HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n")
            assert c.recv(64).startswith(b"HTTP/1.1 200")  # still serving the page
        time.sleep(0.5)
        assert proc.poll() is None
    finally:
        proc.terminate()
        proc.wait(30)
    log = err.read_text(errors="replace")
    assert "Traceback" not in log and "Uncaught exception GET /ws" in log, log
    assert all(len(line) < 800 for line in log.splitlines())
    assert sum(isinstance(a, bytes) and a.startswith(b"HTTP/1.1 4") for a in answers.values()) >= 6


def test_fe_runs_at_a_scheduler_without_workers_stop_in_one_line(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    import nylonflex.engine.cluster as cluster

    monkeypatch.setattr(cluster, "WORKER_WAIT", 1.0)
    with distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp",
                                  host="127.0.0.1", dashboard_address=None) as lc:
        with pytest.raises(RuntimeError, match="no Dask worker joined"):
            plan = _plan()
            from nylonflex.fe.runs import journaled_runs

            journaled_runs(tmp_path / "runs.parts", plan, plan["designs"], _solver([]),
                           scheduler=lc.scheduler_address)


def test_a_dry_run_of_several_models_and_coolings_estimates_their_cube(tmp_path, capsys):
    # the estimate chunks each array as the cube stores it: a model (and cooling)
    # dimension included (it indexed a 5-dim array with the 6 dims of the cube once)
    raw = {**SMALL, "model": ["paper", "sealed_chamber"]}
    assert main(["sweep", str(write_config(tmp_path, raw)), "--dry-run"]) == 0
    one = capsys.readouterr().out
    assert main(["sweep", str(write_config(tmp_path, SMALL, "one.yaml")), "--dry-run"]) == 0
    import re

    def raw_bytes(text):  # "(6.73 MB uncompressed"
        number, unit = re.search(r"\(([0-9.]+) (\w+) uncompressed", text).groups()
        return float(number) * {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}[unit]

    assert raw_bytes(one) > 1.5 * raw_bytes(capsys.readouterr().out)  # two models' arrays
