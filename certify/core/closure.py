"""Closure verdicts: form closure, force closure and positive spanning, each with a certificate.

Every verdict follows the same steps on the closure programme of :mod:`qualgrasp.certify.core.problem`:

1. Solve for ``t*``. With full rank and ``t* >= tol.margin``: ``closure`` (interior certificate).
   Otherwise, if the dual direction separates (strictly on every contact, or exactly orthogonal
   to contacts that carry no force and strictly on the rest): ``no_closure`` with a Farkas
   certificate, whatever the rank and even when ``t* = 0``: a separating direction is a proof.
   A direction with tight contacts is checked exactly (:func:`exact_farkas`): orthogonal in
   floats to nearly parallel wrenches (an antipodal pair) is not always orthogonal to their exact
   span, and the exact projection off that span is stated instead, or nothing.
2. Rank. If the columns' smallest to largest singular value ratio is below ``tol.rank``, the exact
   rank (rational arithmetic on the float data) decides: deficient gives ``no_closure`` with a
   null-space Farkas direction (exactly orthogonal, by :func:`exact_farkas`), full gives
   ``degenerate`` (reason ``rank``): such a grasp could resist some wrench only with unbounded
   forces, and rounding decides which.
3. Otherwise ``degenerate`` (reason ``margin``): ``t*`` is below ``tol.margin`` and no exact
   separating direction exists. A degenerate verdict is never turned into a guess.

The margin reported is ``t*`` for closure and 0 otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import exact as ex
from .certificates import Certificate, Tolerances, verify_system
from .. import models as registry
from ..errors import ArgumentError, SolverError
from .arguments import require
from .grasp import Grasp
from .._kernels.cones import farkas_direction
from .._kernels.linalg import null_direction, pivot_basis
from .wrench import to_exact
from .problem import (ClosureProblem, block_arrays, grasp_problem, grasp_system, span_problem, span_system,
                      span_vectors)
from ..solvers import Method, make_solver

__all__ = ["Verdict", "force_closure", "form_closure", "positive_span", "decide", "exact_farkas",
           "farkas_certificate", "farkas_from_arrays"]


@dataclass(frozen=True)
class Verdict:
    """Outcome of a closure test.

    Attributes
    ----------
    status : {'closure', 'no_closure', 'degenerate'}
    margin : float
        Min-weight margin ``t*`` when in closure, else 0.
    certificate : Certificate
        Evidence re-checkable by :func:`qualgrasp.certify.core.certificates.verify`.
    """

    status: str
    margin: float
    certificate: Certificate

    @property
    def closure(self) -> bool | None:
        """True, False, or None when degenerate."""
        return None if self.status == "degenerate" else self.status == "closure"


def _floats(a) -> tuple[float, ...]:
    return tuple(float(v) for v in np.ravel(a))


def decide(problem: ClosureProblem, exact_columns, solver,
           tol: Tolerances = Tolerances()) -> Verdict:
    """Verdict for ``problem``, with a certificate over its certificate system.

    ``exact_columns`` is a callable returning the exact certificate columns (only called for
    numerically rank-deficient problems).
    """
    C, blocks, layout = problem.system
    d, k = C.shape
    # U spans the wrench space (d x d); V (k x k) is never needed, and too big at many contacts
    U, sv, _ = np.linalg.svd(C, full_matrices=k < d)
    thin = k < d or sv[-1] <= tol.rank * sv[0]
    sol = None
    if k >= d:  # fewer columns than rows: rank-deficient, nothing to solve
        try:
            sol = solver.solve(problem)
        except SolverError:
            if not thin:
                raise  # solvers may fail on rank-deficient data; there the rank decides below
    if sol is not None and not thin and sol.status == "optimal" and sol.t >= tol.margin:
        values = problem.values(sol.x)
        basis = pivot_basis(np.ascontiguousarray(C, dtype=float))
        cert = Certificate("interior", layout, _floats(values), tuple(int(j) for j in basis))
        return Verdict("closure", float(sol.t), cert)
    if sol is not None and sol.y is not None and sol.t < tol.margin:
        cert = farkas_certificate(C, blocks, layout, sol.y)
        if cert is not None and _ill_conditioned(C, blocks, cert.tight):
            cert = exact_farkas(exact_columns(), blocks, cert)
        if cert is not None:
            return Verdict("no_closure", 0.0, cert)
    if thin:
        Cx = exact_columns()
        if k < d or ex.rank([list(r) for r in Cx]) < d:
            y = null_direction(np.ascontiguousarray(C)) if d == 3 and k < d else U[:, -1]
            cert = Certificate("farkas", layout, y=_floats(y),
                               tight=tuple(range(len(blocks))), null_space=True)
            for axis in np.eye(d):  # the exact projection of y vanishes only by accident
                if (found := exact_farkas(Cx, blocks, cert)) is not None:
                    return Verdict("no_closure", 0.0, found)
                cert = replace(cert, y=_floats(axis))
        return Verdict("degenerate", 0.0, Certificate("degenerate", layout, reason="rank"))
    values = None if sol.x is None else _floats(problem.values(sol.x))
    y = None if sol.y is None else _floats(sol.y / np.linalg.norm(sol.y))
    return Verdict("degenerate", 0.0,
                   Certificate("degenerate", layout, values, y=y, reason="margin"))


def _ill_conditioned(C: np.ndarray, blocks, tight) -> bool:
    """Are the columns of the ``tight`` blocks of ``C`` far from independent (singular value
    ratio at most 1e-6, or more columns than rows)? Only then can a direction orthogonal to them
    in floats (to rounding, after the kernel's projection) fail the exact check's ``1e-6 |y|``:
    otherwise the exact projection moves it by about ``1e-16`` times their condition number."""
    cols = [j for b in tight for j in blocks[b].cols]
    if not cols:
        return False
    sv = np.linalg.svd(C[:, cols], compute_uv=False)
    return len(cols) > C.shape[0] or not sv[-1] > 1e-6 * sv[0]


def exact_farkas(Cx, blocks, cert: Certificate) -> Certificate | None:
    """``cert`` if the exact checker accepts it against the exact columns ``Cx``; else the same
    tight blocks with ``y`` replaced by its exact projection off their columns, rounded
    (:func:`qualgrasp.certify.core.exact.unit_direction`), with either sign, if accepted; else
    None.

    A direction orthogonal in floats to nearly parallel generators (antipodal contacts, normals
    through one point) need not be orthogonal to their exact span, which contains a direction
    set by their rounding; the exact projection is. The tight blocks allow either sign, and the
    other blocks decide which (the projection's own first). Compiled counterpart for planar
    batches: :func:`qualgrasp.certify.batch.fastpath` (its thin rows).
    """
    layout = cert.layout
    if verify_system(Cx, blocks, layout, cert):
        return cert
    d = Cx.shape[0]
    cols = [j for b in cert.tight for j in blocks[b].cols]
    yp = ex.project_out(list(to_exact(cert.y)), [[Cx[i, j] for j in cols] for i in range(d)])
    if not cols or not any(yp):
        return None
    u = np.array(ex.unit_direction(yp))
    for y in (u, -u):
        found = replace(cert, y=_floats(y))
        if verify_system(Cx, blocks, layout, found):
            return found
    return None


def farkas_certificate(C: np.ndarray, blocks, layout: str, y: np.ndarray,
                       rel: float = 1e-7) -> Certificate | None:
    """A Farkas certificate built from the dual direction ``y``, or None if ``y`` does not give one.

    A ``y`` strictly separating every block is a certificate as it is. Otherwise blocks on which
    ``y`` vanishes (relative to ``rel``) are declared tight and ``y`` is projected off their
    columns; every other block must then be strictly separated (float check with a margin; the
    exact check is :func:`qualgrasp.certify.core.certificates.verify`). Compiled:
    :func:`qualgrasp.certify._kernels.cones.farkas_direction`.
    """
    dim = max((len(b.n) for b in blocks), default=2) or 2
    return farkas_from_arrays(C, block_arrays(blocks, dim), layout, y, rel)


def farkas_from_arrays(C: np.ndarray, arrays, layout: str, y: np.ndarray,
                       rel: float = 1e-7) -> Certificate | None:
    """:func:`farkas_certificate` with the blocks given as ``(cone, first, width, n, mu, g)``
    arrays (:func:`qualgrasp.certify.core.problem.block_arrays`), as the columnar path holds them."""
    ok, y, tight = farkas_direction(np.ascontiguousarray(C, dtype=float), *arrays,
                                    np.ascontiguousarray(y, dtype=float), rel)
    if not ok:
        return None
    tight = tuple(int(i) for i in np.flatnonzero(tight))
    return Certificate("farkas", layout, y=_floats(y), tight=tight,
                       null_space=bool(tight) and len(tight) == len(arrays[0]))


def force_closure(grasp: Grasp, *, method: Method = "fast", solver=None, socp: bool = False,
                  tol: Tolerances = Tolerances()) -> Verdict:
    """Force closure of ``grasp`` under its declared contact models, with a certificate.

    Planar contacts are exact polyhedral cones (an LP: friction cones are their two edges, a pad's
    cone the edges at its two ends); spatial point and soft contacts exact second-order cones (an
    SOCP). The closure programme and the verdict rules are those of :mod:`qualgrasp.certify.core.problem`
    and :func:`decide`.

    Parameters
    ----------
    grasp : Grasp
        The grasp (contacts, torque ``center`` and ``length``).
    method : {'fast', 'reference'}
        Solver route: the fast route (compiled enumeration, barrier method, clarabel) or the
        readable cvxpy formulation. Both give the same verdict.
    solver : object, optional
        A solver from :func:`qualgrasp.certify.solvers.make_solver`, to reuse prebuilt structure
        across calls (overrides ``method``).
    socp : bool
        Solve a planar grasp with 2-D second-order cones instead of edges (same verdict, margin on
        the cone scale ``mu f_n - abs(f_t)``; a cross-check of the LP). Not for pads.
    tol : Tolerances
        Numerical tolerances of the verdict.

    Returns
    -------
    Verdict
        ``status`` (``closure``, ``no_closure`` or ``degenerate``), the min-weight ``margin``
        (``t*``, 0 unless in closure) and the ``certificate``.

    Raises
    ------
    ArgumentError
        Unknown ``method``, or ``socp`` with a polyhedral contact model (pads).
    TypeError
        ``grasp`` is not a :class:`Grasp` or ``tol`` not a :class:`Tolerances`.
    SolverError
        The solver failed on a full-rank problem (not seen in practice).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp, force_closure
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> v = force_closure(g)
    >>> v.status, v.margin, v.certificate.kind
    ('closure', 0.25, 'interior')
    """
    return _grasp_verdict(grasp, False, method, solver, tol, socp)


def form_closure(grasp: Grasp, *, method: Method = "fast", solver=None,
                 tol: Tolerances = Tolerances()) -> Verdict:
    """Form closure of ``grasp``: force closure with friction ignored at every contact (each
    contact replaced by its model's frictionless counterpart; a pad stays a pad with ``mu = 0``).

    Parameters
    ----------
    grasp : Grasp
    method, solver, tol
        As for :func:`force_closure`.

    Returns
    -------
    Verdict

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp, form_closure
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> form_closure(g).status  # two frictionless contacts cannot hold a planar object
    'no_closure'
    """
    return _grasp_verdict(grasp, True, method, solver, tol)


def _grasp_verdict(grasp, frictionless, method, solver, tol, socp=False) -> Verdict:
    require(grasp, Grasp, "grasp")
    require(tol, Tolerances, "tol")
    polyhedral = [c.model for c in grasp.contacts if registry.get(c.model).forces is None]
    if socp and polyhedral:
        raise ArgumentError(f"socp=True: {polyhedral[0]} contacts have no conic form (they are polyhedral); "
                            "use socp=False")
    solver = solver or make_solver(method)
    kw = dict(frictionless=frictionless, socp=socp)
    return decide(
        grasp_problem(grasp, **kw),
        lambda: grasp_system(grasp, exact=True, **kw).columns,
        solver,
        tol,
    )


def positive_span(vectors, *, method: Method = "fast", solver=None,
                  tol: Tolerances = Tolerances()) -> Verdict:
    """Do the rows of ``vectors`` positively span ``R^d``?

    True iff they have rank ``d`` and a strictly positive combination of them is zero. In the
    plane, unit normals positively span iff their largest angular gap is below pi.

    Parameters
    ----------
    vectors : array_like
        ``(k, d)`` finite vectors.
    method, solver, tol
        As for :func:`force_closure`.

    Returns
    -------
    Verdict
        ``closure`` when they positively span, with a certificate re-checkable by
        :func:`qualgrasp.certify.verify_span`.

    Raises
    ------
    GraspError
        ``vectors`` is not a finite 2-D array.

    Examples
    --------
    >>> from qualgrasp.certify import positive_span
    >>> positive_span([[1, 0], [-0.5, 0.9], [-0.5, -0.9]]).status
    'closure'
    >>> positive_span([[1, 0], [0, 1], [-1, 0.1]]).status  # all in the upper half plane
    'no_closure'
    """
    V = span_vectors(vectors)
    require(tol, Tolerances, "tol")
    solver = solver or make_solver(method)
    return decide(span_problem(V), lambda: span_system(V, exact=True).columns, solver, tol)
