"""Columnar re-check of a results table against its grasps: the independent checker at scale.

:func:`recheck_table` re-checks every row of a results table (:data:`qualgrasp.certify.table.RESULT_SCHEMA`)
against the grasp table it came from. The common certificates are proved in bulk with the
rigorous floating-point kernels of :mod:`qualgrasp.certify.kernels` (error bounds instead of rationals):
planar generator certificates (interior, strict Farkas, null space) and spatial ones (interior
forces, strict Farkas, null-space form certificates). Each row's claims are checked as
:func:`qualgrasp.certify.report.verify_row` checks them (status against certificate kind, closure flags,
margins). Every row not proved in bulk goes through :func:`qualgrasp.certify.report.verify_row`, which uses
exact rational arithmetic; a row fails only if that fails. No solver is involved anywhere.
"""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from .certificates import Tolerances
from .columns import FRICTIONLESS, POINT, SOFT, GraspColumns, grasp_columns
from .kernels import (_planar_generators, null_rows, verify_farkas_general,
                      verify_interior_general)
from .wrench import force_columns, generator_columns

__all__ = ["recheck_table"]

_FLAGS = {"closure": True, "no_closure": False}


def _cert_arrays(struct: pa.StructArray, rows: np.ndarray, width: int, d: int):
    """Kind, values (rows, width), basis (rows, d), y (rows, d), tight lengths, null_space of the
    certificate structs at ``rows`` (values only where their length is ``width``)."""
    sub = struct.take(pa.array(rows))
    fields = dict(zip([f.name for f in sub.type], sub.flatten()))
    kind = np.asarray(fields["kind"].to_numpy(zero_copy_only=False), dtype=object)
    layout = np.asarray(fields["layout"].to_numpy(zero_copy_only=False), dtype=object)

    def fixed(arr, w, dtype=float):
        out = np.zeros((len(rows), w), dtype=dtype)
        lengths = np.asarray(arr.value_lengths().fill_null(0).to_numpy(zero_copy_only=False))
        ok = lengths == w
        flat = arr.flatten().to_numpy(zero_copy_only=False).astype(dtype)
        offsets = np.concatenate([[0], np.cumsum(lengths)])
        for j in range(w):
            idx = offsets[:-1][ok] + j
            out[ok, j] = flat[idx]
        return out, ok

    values, vok = fixed(fields["values"], width)
    basis, bok = fixed(fields["basis"], d, np.int64)
    y, yok = fixed(fields["y"], d)
    tight_len = np.asarray(fields["tight"].value_lengths().fill_null(0).to_numpy(zero_copy_only=False))
    null = np.asarray(fields["null_space"].fill_null(False).to_numpy(zero_copy_only=False), dtype=bool)
    return kind, layout, values, vok, basis, bok, y, yok, tight_len, null


def _claims_ok(status, margin, flag, kind) -> np.ndarray:
    """The row's statements agree with each other (as :func:`verify_row` requires)."""
    expected = np.array([{"closure": "interior", "no_closure": "farkas"}.get(s) for s in status], dtype=object)
    flags = np.array([_FLAGS.get(s) for s in status], dtype=object)
    ok = (kind == expected) & np.array([f is not None and f == g for f, g in zip(flag, flags)])
    ok &= (status == "closure") | (margin == 0)
    return ok


