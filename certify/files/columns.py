"""Grasp sets as columns: Arrow tables and parsed JSON values turned into checked, padded arrays.

:func:`grasp_columns` reads an Arrow grasp table (Parquet, or an in-memory table), and
:func:`value_columns` a list of parsed JSON values, into the same :class:`GraspColumns`: one row
per grasp, contacts kept flat (padded only for the rows of one contact pattern, so one row with
many contacts costs its own size, not the chunk's), every rule of
:mod:`qualgrasp.certify.core.validation` applied once, vectorised, with its messages. The columnar
kernels take the valid rows from the arrays; :meth:`GraspColumns.grasps` builds
:class:`qualgrasp.certify.Grasp` objects of any valid rows for the per-grasp route, and
:meth:`GraspColumns.message` gives the error of an invalid one. Both routes therefore read every
row under the same rules.

Arrow layouts other tools write are read, not rejected: vectors as ``list``, ``large_list`` or
``fixed_size_list`` of any float or integer width; dictionary-encoded or large strings; any
optional field (``model``, ``mu``, ``torsion``, ``width``, ``center``, ``length``, ``id``) absent.
A column of the wrong kind (strings where numbers belong) makes every row that gives a value in
it an error naming the field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc

from .. import models as registry
from ..models import MAX_LENGTH
from ..core.grasp import Grasp, grasps_from_checked
from .reader import READ_ERROR
from ..core.validation import (ABSENT, MAX_CONTACTS, TOP_LEVEL, UNKNOWN, CheckedGrasps, ContactData, GraspData, check_grasps,
                               grasp_data, show)

__all__ = ["GraspColumns", "grasp_columns", "value_columns", "extra_columns", "row_labels"]


@dataclass
class GraspColumns:
    """Checked grasps as columns; contacts flat, in row order.

    Attributes
    ----------
    checked : CheckedGrasps
        The validation's output (errors, stored values, flattened contacts with the rows'
        ``offsets``).
    ok : (n,) bool
        Valid rows.
    dim, count : (n,) int
        Coordinates (2 or 3) and number of contacts.
    center : (n, 3) float
    length : (n,) float
    ids : list or pyarrow.Array
        Grasp ids (str, int or None; an Arrow array for Arrow input, see :meth:`id_of`).
    meta : list of dict or None
        Other top-level fields of each grasp (JSON input).
    """

    checked: CheckedGrasps
    ok: np.ndarray
    dim: np.ndarray
    count: np.ndarray
    center: np.ndarray
    length: np.ndarray
    ids: Any
    meta: list | None = None

    def contacts(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict]:
        """Points ``P`` and stored normals ``N`` (``(B, m, 3)``, the third coordinate 0 for
        planar rows) and model parameters (``(B, m)`` each, 0 where a model does not take one)
        of ``rows``, which must all have ``m`` contacts (one contact pattern)."""
        rows = np.asarray(rows)
        m = int(self.count[rows[0]]) if len(rows) else 0
        if len(rows) and not (self.count[rows] == m).all():
            raise ValueError("contacts(rows) takes rows with the same number of contacts")
        index = (self.checked.offsets[rows][:, None] + np.arange(m)).ravel()
        c = self.checked.contacts
        B = len(rows)
        return (c.p[index].reshape(B, m, 3), c.n[index].reshape(B, m, 3),
                {name: values[index].reshape(B, m) for name, values in c.params.items()})

    def message(self, i: int) -> str | None:
        """The error of row ``i`` (None when valid)."""
        e = self.checked.error[i]
        return None if e is None else str(e)

    def id_of(self, i: int) -> Any:
        """The id of row ``i`` (str, int or None)."""
        value = self.ids[i]
        return value.as_py() if isinstance(value, pa.Scalar) else value

    def id_column(self, rows: np.ndarray) -> pa.Array:
        """The results' ``id`` column (strings) of ``rows``."""
        if isinstance(self.ids, pa.Array):
            ids = self.ids if len(rows) == len(self.ids) else self.ids.take(pa.array(rows))
            return ids.cast(pa.string())
        return pa.array([None if self.ids[i] is None else str(self.ids[i]) for i in rows], pa.string())

    def grasps(self, rows: Sequence[int]) -> list[Grasp]:
        """:class:`Grasp` objects of the valid ``rows``."""
        ids = {int(i): self.id_of(i) for i in rows}
        return grasps_from_checked(self.checked, rows, ids, self.meta)

    def pattern(self) -> np.ndarray:
        """Group label of every valid row: rows with equal labels share dimension, contact count
        and each contact's model and variant (the key of the columnar kernels); -1 for invalid
        rows. Labels count up in the lexicographic order of (dimension, count, key)."""
        n = len(self.ok)
        out = np.full(n, -1)
        c, offsets = self.checked.contacts, self.checked.offsets
        ok = np.flatnonzero(self.ok)
        if not len(ok):
            return out
        count = self.count[ok].astype(np.int64)
        shapes, shape_of = np.unique(self.dim[ok].astype(np.int64) * (int(count.max()) + 1) + count,
                                     return_inverse=True)
        next_label = 0
        for s in range(len(shapes)):
            rows = ok[shape_of.ravel() == s]
            m = int(self.count[rows[0]])
            index = (offsets[rows][:, None] + np.arange(m)).ravel()
            label = row_labels((c.model[index].astype(np.int64) * 8 + c.variant[index]).reshape(len(rows), m))
            out[rows] = next_label + label
            next_label += int(label.max()) + 1
        return out

    def models_of(self, row: int) -> tuple[str, ...]:
        """Model names of the contacts of ``row``."""
        a = self.checked.offsets[row]
        return tuple(registry.get(int(code)).name for code in self.checked.contacts.model[a:a + self.count[row]])

    def variants_of(self, row: int) -> tuple[int, ...]:
        """Model variants of the contacts of ``row``."""
        a = self.checked.offsets[row]
        return tuple(int(v) for v in self.checked.contacts.variant[a:a + self.count[row]])


