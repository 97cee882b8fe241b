"""Helpers the test files share (fixtures themselves live in conftest.py, where pytest
finds them): writing a config or a cube, and a cube without its run-dependent attributes."""

from pathlib import Path

import yaml


def write_config(folder, raw, name="cfg.yaml"):
    """Write a config mapping as YAML to ``folder/name``; return the path."""
    path = Path(folder) / name
    path.write_text(yaml.safe_dump(raw))
    return path


def write_cube(folder, raw):
    """Sweep a config mapping into ``folder/cube.h5``; return the path."""
    from nylonflex.config import parse_config
    from nylonflex.storage.sweep import run_sweep

    path = Path(folder) / "cube.h5"
    run_sweep(parse_config(raw), out=path).close()
    return path


def stable(ds):
    """The dataset without the attributes that differ between two runs of one config."""
    from nylonflex.storage import VOLATILE_ATTRS

    ds = ds.copy()
    ds.attrs = {k: v for k, v in ds.attrs.items() if k not in VOLATILE_ATTRS}
    return ds
