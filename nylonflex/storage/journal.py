"""The journal of a sweep (``<cube>.parts/``) and the lock that makes one writer.

One writer, provably: :func:`exclusive` holds an ``flock`` on ``<cube>.lock`` (a releasing
writer unlinks it while still holding it, and a taker checks that the file it locked is
still the one at that path, so the unlink-then-unlock race cannot admit two writers) *and*
on ``<cube>.building`` itself, opened without truncation. Deleting a "stale" lock file
therefore does not let a second writer in: the building file's lock refuses it before it
touches any file. The cube writer opens the building file with HDF5's own locking off,
since this process already holds the lock on it. Before the building file is renamed onto
the cube, its lock is made a shared one (:func:`share_building`): a reader's HDF5 lock
(shared) never meets the writer's on the published file, and a second writer's
(exclusive) is still refused.

No side path is followed: a symbolic link at ``<cube>.lock``, ``<cube>.building``,
``<cube>.parts`` or inside it is refused with one line naming it, and every file there is
created new (``O_EXCL | O_NOFOLLOW``) and renamed into place, so that a run never writes
outside the output's folder.

The journal verifies itself: the manifest records its format, the nylonflex version, the
model digest, the slab plan and the codec; the run checks each against what the config
and the code imply (:mod:`.run`), not against the manifest itself. Every slab file records
its index, its radius range and a digest of its arrays (of the CRC-32 each zip member
records) bound to the config's hash and to everything that decodes them (codec, filters,
chunking: ``decoding``). A slab that fails verification is recomputed, never trusted.
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
from ..files.atomic import create_new, fsync_dir, publish, refuse_link, refuse_special

__all__ = ["JOURNAL_FORMAT", "Journal", "SlabInvalid", "exclusive", "fsync_dir",
           "publish", "refuse_special", "share_building"]

#: Version of the journal's layout (manifest keys, slab metadata). 3: a slab's digest
#: covers how its chunks decode (codec, filters, chunking). 4: it covers each array's
#: CRC-32 (the one its zip member records) instead of hashing the arrays' bytes again.
JOURNAL_FORMAT = 4
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_MANIFEST_KEYS = ("format", "name", "config_sha256", "slabs", "radius_chunk",
                  "nylonflex_version", "model_digest", "replaces")
_LOCK_TEXT = b"nylonflex sweep lock\n"


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
        return _regular(self.manifest) and _regular(self.dir, stat.S_ISDIR)

    def read_manifest(self) -> dict:
        """The manifest's content; {} when it cannot be read or is not a JSON object."""
        try:
            fd = os.open(self.manifest, os.O_RDONLY | _NOFOLLOW)
            with os.fdopen(fd, "rb") as fh:
                data = json.loads(fh.read(10_000_000).decode("utf-8"))
        except (OSError, ValueError):
            return {}
        return data if isinstance(data, dict) else {}

    def refuse_links(self):
        """Refuse a symbolic link at ``<cube>.parts`` or inside it, with one line naming
        it (a link there would carry the journal's writes out of the output's folder)."""
        refuse_link(self.dir, "--out")
        if _regular(self.dir, stat.S_ISDIR):
            for p in self.dir.iterdir():
                refuse_link(p, "--out")

    def foreign(self) -> bool:
        """True when ``<cube>.parts`` exists but is not a journal nylonflex wrote: a
        non-folder, or a folder with anything but a manifest, slab files and their
        temporaries in it (regular files, never links)."""
        if not os.path.lexists(self.dir):
            return False
        if not _regular(self.dir, stat.S_ISDIR):
            return True
        for p in self.dir.iterdir():
            ours = p.name in ("manifest.json", "manifest.json.tmp") or \
                (p.name.startswith("slab-") and p.suffix in (".npz", ".tmp"))
            if not (ours and _regular(p)):
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
            fd = os.open(path, os.O_RDONLY | _NOFOLLOW)
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

    def discard(self, k: int):
        """Remove slab ``k``'s file (it failed verification and will be recomputed)."""
        with contextlib.suppress(OSError):
            self._slab_path(k).unlink()

    def remove(self):
        shutil.rmtree(self.dir, ignore_errors=True)
        fsync_dir(self.dir.parent)


def _regular(path, kind=stat.S_ISREG) -> bool:
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


def _busy(cube_path, what) -> RuntimeError:
    return RuntimeError(f"another sweep is writing {cube_path} ({what} is locked); wait "
                        "for it or stop it first")


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


