"""Wrenches, friction-cone edges and contact frames: the one place where they are computed.

Wrench of a force ``f`` applied at ``p`` about the reference point ``c``, with characteristic
length ``L``: planar ``w = (f_x, f_y, ((p - c) x f) / L)``, spatial ``w = (f, ((p - c) x f) / L)``.

The functions work on float arrays and equally on object arrays of :class:`fractions.Fraction`
(see :func:`to_exact`): every operation is a sum, product or quotient, so the certificate checker
evaluates the very same formulas in exact rational arithmetic.
"""

from __future__ import annotations

from fractions import Fraction
from typing import Sequence

import numpy as np

from . import exact as ex
from .. import models as registry
from ..errors import ArgumentError
from .._kernels.linalg import ETA
from .._kernels.planar import planar_generators
from .grasp import Grasp
from .validation import param_names

__all__ = [
    "to_exact",
    "tangent",
    "cross",
    "torque",
    "wrench",
    "contact_frame",
    "generator_layout",
    "generator_columns",
    "force_columns",
    "grasp_arrays",
    "variants_of",
    "force_column_errors",
    "planar_generator_arrays",
    "planar_generator_rank",
    "planar_pair_normal",
]


def to_exact(a) -> np.ndarray:
    """Object array of :class:`~fractions.Fraction` holding the exact values of the floats in ``a``."""
    a = np.asarray(a, dtype=float)
    return np.array([Fraction(v) for v in a.ravel()], dtype=object).reshape(a.shape)


def tangent(n: np.ndarray) -> np.ndarray:
    """Planar unit tangent ``t = (-n_y, n_x)``: ``n`` turned a quarter turn counter-clockwise."""
    return np.stack([-n[..., 1], n[..., 0]], axis=-1)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross product of rows: the scalar ``a_x b_y - a_y b_x`` per row in the plane, the 3-vector
    ``a x b`` per row in space (the one product the torques, face normals and twist axes use)."""
    if a.shape[-1] == 2:
        return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return np.stack(
        [
            a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
            a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
            a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0],
        ],
        axis=-1,
    )


def torque(r: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Moment ``r x f`` of force(s) ``f`` at lever(s) ``r``: a scalar per row in the plane, a
    3-vector per row in space."""
    return cross(r, f)


def wrench(p: np.ndarray, f: np.ndarray, center: np.ndarray, length) -> np.ndarray:
    """Wrench(es) of force(s) ``f`` at point(s) ``p``, shape ``(..., 3)`` or ``(..., 6)``.

    Torques are taken about ``center`` (broadcast against ``p``) and divided by ``length``
    (broadcast against ``p.shape[:-1]``) so that every row is a force.
    """
    p, f = np.broadcast_arrays(p, f)
    L = np.asarray(length)
    tau = torque(p - center, f)
    tau = (tau / L)[..., None] if p.shape[-1] == 2 else tau / L[..., None]
    return np.concatenate([f, tau], axis=-1)


