"""Verlet candidates of one replica: an explicit neighbour list in canonical ``(i, j)`` order.

A candidate is a pair whose Lees-Edwards minimum-image distance is below
``r_i + r_j + skin``, or a bond.  The near pairs come from a cell list (:func:`near_pairs_cells`,
O(N), sort-based binning with array operations only) or, for small replicas and boxes of fewer
than 3 cells per side, from the all-pairs search (:func:`near_pairs_all`, also the test oracle).
Both select with the same minimum image and the same comparison, so they return the same pairs
bit for bit (tested).  On the host the all-pairs search tests only the pairs of the y band that
can be within reach (:func:`_y_band`), which returns the same pairs for a fraction of the work.

The list stays valid while no pair can have come into contact: :func:`verlet_bound` is, per
replica, an upper bound of how much any pair separation can have shrunk since the list was built
(from the peculiar displacements and the accumulated strain), and the list is rebuilt when the
bound reaches the skin.  The contacts of every step are therefore exactly those of an all-pairs
search (tested), and a replica's list depends only on its own history.

Array namespace: both searches take the namespace of their inputs
(:func:`~particleShear.engine.xp.array_namespace`); the engine runs them on the host (the
positions of a rebuilt replica are read through the named transfer "rebuild", also for a GPU
batch), and :func:`build_candidates`, which merges the bonds and carries the history over, is NumPy.
"""
__docformat__ = "numpy"

import math

import numpy as np

from .box import in_intervals, min_image
from .xp import array_namespace, minimum, select

__all__ = ["all_pairs", "near_pairs_all", "near_pairs_cells", "near_pairs", "cell_grid", "build_candidates",
           "verlet_bound", "within_reach", "CELL_LIST_MIN_N"]

#: smallest N for which :func:`near_pairs` uses the cell list (below it the all-pairs search is
#: faster; measured with ``benchmarks/bench_engine_large.py --crossover``, docs/performance.md)
CELL_LIST_MIN_N = 200

#: relative margin of a cell over the search reach ``2 r_max + skin``: a cell index computed in
#: floating point can then be off only for spheres closer than this to a cell border, which the
#: margin covers, so rounding never hides a pair
CELL_MARGIN = 1e-9

#: relative margin of the y band of :func:`near_pairs_all` over the reach (see :func:`_y_band`)
BAND_MARGIN = 1e-9

_TRIU = {}
#: the largest pair key ``i·N + j`` that a 32-bit sort takes
_INT32_MAX = np.iinfo(np.int32).max


