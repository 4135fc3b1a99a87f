"""The compiled 3-D hull of planar epsilon evidence against qhull, an independent route: the same
facets on points in general position, and on points with coplanar and repeated ones (rounded
coordinates, Minkowski sums) a closed surface that every point lies inside and whose vertices
lie on the hull's boundary. Then the batch route's evidence held in columns, against the rows
and the Arrow column built from their JSON dicts."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from qualgrasp.certify._kernels.hull import (PLANE_TOL, grow_start, hull_faces, hull_facets, hull_grow, hulls_faces,
                                             live_facets)
from qualgrasp.certify._kernels.surface import TRIANGLES_MAX, cycle_code, orient_cycle
from qualgrasp.certify.quality import evidence as evidence_module
from qualgrasp.certify.quality.evidence import Evidence
from qualgrasp.certify.quality.gws import orient_faces, oriented_surface, surfaces_faces


def _canonical(faces):
    """Faces as a sorted list, each rotated to start at its least index (orientation kept)."""
    return sorted(tuple(np.roll(f, -int(np.argmin(f)))) for f in np.asarray(faces))


def _qhull_oriented(P):
    faces = np.array(ConvexHull(P).simplices, dtype=np.int64)
    flip = np.linalg.det(P[faces]) < 0
    faces[flip, 0], faces[flip, 1] = faces[flip, 1], faces[flip, 0].copy()
    return faces


def _a_hull_of(P, faces):
    """Turned outward about an interior point, a closed oriented surface with every point inside
    every face's plane, and every vertex on the boundary of qhull's hull (within the tolerance)."""
    scale = np.abs(P).max()
    centre = P[np.unique(faces)].mean(axis=0)  # the orientation about the origin is the caller's
    a, b, c = P[faces[:, 0]], P[faces[:, 1]], P[faces[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    inward = np.einsum("fr,fr->f", n, a - centre) < 0
    n[inward] *= -1
    turned = faces.copy()
    turned[inward, 0], turned[inward, 1] = faces[inward, 1], faces[inward, 0]
    assert cycle_code(turned, len(P)) == 0
    height = (P @ n.T) - np.einsum("fr,fr->f", n, a)
    assert height.max() <= 64 * PLANE_TOL * scale
    eq = ConvexHull(P).equations
    for v in np.unique(faces):
        assert np.abs(eq[:, :3] @ P[v] + eq[:, 3]).min() <= 64 * PLANE_TOL * scale


def test_general_position_gives_qhulls_facets():
    rng = np.random.default_rng(1)
    for n in (4, 6, 9, 27, 80, 300):
        for _ in range(20):
            P = rng.normal(size=(n, 3)) + rng.normal(size=3)
            assert _canonical(hull_faces(P)) == _canonical(_qhull_oriented(P))


def test_oriented_outward_about_an_interior_origin():
    rng = np.random.default_rng(2)
    P = rng.normal(size=(40, 3))
    P -= P.mean(axis=0)
    faces = hull_faces(P)
    assert (np.linalg.det(P[faces]) > 0).all()


@settings(max_examples=200, deadline=None)
@given(st.integers(4, 40), st.integers(0, 2**32 - 1), st.sampled_from([1.0, 2.0, 1e-6, 1e6]))
def test_coplanar_and_repeated_points_give_a_hull(n, seed, scale):
    rng = np.random.default_rng(seed)
    P = np.round(rng.normal(size=(n, 3)) * 1.5) * scale
    if np.linalg.matrix_rank(P - P[0]) < 3:
        assert len(hull_faces(P)) == 0  # flat: declined, for the caller's qhull to refuse too
        return
    faces = hull_faces(P)
    if len(faces):  # declining is allowed (the caller asks qhull); a surface must be a hull
        _a_hull_of(P, faces)


def test_minkowski_sums_give_a_hull():
    """The vertices of ``sums`` evidence: every sum of one generator (or none) per contact, whose
    hull has parallelogram facets."""
    rng = np.random.default_rng(3)
    declined = 0
    for _ in range(200):
        G = rng.normal(size=(3, 2, 3))
        choices = [np.vstack([np.zeros(3), g]) for g in G]
        P = np.array([a + b + c for a in choices[0] for b in choices[1] for c in choices[2]])
        faces = hull_faces(P)
        if len(faces):
            _a_hull_of(P, faces)
        else:
            declined += 1
    assert declined == 0


@pytest.mark.parametrize("P", [np.zeros((5, 3)), np.eye(3), np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]),
                               np.array([[np.nan, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])])
def test_degenerate_sets_are_declined(P):
    assert hull_faces(P).shape == (0, 3)


def test_many_sets_at_once():
    """Many sets in one call (their work arrays shared, sized for the largest) give each set's
    own faces, also after a larger set and after a declined one."""
    rng = np.random.default_rng(5)
    sets = [rng.normal(size=(n, 3)) for n in (4, 9, 30, 50, 5, 27)]
    sets.insert(1, np.c_[rng.normal(size=(6, 2)), np.zeros(6)])
    sets.insert(5, np.c_[rng.normal(size=(40, 2)), np.zeros(40)])
    cube = np.array([[x, y, z] for x in (-1.0, 1.0) for y in (-1.0, 1.0) for z in (-1.0, 1.0)])
    sets.append(np.concatenate([cube, 0.5 * cube]))  # coplanar faces, interior points
    V = np.ascontiguousarray(np.concatenate(sets))
    vstart = np.cumsum([0] + [len(s) for s in sets]).astype(np.int64)
    faces, fstart = hulls_faces(V, vstart)
    for s, P in enumerate(sets):
        assert np.array_equal(faces[fstart[s]:fstart[s + 1]], hull_faces(P))
    assert fstart[2] == fstart[1] and fstart[6] == fstart[5]


# --- the evidence of many rows held in columns ----------------------------------------------------

_kinds = st.sampled_from(["generators", "sums", "support", "l1"])
_ints = st.lists(st.integers(-1, 40), max_size=12).map(tuple)
_floats = st.lists(st.floats(-1e3, 1e3, allow_nan=False), max_size=9).map(tuple)
_direction = st.one_of(st.none(), st.tuples(*[st.floats(-10, 10, allow_nan=False)] * 3))
_evidence = st.builds(Evidence, _kinds, _direction, _ints, _floats, _ints)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.one_of(st.none(), st.tuples(_evidence, _evidence)), max_size=12), st.integers(1, 3),
       st.booleans())
def test_evidence_columns_are_the_rows_and_their_arrow_column(pairs, split, backwards):
    """Rows assembled from blocks, in row order or not, give back each row's evidence, and their
    results column is the one Arrow builds from the rows' JSON dicts (the route the columns
    replace)."""
    import pyarrow as pa

    from qualgrasp.certify.batch._arrow import evidence_array
    from qualgrasp.certify.files.results import RESULT_SCHEMA
    from qualgrasp.certify.quality.evidence import EvidenceColumns

    at = np.array([i for i, p in enumerate(pairs) if p is not None], dtype=np.int64)
    cols = []
    for j in range(2):
        local = np.arange(len(at))[::-1 if backwards else 1]
        blocks = [EvidenceColumns.block(part, [pairs[at[q]][j] for q in part]) for part in np.array_split(local, split)
                  if len(part)]
        cols.append(EvidenceColumns.assemble(len(at), blocks))
        assert [cols[j].row(q) for q in range(len(at))] == [pairs[i][j] for i in at]
    got = evidence_array(cols[0], cols[1], at, len(pairs))
    want = pa.array([None if p is None else {"l1": p[0].to_json(), "linf": p[1].to_json()} for p in pairs],
                    type=RESULT_SCHEMA.field("eps_evidence").type)
    assert got.equals(want)


_items = st.one_of(st.integers(-(2**31) - 2, 2**31 + 2), st.floats(allow_nan=True), st.booleans(),
                  st.integers(-5, 5).map(float), st.just("1"))
_json_lists = st.one_of(st.none(), st.lists(_items, max_size=6), st.lists(st.integers(-40, 40), max_size=9),
                        st.lists(st.floats(-1e3, 1e3), max_size=9),
                        st.lists(st.integers(-(2**31) - 2, 2**31 + 2), max_size=3), st.lists(st.floats(), max_size=3))


@settings(max_examples=300, deadline=None)
@given(_kinds, _json_lists, _json_lists, _json_lists, _json_lists)
def test_evidence_read_back_is_the_checks_item_by_item(kind, direction, ref, points, faces):
    """Evidence.from_json takes plain lists as they are; anything else goes item by item: the
    same evidence, or the same error, as the item-by-item checks alone give."""
    d = {"kind": kind, "direction": direction, "ref": ref, "points": points, "faces": faces}

    def read():
        try:
            return Evidence.from_json(d)
        except ValueError as err:
            return str(err)

    got = read()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(evidence_module, "_plain_numbers", lambda v, integer: False)
        want = read()
    assert got == want and type(got) is type(want)
    if not isinstance(got, str):
        assert [type(x) for x in got.ref + got.faces] == [int] * len(got.ref + got.faces)


@settings(max_examples=200, deadline=None)
@given(st.floats(0, 10), st.floats(0, 100), st.floats(0, 2))
def test_lower_bounds_of_many_rows_are_each_rows(eps, d2, spread):
    """The stated ``lo`` of many rows at once is :func:`_lower` of each, bit for bit (near the
    tolerance's edges too)."""
    from qualgrasp.certify.quality import bounds
    from qualgrasp.certify.quality.evidence import EPS_TOL

    x = eps * eps
    rows = [(d2, d2 * (1 + spread)), (x, x), (x * (1 - EPS_TOL / 4), x * (1 + EPS_TOL / 4)),
            (np.nextafter(x * (1 - EPS_TOL / 4), 0), x), (0.0, x), (x * 0.5, x * (1 + EPS_TOL / 4))]
    lo = bounds._lowers(np.full(len(rows), eps), np.array([a for a, _ in rows]), np.array([b for _, b in rows]))
    assert [float(v) for v in lo] == [bounds._lower(eps, r) for r in rows]


# --- hulls in more dimensions: the spatial refinement's guide and the 6-D triangulation ------------

def test_planes_in_six_dimensions_are_qhulls_equations():
    """Facet normals and offsets in 4 and 6 dimensions, built at once and built incrementally
    (points added to a hull of the first ones, as the spatial refinement adds them), against qhull."""
    from qualgrasp.certify._kernels.hull import hull_facets, hull_planes, live_planes, planes_insert, planes_start

    rng = np.random.default_rng(6)
    for d, n, extra in ((4, 12, 3), (6, 20, 2), (6, 40, 5)):
        for _ in range(10):
            P = rng.normal(size=(n + extra, d)) + rng.normal(size=d)
            want = ConvexHull(P).equations
            verts, normal, off, alive, F, centre, ok = planes_start(np.ascontiguousarray(P[:n]))
            assert ok
            verts, normal, off, alive, F, ok = planes_insert(P, n, verts, normal, off, alive, F, centre)
            assert ok
            for normals, dist in (live_planes(normal, off, alive, F), hull_planes(P)):
                got = np.c_[normals, -dist]
                assert len(got) == len(want)
                assert np.abs(got[:, None, :] - want[None, :, :]).max(axis=2).min(axis=1).max() < 1e-9
            facets = hull_facets(P)
            want_facets = np.sort(ConvexHull(P).simplices, axis=1)
            assert sorted(map(tuple, np.sort(facets, axis=1))) == sorted(map(tuple, want_facets))


def test_flat_sets_in_six_dimensions_are_declined():
    from qualgrasp.certify._kernels.hull import hull_planes

    rng = np.random.default_rng(7)
    P = np.c_[rng.normal(size=(30, 5)), np.zeros(30)]
    assert hull_planes(P)[0].shape == (0, 6)
    assert hull_planes(rng.normal(size=(6, 6)))[0].shape == (0, 6)  # too few points


def test_six_dimensional_face_bounds_hold_the_exact_distance():
    """The float checks of 6-D faces (cofactors from shared Laplace minors) bound the exact squared
    distance of each face's hyperplane (rational arithmetic on the float vertices, taken as
    exact), prove the orientation only where the exact determinant is positive, stay tight, and
    agree with Leibniz's sums."""
    from fractions import Fraction

    from qualgrasp.certify._kernels.surface import face_bounds, face_bounds_laplace, leibniz_tables

    def exact(P):
        D = [[Fraction(P[q][r]) - Fraction(P[0][r]) for r in range(6)] for q in range(1, 6)]

        def det(M):
            M, s = [row[:] for row in M], Fraction(1)
            for c in range(len(M)):
                p = next((r for r in range(c, len(M)) if M[r][c] != 0), None)
                if p is None:
                    return Fraction(0)
                if p != c:
                    M[c], M[p], s = M[p], M[c], -s
                s *= M[c][c]
                for r in range(c + 1, len(M)):
                    f = M[r][c] / M[c][c]
                    M[r] = [a - f * b for a, b in zip(M[r], M[c])]
            return s

        n = [(-1) ** r * det([[row[q] for q in range(6) if q != r] for row in D]) for r in range(6)]
        dt = sum(n[r] * Fraction(P[0][r]) for r in range(6))
        return dt, dt * dt / sum(x * x for x in n)

    rng = np.random.default_rng(8)
    perms, signs = leibniz_tables(5)
    widths = []
    for t in range(60):
        P = (rng.normal(size=(6, 6)) + 3 * rng.normal(size=6)) * 10.0 ** rng.integers(-3, 4)
        EV = np.zeros_like(P) if t % 2 else np.abs(rng.normal(size=P.shape)) * 1e-13 * np.abs(P).max()
        face = np.arange(6, dtype=np.int64)[None]
        ok, lo, hi = face_bounds_laplace(P, EV, face, perms, signs)
        leibniz = face_bounds(P, EV, face, perms, signs)
        assert ok[0] == leibniz[0][0] and np.allclose([lo[0], hi[0]], [leibniz[1][0], leibniz[2][0]], rtol=1e-8)
        dt, d2 = exact(P.tolist())
        assert not ok[0] or dt > 0
        if ok[0]:
            assert Fraction(float(lo[0])) <= d2 <= Fraction(float(hi[0]))
            if not EV.any():
                widths.append((hi[0] - lo[0]) / hi[0])
    assert widths and max(widths) < 1e-8


@pytest.mark.parametrize("d", [3, 6])
def test_orientation_propagates_across_ridges_from_the_surest_face(d):
    """qhull's simplices of random points about the origin, each turned over at random: the
    propagated orientation closes the cycle and agrees with every determinant's sign; a face
    whose sign is forced wrong (a sliver whose rounding flipped) is put right by its neighbours;
    faces that are not a closed surface keep their own signs and are reported open."""
    rng = np.random.default_rng(d)
    for _ in range(5):
        P = rng.normal(size=(3 * d + 8, d))
        faces = np.array(ConvexHull(P).simplices, dtype=np.int64)
        turn = rng.random(len(faces)) < 0.5
        faces[turn, 0], faces[turn, 1] = faces[turn, 1], faces[turn, 0].copy()
        oriented = orient_faces(P, faces)
        assert cycle_code(oriented, len(P)) == 0
        assert (np.linalg.det(P[oriented]) > 0).all()
        sliver = int(np.argmin(np.abs(np.linalg.det(P[faces]))))
        wrong = np.linalg.det(P[faces]) < 0
        wrong[sliver] = not wrong[sliver]
        seed = int(np.argmax(np.abs(np.linalg.det(P[faces]))))
        flip, reached = orient_cycle(faces, len(P), seed, bool(wrong[seed]))
        assert reached.all() and flip[sliver] != wrong[sliver] and (flip == (np.linalg.det(P[faces]) < 0)).all()
        open_ = faces[1:]
        flip, reached = orient_cycle(open_, len(P), 0, False)
        assert not reached.any()
        two = np.vstack([faces, faces + len(P)])  # two closed pieces: only the seed's is reached
        assert orient_cycle(two, 2 * len(P), 0, False)[1].sum() == len(faces)
        assert (np.linalg.det(P[orient_faces(P, open_)]) >= 0).all()
        assert cycle_code(surfaces_faces([P])[0], len(P)) == 0
        if d == 6:  # the producer skips the cycle check only where this holds
            faces6, closed = oriented_surface(P, hull_facets(P))
            assert closed and cycle_code(faces6, len(P)) == 0
            assert not oriented_surface(P, hull_facets(P)[1:])[1]


@pytest.mark.parametrize("kind", ["generic", "rounded", "repeated"])
def test_a_hull_grown_batch_by_batch_has_the_facets_of_one_built_at_once(kind):
    """The spatial epsilon grows its hull round by round and its checker builds it at once
    (:func:`hull_facets`): the rule depends on the points alone, so the facets are the same, on
    points in general position and on rounded or repeated ones (near-coplanar sets, failed
    insertions and restarts)."""
    rng = np.random.default_rng(11)
    for _ in range(6):
        P = rng.normal(size=(60, 6))
        if kind == "rounded":
            P = np.round(P, 1)
        elif kind == "repeated":
            P[rng.integers(0, 60, 15)] = P[rng.integers(0, 60, 15)]
        state = grow_start(6)
        n = 0
        while n < len(P):
            n = min(len(P), n + int(rng.integers(1, 6)))
            state = hull_grow(np.ascontiguousarray(P[:n]), *state)
        verts, normal, off, alive, F, centre, done = state
        assert done == len(P)
        assert np.array_equal(live_facets(verts, alive, F), hull_facets(P))
        if kind == "generic":
            assert _canonical(np.sort(hull_facets(P), axis=1)) == _canonical(np.sort(ConvexHull(P).simplices, axis=1))


def test_a_surface_that_cannot_be_oriented_is_not_reported_closed():
    """The real projective plane's six-vertex triangulation: every edge in exactly two triangles,
    yet no orientation agrees across all of them."""
    rp2 = np.array([[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5], [0, 5, 1], [1, 2, 4], [2, 3, 5], [3, 4, 1],
                    [4, 5, 2], [5, 1, 3]])
    edges = np.sort(np.vstack([rp2[:, [0, 1]], rp2[:, [1, 2]], rp2[:, [0, 2]]]), axis=1)
    assert (np.unique(edges, axis=0, return_counts=True)[1] == 2).all()
    assert not orient_cycle(rp2, 6, 0, False)[1].any()
    assert cycle_code(rp2, 6) == 4


def _triangle_sets():
    """Triangle sets on at most 30 vertices: closed hulls of random points (oriented), and the same with a
    face turned over, dropped, repeated, or with one index changed (to another vertex, possibly
    one the face already has)."""
    @st.composite
    def sets(draw):
        n = draw(st.integers(4, 30))
        seed = draw(st.integers(0, 2**32 - 1))
        P = np.random.default_rng(seed).normal(size=(n, 3))
        faces = hull_faces(P).copy()
        flip, reached = orient_cycle(faces, n, 0, False)
        assert reached.all()
        faces[flip] = faces[flip][:, [1, 0, 2]]
        kind = draw(st.sampled_from(["closed", "turned", "dropped", "repeated", "index"]))
        f = draw(st.integers(0, len(faces) - 1))
        if kind == "turned":
            faces[f, [0, 1]] = faces[f, [1, 0]]
        elif kind == "dropped":
            faces = np.delete(faces, f, axis=0)
        elif kind == "repeated":
            faces = np.vstack([faces, faces[f:f + 1]])
        elif kind == "index":
            faces[f, draw(st.integers(0, 2))] = draw(st.integers(0, n - 1))
        return np.ascontiguousarray(faces), n, kind
    return sets()


@settings(max_examples=300, deadline=None)
@given(_triangle_sets())
def test_triangles_are_checked_as_the_sorted_ridges_check_them(case):
    """:func:`cycle_code` checks triangle sets on few vertices by a table of directed edges; past
    ``TRIANGLES_MAX`` vertices it sorts the ridges. Both give the same code (the same set checked
    with the vertex count raised past the table's limit takes the sorting route), closed hulls
    included, and an index out of range is code 1 either way."""
    faces, n, kind = case
    code = cycle_code(faces, n)
    assert code == cycle_code(faces, n + TRIANGLES_MAX) == _cycle_reference(faces, n)
    assert (code == 0) == (kind == "closed") or kind == "index"
    assert cycle_code(faces, int(faces.max())) in (1, 2)


def _cycle_reference(faces, nv):
    """:func:`cycle_code`'s rule in Python, from its docstring: the first face with an index out of
    range (1) or repeating a vertex (2), its vertices in order; then an odd number of ridges (3);
    then the ridges grouped by their sorted vertices, in that order, the first group not of two
    (3) or of two with the same sign (4)."""
    ridges = []
    for f in np.asarray(faces).tolist():
        for q, v in enumerate(f):
            if not 0 <= v < nv:
                return 1
            if v in f[:q]:
                return 2
        for k in range(3):
            a, b = [f[q] for q in range(3) if q != k]
            ridges.append(((min(a, b), max(a, b)), (-1) ** k * (1 if a < b else -1)))
    if len(ridges) % 2:
        return 3
    groups = {}
    for key, sign in ridges:
        groups.setdefault(key, []).append(sign)
    for key in sorted(groups):
        if len(groups[key]) != 2:
            return 3
        if sum(groups[key]):
            return 4
    return 0


def _torus(rows, cols, shift=0):
    """An oriented triangulated torus on ``rows * cols`` vertices (numbered from ``shift``)."""
    v = lambda i, j: shift + (i % rows) * cols + j % cols  # noqa: E731
    return np.array([t for i in range(rows) for j in range(cols)
                     for t in ((v(i, j), v(i + 1, j), v(i + 1, j + 1)), (v(i, j), v(i + 1, j + 1), v(i, j + 1)))],
                    dtype=np.int64)


def test_every_small_triangle_set_and_tori_about_the_table_limit_get_the_rules_code():
    """Every set of at most two triangles on at most 4 vertices, each index from -1 to ``nv`` (out
    of range, repeated, reversed, repeated faces), and tori on 128 to 130 vertices whole, with a
    face turned over, dropped or doubled, all turned over, or given one vertex too few or too many:
    the code of the rule written
    out in Python (:func:`_cycle_reference`), on both sides of ``TRIANGLES_MAX`` (128 vertices)."""
    import itertools

    for nv in range(5):
        for F in range(3):
            for flat in itertools.product(range(-1, nv + 1), repeat=3 * F):
                faces = np.array(flat, dtype=np.int64).reshape(F, 3)
                assert cycle_code(faces, nv) == _cycle_reference(faces, nv), (faces, nv)
    for shape, shift in (((8, 16), 0), ((8, 16), 1), ((5, 26), 0), ((3, 43), 0)):
        torus = _torus(*shape, shift=shift)
        nv = shape[0] * shape[1] + shift
        cases = [torus, torus[1:], np.vstack([torus, torus[:1]]), torus[:, [1, 0, 2]]]
        turned = torus.copy()
        turned[3] = turned[3, [1, 0, 2]]
        cases.append(turned)
        for faces in cases:
            faces = np.ascontiguousarray(faces)
            for n in (nv - 1, nv, nv + 1):
                assert cycle_code(faces, n) == _cycle_reference(faces, n), (shape, shift, n)
        assert cycle_code(torus, nv) == 0


def test_face_normals_in_3d_are_leibniz_sums_bit_for_bit():
    """:func:`face_bounds` writes out the 3-D cofactors and their error bounds: each float is the
    one the general Leibniz loop gives (run as Python), on wide magnitudes, zeros of both signs,
    and infinities."""
    from qualgrasp.certify._kernels.linalg import gamma
    from qualgrasp.certify._kernels.surface import _leibniz_normal, _normal3, leibniz_tables

    perms, signs = leibniz_tables(2)
    rng = np.random.default_rng(12)
    special = np.array([0.0, -0.0, np.inf, -np.inf, 1e-308, -5e-324, 1e308])
    for t in range(3000):
        D = rng.normal(size=(2, 3)) * 10.0 ** rng.integers(-200, 200, size=(2, 3))
        ED = np.abs(rng.normal(size=(2, 3))) * 10.0 ** rng.integers(-300, 0, size=(2, 3))
        if t % 3 == 0:
            D.flat[rng.integers(0, 6, 2)] = rng.choice(special, 2)
            ED.flat[rng.integers(0, 6)] = 0.0
        g = 3.0 * gamma(7)  # face_bounds' constant in 3-D
        fast = np.empty(3), np.empty(3)
        loop = np.empty(3), np.empty(3)
        _normal3(D, ED, g, *fast)
        with np.errstate(all="ignore"):  # infinities on purpose: the loop in Python warns where the kernel does not
            _leibniz_normal.py_func(D, ED, perms, signs, g, *loop)
        for a, b in zip(fast, loop):
            assert np.array_equal(a.view(np.uint64), b.view(np.uint64)), (D, ED, a, b)


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(st.sampled_from([0.0, 1.0, 2.0, -1.0, np.inf]), st.floats(-1, 4)), min_size=1, max_size=40))
def test_insertion_order_is_a_stable_sort_largest_first(d2):
    """The hulls insert points farthest first, ties in index order, the left-out (negative) ones
    last: numpy's stable argsort of ``-d2``, whatever the ties and infinities."""
    from qualgrasp.certify._kernels.hull import _farthest_first

    d2 = np.array(d2)
    order = np.full(len(d2), -1, dtype=np.int64)
    _farthest_first(d2, order)
    assert order.tolist() == np.argsort(-d2, kind="stable").tolist()
