"""The flat pair list of a batch with its history, and the bookkeeping of its Verlet lists.

A :class:`Contacts` is part of the state (:attr:`~particleShear.engine.state.BatchState.contacts`):
the candidates of every replica side by side with their constants, the relations and their
history (state, ξ, creation numbers) as the steps leave them, and what decides when a replica's
list is rebuilt.  The engine (:class:`~particleShear.engine.step.BatchEngine`) and its compiled
step (:mod:`.numba_step`) read and replace these arrays; the per-replica pair tables of the state
(:attr:`~particleShear.engine.state.BatchState.pairs`) are their host view, written by
:meth:`Contacts.sync_down` (the engine's ``flush`` and ``pairs_of``, and before a rebuild).

Life cycle: an engine built on a state starts new contacts (:meth:`Contacts.__init__`): no list
yet (``C`` None), every list due, the creation counters read from the tables.  So its first step
rebuilds every list from the tables and carries their history over, whatever an earlier engine
left there (which must have written its history back first, e.g. with ``flush``).  One engine
steps a state at a time: an earlier engine on the same state sees the contacts of the newest one.
A state made by :meth:`~particleShear.engine.state.BatchState.concat`,
:meth:`~particleShear.engine.state.BatchState.to_backend` or unpickling has no contacts (None):
its tables carry the history, and the engine built on it starts new ones.

Shapes: B replicas, B·N sphere rows, P candidates (every replica's in replica order; replica b's
are ``C.offsets[b] … C.offsets[b + 1] − 1``).  Units µm, s.
"""
__docformat__ = "numpy"

import numpy as np

from .state import PERMANENT, synced_history
from .xp import to_host

__all__ = ["Contacts"]


