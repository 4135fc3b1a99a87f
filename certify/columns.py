"""Grasp sets as columns: Arrow grasp tables turned into padded numpy arrays, validated in bulk.

:func:`grasp_columns` reads a grasp table (:data:`certify.table.GRASP_SCHEMA`) into
:class:`GraspColumns`: one row per grasp, contacts padded to the largest count. Rows that
:func:`certify.grasp.grasp_from_dict` would accept, under exactly the same rules (normal
normalisation, model defaults, ``mu = 0`` meaning frictionless, default ``center`` and
``length``), are marked ``ok`` and carry the values it would store; every other row is left to
the per-grasp path, which produces the error message.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pyarrow as pa

__all__ = ["FRICTIONLESS", "POINT", "SOFT", "GraspColumns", "grasp_columns"]

FRICTIONLESS, POINT, SOFT = 0, 1, 2
_CODES = {"frictionless": FRICTIONLESS, "point": POINT, "soft": SOFT}


@dataclass
class GraspColumns:
    """Padded arrays of a grasp table (``m`` = the most contacts of a row).

    Attributes
    ----------
    ok : (n,) bool
        Rows valid for the columnar path (the rest go through :mod:`certify.grasp`).
    dim, count : (n,) int
        Coordinates (2 or 3) and number of contacts.
    P, N : (n, m, 3) float
        Points and stored normals (unit, as :class:`certify.grasp.Contact` stores them); the
        third coordinate is 0 for planar rows; padding is 0.
    mu, torsion : (n, m) float
    model : (n, m) int
        Effective model codes (``mu = 0`` is frictionless), -1 for padding.
    center : (n, 3) float
    length : (n,) float
    ids : list
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
    ids: list


def _list_values(arr: pa.Array):
    """(offsets from 0, flattened values, row validity) of a possibly sliced list array."""
    offsets = np.asarray(arr.offsets, dtype=np.int64)
    offsets = offsets - offsets[0]
    valid = ~np.asarray(arr.is_null(), dtype=bool)
    return offsets, arr.flatten(), valid


def _fixed(arr: pa.Array, n: int, width: int = 3):
    """Rows of a list<double> array as an (n, 3) array with the lengths; NaN where null."""
    offsets, flat, valid = _list_values(arr)
    lengths = np.diff(offsets)
    values = flat.to_numpy(zero_copy_only=False).astype(float)
    out = np.zeros((n, width))
    good = valid & (lengths >= 1) & (lengths <= width)
    rows = np.repeat(np.arange(n), lengths)
    cols = np.arange(len(values)) - np.repeat(offsets[:-1], lengths)
    keep = np.repeat(good, lengths)
    out[rows[keep], cols[keep]] = values[keep]
    return out, np.where(valid, lengths, -1)


