"""Columnar re-check of a results table against its grasps: the independent checker at scale.

:func:`recheck_table` re-checks every row of a results table
(:data:`qualgrasp.certify.files.results.RESULT_SCHEMA`) against the checked grasp columns it came from.
The common certificates are proved in bulk with the rigorous floating-point kernels of
:mod:`qualgrasp.certify._kernels.recheck` (error bounds instead of rationals):
planar generator certificates (interior, strict Farkas, null space) and spatial ones (interior
forces, strict Farkas, null-space form certificates). Each row's other claims are checked as
:func:`qualgrasp.certify.report.verify_row` checks them: ``verified`` true and ``error`` null,
``dim``, ``n_contacts``, ``center`` and ``length`` against the grasp, status against certificate
kind and closure flags, both margins equal to the certified ones (two-sided), and the epsilon
columns (0 and no evidence without closure; with closure, the evidence re-checked by
:func:`qualgrasp.certify.quality.evidence.verify_bounds`, rigorous float bounds first). A table whose
schema is not the results schema is not proved in bulk at all. Every row not proved in bulk goes
through :func:`qualgrasp.certify.report.verify_row`, which uses exact rational arithmetic and gives
the message; a row fails only if that fails. No solver is involved anywhere.
"""

from __future__ import annotations

import json

import numpy as np
import pyarrow as pa

from .. import models as registry
from .._kernels.jit import kernel_array
from .._kernels.planar import planar_generators
from .._kernels.recheck import null_rows, verify_farkas_general, verify_interior_general
from ..core.certificates import Tolerances, margin_proved
from ..files.columns import GraspColumns
from ..quality.evidence import EPS_COLUMNS, Evidence, verify_bounds
from ..core.problem import conic_block_arrays, ray_block_arrays
from ..report import GEOMETRY_TOL
from ..files.results import RESULT_SCHEMA
from ..core.wrench import force_column_errors, force_columns, generator_columns, generator_layout

__all__ = ["recheck_table", "generator_errors", "schema_matches"]


def schema_matches(schema: pa.Schema) -> bool:
    """Does a results table have every column of the results schema with its type (extra
    columns allowed)? Only such tables are proved in bulk."""
    for field in RESULT_SCHEMA:
        i = schema.get_field_index(field.name)
        if i < 0 or not schema.field(i).type.equals(field.type):
            return False
    return True

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
    models, variants = cols.models_of(rows[0]), cols.variants_of(rows[0])
    if not all(registry.get(name).exact_in_floats for name in models):
        return np.zeros(len(rows), dtype=bool)  # float cone weights are not the exact ones: verify_row
    P, N, params = cols.contacts(rows)
    P, N = kernel_array(P[:, :, :dim]), kernel_array(N[:, :, :dim])
    mu = params["mu"]
    c, L = kernel_array(cols.center[rows, :dim]), kernel_array(cols.length[rows])
    cert = res.column("certificate").combine_chunks()
    status = np.asarray(res.column("status").to_numpy(zero_copy_only=False), dtype=object)[rows]
    form_status = np.asarray(res.column("form_status").to_numpy(zero_copy_only=False), dtype=object)[rows]
    margin = np.nan_to_num(res.column("margin").to_numpy(zero_copy_only=False).astype(float))[rows]
    form_margin = np.nan_to_num(res.column("form_margin").to_numpy(zero_copy_only=False).astype(float))[rows]
    force_flag = res.column("force_closure").to_pylist()
    form_flag = res.column("form_closure").to_pylist()
    proved = np.ones(len(rows), dtype=bool)
    polyhedral = dim == 2 or all(registry.get(name).is_frictionless for name in models)
    planar_W = None
    for key, fl, st, mg, flags in (("force", False, status, margin, [force_flag[r] for r in rows]),
                                   ("form", True, form_status, form_margin, [form_flag[r] for r in rows])):
        struct = cert.field(key)
        if polyhedral or fl:
            C, E = generator_errors(P, N, params, models, variants, c, L, frictionless=fl)
            k = C.shape[2]
            cone, first, width = ray_block_arrays(k)
            nb = np.zeros((len(rows), k, dim))
            mub = np.zeros((len(rows), k))
            gb = np.zeros((len(rows), k))
            layout = "generators"
            blocks = k
        else:
            C, owner = force_columns(P, N, models, c, L)
            C = np.ascontiguousarray(C)
            k = C.shape[2]
            E = force_column_errors(P, N, models, c, L)
            cone, first, width, nb, mub, gb = conic_block_arrays(models, N, mu, params, dim)
            layout = "forces"
            blocks = m
        d = C.shape[1]
        kind, lay, values, vok, basis, bok, y, yok, tight_len, null = _cert_arrays(struct, rows, k, d)
        ok = _claims_ok(st, mg, flags, kind) & (lay == layout)
        interior = ok & (kind == "interior") & vok & bok
        farkas = ok & (kind == "farkas") & yok & (tight_len == 0) & ~null
        nulls = ok & (kind == "farkas") & yok & null & (tight_len == blocks) & (k < d)
        good = np.zeros(len(rows), dtype=bool)
        none = np.zeros(len(cone), dtype=bool)
        for i in np.flatnonzero(interior):
            if verify_interior_general(C[i], E[i], cone, first, width, nb[i], mub[i], gb[i], values[i],
                                       basis[i], tol.residual) and \
                    margin_proved(mg[i], C[i], E[i], (cone, first, width, nb[i], mub[i], gb[i]), values[i], basis[i]):
                good[i] = True
        for i in np.flatnonzero(farkas):
            good[i] = verify_farkas_general(C[i], E[i], cone, first, width, nb[i], mub[i], gb[i], y[i],
                                            none, 0.0)
        if nulls.any():
            good[nulls] = null_rows(C[nulls], np.ascontiguousarray(E[nulls]),
                                    np.ascontiguousarray(y[nulls])) == 3
        proved &= good
        if key == "force" and dim == 2:
            planar_W = (C, E)
    proved &= _eps_proofs(cols, rows, res, status, planar_W if dim == 2 else None, models, variants)
    return proved


