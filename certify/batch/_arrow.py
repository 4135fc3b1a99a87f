"""The results tables of the columnar route (:mod:`qualgrasp.certify.batch.fastpath`), built in
Arrow from the verdict arrays of whole groups of grasps: certificate structs, list columns, a
group's results table, and the results of every group and of the per-grasp path put back in
input order with the input's extra columns carried through."""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from ..files.columns import GraspColumns, extra_columns
from ..files.results import CERTIFICATE, RESULT_SCHEMA, carried_name, result_table

__all__ = ["list_array", "evidence_array", "certificates", "group_table", "assemble", "carry"]


# built at first use: pyarrow imports pandas (when installed) for its first array, about 0.15 s
# that a run writing JSON Lines never needs
_STATUS = ("no_closure", "closure", "degenerate")
_KIND = ("farkas", "interior", "degenerate")


def _labels(names: tuple[str, ...], code: np.ndarray) -> pa.Array:
    """The string of ``names`` for each verdict code (:func:`_kind_index`)."""
    return pa.array(names).take(_kind_index(code))


def _kind_index(code: np.ndarray) -> pa.Array:
    """Index into :data:`_STATUS` and :data:`_KIND` of verdict codes (1 closure, 5 degenerate,
    others no closure)."""
    return pa.array(np.select([code == 1, code == 5], [1, 2], 0).astype(np.int8))


def list_array(values: np.ndarray, valid: np.ndarray | None, type_: pa.DataType) -> pa.Array:
    """Arrow list array with ``values.shape[1]`` items per valid row and nulls elsewhere
    (``valid=None``: every row valid)."""
    n, w = values.shape
    if valid is None:
        offsets = np.arange(0, n * w + 1, w, dtype=np.int32)
        return pa.ListArray.from_arrays(pa.array(offsets), pa.array(values.ravel(), type=type_.value_type))
    offsets = np.zeros(n + 1, dtype=np.int32)
    offsets[1:] = np.cumsum(np.where(valid, w, 0))
    flat = values[valid].ravel()
    return pa.ListArray.from_arrays(pa.array(offsets), pa.array(flat, type=type_.value_type),
                                    mask=pa.array(~valid))


def evidence_array(l1, linf, at: np.ndarray, n: int) -> pa.Array:
    """The ``eps_evidence`` column of ``n`` rows from the evidence of each norm
    (:class:`~qualgrasp.certify.quality.evidence.EvidenceColumns`) of the rows ``at``; null
    elsewhere and where a row has no evidence."""
    outer = RESULT_SCHEMA.field("eps_evidence").type
    null = np.ones(n, dtype=bool)
    null[at] = np.array([k is None for k in l1.kind], dtype=bool)
    norms = []
    for cols, field in zip((l1, linf), outer):
        kind = np.full(n, None, dtype=object)
        kind[at] = cols.kind
        direction = np.zeros((n, cols.direction.shape[1]))
        direction[at] = cols.direction
        valid = ~null & ~np.isnan(direction).any(axis=1)
        children = [pa.array(kind, type=pa.string()), list_array(direction, valid, field.type.field("direction").type)]
        for name in ("ref", "points", "faces"):
            lengths = np.zeros(n, dtype=np.int64)
            lengths[at] = np.diff(getattr(cols, name + "_start"))
            offsets = np.zeros(n + 1, dtype=np.int32)
            np.cumsum(lengths, out=offsets[1:])
            value_type = field.type.field(name).type.value_type
            children.append(pa.ListArray.from_arrays(pa.array(offsets), pa.array(getattr(cols, name), type=value_type)))
        norms.append(pa.StructArray.from_arrays(children, fields=list(field.type), mask=pa.array(null)))
    return pa.StructArray.from_arrays(norms, fields=list(outer), mask=pa.array(null))


