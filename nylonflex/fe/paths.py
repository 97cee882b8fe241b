"""Where ``nylonflex verify`` writes beside a cube: the fidelity datasets and their maps.

Names only (no FE, no xarray): ``nylonflex info`` asks whether a cube has any before it
imports what reads them.
"""

from __future__ import annotations

from pathlib import Path

__all__ = ["fidelity_map_path", "fidelity_path", "stroke_map_path", "stroke_path"]


def fidelity_path(cube) -> Path:
    """The fidelity dataset of a cube: ``<stem>.fidelity.nc`` beside it."""
    cube = Path(cube)
    return cube.with_name(cube.stem + ".fidelity.nc")


def fidelity_map_path(cube) -> Path:
    """The fidelity map of a cube (``nylonflex verify`` draws it): ``<stem>.fidelity_map.png``
    beside it."""
    cube = Path(cube)
    return cube.with_name(cube.stem + ".fidelity_map.png")


def stroke_path(cube) -> Path:
    """The stroke-driven fidelity dataset of a cube: ``<stem>.fidelity_stroke.nc``."""
    cube = Path(cube)
    return cube.with_name(cube.stem + ".fidelity_stroke.nc")


def stroke_map_path(cube) -> Path:
    """Its map: ``<stem>.fidelity_stroke_map.png`` beside the cube."""
    cube = Path(cube)
    return cube.with_name(cube.stem + ".fidelity_stroke_map.png")
