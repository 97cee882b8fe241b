"""Reading YAML boundedly: configs, material files and ``--set`` values.

PyYAML's SafeLoader runs no code, but aliases make a small file describe a huge value (a
740-byte "billion laughs" of nested aliases is gigabytes once anything walks it) and deep
nesting overflows the stack. Here the composed node graph is checked before any Python
object is built: its nesting depth, its size with aliases expanded (counted, not expanded)
and duplicate keys (YAML says keys are unique; PyYAML keeps the last silently).
"""

from __future__ import annotations

from pathlib import Path

import yaml

from ..units import InputError, short

__all__ = ["YAML_MAX_DEPTH", "YAML_MAX_EXPANDED", "load_yaml", "read_yaml"]

#: Deepest nesting accepted (a config is four or five levels deep).
YAML_MAX_DEPTH = 32
#: Nodes a document may reach once its aliases are expanded (only when it uses aliases).
YAML_MAX_EXPANDED = 200_000
_MAX_CONFIG_BYTES = 16 * 2**20


def _check_nodes(node, source: str):
    """Refuse YAML nested deeper than :data:`YAML_MAX_DEPTH`, aliases that expand past
    :data:`YAML_MAX_EXPANDED` nodes, and duplicate keys (without expanding anything)."""
    sizes: dict[int, int] = {}
    aliased = [False]
    seen_ids: set[int] = set()

    def where(n):
        return f"{source} (line {n.start_mark.line + 1})"

    def walk(n, depth):
        if depth > YAML_MAX_DEPTH:
            raise InputError(f"{where(n)}: nested deeper than {YAML_MAX_DEPTH} levels")
        key = id(n)
        if key in sizes:
            aliased[0] = True
            return sizes[key]
        if key in seen_ids:  # a recursive alias
            raise InputError(f"{where(n)}: an alias refers to itself")
        seen_ids.add(key)
        total = 1
        if isinstance(n, yaml.SequenceNode):
            for child in n.value:
                total += walk(child, depth + 1)
        elif isinstance(n, yaml.MappingNode):
            names = set()
            for k, v in n.value:
                if isinstance(k, yaml.ScalarNode) and k.tag != "tag:yaml.org,2002:merge":
                    if k.value in names:
                        raise InputError(f"{where(k)}: key {short(k.value)} appears twice")
                    names.add(k.value)
                total += walk(k, depth + 1) + walk(v, depth + 1)
        sizes[key] = total
        if aliased[0] and total > YAML_MAX_EXPANDED:
            raise InputError(f"{where(n)}: YAML aliases expand to over {YAML_MAX_EXPANDED:,} "
                             "values; write the values out instead of using anchors")
        return total

    walk(node, 0)


def load_yaml(text: str, source: str = "config"):
    """Parse YAML text safely and boundedly: SafeLoader, nesting depth, alias expansion and
    duplicate keys checked before any Python object is built.

    Raises
    ------
    InputError
        Bad YAML, too deep, an alias bomb or a duplicate key; the message names ``source``.
    """
    loader = yaml.SafeLoader(text)
    try:
        try:
            node = loader.get_single_node()
        except RecursionError:
            raise InputError(f"{source}: nested deeper than {YAML_MAX_DEPTH} levels") from None
        except yaml.YAMLError as err:
            mark = getattr(err, "problem_mark", None)
            where = f" (line {mark.line + 1})" if mark else ""
            raise InputError(f"{source}: not valid YAML{where}") from None
        if node is None:
            return None
        _check_nodes(node, source)
        try:
            return loader.construct_document(node)
        except yaml.YAMLError:
            raise InputError(f"{source}: not valid YAML") from None
    finally:
        loader.dispose()


def read_yaml(path) -> dict:
    """Read a YAML file with :func:`load_yaml`; a missing, oversized or non-UTF-8 file or
    bad YAML is an InputError naming it."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such config file")
    if path.stat().st_size > _MAX_CONFIG_BYTES:
        raise InputError(f"{path}: over {_MAX_CONFIG_BYTES // 2**20} MB; not a config file")
    try:
        text = path.read_bytes().decode("utf-8")
    except UnicodeDecodeError as err:
        raise InputError(f"{path}: not UTF-8 text (byte {err.start}); save the config as "
                         "UTF-8") from None
    return load_yaml(text, str(path))
