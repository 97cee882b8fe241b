"""Helpers the command modules share: opening a cube with its warning as one line."""

from __future__ import annotations

import sys
import warnings


def open_cube_for(command: str, path):
    """:func:`nylonflex.open_cube` for a command: an incomplete cube's warning as one line."""
    from ..storage import open_cube

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = open_cube(path)
    for w in caught:
        print(f"nylonflex {command}: warning: {w.message}", file=sys.stderr)
    return ds


class progress_bar:
    """A tqdm bar on a terminal (stderr), nothing otherwise: ``bar(done, total)``.

    The domain code takes a ``progress(done, total)`` callback; this is the CLI's one.
    The bar appears only after ``delay`` seconds, so that quick work prints nothing.
    """

    def __init__(self, desc: str, unit: str = "it", quiet: bool = False, delay: float = 0.5):
        self.desc, self.unit, self.delay = desc, unit, delay
        self.enabled = not quiet and sys.stderr.isatty()
        self._bar = None

    def __enter__(self):
        return self

    def __call__(self, done, total):
        if not self.enabled:
            return
        if self._bar is None:
            from tqdm import tqdm

            self._bar = tqdm(total=total, desc=self.desc, unit=self.unit, leave=False,
                             delay=self.delay, dynamic_ncols=True, file=sys.stderr)
        self._bar.total = total
        self._bar.update(done - self._bar.n)

    def __exit__(self, *exc):
        if self._bar is not None:
            self._bar.close()
        return False
