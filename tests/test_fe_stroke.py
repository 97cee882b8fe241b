"""The FE twin driven as built (nylonflex.fe.sealed, nf.fe_stroke): the wrap shortened by the
stroke, the chamber sealed (docs/fidelity.md, "Driven as built").

Rough and coarse meshes in the fast suite. Expected values: Boyle's law (paper eq. 7), the
cavity's volume of the deformed mesh by an independent tetrahedral decomposition, the
isochoric (Gay-Lussac) limit of a stiff body, the imposed-pressure solve at the same wrap
length, and the caps' pressure moment of the paper's eq. (16).
"""

import dataclasses
import math

import numpy as np
import pytest

from nylonflex.fe import fe_stroke
from nylonflex.fe.mesh import body_mesh
from nylonflex.materials import nylon_parameters, silicone_parameters
from nylonflex.physics.chamber import P_ATM
from nylonflex.units import InputError

felupe = pytest.importorskip("felupe")

A, T, L = 20e-3, 6e-3, 90e-3  # the paper's example 1
#: The hexahedron's faces (local corner indices), each ordered counter-clockwise seen
#: from outside the cell (VTK's node order).
HEX_FACES = np.array([(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6),
                      (3, 0, 4, 7)])


def _cavity_volume(body, displacement):
    """The chamber's volume [m^3] of the deformed half mesh, independently of the solver:
    the body's boundary faces whose corners all lie on the chamber's surface, each split
    into tetrahedra with the origin along both diagonals (their mean is the volume under a
    bilinear face exactly), the symmetry plane x = 0 adding nothing."""
    x = body.points + displacement
    faces = body.cells[:, HEX_FACES].reshape(-1, 4)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    outer = counts[inverse.ravel()] == 1
    faces = faces[outer & np.all(body.chamber[faces], axis=1)]
    p = [x[faces[:, i]] for i in range(4)]

    def tet(a, b, c):
        return np.einsum("ij,ij->i", a, np.cross(b, c)) / 6.0

    out = 0.5 * (tet(p[0], p[1], p[2]) + tet(p[0], p[2], p[3])
                 + tet(p[0], p[1], p[3]) + tet(p[1], p[2], p[3]))
    return -2.0 * float(out.sum())  # outward from the solid is into the cavity


def _solve(body, strokes, mu_scale=1.0, **kw):
    from nylonflex.fe.sealed import solve_stroke

    mu, alpha = silicone_parameters("tc5005").arrays()
    states = {}
    out = solve_stroke(body, mu * mu_scale, alpha, strokes, p_atm=P_ATM,
                       inspect=lambda i, u: states.__setitem__(i, u), **kw)
    return out, states


def test_independent_cavity_volume_of_the_undeformed_mesh():
    # the half D-section pi a^2 / 4 times L, less the arc's polygon segments
    body = body_mesh(A, T, L, mesh="coarse")
    n = 6  # the coarse mesh's arc divisions of the quarter circle
    exact = math.pi * A * A / 4 * L * math.sin(math.pi / 2 / n) / (math.pi / 2 / n)
    assert _cavity_volume(body, 0 * body.points) / 2 == pytest.approx(exact, rel=1e-12)


def test_sealed_chamber_obeys_boyle_with_the_deformed_cavity():
    """At every converged stroke (p0 + p) V / V0 = p0, V the deformed mesh's cavity by
    the independent decomposition, and the reported V/V0 is that cavity's."""
    body = body_mesh(A, T, L, mesh="rough")
    strokes = [0.054, 0.02]
    out, states = _solve(body, strokes)
    v0 = _cavity_volume(body, 0 * body.points)
    assert sorted(states) == [0, 1]
    for i, u in states.items():
        ratio = _cavity_volume(body, u) / v0
        assert out["volume_ratio"][i] == pytest.approx(ratio, rel=1e-10)
        assert (P_ATM + out["pressure"][i]) * ratio == pytest.approx(P_ATM, rel=1e-10)
    # the wrap squeezes: the pressure rises with the stroke, the cavity shrinks
    assert 0 < out["pressure"][1] < out["pressure"][0]
    assert out["volume_ratio"][0] < out["volume_ratio"][1] < 1


