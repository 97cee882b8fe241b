"""Sampled designs: uncertain inputs through the pointwise evaluator, per-design statistics.

The uncertain parameters of a config (``uncertainty.parameters``, resolved to
:class:`nylonflex.config.UncertainParameter`) are driven by standard variables: scrambled
Sobol' points (scipy.stats.qmc, seeded) mapped through the normal or uniform quantile
function, one column a parameter (a fit's covariance takes as many columns as it has
parameters and mixes them by its Cholesky factor). Every design sees the same sample points
(common random numbers), so statistics vary smoothly from design to design and a relaxed
requirement never loses feasibility.

A slab of designs times S samples is one call of :func:`~.pointwise.evaluate` (in chunks of
bounded size) with the sample axis last; the samples reduce to quantiles and to the fraction
of samples meeting every requirement (docs/uncertainty.md).
"""

from __future__ import annotations

import warnings
from dataclasses import fields, replace

import numpy as np

from ..config import ResolvedConfig, UncertaintySpec
from ..materials import SILICONE_PARAMETERS
from ..query.parse import parse_requirements
from ..variables import AXES, COORDS, DESIGN, UNCERTAIN, quantile_name
from .pointwise import evaluate, serial

__all__ = ["FLOAT_NAMES", "perturbed_configs", "perturbed_inputs", "sample_statistics",
           "slab_statistics", "standard_from_unit", "standard_samples", "uncertain_variables"]

#: The design variables that get quantiles (``limit`` is a flag: no quantiles).
FLOAT_NAMES = tuple(n for n, v in DESIGN.items() if v.dtype != "int8")
#: Evaluations per call of the evaluator (bounds the memory of a slab's samples).
_EVALS_PER_CALL = 2**20
#: Lowest factor a relative perturbation may scale a material field by (a normal tail
#: reaching a negative modulus is truncated here).
_MIN_FACTOR = 0.05


def uncertain_variables(cfg: ResolvedConfig) -> dict:
    """Registry entries of the variables a sampled sweep adds (none for a plain sweep)."""
    out = {}
    if cfg.uncertainty is not None:
        out.update({quantile_name(n): UNCERTAIN[quantile_name(n)] for n in FLOAT_NAMES})
    if cfg.requirements:
        out["feasibility"] = UNCERTAIN["feasibility"]
    return out


def standard_samples(spec: UncertaintySpec, samples: int | None = None) -> np.ndarray:
    """Standard variables of the samples, shape (samples, dims): mean 0, variance 1.

    Scrambled Sobol' points seeded by ``spec.seed``, through the normal quantile function
    (normal parameters) or scaled to a uniform of unit variance on +-sqrt(3) (uniform).
    """
    from scipy.stats import qmc

    n = spec.samples if samples is None else samples
    dims = sum(p.dims for p in spec.parameters)
    if dims == 0:
        return np.zeros((n, 0))

    with warnings.catch_warnings():  # a sample count not a power of 2: still a valid QMC set
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(dims, scramble=True, seed=spec.seed).random(n)
    return standard_from_unit(spec, u)


def standard_from_unit(spec: UncertaintySpec, u) -> np.ndarray:
    """Points of the unit cube, shape (n, dims), as standard variables (see
    :func:`standard_samples`); the cube's faces are nudged inside (a normal's 0 and 1)."""
    from scipy.stats import norm

    u = np.clip(np.asarray(u, float), 1e-12, 1.0 - 1e-12)
    z = np.empty_like(u)
    j = 0
    for p in spec.parameters:
        cols = slice(j, j + p.dims)
        if p.distribution == "uniform":
            z[:, cols] = (u[:, cols] - 0.5) * np.sqrt(12.0)
        else:
            z[:, cols] = norm.ppf(u[:, cols])
        j += p.dims
    return z


def _scaled(nominal, p, z):
    """Nominal value(s) moved by one standard variable ``z`` (shape (S,)): sd or rel_sd."""
    nominal = np.asarray(nominal, float)
    z = z.reshape(z.shape + (1,) * nominal.ndim)
    if p.sd is not None:
        return nominal + p.sd * z
    return nominal * np.maximum(1.0 + p.rel_sd * z, _MIN_FACTOR)


