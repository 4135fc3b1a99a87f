"""Ferrari-Canny epsilon: planar exact against qhull and closed forms, spatial bounds against
independent fine linearisations, torque scaling, degenerate inputs, Steinitz efficiency."""

import math
import subprocess
import sys
import time
from itertools import product

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from qualgrasp.certify import Contact, Grasp, force_closure, grasp_from_dict
from qualgrasp.certify.quality import epsilon
from qualgrasp.experiments.bench import epsilon_linearised
from qualgrasp.certify.batch import random_grasp, random_grasps
from qualgrasp.certify.quality import efficiency, steinitz_bound
from helpers import rotation


def _square(s, L):
    """Four frictionless contacts on the sides of [-1, 1]^2 whose torques cancel pairwise."""
    contacts = (Contact((1, s), (-1, 0)), Contact((s, 1), (0, -1)),
                Contact((-1, -s), (1, 0)), Contact((-s, -1), (0, 1)))
    return Grasp(contacts, center=(0, 0), length=L)


@pytest.mark.parametrize("s, L", [(0.5, 1.0), (0.5, 2.0), (0.3, 0.7), (0.8, math.sqrt(2))])
def test_square_closed_forms(s, L):
    """With tau = s / L the wrenches are w = (-1, 0, tau), (0, -1, -tau), (1, 0, tau),
    (0, 1, -tau).

    L1: the GWS is the tetrahedron on these points (the origin is their centroid). Its facet
    through (+-1, 0, tau) and (0, 1, -tau) has normal (0, 2 tau, 1) up to sign and passes at
    distance tau / sqrt(1 + 4 tau^2); by symmetry all four facets do, so
    epsilon_L1 = tau / sqrt(1 + 4 tau^2).

    Linf: the Minkowski sum of the segments [0, w_i] is a zonotope centred at sum(w)/2 = 0; its
    facet normals are w_i x w_j and the support is sum_k |u . w_k| / 2. Pairs (1, 3) and (2, 4)
    give unit normals e_y, e_x and support 1; the other pairs give (tau, tau, -1) up to signs,
    with sum |u . w_k| = 4 tau, hence epsilon_Linf = min(1, 2 tau / sqrt(1 + 2 tau^2)).
    """
    g = _square(s, L)
    tau = s / L
    e1, einf = epsilon(g, "L1"), epsilon(g, "Linf")
    assert e1.lo == e1.hi == pytest.approx(tau / math.sqrt(1 + 4 * tau**2), rel=1e-12)
    assert einf.lo == pytest.approx(min(1.0, 2 * tau / math.sqrt(1 + 2 * tau**2)), rel=1e-12)
    assert e1.center == (0.0, 0.0) and e1.length == L


@pytest.mark.parametrize("mu", [0.2, 0.5, 1.0])
@pytest.mark.parametrize("L", [0.5, 1.0, 3.0])
def test_antipodal_closed_form_and_length_dependence(mu, L):
    """Two opposite point contacts at (+-1, 0) with normals -+x, center 0. The four edge wrenches
    are (-1, -mu, -mu/L), (-1, mu, mu/L), (1, mu, -mu/L), (1, -mu, mu/L): alternate corners of
    the box [+-1] x [+-mu] x [+-mu/L], a tetrahedron centred at the origin whose facets are the
    planes x + y / mu + z L / mu = 1 (with the other sign patterns), at distance
    1 / sqrt(1 + 1/mu^2 + L^2/mu^2). So epsilon_L1 = mu / sqrt(mu^2 + 1 + L^2): it falls as the
    length dividing torques grows, as documented (torque coordinates scale by 1/L)."""
    g = Grasp((Contact((1, 0), (-1, 0), "point", mu), Contact((-1, 0), (1, 0), "point", mu)),
              center=(0, 0), length=L)
    assert epsilon(g).hi == pytest.approx(mu / math.sqrt(mu * mu + 1 + L * L), rel=1e-12)


def _qhull_eps(points):
    eq = ConvexHull(points).equations
    return max(0.0, float((-eq[:, -1]).min()))


def test_planar_epsilon_equals_qhull():
    """Exact planar epsilon (facet-normal enumeration) against scipy's ConvexHull of the
    generators (L1) and of all sums of per-contact vertices (Linf)."""
    worst = 0.0
    count = 0
    for kw in (dict(n_contacts=3, model="point"), dict(n_contacts=2, model="point", spread=0.4),
               dict(n_contacts=5, model="frictionless"), dict(n_contacts=4, model="point")):
        for g in random_grasps(21, 150, dim=2, **kw):
            if force_closure(g).status != "closure":
                continue
            from qualgrasp.certify.core.wrench import generator_columns, grasp_arrays

            P, N, mu, _, c, L = grasp_arrays(g)
            W, owner = generator_columns(P, N, mu, tuple(x.model for x in g.contacts), c, L)
            gens = W.T
            l1 = _qhull_eps(np.vstack([np.zeros(3), gens]))
            parts = [np.vstack([np.zeros(3), gens[owner == i]]) for i in range(len(g.contacts))]
            sums = [sum(choice) for choice in product(*parts)]
            linf = _qhull_eps(np.array(sums))
            worst = max(worst, abs(epsilon(g, "L1").hi - l1), abs(epsilon(g, "Linf").hi - linf))
            count += 1
    assert count > 100
    assert worst < 1e-12


def _support_direct(g, u, norm):
    """Exact support function written from first principles: for each contact the largest
    u . w over wrenches of forces with unit normal component, a_n + mu norm(a_t) (plus the
    torsional term), where a is the force-space functional of u."""
    c = np.array(g.center)
    vals = []
    for ct in g.contacts:
        n = np.array(ct.n)
        r = np.array(ct.p) - c
        uf, ut = u[:3], u[3:]
        a = uf + np.cross(ut, r) / g.length  # u . (f, r x f / L) = f . (uf + (ut x r) / L)
        an = a @ n
        at = a - an * n
        extra = 0.0
        if ct.model == "soft":
            extra = (ct.torsion * (ut @ n) / g.length) ** 2
        v = an + ct.mu * math.sqrt(at @ at + extra) if ct.model != "frictionless" else an
        vals.append(max(0.0, v))
    return max(vals) if norm == "L1" else sum(vals)


