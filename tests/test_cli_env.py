"""Issue 46, item 4: the environment's problems exit 2 with one line (a folder that refuses
the write, a missing extra, a damaged chunk named), and a closed output pipe (``nylonflex
list | head -1``) ends every command quietly with 0 (one mechanism, cli/__init__.py)."""

import errno
import os
import subprocess
import sys

import h5py
import pytest
from helpers import TINY, run, write_config, write_cube

from nylonflex.cli import environment_problem


@pytest.fixture(scope="module")
def cube(tmp_path_factory):
    return write_cube(tmp_path_factory.mktemp("env"), TINY)


@pytest.mark.parametrize("code, words", [(errno.EACCES, "permission denied"),
                                         (errno.EROFS, "a read-only file system"),
                                         (errno.ENOSPC, "no space left on the device")])
def test_a_folder_that_refuses_the_write_is_the_environment(code, words):
    exc = OSError(code, "x", "ro/cube.h5")
    todo = "free some space there, or write somewhere else (--out)" \
        if code == errno.ENOSPC else "write somewhere else (--out)"
    assert environment_problem(exc) == f"cannot write ro/cube.h5: {words}; {todo}"
    assert environment_problem(OSError(errno.EIO, "x")) is None  # a real failure stays 1
    assert environment_problem(RuntimeError("bug")) is None


def test_a_sweep_into_a_read_only_folder_exits_2_with_one_line(tmp_path, capsys,
                                                                monkeypatch):
    # root ignores the mode bits, so the folder's refusal is the write's own exception
    import nylonflex.sweep.conductor as sweep

    def refuse(*a, **k):
        raise PermissionError(errno.EACCES, "Permission denied", str(tmp_path / "ro" / "c.h5"))

    monkeypatch.setattr(sweep, "sweep_file", refuse)
    cfg = write_config(tmp_path, TINY)
    rc, out, err = run(capsys, "sweep", cfg, "--out", tmp_path / "ro" / "c.h5", "--quiet")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert err.strip() == (f"nylonflex sweep: error: cannot write {tmp_path}/ro/c.h5: "
                           "permission denied; write somewhere else (--out)")


def test_a_sweep_into_a_read_only_file_system_exits_2_with_one_line(tmp_path):
    # a read-only tmpfs in a user namespace, where the platform allows it (root or not)
    ro = tmp_path / "ro"
    ro.mkdir()
    probe = subprocess.run(["unshare", "-rm", "sh", "-c",
                            f"mount -t tmpfs -o size=1m,ro tmpfs {ro} && echo ok"],
                           capture_output=True, text=True)
    if probe.stdout.strip() != "ok":
        pytest.skip("no unprivileged read-only mount here")
    cfg = write_config(tmp_path, TINY)
    script = (f"mount -t tmpfs -o size=1m,ro tmpfs {ro} && {sys.executable} -m nylonflex "
              f"sweep {cfg} --out {ro}/sub/cube.h5 --quiet --no-charts")
    proc = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True,
                          text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.strip().splitlines()[-1] == (
        f"nylonflex sweep: error: cannot write {ro}/sub: a read-only file system; write "
        "somewhere else (--out)")


def test_a_missing_extra_names_what_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "zstandard", None)  # as if not installed
    cfg = write_config(tmp_path, {**TINY, "compression": "zstd"})
    rc, out, err = run(capsys, "sweep", cfg, "--out", tmp_path / "z.h5", "--quiet",
                       "--no-charts")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert "pip install 'nylonflex[zstd]'" in err and "RuntimeError" not in err
    exc = ModuleNotFoundError("No module named 'felupe'", name="felupe")
    assert environment_problem(exc) == ("needs the optional package felupe: pip install "
                                        "'nylonflex[fe]'")


def test_a_damaged_chunk_is_named_and_exits_2(cube, tmp_path, capsys):
    bad = tmp_path / "bad.h5"
    bad.write_bytes(cube.read_bytes())
    with h5py.File(bad, "r") as f:
        info = f["tip_force_max"].id.get_chunk_info(0)
    with open(bad, "r+b") as fh:  # scribble over the compressed bytes of one chunk
        fh.seek(info.byte_offset + 8)
        fh.write(b"\xff" * min(64, info.size - 8))
    rc, out, err = run(capsys, "query", bad, "--where", "tip_force_max >= 0.1 N")
    assert rc == 2 and len(err.strip().splitlines()) == 1
    assert err.startswith(f"nylonflex query: error: {bad}: variable tip_force_max [")
    assert "OSError" not in err


@pytest.mark.parametrize("argv", [["list", "variables"], ["list", "materials"],
                                  ["info", "CUBE"], ["query", "CUBE", "--limit", "all"]])
def test_a_closed_pipe_ends_every_command_quietly_with_0(cube, argv):
    argv = [str(cube) if a == "CUBE" else a for a in argv]
    # the reader exits at once (as head -1 does once it has its line): every write fails
    q = subprocess.run(["bash", "-c", f"{sys.executable} -m nylonflex {' '.join(argv)} | "
                        "true; echo ${PIPESTATUS[0]}"], capture_output=True, text=True)
    assert q.stdout.strip() == "0", q.stderr
    assert q.stderr == ""
