"""One spatial grasp through the API (issue 27, part 6): :func:`grasp_problem` builds a point or
soft grasp's programme by the compiled route (:func:`qualgrasp.certify.core.problem.lorentz_layout`,
``_kernels.conic.lorentz_system``), with no sparse map. It must state the very programme the
array route states (``conic_columns`` and ``grasp_system``, which the columnar batches use),
bit for bit, so verdicts, margins and certificates are those of the array route, and the exact
checker accepts every certificate."""

import numpy as np
import pytest
import scipy.sparse as sp

from qualgrasp.certify import Contact, Grasp, form_closure, force_closure, positive_span, verify
from qualgrasp.certify.batch import random_grasps
from qualgrasp.certify.core.closure import decide
from qualgrasp.certify.core.problem import (DENSE_COLUMNS, ClosureProblem, conic_columns, grasp_problem,
                                            grasp_system, span_problem, span_system)
from qualgrasp.certify.core.wrench import grasp_arrays
from qualgrasp.certify.solvers import make_solver


def _array_route(grasp: Grasp) -> ClosureProblem:
    """The programme of ``grasp`` built by the array route, as a batch of one grasp."""
    P, N, _, params, c, L = grasp_arrays(grasp)
    models = tuple(contact.model for contact in grasp.contacts)
    columns, rays, cones, to_values = conic_columns(P[None], N[None], {k: v[None] for k, v in params.items()},
                                                    models, np.array(c)[None], np.array([L]))
    cones = tuple((start, size, float(k[0])) for start, size, k in cones)
    return ClosureProblem(columns[0], rays, cones, to_values[0], grasp_system(grasp))


def _same_bits(a, b) -> bool:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and np.array_equal(a.view(np.int64), b.view(np.int64))


def _antipodal(rng: np.random.Generator, model: str, count: int) -> list[Grasp]:
    """Two contacts squeezing along a line through the object, and one random contact: grasps
    on the closure boundary (tight contacts, the squeeze rule, exact Farkas projections)."""
    out = []
    for _ in range(count):
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        a = rng.uniform(0.5, 1.5)
        params = {"torsion": 0.2} if model == "soft" else {}
        third = rng.normal(size=3)
        contacts = (Contact(a * u, -u, model, 0.5, **params), Contact(-a * u, u, model, 0.5, **params),
                    Contact(third, -third + 0.7 * rng.normal(size=3), model, 0.3, **params))
        out.append(Grasp(contacts))
    return out


def _grasps() -> list[Grasp]:
    grasps = []
    for model in ("point", "soft"):
        for m in range(2, 7):
            grasps += random_grasps(300 + m, 200, dim=3, n_contacts=m, model=model)
        grasps += _antipodal(np.random.default_rng(7), model, 60)
    mixed = [Grasp(a.contacts + b.contacts) for a, b in
             zip(random_grasps(11, 60, dim=3, n_contacts=2, model="point"),
                 random_grasps(12, 60, dim=3, n_contacts=2, model="soft"))]
    return grasps + mixed


@pytest.fixture(scope="module")
def grasps() -> list[Grasp]:
    """The grasps of the comparisons, made once when a test of the module first runs (not at
    collection, which every test process does)."""
    return _grasps()


def test_the_compiled_route_states_the_array_routes_programme_bit_for_bit(grasps):
    assert len(grasps) >= 2000
    for grasp in grasps:
        new, old = grasp_problem(grasp), _array_route(grasp)
        assert isinstance(new.to_values, np.ndarray)  # no sparse map for one small grasp
        assert _same_bits(new.columns, old.columns) and _same_bits(new.to_values, old.to_values)
        assert _same_bits(new.system.columns, old.system.columns)
        assert (new.rays, new.cones, new.system.blocks, new.system.layout) == \
               (old.rays, old.cones, old.system.blocks, old.system.layout)


def test_verdicts_margins_and_certificates_are_the_array_routes_and_all_verify(grasps):
    statuses = set()
    for grasp in grasps:
        v = force_closure(grasp)
        ref = decide(_array_route(grasp), lambda g=grasp: grasp_system(g, exact=True).columns,
                     make_solver("fast"))
        assert (v.status, v.margin, v.certificate) == (ref.status, ref.margin, ref.certificate)
        assert verify(grasp, v.certificate, status=v.status, margin=v.margin).ok
        statuses.add((v.status, bool(v.certificate.tight)))
    # both verdicts were reached, and so were certificates with tight contacts
    assert {("closure", False), ("no_closure", False), ("no_closure", True)} <= statuses


