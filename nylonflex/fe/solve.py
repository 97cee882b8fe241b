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

import numpy as np

from .mesh import BodyMesh
from .model import build_model, felupe_ogden

__all__ = ["MAX_STEP", "FESolveError", "solve_bend"]

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
        try:
            x = self.solver._call_pardiso(A, rhs)
        except Exception as err:  # pypardiso's PyPardisoError: a singular or NaN matrix
            raise RuntimeError(f"PARDISO: {err}") from err
        self.pattern = pattern
        return x.reshape(np.shape(b))

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


def solve_bend(body: BodyMesh, mu, alpha, pressures, *, progress=None, partial=False):
    """Bend angles [rad] of ``body`` at each of ``pressures`` [Pa] (ascending, >= 0).

    ``mu``, ``alpha``: the Ogden set (nylonflex's convention) [Pa], [-]. ``progress`` is
    called as ``progress(p, angle, iterations)`` after every converged increment. Returns an array of
    the angles, in the order of ``pressures``. Raises :class:`FESolveError` when an
    increment cannot converge; with ``partial`` the pressures not reached get NaN instead
    (the solve stalls at large bends; docs/fidelity.md).
    """
    targets = np.asarray(pressures, dtype=float)
    order = np.argsort(targets)
    field, items, pressure, _, (dof0, dof1) = build_model(body, mu, alpha)
    mu0 = float(sum(felupe_ogden(mu, alpha)[0]))
    probes = _probes(body)
    solver = linear_solver()
    try:
        return _increments(body, field, items, pressure, dof0, dof1, mu0, probes, solver,
                           targets, order, progress, partial)
    finally:
        if hasattr(solver, "close"):
            solver.close()


def _increments(body, field, items, pressure, dof0, dof1, mu0, probes, solver, targets,
                order, progress, partial):
    import felupe as fem

    u = field[0]  # FElupe may replace u.values: always read it through the field
    history = [(0.0, u.values.copy())]
    # the u-p-J body's cell-wise pressure and volume: restored with the displacement after
    # a failed increment (left at a failed Newton iterate, they sink the next attempt)
    solid = items[0]
    saved = solid.checkpoint()
    last = _section_angles(body.points, u.values, probes)
    unwrapped = np.zeros(2)
    angles = np.empty(len(targets))
    step = FIRST_STEP * mu0
    p_now = 0.0
    rescued = -1.0  # the pressure a rescue increment was last tried from
    for idx in order:
        target = targets[idx]
        while p_now < target:
            p_next = min(target, p_now + step)
            if target - p_next < 0.25 * step:  # no sliver of a step before a target
                p_next = target
            u.values[:] = _extrapolate(history, p_next)
            pressure.update(p_next)
            try:
                res = fem.newtonraphson(items=items + [pressure], dof1=dof1, dof0=dof0,
                                        verbose=0, tol=NEWTON_TOL, maxiter=NEWTON_MAXITER,
                                        solver=solver,
                                        plugins=[fem.LinesearchPlugin(residual=False)])
                ok = bool(res.success) and np.all(np.isfinite(u.values))
            except (ValueError, RuntimeError, FloatingPointError, np.linalg.LinAlgError):
                # FElupe's NewtonConvergenceError is a ValueError; a NaN matrix fails
                # SuperLU's factorisation with a RuntimeError
                ok = False
            if not ok:
                solid.restore(saved)
                u.values[:] = history[-1][1]
                step *= 0.5
                if step < RESCUE_BELOW * mu0 and rescued != p_now:
                    rescued = p_now  # once from each converged state
                    step = RESCUE_STEP * mu0
                    continue
                if step < MIN_STEP * mu0:
                    if partial:
                        angles[order[np.searchsorted(targets[order], target):]] = np.nan
                        return angles
                    raise FESolveError(f"the FE solve did not converge at {p_next:.4g} Pa")
                continue
            now = _section_angles(body.points, u.values, probes)
            unwrapped += np.angle(np.exp(1j * (now - last)))
            last = now
            p_now = p_next
            history = history[-2:] + [(p_now, u.values.copy())]
            saved = solid.checkpoint()
            if res.iterations <= EASY_STEP:
                step = min(step * 1.5, MAX_STEP * mu0)
            elif res.iterations > 2 * EASY_STEP:
                step *= 2.0 / 3.0
            if progress is not None:
                progress(p_now, float(unwrapped[1] - unwrapped[0]), res.iterations)
        angles[idx] = unwrapped[1] - unwrapped[0] if target > 0 else 0.0
    return angles
