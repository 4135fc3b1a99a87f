"""Wrenches, friction-cone edges and contact frames: the one place where they are computed.

Wrench of a force ``f`` applied at ``p`` about the reference point ``c``, with characteristic
length ``L``: planar ``w = (f_x, f_y, ((p - c) x f) / L)``, spatial ``w = (f, ((p - c) x f) / L)``.

The functions work on float arrays and equally on object arrays of :class:`fractions.Fraction`
(see :func:`to_exact`): every operation is a sum, product or quotient, so the certificate checker
evaluates the very same formulas in exact rational arithmetic.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from .grasp import Grasp

__all__ = [
    "to_exact",
    "tangent",
    "torque",
    "wrench",
    "contact_frame",
    "generator_columns",
    "force_columns",
    "grasp_arrays",
]


def to_exact(a) -> np.ndarray:
    """Object array of :class:`~fractions.Fraction` holding the exact values of the floats in ``a``."""
    a = np.asarray(a, dtype=float)
    return np.array([Fraction(v) for v in a.ravel()], dtype=object).reshape(a.shape)


def tangent(n: np.ndarray) -> np.ndarray:
    """Planar unit tangent ``t = (-n_y, n_x)``: ``n`` turned a quarter turn counter-clockwise."""
    return np.stack([-n[..., 1], n[..., 0]], axis=-1)


def torque(r: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Moment ``r x f``: a scalar per row in the plane, a 3-vector per row in space."""
    if r.shape[-1] == 2:
        return r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]
    return np.stack(
        [
            r[..., 1] * f[..., 2] - r[..., 2] * f[..., 1],
            r[..., 2] * f[..., 0] - r[..., 0] * f[..., 2],
            r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0],
        ],
        axis=-1,
    )


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
    t1 = torque(n, axis)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    return t1, torque(n, t1)


def grasp_arrays(grasp: Grasp, exact: bool = False):
    """``(P, N, mu, torsion, center, length)`` of ``grasp`` as arrays (exact: Fraction objects)."""
    conv = to_exact if exact else (lambda a: np.asarray(a, dtype=float))
    mu = [c.mu for c in grasp.contacts]
    torsion = [c.torsion or 0.0 for c in grasp.contacts]
    length = Fraction(grasp.length) if exact else grasp.length
    return (conv(grasp.points), conv(grasp.normals), conv(mu), conv(torsion),
            conv(grasp.center), length)


def generator_columns(P, N, mu, models, center, length, *, frictionless: bool = False):
    """Generator wrenches of a polyhedral grasp wrench cone, as columns.

    A frictionless contact contributes ``n``; a planar point contact the two edges of its friction
    cone, ``n + mu t`` and ``n - mu t`` (exact in the plane). With ``frictionless=True`` every contact
    is treated as frictionless (form closure).

    Parameters
    ----------
    P, N : array, shape (..., m, dim)
        Contact points and inward unit normals (leading batch dimensions allowed).
    mu : array, shape (..., m)
    models : sequence of str, length m
        Contact model of each contact (shared by the batch).
    center : array, shape (..., dim)
    length : scalar or array, shape (...)

    Returns
    -------
    W : array, shape (..., d, k)
        Generator wrenches (d = 3 planar, 6 spatial).
    owner : ndarray of int, shape (k,)
        Index of the contact each column belongs to.
    """
    owner, sign = [], []
    for i, model in enumerate(models):
        if frictionless or model == "frictionless":
            owner.append(i), sign.append(0)
        elif P.shape[-1] == 2 and model == "point":
            owner += [i, i]
            sign += [1, -1]
        else:
            raise ValueError("spatial friction cones have no finite generators; use force_columns")
    owner = np.array(owner, dtype=int)
    Nk = N[..., owner, :]
    F = Nk
    if any(sign):
        F = Nk + (np.array(sign) * mu[..., owner])[..., None] * tangent(Nk)
    W = wrench(P[..., owner, :], F, np.asarray(center)[..., None, :], np.asarray(length)[..., None])
    return np.swapaxes(W, -1, -2), owner


def force_columns(P, N, models, center, length):
    """Wrenches of unit contact-force components in world coordinates, as columns.

    Layout per contact: frictionless ``[n]``; point ``[e_1, ..., e_dim]`` (world axes); soft
    ``[e_1, e_2, e_3, tau]`` where ``tau = (0, n / L)`` is the wrench of a unit torsional moment
    about the (stored, unit up to rounding) normal ``n``. Arguments as in
    :func:`generator_columns` (leading batch dimensions allowed).

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
    for i, model in enumerate(models):
        forces = N[..., i:i + 1, :] if model == "frictionless" else np.broadcast_to(eye, batch + (dim, dim))
        w = wrench(P[..., i:i + 1, :], forces, c, L)
        cols += [w[..., j, :] for j in range(w.shape[-2])]
        owner += [i] * w.shape[-2]
        if model == "soft":
            cols.append(np.concatenate([N[..., i, :] * 0, N[..., i, :] / np.asarray(length)[..., None]], axis=-1))
            owner.append(i)
    return np.stack(cols, axis=-1), np.array(owner, dtype=int)
