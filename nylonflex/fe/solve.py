"""The FE twin's solve: the bend angle of a body against the chamber pressure.

The pressure is raised in increments (never more than :data:`MAX_STEP` mu0, halved when
Newton's method fails, grown again after easy steps); each increment starts from the
quadratic extrapolation of the last three converged states, and every requested pressure is
landed on exactly. The bend angle is the rotation, about x, of the chamber's end section
z = L against its base section z = 0, read from the line of nodes on the symmetry plane
from the bottom face to the top of the wall (plane sections stay nearly plane: the two
ends of the line give it), unwrapped over the increments so angles past pi are right.
"""

from __future__ import annotations

import ctypes

import numpy as np

from .measures import chamber_volume, tip_moment
from .mesh import BodyMesh
from .model import WRAP_ITEMS, build_model, felupe_ogden

__all__ = ["MAX_STEP", "FESolveError", "Path", "march", "solve_bend", "solve_pressures"]

#: Largest pressure increment over the initial shear modulus [-].
MAX_STEP = 0.1
#: The first increment over the initial shear modulus [-]: small, so that the later ones
#: start from a good extrapolation.
FIRST_STEP = 0.02
#: Smallest increment before the solve gives up, over the initial shear modulus [-].
MIN_STEP = 1e-4
#: When halving has brought the increment below :data:`RESCUE_BELOW` mu0, one longer
#: increment of :data:`RESCUE_STEP` mu0 is tried from the last converged state before
#: halving goes on: Newton's method wanders near a point where the body's tangent is nearly
#: singular (measured on example 1's default mesh near 9 kPa, the residual rising from 1e-4
#: to 1e-1 in the first iterations at any small step), and an increment that lands past it
#: converges (docs/fidelity.md).
RESCUE_BELOW = 4e-3
RESCUE_STEP = 0.04
#: The stroke's unit of increment [-]: the first stroke increment FIRST_STEP times it,
#: the largest MAX_STEP times it (:func:`.sealed.solve_stroke`).
STROKE_UNIT = 0.1
#: Newton's tolerance (FElupe's relative residual norm) and iteration limit.
NEWTON_TOL = 1e-7
NEWTON_MAXITER = 25
#: The increment grows by half after a step that took at most this many iterations, and
#: shrinks by a third after one that took more than twice as many (measured: large steps
#: cost more iterations than they save).
EASY_STEP = 4


def linear_solver():
    """The sparse direct solver of Newton's steps: MKL PARDISO through ``pypardiso`` where
    it is installed (the ``fe-fast`` extra; about 20 times faster than SuperLU on the default
    mesh's 6,000 unknowns, measured, and a whole default-mesh ``fe_bend`` 3.4x cheaper in
    CPU, docs/fidelity.md), reusing its fill-reducing analysis while the matrix's pattern
    stays (:class:`PardisoSteps`); else (the ``fe`` extra) scipy's SuperLU (``spsolve``).
    Newton's converged state does not depend on it beyond its tolerance."""
    try:
        import pypardiso
    except ImportError:
        from scipy.sparse.linalg import spsolve
        return spsolve
    if hasattr(pypardiso.PyPardisoSolver, "_call_pardiso"):
        return PardisoSteps(pypardiso.PyPardisoSolver())
    return pypardiso.spsolve


class PardisoSteps:
    """Solve A x = b for a sequence of matrices of one sparsity pattern (Newton's steps):
    the first call analyses (reordering) and factorises (PARDISO phase 13), later calls with
    the same pattern factorise and solve only (phase 23), 0.13 against 0.19 CPU-s a step on
    the default mesh (measured). ``pypardiso``'s own ``spsolve`` analyses every matrix anew;
    its solver's one-call entry is used here, so a ``pypardiso`` without it falls back to
    ``spsolve`` (:func:`linear_solver`)."""

    def __init__(self, solver):
        self.solver = solver
        self.pattern = None

    def __call__(self, A, b):
        import scipy.sparse as sp

        A = sp.csr_matrix(A)
        A.sort_indices()
        pattern = (A.shape, A.indptr.copy(), A.indices.copy())
        same = (self.pattern is not None and self.pattern[0] == pattern[0]
                and np.array_equal(self.pattern[1], pattern[1])
                and np.array_equal(self.pattern[2], pattern[2]))
        self.solver.set_iparm(12, 0)  # A in CSR, not transposed
        self.solver.set_phase(23 if same else 13)
        rhs = np.asfortranarray(np.asarray(b, dtype=float).reshape(A.shape[0], -1))
        self.pattern = None
        previous = self._one_thread()
        try:
            x = self.solver._call_pardiso(A, rhs)
        except Exception as err:  # pypardiso's PyPardisoError: a singular or NaN matrix
            raise RuntimeError(f"PARDISO: {err}") from err
        finally:
            self._threads(previous)
        self.pattern = pattern
        return x.reshape(np.shape(b))

    def _one_thread(self):
        """Keep this thread's MKL calls to one thread; returns what to restore
        (:meth:`_threads`), or None where MKL has no thread-local setting.

        With two threads PARDISO's factorisation gave other last bits on every run (a
        killed verify resumed to another dataset than an uninterrupted one; the same design
        solved twice differed), and it took 258 CPU-s against 141 for a default-mesh
        ``nylonflex fe`` run at about the same wall time (144 against 141 s, this 2-core
        machine): one thread is reproducible and half the CPU. Parallel FE work is one
        solve a process (``verify --workers``), as the kernels' one level of parallelism.
        """
        set_local = getattr(self.solver.libmkl, "MKL_Set_Num_Threads_Local", None)
        if set_local is None:  # pragma: no cover - every MKL since 10.3 has it
            return None
        set_local.argtypes, set_local.restype = [ctypes.c_int], ctypes.c_int
        return set_local(1)

    def _threads(self, previous):
        if previous is not None:
            self.solver.libmkl.MKL_Set_Num_Threads_Local(previous)

    def close(self):
        """Free PARDISO's factorisation and analysis."""
        self.solver.free_memory(everything=True)
        self.pattern = None


