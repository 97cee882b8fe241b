"""``nylonflex bench [--quick]``: the kernels against the references, side by side."""

from __future__ import annotations

HELP = "time the kernels against scipy"


def add_arguments(b):
    b.add_argument("--quick", action="store_true", help="a small smoke run")


def run(args) -> int:
    from ..bench import run_bench

    run_bench(quick=args.quick, log=lambda msg: print(msg, flush=True))
    return 0