def _fine_lower(g, norm, edges=48):
    """Epsilon of inscribed cones with many edges (qhull); a lower bound of the exact value."""
    return epsilon_linearised(g, norm, edges)


SPATIAL = [g for g in random_grasps(33, 60, dim=3, n_contacts=3, model="point", spread=0.3)
           if force_closure(g).status == "closure"][:3]


@pytest.mark.parametrize("norm", ["L1", "Linf"])
def test_spatial_bounds_bracket_independent_estimates(norm):
    from scipy.optimize import minimize

    rng = np.random.default_rng(5)
    for g in SPATIAL:
        e = epsilon(g, norm)
        assert 0 < e.lo <= e.hi
        assert e.gap <= 0.0101
        # upper bound: the exact support function (written independently) at sampled directions,
        # polished locally; any direction's value is >= epsilon >= lo
        U = rng.normal(size=(1000, 6))
        U /= np.linalg.norm(U, axis=1, keepdims=True)
        f = lambda x: _support_direct(g, x / np.linalg.norm(x), norm)
        best = min(U, key=f)
        ub = minimize(f, best, method="Nelder-Mead", options=dict(maxiter=3000)).fun
        assert e.lo <= ub * (1 + 1e-9)
        assert f(np.array(e.direction)) == pytest.approx(e.hi, rel=1e-9)  # hi is attained there
        # lower bound: inscribed cones with many edges are inside the exact GWS
        lower = _fine_lower(g, norm, edges=48 if norm == "L1" else 8)
        assert lower <= e.hi * (1 + 1e-9)
        if norm == "L1":
            assert lower >= 0.97 * e.lo  # 48 edges lose little; the bracket is tight


@given(st.integers(0, 2**32 - 1), st.floats(0.3, 3.0), st.integers(0, 2**32 - 1))
@settings(max_examples=25)
def test_scaling_everything_together_leaves_epsilon_unchanged(seed, scale, rseed):
    rng = np.random.default_rng(seed)
    g = random_grasp(rng, dim=2, n_contacts=3, model="point")
    R = rotation(np.random.default_rng(rseed), 2)
    moved = Grasp(tuple(Contact(scale * R @ np.array(c.p) + 5, R @ np.array(c.n), c.model, c.mu)
                        for c in g.contacts),
                  center=scale * R @ np.array(g.center) + 5, length=scale * g.length)
    for norm in ("L1", "Linf"):
        assert epsilon(moved, norm).hi == pytest.approx(epsilon(g, norm).hi, rel=1e-9, abs=1e-12)


def test_spatial_scaling_leaves_bounds_consistent():
    g = SPATIAL[0]
    s = 2.5
    big = Grasp(tuple(Contact(s * np.array(c.p), c.n, c.model, c.mu) for c in g.contacts),
                center=s * np.array(g.center), length=s * g.length)
    a, b = epsilon(g), epsilon(big)
    assert a.lo <= b.hi * (1 + 1e-9) and b.lo <= a.hi * (1 + 1e-9)


def test_margin_does_not_depend_on_center_or_length_but_epsilon_does():
    g = _square(0.5, 1.0)
    h = Grasp(g.contacts, center=(0.3, -0.2), length=4.0)
    assert force_closure(g).margin == pytest.approx(force_closure(h).margin, rel=1e-12)
    assert epsilon(g).hi != pytest.approx(epsilon(h).hi, rel=1e-3)


degenerate = st.sampled_from(["duplicate", "collinear", "single", "antipodal-frictionless",
                              "spatial-point-pair", "spatial-flat"])


@given(degenerate, st.integers(0, 2**32 - 1))
def test_degenerate_grasps_give_zero_without_raising(kind, seed):
    rng = np.random.default_rng(seed)
    p = rng.normal(size=2)
    if kind == "duplicate":
        contacts = (Contact(p, -p, "point", 0.5),) * 3
    elif kind == "collinear":
        contacts = tuple(Contact((x, 0.0), (0, 1), "point", 0.3) for x in rng.normal(size=4))
    elif kind == "single":
        contacts = (Contact(p, -p, "point", 0.5),)
    elif kind == "antipodal-frictionless":
        contacts = (Contact((1, 0), (-1, 0)), Contact((-1, 0), (1, 0)))
    elif kind == "spatial-point-pair":
        contacts = (Contact((0, 0, 1), (0, 0, -1), "point", 0.5),
                    Contact((0, 0, -1), (0, 0, 1), "point", 0.5))
    else:
        contacts = tuple(Contact((x, y, 0.0), (0, 0, 1), "point", 0.2)
                         for x, y in rng.normal(size=(4, 2)))
    g = Grasp(contacts)
    for norm in ("L1", "Linf"):
        e = epsilon(g, norm)
        assert e.lo == e.hi == 0.0
    assert epsilon_linearised(g, "L1") >= 0.0


def test_steinitz_square():
    """Frictionless boundary wrenches of [-1, 1]^2 with center 0 and length sqrt(2) fill the
    hull of the segments (+-1, 0, [-1, 1]/L) and (0, +-1, [-1, 1]/L): facets z = +-1/L and
    +-x +- y = 1, so epsilon(S) = min(1/L, 1/sqrt(2)) = 1/sqrt(2). The square grasp above with
    s = 0.5 has epsilon tau / sqrt(1 + 4 tau^2), tau = 0.5 / sqrt(2)."""
    square = [(-1, -1), (1, -1), (1, 1), (-1, 1)]
    eff = efficiency(_square(0.5, 1.0), square)
    tau = 0.5 / math.sqrt(2)
    assert eff.length == pytest.approx(math.sqrt(2))
    assert eff.boundary_epsilon == pytest.approx(1 / math.sqrt(2), rel=1e-9)
    assert eff.epsilon == pytest.approx(tau / math.sqrt(1 + 4 * tau**2), rel=1e-9)
    assert eff.ratio == pytest.approx(eff.epsilon / eff.boundary_epsilon)
    assert eff.bound is None  # 4 fingers < 2d = 6: no guarantee from the theorems
    assert steinitz_bound(6, 3) == pytest.approx(1 / 45)


