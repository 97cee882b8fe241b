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
