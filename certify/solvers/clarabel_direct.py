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
from ..problem import ClosureProblem
from . import Solution

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


class ClarabelSolver:
    """Solve closure programmes with clarabel directly; one prebuilt solver per structure."""

    def __init__(self) -> None:
        self._built: dict[tuple, tuple] = {}

    def solve(self, problem: ClosureProblem) -> Solution:
        rows, cols, vals, m, cones = _triplets(problem)
        n = problem.nvar + 1
        A = sp.csc_matrix((vals, (rows, cols)), shape=(m, n))
        key = problem.structure
        if key in self._built:
            solver = self._built[key]
            solver.update(A=A.data)
        else:
            b = np.zeros(m)
            b[problem.d] = 1.0
            q = np.zeros(n)
            q[-1] = -1.0
            P = sp.csc_matrix((n, n))
            solver = clarabel.DefaultSolver(P, q, A, b, cones, settings())
            self._built[key] = solver
        sol = solver.solve()
        status = str(sol.status)
        z = np.asarray(sol.z)
        if status in ("Solved", "AlmostSolved"):
            x = np.asarray(sol.x)
            return Solution("optimal", float(x[-1]), x[:-1], -z[: problem.d])
        if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
            y = -z[: problem.d]
            return Solution("infeasible", -np.inf, None, y / np.linalg.norm(y))
        raise SolverError(f"clarabel returned status {status}")
