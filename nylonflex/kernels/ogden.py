"""The FE twin's isochoric Ogden material, compiled: stress and tangent at every point.

The FE twin (:mod:`nylonflex.fe.ogden`, FElupe's material interface) calls
:func:`ogden_points` for every quadrature point of every cell in each Newton iteration.
The energy, in FElupe's convention:

    W(C) = sum_k phi(cbar_k),  phi(c) = sum_i 2 mu_i / alpha_i^2 (c^(alpha_i/2) - 1)

with cbar_k the eigenvalues of the distortional part Cbar = J^(-2/3) C; with G = g(Cbar),
g = phi', the matrix function:

    dW/dC = J^(-2/3) (G - (G:C)/3 C^-1)

and its derivative uses the Daleckii-Krein formula for dG (divided differences of g on
the eigenvalues, g' where two eigenvalues meet), so the tangent is exact at any
deformation, the undeformed state (three equal eigenvalues) included. Tested against
FElupe's tensortrax material in tests/test_fe.py.
"""

from __future__ import annotations

import numpy as np

from ._compile import jit_kernel

__all__ = ["MEET", "ogden_points"]

#: Relative gap of two eigenvalues below which their divided difference is taken as the
#: derivative at their mean (error of order gap^2, about 1e-12).
MEET = 1e-6


@jit_kernel
def _g(mu, alpha, c):
    """phi'(c) and phi''(c) at one eigenvalue c [-] [Pa]."""
    g = 0.0
    dg = 0.0
    for i in range(len(mu)):
        e = alpha[i] / 2.0 - 1.0
        ce = c ** e
        g += mu[i] / alpha[i] * ce
        dg += mu[i] / alpha[i] * e * ce / c
    return g, dg


@jit_kernel
def _eigh3(M, lam, Q):
    """Eigenvalues ``lam`` and eigenvectors (columns of ``Q``) of the symmetric 3 x 3 ``M``
    by cyclic Jacobi rotations (Numerical Recipes s. 11.1), to round-off; about a tenth of
    a LAPACK call's cost at this size."""
    A = M.copy()
    for i in range(3):
        for j in range(3):
            Q[i, j] = 1.0 if i == j else 0.0
    for _ in range(30):
        off = A[0, 1] ** 2 + A[0, 2] ** 2 + A[1, 2] ** 2
        if off <= 1e-32 * (A[0, 0] ** 2 + A[1, 1] ** 2 + A[2, 2] ** 2):
            break
        for p, q in ((0, 1), (0, 2), (1, 2)):
            apq = A[p, q]
            if apq == 0.0:
                continue
            theta = (A[q, q] - A[p, p]) / (2.0 * apq)
            t = 1.0 / (abs(theta) + np.sqrt(theta * theta + 1.0))
            if theta < 0.0:
                t = -t
            c = 1.0 / np.sqrt(t * t + 1.0)
            s = t * c
            for k in range(3):
                akp, akq = A[k, p], A[k, q]
                A[k, p] = c * akp - s * akq
                A[k, q] = s * akp + c * akq
            for k in range(3):
                apk, aqk = A[p, k], A[q, k]
                A[p, k] = c * apk - s * aqk
                A[q, k] = s * apk + c * aqk
            for k in range(3):
                qkp, qkq = Q[k, p], Q[k, q]
                Q[k, p] = c * qkp - s * qkq
                Q[k, q] = s * qkp + c * qkq
    for i in range(3):
        lam[i] = A[i, i]