def perturbed_inputs(designs: dict, cfg: ResolvedConfig, z: np.ndarray) -> dict:
    """Keyword arguments of :func:`evaluate` for ``designs`` under the samples ``z``.

    Parameters
    ----------
    designs : dict of str to ndarray
        The five axes [SI], arrays broadcasting together (the design shape D).
    cfg : ResolvedConfig
        Materials, base thickness and the uncertainty spec.
    z : ndarray
        Standard variables, shape (S, dims), from :func:`standard_samples`.

    Returns
    -------
    dict
        Arguments whose broadcast shape is (*D, S): the sample axis is last. Design axes
        are truncated to their accepted range (the coil index to the muscle's table).
    """
    spec = cfg.uncertainty
    S = z.shape[0]
    out = {k: np.asarray(v, float)[..., None] for k, v in designs.items()}
    silicone = {"mu": np.asarray(cfg.silicone.mu, float),
                "alpha": np.asarray(cfg.silicone.alpha, float)}
    nylon = {k: v for k, v in cfg.nylon.to_dict().items() if k != "name"}
    touched = set()
    j = 0
    for p in spec.parameters if spec is not None else ():
        zj = z[:, j:j + p.dims]
        j += p.dims
        if p.target in AXES:
            v = COORDS[p.target]
            lo, hi = (cfg.nylon.coil_index_range if p.target == "coil_index"
                      else (v.lo, v.hi))
            out[p.target] = np.clip(_axis(out[p.target], p, zj[:, 0]), lo, hi)
            continue
        kind, _, fld = p.target.partition(".")
        table = silicone if kind == "silicone" else nylon
        touched.add(kind)
        if p.fields:  # a fit's multivariate normal: nominal + L z
            cov = np.asarray(p.covariance, float)
            delta = zj @ _cholesky(cov).T
            for k, name in enumerate(p.fields):
                field, _, idx = name.rpartition("_")
                if field in table and idx.isdigit():
                    arr = np.atleast_1d(np.asarray(table[field], float))
                    col = np.broadcast_to(arr, (S, arr.shape[-1])).copy()
                    col[:, int(idx) - 1] += delta[:, k]
                    table[field] = col
                else:
                    table[name] = np.asarray(table[name], float) + delta[:, k]
            continue
        table[fld] = _scaled(table[fld], p, zj[:, 0])
    if "silicone" in touched:
        mu, alpha = (np.broadcast_to(np.atleast_2d(silicone[k]), (S, len(cfg.silicone.mu)))
                     for k in ("mu", "alpha"))
        # the cube's own set (its stiffness kind and fitted stretch range: the validity
        # flag's stretch_beyond_fit), or for a fitted or overridden one its stretch range
        # with any kind
        named = cfg.silicone.name in SILICONE_PARAMETERS
        out["silicone"] = {"set": cfg.silicone.name if named else "tc5005", "mu": mu,
                           "alpha": alpha,
                           "stretch_range": [float(x) for x in cfg.silicone.stretch_range],
                           **({} if named else {"kind": "any"})}
    else:
        out["silicone"] = cfg.silicone
    if "nylon" in touched:
        nylon["stroke_max_table"] = np.clip(nylon["stroke_max_table"], 1e-6, 0.999)
        out["nylon"] = {"set": "silver_nylon66", **nylon}
    else:
        out["nylon"] = cfg.nylon
    out["base_thickness"] = cfg.base_thickness
    out["model"] = cfg.models[0]  # a sampled sweep has one model (nylonflex.config refuses more)
    out["supply_voltage"] = cfg.supply_voltage
    out["cooling"] = cfg.cooling
    return out


def perturbed_configs(cfg: ResolvedConfig, design: dict, z: np.ndarray) -> list:
    """One design under each sample ``z``: ``(design, config)`` pairs, config being ``cfg``
    with that sample's silicone and nylon (what :func:`perturbed_inputs` gives the
    evaluator, the same truncations), for code that takes a config (the closed loop).

    Parameters
    ----------
    cfg : ResolvedConfig
        Materials and the uncertainty spec.
    design : dict of str to float
        The five axes [SI].
    z : ndarray
        Standard variables, shape (S, dims).

    Returns
    -------
    list of (dict, ResolvedConfig)
        S pairs: the sample's design axes [SI] (moved where an axis is uncertain) and its
        config (``cfg`` itself where no material is uncertain).
    """
    S = z.shape[0]
    args = perturbed_inputs({k: np.asarray(design[k], float) for k in AXES}, cfg, z)
    axes = {k: np.broadcast_to(np.asarray(args[k], float).reshape(-1), (S,)) for k in AXES}
    silicone, nylon = args["silicone"], args["nylon"]
    out = []
    for s in range(S):
        c = cfg
        if silicone is not cfg.silicone:
            c = replace(c, silicone=replace(cfg.silicone, **{
                k: tuple(float(x) for x in silicone[k][s]) for k in ("mu", "alpha")}))
        if nylon is not cfg.nylon:
            changes = {}
            for f in fields(cfg.nylon):
                own = getattr(cfg.nylon, f.name)
                if f.name not in nylon or not isinstance(own, (int, float, tuple)):
                    continue
                v = np.asarray(nylon[f.name], float)
                if v.ndim > np.ndim(own):  # this field is sampled: the sample's row
                    v = v[s]
                changes[f.name] = tuple(float(x) for x in v) if isinstance(own, tuple) \
                    else float(v)
            c = replace(c, nylon=replace(cfg.nylon, **changes))
        out.append(({k: float(axes[k][s]) for k in AXES}, c))
    return out


