"""The FE twin's model: FElupe bodies, loads and boundary conditions on a :class:`BodyMesh`.

- **Silicone**: the Ogden set in FElupe's convention (:func:`felupe_ogden`) on every cell
  (FElupe's ``ogden`` energy with a hand-written tangent, :mod:`.ogden`), nearly incompressible (the distortional part in the set's constants, a volumetric penalty
  of bulk modulus ``BULK_RATIO`` mu0 on cell-wise constant pressure and volume fields: u-p-J
  hexahedra, FElupe's :class:`~felupe.SolidBodyNearlyIncompressible`).
- **Strain-limiting layer**: a skin of fibres along z in the bottom cell layer, of axial
  stiffness per width ``SKIN_RATIO`` mu0 (a + t + b): it holds y = 0 at its length, the
  neutral axis of docs/model.md s. 6. Like paper or fabric, it gives way in compression
  (``COMPRESSION_RATIO``).
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

__all__ = ["BULK_RATIO", "COMPRESSION_RATIO", "SKIN_RATIO", "WRAP_ITEMS", "WRAP_RATIO",
           "FibreMaterial", "build_model", "element", "felupe_ogden", "model_settings"]

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
#: The strain-limiting skin's axial stiffness in compression over its stiffness in
#: tension [-]. A sheet of paper or fabric holds its length in tension and buckles out of
#: the way in compression. A skin that carried compression as well was a stiff film on a
#: soft body, which wrinkled at a wavelength set by the mesh, so that refining the mesh
#: kept softening large bends (docs/fidelity.md, "Closing the 10 kPa gap"). Zero: the
#: angle converges to it as the ratio falls (0.1, 0.01 and 0.001 give 13, 3.6 and 0.5 %
#: less at 10 kPa on the paper's example 2), and the silicone of the skin's cells still
#: gives a slack skin a tangent. The wrap (and the skin's fibres across) hold their length
#: both ways: the section's contour, which the paper's balance takes as fixed (plane
#: strain across the wall).
COMPRESSION_RATIO = 0.0


def model_settings() -> dict:
    """The FE model's constants (JSON-able): a run folder's plan and a result's provenance
    hold them, so that runs of another version of the model are never mixed in."""
    return {"bulk_ratio": BULK_RATIO, "skin_ratio": SKIN_RATIO, "wrap_ratio": WRAP_RATIO,
            "compression_ratio": COMPRESSION_RATIO}


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

    ``stiffness`` k [Pa] per cell (the fibre modulus at small strain is 2 k) in tension
    (I4 > 1), ``compression`` times k in compression (I4 < 1; W and its first derivative
    are continuous at I4 = 1), and ``direction`` (cells, 3) unit vectors in the reference
    configuration. Implements FElupe's material interface (``gradient``, ``hessian``).

    ``rest_length`` (an attribute, 1 by default) is the fibres' rest length over their
    length in the reference configuration [-]: the direction enters as a / rest_length,
    so I4 = a.C.a / rest_length^2 is the squared stretch over the rest length. The wrap's
    contraction by a muscle stroke s is a rest length 1 - s (:func:`.sealed.solve_stroke`).
    """

    def __init__(self, stiffness, direction, compression=1.0):
        if not 0.0 <= compression <= 1.0:
            raise ValueError(f"compression must be in [0, 1], got {compression!r}")
        self.compression = float(compression)
        self.k = np.asarray(stiffness, dtype=float)
        self.direction = np.asarray(direction, dtype=float).T[:, None, :]  # (3, 1, cells)
        self.rest_length = 1.0
        self.x = [np.eye(3), np.zeros(0)]

    @property
    def a(self):
        """The reference direction over the rest length, (3, 1, cells) [-]."""
        if self.rest_length == 1.0:
            return self.direction
        return self.direction / self.rest_length

    def _parts(self, F):
        fa = np.einsum("iJqc,Jqc->iqc", F, np.broadcast_to(self.a, (3,) + F.shape[2:]))
        i4 = np.einsum("iqc,iqc->qc", fa, fa)
        return fa, i4

    def _stiffness(self, i4):
        """k where the fibre is stretched, ``compression`` k where it is shortened [Pa]."""
        return self.k * np.where(i4 < 1.0, self.compression, 1.0)

    def gradient(self, x):
        F, statevars = x[0], x[-1]
        fa, i4 = self._parts(F)
        a = np.broadcast_to(self.a, (3,) + F.shape[2:])
        P = np.einsum("qc,iqc,Jqc->iJqc", self._stiffness(i4) * (i4 - 1.0), fa, a)
        return [P, statevars]

    def hessian(self, x):
        F = x[0]
        fa, i4 = self._parts(F)
        a = np.broadcast_to(self.a, (3,) + F.shape[2:])
        eye = np.eye(3)
        k = self._stiffness(i4)
        A = np.einsum("qc,ik,Jqc,Lqc->iJkLqc", k * (i4 - 1.0), eye, a, a)
        A += np.einsum("qc,iqc,Jqc,kqc,Lqc->iJkLqc", 2.0 * k, fa, a, fa, a)
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


#: Indices in :func:`build_model`'s items of the fibres the muscle's turns make: the skin's
#: fibres across (the wrap passing under the skin) and the wrap's hoop fibres.
WRAP_ITEMS = (2, 3)


def build_model(body: BodyMesh, mu, alpha, *, blocked=False):
    """FElupe items of the body: (field, items, pressure item, boundaries, dof sets).

    ``mu``, ``alpha``: the Ogden set in nylonflex's convention [Pa], [-]. The items are
    the silicone, the skin's fibres along z, the skin's fibres across and the wrap
    (:data:`WRAP_ITEMS`). With ``blocked`` the tip cap's outer face z = L + t is clamped
    too (boundary "tip"): the actuator held straight, as in the paper's force test.
    """
    import felupe as fem

    from .ogden import OgdenIsochoric  # compiled with Numba: not for the light commands,
    # which read model_settings() through fe.verify (nylonflex info)

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
    for cells, k, direction, compression in (
            (body.skin, np.full(n_skin, skin_k), np.tile([0.0, 0.0, 1.0], (n_skin, 1)),
             COMPRESSION_RATIO),
            (body.skin, np.full(n_skin, 0.5 * WRAP_RATIO * mu0 * (a + t) / body.skin_thickness),
             np.tile([1.0, 0.0, 0.0], (n_skin, 1)), 1.0),
            (body.wrap, wrap_k, body.wrap_direction, 1.0)):
        sub = fem.Mesh(body.points, body.cells[cells], kind)
        sub_field = fem.FieldContainer([fem.Field(Region(sub), dim=3)])
        sub_field.link(field)
        items.append(fem.SolidBody(FibreMaterial(k, direction, compression), sub_field))
    boundary = Boundary(mesh, only_surface=True, mask=body.chamber)
    pressure = fem.SolidBodyPressure(fem.FieldContainer([fem.Field(boundary, dim=3)]))
    pressure.field.link(field)
    x, z = body.points[:, 0], body.points[:, 2]
    tol = 1e-9 * (a + t + b + body.length)
    boundaries = {
        "symmetry": fem.Boundary(field[0], mask=np.abs(x) < tol, skip=(0, 1, 1)),
        "clamp": fem.Boundary(field[0], mask=np.abs(z + t) < tol),
    }
    if blocked:
        boundaries["tip"] = fem.Boundary(field[0], mask=np.abs(z - body.length - t) < tol)
    dof0, dof1 = fem.dof.partition(field, boundaries)
    return field, items, pressure, boundaries, (dof0, dof1)
