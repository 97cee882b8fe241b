"""Off the grid: continuous optimisation over the axes with the exact model.

One objective: SLSQP (scipy.optimize) from the best feasible grid points, the constraints as
inequality functions. Several objectives: the epsilon-constraint method with the same
SLSQP: from each grid-front seed, optimise the first objective with every other objective
held at least as good as the seed's. Each refined design therefore weakly dominates its
seed, so the refined front dominates or equals the grid front by construction; it is
deterministic and needs no new dependency (an evolutionary method such as pymoo's NSGA-II
would need thousands of evaluations and could lose grid-front points to crowding).

The model is only piecewise smooth (the strength limit switches ``limit``), so the
optimiser's answer is never trusted: it is re-evaluated exactly, and when it violates a
constraint or is worse than its seed, the segment from the (feasible) seed to it is
searched for the best point that meets every constraint.

SLSQP, and the straight segment back to the seed, stop short of a curved constraint (at a
small radius the bend-angle constraint binds, and the best wall sits exactly where the bend
reaches its bound). So every refined design (or its seed, when SLSQP found nothing) is then
pushed onto the constraints: along each free axis in turn, a 17-point scan of the axis's whole
range, then five zooms around the best acceptable point (each 1/8 of the last window), until
no axis improves (at most three sweeps); then SLSQP once more from there, and the push again.
A move is kept only when it meets every constraint and the epsilon bounds and strictly
improves the objective, so the result still weakly dominates its seed. Several objectives
also get more starts where the grid front is sparse: between neighbouring grid-front designs
in the second objective, the first is optimised with the second bounded by the midpoint.
SLSQP is given ``range_fraction >= 1`` as ``range_fraction - nylon_use + 1 >= 1``: the same
designs, but a constraint whose value falls towards the strength limit instead of staying 1.
"""

from __future__ import annotations

import numpy as np

from ..engine import evaluate
from ..variables import AXES

__all__ = ["Model", "evaluate_rows", "meets", "refine"]

# finite-difference step in the unit-scaled variables
_FD_STEP = 1e-6
# designs remembered per material set
_MEMO_MAX = 200_000
# bisection steps of the fall-back segment search
_BISECT = 30
# the push onto the active constraints: points of a 1-D scan, zooms, sweeps over the axes
_PUSH_POINTS = 17
_PUSH_ZOOMS = 6
_PUSH_SWEEPS = 3


