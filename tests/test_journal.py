"""The journal's own checks, fast: what it fsyncs, and the three checks a resumed run relies
on before it trusts a journaled slab (index, radius range, digest). The kill-and-resume
runs of test_reliability.py and test_sweep.py exercise them end to end; these pin each one
alone (docs/reliability.md)."""

import io
import json
import os
import stat

import numpy as np
import pytest

from nylonflex.storage.journal import Journal, SlabInvalid

SHA = "c0ffee"
ARRAYS = {"tip_force_max": np.array([[0.5, 1.0], [1.5, 2.0]]),
          "limit": np.array([[0, 1], [2, 3]], dtype=np.int8)}


@pytest.fixture
def journal(tmp_path):
    j = Journal(tmp_path / "cube.h5")
    j.start({"name": "journal", "config_sha256": SHA})
    return j


def _kind(fd) -> str:
    mode = os.fstat(fd).st_mode
    return "folder" if stat.S_ISDIR(mode) else "file"


def test_a_slab_is_fsynced_before_its_rename_and_its_folder_after(journal, monkeypatch):
    # the write-ahead order of docs/reliability.md: the data on disk, then the name, then
    # the name's folder; without the first fsync a crash can leave a named, empty slab
    events = []
    fsync, replace = os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: (events.append(f"fsync {_kind(fd)}"),
                                                 fsync(fd))[1])
    monkeypatch.setattr(os, "replace", lambda a, b: (events.append("rename"),
                                                     replace(a, b))[1])
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    assert events == ["fsync file", "rename", "fsync folder"]


def test_a_manifest_is_fsynced_before_its_rename(tmp_path, monkeypatch):
    events = []
    fsync, replace = os.fsync, os.replace
    monkeypatch.setattr(os, "fsync", lambda fd: (events.append(f"fsync {_kind(fd)}"),
                                                 fsync(fd))[1])
    monkeypatch.setattr(os, "replace", lambda a, b: (events.append("rename"),
                                                     replace(a, b))[1])
    Journal(tmp_path / "cube.h5").start({"name": "journal", "config_sha256": SHA})
    assert events[:3] == ["fsync file", "rename", "fsync folder"]


def test_a_saved_slab_loads_back_unchanged(journal):
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    back = journal.load(0, slab=(0, 2), config_sha=SHA)
    assert set(back) == set(ARRAYS)
    for name, values in ARRAYS.items():
        np.testing.assert_array_equal(back[name], values)
        assert back[name].dtype == values.dtype


def _rewrite(journal, k, arrays, meta):
    """Slab k's file written again with other ``arrays`` and ``meta``, as a bit flip or a
    slab of another run would leave it."""
    buf = io.BytesIO()
    np.savez(buf, **arrays, __meta__=np.frombuffer(json.dumps(meta).encode(), np.uint8))
    (journal.dir / f"slab-{k:06d}.npz").write_bytes(buf.getvalue())


def _meta(journal, k):
    with np.load(journal.dir / f"slab-{k:06d}.npz") as z:
        return json.loads(z["__meta__"].tobytes().decode())


def test_a_slab_whose_values_changed_fails_its_digest(journal):
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    changed = {**ARRAYS, "tip_force_max": ARRAYS["tip_force_max"] + 1e-12}
    _rewrite(journal, 0, changed, _meta(journal, 0))
    with pytest.raises(SlabInvalid, match="fails its digest"):
        journal.load(0, slab=(0, 2), config_sha=SHA)


def test_a_slab_of_another_config_fails_its_digest(journal):
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    with pytest.raises(SlabInvalid, match="fails its digest"):
        journal.load(0, slab=(0, 2), config_sha="another")


def test_a_slab_of_other_radii_is_refused(journal):
    # the plan of the resumed run says slab 0 holds radii 0..3: a slab journaled for 0..2
    # must be recomputed, not written into the wrong rows
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    with pytest.raises(SlabInvalid, match=r"holds radii 0\.\.2, not 0\.\.3"):
        journal.load(0, slab=(0, 3), config_sha=SHA)


def test_a_slab_file_under_another_index_is_refused(journal):
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    os.replace(journal.dir / "slab-000000.npz", journal.dir / "slab-000001.npz")
    with pytest.raises(SlabInvalid, match="holds slab 0, not 1"):
        journal.load(1, slab=(0, 2), config_sha=SHA)


def test_a_flipped_byte_in_a_slab_file_is_caught_by_its_crc(journal):
    # the bytes are checked once, by the CRC-32 of each zip member, which the digest
    # covers: a bit flip in an array's data, the zip left as it was, is refused
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    path = journal.dir / "slab-000000.npz"
    data = bytearray(path.read_bytes())
    values = ARRAYS["tip_force_max"].tobytes()
    at = bytes(data).index(values) + 3
    data[at] ^= 0x10
    path.write_bytes(bytes(data))
    with pytest.raises(SlabInvalid, match="unreadable"):
        journal.load(0, slab=(0, 2), config_sha=SHA)


def test_a_slab_file_is_an_npz_numpy_reads(journal):
    journal.save(0, ARRAYS, slab=(0, 2), config_sha=SHA)
    with np.load(journal.dir / "slab-000000.npz") as z:
        assert set(z.files) == {*ARRAYS, "__meta__"}
        np.testing.assert_array_equal(z["limit"], ARRAYS["limit"])
        assert z["limit"].dtype == np.int8
    assert _meta(journal, 0)["slab"] == [0, 2]
