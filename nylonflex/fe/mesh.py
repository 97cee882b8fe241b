"""The actuator's body as a hexahedral mesh (half model, x >= 0), in plain NumPy.

Coordinates [m]: ``x`` across the width (the symmetry plane is x = 0), ``y`` up from the
bottom face (the strain-limiting layer, y = 0), ``z`` along the actuator (the chamber runs
from z = 0 to z = L; the end caps, of thickness ``t``, fill z in [-t, 0] and [L, L + t]).
The section is that of docs/model.md s. 1: a floor 0 <= y <= b across the full width
|x| <= a + t, and a half-annular wall a <= r <= a + t about (0, b). The chamber r < a,
y > b is void between the caps and filled with silicone inside them (an O-grid quarter disc
whose nodes meet the wall's and the floor's).

Every function here returns values; nothing needs FElupe, so the mesh is tested alone.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["MESHES", "BodyMesh", "MeshSize", "body_mesh"]


@dataclass(frozen=True)
class MeshSize:
    """Divisions of a mesh level: ``wall`` through the wall thickness, ``arc`` along the
    quarter arc (even), ``base`` through the floor (above its skin layer), ``axial`` per
    characteristic length along the chamber (see :func:`body_mesh`), ``cap`` through each
    end cap; ``order`` the elements' (1: 8-node hexahedra, 2: 20-node serendipity
    hexahedra, their edges' midpoints on the arcs)."""

    wall: int
    arc: int
    base: int
    axial: int
    cap: int
    order: int = 1


#: The mesh levels, coarse to fine; each refines the previous one by about 1.5 in every
#: direction (docs/fidelity.md: the convergence study).
MESHES = {
    "rough": MeshSize(wall=1, arc=4, base=1, axial=5, cap=1),  # the coarse level's error estimate
    "coarse": MeshSize(wall=2, arc=6, base=2, axial=8, cap=1),
    "default": MeshSize(wall=3, arc=10, base=3, axial=12, cap=2),
    "fine": MeshSize(wall=5, arc=14, base=4, axial=18, cap=2),
}

#: Refinement ratio between successive levels (for the Richardson estimate).
REFINEMENT = 1.5

#: Thickness of the skin (strain-limiting) layer and of the wrap layer, as a fraction of the
#: smallest element size: thin layers of their own, whose stiffness is given per unit area
#: (a membrane's), so that neither adds bending stiffness of its own.
SKIN_FRACTION = 0.05


@dataclass(frozen=True)
class BodyMesh:
    """A hexahedral mesh of the body and the sets the FE model needs.

    ``points`` (n, 3) [m], ``cells`` (m, 8) hexahedra or (m, 20) quadratic ones (the
    corners first, then the edges' midpoints, :data:`HEX_EDGES`); ``skin`` and ``wrap`` are the cell
    indices of the strain-limiting layer (y < skin thickness) and of the wrap layer (the
    outermost cells of the wall and of the floor's side), ``wrap_direction`` (len(wrap), 3)
    the unit hoop direction of each wrap cell, ``skin_thickness`` and ``wrap_thickness``
    the thickness of those layers [m] (per cell for the wrap); ``chamber`` a point mask of
    the chamber's surface (wall, floor and the caps' inner faces).
    """

    points: np.ndarray
    cells: np.ndarray
    skin: np.ndarray
    skin_thickness: float
    wrap: np.ndarray
    wrap_direction: np.ndarray
    wrap_thickness: np.ndarray
    chamber: np.ndarray
    radius: float
    wall_thickness: float
    base_thickness: float
    length: float


def _grid(xs, ys):
    """Points (n, 2) and counter-clockwise quads of the tensor grid xs x ys."""
    nx, ny = len(xs), len(ys)
    pts = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    i, j = i.ravel(), j.ravel()
    k = i * ny + j
    quads = np.stack([k, k + ny, k + ny + 1, k + 1], -1)
    return pts, quads


def _mapped(corners_fn, nu, nv):
    """Points and quads of a patch mapped from the unit square by ``corners_fn(u, v)``."""
    u, v = np.meshgrid(np.linspace(0, 1, nu + 1), np.linspace(0, 1, nv + 1), indexing="ij")
    pts = corners_fn(u.ravel(), v.ravel())
    _, quads = _grid(np.arange(nu + 1.0), np.arange(nv + 1.0))
    return pts, quads


