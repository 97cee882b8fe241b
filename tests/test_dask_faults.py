"""Dask faults (issue 16): every worker gone -> the stall watchdog's one line, exit 1, and
--resume finishes; the scheduler killed mid-run -> one line, no traceback.

Real processes: a ``dask scheduler``, a ``dask worker --no-nanny`` (so that a killed worker
stays dead) and the sweep itself, killed from here once the journal holds a slab. Slow:
some 10-20 s each.
"""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip("distributed")

from nylonflex.storage import Journal  # noqa: E402

pytestmark = pytest.mark.slow

#: Seventy-odd slabs of about 1 MB: a run of several seconds on one worker.
CONFIG = """\
name: faults
grid:
  radius:         {start: 5, stop: 25, num: 640, units: mm}
  wall_thickness: {start: 1, stop: 6, num: 10, units: mm}
  length:         {values: [60, 90]}
  coil_index:     {values: [1.1, 1.25, 1.4, 1.55, 1.7]}
  wrap_angle:     {start: 2, stop: 30, num: 10, units: deg}
curves:
  stroke:   {start: 0, stop: 0.1, num: 11}
  pressure: {start: 0, stop: 40, num: 21, units: kPa}
slab_megabytes: 1
"""
ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


def _env(**extra):
    env = dict(os.environ, PYTHONPATH=str(ROOT), **extra)
    return env


def _port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start(args, log):
    return subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT, env=_env(),
                            start_new_session=True)


def _stop(proc):
    if proc.poll() is None:
        os.killpg(proc.pid, signal.SIGKILL)
    proc.wait(timeout=30)


@pytest.fixture
def scheduler(tmp_path):
    port = _port()
    log = open(tmp_path / "scheduler.log", "w")
    proc = _start([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port",
                   str(port), "--no-dashboard"], log)
    deadline = time.monotonic() + 60
    while True:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                break
        assert time.monotonic() < deadline and proc.poll() is None, "no scheduler"
        time.sleep(0.2)
    yield proc, f"tcp://127.0.0.1:{port}"
    _stop(proc)
    log.close()


def _worker(address, tmp_path, name):
    log = open(tmp_path / f"{name}.log", "w")
    return _start([str(BIN / "dask"), "worker", address, "--nthreads", "1", "--no-nanny",
                   "--no-dashboard", "--name", name, "--local-directory",
                   str(tmp_path / name)], log)


def _sweep(cfg, out, address, *extra):
    return subprocess.Popen(
        [sys.executable, "-m", "nylonflex", "sweep", str(cfg), "--out", str(out),
         "--scheduler", address, "--quiet", "--no-charts", *extra],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=_env(NYLONFLEX_DASK_STALL="3"), start_new_session=True)


def _after_first_slab(out, run, then):
    """Call ``then()`` once the journal of ``out`` holds a slab (the run still going)."""
    deadline = time.monotonic() + 240
    while not Journal(out).done():
        assert run.poll() is None, run.communicate()
        assert time.monotonic() < deadline, "no slab journaled"
        time.sleep(0.05)
    then()


def _assert_one_line(err):
    assert "Traceback" not in err, err
    lines = [line for line in err.splitlines() if line.startswith("nylonflex sweep:")]
    assert len(lines) == 1, err
    return lines[0]


def _break_after_first_slab(tmp_path, address, fault):
    """Sweep ``CONFIG`` on one worker; ``fault(worker)`` once a slab is journaled.

    Returns the config path, the cube path, the sweep's exit status and its stderr.
    """
    cfg = tmp_path / "faults.yaml"
    cfg.write_text(CONFIG)
    out = tmp_path / "cube.h5"
    worker = _worker(address, tmp_path, "w1")
    try:
        run = _sweep(cfg, out, address)
        _after_first_slab(out, run, lambda: fault(worker))
        _, err = run.communicate(timeout=120)
    finally:
        _stop(worker)
    return cfg, out, run.returncode, err


def test_every_worker_gone_stops_on_the_watchdog_and_resumes(tmp_path, scheduler):
    _, address = scheduler
    cfg, out, returncode, err = _break_after_first_slab(tmp_path, address, _stop)
    assert returncode == 1, err
    line = _assert_one_line(err)
    assert "no Dask worker is alive" in line and "--resume" in line
    assert not out.exists() and Journal(out).done()
    worker = _worker(address, tmp_path, "w2")
    try:
        again = _sweep(cfg, out, address, "--resume")
        got, err = again.communicate(timeout=240)
    finally:
        _stop(worker)
    assert again.returncode == 0, err
    assert "complete" in got and out.exists()


def test_a_killed_scheduler_is_one_line_and_no_traceback(tmp_path, scheduler):
    proc, address = scheduler
    _, out, returncode, err = _break_after_first_slab(tmp_path, address,
                                                      lambda worker: _stop(proc))
    assert returncode == 1, err
    line = _assert_one_line(err)
    assert "--resume" in line, line
    assert not out.exists() and Journal(out).done()
