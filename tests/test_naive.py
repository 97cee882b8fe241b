"""The package's wrap, muscle and heating formulas against tests/naive.py's slow versions.

tests/naive.py writes each formula of docs/model.md (sections 2, 4, 8, 9, 15 and 20) from
its equations, by quadrature and root finding, sharing nothing with nylonflex/physics/ but
the material constants. Here both run at designs drawn over the whole accepted range of
every axis (:func:`naive.random_designs`), for each muscle set, and must agree to
:data:`REL` (1e-9, the accuracy docs/model.md s. 11 asks of the solvers; they agree to
about 1e-14) or, for the closed forms of the wrap and the resistance, :data:`CLOSED`.
"""

import math

import numpy as np
import pytest

import naive
import nylonflex as nf
from nylonflex.materials import NYLON_PARAMETERS, SILICONE_PARAMETERS, nylon_parameters, \
    silicone_parameters
from nylonflex.physics import design_limits, nylon, thermal, wrap

REL = 1e-9
CLOSED = 1e-12
DEG = math.pi / 180

#: Every named muscle set, the default with one r' at every coil index (C_r = 0, as a fit
#: writes it) and one whose r' was measured at C = 1.3.
SETS = {**{name: nylon_parameters(name) for name in NYLON_PARAMETERS},
        "one_r_per_length": nylon_parameters("silver_nylon66", resistance_coil_index=0.0),
        "r_at_1.3": nylon_parameters("silver_nylon66", resistance_coil_index=1.3,
                                     resistance_per_length=120.0)}


def _designs(n, seed):
    """``n`` designs over the accepted ranges (b = t), and two at the smallest wrap angle,
    where the turns touch."""
    d = naive.random_designs(n, seed=seed)
    d = {k: np.append(v, v[:2]) for k, v in d.items()}
    d["wrap_angle"][-2:] = 0.1 * DEG
    return d


def _rows(d):
    return [tuple(float(d[k][i]) for k in ("radius", "wall_thickness", "length", "coil_index",
                                           "wrap_angle")) for i in range(d["radius"].size)]


def _close(got, expected, rel, what):
    got, expected = np.asarray(got, float), np.asarray(expected, float)
    np.testing.assert_allclose(got, expected, rtol=rel, atol=0.0, err_msg=what)


@pytest.mark.parametrize("name", sorted(SETS))
def test_wrap_geometry_matches_naive(name):
    # docs/model.md s. 4: P_out, w, h = max(P_out tan psi, w / cos psi), n = L/h,
    # l_m = n P_out / cos psi, at every design (arrays in, as a sweep calls them)
    ny = SETS[name]
    d = _designs(40, seed=41)
    a, t, L, c, psi = (d[k] for k in ("radius", "wall_thickness", "length", "coil_index",
                                      "wrap_angle"))
    rows = _rows(d)
    d_f = ny.fibre_diameter
    _close(wrap.outer_perimeter(a, t), [naive.outer_perimeter(r[0], r[1], r[1]) for r in rows],
           CLOSED, "outer_perimeter")
    _close(wrap.muscle_width(c, ny), [naive.muscle_width(r[3], d_f) for r in rows], CLOSED,
           "muscle_width")
    pitch = np.array([naive.wrap_pitch(r[0], r[1], r[1], r[4], r[3], d_f) for r in rows])
    _close(wrap.wrap_pitch(a, t, psi, c, nylon=ny), pitch, CLOSED, "wrap_pitch")
    _close(wrap.wrap_turns(a, t, L, psi, c, nylon=ny),
           [naive.wrap_turns(r[0], r[1], r[1], r[2], r[4], r[3], d_f) for r in rows], CLOSED,
           "wrap_turns")
    _close(wrap.muscle_length(a, t, L, psi, c, nylon=ny),
           [naive.muscle_length(r[0], r[1], r[1], r[2], r[4], r[3], d_f) for r in rows],
           CLOSED, "muscle_length")
    # a base of its own (the next design's wall), and both branches of the pitch seen
    b = np.roll(t, 1)
    _close(wrap.muscle_length(a, t, L, psi, c, b, ny),
           [naive.muscle_length(r[0], r[1], bi, r[2], r[4], r[3], d_f)
            for r, bi in zip(rows, b)], CLOSED, "muscle_length, b of its own")
    helix = np.array([naive.outer_perimeter(r[0], r[1], r[1]) * math.tan(r[4]) for r in rows])
    touching = np.array([naive.muscle_width(r[3], d_f) / math.cos(r[4]) for r in rows])
    assert (pitch == touching).any() and (pitch == helix).any()


