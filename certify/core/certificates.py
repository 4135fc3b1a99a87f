"""Certificates of closure verdicts and their independent verification.

A certificate is re-checked against the grasp with exact rational arithmetic on the float data
(:mod:`qualgrasp.certify.core.exact`) and no solver. For a planar grasp with many contacts
(:data:`FLOAT_PROOF_CONTACTS`), :func:`verify` first tries the rigorous floating-point kernels
(error bounds instead of rationals, as ``qualgrasp verify`` uses in bulk), which prove the same
statements below; what they cannot prove goes to the rationals, which also give the reason of a
failure.

``interior`` (closure)
    Values ``x`` over the certificate columns ``C`` (generator weights, or world-frame contact
    forces) and a basis of ``d`` columns. The checker forms the exact residual ``r = C x``,
    solves ``C_B delta = -r`` exactly and checks that ``x + delta`` (``delta`` on the basis) lies
    strictly inside every contact cone. That exhibits an exact internal force in the interior of
    the cones, and ``C_B`` invertible proves ``rank C = d``: closure (Murray, Li & Sastry,
    Prop. 5.2). The residual must also be small, so a certificate copied from another grasp is
    refused even when the correction would rescue it.
``farkas`` (not in closure)
    A direction ``y`` and the set ``tight`` of contact blocks that ``y`` is orthogonal to. Every
    achievable wrench has ``y . w <= 0``, so the wrench ``+y`` cannot be resisted. The checker
    projects ``y`` exactly onto the orthogonal complement of the tight blocks' columns (the
    projection must be non-zero and close to ``y``), so ``y . w = 0`` holds exactly there, and
    checks every other block strictly: ``a_n + mu norm(a_t) < 0`` for ``a`` the functional on the
    block, squared to stay rational. ``null_space`` means every block is tight (rank deficiency).
    Tight blocks are contacts that carry no force in any equilibrium (for example a third finger
    that could only turn the object one way about the line of two squeezing fingers).
``degenerate``
    Evidence that the grasp is within tolerance of the closure boundary: ``rank`` (the smallest
    singular value ratio is below the tolerance but the exact rank is full) or ``margin`` (a
    near-interior ``x`` and a near-separating ``y`` both exist).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from . import cones
from . import exact as ex
from .._kernels.cones import polar_values as kernel_polar_values
from .._kernels.recheck import correction_bound, residual_bound, verify_farkas_general, verify_interior_general
from ..errors import CertificateError
from .arguments import number_in, require
from .grasp import Grasp
from .problem import Block, array_blocks, block_arrays, grasp_system, ray_blocks, span_system, span_vectors
from .wrench import planar_generator_arrays, to_exact

__all__ = [
    "Tolerances",
    "Certificate",
    "Check",
    "verify",
    "verify_span",
    "verify_system",
    "margin_tolerance",
    "margin_matches",
    "margin_proved",
    "FLOAT_PROOF_CONTACTS",
]


@dataclass(frozen=True)
class Tolerances:
    """Numerical tolerances of the verdicts (all unit-free).

    Attributes
    ----------
    rank : float
        A column matrix whose smallest to largest singular value ratio is below this is
        numerically rank deficient: ``no_closure`` if its exact rank is deficient, else
        ``degenerate``.
    margin : float
        ``abs(t*)`` below this is ``degenerate``.
    residual : float
        Largest relative equilibrium residual accepted in an interior certificate.
    near : float
        Slack allowed in the evidence of a degenerate verdict.
    """

    rank: float = 1e-9
    margin: float = 1e-7
    residual: float = 1e-7
    near: float = 1e-5

    def __post_init__(self) -> None:
        for name in ("rank", "margin", "residual", "near"):
            number_in(getattr(self, name), name, 0, math.inf)


@dataclass(frozen=True)
class Certificate:
    """Evidence for a verdict (see module docstring). JSON via :meth:`to_json`/:meth:`from_json`."""

    kind: str
    layout: str
    values: tuple[float, ...] | None = None
    basis: tuple[int, ...] | None = None
    y: tuple[float, ...] | None = None
    tight: tuple[int, ...] = ()
    null_space: bool = False
    reason: str | None = None

    def to_json(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind, "layout": self.layout}
        if self.values is not None:
            out["values"] = list(self.values)
        if self.basis is not None:
            out["basis"] = list(self.basis)
        if self.y is not None:
            out["y"] = list(self.y)
        if self.kind == "farkas":
            out["tight"] = list(self.tight)
            out["null_space"] = self.null_space
        if self.reason is not None:
            out["reason"] = self.reason
        return out

    @classmethod
    def from_json(cls, d: Any) -> "Certificate":
        if not isinstance(d, dict) or d.get("kind") not in ("interior", "farkas", "degenerate"):
            raise CertificateError("a certificate is an object with kind interior/farkas/degenerate")
        try:
            floats = lambda key: None if d.get(key) is None else tuple(float(v) for v in d[key])
            basis = None if d.get("basis") is None else tuple(int(v) for v in d["basis"])
            tight = tuple(int(v) for v in d.get("tight", ()))
            return cls(d["kind"], str(d.get("layout", "")), floats("values"), basis, floats("y"),
                       tight, bool(d.get("null_space", False)), d.get("reason"))
        except (TypeError, ValueError) as err:
            raise CertificateError(f"malformed certificate: {err}") from None


@dataclass(frozen=True)
class Check:
    """Outcome of a verification; truthy when it passed."""

    ok: bool
    reason: str = ""

    def __bool__(self) -> bool:
        return self.ok


# --- cone tests of a block (the formulas are :mod:`qualgrasp.certify.core.cones`') --------------------

def strictly_inside(block: Block, v: Sequence) -> bool:
    """Is the value ``v`` (on the block's columns) strictly inside the block's cone? Exact on
    Fractions."""
    return cones.inside(block.cone, v, block.n, block.mu, block.g)


def strictly_polar(block: Block, a: Sequence) -> bool:
    """Is ``a`` (the functional ``y . w`` on the block's columns) in the cone's strict polar?
    Exact on Fractions."""
    return cones.polar(block.cone, a, block.n, block.mu, block.g)


def slack(block: Block, v: Sequence[float]) -> tuple[float, float]:
    """Float ``(slack, normal force)`` of a value on the block (:func:`qualgrasp.certify.core.cones.slack`)."""
    return cones.slack(block.cone, v, block.n, block.mu, block.g)


def polar_values(C, blocks, y) -> np.ndarray:
    """Float polar value of every block for ``a = C_b' y``: the largest ``y . w`` over the
    block's unit-normal-force wrenches (compiled; shared by every route)."""
    C = np.ascontiguousarray(C, dtype=float)
    dim = max((len(b.n) for b in blocks), default=2) or 2
    return kernel_polar_values(C, *block_arrays(blocks, dim), np.ascontiguousarray(y, dtype=float))


def margin_of(blocks, x) -> float:
    """Min-weight margin certified by values ``x``: smallest slack over total normal force."""
    return _margin([slack(b, [x[j] for j in b.cols]) for b in blocks])


def _margin(pairs) -> float:
    """:func:`margin_of` from each block's ``(slack, normal force)``."""
    total = sum(fn for _, fn in pairs)
    return min(s for s, _ in pairs) / total if total > 0 else -math.inf


# --- verification --------------------------------------------------------------------------

def verify(grasp: Grasp, certificate: Certificate, *, status: str | None = None,
           margin: float | None = None, frictionless: bool = False,
           tol: Tolerances = Tolerances(), exact_margin: bool = False) -> Check:
    """Re-check ``certificate`` against ``grasp`` without a solver, in exact rational arithmetic
    on the float data, or first by rigorous float bounds for planar grasps of
    :data:`FLOAT_PROOF_CONTACTS` contacts or more (module docstring).

    Parameters
    ----------
    grasp : Grasp
    certificate : Certificate
        From :func:`qualgrasp.certify.force_closure` or :func:`~qualgrasp.certify.form_closure`,
        or read back from a results file (:meth:`Certificate.from_json`).
    status : str, optional
        The claimed status; checked against the certificate's kind.
    margin : float, optional
        The claimed margin; an interior certificate must support it: at most the margin ``t``
        its (corrected) values certify, to within :func:`margin_tolerance` of ``t``.
    frictionless : bool
        Check form closure (every contact frictionless) instead of force closure.
    tol : Tolerances
        The tolerances the verdict was made with.
    exact_margin : bool
        Also require the claimed margin to be at least ``t`` minus the tolerance: the claim is
        then the certified margin itself (how results rows are re-checked).

    Returns
    -------
    Check
        Truthy when the certificate proves the claim; otherwise ``reason`` says what failed.
        A malformed certificate is a failed check, never an exception.

    Raises
    ------
    TypeError
        ``grasp`` is not a :class:`Grasp`, ``certificate`` not a :class:`Certificate` (read one
        with :meth:`Certificate.from_json`) or ``tol`` not a :class:`Tolerances`.

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp, force_closure, verify
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> v = force_closure(g)
    >>> bool(verify(g, v.certificate, status=v.status, margin=v.margin))
    True
    >>> verify(g, v.certificate, status=v.status, margin=0.3).reason
    'claimed margin 0.3 exceeds the certified 0.25'
    """
    require(grasp, Grasp, "grasp")
    require(certificate, Certificate, "certificate")
    require(tol, Tolerances, "tol")
    if _proved_in_floats(grasp, certificate, status, margin, frictionless, tol):
        return Check(True)
    socp = certificate.layout == "forces"  # a planar grasp may be certified by its 2-D cones
    try:
        Cx, blocks, layout = grasp_system(grasp, frictionless=frictionless, socp=socp, exact=True)
    except ValueError as err:  # a layout the grasp's contacts do not have (pads are polyhedral)
        return Check(False, f"certificate layout {certificate.layout!r}: {err}")
    return verify_system(Cx, blocks, layout, certificate, status=status, margin=margin, tol=tol,
                         exact_margin=exact_margin)


#: Fewest contacts of a planar grasp whose certificate :func:`verify` first tries to prove with
#: the rigorous floating-point kernels, as ``qualgrasp verify`` proves results in bulk: from 8
#: contacts on, where the exact route costs about a millisecond and more a grasp and the floats
#: a tenth of that. Smaller grasps go to the exact route only, which also spares a short run
#: the kernels' compilation.
FLOAT_PROOF_CONTACTS = 8


def _proved_in_floats(grasp: Grasp, cert: Certificate, status, margin, frictionless: bool,
                      tol: Tolerances) -> bool:
    """Whether the rigorous float kernels (:func:`~qualgrasp.certify._kernels.recheck.verify_interior_general`,
    :func:`~qualgrasp.certify._kernels.recheck.verify_farkas_general`: error bounds instead of
    rationals) prove what :func:`verify` checks, for a planar grasp of at least
    :data:`FLOAT_PROOF_CONTACTS` contacts whose models' float cone weights are exact: an
    interior certificate whose claimed margin matches (:func:`margin_proved`), or a strict
    Farkas one (no tight block). False decides nothing: the exact route then checks, and gives
    the reason of a failure."""
    if grasp.dim != 2 or cert.layout != "generators" or cert.kind not in ("interior", "farkas"):
        return False
    if (status is not None and _KIND.get(status) != cert.kind) or \
            not all(c.contact_model.exact_in_floats for c in grasp.contacts):
        return False
    if len(grasp.contacts) < FLOAT_PROOF_CONTACTS:
        return False
    W, E, _ = planar_generator_arrays(grasp, frictionless=frictionless)
    k = W.shape[1]
    arrays = ray_blocks(k, 2)
    if cert.kind == "farkas":
        if not (_numbers(cert.y, 3, _REALS) and isinstance(cert.tight, (tuple, list)) and not cert.tight
                and isinstance(cert.null_space, (bool, np.bool_)) and not cert.null_space):
            return False
        y = np.array(cert.y, dtype=float)
        return bool(np.isfinite(y).all()) and verify_farkas_general(W, E, *arrays, y, np.zeros(k, dtype=bool),
                                                                    0.0)
    if not (_numbers(cert.values, k, _REALS) and _numbers(cert.basis, 3, _INTEGERS)):
        return False
    x, basis = np.array(cert.values, dtype=float), np.array(cert.basis, dtype=np.int64)
    if not np.isfinite(x).all() or len(set(basis.tolist())) != 3 or not ((basis >= 0) & (basis < k)).all():
        return False
    if not verify_interior_general(W, E, *arrays, x, basis, tol.residual):
        return False
    return margin is None or margin_proved(margin, W, E, arrays, x, basis)


_REALS = (int, float, np.integer, np.floating)
_INTEGERS = (int, np.integer)


def _numbers(values, n: int, kinds) -> bool:
    """Whether ``values`` is a sequence of ``n`` numbers of the types ``kinds`` (booleans not
    counted as numbers): what the float route takes; anything else goes to the exact route."""
    return (isinstance(values, (tuple, list)) and len(values) == n
            and all(isinstance(v, kinds) and not isinstance(v, (bool, np.bool_)) for v in values))


def verify_span(vectors, certificate: Certificate, *, status: str | None = None,
                margin: float | None = None, tol: Tolerances = Tolerances()) -> Check:
    """Re-check a positive-spanning certificate for the rows of ``vectors``."""
    span_vectors(vectors)
    require(certificate, Certificate, "certificate")
    Cx, blocks, layout = span_system(vectors, exact=True)
    return verify_system(Cx, blocks, layout, certificate, status=status, margin=margin, tol=tol)


_KIND = {"closure": "interior", "no_closure": "farkas", "degenerate": "degenerate"}


def verify_system(Cx, blocks, layout: str, cert: Certificate, *, status: str | None = None,
                  margin: float | None = None, tol: Tolerances = Tolerances(),
                  exact_margin: bool = False) -> Check:
    """Re-check ``cert`` against exact certificate columns ``Cx`` and their cone ``blocks``
    (``margin`` and ``exact_margin`` as for :func:`verify`)."""
    if status is not None and _KIND.get(status) != cert.kind:
        return Check(False, f"status {status!r} does not match a {cert.kind} certificate")
    if cert.layout != layout:
        return Check(False, f"certificate layout {cert.layout!r}, expected {layout!r}")
    try:
        if cert.kind == "interior":
            return _verify_interior(Cx, blocks, cert, margin, tol, exact_margin)
        if cert.kind == "farkas":
            return _verify_farkas(Cx, blocks, cert)
        return _verify_degenerate(Cx, blocks, cert, tol)
    except (TypeError, ValueError, IndexError, ZeroDivisionError, OverflowError) as err:
        return Check(False, f"malformed certificate: {err}")


def margin_tolerance(t: float) -> float:
    """How far a claimed margin may lie from the margin ``t`` that a certificate's values
    certify: ``1e-9 + 1e-6 |t|``."""
    return 1e-9 + 1e-6 * abs(t)


def margin_matches(claimed: float, blocks, x, delta: float = 0.0) -> bool:
    """Whether a claimed margin is the margin certified by every values within ``delta`` of ``x``
    (in each entry: the exact checker's corrected values, ``delta`` the float kernels' bound on
    the correction) to within half :func:`margin_tolerance`: the rule of the rigorous float
    proofs, which do not correct the values as the exact checker does. A claim near the edge goes
    to the exact checker.

    Examples
    --------
    >>> from qualgrasp.certify.core.problem import Block
    >>> blocks = [Block("ray", (0,)), Block("ray", (1,))]
    >>> margin_matches(0.25, blocks, [1.0, 3.0]), margin_matches(0.3, blocks, [1.0, 3.0])
    (True, False)
    >>> margin_matches(0.25, blocks, [1.0, 3.0], delta=1e-6)  # the correction may move it by 2e-7
    False
    """
    pairs = [slack(b, [x[j] for j in b.cols]) for b in blocks]
    t = _margin(pairs)
    return abs(claimed - t) + 2 * _margin_shift(blocks, pairs, t, delta) <= 0.5 * margin_tolerance(t)


def margin_proved(claimed: float, C, E, arrays, x, basis) -> bool:
    """:func:`margin_matches` of a certificate proved by the float kernels: its values ``x`` over
    columns ``C`` (error bounds ``E``) with ``basis``, its blocks as :func:`block_arrays` gives
    them (``arrays``), the correction the exact checker would make bounded by
    :func:`~qualgrasp.certify._kernels.recheck.correction_bound`."""
    delta = correction_bound(C, E, basis, residual_bound(C, E, x)[0])
    return margin_matches(claimed, array_blocks(*arrays), x, delta)


def _margin_shift(blocks, pairs, t: float, delta: float) -> float:
    """Bound on how far :func:`margin_of` moves when every entry of ``x`` moves by at most
    ``delta``: a ray's slack and normal force move by ``delta``; a Lorentz block's slack by
    ``(1 + mu) |df| + |n| |dm| / g`` (``|df| <= sqrt(dim) delta``, as the float kernels bound it)
    and its normal force by ``|df|``; the margin (least slack over total normal force) by at most
    ``(S + |t| F) / (T - F)`` for slack moves ``S``, normal-force moves ``F`` and total ``T``
    (``pairs``: each block's ``(slack, normal force)`` at ``x``, ``t`` their margin)."""
    if delta == 0.0:
        return 0.0
    if not math.isfinite(delta) or not math.isfinite(t):
        return math.inf
    most, force = 0.0, 0.0
    for b in blocks:
        if b.cone == "ray":
            most, force = max(most, delta), force + delta
            continue
        dim, rn = len(b.n), math.sqrt(sum(float(v) ** 2 for v in b.n))
        df = math.sqrt(dim) * delta
        moments = len(b.cols) - dim  # columns of torsional moments: none without a moment length
        most = max(most, (1 + float(b.mu)) * df + (moments * rn * delta / float(b.g) if moments else 0.0))
        force += df
    total = sum(fn for _, fn in pairs)
    if not total - force > 0:
        return math.inf
    return (most + abs(t) * force) / (total - force) * (1 + 1e-9)


def _verify_interior(Cx, blocks, cert: Certificate, margin, tol: Tolerances,
                     exact_margin: bool = False) -> Check:
    d, k = Cx.shape
    if cert.values is None or len(cert.values) != k:
        return Check(False, f"interior certificate needs {k} values")
    if cert.basis is None or len(set(cert.basis)) != d or not all(0 <= j < k for j in cert.basis):
        return Check(False, f"interior certificate needs {d} distinct basis columns")
    if not all(math.isfinite(v) for v in cert.values):
        return Check(False, "certificate values are not finite")
    x = list(to_exact(cert.values))
    r = [sum(Cx[i, j] * x[j] for j in range(k)) for i in range(d)]
    scale = max(1.0, sum(abs(v) for v in cert.values)) * max(1.0, float(np.abs(Cx.astype(float)).max()))
    if max(abs(float(v)) for v in r) > tol.residual * scale:
        return Check(False, "forces are not in equilibrium (residual too large)")
    B = [[Cx[i, j] for j in cert.basis] for i in range(d)]
    delta = ex.solve(B, [-v for v in r])
    if delta is None:
        return Check(False, "basis columns are linearly dependent")
    for j, dj in zip(cert.basis, delta):
        x[j] += dj
    for b in blocks:
        if not strictly_inside(b, [x[j] for j in b.cols]):
            return Check(False, f"force on columns {list(b.cols)} is not strictly inside its cone")
    if margin is not None:
        t = margin_of(blocks, [float(v) for v in x])
        if margin > t + margin_tolerance(t):
            return Check(False, f"claimed margin {margin:.6g} exceeds the certified {t:.6g}")
        if exact_margin and margin < t - margin_tolerance(t):
            return Check(False, f"claimed margin {margin:.6g} is below the certified {t:.6g}")
    return Check(True)


def _verify_farkas(Cx, blocks, cert: Certificate) -> Check:
    d, k = Cx.shape
    if cert.y is None or len(cert.y) != d or not all(math.isfinite(v) for v in cert.y):
        return Check(False, f"Farkas certificate needs a finite direction y of length {d}")
    tight = set(cert.tight)
    if not tight <= set(range(len(blocks))):
        return Check(False, "tight blocks out of range")
    if cert.null_space != (len(tight) == len(blocks)):
        return Check(False, "null_space must say whether every block is tight")
    y = list(to_exact(cert.y))
    cols = [j for b in sorted(tight) for j in blocks[b].cols]
    yp = ex.project_out(y, [[Cx[i, j] for j in cols] for i in range(d)]) if cols else y
    if all(v == 0 for v in yp):
        return Check(False, "the direction vanishes once projected off the tight blocks")
    norm_y = math.sqrt(sum(float(v) ** 2 for v in y))
    if math.sqrt(sum(float(a - b) ** 2 for a, b in zip(y, yp))) > 1e-6 * norm_y:
        return Check(False, "y is not orthogonal to the tight blocks")
    for i, b in enumerate(blocks):
        if i in tight:
            continue
        a = [sum(Cx[r, j] * yp[r] for r in range(d)) for j in b.cols]
        if not strictly_polar(b, a):
            return Check(False, f"y does not separate the cone on columns {list(b.cols)}")
    return Check(True)


def _verify_degenerate(Cx, blocks, cert: Certificate, tol: Tolerances) -> Check:
    C = Cx.astype(float)
    d, k = C.shape
    if cert.reason == "rank":
        sv = np.linalg.svd(C, compute_uv=False)
        ratio = sv[-1] / sv[0] if k >= d else 0.0
        if ratio > 10 * tol.rank:
            return Check(False, f"singular value ratio {ratio:.3g} is not near zero")
        if ex.rank([list(row) for row in Cx]) < d:
            return Check(False, "exactly rank deficient: the verdict is no_closure, not degenerate")
        return Check(True)
    if cert.reason != "margin" or cert.values is None or cert.y is None:
        return Check(False, "degenerate certificate needs reason 'rank', or 'margin' with values and y")
    x, y = np.array(cert.values), np.array(cert.y)
    if len(x) != k or len(y) != d or not (np.isfinite(x).all() and np.isfinite(y).all()):
        return Check(False, "degenerate certificate has wrong lengths or non-finite numbers")
    total = sum(slack(b, x[list(b.cols)])[1] for b in blocks)
    if not total > 0:
        return Check(False, "near-interior forces have no positive normal force")
    x = x / total
    if np.abs(C @ x).max() > tol.near or margin_of(blocks, x) < -tol.near:
        return Check(False, "values are not a near-interior equilibrium")
    y = y / np.linalg.norm(y)
    if polar_values(C, blocks, y).max() > tol.near:
        return Check(False, "y is not a near-separating direction")
    return Check(True)
