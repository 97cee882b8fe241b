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


# --------------------------------------------------------------- format 5: chunks found back

def _chunk_files(tmp_path, blobs, *, gap=7):
    """Two files holding ``blobs`` at the same addresses; the first with its second chunk
    changed. Returns (paths, a record of the chunks as the journal keeps it)."""
    from nylonflex.storage.codec import crc32

    addresses, data = [], bytearray(b"x" * gap)
    for blob in blobs:
        addresses.append(len(data))
        data += blob + b"y" * gap
    good, bad = tmp_path / "good.h5", tmp_path / "bad.h5"
    good.write_bytes(bytes(data))
    damaged = bytearray(data)
    damaged[addresses[1]] ^= 0xFF
    bad.write_bytes(bytes(damaged))
    record = {"v:offsets": np.array([[0], [2]], dtype=np.int64),
              "v:sizes": np.array([len(b) for b in blobs], dtype=np.int64),
              "v:crcs": np.array([crc32(b) for b in blobs], dtype=np.uint32),
              "v:addresses": np.array(addresses, dtype=np.int64),
              "plain": np.arange(3)}
    return (bad, good), record


def test_a_slab_is_read_back_from_the_file_whose_chunks_all_match(tmp_path):
    from nylonflex.storage.restore import ChunkSources

    blobs = [b"first chunk", b"second chunk, longer"]
    (bad, good), record = _chunk_files(tmp_path, blobs)
    with ChunkSources([tmp_path / "missing.h5", bad, good]) as sources:
        slab = sources.slab(record)
    assert bytes(slab["v:bytes"]) == b"".join(blobs)
    assert "v:addresses" not in slab and slab["plain"].tolist() == [0, 1, 2]
    assert slab["v:crcs"] is record["v:crcs"]  # the rest of the record as it was


@pytest.mark.parametrize("edit", [
    lambda r: r["v:addresses"].__setitem__(1, 10**9),  # past the end of every file
    lambda r: r["v:addresses"].__setitem__(0, -1),
    lambda r: r["v:sizes"].__setitem__(0, 10**12),  # more than any file holds
    lambda r: r["v:crcs"].__setitem__(0, r["v:crcs"][0] ^ 1),
], ids=["address_past_end", "negative_address", "huge_size", "crc"])
def test_a_record_whose_chunks_no_file_holds_is_invalid(tmp_path, edit):
    from nylonflex.storage.restore import ChunkSources

    (bad, good), record = _chunk_files(tmp_path, [b"first chunk", b"second chunk"])
    edit(record)
    with ChunkSources([bad, good]) as sources, pytest.raises(SlabInvalid, match="slab 4"):
        sources.slab(record, "slab 4")


def test_a_link_is_never_a_source_of_chunks(tmp_path):
    from nylonflex.storage.restore import ChunkSources

    (bad, good), record = _chunk_files(tmp_path, [b"first chunk", b"second chunk"])
    (tmp_path / "link.h5").symlink_to(good)
    with ChunkSources([tmp_path / "link.h5"]) as sources, pytest.raises(SlabInvalid):
        sources.slab(record)


def test_journal_records_drop_the_bytes_and_keep_the_addresses():
    from nylonflex.storage.restore import journal_record

    encoded = {"v:offsets": np.zeros((1, 1)), "v:sizes": np.ones(1), "v:crcs": np.ones(1),
               "v:bytes": np.zeros(1, np.uint8), "plain": np.arange(2)}
    record = journal_record(encoded, {"v:addresses": np.array([40])})
    assert sorted(record) == ["plain", "v:addresses", "v:crcs", "v:offsets", "v:sizes"]
