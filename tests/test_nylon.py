import math

import numpy as np
import pytest

from nylonflex.materials import nylon_parameters
from nylonflex.physics import nylon, thermal, wrap
from nylonflex.physics.nylon import free_strain, stroke, stroke_max, tensile_strength

T_AMB, T_MAX = 298.15, 423.15  # docs/model.md section 9: 25 degC, 150 degC


@pytest.mark.parametrize("c,smax,su", [(1.1, 0.054, 100e6), (1.3, 0.068, 85e6),
                                       (1.5, 0.083, 73e6), (1.7, 0.097, 65e6)])
def test_coil_index_table_rows(c, smax, su):
    # docs/model.md section 9, coil-index table
    assert stroke_max(c) == pytest.approx(smax, rel=1e-12)
    assert tensile_strength(c) == pytest.approx(su, rel=1e-12)


def test_table_interpolates_linearly():
    assert stroke_max(1.2) == pytest.approx((0.054 + 0.068) / 2, rel=1e-12)
    assert tensile_strength(1.6) == pytest.approx((73e6 + 65e6) / 2, rel=1e-12)


def test_force_limit_is_strength_times_fibre_area():
    # F_lim = sigma_u pi d_f^2 / 4, d_f = 0.34 mm (docs/model.md sections 2, 9)
    assert nylon.nylon_force_limit(1.1) == pytest.approx(100e6 * math.pi * 0.34e-3**2 / 4)


def test_larger_coil_index_more_stroke_less_strength():
    # paper section 4 after Haines et al.: inverse relation of stroke and strength
    c = np.linspace(1.1, 1.7, 13)
    assert np.all(np.diff(stroke_max(c)) > 0)
    assert np.all(np.diff(tensile_strength(c)) < 0)


@pytest.mark.parametrize("c", [1.1, 1.37, 1.7])
def test_stroke_choice_zero_at_ambient_and_s_max_at_t_max(c):
    # docs/model.md section 2 [choice]: s(T) = eps(T_amb) - eps(T), scaled to reach s_max(C)
    assert stroke(T_AMB, c) == 0.0
    assert stroke(T_MAX, c) == pytest.approx(stroke_max(c), rel=1e-13)


def test_stroke_is_one_shape_scaled_per_coil_index():
    t = np.linspace(T_AMB, T_MAX + 20, 17)
    ratio = stroke(t[1:], 1.7) / stroke(t[1:], 1.1)
    assert np.allclose(ratio, 0.097 / 0.054, rtol=1e-12)


def test_stroke_follows_eq2_erf_form():
    # eq. (2) written out with the reference constants of docs/model.md section 9 (degC)
    a, g, b, tg, sg = -0.04341, 1.951e-4, 0.04944, 118.6, 41.3
    eps = lambda tc: a - g * tc - b * math.erf((tc - tg) / (sg * math.sqrt(2)))  # noqa: E731
    k = 0.097 / (eps(25.0) - eps(150.0))
    for tc in (40.0, 90.0, 120.0):
        assert stroke(tc + 273.15, 1.7) == pytest.approx(k * (eps(25.0) - eps(tc)), rel=1e-12)
        assert free_strain(tc + 273.15, 1.7) == pytest.approx(k * eps(tc), rel=1e-12)


def test_stroke_increases_with_temperature():
    t = np.linspace(T_AMB, T_MAX, 50)
    assert np.all(np.diff(stroke(t, 1.3)) > 0)


def test_temperature_for_stroke_inverts_stroke():
    for s in (0.0, 0.01, 0.05, 0.097):
        assert stroke(nylon.temperature_for_stroke(s, 1.7), 1.7) == pytest.approx(s, abs=1e-13)