def test_grasps_beyond_the_dense_bound_keep_the_array_route():
    grasp = random_grasps(5, 1, dim=3, n_contacts=DENSE_COLUMNS // 3 + 1, model="point")[0]
    problem = grasp_problem(grasp)
    assert not isinstance(problem.to_values, np.ndarray)
    v, ref = force_closure(grasp), decide(_array_route(grasp), lambda: grasp_system(grasp, exact=True).columns,
                                          make_solver("fast"))
    assert (v.status, v.margin, v.certificate) == (ref.status, ref.margin, ref.certificate)


@pytest.mark.parametrize("model", ["frictionless", "point"])
def test_patterns_with_rays_or_planar_grasps_keep_their_route(model):
    """A spatial pattern with a frictionless contact, and planar grasps, are not Lorentz patterns:
    their programmes are those of the generator or array routes, as before."""
    planar = random_grasps(3, 1, dim=2, n_contacts=3, model=model)[0]
    assert grasp_problem(planar).system.layout == "generators"
    spatial = random_grasps(4, 1, dim=3, n_contacts=3, model="point")[0]
    mixed = Grasp(spatial.contacts + (Contact((0, 0, 1), (0, 0, -1)),))
    problem = grasp_problem(mixed)
    assert problem.rays == (9,) and problem.system.layout == "forces"


def _sparse_identity(problem: ClosureProblem) -> ClosureProblem:
    return ClosureProblem(problem.columns, problem.rays, problem.cones, sp.identity(problem.nvar, format="csr"),
                          problem.system)


def test_generator_programmes_state_the_values_of_the_sparse_identity():
    """Form closure and positive spanning keep a dense identity for small programmes: the same
    verdicts and certificates as with the sparse identity they had."""
    grasps = (random_grasps(21, 150, dim=2, n_contacts=4, model="frictionless")
              + random_grasps(22, 150, dim=3, n_contacts=8, model="frictionless")
              + random_grasps(23, 100, dim=3, n_contacts=9, model="point"))
    closure = 0
    for grasp in grasps:
        problem = grasp_problem(grasp, frictionless=True)
        assert isinstance(problem.to_values, np.ndarray)
        v = form_closure(grasp)
        ref = decide(_sparse_identity(problem), lambda g=grasp: grasp_system(g, frictionless=True, exact=True).columns,
                     make_solver("fast"))
        assert (v.status, v.margin, v.certificate) == (ref.status, ref.margin, ref.certificate)
        closure += v.status == "closure"
    vectors = np.random.default_rng(5).normal(size=(100, 5, 3))
    for V in vectors:
        v = positive_span(V)
        ref = decide(_sparse_identity(span_problem(V)), lambda V=V: span_system(V, exact=True).columns,
                     make_solver("fast"))
        assert (v.status, v.margin, v.certificate) == (ref.status, ref.margin, ref.certificate)
        closure += v.status == "closure"
    assert closure >= 50


def _project_out_by_fractions(y, A):
    """The projection's formula over Fractions: ``y - B (B'B)^{-1} B'y``, ``B`` the pivot
    columns of a reduced row echelon form computed over Fractions (the test's oracle)."""
    from qualgrasp.certify.core import exact as ex

    cols = ex.row_echelon(A)[1]
    if not cols:
        return list(y)
    B = [[row[j] for j in cols] for row in A]
    k = len(cols)
    BtB = [[sum(B[r][i] * B[r][j] for r in range(len(B))) for j in range(k)] for i in range(k)]
    c = ex.solve(BtB, [sum(B[r][i] * y[r] for r in range(len(B))) for i in range(k)])
    return [y[r] - sum(B[r][i] * c[i] for i in range(k)) for r in range(len(B))]


def test_the_exact_projection_in_integers_is_the_fraction_formula(grasps):
    """exact.project_out (integers, fraction-free) gives the very rationals of the formula over
    Fractions: on the tight columns of real certificates, and on random rank-deficient matrices
    of floats, of rationals with odd denominators, and with repeated columns."""
    from fractions import Fraction

    from qualgrasp.certify.core import exact as ex
    from qualgrasp.certify.core.wrench import to_exact

    rng = np.random.default_rng(9)
    cases = []
    for grasp in grasps[::4]:
        v = force_closure(grasp)
        if v.certificate.kind == "farkas" and v.certificate.tight:
            Cx = grasp_system(grasp, exact=True)
            cols = [j for b in v.certificate.tight for j in Cx.blocks[b].cols]
            cases.append((list(to_exact(rng.normal(size=6))), [[Cx.columns[i, j] for j in cols] for i in range(6)]))
    assert len(cases) >= 10
    for _ in range(300):
        d, k, r = 6, int(rng.integers(1, 8)), int(rng.integers(1, 7))
        F = rng.normal(size=(d, r)) @ rng.normal(size=(r, k)) if rng.random() < 0.5 else rng.normal(size=(d, k))
        A = [list(row) for row in to_exact(F)]
        if rng.random() < 0.3:
            A = [[Fraction(int(rng.integers(-9, 9)), int(rng.integers(1, 9)) * 3) for _ in range(k)] for _ in range(d)]
        if rng.random() < 0.3:
            A = [row + row[:1] for row in A]
        y = [Fraction(v) for v in rng.normal(size=d)]
        cases.append((y, A))
    cases.append(([Fraction(1)] * 6, [[0, 0]] * 6))
    for y, A in cases:
        assert ex.project_out(y, A) == _project_out_by_fractions(y, A)
        assert ex.independent_columns(A) == ex.row_echelon(A)[1]
