"""A journal's record of a slab, and the slab restored from it on ``--resume``.

A record (journal format 5) is what :meth:`.cube.CubeFile.encode` made of the slab, with
each compressed variable's bytes (``NAME:bytes``) replaced by where its chunks now lie in
the cube file (``NAME:addresses`` [B], from :meth:`.cube.CubeFile.write_encoded`); the
chunk offsets, sizes [B] and CRC-32s stay. Restoring reads each chunk back from a file
that may hold it and keeps it only when its size and CRC-32 match (a file holds all of a
slab's chunks or none of them is taken from it).
"""

from __future__ import annotations

import contextlib
import os

import numpy as np

from ..files.atomic import NOFOLLOW
from .codec import crc32
from .journal import SlabInvalid

__all__ = ["ChunkSources", "journal_record"]



def journal_record(encoded: dict, addresses: dict) -> dict:
    """What the journal keeps of an encoded slab once it is in the cube: ``encoded``
    without the chunks' bytes, with their addresses in the file (``addresses``,
    ``{NAME:addresses: byte offsets [B]}``)."""
    record = {key: value for key, value in encoded.items() if not key.endswith(":bytes")}
    record.update(addresses)
    return record


class ChunkSources:
    """Files that may hold a journal's chunks, opened for reading (never through a link).

    ``paths``: the files to try, in order (the journal's asides, newest first, then the
    incomplete cube a stopped run published); those that cannot be opened are skipped.
    """

    def __init__(self, paths):
        self._fds = []
        for path in paths:
            with contextlib.suppress(OSError):
                self._fds.append(os.open(path, os.O_RDONLY | NOFOLLOW))

    def slab(self, record: dict, name: str = "slab") -> dict:
        """``record`` with each compressed variable's ``NAME:bytes`` read back from the
        first file that holds every chunk at its address, of its size and CRC-32
        (:class:`~nylonflex.storage.journal.SlabInvalid`, naming ``name``, when none
        does)."""
        wanted = [key.partition(":")[0] for key in record if key.endswith(":addresses")]
        for i, fd in enumerate(self._fds):
            found = self._read(fd, record, wanted)
            if found is not None:
                if i:  # the next slab most likely lies in the same file
                    self._fds.insert(0, self._fds.pop(i))
                return {**{k: v for k, v in record.items() if not k.endswith(":addresses")},
                        **found}
        if not wanted:
            return dict(record)
        raise SlabInvalid(f"{name}'s chunks are in none of the files the journal knows "
                          "(or were changed there)")

    @staticmethod
    def _read(fd: int, record: dict, names) -> dict | None:
        """``{NAME:bytes: the chunks}`` as ``fd`` holds them, or None when one differs."""
        found, room = {}, os.fstat(fd).st_size
        for name in names:
            sizes, crcs = record[f"{name}:sizes"], record[f"{name}:crcs"]
            addresses = record[f"{name}:addresses"]
            if not (len(sizes) == len(crcs) == len(addresses)) or np.sum(sizes) > room:
                return None
            out = np.empty(int(np.sum(sizes)), dtype=np.uint8)
            view, end = memoryview(out), 0
            for where, size, crc in zip(addresses.tolist(), sizes.tolist(), crcs.tolist()):
                if where < 0 or size < 0:
                    return None
                try:
                    got = os.preadv(fd, [view[end:end + size]], where)
                except (OSError, OverflowError):
                    return None
                if got != size or crc32(view[end:end + size]) != crc:
                    return None
                end += size
            found[f"{name}:bytes"] = out
        return found

    def close(self):
        for fd in self._fds:
            os.close(fd)
        self._fds = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
