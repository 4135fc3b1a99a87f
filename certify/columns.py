"""Grasp sets as columns: Arrow grasp tables turned into padded numpy arrays, validated in bulk.

:func:`grasp_columns` reads a grasp table (:data:`qualgrasp.certify.table.GRASP_SCHEMA`) into
:class:`GraspColumns`: one row per grasp, contacts padded to the largest count. Rows that
:func:`qualgrasp.certify.grasp.grasp_from_dict` would accept, under exactly the same rules (normal
normalisation, model defaults, ``mu = 0`` meaning frictionless, default ``center`` and
``length``), are marked ``ok`` and carry the values it would store; every other row is left to
the per-grasp path, which produces the error message.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

__all__ = ["FRICTIONLESS", "POINT", "SOFT", "GraspColumns", "grasp_columns"]

FRICTIONLESS, POINT, SOFT = 0, 1, 2
_NAMES = pa.array(["frictionless", "point", "soft"])


@dataclass
class GraspColumns:
    """Padded arrays of a grasp table (``m`` = the most contacts of a row).

    Attributes
    ----------
    ok : (n,) bool
        Rows valid for the columnar path (the rest go through :mod:`qualgrasp.certify.grasp`).
    dim, count : (n,) int
        Coordinates (2 or 3) and number of contacts.
    P, N : (n, m, 3) float
        Points and stored normals (unit, as :class:`qualgrasp.certify.grasp.Contact` stores them); the
        third coordinate is 0 for planar rows; padding is 0.
    mu, torsion : (n, m) float
    model : (n, m) int
        Effective model codes (``mu = 0`` is frictionless), -1 for padding.
    center : (n, 3) float
    length : (n,) float
    ids : pyarrow array
    """

    ok: np.ndarray
    dim: np.ndarray
    count: np.ndarray
    P: np.ndarray
    N: np.ndarray
    mu: np.ndarray
    torsion: np.ndarray
    model: np.ndarray
    center: np.ndarray
    length: np.ndarray
    ids: pa.Array


def _lists(arr: pa.Array):
    """(offsets from 0, flattened values, row validity) of a possibly sliced list array."""
    offsets = np.asarray(arr.offsets, dtype=np.int64)
    offsets = offsets - offsets[0]
    valid = np.asarray(arr.is_valid(), dtype=bool) if arr.null_count else np.ones(len(arr), bool)
    return offsets, arr.flatten(), valid


def _floats(arr: pa.Array) -> np.ndarray:
    """Float values of an Arrow array, NaN where null."""
    return np.asarray(arr.to_numpy(zero_copy_only=False), dtype=float)


def _vectors(arr: pa.Array, n: int):
    """Rows of a list<double> array as an (n, 3) array (zero-padded) and their lengths (-1 where
    the list is null)."""
    offsets, flat, valid = _lists(arr)
    lengths = np.diff(offsets)
    values = _floats(flat)
    out = np.zeros((n, 3))
    if n and valid.all() and (lengths == lengths[0]).all() and 1 <= lengths[0] <= 3:
        out[:, : lengths[0]] = values.reshape(n, lengths[0])  # the common, uniform case
    else:
        good = valid & (lengths >= 1) & (lengths <= 3)
        rows = np.repeat(np.arange(n), lengths)
        cols = np.arange(len(values)) - np.repeat(offsets[:-1], lengths)
        keep = np.repeat(good, lengths)
        out[rows[keep], cols[keep]] = values[keep]
    return out, np.where(valid, lengths, -1)


def _contact_codes(model: pa.Array, mu_given: np.ndarray) -> np.ndarray:
    """Model codes as :func:`qualgrasp.certify.grasp.grasp_from_dict` reads them: a missing model is
    ``point`` when ``mu`` is given and ``frictionless`` otherwise; -1 for an unknown name."""
    idx = pc.index_in(model, value_set=_NAMES)
    codes = np.asarray(idx.to_numpy(zero_copy_only=False), dtype=float)
    missing = np.asarray(model.is_null(), dtype=bool)
    codes = np.where(np.isnan(codes), -1, codes).astype(np.int64)
    return np.where(missing, np.where(mu_given, POINT, FRICTIONLESS), codes)


def grasp_columns(table: pa.Table) -> GraspColumns:
    """Columns of a grasp table, with the rows the columnar path may take marked ``ok``."""
    table = table.combine_chunks()
    n = table.num_rows
    ids = table.column("id").combine_chunks() if "id" in table.column_names else pa.nulls(n, pa.string())
    contacts = table.column("contacts").combine_chunks()
    offsets, flat, valid_row = _lists(contacts)
    count = np.diff(offsets)
    total = int(offsets[-1]) if n else 0
    child = dict(zip([f.name for f in flat.type], flat.flatten()))
    p, plen = _vectors(child["p"], total)
    nn, nlen = _vectors(child["n"], total)
    mu_raw = _floats(child["mu"])
    tor_raw = _floats(child["torsion"])
    mu_given = ~np.isnan(mu_raw)
    codes = _contact_codes(child["model"], mu_given)

    # per-contact validity, mirroring certify.grasp.Contact
    good = (plen >= 2) & (plen <= 3) & (nlen == plen)
    good &= np.isfinite(p).all(1) & np.isfinite(nn).all(1)
    norm = np.sqrt((nn * nn).sum(1))
    good &= norm >= 1e-9
    good &= codes >= 0
    mu = np.where(mu_given, mu_raw, 0.0)
    good &= np.isfinite(mu) & (mu >= 0)
    good &= ~((codes == FRICTIONLESS) & (mu != 0))
    tor_given = ~np.isnan(tor_raw)
    good &= ~((codes != SOFT) & tor_given)
    good &= ~((codes == SOFT) & ((plen != 3) | ~tor_given | ~(tor_raw > 0) | ~np.isfinite(tor_raw)))
    codes = np.where(mu == 0, FRICTIONLESS, codes)
    torsion = np.where(codes == SOFT, np.nan_to_num(tor_raw), 0.0)
    unit = np.abs(norm - 1.0) <= 1e-12  # unit normals are kept as given, others normalised
    with np.errstate(invalid="ignore", divide="ignore"):
        nstored = np.where(unit[:, None], nn, nn / norm[:, None])

    row = np.repeat(np.arange(n), count)
    ok = valid_row & (count >= 1)
    ok[row[~good]] = False
    dim = np.zeros(n, dtype=np.int64)
    has = count > 0
    dim[has] = plen[offsets[:-1][has]]
    ok[row[plen != dim[row]]] = False

    m = int(count.max()) if n else 0
    P = np.zeros((n, m, 3))
    N = np.zeros((n, m, 3))
    MU = np.zeros((n, m))
    TOR = np.zeros((n, m))
    MODEL = np.full((n, m), -1, dtype=np.int64)
    if n and (count == m).all():
        P[:], N[:] = p.reshape(n, m, 3), nstored.reshape(n, m, 3)
        MU[:], TOR[:], MODEL[:] = mu.reshape(n, m), torsion.reshape(n, m), codes.reshape(n, m)
    else:
        slot = np.arange(total) - np.repeat(offsets[:-1], count)
        P[row, slot], N[row, slot] = p, nstored
        MU[row, slot], TOR[row, slot], MODEL[row, slot] = mu, torsion, codes

    if "center" in table.column_names:
        center, clen = _vectors(table.column("center").combine_chunks(), n)
    else:
        center, clen = np.zeros((n, 3)), np.full(n, -1)
    center_given = clen >= 0
    ok &= ~center_given | ((clen == dim) & np.isfinite(center).all(1))
    if not center_given.all():
        # default centre: mean of the points, as Grasp computes it (sum in contact order / count)
        centroid = P.sum(1) / np.maximum(count, 1)[:, None]
        center = np.where(center_given[:, None], center, centroid)
    length = _floats(table.column("length")) if "length" in table.column_names else np.full(n, np.nan)
    length_given = ~np.isnan(length)
    ok &= ~length_given | (np.isfinite(length) & (length > 0))
    if not length_given.all():
        # default length: the largest distance from the centre to a contact
        reach = np.sqrt(((P - center[:, None, :]) ** 2).sum(2))
        reach = np.where(MODEL >= 0, reach, 0.0).max(1) if m else np.zeros(n)
        length = np.where(length_given, length, np.where(reach > 0, reach, 1.0))
    return GraspColumns(ok, dim, count, P, N, MU, TOR, MODEL, center, length, ids)
