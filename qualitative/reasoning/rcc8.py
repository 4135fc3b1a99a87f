"""RCC-8: the eight base relations between regions, their algebra and constraint networks.

Regions are regular closed sets in the plane; here, shapely polygons and multipolygons (pixel
coordinates, or any unit: only ``tol`` carries one). The eight base relations are jointly
exhaustive and pairwise disjoint:

====== ================================================
name   meaning of ``r(a, b)``
====== ================================================
DC     a and b are disconnected (no common point)
EC     externally connected (boundaries meet, interiors do not)
PO     partial overlap (interiors meet, neither is part of the other)
EQ     equal
TPP    a is a tangential proper part of b (touches b's boundary)
TPPi   b is a tangential proper part of a
NTPP   a is a non-tangential proper part of b (inside b's interior)
NTPPi  b is a non-tangential proper part of a
====== ================================================

Sets of base relations (disjunctions: "one of these holds") are ``frozenset`` of names. A
*network* maps ordered pairs of region names ``(x, y)`` to the set of relations allowed between
x and y; see :func:`path_consistency`. The composition table is the standard one of Randell, Cui
and Cohn (1992); its machine-readable public copies (GQR's ``rcc8.comp``, qualreas'
``rcc8TransTable.csv``) agree with it entry for entry.

Internally a set of relations is an 8-bit mask (bit ``i`` for ``RELATIONS[i]``) so that the
composition of two sets is one lookup in a 256 x 256 table and path consistency works on whole
rows of a uint8 matrix at once.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable, Mapping

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

from ..errors import NetworkError, RegionError

__all__ = [
    "RELATIONS",
    "relation",
    "converse",
    "compose",
    "relations_among",
    "path_consistency",
    "consistent_scenario",
    "consistent",
]

#: The eight base relations, in the order of the bits of the internal masks.
RELATIONS = ("DC", "EC", "PO", "EQ", "TPP", "TPPi", "NTPP", "NTPPi")

_INDEX = {name: i for i, name in enumerate(RELATIONS)}

_CONVERSE = {"DC": "DC", "EC": "EC", "PO": "PO", "EQ": "EQ",
             "TPP": "TPPi", "TPPi": "TPP", "NTPP": "NTPPi", "NTPPi": "NTPP"}

#: DE-9IM patterns (order II IB IE BI BB BE EI EB EE; T = non-empty, F = empty) of the base
#: relations between two polygons (the GeoSPARQL table).
DE9IM_PATTERNS = {
    "TFFFTFFFT": "EQ",
    "FFTFFTTTT": "DC",
    "FFTFTTTTT": "EC",
    "TTTTTTTTT": "PO",
    "TFFTTFTTT": "TPP",
    "TFFTFFTTT": "NTPP",
    "TTTFTTFFT": "TPPi",
    "TTTFFTFFT": "NTPPi",
}

# Randell, Cui & Cohn (1992) composition table: _TABLE[r][s] is the set of t such that
# r(a, b) and s(b, c) allow t(a, c). "*" means all eight relations.
_TABLE = {
    "DC": {"DC": "*", "EC": "DC EC PO TPP NTPP", "PO": "DC EC PO TPP NTPP", "EQ": "DC",
           "TPP": "DC EC PO TPP NTPP", "TPPi": "DC", "NTPP": "DC EC PO TPP NTPP", "NTPPi": "DC"},
    "EC": {"DC": "DC EC PO TPPi NTPPi", "EC": "DC EC PO EQ TPP TPPi", "PO": "DC EC PO TPP NTPP",
           "EQ": "EC", "TPP": "EC PO TPP NTPP", "TPPi": "DC EC", "NTPP": "PO TPP NTPP",
           "NTPPi": "DC"},
    "PO": {"DC": "DC EC PO TPPi NTPPi", "EC": "DC EC PO TPPi NTPPi", "PO": "*", "EQ": "PO",
           "TPP": "PO TPP NTPP", "TPPi": "DC EC PO TPPi NTPPi", "NTPP": "PO TPP NTPP",
           "NTPPi": "DC EC PO TPPi NTPPi"},
    "EQ": {s: s for s in RELATIONS},
    "TPP": {"DC": "DC", "EC": "DC EC", "PO": "DC EC PO TPP NTPP", "EQ": "TPP", "TPP": "TPP NTPP",
            "TPPi": "DC EC PO EQ TPP TPPi", "NTPP": "NTPP", "NTPPi": "DC EC PO TPPi NTPPi"},
    "TPPi": {"DC": "DC EC PO TPPi NTPPi", "EC": "EC PO TPPi NTPPi", "PO": "PO TPPi NTPPi",
             "EQ": "TPPi", "TPP": "PO EQ TPP TPPi", "TPPi": "TPPi NTPPi", "NTPP": "PO TPP NTPP",
             "NTPPi": "NTPPi"},
    "NTPP": {"DC": "DC", "EC": "DC", "PO": "DC EC PO TPP NTPP", "EQ": "NTPP", "TPP": "NTPP",
             "TPPi": "DC EC PO TPP NTPP", "NTPP": "NTPP", "NTPPi": "*"},
    "NTPPi": {"DC": "DC EC PO TPPi NTPPi", "EC": "PO TPPi NTPPi", "PO": "PO TPPi NTPPi",
              "EQ": "NTPPi", "TPP": "PO TPPi NTPPi", "TPPi": "NTPPi",
              "NTPP": "PO EQ TPP TPPi NTPP NTPPi", "NTPPi": "NTPPi"},
}

_ALL = 0xFF
_EQ = 1 << _INDEX["EQ"]


def _names_mask(names: Iterable[str]) -> int:
    return sum(1 << _INDEX[n] for n in set(names))


def _build_tables() -> tuple[np.ndarray, np.ndarray, np.ndarray, tuple[frozenset[str], ...]]:
    """Set-level composition (256 x 256), converse (256), popcount (256), mask -> names."""
    base = np.array([[_ALL if _TABLE[r][s] == "*" else _names_mask(_TABLE[r][s].split())
                      for s in RELATIONS] for r in RELATIONS], dtype=np.uint8)
    member = (np.arange(256)[:, None] >> np.arange(8)[None, :]) & 1 == 1        # mask x base
    # left[m, j] = union over i in m of base[i, j]; then comp[m, n] = union over j in n of left[m, j]
    left = np.bitwise_or.reduce(np.where(member[:, :, None], base[None, :, :], 0), axis=1)
    comp = np.bitwise_or.reduce(np.where(member[None, :, :], left[:, None, :], 0), axis=2)
    conv_bit = np.array([_INDEX[_CONVERSE[r]] for r in RELATIONS])
    conv = np.bitwise_or.reduce(np.where(member, 1 << conv_bit[None, :], 0), axis=1)
    popcount = member.sum(axis=1)
    sets = tuple(frozenset(RELATIONS[i] for i in range(8) if member[m, i]) for m in range(256))
    return comp.astype(np.uint8), conv.astype(np.uint8), popcount, sets


_COMPOSE, _CONV, _POPCOUNT, _SETS = _build_tables()


def _check_name(name: object) -> str:
    if name not in _INDEX:
        hint = next((r for r in RELATIONS if isinstance(name, str) and r.lower() == name.lower()),
                    None)
        extra = f" (did you mean {hint!r}?)" if hint else ""
        raise NetworkError(f"unknown RCC-8 relation {name!r}{extra}; the base relations are "
                           f"{', '.join(RELATIONS)}")
    return name


def _mask(relations: str | Iterable[str]) -> int:
    """Mask of a base relation name or of an iterable of names (validated)."""
    if isinstance(relations, str):
        relations = (relations,)
    try:
        names = list(relations)
    except TypeError:
        raise NetworkError(f"a relation must be a name or an iterable of names, not {relations!r}")
    return _names_mask(_check_name(n) for n in names)


# ----------------------------------------------------------------------------------- algebra

def converse(r: str) -> str:
    """The converse of a base relation: ``r(a, b)`` iff ``converse(r)(b, a)``.

    Swaps TPP/TPPi and NTPP/NTPPi; DC, EC, PO and EQ are symmetric.
    """
    return _CONVERSE[_check_name(r)]


def compose(r: str | Iterable[str], s: str | Iterable[str]) -> frozenset[str]:
    """Weak composition ``r o s``: the relations ``t(a, c)`` allowed by ``r(a, b)`` and ``s(b, c)``.

    Parameters
    ----------
    r, s : str or iterable of str
        A base relation name, or a set of names (read as a disjunction; sets compose
        element-wise: the union over every ``r_i o s_j``).

    Returns
    -------
    frozenset of str
        Empty when ``r`` or ``s`` is the empty set.

    Examples
    --------
    >>> sorted(compose("TPPi", "TPP"))
    ['EQ', 'PO', 'TPP', 'TPPi']
    """
    return _SETS[_COMPOSE[_mask(r), _mask(s)]]


# ---------------------------------------------------------------------------------- geometry

def _check_region(g: object, label: str) -> BaseGeometry:
    if not isinstance(g, BaseGeometry) or g.geom_type not in ("Polygon", "MultiPolygon"):
        kind = g.geom_type if isinstance(g, BaseGeometry) else type(g).__name__
        raise RegionError(f"region {label} must be a shapely Polygon or MultiPolygon, not {kind}")
    if g.is_empty:
        raise RegionError(f"region {label} is empty")
    if not g.is_valid:
        raise RegionError(f"region {label} is not a valid polygon "
                          f"({shapely.is_valid_reason(g)}); repair it, e.g. with shapely.make_valid")
    if not g.area > 0:
        raise RegionError(f"region {label} has zero area")
    return g


def _relation_from_matrix(matrix: str) -> str:
    """The base relation named by a DE-9IM matrix of two regions.

    Reads the matrix cell by cell rather than matching whole patterns: the eight patterns of
    :data:`DE9IM_PATTERNS` are those of connected regions, while a multipolygon can partially
    overlap another with other cells set (e.g. ``212F11212``: one part inside, one outside).
    """
    ii, ib, ie, bi, bb, be, ei, eb, _ = (c != "F" for c in matrix)
    if not ii:
        return "EC" if (ib or bi or bb) else "DC"
    a_in_b = not (ie or be)
    b_in_a = not (ei or eb)
    if a_in_b and b_in_a:
        return "EQ"
    if a_in_b:
        return "TPP" if bb else "NTPP"
    if b_in_a:
        return "TPPi" if bb else "NTPPi"
    return "PO"


def _thin(g: BaseGeometry, tol: float) -> bool:
    """True when ``g`` contains no disc of diameter greater than ``tol`` (erosion is empty)."""
    return g.is_empty or g.buffer(-tol / 2).is_empty


def _relation_tolerant(a: BaseGeometry, b: BaseGeometry, tol: float) -> str:
    """The tolerance rule of :func:`relation` (see there); with ``tol = 0`` it is DE-9IM's."""
    if a.distance(b) > tol:
        return "DC"
    if _thin(a.intersection(b), tol):
        return "EC"
    a_in_b = _thin(a.difference(b), tol)
    b_in_a = _thin(b.difference(a), tol)
    if a_in_b and b_in_a:
        return "EQ"
    if a_in_b:
        return "TPP" if a.distance(b.boundary) <= tol else "NTPP"
    if b_in_a:
        return "TPPi" if b.distance(a.boundary) <= tol else "NTPPi"
    return "PO"


