"""The constitution's algorithms on arrays: crosslinking, cutting, particles, link removal.

Each function works on the spheres' arrays (positions ``x, y`` and radii ``r`` in µm), the cell
(``Lx, Ly`` in µm, the Lees-Edwards offset ``shift = Ly·γ`` in µm), one replica's
:class:`~particleShear.engine.state.PairTable` (changed in place) and the replica's
``numpy.random.Generator`` (every draw in the documented order).  They are the one
implementation of these steps: the documented classes' methods
(:meth:`~particleShear.linkable.canvas.CanvasPointsLinkable.makeAllLinksPermanent`,
:meth:`~particleShear.linkable.compact.EnsembleCompactParticles.cutByTriangulation`, …) call them on
their own rows and table and keep their own bookkeeping (caches, ``particles``,
``removed_fraction``), and :func:`particleShear.linkable.builders.constituted_state` calls them on
an engine state directly (the placement of the spheres:
:func:`particleShear.objects.placement.bimodal_placement`).

A bond is a pair of state :data:`~particleShear.engine.state.PERMANENT` with equilibrium distance
``d_eq = r_i + r_j`` and ξ = 0; a cut bond becomes a slipping contact (``d_eq = 0``, ξ = 0) that
stays a relation while the spheres touch.
"""
__docformat__ = "numpy"
import math

import numpy as np

from ..engine.box import inside_half_cell, min_image
from ..engine.graph import adjacency, component_labels, connected_without_edge
from ..engine.state import PERMANENT, SLIP

__all__ = ["set_bonds", "link_pairs", "cut_slots", "cut_pairs", "physical", "permanent_pairs",
           "link_relations", "cut_line", "cut_top_bottom_edge", "angle_ok", "random_line", "seed_points",
           "nearest_seeds", "cut_between_seeds", "voronoi_cut", "particle_labels", "particle_heights",
           "maximal_particle_height", "remove_non_essential_links",
           "join_isolated_spheres", "MAX_ANGLE_DRAWS"]

#: draws of a cut line's angle before :func:`random_line` gives up (a band < 180° is left: ~never reached)
MAX_ANGLE_DRAWS = 100000


def set_bonds(pairs, slots, state, d_eq):
    """Pairs ``slots`` of ``pairs`` to ``state`` with ``d_eq`` (µm) and ξ = 0; recounts the bonds.

    Parameters
    ----------
    pairs : PairTable
    slots : ndarray of int
        Rows of the table.
    state : int
        :data:`~particleShear.engine.state.PERMANENT` or another state of the table.
    d_eq : float or ndarray
        Equilibrium distance of each row (µm).
    """
    pairs.state[slots] = state
    pairs.d_eq[slots] = d_eq
    pairs.xi_ij[slots] = 0.0
    pairs.xi_ji[slots] = 0.0
    pairs.n_permanent = int((pairs.state == PERMANENT).sum())


def link_pairs(pairs, r, i, j):
    """Make pairs (i, j) bonds: ``d_eq = r_i + r_j``, ξ = 0; missing pairs and relations are created.

    Parameters
    ----------
    pairs : PairTable
    r : ndarray (N,)
        Radii (µm).
    i, j : int or array_like of int
        Sphere indices.

    Raises
    ------
    ValueError
        If a sphere is to be linked to itself.
    """
    i = np.atleast_1d(np.asarray(i, dtype=np.intp))
    j = np.atleast_1d(np.asarray(j, dtype=np.intp))
    if (i == j).any():
        k = int(np.flatnonzero(i == j)[0])
        raise ValueError(f"cannot link sphere {int(i[k])} to itself")
    if not len(i):
        return
    slots = pairs.ensure(i, j)
    pairs.open_relations(slots)
    set_bonds(pairs, slots, PERMANENT, r[pairs.i[slots]] + r[pairs.j[slots]])


def cut_slots(pairs, slots):
    """Cut the bonds among rows ``slots`` (state slip, ``d_eq`` = 0, ξ = 0); other rows are left.

    Parameters
    ----------
    pairs : PairTable
    slots : ndarray of int
    """
    set_bonds(pairs, slots[pairs.state[slots] == PERMANENT], SLIP, 0.0)


def cut_pairs(pairs, i, j):
    """Cut the bonds (i, j) (pairs not in the table are ignored).

    Parameters
    ----------
    pairs : PairTable
    i, j : int or array_like of int
    """
    slots = pairs.find(np.atleast_1d(i), np.atleast_1d(j))
    cut_slots(pairs, slots[slots >= 0])


