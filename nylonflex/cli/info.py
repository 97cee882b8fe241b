"""``nylonflex info CUBE``: dims, ranges, provenance and completeness."""

from __future__ import annotations

import sys

from ..units import InputError, json_text
from ._common import progress_bar

HELP = "describe a cube"


def add_arguments(i):
    i.add_argument("cube")
    i.add_argument("--check", action="store_true",
                   help="read every chunk of every variable (bounded memory) and list the "
                        "unreadable ones; exit 1 if any")
    i.add_argument("--format", choices=["text", "json"], default="text",
                   help="text (display units) or json (SI, with each axis's display unit)")
    i.add_argument("--config", action="store_true",
                   help="print the cube's config as a runnable YAML (nylonflex info CUBE "
                        "--config > c.yaml && nylonflex sweep c.yaml recomputes it)")


def run(args) -> int:
    from ..storage import check_cube, cube_summary

    if args.config:
        from ..engine.provenance import runnable_config
        from ..storage import cube_attrs

        attrs = cube_attrs(args.cube)
        if attrs is None:
            raise InputError(f"{args.cube}: not a nylonflex cube (expected a NetCDF4/HDF5 "
                             "file written by 'nylonflex sweep')")
        print(runnable_config(attrs), end="")
        return 0

    if args.format == "json":
        return _json(args)
    lines = cube_summary(args.cube)
    for line in lines:
        print(line)
    fidelity = _fidelity_lines(args.cube)
    for line in fidelity:
        print(line)
    damaged = any(line.startswith("damaged ") for line in lines)
    if args.check:
        with progress_bar("check", unit="variable") as bar:
            problems = check_cube(args.cube, full=True, progress=bar)
        for line in problems:
            print(f"nylonflex info: {line}", file=sys.stderr)
        print(f"check     {len(problems)} unreadable chunk{'s' if len(problems) != 1 else ''}"
              if problems else "check     every chunk of every variable read")
        damaged = damaged or bool(problems)
    return 1 if damaged else 0


def _json(args) -> int:
    """``info --format json``: the cube's description as one JSON object (SI values)."""
    from ..storage import check_cube, cube_description
    d = cube_description(args.cube)
    fidelity = _fidelity_lines(args.cube)
    if fidelity:
        d["fidelity"] = [line.strip() for line in fidelity]
    if args.check:
        with progress_bar("check", unit="variable") as bar:
            d["unreadable_chunks"] = check_cube(args.cube, full=True, progress=bar)
    sys.stdout.write(json_text(d))
    return 1 if d["damaged"] or d.get("unreadable_chunks") else 0


def _fidelity_lines(cube) -> list[str]:
    """The fidelity dataset beside the cube (``nylonflex verify``), summarised, if any."""
    from ..fe.paths import fidelity_path, stroke_path

    path = fidelity_path(cube)
    if not path.is_file() and not stroke_path(cube).is_file():
        return []  # none: neither the FE modules nor xarray imported
    from ..fe.verify import fidelity_summary, open_fidelity

    try:
        fid = open_fidelity(cube)
    except (OSError, ValueError) as exc:
        return [f"fidelity  {path}: unreadable ({type(exc).__name__})"]
    lines = []
    if fid is not None:
        head = (f"fidelity  {path.name}: {fid.sizes.get('design', 0)} designs, FE mesh "
                f"{fid.attrs.get('fe_mesh', '?')}, drive pressure (nylonflex verify)")
        lines = [head] + [f"          {line}" for line in fidelity_summary(fid)]
    return lines + _stroke_fidelity_lines(cube)


def _stroke_fidelity_lines(cube) -> list[str]:
    """The stroke-driven fidelity dataset beside the cube (``nylonflex verify --drive
    stroke``), summarised, if any."""
    from ..fe.paths import stroke_path
    from ..fe.verify_stroke import open_stroke_fidelity, stroke_summary

    path = stroke_path(cube)
    try:
        fid = open_stroke_fidelity(cube)
    except (OSError, ValueError) as exc:
        return [f"fidelity  {path}: unreadable ({type(exc).__name__})"]
    if fid is None:
        return []
    head = (f"fidelity  {path.name}: {fid.sizes.get('design', 0)} designs at full stroke, "
            f"FE mesh {fid.attrs.get('fe_mesh', '?')}, drive {fid.attrs.get('drive', '?')}"
            f"{', blocked' if fid.attrs.get('blocked') else ''} (nylonflex verify)")
    return [head] + [f"          {line}" for line in stroke_summary(fid)]
