"""The FE twin driven as built: the wrap shortened by the muscle's stroke, the chamber sealed.

The muscle's stroke s shortens the smeared wrap (the hoop fibres and the skin's fibres
across) to a rest length 1 - s (:class:`.model.FibreMaterial`'s ``rest_length``); the
fibres are bonded to the outer cells, so the wrap does not slide on the silicone. The air
in the chamber is sealed: Boyle's law, isothermal, with an optional fixed temperature rise
dT of the air,

    (p0 + p) V = p0 V0 (T0 + dT) / T0,

p0 = :data:`~nylonflex.physics.chamber.P_ATM`, T0 the nylon set's ambient. The cavity's
volume of the half model is V/2 = -int x n_x dA over the chamber's surface (n the solid's
outward normal, the deformed one; the symmetry plane x = 0 adds nothing), exact for the
hexahedra's bilinear faces with their 2 x 2 Gauss points, and its derivative with respect
to the nodes is the pressure's load per unit pressure, g. The pressure is a function of
the displacement, p(V(u)), at every Newton iterate, so Boyle's law holds exactly at each;
its tangent adds the rank-one air stiffness (p0 + p)/(V/2) g g^T, solved as a bordered
system (one extra unknown, one sparse solve) that stays regular through the limit point
of the chamber's imposed-pressure curve.
"""

from __future__ import annotations

import numpy as np

from .mesh import BodyMesh
from .measures import chamber_volume, tip_moment
from .model import WRAP_ITEMS, build_model
from .solve import STROKE_UNIT, Path, linear_solver, march

__all__ = ["HEATING_UNIT", "SealedChamber", "solve_stroke"]

#: The heating's unit of increment (a fraction of the air's temperature rise) [-].
HEATING_UNIT = 5.0


class SealedChamber:
    """The sealed air as a FElupe item: the chamber's pressure item with its pressure
    set, at every evaluation, from the cavity's volume by Boyle's law.

    ``pressure_item``: :func:`.model.build_model`'s chamber pressure; ``points`` the
    body's nodes [m]; ``p_atm`` [Pa]; ``heating`` (T0 + dT)/T0 [-] (settable). After an
    evaluation: ``pressure`` [Pa], ``volume`` (half model) [m^3], ``load`` g = dV/du
    (half model, all dofs) [m^2], ``stiffness`` (p0 + p)/(V/2) [Pa/m^3].
    """

    def __init__(self, pressure_item, points, p_atm, heating=1.0):
        self.item, self.points, self.p_atm, self.heating = pressure_item, points, p_atm, heating
        self.field = pressure_item.field
        self.results = pressure_item.results
        self.assemble = _Assemble(self._vector, self._matrix)
        self.volume0 = chamber_volume(pressure_item, points)
        self.pressure, self.volume, self.load, self.stiffness = 0.0, self.volume0, None, 0.0

    def _boyle(self):
        """The volume of the item's current state, and its pressure by Boyle's law."""
        self.volume = chamber_volume(self.item, self.points)
        self.pressure = self.p_atm * (self.heating * self.volume0 / self.volume - 1.0)

    def settle(self, field):
        """Volume and pressure of the state ``field`` (the body's field container)."""
        self.item.field.link(field)
        self._boyle()

    def _vector(self, field=None, **kwargs):
        g = self.item.assemble.vector(field=field, pressure=1.0, **kwargs)
        self._boyle()
        self.stiffness = (self.p_atm + self.pressure) / self.volume
        self.load = np.asarray(g.toarray()).ravel()
        self.item.update(self.pressure)
        return g * self.pressure

    def _matrix(self, field=None, **kwargs):
        return self.item.assemble.matrix(field=field, pressure=self.pressure, **kwargs)

    def newton_solve(self, dofs):
        """FElupe's ``solve`` for Newton's steps with the air's rank-one stiffness:
        (K + k g g^T) du = -f as the bordered system [[K, s g], [s g^T, -s^2/k]] over the
        active dofs and the chamber's (a fixed pattern for the solver's analysis).
        ``dofs``: the chamber's dofs (all three components of its nodes)."""
        import felupe as fem
        import scipy.sparse as sp

        def solve(A, b, x, dof1, dof0, solver):
            u, u0, K11, _, dof1, dof0, r1 = fem.solve.partition(x, A, dof1, dof0, b)
            n = len(dof1)
            pos = np.searchsorted(dof1, dofs)
            pos = pos[(pos < n) & (dof1[np.minimum(pos, n - 1)] == dofs)]
            g1 = self.load[dof1[pos]]
            diag = float(np.mean(np.abs(K11.diagonal())))
            k = self.stiffness
            s = np.sqrt(k * diag)  # scales the border like the matrix's diagonal
            col = sp.csr_matrix((s * g1, (pos, np.zeros(len(pos), dtype=int))), shape=(n, 1))
            M = sp.bmat([[K11, col], [col.T, sp.csr_matrix([[-s * s / k]])]], format="csr")
            sol = solver(M, np.append(r1, 0.0))
            du = np.empty(u.size)
            du[dof1] = sol[:n]
            du[dof0] = -u0
            return du.reshape(u.shape)

        return solve