def grasp_columns(table: pa.Table) -> GraspColumns:
    """Columns of a grasp table, with the rows the columnar path may take marked ``ok``."""
    n = table.num_rows
    table = table.combine_chunks()
    contacts = table.column("contacts").chunk(0) if table.num_rows else None
    ids = table.column("id").to_pylist() if "id" in table.column_names else [None] * n
    if n == 0:
        e = np.zeros(0)
        return GraspColumns(np.zeros(0, bool), e.astype(int), e.astype(int), np.zeros((0, 0, 3)),
                            np.zeros((0, 0, 3)), np.zeros((0, 0)), np.zeros((0, 0)),
                            np.zeros((0, 0), int), np.zeros((0, 3)), e, [])
    offsets, flat, valid_row = _list_values(contacts)
    count = np.diff(offsets)
    total = int(offsets[-1])
    fields = {name: flat.field(i) if hasattr(flat, "field") else None
              for i, name in enumerate(["p", "n", "model", "mu", "torsion"])}
    child = dict(zip([f.name for f in flat.type], flat.flatten()))
    p, plen = _fixed(child["p"], total)
    nn, nlen = _fixed(child["n"], total)
    model_raw = child["model"].to_numpy(zero_copy_only=False)
    mu_raw = child["mu"].to_numpy(zero_copy_only=False).astype(float)
    tor_raw = child["torsion"].to_numpy(zero_copy_only=False).astype(float)
    del fields

    # per-contact validity, mirroring certify.grasp.Contact
    dimc = plen
    good = (plen >= 2) & (plen <= 3) & (nlen == plen) & np.isfinite(p).all(1) & np.isfinite(nn).all(1)
    norm = np.sqrt((nn * nn).sum(1))
    good &= norm >= 1e-9
    has_mu = ~np.isnan(mu_raw) | np.array([m is None for m in model_raw]) & False
    mu_given = ~np.isnan(mu_raw)
    codes = np.full(total, -1)
    for name, code in _CODES.items():
        codes[model_raw == name] = code
    missing = np.array([m is None for m in model_raw], dtype=bool)
    codes[missing] = np.where(mu_given[missing], POINT, FRICTIONLESS)
    good &= codes >= 0
    mu = np.where(mu_given, mu_raw, 0.0)
    good &= np.isfinite(mu) & (mu >= 0)
    good &= ~((codes == FRICTIONLESS) & (mu != 0))
    tor_given = ~np.isnan(tor_raw)
    good &= ~((codes != SOFT) & tor_given)
    good &= ~((codes == SOFT) & ((dimc != 3) | ~tor_given | ~(tor_raw > 0) | ~np.isfinite(tor_raw)))
    codes = np.where(mu == 0, FRICTIONLESS, codes)
    torsion = np.where(codes == SOFT, np.nan_to_num(tor_raw), 0.0)
    del has_mu
    # stored normals: unit normals are kept as given, others normalised
    unit = np.abs(norm - 1.0) <= 1e-12
    nstored = np.where(unit[:, None], nn, nn / np.where(norm > 0, norm, 1.0)[:, None])

    # per row
    row = np.repeat(np.arange(n), count)
    ok = valid_row & (count >= 1)
    bad_rows = np.unique(row[~good])
    ok[bad_rows] = False
    dim = np.zeros(n, dtype=int)
    first = offsets[:-1][count > 0]
    dim[count > 0] = dimc[first]
    mixed = np.unique(row[dimc != dim[row]])
    ok[mixed] = False

    m = int(count.max()) if n else 0
    slot = np.arange(total) - np.repeat(offsets[:-1], count)
    P = np.zeros((n, m, 3))
    N = np.zeros((n, m, 3))
    MU = np.zeros((n, m))
    TOR = np.zeros((n, m))
    MODEL = np.full((n, m), -1)
    P[row, slot] = p
    N[row, slot] = nstored
    MU[row, slot] = mu
    TOR[row, slot] = torsion
    MODEL[row, slot] = codes

    center, clen = _fixed(table.column("center").chunk(0), n) if "center" in table.column_names \
        else (np.zeros((n, 3)), np.full(n, -1))
    center_given = clen >= 0
    ok &= ~center_given | ((clen == dim) & np.isfinite(center).all(1))
    with np.errstate(invalid="ignore", divide="ignore"):
        centroid = P.sum(1) / np.maximum(count, 1)[:, None]
    center = np.where(center_given[:, None], center, centroid)
    length = table.column("length").to_numpy(zero_copy_only=False).astype(float) \
        if "length" in table.column_names else np.full(n, np.nan)
    length_given = ~np.isnan(length)
    ok &= ~length_given | (np.isfinite(length) & (length > 0))
    reach = np.sqrt(((P - center[:, None, :]) ** 2).sum(2))
    reach = np.where(MODEL >= 0, reach, 0.0).max(1)
    length = np.where(length_given, length, np.where(reach > 0, reach, 1.0))
    return GraspColumns(ok, dim, count, P, N, MU, TOR, MODEL, center, length, ids)