class FESolveError(RuntimeError):
    """The FE solve could not reach a pressure (the increment fell below :data:`MIN_STEP`)."""


def _probes(body: BodyMesh):
    pts = body.points
    a, t, b, L = body.radius, body.wall_thickness, body.base_thickness, body.length
    top = b + a + t

    def node(y, z):
        return int(np.argmin(np.hypot(pts[:, 0], pts[:, 1] - y) + np.abs(pts[:, 2] - z)))

    return [(node(0.0, 0.0), node(top, 0.0)), (node(0.0, L), node(top, L))]


def _section_angles(points, values, probes):
    x = points + values
    out = []
    for i0, i1 in probes:
        v = x[i1] - x[i0]
        out.append(np.arctan2(v[2], v[1]))
    return np.array(out)


def _extrapolate(history, p):
    """The predictor at pressure p: the Lagrange polynomial through the last (up to three)
    converged states (p_i, u_i)."""
    if len(history) == 1:
        return history[0][1]
    ps = [h[0] for h in history]
    out = np.zeros_like(history[0][1])
    for i, (pi, ui) in enumerate(history):
        w = 1.0
        for j, pj in enumerate(ps):
            if j != i:
                w *= (p - pj) / (pi - pj)
        out += w * ui
    return out


class Path:
    """One FE body followed along a load parameter: FElupe's state, the last converged
    states (for the predictor), the unwrapped bend angle, and the Newton step.

    ``load_item`` is the item last in Newton's list (the chamber's pressure, or the sealed
    air of :mod:`.sealed`); ``newton_solve`` FElupe's ``solve`` argument where the step is
    not FElupe's own (the sealed chamber's bordered system).
    """

    def __init__(self, body, model, solver, load_item=None, newton_solve=None):
        field, items, pressure, boundaries, (dof0, dof1) = model
        self.body, self.field, self.items = body, field, items
        self.load_item = pressure if load_item is None else load_item
        self.dof0, self.dof1, self.boundaries = dof0, dof1, boundaries
        self.solver, self.newton_solve = solver, newton_solve
        self.u = field[0]  # FElupe may replace u.values: always read it through the field
        # the u-p-J body's cell-wise pressure and volume: restored with the displacement
        # after a failed increment (left at a failed Newton iterate, they sink the next one)
        self.solid = items[0]
        self.saved = self.solid.checkpoint()
        self.probes = _probes(body)
        self.last = _section_angles(body.points, self.u.values, self.probes)
        self.unwrapped = np.zeros(2)
        self.residual = None
        self.restart(0.0)

    def restart(self, value):
        """Start the predictor's history at the current state, at load ``value``."""
        self.history = [(value, self.u.values.copy())]

    def angle(self):
        """The bend angle of the last converged state [rad]."""
        return float(self.unwrapped[1] - self.unwrapped[0])

    def attempt(self, value, set_load):
        """Newton's method at load ``value`` (``set_load(value)`` applies it) from the
        predictor: its iterations, or None where it failed."""
        import felupe as fem

        self.u.values[:] = _extrapolate(self.history, value)
        set_load(value)
        extra = {} if self.newton_solve is None else {"solve": self.newton_solve}
        try:
            res = fem.newtonraphson(items=self.items + [self.load_item], dof1=self.dof1,
                                    dof0=self.dof0, verbose=0, tol=NEWTON_TOL,
                                    maxiter=NEWTON_MAXITER, solver=self.solver,
                                    plugins=[fem.LinesearchPlugin(residual=False)], **extra)
            ok = bool(res.success) and np.all(np.isfinite(self.u.values))
        except (ValueError, RuntimeError, FloatingPointError, np.linalg.LinAlgError):
            # FElupe's NewtonConvergenceError is a ValueError; a NaN matrix fails
            # SuperLU's factorisation with a RuntimeError
            ok = False
        if not ok:
            return None
        self.residual = res.fun
        return res.iterations

    def restore(self):
        """Back to the last converged state."""
        self.solid.restore(self.saved)
        self.u.values[:] = self.history[-1][1]

    def accept(self, value):
        """Record the state just converged at load ``value``."""
        now = _section_angles(self.body.points, self.u.values, self.probes)
        self.unwrapped += np.angle(np.exp(1j * (now - self.last)))
        self.last = now
        self.history = self.history[-2:] + [(value, self.u.values.copy())]
        self.saved = self.solid.checkpoint()


