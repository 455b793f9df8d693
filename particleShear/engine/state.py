"""The state of a batch of replicas as explicit arrays (docs/engine.md, "Runs").

Spheres of replica b occupy rows ``b·N … b·N + N − 1`` of every per-sphere array; per-replica
values (box, strain, rate, model constants) are arrays of length B and are gathered to spheres
or pairs where a kernel needs them.  Pairs are kept per replica (:class:`PairTable`, sorted by
``(i, j)``) and concatenated in replica order into the flat arrays a step works on.

The arrays live on the state's backend (:attr:`BatchState.backend`, NumPy by default, CuPy with
``backend="cupy"``; :mod:`.xp`); the per-replica pair lists and the random generators stay on the
host (the candidate search and the draws at ``d = 0`` run there).

Units: µm, s, mg per m depth (reference units, docs/parameters.md).
"""
__docformat__ = "numpy"

import numpy as np

from .predictor import Predictor
from .xp import get_backend, select, to_host

__all__ = ["STICK", "SLIP", "PERMANENT", "synced_history", "PairTable", "ReplicaPairs", "BatchState", "PER_SPHERE_PARAMETERS",
           "PER_REPLICA_PARAMETERS", "spread"]

STICK, SLIP, PERMANENT = 0, 1, 2

#: per-sphere model parameters of the documented spheres, in the order of :attr:`BatchState.visit`'s rows:
#: a pair's visit from i sees sphere i's values, its visit from j sphere j's (1.0.2's per-visit rule)
PER_SPHERE_PARAMETERS = ("central_repulsion_coefficient", "permanent_ratio_central", "permanent_ratio_tangential",
                         "keep_viscosity_coefficients_constant")
#: the per-replica arrays of :class:`BatchState` that hold these parameters when a replica's spheres share them
PER_REPLICA_PARAMETERS = ("c", "prc", "prt", "keep")


def spread(values, rep, B):
    """Per-replica values onto the rows of the spheres or candidates: ``values[..., rep]``.

    For a batch of one, ``values`` itself: its (…, 1) columns broadcast to the same numbers
    without a gather (for arithmetic with, or assignment to, arrays over the rows).

    Parameters
    ----------
    values : ndarray (…, B)
        One value per replica along the last axis (any unit).
    rep : ndarray of int (R,)
        The replica of each row.
    B : int
        Replicas of the batch.

    Returns
    -------
    ndarray (…, R), or ``values`` (…, 1) when ``B == 1``
    """
    return values if B == 1 else values[..., rep]


def _copied(a, target):
    """``a`` (an array of any backend) copied onto ``target``: a copy also where both are the host's."""
    host = to_host(a, "state")
    return target.asarray(np.array(host, copy=True) if host is a else host)


def _key(i, j):
    return (np.asarray(i, dtype=np.int64) << 32) | np.asarray(j, dtype=np.int64)


def _merge(k, extra):
    """The sorted union of the sorted arrays ``k`` and ``extra`` that share no value: one pass, no sort
    (``np.insert`` at the sorted positions, without its overhead on small arrays)."""
    at = np.searchsorted(k, extra) + np.arange(len(extra))
    out = np.empty(len(k) + len(extra), dtype=k.dtype)
    rest = np.ones(len(out), dtype=np.bool_)
    rest[at] = False
    out[at] = extra
    out[rest] = k
    return out


#: keys (both arrays) from which :func:`_positions` merges instead of searching (measured crossover
#: ≈ 2,000: 10 µs either way)
_MERGE_MIN = 2000


def _positions(a, v, merge_min=_MERGE_MIN):
    """``np.searchsorted(a, v)`` (left side) of the sorted array ``v`` in the sorted array ``a``, by one merge.

    A stable sort of ``v`` followed by ``a`` merges two sorted runs (O(n) in NumPy's timsort, about
    a third of the binary searches' time at 35,000 keys); ``v[m]`` lands after the m elements of
    ``v`` before it and the elements of ``a`` below it, so its place in the merge less m is its
    position in ``a``.  Below :data:`_MERGE_MIN` keys in all the binary searches are faster.

    Parameters
    ----------
    a, v : ndarray of int (n,), (m,)
        Sorted keys (repeats allowed).
    merge_min : int, default :data:`_MERGE_MIN`
        Keys in all from which it merges (a parameter so that compiled code may choose otherwise;
        the result is the same either way).

    Returns
    -------
    ndarray of intp (m,)
        Index of the first element of ``a`` not below each ``v[m]``.
    """
    if len(a) + len(v) < merge_min:
        return np.searchsorted(a, v)
    order = np.argsort(np.concatenate((v, a)), kind="mergesort")     # (stable: NumPy's "stable")
    return np.flatnonzero(order < len(v)) - np.arange(len(v))


