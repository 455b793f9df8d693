"""Candidate pairs of a batch: their constants, normals, the scatter and the shear stresses.

Each function is a pure function of arrays: the per-candidate constants (:class:`PairConstants`,
whose term constants come from :func:`.terms.term_constants`), the normals of the candidates, the
scatter of pair forces to spheres and the two shear stresses G′/G″ need.  The force terms
themselves are in :mod:`.terms`.  Equations: reference manual eq.
S1-3 (torque split), S1-5/S1-6 (laws), S1-16 (external-force tensor), S1-19 (Love-Weber),
S1-22/S1-24 (torque terms, overall tensor); details in ``docs/engine.md``.

Shapes: P candidate pairs of the whole batch (the replicas' lists concatenated in replica
order), B replicas, B·N spheres.  Units: µm, µm/s, forces in mg·µm·s⁻² per m depth, torques
in mg·µm²·s⁻² per m depth (docs/parameters.md).

The arrays live on the state's backend (NumPy or CuPy, :mod:`.xp`); the index arrays of a
candidate set are built on the host from the per-replica lists and copied to the device once.
"""
__docformat__ = "numpy"


import functools

import numpy as np

from .state import spread
from .xp import SegmentSum, array_namespace, to_host
from . import laws
from .terms import TERM_ROWS, TermConstants, term_constants, term_rows

__all__ = ["PairConstants", "VisitConstants", "geometry_rows", "pair_rows", "splice_arrays", "scatter", "replica_sums", "pair_roles", "shear_rows",
           "shear_from_sums", "shear_stresses"]

#: force·length scale of the stress tensors (mg·µm·s⁻²·µm → N·m per m depth) and torque scale
CF_CL = 1e-18
CT = 1e-18