def relation(a: BaseGeometry, b: BaseGeometry, tol: float = 0.0) -> str:
    """The RCC-8 base relation ``r`` with ``r(a, b)``.

    Parameters
    ----------
    a, b : shapely Polygon or MultiPolygon
        Valid, non-empty regions.
    tol : float, optional
        Tolerance, in the units of the coordinates (pixels for vision polygons), >= 0.

    Returns
    -------
    str
        One of :data:`RELATIONS`.

    Notes
    -----
    With ``tol = 0`` the relation is read from the DE-9IM matrix ``a.relate(b)``: for connected
    regions it is the table :data:`DE9IM_PATTERNS`; in general, interiors disjoint gives DC or EC
    (EC when the regions meet), ``a`` is a part of ``b`` when ``a`` meets no exterior point of
    ``b``, a part is tangential when the boundaries meet, and PO otherwise.

    With ``tol > 0`` a set is called *thin* when it contains no disc of diameter greater than
    ``tol`` (its erosion by ``tol / 2`` is empty), and the relation is, in this order:

    1. ``DC`` when the regions are more than ``tol`` apart: boundaries closer than ``tol`` touch;
    2. ``EC`` when their intersection is thin: overlaps thinner than ``tol`` count as touching;
    3. ``a`` is a part of ``b`` when ``a - b`` is thin (what sticks out is a sliver);
       ``EQ`` when each is a part of the other (the symmetric difference is thin);
    4. a part ``a`` of ``b`` is tangential (``TPP``) when ``a`` comes within ``tol`` of the
       boundary of ``b``, else ``NTPP``; likewise ``TPPi`` / ``NTPPi`` with the roles swapped;
    5. ``PO`` otherwise.

    Every test is symmetric in ``a, b`` or has its mirror image, so
    ``relation(b, a, tol) == converse(relation(a, b, tol))``. As ``tol`` tends to 0 each test
    becomes the exact one (distance 0, interiors meet, ``a - b`` has zero area, ``a`` meets the
    boundary of ``b``), i.e. the DE-9IM rule. Perturbing the regions by less than ``tol / 2``
    keeps the exact relation of regions whose features (widths, gaps, overlaps) all exceed
    ``2 tol``. Regions thinner than ``tol`` cannot be resolved: they come out ``DC`` or ``EC``.
    Tolerant relations are not guaranteed to respect the composition table (a chain of
    near-touches is not transitive); use ``tol = 0`` when exact reasoning matters.
    """
    _check_region(a, "a")
    _check_region(b, "b")
    return _relation_checked(a, b, _check_tol(tol))


