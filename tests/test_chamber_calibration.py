"""``sealed_chamber``'s calibration to FE records (calibration.chamber, docs/model.md s. 22):
it recovers known coefficients from records the model itself made."""

import numpy as np
import pytest

from nylonflex.calibration.chamber import fit_sealed_chamber
from nylonflex.physics import P_ATM
from nylonflex.physics.sealed import COEFFICIENT_NAMES
from nylonflex.physics.sealed_model import sealed_state

#: r0 large enough that the blocked pressure's ratio exceeds 1 on every record drawn below
#: (the model clamps it there, which a log-linear fit cannot see through)
TRUE = dict(k0=0.4, k1=-0.3, g0=0.6, g1=0.25, c0=1.3, c1=0.2, cb=2.5, ca=1.4, r0=3.0, r1=0.5,
            r2=0.1, r3=0.8, r4=2.0)


def _records(n, coef, seed=0, free_volume=True, noise=0.0):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        d = dict(radius=rng.uniform(5e-3, 25e-3), wall_thickness=rng.uniform(1e-3, 6e-3),
                 length=rng.uniform(50e-3, 150e-3))
        s = rng.uniform(0.03, 0.1)
        st = sealed_state(s, d["radius"], d["wall_thickness"], d["length"], coefficients=coef)
        e = 1.0 + noise * rng.standard_normal(3)
        rec = {"design": d, "stroke": s, "pressure": st["pressure"] * e[0],
               "bend_angle": st["bend_angle"] * e[1], "tip_force": st["tip_force"] * e[2],
               "blocked_pressure": st["blocked_pressure"]}
        if free_volume:
            rec["free_volume"] = st["free_volume"]
            rec["volume_ratio"] = st["volume_ratio"]
        out.append(rec)
    return out


def test_recovers_known_coefficients_with_the_free_volume():
    fit = fit_sealed_chamber(_records(10, TRUE))
    assert fit["stiffness_from"] == "free_volume"
    for name in COEFFICIENT_NAMES:
        assert fit["coefficients"][name] == pytest.approx(TRUE[name], rel=1e-6, abs=1e-9), name
    for name in ("pressure", "bend_angle", "tip_force"):
        np.testing.assert_allclose(fit["loo"][name], 1.0, rtol=1e-6)
    assert fit["loo"]["bend_and_force_within"] == fit["loo"]["n"] == 10


def test_without_the_free_volume_the_stiffness_is_lames():
    truth = {**TRUE, "k0": 0.0, "k1": 0.0}
    fit = fit_sealed_chamber(_records(8, truth, seed=1, free_volume=False))
    assert fit["stiffness_from"] == "closed_form"
    for name in COEFFICIENT_NAMES:
        assert fit["coefficients"][name] == pytest.approx(truth[name], rel=1e-6, abs=1e-9), name


def test_recovers_through_noise():
    fit = fit_sealed_chamber(_records(30, TRUE, seed=2, noise=0.01))
    c = fit["coefficients"]
    assert c["c0"] == pytest.approx(TRUE["c0"], rel=0.1)
    assert c["cb"] == pytest.approx(TRUE["cb"], rel=0.1)
    assert c["ca"] == pytest.approx(TRUE["ca"], rel=0.1)
    assert c["g0"] == pytest.approx(TRUE["g0"], abs=0.3)
    assert fit["loo"]["within"]["bend_angle"] >= 28


def test_too_few_records_are_refused():
    with pytest.raises(ValueError, match="records: need at least 3"):
        fit_sealed_chamber(_records(2, TRUE))