def certificates(code: np.ndarray, lam: np.ndarray, basis: np.ndarray, y: np.ndarray,
                  layout: str = "generators", blocks: int | None = None,
                  tight: dict | None = None) -> pa.Array:
    """Certificate structs from verdict codes: 1 interior (values, basis), 2 strict Farkas,
    3 Farkas orthogonal to every one of the ``blocks`` cone blocks (null space), 4 Farkas with
    the tight blocks ``tight[row]``, 5 degenerate (reason ``rank``)."""
    n, k = lam.shape
    nb = k if blocks is None else blocks
    interior = code == 1
    degenerate = code == 5
    lengths = np.where(code == 3, nb, 0).astype(np.int32)
    extra = {r: np.asarray(v, dtype=np.int32) for r, v in (tight or {}).items() if code[r] == 4}
    for r, v in extra.items():
        lengths[r] = len(v)
    offsets = np.zeros(n + 1, dtype=np.int32)
    np.cumsum(lengths, out=offsets[1:])
    flat = np.zeros(int(offsets[-1]), dtype=np.int32)
    null_rows = np.flatnonzero(code == 3)
    if len(null_rows):  # every block tight: 0 .. nb-1 at each such row
        flat[(offsets[null_rows][:, None] + np.arange(nb)).ravel()] = np.tile(np.arange(nb), len(null_rows))
    for r, v in extra.items():
        flat[offsets[r]:offsets[r + 1]] = v
    farkas = ~interior & ~degenerate
    tight_arr = pa.ListArray.from_arrays(pa.array(offsets), pa.array(flat, type=pa.int32()),
                                         mask=pa.array(~farkas))
    return pa.StructArray.from_arrays([
        _labels(_KIND, code),
        pa.array([layout]).take(pa.array(np.zeros(n, np.int8))),
        list_array(lam, interior, CERTIFICATE.field("values").type),
        list_array(basis.astype(np.int32), interior, CERTIFICATE.field("basis").type),
        list_array(y, farkas, CERTIFICATE.field("y").type),
        tight_arr,
        pa.array(lengths == nb, mask=~farkas),
        pa.array(np.where(degenerate, "rank", None), type=pa.string()),
    ], fields=list(CERTIFICATE))


def group_table(cols: GraspColumns, rows: np.ndarray, lines: np.ndarray, out, options) -> pa.Table:
    code, t, lam, basis, yn = out["force"]
    fcode, ft, flam, fbasis, fyn = out["form"]
    closure, fclosure = code == 1, fcode == 1
    n = len(rows)
    dim = int(cols.dim[rows[0]])
    force_layout, blocks = out.get("force_layout", ("generators", None))
    cert = pa.StructArray.from_arrays(
        [certificates(code, lam, basis, yn, force_layout, blocks, out.get("tight")),
         certificates(fcode, flam, fbasis, fyn, tight=out.get("form_tight"))],
        fields=list(RESULT_SCHEMA.field("certificate").type))
    eps = {}
    if options.quality:  # spatial groups settle rows not in closure only: 0 there
        l1_lo, l1_hi, linf_lo, linf_hi, limited, evidence = out.get("eps") or (
            np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n, dtype=bool),
            None)
        for key, values in (("eps_l1_lo", l1_lo), ("eps_l1_hi", l1_hi), ("eps_linf_lo", linf_lo),
                            ("eps_linf_hi", linf_hi)):
            eps[key] = pa.array(values, type=pa.float64())
        eps["eps_limited"] = pa.array(limited, type=pa.bool_())
        eps["eps_evidence"] = pa.nulls(n, RESULT_SCHEMA.field("eps_evidence").type) if evidence is None else evidence
    return result_table({
        "id": cols.id_column(rows),
        "line": pa.array(lines, type=pa.int64()),
        "dim": pa.array(np.full(n, dim, dtype=np.int8)),
        "status": _labels(_STATUS, code),
        "form_closure": pa.array(fclosure, mask=fcode == 5),
        "force_closure": pa.array(closure, mask=code == 5),
        "margin": pa.array(np.where(closure, t, 0.0)),
        "form_status": _labels(_STATUS, fcode),
        "form_margin": pa.array(np.where(fclosure, ft, 0.0)),
        "certificate": cert,
        "verified": pa.array(out.get("verified", np.ones(n, dtype=bool))),
        "error": pa.nulls(n, pa.string()),
        "center": list_array(np.ascontiguousarray(cols.center[rows, :dim]), None, pa.list_(pa.float64())),
        "length": pa.array(cols.length[rows]),
        "n_contacts": pa.array(cols.count[rows].astype(np.int32)),
        **eps,
    }, n)


def assemble(pieces: list[pa.Table], order: list[np.ndarray], table: pa.Table) -> pa.Table:
    """The results tables ``pieces`` (the rows ``order[i]`` of the input each) as one table in input
    order, with the input ``table``'s extra columns carried through."""
    if not pieces:
        return carry(RESULT_SCHEMA.empty_table(), table)
    result = pa.concat_tables(pieces)
    order = np.concatenate(order)
    perm = np.argsort(order, kind="stable")
    starts = np.concatenate([[0], np.flatnonzero(np.diff(perm) != 1) + 1])
    if len(starts) > 64:
        return carry(result.take(pa.array(perm)), table)
    # few runs (one group and a few rows left to the per-grasp path): zero-copy slices
    ends = np.append(starts[1:], len(perm))
    return carry(pa.concat_tables([result.slice(perm[a], b - a) for a, b in zip(starts, ends)]), table)


def carry(result: pa.Table, table: pa.Table) -> pa.Table:
    """``result`` with the input table's extra columns appended (:func:`carried_name`)."""
    for name in extra_columns(table):
        result = result.append_column(carried_name(name), table.column(name))
    return result
