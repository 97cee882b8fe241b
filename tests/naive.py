"""Slow, obviously right references for the fast code (as numbagg's and stumpy's naive.py).

Each function is a deliberately simple and slow version of one formula of docs/model.md,
written from its equations and not from nylonflex's code: adaptive scipy quadrature of the
integrals exactly as written (no change of variables), bracketing root finders for every
inverse and steady state, a plain loop for a table. Nothing here calls nylonflex: the
material constants come in as arguments (a muscle set as any object with the fields of
``materials.Nylon``), so the tests pass each set's values in and compare. The one import of
the package is the registry's accepted ranges, in :func:`random_designs`.

- mechanics (sections 3-6, 8): :func:`stress`, :func:`material_moment`,
  :func:`pressure_moment`, :func:`curvature`, :func:`gauge_pressure`, :func:`nylon_force`,
  :func:`stroke_limit`;
- the muscle (sections 2, 9): :func:`table_value`, :func:`force_limit`, :func:`free_strain`,
  :func:`stroke`, :func:`temperature_for_stroke`;
- the wrap (section 4): :func:`outer_perimeter`, :func:`muscle_width`, :func:`wrap_pitch`,
  :func:`wrap_turns`, :func:`muscle_length`;
- resistance (section 9): :func:`thread_per_muscle_length`, :func:`resistance_per_length`;
- heating (eq. 3; sections 2, 15, 20): :func:`temperature_rate`,
  :func:`steady_temperature`, :func:`time_between`, :func:`temperature_after`,
  :func:`time_constant`, :func:`heating_voltage`, :func:`heating_energy`, and every
  thermal value of one design, :func:`design_thermal`.

The benchmarks time :func:`stroke_limit` and :func:`curvature` (benchmarks/suite.py).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import dblquad, quad
from scipy.optimize import brentq

P_ATM = 101325.0
ZERO_CELSIUS = 273.15
EPSREL = 1e-12
#: Fractions of the working stroke that count as heated and as cooled (docs/model.md s. 15).
HEATED, COOLED = 0.95, 0.05
_RTOL = 4 * np.finfo(float).eps


def _root(f, lo, hi):
    return brentq(f, lo, hi, xtol=1e-300, rtol=_RTOL, maxiter=500)


# ----------------------------------------------------------------------------- mechanics
def stress(lam, mu, alpha):
    """Plane-strain nominal Ogden stress S = sum mu (l^(a-1) - l^(-a-1)) [Pa]."""
    return sum(m * (lam ** (a - 1.0) - lam ** (-a - 1.0)) for m, a in zip(mu, alpha))


def material_moment(kappa, a, t, b, mu, alpha):
    """M_S(kappa) by scipy quad (base) and dblquad (wall) at epsrel 1e-12 [N m]."""
    base, _ = quad(lambda y: stress(1 + kappa * y, mu, alpha) * y, 0.0, b,
                   epsabs=0.0, epsrel=EPSREL, limit=200)

    def wall(r, phi):
        y = b + r * math.sin(phi)
        return stress(1 + kappa * y, mu, alpha) * y * r

    ann, _ = dblquad(wall, 0.0, math.pi, a, a + t, epsabs=0.0, epsrel=EPSREL)
    return 2 * (a + t) * base + ann


def pressure_moment(p, a, b):
    """M_P = p (4a^3 + 3 pi a^2 b)/6 [N m]."""
    return p * (4 * a**3 + 3 * math.pi * a**2 * b) / 6


def curvature(p, a, t, b, mu, alpha, near=None):
    """kappa solving M_S = M_P by brentq on the adaptive moment [1/m].

    ``near`` narrows the bracket to +-1e-6 relative around a candidate; the sign change that
    brentq demands is still checked on the adaptive moment, so a wrong candidate fails.
    """
    target = pressure_moment(p, a, b)
    if target == 0.0:
        return 0.0
    f = lambda k: material_moment(k, a, t, b, mu, alpha) - target  # noqa: E731
    if near is not None:
        lo, hi = near * (1 - 1e-6), near * (1 + 1e-6)
    else:
        lo, hi = 0.0, 1.0
        while f(hi) < 0:
            lo, hi = hi, 2 * hi
    return _root(f, lo, hi)


def gauge_pressure(s):
    """Boyle's gauge pressure of the chamber shrunk by (1 - s) both ways (eqs. 7-8) [Pa]."""
    return P_ATM * ((1 - s) ** -2 - 1)


