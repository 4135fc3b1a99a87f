"""Certify one grasp end to end: force and form closure, certificates, independent re-check.

:func:`certify_grasp` returns a :class:`Report`; :meth:`Report.row` is the results-file row
(:data:`qualgrasp.certify.files.results.COLUMNS`): the force and form closure verdicts, margins and
certificates, whether both certificates re-checked, the ``center`` and ``length`` used, and the
Ferrari-Canny epsilon bounds with their evidence (:mod:`qualgrasp.certify.quality.evidence`; 0 and no
evidence when not in force closure; null when quality was not asked for). ``status`` refers to
force closure under the declared contact models.

:func:`verify_row` re-checks every number a row states against its grasp, without a solver.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from .core.certificates import Certificate, Check, Tolerances, verify
from .errors import CertificateError
from .core.closure import Verdict, form_closure, force_closure
from .quality.evidence import verify_epsilon
from .core.grasp import Grasp
from .core.validation import show_repr
from .solvers import Method
from .quality.bounds import Epsilon, epsilons
from .files.results import NAMES, result_row

__all__ = ["Report", "certify_grasp", "verify_row", "GEOMETRY_TOL"]


@dataclass(frozen=True)
class Report:
    """Force and form closure verdicts of one grasp and whether both certificates re-checked."""

    grasp: Grasp
    force: Verdict
    form: Verdict
    verified: bool
    epsilons: dict[str, Epsilon] | None = None

    @property
    def certified(self) -> bool:
        """Force closure certified: status ``closure`` and both certificates re-checked."""
        return self.force.status == "closure" and self.verified

    @property
    def eps_l1(self) -> float:
        """Upper bound of the L1 epsilon of a certified grasp (computed with quality), else 0."""
        return float(self.epsilons["L1"].hi) if self.certified and self.epsilons else 0.0

    def row(self, line: int | None = None) -> dict[str, Any]:
        """The results-file row of this grasp (:data:`qualgrasp.certify.files.results.COLUMNS`)."""
        g = self.grasp
        eps = {}
        for norm, key in (("L1", "l1"), ("Linf", "linf")):
            e = self.epsilons.get(norm) if self.epsilons else None
            eps[f"eps_{key}_lo"] = None if e is None else e.lo
            eps[f"eps_{key}_hi"] = None if e is None else e.hi
        eps["eps_limited"] = eps["eps_evidence"] = None
        if self.epsilons:
            eps["eps_limited"] = any(e.limited for e in self.epsilons.values())
            if all(e.evidence is not None for e in self.epsilons.values()):
                eps["eps_evidence"] = {key: self.epsilons[norm].evidence.to_json()
                                       for norm, key in (("L1", "l1"), ("Linf", "linf"))}
        return result_row(
            id=g.id, line=line, dim=g.dim, status=self.force.status,
            form_closure=self.form.closure, force_closure=self.force.closure,
            margin=self.force.margin, form_status=self.form.status, form_margin=self.form.margin,
            certificate={"force": self.force.certificate.to_json(),
                         "form": self.form.certificate.to_json()},
            verified=self.verified, error=None, center=list(g.center), length=g.length,
            n_contacts=len(g.contacts), **eps)


def certify_grasp(grasp: Grasp, *, method: Method = "fast", solver=None,
                  tol: Tolerances = Tolerances(), quality: bool = True, eps_gap: float = 0.01,
                  eps_budget: int = 200_000, eps_time: float | None = None) -> Report:
    """Certify one grasp end to end: force and form closure, the re-check of both certificates
    and, with ``quality``, the L1 and L-infinity Ferrari-Canny epsilon.

    Parameters
    ----------
    grasp : Grasp
    method, solver, tol
        As for :func:`qualgrasp.certify.force_closure`.
    quality : bool
        Compute the epsilons (with the grasp's ``center`` and ``length``).
    eps_gap, eps_budget
        Spatial epsilon: relative gap to reach and most work (see
        :func:`qualgrasp.certify.quality.bounds.epsilon`).
    eps_time : float, optional
        Time limit of the quality computation for this grasp, in seconds (both norms
        together); when it is hit the epsilons are the bounds reached, flagged ``limited``
        (results then depend on the machine). None: no limit.

    Returns
    -------
    Report
        Both verdicts, whether both certificates re-checked, the epsilons; :meth:`Report.row` is
        the results-file row.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp, certify_grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0), "pad", mu=0.5, width=0.4),
    ...            Contact((-1, 0), (1, 0), "pad", mu=0.5, width=0.4)))
    >>> r = certify_grasp(g)
    >>> r.force.status, r.form.status, r.verified, round(r.epsilons["L1"].hi, 4)
    ('closure', 'no_closure', True, 0.4667)
    """
    force = force_closure(grasp, method=method, solver=solver, tol=tol)
    form = force if grasp.frictionless else form_closure(grasp, method=method, solver=solver, tol=tol)
    ok = all(
        verify(grasp, v.certificate, status=v.status, margin=v.margin, frictionless=fl, tol=tol)
        for v, fl in ((force, False), (form, True))
    )
    eps = None
    if quality:
        eps = epsilons(grasp, rel_gap=eps_gap, budget=eps_budget, time_limit=eps_time, verdict=force)
    return Report(grasp, force, form, ok, eps)


#: Relative tolerance of a row's ``center`` and ``length`` against the grasp's own (or recomputed
#: default) values, relative to ``max(1, |value|)``.
GEOMETRY_TOL = 1e-12


def _number(value: Any) -> float | None:
    """A finite float from a JSON or Arrow number (not a bool), else None."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def verify_row(grasp: Grasp, row: dict[str, Any], tol: Tolerances = Tolerances()) -> Check:
    """Re-check every claim of a results row (not an error row) against its grasp, without a
    solver.

    * ``verified`` is true and ``error`` null; ``dim``, ``n_contacts``, ``center`` and
      ``length`` are the grasp's (:data:`GEOMETRY_TOL`);
    * ``status`` and ``form_status`` agree with ``force_closure`` and ``form_closure`` and are
      proved by their certificates (:func:`qualgrasp.certify.verify`, exact rationals); each
      margin is 0 without closure and otherwise the margin the certificate's values certify, to
      within :func:`qualgrasp.certify.core.certificates.margin_tolerance` either way;
    * the epsilon columns are proved by their evidence
      (:func:`qualgrasp.certify.quality.evidence.verify_epsilon`).

    Returns
    -------
    Check
        Failed with a reason naming the column at the first claim that does not hold; a
        malformed row (wrong types, missing columns, deep nesting) is a failed check, never an
        exception.
    """
    try:
        return _verify_row(grasp, row, tol)
    except RecursionError:
        return Check(False, "malformed row (too deeply nested)")
    except (TypeError, ValueError, KeyError, AttributeError, IndexError, OverflowError,
            ZeroDivisionError) as err:
        return Check(False, f"malformed row ({type(err).__name__}: {show_repr(str(err))})")


