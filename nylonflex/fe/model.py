"""The FE twin's model: FElupe bodies, loads and boundary conditions on a :class:`BodyMesh`.

- **Silicone**: the Ogden set in FElupe's convention (:func:`felupe_ogden`) on every cell
  (FElupe's ``ogden`` energy with a hand-written tangent, :mod:`.ogden`), nearly incompressible (the distortional part in the set's constants, a volumetric penalty
  of bulk modulus ``BULK_RATIO`` mu0 on cell-wise constant pressure and volume fields: u-p-J
  hexahedra, FElupe's :class:`~felupe.SolidBodyNearlyIncompressible`).
- **Strain-limiting layer**: a skin of fibres along z in the bottom cell layer, of axial
  stiffness per width ``SKIN_RATIO`` mu0 (a + t + b): it holds y = 0 at its length, the
  neutral axis of docs/model.md s. 6.
- **Wrap**: the muscle's turns smeared into a hoop layer (fibres along the outer contour's
  tangent in the section plane, in the outermost cells of the wall and of the floor's side,
  plus along x in the skin), of hoop stiffness per length ``WRAP_RATIO`` mu0 (a + t): it
  holds the outer contour, as the paper's wrap of fixed length does at a given stroke.
- **Load**: the chamber's gauge pressure on its walls, floor and the caps' inner faces, a
  follower load (per deformed area, along the deformed normal).
- **Supports**: the symmetry plane x = 0, and the base cap's outer face z = -t clamped.
"""

from __future__ import annotations

import numpy as np

from .mesh import BodyMesh
from .ogden import OgdenIsochoric

__all__ = ["BULK_RATIO", "SKIN_RATIO", "WRAP_RATIO", "FibreMaterial", "build_model",
           "element", "felupe_ogden"]

#: Bulk modulus of the volumetric penalty over the initial shear modulus (Poisson's ratio
#: 0.4999 at 5000).
BULK_RATIO = 5000.0
#: Axial stiffness per width of the strain-limiting skin, over mu0 times the section's
#: height a + t + b [-], about 30 times the silicone's own. Stiffer skins and wraps barely
#: move the angle (100 against 1000: under 1 %, docs/fidelity.md) but make Newton's method
#: wander through large rotations.
SKIN_RATIO = 100.0
#: Hoop stiffness per length of the smeared wrap over mu0 (a + t) [-].
WRAP_RATIO = 100.0


def felupe_ogden(mu, alpha):
    """The Ogden constants in FElupe's convention.

    nylonflex (the paper's eq. 5) writes W = sum mu_i / alpha_i (sum_k l_k^alpha_i - 3);
    FElupe writes W = sum 2 mu_i' / alpha_i^2 (sum_k l_k^alpha_i - 3), so
    mu_i' = mu_i alpha_i / 2 [Pa] (and sum mu_i' is the initial shear modulus mu0).
    """
    mu = np.asarray(mu, dtype=float)
    alpha = np.asarray(alpha, dtype=float)
    return [float(m) for m in mu * alpha / 2.0], [float(a) for a in alpha]


class FibreMaterial:
    """Fibres of one direction per cell: W = k/4 (I4 - 1)^2 with I4 = a.C.a [J/m^3].

    ``stiffness`` k [Pa] per cell (the fibre modulus at small strain is 2 k) and
    ``direction`` (cells, 3) unit vectors in the reference configuration. Tension and
    compression alike: the skin and the wrap hold their length (docs/fidelity.md).
    Implements FElupe's material interface (``gradient``, ``hessian``).
    """

    def __init__(self, stiffness, direction):
        self.k = np.asarray(stiffness, dtype=float)
        self.a = np.asarray(direction, dtype=float).T[:, None, :]  # (3, 1, cells)
        self.x = [np.eye(3), np.zeros(0)]

    def _parts(self, F):
        fa = np.einsum("iJqc,Jqc->iqc", F, np.broadcast_to(self.a, (3,) + F.shape[2:]))
        i4 = np.einsum("iqc,iqc->qc", fa, fa)
        return fa, i4

    def gradient(self, x):
        F, statevars = x[0], x[-1]
        fa, i4 = self._parts(F)
        a = np.broadcast_to(self.a, (3,) + F.shape[2:])
        P = np.einsum("qc,iqc,Jqc->iJqc", self.k * (i4 - 1.0), fa, a)
        return [P, statevars]

    def hessian(self, x):
        F = x[0]
        fa, i4 = self._parts(F)
        a = np.broadcast_to(self.a, (3,) + F.shape[2:])
        eye = np.eye(3)
        A = np.einsum("qc,ik,Jqc,Lqc->iJkLqc", self.k * (i4 - 1.0), eye, a, a)
        A += np.einsum("qc,iqc,Jqc,kqc,Lqc->iJkLqc", 2.0 * self.k * np.ones_like(i4), fa, a,
                       fa, a)
        return [A]


