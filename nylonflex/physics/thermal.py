"""Thermo-electric model of the muscle, eq. (3): C dT/dt = V^2/R - Lambda (T - T_amb).

docs/model.md sections 2 and 10: R = r' l_m, C = c' l_m, Lambda = lambda' l_m for a muscle of
length l_m, so the time constant tau = c'/lambda' does not depend on the length.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..materials import Nylon, cooling_parameters, nylon_parameters
from ._formula import check, formula, scalar_or_array

__all__ = [
    "AIR_PROPERTIES",
    "WATER_PROPERTIES",
    "coil_heat_loss_per_length",
    "coil_resistance",
    "coil_resistance_per_length",
    "convection_loss_per_length",
    "cooled_nylon",
    "MIN_SUPPLY_RISE",
    "check_supply_rise",
    "coiled_resistance_per_length",
    "free_convection_loss_per_length",
    "muscle_resistance",
    "steady_temperature",
    "temperature_rate",
    "temperature_step",
    "thermal_time_constant",
]


#: Dry air at 1 atm: temperature [K], conductivity k [W/(m K)], kinematic viscosity nu [m^2/s],
#: thermal diffusivity a [m^2/s], Prandtl number [-]. Incropera, DeWitt, Bergman & Lavine,
#: Fundamentals of Heat and Mass Transfer, 6th ed., Table A.4; linear in between.
AIR_PROPERTIES = {
    "t": (300.0, 350.0, 400.0, 450.0),
    "k": (26.3e-3, 30.0e-3, 33.8e-3, 37.3e-3),
    "nu": (15.89e-6, 20.92e-6, 26.41e-6, 32.39e-6),
    "a": (22.5e-6, 29.9e-6, 38.3e-6, 47.2e-6),
    "pr": (0.707, 0.700, 0.690, 0.686),
}
#: Saturated liquid water: temperature [K], k [W/(m K)], nu = mu/rho [m^2/s], a = nu/Pr
#: [m^2/s], Pr [-], volumetric expansion beta [1/K]. Incropera et al., 6th ed., Table A.6
#: (300, 325, 350 K and the boiling point at 1 atm); linear in between.
WATER_PROPERTIES = {
    "t": (300.0, 325.0, 350.0, 373.15),
    "k": (0.613, 0.645, 0.668, 0.680),
    "nu": (855e-6 * 1.003e-3, 528e-6 * 1.013e-3, 365e-6 * 1.027e-3, 279e-6 * 1.044e-3),
    "a": (855e-6 * 1.003e-3 / 5.83, 528e-6 * 1.013e-3 / 3.42, 365e-6 * 1.027e-3 / 2.29,
          279e-6 * 1.044e-3 / 1.76),
    "pr": (5.83, 3.42, 2.29, 1.76),
    "beta": (276.1e-6, 436.7e-6, 624.2e-6, 750.1e-6),
}
_FLUIDS = {"air": AIR_PROPERTIES, "water": WATER_PROPERTIES}
_G = 9.80665  # [m/s^2]
_SIGMA = 5.670374419e-8  # Stefan-Boltzmann [W/(m^2 K^4)]


def free_convection_loss_per_length(diameter, t_surface, t_amb, emissivity=0.0):
    """Heat loss per length of a horizontal cylinder in still air, lambda' [W/(K m)].

    Free convection by the Churchill-Chu correlation for a horizontal cylinder (S. W.
    Churchill and H. H. S. Chu, Int. J. Heat Mass Transfer 18:1049-1053, 1975; valid for
    Ra_D <= 1e12, down to the conduction limit Nu_D -> 0.36)::

        Nu_D = {0.60 + 0.387 Ra_D^(1/6) / [1 + (0.559/Pr)^(9/16)]^(8/27)}^2
        Ra_D = g beta (T_s - T_amb) D^3 / (nu a),  beta = 1/T_f

    with the air's properties (:data:`AIR_PROPERTIES`) at the film temperature T_f =
    (T_s + T_amb)/2; lambda' = h pi D = pi k Nu_D. Radiation to surroundings at T_amb adds
    emissivity sigma (T_s^2 + T_amb^2)(T_s + T_amb) pi D (0 by default: docs/model.md s. 9).

    Parameters
    ----------
    diameter : float
        Outer diameter of the cylinder D [m], > 0 (a coiled muscle: d_f (C + 1)).
    t_surface, t_amb : float
        Surface and ambient temperature [K], T_s > T_amb, T_f within 300-450 K.
    emissivity : float
        Surface emissivity [-], 0-1.

    Returns
    -------
    float
        lambda' [W/(K m)].
    """
    d = float(diameter)
    ts, ta = float(t_surface), float(t_amb)
    if not d > 0:
        raise ValueError(f"diameter: must be > 0 m, got {d:g}")
    if not ts > ta > 0:
        raise ValueError(f"t_surface: must be above t_amb > 0 K, got {ts:g} and {ta:g}")
    if not 0.0 <= emissivity <= 1.0:
        raise ValueError(f"emissivity: must be in [0, 1], got {emissivity:g}")
    tf = 0.5 * (ts + ta)
    t = AIR_PROPERTIES["t"]
    if not t[0] <= tf <= t[-1]:
        raise ValueError(f"film temperature (t_surface + t_amb)/2: must be in [{t[0]:g}, "
                         f"{t[-1]:g}] K (the air table), got {tf:g}")
    k, nu, a, pr = (float(np.interp(tf, t, AIR_PROPERTIES[q])) for q in ("k", "nu", "a", "pr"))
    ra = _G * (ts - ta) / tf * d**3 / (nu * a)
    nu_d = (0.60 + 0.387 * ra ** (1 / 6) / (1 + (0.559 / pr) ** (9 / 16)) ** (8 / 27)) ** 2
    radiation = emissivity * _SIGMA * (ts * ts + ta * ta) * (ts + ta) * np.pi * d
    return float(np.pi * k * nu_d + radiation)


def convection_loss_per_length(diameter, t_surface, t_amb, fluid="air", speed=0.0):
    """Heat loss per length of a horizontal cylinder in a fluid, lambda' [W/(K m)].

    ``speed`` 0: free convection, Churchill and Chu (Int. J. Heat Mass Transfer
    18:1049-1053, 1975), as :func:`free_convection_loss_per_length`, with the fluid's
    expansion coefficient (1/T_f for air, Table A.6 for water). ``speed`` > 0: cross flow,
    Churchill and Bernstein (J. Heat Transfer 99:300-306, 1977; Re_D Pr >= 0.2)::

        Nu_D = 0.3 + 0.62 Re^(1/2) Pr^(1/3) / [1 + (0.4/Pr)^(2/3)]^(1/4)
                   [1 + (Re/282000)^(5/8)]^(4/5),   Re = U D / nu

    free convection left out (Gr/Re^2 is about 1e-3 for the muscle at 2 m/s). Properties at
    the film temperature (T_s + T_amb)/2; lambda' = pi k Nu_D.

    Parameters
    ----------
    diameter : float
        Outer diameter D [m], > 0.
    t_surface, t_amb : float
        Surface and ambient temperature [K], T_s > T_amb; the film temperature inside the
        fluid's table (air 300-450 K, water 300-373.15 K).
    fluid : str
        ``"air"`` or ``"water"``.
    speed : float
        Speed of the fluid across the cylinder [m/s], >= 0.

    Returns
    -------
    float
        lambda' [W/(K m)].
    """
    if fluid not in _FLUIDS:
        raise ValueError(f"fluid: must be one of {', '.join(_FLUIDS)}, got {fluid!r}")
    d, ts, ta, u = float(diameter), float(t_surface), float(t_amb), float(speed)
    if not d > 0:
        raise ValueError(f"diameter: must be > 0 m, got {d:g}")
    if not ts > ta > 0:
        raise ValueError(f"t_surface: must be above t_amb > 0 K, got {ts:g} and {ta:g}")
    if not u >= 0:
        raise ValueError(f"speed: must be >= 0 m/s, got {u:g}")
    table = _FLUIDS[fluid]
    tf = 0.5 * (ts + ta)
    t = table["t"]
    if not t[0] <= tf <= t[-1]:
        raise ValueError(f"film temperature (t_surface + t_amb)/2: must be in [{t[0]:g}, "
                         f"{t[-1]:g}] K (the {fluid} table), got {tf:g}")
    k, nu, a, pr = (float(np.interp(tf, t, table[q])) for q in ("k", "nu", "a", "pr"))
    if u > 0.0:
        re = u * d / nu
        nu_d = 0.3 + (0.62 * re**0.5 * pr ** (1 / 3) / (1 + (0.4 / pr) ** (2 / 3)) ** 0.25
                      * (1 + (re / 282000.0) ** (5 / 8)) ** 0.8)
    else:
        beta = 1.0 / tf if "beta" not in table else float(np.interp(tf, t, table["beta"]))
        ra = _G * beta * (ts - ta) * d**3 / (nu * a)
        nu_d = (0.60 + 0.387 * ra ** (1 / 6) / (1 + (0.559 / pr) ** (9 / 16)) ** (8 / 27)) ** 2
    return float(np.pi * k * nu_d)


def coil_heat_loss_per_length(coil_index, nylon="silver_nylon66", cooling=None):
    """Heat loss per muscle length lambda'(C) [W/(K m)] at each coil index.

    ``cooling`` None: the nylon set's own ``heat_loss_per_length`` at every C (the
    default set's is back-calculated from the paper's operating point, docs/model.md s. 9).
    A cooling set (name, mapping or :class:`~nylonflex.materials.Cooling`):
    :func:`convection_loss_per_length` for the muscle's outer diameter d_f (C + 1),
    linearised at the operating point T_s = t_max.

    Parameters
    ----------
    coil_index : float or array
        C [-], > 0.
    nylon : str, dict or Nylon
        Muscle set (``fibre_diameter``, ``t_max``, ``t_amb``, ``heat_loss_per_length``).
    cooling : str, dict, Cooling or None
        Cooling environment (``materials.COOLING_PARAMETERS``).
    """
    ny = nylon_parameters(nylon)
    c = check("coil_index", coil_index, 0.0, lo_open=True)
    if cooling is None:
        return scalar_or_array(np.full(c.shape, ny.heat_loss_per_length))
    env = cooling_parameters(cooling)
    out = np.vectorize(lambda ci: convection_loss_per_length(
        ny.fibre_diameter * (ci + 1.0), ny.t_max, ny.t_amb, env.fluid, env.speed),
        otypes=[float])(c)
    return scalar_or_array(out)


def cooled_nylon(nylon, cooling, coil_index) -> Nylon:
    """The muscle set with the cooling set's lambda'(C) as its ``heat_loss_per_length``.

    One muscle of coil index C in a cooling environment loses
    :func:`coil_heat_loss_per_length` (C, nylon, cooling) [W/(K m)]; the returned set holds
    that value, so everything that takes the set's lambda' (the thermal step of eq. 3, the
    steady temperature, the time constant) uses it (docs/model.md s. 9). Its ``sources``
    entry for ``heat_loss_per_length`` names the cooling set; every other field is the
    set's own.

    Parameters
    ----------
    nylon : str, dict or Nylon
        Muscle set.
    cooling : str, dict, Cooling or None
        Cooling environment (``materials.COOLING_PARAMETERS``); None: the set as it is.
    coil_index : float
        The muscle's coil index C [-], > 0.

    Returns
    -------
    Nylon
    """
    ny = nylon_parameters(nylon)
    if cooling is None:
        return ny
    env = cooling_parameters(cooling)
    c = float(check("coil_index", coil_index, 0.0, lo_open=True))
    loss = float(coil_heat_loss_per_length(c, ny, env))
    how = "free convection" if env.speed == 0.0 else f"cross flow at {env.speed:g} m/s"
    return dataclasses.replace(ny, heat_loss_per_length=loss, sources={
        **ny.sources,
        "heat_loss_per_length": f"D: cooling set {env.name} ({env.fluid}, {how}): "
                                f"lambda'(C = {c:g}) of coil_heat_loss_per_length, in place "
                                "of the set's own (docs/model.md s. 9)"})


@formula
def coil_resistance(r_ref, c_ref, coil_index):
    """r'(C) = r'_ref sqrt((pi C)^2 + 1) / sqrt((pi C_r)^2 + 1) [ohm/m]; r'_ref if C_r <= 0.

    Exactly r'_ref at C = C_r (x / x is 1 in floating point).
    """
    if c_ref <= 0.0:
        return r_ref
    return r_ref * (math.sqrt((math.pi * coil_index) ** 2 + 1.0)
                    / math.sqrt((math.pi * c_ref) ** 2 + 1.0))


def coil_resistance_per_length(coil_index, nylon="silver_nylon66"):
    """Resistance per muscle length r'(C) of the set at each coil index [ohm/m].

    The set's ``resistance_per_length`` holds at its ``resistance_coil_index`` C_r (the
    paper's 0.15 ohm/mm at its driven actuator's C = 1.7 for the default set); at another C
    the coil holds sqrt((pi C)^2 + 1) of thread per length (:func:`coiled_resistance_per_length`),
    so r' scales by that ratio: 0.663 of it at C = 1.1 (99.4 ohm/m), 0.774 at 1.3, 0.887 at
    1.5 (docs/model.md s. 9). C_r = 0: the same r' at every C.

    Parameters
    ----------
    coil_index : float or array
        C [-], > 0.
    nylon : str, dict or Nylon
        Muscle set.
    """
    ny = nylon_parameters(nylon)
    c = check("coil_index", coil_index, 0.0, lo_open=True)
    out = np.vectorize(lambda ci: coil_resistance(ny.resistance_per_length,
                                                  ny.resistance_coil_index, ci),
                       otypes=[float])(c)
    return scalar_or_array(out)


def coiled_resistance_per_length(thread_resistance_per_length, coil_index):
    """Resistance per muscle length of a close-wound coil of a thread, r' [ohm/m].

    A coil of touching turns (pitch = d_f) of mean diameter C d_f holds
    sqrt((pi C)^2 + 1) of thread per length of muscle (the helix's length per turn over its
    pitch), so r' = r'_thread sqrt((pi C)^2 + 1): 3.6 times the thread's at C = 1.1, 5.4 at
    1.7. The named sets scale their measured r' by its ratio between coil indices
    (:func:`coil_resistance_per_length`; docs/model.md s. 9).

    Parameters
    ----------
    thread_resistance_per_length : float or array
        Resistance per length of the straight (twisted) thread [ohm/m], > 0.
    coil_index : float or array
        Coil index C [-], > 0.
    """
    r = check("thread_resistance_per_length", thread_resistance_per_length, 0.0,
              lo_open=True, unit="ohm/m")
    c = check("coil_index", coil_index, 0.0, lo_open=True)
    return scalar_or_array(r * np.sqrt((np.pi * c) ** 2 + 1.0))


@formula
def _temperature_step(temperature, voltage, dt, muscle_length, t_amb, r_per_len,
                      c_per_len, loss_per_len):
    """Exact solution of eq. (3) over a step dt at constant voltage [K].

    T(t + dt) = T_ss + (T(t) - T_ss) exp(-dt/tau), T_ss = T_amb + V^2/(R Lambda).
    """
    r = r_per_len * muscle_length
    loss = loss_per_len * muscle_length
    t_ss = t_amb + voltage * voltage / (r * loss)
    return t_ss + (temperature - t_ss) * np.exp(-dt * loss_per_len / c_per_len)


@formula
def _steady_temperature(voltage, muscle_length, t_amb, r_per_len, loss_per_len):
    """T_ss = T_amb + V^2 / (r' lambda' l_m^2), the steady state of eq. (3) [K]."""
    return t_amb + voltage * voltage / (r_per_len * loss_per_len * muscle_length * muscle_length)


@formula
def _heating_power(temperature, muscle_length, t_amb, loss_per_len):
    """Steady power that holds the muscle at T, P = lambda' l_m (T - T_amb) [W]."""
    return loss_per_len * muscle_length * (temperature - t_amb)


