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

__all__ = ["fsync_dir", "publish", "refuse_special"]


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