def _increasing(k, strict=True):
    """True if the 1-D array ``k`` is sorted (strictly: also without repeats); O(n), no sort."""
    if len(k) < 2:
        return True
    return bool((k[1:] > k[:-1]).all()) if strict else bool((k[1:] >= k[:-1]).all())


def carried_rows(old_key, kept, k, merge_min=_MERGE_MIN):
    """The keys of a new candidate set and the old row each of them carries: the history merge of
    :meth:`PairTable.replace`.

    The new keys ``k`` (any order, repeats allowed) are sorted and made unique; the kept old keys
    that ``k`` misses (bonds stretched beyond the search reach, relations) are merged in, in O(n)
    (a union would sort the whole set anew, ≈ 60 ms of a rebuild at N = 100,000); each resulting
    key reads its old row, a key new to the table the row ``len(old_key)`` (the zero appended after
    the old rows: one gather per field instead of a gather and a scatter, ≈ 0.3 ms of a rebuild at
    N = 10,000).  Written in the array operations Numba compiles as they stand: the compiled
    backend runs this very function compiled (:func:`~particleShear.engine.numba_step.carried`).

    Parameters
    ----------
    old_key : ndarray of int64 (n,)
        The table's keys ``i << 32 | j``, sorted and unique.
    kept : ndarray of int64 (m,)
        Old keys to keep although ``k`` may miss them, sorted (a subset of ``old_key``).
    k : ndarray of int64 (p,)
        The new candidates' keys.
    merge_min : int, default :data:`_MERGE_MIN`
        As :func:`_positions`.

    Returns
    -------
    key : ndarray of int64
        The sorted unique keys of the new table.
    src : ndarray of int64
        The old row of each key, ``len(old_key)`` for a pair new to the table.
    """
    if not _increasing(k):          # (a search's pairs come sorted and unique: no sort)
        k = np.sort(k)
        if len(k) > 1 and np.count_nonzero(k[1:] == k[:-1]):
            k = np.unique(k)
    if len(kept):
        at = _positions(k, kept, merge_min)
        found = at < len(k)
        found[found] = k[at[found]] == kept[found]
        if not found.all():
            extra = kept[~found]
            if _increasing(extra, False):     # (the table's keys are sorted: no sort)
                extra = extra[np.concatenate((np.ones(1, np.bool_), extra[1:] != extra[:-1]))]
            else:
                extra = np.unique(extra)
            k = _merge(k, extra)
    n = len(old_key)
    pos = _positions(old_key, k, merge_min)
    pos_c = np.minimum(pos, max(n - 1, 0))
    had = (pos < n) & (old_key[pos_c] == k) if n else np.zeros(len(k), np.bool_)
    return k, np.where(had, pos_c, n).astype(np.int64)


def carried_fields(src, state, d_eq, active, birth, xi):
    """The history of a new candidate set: each field's old row ``src`` (:func:`carried_rows`), the
    zeros of a pair new to the table (``src = len(state)``: inactive, sticking, ξ = 0, no number).
    Written in the array operations Numba compiles as they stand (one gather per field, after one
    zero appended; :func:`~particleShear.engine.numba_step.rebuild` runs it compiled).

    Parameters
    ----------
    src : ndarray of int64 (C,)
        The old row of each new candidate.
    state, d_eq, active, birth : ndarray (n,) of int8, float, bool, int64
        The old table's fields.
    xi : ndarray (2, n)
        The old table's ξ (µm).

    Returns
    -------
    tuple of ndarray
        ``state, d_eq, active, birth, xi`` of the new candidates (new arrays).
    """
    xi_new = np.empty((2, len(src)))        # (C-contiguous, as the engine's ξ must be: row by row)
    for row in range(2):
        xi_new[row] = np.concatenate((xi[row], np.zeros(1)))[src]
    return (np.concatenate((state, np.zeros(1, np.int8)))[src], np.concatenate((d_eq, np.zeros(1)))[src],
            np.concatenate((active, np.zeros(1, np.bool_)))[src], np.concatenate((birth, np.zeros(1, np.int64)))[src],
            xi_new)