@pytest.mark.parametrize("name", sorted(SETS))
def test_resistance_matches_naive(name):
    # docs/model.md s. 9: r'(C) = r'(C_r) times the thread per muscle length of a close-wound
    # coil (the arc length of a helix turn over its pitch) at C over that at C_r; R = r' l_m
    ny = SETS[name]
    d = _designs(30, seed=43)
    c = d["coil_index"]
    l_m = np.array([naive.muscle_length(r[0], r[1], r[1], r[2], r[4], r[3], ny.fibre_diameter)
                    for r in _rows(d)])
    r_per = [naive.resistance_per_length(ci, ny) for ci in c]
    _close(thermal.coil_resistance_per_length(c, ny), r_per, CLOSED, "r'(C)")
    _close(thermal.muscle_resistance(l_m, ny, coil_index=c), np.multiply(r_per, l_m), CLOSED,
           "R")
    _close(thermal.coiled_resistance_per_length(2.5, c),
           [2.5 * naive.thread_per_muscle_length(ci) for ci in c], CLOSED, "coiled r'")


@pytest.mark.parametrize("name", sorted(NYLON_PARAMETERS))
def test_stroke_table_and_its_inverse_match_naive(name):
    # docs/model.md s. 2: s(T) = k(C) (eps(T_amb) - eps(T)) with eq. (2) in degC, k(C) =
    # s_max(C) / s_ref(T_max); T(s) its inverse; s_max, F_lim from the table (s. 9)
    ny = SETS[name]
    rng = np.random.default_rng(47)
    c = rng.uniform(1.1, 1.7, 40)
    temp = rng.uniform(ny.t_amb + 0.1, ny.t_max, 40)
    _close(nylon.stroke(temp, c, ny), [naive.stroke(x, ci, ny) for x, ci in zip(temp, c)], REL,
           "s(T)")
    _close(nylon.stroke_max(c, ny),
           [naive.table_value(ci, ny.coil_index_table, ny.stroke_max_table) for ci in c], REL,
           "s_max")
    _close(nylon.nylon_force_limit(c, ny),
           [naive.force_limit(ci, ny.coil_index_table, ny.tensile_strength_table,
                              ny.fibre_diameter) for ci in c], REL, "F_lim")
    s = rng.uniform(0.0, 1.0, 40) * nylon.stroke_max(c, ny)
    _close([nylon.temperature_for_stroke(si, ci, ny) - ny.t_amb for si, ci in zip(s, c)],
           [naive.temperature_for_stroke(si, ci, ny) - ny.t_amb for si, ci in zip(s, c)], REL,
           "T(s) - T_amb")


@pytest.mark.parametrize("name", sorted(SETS))
def test_heating_formulas_match_naive(name):
    # eq. (3) (docs/model.md s. 2): its right-hand side, its steady state (a root of it),
    # the exact step at constant V (the time a quadrature of dT / (dT/dt) takes, inverted
    # by a root finder) and the time constant (the time to cool by a factor e)
    ny = SETS[name]
    rng = np.random.default_rng(53)
    d = _designs(20, seed=53)
    c_per, loss_per, t_amb = ny.heat_capacity_per_length, ny.heat_loss_per_length, ny.t_amb
    assert thermal.thermal_time_constant(ny) == pytest.approx(
        naive.time_constant(c_per, loss_per), rel=REL, abs=0.0)
    for a, t, L, c, psi in _rows(d):
        l_m = naive.muscle_length(a, t, t, L, psi, c, ny.fibre_diameter)
        r_per = naive.resistance_per_length(c, ny)
        # a supply that lifts the muscle 1-400 K above ambient
        rise = math.exp(rng.uniform(0.0, math.log(400.0)))
        v = math.sqrt(r_per * loss_per * rise) * l_m
        t_ss = naive.steady_temperature(v, l_m, r_per, loss_per, t_amb)
        got = float(thermal.steady_temperature(v, l_m, ny, coil_index=c))
        assert got - t_amb == pytest.approx(t_ss - t_amb, rel=REL, abs=0.0), (a, t, L, c, psi)
        t0 = t_amb + rng.uniform(0.0, 1.5) * rise
        assert float(thermal.temperature_rate(t0, v, l_m, ny, coil_index=c)) == pytest.approx(
            naive.temperature_rate(t0, v, l_m, r_per, c_per, loss_per, t_amb), rel=REL)
        for volts in (v, 0.0):  # heating (or cooling towards T_ss) and cooling off
            dt = rng.uniform(0.05, 3.0) * c_per / loss_per
            got = float(thermal.temperature_step(t0, volts, dt, l_m, ny, coil_index=c))
            exp = naive.temperature_after(t0, volts, dt, l_m, r_per, c_per, loss_per, t_amb)
            assert got - t_amb == pytest.approx(exp - t_amb, rel=REL, abs=0.0), (volts, dt)


