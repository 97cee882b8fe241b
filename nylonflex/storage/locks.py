"""The writer's locks on a cube being written: ``<cube>.lock`` and ``<cube>.building``.

One writer, provably: :func:`exclusive` holds an ``flock`` on ``<cube>.lock`` (a releasing
writer unlinks it while still holding it, and a taker checks that the file it locked is
still the one at that path, so the unlink-then-unlock race cannot admit two writers) *and*
on ``<cube>.building`` itself, opened without truncation. Deleting a "stale" lock file
therefore does not let a second writer in: the building file's lock refuses it before it
touches any file. Before the building file is renamed onto the cube, its lock is made a
shared one (:func:`share_building`). :func:`renew_building` moves an interrupted run's
building file into the journal (its chunks are what the journal records) and locks a new
one in its place.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from ..files.atomic import NOFOLLOW, create_new, fsync_dir, refuse_link, refuse_special
from ..units import InputError
from .journal import Journal, file_locks, regular

__all__ = ["building_is_ours", "building_path", "check_building", "exclusive",
           "renew_building", "share_building"]

_LOCK_TEXT = b"nylonflex sweep lock\n"


def _busy(cube_path, what) -> RuntimeError:
    return RuntimeError(f"another sweep is writing {cube_path} ({what} is locked); wait "
                        "for it or stop it first")


def _lock_file(lock: Path):
    """An fd of ``lock`` holding its flock: the file at that path when the lock was won."""
    fcntl = file_locks()

    refuse_special(lock, "--out")
    if regular(lock):
        with os.fdopen(os.open(lock, os.O_RDONLY | NOFOLLOW), "rb") as fh:
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
        return os.open(path, os.O_RDWR | os.O_CREAT | NOFOLLOW, 0o644)
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
            regular(building)
    except OSError:
        same = False
    if not same:
        raise RuntimeError(f"{building} was replaced while this run held it; nothing is "
                           "published: run again")


def renew_building(building, aside: Path):
    """Move the locked building file of an interrupted run to ``aside`` (in the journal's
    folder: its chunks are what the journal's records point to) and lock a new, empty
    file at ``building`` in its place; this process then holds that one.

    The writer's lock on ``<cube>.lock`` is held throughout, so no second writer can take
    the path between the two steps; the new file is made with ``O_EXCL`` (never through a
    link) and locked before the old one's lock is let go.
    """
    fcntl = file_locks()

    check_building(building)
    old = _HELD[str(building)]
    os.rename(building, aside)
    try:
        fd = create_new(building)
    except OSError as exc:
        raise InputError(f"--out: {building} cannot be made ({exc.strerror})") from None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        raise _busy(building.with_suffix(""), building.name) from None
    _HELD[str(building)] = fd
    os.close(old)
    fsync_dir(Path(building).parent)
    fsync_dir(Path(aside).parent)


def building_path(cube_path) -> Path:
    cube_path = Path(cube_path)
    return cube_path.with_name(cube_path.name + ".building")


def building_is_ours(building: Path, journal: Journal) -> bool:
    """Whether an existing ``<cube>.building`` may be rewritten: empty, an HDF5 file (a
    building cube), or accompanied by this output's journal."""
    import h5py

    if not os.path.lexists(building):
        return True
    if not regular(building):
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
        # the fd now held: renew_building may have replaced the first one
        bfd = _HELD.pop(str(building), bfd)
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
