"""The journal of a sweep (``<cube>.parts/``) and the lock that makes one writer."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
from pathlib import Path

import numpy as np

__all__ = ["Journal", "exclusive"]


class Journal:
    """The ``<cube>.parts`` folder: a manifest and one ``.npz`` per finished slab."""

    def __init__(self, cube_path):
        self.dir = Path(str(cube_path) + ".parts")
        self.manifest = self.dir / "manifest.json"

    def exists(self) -> bool:
        return self.manifest.is_file()

    def read_manifest(self) -> dict:
        try:
            return json.loads(self.manifest.read_text())
        except (OSError, ValueError):
            return {}

    def start(self, manifest: dict):
        if self.dir.exists():
            shutil.rmtree(self.dir)
        self.dir.mkdir(parents=True)
        _atomic_write(self.manifest, json.dumps(manifest, indent=1).encode())

    def _slab_path(self, k):
        return self.dir / f"slab-{k:06d}.npz"

    def done(self) -> set[int]:
        out = set()
        for p in self.dir.glob("slab-*.npz"):
            with contextlib.suppress(ValueError):
                out.add(int(p.stem.split("-")[1]))
        return out

    def save(self, k: int, arrays: dict):
        tmp = self._slab_path(k).with_suffix(".tmp")
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
        os.replace(tmp, self._slab_path(k))

    def load(self, k: int) -> dict:
        with np.load(self._slab_path(k)) as z:
            return {name: z[name] for name in z.files}

    def remove(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def _atomic_write(path: Path, data: bytes):
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


@contextlib.contextmanager
def exclusive(cube_path):
    """Hold ``<cube>.lock`` for a run; a second run on the same output is refused."""
    import fcntl

    lock = Path(str(cube_path) + ".lock")
    lock.parent.mkdir(parents=True, exist_ok=True)
    fh = open(lock, "a+")
    try:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        fh.close()
        raise RuntimeError(f"another sweep is writing {cube_path} (lock {lock}); "
                           "wait for it or stop it first") from None
    try:
        yield
    finally:
        with contextlib.suppress(OSError):
            lock.unlink()
        fcntl.flock(fh, fcntl.LOCK_UN)
        fh.close()