def row_labels(key: np.ndarray) -> np.ndarray:
    """Labels of the rows of ``key`` ((B, m) integers), numbered in the rows'
    lexicographic order: ``np.unique(key, axis=0, return_inverse=True)[1]``, without its sort of
    rows where every row is the same (the usual grasp set) or the rows pack into one integer."""
    B, m = key.shape
    if not B or not m or (key == key[0]).all():
        return np.zeros(B, dtype=np.int64)
    base = int(key.max()) + 1
    if key.dtype.kind in "iu" and int(key.min()) >= 0 and m * math.log2(base) < 62:
        packed = np.zeros(B, dtype=np.int64)
        small = key.astype(np.int64)  # exact: every value is below 2**62 (uint64 would go to float)
        for j in range(m):  # the first column weighs most: the packed order is the lexicographic one
            packed = packed * base + small[:, j]
        return np.unique(packed, return_inverse=True)[1].ravel()
    return np.unique(key, axis=0, return_inverse=True)[1].ravel()


def _columns(checked: CheckedGrasps, count: np.ndarray, ids: list, meta) -> GraspColumns:
    ok = checked.error == None  # noqa: E711  (elementwise)
    return GraspColumns(checked, ok, checked.dim, np.asarray(count), checked.center, checked.length, ids, meta)


def value_columns(values: Sequence[Any]) -> GraspColumns:
    """Columns of grasps given as parsed JSON values (a value that is an exception, such as a
    line that did not parse, becomes an error row with its message)."""
    failed = {i: v for i, v in enumerate(values) if isinstance(v, Exception)}
    data, contacts = grasp_data([None if i in failed else v for i, v in enumerate(values)])
    for i, err in failed.items():
        data.errors[i] = str(err)
    checked = check_grasps(data, contacts)
    return _columns(checked, data.count, data.ids, data.meta)


