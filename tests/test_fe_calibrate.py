"""``nylonflex fit fe`` (docs/fidelity.md): the training pressures bend ``lateral_pressure``
by the target angles, the correction's fit recovers a known synthetic correction (and its
leave-one-out predicts designs it has not seen), and bad input is one line."""

import math

import numpy as np
import pytest

from nylonflex.fe.calibrate import (TARGET_ANGLES, correction_terms, extrapolated,
                                    fit_correction, training_plan)
from nylonflex.physics.limits import model_bend_angle


@pytest.fixture(scope="module")
def plan():
    return training_plan(6, seed=3, mesh="coarse")


def _synthetic(plan, coef):
    """'FE' angles: lateral_pressure's moment scaled by exp(X c), as mesh pairs whose
    Richardson extrapolation is that angle."""
    done = {}
    for k, d in enumerate(plan["designs"]):
        f = math.exp(float(correction_terms(d["radius"], d["wall_thickness"]) @ coef))
        th = [model_bend_angle(p * f, d["radius"], d["wall_thickness"], d["length"],
                               model="lateral_pressure") for p in d["pressures"]]
        done[k] = {"bend_angle": th, "coarser_bend_angle": th}
    return done


def test_training_pressures_bend_lateral_pressure_by_the_target_angles(plan):
    for d in plan["designs"]:
        th = [model_bend_angle(p, d["radius"], d["wall_thickness"], d["length"],
                               model="lateral_pressure") for p in d["pressures"]]
        np.testing.assert_allclose(th, TARGET_ANGLES, rtol=1e-9)


def test_fit_recovers_a_known_correction(plan):
    truth = np.array([0.15, -0.08, 0.03])
    res = fit_correction(plan, _synthetic(plan, truth))
    np.testing.assert_allclose(res["coefficients"], truth, atol=1e-6)
    np.testing.assert_allclose(res["calibrated_over_fe"], 1.0, atol=1e-8)
    # leave-one-out predicts a design it has not seen, exactly when the truth is in the family
    np.testing.assert_allclose(res["loo_calibrated_over_fe"], 1.0, atol=1e-6)
    assert np.all(np.asarray(res["lateral_over_fe"]) < 1.0)  # the truth bends further


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
