"""Certificates re-check without a solver; tampered ones are rejected."""

import dataclasses
import functools

import numpy as np
import pytest

from qualgrasp.certify import Certificate, Contact, Grasp, certify_grasp, force_closure, form_closure, verify
from qualgrasp.experiments.bench import KINDS
from qualgrasp.certify.batch import random_grasps, textbook_grasps

@functools.cache
def _grasps(kind: str) -> list:
    """150 random grasps of a bench kind, made once when first asked for (not at collection,
    which every test process does)."""
    return random_grasps(7, 150, **KINDS[kind])


@pytest.mark.parametrize("kind", list(KINDS))
def test_every_certificate_verifies(kind):
    for g in _grasps(kind):
        report = certify_grasp(g)
        assert report.verified, g


def _verdicts(kind, status):
    out = [(g, force_closure(g)) for g in _grasps(kind)]
    return [(g, v) for g, v in out if v.status == status]


def _other(kind, g):
    return next(h for h in _grasps(kind) if h is not g)


@pytest.mark.parametrize("kind", list(KINDS))
def test_tampered_interior_certificates_are_rejected(kind):
    rng = np.random.default_rng(0)
    closures = _verdicts(kind, "closure")
    assert closures
    for g, v in closures[:40]:
        c = v.certificate
        assert verify(g, c, status="closure", margin=v.margin)
        x = np.array(c.values)
        negated = dataclasses.replace(c, values=tuple(-x))
        assert not verify(g, negated, status="closure")
        noisy = dataclasses.replace(c, values=tuple(x + 1e-3 * rng.normal(size=x.size)))
        assert not verify(g, noisy, status="closure")
        # the same certificate on another grasp of the same size
        other = _other(kind, g)
        assert not verify(other, c, status="closure")
        # claiming more margin than the forces show
        assert not verify(g, c, status="closure", margin=2 * v.margin + 0.01)
        # wrong status for the kind of evidence
        assert not verify(g, c, status="no_closure")


@pytest.mark.parametrize("kind", list(KINDS))
def test_tampered_farkas_certificates_are_rejected(kind):
    rng = np.random.default_rng(1)
    closures = [g for g, _ in _verdicts(kind, "closure")]
    for g, v in _verdicts(kind, "no_closure")[:40]:
        c = v.certificate
        assert verify(g, c, status="no_closure")
        y = np.array(c.y)
        if not c.null_space:  # -y of a null-space direction is as valid as y
            assert not verify(g, dataclasses.replace(c, y=tuple(-y)), status="no_closure")
        noisy = dataclasses.replace(c, y=tuple(y + 1e-3 * rng.normal(size=y.size)))
        if c.tight:  # the direction must stay exactly orthogonal to the tight contacts
            assert not verify(g, noisy, status="no_closure")
        # a grasp in closure has no separating direction at all: nothing may pass
        for h in closures[:5]:
            assert not verify(h, c, status="no_closure")


def test_malformed_certificates_are_rejected_not_raised():
    g = textbook_grasps()[0]
    good = form_closure(g).certificate
    for bad in (
        dataclasses.replace(good, values=good.values[:-1]),
        dataclasses.replace(good, basis=(0, 0, 1)),
        dataclasses.replace(good, values=(float("nan"),) * len(good.values)),
        dataclasses.replace(good, layout="forces"),
        Certificate("farkas", "generators", y=(0.0, 0.0, 0.0)),
        Certificate("farkas", "generators", y=(1.0, 0.0)),
        Certificate("degenerate", "generators", reason="rank"),
    ):
        assert not verify(g, bad, frictionless=True)


def test_certificate_json_round_trip():
    for g in textbook_grasps():
        for v in (force_closure(g), form_closure(g)):
            c = Certificate.from_json(v.certificate.to_json())
            assert c == v.certificate


def test_strict_separation_with_small_products_is_a_certificate():
    # Found in a 10-million-row run: three frictionless contacts whose lines of action are
    # almost concurrent (singular value ratio 7e-8). The dual direction separates every contact
    # strictly, by about 6e-8 only; it used to be read as "all tight" and the verdict came out
    # degenerate with no checkable evidence.
    from qualgrasp.certify import grasp_from_dict

    grasp = grasp_from_dict({"contacts": [
        {"p": [0.08487203384727166, -0.9607936621023784], "n": [-0.32560050505541177, 2.091382879951419],
         "model": "point", "mu": 0.6920278061753009},
        {"p": [0.6654720032440128, -0.4503054549567775], "n": [-0.8695851629374756, 0.12345552898877554],
         "model": "point", "mu": 0.3179183556062011},
        {"p": [-0.5094172464502014, 0.6504739073678544], "n": [0.4711621550474892, -0.9471897710793764],
         "model": "point", "mu": 0.5529367462378985}]})
    form = form_closure(grasp)
    assert form.status == "no_closure" and form.certificate.tight == ()
    assert verify(grasp, form.certificate, status="no_closure", frictionless=True).ok
    report = certify_grasp(grasp, quality=False)
    assert report.force.status == "closure" and report.verified


