"""A cube's ``history`` (CF's audit line) records the command that made it, with its
arguments (issue 50), so a cube says how to make it again; from Python it names
``nylonflex.run_sweep``."""

import shlex

import h5py
from helpers import write_config, write_cube

from nylonflex.cli import main

SMALL = {
    "name": "hist",
    "grid": {"radius": {"start": 5, "stop": 25, "num": 4, "units": "mm"},
             "wall_thickness": {"values": [2], "units": "mm"},
             "length": {"values": [70], "units": "mm"},
             "coil_index": {"values": [1.7]}, "wrap_angle": {"values": [8], "units": "deg"}},
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
               "pressure": {"start": 0, "stop": 25, "num": 3, "units": "kPa"}},
    "charts": [],
}


def _history(path) -> str:
    with h5py.File(path, "r") as f:
        value = f.attrs["history"]
    return value.decode() if isinstance(value, bytes) else str(value)


def test_the_command_line_and_its_arguments_are_in_the_history(tmp_path):
    cfg = write_config(tmp_path, SMALL, "my config.yaml")  # a space: quoted
    out = tmp_path / "out" / "cube.h5"
    assert main(["sweep", str(cfg), "--set", "grid.radius.num=3", "--out", str(out),
                 "--workers", "1", "--no-charts", "--quiet"]) == 0
    history = _history(out)
    line = history.split(": ", 1)[1]
    assert shlex.split(line) == ["nylonflex", "sweep", str(cfg), "--set", "grid.radius.num=3",
                                 "--out", str(out), "--workers", "1"]
    assert "'" in line  # the path with a space is quoted, so the line runs as it is


def test_a_python_sweep_names_run_sweep(tmp_path):
    assert _history(write_cube(tmp_path, SMALL)).endswith("nylonflex.run_sweep")
