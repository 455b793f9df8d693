"""Central force laws over arrays, written once (eq. S1-5a/b, S1-6; docs/parameters.md).

Forces in mg·µm·s⁻² per m depth; negative = repulsion.
"""
__docformat__ = "numpy"

import numpy as np

__all__ = ["central_law", "tensile_law"]


def central_law(d, d0, k, c):
    """Compressive law: ``−k(1−c)(d0−d) − k·c·d0·(d0/max(d, d0/1000) − 1)`` for ``d ≤ d0``, else 0.

    ``c`` blends the linear law (eq. S1-5a, c = 0) and the divergent law (eq. S1-5b, c = 1);
    the ratio ``d0/d`` is capped at 1000 (eq. S1-6).  All arguments broadcast.

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the pair (µm).
    d0 : ndarray or float
        Contact distance (µm, > 0): ``r_i + r_j`` for a contact, ``d_eq`` for a bond.
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).
    c : ndarray or float
        Central repulsion coefficient in [0, 1] (0 linear, 1 divergent).

    Returns
    -------
    ndarray or float
        Scalar central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; ≤ 0, repulsive,
        and 0 beyond ``d0``).
    """
    inside = -k * (1 - c) * (d0 - d) + (-k * c * d0) * (d0 / np.maximum(d, d0 / 1000) - 1)
    return np.where(d > d0, 0.0, inside)


def tensile_law(d, d_eq, k):
    """Linear tensile law of a stretched bond, ``k (d − d_eq)`` (≥ 0 for ``d ≥ d_eq``, attractive).

    The linear law eq. S1-5a on the stretched side of a permanent link.

    Parameters
    ----------
    d : ndarray or float
        Centre distance of the bonded pair (µm).
    d_eq : ndarray or float
        Equilibrium distance of the bond (µm).
    k : ndarray or float
        Spring constant (mg·s⁻² per m depth, eq. S1-8).

    Returns
    -------
    ndarray or float
        Scalar central force on i along ``n_ij`` (mg·µm·s⁻² per m depth; positive attracts).
    """
    return k * (d - d_eq)
