"""Columnar certification of a chunk of grasps: compiled kernels for whole groups at once.

:func:`certify_table` takes a grasp table (:data:`certify.table.GRASP_SCHEMA`) and returns the
results table (:data:`certify.table.RESULT_SCHEMA`), row for row equal to what
:func:`certify.report.certify_grasp` gives grasp by grasp. Valid planar grasps are grouped by
contact pattern and each group goes through the compiled kernels of :mod:`certify.kernels`:
the LP (the same kernel the per-grasp path calls), the certificate, its rigorous re-check in
floating point with error bounds, and the exact planar epsilon. Every row the columnar rules do
not settle (invalid input, spatial grasps, numerically thin or near-degenerate problems, Farkas
directions with tight contacts, certificates the float re-check cannot prove) goes through the
per-grasp path, so the two agree by construction.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pyarrow as pa

from .certificates import Tolerances
from .columns import FRICTIONLESS, POINT, GraspColumns, grasp_columns
from .kernels import (lp_planar, pivot_bases, planar_epsilon, thin_planar, verify_null_planar,
                      verify_planar)
from .solvers.enumeration import _FEAS, bases
from .table import CERTIFICATE, RESULT_SCHEMA
from .wrench import generator_columns

__all__ = ["certify_table", "generator_error"]

_U = 2.0**-53
_MODEL_NAMES = {FRICTIONLESS: "frictionless", POINT: "point"}


def _gamma(n: int) -> float:
    return n * _U / (1 - n * _U)


def generator_error(P, N, mu, models, center, length, *, frictionless: bool = False) -> np.ndarray:
    """Bounds on the difference between the planar generator wrenches computed in floating point
    by :func:`certify.wrench.generator_columns` and their exact values on the same float data.

    A frictionless generator ``(n, ((p - c) x n) / L)``: forces exact, torque within
    ``gamma_10 (|dx| |n_y| + |dy| |n_x|) / L``. A friction edge ``n +- mu t``: each force
    component within ``gamma_2 (|n_x| + mu |n_y|)`` (resp. ``y``), torque as above with those
    magnitudes. ``gamma_n = n u / (1 - n u)``, ``u = 2^-53`` (Higham); generous by a few units.
    """
    owner, edge = [], []
    for i, model in enumerate(models):
        if frictionless or model == "frictionless":
            owner.append(i), edge.append(False)
        else:
            owner += [i, i]
            edge += [True, True]
    owner = np.array(owner)
    edge = np.array(edge)
    n = np.abs(N[..., owner, :])
    m = np.where(edge, mu[..., owner], 0.0)
    ax = n[..., 0] + m * n[..., 1]
    ay = n[..., 1] + m * n[..., 0]
    d = np.abs(P[..., owner, :] - np.asarray(center)[..., None, :])
    L = np.asarray(length)[..., None]
    E = np.zeros(P.shape[:-2] + (3, len(owner)))
    E[..., 0, :] = np.where(edge, _gamma(2) * ax, 0.0)
    E[..., 1, :] = np.where(edge, _gamma(2) * ay, 0.0)
    E[..., 2, :] = _gamma(10) * (d[..., 0] * ay + d[..., 1] * ax) / L
    return E


def _list_array(values: np.ndarray, valid: np.ndarray, type_: pa.DataType) -> pa.Array:
    """Arrow list array with ``values.shape[1]`` items per valid row and nulls elsewhere."""
    n, w = values.shape
    offsets = np.zeros(n + 1, dtype=np.int32)
    offsets[1:] = np.cumsum(np.where(valid, w, 0))
    flat = values[valid].ravel()
    return pa.ListArray.from_arrays(pa.array(offsets), pa.array(flat, type=type_.value_type),
                                    mask=pa.array(~valid))


def _certificates(interior: np.ndarray, lam: np.ndarray, basis: np.ndarray, y: np.ndarray,
                  null_space: bool) -> pa.Array:
    """Certificate structs (generators layout): interior rows carry weights and basis, the
    others a Farkas direction: strict, or (``null_space``) orthogonal to every generator."""
    n, k = lam.shape
    far = ~interior
    tight = np.tile(np.arange(k if null_space else 0, dtype=np.int32), (n, 1))
    return pa.StructArray.from_arrays([
        pa.array(np.where(interior, "interior", "farkas").astype(object)),
        pa.array(np.full(n, "generators", dtype=object)),
        _list_array(lam, interior, CERTIFICATE.field("values").type),
        _list_array(basis.astype(np.int32), interior, CERTIFICATE.field("basis").type),
        _list_array(y, far, CERTIFICATE.field("y").type),
        _list_array(tight, far, CERTIFICATE.field("tight").type),
        pa.array(np.where(far, null_space, None).tolist(), type=pa.bool_()),
        pa.nulls(n, pa.string()),
    ], fields=list(CERTIFICATE))


def _verdicts(W: np.ndarray, tol: Tolerances):
    """Closure verdicts of a group of planar generator matrices (B, 3, k), as
    :func:`certify.closure.decide` gives them; ``settled`` is False where that needs the per-grasp
    path (thin, near-degenerate, tight Farkas directions)."""
    B, d, k = W.shape
    if k < d:  # fewer generators than wrench dimensions: a null-space direction, from the SVD
        y = np.linalg.svd(W)[0][:, :, -1]
        no = np.zeros(B, dtype=bool)
        return no, ~no, np.full(B, -np.inf), np.zeros((B, k)), np.zeros((B, d), int), y
    t, lam, y, has_y = lp_planar(W, bases(k, d), _FEAS)
    thin = thin_planar(W)
    closure = ~thin & (t >= tol.margin)
    # strict Farkas direction exactly as farkas_certificate builds it (no tight contacts)
    with np.errstate(invalid="ignore", divide="ignore"):
        yn = y / np.sqrt(np.sum(y * y, axis=1, keepdims=True))
    funct = np.einsum("bdk,bd->bk", W, yn)
    scale = np.abs(W).max(axis=(1, 2))
    tight = (np.abs(funct) <= 1e-7 * scale[:, None]).any(axis=1)
    strict = funct.max(axis=1) < -1e-9 * scale
    farkas = ~thin & ~closure & has_y & (t < tol.margin) & ~tight & strict
    basis = np.zeros((B, d), dtype=np.int64)
    if closure.any():
        basis[closure] = pivot_bases(np.ascontiguousarray(W[closure]))
    return closure, farkas, t, lam, basis, yn


def _planar_group(cols: GraspColumns, rows: np.ndarray, options, tol: Tolerances):
    """Certify the planar grasps ``rows`` (one contact pattern); return the settled rows and
    their result columns."""
    m = int(cols.count[rows[0]])
    models = tuple(_MODEL_NAMES[int(c)] for c in cols.model[rows[0], :m])
    P = np.ascontiguousarray(cols.P[rows, :m, :2])
    N = np.ascontiguousarray(cols.N[rows, :m, :2])
    mu = cols.mu[rows, :m]
    c, L = cols.center[rows, :2], cols.length[rows]
    out: dict[str, Any] = {}
    settled = np.ones(len(rows), dtype=bool)
    frictionless = all(name == "frictionless" for name in models)
    for key, fl in (("force", False), ("form", True)):
        if key == "form" and frictionless:
            out["form"] = out["force"]
            break
        W, _ = generator_columns(P, N, mu, models, c, L, frictionless=fl)
        W = np.ascontiguousarray(W)
        closure, farkas, t, lam, basis, yn = _verdicts(W, tol)
        E = np.ascontiguousarray(generator_error(P, N, mu, models, c, L, frictionless=fl))
        if W.shape[2] < W.shape[1]:
            proved = verify_null_planar(W, E, np.ascontiguousarray(yn))
        else:
            kind = np.where(closure, 1, np.where(farkas, 2, 0))
            proved = verify_planar(W, E, kind, np.nan_to_num(lam), basis, np.nan_to_num(yn),
                                   tol.residual)
        settled &= (closure | farkas) & (proved == 1)
        out[key] = (closure, t, lam, basis, yn, W.shape[2] < W.shape[1])
    if options.quality:
        W, owner = generator_columns(P, N, mu, models, c, L)
        W = np.ascontiguousarray(W)
        closed = out["force"][0]
        for norm in ("L1", "Linf"):
            eps = np.zeros(len(rows))
            if closed.any():
                eps[closed] = planar_epsilon(np.ascontiguousarray(W[closed]), owner, m,
                                             norm == "Linf")[0]
            out[norm] = eps
    return settled, out


def _group_table(cols: GraspColumns, rows: np.ndarray, lines: np.ndarray, out, options) -> pa.Table:
    closure, t, lam, basis, yn, null = out["force"]
    fclosure, ft, flam, fbasis, fyn, fnull = out["form"]
    n = len(rows)
    status = np.where(closure, "closure", "no_closure").astype(object)
    form_status = np.where(fclosure, "closure", "no_closure").astype(object)
    cert = pa.StructArray.from_arrays(
        [_certificates(closure, lam, basis, yn, null), _certificates(fclosure, flam, fbasis, fyn, fnull)],
        fields=list(RESULT_SCHEMA.field("certificate").type))
    eps = {}
    for norm, key in (("L1", "l1"), ("Linf", "linf")):
        values = out.get(norm) if options.quality else None
        arr = pa.array(values) if values is not None else pa.nulls(n, pa.float64())
        eps[f"eps_{key}_lo"] = eps[f"eps_{key}_hi"] = arr
    ids = [cols.ids[r] for r in rows]
    return pa.table({
        "id": pa.array(ids, type=pa.string()),
        "line": pa.array(lines, type=pa.int64()),
        "dim": pa.array(np.full(n, 2, dtype=np.int8)),
        "status": pa.array(status, type=pa.string()),
        "form_closure": pa.array(fclosure),
        "force_closure": pa.array(closure),
        "margin": pa.array(np.where(closure, t, 0.0)),
        "form_status": pa.array(form_status, type=pa.string()),
        "form_margin": pa.array(np.where(fclosure, ft, 0.0)),
        "certificate": cert,
        "verified": pa.array(np.ones(n, dtype=bool)),
        "error": pa.nulls(n, pa.string()),
        "center": _list_array(cols.center[rows, :2], np.ones(n, bool), RESULT_SCHEMA.field("center").type),
        "length": pa.array(cols.length[rows]),
        "n_contacts": pa.array(cols.count[rows].astype(np.int32)),
        **eps,
    }, schema=RESULT_SCHEMA)


def certify_table(table: pa.Table, lines, options, tol: Tolerances = Tolerances(),
                  slow=None) -> pa.Table:
    """Results table of a grasp table (rows in input order).

    ``slow(row_indices) -> list of results rows`` certifies rows grasp by grasp (the per-grasp
    path of :func:`certify.batch.certify_values`); it receives every row that the columnar rules
    do not settle.
    """
    cols = grasp_columns(table)
    lines = np.asarray(lines, dtype=np.int64)
    n = len(lines)
    done = np.zeros(n, dtype=bool)
    pieces, order = [], []
    planar = cols.ok & (cols.dim == 2) & ((cols.model <= POINT)).all(axis=1) & (cols.count >= 1)
    if options.method == "fast" and planar.any():
        m = cols.model.shape[1]
        key = cols.count * 3 ** m + (np.where(cols.model < 0, 0, cols.model) * 3 ** np.arange(m)).sum(1)
        for k in np.unique(key[planar]):
            rows = np.flatnonzero(planar & (key == k))
            settled, out = _planar_group(cols, rows, options, tol)
            if settled.any():
                sub = {name: _take(value, settled) for name, value in out.items()}
                pieces.append(_group_table(cols, rows[settled], lines[rows[settled]], sub, options))
                order.append(rows[settled])
                done[rows[settled]] = True
    rest = np.flatnonzero(~done)
    if len(rest):
        from .table import rows_to_table

        pieces.append(rows_to_table(slow(rest)))
        order.append(rest)
    result = pa.concat_tables(pieces) if pieces else RESULT_SCHEMA.empty_table()
    return result.take(pa.array(np.argsort(np.concatenate(order), kind="stable")))


def _take(value, mask):
    if isinstance(value, tuple):
        return tuple(v[mask] if isinstance(v, np.ndarray) else v for v in value)
    return value[mask]