@given(st.integers(0, 2**32 - 1))
@settings(max_examples=20)
def test_efficiency_never_exceeds_one(seed):
    """A grasp's wrenches are a subset of the boundary's, so its efficiency is at most 1."""
    rng = np.random.default_rng(seed)
    angles = np.sort(rng.uniform(0, 2 * np.pi, 7))
    poly = np.column_stack([np.cos(angles), np.sin(angles)]) * rng.uniform(0.5, 2.0)
    from qualgrasp.certify.quality import boundary_contacts

    cs = boundary_contacts(poly, 0.05, model="point", mu=0.4)
    pick = rng.choice(len(cs), 3, replace=False)
    eff = efficiency(Grasp(tuple(cs[i] for i in pick)), poly, spacing=0.01)
    assert 0.0 <= eff.ratio <= 1.0 + 1e-9


# --- routes at many contacts, evidence, time limit ---------------------------------------------

from qualgrasp.certify import certify_grasp  # noqa: E402
from qualgrasp.certify.quality import bounds as quality_module  # noqa: E402
from qualgrasp.certify._kernels.epsilon import planar_epsilon_one  # noqa: E402
from qualgrasp.certify.quality.evidence import verify_epsilon  # noqa: E402
from qualgrasp.certify.core.wrench import planar_generator_arrays  # noqa: E402
from qualgrasp.certify.quality.gws import surface_faces  # noqa: E402
from qualgrasp.certify.quality.bounds import epsilons, planar_epsilons  # noqa: E402

PLANAR_KINDS = [dict(n_contacts=3, model="point"), dict(n_contacts=5, model="frictionless"),
                dict(n_contacts=3, model="pad"), dict(n_contacts=8, model="point"),
                dict(n_contacts=14, model="point"), dict(n_contacts=6, model="pad")]


def _closure(grasps):
    return [g for g in grasps if force_closure(g).status == "closure"]


def _row(e):
    """The epsilon columns of a results row from :func:`epsilons`."""
    row = {}
    for norm, key in (("L1", "l1"), ("Linf", "linf")):
        row[f"eps_{key}_lo"], row[f"eps_{key}_hi"] = e[norm].lo, e[norm].hi
    row["eps_limited"] = any(x.limited for x in e.values())
    row["eps_evidence"] = {"l1": e["L1"].evidence.to_json(), "linf": e["Linf"].evidence.to_json()}
    return row


def test_planar_routes_agree_with_the_enumeration(monkeypatch):
    """The hull (L1) and the sweep (L-infinity) give the compiled enumeration's epsilon to
    1e-12 relative, on every planar contact model and across the size thresholds."""
    worst, count = 0.0, 0
    for kw in PLANAR_KINDS:
        for g in _closure(random_grasps(11, 30, dim=2, **kw)):
            W, E, owner = planar_generator_arrays(g)
            m = len(g.contacts)
            ref = {"L1": planar_epsilon_one(W, owner, m, False)[0],
                   "Linf": planar_epsilon_one(W, owner, m, True)[0]}
            monkeypatch.setattr(quality_module, "L1_ENUMERATION_MAX", 0)
            monkeypatch.setattr(quality_module, "LINF_ENUMERATION_MAX", 0)
            fast = planar_epsilons(W, E, owner, m)
            monkeypatch.undo()
            for norm in ("L1", "Linf"):
                worst = max(worst, abs(fast[norm][1] - ref[norm]) / ref[norm])
            count += 1
    assert count > 60
    assert worst < 1e-12


def test_linf_sweep_equals_the_hull_of_all_sums(monkeypatch):
    """Brute force: the L-infinity GWS is the hull of every sum of one vertex (the origin or a
    generator) per contact."""
    monkeypatch.setattr(quality_module, "LINF_ENUMERATION_MAX", 0)
    for kw in (dict(n_contacts=4, model="point"), dict(n_contacts=3, model="pad"),
               dict(n_contacts=6, model="frictionless")):
        for g in _closure(random_grasps(12, 25, dim=2, **kw)):
            W, E, owner = planar_generator_arrays(g)
            parts = [np.vstack([np.zeros(3), W.T[owner == i]]) for i in range(len(g.contacts))]
            brute = _qhull_eps(np.array([sum(c) for c in product(*parts)]))
            hi = planar_epsilons(W, E, owner, len(g.contacts))["Linf"][1]
            assert hi == pytest.approx(brute, rel=1e-12)


@pytest.mark.parametrize("dim, kw", [
    (2, dict(n_contacts=3, model="point")), (2, dict(n_contacts=10, model="point")),
    (2, dict(n_contacts=60, model="point")), (2, dict(n_contacts=4, model="pad")),
    (3, dict(n_contacts=3, model="point", spread=0.3)), (3, dict(n_contacts=2, model="soft", spread=0.15)),
    (3, dict(n_contacts=8, model="frictionless")),
])
def test_evidence_proves_the_stated_bounds(dim, kw):
    """Every bound comes with evidence that the solver-free checker accepts; planar bounds are
    exact (lo == hi) at any size, spatial ones within the relative gap; tampering with a bound by
    1e-6 relative is refused."""
    for g in _closure(random_grasps(13, 40, dim=dim, **kw))[:2]:
        e = epsilons(g)
        row = _row(e)
        assert verify_epsilon(g, row, True)
        for norm in ("L1", "Linf"):
            assert 0 < e[norm].lo <= e[norm].hi and not e[norm].limited
            if dim == 2:
                assert e[norm].lo == e[norm].hi
            elif norm == "L1":
                assert e[norm].gap <= 0.0101
        for key in ("eps_l1_lo", "eps_l1_hi", "eps_linf_lo", "eps_linf_hi"):
            bad = dict(row, **{key: row[key] * (1 + 1e-6)})
            check = verify_epsilon(g, bad, True)
            assert not check and key in check.reason


