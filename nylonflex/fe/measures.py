"""What the FE twin reports of a converged state beyond the bend angle: the chamber's
volume (:func:`chamber_volume`) and the moment on a held tip (:func:`tip_moment`)."""

from __future__ import annotations

import numpy as np

__all__ = ["chamber_volume", "tip_moment"]


def chamber_volume(pressure_item, points):
    """Half the chamber's volume [m^3] of the pressure item's boundary in its current
    (deformed) state: -int x n_x dA (n the solid's outward normal)."""
    import felupe as fem

    field = pressure_item.field
    region = field.region
    F = field.extract()
    area = fem.constitution.AreaChange().function(F, region.normals)[0]  # (3, q, c)
    x = _at_points(region, points + field[0].values)
    return float(-np.sum(x[0] * area[0] * region.dV))


def _at_points(region, values):
    """Nodal ``values`` (n, 3) interpolated to the region's quadrature points (3, q, c)."""
    cells = region.mesh.cells  # (c, a), each cell's nodes ordered for its face
    h = np.broadcast_to(region.h, region.h.shape[:2] + (len(cells),))
    return np.einsum("aqc,cai->iqc", h, values[cells])


def tip_moment(path):
    """Moment [N m] the whole body exerts on the holder of its tip (boundary "tip") about
    the x-axis through y = 0 on the tip face, from the reactions of the last converged
    state: M = 2 sum_i y_i F_z,i (half model; positive when the pressure on the caps
    pushes the tip face's upper part out, the sense of eq. 16)."""
    if path.residual is None:  # nothing solved yet: the unloaded body
        return 0.0
    mask = path.boundaries["tip"].points  # point indices
    f = np.asarray(path.residual).reshape(-1, 3)  # reactions of the supports on the body
    y = path.body.points[:, 1]
    return float(2.0 * np.sum(y[mask] * -f[mask, 2]))