class PairConstants:
    """Per-candidate constants of a batch, valid until the candidate lists change.

    Built from the per-replica lists and the per-replica constants of the state; ``rep`` is
    each pair's replica, ``ai``/``aj`` the global sphere rows.  The bond-dependent constants are
    added by :meth:`set_bonds` (until then their rows of :attr:`f` hold no defined value: the block
    is allocated without a fill, ≈ 0.2 ms of a rebuild at N = 10,000).

    The constants are stored in three stacked blocks of P columns, one per kind: :attr:`f`
    (floats, rows :data:`FLOAT_ROWS`), :attr:`i` (sphere and replica indices, :data:`INT_ROWS`,
    with its host copy :attr:`i_host`) and :attr:`b` (flags, :data:`BOOL_ROWS`).  Each named
    attribute (``C.ri``, ``C.mu``, …) is a view of its row, and assigning one writes into the
    row, so the blocks always hold every constant and a rebuild of some replicas' lists
    (:meth:`splice`) is a few concatenations of blocks instead of one per constant
    (docs/engine.md, "Caches").

    Parameters
    ----------
    s : BatchState
        The batch; its ``pairs`` (one :class:`~particleShear.engine.state.ReplicaPairs` per
        replica), radii, boxes and constants are read.
    offsets : ndarray of int (B + 1,)
        Start of each replica's candidates in the flat arrays (``offsets[b] … offsets[b+1] − 1``),
        ``offsets[0] = 0`` and ``offsets[B] = P``.
    replicas : sequence of int, optional
        Build the constants of these replicas only, in this order (their candidates
        concatenated; ``offsets`` then describes that concatenation), for :meth:`splice` (which
        reads the blocks; the index arrays of the scatter and the sums are then the spliced
        batch's, not built here).
    state, d_eq : ndarray (P,), optional
        The candidates' states and equilibrium distances: every constant is set at once
        (:meth:`set_bonds`); default: the rows of :func:`geometry_rows` only, the others by a later
        :meth:`set_bonds`.
    fill : callable, optional
        As :meth:`set_bonds`.
    """

    #: rows of the float block :attr:`f`: radii and weights ``r/(r_i + r_j)``, box and half box (µm),
    #: then the constants of :meth:`set_bonds`
    FLOAT_ROWS = ("ri", "rj", "d0", "w_i", "w_j", "Lx", "Ly", "hy", "hx", "k", "c", "d_law", "d_cap", "a_lin", "a_div",
                  "d_eq", "a_tens", "ratio_c", "nu", "k_t", "nu_t", "mu", "fc_inf")
    #: the rows set from :func:`~particleShear.engine.terms.term_constants` (the attributes of a
    #: :class:`~particleShear.engine.terms.TermConstants` but ``form``)
    TERM_ROWS = TERM_ROWS
    #: form of the compressive law: c is a constant per candidate, so the general blend
    form = laws.BLEND
    #: rows of the index block :attr:`i` (and of its host copy :attr:`i_host`): replica, sphere rows i and j
    INT_ROWS = ("rep", "ai", "aj")
    #: rows of the flag block :attr:`b`: bond, transient candidate
    BOOL_ROWS = ("perm", "trans")
    #: the per-candidate arrays (length P), in the order the replicas' candidates are concatenated
    #: (``perm_code`` = 2·perm, int8, follows from ``perm``)
    PER_PAIR = INT_ROWS + FLOAT_ROWS + BOOL_ROWS + ("perm_code",)
    #: host copies of the index arrays (rows of :attr:`i_host`; the same arrays on NumPy)
    HOST_PER_PAIR = ("rep_host", "ai_host", "aj_host")
    #: the blocks, each (rows, P)
    BLOCKS = ("f", "i", "b", "i_host")
    #: the candidates' image period counts of the last step ``(Ly·k_y, k_y, Lx·k_x, k_x)``, reused by
    #: :meth:`~particleShear.engine.step.BatchEngine.step` while they still place every separation
    #: in its interval; None until set, and gone with these constants at a rebuild
    images = None
    #: the constants seen by the visit from j (:meth:`set_visits`) where some replica's spheres have
    #: parameters of their own; None: every visit sees the constants of this object
    Kj = None
    #: attribute → (block, row)
    _ROWS = {**{n: ("f", k) for k, n in enumerate(FLOAT_ROWS)}, **{n: ("i", k) for k, n in enumerate(INT_ROWS)},
             **{n: ("b", k) for k, n in enumerate(BOOL_ROWS)},
             **{n: ("i_host", k) for k, n in enumerate(HOST_PER_PAIR)}}

    def __init__(self, s, offsets, replicas=None, state=None, d_eq=None, fill=None):
        be = self.backend = s.backend
        xp = s.xp
        replicas = np.arange(s.B) if replicas is None else np.asarray(replicas)
        pairs = [s.pairs[b] for b in replicas]
        N = s.N
        # index rows on the host (from the per-replica lists), then once on the device
        rep = np.repeat(replicas, [len(p.i) for p in pairs])
        P = len(rep)
        i_host = np.empty((3, P), dtype=np.intp)
        i_host[0] = rep
        i_host[1] = np.concatenate([p.i for p in pairs]) + rep * N
        i_host[2] = np.concatenate([p.j for p in pairs]) + rep * N
        self._set_blocks(xp.empty((len(self.FLOAT_ROWS), P)), be.asarray(i_host), xp.zeros((2, P), dtype=bool), i_host)
        if len(replicas) == s.B:
            self._index(s, offsets)
        else:       # (the rebuilt replicas' constants, read by splice only: the batch's index arrays are the spliced ones')
            self.offsets, self.P = offsets, P
        if state is not None:
            self.set_bonds(s, state, d_eq, fill)
            return
        box = spread(s.xp.stack((s.Lx, s.Ly)), self.rep, s.B)
        for k, row in enumerate(geometry_rows(s.r[self.i[1]], s.r[self.i[2]], box[0], box[1])):
            self.f[k] = row

    @property
    def w(self):
        """The lever fractions ``(w_i, w_j)`` as one (2, P) view of the float block (eq. S1-3)."""
        return self.f[3:5]

    def _set_blocks(self, f, i, b, i_host):
        """Take the blocks and bind every named attribute to a view of its row."""
        d = self.__dict__
        d.update(f=f, i=i, b=b, i_host=i_host)
        for name, (block, k) in self._ROWS.items():
            d[name] = d[block][k]
        d["perm_code"] = self.perm.view(np.int8) * np.int8(2)

    def __setattr__(self, name, value):
        """Assigning a named constant writes into its row of the block (the block stays complete)."""
        where = self._ROWS.get(name)
        if where is None or where[0] not in self.__dict__:
            object.__setattr__(self, name, value)
            return
        self.__dict__[where[0]][where[1]] = value
        if name == "perm":
            self.__dict__["perm_code"] = self.perm.view(np.int8) * np.int8(2)

    def _index(self, s, offsets):
        """Sizes and index arrays that follow from ``ai``, ``aj`` and the replicas' segments."""
        be = self.backend
        self.offsets = offsets
        self.P = self.i_host.shape[1]
        # the replicas that have candidates and where their segments start, for replica_sums: each
        # such segment ends where the next one starts (empty replicas in between have no rows)
        self.B = len(offsets) - 1
        self.seg_rep = np.flatnonzero(offsets[1:] > offsets[:-1])
        self.seg_starts = offsets[:-1][self.seg_rep]
        # (the scatter of the pair forces, read by the array step only, is built on its first read: scatter)
        self.spheres = s.B * s.N
        self.replica_sum = None       # pair rows → replica sums on a device without ordered reduceat
        if be.ordered_reductions:
            self.seg_rep_b, self.seg_starts_b = be.asarray(self.seg_rep), be.asarray(self.seg_starts)
        elif self.B == s.B:           # the whole batch (not the rebuilt replicas alone)
            self.replica_sum = SegmentSum(self.rep_host, s.B, be)

    @functools.cached_property
    def scatter_idx(self):
        """The rows ``(ai, aj, ai + nb, aj + nb, ai + 2nb, aj + 2nb)`` of the three components (F_x,
        F_y, torque) of the pair forces, ``nb`` = B·N spheres; built on its first read and kept
        with these constants (dropped with them at the one invalidation point, a rebuild).

        Only the array step reads it (:func:`scatter_forces`); the compiled backend sums its pair
        forces inside its kernels, so building it with every set of candidates (each hand-back of a
        compiled block) cost that backend ≈ 0.3 ms per set at N = 10,000 for nothing."""
        pair_rows = self.i_host[1:3]          # (ai, aj)
        return (pair_rows + (self.spheres * np.arange(3))[:, None, None]).reshape(-1)

    @functools.cached_property
    def scatter(self):
        """Pair forces → sphere totals (:attr:`scatter_idx`): one bincount over the three components
        on NumPy; on CuPy a padded gather over (ai, aj), applied to each component's row (a third of
        the layout to build).  Built on its first read, as :attr:`scatter_idx`."""
        be, nb = self.backend, self.spheres
        if be.ordered_reductions:
            return SegmentSum(self.scatter_idx, 3 * nb, be)
        return SegmentSum(self.i_host[1:3].reshape(-1), nb, be)

    @classmethod
    def splice(cls, s, old, new, segments, offsets):
        """The constants of the batch after some replicas' lists were rebuilt: the segments of the
        other replicas are copied from ``old``, those of the rebuilt ones from ``new``.

        Every constant is an elementwise function of its own pair and replica, so the result is
        the same number as a full rebuild; it costs one concatenation per block.

        Parameters
        ----------
        s : BatchState
            The batch.
        old : PairConstants
            Constants of the whole batch before the rebuild.
        new : PairConstants
            Constants of the rebuilt replicas only (``replicas=`` of the constructor), with bonds set.
        segments : list of tuple
            ``(from_new, lo, hi)`` in replica order: the columns ``lo:hi`` of ``new`` (if
            ``from_new``) or of ``old`` that make up the batch, see :func:`splice_arrays`.
        offsets : ndarray of int (B + 1,)
            Segments of the replicas in the spliced arrays.

        Returns
        -------
        PairConstants
        """
        C = cls.__new__(cls)
        C.backend = old.backend
        f, i, b = (splice_arrays(getattr(old, n), getattr(new, n), segments) for n in ("f", "i", "b"))
        i_host = i if old.i_host is old.i else splice_arrays(old.i_host, new.i_host, segments)
        C._set_blocks(f, i, b, i_host)
        C._index(s, offsets)
        return C

    @classmethod
    def from_blocks(cls, s, f, i, b, offsets):
        """The constants of a batch from blocks already written: the compiled backend's block, whose
        rebuilds write each replica's new candidates and their constants in its own columns
        (:func:`~particleShear.engine.numba_step.run_block`), hands them back this way.

        Parameters
        ----------
        s : BatchState
            The batch (on a host backend).
        f, i, b : ndarray
            The blocks (rows :data:`FLOAT_ROWS`, :data:`INT_ROWS`, :data:`BOOL_ROWS`; P columns), taken as they are.
        offsets : ndarray of int (B + 1,)
            Segments of the replicas.

        Returns
        -------
        PairConstants
        """
        C = cls.__new__(cls)
        C.backend = s.backend
        C._set_blocks(f, i, b, i)
        C._index(s, offsets)
        return C

    def set_bonds(self, s, state, d_eq, fill=None):
        """Set every constant of the candidates from their states (bonds never change during the measurement).

        The rows of :data:`FLOAT_ROWS` are :func:`pair_rows` of each candidate (the geometry, and the
        constants of the central law, eq. S1-5a/b, S1-6, of the tensile law of bonds, the permanent
        ratios and the viscosities, the tangential constants and the Coulomb bound offset, ``inf``
        for bonds, seen by the visit from i), the flags ``perm``, ``trans`` follow from ``state``:
        :func:`pair_rows` on the arrays, one row at a time, or ``fill``.

        Parameters
        ----------
        s : BatchState
            The batch whose radii, boxes and per-replica constants (``k, nu, k_t, nu_t, mu`` and
            ``c, prc, prt, keep``, or the spheres' own :attr:`~particleShear.engine.state.BatchState.visit`)
            are gathered to the candidates.
        state : ndarray of int8 (P,)
            State of each candidate; 2 (:data:`~particleShear.engine.state.PERMANENT`) marks a bond.
        d_eq : ndarray (P,)
            Equilibrium distance of each candidate (µm; used for bonds only).
        fill : callable, optional
            ``fill(f, b, i, s, state, d_eq)`` writes the blocks :attr:`f` and :attr:`b` in one pass
            from the same :func:`pair_rows` (the compiled backend's
            :func:`~particleShear.engine.numba_step.constant_rows`); default NumPy's rows.
        """
        if fill is not None:
            fill(self.f, self.b, self.i, s, state, d_eq)
            self.__dict__["perm_code"] = self.perm.view(np.int8) * np.int8(2)
            return
        perm = state == 2
        self.perm = perm
        self.trans = ~perm
        rep = spread(s.xp.stack((s.Lx, s.Ly, s.k, s.nu, s.k_t, s.nu_t, s.mu)), self.rep, s.B)
        # the visiting sphere's own values; where a replica's spheres share them, its values directly
        own = s.per_replica_parameters(self.rep) if s.visit is None else s.visit[:, self.ai]
        rows = pair_rows(s.r[self.ai], s.r[self.aj], rep[0], rep[1], perm, d_eq, rep[2], own[0], rep[3], rep[4], rep[5],
                         rep[6], own[1], own[2], own[3])
        for n, row in enumerate(rows):
            self.f[n] = row

    def _visit(self, s, spheres, d_eq, rows=False):
        """The :class:`~particleShear.engine.terms.TermConstants` of the candidates as seen from the sphere
        rows ``spheres`` (``ai`` or ``aj``): the per-replica constants of each candidate's replica and the
        visiting sphere's own c, permanent ratios and kept viscosities, gathered at once.

        Parameters
        ----------
        s : BatchState
            The batch (its per-replica constants and ``visit`` rows).
        spheres : ndarray of int (P,)
            The visiting sphere's row of each candidate.
        d_eq : ndarray (P,)
            Equilibrium distance of each candidate (µm; read on bonds).
        rows : bool, default False
            The constants are only written into the rows of the blocks: in a batch of one its
            per-replica values are not gathered (:func:`~particleShear.engine.state.spread`, (1,)
            arrays that broadcast to the same numbers).  Otherwise every constant that is not a
            number is an array over the candidates.

        Returns
        -------
        TermConstants
        """
        per_replica = s.xp.stack((s.k, s.nu, s.k_t, s.nu_t, s.mu))
        rep = spread(per_replica, self.rep, s.B) if rows else per_replica[:, self.rep]
        # the visiting sphere's own values; where a replica's spheres share them, its values directly
        own = (s.per_replica_parameters(self.rep) if rows else s.per_replica_parameters()[:, spheres]) \
            if s.visit is None else s.visit[:, spheres]
        return term_constants(self.d0, self.perm, d_eq, rep[0], own[0], rep[1], rep[2], rep[3], rep[4], own[1], own[2],
                              own[3])

    def set_visits(self, s):
        """Set :attr:`Kj`, the constants of the visit from j, when spheres have parameters of their own.

        1.0.2 evaluates each relation once from each sphere, with that sphere's c, permanent ratios
        and kept viscosities; where the two spheres' values differ, the central force on j is the
        law of j's visit and the tangential rule takes j's ``k_t``, ``ν_t`` for its second visit
        (:func:`~particleShear.engine.terms.tangential_term`).  Without :attr:`~particleShear.engine.state.BatchState.visit`
        every visit sees this object's constants (``Kj`` None).  Called with every new set of
        constants (the one invalidation point, a rebuild of the candidate lists).

        Parameters
        ----------
        s : BatchState
            The batch (its ``visit`` rows and per-replica constants).
        """
        self.Kj = None if s.visit is None else VisitConstants(self._visit(s, self.aj, self.d_eq), self)