def test_time_limit_keeps_the_verdict_and_states_the_bounds_reached():
    """With a time limit that is hit, the row keeps its certified closure and states rigorous
    bounds with their evidence (planar L-infinity: hi the best support value found, lo the L1
    epsilon); without the limit nothing is flagged."""
    g = _closure(random_grasps(14, 5, dim=2, n_contacts=400, model="point"))[0]
    full = epsilons(g)
    cut = epsilons(g, time_limit=1e-6)
    assert cut["Linf"].limited and not full["Linf"].limited
    assert cut["Linf"].lo == cut["L1"].lo and cut["Linf"].evidence.kind == "l1"
    assert cut["Linf"].hi >= full["Linf"].hi * (1 - 1e-12)
    assert cut["L1"].hi == full["L1"].hi  # the hull needs no limit
    assert verify_epsilon(g, _row(cut), True)
    s = _closure(random_grasps(15, 5, dim=3, n_contacts=40, model="point", spread=0.3))[0]
    report = certify_grasp(s, eps_time=1e-6)
    row = report.row(line=1)
    assert row["status"] == "closure" and row["verified"] and row["eps_limited"] is True
    assert 0 <= row["eps_l1_lo"] <= row["eps_l1_hi"] and 0 <= row["eps_linf_lo"] <= row["eps_linf_hi"]
    assert verify_epsilon(s, row, True)


def test_default_time_limit_is_never_hit_on_small_grasps():
    """The default limit (10 s per grasp, Options.eps_time) leaves the benchmark's and the
    study's grasps (2 to 10 contacts) untouched."""
    from qualgrasp.experiments.bench import QUALITY_KINDS
    from qualgrasp.certify.batch import Options

    for kwargs in QUALITY_KINDS.values():
        for g in _closure(random_grasps(16, 20, **kwargs))[:2]:
            row = certify_grasp(g, eps_time=Options().eps_time).row(line=1)
            assert row["eps_limited"] is False


def test_compiled_sums_are_every_sum_within_their_bounds():
    """Brute force against the exact generators: the compiled sums of sums evidence are every
    sum of one point per contact polytope, in order (the first contact's choice slowest), each
    the float sum in contact order, and within its stated bound of the exact sum; the sums of
    support evidence (:func:`sum_rows`) are the same sums."""
    from fractions import Fraction

    from qualgrasp.certify._kernels.evidence import minkowski_sums
    from qualgrasp.certify.core.problem import grasp_system
    from qualgrasp.certify.quality.gws import sum_rows

    for kw in (dict(n_contacts=3, model="point"), dict(n_contacts=2, model="pad"),
               dict(n_contacts=4, model="frictionless")):
        for g in random_grasps(13, 6, dim=2, **kw):
            W, E, owner = planar_generator_arrays(g)
            m, k = len(g.contacts), W.shape[1]
            X = grasp_system(g, exact=True).columns
            pts, err, choice = minkowski_sums(W[None], E[None], owner, m)
            options = [[-1] + [j for j in range(k) if owner[j] == i] for i in range(m)]
            assert choice.tolist() == [list(c) for c in product(*options)]
            V, EV = sum_rows(W, E, choice)
            assert np.array_equal(V, pts[0]) and np.array_equal(EV, err[0])
            for p, c in enumerate(choice):
                for r in range(3):
                    s = 0.0
                    for j in c:
                        s = s + (W[r, j] if j >= 0 else 0.0)
                    assert pts[0, p, r] == s
                    exact = sum((X[r, j] for j in c if j >= 0), Fraction(0))
                    assert abs(Fraction(s) - exact) <= Fraction(err[0, p, r])


def test_compiled_support_choices_are_planar_support_choice():
    """The compiled choice is :func:`planar_support_choice`'s (the largest value per contact, the
    first of ties, -1 when not positive), sure or not; ties are never sure."""
    from qualgrasp.certify._kernels.evidence import support_choices
    from qualgrasp.certify.quality.gws import planar_support_choice, planar_support_choices

    rng = np.random.default_rng(3)
    sure_seen = unsure_seen = 0
    for kw in (dict(n_contacts=10, model="point"), dict(n_contacts=3, model="pad")):
        for g in random_grasps(14, 20, dim=2, **kw):
            W, E, owner = planar_generator_arrays(g)
            m = len(g.contacts)
            dirs = np.vstack([np.eye(3), -np.eye(3), rng.normal(size=(20, 3))])
            R, sure = support_choices(W, owner, m, dirs)
            ref = np.array([planar_support_choice(W, owner, m, v) for v in dirs])
            assert np.array_equal(R, ref)
            assert np.array_equal(planar_support_choices(W, owner, m, dirs), ref)
            sure_seen += int(sure.sum())
            unsure_seen += int((~sure).sum())
    assert sure_seen > 500 and unsure_seen > 0  # the pads' equal forces tie along the force axes
    W = np.array([[1.0, 1.0], [0.0, 0.0], [2.0, -2.0]])  # one contact, a tie along (1, 0, 0)
    R, sure = support_choices(W, np.zeros(2, dtype=np.int64), 1, np.array([[1.0, 0, 0], [0, 0, 1.0]]))
    assert not sure[0] and sure[1] and R[1, 0] == 0 and R[0, 0] == 0
    W = np.array([[1.0, 2.0, -1.0, 3.0], [0.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 1.0]])
    for owner, m in ((np.array([0, 0, 2, 2]), 3), (np.array([0, 0, 1, 1]), 3)):  # a contact without generators
        dirs = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.5]])
        R = support_choices(W, owner, m, dirs)[0]
        assert R.tolist() == [list(planar_support_choice(W, owner, m, v)) for v in dirs]
        assert (R[:, 1 if owner[-1] == 2 else 2] == -1).all()