def _verify_row(grasp: Grasp, row: Any, tol: Tolerances) -> Check:
    if not isinstance(row, dict):
        return Check(False, "row is not an object")
    missing = [name for name in NAMES if name not in row]
    if missing:
        return Check(False, f"column{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                            f"{'are' if len(missing) > 1 else 'is'} missing")
    if row["verified"] is not True:
        return Check(False, f"verified must be true on a certified row, got {show_repr(row['verified'])}")
    if row["error"] is not None:
        return Check(False, f"error must be null on a certified row, got {show_repr(row['error'])}")
    for key, expected in (("dim", grasp.dim), ("n_contacts", len(grasp.contacts))):
        value = row[key]
        if isinstance(value, bool) or not isinstance(value, int) or value != expected:
            return Check(False, f"{key} {show_repr(value)} does not match the grasp's {expected}")
    center = row["center"]
    if not isinstance(center, (list, tuple)) or len(center) != grasp.dim:
        return Check(False, f"center must hold {grasp.dim} numbers, got {show_repr(center)}")
    for a, b in zip(center, grasp.center):
        x = _number(a)
        if x is None or abs(x - b) > GEOMETRY_TOL * max(1.0, abs(b)):
            return Check(False, f"center {show_repr(center)} does not match the grasp's {list(grasp.center)}")
    x = _number(row["length"])
    if x is None or abs(x - grasp.length) > GEOMETRY_TOL * max(1.0, grasp.length):
        return Check(False, f"length {show_repr(row['length'])} does not match the grasp's {grasp.length!r}")
    if not isinstance(row["certificate"], dict):
        return Check(False, "certificate must be an object with force and form")
    flags = {"closure": True, "no_closure": False, "degenerate": None}
    for key, fl, status_key, margin_key, flag_key in (
        ("force", False, "status", "margin", "force_closure"),
        ("form", True, "form_status", "form_margin", "form_closure"),
    ):
        status = row[status_key]
        if not isinstance(status, str) or status not in flags:
            return Check(False, f"{status_key} must be closure, no_closure or degenerate, got {show_repr(status)}")
        if row[flag_key] is not flags[status]:
            return Check(False, f"{flag_key} {show_repr(row[flag_key])} does not match {status_key} {status!r}")
        margin = _number(row[margin_key])
        if margin is None:
            return Check(False, f"{margin_key} must be a finite number, got {show_repr(row[margin_key])}")
        if status != "closure" and margin != 0:
            return Check(False, f"{margin_key} must be 0 when not in closure")
        try:
            cert = Certificate.from_json(row["certificate"].get(key))
        except CertificateError as err:
            return Check(False, f"certificate.{key}: {err}")
        check = verify(grasp, cert, status=status, margin=margin if status == "closure" else None,
                       frictionless=fl, tol=tol, exact_margin=True)
        if not check:
            what = margin_key if "margin" in check.reason else f"certificate.{key}"
            return Check(False, f"{what}: {check.reason}")
    check = verify_epsilon(grasp, row, row["status"] == "closure")
    if not check:
        return check
    return Check(True)
