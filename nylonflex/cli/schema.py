"""``nylonflex schema sweep|simulate|design``: the JSON Schema of a config, for editors."""

from __future__ import annotations

HELP = "print the JSON Schema of a sweep, simulate or design config (for editors)"


def add_arguments(p):
    from ..config.schema import SCHEMAS

    p.add_argument("kind", choices=SCHEMAS, help="which config")


def run(args) -> int:
    import json

    from ..config.schema import json_schema

    print(json.dumps(json_schema(args.kind), indent=2))
    return 0