def _choice_in_python_floats(W, owner, m, v):
    """The rule of planar_support_choice written out in Python floats (each operation rounded on
    its own, never fused): values (v0 g0 + v1 g1) + v2 g2, per contact the first largest, -1
    when it is not positive or a value is NaN."""
    out = [-1] * m
    for i in range(m):
        cols = [j for j in range(W.shape[1]) if owner[j] == i]
        vals = [(float(v[0]) * float(W[0, j]) + float(v[1]) * float(W[1, j])) + float(v[2]) * float(W[2, j])
                for j in cols]
        if not cols or any(x != x for x in vals):
            continue
        best = max(vals)
        if best > 0:
            out[i] = cols[vals.index(best)]
    return out


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([(3, "point"), (10, "point"), (3, "pad")]),
       st.sampled_from(["random", "faces", "axes"]))
def test_support_choices_round_in_their_stated_order(seed, kind, dirs_kind):
    """Both routes of the support choice (numpy, compiled) give the rule computed in Python floats
    in its stated order, also on the ties of face normals of the GWS and of the axes (where a
    BLAS product's fused multiply-adds would break ties differently)."""
    from qualgrasp.certify._kernels.evidence import support_choices
    from qualgrasp.certify.quality.gws import planar_support_choice

    rng = np.random.default_rng(seed)
    g = random_grasp(rng, dim=2, n_contacts=kind[0], model=kind[1])
    W, E, owner = planar_generator_arrays(g)
    m = len(g.contacts)
    if dirs_kind == "random":
        dirs = rng.normal(size=(8, 3))
    elif dirs_kind == "axes":
        dirs = np.vstack([np.eye(3), -np.eye(3)]) * rng.choice([1.0, 0.5, 3.0])
    else:  # normals orthogonal to differences of a contact's generators: exact ties, rounded
        a, b = rng.integers(0, W.shape[1], size=2)
        d = W[:, a] - W[:, b]
        dirs = np.cross(d, rng.normal(size=(8, 3)))
    dirs = np.ascontiguousarray(dirs)
    R = support_choices(W, owner, m, dirs)[0]
    for v, r in zip(dirs, R):
        ref = _choice_in_python_floats(W, owner, m, v)
        assert list(planar_support_choice(W, owner, m, v)) == ref == list(r)


def test_surfaces_faces_are_surface_faces():
    """Orienting the faces of many hulls at once gives each hull's own faces; a flat set gives
    None in its place."""
    from qualgrasp.certify.quality.gws import surface_faces, surfaces_faces

    rng = np.random.default_rng(4)
    sets = [rng.normal(size=(n, 3)) for n in (4, 9, 30)]
    sets.insert(1, np.c_[rng.normal(size=(6, 2)), np.zeros(6)])
    out = surfaces_faces(sets)
    assert out[1] is None and surface_faces(sets[1]) is None
    for pts, faces in zip(sets, out):
        if faces is not None:
            assert np.array_equal(faces, surface_faces(pts))


def test_compiled_surface_checks_are_surface_minimum():
    """The float checks of many surfaces at once bound each surface's smallest face distance
    as :func:`surface_minimum` does, and leave undecided what needs the exact vertices (here: a
    face turned the wrong way)."""
    from qualgrasp.certify._kernels.evidence import surface_rows
    from qualgrasp.certify._kernels.surface import leibniz_tables
    from qualgrasp.certify.quality.evidence import EPS_TOL, surface_minimum
    from qualgrasp.certify.quality.gws import surface_faces

    V, EV, F = [], [], []
    for g in _closure(random_grasps(15, 20, dim=2, n_contacts=3, model="point"))[:8]:
        W, E, owner = planar_generator_arrays(g)
        V.append(np.ascontiguousarray(W.T))
        EV.append(np.ascontiguousarray(E.T))
        F.append(surface_faces(W.T))
    bad = F[0].copy()
    bad[0, [0, 1]] = bad[0, [1, 0]]  # wrong orientation: not a closed oriented cycle
    V.append(V[0]), EV.append(EV[0]), F.append(bad)
    vstart = np.cumsum([0] + [len(v) for v in V])
    fstart = np.cumsum([0] + [len(f) for f in F])
    perms, signs = leibniz_tables(2)
    decided, lo, hi = surface_rows(np.concatenate(V), np.concatenate(EV), vstart, np.concatenate(F),
                                   fstart, perms, signs, EPS_TOL / 8)
    assert decided[:-1].all() and not decided[-1]

    def no_exact(i):
        raise AssertionError("the float checks settle these surfaces")

    for s in range(len(V) - 1):
        reason, d2_lo, d2_hi = surface_minimum(V[s], EV[s], F[s], no_exact)
        assert reason is None and (float(d2_lo), float(d2_hi)) == (lo[s], hi[s])