def _check_tol(tol: float) -> float:
    if not tol >= 0:
        raise RegionError(f"tol must be >= 0, got {tol!r}")
    return float(tol)


def _relation_checked(a: BaseGeometry, b: BaseGeometry, tol: float) -> str:
    if tol == 0:
        return _relation_from_matrix(a.relate(b))
    return _relation_tolerant(a, b, tol)


def relations_among(regions: Mapping[str, BaseGeometry],
                    tol: float = 0.0) -> dict[tuple[str, str], str]:
    """The base relation between every ordered pair of distinct named regions.

    Each unordered pair is computed once with :func:`relation`; the reversed pair gets the
    converse, so the result is always a consistent scenario. The result is a network in the
    format of :func:`path_consistency` (a name counts as a one-element set) and a frame of an ST0
    trace (:mod:`qualgrasp.qualitative.reasoning.st0`).
    """
    names = list(regions)
    for name in names:
        _check_region(regions[name], repr(name))
    tol = _check_tol(tol)
    out = {}
    for i, x in enumerate(names):
        for y in names[i + 1:]:
            r = _relation_checked(regions[x], regions[y], tol)
            out[(x, y)] = r
            out[(y, x)] = _CONVERSE[r]
    return out


# ---------------------------------------------------------------------------------- networks