def synced_history(state, xi, active, birth):
    """The history a candidate list keeps of the engine's flat rows: what the pair table holds of a
    candidate (pure: arrays or numbers).

    A candidate that is no relation (not ``active``) keeps no ξ and no number and sticks, unless it
    is a bond, which keeps its state.  The engine writes its flat history back this way
    (:meth:`~particleShear.engine.contacts.Contacts.sync_down`, on arrays) and the compiled backend's
    rebuild inside a block reads it this way before the history merge (on the numbers of each
    candidate, :mod:`particleShear.engine.numba_step`), so both merge the same history.

    Parameters
    ----------
    state : ndarray of int8 or int
        The candidate's state (:data:`STICK`, :data:`SLIP`, :data:`PERMANENT`).
    xi : ndarray (…, P) or float
        A component of ξ, or both (µm).
    active : ndarray of bool or bool
        Whether the candidate is a relation.
    birth : ndarray of int64 or int
        The relation's number.

    Returns
    -------
    tuple
        ``state, xi, birth`` as the table keeps them (``active`` is kept as it is).
    """
    return select(active | (state == PERMANENT), state, STICK), select(active, xi, 0.0), select(active, birth, 0)


class PairTable:
    """Candidate pairs of one ensemble (one replica): sphere indices ``i < j`` in canonical ``(i, j)``
    order and their history, as a structure of arrays.

    ``state`` (stick / slip / permanent), ``xi`` (2, C: ξ_ij, ξ_ji in µm), ``d_eq`` (µm, bonds),
    ``active`` (a relation of the reference: touching at the last neighbour update, or a bond) and
    ``birth``, the creation number of each relation (the order of ``sphere.neighbors``), with the
    counter of the next number (:attr:`birth_count`).  The one pair table of the package: the documented
    ensembles hold one (a copy: ``ens.pair_table``), and the engine keeps one per replica
    (:attr:`BatchState.pairs`; a state on an ensemble's own memory,
    :func:`particleShear.base.engine_adapter.state_of_ensembles`, keeps the
    ensemble's own).  The arguments are converted (not validated) to the dtypes below.

    Parameters
    ----------
    i, j : array_like of int (C,), optional
        Sphere indices of each candidate, ``i < j`` (put in ``(i, j)`` order with their fields when
        given in another order); default none.
    state : array_like of int (C,), optional
        :data:`STICK`, :data:`SLIP` or :data:`PERMANENT` per candidate (default stick).
    xi : array_like (2, C) or (2·C,), optional
        Tangential displacement histories ξ_ij (row 0) and ξ_ji (row 1), µm (default 0).
    d_eq : array_like (C,), optional
        Equilibrium distance of each bond (µm; unused for transient contacts; default 0).
    active : array_like of bool (C,), optional
        The candidate is a relation (touching at the last update, or a bond; default False).
    birth : array_like of int (C,), optional
        Creation number of each relation (unused where ``active`` is False); default 0.
    """

    FIELDS = ("i", "j", "state", "xi_ij", "xi_ji", "d_eq", "active", "birth")
    #: the arrays of a table (one value per candidate; ``xi`` one column per candidate)
    ARRAYS = ("i", "j", "key", "state", "xi", "d_eq", "active", "birth")

    def __init__(self, i=(), j=(), state=None, xi=None, d_eq=None, active=None, birth=None):
        self.i = np.asarray(i, dtype=np.intp).reshape(-1)
        self.j = np.asarray(j, dtype=np.intp).reshape(-1)
        C = len(self.i)
        self.key = _key(self.i, self.j)
        self.state = np.zeros(C, np.int8) if state is None else np.asarray(state, dtype=np.int8)
        self.xi = np.zeros((2, C)) if xi is None else np.asarray(xi, dtype=float).reshape(2, -1)
        self.d_eq = np.zeros(C) if d_eq is None else np.asarray(d_eq, dtype=float)
        self.active = np.zeros(C, bool) if active is None else np.asarray(active, dtype=bool)
        self.birth = np.zeros(C, np.int64) if birth is None else np.asarray(birth, dtype=np.int64)
        if C > 1 and not (self.key[1:] >= self.key[:-1]).all():      # the lookups need the canonical order
            order = np.argsort(self.key, kind="stable")
            for name in self.ARRAYS:
                setattr(self, name, getattr(self, name)[..., order])
        self.n_permanent = int((self.state == PERMANENT).sum())
        self._births = 0
        self.version = 0

    def __len__(self):
        return len(self.i)

    def copy(self, rows=None):
        """An independent table of the candidates ``rows`` (a boolean mask or indices; default all),
        with the same counter of creation numbers.

        Parameters
        ----------
        rows : array_like, optional
            Which candidates to keep.

        Returns
        -------
        PairTable
        """
        rows = slice(None) if rows is None else rows
        out = PairTable(self.i[rows].copy(), self.j[rows].copy(), self.state[rows].copy(), self.xi[:, rows].copy(),
                        self.d_eq[rows].copy(), self.active[rows].copy(), self.birth[rows].copy())
        out._births = self._births
        return out

    def assign(self, other):
        """Make this table hold copies of ``other``'s candidates, history and counter, in place (so
        every reference to this table sees them); its version advances.

        Parameters
        ----------
        other : PairTable
        """
        for name in self.ARRAYS:
            setattr(self, name, getattr(other, name).copy())
        self.n_permanent = int((self.state == PERMANENT).sum())
        self._births = other._births
        self.version += 1

    @property
    def birth_count(self):
        """How many creation numbers were handed out (int): the number the next relation gets.

        :meth:`next_births` and :meth:`open_relations` advance it; an engine that numbered this
        table's relations in its own counter hands it back with :meth:`resume_births`.
        """
        return self._births

    def resume_births(self, n):
        """Go on numbering relations from ``n``: the counter an engine kept for this table while
        its steps numbered the relations that formed (the next relation gets ``n``).

        Parameters
        ----------
        n : int
            The next creation number.
        """
        self._births = int(n)

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

    def open_relations(self, slots):
        """Make the pairs at ``slots`` relations; those that were none get the next creation numbers in order.

        Parameters
        ----------
        slots : ndarray of int
            Rows of the table.

        Returns
        -------
        ndarray of int
            The rows that became relations now (their state and ξ are the caller's to set).
        """
        slots = np.atleast_1d(slots)
        new = slots[~self.active[slots]]
        if len(new):
            self.birth[new] = self.next_births(len(new))
            self.active[new] = True
        return new

    def close_relations(self, slots):
        """End the relations at ``slots`` that are not bonds: no longer active, both histories ξ = 0.

        Parameters
        ----------
        slots : ndarray of int or of bool
            Rows (or a mask of rows) of the table.
        """
        m = np.zeros(len(self.i), bool)
        m[slots] = True
        m &= self.active & (self.state != PERMANENT)
        self.active[m] = False
        self.xi[:, m] = 0.0

    def relations_of(self, p, bonds=True):
        """Rows of the relations of sphere ``p`` in creation order (the order of its ``neighbors``).

        Parameters
        ----------
        p : int
            Sphere index.
        bonds : bool
            Include the bonds (False: the transient relations only).
        """
        m = self.active & ((self.i == p) | (self.j == p))
        if not bonds:
            m &= self.state != PERMANENT
        slots = np.flatnonzero(m)
        return slots[np.argsort(self.birth[slots], kind="stable")]

    def replace(self, i, j, keep_existing=False, keep_relations=True, rows=None):
        """Make (i, j) the candidate set, keeping the history of the pairs present before.

        Bonds are always kept, also where (i, j) misses them (a bond stretched beyond the search
        reach), and so are relations (active) with ``keep_relations``; with ``keep_existing`` every
        existing row is kept and (i, j) are added.  A pair new to the table starts inactive,
        sticking, with ξ = 0.

        Parameters
        ----------
        i, j : array_like of int
            Sphere indices of the new candidate pairs, in either order (duplicates allowed).
        keep_existing : bool
            Keep every existing row instead of only the active and permanent ones.
        keep_relations : bool, default True
            Keep the relations that (i, j) misses (the engine's lists keep only bonds: a relation
            out of its reach ended).
        rows : callable, optional
            ``rows(old_key, kept, k)`` → ``(key, src)``: :func:`carried_rows` (default), or the same
            function compiled (:func:`~particleShear.engine.numba_step.carried`, the compiled backend's).
        """
        old_key = self.key
        k = _key(np.minimum(i, j), np.maximum(i, j))
        # rows to keep that the new candidates miss (e.g. bonds stretched beyond the search reach)
        bond = self.state == PERMANENT
        kept = old_key if keep_existing else old_key[np.flatnonzero((self.active | bond) if keep_relations else bond)]
        k, src = (rows or carried_rows)(old_key, kept, k)
        self.adopt(k, *carried_fields(src, *self.fields()))

    def fields(self):
        """The history of the candidates as :func:`carried_fields` takes it: ``state`` (int8), ``d_eq``
        (float), ``active`` (bool), ``birth`` (int64), ``xi`` (2, C), C-contiguous.

        Returns
        -------
        tuple of ndarray
        """
        return (np.ascontiguousarray(self.state, dtype=np.int8), np.ascontiguousarray(self.d_eq, dtype=float),
                np.ascontiguousarray(self.active, dtype=np.bool_), np.ascontiguousarray(self.birth, dtype=np.int64),
                np.ascontiguousarray(np.asarray(self.xi, dtype=float).reshape(2, -1)))

    def adopt(self, key, state, d_eq, active, birth, xi, i=None, j=None):
        """Make the sorted unique keys ``key`` (``i << 32 | j``) the candidates, with the history given
        (:func:`carried_fields`); the version advances.

        Parameters
        ----------
        key : ndarray of int64 (C,)
        state, d_eq, active, birth, xi : ndarray
            One value (``xi``: one column) per key.
        i, j : ndarray of intp (C,), optional
            The sphere indices of the keys where the caller has them already (taken as they are,
            not copied); default: read from ``key``.
        """
        self.i = (key >> 32).astype(np.intp) if i is None else i
        self.j = (key & 0xFFFFFFFF).astype(np.intp) if j is None else j
        self.state, self.d_eq, self.active, self.birth, self.xi = state, d_eq, active, birth, xi
        self.key = key
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