# (pair_rows returns the rows in this order)
assert PairConstants.FLOAT_ROWS[:11] == ("ri", "rj", "d0", "w_i", "w_j", "Lx", "Ly", "hy", "hx", "k", "c")
assert PairConstants.FLOAT_ROWS[11:] == TERM_ROWS


class VisitConstants(TermConstants):
    """The :class:`~particleShear.engine.terms.TermConstants` of one visit of a batch's candidates,
    with what the laws of a force phase read besides them (:func:`~particleShear.engine.phase_laws.force_phase_laws`):
    the candidates' bonds, replicas and radii, and a place for their prepared law arguments.

    Parameters
    ----------
    K : TermConstants
        The constants of the visit.
    C : PairConstants
        The candidates they belong to (``perm``, ``rep``).
    """

    def __init__(self, K, C):
        TermConstants.__init__(self, **{name: getattr(K, name) for name in TermConstants.__slots__})
        self.perm, self.rep, self.ri, self.rj = C.perm, C.rep, C.ri, C.rj


def geometry_rows(ri, rj, Lx, Ly):
    """The geometric constants of candidates, the first rows of :data:`PairConstants.FLOAT_ROWS` (pure:
    arrays or numbers): radii, contact distance ``d0 = r_i + r_j``, lever fractions ``r/d0`` (eq.
    S1-3), box and half box.

    Parameters
    ----------
    ri, rj : ndarray or float
        Radii (µm).
    Lx, Ly : ndarray or float
        Box of the candidate's replica (µm).

    Returns
    -------
    tuple
        ``(r_i, r_j, d0, w_i, w_j, Lx, Ly, hy, hx)`` (µm but the fractions).
    """
    d0 = ri + rj
    return ri, rj, d0, ri / d0, rj / d0, Lx, Ly, Ly / 2, Lx / 2