def nylon_force(s, a, t, b, psi, c, mu, alpha, fibre_diameter):
    """F_n(s) of docs/model.md section 4, written out [N]."""
    p = gauge_pressure(s)
    s_theta = stress(1 - s, mu, alpha)
    p_out = math.pi * (a + t) + 2 * (a + t) + 2 * b
    pitch = max(p_out * math.tan(psi), fibre_diameter * (c + 1) / math.cos(psi))
    return (p * a + abs(s_theta) * t) * pitch / math.cos(psi)


def stroke_limit(force_limit, s_max, a, t, b, psi, c, mu, alpha, fibre_diameter):
    """s* = min(s_max, s_lim) by brentq [-]."""
    f = lambda s: nylon_force(s, a, t, b, psi, c, mu, alpha, fibre_diameter) - force_limit  # noqa
    if f(s_max) <= 0:
        return s_max
    return _root(f, 0.0, s_max)


# ------------------------------------------------------------------------------ the muscle
def table_value(c, xs, ys):
    """The coil-index table's column ``ys`` at C by linear interpolation between rows."""
    rows = list(zip(xs, ys))
    for (x0, y0), (x1, y1) in zip(rows, rows[1:]):
        if x0 <= c <= x1:
            return y0 + (y1 - y0) * (c - x0) / (x1 - x0)
    raise ValueError(f"coil index {c} outside the table {xs}")


def force_limit(c, xs, strengths, fibre_diameter):
    """Breaking force sigma_u(C) pi d_f^2 / 4 [N]."""
    return table_value(c, xs, strengths) * math.pi * fibre_diameter**2 / 4


def free_strain(temp, ny):
    """eps(T) = alpha - gamma T - beta erf((T - T_g)/(sigma_g sqrt 2)) of eq. (2), T in
    degC for alpha and gamma, with the set's reference constants (unscaled) [-]."""
    return (ny.alpha - ny.gamma * (temp - ZERO_CELSIUS)
            - ny.beta * math.erf((temp - ny.t_g) / (ny.sigma_g * math.sqrt(2.0))))


def stroke(temp, c, ny):
    """s(T) = k(C) (eps(T_amb) - eps(T)), k(C) = s_max(C) / s_ref(T_max) (section 2) [-]."""
    reference_top = free_strain(ny.t_amb, ny) - free_strain(ny.t_max, ny)
    k = table_value(c, ny.coil_index_table, ny.stroke_max_table) / reference_top
    return k * (free_strain(ny.t_amb, ny) - free_strain(temp, ny))


def temperature_for_stroke(s, c, ny):
    """The T in [T_amb, T_max] with s(T) = s, by brentq; T_max at or beyond s(T_max) [K]."""
    if s <= 0.0:
        return ny.t_amb
    f = lambda temp: stroke(temp, c, ny) - s  # noqa: E731
    if f(ny.t_max) <= 0.0:
        return ny.t_max
    return _root(f, ny.t_amb, ny.t_max)


# -------------------------------------------------------------------------------- the wrap
def outer_perimeter(a, t, b):
    """P_out: the half circle of radius a + t, its two flanks a + t and the base 2b [m]."""
    r = a + t
    return math.pi * r + 2 * r + 2 * b


def muscle_width(c, fibre_diameter):
    """Outer width of the coiled muscle w = d_f (C + 1) [m]."""
    return fibre_diameter * (c + 1)


def wrap_pitch(a, t, b, psi, c, fibre_diameter):
    """h = max(P_out tan psi, w / cos psi): the helix, or touching turns [m]."""
    return max(outer_perimeter(a, t, b) * math.tan(psi),
               muscle_width(c, fibre_diameter) / math.cos(psi))


def wrap_turns(a, t, b, length, psi, c, fibre_diameter):
    """n = L / h [-]."""
    return length / wrap_pitch(a, t, b, psi, c, fibre_diameter)


def muscle_length(a, t, b, length, psi, c, fibre_diameter):
    """l_m = n P_out / cos psi: n turns of the outer contour along the helix [m]."""
    return (wrap_turns(a, t, b, length, psi, c, fibre_diameter) * outer_perimeter(a, t, b)
            / math.cos(psi))


# ------------------------------------------------------------------------------ resistance
def thread_per_muscle_length(c):
    """Thread in a close-wound coil per length of muscle [-]: the arc length of one turn of
    the helix (r cos u, r sin u, h u / 2 pi) of mean diameter 2r = C d_f and pitch h = d_f
    (touching turns), the quadrature of its speed over u in [0, 2 pi], over the pitch (in
    units of d_f, which cancels)."""
    r, h = c / 2, 1.0
    speed = lambda u: math.sqrt((-r * math.sin(u)) ** 2 + (r * math.cos(u)) ** 2  # noqa: E731
                                + (h / (2 * math.pi)) ** 2)
    turn, _ = quad(speed, 0.0, 2 * math.pi, epsabs=0.0, epsrel=1e-13)
    return turn / h