#: What design_limits returns that tests/naive.py computes (docs/model.md s. 8, 15, 20).
THERMAL = ("usable_stroke", "limit", "pressure_max", "torque_max", "tip_force_max",
           "nylon_force_max", "nylon_use", "muscle_length", "resistance", "heating_power",
           "heating_voltage", "cooling_time", "heating_time", "cycle_time", "cycle_rate",
           "heating_energy", "mechanical_work", "efficiency")


def _check_design_values(name, supply, limits_of, n=16, seed=59):
    ny = SETS[name]
    rng = np.random.default_rng(seed)
    sets = list(SILICONE_PARAMETERS)
    limits = set()
    for i, (a, t, L, c, psi) in enumerate(_rows(_designs(n, seed=seed))):
        silicone = sets[i % len(sets)]
        mu, alpha = silicone_parameters(silicone).arrays()
        v = None
        if supply:  # T_ss 2-400 K above ambient (supply-limited below T_max - T_amb =
            # 125 K), or less where that needs more than the 1000 V accepted
            l_m = naive.muscle_length(a, t, t, L, psi, c, ny.fibre_diameter)
            rise = math.exp(rng.uniform(math.log(2.0), math.log(400.0)))
            v = min(1000.0, math.sqrt(naive.resistance_per_length(c, ny)
                                      * ny.heat_loss_per_length * rise) * l_m)
        got = limits_of(a, t, L, c, psi, silicone=silicone, nylon=ny, supply_voltage=v)
        exp = naive.design_thermal(a, t, t, L, c, psi, mu, alpha, ny, v)
        for key in THERMAL:
            if key == "limit":
                assert got[key] == exp[key], (key, a, t, L, c, psi)
            elif math.isnan(exp[key]):
                assert math.isnan(got[key]), key
            else:
                assert got[key] == pytest.approx(exp[key], rel=REL, abs=0.0), \
                    (key, a, t, L, c, psi, v)
        limits.add(int(got["limit"]))
    return limits


@pytest.mark.parametrize("supply", [False, True], ids=["no supply", "supply"])
@pytest.mark.parametrize("name", sorted(SETS))
def test_design_thermal_values_match_naive(name, supply):
    # physics.design_limits' muscle and heating values at designs over the accepted ranges:
    # s* (the supply's cap T_ss = T_amb + V^2/(r' lambda' l_m^2), then the strength's),
    # T*, T_5 and T_95 by root finding on eq. (2), the heating power and voltage, cooling,
    # heating and cycle times by quadrature of eq. (3), the heating energy by its energy
    # balance and the work by a quadrature of F_n
    limits = _check_design_values(name, supply, design_limits)
    assert limits == ({0, 1, 2} if supply else {0, 1})  # every branch seen


# every set, also one with resistance_coil_index 0 (one r' at every C, as 'fit thermal'
# writes it), which Nylon.to_dict() leaves out so that such a set hashes as before issue 30
@pytest.mark.parametrize("name", sorted(SETS))
def test_the_compiled_design_limits_match_naive_too(name):
    # nf.design_limits (nf.evaluate's compiled kernel), with a supply, at fewer designs
    _check_design_values(name, True, nf.design_limits, n=6, seed=61)
