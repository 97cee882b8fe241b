"""Thermo-electric model of the muscle, eq. (3): C dT/dt = V^2/R - Lambda (T - T_amb).

docs/model.md sections 2 and 10: R = r' l_m, C = c' l_m, Lambda = lambda' l_m for a muscle of
length l_m, so the time constant tau = c'/lambda' does not depend on the length.
"""

from __future__ import annotations

import math

import numpy as np

from ..materials import nylon_parameters
from ._formula import check, formula, scalar_or_array

__all__ = [
    "MIN_SUPPLY_RISE",
    "check_supply_rise",
    "muscle_resistance",
    "steady_temperature",
    "temperature_rate",
    "temperature_step",
    "thermal_time_constant",
]


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


def muscle_resistance(muscle_length, nylon="silver_nylon66"):
    """Electrical resistance R = r' l_m of the muscle [ohm].

    Parameters
    ----------
    muscle_length : float or array
        Length of muscle in the wrap l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set (``resistance_per_length`` r' [ohm/m]; the paper measured 0.15 ohm/mm).
    """
    ny = nylon_parameters(nylon)
    return scalar_or_array(ny.resistance_per_length * _lengths(muscle_length))


def thermal_time_constant(nylon="silver_nylon66"):
    """Time constant tau = C/Lambda = c'/lambda' of eq. (3) [s]."""
    ny = nylon_parameters(nylon)
    return ny.heat_capacity_per_length / ny.heat_loss_per_length


def temperature_rate(temperature, voltage, muscle_length, nylon="silver_nylon66"):
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

    References
    ----------
    Paper eq. (3) (Yip & Niemeyer 2015).
    """
    ny = nylon_parameters(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    v = check("voltage", voltage, unit="V")
    lm = _lengths(muscle_length)
    heat = v * v / (ny.resistance_per_length * lm)
    loss = ny.heat_loss_per_length * lm * (t - ny.t_amb)
    return scalar_or_array((heat - loss) / (ny.heat_capacity_per_length * lm))


def steady_temperature(voltage, muscle_length, nylon="silver_nylon66"):
    """Steady state of eq. (3), T_ss = T_amb + V^2 / (R Lambda) [K].

    Parameters
    ----------
    voltage : float or array
        Applied voltage V [V].
    muscle_length : float or array
        Muscle length l_m [m], > 0.
    nylon : str, dict or Nylon
        Muscle set.
    """
    ny = nylon_parameters(nylon)
    v = check("voltage", voltage, unit="V")
    lm = _lengths(muscle_length)
    return scalar_or_array(ny.t_amb + v * v / (ny.resistance_per_length * ny.heat_loss_per_length
                                               * lm * lm))


def temperature_step(temperature, voltage, dt, muscle_length, nylon="silver_nylon66"):
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
    """
    ny = nylon_parameters(nylon)
    t = check("temperature", temperature, 0.0, lo_open=True, unit="K")
    v = check("voltage", voltage, unit="V")
    h = check("dt", dt, 0.0, unit="s")
    lm = _lengths(muscle_length)
    return scalar_or_array(_temperature_step(t, v, h, lm, ny.t_amb, ny.resistance_per_length,
                                             ny.heat_capacity_per_length,
                                             ny.heat_loss_per_length))
