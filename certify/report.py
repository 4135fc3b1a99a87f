"""Certify one grasp end to end: force and form closure, certificates, independent re-check.

:func:`certify_grasp` returns a :class:`Report`; :meth:`Report.row` is the results-file row
(one JSON object per input grasp) with the keys ``id``, ``line``, ``dim``, ``status``,
``form_closure``, ``force_closure``, ``margin``, ``form_status``, ``form_margin``,
``certificate`` (``{"force": ..., "form": ...}``), ``verified``, ``error``, ``center``, ``length``
and ``n_contacts``. ``status`` refers to force closure under the declared contact models.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .certificates import Certificate, Check, Tolerances, verify
from .errors import CertificateError
from .closure import Verdict, form_closure, force_closure
from .grasp import Grasp

__all__ = ["Report", "certify_grasp", "error_row", "verify_row"]


@dataclass(frozen=True)
class Report:
    """Force and form closure verdicts of one grasp and whether both certificates re-checked."""

    grasp: Grasp
    force: Verdict
    form: Verdict
    verified: bool

    def row(self, line: int | None = None) -> dict[str, Any]:
        g = self.grasp
        return {
            "id": g.id,
            "line": line,
            "dim": g.dim,
            "status": self.force.status,
            "form_closure": self.form.closure,
            "force_closure": self.force.closure,
            "margin": self.force.margin,
            "form_status": self.form.status,
            "form_margin": self.form.margin,
            "certificate": {"force": self.force.certificate.to_json(),
                            "form": self.form.certificate.to_json()},
            "verified": self.verified,
            "error": None,
            "center": list(g.center),
            "length": g.length,
            "n_contacts": len(g.contacts),
        }


def certify_grasp(grasp: Grasp, *, method: str = "fast", solver=None,
                  tol: Tolerances = Tolerances()) -> Report:
    """Force closure, form closure and the re-check of both certificates for ``grasp``."""
    force = force_closure(grasp, method=method, solver=solver, tol=tol)
    form = force if grasp.frictionless else form_closure(grasp, method=method, solver=solver, tol=tol)
    ok = all(
        verify(grasp, v.certificate, status=v.status, margin=v.margin, frictionless=fl, tol=tol)
        for v, fl in ((force, False), (form, True))
    )
    return Report(grasp, force, form, ok)


def error_row(message: str, *, id: Any = None, line: int | None = None) -> dict[str, Any]:
    """Results row for an input that could not be certified."""
    return {
        "id": id, "line": line, "dim": None, "status": "error", "form_closure": None,
        "force_closure": None, "margin": None, "form_status": "error", "form_margin": None,
        "certificate": None, "verified": False, "error": message, "center": None,
        "length": None, "n_contacts": None,
    }


def verify_row(grasp: Grasp, row: dict[str, Any], tol: Tolerances = Tolerances()) -> Check:
    """Re-check both certificates of a results row against its grasp."""
    if not isinstance(row.get("certificate"), dict):
        return Check(False, "row has no certificate")
    flags = {"closure": True, "no_closure": False, "degenerate": None}
    for key, fl, status_key, margin_key, flag_key in (
        ("force", False, "status", "margin", "force_closure"),
        ("form", True, "form_status", "form_margin", "form_closure"),
    ):
        status = row.get(status_key)
        if status not in flags or row.get(flag_key) != flags[status]:
            return Check(False, f"{flag_key} does not match {status_key} {status!r}")
        try:
            cert = Certificate.from_json(row["certificate"].get(key))
        except CertificateError as err:
            return Check(False, f"{key} certificate: {err}")
        margin = row.get(margin_key)
        if status != "closure" and margin != 0:
            return Check(False, f"{margin_key} must be 0 when not in closure")
        check = verify(grasp, cert, status=status, margin=margin if status == "closure" else None,
                       frictionless=fl, tol=tol)
        if not check:
            return Check(False, f"{key} certificate: {check.reason}")
    return Check(True)