class Contacts:
    """The candidates of a batch, their relations and history, and the bookkeeping of their lists.

    Made by each :class:`~particleShear.engine.step.BatchEngine` on its state (see the module
    docstring for the life cycle); arrays on the state's backend unless marked host.

    Parameters
    ----------
    state : BatchState
        The batch (its B, N, backend and pair tables are read; nothing is kept of it).

    Attributes
    ----------
    C : PairConstants or None
        The per-candidate constants of every replica's list side by side
        (:class:`~particleShear.engine.forces.PairConstants`: replica and sphere rows, radii, boxes,
        law, bond, viscous and friction constants; the candidate set's caches hang on it); None
        before the first step builds the lists (or after :meth:`reload`).  Rebuilt by the engine's
        ``neighbours`` and by a compiled block's rebuilds, the one invalidation point.
    state_p : ndarray of int8 (P,)
        State of each candidate: :data:`~.state.STICK`, :data:`~.state.SLIP` or
        :data:`~.state.PERMANENT` (bond).  None while ``C`` is None (so are the next three).
    xi : ndarray (2, P)
        Tangential displacement histories ξ_ij (row 0) and ξ_ji (row 1) of each candidate (µm);
        0 where it is no relation.
    active : ndarray of bool (P,)
        The candidate is a relation (touching at the last force phase, or a bond).
    birth : ndarray of int64 (P,)
        Creation number of each relation (the order of ``sphere.neighbors``), counted per replica
        when the engine numbers relations (``numbers_relations``), else 0.
    next_birth : ndarray of int64 (B,)
        Per replica, the number the next relation gets (read from the tables' ``birth_count`` at
        the start, handed back to them by :meth:`sync_down`).
    free_p : None, True or ndarray of bool (P,)
        Per candidate, whether its replica has no tangential force (μ = 0 and no bond): None when
        no replica is such, True when all are (:meth:`refresh_free`).
    u : ndarray (2, B·N)
        Displacement of each sphere relative to the shear flow since its replica's list was built (µm).
    u_max : ndarray (B,)
        Running maximum of ``|u|`` over each replica's spheres (µm).
    strain : ndarray (B,)
        ``Σ |γ̇| dt`` of each replica's images since its list was built (dimensionless).
    bound : ndarray (B,)
        The Verlet bound of each replica (µm, :func:`~.neighbours.verlet_bound`); its list is due
        when it reaches the skin (inf at the start).
    need : ndarray of bool (B,), host
        Per replica, its list is rebuilt at the next force phase (all at the start).
    rebuilds : ndarray of int64 (B,), host
        How many times each replica's list was built since these contacts started.
    """

    def __init__(self, state):
        xp, be, B, N = state.xp, state.backend, state.B, state.N
        self.C = None
        self.state_p = self.xi = self.active = self.birth = None
        self.free_p = None
        self.next_birth = be.asarray(np.array([p.birth_count for p in state.pairs], dtype=np.int64))
        self.u = xp.zeros((2, B * N))
        self.u_max = xp.zeros(B)
        self.strain = xp.zeros(B)
        self.bound = xp.full(B, np.inf)
        self.need = np.ones(B, bool)
        self.rebuilds = np.zeros(B, dtype=np.int64)

    @property
    def history(self):
        """``(state_p, xi, active, birth)``, the relation history of the candidates (the arrays themselves)."""
        return self.state_p, self.xi, self.active, self.birth

    def take(self, C, history):
        """Make ``C`` the candidates and ``history`` = ``(state_p, xi, active, birth)`` their history
        (the arrays themselves, not copies).

        Parameters
        ----------
        C : PairConstants
            The candidates' constants (:attr:`C`).
        history : tuple of ndarray
            As :attr:`history`, P columns each.
        """
        self.C = C
        self.state_p, self.xi, self.active, self.birth = history

    def use_history(self, state_p, xi, active, birth):
        """Make the given arrays the candidates' history in place of the present ones (the same shapes
        and dtypes; e.g. a pair table's own arrays, for a batch of one whose table is the list).

        Parameters
        ----------
        state_p : ndarray of int8 (P,)
        xi : ndarray (2, P)
        active : ndarray of bool (P,)
        birth : ndarray of int64 (P,)
            As the attributes of the same names.
        """
        self.state_p, self.xi, self.active, self.birth = state_p, xi, active, birth

    def reload(self, state):
        """Forget the candidates: every list is built anew from the state's tables at the next step,
        with the tables' creation counters (a table edited since it was written: the lists are
        then its own).

        Parameters
        ----------
        state : BatchState
            The batch these contacts belong to.
        """
        self.C = None
        self.state_p = self.xi = self.active = self.birth = None
        self.need[:] = True
        self.next_birth[...] = state.backend.asarray(np.array([p.birth_count for p in state.pairs], dtype=np.int64))

    def restart(self, due, state):
        """The bookkeeping of the replicas whose lists were just built: displacement, strain and
        bound from 0; no list due.

        Parameters
        ----------
        due : ndarray of bool (B,)
            The rebuilt replicas, on the state's backend.
        state : BatchState
            The batch these contacts belong to (its namespace and sphere replicas are read).
        """
        where = state.xp.where
        self.bound = where(due, 0.0, self.bound)
        self.u = where(due[state.rep], 0.0, self.u)
        self.u_max = where(due, 0.0, self.u_max)
        self.strain = where(due, 0.0, self.strain)
        self.need = np.zeros(state.B, bool)

    def refresh_free(self, state):
        """Set :attr:`free_p`, which replicas have no tangential force (μ = 0 and no bond), per
        candidate (after a rebuild and a change of μ; nothing before the lists are built).

        Parameters
        ----------
        state : BatchState
            The batch (its μ and pair tables are read).
        """
        if self.C is None:
            return
        mu = to_host(state.mu, "state") if not isinstance(state.mu, np.ndarray) else state.mu
        free = mu == 0
        for b in np.flatnonzero(free):          # (only the replicas without friction are looked at)
            free[b] = not (state.pairs[b].state == PERMANENT).any()
        if not free.any():
            self.free_p = None
        elif free.all():
            self.free_p = True
        else:
            self.free_p = state.backend.asarray(free)[self.C.rep]

    def sync_down(self, state, replicas=None, written=False):
        """Write the history of the candidates back into the state's pair tables (of ``replicas``;
        all by default), with each replica's creation counter; each table's version advances.

        A candidate that is no relation is written as the classes' tables keep it: sticking (a bond
        keeps its state), without ξ or number (:func:`~.state.synced_history`).  On a device the
        rows of those replicas are gathered there and read on the host at once.  Nothing while
        :attr:`C` is None.

        Parameters
        ----------
        state : BatchState
            The batch these contacts belong to.
        replicas : iterable of int, optional
            The replicas whose tables are written.
        written : bool, default False
            Their tables hold this history already (written by the caller as this method writes
            it, e.g. a compiled block's hand-back, :func:`~particleShear.engine.numba_step._settle`):
            only the creation counters and versions are brought up to date.
        """
        C, be = self.C, state.backend
        if C is None:
            return
        which = list(range(state.B)) if replicas is None else list(replicas)
        if not written:
            self._write_history(state, which)
        counters = to_host(self.next_birth, "pair history")
        for b in which:      # (each table's creation counter and version, written or not here)
            p = state.pairs[b]
            p.resume_births(counters[b])
            p.version += 1

    def _write_history(self, state, which):
        """Write the history of the candidates of the replicas ``which`` into their pair tables
        (:meth:`sync_down`, the table's fields as :func:`~particleShear.engine.state.synced_history` gives them)."""
        C, be = self.C, state.backend
        spans = [(C.offsets[b], C.offsets[b + 1]) for b in which]
        state_p, xi, active, birth = self.history
        if not be.host and which:
            sel = be.asarray(np.concatenate([np.arange(lo, hi) for lo, hi in spans]))
            state_p, xi, active, birth = (to_host(a, "pair history")
                                          for a in (state_p[sel], xi[:, sel], active[sel], birth[sel]))
            ends = np.cumsum([hi - lo for lo, hi in spans])
            spans = list(zip(ends - [hi - lo for lo, hi in spans], ends))
        for b, (lo, hi) in zip(which, spans):
            p = state.pairs[b]
            a = active[lo:hi].copy()
            # the classes' table: a candidate that is no relation sticks, without history or number
            kept, p.xi, p.birth = synced_history(state_p[lo:hi], xi[:, lo:hi], a, birth[lo:hi])
            p.state = kept.astype(np.int8)
            p.active = a
