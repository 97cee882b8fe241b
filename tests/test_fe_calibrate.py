"""``nylonflex fit fe`` (docs/fidelity.md): the training pressures bend ``lateral_pressure``
by the target angles, the correction's fit recovers a known synthetic correction (and its
leave-one-out predicts designs it has not seen), and bad input is one line."""

import math

import numpy as np
import pytest

from nylonflex.fe.calibrate import (TARGET_ANGLES, correction_terms, extrapolated,
                                    fit_correction, training_plan)
from nylonflex.materials import silicone_parameters
from nylonflex.physics.limits import model_bend_angle


@pytest.fixture(scope="module")
def plan():
    return training_plan(6, seed=3, mesh="coarse")


def _synthetic(plan, coef, noise=0.0, seed=0):
    """'FE' angles: lateral_pressure's angle scaled by exp(X c) (times a log-normal noise,
    one draw a design, so a design's two angles err together), as mesh pairs whose
    Richardson extrapolation is that angle."""
    mu0 = silicone_parameters("tc5005").initial_shear_modulus
    rng = np.random.default_rng(seed)
    done = {}
    for k, d in enumerate(plan["designs"]):
        e = rng.normal(0.0, noise)
        th = [model_bend_angle(p, d["radius"], d["wall_thickness"], d["length"],
                               model="lateral_pressure") * math.exp(float(
                                   correction_terms(p, d["radius"], d["wall_thickness"],
                                                    d["length"], mu0) @ coef) + e)
              for p in d["pressures"]]
        done[k] = {"bend_angle": th, "coarser_bend_angle": th}
    return done


def test_training_pressures_bend_lateral_pressure_by_the_target_angles(plan):
    for d in plan["designs"]:
        th = [model_bend_angle(p, d["radius"], d["wall_thickness"], d["length"],
                               model="lateral_pressure") for p in d["pressures"]]
        np.testing.assert_allclose(th, TARGET_ANGLES, rtol=1e-9)


def test_fit_recovers_a_known_correction(plan):
    truth = np.array([0.15, -0.08, -0.2, -0.5])
    res = fit_correction(plan, _synthetic(plan, truth))
    np.testing.assert_allclose(res["coefficients"], truth, atol=1e-6)
    np.testing.assert_allclose(res["calibrated_over_fe"], 1.0, atol=1e-8)
    # leave-one-out predicts a design it has not seen, exactly when the truth is in the family
    np.testing.assert_allclose(res["loo_calibrated_over_fe"], 1.0, atol=1e-6)
    # lateral_pressure/FE is the truth's factor undone
    mu0 = silicone_parameters("tc5005").initial_shear_modulus
    rows = [plan["designs"][k] for k in res["design_index"]]
    X = correction_terms(res["pressure"], [d["radius"] for d in rows],
                         [d["wall_thickness"] for d in rows], [d["length"] for d in rows], mu0)
    np.testing.assert_allclose(res["lateral_over_fe"], np.exp(-X @ truth), rtol=1e-9)


def test_fit_recovers_a_known_correction_through_correlated_noise():
    # 2 % log-normal noise shared by each design's two angles (a mesh error is of one
    # design): 40 designs still give the coefficients to a few times their standard error
    plan = training_plan(40, seed=5, mesh="coarse")
    truth = np.array([0.6, 0.02, -0.27, -0.9])
    res = fit_correction(plan, _synthetic(plan, truth, noise=0.02, seed=1))
    np.testing.assert_allclose(res["coefficients"], truth, atol=0.12)
    loo = np.asarray(res["loo_calibrated_over_fe"])
    assert np.median(np.abs(loo - 1.0)) < 0.03


def test_the_kernels_correction_is_the_fitted_form():
    # physics.calibrated (compiled into the kernels) against correction_terms (the fit's)
    from nylonflex.physics.calibrated import (COEFFICIENTS, _length_correction,
                                              _section_correction)

    sil = silicone_parameters("tc5005")
    mu, alpha = sil.arrays()
    for p, a, t, L in [(2e3, 20e-3, 6e-3, 90e-3), (9e3, 7.5e-3, 2e-3, 70e-3),
                       (0.0, 25e-3, 1e-3, 150e-3)]:
        X = correction_terms(p, a, t, L, sil.initial_shear_modulus)
        expected = math.exp(float(X @ np.asarray(COEFFICIENTS)))
        got = _section_correction(p, a, t, mu, alpha) * _length_correction(a, L)
        assert got == pytest.approx(expected, rel=1e-12)


def test_extrapolation_is_richardsons():
    # r = 1.5, order 2: theta_h + (theta_h - theta_2h) / 1.25
    assert extrapolated(2.0, 1.5) == pytest.approx(2.4, rel=1e-15)


@pytest.mark.parametrize("args, match", [
    (["fit", "fe", "--designs", "0"], "--designs: must be in"),
    (["fit", "fe", "--mesh", "huge"], "--mesh: must be one of"),
    (["fit", "fe", "data.csv"], "fit fe: takes no data file"),
    (["fit", "silicone"], "DATA: required for 'fit silicone'"),
])
def test_fit_fe_bad_input_is_one_line_and_exit_2(args, match, capsys, tmp_path, monkeypatch):
    from nylonflex.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and match in err[0]