def test_heated_air_obeys_boyle_and_the_isochoric_limit():
    """Air warmed by dT at zero stroke: (p0 + p) V/V0 = p0 (T0 + dT)/T0 on the deformed
    mesh. In a body 1e3 and 1e4 times stiffer than TC5005 (silicone, skin and wrap alike)
    the cavity hardly moves, so p -> p0 dT / T0 (Gay-Lussac, isochoric), the gap falling as
    the stiffness rises (about tenfold: measured 159 and 16 Pa); TC5005 itself gives way
    (V/V0 1.064, p 335 Pa measured: the chamber's volumetric stiffness of about 5 kPa)."""
    t0 = nylon_parameters().t_amb
    dT = 20.0
    theta = (t0 + dT) / t0
    body = body_mesh(7.5e-3, 2e-3, 70e-3, mesh="rough")
    v0 = _cavity_volume(body, 0 * body.points)
    p = {}
    for scale in (1.0, 1e3, 1e4):
        out, states = _solve(body, [0.0], mu_scale=scale, heating=theta)
        ratio = _cavity_volume(body, states[0]) / v0
        assert (P_ATM + out["pressure"][0]) * ratio == pytest.approx(P_ATM * theta, rel=1e-10)
        p[scale] = out["pressure"][0]
    isochoric = P_ATM * dT / t0  # 6797 Pa
    assert p[1e4] == pytest.approx(isochoric, rel=3e-3)
    assert (isochoric - p[1e3]) / (isochoric - p[1e4]) == pytest.approx(10, rel=0.05)
    assert 0 < p[1.0] < 0.1 * isochoric


def test_sealed_state_is_the_imposed_pressure_state_at_that_wrap_length():
    """The sealed solve at stroke s lands on (p, V, angle); the pressure-driven solve of
    the same body, its wrap shortened to 1 - s with the chamber vented and then loaded with
    that p, must reach the same V and angle (one equilibrium, two paths)."""
    from nylonflex.fe.solve import solve_pressures

    body = body_mesh(7.5e-3, 2e-3, 70e-3, mesh="rough")
    s = 0.06
    sealed, _ = _solve(body, [s])
    mu, alpha = silicone_parameters("tc5005").arrays()
    imposed = solve_pressures(body, mu, alpha, [sealed["pressure"][0]], stroke=s)
    assert imposed["volume_ratio"][0] == pytest.approx(sealed["volume_ratio"][0], rel=1e-6)
    assert imposed["bend_angle"][0] == pytest.approx(sealed["bend_angle"][0], rel=1e-4)


def _caps_only(body):
    a, b, L = body.radius, body.base_thickness, body.length
    px, py, pz = body.points.T
    tol = 1e-9 * (a + body.wall_thickness + b + L)
    caps = ((np.abs(pz) < tol) | (np.abs(pz - L) < tol)) & (np.hypot(px, py - b) <= a + tol) \
        & (py >= b - tol)
    return dataclasses.replace(body, chamber=caps)


@pytest.mark.parametrize("a, t, L", [(20e-3, 6e-3, 90e-3), (7.5e-3, 2e-3, 70e-3)])
def test_blocked_moment_of_the_caps_pressure_is_eq_16(a, t, L):
    """Held straight at both ends, the pressure on the caps only is balanced by the
    holders: the tip's moment about the skin is the caps' D-section pressure moment,
    M = (4 a^3 + 3 pi a^2 b) / 6 p (paper eq. 16; half disc pi a^2/2 at b + 4a/(3 pi)),
    to the coarse mesh's polygon arc (measured 0.3 and 0.5 %). With the wall and floor
    loaded too, the held wall pushes on the holder besides (the lateral pressure's
    lengthening, docs/fidelity.md): measured 1.7-1.9 times eq. (16)."""
    from nylonflex.fe.solve import solve_pressures

    mu, alpha = silicone_parameters("tc5005").arrays()
    p = 1e3
    eq16 = (4 * a ** 3 + 3 * math.pi * a * a * t) / 6 * p
    body = body_mesh(a, t, L, mesh="coarse")
    caps = solve_pressures(_caps_only(body), mu, alpha, [p], blocked=True)
    assert caps["tip_moment"][0] == pytest.approx(eq16, rel=0.02)
    full = solve_pressures(body_mesh(a, t, L, mesh="rough"), mu, alpha, [p], blocked=True)
    assert 1.3 < full["tip_moment"][0] / eq16 < 2.5