@formula
def _cooling_time(t_start, t_end, t_amb, tau):
    """Time for eq. (3) with V = 0 to cool from t_start to t_end [s]: tau ln(dT0/dT1)."""
    return tau * math.log((t_start - t_amb) / (t_end - t_amb))


@formula
def _heating_time(t_end, t_ss, t_amb, tau):
    """Time for eq. (3) at constant V to heat from T_amb to t_end < T_ss [s]; inf if not reached.

    T(t) = T_ss - (T_ss - T_amb) exp(-t/tau), so t = -tau ln(1 - (T - T_amb)/(T_ss - T_amb)).
    """
    if t_end >= t_ss:
        return math.inf
    return -tau * math.log(1.0 - (t_end - t_amb) / (t_ss - t_amb))


#: The least steady temperature rise a supply must give every muscle, T_ss - T_amb [K].
#: Below about 1e-10 K the working, cooling and heating temperatures are not resolved next
#: to T_amb in float64 (1e-9 V: cooling_time NaN and heating_time inf in every design;
#: 1e-6 V on a 2 m muscle: inf); 1 mK keeps ten orders of magnitude from that.
MIN_SUPPLY_RISE = 1e-3


def check_supply_rise(voltage, muscle_length, r_per_len, loss_per_len,
                      field="supply.voltage"):
    """Refuse a supply that cannot heat every muscle at least :data:`MIN_SUPPLY_RISE`
    above ambient: T_ss - T_amb = V^2 / (r' lambda' l_m^2) (eq. 3).

    Parameters
    ----------
    voltage : float
        Supply voltage [V] (<= 0: no supply, nothing checked).
    muscle_length : float or ndarray
        Muscle lengths [m]; the longest is checked.
    r_per_len, loss_per_len : float or ndarray
        r' [ohm/m] and lambda' [W/(K m)], broadcast with ``muscle_length``.

    Raises
    ------
    ValueError
        One line naming ``field``, the rise and the least voltage that gives it.
    """
    if not voltage > 0.0:
        return
    l_m, r, loss = np.broadcast_arrays(*(np.asarray(x, float) for x in
                                         (muscle_length, r_per_len, loss_per_len)))
    rise = voltage * voltage / (r * loss * l_m * l_m)
    bad = ~(rise >= MIN_SUPPLY_RISE)
    if np.any(bad):
        j = int(np.argmin(np.where(np.isnan(rise), -np.inf, rise)))
        need = l_m.flat[j] * math.sqrt(MIN_SUPPLY_RISE * r.flat[j] * loss.flat[j])
        raise ValueError(f"{field}: {voltage:g} V heats a {l_m.flat[j]:.3g} m muscle only "
                         f"{rise.flat[j]:.3g} K above ambient; a supply must heat every "
                         f"muscle at least {MIN_SUPPLY_RISE:g} K (here at least {need:.3g} V)")