def pair_rows(ri, rj, Lx, Ly, perm, d_eq, k, c, nu, k_t, nu_t, mu, prc, prt, keep):
    """Every constant of candidates as seen by the visit from i, in the order of
    :data:`PairConstants.FLOAT_ROWS` (pure: arrays or numbers): :func:`geometry_rows`, ``k``, ``c``
    and :func:`~particleShear.engine.terms.term_rows` at ``d0 = r_i + r_j``.

    Parameters
    ----------
    ri, rj, Lx, Ly : ndarray or float
        As :func:`geometry_rows` (µm).
    perm : ndarray of bool or bool
        Which candidates are bonds.
    d_eq : ndarray or float
        Equilibrium distance of a bond (µm).
    k, c, nu, k_t, nu_t, mu, prc, prt, keep : ndarray or float
        The model parameters the visit sees (:func:`~particleShear.engine.terms.term_constants`).

    Returns
    -------
    tuple
        The 23 values of :data:`PairConstants.FLOAT_ROWS`.
    """
    geometry = geometry_rows(ri, rj, Lx, Ly)
    return geometry + (k, c) + term_rows(geometry[2], perm, d_eq, k, c, nu, k_t, nu_t, mu, prc, prt, keep)


def splice_arrays(old, new, segments):
    """Concatenate along the last axis the columns ``lo:hi`` of ``new`` or ``old`` named by ``segments``.

    Parameters
    ----------
    old, new : ndarray (…, P_old) and (…, P_new)
        Per-candidate arrays of the batch before a rebuild and of the rebuilt replicas.
    segments : list of tuple
        ``(from_new, lo, hi)``: take ``new[..., lo:hi]`` if ``from_new`` else ``old[..., lo:hi]``.

    Returns
    -------
    ndarray (…, Σ (hi − lo))
    """
    xp = array_namespace(old, new)
    return xp.concatenate([(new if from_new else old)[..., lo:hi] for from_new, lo, hi in segments], axis=-1)