def _bisected_temperature(s, scale, ny):
    """The root of eq. (2) by plain bisection on the same float64 shape, run until the
    bracket cannot shrink: the slow reference of the Newton solve [K]."""
    args = (ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    lo, hi = ny.t_amb, ny.t_max
    while True:
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            return mid
        if nylon._stroke_shape(mid, *args) * scale < s:
            lo = mid
        else:
            hi = mid


def test_temperature_solve_converges_in_a_few_steps_to_the_rounding_of_the_root(
        monkeypatch):
    # the solve once tested convergence only after its bracket test, so a step below half
    # an ulp, which leaves T on the bracket's edge, was bisected away from the root: 16
    # steps on average (46 at most), ending on a bisection midpoint up to 7e-11 of
    # T - T_amb from the root, which the cooling time's log then carried (docs/model.md
    # s. 15)
    from nylonflex.materials import nylon_parameters

    ny = nylon_parameters("silver_nylon66")
    calls = []
    shape_at = nylon._stroke_shape_at
    monkeypatch.setattr(nylon, "_stroke_shape_at", lambda *a: calls.append(1) or shape_at(*a))
    scale = 0.05
    top = nylon._stroke_shape(ny.t_max, ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)
    steps, errors = [], []
    for frac in np.concatenate([np.linspace(1e-4, 0.999, 120), np.geomspace(1e-6, 1e-2, 30)]):
        s = frac * top * scale
        calls.clear()
        t = nylon._temperature_for_stroke(s, scale, ny.t_amb, ny.t_max, ny.gamma, ny.beta,
                                          ny.t_g, ny.sigma_g)
        steps.append(len(calls) - 1)  # the first call is T_max's stroke
        # as close as the best float64 root: its stroke misses s by no more than the
        # bisected root's (plus a few roundings of s)
        miss = lambda temp: abs(scale * nylon._stroke_shape(  # noqa: E731
            temp, ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g) - s)
        errors.append(miss(t) / (2.0 * miss(_bisected_temperature(s, scale, ny))
                                 + 8.0 * np.finfo(float).eps * s))
    assert max(steps) <= 8 and np.mean(steps) < 6
    assert max(errors) <= 1.0


def test_thermomechanical_force_eq1():
    # F = k (x - x0) + b_d v + c (T - T0), docs/model.md section 9 constants
    f = nylon.thermomechanical_force(0.002, 0.01, T_AMB + 50, rest_displacement=0.001)
    assert f == pytest.approx(16 * 0.001 + 0.1 * 0.01 + 2e-3 * 50)


def test_default_design_muscle_length_and_heating():
    # docs/model.md section 10: l_m ~ 503 mm, R ~ 75 ohm, 1.91 W at 12 V, tau = c'/lambda' = 15 s
    lm = wrap.muscle_length(7.5e-3, 2e-3, 70e-3, 8 * math.pi / 180, 1.7)
    assert lm == pytest.approx(0.503, abs=1e-3)
    assert thermal.muscle_resistance(lm) == pytest.approx(75.5, abs=0.2)
    assert 12**2 / thermal.muscle_resistance(lm) == pytest.approx(1.91, abs=0.01)
    assert thermal.thermal_time_constant() == pytest.approx(15.0)
    # docs/model.md section 9: with 12 V on ~0.5 m the muscle settles near T_max
    assert thermal.steady_temperature(12.0, lm) == pytest.approx(T_MAX, abs=3.0)


def test_thermal_step_is_the_exact_solution_of_eq3():
    from scipy.integrate import solve_ivp

    lm, v, t0 = 0.5, 12.0, T_AMB + 10
    sol = solve_ivp(lambda t, y: [thermal.temperature_rate(y[0], v, lm)], (0, 7.0), [t0],
                    rtol=1e-12, atol=1e-12)
    assert thermal.temperature_step(t0, v, 7.0, lm) == pytest.approx(sol.y[0, -1], rel=1e-10)
    assert thermal.temperature_rate(thermal.steady_temperature(v, lm), v, lm) == \
        pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("kwargs,match", [
    (dict(temperature=300.0, coil_index=1.0), r"coil_index: must be in \[1.1, 1.7\]"),
    (dict(temperature=300.0, coil_index=1.8), r"coil_index: must be in \[1.1, 1.7\]"),
    (dict(temperature=-3.0, coil_index=1.3), r"temperature: must be > 0 \[K\]"),
    (dict(temperature=float("nan"), coil_index=1.3), r"temperature: must be > 0"),
])
def test_bad_input_names_the_parameter(kwargs, match):
    with pytest.raises(ValueError, match=match):
        stroke(**kwargs)


def test_still_air_heat_loss_is_churchill_chu_for_the_muscles_diameter():
    # issue 30: Churchill & Chu 1975, Nu = {0.60 + 0.387 Ra^(1/6)/[1 + (0.559/Pr)^(9/16)]^(8/27)}^2;
    # by hand at T_f = 360.65 K (Incropera A.4 between 350 and 400 K: k 0.030808,
    # nu 2.2089e-5, a 3.1688e-5, Pr 0.69787), D = 0.34 mm (1.4 + 1), dT = 125 K:
    # Ra = 9.80665 125/360.65 (0.816e-3)^3 / (nu a) = 2.638, Nu = 0.9548, pi k Nu = 0.09242
    d = 0.34e-3 * (1.4 + 1.0)
    lam = thermal.free_convection_loss_per_length(d, T_MAX, T_AMB)
    assert lam == pytest.approx(0.09242, rel=2e-4)
    still = nylon_parameters("silver_nylon66_still_air")
    assert still.heat_loss_per_length == pytest.approx(lam, rel=1e-3)  # the set, rounded
    # a thin wire: the conduction limit Nu -> 0.36, lambda' -> 0.36 pi k
    k300 = thermal.AIR_PROPERTIES["k"][0]
    assert thermal.free_convection_loss_per_length(1e-9, 300.5, 299.5) == pytest.approx(
        0.36 * math.pi * k300, rel=2e-3)
    # radiation adds eps sigma (Ts^2 + Ta^2)(Ts + Ta) pi D
    rad = 0.9 * 5.670374419e-8 * (T_MAX**2 + T_AMB**2) * (T_MAX + T_AMB) * math.pi * d
    assert thermal.free_convection_loss_per_length(d, T_MAX, T_AMB, 0.9) == pytest.approx(
        lam + rad, rel=1e-12)
    with pytest.raises(ValueError, match="film temperature"):
        thermal.free_convection_loss_per_length(d, 700.0, T_AMB)


def test_close_wound_coil_holds_sqrt_pi_c_squared_plus_one_of_thread():
    # a helix of pitch d_f and mean diameter C d_f: sqrt((pi C d_f)^2 + d_f^2) per d_f
    assert thermal.coiled_resistance_per_length(1.0, 1.1) == pytest.approx(3.5975, abs=1e-4)
    assert thermal.coiled_resistance_per_length(1.0, 1.7) == pytest.approx(5.4335, abs=1e-4)