# --- Arrow --------------------------------------------------------------------------------------

def _lists(arr: pa.Array):
    """``(offsets from 0 (len + 1,), flattened values, row validity)`` of a list, large list or
    fixed-size list array (possibly sliced); None when ``arr`` is not a list."""
    n = len(arr)
    valid = np.asarray(arr.is_valid(), dtype=bool) if arr.null_count else np.ones(n, bool)
    if pa.types.is_fixed_size_list(arr.type):
        size = arr.type.list_size
        offsets = np.arange(n + 1, dtype=np.int64) * size
        flat = arr.values.slice(arr.offset * size, n * size)
        lengths = np.where(valid, size, 0)
        if not valid.all():  # nulls of a fixed-size list still occupy their slots
            keep = np.repeat(valid, size)
            flat = flat.filter(pa.array(keep))
            offsets = np.concatenate([[0], np.cumsum(lengths)])
        return offsets, flat, valid
    if pa.types.is_list(arr.type) or pa.types.is_large_list(arr.type):
        offsets = np.asarray(arr.offsets, dtype=np.int64)
        if not valid.all():  # flatten() skips a null list's values, which its offsets may still cover
            return np.concatenate([[0], np.cumsum(np.where(valid, np.diff(offsets), 0))]), arr.flatten(), valid
        return offsets - offsets[0], arr.flatten(), valid
    return None


def _floats(arr: pa.Array) -> np.ndarray | None:
    """Float64 values of a numeric Arrow array (NaN where null), None when not numeric."""
    if pa.types.is_dictionary(arr.type):
        arr = arr.dictionary_decode()
    t = arr.type
    if not (pa.types.is_floating(t) or pa.types.is_integer(t) or pa.types.is_decimal(t)
            or pa.types.is_null(t)):
        return None
    if pa.types.is_null(t):
        return np.full(len(arr), np.nan)
    return np.asarray(arr.cast(pa.float64(), safe=False).to_numpy(zero_copy_only=False), dtype=float)


def _vectors(arr: pa.Array, n: int):
    """Rows of a list of numbers as an (n, 3) array (zero-padded) and their lengths (-1 where
    the list is null, 4 for any longer list and for one holding a null: not a vector of numbers,
    as the JSON reader has it); None when ``arr`` is not a list of numbers."""
    lists = _lists(arr)
    if lists is None:
        return None
    offsets, flat, valid = lists
    values = _floats(flat)
    if values is None:
        return None
    lengths = np.diff(offsets)
    out = np.zeros((n, 3))
    if n and valid.all() and (lengths == lengths[0]).all() and 1 <= lengths[0] <= 3:
        out[:, : lengths[0]] = values.reshape(n, lengths[0])  # the common, uniform case
    else:
        good = valid & (lengths >= 1) & (lengths <= 3)
        rows = np.repeat(np.arange(n), lengths)
        cols = np.arange(len(values)) - np.repeat(offsets[:-1], lengths)
        keep = np.repeat(good, lengths)
        out[rows[keep], cols[keep]] = values[keep]
    lengths = np.minimum(lengths, 4)
    if flat.null_count:  # a null inside a list is not a number (its NaN would be reported instead)
        holes = np.repeat(np.arange(n), np.diff(offsets))[~np.asarray(flat.is_valid(), dtype=bool)]
        lengths[holes] = 4
    return out, np.where(valid, lengths, -1)


def _keep_refused(raw: dict, key: str, col, vec: np.ndarray, lengths: np.ndarray) -> None:
    """Record in ``raw`` (by ``(row, key)``) the values as given of the rows of ``col`` holding a
    NaN, an infinity or a number beyond :data:`~qualgrasp.certify.models.MAX_LENGTH` (what the
    value rules refuse, of a normal the first two), so that their messages show them as the JSON
    reader does (integers as integers)."""
    for j in np.flatnonzero((lengths >= 1) & ~(np.abs(vec) <= MAX_LENGTH).all(axis=1)):
        raw[(int(j), key)] = col[int(j)].as_py()