def _lengths(muscle_length):
    return check("muscle_length", muscle_length, 0.0, lo_open=True, unit="m")


def _r_per_len(ny, coil_index):
    """r' [ohm/m] of a set: at ``coil_index`` (:func:`coil_resistance_per_length`), or the
    set's own (at its ``resistance_coil_index``) when None."""
    if coil_index is None:
        return ny.resistance_per_length
    return np.asarray(coil_resistance_per_length(coil_index, ny), float)


def muscle_resistance(muscle_length, nylon="silver_nylon66", coil_index=None):
    """Electrical resistance R = r' l_m of the muscle [ohm].

    Parameters
    ----------
    muscle_length : float or array
        Length of muscle in the wrap l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set (``resistance_per_length`` r' [ohm/m]; the paper measured 0.15 ohm/mm).
    coil_index : float or array, optional
        C [-]: r'(C) (:func:`coil_resistance_per_length`); None: the set's own r'.
    """
    ny = nylon_parameters(nylon)
    return scalar_or_array(_r_per_len(ny, coil_index) * _lengths(muscle_length))


def thermal_time_constant(nylon="silver_nylon66"):
    """Time constant tau = C/Lambda = c'/lambda' of eq. (3) [s]."""
    ny = nylon_parameters(nylon)
    return ny.heat_capacity_per_length / ny.heat_loss_per_length


