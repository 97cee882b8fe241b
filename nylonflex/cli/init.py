"""``nylonflex init [DIR]``: write the example configs and data for a user to edit."""

from __future__ import annotations

HELP = "write the README's example configs (configs/) and fit data (data/) to edit"


def add_arguments(p):
    from ..examples import EXAMPLES

    p.add_argument("dir", nargs="?", default=".",
                   help="folder for configs/ and data/ (default: the current one; created "
                        "if missing); existing files are never overwritten")
    p.add_argument("--example", nargs="+", metavar="NAME", choices=list(EXAMPLES),
                   help=f"only these examples: {', '.join(EXAMPLES)}")


def run(args) -> int:
    from ..examples import EXAMPLES, write_examples

    for path in write_examples(args.dir, args.example):
        what = EXAMPLES.get(path.stem) if path.parent.name == "configs" else None
        print(f"{path}  {what}" if what else str(path))
    return 0