class Model:
    """The exact model with a cube's materials; counts its evaluations.

    Parameters
    ----------
    silicone, nylon : Silicone, Nylon
        Material sets.
    base_thickness : float or None
        b [m]; None for b = t.
    model : str
        Model variant.
    memo : dict, optional
        Designs already evaluated with these materials, model and supply.
    supply_voltage : float, optional
        The cube's supply [V] (docs/model.md s. 15); None: no supply limit.
    cooling : Cooling, optional
        The cube's cooling set (docs/model.md s. 9); None: the nylon set's heat loss.
    chamber : tuple, optional
        ``sealed_chamber``'s coefficients the cube ran with (docs/model.md s. 22); None:
        the shipped ones.
    """

    def __init__(self, silicone, nylon, base_thickness=None, model="paper", memo=None,
                 supply_voltage=None, cooling=None, chamber=None):
        self.silicone, self.nylon = silicone, nylon
        self.base_thickness, self.model = base_thickness, model
        self.supply_voltage = supply_voltage
        self.cooling = cooling
        self.chamber = chamber
        self.evaluations = 0
        # designs already evaluated with these materials (shared between runs on one cube)
        self.memo = {} if memo is None else memo

    def __call__(self, X) -> dict:
        """Every axis and design variable at designs ``X`` (n, 5) [SI], as (n,) arrays."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        keys = [x.tobytes() for x in X]
        todo = [i for i, k in enumerate(keys) if k not in self.memo]
        if todo:
            self.evaluations += len(todo)
            design = dict(zip(AXES, X[todo].T))
            values = _exact(**design, base_thickness=self.base_thickness,
                            silicone=self.silicone, nylon=self.nylon, model=self.model,
                            supply_voltage=self.supply_voltage, cooling=self.cooling,
                            chamber=self.chamber)
            values = {k: np.asarray(v, dtype=float).reshape(-1) for k, v in values.items()}
            if len(self.memo) > _MEMO_MAX:
                self.memo.clear()
            for j, i in enumerate(todo):
                self.memo[keys[i]] = {k: v[j] for k, v in values.items()}
        names = list(self.memo[keys[0]])
        out = {k: np.array([self.memo[key][k] for key in keys]) for k in names}
        out.update({k: X[:, i].copy() for i, k in enumerate(AXES)})
        return out


def _exact(radius, wall_thickness, length, coil_index, wrap_angle, *, base_thickness,
           silicone, nylon, model, supply_voltage=None, cooling=None, chamber=None):
    """The one call into the exact pointwise model, :func:`nylonflex.evaluate` (compiled;
    every design variable, SI)."""
    return evaluate(radius, wall_thickness, length, coil_index, wrap_angle,
                    base_thickness=base_thickness, silicone=silicone, nylon=nylon,
                    model=model, supply_voltage=supply_voltage, cooling=cooling,
                    chamber=chamber)


def evaluate_rows(model, rows) -> dict:
    """Re-evaluate the designs of ``rows`` (columns by name) exactly."""
    X = np.column_stack([np.asarray(rows[a], float) for a in AXES])
    return model(X) if len(X) else {k: np.empty(0) for k in rows}


def meets(spec, rows, fixed) -> np.ndarray:
    """True where a design meets every constraint (fixed axes hold by construction)."""
    n = len(rows["radius"])
    ok = np.ones(n, dtype=bool)
    for c in spec.constraints:
        if c.op == "==" and c.name in fixed:
            ok &= np.asarray(rows[c.name], float) == fixed[c.name]
        else:
            ok &= c.mask(np.asarray(rows[c.name], float))
    return ok


def _bounds(spec, ranges, fixed):
    """Per axis ``(lo, hi)`` [SI]: the grid range narrowed by axis constraints."""
    out = {}
    for a in AXES:
        if a in fixed:
            out[a] = (fixed[a], fixed[a])
            continue
        lo, hi = ranges[a]
        span = max(hi - lo, abs(hi), 1e-300)
        for c in spec.constraints:
            if c.name != a:
                continue
            inset = 1e-9 * span if c.op in ("<", ">") else 0.0
            if c.op in ("<=", "<"):
                hi = min(hi, c.value - inset)
            elif c.op in (">=", ">"):
                lo = max(lo, c.value + inset)
        out[a] = (lo, hi)
    return out


def _full_range(c) -> bool:
    """Whether a constraint asks for a full range of motion (``range_fraction >= 1``)."""
    return c.name == "range_fraction" and c.op in (">=", ">") and c.value == 1.0


class _Problem:
    """SLSQP's view: unit-scaled free axes, one primary objective, inequality functions."""

    def __init__(self, model, spec, bounds, seed_row, primary, eps):
        self.model, self.spec = model, spec
        self.free = [a for a in AXES if bounds[a][1] > bounds[a][0]]
        self.lo = np.array([bounds[a][0] for a in self.free])
        self.span = np.array([bounds[a][1] - bounds[a][0] for a in self.free])
        self.base = np.array([float(seed_row[a]) for a in AXES])
        self.primary = primary
        self.eps = eps  # [(objective, seed value)]: sign * value <= sign * seed value
        self.conds = [c for c in spec.constraints
                      if c.name not in AXES and c.op in ("<=", "<", ">=", ">", "==")]
        scale = lambda v: max(abs(float(v)), 1e-12)  # noqa: E731
        self.f_scale = scale(seed_row[primary.name])
        self.c_scale = [scale(c.value) if c.value != 0 else 1.0 for c in self.conds]
        self.e_scale = [scale(v) for _, v in eps]
        self._cache = (None, None)

    def design(self, U) -> np.ndarray:
        U = np.clip(np.atleast_2d(U), 0.0, 1.0)
        X = np.repeat(self.base[None, :], len(U), axis=0)
        for k, a in enumerate(self.free):
            X[:, AXES.index(a)] = self.lo[k] + U[:, k] * self.span[k]
        return X

    def u0(self) -> np.ndarray:
        x = np.array([self.base[AXES.index(a)] for a in self.free])
        return np.clip((x - self.lo) / self.span, 0.0, 1.0)

    def _quantities(self, rows):
        """Rows of [objective, inequality..., equality...] values, all scaled."""
        q = [self.primary.sign * rows[self.primary.name] / self.f_scale]
        for c, s in zip(self.conds, self.c_scale):
            x = rows[c.name]
            if _full_range(c) and "nylon_use" in rows:
                # range_fraction is 1 all over the stroke-limited side (no gradient to see
                # the boundary coming); range_fraction - nylon_use + 1 is the same on the
                # strength-limited side (nylon_use = 1) and 2 - nylon_use on the other,
                # both 1 at the boundary: the same feasible set, with a gradient
                x = x - rows["nylon_use"] + 1.0
            q.append((x - c.value) / s if c.op in (">=", ">", "==") else (c.value - x) / s)
        for (o, v), s in zip(self.eps, self.e_scale):
            q.append(o.sign * (v - rows[o.name]) / s)
        return np.array(q)

    def _at(self, u):
        key = np.asarray(u, float).tobytes()
        if self._cache[0] != key:
            u = np.clip(np.asarray(u, float), 0.0, 1.0)
            steps = np.where(u + _FD_STEP <= 1.0, _FD_STEP, -_FD_STEP)
            U = np.vstack([u, u + np.diag(steps)])
            q = self._quantities(self.model(self.design(U)))
            jac = (q[:, 1:] - q[:, :1]) / steps[None, :]
            self._cache = (key, (q[:, 0], jac))
        return self._cache[1]

    def objective(self, u):
        q, jac = self._at(u)
        return q[0], jac[0]

    def constraints(self):
        n_ineq = 1 + len(self.conds)
        out = []
        for i in range(1, n_ineq + len(self.eps)):
            kind = "eq" if i < n_ineq and self.conds[i - 1].op == "==" else "ineq"
            out.append({"type": kind, "fun": lambda u, i=i: self._at(u)[0][i],
                        "jac": lambda u, i=i: self._at(u)[1][i]})
        return out


