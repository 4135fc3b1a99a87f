"""Certificates re-check without a solver; tampered ones are rejected."""

import dataclasses
import functools

import numpy as np
import pytest

from qualgrasp.certify import Certificate, certify_grasp, force_closure, form_closure, verify
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
    grasps = (random_grasps(11, 24, dim=2, n_contacts=10) + random_grasps(12, 12, dim=2, n_contacts=20)
              + random_grasps(13, 12, dim=2, n_contacts=8, model="pad"))
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
    assert checked > 500 and genuine > 50
    assert proved >= 0.9 * genuine, (proved, genuine)