def _exact_only(g, cert, frictionless, **claims):
    """:func:`verify` by its exact route alone (rationals, no float proof first)."""
    from qualgrasp.certify.core.certificates import verify_system
    from qualgrasp.certify.core.problem import grasp_system

    return verify_system(*grasp_system(g, frictionless=frictionless, exact=True), cert, **claims)


def _tampered(g, v, other, rng):
    """The certificate of verdict ``v`` of ``g`` with its claims, then tampered versions of it:
    values or direction moved or negated, another basis, margins claimed a little or much off,
    the wrong status, and ``other``'s certificate for ``g``."""
    c, status = v.certificate, v.status
    yield c, dict(status=status, margin=v.margin)
    yield c, dict(status=status, margin=v.margin, exact_margin=True)
    yield c, dict(status="no_closure" if status == "closure" else "closure")
    yield other, dict(status=status)
    if c.kind == "interior":
        x = np.array(c.values)
        yield dataclasses.replace(c, values=tuple(-x)), dict(status=status)
        yield dataclasses.replace(c, values=tuple(x + 1e-3 * rng.normal(size=x.size))), dict(status=status)
        yield dataclasses.replace(c, values=tuple(x * (1 + 1e-9))), dict(status=status, margin=v.margin)
        yield dataclasses.replace(c, basis=tuple((b + 1) % len(x) for b in c.basis)), dict(status=status)
        for factor in (1 + 3e-6, 1 + 6e-7, 1 - 6e-7, 1 - 3e-6, 2):
            yield c, dict(status=status, margin=v.margin * factor, exact_margin=True)
            yield c, dict(status=status, margin=v.margin * factor)
    elif c.y is not None:
        y = np.array(c.y)
        yield dataclasses.replace(c, y=tuple(-y)), dict(status=status)
        yield dataclasses.replace(c, y=tuple(y + 1e-3 * rng.normal(size=y.size))), dict(status=status)
        yield dataclasses.replace(c, y=tuple(y + 1e-12 * rng.normal(size=y.size))), dict(status=status)


def test_float_proofs_of_large_planar_grasps_agree_with_the_exact_route():
    # From FLOAT_PROOF_CONTACTS contacts on, verify proves planar certificates with the
    # rigorous float kernels first. Such a proof must never accept what the exact route refuses
    # (genuine and tampered certificates alike), and it must prove most genuine ones (else the
    # route is dead code and the test would pass vacuously).
    from qualgrasp.certify.core import certificates

    rng = np.random.default_rng(3)
    grasps = (random_grasps(11, 12, dim=2, n_contacts=10) + random_grasps(12, 6, dim=2, n_contacts=20)
              + random_grasps(13, 6, dim=2, n_contacts=8, model="pad"))
    genuine = proved = checked = 0
    for i, g in enumerate(grasps):
        for fl in (False, True):
            v = form_closure(g) if fl else force_closure(g)
            other = (form_closure if fl else force_closure)(grasps[i - 1]).certificate
            for n, (cert, claims) in enumerate(_tampered(g, v, other, rng)):
                exact = bool(_exact_only(g, cert, fl, **claims))
                fast = certificates._proved_in_floats(g, cert, claims.get("status"), claims.get("margin"), fl,
                                                      certificates.Tolerances())
                assert exact or not fast, (g, cert, claims)  # sound: never more than the exact route
                assert bool(verify(g, cert, frictionless=fl, **claims)) == exact, (g, cert, claims)
                checked += 1
                large = len(g.contacts) >= certificates.FLOAT_PROOF_CONTACTS
                if n == 0 and large and v.certificate.kind in ("interior", "farkas") and not v.certificate.tight:
                    genuine += 1
                    proved += fast
    assert checked > 400 and genuine > 30, (checked, genuine)
    assert proved >= 0.9 * genuine, (proved, genuine)


def _off_equilibrium(W, values, basis, shift):
    """Interior values over generators ``W`` moved along the null space of ``W`` until their
    least weight is on ``basis[0]``, then moved off equilibrium on that column by ``shift`` times
    their sum: the exact checker's correction moves that weight back."""
    k = W.shape[1]
    rest = [j for j in range(k) if j not in basis]
    for s in range(len(rest)):
        zn = np.zeros(len(rest))
        zn[s] = 1.0
        zb = np.linalg.solve(W[:, basis], -W[:, rest] @ zn)
        if zb[0] < 0:
            break
    z = np.zeros(k)
    z[list(basis)], z[rest] = zb, zn
    x = np.asarray(values, dtype=float)
    x = x + 0.3 * x[basis[0]] / -zb[0] * z
    x[basis[0]] += shift * np.abs(x).sum()
    return x


