"""The closure programme through clarabel's own Python API, with prebuilt sparse structure.

Clarabel solves ``min q'x : A x + s = b, s in K``. With ``X = (x, t)`` and ``q = (0, -1)`` the rows
are: the zero cone ``columns @ x = 0, normal @ x = 1``; the non-negative cone ``x_r - t`` for rays;
one second-order cone ``(kappa x_n - t, x_tan)`` per cone block. Problems that share a structure
(:attr:`ClosureProblem.structure`) share the sparsity pattern of ``A``, so the solver object is
built once per structure and only its values are updated.

Sign of the dual: stationarity gives ``columns' z_eq + normal z_n = z_cone`` terms, so
``y = -z_eq`` satisfies ``w . y <= z_n`` on every ray (and the polar-cone analogue on cones).
"""

from __future__ import annotations

import clarabel
import numpy as np
import scipy.sparse as sp

from ..errors import SolverError
from ..core.problem import ClosureProblem
from .base import Solution

__all__ = ["ClarabelSolver", "settings"]


def settings() -> "clarabel.DefaultSettings":
    """Clarabel settings used throughout: tight tolerances, updatable data, silent."""
    s = clarabel.DefaultSettings()
    s.verbose = False
    s.presolve_enable = False  # data updates need the full structure
    s.input_sparse_dropzeros = False
    s.tol_gap_abs = s.tol_gap_rel = 1e-10
    s.tol_feas = 1e-10
    s.tol_infeas_abs = s.tol_infeas_rel = 1e-10
    s.max_iter = 100
    return s


def _triplets(problem: ClosureProblem):
    """Row, column and value of every structural entry of ``A`` and the cone list."""
    d, nvar = problem.columns.shape
    tcol = nvar
    r_idx, c_idx = np.meshgrid(np.arange(d), np.arange(nvar), indexing="ij")
    rows = [r_idx.ravel()]
    cols = [c_idx.ravel()]
    vals = [problem.columns.ravel()]
    normal = problem.normal
    nz = np.flatnonzero(normal)
    rows.append(np.full(len(nz), d)), cols.append(nz), vals.append(normal[nz])
    r = d + 1
    cones = [clarabel.ZeroConeT(d + 1)]
    rays = np.array(problem.rays, dtype=int)
    if len(rays):
        m = len(rays)
        rows += [r + np.arange(m), r + np.arange(m)]
        cols += [rays, np.full(m, tcol)]
        vals += [-np.ones(m), np.ones(m)]
        cones.append(clarabel.NonnegativeConeT(m))
        r += m
    for start, size, kappa in problem.cones:
        rows += [np.array([r, r]), r + np.arange(1, size)]
        cols += [np.array([start, tcol]), start + np.arange(1, size)]
        vals += [np.array([-kappa, 1.0]), -np.ones(size - 1)]
        cones.append(clarabel.SecondOrderConeT(size))
        r += size
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(vals), r, cones


class _Built:
    """A clarabel solver prebuilt for one structure, and how to refill its ``A`` values."""

    def __init__(self, problem: ClosureProblem, equilibrate: bool = False) -> None:
        rows, cols, vals, m, cones = _triplets(problem)
        n = problem.nvar + 1
        # CSC order of the triplets: fill a matrix with their indices and read them back.
        order = sp.csc_matrix((np.arange(len(vals), dtype=float), (rows, cols)), shape=(m, n))
        self.perm = order.data.astype(int)
        self.template = vals
        self.ncol = problem.columns.size
        self.kappa_at = np.array([np.flatnonzero((rows == r) & (cols == s))[0]
                                  for r, s in _cone_rows(problem)], dtype=int)
        A = sp.csc_matrix((vals[self.perm], order.indices, order.indptr), shape=(m, n))
        b = np.zeros(m)
        b[problem.d] = 1.0
        q = np.zeros(n)
        q[-1] = -1.0
        s = settings()
        s.equilibrate_enable = equilibrate
        self.solver = clarabel.DefaultSolver(sp.csc_matrix((n, n)), q, A, b, cones, s)
        self.fresh = True

    def solve(self, problem: ClosureProblem):
        if not self.fresh:
            vals = self.template.copy()
            vals[: self.ncol] = problem.columns.ravel()
            vals[self.kappa_at] = [-mu for _, _, mu in problem.cones]
            self.solver.update(A=vals[self.perm])
        self.fresh = False
        return self.solver.solve()


def _cone_rows(problem: ClosureProblem):
    """(row, column) of each cone's ``-kappa`` entry in ``A``, in cone order."""
    r = problem.d + 1 + len(problem.rays)
    out = []
    for start, size, _ in problem.cones:
        out.append((r, start))
        r += size
    return out


_ANSWERS = ("Solved", "AlmostSolved", "PrimalInfeasible", "AlmostPrimalInfeasible")


class ClarabelSolver:
    """Solve closure programmes with clarabel directly; one prebuilt solver per structure."""

    def __init__(self) -> None:
        self._built: dict[tuple, _Built] = {}

    def solve(self, problem: ClosureProblem) -> Solution:
        # A prebuilt solver is refilled without equilibration: updating would reuse the scaling
        # computed for the first problem, making results depend on which grasp came first.
        # Closure data are well scaled (unit normals, torques divided by the length); the rare
        # problem that needs equilibration gets a fresh, equilibrated solver of its own.
        key = problem.structure
        if key not in self._built:
            self._built[key] = _Built(problem)
        sol = self._built[key].solve(problem)
        status = str(sol.status)
        if status not in _ANSWERS:
            sol = _Built(problem, equilibrate=True).solve(problem)
            status = str(sol.status)
        z = np.asarray(sol.z)
        if status in ("Solved", "AlmostSolved"):
            x = np.asarray(sol.x)
            return Solution("optimal", float(x[-1]), x[:-1], -z[: problem.d])
        if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
            y = -z[: problem.d]
            return Solution("infeasible", -np.inf, None, y / np.linalg.norm(y))
        raise SolverError(f"clarabel returned status {status}")