def march(path, targets, set_load, unit, record, *, progress=None, partial=False,
          what="{:.4g} Pa"):
    """Follow ``path`` through the load values ``targets`` (>= the path's current value
    0, any order), calling ``record(index, value)`` at each.

    Increments of at most :data:`MAX_STEP` ``unit`` (the first :data:`FIRST_STEP` unit),
    halved when Newton's method fails, grown after easy steps, every target landed on
    exactly (the module's docstring). Returns the indices of the targets not reached
    (empty unless ``partial``; without it a failure raises :class:`FESolveError`, its
    message the load formatted by ``what``).
    """
    targets = np.asarray(targets, dtype=float)
    order = np.argsort(targets)
    step = FIRST_STEP * unit
    now = 0.0
    rescued = -1.0  # the load a rescue increment was last tried from
    for k, idx in enumerate(order):
        target = targets[idx]
        while now < target:
            nxt = min(target, now + step)
            if target - nxt < 0.25 * step:  # no sliver of a step before a target
                nxt = target
            iterations = path.attempt(nxt, set_load)
            if iterations is None:
                path.restore()
                step *= 0.5
                if step < RESCUE_BELOW * unit and rescued != now:
                    rescued = now  # once from each converged state
                    step = RESCUE_STEP * unit
                    continue
                if step < MIN_STEP * unit:
                    if partial:
                        return order[k:]
                    raise FESolveError(f"the FE solve did not converge at {what.format(nxt)}")
                continue
            path.accept(nxt)
            now = nxt
            if iterations <= EASY_STEP:
                step = min(step * 1.5, MAX_STEP * unit)
            elif iterations > 2 * EASY_STEP:
                step *= 2.0 / 3.0
            if progress is not None:
                progress(now, path.angle(), iterations)
        record(idx, target)
    return order[:0]


def solve_bend(body: BodyMesh, mu, alpha, pressures, *, progress=None, partial=False):
    """Bend angles [rad] of ``body`` at each of ``pressures`` [Pa] (ascending, >= 0).

    ``mu``, ``alpha``: the Ogden set (nylonflex's convention) [Pa], [-]. ``progress`` is
    called as ``progress(p, angle, iterations)`` after every converged increment. Returns an array of
    the angles, in the order of ``pressures``. Raises :class:`FESolveError` when an
    increment cannot converge; with ``partial`` the pressures not reached get NaN instead
    (the solve stalls at large bends; docs/fidelity.md).
    """
    return solve_pressures(body, mu, alpha, pressures, progress=progress,
                           partial=partial)["bend_angle"]


def solve_pressures(body: BodyMesh, mu, alpha, pressures, *, progress=None, partial=False,
                    blocked=False, stroke=0.0):
    """:func:`solve_bend`'s states as a dict of arrays in the order of ``pressures``:
    ``bend_angle`` [rad], ``volume_ratio`` V/V0 of the chamber [-] and, with ``blocked`` (the tip held straight), ``tip_moment``
    [N m] (:func:`.sealed.tip_moment`, the whole body's). With ``stroke`` s > 0 the wrap
    is first shortened to its rest length 1 - s with the chamber vented (p = 0), then the
    pressures are imposed at that wrap length. NaN where not reached (``partial``)."""
    targets = np.asarray(pressures, dtype=float)
    model = build_model(body, mu, alpha, blocked=blocked)
    mu0 = float(sum(felupe_ogden(mu, alpha)[0]))
    solver = linear_solver()
    out = {"bend_angle": np.full(len(targets), np.nan),
           "volume_ratio": np.full(len(targets), np.nan)}
    volume0 = chamber_volume(model[2], body.points)
    if blocked:
        out["tip_moment"] = np.full(len(targets), np.nan)
    try:
        path = Path(body, model, solver)
        if stroke > 0:
            wraps = [path.items[i].umat for i in WRAP_ITEMS]

            def shorten(s):
                for w in wraps:
                    w.rest_length = 1.0 - s
            if len(march(path, [stroke], shorten, STROKE_UNIT, lambda i, v: None,
                         partial=partial, what="stroke {:.4g}")):
                return out
            path.restart(0.0)

        def record(idx, target):
            out["bend_angle"][idx] = path.angle() if target > 0 or stroke > 0 else 0.0
            path.load_item.field.link(path.field)
            out["volume_ratio"][idx] = chamber_volume(path.load_item, body.points) / volume0
            if blocked:
                out["tip_moment"][idx] = tip_moment(path)

        march(path, targets, path.load_item.update, mu0, record, progress=progress,
              partial=partial)
    finally:
        if hasattr(solver, "close"):
            solver.close()
    return out
