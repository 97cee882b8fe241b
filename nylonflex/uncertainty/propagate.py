"""Propagation of a config's uncertain parameters at scattered designs."""

from __future__ import annotations

import numpy as np

from ..config import ResolvedConfig
from ..engine.pointwise import evaluate
from ..engine.sampled import perturbed_inputs, sample_statistics, standard_samples
from ..units import InputError
from ..variables import AXES

__all__ = ["propagate"]


def propagate(cfg: ResolvedConfig, designs: dict, *, samples: int | None = None,
              keep_samples: bool = False) -> dict:
    """Quantiles and feasibility of designs under the config's uncertainty.

    Parameters
    ----------
    cfg : ResolvedConfig
        A config with an ``uncertainty`` section (and optionally ``requirements``).
    designs : dict of str to float or ndarray
        The five axes [SI] (radius [m], wall_thickness [m], length [m], coil_index [1],
        wrap_angle [rad]), broadcasting together to the design shape D.
    samples : int, optional
        Sample count; the config's by default.
    keep_samples : bool
        Also return the sampled outputs (``"samples"``: dict name -> (*D, S)).

    Returns
    -------
    dict
        ``<name>_quantile`` (*D, Q), ``feasibility`` (*D) with requirements, and
        ``"samples"`` when asked.

    Raises
    ------
    InputError
        No ``uncertainty`` section, or a design axis missing.
    """
    if cfg.uncertainty is None:
        raise InputError("uncertainty: the config has no 'uncertainty' section")
    missing = [a for a in AXES if a not in designs]
    if missing:
        raise InputError(f"designs: missing {', '.join(missing)}")
    z = standard_samples(cfg.uncertainty, samples)
    out = evaluate(**perturbed_inputs({a: np.asarray(designs[a], float) for a in AXES}, cfg, z))
    stats = sample_statistics(out, cfg.uncertainty.quantiles, cfg.requirements)
    if keep_samples:
        stats["samples"] = out
    return stats
