"""Verlet candidates of one replica: an explicit neighbour list in canonical ``(i, j)`` order.

A candidate is a pair whose Lees-Edwards minimum-image distance is below
``r_i + r_j + skin``, or a bond.  The list stays valid while no pair can have come into
contact: :func:`verlet_bound` is, per replica, an upper bound of how much any pair separation
can have shrunk since the list was built (from the peculiar displacements and the accumulated
strain), and the list is rebuilt when the bound reaches the skin.  The contacts of every step
are therefore exactly those of an all-pairs search (tested), and a replica's list depends only
on its own history.
"""
__docformat__ = "numpy"

import numpy as np

from .box import min_image
from .state import PERMANENT, ReplicaPairs

__all__ = ["all_pairs", "build_candidates", "verlet_bound"]

_TRIU = {}


def all_pairs(N):
    """``(i, j)`` of every pair ``i < j`` of N spheres, in canonical order (kept per N).

    The all-pairs search that :func:`build_candidates` filters; cached for the last few N
    so a rebuild does not allocate the index arrays again.

    Parameters
    ----------
    N : int
        Number of spheres of one replica (≥ 0).

    Returns
    -------
    i, j : ndarray of int (N·(N−1)/2,)
        Local sphere indices of every pair, sorted by ``(i, j)`` (shared cached arrays: do
        not modify).
    """
    ij = _TRIU.get(N)
    if ij is None:
        if len(_TRIU) > 16:
            _TRIU.clear()
        ij = _TRIU[N] = np.triu_indices(N, 1)
    return ij


def build_candidates(x, y, r, Lx, Ly, shift, skin, old):
    """New candidate list of one replica, keeping the history of pairs that stay candidates.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions (inside the cell) and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm).
    old : ReplicaPairs
        The current list (bonds and relations are carried over).

    Returns
    -------
    ReplicaPairs
        The candidates in canonical ``(i, j)`` order; a pair of ``old`` that is still a
        candidate keeps its state, ξ, ``d_eq`` and relation, a new one starts at rest.
    """
    N = len(x)
    i, j = all_pairs(N)
    dx, dy, _, _ = min_image(x[j] - x[i], y[j] - y[i], Lx, Ly, shift)
    reach = r[i] + r[j] + skin
    near = dx * dx + dy * dy < reach * reach
    key_new = i * N + j
    key_old = old.i * N + old.j
    bonds = key_old[old.state == PERMANENT]
    if len(bonds):
        near[np.searchsorted(key_new, bonds)] = True
    sel = np.flatnonzero(near)
    key = key_new[sel]
    C = len(sel)
    state = np.zeros(C, np.int8)
    xi = np.zeros((2, C))
    d_eq = np.zeros(C)
    active = np.zeros(C, bool)
    kept = old.active | (old.state == PERMANENT)
    if kept.any():
        pos = np.searchsorted(key, key_old[kept])
        found = pos < C
        found[found] &= key[pos[found]] == key_old[kept][found]
        src = np.flatnonzero(kept)[found]
        dst = pos[found]
        state[dst] = old.state[src]
        xi[:, dst] = old.xi[:, src]
        d_eq[dst] = old.d_eq[src]
        active[dst] = old.active[src]
    return ReplicaPairs(i[sel], j[sel], state, xi, d_eq, active)


def verlet_bound(u_max, strain, r_max):
    """Upper bound (µm) of how much any pair separation can have shrunk since the list was built.

    Under Lees-Edwards shear a pair vector (through a fixed image) evolves as
    ``dΔ = γ̇ Δ_y dt + (peculiar displacements)``, the peculiar velocity being ``v − γ̇ (y − Ly/2)``
    (invariant under the wrap).  With ``u_max`` the largest peculiar displacement of any sphere
    since the build (running maximum) and ``strain`` the accumulated ``Σ |γ̇| dt``, a pair that
    touches now (``|Δ| < r_i + r_j ≤ 2 r_max``) was at most
    ``2 u_max (1 + 2·strain) + 2·strain·r_max`` farther apart at the build.  The list is valid
    while this stays below the skin.

    Parameters
    ----------
    u_max : ndarray (B,) or float
        Largest peculiar displacement of any sphere of each replica since its build (µm).
    strain : ndarray (B,) or float
        Accumulated ``Σ |γ̇| dt`` of each replica since its build (dimensionless).
    r_max : ndarray (B,) or float
        Largest radius of each replica (µm).

    Returns
    -------
    ndarray (B,) or float
        The bound (µm); the list is rebuilt when it reaches the skin.
    """
    return 2 * u_max * (1 + 2 * strain) + 2 * strain * r_max