Network = Mapping[tuple[str, str], str | Iterable[str]]


def _matrix(network: Network) -> tuple[list[str], np.ndarray]:
    """Region names (in order of first appearance) and the n x n matrix of relation masks."""
    if not isinstance(network, Mapping):
        raise NetworkError(f"a network must be a mapping (x, y) -> relations, "
                           f"not {type(network).__name__}")
    names: dict[str, int] = {}
    given = []
    for pair, rels in network.items():
        if not (isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(p, str) for p in pair)):
            raise NetworkError(f"network keys must be pairs of region names (x, y), got {pair!r}")
        for p in pair:
            names.setdefault(p, len(names))
        try:
            given.append((names[pair[0]], names[pair[1]], _mask(rels)))
        except NetworkError as err:
            raise NetworkError(f"pair {pair!r}: {err}") from None
    n = len(names)
    m = np.full((n, n), _ALL, dtype=np.uint8)
    np.fill_diagonal(m, _EQ)
    for i, j, mask in given:
        m[i, j] &= mask
        m[j, i] &= _CONV[mask]
    return list(names), m


def _refine(m: np.ndarray, queue: Iterable[tuple[int, int]] | None = None) -> bool:
    """Path consistency in place (queue-based, O(n^3)); False when some relation becomes empty.

    The matrix is kept closed under converse (``m[j, i] == conv(m[i, j])``), so only unordered
    edges ``i < j`` are queued: revising through ``(j, i)`` is the converse of revising through
    ``(i, j)``. Popping edge ``(i, j)`` revises, for every k at once,
    ``m[i, k] &= m[i, j] o m[j, k]`` and ``m[k, j] &= m[k, i] o m[i, j]``.
    """
    n = len(m)
    if np.any(m == 0):
        return False
    if queue is None:
        queue = ((i, j) for i in range(n) for j in range(i + 1, n))
    queue = deque(queue)
    queued = np.zeros((n, n), dtype=bool)
    for i, j in queue:
        queued[i, j] = True
    while queue:
        i, j = queue.popleft()
        queued[i, j] = False
        rij = m[i, j]
        for row_is_i in (True, False):
            if row_is_i:  # paths i -> j -> k revise (i, k)
                old = m[i].copy()
                new = old & _COMPOSE[rij, m[j]]
            else:         # paths k -> i -> j revise (k, j)
                old = m[:, j].copy()
                new = old & _COMPOSE[m[:, i], rij]
            changed = np.flatnonzero(new != old)
            if changed.size == 0:
                continue
            if np.any(new[changed] == 0):
                return False
            if row_is_i:
                m[i] = new
                m[:, i] = _CONV[new]
            else:
                m[:, j] = new
                m[j] = _CONV[new]
            fixed = i if row_is_i else j
            for k in changed:
                a, b = (fixed, int(k)) if fixed < k else (int(k), fixed)
                if not queued[a, b]:
                    queued[a, b] = True
                    queue.append((a, b))
    return True