def test_epsilon_rows_are_planar_epsilons_also_where_floats_cannot_decide(monkeypatch):
    """The batch route gives each row what :func:`planar_epsilons` gives (sums, support and
    generators evidence), and still does when the compiled float checks settle no surface at
    all, or none but the L1 ones (checked first): every such surface is then proved exactly,
    as the per-grasp route proves it."""
    from qualgrasp.certify.core.problem import grasp_system
    from qualgrasp.certify.core.wrench import generator_layout, variants_of
    from qualgrasp.certify.quality.bounds import planar_epsilon_rows

    real, kinds, calls = quality_module.surface_rows, set(), []

    def undecided(*args):
        decided, lo, hi = real(*args)
        calls.append(1)
        return (decided if keep_first and len(calls) == 1 else np.zeros_like(decided)), lo, hi

    for kw in (dict(n_contacts=3, model="point"), dict(n_contacts=10, model="point"),
               dict(n_contacts=3, model="pad")):
        grasps = _closure(random_grasps(16, 12, dim=2, spread=0.4, **kw))[:6]
        owner = generator_layout(tuple(c.model for c in grasps[0].contacts), variants_of(grasps[0]), 2)[0]
        arrays = [planar_generator_arrays(g) for g in grasps]
        W, E = np.stack([a[0] for a in arrays]), np.stack([a[1] for a in arrays])
        m = len(grasps[0].contacts)
        exact = lambda b: grasp_system(grasps[b], exact=True).columns  # noqa: E731
        ref = [planar_epsilons(W[b], E[b], owner, m, exact=lambda b=b: exact(b)) for b in range(len(grasps))]
        assert planar_epsilon_rows(W, E, owner, m, exact=exact) == ref
        monkeypatch.setattr(quality_module, "surface_rows", undecided)
        for keep_first in (False, True):
            calls.clear()
            assert planar_epsilon_rows(W, E, owner, m, exact=exact) == ref
        monkeypatch.undo()
        kinds |= {r["Linf"][3].kind for r in ref}
    assert {"sums", "support"} <= kinds


#: A spatial grasp (the 10,494th of ``random_grasp_table(0, 100000, dim=3, n_contacts=3, spread=0.3)``)
#: on which qhull's incremental mode, once used for the inscribed polytope, hit a precision error and
#: ended the whole process with exit code 7 and no exception (scipy issue 4974).
_QHULL_EXIT = [((-0.12583017335373678, -0.6926030617793424, 0.08240230754888508),
                (0.2565282335436242, 0.7023932218591253, -0.594523249796205), 0.8645646262224405),
               ((0.6957657578956175, -0.33196433055367264, -0.9660734533235635),
                (-0.5739031538071512, 0.2548342222720025, 0.42923753305820567), 0.4288170667369781),
               ((-0.6104408853090029, -0.24305585344434316, 0.7357854124115999),
                (0.39738360173717646, 0.19147550094834725, -0.23305847241371713), 0.799361815319938)]