def physical(x, y, Lx, Ly, i, j):
    """Whether each pair (i, j) does not cross the periodic boundary (raw differences below L/2).

    Parameters
    ----------
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly : float
        Cell (µm).
    i, j : ndarray of int

    Returns
    -------
    ndarray of bool
    """
    return inside_half_cell(x[i] - x[j], y[i] - y[j], Lx, Ly)


def permanent_pairs(pairs, x, y, Lx, Ly, physical_only=False):
    """Sphere indices ``(i, j)``, i < j, of the bonds (copies), optionally the physical ones only.

    Parameters
    ----------
    pairs : PairTable
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly : float
        Cell (µm).
    physical_only : bool, optional
        Only bonds not wrapping through the periodic boundary (:func:`physical`).

    Returns
    -------
    i, j : ndarray of int
    """
    m = pairs.state == PERMANENT
    i, j = pairs.i[m], pairs.j[m]
    if physical_only:
        keep = physical(x, y, Lx, Ly, i, j)
        i, j = i[keep], j[keep]
    return i.copy(), j.copy()


def link_relations(pairs, r):
    """Bond every current relation (``active`` row) of ``pairs``: ``d_eq = r_i + r_j``, ξ = 0.

    Parameters
    ----------
    pairs : PairTable
    r : ndarray (N,)
        Radii (µm).
    """
    m = np.flatnonzero(pairs.active)
    link_pairs(pairs, r, pairs.i[m], pairs.j[m])


def cut_line(pairs, x, y, Lx, Ly, shift, point, angle):
    """Cut every bond crossed by the infinite, non-periodic line through ``point`` with normal ``angle``.

    With ``n = (cos angle, sin angle)``, ``b = n·point``: bond i–j is cut when
    ``(n·x_i − b)·(n·(x_i + Δ_ij) − b) <= 0`` from either end (``Δ_ij``: Lees-Edwards minimum image).

    Parameters
    ----------
    pairs : PairTable
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly, shift : float
        Cell and Lees-Edwards offset (µm).
    point : sequence of float
        A point ``(x, y)`` of the line (µm).
    angle : float
        Angle of the line's normal to the x axis (rad).
    """
    slots = np.flatnonzero(pairs.state == PERMANENT)
    if not len(slots):
        return
    i, j = pairs.i[slots], pairs.j[slots]
    nu = (math.cos(angle), math.sin(angle))
    b = nu[0] * point[0] + nu[1] * point[1]
    xi, yi, xj, yj = x[i], y[i], x[j], y[j]
    dx, dy = min_image(xj - xi, yj - yi, Lx, Ly, shift)[:2]
    ex, ey = min_image(xi - xj, yi - yj, Lx, Ly, shift)[:2]
    si = nu[0] * xi + nu[1] * yi - b
    sj = nu[0] * xj + nu[1] * yj - b
    cut = (si * (nu[0] * (xi + dx) + nu[1] * (yi + dy) - b) <= 0) | \
          (sj * (nu[0] * (xj + ex) + nu[1] * (yj + ey) - b) <= 0)
    cut_slots(pairs, slots[cut])


def cut_top_bottom_edge(pairs, x, y, Lx, Ly, shift):
    """Cut every bond crossing y = 0 or y = Ly (:func:`cut_line` along both).

    Parameters
    ----------
    pairs : PairTable
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly, shift : float
        Cell and Lees-Edwards offset (µm).
    """
    cut_line(pairs, x, y, Lx, Ly, shift, (0, 0), math.pi / 2)
    cut_line(pairs, x, y, Lx, Ly, shift, (0, Ly), math.pi / 2)


def angle_ok(angle, avoid_degree):
    """False if the normal ``angle`` (rad, in [0, 2π)) lies within ``avoid_degree`` degrees of ±y.

    Parameters
    ----------
    angle : float
    avoid_degree : float
        Half-width of the rejected bands (degrees; <= 0: every angle is accepted).
    """
    if not avoid_degree > 0:
        return True
    w = avoid_degree / 180 * math.pi
    return not ((math.pi / 2 - w <= angle <= math.pi / 2 + w)
                or (3 * math.pi / 2 - w <= angle <= 3 * math.pi / 2 + w))