def normals(dx, dy, d, rep, rng):
    """Unit normals ``n = D/d``; at ``d = 0`` a random direction from the replica's own generator.

    Drawing from the generator of the pair's own replica keeps a replica's trajectory
    independent of its batch (one seed per replica).

    Parameters
    ----------
    dx, dy : ndarray (P,)
        Pair vectors (µm).
    d : ndarray (P,)
        Their lengths (µm, ≥ 0).
    rep : ndarray of int (P,) or None
        Replica of each pair (index into ``rng``); None: every pair is of replica 0.
    rng : sequence of numpy.random.Generator
        One generator per replica; one uniform number ``u`` is drawn per pair at ``d = 0``,
        in pair order, and the normal is ``(cos 2πu, sin 2πu)``.

    Returns
    -------
    nx, ny : ndarray (P,)
        Components of the unit normal from i towards j.
    """
    xp = array_namespace(d)
    zero = d == 0
    if not to_host(zero.any(), "d = 0"):
        return dx / d, dy / d
    safe = xp.where(zero, 1.0, d)
    nx, ny = dx / safe, dy / safe
    # the draws happen on the host, pair by pair in list order, from each pair's own replica's generator
    where = to_host(xp.flatnonzero(zero), "d = 0")
    reps = [0] * len(where) if rep is None else to_host(rep, "d = 0")[where]
    theta = [2 * np.pi * rng[int(b)].random() for b in reps]
    idx = where if isinstance(d, np.ndarray) else xp.asarray(where)
    nx[idx] = xp.asarray(np.array([np.cos(t) for t in theta]))
    ny[idx] = xp.asarray(np.array([np.sin(t) for t in theta]))
    return nx, ny


