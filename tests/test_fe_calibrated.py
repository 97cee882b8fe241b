"""The ``fe_calibrated`` variant (docs/model.md s. 21): ``lateral_pressure``'s angle times
the shipped correction, in every kernel.

Expected values come from ``lateral_pressure`` (its own tests pin it) times the
correction written independently from the fit's regressors (``fe.calibrate
.correction_terms``), and from the shipped calibration file itself.
"""

import math

import numpy as np
import pytest

import nylonflex as nf
from nylonflex.fe.calibrate import correction_terms
from nylonflex.materials import silicone_parameters
from nylonflex.physics.calibrated import COEFFICIENTS, TERMS, calibration

MU0 = silicone_parameters("tc5005").initial_shear_modulus


def _factor(p, a, t, L):
    return np.exp(correction_terms(p, a, t, L, MU0) @ np.asarray(COEFFICIENTS))


def test_the_shipped_file_holds_its_fit_and_provenance():
    doc = calibration()
    assert doc["model"] == "fe_calibrated" and tuple(doc["terms"]) == TERMS
    assert len(doc["training"]) >= 40
    assert {"command", "nylonflex_version", "created", "mesh", "silicone"} <= \
        set(doc["provenance"])
    # the leave-one-design-out error it reports: within 10 % for at least 40 designs
    idx = np.asarray(doc["fit"]["design_index"])
    loo = np.abs(np.asarray(doc["fit"]["loo_calibrated_over_fe"]) - 1.0) <= 0.1
    assert sum(bool(loo[idx == k].all()) for k in np.unique(idx)) >= 40


@pytest.mark.parametrize("a, t, L", [(20e-3, 6e-3, 90e-3), (7.5e-3, 2e-3, 70e-3),
                                     (25e-3, 1e-3, 150e-3), (5e-3, 6e-3, 50e-3)])
def test_angle_is_lateral_pressures_times_the_correction(a, t, L):
    p = np.array([0.0, 1e3, 5e3, 20e3])
    lateral = nf.bend_angle(p, a, t, L, model="lateral_pressure")
    cal = nf.bend_angle(p, a, t, L, model="fe_calibrated")
    np.testing.assert_allclose(cal, lateral * _factor(p, a, t, L), rtol=1e-12)


@pytest.mark.parametrize("a, t, L", [(25e-3, 1e-3, 150e-3), (5e-3, 6e-3, 50e-3),
                                     (15e-3, 0.5e-3, 200e-3)])
def test_angle_grows_with_pressure_beyond_the_training_range(a, t, L):
    # the correction is bounded in q = p a / (mu0 t), so the angle keeps rising
    p = np.linspace(0.0, 60e3, 241)
    theta = nf.bend_angle(p, a, t, L, model="fe_calibrated")
    assert np.all(np.diff(theta) > 0)


def test_cube_and_evaluate_agree_with_the_correction():
    from nylonflex.config import parse_config
    from nylonflex.sweep.conductor import run_sweep

    cfg = parse_config({
        "name": "calibrated", "model": ["lateral_pressure", "fe_calibrated"],
        "grid": {"radius": {"values": [7.5, 20], "units": "mm"},
                 "wall_thickness": {"values": [2, 6], "units": "mm"},
                 "length": {"values": [70, 90], "units": "mm"},
                 "coil_index": {"values": [1.1, 1.7]},
                 "wrap_angle": {"values": [8], "units": "deg"}},
        "curves": {"stroke": {"start": 0, "stop": 0.1, "num": 3},
                   "pressure": {"start": 0, "stop": 20, "num": 5, "units": "kPa"}}})
    ds = run_sweep(cfg)
    lat, cal = ds.sel(model="lateral_pressure"), ds.sel(model="fe_calibrated")
    a, t, L = (ds[n].values for n in ("radius", "wall_thickness", "length"))
    # the curve: theta(p) of each (a, t, L)
    f = _factor(ds.pressure.values[None, None, None, :], a[:, None, None, None],
                t[None, :, None, None], L[None, None, :, None])
    np.testing.assert_allclose(cal["bend_angle"].values, lat["bend_angle"].values * f,
                               rtol=1e-12)
    # the design: the same pressure, the angle corrected at p*, the tip force unchanged
    np.testing.assert_array_equal(cal["pressure_max"].values, lat["pressure_max"].values)
    np.testing.assert_array_equal(cal["tip_force_max"].values, lat["tip_force_max"].values)
    pstar = cal["pressure_max"].transpose("radius", "wall_thickness", "length", ...).values
    fd = _factor(pstar, a[:, None, None, None, None], t[None, :, None, None, None],
                 L[None, None, :, None, None])
    np.testing.assert_allclose(
        cal["bend_angle_max"].transpose("radius", "wall_thickness", "length", ...).values,
        lat["bend_angle_max"].transpose("radius", "wall_thickness", "length", ...).values
        * fd, rtol=1e-9)
    # and the pointwise kernel (nf.evaluate) gives the grid's numbers
    one = dict(radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
               wrap_angle=math.radians(8))
    ev = nf.evaluate(**one, model="fe_calibrated")
    grid = cal.sel(radius=20e-3, wall_thickness=6e-3, length=90e-3, coil_index=1.1,
                   method="nearest").isel(wrap_angle=0)
    assert ev["bend_angle_max"] == pytest.approx(float(grid["bend_angle_max"]), rel=1e-9)
    assert ev["range_fraction"] == pytest.approx(float(grid["range_fraction"]), rel=1e-9)
