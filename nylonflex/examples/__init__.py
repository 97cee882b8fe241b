"""Example configs and data shipped with the package, for ``nylonflex init`` to copy and
users to edit.

``nylonflex init DIR`` lays them out as the README's commands expect them: ``configs/``
(the files of the repository's ``configs/``, a test keeps them identical, with the fitted
material ``configs/fits/``) and ``data/`` (the bench file ``nylonflex fit silicone`` reads,
a copy of ``tests/data/ecoflex_0050.csv``), so every command of the README runs in DIR.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

from ..files.atomic import create_files, path_error
from ..units import InputError

__all__ = ["DATA", "EXAMPLES", "NEEDS", "example_text", "write_examples"]

#: Example name -> what it is for (the file is ``configs/<name>.yaml``).
EXAMPLES = {
    "fig12": "sweep: the design space of the paper's figure 12 (nylonflex sweep configs/fig12.yaml)",
    "fig12_uncertain": "sweep with uncertainty and requirements: quantiles and feasibility",
    "fig12_fitted": "sweep with a fitted silicone (configs/fits/ecoflex_0050_ogden2.yaml)",
    "fig12_dynamics": "sweep at the paper's 12 V: cycle rate, energy, work and efficiency",
    "big20m": "sweep: 20 million designs, for clusters and memory checks",
    "fig12_tracking": "sweep with tracking: the closed loop of figure 9 for every design",
    "design_force": "design: the largest tip force with a full range (needs sweeps/fig12)",
    "design_front": "design: the Pareto front of force and size (needs sweeps/fig12)",
    "design_tracking": "design: the largest force that tracks the figure-9 sine within 2 deg "
                       "(needs sweeps/fig12_tracking)",
    "control": "simulate: the closed loop of figure 9 (nylonflex simulate configs/control.yaml)",
    "step": "simulate: a step response with rise time and overshoot",
    "gripper": "simulate: three actuators on one 9 V battery",
}
#: Files an example reads, written with it (paths inside the package = paths in DIR/configs).
NEEDS = {"fig12_fitted": ("fits/ecoflex_0050_ogden2.yaml",)}
#: Data files a full ``init`` writes under DIR/data.
DATA = ("ecoflex_0050.csv", "README.md")


def example_text(name: str) -> str:
    """The text of example ``name`` (one of :data:`EXAMPLES`)."""
    if name not in EXAMPLES:
        raise ValueError(f"example: unknown {name!r}; accepted: {', '.join(EXAMPLES)}")
    return resources.files(__name__).joinpath(f"{name}.yaml").read_text()


def _package_file(rel: str) -> bytes:
    return resources.files(__name__).joinpath(rel).read_bytes()


def write_examples(folder, names=None) -> list[Path]:
    """Write the example configs (and what they read) into ``folder``; never overwrite.

    Parameters
    ----------
    folder : path
        Where the files go (``configs/``, ``configs/fits/``, ``data/`` inside it).
    names : sequence of str, optional
        Which examples (default: all of :data:`EXAMPLES`, and the data).

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    nylonflex.units.InputError
        One of the files exists already (nothing is written then), or an unknown name.
    """
    folder = Path(folder)
    everything = not names
    names = list(EXAMPLES) if everything else list(names)
    for n in names:
        if n not in EXAMPLES:
            raise InputError(f"init: unknown example {n!r}; accepted: {', '.join(EXAMPLES)}")
    files = {}  # target path -> package file
    for n in names:
        files[folder / "configs" / f"{n}.yaml"] = f"{n}.yaml"
        for rel in NEEDS.get(n, ()):
            files[folder / "configs" / rel] = rel
    if everything:
        for rel in DATA:
            files[folder / "data" / rel] = f"data/{rel}"
    existing = [str(p) for p in files if os.path.lexists(p)]
    if existing:
        what = existing[0] if len(existing) == 1 else \
            f"{len(existing)} of its files ({existing[0]}, ...)"
        verb = "already exists" if len(existing) == 1 else "already exist"
        raise InputError(f"init: {what} {verb}; nothing written (move them away, or init "
                         "another folder)")
    try:
        return create_files({target: _package_file(rel) for target, rel in files.items()},
                            "init")
    except FileExistsError as exc:  # made meanwhile: nothing of this init is left
        raise InputError(f"init: {exc.filename} already exists; nothing written") from None
    except OSError as exc:
        raise path_error(exc, exc.filename or folder, "init") from None