def _acceptable(spec, fixed, prob, rows, seed_value):
    """Mask: meets every constraint, keeps the seed's other objectives, no worse."""
    ok = meets(spec, rows, fixed)
    for o, v in prob.eps:
        ok &= o.sign * rows[o.name] <= o.sign * v
    f = prob.primary.sign * rows[prob.primary.name]
    return ok & (f <= prob.primary.sign * seed_value), f


def _improve(model, spec, bounds, fixed, seed_row, primary, eps, maxiter):
    """The best design found from ``seed_row``: a row dict, or None when none beats it."""
    from scipy.optimize import minimize

    prob = _Problem(model, spec, bounds, seed_row, primary, eps)
    if not prob.free:
        return None
    u0 = prob.u0()
    try:
        res = minimize(prob.objective, u0, jac=True, method="SLSQP",
                       bounds=[(0.0, 1.0)] * len(u0), constraints=prob.constraints(),
                       options={"maxiter": maxiter, "ftol": 1e-10})
        u1 = np.clip(res.x, 0.0, 1.0)
    except (ValueError, ArithmeticError):
        return None
    if not np.all(np.isfinite(u1)) or np.allclose(u1, u0, rtol=0, atol=1e-12):
        return None
    seed_value = float(seed_row[primary.name])
    # the answer, then points along the segment from the seed toward it
    t = np.concatenate([[1.0], np.linspace(0.0, 1.0, 17)[1:-1]])
    rows = model(prob.design(u0[None, :] + t[:, None] * (u1 - u0)[None, :]))
    ok, f = _acceptable(spec, fixed, prob, rows, seed_value)
    if ok[0]:
        k = 0
    else:
        if not ok.any():
            ok_t, bad_t = 0.0, float(t[1:].min()) if len(t) > 1 else 1.0
        else:
            k = int(np.argmin(np.where(ok, f, np.inf)))
            ok_t = float(t[k])
            above = t[t > ok_t]
            bad_t = float(above.min()) if len(above) else 1.0
        best = None if not ok.any() else _take1(rows, int(np.argmin(np.where(ok, f, np.inf))))
        for _ in range(_BISECT):  # the last acceptable point before the first bad one
            mid = 0.5 * (ok_t + bad_t)
            r = model(prob.design(u0 + mid * (u1 - u0)))
            good, fm = _acceptable(spec, fixed, prob, r, seed_value)
            if good[0]:
                ok_t = mid
                if best is None or fm[0] < primary.sign * best[primary.name]:
                    best = _take1(r, 0)
            else:
                bad_t = mid
        if best is None:
            return None
        rows, k = {key: np.array([v]) for key, v in best.items()}, 0
    row = _take1(rows, k)
    if not primary.sign * row[primary.name] < primary.sign * seed_value:
        return None  # no strict improvement: the seed stays
    return row


def _acceptable_rows(spec, fixed, eps, rows):
    """Mask: meets every constraint and keeps every epsilon bound."""
    ok = meets(spec, rows, fixed)
    for o, v in eps:
        ok &= o.sign * rows[o.name] <= o.sign * v
    return ok


