"""Sobol' sensitivity indices of design variables to the uncertain parameters (SALib).

Each entry of ``uncertainty.parameters`` is one factor; a fit's covariance (``from_fit``)
is one group of its whitened (independent) standard variables, so its index is the share of
the whole fit. Saltelli's scheme (SALib ``sample.sobol``, scrambled Sobol' points, seeded)
gives first-order and total indices with bootstrap confidence intervals
(``analyze.sobol``, 95 %).

At one design the indices are those of its outputs. Over the design space (designs of the
grid, at most ``max_designs`` of them drawn with the seed) they are the mean of the
per-design indices, with the mean of their confidence half-widths: "which parameter decides
the typical design". Designs where an output does not vary are left out of its mean.

With a ``tracking:`` block the closed-loop variables (``tracking_rms_error``, ...) are
outputs too: each sample of each design runs the sweep's closed loop under that sample's
materials (:func:`nylonflex.engine.tracking.sampled_tracking`, about 8 ms a run), so the
nominal materials give the cube's value. Their run count is bounded by
:data:`MAX_LOOP_RUNS`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..config import ResolvedConfig
from ..engine.pointwise import evaluate
from ..engine.sampled import FLOAT_NAMES, perturbed_inputs, standard_from_unit
from ..engine.tracking import sampled_tracking, tracking_variables
from ..units import InputError
from ..variables import AXES, TRACKING

__all__ = ["SensitivityResult", "sobol_indices"]

_KEYS = ("first", "total", "first_conf", "total_conf")

#: Saltelli's largest base sample N [-] (a power of 2).
MAX_BASE_SAMPLES = 2**20
#: The most grid designs averaged over [-].
MAX_DESIGNS = 10_000
#: The most model runs of one analysis, N (factors + 2) x designs [-]: about 0.4 GB of
#: memory (2^24 base samples of one factor, 5 x 10^7 runs, held 1.2 GB).
MAX_RUNS = 2**24
#: The most closed-loop runs of one analysis with tracking outputs, N (factors + 2) x
#: designs (x the bandwidth search's runs) [-]: about 8 ms each, some 2 minutes of one core.
MAX_LOOP_RUNS = 2**14


@dataclass
class SensitivityResult:
    """Sobol' indices: ``indices[output][key][parameter]``, key one of first, total,
    first_conf, total_conf (confidence half-widths, 95 %)."""

    indices: dict
    parameters: tuple
    designs: int
    samples: int
    at: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        """docs/interface.md's document: ``{"outputs": {NAME: {"first": {PARAM: value}, ...}}}``
        plus what was computed (``parameters``, ``designs``, ``samples``, ``at`` SI)."""
        clean = lambda x: None if not np.isfinite(x) else float(x)
        return {"outputs": {o: {k: {p: clean(v) for p, v in d[k].items()} for k in _KEYS}
                            for o, d in self.indices.items()},
                "parameters": list(self.parameters), "designs": self.designs,
                "samples": self.samples, "at": dict(self.at)}


def _grid_designs(cfg, at, max_designs, seed):
    """The designs to analyse: ``at`` alone when it names all five axes, else grid designs
    with the ``at`` axes fixed, at most ``max_designs`` (seeded draw)."""
    axes = {a: (np.array([at[a]]) if a in at else cfg.axes[a]) for a in AXES}
    grid = np.meshgrid(*(axes[a] for a in AXES), indexing="ij")
    flat = {a: g.reshape(-1) for a, g in zip(AXES, grid)}
    n = flat["radius"].size
    if n > max_designs:
        pick = np.sort(np.random.default_rng(seed).choice(n, max_designs, replace=False))
        flat = {a: v[pick] for a, v in flat.items()}
    return flat


def sobol_indices(cfg: ResolvedConfig, outputs=("tip_force_max",), *, at=None,
                  base_samples: int = 512, max_designs: int = 16, seed: int | None = None,
                  num_resamples: int = 100, progress=None) -> SensitivityResult:
    """First-order and total Sobol' indices of ``outputs`` w.r.t. the uncertain parameters.

    Parameters
    ----------
    cfg : ResolvedConfig
        A config whose ``uncertainty.parameters`` name the factors (at least one).
    outputs : sequence of str
        Float design variables (``tip_force_max``, ``range_fraction``, ...) and, with
        ``cfg.tracking``, its tracking variables (``tracking_rms_error``, ...: the closed
        loop of each sample, see module).
    at : dict, optional
        Axis values [SI]; all five: one design; some or none: grid designs (see module).
    base_samples : int
        Saltelli's N (a power of 2); the model runs N (factors + 2) times a design.
    max_designs : int
        Most grid designs averaged over.
    seed : int, optional
        Seed of the samples and the bootstrap; the config's ``uncertainty.seed`` by default.
    num_resamples : int
        Bootstrap resamples of the confidence intervals.
    progress : callable, optional
        Called as ``progress(done, total)`` [steps: a design's closed loops, an output's
        analysis of a design] as the work goes.

    Returns
    -------
    SensitivityResult

    Raises
    ------
    InputError
        No uncertain parameter, an unknown output (a tracking one without ``tracking:``),
        a bad ``base_samples``, or too many model or closed-loop runs.
    """
    from SALib.analyze import sobol as analyze
    from SALib.sample import sobol as sample

    spec = cfg.uncertainty
    if spec is None or not spec.parameters:
        raise InputError("uncertainty.parameters: sensitivity needs at least one uncertain "
                         "parameter in the config")
    tracked = tracking_variables(cfg)
    for o in outputs:
        if o in TRACKING and o not in tracked:
            raise InputError(f"--output: {o} needs " + (
                "a tracking: block in the config (the closed loop of every design, "
                "docs/model.md s. 19)" if cfg.tracking is None else
                "tracking.bandwidth in the config's tracking: block"))
    bad = [o for o in outputs if o not in FLOAT_NAMES and o not in tracked]
    if bad or not outputs:
        raise InputError(f"--output: unknown {', '.join(bad) or 'none given'}; accepted: "
                         f"{', '.join((*FLOAT_NAMES, *tracked))}")
    if base_samples < 8 or base_samples & (base_samples - 1) or \
            base_samples > MAX_BASE_SAMPLES:
        raise InputError(f"--samples: must be a power of 2 in [8, {MAX_BASE_SAMPLES:,}], got "
                         f"{base_samples:,}")
    if not 1 <= max_designs <= MAX_DESIGNS:
        raise InputError(f"--designs: must be in [1, {MAX_DESIGNS:,}], got {max_designs:,}")
    seed = spec.seed if seed is None else seed
    names = [p.name for p in spec.parameters]
    groups = [p.name for p in spec.parameters for _ in range(p.dims)]
    at_ = dict(at or {})
    n_designs = min(max_designs, int(np.prod([1 if a in at_ else len(cfg.axes[a])
                                              for a in AXES])))
    groups_n = len(set(groups)) if any(p.dims > 1 for p in spec.parameters) else len(groups)
    runs = base_samples * (groups_n + 2) * n_designs
    if runs > MAX_RUNS:  # checked before any sample is drawn
        raise InputError(f"--samples: {base_samples:,} x {groups_n + 2} (factors + 2) x "
                         f"{n_designs:,} design{'s' if n_designs != 1 else ''} = {runs:,} "
                         f"model runs, over the {MAX_RUNS:,} one analysis may make; lower "
                         "--samples or --designs (or fix more axes with --at)")
    loop = [o for o in outputs if o in tracked]
    if loop:
        b = cfg.tracking.bandwidth
        per = 1 + b["iterations"] + 2 if "tracking_bandwidth" in loop else 1
        loop_runs = runs * per
        if loop_runs > MAX_LOOP_RUNS:
            times = f" x {per} (the loop and tracking.bandwidth's search)" if per > 1 else ""
            raise InputError(
                f"--samples: {base_samples:,} x {groups_n + 2} (factors + 2) x {n_designs:,} "
                f"design{'s' if n_designs != 1 else ''}{times} = {loop_runs:,} closed-loop "
                f"runs, over the {MAX_LOOP_RUNS:,} one analysis may make (about 8 ms each); "
                "lower --samples or --designs (or fix more axes with --at)")
    d = len(groups)
    problem = {"num_vars": d, "names": [f"{g}[{i}]" for i, g in enumerate(groups)],
               "bounds": [[0.0, 1.0]] * d}
    if any(p.dims > 1 for p in spec.parameters):
        problem["groups"] = groups
    u = sample.sample(problem, base_samples, calc_second_order=False, seed=seed)
    z = standard_from_unit(spec, u)
    designs = _grid_designs(cfg, dict(at or {}), max_designs, seed)
    relative = bool(loop) and cfg.tracking.relative_to == "bend_angle_max"
    out = {}
    if relative or any(o not in tracked for o in outputs):
        out = evaluate(**perturbed_inputs(designs, cfg, z))  # (designs, samples)
    n = len(designs["radius"])
    total, step = (n if loop else 0) + len(outputs) * n, 0

    def tick():
        nonlocal step
        step += 1
        if progress is not None:
            progress(step, total)

    if loop:  # the closed loop of each sample of each design
        rows = []
        for i in range(n):
            rows.append(sampled_tracking(cfg, {a: designs[a][i] for a in AXES}, z, loop,
                                         bend_angle_max=out["bend_angle_max"][i] if relative
                                         else None))
            tick()
        out = {**out, **{o: np.array([r[o] for r in rows]) for o in loop}}
    acc = {o: {k: {p: [] for p in names} for k in _KEYS} for o in outputs}
    for o in outputs:
        for row in np.asarray(out[o]):
            tick()
            if not np.all(np.isfinite(row)) or np.ptp(row) <= 1e-12 * max(np.abs(row).max(), 1e-300):
                continue  # a design whose output does not vary: no indices
            res = analyze.analyze(problem, row, calc_second_order=False, seed=seed,
                                  num_resamples=num_resamples)
            for key, salib in zip(_KEYS, ("S1", "ST", "S1_conf", "ST_conf")):
                for p, v in zip(names, np.atleast_1d(res[salib])):
                    acc[o][key][p].append(float(v))
    indices = {o: {k: {p: float(np.mean(v)) if v else float("nan") for p, v in d_.items()}
                   for k, d_ in by_key.items()} for o, by_key in acc.items()}
    return SensitivityResult(indices, tuple(names), len(designs["radius"]),
                             int(u.shape[0]), dict(at or {}))
