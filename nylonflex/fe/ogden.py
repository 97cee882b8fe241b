"""The isochoric Ogden material with a hand-written tangent, for FElupe.

FElupe's ``Hyperelastic(ogden, ...)`` differentiates the strain energy with tensortrax's
hyper-dual numbers through an eigenvalue solve: correct, but most of a Newton iteration's
time on the FE twin's meshes (docs/fidelity.md). :class:`OgdenIsochoric` gives FElupe the
same energy's stress and tangent in closed form, computed by the compiled
:func:`nylonflex.kernels.ogden.ogden_points` (the formulas are in its module docstring).
"""

from __future__ import annotations

import numpy as np

from ..kernels.ogden import ogden_points

__all__ = ["OgdenIsochoric"]


class OgdenIsochoric:
    """The distortional Ogden energy in FElupe's convention (``felupe.ogden``) as a FElupe
    material (``gradient``, ``hessian``).

    ``mu``: moduli mu_i [Pa] (FElupe's convention: their sum is the shear modulus);
    ``alpha``: exponents alpha_i [-].
    """

    def __init__(self, mu, alpha):
        self.mu = np.asarray(mu, dtype=float)
        self.alpha = np.asarray(alpha, dtype=float)
        self.x = [np.eye(3), np.zeros(0)]

    def _run(self, F, tangent):
        F = np.ascontiguousarray(F, dtype=float)
        shape = F.shape[2:]
        Fr = F.reshape(3, 3, -1)
        P = np.empty_like(Fr)
        A = np.empty((3, 3, 3, 3, Fr.shape[2]) if tangent else (3, 3, 3, 3, 0))
        ogden_points(Fr, self.mu, self.alpha, P, A, tangent)
        return P.reshape((3, 3) + shape), A.reshape((3, 3, 3, 3) + shape) if tangent else None

    def gradient(self, x):
        """First Piola-Kirchhoff stress P = F S [Pa], (3, 3, q, c), and the state."""
        return [self._run(x[0], False)[0], x[-1]]

    def hessian(self, x):
        """dP/dF [Pa], (3, 3, 3, 3, q, c) in FElupe's index order iJkL."""
        return [self._run(x[0], True)[1]]

