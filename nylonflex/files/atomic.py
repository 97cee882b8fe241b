"""Files the user owns: one way to create or replace a path, and refusing what is in the way.

Every writer of nylonflex (the sweep's cube, building file, lock and journal; charts,
material files, explorer pages, simulations, manifests) goes through this module:

- a path is written only through a temporary created new beside it (``O_CREAT | O_EXCL |
  O_NOFOLLOW``: never an existing file, never through a link) and renamed onto it once its
  bytes are on disk (:func:`replacing`, :func:`write_atomic`); the rename is preceded by an
  fsync of the file and followed by one of its folder, so that after a crash the name
  points to whole data or to the old file;
- nothing is written at a path that is a symbolic link, a device, fifo, socket or folder
  (:func:`refuse_special`, which looks at the path itself with ``lstat``), nor onto a file
  the same command reads (``inputs``): a run never writes outside the output's folder.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import secrets
import stat
from pathlib import Path

from ..units import InputError

__all__ = ["NOFOLLOW", "OwnedFiles", "create_files", "create_new", "fsync_dir", "make_folder", "publish",
           "read_bounded", "read_json", "refuse_link", "refuse_special", "replacing",
           "save_figure", "write_atomic"]

#: ``os.O_NOFOLLOW`` where the platform has it (0 elsewhere): open never through a link.
NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
#: The flags of a file nylonflex creates: a new file, never through a link at its path.
NEW_FILE = os.O_WRONLY | os.O_CREAT | os.O_EXCL | NOFOLLOW | \
    getattr(os, "O_CLOEXEC", 0)


def fsync_dir(path):
    """fsync a folder, so that a rename inside it survives a crash."""
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def publish(tmp: Path, final: Path):
    """Rename ``tmp`` onto ``final`` durably: fsync the file, rename, fsync the folder."""
    fd = os.open(tmp, os.O_RDONLY | NOFOLLOW)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
    os.replace(tmp, final)
    fsync_dir(final.parent)


def _link_error(path, what) -> InputError:
    try:
        target = f" (to {os.readlink(path)!s:.200})"
    except OSError:
        target = ""
    return InputError(f"{what}: {path} is a symbolic link{target}; nylonflex never writes "
                      "through a link: remove it or choose another path")


def refuse_link(path, what: str):
    """Refuse ``path`` when it is a symbolic link (dangling or not): one line naming it.

    For the side paths of an output (``<out>.lock``, ``<out>.building``, ``<out>.parts``
    and what is in it), where a link would carry a write out of the output's folder.
    """
    if os.path.islink(path):
        raise _link_error(path, what)


def refuse_special(path: Path, what: str, inputs=()):
    """Refuse a path that exists and is not a regular file (a symbolic link, device, fifo,
    socket, or folder), or that is one of ``inputs`` (files the same command reads):
    nothing is ever written over it.

    The path itself is looked at (``lstat``): a link is refused, not followed.
    """
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise InputError(f"{what}: {path} cannot be read ({exc.strerror})") from None
    mode = st.st_mode
    if stat.S_ISLNK(mode):
        raise _link_error(path, what)
    if stat.S_ISDIR(mode):
        raise InputError(f"{what}: {path} is a folder; give a file path such as "
                         f"{path}/cube.h5")
    if not stat.S_ISREG(mode):
        raise InputError(f"{what}: {path} is a special file (device, fifo or socket); "
                         "nylonflex writes only regular files")
    for source in inputs:
        try:
            other = os.stat(source)
        except (OSError, TypeError, ValueError):
            continue
        if (other.st_dev, other.st_ino) == (st.st_dev, st.st_ino):
            raise InputError(f"{what}: {path} is also an input of this command ({source}); "
                             "it is not replaced: choose another path")


def create_new(path, mode: int = 0o666) -> int:
    """Open ``path`` as a new regular file (an fd for writing): refused (FileExistsError)
    when anything is at the path, a link included; the umask applies to ``mode``."""
    return os.open(path, NEW_FILE, mode)


def _temporary(path: Path) -> tuple[Path, int]:
    """A new temporary file beside ``path``, created by this process: (its path, an fd)."""
    for _ in range(100):
        tmp = path.with_name(f".{path.name[:200]}.{os.getpid()}.{secrets.token_hex(4)}.tmp")
        try:
            return tmp, create_new(tmp)
        except FileExistsError:
            continue
    raise InputError(f"{path.parent}: cannot create a temporary file there")


@contextlib.contextmanager
def replacing(path, what: str = "--out", inputs=()):
    """Write ``path`` through a new temporary file: yields the temporary's path.

    The caller writes the whole result into the yielded path (a library that takes a file
    name: matplotlib, h5py). On a clean exit it is fsynced and renamed onto ``path``; on an
    error it is removed and ``path`` is left as it was. ``path`` is refused first (see
    :func:`refuse_special`) when it is a link, a special file, a folder or one of
    ``inputs``; its folder is made when missing.
    """
    path = Path(path)
    refuse_special(path, what, inputs)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp, fd = _temporary(path)
    os.close(fd)
    try:
        yield tmp
        refuse_special(path, what, inputs)  # nothing was put in the way meanwhile
        publish(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)


#: OSError numbers that are no fault of the path the user gave (a full disk, an I/O
#: error): they stay failures (exit 1) where every other error at a path is bad input.
NOT_THE_PATH = (errno.ENOSPC, errno.EDQUOT, errno.EIO, errno.EINTR, errno.ENOMEM)


def path_error(exc: OSError, path, what: str) -> Exception:
    """``exc``, raised at ``path``, as the one line a user reads: an :class:`InputError`
    naming ``what`` and the path (a file where a folder goes, a missing or unwritable
    folder, ``/proc``), or ``exc`` itself for a full disk or an I/O error."""
    if exc.errno in NOT_THE_PATH:
        return exc
    return InputError(f"{what}: {path}: {exc.strerror or exc}")


def make_folder(folder, what: str) -> list[Path]:
    """Make the folder ``folder`` and its missing parents; returns those it made (outermost
    first). A file, a dangling link or anything but a folder at ``folder`` or a parent is
    refused in one line (:func:`path_error`)."""
    folder = Path(folder)
    missing = []
    for p in (folder, *folder.parents):
        if os.path.isdir(p):
            break
        if os.path.lexists(p):
            kind = "a dangling symbolic link" if os.path.islink(p) else "not a folder"
            raise InputError(f"{what}: {p} is {kind}; give a folder")
        missing.append(p)
    made = []
    for p in reversed(missing):
        try:
            p.mkdir()
        except FileExistsError:
            if not os.path.isdir(p):
                raise InputError(f"{what}: {p} is not a folder; give a folder") from None
            continue
        except OSError as exc:
            raise path_error(exc, p, what) from None
        made.append(p)
    return made


def _link_new(tmp: Path, path: Path):
    """Give the whole file ``tmp`` the name ``path`` unless something is there already
    (``FileExistsError``): a hard link, or a rename after a check where the file system
    has no hard links."""
    try:
        os.link(tmp, path, follow_symlinks=False)
    except FileExistsError:
        raise
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EMLINK):
            raise
        if os.path.lexists(path):
            raise FileExistsError(errno.EEXIST, "File exists", str(path)) from None
        os.rename(tmp, path)


def create_files(contents: dict, what: str) -> list[Path]:
    """Create every file of ``contents`` ({path: bytes}) whole, or none of them: each is
    written into a new temporary beside it, fsynced, then given its name without replacing
    anything (a file made meanwhile is refused, ``FileExistsError``). On any failure (a
    full disk) the files and folders made so far are removed: no truncated file is left.
    Returns the paths, in order."""
    paths = [Path(p) for p in contents]
    temps, made, folders = [], [], []
    try:
        for path in paths:
            folders += make_folder(path.parent, what)
            tmp, fd = _temporary(path)
            temps.append(tmp)
            with os.fdopen(fd, "wb") as fh:
                fh.write(contents[path])
                fh.flush()
                os.fsync(fh.fileno())
        for path, tmp in zip(paths, temps):
            _link_new(tmp, path)
            made.append(path)
        for folder in dict.fromkeys(p.parent for p in paths):
            fsync_dir(folder)
    except BaseException:
        for path in made:
            with contextlib.suppress(OSError):
                os.unlink(path)
        for tmp in temps:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
        for folder in reversed(folders):
            with contextlib.suppress(OSError):
                folder.rmdir()
        raise
    for tmp in temps:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
    return paths


#: How a file nylonflex reads back is opened: never through a link, never waiting for a
#: writer (a fifo opened for reading blocks until one comes: forever).
READ_FLAGS = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | NOFOLLOW | \
    getattr(os, "O_CLOEXEC", 0)


def read_bounded(path, what: str, max_bytes: int) -> bytes | None:
    """The bytes of the regular file ``path`` (None when nothing is there), at most
    ``max_bytes`` [B] of them.

    Opened without following a link and without blocking, then checked on the open file:
    a link, fifo, device, socket or folder is an :class:`InputError` naming ``what``,
    before anything is read; a larger file is a ``ValueError`` (the caller decides whether
    that is damage or bad input).
    """
    try:
        fd = os.open(path, READ_FLAGS)
    except FileNotFoundError:
        return None
    except OSError as exc:
        if exc.errno == errno.ELOOP or os.path.islink(path):
            raise _link_error(path, what) from None
        raise path_error(exc, path, what) from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise InputError(f"{what}: {path} is a folder, not a file nylonflex wrote")
        if not stat.S_ISREG(st.st_mode):
            raise InputError(f"{what}: {path} is a special file (device, fifo or socket); "
                             "nylonflex reads back only regular files")
        if st.st_size > max_bytes:
            raise ValueError(f"{st.st_size:,} bytes, more than {max_bytes:,}")
        chunks, left = [], max_bytes + 1
        while left > 0:
            block = os.read(fd, min(left, 1 << 20))
            if not block:
                break
            chunks.append(block)
            left -= len(block)
        data = b"".join(chunks)
        if len(data) > max_bytes:  # it grew meanwhile
            raise ValueError(f"more than {max_bytes:,} bytes")
        return data
    finally:
        os.close(fd)


#: Nesting that a JSON file nylonflex writes never reaches (its run files: 4).
JSON_DEPTH = 32


def read_json(path, what: str, max_bytes: int = 1 << 20, max_depth: int = JSON_DEPTH):
    """The JSON value of the file ``path`` (None when nothing is there).

    Read by :func:`read_bounded` (links and special files: :class:`InputError`); text that
    is larger than ``max_bytes``, not UTF-8, nested deeper than ``max_depth`` or not
    JSON is a plain ``ValueError`` saying which, so a caller never meets a RecursionError.
    """
    import numpy as np

    data = read_bounded(path, what, max_bytes)
    if data is None:
        return None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise ValueError("not UTF-8 text") from None
    # nesting: brackets outside strings, counted at C speed
    bare = re.sub(r'"(?:[^"\\]|\\.)*"', '""', text).encode()
    arr = np.frombuffer(bare, dtype=np.uint8)
    if arr.size:
        step = np.isin(arr, (91, 123)).astype(np.int32) - np.isin(arr, (93, 125))
        if int(np.cumsum(step).max()) > max_depth:
            raise ValueError(f"nested deeper than {max_depth}")
    try:
        return json.loads(text)
    except (ValueError, RecursionError) as exc:
        raise ValueError(f"not JSON ({str(exc)[:80]})") from None


def save_figure(fig, path, what: str = "--out", inputs=(), **kwargs) -> Path:
    """``fig.savefig`` into ``path`` through a new temporary and a rename (:func:`replacing`);
    the format is the suffix's unless ``format`` is given. Returns ``path``."""
    path = Path(path)
    kwargs.setdefault("format", path.suffix.lstrip(".").lower() or "png")
    with replacing(path, what, inputs) as tmp:
        fig.savefig(tmp, **kwargs)
    return path