def scatter(C, n_spheres, fx_i, fy_i, tq_i, tq_j, fx_j=None, fy_j=None):
    """Pair forces to per-sphere totals: ``+F`` on i, ``−F`` on j, torques on both (eq. S1-3).

    One ``bincount`` over ``(ai, aj)`` of each component (offset by ``k·n_spheres``): each sphere's
    sum runs over its own replica's pairs in list order, whatever else the batch holds.  Returns
    the (3, n_spheres) block (F_x, F_y, torque).

    Parameters
    ----------
    C : PairConstants
        The candidates (``scatter_idx`` built from ``ai``, ``aj``).
    n_spheres : int
        Number of sphere rows, B·N.
    fx_i, fy_i : ndarray (P,)
        Pair force on sphere i (mg·µm·s⁻² per m depth); j receives its negative.
    tq_i, tq_j : ndarray (P,)
        Torques on i and on j (mg·µm²·s⁻² per m depth): ``d·F_T`` split in proportion to the
        radii (eq. S1-3).
    fx_j, fy_j : ndarray (P,), optional
        The pair force of j's own visit (spheres with parameters of their own,
        :meth:`PairConstants.set_visits`): j receives ``−(fx_j, fy_j)``.  Default: ``fx_i, fy_i``.

    Returns
    -------
    ndarray (3, n_spheres)
        Per-sphere totals F_x, F_y (mg·µm·s⁻² per m depth) and torque (mg·µm²·s⁻² per m depth).
    """
    if fx_j is None:
        fx_j, fy_j = fx_i, fy_i
    w = array_namespace(fx_i).concatenate((fx_i, -fx_j, fy_i, -fy_j, tq_i, tq_j))
    if C.backend.ordered_reductions:
        return C.scatter(w).reshape(3, n_spheres)
    return C.scatter(w.reshape(3, -1))       # rows (F_x, F_y, torque) of (on i, on j) each