def path_consistency(network: Network) -> dict[tuple[str, str], frozenset[str]] | None:
    """Refine an RCC-8 network to path consistency, or detect that it is inconsistent.

    Parameters
    ----------
    network : mapping (x, y) -> relations
        Keys are ordered pairs (tuples) of region names; values are iterables of base relation
        names (a disjunction), or a single name. A pair missing in both directions allows all
        eight relations; a pair given in one direction constrains the other by the converse; a
        pair given in both directions gets the intersection. ``(x, x)`` pairs are allowed and
        must admit EQ.

    Returns
    -------
    dict or None
        Every ordered pair of distinct names mapped to the refined ``frozenset`` of names, where
        each relation survives only if, for every third region, some pair of relations through it
        composes to it (``C_ik <- C_ik & (C_ij o C_jk)`` until nothing changes). ``None`` when a
        relation becomes empty: the network is inconsistent. Path consistency is complete (a
        non-``None`` result means consistent) for networks of base relations and, more
        generally, of relations in the tractable class H8 (Renz & Nebel 1999); in general use
        :func:`consistent_scenario`.

    Raises
    ------
    NetworkError
        For an unknown relation name (the message names it) or a key that is not a pair.
    """
    names, m = _matrix(network)
    if not _refine(m):
        return None
    return _as_dict(names, m, lambda mask: _SETS[mask])


def _as_dict(names, m, convert):
    return {(x, y): convert(int(m[i, j])) for i, x in enumerate(names)
            for j, y in enumerate(names) if i != j}


def consistent_scenario(network: Network) -> dict[tuple[str, str], str] | None:
    """A consistent scenario of the network: one base relation per pair, or None.

    Backtracking (depth first) over the base relations of the pair with the fewest candidates,
    running path consistency after each choice; a path-consistent network of base relations is
    consistent (Renz & Nebel 1999), so a leaf is a scenario realisable by regions. Worst case
    exponential (RCC-8 consistency is NP-complete), fast in practice on small networks.

    Parameters
    ----------
    network : mapping (x, y) -> relations
        As in :func:`path_consistency`.

    Returns
    -------
    dict or None
        Every ordered pair of distinct names mapped to a base relation name, each within the
        given set; ``None`` when the network is inconsistent.
    """
    names, m = _matrix(network)
    if not _refine(m):
        return None
    stack = [(m, None)]  # (network, choice to make first); children are refined when popped
    while stack:
        m, choice = stack.pop()
        if choice is not None:
            i, j, bit = choice
            m = m.copy()
            m[i, j] = 1 << bit
            m[j, i] = _CONV[1 << bit]
            if not _refine(m, [(i, j)]):
                continue
        counts = _POPCOUNT[m]
        if counts.max(initial=1) <= 1:
            return _as_dict(names, m, lambda mask: RELATIONS[mask.bit_length() - 1])
        # branch on the pair with the fewest candidates (first such pair with i < j)
        flat = np.argmin(np.where(np.triu(counts > 1), counts, 9))
        i, j = (int(v) for v in np.unravel_index(flat, m.shape))
        bits = [bit for bit in range(8) if m[i, j] >> bit & 1]
        stack.extend((m, (i, j, bit)) for bit in reversed(bits))  # RELATIONS order first
    return None


def consistent(network: Network) -> bool:
    """Whether the network has a consistent scenario (see :func:`consistent_scenario`)."""
    return consistent_scenario(network) is not None
