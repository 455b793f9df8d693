"""Pair table and O(N) neighbour search with Lees-Edwards-shifted cell rows (see docs/design.md).

The pair table (:class:`~particleShear.engine.state.PairTable`, the engine's, re-exported) holds candidate pairs ``i < j`` (list indices) found within
``r_i + r_j + skin`` plus every permanent link; a pair is *active* (a relation
in the reference sense) while it touches or is permanent.  Candidates are
rebuilt only when spheres or the shear offset have moved by more than the skin
allows, so the per-step contact set is exactly the all-pairs one.
"""
__docformat__ = "numpy"

from ..engine.neighbours import all_pairs, near_pairs
from ..engine.state import PERMANENT, SLIP, STICK, PairTable

__all__ = ["PairTable", "STICK", "SLIP", "PERMANENT", "STATE_NAMES", "candidate_pairs", "all_pairs"]

STATE_NAMES = ("stick", "slip", "permanent")
STATE_CODES = {"stick": STICK, "slip": SLIP, "permanent": PERMANENT}



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