def _push(model, spec, bounds, fixed, row, primary, eps):
    """The best acceptable design reached from ``row`` by moves along one axis at a time.

    Per free axis: a scan of its whole range, then zooms around the best acceptable value,
    so a constraint that binds is reached to about 1e-6 of the range. Returns ``row`` itself
    when nothing improves it.
    """
    free = [a for a in AXES if bounds[a][1] > bounds[a][0] and a not in fixed]
    x = np.array([float(row[a]) for a in AXES])
    best, best_f = row, primary.sign * float(row[primary.name])
    for _ in range(_PUSH_SWEEPS):
        moved = False
        for a in free:
            k = AXES.index(a)
            lo, hi = bounds[a]
            w_lo, w_hi = lo, hi
            for _ in range(_PUSH_ZOOMS):
                t = np.linspace(w_lo, w_hi, _PUSH_POINTS)
                X = np.repeat(x[None, :], len(t), axis=0)
                X[:, k] = t
                rows = model(X)
                f = np.where(_acceptable_rows(spec, fixed, eps, rows),
                             primary.sign * rows[primary.name], np.inf)
                j = int(np.argmin(f))
                if f[j] < best_f:
                    x[k], best_f, best, moved = t[j], float(f[j]), _take1(rows, j), True
                step = (w_hi - w_lo) / (_PUSH_POINTS - 1)
                w_lo, w_hi = max(lo, x[k] - step), min(hi, x[k] + step)
        if not moved:
            break
    return best


def _refine_one(model, spec, bounds, fixed, seed, primary, eps):
    """SLSQP, push, SLSQP, push from one seed: the best row, or None when nothing beats it."""
    best = seed
    for _ in range(2):
        row = _improve(model, spec, bounds, fixed, best, primary, eps, spec.maxiter)
        best = row if row is not None else best
        best = _push(model, spec, bounds, fixed, best, primary, eps)
    if not primary.sign * best[primary.name] < primary.sign * seed[primary.name]:
        return None
    return best


def _sparse_targets(seeds, others, n_max):
    """Extra (seed index, epsilon bounds) between neighbouring front designs (2 objectives).

    Sorted by the second objective, each neighbour pair gets a start from the design that is
    better in it, with the second objective bounded by the pair's midpoint.
    """
    if len(others) != 1 or n_max <= 0:
        return []
    o = others[0]
    v = o.sign * np.asarray(seeds[o.name], float)
    order = np.argsort(v, kind="stable")
    gaps = [(v[order[i + 1]] - v[order[i]], int(order[i]), int(order[i + 1]))
            for i in range(len(order) - 1) if v[order[i + 1]] > v[order[i]]]
    gaps.sort(reverse=True)
    out = []
    for _, i, j in gaps[:n_max]:
        mid = 0.5 * (float(seeds[o.name][i]) + float(seeds[o.name][j]))
        out.append((i, [(o, mid)]))
    return out


def _take1(rows, k) -> dict:
    return {key: float(np.asarray(v)[k]) for key, v in rows.items()}


def refine(model, spec, scan, progress=None) -> list:
    """Refined designs (row dicts) from the grid stage's best rows or front.

    Parameters
    ----------
    model : Model
        The exact model.
    spec : DesignSpec
    scan : GridScan
    progress : callable, optional
        Called as ``progress(done, total)`` [starts] after each start.

    Returns
    -------
    list of dict
        One objective: at most one design, better than the best grid point. Several: one
        design per seed that it improved, each weakly dominating its seed.
    """
    bounds = _bounds(spec, scan.ranges, scan.fixed)
    seeds = evaluate_rows(model, scan.best)
    n = len(seeds["radius"])
    if n == 0:
        return []
    primary, others = spec.objectives[0], spec.objectives[1:]
    if others:
        pick = np.unique(np.linspace(0, n - 1, min(spec.starts, n)).round().astype(int))
    else:
        pick = np.arange(min(spec.starts, n))
    tasks = [(int(i), None) for i in pick]
    if others:
        tasks += _sparse_targets(seeds, others, spec.starts)
    out = []
    for done, (i, eps) in enumerate(tasks):
        if progress is not None:
            progress(done, len(tasks))
        seed = _take1(seeds, i)
        if not meets(spec, {k: np.array([v]) for k, v in seed.items()}, scan.fixed)[0]:
            continue
        eps = [(o, seed[o.name]) for o in others] if eps is None else eps
        row = _refine_one(model, spec, bounds, scan.fixed, seed, primary, eps)
        if row is not None:
            out.append(row)
    if progress is not None:
        progress(len(tasks), len(tasks))
    if not others and out:
        out = [min(out, key=lambda r: primary.sign * r[primary.name])]
    return out
