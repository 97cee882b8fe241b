"""A cube re-run from itself: ``nylonflex info CUBE --config`` then ``nylonflex sweep``
gives the same data bit for bit (issue 24)."""

from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from nylonflex.cli import main

REPO = Path(__file__).resolve().parents[1]

SMALL = {
    "name": "rerun",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 9, "units": "mm"},
        "wall_thickness": {"values": [1.3, 3, 6], "units": "mm"},
        "length": {"start": 70, "stop": 90, "num": 2, "units": "mm"},
        "coil_index": {"values": [1.1, 1.45, 1.7]},
        "wrap_angle": {"start": 5, "stop": 20, "num": 4, "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
    "silicone": {"set": "tc5005", "mu": [56000, 10490]},
    "base_thickness": {"value": 2.5, "units": "mm"},
}
CASES = {
    "plain": {},
    "models": {"model": ["paper", "coupled_muscle", "cauchy_moment"]},
    "supply": {"supply": {"voltage": 12}, "nylon": {"set": "silver_nylon66",
                                                    "fibre_diameter": 3.5e-4}},
    "uncertain": {"uncertainty": {"samples": 8, "seed": 3, "parameters": {
        "wall_thickness": {"sd": 0.1, "units": "mm"}, "silicone.mu": {"rel_sd": 0.1}}},
        "requirements": ["tip_force_max >= 0.1 N"]},
    "fitted": {"silicone": {"file": str(REPO / "configs" / "fits" /
                                        "ecoflex_0050_ogden2.yaml")}},
    # a cooling set, and several as an axis with models (docs/model.md s. 9)
    "cooling": {"cooling": {"set": "forced_air", "speed": 3.5}, "supply": {"voltage": 12}},
    "coolings": {"cooling": ["still_air", {"set": "forced_air", "speed": 3.5}, "still_water"],
                 "model": ["paper", "lateral_pressure"], "supply": {"voltage": 12}},
}


def _data(path) -> dict:
    with h5py.File(path, "r") as f:
        return {k: f[k][...] for k in f if isinstance(f[k], h5py.Dataset)}


@pytest.mark.parametrize("case", list(CASES))
def test_info_config_sweeps_to_the_same_cube_bit_for_bit(tmp_path, capsys, case):
    src = tmp_path / "c.yaml"
    src.write_text(yaml.safe_dump({**SMALL, **CASES[case]}))
    first = tmp_path / "C.h5"
    assert main(["sweep", str(src), "--out", str(first), "--quiet", "--no-charts"]) == 0
    capsys.readouterr()
    assert main(["info", str(first), "--config"]) == 0
    text = capsys.readouterr().out
    again = tmp_path / "again.yaml"
    again.write_text(text)
    doc = yaml.safe_load(text)
    # readable: grids in display units, as typed (start/stop/num where evenly spaced)
    assert doc["grid"]["radius"] == {"start": 5, "stop": 25, "num": 9, "units": "mm"}
    assert doc["grid"]["wall_thickness"] == {"values": [1.3, 3, 6], "units": "mm"}
    assert doc["grid"]["coil_index"] == {"values": [1.1, 1.45, 1.7]}
    assert doc["silicone"] == ({"file": CASES["fitted"]["silicone"]["file"]} if case == "fitted"
                               else {"set": "tc5005", "mu": [56000.0, 10490.0]})
    second = tmp_path / "C2.h5"
    assert main(["sweep", str(again), "--out", str(second), "--quiet", "--no-charts"]) == 0
    a, b = _data(first), _data(second)
    assert a.keys() == b.keys()
    for name in a:
        assert a[name].dtype == b[name].dtype, name
        if a[name].dtype.kind == "O":  # the model (cooling set) names
            assert a[name].tolist() == b[name].tolist(), name
        else:
            assert a[name].tobytes() == b[name].tobytes(), name  # bit for bit, NaNs too
    with h5py.File(first) as f, h5py.File(second) as g:
        assert f.attrs["config_sha256"] == g.attrs["config_sha256"]
