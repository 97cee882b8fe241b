"""Sampled designs: uncertain inputs through the pointwise evaluator, per-design statistics.

The uncertain parameters of a config (``uncertainty.parameters``, resolved to
:class:`nylonflex.config.UncertainParameter`) are driven by standard variables: scrambled
Sobol' points (scipy.stats.qmc, seeded) mapped through the normal or uniform quantile
function, one column a parameter (a fit's covariance takes as many columns as it has
parameters and mixes them by its Cholesky factor). Every design sees the same sample points
(common random numbers), so statistics vary smoothly from design to design and a relaxed
requirement never loses feasibility.

Every sample of a slab is a grid of its own (:func:`sample_configs`) through the grid
kernel (in chunks of bounded size), stacked with the sample axis last; the samples reduce to
quantiles and to the fraction of samples meeting every requirement (docs/uncertainty.md).
:func:`perturbed_inputs` gives the same samples as arguments of
:func:`~.pointwise.evaluate` (scattered designs, the closed loop, sensitivity).
"""

from __future__ import annotations

import warnings
from dataclasses import fields, replace

import numpy as np

from ..config import ResolvedConfig, UncertaintySpec
from ..config.uncertainty import MIN_FACTOR
from ..kernels.rows import DESIGN_ROWS, FLAG_ROWS
from ..materials import SILICONE_PARAMETERS
from ..physics.chamber import chamber_pressure
from ..physics.nylon import stroke_max
from ..conditions import parse_requirements
from ..variables import AXES, COORDS, DESIGN, UNCERTAIN, quantile_name
from .model_slab import (chamber_coefficients, grid_axes, grid_out, kernel_inputs, paper_kernel,
                         run_grid)
from .threads import run_chunks

__all__ = ["FLOAT_NAMES", "perturbed_configs", "perturbed_inputs", "sample_configs",
           "sample_statistics", "slab_statistics", "standard_from_unit", "standard_samples",
           "uncertain_variables"]

#: The design variables that get quantiles (``limit`` is a flag: no quantiles).
FLOAT_NAMES = tuple(n for n, v in DESIGN.items() if v.dtype != "int8")
#: Evaluations (designs x samples) computed before they reduce to statistics: bounds the
#: memory of a slab's samples (fig12 x 256 samples: 0.32 GB peak at 2^18, 0.57 GB at 2^20).
_EVALS_PER_CALL = 2**18


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
    return nominal * np.maximum(1.0 + p.rel_sd * z, MIN_FACTOR)


def _kept_sign(nominal, delta):
    """A fitted parameter's samples ``nominal + delta``, truncated at MIN_FACTOR times the
    nominal value so that none crosses zero (config refuses a fit where this bites in
    over ``MAX_TRUNCATED`` of the draws; a zero value, which config passes only with no
    spread, stays as drawn)."""
    nominal = np.asarray(nominal, float)
    if not np.all(nominal != 0.0):
        return nominal + delta
    return nominal * np.maximum(1.0 + delta / nominal, MIN_FACTOR)


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
        if p.fields:  # a fit's multivariate normal: nominal + L z, each kept on its side
            cov = np.asarray(p.covariance, float)  # of zero (at least MIN_FACTOR of it)
            delta = zj @ _cholesky(cov).T
            for k, name in enumerate(p.fields):
                field, _, idx = name.rpartition("_")
                if field in table and idx.isdigit():
                    arr = np.atleast_1d(np.asarray(table[field], float))
                    col = np.broadcast_to(arr, (S, arr.shape[-1])).copy()
                    i = int(idx) - 1  # col[:, i] is still the nominal value
                    col[:, i] = _kept_sign(col[:, i], delta[:, k])
                    table[field] = col
                else:
                    table[name] = _kept_sign(np.asarray(table[name], float), delta[:, k])
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
    out["chamber"] = chamber_coefficients(cfg)  # sealed_chamber's (docs/model.md s. 22)
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
    return [({k: float(axes[k][s]) for k in AXES}, _sample_config(cfg, args, s))
            for s in range(S)]


def sample_configs(cfg: ResolvedConfig, z: np.ndarray, i0: int = 0,
                   i1: int | None = None) -> list:
    """Every sample of ``z`` as a plain config of its own: its axes moved as
    :func:`perturbed_inputs` moves them (the same truncations), radius cut to the indices
    [i0, i1), and its silicone and nylon.

    Every uncertain parameter moves an axis value by a function of that value alone, or a
    material field, so each sample's designs are again a grid, which the grid kernel
    computes as it computes a cube: every sample's curvature solves warm-started along its
    own pressure curve and shared by every length, wrap angle and coil index that can share
    them. The configs carry no uncertainty, requirements or tracking.

    Parameters
    ----------
    cfg : ResolvedConfig
        The sampled sweep's config.
    z : ndarray
        Standard variables, shape (S, dims), from :func:`standard_samples`.
    i0, i1 : int
        The radius indices of the slab.

    Returns
    -------
    list of ResolvedConfig
        S configs.
    """
    S = z.shape[0]
    axes = dict(cfg.axes)
    axes["radius"] = axes["radius"][i0:i1]
    args = perturbed_inputs({k: np.asarray(axes[k], float) for k in AXES}, cfg, z)
    moved = {k: np.broadcast_to(np.asarray(args[k], float), (len(axes[k]), S)) for k in AXES}
    return [replace(_sample_config(cfg, args, s),
                    axes={k: np.ascontiguousarray(moved[k][:, s]) for k in AXES},
                    uncertainty=None, requirements=(), tracking=None)
            for s in range(S)]


