"""The conic closure programme of one spatial grasp, compiled (numba): its solver columns, the
map to the certificate's values and the certificate columns, in one pass over the contacts
(:func:`lorentz_system`; the programme is that of :mod:`qualgrasp.certify.core.problem`).

Every float is computed by the same operations, in the same order, as the array formulas of
:func:`qualgrasp.certify.core.wrench.contact_frame`, :func:`~qualgrasp.certify.core.wrench.wrench`,
:func:`~qualgrasp.certify.core.wrench.force_columns` and
:func:`qualgrasp.certify.core.problem.conic_columns`, so both give the same bits (tested): the
per-grasp call takes this route, the columnar batches the array one.

:func:`support_points`: the vertices of spatial ``support`` evidence (the support forces of every
contact along given directions, pulled inside their cones and scaled towards the origin), with
their error bounds and a float test of each force being inside its cone, for
:class:`qualgrasp.certify.quality.gws.ConicSupport`, which the bounds and their checker share.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel

__all__ = ["lorentz_system", "support_points", "SHRINK"]

#: Support forces are pulled this far inside their cones (tangential part times ``SHRINK``).
SHRINK = 1.0 - 2.0**-30
#: Unit roundoff of float64.
_U = 2.0**-53


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


@kernel
def support_points(C, errors, absC, P, index, ref, l1, ray, col0, f_col, m_col, n, nh, nn, mu, g, gr):
    """Support points of a spatial GWS along the rows of ``P``, as
    :meth:`qualgrasp.certify.quality.gws.ConicSupport.vertices` states them.

    Parameters
    ----------
    C, errors, absC : array, shape (d, k)
        Certificate columns, bounds on their errors, and their absolute values.
    P : array, shape (n, d)
        Directions.
    index : int array, shape (n,)
        Each point's vertex position (its scale ``1 - ((i * 40503) % 65536) 2^-30``).
    ref : int array, shape (n,)
        L1: the contact whose forces make the point (-1: the one with the largest support value).
    l1 : bool
        L1 (one contact per point) or L-infinity (every contact with a positive support value).
    ray, col0, f_col, m_col : arrays over the contacts (blocks)
        Ray block or Lorentz; a ray's column; a Lorentz block's three force columns and its moment
        column (-1: none).
    n, nh, nn, mu, g, gr : arrays over the contacts
        Normal, unit normal, ``n . n``, friction coefficient, moment length and moment length over
        ``|n|`` (zeros for rays).

    Returns
    -------
    W, EW : array, shape (n, d)
        The points and bounds on their distance to the exact wrenches of the column values.
    X : array, shape (n, k)
        The column values (0 off the contacts used).
    open_ : bool array, shape (n, m)
        Forces the float test leaves undecided (an exact test decides them).
    ok : bool array, shape (n,)
        False when a used force is proved outside its cone.
    """
    d, k = C.shape
    nb = ray.shape[0]
    N = P.shape[0]
    W, EW, X = np.zeros((N, d)), np.zeros((N, d)), np.zeros((N, k))
    used = np.zeros(nb, dtype=np.bool_)
    open_ = np.zeros((N, nb), dtype=np.bool_)
    ok = np.ones(N, dtype=np.bool_)
    a = np.empty(k)
    c = np.empty(nb)
    Xf = np.empty(k)
    for q in range(N):
        for j in range(k):
            s = 0.0
            for r in range(d):
                s += C[r, j] * P[q, r]
            a[j] = s
        _support_forces(a, ray, col0, f_col, m_col, nh, mu, gr, c, Xf)
        for b in range(nb):
            used[b] = False
        _use(c, ref[q], l1, used)
        scale = 1.0 - ((index[q] * 40503) % 65536) * 2.0**-30
        terms = 0
        for b in range(nb):
            if not used[b]:
                continue
            if ray[b]:
                X[q, col0[b]] = Xf[col0[b]] * scale
                terms += 1
                ok[q] = ok[q] and X[q, col0[b]] > 0
                continue
            for t in range(3):
                X[q, f_col[b, t]] = Xf[f_col[b, t]] * scale
            terms += 3
            if m_col[b] >= 0:
                X[q, m_col[b]] = Xf[m_col[b]] * scale
                terms += 1
            open_[q, b] = not _inside_float(X[q], f_col[b], m_col[b], n[b], nn[b], mu[b], g[b])
        for r in range(d):
            s, e, mag = 0.0, 0.0, 0.0
            for j in range(k):
                x = X[q, j]
                s += C[r, j] * x
                e += errors[r, j] * abs(x)
                mag += absC[r, j] * abs(x)
            W[q, r] = s
            EW[q, r] = e + 2 * (terms + 1) * _U * mag
    return W, EW, X, open_, ok


@kernel
def _support_forces(a, ray, col0, f_col, m_col, nh, mu, gr, c, X):
    """Into ``c`` each contact's support value for the functional values ``a`` (``C' v``), into
    ``X`` the forces reaching them, pulled inside by :data:`SHRINK`: ``f = nh + SHRINK mu z_t /
    |z|``, ``m = gr SHRINK mu z_m / |z|`` with ``z = (a_t, a_m gr)``; a ray's value is 1."""
    for b in range(ray.shape[0]):
        if ray[b]:
            c[b] = a[col0[b]]
            X[col0[b]] = 1.0
            continue
        i0, i1, i2 = f_col[b, 0], f_col[b, 1], f_col[b, 2]
        an = (a[i0] * nh[b, 0] + a[i1] * nh[b, 1]) + a[i2] * nh[b, 2]
        t0, t1, t2 = a[i0] - an * nh[b, 0], a[i1] - an * nh[b, 1], a[i2] - an * nh[b, 2]
        am = a[m_col[b]] * gr[b] if m_col[b] >= 0 else 0.0
        nz = np.sqrt(((t0 * t0 + t1 * t1) + t2 * t2) + am * am)
        c[b] = an + mu[b] * nz
        kk = SHRINK * mu[b] / nz if nz > 0 else 0.0
        X[i0], X[i1], X[i2] = nh[b, 0] + kk * t0, nh[b, 1] + kk * t1, nh[b, 2] + kk * t2
        if m_col[b] >= 0:
            X[m_col[b]] = kk * am * gr[b]