def test_fe_stroke_returns_both_meshes_and_the_blocked_force():
    out = fe_stroke(7.5e-3, 2e-3, 70e-3, [0.0, 0.03], mesh="coarse", blocked=True)
    for name in ("stroke", "pressure", "volume_ratio", "bend_angle", "tip_moment",
                 "tip_force", "discretisation_error", "pressure_error", "coarser_pressure",
                 "coarser_tip_moment"):
        assert np.shape(out[name]) == (2,), name
    assert out["pressure"][0] == 0 and out["tip_force"][0] == pytest.approx(0, abs=1e-12)
    assert out["tip_force"][1] == pytest.approx(out["tip_moment"][1] / 70e-3, rel=1e-14)
    assert out["tip_force"][1] > 0 and 0 < out["discretisation_error"][1] < 0.2
    # the pressure's estimate: first order with Roache's safety factor 3, 3 / (1.5 - 1) = 6
    # times the relative gap between the two meshes
    gap = abs(out["pressure"][1] / out["coarser_pressure"][1] - 1) * out["coarser_pressure"][1] \
        / out["pressure"][1]
    assert out["pressure_error"][1] == pytest.approx(6 * gap, rel=1e-12)


@pytest.mark.parametrize("kw, match", [
    ({"strokes": [0.5]}, r"strokes: each must be in \[0, 0.5\)"),
    ({"strokes": [-0.01]}, r"strokes: each must be in"),
    ({"strokes": []}, r"strokes: need at least one"),
    ({"strokes": np.zeros(101)}, r"strokes: at most 100"),
    ({"strokes": [0.05], "air_heating": -1.0}, r"air_heating: must be in \[0, 200\] K"),
    ({"strokes": [0.05], "mesh": "huge"}, r"mesh: must be one of"),
])
def test_fe_stroke_rejects_bad_input(kw, match):
    with pytest.raises(InputError, match=match):
        fe_stroke(A, T, L, **kw)


@pytest.mark.parametrize("args, match", [
    (["--stroke", "0:0.6:4"], r"--stroke: each must be in \[0, 0.5\)"),
    (["--stroke", "0:0.05:0.01"], r"--stroke: START:STOP:NUM takes a whole NUM"),
    (["--stroke", "0.05", "--air-heating=-5K"], r"--air-heating: must be in \[0, 200\] K"),
    (["--stroke", "0.05", "--air-heating", "20"], r"--air-heating: .*unit K"),
    (["--stroke", "0.05", "--air-heating", "20degC"], r"--air-heating: .*unit K"),
    (["--blocked"], r"--blocked: needs --pressure or --stroke"),
    (["--stroke", "0:0.2:101"], r"--stroke: at most 100"),
    (["--stroke", "0.05", "--pressure", "2kPa"], r"--stroke: .*not both"),
    (["--air-heating", "5K", "--pressure", "2kPa"], r"--air-heating: .*--stroke"),
])
def test_cli_stroke_bad_input_exits_2_with_one_line(args, match, capsys):
    from nylonflex.cli import main

    code = main(["fe", "--at", "radius=20mm,wall_thickness=6mm,length=90mm", *args])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1, err
    assert err[0].startswith("nylonflex fe: error: ") and __import__("re").search(match, err[0])


def test_fe_bend_blocked_returns_the_moment_and_eq_16s_force():
    """``fe_bend(blocked=True)``: the moment on the held tip, F = M/L (eq. 16), its
    Richardson estimate against the coarser mesh; the free call is as before."""
    from nylonflex.fe import fe_bend

    out = fe_bend(7.5e-3, 2e-3, 70e-3, [1e3], mesh="coarse", blocked=True)
    assert out["tip_force"][0] == pytest.approx(out["tip_moment"][0] / 70e-3, rel=1e-14)
    eq16 = (4 * 7.5e-3 ** 3 + 3 * math.pi * 7.5e-3 ** 2 * 2e-3) / 6 * 1e3
    assert 1.5 < out["tip_moment"][0] / eq16 < 2.5  # measured 1.99 (coarse)
    assert out["coarser_tip_moment"][0] > 0 and 0 < out["discretisation_error"][0] < 0.1