def _axis(nominal, p, z):
    """A design axis (shape (*D, 1)) moved by the samples ``z`` (S,): shape (*D, S)."""
    if p.sd is not None:
        return nominal + p.sd * z
    return nominal * (1.0 + p.rel_sd * z)


def _cholesky(cov):
    """A factor L with L L^T = cov, also for a semi-definite covariance."""
    try:
        return np.linalg.cholesky(cov)
    except np.linalg.LinAlgError:
        w, v = np.linalg.eigh(cov)
        return v * np.sqrt(np.clip(w, 0.0, None))


def sample_statistics(out: dict, quantiles, requirements=()) -> dict:
    """Quantiles (a new last axis) and feasibility of sampled outputs (sample axis last).

    Parameters
    ----------
    out : dict of str to ndarray
        :func:`evaluate`'s result of shape (*D, S).
    quantiles : sequence of float
        Probability levels in (0, 1) [1].
    requirements : sequence of str or Condition
        All must hold; ``feasibility`` is the fraction of samples where they do [1].

    Returns
    -------
    dict
        ``<name>_quantile`` of shape (*D, Q) for every float design variable, and
        ``feasibility`` (*D) when there are requirements.
    """
    q = np.asarray(quantiles, float)
    stats = {quantile_name(n): np.moveaxis(np.quantile(out[n], q, axis=-1), 0, -1)
             for n in FLOAT_NAMES}
    reqs = parse_requirements([r if isinstance(r, str) else r.text for r in requirements])
    if reqs:
        ok = np.ones(out[FLOAT_NAMES[0]].shape, dtype=bool)
        for r in reqs:
            ok &= r.holds(out[r.name])
        stats["feasibility"] = ok.mean(axis=-1)
    return stats


def slab_statistics(cfg: ResolvedConfig, i0: int, i1: int, nominal: dict,
                    parallel: bool = True) -> dict:
    """The sampled variables of the radii [i0, i1): quantiles and feasibility.

    ``nominal`` is the slab's plain result (grid kernel); without ``uncertainty`` the
    feasibility is that of the nominal designs (0 or 1). ``parallel=False`` (Dask workers)
    runs the evaluator on one Numba thread: one level of parallelism.
    """
    if not parallel:
        with serial():
            return slab_statistics(cfg, i0, i1, nominal, parallel=True)
    reqs = parse_requirements(list(cfg.requirements))
    if cfg.uncertainty is None:
        ok = np.ones(nominal[FLOAT_NAMES[0]].shape, dtype=bool)
        for r in reqs:
            ok &= r.holds(nominal[r.name])
        return {"feasibility": ok.astype(float)}
    spec = cfg.uncertainty
    z = standard_samples(spec)
    S = z.shape[0]
    axes = {k: v for k, v in cfg.axes.items()}
    axes["radius"] = axes["radius"][i0:i1]
    shape = tuple(len(axes[k]) for k in AXES)
    per_radius = int(np.prod(shape[1:])) * S
    step = max(1, _EVALS_PER_CALL // max(per_radius, 1))
    result = {n: np.empty((*shape, len(spec.quantiles))) for n in
              (quantile_name(m) for m in FLOAT_NAMES)}
    if reqs:
        result["feasibility"] = np.empty(shape)
    for r0 in range(0, shape[0], step):
        r1 = min(shape[0], r0 + step)
        grid = np.meshgrid(axes["radius"][r0:r1], *(axes[k] for k in AXES[1:]),
                           indexing="ij", sparse=True)
        designs = dict(zip(AXES, grid))
        out = evaluate(**perturbed_inputs(designs, cfg, z))
        for name, arr in sample_statistics(out, spec.quantiles, reqs).items():
            result[name][r0:r1] = arr
    return result