def _write_fe_records(folder, records, stalled=1):
    """Records in the sealed twin's file format (fe_runs/README.txt), one of them stalled."""
    import json
    folder.mkdir()
    for i, r in enumerate(records):
        d = {**r["design"], "base_thickness": r["design"]["wall_thickness"],
             "coil_index": 1.1, "wrap_angle": 0.14}
        doc = {"index": i, "design": d, "silicone": "tc5005", "stroke": r["stroke"],
               "paper": {"pressure": 1e4, "bend_angle": 1.0, "tip_force": 1.0},
               "free": {"pressure": r["pressure"], "volume_ratio": P_ATM / (P_ATM + r["pressure"]),
                        "bend_angle": r["bend_angle"], "discretisation_error": 0.01},
               "blocked": {"pressure": r["blocked_pressure"], "volume_ratio": 0.9,
                           "tip_force": r["tip_force"], "tip_moment": 0.0,
                           "discretisation_error": 0.02},
               "reached": {"free": True, "blocked": i >= stalled}}
        (folder / f"design_{i:03d}.json").write_text(json.dumps(doc))


def test_fit_sealed_reads_the_twins_records_and_writes_the_variants_file(tmp_path, capsys):
    import json
    from nylonflex.cli import main

    truth = {**TRUE, "k0": 0.0, "k1": 0.0}
    # ten designs, one stalled: each left-out fit still has the 8 blocked pressures the
    # blocked pressure's five coefficients need
    _write_fe_records(tmp_path / "runs", _records(10, truth, seed=3, free_volume=False))
    out = tmp_path / "sealed.json"
    assert main(["fit", "sealed", str(tmp_path / "runs"), "--out", str(out)]) == 0
    text = capsys.readouterr().out
    assert "10 designs (0 records left out)" in text and "within 15%" in text
    doc = json.loads(out.read_text())
    # the record whose blocked solve stalled informs the free fit, not the blocked one
    assert doc["status"] == "fitted" and doc["provenance"]["skipped"] == []
    for name in COEFFICIENT_NAMES:
        assert doc["coefficients"][name] == pytest.approx(truth[name], rel=1e-6, abs=1e-9)
    loo = doc["fit"]["loo"]
    assert len(doc["training"]) == 10 and loo["bend_and_force_within"] == loo["n_both"] == 9
    assert loo["counted"] == {"pressure": 10, "bend_angle": 10, "tip_force": 9}
    assert main(["fit", "sealed", str(tmp_path / "runs"), "--out", str(out)]) == 2
    assert main(["fit", "sealed", str(tmp_path / "nowhere"), "--out", str(out)]) == 2


def test_the_blocked_pressure_ratio_is_at_least_one_and_one_at_rest():
    from nylonflex.physics.sealed import _blocked_ratio, sealed_coefficients

    coef = sealed_coefficients(TRUE)
    assert _blocked_ratio(0.0, 0.01, 0.002, 0.09, coef) == 1.0
    low = sealed_coefficients({**TRUE, "r0": -20.0})
    assert _blocked_ratio(0.05, 0.01, 0.002, 0.09, low) == 1.0
    x = np.log(0.2)
    assert _blocked_ratio(0.05, 0.01, 0.002, 0.09, coef) == pytest.approx(np.exp(
        3.0 + 0.5 * x + 0.1 * x * x + 0.8 * np.log(0.05) + 2.0 * 0.01 / 0.09), rel=1e-14)


def test_coefficients_without_the_blocked_pressure_keep_the_blocked_moment_they_had():
    from nylonflex.physics.sealed import BLOCKED_NEUTRAL, sealed_coefficients

    old = {k: TRUE[k] for k in ("k0", "k1", "g0", "g1", "c0", "c1", "cb")}
    coef = sealed_coefficients(old)
    assert {k: getattr(coef, k) for k in BLOCKED_NEUTRAL} == BLOCKED_NEUTRAL
    st = sealed_state(0.06, 0.01, 0.002, 0.09, coefficients=coef)
    assert st["blocked_pressure"] == st["pressure"]
    assert st["torque"] == pytest.approx(st["pressure_moment"] + st["squeeze_moment"],
                                         rel=1e-15)
    # a cube written before them stores the first seven: read as it was computed
    assert sealed_coefficients(tuple(old.values())) == coef
    with pytest.raises(ValueError, match="needs 13 finite numbers"):
        sealed_coefficients(tuple(old.values())[:6])
    with pytest.raises(ValueError, match="missing r1"):
        sealed_coefficients({**old, "ca": 1.0, "r0": 0.0})