def _section(a, t, b, size: MeshSize, skin):
    # ``skin`` is also the thickness of the wrap layer, outside r = a + t - skin
    """The 2-D pieces of the half section: (points, quads, kind) for the body (floor and
    wall, kind 0 floor, 1 wall) and for the chamber's fill (the caps)."""
    m = size.arc // 2
    c = 0.5 * a
    k_r = max(1, int(round(size.arc / 4)))  # radial cells of the O-grid's outer ring
    r_out = a + t
    walls = np.concatenate([np.linspace(a, r_out - skin, size.wall + 1), [r_out]])
    xs = np.concatenate([np.linspace(0, c, m + 1), np.linspace(c, a, k_r + 1)[1:], walls[1:]])
    ys = np.concatenate([[0.0], np.linspace(skin, b, size.base + 1)])
    floor_pts, floor_q = _grid(xs, ys)
    radii = walls
    phis = np.linspace(0, 0.5 * np.pi, size.arc + 1)
    rr, pp = np.meshgrid(radii, phis, indexing="ij")
    wall_pts = np.stack([rr * np.cos(pp), b + rr * np.sin(pp)], -1).reshape(-1, 2)
    _, wall_q = _grid(radii, phis)
    # the chamber's fill: an O-grid (inner square and two curved patches)
    sq_pts, sq_q = _grid(np.linspace(0, c, m + 1), b + np.linspace(0, c, m + 1))

    def right(u, v):  # square's right edge (x = c) to the arc phi in [0, pi/4]
        phi = 0.25 * np.pi * v
        edge = np.stack([np.full_like(v, c), b + c * v], -1)
        arc = np.stack([a * np.cos(phi), b + a * np.sin(phi)], -1)
        return edge + u[:, None] * (arc - edge)

    def top(u, v):  # the arc phi in [pi/4, pi/2] down to the square's top edge (y = b + c)
        phi = 0.25 * np.pi * (1.0 + u)
        edge = np.stack([c * (1.0 - u), np.full_like(u, b + c)], -1)
        arc = np.stack([a * np.cos(phi), b + a * np.sin(phi)], -1)
        return edge + v[:, None] * (arc - edge)

    pa, qa = _mapped(right, k_r, m)
    pb, qb = _mapped(top, m, k_r)
    # orient every quad counter-clockwise
    fill = [(sq_pts, sq_q), (pa, qa), (pb, qb)]
    fill = [(p, _ccw(p, q)) for p, q in fill]
    body = [(floor_pts, _ccw(floor_pts, floor_q), 0), (wall_pts, _ccw(wall_pts, wall_q), 1)]
    return body, fill


def _ccw(pts, quads):
    x, y = pts[quads, 0], pts[quads, 1]
    area = 0.5 * np.sum(x * np.roll(y, -1, 1) - np.roll(x, -1, 1) * y, axis=1)
    quads = quads.copy()
    quads[area < 0] = quads[area < 0][:, ::-1]
    return quads


def _extrude(pts, quads, zs):
    """Hexahedra (points (n, 3), cells (m, 8)) of quads extruded through the z nodes zs."""
    n = len(pts)
    p3 = np.concatenate([np.column_stack([pts, np.full(n, z)]) for z in zs])
    cells = [np.concatenate([quads + i * n, quads + (i + 1) * n], 1) for i in range(len(zs) - 1)]
    return p3, np.concatenate(cells)


