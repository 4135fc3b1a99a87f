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


GRASPS = _grasps()


def test_the_compiled_route_states_the_array_routes_programme_bit_for_bit():
    assert len(GRASPS) >= 2000
    for grasp in GRASPS:
        new, old = grasp_problem(grasp), _array_route(grasp)
        assert isinstance(new.to_values, np.ndarray)  # no sparse map for one small grasp
        assert _same_bits(new.columns, old.columns) and _same_bits(new.to_values, old.to_values)
        assert _same_bits(new.system.columns, old.system.columns)
        assert (new.rays, new.cones, new.system.blocks, new.system.layout) == \
               (old.rays, old.cones, old.system.blocks, old.system.layout)


def test_verdicts_margins_and_certificates_are_the_array_routes_and_all_verify():
    statuses = set()
    for grasp in GRASPS:
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
