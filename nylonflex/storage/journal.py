"""The journal of a sweep (``<cube>.parts/``): what makes an interrupted run resumable.

The journal records where each finished slab lies in the cube, not the slab again (format
5): for each compressed variable, each chunk's offset, its address in the cube file [B],
its size [B] and its CRC-32 (:func:`.restore.journal_record`). The chunks themselves are
written once, into ``<cube>.building``, and made durable (``fsync``) before their record
is written; on ``--resume`` they are read back from the files that may hold them (the
interrupted run's building file, moved into the journal as ``aside-NNNNNN.h5``, or the
incomplete cube a stopped run published) and each is checked against its size and CRC
(:class:`.restore.ChunkSources`). What is not a whole compressed chunk (a variable without
the radius axis, a chunk the slab only partly covers, every array of an lz4 cube, which
HDF5 compresses itself) is kept in the record as it is. docs/reliability.md argues the
crash safety.

No side path is followed: a symbolic link at ``<cube>.parts`` or inside it is refused with
one line naming it, and every file there is created new (``O_EXCL | O_NOFOLLOW``) and
renamed into place, so that a run never writes outside the output's folder. The lock
that makes one writer is :mod:`.locks`.

The journal verifies itself: the manifest records its format, the nylonflex version, the
model digest, the slab plan and the codec; the run checks each against what the config
and the code imply (:mod:`.run`), not against the manifest itself. Every slab file records
its index, its radius range and a digest of its arrays (of the CRC-32 each zip member
records, the chunks' own CRC-32s among them) bound to the config's hash and to everything
that decodes them (codec, filters, chunking: ``decoding``). A slab that fails
verification, or whose chunks are found in no file, is recomputed, never trusted.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import shutil
import zipfile
from pathlib import Path

import numpy as np

import stat

from ..units import InputError
from ..files.atomic import NOFOLLOW, create_new, fsync_dir, publish, refuse_link, \
    refuse_special

__all__ = ["JOURNAL_FORMAT", "Journal", "SlabInvalid", "file_locks", "fsync_dir", "publish",
           "refuse_special"]

#: Version of the journal's layout (manifest keys, slab metadata). 3: a slab's digest
#: covers how its chunks decode (codec, filters, chunking). 4: it covers each array's
#: CRC-32 (the one its zip member records) instead of hashing the arrays' bytes again.
#: 5: a slab's file records where its compressed chunks lie in the cube (addresses, sizes,
#: CRC-32s), not their bytes.
JOURNAL_FORMAT = 5
_MANIFEST_KEYS = ("format", "name", "config_sha256", "slabs", "radius_chunk",
                  "nylonflex_version", "model_digest", "replaces")


class SlabInvalid(Exception):
    """A journaled slab that fails verification (its message says why)."""


def _digest(config_sha, k, i0, i1, crcs: dict, decoding: str = "") -> str:
    """A slab's digest: its config's hash, index, radius range and ``decoding``, and the
    CRC-32 of each array's ``.npy`` member (``crcs``, name -> CRC; the member holds the
    array's dtype, shape and bytes).

    The bytes are checked once, by the CRC-32 the zip format keeps for each member (the
    writer computes it as it writes; :meth:`Journal.load` reads each member whole, which
    makes :mod:`zipfile` check it). A SHA-256 of the bytes besides it was a second pass
    over every slab (4-5 % of a sweep's CPU) that caught nothing more: the digest is not
    keyed, so it is a check against accidents and mixed-up files, not a seal.
    """
    h = hashlib.sha256(f"{config_sha}:{k}:{i0}:{i1}:{decoding}".encode())
    for name in sorted(crcs):
        h.update(f"|{name}|{int(crcs[name]):08x}".encode())
    return h.hexdigest()


def manifest_digest(manifest: dict) -> str:
    """The digest of a manifest's content (every key but ``digest``)."""
    body = {k: v for k, v in manifest.items() if k != "digest"}
    return hashlib.sha256(json.dumps(body, sort_keys=True).encode()).hexdigest()


class Journal:
    """The ``<cube>.parts`` folder: a manifest and one ``.npz`` per finished slab."""

    def __init__(self, cube_path):
        self.dir = Path(str(cube_path) + ".parts")
        self.manifest = self.dir / "manifest.json"

    def exists(self) -> bool:
        """Whether the folder holds a manifest (a regular file, never a link's target)."""
        return regular(self.manifest) and regular(self.dir, stat.S_ISDIR)

    def read_manifest(self) -> dict:
        """The manifest's content; {} when it cannot be read or is not a JSON object."""
        try:
            fd = os.open(self.manifest, os.O_RDONLY | NOFOLLOW)
            with os.fdopen(fd, "rb") as fh:
                data = json.loads(fh.read(10_000_000).decode("utf-8"))
        except (OSError, ValueError):
            return {}
        return data if isinstance(data, dict) else {}

    def refuse_links(self):
        """Refuse a symbolic link at ``<cube>.parts`` or inside it, with one line naming
        it (a link there would carry the journal's writes out of the output's folder)."""
        refuse_link(self.dir, "--out")
        if regular(self.dir, stat.S_ISDIR):
            for p in self.dir.iterdir():
                refuse_link(p, "--out")

    def foreign(self) -> bool:
        """True when ``<cube>.parts`` exists but is not a journal nylonflex wrote: a
        non-folder, or a folder with anything but a manifest, slab files and their
        temporaries in it (regular files, never links)."""
        if not os.path.lexists(self.dir):
            return False
        if not regular(self.dir, stat.S_ISDIR):
            return True
        for p in self.dir.iterdir():
            ours = p.name in ("manifest.json", "manifest.json.tmp") or \
                (p.name.startswith("slab-") and p.suffix in (".npz", ".tmp")) or \
                (p.name.startswith("aside-") and p.suffix == ".h5" and p.stem[6:].isdigit())
            if not (ours and regular(p)):
                return True
        return False

    def start(self, manifest: dict):
        """Begin a journal (the folder must be absent, empty or a nylonflex journal)."""
        self.refuse_links()
        if self.foreign():
            raise InputError(f"{self.dir} exists and was not written by nylonflex; it is "
                             "not deleted: move it or choose another --out")
        if os.path.lexists(self.dir):
            shutil.rmtree(self.dir)
        self.dir.mkdir(parents=True)
        manifest = {"format": JOURNAL_FORMAT, **manifest}
        manifest["digest"] = manifest_digest(manifest)
        _atomic_write(self.manifest, json.dumps(manifest, indent=1).encode())
        fsync_dir(self.dir.parent)

    def _slab_path(self, k):
        return self.dir / f"slab-{k:06d}.npz"

    def done(self) -> set[int]:
        out = set()
        for p in self.dir.glob("slab-*.npz"):
            with contextlib.suppress(ValueError):
                out.add(int(p.stem.split("-")[1]))
        return out

    def save(self, k: int, arrays: dict, *, slab=(0, 0), config_sha: str = "",
             decoding: str = ""):
        """Journal slab ``k`` (radii ``slab``) with its index, range and digest (of the
        arrays, the config's hash and ``decoding``: how its chunks decode)."""
        i0, i1 = (int(x) for x in slab)
        tmp = self._slab_path(k).with_suffix(".tmp")
        with _new_file(tmp) as fh:
            # an .npz as np.savez writes it (stored members), the arrays first: their
            # CRC-32s, computed as they are written, go into the digest of __meta__
            with zipfile.ZipFile(fh, "w", zipfile.ZIP_STORED, allowZip64=True) as zf:
                crcs = {name: _write_member(zf, name, arrays[name]) for name in arrays}
                meta = {"index": int(k), "slab": [i0, i1], "config_sha256": config_sha,
                        "digest": _digest(config_sha, k, i0, i1, crcs, decoding)}
                _write_member(zf, "__meta__",
                              np.frombuffer(json.dumps(meta).encode(), np.uint8))
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, self._slab_path(k))
        fsync_dir(self.dir)

    def load(self, k: int, *, slab=None, config_sha: str | None = None,
             decoding: str = "") -> dict:
        """Slab ``k``'s arrays, verified against its index, radius range ``slab`` and
        digest (which covers ``decoding``); :class:`SlabInvalid` when anything does not
        match or cannot be read."""
        path = self._slab_path(k)
        try:
            fd = os.open(path, os.O_RDONLY | NOFOLLOW)
            with os.fdopen(fd, "rb") as fh, zipfile.ZipFile(fh) as zf:
                arrays, crcs = {}, {}
                for info in zf.infolist():
                    name = info.filename.removesuffix(".npy")
                    # read whole, so that zipfile checks the member's CRC-32
                    arrays[name] = np.lib.format.read_array(io.BytesIO(zf.read(info)),
                                                            allow_pickle=False)
                    crcs[name] = info.CRC
        except Exception as exc:  # noqa: BLE001 - zip, zlib, format: all mean "unreadable"
            raise SlabInvalid(f"{path.name} is unreadable ({type(exc).__name__})") from None
        crcs.pop("__meta__", None)
        raw = arrays.pop("__meta__", None)
        if raw is None:
            raise SlabInvalid(f"{path.name} has no index, range or digest")
        try:
            meta = json.loads(raw.tobytes().decode())
            index, (i0, i1), digest = meta["index"], meta["slab"], meta["digest"]
        except Exception:  # noqa: BLE001
            raise SlabInvalid(f"{path.name} has damaged metadata") from None
        if index != k:
            raise SlabInvalid(f"{path.name} holds slab {index}, not {k}")
        if slab is not None and [i0, i1] != [int(x) for x in slab]:
            raise SlabInvalid(f"{path.name} holds radii {i0}..{i1}, not "
                              f"{slab[0]}..{slab[1]}")
        sha = meta.get("config_sha256", "") if config_sha is None else config_sha
        if _digest(sha, k, i0, i1, crcs, decoding) != digest:
            raise SlabInvalid(f"{path.name} fails its digest")
        return arrays

    def asides(self) -> list[Path]:
        """The building files of interrupted runs moved here (:meth:`aside_path`), newest
        first: where this journal's chunks may lie."""
        return sorted((p for p in self.dir.glob("aside-*.h5") if p.stem[6:].isdigit()),
                      reverse=True)

    def aside_path(self) -> Path:
        """A new name for an interrupted run's building file in this folder."""
        last = self.asides()
        n = int(last[0].stem.split("-")[1]) + 1 if last else 1
        return self.dir / f"aside-{n:06d}.h5"

    def drop_asides(self):
        """Remove the moved building files (every record now points into the new cube)."""
        for p in self.asides():
            with contextlib.suppress(OSError):
                p.unlink()
        fsync_dir(self.dir)

    def discard(self, k: int):
        """Remove slab ``k``'s file (it failed verification and will be recomputed)."""
        with contextlib.suppress(OSError):
            self._slab_path(k).unlink()

    def remove(self):
        shutil.rmtree(self.dir, ignore_errors=True)
        fsync_dir(self.dir.parent)