def test_float_proofs_bound_the_margin_after_the_exact_correction():
    # The exact checker corrects the values before it compares the stated margin with theirs; the
    # float route must allow for that correction (bounded by the float kernels), or it accepts a
    # margin the exact route refuses. Eight contacts around a circle; an equilibrium whose least
    # weight is on a basis column, moved off equilibrium along that column so that the correction
    # moves the least weight back (_off_equilibrium), and the margin of the moved values stated.
    from qualgrasp.certify.core import certificates
    from qualgrasp.certify.core.certificates import margin_of
    from qualgrasp.certify.core.problem import Block
    from qualgrasp.certify.core.wrench import planar_generator_arrays

    a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    g = Grasp(tuple(Contact((np.cos(t), np.sin(t)), (-np.cos(t), -np.sin(t)), "point", mu=0.5) for t in a))
    v = force_closure(g)
    W, _, _ = planar_generator_arrays(g)
    blocks = [Block("ray", (j,), contact=j) for j in range(W.shape[1])]
    refused = 0
    for shift in (1e-9, 3e-8, 5e-8, 8e-8, 1.2e-7):
        moved = _off_equilibrium(W, v.certificate.values, v.certificate.basis, shift)
        cert = dataclasses.replace(v.certificate, values=tuple(moved))
        for exact_margin in (False, True):
            claims = dict(status="closure", margin=margin_of(blocks, moved), exact_margin=exact_margin)
            exact = bool(_exact_only(g, cert, False, **claims))
            assert exact or not certificates._proved_in_floats(g, cert, "closure", claims["margin"], False,
                                                               certificates.Tolerances())
            assert bool(verify(g, cert, **claims)) == exact
            refused += not exact
    assert refused >= 2  # the moves beyond the tolerance are refused (by both routes)


def test_float_proofs_refuse_certificates_of_the_wrong_types():
    # Certificates built in code rather than read from JSON: strings, a fractional basis index,
    # complex values, tight or null_space of None. The exact route refuses them; the float route
    # must not accept them (numpy would convert or truncate them), nor raise.
    a = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    g = Grasp(tuple(Contact((np.cos(t), np.sin(t)), (-np.cos(t), -np.sin(t)), "point", mu=0.5) for t in a))
    closure = force_closure(g)
    c = closure.certificate
    shifted = Grasp(tuple(Contact((np.cos(t) + 3, np.sin(t)), (1.0, 0.2 * np.sin(t)), "point", mu=0.1) for t in a))
    farkas = force_closure(shifted).certificate
    assert c.kind == "interior" and farkas.kind == "farkas" and not farkas.tight
    for bad, status in ((dataclasses.replace(c, values=tuple(str(v) for v in c.values)), "closure"),
                        (dataclasses.replace(c, basis=(c.basis[0] + 0.5,) + tuple(c.basis[1:])), "closure"),
                        (dataclasses.replace(c, basis=tuple(str(j) for j in c.basis)), "closure"),
                        (dataclasses.replace(c, values=tuple(complex(v) for v in c.values)), "closure"),
                        (dataclasses.replace(farkas, y=tuple(str(v) for v in farkas.y)), "no_closure"),
                        (dataclasses.replace(farkas, null_space=None), "no_closure"),
                        (dataclasses.replace(farkas, tight=None), "no_closure")):
        assert not verify(shifted if status == "no_closure" else g, bad, status=status)
    assert verify(g, c, status="closure", margin=closure.margin) and verify(shifted, farkas, status="no_closure")


def test_bulk_recheck_bounds_the_margin_after_the_exact_correction(tmp_path):
    # ``qualgrasp verify`` proves most rows in bulk with the float kernels: a stated margin must
    # hold for the values the exact checker corrects the certificate to, as in verify (above).
    from qualgrasp.certify.batch import certify_file, verify_file
    from qualgrasp.certify.core.certificates import margin_of
    from qualgrasp.certify.core.problem import Block
    from qualgrasp.certify.core.wrench import planar_generator_arrays
    from qualgrasp.certify.files import table_to_rows, write_grasps
    import pyarrow as pa
    import pyarrow.parquet as pq

    a = np.linspace(0, 2 * np.pi, 8, endpoint=False)  # normals tilted both ways: form closure too
    g = Grasp(tuple(Contact((np.cos(t), np.sin(t)), (-np.cos(t) - 0.3 * (-1) ** i * np.sin(t),
                                                     -np.sin(t) + 0.3 * (-1) ** i * np.cos(t)), "point", mu=0.5)
                    for i, t in enumerate(a)), id="g")
    grasps, results, tampered = tmp_path / "g.parquet", tmp_path / "r.parquet", tmp_path / "t.parquet"
    write_grasps(grasps, [g] * 80)  # enough rows for the bulk proofs
    certify_file(grasps, results, quality=False)
    rows = table_to_rows(pq.read_table(results))
    W, _, _ = planar_generator_arrays(g)
    cert = rows[0]["certificate"]["force"]
    blocks = [Block("ray", (j,), contact=j) for j in range(W.shape[1])]
    x = _off_equilibrium(W, cert["values"], cert["basis"], 8e-8)
    rows[5]["certificate"]["force"]["values"] = x.tolist()
    rows[5]["margin"] = margin_of(blocks, x)
    pq.write_table(pa.Table.from_pylist(rows, schema=pq.read_table(results).schema), tampered)  # bulk-proved
    assert not verify_file(results, grasps).failures
    failures = verify_file(tampered, grasps).failures
    assert len(failures) == 1 and "margin" in str(failures[0]), failures