def resistance_per_length(c, ny):
    """r'(C): the set's r' at its C_r scaled by the thread per muscle length (section 9);
    the set's r' at every C when C_r <= 0 [ohm/m]."""
    if ny.resistance_coil_index <= 0.0:
        return ny.resistance_per_length
    return (ny.resistance_per_length * thread_per_muscle_length(c)
            / thread_per_muscle_length(ny.resistance_coil_index))


# --------------------------------------------------------------------------------- heating
def temperature_rate(temp, voltage, l_m, r_per_len, c_per_len, loss_per_len, t_amb):
    """dT/dt of eq. (3): C_th dT/dt = V^2/R - Lambda (T - T_amb), with R = r' l_m,
    C_th = c' l_m, Lambda = lambda' l_m [K/s]."""
    heat = voltage**2 / (r_per_len * l_m)
    return (heat - loss_per_len * l_m * (temp - t_amb)) / (c_per_len * l_m)


def steady_temperature(voltage, l_m, r_per_len, loss_per_len, t_amb):
    """The T where eq. (3) stands still (dT/dt = 0), by brentq [K]."""
    f = lambda temp: voltage**2 / (r_per_len * l_m) - loss_per_len * l_m * (temp - t_amb)  # noqa
    if voltage == 0.0:
        return t_amb
    hi = 1.0
    while f(t_amb + hi) > 0:
        hi *= 2
    return _root(f, t_amb, t_amb + hi)


def time_between(t_from, t_to, voltage, l_m, r_per_len, c_per_len, loss_per_len, t_amb):
    """Time eq. (3) takes at constant V from t_from to t_to [s]: the quadrature of
    dt = dT / (dT/dt) between them (the temperature moves one way, so t(T) is one-to-one)."""
    value, _ = quad(lambda temp: 1.0 / temperature_rate(temp, voltage, l_m, r_per_len,
                                                        c_per_len, loss_per_len, t_amb),
                    t_from, t_to, epsabs=0.0, epsrel=1e-13, limit=200)
    return value


def temperature_after(t_from, voltage, dt, l_m, r_per_len, c_per_len, loss_per_len, t_amb):
    """T after dt at constant V from t_from, by brentq on :func:`time_between` [K]; the
    bracket halves the distance left to the steady state until it takes longer than dt."""
    if dt == 0.0:
        return t_from
    args = (voltage, l_m, r_per_len, c_per_len, loss_per_len, t_amb)
    t_ss = steady_temperature(voltage, l_m, r_per_len, loss_per_len, t_amb)
    f = lambda temp: time_between(t_from, temp, *args) - dt  # noqa: E731
    inner, outer = t_from, t_ss + 0.5 * (t_from - t_ss)
    while f(outer) < 0.0:
        inner, outer = outer, t_ss + 0.5 * (outer - t_ss)
    return _root(f, min(inner, outer), max(inner, outer))


def time_constant(c_per_len, loss_per_len):
    """tau: the time eq. (3) without a supply takes to cool by a factor e in T - T_amb
    (any l_m, any T_amb: here 1 m and 0 K) [s]."""
    return time_between(1.0, math.exp(-1.0), 0.0, 1.0, 1.0, c_per_len, loss_per_len, 0.0)


def heating_voltage(temp, l_m, r_per_len, loss_per_len, t_amb):
    """The steady supply V whose :func:`steady_temperature` is ``temp``, by brentq [V]."""
    if temp <= t_amb:
        return 0.0
    f = lambda v: steady_temperature(v, l_m, r_per_len, loss_per_len, t_amb) - temp  # noqa
    hi = 1.0
    while f(hi) < 0:
        hi *= 2
    return _root(f, 0.0, hi)


def heating_energy(t_to, voltage, l_m, r_per_len, c_per_len, loss_per_len, t_amb):
    """Energy the supply puts in while heating from T_amb to t_to [J], by the balance of
    eq. (3): what is stored, C_th (T - T_amb), and what is lost on the way,
    Lambda int (T - T_amb) dt, the latter a quadrature over T with dt = dT / (dT/dt)."""
    args = (voltage, l_m, r_per_len, c_per_len, loss_per_len, t_amb)
    lost, _ = quad(lambda temp: loss_per_len * l_m * (temp - t_amb)
                   / temperature_rate(temp, *args), t_amb, t_to, epsabs=0.0, epsrel=1e-13,
                   limit=200)
    return c_per_len * l_m * (t_to - t_amb) + lost


