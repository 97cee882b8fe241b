"""The cube against the CF conventions: compliance-checker (cf:1.8) on fresh small cubes
of each kind (issue 24). Skipped where compliance-checker is not installed (the test extra
installs it)."""

import json

import h5py
import numpy as np
import pytest

pytest.importorskip("compliance_checker")

SMALL = {
    "name": "cf",
    "grid": {
        "radius": {"start": 5, "stop": 25, "num": 5, "units": "mm"},
        "wall_thickness": {"values": [1, 3], "units": "mm"},
        "length": {"values": [70, 90], "units": "mm"},
        "coil_index": {"values": [1.1, 1.7]},
        "wrap_angle": {"values": [5, 20], "units": "deg"},
    },
    "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 6},
               "pressure": {"start": 0, "stop": 40, "num": 5, "units": "kPa"}},
}
KINDS = {
    "plain": {},
    "models_supply": {"model": ["paper", "coupled_muscle"], "supply": {"voltage": 12}},
    "coolings": {"cooling": ["still_air", "still_water"], "supply": {"voltage": 12}},
    # a model spread over a cooling list: the range on its variables' cooling dimension
    "spread": {"fidelity": {"spread": ["paper", "incompressible_wall"]},
               "cooling": ["still_air", "still_water"], "supply": {"voltage": 12}},
    "uncertain": {"uncertainty": {"samples": 8, "seed": 1, "parameters": {
        "silicone.mu": {"rel_sd": 0.1}}}, "requirements": ["tip_force_max >= 0.1 N"]},
}

#: What the checker reports that the cube keeps, and why: nothing. (Before cube format 3,
#: s. 5.1 asked the dimension *named* ``pressure`` for standard_name air_pressure, which
#: the chamber's gauge pressure is not; the curves now lie over ``pressure_point`` with
#: ``pressure`` their auxiliary coordinate: storage.netcdf4.STORED_DIMS.)
KNOWN: dict = {}


def _report(path, tmp_path) -> dict:
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    CheckSuite().load_all_available_checkers()
    out = tmp_path / "cf.json"
    ComplianceChecker.run_checker(str(path), ["cf:1.8"], 0, "normal",
                                  output_filename=str(out), output_format="json")
    return json.loads(out.read_text())["cf:1.8"]


@pytest.mark.parametrize("kind", list(KINDS))
def test_compliance_checker_finds_nothing(tmp_path, kind):
    import nylonflex as nf
    from nylonflex.config import parse_config

    path = tmp_path / "cube.nc"  # s. 2.1 asks for '.nc'; the default cube.h5 is INTERFACE's
    nf.run_sweep(parse_config({**SMALL, **KINDS[kind]}), path).close()
    report = _report(path, tmp_path)
    found = [(p, item["name"], msg) for p in ("high_priorities", "medium_priorities")
             for item in report[p] for msg in item["msgs"]]
    unexpected = [f for f in found if not KNOWN.get(f[1], "\0") in f[2]]
    assert not unexpected, unexpected
    assert report["scored_points"] == report["possible_points"]
    # what the checker asked of the attributes: typed, a history, CF-1.8, no host name
    with h5py.File(path, "r") as f:
        a = f.attrs
        assert a["Conventions"] == "CF-1.8" and "nylonflex.run_sweep" in a["history"]
        assert a["complete"].dtype == np.int8 and int(a["complete"][0]) == 1
        assert a["run_seconds"].dtype == np.float64 and a["workers"].dtype.kind == "i"
        assert "hostname" not in a
        assert f["validity"].attrs["standard_name"] == "quality_flag"
        assert f["limit"].attrs["standard_name"] == "status_flag"


def test_the_host_name_is_recorded_only_on_request(tmp_path, monkeypatch):
    import platform

    import nylonflex as nf
    from nylonflex.config import parse_config
    from nylonflex.engine.provenance import RECORD_HOST_ENV

    monkeypatch.setenv(RECORD_HOST_ENV, "1")
    ds = nf.run_sweep(parse_config(SMALL), tmp_path / "cube.h5")
    assert ds.attrs["hostname"] == platform.node()