class _Assemble:
    """FElupe's item interface: ``vector``, ``matrix`` and the sign they enter with."""

    def __init__(self, vector, matrix):
        self.vector, self.matrix, self.multiplier, self.mass = vector, matrix, -1.0, None


def solve_stroke(body: BodyMesh, mu, alpha, strokes, *, p_atm, heating=1.0, blocked=False,
                 progress=None, partial=False, inspect=None):
    """States of the sealed body at each of ``strokes`` (any order, each in [0, 1)).

    ``mu``, ``alpha``: the Ogden set (nylonflex's convention) [Pa], [-]; ``p_atm`` the
    air's initial absolute pressure [Pa]; ``heating`` (T0 + dT)/T0 >= 1 [-], applied at
    zero stroke first (the air warmed, sealed, before the wrap contracts). Returns arrays
    in the order of ``strokes``: ``pressure`` [Pa], ``volume_ratio`` V/V0 [-],
    ``bend_angle`` [rad] and, with ``blocked``, ``tip_moment`` [N m]; NaN where not
    reached (``partial``; else :class:`.solve.FESolveError`). ``inspect(index,
    displacement)`` is called at each stroke reached with the nodes' displacement (n, 3)
    [m] (for checks against the deformed mesh).
    """
    targets = np.asarray(strokes, dtype=float)
    model = build_model(body, mu, alpha, blocked=blocked)
    field, items, pressure, _, (dof0, dof1) = model
    air = SealedChamber(pressure, body.points, p_atm)
    nodes = np.flatnonzero(body.chamber)
    dofs = np.sort((3 * nodes[:, None] + np.arange(3)).ravel())
    solver = linear_solver()
    names = ["pressure", "volume_ratio", "bend_angle"] + (["tip_moment"] if blocked else [])
    out = {n: np.full(len(targets), np.nan) for n in names}
    wraps = [items[i].umat for i in WRAP_ITEMS]

    def shorten(s):
        for w in wraps:
            w.rest_length = 1.0 - s

    def record(idx, target):
        air.settle(field)
        out["pressure"][idx] = air.pressure
        out["volume_ratio"][idx] = air.volume / air.volume0
        out["bend_angle"][idx] = path.angle()
        if blocked:
            out["tip_moment"][idx] = tip_moment(path)
        if inspect is not None:
            inspect(idx, path.u.values.copy())

    try:
        path = Path(body, model, solver, load_item=air, newton_solve=air.newton_solve(dofs))
        if heating != 1.0:
            def heat(h):
                air.heating = 1.0 + h * (heating - 1.0)
            if len(march(path, [1.0], heat, HEATING_UNIT, lambda i, v: None,
                         partial=partial, what="heating {:.4g}")):
                return out
            path.restart(0.0)
        march(path, targets, shorten, STROKE_UNIT, record, progress=progress,
              partial=partial, what="stroke {:.4g}")
    finally:
        if hasattr(solver, "close"):
            solver.close()
    return out
