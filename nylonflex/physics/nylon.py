"""The coiled nylon muscle: stroke against temperature, coil-index table, eq. (1).

docs/model.md section 2. Temperatures are in K.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import nylon_parameters
from ._formula import ZERO_CELSIUS, check, formula, scalar_or_array

__all__ = [
    "check_stroke_shape",
    "free_strain",
    "nylon_force_limit",
    "stroke",
    "stroke_max",
    "stroke_scale",
    "temperature_for_stroke",
    "tensile_strength",
    "thermomechanical_force",
]

_SQRT2 = math.sqrt(2.0)


@formula
def _stroke_shape(temperature, t_amb, gamma, beta, t_g, sigma_g):
    """Reference stroke eps_ref(T_amb) - eps_ref(T) of the eq. (2) shape [-]; T in K."""
    c = 1.0 / (sigma_g * _SQRT2)
    return _stroke_shape_at(temperature, t_amb, gamma, beta, t_g, c,
                            math.erf((t_amb - t_g) * c))


@formula
def _stroke_shape_at(temperature, t_amb, gamma, beta, t_g, c, erf_amb):
    """:func:`_stroke_shape` with c = 1/(sigma_g sqrt 2) [1/K] and erf((T_amb - T_g) c)
    [-] given: a solver over T computes those once (the same operations, the same bits)."""
    return gamma * (temperature - t_amb) + beta * (math.erf((temperature - t_g) * c) - erf_amb)


@formula
def stroke_scale(coil_index, c_table, smax_table, t_amb, t_max, gamma, beta, t_g, sigma_g):
    """Factor s_max(C) / s_ref(T_max) that scales alpha, beta, gamma to coil index C [-]."""
    return np.interp(coil_index, c_table, smax_table) / _stroke_shape(
        t_max, t_amb, gamma, beta, t_g, sigma_g
    )


@formula
def _stroke_shape_slope(temperature, t_amb, gamma, beta, t_g, sigma_g):
    """d/dT of :func:`_stroke_shape` [1/K]; positive for gamma, beta > 0."""
    c = 1.0 / (sigma_g * _SQRT2)
    x = (temperature - t_g) * c
    return gamma + beta * 2.0 / math.sqrt(math.pi) * c * math.exp(-x * x)


@formula
def _free_stroke(temperature, scale, t_amb, gamma, beta, t_g, sigma_g):
    """Free stroke s(T) = k (eps_ref(T_amb) - eps_ref(T)) of eq. (2) at coil scale k [-]."""
    return scale * _stroke_shape(temperature, t_amb, gamma, beta, t_g, sigma_g)


#: Relative Newton step below which the inverse of eq. (2) counts as converged [-].
TEMPERATURE_RTOL = 1e-13


@formula
def _temperature_for_stroke(stroke_value, scale, t_amb, t_max, gamma, beta, t_g, sigma_g):
    """Temperature T in [T_amb, T_max] whose free stroke (eq. 2) is ``stroke_value`` [K].

    Safeguarded Newton (a step that leaves the bracket is replaced by bisection), so it
    compiles with Numba; the stroke is increasing in T. Strokes at or beyond s(T_max)
    return T_max, strokes <= 0 return T_amb.
    """
    if stroke_value <= 0.0:
        return t_amb
    target = stroke_value / scale
    c = 1.0 / (sigma_g * _SQRT2)
    erf_amb = math.erf((t_amb - t_g) * c)  # once a solve, not once an iteration
    top = _stroke_shape_at(t_max, t_amb, gamma, beta, t_g, c, erf_amb)
    if target >= top:
        return t_max
    lo = t_amb
    hi = t_max
    temp = t_amb + (t_max - t_amb) * target / top
    for _ in range(200):
        f = _stroke_shape_at(temp, t_amb, gamma, beta, t_g, c, erf_amb) - target
        if f == 0.0:
            return temp
        if f > 0.0:
            hi = temp
        else:
            lo = temp
        step = f / _stroke_shape_slope(temp, t_amb, gamma, beta, t_g, sigma_g)
        new = temp - step
        # converged first: a step below half an ulp leaves temp where it is, on the
        # bracket's edge, which the bracket test would take for a step out of it and
        # bisect away from the root (16 iterations on average instead of 4)
        if abs(step) <= TEMPERATURE_RTOL * temp:
            return new
        if not (lo < new < hi):
            new = 0.5 * (lo + hi)
        if hi - lo <= TEMPERATURE_RTOL * temp:
            return new
        temp = new
    return temp


def _nylon(nylon):
    return nylon_parameters(nylon)


def check_stroke_shape(t_max, t_amb, gamma, beta, t_g, sigma_g):
    """Refuse a muscle whose eq. (2) stroke shape does not rise from T_amb to T_max.

    The shape at T_max, gamma (T_max - T_amb) + beta (erf((T_max - T_g) c) - erf((T_amb -
    T_g) c)), scales s_max(C) to the stroke curve (docs/model.md s. 9): at 0 (``gamma =
    beta = 0``, each in range) the curve is zero everywhere while the usable stroke still
    came from the coil table, and every thermal value was NaN. Arguments [K], [1/K], [-]
    (arrays broadcast).

    Raises
    ------
    ValueError
        One line naming nylon.gamma and nylon.beta and the shape's value.
    """
    args = np.broadcast_arrays(*(np.asarray(x, float) for x in
                                 (t_max, t_amb, gamma, beta, t_g, sigma_g)))
    top = np.vectorize(_stroke_shape, otypes=[float])(*args)
    # relative to the size of its two terms: a cancellation to rounding is 0 too
    size = np.abs(args[2]) * np.abs(args[0] - args[1]) + 2.0 * np.abs(args[3])
    bad = ~(top > 1e-9 * size)
    if np.any(bad):
        j = np.flatnonzero(bad.reshape(-1))[0]
        g, b, v = (x.reshape(-1)[j] for x in (args[2], args[3], top))
        raise ValueError(f"nylon.gamma, nylon.beta: the stroke shape of eq. (2) is {v:g} at "
                         f"t_max (gamma {g:g} 1/K, beta {b:g}); it must be > 0, a muscle "
                         "that contracts when heated")


def _coil_index(coil_index, ny):
    lo, hi = ny.coil_index_range
    return check("coil_index", coil_index, lo, hi, unit="-")


def _shape_args(ny):
    return ny.t_amb, ny.gamma, ny.beta, ny.t_g, ny.sigma_g


def _scale(coil_index, ny):
    c = _coil_index(coil_index, ny)
    return stroke_scale(c, np.asarray(ny.coil_index_table), np.asarray(ny.stroke_max_table),
                         ny.t_amb, ny.t_max, ny.gamma, ny.beta, ny.t_g, ny.sigma_g)


def stroke_max(coil_index, nylon="silver_nylon66"):
    """Largest stroke s_max(C) of a muscle of coil index C, reached at T_max [-].

    Linear interpolation in the coil-index table (docs/model.md section 9).

    Parameters
    ----------
    coil_index : float or array
        Spring index C = D/d [-], inside the table (1.1-1.7 for the default set).
    nylon : str, dict or Nylon
        Muscle set.

    Raises
    ------
    ValueError
        A coil index outside the table.
    """
    ny = _nylon(nylon)
    c = _coil_index(coil_index, ny)
    return scalar_or_array(np.interp(c, ny.coil_index_table, ny.stroke_max_table))


def tensile_strength(coil_index, nylon="silver_nylon66"):
    """Tensile strength sigma_u(C) on the fibre cross-section [Pa] (table, linear in C)."""
    ny = _nylon(nylon)
    c = _coil_index(coil_index, ny)
    return scalar_or_array(np.interp(c, ny.coil_index_table, ny.tensile_strength_table))


def nylon_force_limit(coil_index, nylon="silver_nylon66"):
    """Breaking force F_lim(C) = sigma_u(C) pi d_f^2 / 4 of the muscle [N]."""
    ny = _nylon(nylon)
    return scalar_or_array(np.asarray(tensile_strength(coil_index, ny)) * ny.fibre_area)


def free_strain(temperature, coil_index, nylon="silver_nylon66"):
    """Free tensile strain eps(T) of eq. (2) for coil index C [-].

    eps(T) = alpha - gamma T - beta erf((T - T_g) / (sigma_g sqrt 2)), with alpha, beta,
    gamma the reference constants times s_max(C)/s_ref(T_max) and T in degC for alpha.

    Parameters
    ----------
    temperature : float or array
        Muscle temperature T [K], > 0.
    coil_index : float or array
        Coil index C [-], inside the table.
    nylon : str, dict or Nylon
        Muscle set.

    References
    ----------
    Paper eq. (2) (Sharafi & Li 2015); docs/model.md section 2.
    """
    ny = _nylon(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    k = _scale(coil_index, ny)
    erf = np.vectorize(math.erf, otypes=[float])
    eps = ny.alpha - ny.gamma * (t - ZERO_CELSIUS) - ny.beta * erf(
        (t - ny.t_g) / (ny.sigma_g * _SQRT2)
    )
    return scalar_or_array(k * eps)


def stroke(temperature, coil_index, nylon="silver_nylon66"):
    """Muscle contraction s(T) = eps(T_amb) - eps(T) [-]; zero at T_amb, s_max(C) at T_max.

    Parameters
    ----------
    temperature : float or array
        Muscle temperature T [K], > 0.
    coil_index : float or array
        Coil index C [-], inside the table.
    nylon : str, dict or Nylon
        Muscle set.

    Notes
    -----
    docs/model.md section 2 [choice]: one eq. (2) shape scaled per coil index. The scale is
    s_max(C) over the reference shape's own stroke at T_max (0.1000054 for the default set,
    not the nominal 0.10), so s(T_max) = s_max(C) exactly.
    """
    ny = _nylon(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    k = _scale(coil_index, ny)
    shape = np.vectorize(lambda x: _stroke_shape(x, *_shape_args(ny)), otypes=[float])(t)
    return scalar_or_array(k * shape)


def temperature_for_stroke(stroke_value, coil_index, nylon="silver_nylon66"):
    """Temperature [K] at which the muscle reaches a stroke, the inverse of :func:`stroke`.

    Parameters
    ----------
    stroke_value : float
        Contraction s [-], 0 <= s <= s_max(C) (the range between T_amb and T_max).
    coil_index : float
        Coil index C [-].
    nylon : str, dict or Nylon
        Muscle set.
    """
    ny = _nylon(nylon)
    smax = float(stroke_max(coil_index, ny))
    s = float(check("stroke", stroke_value, 0.0, smax, unit="-"))
    if s == 0.0:
        return ny.t_amb
    k = float(_scale(coil_index, ny))
    f = lambda t: k * _stroke_shape(t, *_shape_args(ny)) - s  # noqa: E731
    from scipy.optimize import brentq  # imported here: scipy costs 0.4 s of start-up

    return brentq(f, ny.t_amb, ny.t_max, xtol=1e-12, rtol=1e-15)


def thermomechanical_force(displacement, velocity, temperature, rest_displacement=0.0,
                           rest_temperature=None, nylon="silver_nylon66"):
    """Force of the muscle, eq. (1): F = k (x - x0) + b_d dx/dt + c (T - T0) [N].

    Parameters
    ----------
    displacement : float or array
        End displacement x [m].
    velocity : float or array
        End velocity dx/dt [m/s].
    temperature : float or array
        Muscle temperature T [K], > 0.
    rest_displacement : float, default 0
        x0 [m].
    rest_temperature : float, optional
        T0 [K]; the set's ambient temperature by default.
    nylon : str, dict or Nylon
        Muscle set (``stiffness`` k [N/m], ``damping`` b_d [N s/m],
        ``thermal_force_coefficient`` c [N/K]).

    References
    ----------
    Paper eq. (1), after Yip & Niemeyer 2015 and Kianzad et al. 2015; not used by the sweep.
    """
    ny = _nylon(nylon)
    x = check("displacement", displacement, unit="m")
    v = check("velocity", velocity, unit="m/s")
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    t0 = ny.t_amb if rest_temperature is None else float(
        check("rest_temperature", rest_temperature, 0.0, lo_open=True, unit="K"))
    f = ny.stiffness * (x - rest_displacement) + ny.damping * v + \
        ny.thermal_force_coefficient * (t - t0)
    return scalar_or_array(f)