def replica_sums(C, W):
    """Σ of each row of ``W`` over each replica's own candidates: a (rows, B) array.

    The candidates of a replica are contiguous (``C.offsets``), so each sum is one reduction over
    that replica's own segment, in list order (NumPy's pairwise summation of the segment): it
    depends only on the replica's own pairs, never on the rest of the batch, and it costs one
    pass over ``W`` (a ``bincount`` over the replica index adds every pair of a replica into the
    same bin one after the other, which serialises on that bin: 244 against 11 µs for three
    sums over 19,600 pairs at B = 32).

    Parameters
    ----------
    C : PairConstants
        The candidates (``seg_rep``, ``seg_starts``: the replicas with candidates and where
        their segments start).
    W : ndarray (rows, P)
        Weights per candidate pair, any unit.

    Returns
    -------
    ndarray (rows, B)
        ``out[r, b] = Σ_{pairs p of replica b} W[r, p]`` (0 for a replica without candidates).
    """
    if C.replica_sum is not None:      # a device: the padded gather of SegmentSum
        return C.replica_sum(W)
    xp = array_namespace(W)
    out = xp.zeros((W.shape[0], C.B))
    if C.P:
        out[:, C.seg_rep_b] = xp.add.reduceat(W, C.seg_starts_b, axis=1)
    return out


def pair_roles(mob_i, mob_j, shifted):
    """Where the force of each pair is counted in the stress tensors (eqs. S1-16, S1-19): the one rule.

    A pair is internal when both spheres are mobile and it does not act through the boundary (its
    minimum image removed no period); otherwise each mobile sphere of the pair receives the pair's
    force as an external force.  An immobile sphere receives nothing.

    Parameters
    ----------
    mob_i, mob_j : ndarray of bool (P,) or bool
        The pair's spheres are mobile (True: all mobile).
    shifted : ndarray of bool (P,)
        The minimum image of the pair removed a period.

    Returns
    -------
    internal, ext_i, ext_j : ndarray of bool (P,)
        The pair is internal; i, j receive an external entry.
    """
    internal = mob_i & mob_j & ~shifted
    return internal, mob_i & ~internal, mob_j & ~internal


def shear_stresses(C, B, yc, roles, active, dy, fx_i, dF, V, fx_j=None):
    """τ_internal = −σ_xy of the overall tensor and τ_surface = −σ_xy of the external-force tensor (Pa).

    ``σ_LW,xy = (1/V) Σ_internal F_x,i (y_i − y_j)`` (eq. S1-19) with ``y_i − y_j = −D_y`` for
    an unshifted pair; ``σ_Tint,xy = −(1/V) Σ_internal d·F_T/2`` (eq. S1-22, ``dF = d·F_T``);
    the centrifugal term has no xy part.  ``σ_ext,xy = −(1/V) Σ_external F_x (y_target − Ly/2)``
    (eq. S1-16), with the internal and external pairs of :func:`pair_roles`.  ``yc`` is ``y − Ly/2``
    per sphere.  Sums per replica over its own pairs in list order (:func:`replica_sums`).

    Parameters
    ----------
    C : PairConstants
        The candidates.
    B : int
        Number of replicas.
    yc : ndarray (B·N,)
        Height of each sphere above its cell's centre line, ``y − Ly/2`` (µm).
    roles : tuple of three ndarray of bool (P,)
        ``(internal, ext_i, ext_j)`` of each candidate (:func:`pair_roles`).
    active : ndarray of bool (P,)
        Relations (touching, or a bond): only they carry forces.
    dy : ndarray (P,)
        y component of the minimum-image pair vector ``D`` (µm).
    fx_i : ndarray (P,)
        x component of the pair force on i (mg·µm·s⁻² per m depth).
    dF : ndarray (P,)
        ``d·F_T``, the internal torque of each pair (mg·µm²·s⁻² per m depth).
    V : ndarray (B,)
        Cell area of each replica, ``Lx·Ly·1e-12`` (m², i.e. m³ per m depth).
    fx_j : ndarray (P,), optional
        x component of the pair force of j's own visit (j receives ``−fx_j``; spheres with
        parameters of their own): an internal pair counts the mean of the two visits (1.0.2
        registers each visit with half its force), an external entry of j its own visit's force.
        Default: ``fx_i``.

    Returns
    -------
    tau_internal, tau_surface : ndarray (B,)
        Shear stresses ``−σ_xy`` of the overall and of the external-force tensor (Pa, eq. S1-25).
    """
    xp = array_namespace(fx_i)
    internal, ext_i, ext_j = roles
    rows = xp.empty((3, fx_i.shape[0]))
    rows[0], rows[1], rows[2] = shear_rows(internal, ext_i, ext_j, active, yc[C.ai], yc[C.aj], dy, fx_i, dF, fx_j)
    sums = replica_sums(C, rows)
    return shear_from_sums(sums[0], sums[1], sums[2], V)