def random_line(rng, Lx, Ly, avoid_degree=0):
    """A random cut line: a random integer point of the cell, a uniform normal angle redrawn while
    :func:`angle_ok` rejects it.  Draws x, y, then the angles.

    Parameters
    ----------
    rng : numpy.random.Generator
    Lx, Ly : float
        Cell (µm).
    avoid_degree : float, optional
        As for :func:`angle_ok`.

    Returns
    -------
    point : tuple of int
        ``(x, y)`` in µm.
    angle : float
        The normal's angle (rad).

    Raises
    ------
    RuntimeError
        If :data:`MAX_ANGLE_DRAWS` angles were all rejected.
    """
    point = (int(rng.integers(0, int(Lx) + 1)), int(rng.integers(0, int(Ly) + 1)))
    for _ in range(MAX_ANGLE_DRAWS):
        angle = 2 * math.pi * rng.random()
        if angle_ok(angle, avoid_degree):
            return point, angle
    raise RuntimeError(f"no cut angle outside ±{avoid_degree}° of the vertical normal in {MAX_ANGLE_DRAWS} draws")


def seed_points(rng, n, Lx, Ly):
    """``n`` uniform random points of the cell: the Voronoi seeds (one block of draws).

    Parameters
    ----------
    rng : numpy.random.Generator
    n : int
        Number of points (none for n <= 0).
    Lx, Ly : float
        Cell (µm).

    Returns
    -------
    ndarray (max(n, 0), 2)
        The points (µm).
    """
    return rng.random((max(int(n), 0), 2)) * np.array([Lx, Ly])


def nearest_seeds(x, y, Lx, Ly, shift, points, edge_fuzziness, r_max, rng):
    """The seed of each sphere: least Lees-Edwards minimum-image distance plus ``edge_fuzziness·U·r_max``.

    U is uniform, drawn per sphere and seed even at ``edge_fuzziness = 0``; ties go to the lower seed.

    Parameters
    ----------
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly, shift : float
        Cell and Lees-Edwards offset (µm).
    points : ndarray (n, 2)
        Seed points (µm), n >= 1.
    edge_fuzziness : float
        Edge roughness in units of ``r_max``.
    r_max : float
        Largest radius (µm).
    rng : numpy.random.Generator

    Returns
    -------
    ndarray of int (N,)
    """
    dx, dy = min_image(points[None, :, 0] - x[:, None], points[None, :, 1] - y[:, None], Lx, Ly, shift)[:2]
    dist = np.sqrt(dx * dx + dy * dy)
    dist = dist + edge_fuzziness * rng.random(dist.shape) * r_max  # drawn even at 0
    return np.argmin(dist, axis=1)


def cut_between_seeds(pairs, seed):
    """Cut every bond between spheres of different seeds (a Voronoi cut).

    Parameters
    ----------
    pairs : PairTable
    seed : ndarray of int (N,)
        The seed of each sphere (:func:`nearest_seeds`).
    """
    slots = np.flatnonzero(pairs.state == PERMANENT)
    cut_slots(pairs, slots[seed[pairs.i[slots]] != seed[pairs.j[slots]]])


def voronoi_cut(pairs, x, y, Lx, Ly, shift, points, edge_fuzziness, r_max, rng):
    """Periodic Voronoi cut around ``points``: :func:`nearest_seeds`, then :func:`cut_between_seeds`.

    Nothing is drawn or cut without points or spheres.

    Parameters
    ----------
    pairs : PairTable
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly, shift : float
        Cell and Lees-Edwards offset (µm).
    points : ndarray (n, 2)
        Seed points (µm).
    edge_fuzziness, r_max : float
        As for :func:`nearest_seeds`.
    rng : numpy.random.Generator

    Returns
    -------
    ndarray of int (N,) or None
        The seed of each sphere, None where nothing was cut.
    """
    if not len(points) or not len(x):
        return None
    seed = nearest_seeds(x, y, Lx, Ly, shift, points, edge_fuzziness, r_max, rng)
    cut_between_seeds(pairs, seed)
    return seed


def particle_labels(pairs, x, y, Lx, Ly, physical_only=True):
    """The particle of each sphere: the lowest index of its connected component of the bond graph.

    Parameters
    ----------
    pairs : PairTable
    x, y : ndarray (N,)
        Positions (µm).
    Lx, Ly : float
        Cell (µm).
    physical_only : bool, optional
        Bonds through the periodic boundary do not connect (:func:`physical`).

    Returns
    -------
    ndarray of int (N,)
    """
    i, j = permanent_pairs(pairs, x, y, Lx, Ly, physical_only)
    return component_labels(len(x), i, j)