#: the engine's name of a replica's pair list (the same class)
ReplicaPairs = PairTable


class BatchState:
    """Arrays of B replicas of N spheres each (see the module docstring).

    Attributes
    ----------
    B, N : int
        Replicas and spheres per replica.
    x, y, vx, vy, omega, phi, r, m, inertia : ndarray (B·N,)
        Sphere state (µm, µm/s, 1/s, rad, µm, mg/m, mg·µm²/m); ``x, y`` are the rows of ``pos``
        (2, B·N) and ``vx, vy, omega`` those of ``vel`` (3, B·N).
    Lx, Ly, gamma, rate, t : ndarray (B,)
        Box (µm), strain γ, strain rate γ̇ (1/s) and clock (s) of each replica; the engine writes
        ``gamma``, ``rate``, ``t`` and ``mu`` in place (they may be the documented ensembles'
        cells, :meth:`use_replica_rows`).
    k, nu, k_t, nu_t, mu, c, prc, prt, keep : ndarray (B,)
        Ensemble constants of each replica (the values a step of its ensemble uses).
    pairs : list of PairTable
        Candidate pairs of each replica (NumPy arrays, on the host), each with its counter of
        creation numbers: the host view of :attr:`contacts`, as its last write-back left it
        (:meth:`~particleShear.engine.contacts.Contacts.sync_down`).
    contacts : Contacts or None
        The candidates of every replica side by side with their relation history and the
        bookkeeping of their lists (:class:`~particleShear.engine.contacts.Contacts`), on the
        state's backend: started anew by each engine built on the state; None before (and in a
        state made by :meth:`concat`, :meth:`to_backend` or unpickling, whose tables carry the history).
    predictor : Predictor
        The velocity Verlet predictor, the half kick of the last step
        (:class:`~particleShear.engine.predictor.Predictor`; its ``half`` None before a Verlet
        step): continued by an engine built on the state, kept by :meth:`to_backend` and
        pickling, joined by :meth:`concat` (the rules: :mod:`particleShear.engine.predictor`).
    rng : list of numpy.random.Generator
        Each replica's own generator (random normals at ``d = 0``).
    applying_shear : bool
        Plates active (spheres overlapping ``y = 0`` or ``y = Ly`` are immobile).
    visit : ndarray (4, B·N) or None
        The parameters of :data:`PER_SPHERE_PARAMETERS` per sphere (c, permanent ratios, kept
        viscosities) when the spheres of some replica do not share them, else None (then the
        per-replica ``c, prc, prt, keep`` hold them; with ``visit`` they hold sphere 0's values).
        Each visit of a pair sees its own sphere's values (:meth:`~particleShear.engine.forces.PairConstants.set_visits`).
    law : str or None
        Central law of every replica, a name of :data:`~particleShear.engine.laws.LAWS` (one per
        batch), or None: the central law of ``callback_laws`` (looked up once per force phase,
        :func:`~particleShear.engine.phase_laws.force_phase_laws`).
    law_params : ndarray (n, B)
        The law's parameters per replica, in the order of its ``parameters`` (n = 0 for None).
    callback_laws : callable or None
        ``callback_laws(C, central)`` → ``(central or None, tensile or None)``: the law callbacks
        of the documented classes, given by the adapter that built the state from ensembles
        (:func:`particleShear.base.callbacks.callback_phase_laws`); None: the built-in laws
        (:func:`~particleShear.engine.phase_laws.force_phase_laws`).
    backend : Backend
        Where the arrays live (:func:`~particleShear.engine.xp.get_backend`).
    xp : module
        Its array namespace (``numpy`` or ``cupy``).

    Parameters
    ----------
    B : int
        Number of replicas (≥ 0).
    N : int
        Spheres per replica (≥ 0).  Every array starts at zero (the caller fills them, e.g.
        :func:`particleShear.base.engine_adapter.state_from_ensembles`).
    backend : str or Backend, default "auto"
        Array backend of the state (``"numpy"``, ``"numba"``, ``"cupy"``, a registered one, or
        ``"auto"``: :func:`~particleShear.engine.xp.resolve_backend`).

    Raises
    ------
    ValueError
        For an unknown backend, ``"numba"`` without Numba, or ``"cupy"`` without CuPy or a CUDA device.
    """

    #: names of the per-sphere (B·N,) and per-replica (B,) arrays, in the order :meth:`concat` copies them
    SPHERE_ARRAYS = ("x", "y", "vx", "vy", "omega", "phi", "r", "m", "inertia", "fx", "fy", "torque")
    REPLICA_ARRAYS = ("Lx", "Ly", "gamma", "rate", "t", "k", "nu", "k_t", "nu_t", "mu", "c", "prc", "prt", "keep")

    #: per-sphere parameters (see above); a class default, so a state pickled without it loads as shared
    visit = None
    #: the flat candidate list and its history (:class:`~particleShear.engine.contacts.Contacts`),
    #: made by the engine built on this state; None until then (a class default: a state pickled
    #: without it loads with None)
    contacts = None

    def __init__(self, B, N, backend="auto"):
        self.backend = get_backend(backend)
        xp = self.xp = self.backend.xp
        self.B = int(B)
        self.N = int(N)
        n = self.B * self.N
        # positions and velocities as row views of two blocks: one gather fetches all rows of a pair side
        self.pos = xp.zeros((2, n))
        self.vel = xp.zeros((3, n))
        self.frc = xp.zeros((3, n))            # (F_x, F_y, torque) of the last force phase
        self._bind_views()
        for name in ("phi", "r", "m", "inertia"):
            setattr(self, name, xp.zeros(n))
        for name in self.REPLICA_ARRAYS:
            setattr(self, name, xp.zeros(self.B))
        self.rep = xp.repeat(xp.arange(self.B), self.N)
        self.pairs = [None] * self.B
        self.rng = [None] * self.B
        self.applying_shear = True
        self.law = None
        self.law_params = xp.zeros((0, self.B))
        self.callback_laws = None
        self.visit = None
        self.predictor = Predictor()

    def __getstate__(self):
        """Pickle and copy by backend name (a module is not picklable); the row views are rebound on load.

        The contacts are left out (the copy has None): its pair tables carry the history as the
        last write-back left it (an engine's ``flush``), and an engine built on the copy starts anew.
        The predictor is kept (an engine built on the copy continues it)."""
        state = dict(self.__dict__)
        state["backend"] = self.backend.name
        del state["xp"]
        state.pop("contacts", None)       # (engine bookkeeping; the tables are the carried view)
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        if "predictor" not in state:        # (a state pickled before the predictor was the state's)
            self.predictor = Predictor()
        self.backend = get_backend(state["backend"])
        self.xp = self.backend.xp
        self._bind_views()

    def _bind_views(self):
        """Row views of the position, velocity and force blocks (indexing, not iteration: no host read)."""
        self.x, self.y = self.pos[0], self.pos[1]
        self.vx, self.vy, self.omega = self.vel[0], self.vel[1], self.vel[2]
        self.fx, self.fy, self.torque = self.frc[0], self.frc[1], self.frc[2]

    def use_rows(self, pos, vel, frc, phi, r, m, inertia):
        """Make the given arrays the state's per-sphere arrays (views of memory the caller keeps, e.g.
        the rows of an ensemble's state block): what a step writes, the caller's arrays hold.

        Parameters
        ----------
        pos : ndarray (2, B·N)
            Positions (x, y), µm.
        vel : ndarray (3, B·N)
            Velocities (vx, vy in µm/s, ω in 1/s).
        frc : ndarray (3, B·N)
            Forces and torques of the last force phase (F_x, F_y, torque).
        phi, r, m, inertia : ndarray (B·N,)
            Orientation (rad), radius (µm), mass (mg/m) and moment of inertia (mg·µm²/m).

        Raises
        ------
        ValueError
            If a shape does not match the state's B·N rows.
        """
        n = self.B * self.N
        for name, a, rows in (("pos", pos, 2), ("vel", vel, 3), ("frc", frc, 3), ("phi", phi, None), ("r", r, None),
                              ("m", m, None), ("inertia", inertia, None)):
            want = (n,) if rows is None else (rows, n)
            if tuple(a.shape) != want:
                raise ValueError(f"{name} has shape {tuple(a.shape)}: it must be {want} (B·N = {n} rows)")
        self.pos, self.vel, self.frc = pos, vel, frc
        self.phi, self.r, self.m, self.inertia = phi, r, m, inertia
        self._bind_views()

    def use_replica_rows(self, **rows):
        """Make the given arrays the state's per-replica arrays of those names (views of memory the
        caller keeps, e.g. the documented ensembles' replica cells): what a step writes there (the
        clock, the strain, a rate or μ set through the engine), the caller's arrays hold.

        Parameters
        ----------
        **rows : ndarray (B,)
            By name of :attr:`REPLICA_ARRAYS` (e.g. ``t``, ``gamma``, ``rate``, ``mu``), float.

        Raises
        ------
        ValueError
            For another name or a shape other than (B,).
        """
        for name, a in rows.items():
            if name not in self.REPLICA_ARRAYS or tuple(a.shape) != (self.B,):
                raise ValueError(f"{name} of shape {tuple(a.shape)} is not a per-replica array: allowed the "
                                 f"names {self.REPLICA_ARRAYS}, shape ({self.B},)")
        self.__dict__.update(rows)

    def to_backend(self, backend):
        """This state with its arrays copied to ``backend`` (the same object if it is there already).

        Pair lists and generators are shared (they stay on the host); the copy has no contacts
        (None: an engine built on it starts them from the tables) and a copy of the predictor.

        Parameters
        ----------
        backend : str or Backend
            The target backend.

        Returns
        -------
        BatchState
        """
        target = get_backend(backend)
        if target is self.backend:
            return self
        out = object.__new__(type(self))
        out.__dict__.update(self.__dict__)
        out.backend, out.xp = target, target.xp
        out.contacts = None         # (the flat list lives on the source's backend; the tables are shared)
        out.predictor = self.predictor.on(target)
        for name in ("pos", "vel", "frc", "phi", "r", "m", "inertia", "rep", "law_params") + self.REPLICA_ARRAYS:
            out.__dict__[name] = _copied(getattr(self, name), target)
        if self.visit is not None:
            out.visit = _copied(self.visit, target)
        out._bind_views()
        return out

    @classmethod
    def concat(cls, states):
        """One state holding the replicas of ``states`` in order (equal N).

        Parameters
        ----------
        states : sequence of BatchState
            States with the same N; their arrays and pair lists are copied, their generators
            shared; the result has no contacts (None), so the states' engines must have written
            their history into the tables first (``flush``); their predictors are joined
            (:meth:`~particleShear.engine.predictor.Predictor.joined`).

        Returns
        -------
        BatchState
            ``sum(st.B)`` replicas; plates active only if they are in every state.

        Raises
        ------
        ValueError
            If the states differ in N or in backend.
        """
        Ns = {st.N for st in states}
        if len(Ns) != 1:
            raise ValueError(f"states have N = {sorted(Ns)}: a batch needs one N")
        backends = {st.backend.name for st in states}
        if len(backends) != 1:
            raise ValueError(f"states live on the backends {sorted(backends)}: a batch needs one backend")
        laws = {st.law for st in states}
        if len(laws) != 1:
            raise ValueError(f"states have the laws {sorted(map(str, laws))}: a batch needs one law")
        out = cls(sum(st.B for st in states), Ns.pop(), backend=states[0].backend)
        xp = out.xp
        for name in cls.SPHERE_ARRAYS + cls.REPLICA_ARRAYS:
            getattr(out, name)[...] = xp.concatenate([getattr(st, name) for st in states])
        out.pairs = [p.copy() for st in states for p in st.pairs]     # the engine changes its lists in place
        out.rng = [g for st in states for g in st.rng]
        out.applying_shear = all(st.applying_shear for st in states)
        out.law = laws.pop()
        given = {st.callback_laws for st in states}
        if len(given) != 1:
            raise ValueError("states have different law callbacks: a batch needs one source of laws")
        out.callback_laws = given.pop()
        out.law_params = xp.concatenate([st.law_params for st in states], axis=1)
        if any(st.visit is not None for st in states):
            out.visit = xp.concatenate([st.visit_rows() for st in states], axis=1)
        out.predictor = Predictor.joined([st.predictor for st in states], [st.B * st.N for st in states], xp)
        return out

    def per_replica_parameters(self, rep=None):
        """The per-replica parameters ``c, prc, prt, keep`` on every sphere row (or on the rows of
        the replica index ``rep``, e.g. a batch's candidates, through :func:`spread`).

        Parameters
        ----------
        rep : ndarray of int, optional
            The replica of each row (default: :attr:`rep`, the sphere rows).

        Returns
        -------
        ndarray (4, B·N) or (4, len(rep))
            For a given ``rep`` in a batch of one, (4, 1): the values, which broadcast to its rows.
        """
        values = self.xp.stack([getattr(self, name) for name in PER_REPLICA_PARAMETERS])
        return values[:, self.rep] if rep is None else spread(values, rep, self.B)

    def visit_rows(self):
        """The parameters of :data:`PER_SPHERE_PARAMETERS` of every sphere: :attr:`visit`, or the
        per-replica values on every row when the spheres of each replica share them.

        Returns
        -------
        ndarray (4, B·N)
        """
        return self.per_replica_parameters() if self.visit is None else self.visit

    def replica(self, b):
        """Row slice of replica ``b`` in the per-sphere arrays.

        Parameters
        ----------
        b : int
            Replica index (0 … B−1; not checked).

        Returns
        -------
        slice
            Rows ``b·N … b·N + N − 1``.
        """
        return slice(b * self.N, (b + 1) * self.N)
