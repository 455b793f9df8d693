"""Pair table and O(N) neighbour search with Lees-Edwards-shifted cell rows (see docs/design.md).

The pair table holds candidate pairs ``i < j`` (list indices) found within
``r_i + r_j + skin`` plus every permanent link; a pair is *active* (a relation
in the reference sense) while it touches or is permanent.  Candidates are
rebuilt only when spheres or the shear offset have moved by more than the skin
allows, so the per-step contact set is exactly the all-pairs one.
"""
__docformat__ = "numpy"

import numpy as np

from ..engine.neighbours import all_pairs, near_pairs
from .namespace import count_nonzero as _nz

__all__ = ["PairTable", "STICK", "SLIP", "PERMANENT", "STATE_NAMES", "candidate_pairs", "all_pairs"]

STICK, SLIP, PERMANENT = 0, 1, 2
STATE_NAMES = ("stick", "slip", "permanent")
STATE_CODES = {"stick": STICK, "slip": SLIP, "permanent": PERMANENT}



def _key(i, j):
    return (np.asarray(i, dtype=np.int64) << 32) | np.asarray(j, dtype=np.int64)


class PairTable:
    """Structure of arrays over candidate pairs, sorted by (i, j)."""

    FIELDS = ("i", "j", "state", "xi_ij", "xi_ji", "d_eq", "active", "birth")

    def __init__(self):
        self.i = np.zeros(0, dtype=np.intp)
        self.j = np.zeros(0, dtype=np.intp)
        self.key = np.zeros(0, dtype=np.int64)
        self.state = np.zeros(0, dtype=np.int8)
        self.xi = np.zeros((2, 0))
        self.d_eq = np.zeros(0)
        self.active = np.zeros(0, dtype=bool)
        self.birth = np.zeros(0, dtype=np.int64)
        self.n_permanent = 0
        self._births = 0
        self.version = 0

    def __len__(self):
        return len(self.i)

    @property
    def xi_ij(self):
        """ξ of relation i→j (µm), a row view of ``xi`` (both directions gathered in one call)."""
        return self.xi[0]

    @property
    def xi_ji(self):
        """ξ of relation j→i (µm), a row view of ``xi``."""
        return self.xi[1]

    def find(self, i, j):
        """Slots of pairs (i, j) (any order), -1 where absent.

        Parameters
        ----------
        i, j : int or array_like of int
            Sphere indices (``sphereList`` order) of the pairs, in either order.

        Returns
        -------
        numpy.ndarray of int
            Row of each pair in the table, -1 where the pair is not a candidate.
        """
        i = np.asarray(i)
        j = np.asarray(j)
        lo, hi = np.minimum(i, j), np.maximum(i, j)
        k = _key(lo, hi)
        pos = np.searchsorted(self.key, k)
        pos_c = np.minimum(pos, max(len(self.key) - 1, 0))
        found = (pos < len(self.key)) & (self.key[pos_c] == k) if len(self.key) else np.zeros(np.shape(k), bool)
        return np.where(found, pos_c, -1)

    def next_births(self, n):
        """Reserve ``n`` consecutive birth numbers (the order in which relations were created).

        Parameters
        ----------
        n : int
            How many numbers to reserve (≥ 0).

        Returns
        -------
        numpy.ndarray of int64
            The reserved numbers, increasing.
        """
        b = np.arange(self._births, self._births + n, dtype=np.int64)
        self._births += n
        return b

    def replace(self, i, j, keep_existing=False):
        """Make (i, j) the candidate set, keeping the state of pairs present before.

        Permanent and active pairs are always kept; with ``keep_existing`` every
        existing row is kept and (i, j) are added.

        Parameters
        ----------
        i, j : array_like of int
            Sphere indices of the new candidate pairs, in either order (duplicates allowed).
        keep_existing : bool
            Keep every existing row instead of only the active and permanent ones.
        """
        old_key = self.key
        k = np.sort(_key(np.minimum(i, j), np.maximum(i, j)))
        if len(k) > 1 and _nz(k[1:] == k[:-1]):
            k = np.unique(k)
        # rows to keep that the new candidates miss (e.g. bonds stretched beyond the search reach)
        kept = old_key if keep_existing else old_key[self.active | (self.state == PERMANENT)]
        if len(kept):
            at = np.searchsorted(k, kept)
            found = at < len(k)
            found[found] = k[at[found]] == kept[found]
            if not found.all():
                k = np.union1d(k, kept[~found])
        pos = np.searchsorted(old_key, k)
        pos_c = np.minimum(pos, max(len(old_key) - 1, 0))
        had = (pos < len(old_key)) & (old_key[pos_c] == k) if len(old_key) else np.zeros(len(k), bool)
        src = pos_c[had]
        n = len(k)
        self.i = (k >> 32).astype(np.intp)
        self.j = (k & 0xFFFFFFFF).astype(np.intp)
        for name, dtype in (("state", np.int8), ("d_eq", float), ("active", bool), ("birth", np.int64)):
            arr = np.zeros(n, dtype=dtype)
            if len(src):
                arr[had] = getattr(self, name)[src]
            setattr(self, name, arr)
        xi = np.zeros((2, n))
        if len(src):
            dst = np.flatnonzero(had)
            xi[0, dst] = self.xi[0, src]
            xi[1, dst] = self.xi[1, src]
        self.xi = xi
        self.key = k
        self.version += 1

    def ensure(self, i, j):
        """Slots of pairs (i, j), inserting missing ones (inactive, stick, ξ = 0).

        Parameters
        ----------
        i, j : int or array_like of int
            Sphere indices (``sphereList`` order) of the pairs, in either order.

        Returns
        -------
        numpy.ndarray of int
            Row of each pair in the table (at least one-dimensional).
        """
        i = np.atleast_1d(np.asarray(i, dtype=np.intp))
        j = np.atleast_1d(np.asarray(j, dtype=np.intp))
        slots = self.find(i, j)
        miss = slots < 0
        if miss.any():
            self.replace(i[miss], j[miss], keep_existing=True)
            slots = self.find(i, j)
        return slots


def candidate_pairs(x, y, r, Lx, Ly, shift, skin):
    """Pairs i < j whose minimum-image distance is below ``r_i + r_j + skin``.

    The engine's search, written once for both layers
    (:func:`particleShear.engine.neighbours.near_pairs`): a cell list whose rows above/below
    the cell are searched at the x position moved by the Lees-Edwards offset
    ``shift = Ly·γ``, or all pairs for small systems and for cell grids smaller than 3 × 3.
    ``x``, ``y`` should lie in the cell.

    Parameters
    ----------
    x, y : numpy.ndarray
        Sphere positions (µm), inside ``[0, Lx) × [0, Ly)``.
    r : numpy.ndarray
        Sphere radii (µm).
    Lx, Ly : float
        Cell size (µm).
    shift : float
        Lees-Edwards offset ``Ly·γ`` of the image rows (µm).
    skin : float
        Extra search distance (µm) so the candidates stay valid while spheres move.

    Returns
    -------
    tuple of numpy.ndarray
        ``(i, j)`` with ``i < j``, the candidate pairs, sorted by ``(i, j)``.
    """
    return near_pairs(x, y, r, Lx, Ly, shift, skin)