def element(cells):
    """FElupe's cell type, region and boundary region of hexahedral ``cells`` (m, 8) or
    (m, 20): 8-node hexahedra (2 x 2 x 2 Gauss points) or 20-node serendipity ones
    (3 x 3 x 3)."""
    import felupe as fem

    if np.shape(cells)[1] == 20:
        return ("hexahedron20", fem.RegionQuadraticHexahedron,
                fem.RegionQuadraticHexahedronBoundary)
    return "hexahedron", fem.RegionHexahedron, fem.RegionHexahedronBoundary


def build_model(body: BodyMesh, mu, alpha):
    """FElupe items of the body: (field, items, pressure item, boundaries, dof sets).

    ``mu``, ``alpha``: the Ogden set in nylonflex's convention [Pa], [-].
    """
    import felupe as fem

    a, t, b = body.radius, body.wall_thickness, body.base_thickness
    mu_f, alpha_f = felupe_ogden(mu, alpha)
    mu0 = float(sum(mu_f))
    kind, Region, Boundary = element(body.cells)
    mesh = fem.Mesh(body.points, body.cells, kind)
    region = Region(mesh)
    field = fem.FieldContainer([fem.Field(region, dim=3)])
    silicone = OgdenIsochoric(mu_f, alpha_f)
    items = [fem.SolidBodyNearlyIncompressible(silicone, field, bulk=BULK_RATIO * mu0)]
    # fibres: the skin (axial and across) and the wrap (hoop)
    skin_k = 0.5 * SKIN_RATIO * mu0 * (a + t + b) / body.skin_thickness
    wrap_k = 0.5 * WRAP_RATIO * mu0 * (a + t) / body.wrap_thickness
    n_skin = len(body.skin)
    for cells, k, direction in (
            (body.skin, np.full(n_skin, skin_k), np.tile([0.0, 0.0, 1.0], (n_skin, 1))),
            (body.skin, np.full(n_skin, 0.5 * WRAP_RATIO * mu0 * (a + t) / body.skin_thickness),
             np.tile([1.0, 0.0, 0.0], (n_skin, 1))),
            (body.wrap, wrap_k, body.wrap_direction)):
        sub = fem.Mesh(body.points, body.cells[cells], kind)
        sub_field = fem.FieldContainer([fem.Field(Region(sub), dim=3)])
        sub_field.link(field)
        items.append(fem.SolidBody(FibreMaterial(k, direction), sub_field))
    boundary = Boundary(mesh, only_surface=True, mask=body.chamber)
    pressure = fem.SolidBodyPressure(fem.FieldContainer([fem.Field(boundary, dim=3)]))
    pressure.field.link(field)
    x, z = body.points[:, 0], body.points[:, 2]
    tol = 1e-9 * (a + t + b + body.length)
    boundaries = {
        "symmetry": fem.Boundary(field[0], mask=np.abs(x) < tol, skip=(0, 1, 1)),
        "clamp": fem.Boundary(field[0], mask=np.abs(z + t) < tol),
    }
    dof0, dof1 = fem.dof.partition(field, boundaries)
    return field, items, pressure, boundaries, (dof0, dof1)