def _eps_proofs(cols: GraspColumns, rows: np.ndarray, res: pa.Table, status: np.ndarray, planar,
                models, variants) -> np.ndarray:
    """Rows (of ``rows``) whose epsilon columns hold: all null (no quality), 0 without evidence
    and not limited when not in closure, or proved by their evidence in closure."""
    vals = np.column_stack([res.column(k).to_numpy(zero_copy_only=False).astype(float)[rows]
                            for k in EPS_COLUMNS])
    limited = res.column("eps_limited").to_pylist()
    evidence = res.column("eps_evidence")
    present = res.column("eps_l1_hi").is_valid().to_numpy(zero_copy_only=False)[rows]
    ok = np.zeros(len(rows), dtype=bool)
    nulls = ~np.isfinite(vals).any(axis=1)
    ev_null = ~evidence.is_valid().to_numpy(zero_copy_only=False)[rows]
    lim = np.array([limited[r] for r in rows], dtype=object)
    none = ~present & nulls & ev_null & np.array([x is None for x in lim])
    ok |= none
    closure = status == "closure"
    zero = present & ~closure & (vals == 0).all(axis=1) & ev_null & np.array([x is False for x in lim])
    ok |= zero
    candidates = np.flatnonzero(present & closure & np.isfinite(vals).all(axis=1) & ~ev_null
                                & np.array([isinstance(x, bool) for x in lim]))
    if len(candidates):
        if planar is not None:
            W, E = planar
            owner = generator_layout(models, variants, 2)[0]
        for j in candidates:
            r = int(rows[j])
            v = dict(zip(EPS_COLUMNS, vals[j]))
            if not ((v["eps_l1_lo"] <= v["eps_l1_hi"]) and (v["eps_linf_lo"] <= v["eps_linf_hi"])
                    and (vals[j] >= 0).all()):
                continue
            ev = evidence[r].as_py()
            try:
                evs = {key: Evidence.from_json(ev.get(key)) for key in ("l1", "linf")}
                grasp = cols.grasps([r])[0]
                arrays = (np.ascontiguousarray(W[j]), np.ascontiguousarray(E[j]), owner) if planar is not None else None
                ok[j] = bool(verify_bounds(grasp, v, evs, arrays))
            except (ValueError, TypeError, IndexError, ZeroDivisionError, OverflowError):
                ok[j] = False
    return ok


