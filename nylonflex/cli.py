"""The ``nylonflex`` command line: argument parsing and nothing else.

Every command hands its parsed arguments to a library function; no science lives here.
Exit status: 0 done, 2 bad input (one line naming the field), 1 other failure. A traceback
is printed only with ``--debug``.
"""

from __future__ import annotations

import argparse
import sys

from . import __version__

EXIT_OK, EXIT_FAILURE, EXIT_INPUT = 0, 1, 2


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own usage errors are bad input too: one line, 2
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The parser of every ``nylonflex`` command (INTERFACE.md)."""
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--debug", action="store_true", help="show tracebacks on errors")
    p = _Parser(prog="nylonflex", parents=[common],
                description="Design-space sweeps of nylon-muscle soft bending actuators.")
    p.add_argument("--version", action="version", version=f"nylonflex {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    s = sub.add_parser("sweep", parents=[common], help="evaluate a design space into a cube")
    s.add_argument("config", help="YAML config (see configs/)")
    s.add_argument("--out", help="cube path (default sweeps/<name>/cube.h5)")
    s.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a config key, e.g. grid.radius.num=81 (repeatable)")
    s.add_argument("--resume", action="store_true", help="finish an interrupted run")
    s.add_argument("--workers", type=int, help="local threads (default: all cores)")
    s.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask distributed cluster, e.g. tcp://host:8786")
    s.add_argument("--no-charts", action="store_true", help="skip the config's charts")
    s.add_argument("--quiet", action="store_true", help="no progress bar")

    c = sub.add_parser("chart", parents=[common], help="draw design charts from a cube")
    c.add_argument("cube")
    c.add_argument("--figure", nargs="+", metavar="NAME", help="figures (default: all)")
    c.add_argument("--out", help="folder for the images (default: beside the cube)")
    c.add_argument("--format", choices=["png", "pdf", "svg"], default="png")

    q = sub.add_parser("query", parents=[common], help="ask a cube about designs")
    q.add_argument("cube")
    q.add_argument("--at", metavar="NAME=VALUE,...", help="one design, e.g. radius=7.5mm")
    q.add_argument("--where", action="append", default=[], metavar="EXPR",
                   help='filter, e.g. "tip_force_max >= 0.5 N" (repeatable)')
    q.add_argument("--sort", metavar="NAME", help="order by a variable or axis (- for desc)")
    q.add_argument("--limit", type=int, help="at most N rows")
    q.add_argument("--format", choices=["table", "json", "csv"], default="table")

    i = sub.add_parser("info", parents=[common], help="describe a cube")
    i.add_argument("cube")

    m = sub.add_parser("simulate", parents=[common], help="simulate the closed loop in time")
    m.add_argument("config", help="YAML simulation config (configs/control.yaml)")
    m.add_argument("--out", help="output file (default sweeps/<name>/sim.h5)")
    m.add_argument("--no-charts", action="store_true", help="skip the chart")

    b = sub.add_parser("bench", parents=[common], help="time the kernels against scipy")
    b.add_argument("--quick", action="store_true", help="a small smoke run")
    return p


def _run(args) -> int:
    if args.command == "sweep":
        from .sweep import sweep_command

        return sweep_command(args)
    if args.command == "chart":
        from .charts import chart_command

        return chart_command(args)
    if args.command == "query":
        from .query import query_command

        return query_command(args)
    if args.command == "info":
        from .storage import info_command

        return info_command(args)
    if args.command == "simulate":
        from .simulate import simulate_command

        return simulate_command(args)
    if args.command == "bench":
        from .bench import bench_command

        return bench_command(args)
    raise AssertionError(args.command)


def _join_negative_values(argv):
    """``--sort -tip_force_max`` means descending; argparse would read ``-tip...`` as a flag."""
    out = list(argv)
    for i, item in enumerate(out[:-1]):
        if item == "--sort" and out[i + 1].startswith("-") and out[i + 1][1:2].isalpha():
            out[i:i + 2] = [f"--sort={out[i + 1]}"]
            return _join_negative_values(out)
    return out


def main(argv=None) -> int:
    """Entry point of the ``nylonflex`` console script."""
    parser = build_parser()
    argv = sys.argv[1:] if argv is None else argv
    args = parser.parse_args(_join_negative_values(argv))
    if args.command is None:
        parser.print_help()
        return EXIT_OK
    try:
        return _run(args) or EXIT_OK
    except KeyboardInterrupt:
        print("nylonflex: interrupted", file=sys.stderr)
        return 130
    except ValueError as exc:  # InputError and the physics' range checks: bad input
        if args.debug:
            raise
        print(f"nylonflex {args.command}: error: {_one_line(exc)}", file=sys.stderr)
        return EXIT_INPUT
    except Exception as exc:  # noqa: BLE001 - one line for the user, --debug for the rest
        if args.debug:
            raise
        print(f"nylonflex {args.command}: failed: {type(exc).__name__}: {_one_line(exc)}",
              file=sys.stderr)
        return EXIT_FAILURE


def _one_line(exc) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