def _strings(arr: pa.Array) -> pa.Array | None:
    """A string array (dictionary-decoded, large strings cast), None when not strings."""
    if pa.types.is_dictionary(arr.type):
        arr = arr.dictionary_decode()
    if pa.types.is_null(arr.type):
        return pa.nulls(len(arr), pa.string())
    if pa.types.is_string(arr.type):
        return arr
    if pa.types.is_large_string(arr.type) or getattr(pa.types, "is_string_view", lambda t: False)(arr.type):
        return arr.cast(pa.string())
    return None


def _type_error(data, rows: np.ndarray, message: str) -> None:
    """Record ``message`` for the ``rows`` of ``data`` without an error yet."""
    for j in np.flatnonzero(rows):
        if data.errors[j] is None:
            data.errors[j] = message


def _arrow_contacts(flat: pa.Array) -> ContactData:
    """Contacts of a flattened ``contacts`` column (struct per contact) as :class:`ContactData`."""
    k = len(flat)
    data = ContactData.empty(k)
    data.errors = np.full(k, None, dtype=object)
    if not pa.types.is_struct(flat.type):
        _type_error(data, np.ones(k, bool), f"expected an object with keys p, n, model, ..., got a "
                                           f"{flat.type} value")
        return data
    fields = {f.name: flat.field(i) for i, f in enumerate(flat.type)}
    row_null = np.asarray(flat.is_null(), dtype=bool) if flat.null_count else np.zeros(k, bool)
    _type_error(data, row_null, "expected an object with keys p, n, model, ..., got null")
    for key in ("p", "n"):
        if key not in fields:
            _type_error(data, ~row_null, f"{key}: missing (no '{key}' field in the contacts)")
            continue
        got = _vectors(fields[key], k)
        if got is None:
            _type_error(data, np.asarray(fields[key].is_valid(), bool),
                        f"{key}: expected 2 (planar) or 3 (spatial) finite numbers, got a "
                        f"{fields[key].type} value")
            continue
        vec, lengths = got
        _keep_refused(data.raw, key, fields[key], vec, lengths)
        if key == "p":
            data.p, data.plen = vec, lengths
        else:
            data.n, data.nlen = vec, lengths
    bad_len = (data.plen == 4) | (data.nlen == 4) | (data.plen == 1) | (data.nlen == 1) | \
        (data.plen == 0) | (data.nlen == 0)
    for j in np.flatnonzero(bad_len):
        key = "p" if data.plen[j] in (0, 1, 4) else "n"
        if data.errors[j] is None:
            data.errors[j] = (f"{key}: expected 2 (planar) or 3 (spatial) finite numbers, got "
                              f"{show((fields[key][j]).as_py())}")
    if "model" in fields:
        names = _strings(fields["model"])
        if names is None:
            _type_error(data, np.asarray(fields["model"].is_valid(), bool),
                        f"model: expected one of {', '.join(map(repr, registry.names()))}, got a "
                        f"{fields['model'].type} value")
        else:
            idx = pc.index_in(names, value_set=pa.array(registry.names()))
            codes = np.asarray(idx.to_numpy(zero_copy_only=False), dtype=float)
            given = np.asarray(names.is_valid(), dtype=bool)
            data.model = np.where(given, np.where(np.isnan(codes), UNKNOWN, codes), ABSENT).astype(np.int64)
            data.names = names
    for name in data.params:
        if name not in fields:
            continue
        values = _floats(fields[name])
        if values is None:
            _type_error(data, np.asarray(fields[name].is_valid(), bool),
                        f"{name}: expected a number, got a {fields[name].type} value")
            continue
        given = np.asarray(fields[name].is_valid(), dtype=bool)
        data.params[name] = np.where(given, values, np.nan)
        data.given[name] = given
    return data


