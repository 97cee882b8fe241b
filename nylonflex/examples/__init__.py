"""Example configs shipped with the package, for ``nylonflex init`` to copy and users to edit.

``configs/`` in the repository holds the same files (a test keeps them identical).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

__all__ = ["EXAMPLES", "example_text", "write_examples"]

#: Example name -> what it is for (the file is ``<name>.yaml``).
EXAMPLES = {
    "fig12": "sweep: the design space of the paper's figure 12 (nylonflex sweep fig12.yaml)",
    "control": "simulate: the closed loop of figure 9 (nylonflex simulate control.yaml)",
    "step": "simulate: a step response with rise time and overshoot",
    "gripper": "simulate: three actuators on one 9 V battery",
}


def example_text(name: str) -> str:
    """The text of example ``name`` (one of :data:`EXAMPLES`)."""
    if name not in EXAMPLES:
        raise ValueError(f"example: unknown {name!r}; accepted: {', '.join(EXAMPLES)}")
    return resources.files(__name__).joinpath(f"{name}.yaml").read_text()


def write_examples(folder, names=None) -> list[Path]:
    """Write the example configs into ``folder`` (created if missing); never overwrite.

    Parameters
    ----------
    folder : path
        Where the files go.
    names : sequence of str, optional
        Which examples (default: all of :data:`EXAMPLES`).

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    nylonflex.units.InputError
        One of the files exists already (nothing is written then), or an unknown name.
    """
    from ..units import InputError

    folder = Path(folder)
    names = list(EXAMPLES) if not names else list(names)
    for n in names:
        if n not in EXAMPLES:
            raise InputError(f"init: unknown example {n!r}; accepted: {', '.join(EXAMPLES)}")
    if folder.exists() and not folder.is_dir():
        raise InputError(f"init: {folder} is a file; give a folder for the example configs")
    paths = [folder / f"{n}.yaml" for n in names]
    existing = [str(p) for p in paths if p.exists()]
    if existing:
        verb = "exists" if len(existing) == 1 else "exist"
        raise InputError(f"init: {', '.join(existing)} already {verb}; nothing written "
                         "(move them away, or init another folder)")
    folder.mkdir(parents=True, exist_ok=True)
    for n, p in zip(names, paths):
        with open(p, "x") as f:  # exclusive: never replace a file made meanwhile
            f.write(example_text(n))
    return paths