def contact_frame(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit tangents ``t1, t2`` completing the unit normal ``n`` (spatial, float) to a
    right-handed orthonormal frame ``(n, t1, t2)``."""
    n = np.asarray(n, dtype=float)
    axis = np.zeros_like(n)
    axis[np.arange(len(n)), np.argmin(np.abs(n), axis=1)] = 1.0
    t1 = cross(n, axis)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, torque(n, t1)


def grasp_arrays(grasp: Grasp, exact: bool = False):
    """``(P, N, mu, params, center, length)`` of ``grasp`` as arrays (exact: Fraction objects);
    ``params`` maps every registered parameter name to its values per contact (0 where a
    contact's model does not take it), ``mu`` is ``params["mu"]``."""
    conv = to_exact if exact else (lambda a: np.asarray(a, dtype=float))
    params = {name: conv([float(c.param(name, 0.0)) for c in grasp.contacts]) for name in param_names()}
    length = Fraction(grasp.length) if exact else grasp.length
    return (conv(grasp.points), conv(grasp.normals), params["mu"], params, conv(grasp.center), length)


def variants_of(grasp: Grasp) -> tuple[int, ...]:
    """The model variant of each contact of ``grasp`` (see :meth:`ContactModel.variant`)."""
    return tuple(int(c.contact_model.variant({k: np.array([v]) for k, v in c.params})[0])
                 if c.params else 0 for c in grasp.contacts)


def generator_layout(models: Sequence[str], variants: Sequence[int], dim: int, *,
                     frictionless: bool = False):
    """Owner contact, offset and friction factors of every generator of a polyhedral grasp
    wrench cone (:class:`~qualgrasp.certify.models.Generator`), in contact order.

    ``frictionless=True`` uses each model's frictionless counterpart (form closure). Raises
    ValueError when a model has no finite generators in ``dim`` (spatial friction cones).
    """
    owner, offset, friction = [], [], []
    for i, (name, variant) in enumerate(zip(models, variants)):
        model = registry.get(name)
        if frictionless:
            target, _, variant = model.frictionless()
            model = registry.get(target)
        gens = model.generators(dim, variant)
        if gens is None:
            raise ArgumentError(f"{model.name} contacts have no finite generators in {dim} dimensions; "
                             "use force_columns (the conic form)")
        for g in gens:
            owner.append(i), offset.append(g.offset), friction.append(g.friction)
    return (np.array(owner, dtype=np.int64), np.array(offset, dtype=float),
            np.array(friction, dtype=float))


def _first_variant(model, mu: float, offset_length: float) -> int:
    """The variant of a contact of ``model`` with friction ``mu`` and offset length
    ``offset_length`` (its other parameters 0)."""
    values = {name: np.zeros(1) for name in model.param_names}
    values["mu"] = np.array([mu])
    if model.offset_param is not None:
        values[model.offset_param] = np.array([offset_length])
    return int(model.variant(values)[0])


def generator_columns(P, N, mu, models, center, length, *, frictionless: bool = False,
                      width=None, variants: Sequence[int] | None = None):
    """Generator wrenches of a polyhedral grasp wrench cone, as columns.

    Generator ``j`` of contact ``i`` (:func:`generator_layout`) is the force
    ``n + friction_j mu_i t`` applied at ``p + offset_j width_i t`` (``t`` the planar tangent):
    a frictionless contact contributes ``n``; a planar point contact the two edges of its friction
    cone, ``n + mu t`` and ``n - mu t`` (exact in the plane); a pad the edges at its two ends. With
    ``frictionless=True`` every contact is replaced by its frictionless counterpart (form closure).
    The arithmetic is that of :func:`qualgrasp.certify._kernels.planar.planar_generators`, term
    for term, so both give the same floats; on Fraction arrays it is exact.

    Parameters
    ----------
    P, N : array, shape (..., m, dim)
        Contact points and inward unit normals (leading batch dimensions allowed).
    mu : array, shape (..., m)
    models : sequence of str, length m
        Contact model of each contact (shared by the batch).
    center : array, shape (..., dim)
    length : scalar or array, shape (...)
    width : array, shape (..., m), optional
        Offset lengths (:func:`qualgrasp.certify.models.offset_lengths`: a pad's width; zeros
        by default).
    variants : sequence of int, optional
        Model variant of each contact (shared by the batch); default: from the first grasp's
        ``mu`` and ``width``.

    Returns
    -------
    W : array, shape (..., d, k)
        Generator wrenches (d = 3 planar, 6 spatial).
    owner : ndarray of int, shape (k,)
        Index of the contact each column belongs to.
    """
    exact = np.asarray(N).dtype == object
    width = np.zeros(np.shape(mu)) if width is None else width
    if variants is None:
        first = (0,) * (np.ndim(mu) - 1)
        variants = [_first_variant(registry.get(name), float(np.asarray(mu)[first + (i,)]),
                                   float(np.asarray(width)[first + (i,)])) for i, name in enumerate(models)]
    owner, offset, friction = generator_layout(models, variants, P.shape[-1], frictionless=frictionless)
    conv = to_exact if exact else (lambda a: a)
    Nk = N[..., owner, :]
    Pk = P[..., owner, :]
    F = Nk
    if friction.any() or offset.any():
        T = tangent(Nk)
        if friction.any():
            F = np.where((friction != 0)[:, None], Nk + (conv(friction) * mu[..., owner])[..., None] * T, Nk)
        if offset.any():
            Pk = np.where((offset != 0)[:, None], Pk + (conv(offset) * width[..., owner])[..., None] * T, Pk)
    W = wrench(Pk, F, np.asarray(center)[..., None, :], np.asarray(length)[..., None])
    return np.swapaxes(W, -1, -2), owner


def planar_generator_arrays(grasp: Grasp, *, frictionless: bool = False):
    """Generator wrenches ``W`` (3, k) of a planar grasp, bounds ``E`` on their distance to the
    exact values (:func:`qualgrasp.certify._kernels.planar.planar_generators`: the floats of
    :func:`qualgrasp.certify.core.problem.grasp_system`), and the owner contact of each (sorted).
    ``frictionless=True`` gives those of its form-closure problem (each model's frictionless
    counterpart, :func:`generator_layout`).

    Examples
    --------
    >>> from qualgrasp.certify import Contact, Grasp
    >>> g = Grasp((Contact((1, 0), (-1, 0), "point", 0.5), Contact((-1, 0), (1, 0), "point", 0.5)))
    >>> W, E, owner = planar_generator_arrays(g)
    >>> W.shape, owner.tolist(), planar_generator_arrays(g, frictionless=True)[0].shape
    ((3, 4), [0, 0, 1, 1], (3, 2))
    """
    P, N, mu, params, c, L = grasp_arrays(grasp)
    models = tuple(ct.model for ct in grasp.contacts)
    owner, offset, friction = generator_layout(models, variants_of(grasp), 2, frictionless=frictionless)
    W = np.empty((3, len(owner)))
    E = np.empty((3, len(owner)))
    planar_generators(P, N, mu, registry.offset_lengths(models, params), c, float(L), owner, offset, friction, W, E)
    return W, E, owner


def planar_generator_rank(P, N, mu, width, owner, offset, friction, cols=None) -> int:
    """Exact rank of the planar generator columns of one grasp (:func:`generator_columns`'
    formulas on the float data, in exact arithmetic), or of the generators ``cols`` only.

    The torque row ``((q - c) x f) / L`` is ``(q x f - c x f) / L``, a row operation away from
    ``q x f``, so the rank does not depend on ``center`` and ``length``; the rows ``f_x, f_y,
    q x f`` are evaluated in integers (every float scaled by one power of two) and ranked by
    :func:`qualgrasp.certify.core.exact.rank`. The same rank as
    ``exact.rank(generator_columns(...exact...))``, without building Fractions.

    Parameters
    ----------
    P, N : array, shape (m, 2)
        Contact points and inward unit normals (floats, as the grasp stores them).
    mu, width : array, shape (m,)
    owner, offset, friction : array, shape (k,)
        The generator layout (:func:`generator_layout`).
    cols : sequence of int, optional
        Generators to rank (default all).

    Examples
    --------
    >>> import numpy as np
    >>> P = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0]])
    >>> owner, offset, friction = np.arange(3), np.zeros(3), np.zeros(3)
    >>> planar_generator_rank(P, -P, np.zeros(3), np.zeros(3), owner, offset, friction)  # through 0
    2
    >>> planar_generator_rank(P + 0.5, -P, np.zeros(3), np.zeros(3), owner, offset, friction)
    2
    >>> planar_generator_rank(P, -P[[1, 2, 0]], np.zeros(3), np.zeros(3), owner, offset, friction)
    3
    """
    cols = range(len(owner)) if cols is None else cols
    fx, fy, qx, qy, _, _ = _generator_integers(P, N, mu, width, (0.0, 0.0), owner, offset, friction, cols)
    return ex.rank([fx, fy, [a * d - b * c for a, b, c, d in zip(qx, qy, fx, fy)]])


def _generator_integers(P, N, mu, width, center, owner, offset, friction, cols):
    """Forces ``f = n + s t`` and points ``q = p + o t`` of the planar generators ``cols``
    (:func:`generator_columns`), and the ``center``, exactly, as integers: every value times one
    power of two (:func:`qualgrasp.certify.core.exact.dyadic_integers`), cubed for ``f``, ``q``
    and the center. Returns ``(fx, fy, qx, qy, (cx, cy), S)`` with ``S`` that power."""
    cols = list(cols)
    own = [int(owner[j]) for j in cols]
    floats = [v for i in own for v in (N[i, 0], N[i, 1], P[i, 0], P[i, 1], mu[i], width[i])]
    floats += [v for j in cols for v in (offset[j], friction[j])] + [center[0], center[1]]
    ints, s = ex.dyadic_integers(floats)
    S2 = 1 << (2 * s)
    fx, fy, qx, qy = [], [], [], []
    for a, j in enumerate(cols):
        nx, ny, px, py, mu_i, w_i = ints[6 * a: 6 * a + 6]
        off, fr = ints[6 * len(cols) + 2 * a: 6 * len(cols) + 2 * a + 2]
        sm, so = fr * mu_i, off * w_i
        fx.append(nx * S2 - sm * ny)  # t = (-n_y, n_x)
        fy.append(ny * S2 + sm * nx)
        qx.append(px * S2 - so * ny)
        qy.append(py * S2 + so * nx)
    cx, cy = ints[-2] * S2, ints[-1] * S2
    return fx, fy, qx, qy, (cx, cy), 1 << s


def planar_pair_normal(P, N, mu, width, center, length, owner, offset, friction) -> tuple[int, int, int]:
    """A positive multiple of the cross product ``w_0 x w_1`` of the exact wrenches of a planar
    grasp with two generators (:func:`generator_columns`' formulas in exact arithmetic), as
    integers: the direction orthogonal to both, exactly (zero when they are parallel).

    With ``T_j = (q_j - c) x f_j`` the wrench is ``(f_j, T_j / L)``; ``L (w_0 x w_1)`` is
    ``(f_0y T_1 - T_0 f_1y, T_0 f_1x - f_0x T_1, L (f_0 x f_1))``, every term a product of
    floats, evaluated in integers (:func:`qualgrasp.certify.core.exact.dyadic_integers`).

    Examples
    --------
    >>> import numpy as np
    >>> P, N = np.array([[1.0, 0.0], [-1.0, 0.0]]), np.array([[-1.0, 0.0], [1.0, 0.0]])
    >>> z = planar_pair_normal(P, N, np.zeros(2), np.zeros(2), np.zeros(2), 1.0, np.arange(2),
    ...                        np.zeros(2), np.zeros(2))
    >>> [v != 0 for v in z]  # antipodal: the wrenches are opposite, parallel
    [False, False, False]
    """
    fx, fy, qx, qy, (cx, cy), S = _generator_integers(P, N, mu, width, center, owner, offset, friction, range(2))
    T = [(qx[j] - cx) * fy[j] - (qy[j] - cy) * fx[j] for j in range(2)]  # scale S^6
    (L,), s = ex.dyadic_integers([length])
    # f is scaled by S^3, T by S^6, L by 2^s: bring L f_0 x f_1 to S^9
    z2 = (fx[0] * fy[1] - fy[0] * fx[1]) * L * S ** 3
    return (fy[0] * T[1] - T[0] * fy[1]) << s, (T[0] * fx[1] - fx[0] * T[1]) << s, z2


def force_columns(P, N, models, center, length):
    """Wrenches of the unit values of the conic form's certificate columns, as columns.

    Layout per contact (:class:`~qualgrasp.certify.models.ContactModel`): ``forces == "normal"``
    one column ``[n]``; ``"axes"`` one per world axis ``[e_1, ..., e_dim]``; then one column
    ``(0, n / L)`` per moment in ``extra`` (a unit moment about the stored, unit up to rounding,
    normal ``n``). Arguments as in :func:`generator_columns` (leading batch dimensions allowed).

    Returns
    -------
    C : array, shape (..., d, k)
    owner : ndarray of int, shape (k,)
    """
    dim = P.shape[-1]
    batch = P.shape[:-2]
    eye = to_exact(np.eye(dim)) if N.dtype == object else np.eye(dim)
    c = np.asarray(center)[..., None, :]
    L = np.asarray(length)[..., None]
    cols, owner = [], []
    for i, name in enumerate(models):
        model = registry.get(name)
        if model.forces is None:
            raise ArgumentError(f"{name} contacts have no conic form (they are polyhedral: use the generators)")
        forces = N[..., i:i + 1, :] if model.forces == "normal" else np.broadcast_to(eye, batch + (dim, dim))
        w = wrench(P[..., i:i + 1, :], forces, c, L)
        cols += [w[..., j, :] for j in range(w.shape[-2])]
        owner += [i] * w.shape[-2]
        for _ in model.extra:
            cols.append(np.concatenate([N[..., i, :] * 0, N[..., i, :] / np.asarray(length)[..., None]], axis=-1))
            owner.append(i)
    return np.stack(cols, axis=-1), np.array(owner, dtype=int)


def force_column_errors(P, N, models, center, length) -> np.ndarray:
    """Bounds (B, 6, k) on the distance between the float spatial columns of
    :func:`force_columns` and their exact values on the same data, for a batch (B, m, 3):
    forces are exact (world axes or stored normals); torques ``(r x f) / L`` within
    ``(gamma_8 (|r_a| |f_b| + |r_b| |f_a|) + 4 eta) / L + eta`` per component
    (``gamma_n = n u / (1 - n u)``, ``eta`` the smallest subnormal, for products that
    underflow); a moment column ``n / L`` within ``2u |n| / L + eta``."""
    B = P.shape[0]
    k = sum(registry.get(name).columns(3) for name in models)
    E = np.zeros((B, 6, k))
    L = np.asarray(length)
    g8 = 8 * 2.0**-53 / (1 - 8 * 2.0**-53)
    j = 0
    for i, name in enumerate(models):
        model = registry.get(name)
        r = np.abs(P[:, i, :] - center)
        forces = ([np.abs(N[:, i, :])] if model.forces == "normal"
                  else [np.broadcast_to(np.eye(3)[q], (B, 3)) for q in range(3)])
        for f in forces:
            E[:, 3, j] = (g8 * (r[:, 1] * f[:, 2] + r[:, 2] * f[:, 1]) + 4 * ETA) / L + ETA
            E[:, 4, j] = (g8 * (r[:, 2] * f[:, 0] + r[:, 0] * f[:, 2]) + 4 * ETA) / L + ETA
            E[:, 5, j] = (g8 * (r[:, 0] * f[:, 1] + r[:, 1] * f[:, 0]) + 4 * ETA) / L + ETA
            j += 1
        for _ in model.extra:
            E[:, 3:, j] = 2 * 2.0**-53 * np.abs(N[:, i, :]) / L[:, None] + ETA
            j += 1
    return E