@jit_kernel
def ogden_points(F, mu, alpha, P, A, tangent):  # noqa: C901 (one compiled pass a point)
    """Stress P[i, J, n] and, with ``tangent``, A[i, J, k, L, n] at every point n of
    F[i, I, n] (all in FElupe's index order) [Pa]."""
    n_points = F.shape[2]
    Fn = np.empty((3, 3))
    C = np.empty((3, 3))
    Ci = np.empty((3, 3))
    G = np.empty((3, 3))
    dWdC = np.empty((3, 3))
    S = np.empty((3, 3))
    gamma = np.empty((3, 3))
    GG = np.empty((3, 3, 3, 3))
    CC = np.empty((3, 3, 3, 3))
    GGC = np.empty((3, 3))
    CD = np.empty((3, 3))
    g = np.empty(3)
    lam = np.empty(3)
    Q = np.empty((3, 3))
    Cb = np.empty((3, 3))
    for n in range(n_points):
        for i in range(3):
            for j in range(3):
                Fn[i, j] = F[i, j, n]
        for i in range(3):
            for j in range(3):
                C[i, j] = Fn[0, i] * Fn[0, j] + Fn[1, i] * Fn[1, j] + Fn[2, i] * Fn[2, j]
        det = (C[0, 0] * (C[1, 1] * C[2, 2] - C[1, 2] * C[2, 1])
               - C[0, 1] * (C[1, 0] * C[2, 2] - C[1, 2] * C[2, 0])
               + C[0, 2] * (C[1, 0] * C[2, 1] - C[1, 1] * C[2, 0]))
        Ci[0, 0] = (C[1, 1] * C[2, 2] - C[1, 2] * C[2, 1]) / det
        Ci[0, 1] = (C[0, 2] * C[2, 1] - C[0, 1] * C[2, 2]) / det
        Ci[0, 2] = (C[0, 1] * C[1, 2] - C[0, 2] * C[1, 1]) / det
        Ci[1, 1] = (C[0, 0] * C[2, 2] - C[0, 2] * C[2, 0]) / det
        Ci[1, 2] = (C[0, 2] * C[1, 0] - C[0, 0] * C[1, 2]) / det
        Ci[2, 2] = (C[0, 0] * C[1, 1] - C[0, 1] * C[1, 0]) / det
        Ci[1, 0] = Ci[0, 1]
        Ci[2, 0] = Ci[0, 2]
        Ci[2, 1] = Ci[1, 2]
        jm23 = det ** (-1.0 / 3.0)
        for i in range(3):
            for j in range(3):
                Cb[i, j] = jm23 * C[i, j]
        _eigh3(Cb, lam, Q)
        for a in range(3):
            g[a] = _g(mu, alpha, lam[a])[0]
        GC = 0.0
        for i in range(3):
            for j in range(3):
                G[i, j] = (Q[i, 0] * g[0] * Q[j, 0] + Q[i, 1] * g[1] * Q[j, 1]
                           + Q[i, 2] * g[2] * Q[j, 2])
                GC += G[i, j] * C[i, j]
        for i in range(3):
            for j in range(3):
                dWdC[i, j] = jm23 * (G[i, j] - GC / 3.0 * Ci[i, j])
                S[i, j] = 2.0 * dWdC[i, j]
        for i in range(3):
            for j in range(3):
                P[i, j, n] = Fn[i, 0] * S[0, j] + Fn[i, 1] * S[1, j] + Fn[i, 2] * S[2, j]
        if not tangent:
            continue
        # Daleckii-Krein: dG = Q (gamma o (Q^T dCbar Q)) Q^T
        for a in range(3):
            for b in range(3):
                gap = lam[a] - lam[b]
                if abs(gap) <= MEET * max(abs(lam[a]), abs(lam[b])):
                    gamma[a, b] = _g(mu, alpha, 0.5 * (lam[a] + lam[b]))[1]
                else:
                    gamma[a, b] = (g[a] - g[b]) / gap
        for I in range(3):
            for J in range(3):
                for K in range(3):
                    for L in range(K, 3):
                        v = 0.0
                        for a in range(3):
                            for b in range(3):
                                v += gamma[a, b] * Q[I, a] * Q[J, b] * (
                                    Q[K, a] * Q[L, b] + Q[L, a] * Q[K, b])
                        GG[I, J, K, L] = 0.5 * v
                        GG[I, J, L, K] = 0.5 * v
        for I in range(3):
            for J in range(3):
                v = 0.0
                for K in range(3):
                    for L in range(3):
                        v += GG[I, J, K, L] * C[K, L]
                GGC[I, J] = v
        # D = dG/dC = J^-2/3 (GG - (GG:C) x C^-1 / 3), held in GG; CD = C:D
        for I in range(3):
            for J in range(3):
                for K in range(3):
                    for L in range(3):
                        GG[I, J, K, L] = jm23 * (GG[I, J, K, L] - GGC[I, J] * Ci[K, L] / 3.0)
        for K in range(3):
            for L in range(3):
                v = 0.0
                for I in range(3):
                    for J in range(3):
                        v += C[I, J] * GG[I, J, K, L]
                CD[K, L] = v
        for I in range(3):
            for J in range(3):
                for K in range(3):
                    for L in range(3):
                        CC[I, J, K, L] = 4.0 * (
                            -dWdC[I, J] * Ci[K, L] / 3.0 + jm23 * GG[I, J, K, L]
                            - jm23 / 3.0 * Ci[I, J] * (CD[K, L] + G[K, L])
                            + jm23 * GC / 6.0 * (Ci[I, K] * Ci[J, L] + Ci[I, L] * Ci[J, K]))
        # A_iJkL = F_iI F_kK CC_IJKL + delta_ik S_JL
        for i in range(3):
            for J in range(3):
                for K in range(3):
                    for L in range(3):
                        GG[i, J, K, L] = (Fn[i, 0] * CC[0, J, K, L] + Fn[i, 1] * CC[1, J, K, L]
                                          + Fn[i, 2] * CC[2, J, K, L])
        for i in range(3):
            for J in range(3):
                for k in range(3):
                    for L in range(3):
                        v = (Fn[k, 0] * GG[i, J, 0, L] + Fn[k, 1] * GG[i, J, 1, L]
                             + Fn[k, 2] * GG[i, J, 2, L])
                        if i == k:
                            v += S[J, L]
                        A[i, J, k, L, n] = v