def _claims(cols: GraspColumns, results: pa.Table, lines) -> np.ndarray:
    """Rows whose statements other than certificates, margins and epsilon hold, in bulk: a
    valid grasp, status closure or no_closure, ``line`` and ``id``, ``verified`` true, ``error``
    null, ``dim``, ``n_contacts``, ``center`` and ``length`` the grasp's."""
    n = results.num_rows

    def column(name, fill):
        return results.column(name).fill_null(fill).to_numpy(zero_copy_only=False)

    status = np.asarray(column("status", ""), dtype=object)
    line = column("line", -1)
    ids = results.column("id").to_pylist()
    ids_ok = np.array([a == _text(cols.id_of(i)) for i, a in enumerate(ids)], dtype=bool)
    fine = cols.ok & np.isin(status, ["closure", "no_closure"]) & ids_ok
    fine &= np.asarray(line) == np.asarray(lines)
    fine &= column("verified", False).astype(bool) & ~results.column("error").is_valid().to_numpy(zero_copy_only=False)
    for name in ("margin", "form_margin"):
        fine &= np.isfinite(column(name, np.nan).astype(float))
    fine &= column("dim", 0) == cols.dim
    fine &= column("n_contacts", -1) == cols.count
    length = column("length", np.nan).astype(float)
    fine &= np.abs(length - cols.length) <= GEOMETRY_TOL * np.maximum(1.0, np.abs(cols.length))
    center = results.column("center")
    lengths = center.combine_chunks().value_lengths().fill_null(0).to_numpy(zero_copy_only=False) if n else np.zeros(0)
    fine &= lengths == cols.dim
    flat = center.combine_chunks().flatten().to_numpy(zero_copy_only=False) if n else np.zeros(0)
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(int)
    for d in (2, 3):
        sel = np.flatnonzero(fine & (lengths == d))
        if len(sel):
            got = flat[offsets[sel][:, None] + np.arange(d)].astype(float)
            want = cols.center[sel, :d]
            close = (np.abs(got - want) <= GEOMETRY_TOL * np.maximum(1.0, np.abs(want))).all(axis=1)
            fine[sel[~close]] = False
    return fine


def _text(gid):
    """An id as the results' string column holds it."""
    if gid is None or isinstance(gid, str):
        return gid
    return str(gid) if isinstance(gid, (int, float)) and not isinstance(gid, bool) else json.dumps(gid)


def generator_errors(P, N, params, models, variants, c, L, *, frictionless: bool = False):
    """Generator columns (B, d, k) of a group of grasps and bounds on their distance to the
    exact values on the same data: the planar kernel's
    (:func:`qualgrasp.certify._kernels.planar.planar_generators`) or, in space, those of
    frictionless force columns (:func:`qualgrasp.certify.core.wrench.force_column_errors`)."""
    B, m, dim = P.shape
    if dim == 2:
        owner, offset, friction = generator_layout(models, variants, 2, frictionless=frictionless)
        k = len(owner)
        W = np.empty((B, 3, k))
        E = np.empty((B, 3, k))
        width = registry.offset_lengths(models, params)
        for i in range(B):
            planar_generators(P[i], N[i], params["mu"][i], width[i], c[i], L[i], owner,
                              offset, friction, W[i], E[i])
        return W, E
    W, _ = generator_columns(P, N, params["mu"], models, c, L, frictionless=True, variants=(0,) * m)
    return np.ascontiguousarray(W), force_column_errors(P, N, registry.frictionless_names(models), c, L)


def recheck_table(cols: GraspColumns, results: pa.Table, lines, slow, tol: Tolerances = Tolerances()):
    """Re-check ``results`` against the checked grasp columns ``cols`` (same rows, same order).

    ``slow(index) -> bool`` re-checks one row exactly; it receives every row not proved in
    bulk. Returns the boolean array of rows that passed.
    """
    n = results.num_rows
    passed = np.zeros(n, dtype=bool)
    if schema_matches(results.schema):
        fine = _claims(cols, results, lines)
    else:
        fine = passed.copy()
    label = cols.pattern()
    for k in np.unique(label[fine]):
        rows = np.flatnonzero(fine & (label == k))
        passed[rows] = _group_proofs(cols, rows, results, tol)
    for i in np.flatnonzero(~passed):
        passed[i] = bool(slow(int(i)))
    return passed