def _group_proofs(cols: GraspColumns, rows: np.ndarray, res: pa.Table, tol: Tolerances) -> np.ndarray:
    """Rows (indices into ``rows``) whose force and form certificates are proved in bulk."""
    m = int(cols.count[rows[0]])
    dim = int(cols.dim[rows[0]])
    names = {FRICTIONLESS: "frictionless", POINT: "point", SOFT: "soft"}
    models = tuple(names[int(c)] for c in cols.model[rows[0], :m])
    P = np.ascontiguousarray(cols.P[rows, :m, :dim])
    N = np.ascontiguousarray(cols.N[rows, :m, :dim])
    mu = np.ascontiguousarray(cols.mu[rows, :m])
    tor = np.ascontiguousarray(cols.torsion[rows, :m])
    c, L = np.ascontiguousarray(cols.center[rows, :dim]), np.ascontiguousarray(cols.length[rows])
    cert = res.column("certificate").combine_chunks()
    status = np.asarray(res.column("status").to_numpy(zero_copy_only=False), dtype=object)[rows]
    form_status = np.asarray(res.column("form_status").to_numpy(zero_copy_only=False), dtype=object)[rows]
    margin = np.nan_to_num(res.column("margin").to_numpy(zero_copy_only=False).astype(float))[rows]
    form_margin = np.nan_to_num(res.column("form_margin").to_numpy(zero_copy_only=False).astype(float))[rows]
    force_flag = res.column("force_closure").to_pylist()
    form_flag = res.column("form_closure").to_pylist()
    proved = np.ones(len(rows), dtype=bool)
    polyhedral = dim == 2 or all(name == "frictionless" for name in models)
    for key, fl, st, mg, flags in (("force", False, status, margin, [force_flag[r] for r in rows]),
                                   ("form", True, form_status, form_margin, [form_flag[r] for r in rows])):
        struct = cert.field(key)
        if polyhedral or fl:
            C, owner = generator_columns(P, N, mu, models, c, L, frictionless=fl)
            C = np.ascontiguousarray(C)
            k = C.shape[2]
            E = _generator_error(P, N, mu, models, c, L, fl, C.shape)
            kind_b = np.zeros(k, dtype=np.int64)
            first = np.arange(k)
            nb = np.zeros((len(rows), k, dim))
            mub = np.zeros((len(rows), k))
            torb = np.zeros((len(rows), k))
            layout = "generators"
            blocks = k
        else:
            C, owner = force_columns(P, N, models, c, L)
            C = np.ascontiguousarray(C)
            k = C.shape[2]
            from .fastpath import _force_column_error

            E = _force_column_error(P, N, models, c, L, k)
            kind_b = np.array([("frictionless", "point", "soft").index(name) for name in models])
            first = np.array([np.flatnonzero(owner == i)[0] for i in range(m)])
            nb, mub, torb = N, mu, tor
            layout = "forces"
            blocks = m
        d = C.shape[1]
        kind, lay, values, vok, basis, bok, y, yok, tight_len, null = _cert_arrays(struct, rows, k, d)
        ok = _claims_ok(st, mg, flags, kind) & (lay == layout)
        interior = ok & (kind == "interior") & vok & bok
        farkas = ok & (kind == "farkas") & yok & (tight_len == 0) & ~null
        nulls = ok & (kind == "farkas") & yok & null & (tight_len == blocks) & (k < d)
        good = np.zeros(len(rows), dtype=bool)
        none = np.zeros(len(kind_b), dtype=bool)
        for i in np.flatnonzero(interior):
            if verify_interior_general(C[i], E[i], kind_b, first, nb[i], mub[i], torb[i], values[i],
                                       basis[i], tol.residual) and \
                    mg[i] <= _certified_margin(C[i], kind_b, first, nb[i], mub[i], torb[i], values[i]):
                good[i] = True
        for i in np.flatnonzero(farkas):
            good[i] = verify_farkas_general(C[i], E[i], kind_b, first, nb[i], mub[i], torb[i], y[i],
                                            none, 0.0)
        if nulls.any():
            good[nulls] = null_rows(C[nulls], np.ascontiguousarray(E[nulls]),
                                    np.ascontiguousarray(y[nulls])) == 3
        proved &= good
    return proved


def _certified_margin(C, kind, first, n, mu, torsion, x) -> float:
    """Margin the values certify (slack over total normal force), with slack for rounding; the
    claimed margin may not exceed it (the exact checker's rule, with its tolerance)."""
    from .certificates import margin_of
    from .problem import Block

    dim = n.shape[1]
    blocks = []
    for b in range(len(kind)):
        width = 1 if kind[b] == 0 else (dim if kind[b] == 1 else dim + 1)
        blocks.append(Block(("ray", "point", "soft")[kind[b]], tuple(range(first[b], first[b] + width)),
                            tuple(n[b]), mu[b], torsion[b]))
    t = margin_of(blocks, x)
    return t + 1e-9 + 1e-6 * abs(t)


def _generator_error(P, N, mu, models, c, L, frictionless, shape) -> np.ndarray:
    """Error bounds of planar or spatial generator columns (see :func:`_planar_generators` and
    :func:`qualgrasp.certify.fastpath._force_column_error`)."""
    B, d, k = shape
    if d == 3:
        from .fastpath import _layout

        owner, sgn = _layout(models, frictionless)
        W = np.empty((3, k))
        E = np.empty((B, 3, k))
        for i in range(B):
            _planar_generators(P[i], N[i], mu[i], c[i], L[i], owner, sgn, W, E[i])
        return E
    from .fastpath import _force_column_error

    return _force_column_error(P, N, ("frictionless",) * k, c, L, k)


def recheck_table(grasps: pa.Table, results: pa.Table, lines, slow, tol: Tolerances = Tolerances()):
    """Re-check ``results`` against ``grasps`` (same rows in the same order).

    ``slow(index) -> Check`` re-checks one row exactly; it receives every row not proved in
    bulk. Returns the boolean array of rows that passed.
    """
    n = results.num_rows
    cols = grasp_columns(grasps)
    status = np.asarray(results.column("status").to_numpy(zero_copy_only=False), dtype=object)
    passed = np.zeros(n, dtype=bool)
    line = results.column("line").to_numpy(zero_copy_only=False)
    ids_ok = np.array([a == b or str(a) == str(b) for a, b in
                       zip(results.column("id").to_pylist(), cols.ids.to_pylist())], dtype=bool)
    fine = cols.ok & (status != "error") & ids_ok & (np.asarray(line) == np.asarray(lines))
    m = cols.model.shape[1]
    key = cols.dim * 3 ** (m + 2) + cols.count * 3 ** m + \
        (np.where(cols.model < 0, 0, cols.model) * 3 ** np.arange(m)).sum(1)
    for k in np.unique(key[fine]):
        rows = np.flatnonzero(fine & (key == k))
        passed[rows] = _group_proofs(cols, rows, results, tol)
    for i in np.flatnonzero(~passed):
        passed[i] = bool(slow(int(i)))
    return passed
