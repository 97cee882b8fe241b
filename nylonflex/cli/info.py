"""``nylonflex info CUBE``: dims, ranges, provenance and completeness."""

from __future__ import annotations

HELP = "describe a cube"


def add_arguments(i):
    i.add_argument("cube")


def run(args) -> int:
    from ..storage import cube_summary

    for line in cube_summary(args.cube):
        print(line)
    return 0