def design_thermal(a, t, b, length, c, psi, mu, alpha, ny, voltage=None):
    """The usable stroke, limit and the wrap's and eq. (3)'s values of one design (the
    paper's model; the set's own lambda'), as docs/model.md sections 4, 8, 15 and 20 define
    them; ``voltage`` None: no supply, and the supply's values are NaN. SI."""
    d_f = ny.fibre_diameter
    r_per, c_per, loss_per, t_amb = (resistance_per_length(c, ny), ny.heat_capacity_per_length,
                                     ny.heat_loss_per_length, ny.t_amb)
    l_m = muscle_length(a, t, b, length, psi, c, d_f)
    f_lim = force_limit(c, ny.coil_index_table, ny.tensile_strength_table, d_f)
    s_free = table_value(c, ny.coil_index_table, ny.stroke_max_table)
    supply_limited = False
    if voltage is not None:  # the supply caps the temperature at T_ss
        t_ss = steady_temperature(voltage, l_m, r_per, loss_per, t_amb)
        if t_ss < ny.t_max:
            s_free, supply_limited = stroke(t_ss, c, ny), True
    s_star = stroke_limit(f_lim, s_free, a, t, b, psi, c, mu, alpha, d_f)
    strength = nylon_force(s_free, a, t, b, psi, c, mu, alpha, d_f) > f_lim
    t_work = temperature_for_stroke(s_star, c, ny)
    s_work = stroke(t_work, c, ny)
    t_cool = temperature_for_stroke(COOLED * s_work, c, ny)
    t_hot = temperature_for_stroke(HEATED * s_work, c, ny)
    heat = (l_m, r_per, c_per, loss_per, t_amb)
    p_star = gauge_pressure(s_star)
    out = {
        "usable_stroke": s_star,
        "limit": 1 if strength else 2 if supply_limited else 0,
        "pressure_max": p_star,
        "torque_max": pressure_moment(p_star, a, b),
        "tip_force_max": pressure_moment(p_star, a, b) / length,
        "nylon_force_max": nylon_force(s_star, a, t, b, psi, c, mu, alpha, d_f),
        "muscle_length": l_m,
        "resistance": r_per * l_m,
        "heating_power": loss_per * l_m * (t_work - t_amb),  # what eq. (3) loses at T*
        "heating_voltage": heating_voltage(t_work, l_m, r_per, loss_per, t_amb),
        "cooling_time": time_between(t_work, t_cool, 0.0, *heat),
    }
    out["nylon_use"] = out["nylon_force_max"] / f_lim
    nan = dict.fromkeys(("heating_time", "cycle_time", "cycle_rate", "heating_energy",
                         "mechanical_work", "efficiency"), math.nan)
    if voltage is None:
        return {**out, **nan}
    work, _ = quad(lambda s: nylon_force(s, a, t, b, psi, c, mu, alpha, d_f), 0.0, s_star,
                   epsabs=0.0, epsrel=1e-13)
    out["heating_time"] = time_between(t_amb, t_hot, voltage, *heat)
    out["cycle_time"] = out["heating_time"] + time_between(t_hot, t_cool, 0.0, *heat)
    out["cycle_rate"] = 1.0 / out["cycle_time"]
    out["heating_energy"] = heating_energy(t_hot, voltage, *heat)
    out["mechanical_work"] = l_m * work
    out["efficiency"] = out["mechanical_work"] / out["heating_energy"]
    return out


# ------------------------------------------------------------------------- where to compare
def random_designs(n: int, seed: int = 2026) -> dict:
    """``n`` designs drawn over the whole accepted range of each axis (log-uniform lengths).

    Radius, wall and length log-uniform over the registry's ranges, coil index uniform over
    the default table, wrap angle uniform over its range; SI.
    """
    from nylonflex.variables import COORDS

    rng = np.random.default_rng(seed)
    log_uniform = lambda v: np.exp(rng.uniform(np.log(v.lo), np.log(v.hi), n))  # noqa: E731
    return {"radius": log_uniform(COORDS["radius"]),
            "wall_thickness": log_uniform(COORDS["wall_thickness"]),
            "length": log_uniform(COORDS["length"]),
            "coil_index": rng.uniform(1.1, 1.7, n),
            "wrap_angle": rng.uniform(COORDS["wrap_angle"].lo, COORDS["wrap_angle"].hi, n)}