def write_atomic(path, data: bytes, what: str = "--out", inputs=()) -> Path:
    """Write ``data`` [bytes] to ``path`` through a new temporary and a rename
    (:func:`replacing`); returns ``path``."""
    path = Path(path)
    with replacing(path, what, inputs) as tmp:
        fd = os.open(tmp, os.O_WRONLY | NOFOLLOW)
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
    return path


class OwnedFiles:
    """The files nylonflex wrote into a folder, and for which source, in a small manifest.

    ``<folder>/.nylonflex-charts.json`` maps a file name to the source it was drawn from
    (a cube's resolved path) and the SHA-256 of the bytes written. A file may be replaced
    only when the manifest says this source wrote it and its bytes are still the ones
    written: a file of the user's, of another cube, or edited since is left alone.

    Parameters
    ----------
    folder : path
        The output folder [-].
    owner : str
        Who writes [-]: the cube's resolved path (or its name when it has no file).
    """

    NAME = ".nylonflex-charts.json"

    def __init__(self, folder, owner: str):
        self.folder, self.owner = Path(folder), str(owner)
        self.path = self.folder / self.NAME
        self.files = self._read()

    def _read(self) -> dict:
        refuse_special(self.path, "--out")
        try:
            raw = self.path.read_bytes()
        except FileNotFoundError:
            return {}
        except OSError as exc:
            raise InputError(f"{self.path} cannot be read ({exc.strerror})") from None
        try:
            data = json.loads(raw[:10_000_000].decode("utf-8"))
            files = data["files"]
            if data.get("format") != 1 or not isinstance(files, dict):
                raise ValueError
        except (ValueError, KeyError, TypeError, UnicodeDecodeError):
            raise InputError(f"{self.path} is not a nylonflex chart manifest; move it "
                             "away (the charts it listed are then treated as the user's)"
                             ) from None
        return files

    @staticmethod
    def _digest(path: Path) -> str:
        import hashlib

        h = hashlib.sha256()
        with open(path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        return h.hexdigest()

    def foreign(self, path) -> str | None:
        """Why ``path`` may not be replaced (a one-line reason), or None when it may: it
        does not exist, or this owner wrote it and it is unchanged."""
        path = Path(path)
        try:
            mode = os.lstat(path).st_mode
        except FileNotFoundError:
            return None
        if not stat.S_ISREG(mode):
            return f"{path} exists and is not a regular file"
        entry = self.files.get(path.name)
        if not isinstance(entry, dict):
            return f"{path} exists and nylonflex did not write it"
        if entry.get("source") != self.owner:
            return f"{path} was drawn from another cube ({entry.get('source')!s:.80})"
        if entry.get("sha256") != self._digest(path):
            return f"{path} was changed since nylonflex wrote it"
        return None

    def record(self, paths):
        """Record ``paths`` as written by this owner and save the manifest atomically."""
        for path in paths:
            path = Path(path)
            self.files[path.name] = {"source": self.owner, "sha256": self._digest(path)}
        write_atomic(self.path, json.dumps({"format": 1, "files": self.files}, indent=1,
                                           sort_keys=True).encode(), "--out")
