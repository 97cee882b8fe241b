"""Reliability: nothing lost, nothing corrupted, nothing hangs (issue 16).

Each test keeps one finding of the attack on the tool as a regression: the writer's lock,
the journal's verification, the output path, hostile input (alias bombs, deep nesting,
huge grids, implausible materials), Dask listeners that never answer, signals and a full
disk. The fast ones run in-process on small grids; the kill-and-resume loops are slow.
"""

import errno
from pathlib import Path
import fcntl
import os
import random
import resource
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time

import h5py
import json
import numpy as np
import pytest
import xarray as xr
import yaml
from helpers import stable, write_config

import nylonflex.storage.journal as journal_mod
import nylonflex.sweep.run as run_mod
from nylonflex.cli import main
from nylonflex.config import parse_config
from nylonflex.storage import Journal, exclusive, open_cube
from nylonflex.sweep.conductor import run_sweep
from nylonflex.units import InputError
from nylonflex.variables import is_complete

#: 6 slabs of 3 radii (slab_megabytes 1), about a second to sweep.
MULTI = {
    "name": "multi",
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




@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The reference cube of MULTI, swept without interruption."""
    return run_sweep(parse_config(MULTI), tmp_path_factory.mktemp("whole") / "cube.h5")


def interrupted(out, k=3, raw=MULTI, **kwargs):
    """Sweep ``raw`` into ``out``, stopping it (SIGTERM to itself) after ``k`` slabs."""
    original = run_mod.run_slabs

    def run_slabs(cfg, plan, todo, executor, sink, progress=None):
        class Stopping:
            stored = 0

            def put(self, *args):
                sink.put(*args)
                Stopping.stored += 1
                if Stopping.stored == k:
                    os.kill(os.getpid(), signal.SIGTERM)

        return original(cfg, plan, todo, executor, Stopping(), progress)

    run_mod.run_slabs = run_slabs
    try:
        with pytest.raises(KeyboardInterrupt):
            run_sweep(parse_config(raw), out, **kwargs)
    finally:
        run_mod.run_slabs = original


def resume(out, raw=MULTI, log=None):
    return run_sweep(parse_config(raw), out, resume=True, log=log)


# --------------------------------------------------------------------------- 1. two writers

def test_lock_race_unlink_before_release_admits_one_writer(tmp_path, monkeypatch):
    # writer A holds the lock; writer B opened the lock file just before A released it
    # (the injected delay): B's flock then succeeds on the unlinked file. B must notice
    # and lock the file now at the path, so that a third writer C is refused.
    out = tmp_path / "cube.h5"
    a = exclusive(out)
    a.__enter__()
    real_flock = fcntl.flock
    released = []

    def delayed_flock(fd, op):
        if not released and op & fcntl.LOCK_NB and op & fcntl.LOCK_EX:
            released.append(True)
            a.__exit__(None, None, None)  # A releases between B's open and B's flock
        return real_flock(fd, op)

    monkeypatch.setattr(fcntl, "flock", delayed_flock)
    with exclusive(out):
        monkeypatch.setattr(fcntl, "flock", real_flock)
        lock = out.with_name(out.name + ".lock")
        assert lock.exists()
        with pytest.raises(RuntimeError, match="another sweep is writing"):
            with exclusive(out):
                pass


_HOLD = """
import sys, time
import h5py
from nylonflex.storage import exclusive
with exclusive(sys.argv[1]) as building:
    with h5py.File(building, "w", locking=False) as f:
        f["x"] = list(range(1000))
    print("held", flush=True)
    time.sleep(60)
"""


def test_deleting_the_lock_file_does_not_let_a_second_writer_in(tmp_path, capsys):
    out = tmp_path / "cube.h5"
    cfg = write_config(tmp_path, MULTI)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    first = subprocess.Popen([sys.executable, "-c", _HOLD, str(out)], stdout=subprocess.PIPE,
                             env=env)
    try:
        assert first.stdout.readline().strip() == b"held"
        out.with_name("cube.h5.lock").unlink()  # "a stale lock"
        rc = main(["sweep", str(cfg), "--out", str(out), "--resume", "--quiet",
                   "--no-charts"])
        assert rc == 1
        assert "another sweep is writing" in capsys.readouterr().err
        # the first writer's file is untouched, and nothing was published
        with h5py.File(out.with_name("cube.h5.building"), "r", locking=False) as f:
            assert f["x"][-1] == 999
        assert not out.exists()
    finally:
        first.kill()
        first.wait()


# --------------------------------------------------------------------------- 3. the journal

def _tamper_swap(parts):
    a, b = parts / "slab-000000.npz", parts / "slab-000001.npz"
    tmp = parts / "x"
    a.rename(tmp), b.rename(a), tmp.rename(b)


def _tamper_empty(parts):
    (parts / "slab-000001.npz").write_bytes(b"")


def _tamper_deflate(parts):
    p = parts / "slab-000002.npz"
    data = bytearray(p.read_bytes())
    for i in range(len(data) // 3, len(data) // 3 + 64):
        data[i] ^= 0x5A
    p.write_bytes(bytes(data))


def _tamper_arrays(parts):
    # a well-formed slab file whose arrays were changed: only the digest can tell. Journal
    # format 5 keeps each chunk's CRC-32 where format 4 kept its bytes: both are changed
    p = parts / "slab-000000.npz"
    with np.load(p) as z:
        arrays = {k: z[k] for k in z.files}
    key = next(k for k in arrays if k.endswith((":bytes", ":crcs")))
    arrays[key] = arrays[key].copy()
    arrays[key][:8] = 0
    with open(p, "wb") as fh:
        np.savez(fh, **arrays)


def _record(parts, k):
    with np.load(parts / f"slab-{k:06d}.npz") as z:
        return {key: z[key] for key in z.files}


def _tamper_chunk_in_cube(parts):
    # the journal is intact, but a chunk it points to was changed in the (incomplete,
    # published) cube: only the chunk's CRC-32 can tell
    record = _record(parts, 1)
    name = next(k for k in record if k.endswith(":addresses"))
    where, size = int(record[name][0]), int(record[name.replace("addresses", "sizes")][0])
    cube = parts.with_name(parts.name.removesuffix(".parts"))
    with open(cube, "r+b") as fh:
        fh.seek(where + size // 2)
        fh.write(b"\x00\x01\x02\x03")


def _tamper_cube_gone(parts):
    # the files the records point into are gone: every slab is recomputed
    parts.with_name(parts.name.removesuffix(".parts")).unlink()


def _tamper_copy(parts):
    # a slab replaced by a copy of another (the old journal resumed it: 17 % NaN, complete)
    shutil.copy(parts / "slab-000001.npz", parts / "slab-000000.npz")


def _tamper_foreign(parts):
    # a slab replaced by the same slab of another config's journal (old: wrong values)
    other = parts.parent / "other" / "cube.h5"
    other.parent.mkdir()
    interrupted(other, k=1, raw={**MULTI, "silicone": "ecoflex_00_30"})
    shutil.copy(Journal(other).dir / "slab-000000.npz", parts / "slab-000000.npz")


@pytest.mark.parametrize("tamper", [_tamper_swap, _tamper_copy, _tamper_deflate,
                                    pytest.param(_tamper_foreign, marks=pytest.mark.slow),
                                    pytest.param(_tamper_empty, marks=pytest.mark.slow),
                                    pytest.param(_tamper_arrays, marks=pytest.mark.slow),
                                    _tamper_chunk_in_cube,
                                    pytest.param(_tamper_cube_gone, marks=pytest.mark.slow)])
def test_a_tampered_slab_is_recomputed_not_trusted(tmp_path, whole, tamper):
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    tamper(Journal(out).dir)
    messages = []
    ds = resume(out, log=messages.append)
    assert any("recomputing" in m for m in messages), messages
    assert ds.attrs["complete"] == 1
    xr.testing.assert_identical(stable(ds.load()), stable(whole.load()))


@pytest.mark.parametrize("edit", [
    lambda doc: doc.update(radius_chunk=doc["radius_chunk"] + 1),
    # slabs 0-2 declared as one of 9 radii (the old journal resumed it: 33 % NaN, complete)
    lambda doc: doc.update(slabs=[[0, 9], *doc["slabs"][3:]]),
], ids=["radius_chunk", "slab_plan"])
def test_an_edited_manifest_is_refused(tmp_path, edit):
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    manifest = Journal(out).manifest
    doc = json.loads(manifest.read_text())
    edit(doc)  # any edit the digest does not cover
    manifest.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="damaged or was edited"):
        resume(out)


@pytest.mark.parametrize("key,value", [("nylonflex_version", "0.0.1"),
                                       ("model_digest", "0123456789abcdef"),
                                       ("format", 1)])
def test_a_journal_of_another_version_or_model_is_refused(tmp_path, capsys, key, value):
    out = tmp_path / "cube.h5"
    interrupted(out, k=2)
    journal = Journal(out)
    doc = journal.read_manifest()
    doc.pop("digest"), doc.pop("format")
    doc[key] = value
    slabs = {p.name: p.read_bytes() for p in journal.dir.glob("slab-*.npz")}
    journal.start(doc)
    if key == "format":  # start() writes the current format: edit it, then re-digest
        raw = journal.read_manifest()
        raw["format"] = value
        raw["digest"] = journal_mod.manifest_digest(raw)
        journal.manifest.write_text(json.dumps(raw))
    for name, data in slabs.items():
        (journal.dir / name).write_bytes(data)
    cfg = write_config(tmp_path, MULTI)
    assert main(["sweep", str(cfg), "--out", str(out), "--resume", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and key in err and "delete" in err


def test_a_journal_of_format_4_is_refused_in_one_line(tmp_path, capsys):
    # format 4 kept every chunk's bytes in the journal; format 5 keeps where they lie
    out = tmp_path / "cube.h5"
    interrupted(out, k=2)
    journal = Journal(out)
    raw = journal.read_manifest()
    raw["format"] = 4
    raw["digest"] = journal_mod.manifest_digest(raw)
    journal.manifest.write_text(json.dumps(raw))
    cfg = write_config(tmp_path, MULTI)
    assert main(["sweep", str(cfg), "--out", str(out), "--resume", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "format" in err and "delete" in err, err


def test_the_journal_holds_no_chunk_of_the_cube(tmp_path):
    # the journal records where the chunks lie, not the chunks: its slab files are small
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    parts = Journal(out).dir
    records = [_record(parts, k) for k in range(3)]
    assert all(not any(key.endswith(":bytes") for key in r) for r in records)
    assert all(any(key.endswith(":addresses") for key in r) for r in records)
    journal_bytes = sum(p.stat().st_size for p in parts.glob("slab-*.npz"))
    assert journal_bytes < 0.2 * out.stat().st_size, (journal_bytes, out.stat().st_size)


def test_crash_safety_kill_at_random_points_resumes_identical(tmp_path, whole):
    out = tmp_path / "cube.h5"
    interrupted(out, k=1)
    interrupted(out, k=2, resume=True)  # a resume stopped in its turn
    ds = resume(out)
    assert ds.attrs["resumed_slabs"] == 3
    xr.testing.assert_identical(stable(ds.load()), stable(whole.load()))


# --------------------------------------------------------------------------- 4. output path

@pytest.fixture
def small_cfg(tmp_path):
    raw = {**MULTI, "name": "tiny", "grid": {**MULTI["grid"],
                                             "radius": {"values": [5, 10], "units": "mm"},
                                             "wall_thickness": {"values": [1, 2],
                                                                "units": "mm"}}}
    return raw, write_config(tmp_path, raw, "tiny.yaml")


def sweep(cfg_path, out, *extra):
    return main(["sweep", str(cfg_path), "--out", str(out), "--quiet", "--no-charts",
                 *extra])


def test_out_onto_the_config_itself_is_refused(small_cfg, capsys):
    raw, cfg = small_cfg
    before = cfg.read_bytes()
    assert sweep(cfg, cfg) == 2
    assert "not a nylonflex cube" in capsys.readouterr().err
    assert cfg.read_bytes() == before


def test_unrelated_parts_lock_and_building_are_left_alone(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    for suffix, make in [(".parts", "folder"), (".lock", "text"), (".building", "text")]:
        out = tmp_path / f"c{suffix[1:]}.h5"
        other = out.with_name(out.name + suffix)
        if make == "folder":
            other.mkdir()
            (other / "thesis.tex").write_text("precious")
        else:
            other.write_text("precious")
        assert sweep(cfg, out) == 2, suffix
        err = capsys.readouterr().err
        assert "not written by nylonflex" in err or "not a nylonflex lock" in err
        kept = other / "thesis.tex" if make == "folder" else other
        assert kept.read_text() == "precious"
        assert not out.exists()


def test_a_finished_cube_is_replaced_only_with_overwrite(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    out = tmp_path / "cube.h5"
    assert sweep(cfg, out) == 0
    first = out.stat().st_mtime_ns
    capsys.readouterr()
    # identical config: up to date, left alone
    assert main(["sweep", str(cfg), "--out", str(out), "--no-charts"]) == 0
    assert "up to date" in capsys.readouterr().err
    assert out.stat().st_mtime_ns == first
    other = write_config(tmp_path, {**raw, "name": "other"}, "other.yaml")
    assert sweep(other, out) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert open_cube(out).attrs["name"] == "tiny"
    assert sweep(other, out, "--overwrite") == 0
    assert open_cube(out).attrs["name"] == "other"


@pytest.mark.slow
def test_an_interrupted_overwrite_keeps_the_old_cube(tmp_path, whole):
    out = tmp_path / "cube.h5"
    raw = {**MULTI, "name": "old", "grid": {**MULTI["grid"],
                                           "radius": {"values": [5, 10], "units": "mm"}}}
    run_sweep(parse_config(raw), out).close()
    interrupted(out, k=3, overwrite=True)
    old = open_cube(out)
    assert old.attrs["name"] == "old" and old.attrs["complete"] == 1
    old.close()
    ds = resume(out)  # the replacement, once complete, is published
    xr.testing.assert_identical(stable(ds.load()), stable(whole.load()))


def test_special_files_are_refused(small_cfg, tmp_path, capsys):
    # a fifo of the test's own, not /dev/null: code with this bug would replace the
    # machine's /dev/null with a regular file (it happened once while checking the old code)
    raw, cfg = small_cfg
    fifo = tmp_path / "fifo.h5"
    os.mkfifo(fifo)
    assert sweep(cfg, str(fifo)) == 2
    assert "special file" in capsys.readouterr().err
    assert fifo.is_fifo()


def test_simulate_never_writes_over_a_cube(tmp_path, small_cfg):
    from nylonflex.sim import write_simulation

    raw, cfg = small_cfg
    out = tmp_path / "cube.h5"
    assert sweep(cfg, out) == 0
    before = out.read_bytes()
    with pytest.raises(InputError, match="not a nylonflex simulation"):
        write_simulation(xr.Dataset({"x": ("t", [1.0])}), out)
    assert out.read_bytes() == before


def test_every_rename_that_publishes_follows_an_fsync(tmp_path, small_cfg, monkeypatch):
    # a slab, the manifest and the cube are renamed into place only after their bytes
    # (and, for the cube, its folder) are on disk (the old code called fsync nowhere)
    log, real_fsync, real_replace = [], os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: (log.append("fsync"), real_fsync(fd))[1])
    monkeypatch.setattr(os, "replace",
                        lambda a, b: (log.append(("replace", str(b))), real_replace(a, b))[1])
    raw, cfg = small_cfg
    assert sweep(cfg, tmp_path / "cube.h5") == 0
    renames = [i for i, entry in enumerate(log) if entry != "fsync"]
    published = {Path(log[i][1]).name for i in renames}
    assert "cube.h5" in published and "manifest.json" in published
    assert any(name.startswith("slab-") for name in published)
    for i in renames:
        assert i > 0 and log[i - 1] == "fsync", log[i]


# --------------------------------------------------------------------------- 2, 10. input

def _bomb(levels=9):
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for i in range(1, levels):
        refs = ", ".join([f"*a{i - 1}"] * 9)
        lines.append(f"a{i}: &a{i} [{refs}]")
    return "\n".join(lines) + f"\nname: bomb\nsilicone: {{set: tc5005, mu: *a{levels - 1}}}\n"


_MEASURE = """
import resource, sys, time
resource.setrlimit(resource.RLIMIT_AS, (2 * 2**30, 2 * 2**30))
t = time.perf_counter()
from nylonflex.cli import main
rc = main(["sweep", sys.argv[1], "--out", sys.argv[2], "--quiet"])
# VmHWM: this process's peak resident memory (ru_maxrss may carry the forking parent's)
hwm = [line for line in open("/proc/self/status") if line.startswith("VmHWM")]
peak = int(hwm[0].split()[1]) / 1024 if hwm else 0.0
print(rc, time.perf_counter() - t, peak, flush=True)
"""


@pytest.mark.parametrize("levels", [9, 12])  # 9^9 and 9^12 strings; 12 levels: 700 bytes
def test_an_alias_bomb_is_refused_quickly_in_little_memory(tmp_path, levels):
    cfg = tmp_path / "bomb.yaml"
    cfg.write_text(_bomb(levels))
    assert len(cfg.read_bytes()) < 800
    proc = subprocess.run([sys.executable, "-c", _MEASURE, str(cfg), str(tmp_path / "c.h5")],
                          capture_output=True, text=True, timeout=120)
    rc, seconds, megabytes = proc.stdout.split()
    assert rc == "2", proc.stderr
    assert "aliases expand" in proc.stderr and proc.stderr.count("\n") == 1
    assert float(megabytes) < 200  # peak memory of the whole process, imports included
    assert not (tmp_path / "c.h5").exists()


@pytest.mark.parametrize("text,match", [
    ("a: " + "[" * 200 + "]" * 200 + "\n", "nested deeper"),
    # deep enough that a recursive reader fails (RecursionError from depth ~500)
    ("a: " + "[" * 5000 + "]" * 5000 + "\n", "nested deeper"),
    ("name: x\nname: y\n", "appears twice"),
    # a complete config with a second name: a reader that lets the last win runs it
    (yaml.safe_dump(MULTI) + "name: second\n", "appears twice"),
    ("a: &x [*x]\n", "not valid YAML|refers to itself"),
], ids=["depth200", "depth5000", "duplicate", "duplicate_in_a_whole_config", "self_alias"])
def test_hostile_yaml_is_one_line_exit_2(tmp_path, capsys, text, match):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(text)
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "c.h5")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert __import__("re").search(match, err), err


@pytest.mark.parametrize("setting", [".".join(["a"] * 5000) + "=1",
                                     "name=" + "[" * 2000 + "]" * 2000],
                         ids=["deep_key", "deep_value"])
def test_a_deep_set_is_one_line_exit_2(tmp_path, small_cfg, capsys, setting):
    raw, cfg = small_cfg
    assert main(["sweep", str(cfg), "--out", str(tmp_path / "c.h5"), "--set", setting]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "RecursionError" not in err, err
    assert "nested deeper" in err, err


def test_a_non_utf8_config_names_its_file(tmp_path, capsys):
    bad = tmp_path / "latin1.yaml"
    bad.write_bytes("name: caf\xe9\n".encode("latin-1"))
    assert main(["sweep", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(bad) in err and "UTF-8" in err


@pytest.mark.parametrize("path,value", [
    (("grid", "radius"), {"values": [True], "units": "mm"}),
    (("grid", "radius"), {"start": 5, "stop": 10, "num": True}),
])
def test_booleans_are_not_numbers(path, value):
    raw = yaml.safe_load(yaml.safe_dump(MULTI))
    raw[path[0]][path[1]] = value
    with pytest.raises(InputError, match="must be a number|true"):
        parse_config(raw)


def test_messages_print_only_a_prefix_of_a_huge_value():
    raw = yaml.safe_load(yaml.safe_dump(MULTI))
    raw["grid"]["radius"] = {"start": "x" * 10**7, "stop": 10, "num": 3}
    with pytest.raises(InputError) as info:
        parse_config(raw)
    assert len(str(info.value)) < 300


# --------------------------------------------------------------------------- 6. budget

_BOUNDED = """
import resource, sys
resource.setrlimit(resource.RLIMIT_AS, (3 * 2**30, 3 * 2**30))
resource.setrlimit(resource.RLIMIT_FSIZE, (64 * 2**20, 64 * 2**20))
from nylonflex.cli import main
sys.exit(main(sys.argv[1:]))
"""


def test_a_huge_grid_is_refused_before_any_file(tmp_path):
    raw = {**MULTI, "grid": {**MULTI["grid"],
                             "radius": {"start": 1, "stop": 50, "num": 100_000},
                             "wall_thickness": {"start": 1, "stop": 6, "num": 100_000},
                             "length": {"start": 20, "stop": 200, "num": 100}}}
    cfg = write_config(tmp_path, raw)
    out = tmp_path / "run" / "cube.h5"
    # in a bounded process (memory, file size, time): code with the bug would start
    # writing a 10^12-design cube
    proc = subprocess.run([sys.executable, "-c", _BOUNDED, "sweep", str(cfg), "--out",
                           str(out)], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    err = proc.stderr
    assert "designs" in err and "GB" in err and "limits" in err
    assert not (tmp_path / "run").exists()
    raw["grid"]["radius"]["num"] = 10
    raw["grid"]["wall_thickness"]["num"] = 10
    raw["limits"] = {"designs": 1000}
    with pytest.raises(InputError, match="budget of 1,000 designs"):
        parse_config(raw)


def test_long_value_lists_are_capped():
    raw = yaml.safe_load(yaml.safe_dump(MULTI))
    # increasing (a valid axis but for its length): 200,001 strokes would be 52 GB of curves
    raw["curves"]["stroke"] = {"values": [float(x) for x in np.linspace(0, 0.1, 200_001)]}
    with pytest.raises(InputError, match="at most"):
        parse_config(raw)


# --------------------------------------------------------------------------- 9. materials

@pytest.mark.parametrize("override,match", [
    ({"silicone": {"set": "tc5005", "mu": [1e-300, 1e-300]}}, "silicone.mu"),
    ({"nylon": {"set": "silver_nylon66", "fibre_diameter": 1e-300}}, "nylon.fibre_diameter"),
    ({"nylon": {"set": "silver_nylon66", "tensile_strength_table": [1, 1, 1, 1]}},
     "nylon.tensile_strength_table"),
    ({"nylon": {"set": "silver_nylon66", "gamma": float("nan")}}, "nylon.gamma"),
    ({"nylon": {"set": "silver_nylon66", "stiffness": float("nan")}}, "nylon.stiffness"),
    ({"nylon": {"set": "silver_nylon66", "damping": float("inf")}}, "nylon.damping"),
])
def test_implausible_materials_are_refused_with_their_range(override, match):
    with pytest.raises(InputError, match=match + r".*(\[|must be)"):
        parse_config({**MULTI, **override})


def test_array_material_fields_are_range_checked():
    import nylonflex as nf

    with pytest.raises(ValueError, match=r"nylon.gamma: must be finite"):
        nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.14,
                    nylon={"set": "silver_nylon66", "gamma": np.array([[1e-4], [np.nan]])})
    with pytest.raises(ValueError, match=r"nylon.tensile_strength_table: must be finite and in"):
        nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.14,
                    nylon={"set": "silver_nylon66",
                           "tensile_strength_table": np.array([[1.0, 1, 1, 1], [1e8] * 4])})


def test_accepted_input_gives_no_nan_and_use_at_most_one(whole):
    ds = whole
    for name in ("nylon_use", "tip_force_max", "pressure_max"):
        values = ds[name].values
        assert np.all(np.isfinite(values)), name
    assert float(ds["nylon_use"].max()) <= 1 + 1e-9


# --------------------------------------------------------------------------- 5. reading

def test_an_incomplete_cube_is_masked_lazily(tmp_path, whole):
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = open_cube(out)
    var = ds["tip_force_max"].variable
    assert not isinstance(var._data, np.ndarray)  # nothing loaded by opening
    done = ds["slab_done"].values.astype(bool)
    part = ds["tip_force_max"].isel(radius=slice(0, 20)).values
    assert np.isnan(part[~done[:20]]).all()
    np.testing.assert_array_equal(part[done[:20]],
                                  whole["tip_force_max"].values[:20][done[:20]])


# --------------------------------------------------------------------------- 7. Dask

def test_a_silent_listener_as_scheduler_times_out(tmp_path):
    pytest.importorskip("distributed")
    from nylonflex.engine.cluster import DaskExecutor

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    srv.settimeout(20)  # bounded: closes itself
    accepted = []

    def accept():
        try:
            while True:
                accepted.append(srv.accept()[0])
        except OSError:
            pass

    threading.Thread(target=accept, daemon=True).start()
    try:
        with pytest.raises(InputError, match="no Dask scheduler answers"):
            DaskExecutor(f"tcp://127.0.0.1:{srv.getsockname()[1]}", timeout=1.0)
    finally:
        srv.close()
        for c in accepted:
            c.close()


# --------------------------------------------------------------------------- 8. signals, disk

def test_a_full_disk_is_one_line_with_the_size_and_resume(tmp_path, small_cfg, capsys,
                                                           monkeypatch):
    raw, cfg = small_cfg
    out = tmp_path / "cube.h5"
    real = Journal.save

    def full(self, k, arrays, **kw):
        if k >= 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        return real(self, k, arrays, **kw)

    monkeypatch.setattr(Journal, "save", full)
    assert sweep(cfg, out) == 2  # the environment's problem: exit 2 (issue 46)
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "GB" in err and "--resume" in err and "full" in err
    monkeypatch.setattr(Journal, "save", real)
    assert sweep(cfg, out, "--resume") == 0


def test_a_signal_while_a_slab_computes_stops_after_it(tmp_path):
    # the handler only records: a raise that lands in a weakref callback is swallowed
    from nylonflex.engine.slabs import run_slabs

    class Executor:
        def map_slabs(self, cfg, slabs, todo):
            for k in todo:
                if k == 1:
                    os.kill(os.getpid(), signal.SIGINT)
                yield k, {}

    class Sink:
        stored = []

        def put(self, k, *args):
            Sink.stored.append(k)

    cfg = parse_config(MULTI)
    stats = run_slabs(cfg, [(0, 4), (4, 8), (8, 12)], [0, 1, 2], Executor(), Sink())
    assert stats.stopped and Sink.stored == [0, 1]


_FINALISER_SIGNAL = """
import os, signal, sys
import nylonflex.engine.slabs as slabs
import nylonflex.sweep.run as run_mod

WHERE, SIG = sys.argv[1], int(sys.argv[2])


class Finalised:  # the signal lands inside a finaliser, where Python drops an exception
    def __del__(self):
        os.kill(os.getpid(), SIG)
        for _ in range(1000):
            pass


def fire():
    x = Finalised()
    del x


class Executor(run_mod.LocalExecutor):
    def __init__(self, *args, **kwargs):
        if WHERE == "setup":  # while the run is set up, before any slab
            fire()
        super().__init__(*args, **kwargs)

    def map_slabs(self, cfg, plan, todo, **kwargs):
        for n, (k, arrays) in enumerate(super().map_slabs(cfg, plan, todo, **kwargs)):
            if WHERE == "loop" and n == 1:
                fire()
            yield k, arrays


run_mod.LocalExecutor = Executor
if WHERE == "warmup":  # while the kernels load, before the run is set up
    import nylonflex.engine.warmup as warmup

    load = warmup.warm_up_grid

    def warm_up_grid(*args, **kwargs):
        fire()
        return load(*args, **kwargs)

    warmup.warm_up_grid = warm_up_grid
from nylonflex.cli import main
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.parametrize("where", ["warmup", "setup", "loop"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["INT", "TERM"])
def test_a_signal_in_a_finaliser_is_never_swallowed(tmp_path, where, sig):
    # Python prints "Exception ignored" and drops a KeyboardInterrupt raised inside a
    # finaliser; the run must stop anyway (the old code ran on to exit 0)
    cfg = write_config(tmp_path, MULTI)
    out = tmp_path / "cube.h5"
    proc = subprocess.run([sys.executable, "-c", _FINALISER_SIGNAL, where, str(int(sig)),
                           "sweep", str(cfg), "--out", str(out), "--no-charts"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 128 + sig, (proc.returncode, proc.stderr)  # 143 for SIGTERM
    assert "Traceback" not in proc.stderr and "ignored" not in proc.stderr, proc.stderr
    assert "--resume" in proc.stderr
    ds = open_cube(out, quiet=True)
    assert ds.attrs["complete"] == 0
    ds.close()


_EARLY_SIGNAL = """
import os, signal, sys
import nylonflex.config as config

SIG, FALLOUT = int(sys.argv[1]), sys.argv[2]
load = config.load_config


def load_config(*args, **kwargs):
    # a signal while the config's modules are imported, its exception dropped on the way
    # (a finaliser drops it), and an ImportError after it: what numpy does when a signal
    # lands in its C extension's import
    try:
        os.kill(os.getpid(), SIG)
        for _ in range(10**6):
            pass
    except KeyboardInterrupt:
        pass
    if FALLOUT == "import":
        raise ImportError("numpy half imported")
    return load(*args, **kwargs)


config.load_config = load_config
from nylonflex.cli import main
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.parametrize("fallout", ["import", "none"])
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["INT", "TERM"])
def test_a_signal_before_the_sweeps_own_handler_is_a_stop(tmp_path, sig, fallout):
    # CI once saw "failed: ImportError" (exit 1) for a SIGINT during numpy's import: a
    # signal at any point is a stop (128 + it), and a dropped one still stops the sweep
    # before its first slab
    cfg = write_config(tmp_path, MULTI)
    out = tmp_path / "cube.h5"
    proc = subprocess.run([sys.executable, "-c", _EARLY_SIGNAL, str(int(sig)), fallout,
                           "sweep", str(cfg), "--out", str(out), "--no-charts"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 128 + sig, (proc.returncode, proc.stderr)
    assert "Traceback" not in proc.stderr and "failed" not in proc.stderr, proc.stderr
    assert "interrupted" in proc.stderr or "--resume" in proc.stderr, proc.stderr
    if out.exists():
        ds = open_cube(out, quiet=True)
        assert ds.attrs["complete"] == 0
        ds.close()


_SIGNAL_AT = """
import os, random, signal, sys, threading, time
delay, sig = float(sys.argv[1]), int(sys.argv[2])
from nylonflex.cli import main  # a signal during Python's own start-up is not covered
timer = threading.Timer(delay, lambda: os.kill(os.getpid(), sig))
timer.daemon = True  # a run that finishes first exits without waiting for it
timer.start()
sys.exit(main(sys.argv[3:]))
"""


@pytest.mark.slow
def test_signals_at_random_points_stop_cleanly_and_resume_identical(tmp_path, whole):
    cfg = write_config(tmp_path, MULTI)
    rng = random.Random(16)
    for trial in range(8):
        out = tmp_path / f"t{trial}" / "cube.h5"
        sig = rng.choice([signal.SIGINT, signal.SIGTERM])
        delay = rng.uniform(0.0, 6.0)
        proc = subprocess.run([sys.executable, "-c", _SIGNAL_AT, str(delay), str(int(sig)),
                               "sweep", str(cfg), "--out", str(out), "--quiet",
                               "--no-charts"], capture_output=True, text=True, timeout=300)
        assert "Traceback" not in proc.stderr, proc.stderr
        assert proc.returncode in (0, 128 + sig, -sig), (proc.returncode, proc.stderr)
        if proc.returncode == 0:
            continue  # finished before the signal
        assert sweep(cfg, out, "--resume") == 0
        ds = open_cube(out)
        xr.testing.assert_identical(stable(ds.load()), stable(whole.load()))
        ds.close()
        shutil.rmtree(out.parent)


@pytest.mark.slow
def test_a_tiny_filesystem(tmp_path, small_cfg):
    # a 1 MB tmpfs in a user namespace, where the platform allows it
    raw, cfg = small_cfg
    probe = subprocess.run(["unshare", "-rm", "sh", "-c",
                            f"mount -t tmpfs -o size=1m tmpfs {tmp_path} && echo ok"],
                           capture_output=True, text=True)
    if probe.stdout.strip() != "ok":
        pytest.skip("no unprivileged tmpfs mount here")
    big = {**MULTI, "name": "big"}
    cfgp = write_config(tmp_path.parent, big, "big.yaml")
    script = (f"mount -t tmpfs -o size=1m tmpfs {tmp_path} && cd {tmp_path} && "
              f"{sys.executable} -m nylonflex sweep {cfgp} --out {tmp_path}/cube.h5 --quiet "
              "--no-charts")
    proc = subprocess.run(["unshare", "-rm", "sh", "-c", script], capture_output=True,
                          text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert proc.returncode == 2, proc.stderr  # the environment's (issue 46)
    assert "Traceback" not in proc.stderr and "--resume" in proc.stderr


# --------------------------------------------------------------------------- 4/10. charts, info

def _corrupt_chunk(path, name, index):
    """Overwrite the stored (compressed) bytes of chunk ``index`` of ``name``."""
    with h5py.File(path, "r") as f:
        info = f[name].id.get_chunk_info(index)
        n = f[name].id.get_num_chunks()
    with open(path, "r+b") as fh:
        fh.seek(info.byte_offset)
        fh.write(b"\xff" * info.size)
    return n


def test_charts_replace_only_what_nylonflex_drew_for_that_cube(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    cube, other = tmp_path / "a" / "cube.h5", tmp_path / "b" / "cube.h5"
    cube.parent.mkdir()
    assert sweep(cfg, cube) == 0 and sweep(cfg, other) == 0
    mine = cube.parent / "fig12b.png"
    mine.write_bytes(b"my own figure")
    chart = ["chart", "--figure", "fig12b", "--quiet"]
    capsys.readouterr()
    # beside the cube: a user's file is refused before anything is drawn
    assert main([*chart, str(cube)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "did not write it" in err and "--overwrite" in err
    assert mine.read_bytes() == b"my own figure"
    # a folder of its own: drawn, then redrawn (its own earlier chart is replaced)
    out = tmp_path / "figs"
    assert main([*chart, str(cube), "--out", str(out)]) == 0
    assert main([*chart, str(cube), "--out", str(out)]) == 0
    # another cube's chart there is not replaced, nor one edited since
    assert main([*chart, str(other), "--out", str(out)]) == 2
    assert "another cube" in capsys.readouterr().err
    (out / "fig12b.png").write_bytes(b"edited")
    assert main([*chart, str(cube), "--out", str(out)]) == 2
    assert "changed since" in capsys.readouterr().err
    assert (out / "fig12b.png").read_bytes() == b"edited"
    assert main([*chart, str(other), "--out", str(out), "--overwrite"]) == 0
    assert (out / "fig12b.png").read_bytes()[:4] == b"\x89PNG"
    # the sweep's own charts beside its cube: the user's file is skipped with one line
    with_charts = write_config(tmp_path, {**raw, "charts": ["fig12b", "fig12c"]}, "c.yaml")
    capsys.readouterr()
    assert main(["sweep", str(with_charts), "--out", str(cube), "--quiet",
                 "--overwrite"]) == 0
    cap = capsys.readouterr()
    assert mine.read_bytes() == b"my own figure"
    assert "fig12b.png" in cap.err and "not replaced" in cap.err
    assert (cube.parent / "fig12c.png").exists()


def test_a_huge_name_attribute_does_not_hang_chart_or_info(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    cube = tmp_path / "cube.h5"
    assert sweep(cfg, cube) == 0
    with h5py.File(cube, "a") as f:
        f.attrs["name"] = "n" * 10_000_000
    capsys.readouterr()
    assert main(["chart", str(cube), "--figure", "fig12b", "--quiet"]) == 0
    assert (tmp_path / "fig12b.png").exists()
    assert main(["info", str(cube)]) == 0
    assert max(len(line) for line in capsys.readouterr().out.splitlines()) < 400


def test_info_does_not_call_a_cube_with_a_corrupt_chunk_complete(tmp_path, whole, capsys):
    source = whole.encoding["source"]
    first, last = tmp_path / "first.h5", tmp_path / "last.h5"
    shutil.copy(source, first)
    shutil.copy(source, last)
    _corrupt_chunk(first, "tip_force_max", 0)
    with h5py.File(last, "r") as f:
        n = f["bend_angle_max"].id.get_num_chunks()
    assert n > 2
    _corrupt_chunk(last, "bend_angle_max", n - 1)
    _corrupt_chunk(last, "bend_angle_max", n - 2)
    # plain info reads one chunk of each variable: the first chunk's damage shows
    assert main(["info", str(first)]) == 1
    out = capsys.readouterr().out
    assert "DAMAGED" in out and "complete (" not in out and "tip_force_max" in out
    # a later chunk needs --check: one line for each unreadable chunk, exit 1
    assert main(["info", str(last)]) == 0
    assert "complete (" in capsys.readouterr().out
    assert main(["info", str(last), "--check"]) == 1
    cap = capsys.readouterr()
    bad = [line for line in cap.err.splitlines() if "cannot be read" in line]
    assert len(bad) == 2 and all("bend_angle_max" in line for line in bad)
    assert "Traceback" not in cap.err
    assert main(["info", source, "--check"]) == 0
    assert "every chunk" in capsys.readouterr().out


def test_nylon_use_is_at_most_one_by_construction(monkeypatch):
    """Even for a muscle far weaker than the accepted range (checks bypassed), in the
    reference loop and in the compiled kernels; it was 1 + 1e-8 (and 1 + 6e-15 on the
    reference cube's strength-limited designs)."""
    import nylonflex as nf
    import nylonflex.materials as materials
    from nylonflex.physics.limits import design_limits

    monkeypatch.setitem(materials.NYLON_RANGES, "tensile_strength_table",
                        (1e-300, 1e300, "Pa"))
    radius = np.linspace(4e-3, 25e-3, 23)
    for table in ([1.0] * 4, [1e3] * 4, [2e8] * 4):
        nylon = {"set": "silver_nylon66", "tensile_strength_table": table}
        slow = design_limits(radius, 2e-3, 70e-3, 1.3, 0.14, nylon=nylon)
        fast = nf.evaluate(radius, 2e-3, 70e-3, 1.3, 0.14, nylon=nylon)
        for use in (slow["nylon_use"], fast["nylon_use"]):
            assert np.all(np.isfinite(use)) and np.max(use) <= 1.0, table
    ref = run_sweep(parse_config(yaml.safe_load(
        open(os.path.join(os.path.dirname(__file__), "data", "reference_cube.yaml")))))
    assert float(ref["nylon_use"].max()) == 1.0


def test_a_simulation_over_its_budget_says_its_size_and_how_to_raise_it():
    from nylonflex.config.simulate import parse_sim_config

    raw = {"name": "long", "time": {"duration": "1000 s", "step": "0.01 ms"},
           "reference": {"kind": "step", "initial": 0, "final": 120, "at": "1 s"}}
    with pytest.raises(InputError) as info:
        parse_sim_config(raw)
    msg = str(info.value)
    assert "100,000,000" in msg and "GB" in msg and "limits: {samples: N}" in msg
    assert "\n" not in msg
    parse_sim_config({**raw, "limits": {"samples": 2e8}})  # raised: accepted
    for bad in (0, True, float("nan")):
        with pytest.raises(InputError, match="limits.samples"):
            parse_sim_config({**raw, "limits": {"samples": bad}})


# --------------------------------------------------------------------------- issue 26: links

def _plant_building_to_another_cube(tmp_path, out, small_cfg):
    raw, cfg = small_cfg
    other = write_config(tmp_path, {**raw, "name": "victim"}, "victim.yaml")
    victim = tmp_path / "elsewhere" / "victim.h5"
    assert sweep(other, victim) == 0
    out.with_name(out.name + ".building").symlink_to(victim)
    return victim, []


def _plant_dangling(suffix):
    def plant(tmp_path, out, small_cfg):
        target = tmp_path / "elsewhere" / f"landed{suffix}"
        target.parent.mkdir(exist_ok=True)
        out.with_name(out.name + suffix).symlink_to(target)
        return None, []
    return plant


def _plant_manifest_and_building_link(tmp_path, out, small_cfg):
    victim = tmp_path / "elsewhere" / "thesis.tex"
    victim.parent.mkdir(exist_ok=True)
    victim.write_text("precious")
    parts = Journal(out).dir
    parts.mkdir()
    (parts / "manifest.json").write_text('{"name": "planted"}')
    out.with_name(out.name + ".building").symlink_to(victim)
    return victim, ["--overwrite"]


def _plant_manifest_link(tmp_path, out, small_cfg):
    victim = tmp_path / "elsewhere" / "notes.json"
    victim.parent.mkdir(exist_ok=True)
    victim.write_text('{"precious": true}')
    Journal(out).dir.mkdir()
    Journal(out).manifest.symlink_to(victim)
    return victim, ["--overwrite"]


def _plant_parts_link(tmp_path, out, small_cfg):
    victim = tmp_path / "elsewhere" / "project"
    victim.mkdir(parents=True)
    (victim / "thesis.tex").write_text("precious")
    Journal(out).dir.symlink_to(victim)
    return victim / "thesis.tex", ["--overwrite"]


@pytest.mark.parametrize("plant", [
    _plant_building_to_another_cube, _plant_dangling(".lock"), _plant_dangling(".building"),
    _plant_manifest_and_building_link, _plant_manifest_link, _plant_parts_link,
], ids=["building_to_a_cube", "dangling_lock", "dangling_building",
        "manifest_and_building", "manifest", "parts"])
def test_a_link_at_a_side_path_is_refused_naming_it(tmp_path, small_cfg, capsys, plant):
    # a link at <out>.building once made a plain sweep write its cube into another
    # config's finished cube (exit 0, <out> a link to it); a dangling one put the lock or
    # the cube outside the output folder; a planted manifest let --overwrite replace any
    # file the building link named
    raw, cfg = small_cfg
    out = tmp_path / "run" / "cube.h5"
    out.parent.mkdir()
    victim, extra = plant(tmp_path, out, small_cfg)
    before = victim.read_bytes() if victim is not None else None
    capsys.readouterr()
    assert sweep(cfg, out, *extra) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "symbolic link" in err, err
    link = next(p for p in out.parent.rglob("*") if p.is_symlink())
    assert str(link) in err
    if victim is not None:
        assert victim.read_bytes() == before
    else:
        assert not any((tmp_path / "elsewhere").iterdir())  # nothing landed outside
    assert not os.path.lexists(out)


def test_a_slab_temporary_link_is_refused_on_resume(tmp_path, capsys):
    # after an interrupted run, <out>.parts/slab-000004.tmp -> victim.txt once made
    # --resume write the slab into victim.txt
    out = tmp_path / "cube.h5"
    interrupted(out, k=2)
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    tmp = Journal(out).dir / "slab-000004.tmp"
    tmp.symlink_to(victim)
    cfg = write_config(tmp_path, MULTI)
    assert sweep(cfg, out, "--resume") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "symbolic link" in err and str(tmp) in err
    assert victim.read_text() == "precious"


def test_a_link_planted_as_an_aside_is_refused_on_resume(tmp_path, capsys):
    # journal format 5 reads chunks back from <out>.parts/aside-NNNNNN.h5: a link planted
    # there (to a file of the same chunks, or any other) is refused before anything is read
    # or moved, with one line naming it
    out = tmp_path / "cube.h5"
    interrupted(out, k=2)
    victim = tmp_path / "victim.h5"
    victim.write_bytes(b"precious")
    aside = Journal(out).dir / "aside-000007.h5"
    aside.symlink_to(victim)
    cfg = write_config(tmp_path, MULTI)
    assert sweep(cfg, out, "--resume") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "symbolic link" in err and str(aside) in err, err
    assert victim.read_bytes() == b"precious" and aside.is_symlink()


def test_a_link_at_the_output_itself_is_refused(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    victim = tmp_path / "victim.h5"
    victim.write_bytes(b"precious")
    out = tmp_path / "cube.h5"
    out.symlink_to(victim)
    assert sweep(cfg, out, "--overwrite") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "symbolic link" in err and str(out) in err
    assert victim.read_bytes() == b"precious" and out.is_symlink()


def test_the_journal_is_written_only_through_new_files(tmp_path, small_cfg, monkeypatch):
    # every file in <out>.parts is created new (O_EXCL | O_NOFOLLOW), never opened as it is
    raw, cfg = small_cfg
    out = tmp_path / "cube.h5"
    real_open, opened = os.open, []

    def spy(path, flags, *args, **kwargs):
        if ".parts" in str(path) and flags & (os.O_WRONLY | os.O_RDWR):
            opened.append((Path(path).name, flags))
        return real_open(path, flags, *args, **kwargs)

    monkeypatch.setattr(os, "open", spy)
    assert sweep(cfg, out) == 0
    assert opened and any(name.startswith("slab-") for name, _ in opened)
    for name, flags in opened:
        assert flags & os.O_EXCL and flags & os.O_NOFOLLOW, name


# --------------------------------------------------------------------------- issue 26: writers

def _fit(tmp_path, *extra):
    data = tmp_path / "data.csv"
    if not data.exists():
        shutil.copy(Path(__file__).parent / "data" / "ecoflex_0050.csv", data)
    # in a child with a time limit: the old code blocked forever opening a fifo
    return subprocess.run([sys.executable, "-m", "nylonflex", "fit", "silicone", str(data),
                           "--max-stretch", "2", *extra], capture_output=True, text=True,
                          timeout=120, env={**os.environ,
                                            "PYTHONPATH": os.pathsep.join(sys.path)})


def test_fit_never_writes_onto_a_fifo_its_data_or_through_a_link(tmp_path):
    data = tmp_path / "data.csv"
    fifo = tmp_path / "fifo.yaml"
    os.mkfifo(fifo)
    proc = _fit(tmp_path, "--out", str(fifo), "--overwrite")
    assert proc.returncode == 2 and "special file" in proc.stderr, proc.stderr
    before = data.read_bytes()
    proc = _fit(tmp_path, "--out", str(data), "--overwrite")
    assert proc.returncode == 2 and "input of this command" in proc.stderr, proc.stderr
    assert data.read_bytes() == before
    victim = tmp_path / "victim.txt"
    victim.write_text("precious")
    link = tmp_path / "link.yaml"
    link.symlink_to(victim)
    proc = _fit(tmp_path, "--out", str(link), "--overwrite")
    assert proc.returncode == 2 and "symbolic link" in proc.stderr and str(link) in proc.stderr
    assert victim.read_text() == "precious"
    # a plain --out is written whole, through a temporary that does not stay behind
    good = tmp_path / "fit.yaml"
    assert _fit(tmp_path, "--out", str(good)).returncode == 0
    assert yaml.safe_load(good.read_text())["kind"] == "silicone"
    assert not list(tmp_path.glob(".*.tmp"))


def test_explore_html_never_replaces_the_cube_it_reads(tmp_path, small_cfg, capsys):
    raw, cfg = small_cfg
    cube = tmp_path / "cube.h5"
    assert sweep(cfg, cube) == 0
    before = cube.read_bytes()
    assert main(["explore", str(cube), "--html", str(cube), "--overwrite"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "input of this command" in err
    assert cube.read_bytes() == before


# --------------------------------------------------------------------------- issue 26: publish

_POLL = """
import os, sys, time
import h5py
path, stop = sys.argv[1], sys.argv[2]
reads = failures = 0
names = set()
end = time.monotonic() + 300  # bounded: the test creates ``stop`` when it is done
while time.monotonic() < end and not os.path.exists(stop):
    try:
        with h5py.File(path, "r") as f:  # plain h5py: HDF5's own (shared) file lock
            names.add((f.attrs["name"].decode() if isinstance(f.attrs["name"], bytes)
                       else str(f.attrs["name"]), str(f.attrs["complete"])))
        reads += 1
    except BlockingIOError as exc:
        failures += 1
        print("locked", exc, file=sys.stderr)
    except OSError as exc:
        failures += 1
        print("failed", exc, file=sys.stderr)
print(reads, failures, sorted(names))
"""


def test_readers_never_meet_the_writers_lock_during_overwrite(tmp_path, small_cfg):
    # the writer kept its exclusive lock on the published inode until the journal was
    # removed: 2-8 % of plain h5py reads failed with "unable to lock file" during
    # --overwrite. Each read must succeed and see a complete old or new cube.
    raw, cfg = small_cfg
    out = tmp_path / "cube.h5"
    assert sweep(cfg, out) == 0
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    configs = [write_config(tmp_path, {**raw, "name": f"n{i}"}, f"n{i}.yaml")
               for i in range(2)]
    stop = tmp_path / "stop"
    poll = subprocess.Popen([sys.executable, "-c", _POLL, str(out), str(stop)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=env)
    try:
        for i in range(4):
            assert subprocess.run([sys.executable, "-m", "nylonflex", "sweep",
                                   str(configs[i % 2]), "--out", str(out), "--overwrite",
                                   "--quiet", "--no-charts"], env=env, timeout=120,
                                  capture_output=True).returncode == 0
    finally:
        stop.touch()
        stdout, stderr = poll.communicate(timeout=60)
    reads, failures, names = stdout.split(" ", 2)
    assert int(failures) == 0, stderr[:2000]
    assert int(reads) > 100
    # complete: a typed one-element int8 attribute, 1 (h5py reads it as [1])
    assert set(eval(names)) <= {("tiny", "[1]"), ("n0", "[1]"), ("n1", "[1]")}


# --------------------------------------------------------------------------- issue 26: journal

def test_a_forged_codec_in_the_manifest_never_makes_an_unreadable_cube(tmp_path, whole):
    # the manifest's digest hashes only the manifest: switching its codec from zstd to
    # gzip and recomputing it once resumed to a cube marked complete whose journaled
    # chunks (zstd frames in a gzip dataset) could not be read. A slab's digest now covers
    # the codec it decodes with: every journaled slab is recomputed.
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    journal = Journal(out)
    doc = journal.read_manifest()
    assert doc["compression"] == parse_config(MULTI).compression
    forged = "zstd" if doc["compression"] == "gzip" else "gzip"
    doc["compression"] = forged
    doc["digest"] = journal_mod.manifest_digest(doc)
    journal.manifest.write_text(json.dumps(doc))
    messages = []
    ds = resume(out, log=messages.append)
    assert sum("recomputing" in m for m in messages) == 3, messages
    assert is_complete(ds.attrs) and ds.attrs["compression"] == forged
    ds.close()
    from nylonflex.storage import check_cube

    assert check_cube(out) == []
    got, want = stable(open_cube(out).load()), stable(whole.load())
    got.attrs.pop("compression"), want.attrs.pop("compression")  # the one difference
    xr.testing.assert_identical(got, want)


@pytest.mark.parametrize("edit", [
    # a plan of equal slabs from 0 to the end, but with a chunk length no plan gives
    lambda doc: doc.update(slabs=[[i, i + 3] for i in range(0, 18, 3)]),
    lambda doc: doc.update(compression="brotli"),
], ids=["plan_the_config_cannot_give", "unknown_codec"])
def test_a_manifest_that_recomputes_its_digest_is_checked_against_the_config(tmp_path, edit):
    out = tmp_path / "cube.h5"
    interrupted(out, k=3)
    journal = Journal(out)
    doc = journal.read_manifest()
    edit(doc)
    doc["digest"] = journal_mod.manifest_digest(doc)  # the forger recomputes it
    journal.manifest.write_text(json.dumps(doc))
    with pytest.raises(InputError, match="damaged or was edited"):
        resume(out)


@pytest.mark.parametrize("garbage", [b"\x00\xff garbage", b"[1, 2, 3]", b'{"name": "x"}'])
def test_a_garbage_manifest_is_damaged_not_a_changed_config(tmp_path, capsys, garbage):
    out = tmp_path / "cube.h5"
    interrupted(out, k=2)
    Journal(out).manifest.write_bytes(garbage)
    cfg = write_config(tmp_path, MULTI)
    assert sweep(cfg, out, "--resume") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "damaged" in err and "config changed" not in err, err


# --------------------------------------------------------------------------- issue 26: bounds

def _timed_main(argv):
    """``main(argv)`` and its wall time [s] (a bound checked before the work is quick)."""
    t = time.perf_counter()
    rc = main(argv)
    return rc, time.perf_counter() - t


@pytest.mark.parametrize("columns", [20_000, 100_000])
def test_a_wide_csv_header_is_refused_before_the_fit(tmp_path, capsys, columns):
    # 20,000 columns took 47 s to refuse (a quadratic duplicate check), 100,000 ran past
    # 120 s; the header holds at most MAX_COLUMNS
    from nylonflex.calibration.data import MAX_COLUMNS

    data = tmp_path / "wide.csv"
    data.write_text(",".join(f"c{i} [kPa]" for i in range(columns)) + "\n" +
                    ",".join(["1"] * columns) + "\n")
    rc, seconds = _timed_main(["fit", "silicone", str(data)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1, err
    assert f"{columns:,} columns" in err and f"{MAX_COLUMNS:,}" in err and str(data) in err
    assert seconds < 20  # generous: the refusal itself is a few milliseconds of parsing


def test_duplicate_columns_are_found_by_a_set(tmp_path, capsys):
    data = tmp_path / "dup.csv"
    data.write_text("stretch,stress [kPa],stretch\n1,0,1\n")
    assert main(["fit", "silicone", str(data)]) == 2
    assert "'stretch' appears twice" in capsys.readouterr().err


def test_a_huge_csv_cell_names_the_file_and_line(tmp_path, capsys):
    # the csv module said only "field larger than field limit (131072)"
    from nylonflex.calibration.data import MAX_CELL

    data = tmp_path / "cell.csv"
    data.write_text("stretch,stress [kPa]\n1,0\n1.5," + "9" * 20_000_000 + "\n")
    assert main(["fit", "silicone", str(data)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and str(data) in err and "line 3" in err
    assert f"{MAX_CELL:,} characters" in err and "field limit" not in err


def test_too_many_csv_lines_are_refused(tmp_path, capsys, monkeypatch):
    import nylonflex.calibration.data as data_mod

    monkeypatch.setattr(data_mod, "MAX_ROWS", 10)  # the bound, not its size, is tested
    data = tmp_path / "long.csv"
    data.write_text("stretch,stress [kPa]\n" + "".join(f"{1 + i / 100},{i}\n"
                                                       for i in range(20)))
    assert main(["fit", "silicone", str(data)]) == 2
    err = capsys.readouterr().err
    assert "21 lines" in err and "10 a data file" in err and str(data) in err


@pytest.mark.parametrize("samples,designs,match", [
    (2**30, 16, r"--samples: must be a power of 2 in \[8, 1,048,576\], got 1,073,741,824"),
    (2**20, 16, r"1,048,576 x 3 \(factors \+ 2\) x 16 designs = 50,331,648 model runs"),
    (512, 10**6, r"--designs: must be in \[1, 10,000\]"),
])
def test_sensitivity_work_is_bounded_before_any_sample(tmp_path, capsys, samples, designs,
                                                        match):
    # 2^24 samples ran at 1.2 GB, 2^30 tried 32 GiB: refused before sampling
    raw = {**MULTI, "uncertainty": {"samples": 64, "parameters": {
        "wall_thickness": {"sd": 0.1, "units": "mm"}}}}
    cfg = write_config(tmp_path, raw)
    rc, seconds = _timed_main(["sensitivity", str(cfg), "--samples", str(samples),
                               "--designs", str(designs)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1, err
    assert __import__("re").search(match, err), err
    assert seconds < 20


def test_a_design_refine_budget_past_the_bound_is_refused():
    from nylonflex.design.spec import MAX_REFINE_ITERATIONS, parse_spec

    raw = {"cube": "c.h5", "objectives": [{"max": "tip_force_max"}],
           "refine": {"starts": 1000, "maxiter": 10_000}}  # each in its own range
    with pytest.raises(InputError, match=r"refine: starts x maxiter = 1,000 x 10,000 = "
                                         r"10,000,000 SLSQP iterations, over the 20,000"):
        parse_spec(raw)
    raw["refine"] = {"starts": 4, "maxiter": MAX_REFINE_ITERATIONS // 4}
    assert parse_spec(raw).maxiter == MAX_REFINE_ITERATIONS // 4


def test_design_refinement_reports_its_progress(tmp_path, small_cfg):
    from nylonflex.design import run_design

    raw, cfg = small_cfg
    cube = tmp_path / "cube.h5"
    assert sweep(cfg, cube) == 0
    seen = []
    run_design({"cube": str(cube), "objectives": [{"max": "tip_force_max"}],
                "refine": {"starts": 3, "maxiter": 5}},
               progress=lambda done, total: seen.append((done, total)))
    assert seen and seen[-1][0] == seen[-1][1] and seen[0][0] == 0


def test_info_refuses_a_crafted_huge_chunk_before_reading_it(tmp_path, small_cfg, capsys):
    # one 2^29-element chunk made info allocate 4 GiB
    raw, cfg = small_cfg
    cube = tmp_path / "cube.h5"
    assert sweep(cfg, cube) == 0
    with h5py.File(cube, "a") as f:
        del f["tip_force_max"]
        f.create_dataset("tip_force_max", shape=(2**15, 2**14), chunks=(2**15, 2**14),
                         dtype="f8", compression="gzip")  # nothing stored: no disk used
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    capsys.readouterr()
    for argv in (["info", str(cube)], ["info", str(cube), "--check"]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "tip_force_max" in err and "4,096 MiB" in err, err
    # ru_maxrss [KiB]: well under the 4 GiB the chunk would have taken
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak < 2**20


# --------------------------------------------------------------------------- issue 26: nonsense

def test_a_stroke_shape_zero_everywhere_is_refused(tmp_path, capsys):
    # gamma = beta = 0 (each in range) gave a zero stroke curve, usable_stroke up to 0.054
    # and NaN cooling times, marked complete
    import nylonflex as nf

    raw = {**MULTI, "nylon": {"set": "silver_nylon66", "gamma": 0, "beta": 0}}
    cfg = write_config(tmp_path, raw)
    out = tmp_path / "run" / "cube.h5"
    assert sweep(cfg, out) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nylon.gamma, nylon.beta" in err and "> 0" in err
    assert not (tmp_path / "run").exists()
    with pytest.raises(ValueError, match="nylon.gamma, nylon.beta"):
        nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.14,
                    nylon={"set": "silver_nylon66", "gamma": 0.0, "beta": 0.0})
    with pytest.raises(ValueError, match="nylon.gamma, nylon.beta"):
        nf.design_limits(7.5e-3, 2e-3, 70e-3, 1.7, 0.14,
                         nylon={"set": "silver_nylon66", "gamma": 0.0, "beta": 0.0})


def test_a_supply_that_cannot_heat_the_muscle_is_refused(tmp_path, capsys):
    # 1e-9 V gave cooling_time NaN and heating_time inf in every design
    import nylonflex as nf
    from nylonflex.physics.thermal import MIN_SUPPLY_RISE

    raw = {**MULTI, "supply": {"voltage": 1e-9}}
    cfg = write_config(tmp_path, raw)
    out = tmp_path / "run" / "cube.h5"
    assert sweep(cfg, out) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "supply.voltage" in err and "K above ambient" in err
    assert not (tmp_path / "run").exists()
    with pytest.raises(ValueError, match="supply_voltage: 1e-09 V"):
        nf.evaluate(7.5e-3, 2e-3, 70e-3, 1.7, 0.14, supply_voltage=1e-9)
    # the least voltage the message names is accepted, and its designs have no NaN
    need = float(err.split("at least ")[-1].split(" V")[0]) * 1.01
    ds = run_sweep(parse_config({**MULTI, "supply": {"voltage": need}}))
    for name in ("cooling_time", "heating_time", "usable_stroke", "heating_power"):
        assert np.all(np.isfinite(ds[name].values)), name
    assert MIN_SUPPLY_RISE == 1e-3


def test_validate_with_absurd_pressures_is_refused_and_json_is_valid(tmp_path, capsys):
    config = Path(__file__).parents[1] / "configs" / "control.yaml"
    data = tmp_path / "p.csv"
    data.write_text("pressure [kPa],bend_angle [deg]\n1e300,10\n2,20\n")
    assert main(["validate", str(config), str(data), "--format", "json"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "[0, 100] kPa" in err and "1e+300" in err
    data.write_text("pressure [kPa],bend_angle [deg]\n1,1\n20,30\n")
    assert main(["validate", str(config), str(data), "--format", "json"]) == 0
    text = capsys.readouterr().out
    json.loads(text, parse_constant=lambda name: pytest.fail(f"{name} in the JSON"))


def test_json_text_writes_null_for_nan_and_infinity():
    from nylonflex.units import json_text

    doc = {"a": float("nan"), "b": [np.float64("inf"), 1.5], "c": np.array([-np.inf, 2.0])}
    text = json_text(doc)
    assert json.loads(text) == {"a": None, "b": [None, 1.5], "c": [None, 2.0]}
    assert "NaN" not in text and "Infinity" not in text


# --------------------------------------------------------------------------- issue 26: messages

def test_a_listener_answering_garbage_as_scheduler_names_the_option(tmp_path, small_cfg,
                                                                    capsys):
    # it said "Maximum allowed dimension exceeded" (naming no option)
    pytest.importorskip("distributed")
    raw, cfg = small_cfg
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)
    srv.settimeout(20)  # bounded: closes itself
    rng = random.Random(26)
    garbage = bytes(rng.randrange(256) for _ in range(4096)) * 4

    def serve():
        try:
            while True:
                c = srv.accept()[0]
                with c:
                    c.recv(65536)
                    c.sendall(garbage)
        except OSError:
            pass

    threading.Thread(target=serve, daemon=True).start()
    try:
        rc = sweep(cfg, tmp_path / "c.h5", "--scheduler",
                   f"tcp://127.0.0.1:{srv.getsockname()[1]}")
    finally:
        srv.close()
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1, err
    assert "--scheduler" in err and "not a Dask scheduler" in err
    assert not (tmp_path / "c.h5").exists()


def test_sigterm_exits_143(tmp_path):
    # the shell's convention, 128 + 15 (it exited 130 as for Ctrl-C)
    cfg = write_config(tmp_path, MULTI)
    out = tmp_path / "cube.h5"
    script = _FINALISER_SIGNAL
    proc = subprocess.run([sys.executable, "-c", script, "loop", str(int(signal.SIGTERM)),
                           "sweep", str(cfg), "--out", str(out), "--no-charts"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 143, (proc.returncode, proc.stderr)
