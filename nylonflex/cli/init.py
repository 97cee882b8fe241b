"""``nylonflex init [DIR]``: write the example configs for a user to edit."""

from __future__ import annotations

HELP = "write the example configs (fig12, control, step, gripper) to edit"


def add_arguments(p):
    from ..examples import EXAMPLES

    p.add_argument("dir", nargs="?", default=".",
                   help="folder for the configs (default: the current one; created if "
                        "missing); existing files are never overwritten")
    p.add_argument("--example", nargs="+", metavar="NAME", choices=list(EXAMPLES),
                   help=f"only these examples: {', '.join(EXAMPLES)}")


def run(args) -> int:
    from ..examples import EXAMPLES, write_examples

    for path in write_examples(args.dir, args.example):
        print(f"{path}  {EXAMPLES[path.stem]}")
    return 0