def temperature_rate(temperature, voltage, muscle_length, nylon="silver_nylon66",
                     coil_index=None):
    """Right-hand side of eq. (3): dT/dt = (V^2/R - Lambda (T - T_amb)) / C [K/s].

    Parameters
    ----------
    temperature : float or array
        Muscle temperature T [K], > 0.
    voltage : float or array
        Applied voltage V [V].
    muscle_length : float or array
        Muscle length l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set.
    coil_index : float or array, optional
        C [-] for r'(C); None: the set's own r'.

    References
    ----------
    Paper eq. (3) (Yip & Niemeyer 2015).
    """
    ny = nylon_parameters(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    v = check("voltage", voltage, unit="V")
    lm = _lengths(muscle_length)
    heat = v * v / (_r_per_len(ny, coil_index) * lm)
    loss = ny.heat_loss_per_length * lm * (t - ny.t_amb)
    return scalar_or_array((heat - loss) / (ny.heat_capacity_per_length * lm))


def steady_temperature(voltage, muscle_length, nylon="silver_nylon66", coil_index=None,
                       cooling=None):
    """Steady state of eq. (3), T_ss = T_amb + V^2 / (R Lambda) [K].

    Parameters
    ----------
    voltage : float or array
        Applied voltage V [V].
    muscle_length : float or array
        Muscle length l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set.
    coil_index : float or array, optional
        C [-] for r'(C); None: the set's own r'.
    cooling : str, dict, Cooling or None
        Cooling environment: lambda'(C) of :func:`coil_heat_loss_per_length` (needs
        ``coil_index``); None: the set's own lambda'.
    """
    ny = nylon_parameters(nylon)
    v = check("voltage", voltage, unit="V")
    lm = _lengths(muscle_length)
    if cooling is None:
        loss = ny.heat_loss_per_length
    elif coil_index is None:
        raise ValueError("coil_index: needed with a cooling set (lambda' depends on C)")
    else:
        loss = np.asarray(coil_heat_loss_per_length(coil_index, ny, cooling), float)
    return scalar_or_array(ny.t_amb + v * v / (_r_per_len(ny, coil_index) * loss * lm * lm))


def temperature_step(temperature, voltage, dt, muscle_length, nylon="silver_nylon66",
                     coil_index=None):
    """Temperature after a step dt at constant voltage, exact solution of eq. (3) [K].

    Parameters
    ----------
    temperature : float
        Temperature at the start of the step [K], > 0.
    voltage : float
        Voltage held over the step [V].
    dt : float
        Step [s], >= 0.
    muscle_length : float
        Muscle length l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set.
    coil_index : float, optional
        C [-] for r'(C); None: the set's own r'.
    """
    ny = nylon_parameters(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    v = check("voltage", voltage, unit="V")
    h = check("dt", dt, 0.0, unit="s")
    lm = _lengths(muscle_length)
    return scalar_or_array(_temperature_step(t, v, h, lm, ny.t_amb, _r_per_len(ny, coil_index),
                                             ny.heat_capacity_per_length,
                                             ny.heat_loss_per_length))