def shear_rows(internal, ext_i, ext_j, active, yc_i, yc_j, dy, fx_i, dF, fx_j=None):
    """The three pair rows of the shear stresses (pure; summed per replica by :func:`shear_stresses`).

    ``F_x,i·D_y`` of an internal relation (``= −F_x,i (y_i − y_j)``), ``d·F_T`` of an internal
    relation, and ``F_x·(y_target − Ly/2)`` of the external entries — the products of the
    tensors' xy entries (:mod:`particleShear.engine.stress`).  Numbers or arrays; the compiled
    step (:mod:`particleShear.engine.numba_step`) calls it pair by pair.

    Parameters
    ----------
    internal, ext_i, ext_j : ndarray of bool or bool
        The roles of :func:`pair_roles`.
    active : ndarray of bool or bool
        Relations.
    yc_i, yc_j : ndarray or float
        Heights of i and j above the centre line (µm).
    dy : ndarray or float
        ``D_y`` (µm).
    fx_i : ndarray or float
        x force on i (mg·µm·s⁻² per m depth).
    dF : ndarray or float
        ``d·F_T``.
    fx_j : ndarray or float, optional
        x force of j's own visit (default ``fx_i``).

    Returns
    -------
    tuple of three ndarray or float
    """
    internal = internal & active
    ext_j = ext_j & active
    lever_j = yc_j * ext_j
    lever = yc_i * (ext_i & active)
    lever -= lever_j
    fx_lw = fx_i if fx_j is None else (fx_i + fx_j) * 0.5
    surface = fx_i * lever
    if fx_j is not None:
        # F_i at i and −F_j at j: F_i·lever + (F_i − F_j)·(y_j − Ly/2), so a pair with F_j = F_i gives
        # the same number as without fx_j (a batch's replica equals its single run)
        surface += (fx_i - fx_j) * lever_j
    return (fx_lw * internal) * dy, dF * internal, surface


def shear_from_sums(lw, tint, surf, V):
    """τ_internal and τ_surface (Pa, eq. S1-25) from per-replica sums of the pair rows.

    The one formula of the shear stresses: :func:`shear_stresses` and the tensors' xy entries
    (:mod:`particleShear.engine.stress`) both finish with it.

    Parameters
    ----------
    lw : ndarray (B,)
        Σ_internal F_x,i·D_y (mg·µm²·s⁻² per m depth).
    tint : ndarray (B,)
        Σ_internal d·F_T (same unit).
    surf : ndarray (B,)
        Σ_external F_x·(y_target − Ly/2) (same unit).
    V : ndarray (B,)
        Cell area of each replica (m²).

    Returns
    -------
    tau_internal, tau_surface : ndarray (B,)
        ``−σ_xy`` of the overall and of the external-force tensor (Pa).
    """
    sigma_all = -lw * (CF_CL / V) - tint * (CT / V) / 2
    sigma_ext = -surf * (CF_CL / V)
    return -sigma_all, -sigma_ext