def test_spatial_epsilon_survives_qhull_precision_errors():
    code = ("from qualgrasp import Contact, Grasp, epsilon\n"
            f"g = Grasp(tuple(Contact(p, n, 'point', mu) for p, n, mu in {_QHULL_EXIT!r}))\n"
            "e = epsilon(g, 'L1')\n"
            "print(e.lo <= e.hi)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "True", (done.returncode, done.stderr[-500:])


def test_spatial_epsilon_looks_off_a_flat_set_of_support_points():
    """Three point contacts (a random grasp) whose first contact wins the L1 support only in a
    narrow cone of directions: the coordinate and random starting directions all find support
    points of the other two, which lie in a hyperplane, so no hull forms. Looking along that
    hyperplane's normal finds the first contact's; before, the bounds stayed (0, hi)."""
    grasp = grasp_from_dict(
        {"contacts": [{"p": [0.9639672199247169, 0.09084107021170755, -0.07363865738953423],
                       "n": [-0.9928341145295501, 0.09236101234501155, 0.07582786047970083], "model": "point",
                       "mu": 0.34573080313781357},
                      {"p": [-0.8963490673343812, -0.033303193512310744, -0.6719813428670721],
                       "n": [0.8047984967123155, 0.35681752724729915, 0.4743212328567212], "model": "point",
                       "mu": 0.8967106633239514},
                      {"p": [0.7219464361652197, 0.23546073068432355, 0.44001300985748293],
                       "n": [-0.9814322054498834, 0.03416767196159177, -0.18874161252490887], "model": "point",
                       "mu": 0.9916831712923566}],
         "center": [0.2631881962518518, 0.09766620246124012, -0.1018689967997078], "length": 1.2987331271147127})
    report = certify_grasp(grasp)  # its evidence re-checked
    e = report.epsilons["L1"]
    assert report.verified and e.evidence.kind == "support" and 0 < e.lo <= e.hi and e.gap <= 0.01


def _float_bits(a):
    a = np.asarray(a)
    return a.view(np.int64) if a.dtype == float else a


def _python_refinement(W, E, owner, m, eps, u, deadline=None):
    """The refinement of planar support evidence as a loop in Python from its first directions
    (``_refine_here``, the route the compiled one hands over to)."""
    bounds = quality_module
    first = np.vstack([np.eye(3), -np.eye(3), u[None]])
    dirs, picks, seen = [], [], set()
    for v, r in zip(first, bounds.planar_support_choices(W, owner, m, first)):
        if r.tobytes() not in seen:
            seen.add(r.tobytes())
            dirs.append(v)
            picks.append(r)
    return bounds._refine_here(W, E, owner, m, eps * (1 - bounds.EPS_TOL / 16), dirs, picks, deadline)


def _same_surface(got, ref):
    (a, limited_a), (b, limited_b) = got, ref
    assert limited_a == limited_b and (a is None) == (b is None)
    if a is not None:
        assert len(a) == len(b) == 5
        for x, y in zip(a, b):
            assert x.shape == y.shape and np.array_equal(_float_bits(x), _float_bits(y))


@pytest.mark.parametrize("kwargs", [dict(n_contacts=10, model="point"), dict(n_contacts=20, model="point"),
                                    dict(n_contacts=4, model="pad")])
def test_compiled_support_refinement_is_the_loop_in_python(kwargs):
    """The compiled refinement of planar ``support`` evidence keeps the directions, vertices,
    error bounds, choices and hull faces of the same loop run in Python from its first hull (the
    route it hands over to where its hull declines), bit for bit (-0.0 of the axes included);
    the faces are surface_faces' of the vertices. A deadline already passed stops both after
    their first hull."""
    n = 0
    for g in random_grasps(7, 40, dim=2, **kwargs):
        if not force_closure(g).closure:
            continue
        W, E, owner = planar_generator_arrays(g)
        m = len(g.contacts)
        u = np.array([0.3, -0.5, 0.2])
        eps = float(planar_epsilon_one(W, owner, m, True)[0]) if W.shape[1] <= 24 else 0.01
        got = quality_module._support_surface(W, E, owner, m, eps, u, None)
        _same_surface(got, _python_refinement(W, E, owner, m, eps, u))
        assert not got[1] and np.array_equal(got[0][4], surface_faces(got[0][1]))
        past = time.perf_counter() - 1.0
        cut = quality_module._support_surface(W, E, owner, m, eps, u, past)
        _same_surface(cut, _python_refinement(W, E, owner, m, eps, u, past))
        n += 1
    assert n >= 5


def test_compiled_support_refinement_hands_over_where_its_hull_declines(monkeypatch):
    """Generators nearly in a plane: the compiled hull declines some vertex sets part-way (their
    points within its tolerance of a plane), the refinement goes on in Python with qhull's faces,
    and the result is the whole loop's in Python."""
    rng = np.random.default_rng(11)
    handed = []
    refine_here = quality_module._refine_here
    monkeypatch.setattr(quality_module, "_refine_here", lambda *a: handed.append(len(a[5])) or refine_here(*a))
    mid = 0
    for _ in range(300):
        m = int(rng.integers(3, 15))
        owner = np.repeat(np.arange(m), rng.integers(1, 6, size=m)).astype(np.int64)
        W = rng.normal(size=(3, len(owner)))
        W[2] = np.where(rng.random(len(owner)) < rng.uniform(0.5, 0.95), W[2] * rng.choice([1e-11, 1e-12, 1e-13]),
                        W[2])
        W, E = np.ascontiguousarray(W), np.abs(W) * 2.0**-52
        u = rng.normal(size=3)
        u /= np.linalg.norm(u)
        eps = float(rng.choice([0.1, 1.0, 10.0]))
        handed.clear()
        got = quality_module._support_surface(W, E, owner, m, eps, u, None)
        first = len(np.unique(quality_module.planar_support_choices(W, owner, m, np.vstack([np.eye(3), -np.eye(3),
                                                                                          u[None]])), axis=0))
        mid += bool(handed) and handed[0] > first
        with monkeypatch.context() as patch:
            patch.setattr(quality_module, "_refine_here", refine_here)
            _same_surface(got, _python_refinement(W, E, owner, m, eps, u))
    assert mid >= 3


def _support_batch():
    """Generator arrays ``(W, E, owner, m)`` of planar rows with ``support`` evidence (more than
    4,096 sums, at most 24 generators): grasps in closure of 8 to 12 point contacts and of 6 pads,
    and generators of 8 contacts nearly in a plane, where the compiled hull declines part-way."""
    groups = []
    for seed, kwargs in ((1, dict(n_contacts=8)), (2, dict(n_contacts=10)), (3, dict(n_contacts=12)),
                         (4, dict(n_contacts=6, model="pad"))):
        arrays = [planar_generator_arrays(g) for g in _closure(random_grasps(seed, 40, dim=2, **kwargs))]
        groups.append((np.stack([a[0] for a in arrays]), np.stack([a[1] for a in arrays]), arrays[0][2],
                       int(kwargs["n_contacts"])))
    rng = np.random.default_rng(5)
    owner = np.repeat(np.arange(8), 3).astype(np.int64)
    W = rng.normal(size=(60, 3, 24))
    W[:, 2] *= np.where(rng.random((60, 24)) < 0.8, 1e-12, 1.0)
    groups.append((W, np.abs(W) * 2.0**-52, owner, 8))
    return groups


def _same_columns(a, b):
    for name in ("kind", "direction", "ref", "ref_start", "points", "points_start", "faces", "faces_start"):
        x, y = getattr(a, name), getattr(b, name)
        assert x.shape == y.shape and np.array_equal(_float_bits(x), _float_bits(y)), name


class _SlowClock:
    """A clock that moves 6 ms each time it is read (as ``time`` for the refinement's module)."""

    def __init__(self):
        self.now = 0.0

    def perf_counter(self):
        self.now += 0.006
        return self.now


@pytest.mark.parametrize("time_limit", [None, 10.0, "rounds", "clock", 1e-9])
def test_batched_support_refinement_is_the_row_by_row_one(monkeypatch, time_limit):
    """Planar rows with ``support`` evidence refined in one compiled call give the values, limits
    and evidence of the row-by-row route bit for bit: without a time limit, with the default one,
    with rows whose rounds are spent before the refinement ends (the rounds between two looks at
    the clock cut to 1: those rows start again row by row), with hulls that decline part-way
    under a limit that a slow clock lets pass (those rows go on row by row under their own
    deadline), and under a limit too short for the batch (every row by row)."""
    from qualgrasp.certify.core.wrench import to_exact

    spent = time_limit == "rounds"
    clock = time_limit == "clock"
    if spent:
        monkeypatch.setattr(quality_module, "_ROUNDS", 1)
        time_limit = 10.0
    if clock:
        time_limit = 0.011
    each, batch = [], []
    real_each, real_batch = quality_module._support_rows_each, quality_module.support_refine_rows
    monkeypatch.setattr(quality_module, "_support_rows_each", lambda *a: each.append(len(a[4])) or real_each(*a))
    monkeypatch.setattr(quality_module, "support_refine_rows", lambda *a: batch.append(len(a[0])) or real_batch(*a))
    batched = rows = limited = 0
    for W, E, owner, m in _support_batch():
        exact = lambda b, W=W: to_exact(W[b])  # noqa: E731 (the floats as exact generators)
        with monkeypatch.context() as patch:
            if clock:
                patch.setattr(quality_module, "time", _SlowClock())
            got = quality_module.planar_epsilon_columns(W, E, owner, m, time_limit=time_limit, exact=exact)
        handed, called = sum(each), sum(batch)
        each.clear()
        batch.clear()
        with monkeypatch.context() as patch:
            patch.setattr(quality_module, "_support_rows", real_each)
            if clock:
                patch.setattr(quality_module, "time", _SlowClock())
            ref = quality_module.planar_epsilon_columns(W, E, owner, m, time_limit=time_limit, exact=exact)
        limited += int(got[1].sum())
        assert np.array_equal(_float_bits(got[0]), _float_bits(ref[0])) and np.array_equal(got[1], ref[1])
        _same_columns(got[2], ref[2])
        _same_columns(got[3], ref[3])
        assert (got[3].kind == "support").any()
        batched += called - (handed if called else 0)
        rows += called or handed
    assert (limited > 0) == (clock or time_limit == 1e-9), limited  # only these limits can pass
    if time_limit == 1e-9:
        assert batched == 0
    else:  # the rounds cut to 1: some rows refined in the batch, most started again row by row
        assert batched > 10 and (rows - batched > 100 if spent else batched > 100), (batched, rows)


def test_planar_support_evidence_of_earlier_builds_is_rechecked(monkeypatch):
    """Builds before 2026-11-28 broke a tie of the support choice by the values ``v @ W`` as the
    BLAS library rounds them; the checker re-checks their evidence with those choices where the
    stated order's do not prove the stated bound. The earlier build is replayed here: its
    refinement in Python with the BLAS choices."""
    from functools import partial

    from qualgrasp.certify.core.problem import grasp_system
    from qualgrasp.certify.quality import evidence as evidence_module
    from qualgrasp.certify.quality.evidence import Evidence

    grasps = _closure(random_grasps(11, 60, dim=2, n_contacts=10, model="point"))
    with monkeypatch.context() as patch:  # the loop in Python, its choices the BLAS ones throughout
        patch.setattr(quality_module, "_support_surface", _python_refinement)
        patch.setattr(quality_module, "planar_support_choices",
                      partial(quality_module.planar_support_choices, blas=True))
        rows = [certify_grasp(g).row(line=1) for g in grasps]
    needed = 0
    for g, row in zip(grasps, rows):
        assert verify_epsilon(g, row, True), verify_epsilon(g, row, True).reason
        ev = Evidence.from_json(row["eps_evidence"]["linf"])
        if ev.kind == "support":
            W, E, owner = planar_generator_arrays(g)
            exact = partial(lambda g: grasp_system(g, exact=True).columns, g)
            needed += bool(evidence_module._planar_lower(W, E, owner, 10, ev, exact, row["eps_linf_lo"], "linf",
                                                         "eps_linf_lo"))
    # on a machine whose BLAS fuses multiply-adds (most), some of them need the earlier choices
    print(f"{needed} of {len(rows)} rows re-checked by the earlier builds' choices")


def _hull_minimum_in_numpy(W, owner, m, faces, top=16):
    """The L1 hull minimum as hull_minima states it, in numpy: sorted face vertices, normals
    (g_b - g_a) x (g_c - g_a) made unit by sqrt((n0^2 + n1^2) + n2^2), offsets
    (n0 a0 + n1 a1) + n2 a2 made non-negative, the support at the `top` nearest (stable)."""
    tri = np.sort(faces, axis=1)
    A, B, C = W.T[tri[:, 0]], W.T[tri[:, 1]], W.T[tri[:, 2]]
    p, q = B - A, C - A
    n = np.stack([p[:, 1] * q[:, 2] - p[:, 2] * q[:, 1], p[:, 2] * q[:, 0] - p[:, 0] * q[:, 2],
                  p[:, 0] * q[:, 1] - p[:, 1] * q[:, 0]], axis=1)
    norm = np.sqrt((n[:, 0] * n[:, 0] + n[:, 1] * n[:, 1]) + n[:, 2] * n[:, 2])
    good = norm > 0
    n, A = n[good] / norm[good, None], A[good]
    off = (n[:, 0] * A[:, 0] + n[:, 1] * A[:, 1]) + n[:, 2] * A[:, 2]
    n[off < 0] *= -1
    U = n[np.argsort(np.abs(off), kind="stable")[:top]]
    h = np.array([max(max(0.0, max((float(U[r, 0]) * W[0, j] + float(U[r, 1]) * W[1, j]) + float(U[r, 2]) * W[2, j]
                                   for j in range(W.shape[1]) if owner[j] == i)) for i in range(m))
                  for r in range(len(U))])
    j = int(np.argmin(h))
    return h[j], U[j]


@pytest.mark.parametrize("kwargs", [dict(n_contacts=9, model="point"), dict(n_contacts=20, model="point"),
                                    dict(n_contacts=6, model="pad")])
def test_compiled_hull_minima_are_their_stated_arithmetic(kwargs):
    """The compiled L1 hull minimum of many grasps at once is its formula in numpy, bit for bit,
    and within rounding of the enumeration's exact planar epsilon (an independent route)."""
    from qualgrasp.certify._kernels.epsilon import hull_minima
    from qualgrasp.certify.quality.gws import surfaces_faces

    grasps = [g for g in random_grasps(13, 30, dim=2, **kwargs) if force_closure(g).closure]
    arrays = [planar_generator_arrays(g) for g in grasps]
    m = len(grasps[0].contacts)
    owner = arrays[0][2]
    faces = surfaces_faces([W.T.copy() for W, _, _ in arrays])
    assert all(f is not None for f in faces)
    fstart = np.cumsum([0] + [len(f) for f in faces]).astype(np.int64)
    eps, arg = hull_minima(np.stack([W for W, _, _ in arrays]), owner, m, np.concatenate(faces), fstart, 16)
    for b, (W, _, _) in enumerate(arrays):
        h, u = _hull_minimum_in_numpy(W, owner, m, faces[b])
        assert float(h).hex() == float(eps[b]).hex() and [x.hex() for x in map(float, u)] == \
            [x.hex() for x in map(float, arg[b])]
        exact = float(planar_epsilon_one(W, owner, m, False)[0])
        assert abs(eps[b] - exact) <= 1e-12 * max(1.0, exact)