def particle_heights(labels, y, r):
    """Height ``max(y + r) − min(y − r)`` of each particle (µm), in the order of their lowest index.

    Parameters
    ----------
    labels : ndarray of int (N,)
        :func:`particle_labels`.
    y, r : ndarray (N,)
        Heights and radii (µm).

    Returns
    -------
    ndarray (number of particles,)
    """
    n = len(labels)
    top = np.full(n, -np.inf)
    bottom = np.full(n, np.inf)
    np.maximum.at(top, labels, y + r)
    np.minimum.at(bottom, labels, y - r)
    roots = np.flatnonzero(labels == np.arange(n))
    return top[roots] - bottom[roots]


def remove_non_essential_links(pairs, x, y, r, Lx, Ly, fraction, rng, physical_only=True, max_trials=1000):
    """Cut random links that do not split a particle (sphere first, then one of its links, as 1.0.2).

    A trial draws a sphere and one of its links (partners in increasing order); the link is cut
    when its spheres stay connected without it, else it is re-made a bond (``d_eq = r_i + r_j``,
    ξ = 0, as the reference's cut-and-relink).  Stops at ``fraction`` of the links or after
    ``max_trials`` consecutive failed trials.

    Parameters
    ----------
    pairs : PairTable
    x, y, r : ndarray (N,)
        Positions and radii (µm).
    Lx, Ly : float
        Cell (µm).
    fraction : float
        Target fraction of the links, >= 0.
    rng : numpy.random.Generator
    physical_only : bool, optional
        Only links not through the periodic boundary count (:func:`physical`).
    max_trials : int, optional

    Returns
    -------
    float
        The fraction of the links removed (0 without links).
    """
    n = len(x)
    i, j = permanent_pairs(pairs, x, y, Lx, Ly, physical_only)
    n_links = len(i)
    if n_links == 0:
        return 0
    adj = adjacency(n, i, j)
    failures = successes = 0
    target = fraction * n_links
    while failures < max_trials and successes < target:
        failures += 1
        p = int(rng.integers(0, n))
        cand = adj[p]
        if not cand:
            continue
        q = sorted(cand)[int(rng.integers(0, len(cand)))]
        if connected_without_edge(adj, p, q):
            adj[p].discard(q)
            adj[q].discard(p)
            cut_pairs(pairs, [p], [q])
            successes += 1
            failures = 0
        else:  # the reference cuts and re-establishes: d_eq = r_i + r_j, ξ = 0
            link_pairs(pairs, r, [p], [q])
    return successes / n_links


def join_isolated_spheres(pairs, x, y, r, Lx, Ly, rng, physical_only=True):
    """Bond each unbonded sphere (index order) to a random partner among its relations (may cross a cut).

    Parameters
    ----------
    pairs : PairTable
    x, y, r : ndarray (N,)
        Positions and radii (µm).
    Lx, Ly : float
        Cell (µm).
    rng : numpy.random.Generator
        One draw per unbonded sphere with relations.
    physical_only : bool, optional
        Only bonds not through the periodic boundary make a sphere bonded (:func:`physical`).
    """
    i, j = permanent_pairs(pairs, x, y, Lx, Ly, physical_only)
    bonded = np.zeros(len(x), bool)
    bonded[i] = True
    bonded[j] = True
    for p in np.flatnonzero(~bonded):
        if bonded[p]:
            continue
        slots = pairs.relations_of(p, bonds=False)          # relation-list order
        if not len(slots):
            continue
        s = slots[int(rng.integers(0, len(slots)))]
        q = int(pairs.j[s] if pairs.i[s] == p else pairs.i[s])
        link_pairs(pairs, r, [p], [q])
        if not physical_only or physical(x, y, Lx, Ly, np.array([p]), np.array([q]))[0]:
            bonded[p] = bonded[q] = True


def maximal_particle_height(labels, y, r):
    """Height of the tallest particle (µm; 0 without spheres): the largest of :func:`particle_heights`.

    Parameters
    ----------
    labels : ndarray of int (N,)
        :func:`particle_labels`.
    y, r : ndarray (N,)
        Heights and radii (µm).

    Returns
    -------
    float
    """
    return float(particle_heights(labels, y, r).max()) if len(labels) else 0