def grasp_columns(table: pa.Table) -> GraspColumns:
    """Checked columns of an Arrow grasp table (any of the layouts in the module docstring)."""
    table = table.combine_chunks()
    n = table.num_rows
    names = table.column_names
    data = GraspData(np.zeros(n, dtype=np.int64), np.zeros((n, 3)), np.full(n, -1), np.full(n, np.nan),
                     np.zeros(n, dtype=bool), [None] * n, np.full(n, None, dtype=object), None)
    ids = [None] * n
    if "id" in names:
        col = table.column("id").combine_chunks()
        if pa.types.is_dictionary(col.type):
            col = col.dictionary_decode()
        if pa.types.is_integer(col.type) or _strings(col) is not None or pa.types.is_null(col.type):
            ids = _strings(col) if _strings(col) is not None else col
        else:
            _type_error(data, np.asarray(col.is_valid(), bool),
                        f"id: expected a string or an integer, got a {col.type} value")
    contacts = None
    if "contacts" not in names:
        _type_error(data, np.ones(n, bool), "contacts: missing (no 'contacts' column)")
    else:
        col = table.column("contacts").combine_chunks()
        lists = _lists(col)
        if lists is None:
            _type_error(data, np.ones(n, bool), f"contacts: expected a list of contacts, got a {col.type} column")
        else:
            offsets, flat, valid = lists
            data.count = np.diff(offsets)
            _type_error(data, ~valid, "contacts: missing (a grasp needs a 'contacts' list)")
            over = data.count > MAX_CONTACTS
            for i in np.flatnonzero(over):
                data.errors[i] = data.errors[i] or (f"contacts: {data.count[i]} contacts, more than the "
                                                    f"limit of {MAX_CONTACTS}")
            if over.any():  # as the JSON reader does: such a row's contacts are not read
                flat = flat.filter(pa.array(np.repeat(~over, data.count)))
                data.count = np.where(over, 0, data.count)
            contacts = _arrow_contacts(flat)
    if contacts is None:
        data.count[:] = 0
        contacts = ContactData.empty(0)
        contacts.errors = np.full(0, None, dtype=object)
    if "center" in names:
        col = table.column("center")
        got = _vectors(col.combine_chunks(), n)
        if got is None:
            _type_error(data, np.asarray(col.is_valid(), bool),
                        f"center: expected 2 (planar) or 3 (spatial) finite numbers, got a {col.type} value")
        else:
            data.center, data.clen = got
            _keep_refused(data.raw, "center", col, data.center, data.clen)
            for i in np.flatnonzero(np.isin(data.clen, (0, 1, 4))):  # worded as the JSON reader words it
                data.errors[i] = data.errors[i] or (f"center: expected 2 or 3 finite numbers, got "
                                                    f"{show(col[i].as_py())}")
    if "length" in names:
        col = table.column("length").combine_chunks()
        values = _floats(col)
        if values is None:
            _type_error(data, np.asarray(col.is_valid(), bool), f"length: expected a number, got a {col.type} value")
        else:
            data.length_given = np.asarray(col.is_valid(), dtype=bool)
            data.length = np.where(data.length_given, values, np.nan)
    if READ_ERROR in names:
        unreadable = table.column(READ_ERROR).combine_chunks()
        for i in np.flatnonzero(np.asarray(unreadable.is_valid(), dtype=bool)):
            data.errors[i] = unreadable[i].as_py()
    checked = check_grasps(data, contacts)
    return _columns(checked, data.count, ids, None)


def extra_columns(table: pa.Table) -> list[str]:
    """Names of a grasp table's own extra top-level columns (not ``id``, ``contacts``, ``center``,
    ``length``): a user's data, carried through to the results."""
    return [name for name in table.column_names if name not in TOP_LEVEL and name != READ_ERROR]