@kernel
def _use(c, ref, l1, used):
    """Into ``used``: the contacts a point sums (L1: ``ref``, or the first with the largest value;
    L-infinity: those with a positive value)."""
    if not l1:
        for b in range(c.shape[0]):
            used[b] = c[b] > 0
        return
    if ref < 0:
        ref = 0
        for b in range(1, c.shape[0]):
            if c[b] > c[ref]:
                ref = b
    used[ref] = True


@kernel
def _inside_float(x, f_col, m_col, n, nn, mu, g):
    """Is the force ``x[f_col]`` (and moment ``x[m_col]``) strictly inside the cone, by a float
    test with a rigorous margin (the rounding of ``|n|^2 |f|^2 - (f . n)^2 + (m |n|^2 / g)^2`` is
    far below ``1e-14`` of its terms)? False also when the test cannot tell."""
    f0, f1, f2 = x[f_col[0]], x[f_col[1]], x[f_col[2]]
    fn = (f0 * n[0] + f1 * n[1]) + f2 * n[2]
    ff = (f0 * f0 + f1 * f1) + f2 * f2
    extra = 0.0
    if m_col >= 0:
        t = x[m_col] * nn / (g if g > 0 else 1.0)
        extra = t * t
    tang = nn * ff - fn * fn + extra
    mu2 = mu * mu * fn * fn
    err = 1e-14 * (nn * ff + fn * fn + extra + mu2)
    return fn > 0 and tang + err < mu2 - err