def regular(path, kind=stat.S_ISREG) -> bool:
    """Whether ``path`` itself (not a link's target) is of ``kind`` (a regular file)."""
    try:
        return kind(os.lstat(path).st_mode)
    except OSError:
        return False


def _write_member(zf, name: str, array) -> int:
    """``array`` written as the member ``<name>.npy`` of the zip ``zf`` (NumPy's .npy
    format, as np.savez writes it); returns the member's CRC-32."""
    with zf.open(name + ".npy", "w", force_zip64=True) as member:
        np.lib.format.write_array(member, np.asanyarray(array), allow_pickle=False)
    return zf.getinfo(name + ".npy").CRC


def _new_file(tmp: Path):
    """``tmp`` created new for writing (a leftover temporary of a killed run is removed
    first; a link there is removed, never followed)."""
    with contextlib.suppress(FileNotFoundError):
        os.unlink(tmp)
    return os.fdopen(create_new(tmp), "wb")


def _atomic_write(path: Path, data: bytes):
    tmp = path.with_name(path.name + ".tmp")
    with _new_file(tmp) as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    fsync_dir(path.parent)


def file_locks():
    """The ``fcntl`` module, whose ``flock`` guards a cube being written (POSIX: Linux,
    macOS, the BSDs). Without it (Windows) writing a cube is refused with one line
    (InputError); a sweep in memory (``nylonflex.run_sweep(cfg)``) and reading cubes work
    everywhere."""
    try:
        import fcntl
    except ImportError:
        raise InputError("sweep: writing a cube needs POSIX file locks (fcntl), which this "
                         "platform lacks: run it on Linux or macOS (or WSL), or sweep in "
                         "memory from Python with nylonflex.run_sweep(cfg)") from None
    return fcntl
