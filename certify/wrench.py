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

    Torques are taken about ``center`` and divided by ``length`` so that every row is a force.
    """
    p, f = np.broadcast_arrays(p, f)
    tau = torque(p - center, f) / length
    if p.shape[-1] == 2:
        tau = tau[..., None]
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


def _arrays(grasp: Grasp, exact: bool):
    conv = to_exact if exact else (lambda a: np.asarray(a, dtype=float))
    mu = np.array([c.mu for c in grasp.contacts], dtype=float)
    return (conv(grasp.points), conv(grasp.normals), conv(mu), conv(grasp.center),
            Fraction(grasp.length) if exact else grasp.length)


def generator_columns(grasp: Grasp, *, frictionless: bool = False, exact: bool = False):
    """Generator wrenches of a polyhedral grasp wrench cone, as columns.

    A frictionless contact contributes ``n``; a planar point contact the two edges of its friction
    cone, ``n + mu t`` and ``n - mu t`` (exact in the plane). With ``frictionless=True`` every contact
    is treated as frictionless (form closure).

    Returns
    -------
    W : ndarray, shape (d, k)
        Generator wrenches (d = 3 planar, 6 spatial).
    owner : ndarray of int, shape (k,)
        Index of the contact each column belongs to.
    """
    P, N, mu, c, L = _arrays(grasp, exact)
    forces, owner = [], []
    for i, contact in enumerate(grasp.contacts):
        if frictionless or contact.model == "frictionless":
            forces.append(N[i]), owner.append(i)
        elif grasp.dim == 2 and contact.model == "point":
            t = tangent(N[i])
            forces += [N[i] + mu[i] * t, N[i] - mu[i] * t]
            owner += [i, i]
        else:
            raise ValueError("spatial friction cones have no finite generators; use force_columns")
    owner = np.array(owner, dtype=int)
    return wrench(P[owner], np.array(forces), c, L).T, owner


def force_columns(grasp: Grasp, *, exact: bool = False):
    """Wrenches of unit contact-force components in world coordinates, as columns.

    Layout per contact: frictionless ``[n]``; point ``[e_1, ..., e_dim]`` (world axes); soft
    ``[e_1, e_2, e_3, tau]`` where ``tau = (0, n / L)`` is the wrench of a unit torsional moment
    about the (stored, unit up to rounding) normal ``n``.

    Returns
    -------
    C : ndarray, shape (d, k)
    owner : ndarray of int, shape (k,)
    """
    P, N, _, c, L = _arrays(grasp, exact)
    dim = grasp.dim
    eye = to_exact(np.eye(dim)) if exact else np.eye(dim)
    cols, owner = [], []
    for i, contact in enumerate(grasp.contacts):
        forces = [N[i]] if contact.model == "frictionless" else list(eye)
        cols += list(wrench(P[i], np.array(forces), c, L))
        if contact.model == "soft":
            zero = N[i] * 0
            cols.append(np.concatenate([zero, N[i] / L]))
        owner += [i] * (len(cols) - len(owner))
    return np.array(cols).T, np.array(owner, dtype=int)
