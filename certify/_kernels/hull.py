"""Convex hulls of small 3-D point sets, compiled (numba): the triangulated surface of the hull,
each face oriented as the epsilon evidence states it, for many sets at once.

The planar grasp wrench space lives in 3-D (``fx``, ``fy``, torque), and every planar epsilon
row needs the hull of its generators and of their sums. qhull through
:class:`scipy.spatial.ConvexHull` costs 25 to 35 us a call, mostly Python around it; this
incremental hull costs a few microseconds for the tens of points a planar grasp gives.

The hull is a guide, never a proof: :func:`~.surface.cycle_code` and :func:`~.surface.face_bounds`
check every surface it gives, and a surface they cannot settle goes to exact arithmetic. Its
floating-point decisions therefore only need to be sensible, not exact: a point within
:data:`PLANE_TOL` times the sets's largest coordinate of a face's plane counts as on it (so
coplanar points do not split a flat facet into slivers), and a set whose points all lie that
close to one plane, or whose insertion meets an inconsistent horizon, is reported as failed
for its caller to hand to qhull.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel
from .order import stable_argsort

__all__ = ["PLANE_TOL", "hull_faces", "hull_faces_work", "hull_work", "hulls_faces", "face_planes", "used_vertices",
           "hull_planes", "planes_start", "planes_insert", "live_planes", "weakest_plane", "hull_grow", "grow_start",
           "live_facets", "hull_facets"]

#: Relative distance below which a point counts as on a face's plane (times the set's largest
#: absolute coordinate).
PLANE_TOL = 2.0**-40


@kernel
def _farthest_first(d2, order):
    """Into ``order``: the indices of ``d2`` (squared distances, no NaN; negative for points to
    leave out) from the largest down, ties in index order, the negative ones last (an insertion
    sort, stable: the sets are small, and this compiles in a fraction of numpy's sort)."""
    n = d2.shape[0]
    for k in range(n):  # insertion: a stable sort, largest first
        j = k
        while j > 0 and d2[order[j - 1]] < d2[k]:
            order[j] = order[j - 1]
            j -= 1
        order[j] = k


@kernel
def _plane(P, a, b, c, out):
    """Into ``out`` (4,): the normal ``(b - a) x (c - a)`` of the face ``a, b, c`` and its offset
    ``n . P[a]``; returns ``|n|``."""
    ux, uy, uz = P[b, 0] - P[a, 0], P[b, 1] - P[a, 1], P[b, 2] - P[a, 2]
    vx, vy, vz = P[c, 0] - P[a, 0], P[c, 1] - P[a, 1], P[c, 2] - P[a, 2]
    nx, ny, nz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
    out[0], out[1], out[2] = nx, ny, nz
    out[3] = nx * P[a, 0] + ny * P[a, 1] + nz * P[a, 2]
    return np.sqrt(nx * nx + ny * ny + nz * nz)


@kernel
def _start(P, tol):
    """Four affinely independent points of ``P`` (an initial tetrahedron: the two farthest apart
    along the axis of widest spread, the farthest from their line, the farthest from their
    plane), or -1 in the first entry when the points lie within ``tol`` of a plane."""
    n = P.shape[0]
    out = np.full(4, -1, dtype=np.int64)
    # indices typed int64 from the start: an int literal would have numba compile _plane for it too
    best, i0, i1 = -1.0, np.int64(0), np.int64(0)
    for r in range(3):
        lo, hi = 0, 0
        for i in range(n):
            if P[i, r] < P[lo, r]:
                lo = i
            if P[i, r] > P[hi, r]:
                hi = i
        if P[hi, r] - P[lo, r] > best:
            best, i0, i1 = P[hi, r] - P[lo, r], lo, hi
    if not best > tol:
        return out
    dx, dy, dz = P[i1, 0] - P[i0, 0], P[i1, 1] - P[i0, 1], P[i1, 2] - P[i0, 2]
    dd = np.sqrt(dx * dx + dy * dy + dz * dz)
    best, i2 = -1.0, np.int64(-1)
    for i in range(n):
        wx, wy, wz = P[i, 0] - P[i0, 0], P[i, 1] - P[i0, 1], P[i, 2] - P[i0, 2]
        cx, cy, cz = dy * wz - dz * wy, dz * wx - dx * wz, dx * wy - dy * wx
        h = np.sqrt(cx * cx + cy * cy + cz * cz) / dd
        if h > best:
            best, i2 = h, i
    if not best > tol:
        return out
    pl = np.empty(4)
    nn = _plane(P, i0, i1, i2, pl)
    best, i3 = -1.0, -1
    for i in range(n):
        h = abs(pl[0] * P[i, 0] + pl[1] * P[i, 1] + pl[2] * P[i, 2] - pl[3]) / nn
        if h > best:
            best, i3 = h, i
    if not best > tol:
        return out
    out[0], out[1], out[2], out[3] = i0, i1, i2, i3
    return out


@kernel
def _tolerance(P):
    """:data:`PLANE_TOL` times the largest absolute coordinate of ``P``; NaN when one is not finite."""
    s = 0.0
    for i in range(P.shape[0]):
        for r in range(P.shape[1]):
            if not abs(P[i, r]) <= 1e300:
                return np.nan
            s = max(s, abs(P[i, r]))
    return PLANE_TOL * s


@kernel
def hull_faces(P):
    """Faces (F, 3) of the convex hull of ``P`` (n, 3), triangulated, each ordered so that its
    float determinant ``det(v_1, v_2, v_3)`` is not negative (outward about an interior origin,
    as :func:`qualgrasp.certify.quality.gws.orient_faces` orders qhull's); an empty (0, 3)
    array when the points lie within :data:`PLANE_TOL` of a plane or the construction fails.

    Points are inserted after an initial tetrahedron, farthest from its centre first; a point
    sees the faces whose planes it lies more than the tolerance beyond, which are replaced by the
    cone from the point to their horizon. A new face of (near) zero area declines the set.
    """
    return hull_faces_work(P, hull_work(P.shape[0]))


@kernel
def hull_work(n):
    """The work arrays of :func:`hull_faces_work` for sets of up to ``n`` points (a caller
    building many hulls allocates them once)."""
    cap = 8 * n + 16
    return (np.empty((cap, 3), dtype=np.int64), np.empty((cap, 4)), np.empty(cap), np.zeros(cap, dtype=np.bool_),
            np.empty(cap, dtype=np.int64), np.empty(cap, dtype=np.int64), np.empty((3 * cap, 2), dtype=np.int64),
            np.empty(n, dtype=np.int64), np.empty(n), np.empty(n, dtype=np.int64), np.zeros(n, dtype=np.bool_))


@kernel
def hull_faces_work(P, work):
    """:func:`hull_faces` of ``P`` in the work arrays of :func:`hull_work` (made for at least as
    many points): the same faces."""
    face, plane, size, alive, live, visible, edges, nxt, far, order, taken = work
    n = P.shape[0]
    tol = _tolerance(P)
    if n < 4 or not tol >= 0.0:  # too few points, or one not finite
        return np.zeros((0, 3), dtype=np.int64)
    s = tol / PLANE_TOL  # the largest absolute coordinate (exact: PLANE_TOL is a power of 2)
    first = _start(P, tol)
    if first[0] < 0:
        return np.zeros((0, 3), dtype=np.int64)
    cap = 8 * n + 16
    alive[:cap] = False
    taken[:n] = False
    nxt[:n] = -1
    F = 0
    for o4 in range(4):  # the tetrahedron's faces, each turned away from its fourth vertex
        i, j, k, o = first[0 if o4 > 0 else 1], first[1 if o4 > 1 else 2], first[2 if o4 > 2 else 3], first[o4]
        nn = _plane(P, i, j, k, plane[F])
        if plane[F, 0] * P[o, 0] + plane[F, 1] * P[o, 1] + plane[F, 2] * P[o, 2] - plane[F, 3] > 0.0:
            j, k = k, j
            nn = _plane(P, i, j, k, plane[F])
        face[F, 0], face[F, 1], face[F, 2] = i, j, k
        size[F] = nn
        alive[F] = True
        F += 1
    for q in range(4):
        taken[first[q]] = True
    nl = 4  # live: the live faces, ascending (the scan skips dead ones)
    for f in range(4):
        live[f] = f
    # farthest from the tetrahedron's centre first: extreme points before the points on a facet
    # or edge between them, which would make slivers
    for i in range(n):
        d2 = 0.0
        for r in range(3):
            x = P[i, r] - 0.25 * (P[first[0], r] + P[first[1], r] + P[first[2], r] + P[first[3], r])
            d2 += x * x
        far[i] = d2
    _farthest_first(far[:n], order)
    for p in order[:n]:
        if taken[p]:
            continue
        nv = 0
        for q in range(nl):
            f = live[q]
            h = plane[f, 0] * P[p, 0] + plane[f, 1] * P[p, 1] + plane[f, 2] * P[p, 2] - plane[f, 3]
            if h > tol * size[f]:
                visible[nv] = f
                nv += 1
        if nv == 0:
            continue
        ne = 0
        for q in range(nv):  # the horizon: edges of visible faces whose twin is not visible
            f = visible[q]
            for e in range(3):
                a, b = face[f, e], face[f, (e + 1) % 3]
                twin = False
                for q2 in range(nv):
                    g = visible[q2]
                    if ((face[g, 0] == b and face[g, 1] == a) or (face[g, 1] == b and face[g, 2] == a)
                            or (face[g, 2] == b and face[g, 0] == a)):
                        twin = True
                        break
                if not twin:
                    edges[ne, 0], edges[ne, 1] = a, b
                    ne += 1
        simple = ne >= 3
        for q in range(ne):  # one simple cycle: each horizon vertex starts one edge, ...
            if nxt[edges[q, 0]] >= 0:
                simple = False
            nxt[edges[q, 0]] = edges[q, 1]
        v, steps = edges[0, 0], 0
        while simple and steps < ne:  # ... and following them from one returns after all
            v = nxt[v]
            steps += 1
            if v < 0:
                simple = False
            elif v == edges[0, 0] and steps < ne:
                simple = False
        if simple and v != edges[0, 0]:
            simple = False
        for q in range(ne):
            nxt[edges[q, 0]] = -1
        if not simple or F + ne > cap:
            return np.zeros((0, 3), dtype=np.int64)
        for q in range(nv):
            alive[visible[q]] = False
        w = 0
        for q in range(nl):
            if alive[live[q]]:
                live[w] = live[q]
                w += 1
        nl = w
        for q in range(ne):
            a, b = edges[q, 0], edges[q, 1]
            nn = _plane(P, a, b, p, plane[F])
            if not nn > tol * s:  # a sliver (the point on a horizon edge's line)
                return np.zeros((0, 3), dtype=np.int64)
            face[F, 0], face[F, 1], face[F, 2] = a, b, p
            size[F] = nn
            alive[F] = True
            live[nl] = F
            nl += 1
            F += 1
        taken[p] = True
        if F > cap - 2 * n:  # compact: keep the live faces at the front
            w = 0
            for f in range(F):
                if alive[f]:
                    for r in range(3):
                        face[w, r] = face[f, r]
                    for r in range(4):
                        plane[w, r] = plane[f, r]
                    size[w] = size[f]
                    alive[w] = True
                    w += 1
            for f in range(w, F):
                alive[f] = False
            F = nl = w
            for f in range(w):
                live[f] = f
    count = 0
    for f in range(F):
        if alive[f]:
            count += 1
    out = np.empty((count, 3), dtype=np.int64)
    w = 0
    for f in range(F):
        if alive[f]:
            i, j, k = face[f, 0], face[f, 1], face[f, 2]
            det = (P[i, 0] * (P[j, 1] * P[k, 2] - P[j, 2] * P[k, 1])
                   - P[i, 1] * (P[j, 0] * P[k, 2] - P[j, 2] * P[k, 0])
                   + P[i, 2] * (P[j, 0] * P[k, 1] - P[j, 1] * P[k, 0]))
            if det < 0.0:
                i, j = j, i
            out[w, 0], out[w, 1], out[w, 2] = i, j, k
            w += 1
    return out


@kernel
def hulls_faces(V, vstart):
    """:func:`hull_faces` of many sets: set ``s`` is ``V[vstart[s]:vstart[s + 1]]``. Returns the
    faces of all sets one after another (indices local to each set) and ``fstart`` (S + 1,),
    set ``s`` owning ``faces[fstart[s]:fstart[s + 1]]`` (none where its hull failed)."""
    S = vstart.shape[0] - 1
    fstart = np.zeros(S + 1, dtype=np.int64)
    faces = np.empty((max(16, 2 * (vstart[S] - vstart[0])), 3), dtype=np.int64)
    most = 0
    for s in range(S):
        most = max(most, vstart[s + 1] - vstart[s])
    work = hull_work(most)
    for s in range(S):
        n = vstart[s + 1] - vstart[s]
        P = np.empty((n, 3))  # a copy in C order: the one specialisation of hull_faces_work
        for i in range(n):
            for r in range(3):
                P[i, r] = V[vstart[s] + i, r]
        f = hull_faces_work(P, work)
        end = fstart[s] + f.shape[0]
        if end > faces.shape[0]:  # room for twice as many
            grown = np.empty((2 * end, 3), dtype=np.int64)
            for i in range(fstart[s]):
                for r in range(3):
                    grown[i, r] = faces[i, r]
            faces = grown
        for i in range(f.shape[0]):
            for r in range(3):
                faces[fstart[s] + i, r] = f[i, r]
        fstart[s + 1] = end
    out = np.empty((fstart[S], 3), dtype=np.int64)
    for i in range(fstart[S]):
        for r in range(3):
            out[i, r] = faces[i, r]
    return out, fstart


@kernel
def face_planes(P, faces):
    """Unit normals (F, 3) of the ``faces`` of the hull of ``P`` (n, 3), turned away from the mean
    of the faces' vertices, and each plane's signed distance from the origin (positive when the
    origin is on the inner side), in floats: a guide, not a proof."""
    F = faces.shape[0]
    normal = np.empty((F, 3))
    dist = np.empty(F)
    used = np.zeros(P.shape[0], dtype=np.bool_)
    for f in range(F):
        for q in range(3):
            used[faces[f, q]] = True
    centre = np.zeros(3)
    count = 0
    for i in range(P.shape[0]):
        if used[i]:
            count += 1
            for r in range(3):
                centre[r] += P[i, r]
    pl = np.empty(4)
    for f in range(F):
        a = faces[f, 0]
        nn = _plane(P, a, faces[f, 1], faces[f, 2], pl)
        side = 0.0
        for r in range(3):
            normal[f, r] = pl[r] / nn
            side += normal[f, r] * (P[a, r] - centre[r] / count)
        if side < 0.0:
            for r in range(3):
                normal[f, r] = -normal[f, r]
        dist[f] = normal[f, 0] * P[a, 0] + normal[f, 1] * P[a, 1] + normal[f, 2] * P[a, 2]
    return normal, dist


@kernel
def used_vertices(faces, fstart, vstart):
    """The vertices the faces of each set use, for evidence that names only those: set ``s`` has
    the points ``vstart[s]:vstart[s + 1]`` and the faces ``faces[fstart[s]:fstart[s + 1]]``
    (indices local to its points). Returns ``used`` (each set's used local indices, ascending, as
    :func:`numpy.unique` gives them), ``ustart`` (S + 1,) and the faces renumbered into ``used``."""
    S = fstart.shape[0] - 1
    local = np.empty_like(faces)
    used = np.empty(faces.shape[0] * 3, dtype=np.int64)
    ustart = np.zeros(S + 1, dtype=np.int64)
    at = np.full(vstart[S] - vstart[0], -1, dtype=np.int64)
    w = 0
    for s in range(S):
        n = vstart[s + 1] - vstart[s]
        base = vstart[s] - vstart[0]
        for f in range(fstart[s], fstart[s + 1]):
            for q in range(3):
                at[base + faces[f, q]] = 0
        for i in range(n):
            if at[base + i] == 0:
                at[base + i] = w - ustart[s]
                used[w] = i
                w += 1
        ustart[s + 1] = w
        for f in range(fstart[s], fstart[s + 1]):
            for q in range(3):
                local[f, q] = at[base + faces[f, q]]
    return used[:w], ustart, local


@kernel
def _facet_plane(P, verts, centre, normal, work, x, col):
    """Into ``normal`` (d,): the unit normal of the hyperplane through the ``d`` points
    ``P[verts]``, turned away from ``centre``; returns its offset ``normal . P[verts[0]]``, or NaN
    when the points are (numerically) affinely dependent. The normal spans the null space of the
    edges from the first point (``work``, (d - 1, d)), found by Gaussian elimination with full
    pivoting and back substitution (``x``, ``col``: scratch of length d)."""
    d = P.shape[1]
    a = verts[0]
    for r in range(d):
        col[r] = r
    for i in range(d - 1):
        for q in range(d):
            work[i, q] = P[verts[i + 1], q] - P[a, q]
    for k in range(d - 1):
        pi, pj, best = k, k, 0.0
        for i in range(k, d - 1):
            for j in range(k, d):
                if abs(work[i, j]) > best:
                    pi, pj, best = i, j, abs(work[i, j])
        if not best > 0.0:
            return np.nan
        if pi != k:
            for q in range(d):
                work[k, q], work[pi, q] = work[pi, q], work[k, q]
        if pj != k:
            for i in range(d - 1):
                work[i, k], work[i, pj] = work[i, pj], work[i, k]
            col[k], col[pj] = col[pj], col[k]
        for i in range(k + 1, d - 1):
            f = work[i, k] / work[k, k]
            for q in range(k + 1, d):
                work[i, q] -= f * work[k, q]
    x[d - 1] = 1.0
    for k in range(d - 2, -1, -1):
        t = 0.0
        for q in range(k + 1, d):
            t += work[k, q] * x[q]
        x[k] = -t / work[k, k]
    nn = 0.0
    for r in range(d):
        nn += x[r] * x[r]
    nn = np.sqrt(nn)
    if not (nn > 0.0 and nn < np.inf):
        return np.nan
    off, side = 0.0, 0.0
    for r in range(d):
        normal[col[r]] = x[r] / nn
    for r in range(d):
        off += normal[r] * P[a, r]
        side += normal[r] * centre[r]
    if side > off:
        for r in range(d):
            normal[r] = -normal[r]
        off = -off
    return off


@kernel
def _residual(P, i, i0, Q, k, x):
    """Into ``x``: ``P[i] - P[i0]`` less its projection on the first ``k`` rows of ``Q``
    (orthonormal, Gram-Schmidt); returns its length."""
    d = P.shape[1]
    for r in range(d):
        x[r] = P[i, r] - P[i0, r]
    for j in range(k):
        dot = 0.0
        for r in range(d):
            dot += Q[j, r] * x[r]
        for r in range(d):
            x[r] -= dot * Q[j, r]
    h = 0.0
    for r in range(d):
        h += x[r] * x[r]
    return np.sqrt(h)


@kernel
def _simplex(P, tol):
    """``d + 1`` affinely independent points of ``P`` (n, d), each the farthest from the affine
    hull of those before (Gram-Schmidt), starting from the least first coordinate; -1 in the
    first entry when every point lies within ``tol`` of a hyperplane."""
    n, d = P.shape
    out = np.full(d + 1, -1, dtype=np.int64)
    i0 = 0
    for i in range(n):
        if P[i, 0] < P[i0, 0]:
            i0 = i
    Q = np.zeros((d, d))
    x = np.empty(d)
    chosen = np.empty(d + 1, dtype=np.int64)
    chosen[0] = i0
    for k in range(d):
        best, arg = -1.0, -1
        for i in range(n):
            h = _residual(P, i, i0, Q, k, x)
            if h > best:
                best, arg = h, i
        if not best > tol:
            return out
        h = _residual(P, arg, i0, Q, k, x)
        for r in range(d):
            Q[k, r] = x[r] / h
        chosen[k + 1] = arg
    for q in range(d + 1):
        out[q] = chosen[q]
    return out


@kernel
def _compact(verts, normal, off, alive, F):
    """Move the live facets among the first ``F`` to the front; returns how many there are."""
    w = 0
    for f in range(F):
        if alive[f]:
            for r in range(verts.shape[1]):
                verts[w, r], normal[w, r] = verts[f, r], normal[f, r]
            off[w] = off[f]
            alive[w] = True
            w += 1
    for f in range(w, F):
        alive[f] = False
    return w


@kernel
def planes_start(P):
    """An incremental hull of ``P`` (n, d), ``d >= 3``, for :func:`planes_insert` and
    :func:`live_planes`: ``(verts, normal, off, alive, F, centre, ok)``, the facets (simplices,
    rows of ``verts``), their unit outward normals and offsets (``normal . x <= off`` inside), which
    of the first ``F`` rows are live, and an interior point. ``ok`` is False when the points lie
    within :data:`PLANE_TOL` of a hyperplane or the construction fails.

    Points are inserted after an initial simplex, farthest from its centre first; the facets a
    point lies more than the tolerance beyond are replaced by the cone from the point to their
    horizon (the ridges they share with the other facets, found by sorting ridge keys). A guide
    for the spatial epsilon's refinement, never a proof: the evidence is checked on a
    triangulation of its own.
    """
    n, d = P.shape
    cap = 64 * n + 64
    verts = np.zeros((cap, d), dtype=np.int64)
    normal = np.zeros((cap, d))
    off = np.zeros(cap)
    alive = np.zeros(cap, dtype=np.bool_)
    centre = np.zeros(d)
    tol = _tolerance(P)
    if n <= d or not tol >= 0.0:
        return verts, normal, off, alive, 0, centre, False
    first = _simplex(P, tol)
    if first[0] < 0:
        return verts, normal, off, alive, 0, centre, False
    for q in range(d + 1):
        for r in range(d):
            centre[r] += P[first[q], r] / (d + 1)
    work = np.empty((d - 1, d))
    x = np.empty(d)
    col = np.empty(d, dtype=np.int64)
    F = 0
    for j in range(d + 1):  # the simplex's facets (vertices ascending, as every facet keeps them)
        c = 0
        for q in range(d + 1):
            if q != j:
                verts[F, c] = first[q]
                c += 1
        for i in range(1, d):  # ascending (insertion sort)
            t = i
            while t > 0 and verts[F, t - 1] > verts[F, t]:
                verts[F, t - 1], verts[F, t] = verts[F, t], verts[F, t - 1]
                t -= 1
        off[F] = _facet_plane(P, verts[F], centre, normal[F], work, x, col)
        if np.isnan(off[F]):
            return verts, normal, off, alive, 0, centre, False
        alive[F] = True
        F += 1
    far = np.empty(n)
    for i in range(n):
        d2 = 0.0
        for r in range(d):
            d2 += (P[i, r] - centre[r]) ** 2
        far[i] = d2
    for q in range(d + 1):
        far[first[q]] = -1.0  # taken: last, and skipped
    order = np.empty(n, dtype=np.int64)
    _farthest_first(far, order)
    for p in order:
        if far[p] < 0.0:
            continue
        verts, normal, off, alive, F, ok = _insert(P, p, verts, normal, off, alive, F, centre, tol, work, x, col)
        if not ok:
            return verts, normal, off, alive, 0, centre, False
    return verts, normal, off, alive, F, centre, True


@kernel
def planes_insert(P, start, verts, normal, off, alive, F, centre):
    """Insert the points ``P[start:]`` (in order) into the hull of :func:`planes_start` built on
    the points before them. Returns ``(verts, normal, off, alive, F, ok)``, the arrays grown where
    needed; ``ok`` False when the construction fails (build the hull anew)."""
    tol = _tolerance(P)
    if not tol >= 0.0:
        return verts, normal, off, alive, F, False
    work = np.empty((P.shape[1] - 1, P.shape[1]))
    x = np.empty(P.shape[1])
    col = np.empty(P.shape[1], dtype=np.int64)
    for p in range(start, P.shape[0]):
        verts, normal, off, alive, F, ok = _insert(P, p, verts, normal, off, alive, F, centre, tol, work, x, col)
        if not ok:
            return verts, normal, off, alive, F, False
    return verts, normal, off, alive, F, True


@kernel
def live_planes(normal, off, alive, F):
    """The live facets' unit outward normals (L, d) and offsets (L,), in facet order."""
    count = 0
    for f in range(F):
        if alive[f]:
            count += 1
    normals = np.empty((count, normal.shape[1]))
    dist = np.empty(count)
    w = 0
    for f in range(F):
        if alive[f]:
            for r in range(normal.shape[1]):
                normals[w, r] = normal[f, r]
            dist[w] = off[f]
            w += 1
    return normals, dist


@kernel
def weakest_plane(normal, off, alive, F):
    """The live facet with the least offset (the first in facet order on ties): its unit outward
    normal (d,) and offset, as the smallest of :func:`live_planes` without building them all."""
    best = -1
    for f in range(F):
        if alive[f] and (best < 0 or off[f] < off[best]):
            best = f
    u = np.empty(normal.shape[1])
    if best < 0:
        return u, np.nan
    for r in range(normal.shape[1]):
        u[r] = normal[best, r]
    return u, off[best]


@kernel
def hull_planes(P):
    """The facets of the convex hull of ``P`` (n, d), ``d >= 3``, as unit outward normals
    (F, d) and each facet's offset (the distance of its plane from the origin, negative when the
    origin is outside), as qhull's ``equations`` give them (``normal``, ``-offset``; a facet
    holding more than ``d`` points comes in simplices); empty arrays where :func:`planes_start`
    fails."""
    verts, normal, off, alive, F, centre, ok = planes_start(P)
    return live_planes(normal, off, alive, F if ok else 0)


def grow_start(d: int) -> tuple:
    """The state of :func:`hull_grow` before any point: no hull, no point done."""
    return (np.zeros((1, d), dtype=np.int64), np.zeros((1, d)), np.zeros(1), np.zeros(1, dtype=np.bool_), 0,
            np.zeros(d), 0)


def hull_facets(P) -> np.ndarray:
    """The facets of the convex hull of ``P`` (n, d), ``d >= 3``, as rows of ``d`` vertex indices
    (a triangulation of its boundary into simplices), grown by :func:`hull_grow`, in the order
    :func:`live_planes` gives their planes; an empty (0, d) array where no hull grows. (Python
    around the two kernels, which the spatial epsilon calls with the same types: compiled once.)"""
    P = np.ascontiguousarray(P, dtype=np.float64)
    verts, normal, off, alive, F, centre, done = hull_grow(P, *grow_start(P.shape[1]))
    return live_facets(verts, alive, F)


@kernel
def hull_grow(P, verts, normal, off, alive, F, centre, done):
    """Grow the hull of ``P[:done]`` (the state of :func:`planes_start`; ``F == 0``: no hull yet)
    to the hull of all of ``P`` (n, d) by a rule that depends on ``P`` alone, so that growing it
    round by round and building it at once give the same facets: start at the shortest prefix
    ``P[:k]``, ``k > d``, whose :func:`planes_start` succeeds; insert each later point in order,
    point ``p`` with the tolerance of ``P[:p + 1]``; where inserting point ``p`` fails, start again
    at the shortest prefix holding it, ``P[:k]``, ``k > p``, that succeeds. Returns ``(verts,
    normal, off, alive, F, centre, done)``, ``F == 0`` when no hull grows that way (no prefix
    builds, no restart after a failed insertion builds, or a coordinate is not finite)."""
    n, d = P.shape
    work = np.empty((d - 1, d))
    x = np.empty(d)
    col = np.empty(d, dtype=np.int64)
    scale = 0.0
    for i in range(done):
        for r in range(d):
            scale = max(scale, abs(P[i, r]))
    p = done
    while p < n:
        if F == 0:
            k = max(p + 1, d + 1)
            while k <= n:
                verts, normal, off, alive, F, centre, ok = planes_start(P[:k])
                if ok:
                    break
                F = 0
                k += 1
            if F == 0:
                return verts, normal, off, alive, 0, centre, n
            if alive.shape[0] < 64 * n + 64:  # the room planes_start gives n points: less growing later
                verts, normal, off, alive = _room(verts, normal, off, alive, F, 64 * n + 64)
            for i in range(p, k):
                for r in range(d):
                    scale = max(scale, abs(P[i, r]))
            p = k
            continue
        for r in range(d):
            if not abs(P[p, r]) <= 1e300:
                return verts, normal, off, alive, 0, centre, n
            scale = max(scale, abs(P[p, r]))
        verts, normal, off, alive, F, ok = _insert(P, p, verts, normal, off, alive, F, centre, PLANE_TOL * scale,
                                                   work, x, col)
        if ok:
            p += 1
        else:
            F = 0  # start again at the shortest prefix holding this point that builds
    return verts, normal, off, alive, F, centre, n


@kernel
def _room(verts, normal, off, alive, F, cap):
    """The first ``F`` facets copied into arrays of ``cap`` rows."""
    d = verts.shape[1]
    verts2, normal2 = np.zeros((cap, d), dtype=np.int64), np.zeros((cap, d))
    off2, alive2 = np.zeros(cap), np.zeros(cap, dtype=np.bool_)
    for f in range(F):
        for r in range(d):
            verts2[f, r], normal2[f, r] = verts[f, r], normal[f, r]
        off2[f], alive2[f] = off[f], alive[f]
    return verts2, normal2, off2, alive2


@kernel
def live_facets(verts, alive, F):
    """The live facets among the first ``F`` rows of ``verts``, in order (rows of vertex indices)."""
    count = 0
    for f in range(F):
        if alive[f]:
            count += 1
    out = np.empty((count, verts.shape[1]), dtype=np.int64)
    w = 0
    for f in range(F):
        if alive[f]:
            for r in range(verts.shape[1]):
                out[w, r] = verts[f, r]
            w += 1
    return out


@kernel
def _insert(P, p, verts, normal, off, alive, F, centre, tol, work, x, col):
    """Insert the point ``P[p]``: returns ``(verts, normal, off, alive, F, ok)``. Every facet keeps
    its vertices ascending, so that dropping one gives a ridge's sorted key."""
    n, d = P.shape
    nv = 0
    visible = np.empty(F, dtype=np.int64)
    for f in range(F):
        if alive[f]:
            h = -off[f]
            for r in range(d):
                h += normal[f, r] * P[p, r]
            if h > tol:
                visible[nv] = f
                nv += 1
    if nv == 0:
        return verts, normal, off, alive, F, True
    keys = np.empty(nv * d, dtype=np.int64)
    for q in range(nv):  # every ridge of the visible facets, as a key of its (sorted) vertices
        f = visible[q]
        for j in range(d):
            key = 0
            for t in range(d):
                if t != j:
                    key = key * n + verts[f, t]
            keys[q * d + j] = key
    order = stable_argsort(keys)
    horizon = np.empty(nv * d, dtype=np.int64)  # positions (q * d + j) of the ridges seen once
    nh, i = 0, 0
    while i < nv * d:
        j = i
        while j + 1 < nv * d and keys[order[j + 1]] == keys[order[i]]:
            j += 1
        if j == i:
            horizon[nh] = order[i]
            nh += 1
        elif j - i > 1:
            return verts, normal, off, alive, F, False  # a ridge in three facets: not a manifold
        i = j + 1
    if nh < d:
        return verts, normal, off, alive, F, False
    new_verts = np.empty((nh, d), dtype=np.int64)
    for q in range(nh):  # the ridge and the point, ascending
        f, j = visible[horizon[q] // d], horizon[q] % d
        c, put = 0, False
        for t in range(d):
            if t != j:
                v = verts[f, t]
                if not put and p < v:
                    new_verts[q, c] = p
                    c += 1
                    put = True
                new_verts[q, c] = v
                c += 1
        if not put:
            new_verts[q, c] = p
    for q in range(nv):
        alive[visible[q]] = False
    if F + nh > alive.shape[0]:  # compact the live facets to the front, then grow if short of room
        F = _compact(verts, normal, off, alive, F)
        if F + nh > alive.shape[0]:
            cap = 2 * (F + nh)
            verts2 = np.zeros((cap, d), dtype=np.int64)
            normal2 = np.zeros((cap, d))
            off2 = np.zeros(cap)
            alive2 = np.zeros(cap, dtype=np.bool_)
            for f in range(F):
                for r in range(d):
                    verts2[f, r], normal2[f, r] = verts[f, r], normal[f, r]
                off2[f], alive2[f] = off[f], alive[f]
            verts, normal, off, alive = verts2, normal2, off2, alive2
    for q in range(nh):
        for r in range(d):
            verts[F, r] = new_verts[q, r]
        off[F] = _facet_plane(P, verts[F], centre, normal[F], work, x, col)
        if np.isnan(off[F]):
            return verts, normal, off, alive, F, False
        alive[F] = True
        F += 1
    return verts, normal, off, alive, F, True