def _sample_config(cfg: ResolvedConfig, args: dict, s: int) -> ResolvedConfig:
    """``cfg`` with sample ``s``'s silicone and nylon of :func:`perturbed_inputs`'s
    ``args`` (``cfg`` itself where no material is uncertain)."""
    silicone, nylon = args["silicone"], args["nylon"]
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
    return c


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
            ok &= r.mask(out[r.name])
        stats["feasibility"] = ok.mean(axis=-1)
    return stats


def slab_statistics(cfg: ResolvedConfig, i0: int, i1: int, nominal: dict, model: int = 0,
                    parallel: bool = True) -> dict:
    """The sampled variables of the radii [i0, i1): quantiles and feasibility.

    ``nominal`` is the slab's plain result (grid kernel); without ``uncertainty`` the
    feasibility is that of the nominal designs (0 or 1). With it, every sample is a grid of
    its own (:func:`sample_configs`) through the grid kernel of ``model`` (an index into
    :data:`~nylonflex.physics.limits.MODELS`), without the curves a cube stores: a short
    pressure curve up to the highest full-stroke pressure of the samples starts the
    curvature solves. The samples are split over the engine's threads when ``parallel``
    (False: Dask workers, one level of parallelism).
    """
    reqs = parse_requirements(list(cfg.requirements))
    if cfg.uncertainty is None:
        ok = np.ones(nominal[FLOAT_NAMES[0]].shape, dtype=bool)
        for r in reqs:
            ok &= r.mask(nominal[r.name])
        return {"feasibility": ok.astype(float)}
    spec = cfg.uncertainty
    z = standard_samples(spec)
    S = z.shape[0]
    samples = _with_start_curve(sample_configs(cfg, z, i0, i1))
    inputs = [kernel_inputs(c, model) for c in samples]
    shape = (i1 - i0, *(len(cfg.axes[k]) for k in AXES[1:]))
    per_radius = int(np.prod(shape[1:])) * S
    step = max(1, _EVALS_PER_CALL // max(per_radius, 1))
    result = {n: np.empty((*shape, len(spec.quantiles))) for n in
              (quantile_name(m) for m in FLOAT_NAMES)}
    if reqs:
        result["feasibility"] = np.empty(shape)
    for r0 in range(0, shape[0], step):
        r1 = min(shape[0], r0 + step)
        out = _sampled_grids(samples, inputs, r0, r1, parallel)
        for name, arr in sample_statistics(out, spec.quantiles, reqs).items():
            result[name][r0:r1] = arr
    return result


#: Points of the pressure curve each sample's grid solves first: its solves start the
#: full-stroke and stroke-limit solves (the grid kernel's warm starts).
_START_PRESSURES = 4


def _with_start_curve(samples: list) -> list:
    """The sample configs with no stroke curve and a pressure curve of
    :data:`_START_PRESSURES` points from 0 to the highest full-stroke pressure p(s_max)
    of any sample's coil index [Pa] (what starts the kernel's solves; nothing stored)."""
    s_top = max(float(np.max(stroke_max(c.axes["coil_index"], c.nylon))) for c in samples)
    p_top = float(chamber_pressure(min(s_top, 0.999)))
    curves = {"stroke": np.empty(0), "pressure": np.linspace(0.0, p_top, _START_PRESSURES)}
    return [replace(c, curves=curves) for c in samples]


def _sampled_grids(samples: list, inputs: list, r0: int, r1: int, parallel: bool) -> dict:
    """Every design variable of the radii [r0, r1) of every sample, sample axis last."""
    S = len(samples)
    first = grid_out(samples[0], r1 - r0)
    design = np.empty((S, *first.design.shape))
    flags = np.empty((S, *first.flags.shape), dtype=np.int8)

    def run(s0, s1):
        # the curves are scratch (a short pressure curve, no stroke): one set a thread
        scratch = first if s0 == 0 else grid_out(samples[s0], r1 - r0)
        for s in range(s0, s1):
            run_grid(grid_axes(samples[s], r0, r1), inputs[s],
                     scratch._replace(design=design[s], flags=flags[s]), parallel=False,
                     paper=paper_kernel(samples[s]))

    run_chunks(run, S, parallel=parallel)
    last = lambda a: np.moveaxis(a, 0, -1)  # noqa: E731
    out = {n: last(design[:, row]) for n, row in DESIGN_ROWS.items()}
    out.update({n: last(flags[:, row]) for n, row in FLAG_ROWS.items()})
    return out
