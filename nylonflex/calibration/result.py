"""The result of a fit: values, uncertainties, statistics and where the data came from."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["FitResult"]


@dataclass
class FitResult:
    """A fitted parameter set, SI.

    Attributes
    ----------
    kind : str
        ``"silicone"``, ``"stroke"``, ``"thermal"`` or ``"muscle"``.
    model : str
        The fitted form (``"ogden2"``, ``"eq2"``, ...).
    parameters, stderr, ci95 : dict
        Parameter name -> value (float, or list for Ogden terms), its standard error and its
        95 % interval ``[lo, hi]`` (a list of them for a list), SI.
    parameter_order : list of str
        Flat names (``mu_1``, ``alpha_1``, ...) in the order of ``covariance``.
    covariance : ndarray
        Covariance of the flat parameters, SI.
    derived : dict
        Name -> ``{"value", "stderr", "ci95"}`` of a quantity computed from the parameters
        (``initial_shear_modulus`` [Pa], ``stroke_max`` [-], ``tau`` [s], ...).
    rmse, r2 : float
        Root-mean-square residual [unit of y] and coefficient of determination [-].
    fitted_range : dict
        Name of x -> ``[lo, hi]`` of the data fitted, SI.
    data : dict
        ``{"path", "sha256"}`` of the data file.
    x_name, y_name : str
        Names of the fitted abscissa and ordinate (variables of the data).
    x, y, y_fit : ndarray
        The data fitted and the fit at the same x, SI.
    uncertainty : str
        ``"jacobian"`` or ``"bootstrap"``.
    units : dict
        Parameter or derived name -> SI unit.
    extra : dict
        Fit-specific fields for the material file (the nylon set's row, ...).
    """

    kind: str
    model: str
    parameters: dict
    stderr: dict
    ci95: dict
    parameter_order: list
    covariance: np.ndarray
    derived: dict
    rmse: float
    r2: float
    fitted_range: dict
    data: dict
    x_name: str
    y_name: str
    x: np.ndarray
    y: np.ndarray
    y_fit: np.ndarray
    uncertainty: str = "jacobian"
    units: dict = field(default_factory=dict)
    test: str | None = None
    name: str = ""
    extra: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    @property
    def n_points(self) -> int:
        return int(self.x.size)

    @property
    def residuals(self) -> np.ndarray:
        """Data minus fit [unit of y]."""
        return self.y - self.y_fit

    def to_json(self) -> dict:
        """The object ``nylonflex fit ... --format json`` prints (docs/interface.md), SI."""
        out = {"model": self.model, "parameters": _plain(self.parameters),
               "stderr": _plain(self.stderr), "ci95": _plain(self.ci95)}
        for name, d in self.derived.items():
            out[name] = float(d["value"])
        out["rmse"] = float(self.rmse)
        out["r2"] = float(self.r2)
        for name, rng in self.fitted_range.items():
            out[f"{name}_range"] = [float(v) for v in rng]
        out["data"] = dict(self.data)
        return out


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple, np.ndarray)):
        return [_plain(v) for v in obj]
    return float(obj)


def statistics(y, y_fit) -> tuple[float, float]:
    """RMSE [unit of y] and R^2 [-] of a fit."""
    res = np.asarray(y) - np.asarray(y_fit)
    rmse = float(np.sqrt(np.mean(res**2)))
    ss_tot = float(np.sum((y - np.mean(y)) ** 2))
    r2 = 1.0 - float(res @ res) / ss_tot if ss_tot > 0 else float("nan")
    return rmse, r2
