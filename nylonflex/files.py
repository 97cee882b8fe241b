"""Files the user owns: durable publishing renames, and refusing special files.

Used by every writer of an output (the sweep's cube and journal, a simulation): nothing is
ever written over a device, fifo, socket or folder, and a rename that publishes a result is
preceded by an fsync of the file and followed by one of its folder, so that after a crash
the name points to whole data or to the old file.
"""

from __future__ import annotations

import contextlib
import os
import stat
from pathlib import Path

from .units import InputError

__all__ = ["OwnedFiles", "fsync_dir", "publish", "refuse_special"]


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
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, final)
    fsync_dir(final.parent)


def refuse_special(path: Path, what: str):
    """Refuse a path that exists and is not a regular file (a device, fifo, socket, link
    to one, or folder): nothing is ever written over it."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as exc:
        raise InputError(f"{what}: {path} cannot be read ({exc.strerror})") from None
    if stat.S_ISDIR(mode):
        raise InputError(f"{what}: {path} is a folder; give a file path such as "
                         f"{path}/cube.h5")
    if not stat.S_ISREG(mode):
        raise InputError(f"{what}: {path} is a special file (device, fifo or socket); "
                         "nylonflex writes only regular files")


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
        import json

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
        import json

        for path in paths:
            path = Path(path)
            self.files[path.name] = {"source": self.owner, "sha256": self._digest(path)}
        tmp = self.path.with_name(self.NAME + ".tmp")
        tmp.write_text(json.dumps({"format": 1, "files": self.files}, indent=1,
                                  sort_keys=True))
        publish(tmp, self.path)