def _lock_file(lock: Path):
    """An fd of ``lock`` holding its flock: the file at that path when the lock was won."""
    fcntl = file_locks()

    refuse_special(lock, "--out")
    if _regular(lock):
        with os.fdopen(os.open(lock, os.O_RDONLY | _NOFOLLOW), "rb") as fh:
            head = fh.read(64)
        if head and not head.startswith(_LOCK_TEXT.strip()):
            raise InputError(f"{lock} exists and is not a nylonflex lock; it is not "
                             "replaced: move it or choose another --out")
    while True:
        fd = _open_side(lock)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            return None
        try:
            same = os.lstat(lock).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            same = False
        if same:
            os.ftruncate(fd, 0)
            os.write(fd, _LOCK_TEXT + f"pid {os.getpid()}\n".encode())
            return fd
        os.close(fd)  # a releasing writer unlinked it after we opened it: take the new one


def _open_side(path: Path) -> int:
    """An fd of the side file ``path`` for reading and writing, made if missing, never
    truncated and never through a link (one placed there meanwhile is refused)."""
    try:
        return os.open(path, os.O_RDWR | os.O_CREAT | _NOFOLLOW, 0o644)
    except OSError as exc:
        if os.path.islink(path):
            refuse_link(path, "--out")
        raise InputError(f"--out: {path} cannot be opened ({exc.strerror})") from None


#: The building files this process holds: path -> the fd that holds its lock.
_HELD: dict = {}


def share_building(building):
    """Make this process's lock on ``building`` a shared one, before it is published.

    A reader's HDF5 lock is a shared ``flock``: an exclusive lock on the published inode
    made it fail ("unable to lock file") until the journal was removed. A second writer's
    exclusive lock is still refused (and the lock file is still held).
    """
    fcntl = file_locks()

    fd = _HELD.get(str(building))
    if fd is not None:
        fcntl.flock(fd, fcntl.LOCK_SH)


def check_building(building):
    """Raise RuntimeError unless ``building`` is still the file this process locked (not
    replaced, nor by a link, since the lock was taken)."""
    fd = _HELD.get(str(building))
    try:
        same = fd is not None and os.lstat(building).st_ino == os.fstat(fd).st_ino and \
            _regular(building)
    except OSError:
        same = False
    if not same:
        raise RuntimeError(f"{building} was replaced while this run held it; nothing is "
                           "published: run again")


def building_path(cube_path) -> Path:
    cube_path = Path(cube_path)
    return cube_path.with_name(cube_path.name + ".building")


def building_is_ours(building: Path, journal: Journal) -> bool:
    """Whether an existing ``<cube>.building`` may be rewritten: empty, an HDF5 file (a
    building cube), or accompanied by this output's journal."""
    import h5py

    if not os.path.lexists(building):
        return True
    if not _regular(building):
        return False
    if building.stat().st_size == 0 or journal.exists():
        return True
    try:
        return h5py.is_hdf5(building)
    except OSError:
        return False


@contextlib.contextmanager
def exclusive(cube_path):
    """Hold the writer's locks on ``<cube>.lock`` and ``<cube>.building`` for a run.

    A second run on the same output is refused (RuntimeError) before it changes any file,
    even when the first run's lock file was deleted. Yields the path of the building file,
    which the holder may then open for writing (with HDF5 file locking off).
    """
    fcntl = file_locks()

    cube_path = Path(cube_path)
    lock = Path(str(cube_path) + ".lock")
    building = building_path(cube_path)
    lock.parent.mkdir(parents=True, exist_ok=True)
    refuse_special(building, "--out")
    Journal(cube_path).refuse_links()
    fd = _lock_file(lock)
    if fd is None:
        raise _busy(cube_path, lock.name)
    bfd, created = None, False
    try:
        if not building_is_ours(building, Journal(cube_path)):
            raise InputError(f"{building} exists and was not written by nylonflex; it is "
                             "not replaced: move it or choose another --out")
        created = not os.path.lexists(building)
        bfd = _open_side(building)  # never truncating
        try:
            fcntl.flock(bfd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            raise _busy(cube_path, building.name) from None
        _HELD[str(building)] = bfd
        yield building
    finally:
        _HELD.pop(str(building), None)
        if bfd is not None:
            # an unused building file this run created is not left behind
            with contextlib.suppress(OSError):
                st = os.lstat(building)
                if created and st.st_ino == os.fstat(bfd).st_ino and st.st_size == 0:
                    building.unlink()
            os.close(bfd)
        with contextlib.suppress(OSError):
            lock.unlink()  # while still held: a waiting taker re-checks the inode
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)