def all_pairs(N):
    """``(i, j)`` of every pair ``i < j`` of N spheres, in canonical order (kept per N).

    The all-pairs search that :func:`near_pairs_all` filters; cached for the last few N
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


def _near(i, j, x, y, r, Lx, Ly, shift, skin):
    """Mask of the pairs ``(i, j)`` whose minimum-image distance is below ``r_i + r_j + skin``.

    The one selection both searches use (the same operations element by element, so the same
    decisions bit for bit).  Only the separations outside the intervals ``[−L/2, L/2)`` of the
    minimum image go through :func:`~particleShear.engine.box.min_image` (which leaves the others
    as they are, so the distances are the same numbers); with a non-finite offset every one does.

    Parameters
    ----------
    i, j : ndarray of int (M,)
        Local sphere indices of the pairs tested.
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm).

    Returns
    -------
    ndarray of bool (M,)
    """
    xp = array_namespace(x)
    dx, dy = x[j] - x[i], y[j] - y[i]
    if math.isfinite(shift):      # (a shift that is not finite makes every x it moves NaN)
        moved = xp.flatnonzero(~in_intervals(dx, dy, Lx, Ly))
    else:
        moved = slice(None)
    dx[moved], dy[moved], _, _ = min_image(dx[moved], dy[moved], Lx, Ly, shift)
    return within_reach(dx, dy, r[i] + r[j] + skin)


def within_reach(dx, dy, reach):
    """Whether a minimum-image separation is shorter than ``reach``: ``dx² + dy² < reach²`` (pure).

    The one criterion of the candidate searches (:func:`_near`, and the compiled search of
    :mod:`particleShear.engine.numba_step`).

    Parameters
    ----------
    dx, dy : ndarray or float
        Separation (µm).
    reach : ndarray or float
        ``r_i + r_j + skin`` (µm).

    Returns
    -------
    ndarray of bool or bool
    """
    return dx * dx + dy * dy < reach * reach


def near_pairs_all(x, y, r, Lx, Ly, shift, skin):
    """Pairs ``i < j`` within ``r_i + r_j + skin`` (minimum image), by testing every pair.

    O(N²) time and memory: the search of small replicas and small boxes, and the oracle
    of the cell list in the tests.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm, ≥ 0).

    Returns
    -------
    i, j : ndarray of int
        The pairs, sorted by ``(i, j)``.
    """
    i, j = all_pairs(len(x))
    xp = array_namespace(x)
    if xp is not np:          # the cached index arrays live on the host
        i, j = xp.asarray(i), xp.asarray(j)
    else:                     # on the host: test only the pairs of the y band that can be within reach
        i, j = _y_band(i, j, y, r, Ly, skin)
    near = _near(i, j, x, y, r, Lx, Ly, shift, skin)
    return i[near], j[near]


def _y_band(i, j, y, r, Ly, skin):
    """The pairs ``(i, j)`` whose y separation can be within reach: a pre-selection for :func:`_near`.

    A pair within ``r_i + r_j + skin`` has a y image within ``R = 2 r_max + skin``.  With every
    height inside the cell (``0 ≤ y < Ly``, as the engine keeps them), ``|y_j − y_i| < Ly`` and
    the image is ``y_j − y_i`` or one period from it, so a pair whose ``|y_j − y_i|`` is farther
    than ``R' = R·(1 + BAND_MARGIN) + BAND_MARGIN·Ly`` from both 0 and ``Ly`` cannot be within
    reach and is dropped (the margin covers the rounding of the image and of the distance test,
    a few ulps).  The pairs kept are then tested by :func:`_near` as every pair was before, so
    the search returns the same pairs in the same order, at a fraction of the cost (about a
    quarter of the pairs at the default density).  Without a usable band (a height outside the
    cell or not finite, a reach of half the box or more) every pair is kept.

    Parameters
    ----------
    i, j : ndarray of int
        Candidate pairs (host arrays).
    y, r : ndarray (N,)
        Heights and radii of the replica's spheres (µm).
    Ly, skin : float
        Box height and Verlet skin (µm).

    Returns
    -------
    i, j : ndarray of int
        The pairs of the band, in their order.
    """
    reach = (2 * r.max() + skin) * (1 + BAND_MARGIN) + BAND_MARGIN * Ly if len(r) else math.nan
    if not (reach < Ly / 2 and (y >= 0).all() and (y < Ly).all()):
        return i, j
    a = abs(y[j] - y[i])
    keep = np.flatnonzero((a < reach) | (a > Ly - reach))
    return i[keep], j[keep]


def cell_grid(Lx, Ly, reach, N):
    """Cells per side of the cell list: each at least ``reach·(1 + CELL_MARGIN)`` wide and high.

    A pair closer than ``reach`` then lies in the same or adjacent cells (the rows through
    ``y = 0`` / ``Ly`` taken at the x moved by the Lees-Edwards offset).  The grid is made
    coarser (cells larger, still valid) where it would have more than ``2N + 9`` cells, so
    the cell arrays stay O(N) for sparse boxes.

    Parameters
    ----------
    Lx, Ly : float
        Box (µm).
    reach : float
        Largest distance searched, ``2 r_max + skin`` (µm).
    N : int
        Number of spheres.

    Returns
    -------
    nx, ny : int
        Cells along x and y; 0 where ``reach`` is not positive and finite.  The cell list
        needs at least 3 of each (otherwise a row or column would be visited twice).
    """
    if not (reach > 0 and math.isfinite(reach) and Lx > 0 and Ly > 0):
        return 0, 0
    size = reach * (1 + CELL_MARGIN)
    nx, ny = int(Lx // size), int(Ly // size)
    most = 2 * N + 9
    if nx * ny > most:
        f = math.sqrt(nx * ny / most)
        nx, ny = max(3, int(nx / f)), max(3, int(ny / f))
    return nx, ny


def cell_index(v, size, n):
    """The cell of coordinates ``v`` in ``[0, n·size]``, as a float: ``floor(v/size)``, a non-finite or
    negative one in cell 0 (its pairs fail the distance test anyway), one on the far border in the
    last cell ``n − 1`` (pure: the binning of both cell lists, :func:`near_pairs_cells` and the
    compiled one of :mod:`particleShear.engine.numba_step`).

    Parameters
    ----------
    v : ndarray or float
        Coordinates folded into the box (µm).
    size : float
        Cell width (µm).
    n : int
        Cells along the axis.

    Returns
    -------
    ndarray or float
    """
    c = np.floor(v / size)
    return minimum(select(c >= 0, c, 0.0), n - 1)


def near_pairs_cells(x, y, r, Lx, Ly, shift, skin):
    """Pairs ``i < j`` within ``r_i + r_j + skin`` (minimum image), by a cell list in O(N).

    The box is divided into ``nx × ny`` cells of at least ``2 r_max + skin`` (:func:`cell_grid`);
    spheres are binned by sorting their cell numbers (``argsort``, ``bincount``, ``cumsum``).
    A pair closer than the reach lies in the same cell or in adjacent ones (3 × 3 around each
    sphere); each pair is visited once, from the same cell (``i < j``) or from the sphere whose
    partner lies in the cell to the right or in one of the three cells of the row above.  The
    row above the top row is the bottom row seen through the Lees-Edwards image, so it is
    searched around ``x − shift``, as the minimum image of docs/engine.md moves x by the offset
    when it takes the y image.  Every candidate is then tested exactly as
    :func:`near_pairs_all` tests it (same orientation ``i < j``, same operations), so both
    return the same pairs.

    Array operations only (a loop over the 5 cell offsets of the half neighbourhood), in the
    namespace of the inputs.  Falls back to :func:`near_pairs_all` when the grid has fewer than 3 cells per
    side.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).  Positions outside the cell are
        folded into it for the binning (whole periods, with the offset of the y images).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm, ≥ 0).

    Returns
    -------
    i, j : ndarray of int
        The pairs, sorted by ``(i, j)``.
    """
    xp = array_namespace(x)
    N = int(x.shape[0])
    if N < 2:
        return xp.zeros(0, dtype=xp.intp), xp.zeros(0, dtype=xp.intp)
    Lx, Ly, shift, skin = float(Lx), float(Ly), float(shift), float(skin)
    # device-to-host transfers on CuPy (once per rebuild): the largest radius sizes the grid, and
    # each expansion's length below sizes its arrays
    nx, ny = cell_grid(Lx, Ly, 2 * float(r.max()) + skin, N)
    if nx < 3 or ny < 3:
        return near_pairs_all(x, y, r, Lx, Ly, shift, skin)
    cw, ch = Lx / nx, Ly / ny

    def index(v, size, n):
        return cell_index(v, size, n).astype(xp.intp)

    def column(xs):
        return index(xp.mod(xs, Lx), cw, nx)

    # bin: fold into the cell (a y period moves x by the offset), cell number, spheres sorted by cell
    ky = xp.floor(y / Ly)
    xf = x - shift * ky
    cy = index(y - Ly * ky, ch, ny)
    cx = column(xf)
    order = xp.argsort(cy * nx + cx)
    counts = xp.bincount(cy * nx + cx, minlength=nx * ny)
    start = xp.cumsum(counts) - counts
    # half the neighbourhood: a pair in one cell once (i < j), a pair in adjacent cells from the sphere
    # whose neighbour lies to the right in its row or in the row above (exactly one of the two spheres
    # sees the other so with at least 3 cells per side)
    up = cy + 1
    col_up = column(xp.where(up >= ny, xf - shift, xf))      # the row above the top row: the bottom row at x − shift
    up = xp.mod(up, ny)
    found = []
    for row, col, dcol, same in ((cy, cx, 0, True), (cy, cx, 1, False), (up, col_up, -1, False),
                                 (up, col_up, 0, False), (up, col_up, 1, False)):
        cell = row * nx + xp.mod(col + dcol, nx)
        cnt = counts[cell]
        ends = xp.cumsum(cnt)
        total = int(ends[-1])
        if total == 0:
            continue
        # slot k of the expansion belongs to sphere a = #(ends ≤ k) and reads the
        # (k − first slot of a)-th sphere of a's neighbouring cell in cell order
        a = xp.cumsum(xp.bincount(ends[:-1], minlength=total)[:total])
        b = order[(start[cell] - (ends - cnt))[a] + xp.arange(total, dtype=xp.intp)]
        if same:
            keep = xp.flatnonzero(a < b)       # (an index array gathers faster than a mask selects)
            i, j = a[keep], b[keep]
        else:
            i, j = xp.minimum(a, b), xp.maximum(a, b)          # the pair vector as the all-pairs search takes it
        near = xp.flatnonzero(_near(i, j, x, y, r, Lx, Ly, shift, skin))
        found.append(i[near] * N + j[near])
    if not found:
        return xp.zeros(0, dtype=xp.intp), xp.zeros(0, dtype=xp.intp)
    key = xp.concatenate(found)
    if N * N <= _INT32_MAX:       # (a 32-bit key sorts in ≈ 0.6 of the time: ≈ 0.5 ms of a rebuild at N = 10,000)
        key = key.astype(xp.int32)
    key = xp.sort(key)
    return (key // N).astype(xp.intp), (key % N).astype(xp.intp)


def near_pairs(x, y, r, Lx, Ly, shift, skin):
    """Pairs ``i < j`` within ``r_i + r_j + skin`` (minimum image), by the faster search.

    The cell list (:func:`near_pairs_cells`) from :data:`CELL_LIST_MIN_N` spheres on, the
    all-pairs search (:func:`near_pairs_all`) below; both give the same pairs.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm, ≥ 0).

    Returns
    -------
    i, j : ndarray of int
        The pairs, sorted by ``(i, j)``.
    """
    if len(x) >= CELL_LIST_MIN_N:
        return near_pairs_cells(x, y, r, Lx, Ly, shift, skin)
    return near_pairs_all(x, y, r, Lx, Ly, shift, skin)


def build_candidates(x, y, r, Lx, Ly, shift, skin, old, search=None, rows=None):
    """Make the near pairs of one replica its candidates, keeping the history of those that stay.

    Parameters
    ----------
    x, y, r : ndarray (N,)
        Positions (inside the cell) and radii of the replica's spheres (µm).
    Lx, Ly, shift : float
        Box and Lees-Edwards offset ``Ly·γ`` (µm).
    skin : float
        Verlet skin (µm).
    old : PairTable
        The replica's pair list, changed in place (:meth:`~particleShear.engine.state.PairTable.replace`).
    search : callable, optional
        The search, with the arguments and result of :func:`near_pairs` (default :func:`near_pairs`;
        the compiled backend's gives the same pairs).
    rows : callable, optional
        The history merge (:func:`~particleShear.engine.state.carried_rows`, default; the compiled
        backend passes it compiled).

    Returns
    -------
    PairTable
        ``old``, now the near pairs (:func:`near_pairs`) and every bond it had, in canonical
        ``(i, j)`` order; a pair that stays a candidate keeps its state, ξ, ``d_eq``, relation and
        creation number, a new one starts at rest.
    """
    old.replace(*(search or near_pairs)(x, y, r, Lx, Ly, shift, skin), keep_relations=False, rows=rows)
    return old


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