def body_mesh(radius, wall_thickness, length, *, base_thickness=None, mesh="default"):
    """The body of a design as a hexahedral half mesh (see the module's docstring).

    Parameters
    ----------
    radius, wall_thickness, length : float
        a, t, L [m].
    base_thickness : float, optional
        b [m]; the wall thickness when None (docs/model.md s. 1).
    mesh : str or MeshSize
        A level of :data:`MESHES` or the divisions themselves. Along the chamber the
        number of cells is ``axial`` times max(1, L / (4 (a + t + b)) ) ** 0.5 rounded up:
        long, slender actuators get more.
    """
    a, t, L = float(radius), float(wall_thickness), float(length)
    b = t if base_thickness is None else float(base_thickness)
    size = MESHES[mesh] if isinstance(mesh, str) else mesh
    h_min = min(t / size.wall, b / size.base, 0.5 * np.pi * a / size.arc)
    skin = SKIN_FRACTION * h_min
    body, fill = _section(a, t, b, size, skin)
    n_ax = int(np.ceil(size.axial * max(1.0, L / (4.0 * (a + t + b))) ** 0.5))
    z_cap0 = np.linspace(-t, 0.0, size.cap + 1)
    z_mid = np.linspace(0.0, L, n_ax + 1)
    z_cap1 = np.linspace(L, L + t, size.cap + 1)
    z_all = np.concatenate([z_cap0, z_mid[1:], z_cap1[1:]])
    pieces = []
    kinds = []
    for pts, q, kind in body:
        p3, c3 = _extrude(pts, q, z_all)
        pieces.append((p3, c3))
        kinds.append(np.full(len(c3), kind))
    for pts, q in fill:
        for zs in (z_cap0, z_cap1):
            p3, c3 = _extrude(pts, q, zs)
            pieces.append((p3, c3))
            kinds.append(np.full(len(c3), 2))
    points, cells = _merge(pieces, scale=a + t + b + L)
    kind = np.concatenate(kinds)
    centre = points[cells].mean(axis=1)
    corners = points[cells]  # (cells, 8, 3): a layer's cells have every corner inside it
    eps = 1e-6 * skin
    r_out = a + t
    skin_cells = np.flatnonzero(np.all(corners[:, :, 1] <= skin + eps, axis=1))
    r_corner = np.hypot(corners[:, :, 0], corners[:, :, 1] - b)
    wall_wrap = (kind == 1) & np.all(r_corner >= r_out - skin - eps, axis=1)
    side_wrap = (kind == 0) & np.all(corners[:, :, 0] >= r_out - skin - eps, axis=1)
    wrap_cells = np.flatnonzero(wall_wrap | side_wrap)
    phi = np.arctan2(centre[wrap_cells, 1] - b, centre[wrap_cells, 0])
    direction = np.zeros((len(wrap_cells), 3))
    on_wall = wall_wrap[wrap_cells]
    direction[on_wall, 0] = -np.sin(phi[on_wall])
    direction[on_wall, 1] = np.cos(phi[on_wall])
    direction[~on_wall, 1] = 1.0  # the floor's side face: the wrap runs vertically
    thickness = np.full(len(wrap_cells), skin)
    # the chamber's surface: wall r = a and floor y = b for x <= a, and the caps' inner
    # faces z = 0 and z = L inside the chamber
    tol = 1e-9 * (a + t + b + L)
    px, py, pz = points.T
    r_p = np.hypot(px, py - b)
    along = (pz > -tol) & (pz < L + tol)
    on_wall_in = np.abs(r_p - a) < tol * 10 + 1e-12 * a
    on_floor = (np.abs(py - b) < tol) & (px <= a + tol)
    in_disc = (r_p <= a + tol) & (py >= b - tol)
    on_caps = (np.abs(pz) < tol) | (np.abs(pz - L) < tol)
    chamber = (along & ((on_wall_in & (py >= b - tol)) | on_floor)) | (on_caps & in_disc)
    if size.order == 2:
        points, cells, chamber = _quadratic(points, cells, chamber, a, b, tol)
    elif size.order != 1:
        raise ValueError(f"mesh order: 1 or 2, got {size.order!r}")
    return BodyMesh(points=points, cells=cells, skin=skin_cells, skin_thickness=skin,
                    wrap=wrap_cells, wrap_direction=direction, wrap_thickness=thickness,
                    chamber=chamber, radius=a, wall_thickness=t, base_thickness=b, length=L)


#: The edges of a hexahedron, in the order of the 20-node element's midpoints (VTK's).
HEX_EDGES = np.array([(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4),
                      (0, 4), (1, 5), (2, 6), (3, 7)])


def _quadratic(points, cells, chamber, a, b, tol):
    """20-node hexahedra from 8-node ones: a point at the middle of every edge (appended
    after the corners), on the arc where both ends lie at one radius r >= a about (0, b)
    in one section (the wall's and the chamber's arcs: the element's edges follow the
    curved surfaces). A midpoint is on the chamber's surface where both its ends are."""
    edges = np.sort(cells[:, HEX_EDGES].reshape(-1, 2), axis=1)
    unique, inverse = np.unique(edges, axis=0, return_inverse=True)
    p0, p1 = points[unique[:, 0]], points[unique[:, 1]]
    mid = 0.5 * (p0 + p1)
    r0 = np.hypot(p0[:, 0], p0[:, 1] - b)
    r1 = np.hypot(p1[:, 0], p1[:, 1] - b)
    arc = ((np.abs(r0 - r1) < tol) & (np.abs(p0[:, 2] - p1[:, 2]) < tol) & (r0 >= a - tol)
           & (p0[:, 1] >= b - tol) & (p1[:, 1] >= b - tol))
    phi = 0.5 * (np.arctan2(p0[arc, 1] - b, p0[arc, 0]) + np.arctan2(p1[arc, 1] - b, p1[arc, 0]))
    mid[arc, 0] = r0[arc] * np.cos(phi)
    mid[arc, 1] = b + r0[arc] * np.sin(phi)
    cells20 = np.concatenate([cells, len(points) + inverse.reshape(len(cells), 12)], axis=1)
    on = chamber[unique[:, 0]] & chamber[unique[:, 1]]
    return np.concatenate([points, mid]), cells20, np.concatenate([chamber, on])


def _merge(pieces, scale):
    """Concatenate meshes and merge coincident points (to 1e-9 of ``scale``)."""
    offsets = np.cumsum([0] + [len(p) for p, _ in pieces])
    points = np.concatenate([p for p, _ in pieces])
    cells = np.concatenate([c + o for (_, c), o in zip(pieces, offsets)])
    key = np.round(points / (1e-9 * scale)).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    rank = np.empty_like(order)
    rank[order] = np.arange(len(order))
    return points[first[order]], rank[inverse.ravel()][cells]
