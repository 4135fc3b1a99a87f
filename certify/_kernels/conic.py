"""The conic closure programme of one spatial grasp, compiled (numba): its solver columns, the
map to the certificate's values and the certificate columns, in one pass over the contacts
(:func:`lorentz_system`; the programme is that of :mod:`qualgrasp.certify.core.problem`).

Every float is computed by the same operations, in the same order, as the array formulas of
:func:`qualgrasp.certify.core.wrench.contact_frame`, :func:`~qualgrasp.certify.core.wrench.wrench`,
:func:`~qualgrasp.certify.core.wrench.force_columns` and
:func:`qualgrasp.certify.core.problem.conic_columns`, so both give the same bits (tested): the
per-grasp call takes this route, the columnar batches the array one.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["lorentz_system"]


@kernel
def _cross_into(a0, a1, a2, b0, b1, b2, out):
    out[0] = a1 * b2 - a2 * b1
    out[1] = a2 * b0 - a0 * b2
    out[2] = a0 * b1 - a1 * b0


@kernel
def _wrench_into(r, f, L, out):
    """``out = (f, (r x f) / L)``: the wrench of force ``f`` at lever ``r``."""
    tau = np.empty(3)
    _cross_into(r[0], r[1], r[2], f[0], f[1], f[2], tau)
    for j in range(3):
        out[j] = f[j]
        out[3 + j] = tau[j] / L


@kernel
def lorentz_system(P, N, c, L, first, nextra, G):
    """Solver columns, value map and certificate columns of a spatial grasp whose contacts all
    have Lorentz cones over world-axis forces (point and soft contacts).

    Parameters
    ----------
    P, N : array, shape (m, 3)
        Contact points and stored unit inward normals.
    c : array, shape (3,)
        Torque reference point.
    L : float
        Characteristic length (torques are divided by it).
    first : int array, shape (m,)
        First column of each contact; contact ``i`` owns ``3 + nextra[i]`` columns.
    nextra : int array, shape (m,)
        Number of moment columns of each contact (a soft finger's torsion: 1).
    G : array, shape (m, max(nextra))
        Moment lengths of those columns (the torsional length).

    Returns
    -------
    columns : array, shape (6, k)
        Solver columns: the wrenches of the contact frame ``(n, t1, t2)``, then ``(0, g n / L)``
        per moment (:func:`qualgrasp.certify.core.problem.conic_columns`).
    to_values : array, shape (k, k)
        Block diagonal map from the solver's variables to world-frame forces and moments: the
        transposed frame, then ``g`` per moment.
    C : array, shape (6, k)
        Certificate columns: the wrenches of the world axes, then ``(0 n, n / L)`` per moment
        (:func:`qualgrasp.certify.core.wrench.force_columns`).
    """
    m = P.shape[0]
    k = 0
    for i in range(m):
        k += 3 + nextra[i]
    columns = np.zeros((6, k))
    to_values = np.zeros((k, k))
    C = np.zeros((6, k))
    r = np.empty(3)
    frame = np.empty((3, 3))
    axis = np.empty(3)
    w = np.empty(6)
    for i in range(m):
        for j in range(3):
            r[j] = P[i, j] - c[j]
        # contact_frame: the tangent off the axis where n is smallest (first on ties)
        a = 0
        best = abs(N[i, 0])
        for j in range(1, 3):
            if abs(N[i, j]) < best:
                a, best = j, abs(N[i, j])
        axis[:] = 0.0
        axis[a] = 1.0
        frame[0] = N[i]
        _cross_into(N[i, 0], N[i, 1], N[i, 2], axis[0], axis[1], axis[2], frame[1])
        norm = np.sqrt((frame[1, 0] * frame[1, 0] + frame[1, 1] * frame[1, 1]) + frame[1, 2] * frame[1, 2])
        for j in range(3):
            frame[1, j] /= norm
        _cross_into(N[i, 0], N[i, 1], N[i, 2], frame[1, 0], frame[1, 1], frame[1, 2], frame[2])
        f0 = first[i]
        for j in range(3):
            _wrench_into(r, frame[j], L, w)
            columns[:, f0 + j] = w
            axis[:] = 0.0
            axis[j] = 1.0
            _wrench_into(r, axis, L, w)
            C[:, f0 + j] = w
            for q in range(3):
                to_values[f0 + q, f0 + j] = frame[j, q]
        for e in range(nextra[i]):
            col = f0 + 3 + e
            g = G[i, e]
            for j in range(3):
                columns[3 + j, col] = g * N[i, j] / L
                C[j, col] = N[i, j] * 0.0
                C[3 + j, col] = N[i, j] / L
            to_values[col, col] = g
    return columns, to_values, C
