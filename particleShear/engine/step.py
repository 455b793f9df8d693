"""One step of a batch of replicas, top to bottom in the reference order.

:meth:`BatchEngine.step` reads like the reference's step (docs/engine.md, "One step"): shear rate →
neighbours → forces → shear stresses when sampled → kick/damping → ξ → drift → wrap → clock.
The phases pass what one leaves the next as values: :meth:`BatchEngine.force_phase` returns a
:class:`ForceRecord`, which :meth:`BatchEngine.accelerate` and :meth:`BatchEngine.move` take as an
argument, so the engine holds no record of a phase between calls.
The measurement's loops, :func:`~.loops.pre_equilibrate` and :func:`~.loops.protocol`, are in
:mod:`.loops` (and importable from here).

The candidates, their relation history and the bookkeeping of their lists are the state's
(``state.contacts``, a :class:`~particleShear.engine.contacts.Contacts`, started anew by each
engine); the only cache is its ``C`` (the per-candidate constants), rebuilt in one place,
:meth:`BatchEngine.neighbours`, whenever a replica's candidate list is rebuilt.

The arrays live on the state's backend (NumPy or CuPy, :mod:`.xp`).  A step reads device values
on the host only through :func:`~particleShear.engine.xp.to_host`, for named reasons: once at its
end, the per-replica flags (neighbour-list rebuilds due, the stability guard's verdict) in one
small array; the check for pairs at ``d = 0``, whose random normal comes from the replica's NumPy
generator; and, when a list is rebuilt, the positions of the replicas concerned (the candidate
search runs on the host) and their pair history.  The recorded series come back at the end of
the protocol.  On NumPy (reading is free) the step keeps a few early exits and caches that a
device replaces by branch-free code; both give the same numbers.

Shapes: B replicas, B·N sphere rows, P candidate pairs; units µm, s, mg per m depth, stresses
in Pa (docs/parameters.md, docs/output.md).
"""
__docformat__ = "numpy"

import collections

import numpy as np

from .box import min_image, wrap
from .integrate import damp, drift, half_kick, kick, mobile_mask, plates_follow, shift_flow, xi_increments
from .guard import KINETIC_ENERGY, NON_FINITE, closest_transient, verdict as guard_verdict
from .forces import PairConstants, normals, pair_roles, scatter, shear_stresses, splice_arrays
from .phase_laws import force_phase_laws
from .terms import (central_term, elastic_term, normal_speed, pair_forces, relative_velocity, slip_speed,
                    tangential_term, viscous_term)
from .config import INTEGRATORS, EngineConfig
from .contacts import Contacts
from .memory import tune_allocator
from .neighbours import build_candidates, verlet_bound
from .state import SLIP, STICK, spread
from .stress import EXTERNAL, OVERALL, StressInputs, evaluate_all
from .xp import to_host
from . import numba_driver, numba_step

__all__ = ["BatchEngine", "EngineInstability", "ForceRecord", "pre_equilibrate", "protocol", "pre_equilibration_blocks"]


class EngineInstability(RuntimeError):
    """A replica's state became non-finite or unstable (``replica``, ``step``, ``phase`` say where).

    Raised by the stability guard of :class:`BatchEngine` (see its ``guard``).

    Parameters
    ----------
    message : str
        What happened, for people.
    replica : int, optional
        Index of the replica in its batch (0 … B−1).
    step : int, optional
        Step count within the phase when the guard fired.
    phase : str, optional
        ``"pre-equilibration"`` or ``"protocol"``.
    """

    def __init__(self, message, replica=None, step=None, phase=None):
        RuntimeError.__init__(self, message)
        self.replica = replica
        self.step = step
        self.phase = phase


class ForceRecord(collections.namedtuple("ForceRecord", "dx dy nx ny dvx active yc mob verdict")):
    """What a force phase hands to the acceleration and movement phases of its step.

    :meth:`BatchEngine.force_phase` returns it; :meth:`BatchEngine.accelerate`,
    :meth:`BatchEngine.move`, :meth:`BatchEngine.move_spheres` and :meth:`BatchEngine.advance_cells`
    take it as an argument (None: a phase without a force phase before it).  The phases pass it as
    a value rather than through an attribute of the engine, so what a phase reads is in its
    signature, and the arrays are freed when the caller drops the record (in :meth:`BatchEngine.step`
    at the end of the step, before the next force phase allocates their successors: kept alive they
    double the step's peak memory, measured ≈ 30 % of a step at B = 16 in page faults).

    Attributes
    ----------
    dx, dy : array (P,)
        Per candidate, the minimum-image pair vector (µm, j's nearest image minus i).
    nx, ny : array (P,)
        Per candidate, the unit normal.
    dvx : array (P,)
        Per candidate, the x velocity of j's image relative to j (µm/s, ``−Ly·γ̇`` per period above).
    active : array of bool (P,)
        The relations (touching or bonded).
    yc : array (B·N,)
        The heights ``y − Ly/2`` of the spheres above their cell's centre line (µm).
    mob : array of bool (B·N,)
        The mobility mask (:meth:`BatchEngine.mobile`).
    verdict : tuple or None
        On a device, the stability guard's verdict of the phase (:meth:`BatchEngine._check`), read
        with the step's flags at its end (:meth:`BatchEngine.advance_cells`); None when the phase
        did not check or on NumPy (which reports at once).
    """
    __slots__ = ()


#: what an engine's configuration fixes per replica at its construction (read-only properties of the engine)
_Fixed = collections.namedtuple("_Fixed", "skin guard guard_dev lees_edwards held")


class BatchEngine:
    """Advances a :class:`~particleShear.engine.state.BatchState` step by step.

    Its configuration (every parameter but ``state``, ``half`` and ``phase``) is fixed at its
    construction: it is :attr:`config`, a frozen :class:`~particleShear.engine.config.EngineConfig`,
    whose fields the engine also shows as read-only properties (``engine.integrator``,
    ``engine.keep_terms`` …); an engine configured otherwise is a new engine.

    What the steps change is the state's: the spheres, boxes, strain, rate and clock, and the
    contacts ``state.contacts`` (:class:`~particleShear.engine.contacts.Contacts`: the candidates
    with their constants and relation history, the bookkeeping of the Verlet lists), which the
    engine starts anew at its construction (every list built at the first step from
    ``state.pairs``), and the Verlet predictor ``state.predictor``
    (:class:`~particleShear.engine.predictor.Predictor`), which the engine continues (an Euler
    engine drops it; :meth:`~particleShear.engine.predictor.Predictor.start`).  The engine keeps of
    the run only the guard's ``rate_max`` (the largest |γ̇| of each replica since it started, 1/s),
    the step count ``step_count``, the ``phase``, the protocol's ``record`` and the ``notes`` of why
    the compiled backend fell back to NumPy; the terms a force phase keeps (``keep_terms``) go to
    the caller's ``terms_to``, as a value.

    Parameters
    ----------
    state : BatchState
        The batch to advance (modified in place).
    skin_factor : float
        Verlet skin in units of each replica's largest radius (> 0).
    check_interval : int
        Steps between the checks of the stability guard.
    guard : bool or array of bool (B,)
        Check every ``check_interval`` steps, for each replica where it is true, what
        :class:`~particleShear.base.stability.StabilityGuard` checks (:func:`~.guard.verdict`): a
        finite state, the kinetic energy relative to the flow below ``N·k·r_mean² + Σ m (γ̇_max·Ly/2)²``
        (k taken as 1 where it is 0) and no transient contact closer than 5 % of its contact
        distance; raise :class:`EngineInstability` otherwise.
    integrator : {"euler", "verlet"}
        ``"euler"``: the reference's semi-implicit Euler.  ``"verlet"``: velocity Verlet with a
        half-kick predictor — the velocity-dependent terms of a force phase see the velocities
        moved ``F·dt/(2m)`` ahead by the forces of the previous step (the classes'
        ``set_integrator("verlet")``).
    keep_terms : bool, keyword-only
        Keep the per-term arrays of each force phase for the force register of a script's
        ensemble (:func:`particleShear.base.register.register_block`): they go to ``terms_to``.
    min_distance_ratio : float, keyword-only
        The guard's smallest d/(r_i + r_j) of a transient contact (the attribute of a
        :class:`~particleShear.base.stability.StabilityGuard`).
    max_kinetic_energy : float or None, keyword-only
        The guard's bound of the kinetic energy relative to the flow (mg·µm²/s² per m depth);
        None: the bound above.
    half : ndarray (3, B·N) or None, keyword-only
        Verlet: the half kick F·dt/(2m) of (vx, vy, ω) of the step before, set as the state's
        predictor (``state.predictor.half``); None: the predictor the state carries, continued
        (dropped where :meth:`~particleShear.engine.predictor.Predictor.start` says).
    phase : str, keyword-only
        The phase its steps belong to, for messages (the loops set it as they run).
    numbers_relations : bool, keyword-only
        Number the relations as they form (their creation numbers order a documented ensemble's
        neighbours: an engine on an ensemble's memory is built with True by the adapters).
    lees_edwards : bool, keyword-only
        False: plain periodic cells (no Lees-Edwards images; the documented ``use_lees_edwards =
        False`` ensembles).
    strain_only_while_shearing : bool, keyword-only
        The strain advances only in the steps where the state applies shear (the documented
        frictionless canvases).
    config : EngineConfig or None, keyword-only
        The whole configuration at once (:class:`~particleShear.engine.config.EngineConfig`),
        instead of the keyword arguments above (``state``, ``half``, ``phase`` and ``terms_to`` aside).
    terms_to : callable or None, keyword-only
        With ``keep_terms`` (and only then): ``terms_to(terms)`` receives the per-term arrays of a
        force phase by name (a plain dict; the register reads it as a
        :class:`particleShear.base.register.TermRecord`) when the phase ends, before an unsound
        guard verdict is raised: every force phase of :meth:`force_phase` and of NumPy's
        :meth:`step`, the last of each compiled step or block (the compiled backend keeps only
        that one).  A value handed out, as HOOMD-blue's writers take theirs: the engine keeps
        none (:class:`particleShear.base.register.KeptTerms` holds the last one).

    Raises
    ------
    ValueError
        If ``skin_factor`` is not > 0, ``integrator`` is unknown, ``check_interval`` < 1,
        ``config`` is given with configuration keywords, or ``keep_terms`` and ``terms_to`` are
        not given together (``terms_to`` callable).
    """

    INTEGRATORS = INTEGRATORS

    def __init__(self, state, skin_factor=0.5, check_interval=4, guard=True, integrator="euler", *,
                 keep_terms=False, min_distance_ratio=0.05, max_kinetic_energy=None, half=None,
                 phase="pre-equilibration", numbers_relations=False, lees_edwards=True,
                 strain_only_while_shearing=False, config=None, terms_to=None):
        given = EngineConfig(integrator=integrator, skin_factor=skin_factor, check_interval=check_interval,
                             guard=guard, min_distance_ratio=min_distance_ratio,
                             max_kinetic_energy=max_kinetic_energy, keep_terms=keep_terms,
                             numbers_relations=numbers_relations, lees_edwards=lees_edwards,
                             strain_only_while_shearing=strain_only_while_shearing)
        if config is None:
            config = given
        elif given != EngineConfig():
            raise ValueError("give the engine's configuration either as config or as keyword arguments, not both")
        if config.keep_terms != (terms_to is not None) or not (terms_to is None or callable(terms_to)):
            raise ValueError(f"keep_terms={config.keep_terms!r}, terms_to={terms_to!r}: the kept terms need "
                             "terms_to, a callable that receives them, and terms_to needs keep_terms=True")
        s = self.s = state
        self._config = config     # (read-only: the property config)
        self._terms_to = terms_to     # (read-only: the property terms_to)
        xp = self.xp = s.xp
        self.backend = s.backend
        self.notes = set()        # why the compiled backend fell back to NumPy (each reason once)
        if xp is np:
            tune_allocator()   # step temporaries stay mapped (engine/memory.py; measured, see there)
        B, N = s.B, s.N
        self.r_max = s.r.reshape(B, N).max(axis=1)
        guard_mask = config.guard_mask(B)           # per replica, on the host
        guard_mask.setflags(write=False)
        # what the configuration fixes per replica (read through the properties below)
        self._fixed = _Fixed(skin=config.skin_factor * self.r_max, guard=guard_mask,
                             guard_dev=self.backend.asarray(guard_mask),
                             lees_edwards=None if config.lees_edwards else xp.zeros(B),
                             held=xp.zeros(B) if config.strain_only_while_shearing else None)
        # the candidates, their history and the lists' bookkeeping start anew (every list due at the first step)
        s.contacts = Contacts(s)
        s.predictor.start(config.integrator, B * N, half)       # (the state's, continued or dropped)
        self.Lx_s = s.Lx[s.rep]
        self.Ly_s = s.Ly[s.rep]
        self.hy_s = self.Ly_s / 2
        self.V = (s.Lx * 1e-6) * (s.Ly * 1e-6)
        self.mmi = xp.stack((s.m, s.m, s.inertia))        # kick weights of (vx, vy, ω)
        # what the candidate search (on the host) needs besides the positions: radii, boxes, skins
        self.host_consts = [to_host(a, "state") for a in (s.r, s.Lx, s.Ly, self.skin)]
        self.rate_max = xp.zeros(B)       # the guard's largest |γ̇| of each replica since this engine started (1/s)
        self.step_count = 0
        self.phase = phase        # (run state, not configuration: begin_phase sets it as the loops run)
        #: the record of the running protocol (rows written so far; None outside one): what observers read
        self.record = None

    # -- the configuration, read-only -------------------------------------------------------------
    @property
    def config(self):
        """The engine's configuration (:class:`~particleShear.engine.config.EngineConfig`), fixed at
        construction; its fields are also read-only
        properties of the engine of the same names."""
        return self._config

    integrator = property(lambda self: self.config.integrator,
                          doc="The integrator, ``\"euler\"`` or ``\"verlet\"`` (:attr:`config`).")
    keep_terms = property(lambda self: self.config.keep_terms,
                          doc="Keep the per-term arrays of each force phase for the force register "
                              "(``base.register``; :attr:`config`), handed to :attr:`terms_to`.")
    terms_to = property(lambda self: self._terms_to,
                        doc="The callable that receives the kept terms of the force phases (None without "
                            ":attr:`keep_terms`); fixed at construction.")
    check_interval = property(lambda self: self.config.check_interval,
                              doc="Steps between the checks of the stability guard (:attr:`config`).")
    min_distance_ratio = property(lambda self: self.config.min_distance_ratio,
                                  doc="The guard's smallest d/(r_i + r_j) of a transient contact (:attr:`config`).")
    max_kinetic_energy = property(lambda self: self.config.max_kinetic_energy,
                                  doc="The guard's bound of the kinetic energy relative to the flow "
                                      "(mg·µm²/s² per m depth; None: the bound of the class docstring; :attr:`config`).")
    numbers_relations = property(lambda self: self.config.numbers_relations,
                                 doc="Number the relations as they form (:meth:`_number`), for a write-back "
                                     "into ensembles (:attr:`config`).")
    skin = property(lambda self: self._fixed.skin,
                    doc="The Verlet skin of each replica, ``skin_factor`` times its largest radius (µm, (B,)).")
    guard = property(lambda self: self._fixed.guard,
                     doc="Per replica, whether the stability guard checks it (a read-only host array (B,)).")
    guard_dev = property(lambda self: self._fixed.guard_dev,
                         doc=":attr:`guard` on the state's backend.")
    lees_edwards = property(lambda self: self._fixed.lees_edwards,
                            doc="Per replica, 1.0 for a Lees-Edwards cell and 0.0 for a plain periodic one: the "
                                "factor of the image offset ``Ly·γ`` and of the image velocity ``Ly·γ̇``; None: "
                                "every replica is Lees-Edwards (the configuration's ``lees_edwards``; the same "
                                "object at every read).")

    @property
    def strain_advances(self):
        """Per replica, 1.0 where the strain advances by ``γ̇·dt`` in this step and 0.0 where it is
        held; None: everywhere (the configuration's ``strain_only_while_shearing`` holds it while the
        state does not apply shear; the same object at every read)."""
        return None if self._fixed.held is None or self.s.applying_shear else self._fixed.held

    # -- the candidates (the state's contacts) ---------------------------------------------------
    def neighbours(self):
        """Rebuild the candidate lists of the replicas whose Verlet bound reached the skin, and the
        per-candidate constants with them (the one invalidation point).

        Only the rebuilt replicas' constants are computed; the other replicas' segments are copied
        from the previous constants (:meth:`~particleShear.engine.forces.PairConstants.splice`).
        Which replicas are due was read at the end of the previous step (``state.contacts.need``, on
        the host); the candidate search runs on the host, on the positions of those replicas.  The
        rebuilt lists carry the history written back into their tables first, and their
        bookkeeping starts from 0 (:meth:`~particleShear.engine.contacts.Contacts.restart`)."""
        c = self.s.contacts
        need = c.need
        if not need.any():
            return
        s, be = self.s, self.backend
        changed = np.flatnonzero(need)
        c.sync_down(s, changed)          # the history the rebuilt lists carry over
        rows = np.concatenate([np.arange(b * s.N, (b + 1) * s.N) for b in changed])
        pos = to_host(s.pos[:, rows] if be.host else s.pos[:, be.asarray(rows)], "rebuild")
        # the images' offset the force phase sees: Ly·γ, 0 for a plain periodic replica (lees_edwards)
        shift = to_host(self.image_shift(), "rebuild")
        r, Lx, Ly, skin = self.host_consts
        # (compiled: the same pairs from the same grid, the same history merge, numba_step.rebuild)
        build = numba_step.rebuild if be.compiled else build_candidates
        for k, b in enumerate(changed):
            mine, own = slice(k * s.N, (k + 1) * s.N), s.replica(b)
            s.pairs[b] = build(pos[0, mine], pos[1, mine], r[own], Lx[b], Ly[b], shift[b], skin[b], s.pairs[b])
            c.rebuilds[b] += 1
        c.restart(be.asarray(need), s)
        offsets = np.concatenate(([0], np.cumsum([len(p.i) for p in s.pairs])))
        fresh = [s.pairs[b] for b in changed]
        state_p = be.asarray(np.concatenate([p.state for p in fresh]))
        xi = be.asarray(np.concatenate([p.xi for p in fresh], axis=1))
        active = be.asarray(np.concatenate([p.active for p in fresh]))
        birth = be.asarray(np.concatenate([p.birth for p in fresh]))
        # (every constant of the rebuilt replicas' candidates at once, from their states and d_eq)
        new = PairConstants(s, np.concatenate(([0], np.cumsum([len(p.i) for p in fresh]))), replicas=changed,
                            state=state_p, d_eq=be.asarray(np.concatenate([p.d_eq for p in fresh])),
                            fill=numba_step.constant_rows if be.compiled else None)
        if c.C is None or len(changed) == s.B:
            c.take(new, (state_p, xi, active, birth))
            new.set_visits(s)
            c.refresh_free(s)
            return
        # the batch's arrays: the unchanged replicas' segments from the old arrays, in replica order
        old_off, segments, k = c.C.offsets, [], 0
        for b in range(s.B):
            if k < len(changed) and changed[k] == b:
                segments.append((True, new.offsets[k], new.offsets[k + 1]))
                k += 1
            elif segments and not segments[-1][0] and segments[-1][2] == old_off[b]:
                segments[-1] = (False, segments[-1][1], old_off[b + 1])     # extend a run of unchanged replicas
            else:
                segments.append((False, old_off[b], old_off[b + 1]))
        history = tuple(splice_arrays(old, fresh_rows, segments)
                        for old, fresh_rows in zip(c.history, (state_p, xi, active, birth)))
        c.take(PairConstants.splice(s, c.C, new, segments, offsets), history)
        c.C.set_visits(s)
        c.refresh_free(s)

    def image_shift(self):
        """The Lees-Edwards offset ``Ly·γ`` of the images of each replica (B,), 0 for a plain periodic
        replica (:attr:`lees_edwards`)."""
        s = self.s
        return s.Ly * s.gamma if self.lees_edwards is None else s.Ly * s.gamma * self.lees_edwards

    def _image_rate(self):
        """The rate γ̇ the images of each replica move with (B,), 0 for a plain periodic replica."""
        s = self.s
        return s.rate if self.lees_edwards is None else s.rate * self.lees_edwards

    def _images(self, raw_x, raw_y, shift_p):
        """Minimum image of the candidates, reusing the period counts of the last step while they
        still give separations inside the half-open intervals (one period at most, so the result is
        the same number as a fresh :func:`~particleShear.engine.box.min_image`).

        The counts are kept with the candidates' constants (``C.images``), so they are dropped at the
        one invalidation point, a rebuild.  On NumPy only (deciding the reuse reads the arrays); it
        saves ≈ 14 % of a step of one replica and nothing measurable at B = 32 (docs/performance.md)."""
        C = self.s.contacts.C
        img = C.images
        if img is not None:
            Lyky, ky, Lxkx, kx = img
            dy = raw_y - Lyky
            dx = raw_x - shift_p * ky
            dx -= Lxkx
            if (np.abs(dy) < C.hy).all() and (np.abs(dx) < C.hx).all():
                return dx, dy, ky, kx
        dx, dy, ky, kx = min_image(raw_x, raw_y, C.Lx, C.Ly, shift_p)
        if self.backend.host:
            one = (np.abs(ky) <= 1).all() and (np.abs(kx) <= 1).all()
            C.images = (C.Ly * ky, ky, C.Lx * kx, kx) if one else None
        return dx, dy, ky, kx

    def adopt_candidates(self, C, history, counts, written=False):
        """Take candidate lists rebuilt elsewhere (a compiled block's, :func:`~particleShear.engine.numba_step._settle`)
        as what :meth:`neighbours` leaves after the same rebuilds: the constants ``C`` and the flat
        history of every replica, the rebuilt replicas' pair tables written as :meth:`flush` writes
        them, their rebuild counts, the frictionless replicas anew.

        Parameters
        ----------
        C : PairConstants
            The candidates of every replica, side by side.
        history : tuple of ndarray
            ``(state_p, xi, active, birth)`` of those candidates.
        counts : ndarray of int (B,)
            How many times each replica's list was rebuilt (the rebuilt ones' pair tables hold
            their new lists already).
        written : bool, default False
            The rebuilt replicas' tables hold their history too, as
            :meth:`~particleShear.engine.contacts.Contacts.sync_down` writes it: only their
            creation counters and versions are brought up to date (no second write of the tables).
        """
        s = self.s
        c = s.contacts
        c.take(C, history)
        C.set_visits(s)
        c.sync_down(s, np.flatnonzero(counts), written=written)
        c.rebuilds += counts
        c.refresh_free(s)

    def flush(self):
        """Write the flat pair history of ``state.contacts`` back into ``state.pairs`` (after a phase;
        :meth:`~particleShear.engine.contacts.Contacts.sync_down`)."""
        self.s.contacts.sync_down(self.s)

    def pairs_of(self, b):
        """Current candidate list of replica ``b`` (a copy, with the flat history written in).

        Parameters
        ----------
        b : int
            Replica index (0 … B−1).

        Returns
        -------
        PairTable
            The candidates of replica b with their current state, ξ, ``d_eq``, relations and
            creation numbers (those formed in this engine are numbered only with
            :attr:`numbers_relations`; else 0).
        """
        self.s.contacts.sync_down(self.s)
        return self.s.pairs[b].copy()

    def mobile(self):
        """Mobility mask: with the plates on, spheres overlapping ``y = 0`` or ``y = Ly`` are immobile.

        Returns
        -------
        array of bool (B·N,)
            True for the spheres that move freely (on the state's backend).
        """
        s = self.s
        if not s.applying_shear:
            return self.xp.ones(len(s.y), bool)
        return mobile_mask(s.r, s.y, self.Ly_s)

    # -- the run state ---------------------------------------------------------------------------
    def begin_phase(self, phase, record=None):
        """Start a phase of a run: its name (the guard's reports name it), the step count from 0,
        and the record observers read while it runs (None: none).

        Parameters
        ----------
        phase : str
            ``"pre-equilibration"`` or ``"protocol"``.
        record : dict of ndarray, optional
            The protocol's record (:func:`~particleShear.engine.rheometer.shear_record`).
        """
        self.phase, self.step_count, self.record = phase, 0, record

    def end_phase(self):
        """End a phase: the record is no longer the engine's to show (observers read None)."""
        self.record = None

    # -- the step --------------------------------------------------------------------------------
    def set_rate(self, rate):
        """Change γ̇ per replica; each sphere keeps its velocity relative to the local flow.

        ``vx += (y − Ly/2)·Δγ̇`` and ``ω −= Δγ̇/2`` (the flow's rotation rate), so a change of
        rate gives no velocity shock (docs/engine.md).

        Parameters
        ----------
        rate : array_like (B,)
            New shear rate γ̇ of each replica (1/s).
        """
        s = self.s
        shift_flow(s.vx, s.omega, s.y - self.hy_s, spread(rate - s.rate, s.rep, s.B))
        s.rate[...] = self.xp.asarray(rate, dtype=float)     # (in place: the arrays may be ensembles' cells)

    def set_mu(self, mu):
        """Change the Coulomb friction coefficient μ of each replica (the constitution's μ = 0 blocks).

        The per-candidate μ of the candidates' constants (``state.contacts.C``) is refreshed with it
        and the frictionless replicas found anew; nothing else depends on μ.

        Parameters
        ----------
        mu : array_like (B,)
            New μ of each replica (≥ 0).
        """
        s = self.s
        s.mu[...] = self.xp.asarray(mu, dtype=float)     # (in place, as the rate)
        c = s.contacts
        C = c.C
        if C is not None:
            C.mu = s.mu[C.rep]
            if C.Kj is not None:
                C.Kj.mu = C.mu
        c.refresh_free(s)

    def step(self, cool, dt, sample=False):
        """One step of every replica: :meth:`force_phase`, :meth:`accelerate`, :meth:`move`.

        Returns ``(τ_internal, τ_surface)`` (Pa, arrays of B) when ``sample``, and also every
        tensor of :data:`~particleShear.engine.stress.TENSORS` as a (B, 9, 2, 2) array when
        ``sample == "tensors"``.

        Parameters
        ----------
        cool : float
            Damping factor of this step, applied to the velocity relative to the flow and to ω
            (1 = no damping).
        dt : float
            Time step (s), shared by the replicas.
        sample : bool or str
            False: no stresses; True: the two shear stresses; ``"tensors"``: also every tensor.

        Returns
        -------
        None or tuple
            None unless ``sample``; else ``(tau_internal, tau_surface)`` (ndarray (B,), Pa) and,
            for ``"tensors"``, a third item, the (B, 9, 2, 2) tensors (Pa), all evaluated from
            the forces of the positions at the start of the step.

        Raises
        ------
        EngineInstability
            If the stability guard finds a guarded replica unstable (checked every
            ``check_interval`` steps).
        """
        if self.backend.compiled:      # the whole step in one compiled call
            out = numba_step.run_step(self, cool, dt, sample)
            if out is not numba_step.NOT_RUN:
                return out
        g, out = self._force_phase(sample)       # (g, the phase's record, is freed with this call)
        self.accelerate(cool, dt, g)
        self._move(dt, g)
        return out

    def steps(self, n, cool, dt):
        """``n`` steps without samples at the state's rate (:meth:`step` n times; on the compiled
        backend in compiled blocks, :func:`~particleShear.engine.numba_step.run_block`).

        Parameters
        ----------
        n : int
            Steps (≥ 0).
        cool, dt : float
            Damping factor and time step (s).
        """
        done = numba_step.run_block(self, None, cool, dt, n=n) if self.backend.compiled and n > 0 else 0
        for _ in range(done, n):
            self.step(cool, dt)

    def force_phase(self, sample=False):
        """Neighbours (when due) → geometry and relations → kinematics → force terms → scatter.

        Writes the forces and torques of every sphere into ``state.frc`` and returns what the other
        two phases of the step read, a :class:`ForceRecord` (the candidates' ``dx, dy``, normals
        ``nx, ny``, image velocity ``dvx``, relations ``active``, the heights ``y − Ly/2``, the
        mobility mask, a device's guard verdict), which the caller hands to :meth:`accelerate` and
        :meth:`move` and then drops (the engine keeps no record of the phase: what a phase reads
        is its arguments).  With :attr:`keep_terms` the per-term arrays go to :attr:`terms_to`
        for the force register.  With the velocity Verlet integrator (:attr:`integrator`) the
        velocity-dependent terms see the velocities moved half a kick ahead (the half kick of the
        previous step).  On the compiled backend the phase runs in the compiled step kernel, alone
        (:func:`~particleShear.engine.numba_step.force_phase`: the kernel's force phase, the same
        bits; the record's rows and the kept terms are then the phase's own buffers, which later
        steps and phases leave as they are), where the compiled step covers the engine
        (:func:`~particleShear.engine.numba_step.reason`); else it is the NumPy step's phase, the
        one :meth:`step` runs on NumPy (the compiled step runs its force phase in its one call).

        Parameters
        ----------
        sample : bool or str
            False: no stresses; True: the two shear stresses; ``"tensors"``: also every tensor.

        Returns
        -------
        record : ForceRecord
            What :meth:`accelerate` and :meth:`move` of the step read.  Its ``verdict`` is None on
            the host backends (NumPy and compiled), where an unsound guard verdict is reported at
            once (raised here); a device's verdict is read with the flags by :meth:`move`.
        stresses : None or tuple
            As :meth:`step` returns.

        Raises
        ------
        EngineInstability
            On the host backends, when the stability guard (checked every ``check_interval`` steps)
            finds a guarded replica unstable; the forces of the phase are then written and its
            kept terms handed to :attr:`terms_to`.
        """
        if self.backend.compiled:
            got = numba_step.force_phase(self, sample)
            if got is not None:       # (the compiled phase has reported an unsound verdict at once)
                return ForceRecord(*got[0], None), got[1]
        return self._force_phase(sample)

    def _force_phase(self, sample=False):
        """The NumPy step's force phase (:meth:`force_phase` where it does not run compiled, and the
        phase of :meth:`step` on NumPy); the parameters and results of :meth:`force_phase`."""
        s = self.s
        x, y, vx, vy, om = s.x, s.y, s.vx, s.vy, s.omega
        yc, dx, dy, ky, kx, d, touching, active, image_rate = self.relations()
        c = s.contacts
        C = c.C
        ai, aj = C.ai, C.aj
        xi = c.xi
        nx, ny = normals(dx, dy, d, C.rep_host, s.rng)
        # relative velocities (image velocity −Ly·γ̇ per period above); Verlet: half a kick ahead
        dvx = -(C.Ly * spread(image_rate, C.rep, s.B)) * ky
        half = s.predictor.half
        vel = s.vel if half is None else s.vel + half
        Vi = vel.take(ai, axis=1)
        Vj = vel.take(aj, axis=1)
        rv = relative_velocity(Vi, Vj, dvx)
        vn = normal_speed(rv, nx, ny)
        # the slip speed only where a replica has a tangential force (see _tangential)
        vt = None if c.free_p is True else slip_speed(rv, nx, ny, C.ri, C.rj, Vi[2], Vj[2])
        # forces: central (elastic + viscous), tangential (two visits), scatter
        parts = ([], [])          # the central terms of each visit, kept for the register (keep_terms)
        if self.backend.compiled and self._compiled_terms(C):   # the same laws in one compiled loop (bit-identical)
            fn, law, F, slip = numba_driver.pair_terms(C, d, vn, vt, touching, active, xi, C.Kj)
        else:
            fn, law = self._central(C, d, vn, active, parts[0])
            F, slip = self._tangential(C, vt, touching, xi, law, active)
        c.state_p = slip.view(np.int8) + C.perm_code
        ft = (F[0] + F[1]) * 0.5
        fx_i, fy_i, dF, tq = pair_forces(fn, ft, nx, ny, d, C.w)
        fx_j = fy_j = None
        if C.Kj is not None:       # spheres with parameters of their own: the central force of j's visit
            fn_j = self._central(C.Kj, d, vn, active, parts[1])[0]
            fx_j, fy_j = pair_forces(fn_j, ft, nx, ny, d, None)[:2]
        s.frc[...] = scatter(C, len(x), fx_i, fy_i, tq[0], tq[1], fx_j, fy_j)
        mob = self.mobile()
        out = None
        shifted = (ky != 0) | (kx != 0) if sample or self.keep_terms else None
        if self.keep_terms:
            self._terms_to(dict(C=C, parts=parts, F=self.xp.stack(F), dx=dx, dy=dy, nx=nx, ny=ny, d=d, touching=touching,
                              active=active, shifted=shifted, mob=mob, fx_i=fx_i, fy_i=fy_i, fx_j=fx_j, fy_j=fy_j, dF=dF,
                                tq=tq, birth=c.birth, totals=s.frc.copy()))   # (the kick resets s.frc)
        if sample:
            q = None if sample != "tensors" else StressInputs(
                C=C, B=s.B, rep=s.rep, x=x, y=y, vx=vx, vy=vy, omega=om, m=s.m, inertia=s.inertia, Lx=s.Lx, Ly=s.Ly,
                rate=s.rate, V=self.V, mob=mob, active=active, shifted=shifted, dx=dx, dy=dy, fx_i=fx_i, fy_i=fy_i,
                fx_j=fx_j, fy_j=fy_j, dF=dF, fx=s.fx, fy=s.fy, torque=s.torque)
            if q is None:
                out = shear_stresses(C, s.B, yc, pair_roles(mob[ai], mob[aj], shifted), active, dy, fx_i, dF,
                                     self.V, fx_j)
            else:       # the tensors' xy entries are the shear stresses, bit for bit (engine.stress)
                T = evaluate_all(q)
                out = (-T[:, OVERALL, 0, 1], -T[:, EXTERNAL, 0, 1], T)
        verdict = None
        if not self.step_count % self.check_interval and self.guard.any():
            verdict = self._check(d, active)
            if self.backend.host:     # NumPy: report at once (a device reports with the flags at the end)
                self.report_verdict(verdict, self.step_count)
                verdict = None
        return ForceRecord(dx, dy, nx, ny, dvx, active, yc, mob, verdict), out

    def relations(self):
        """The neighbour update of a force phase: neighbour lists (when due) → Lees-Edwards minimum
        image of every candidate → distances → relations (``touching | bond``; a new relation starts
        sticking and takes its number, an opened contact loses its ξ).

        Returns
        -------
        tuple
            ``(yc, dx, dy, ky, kx, d, touching, active, image_rate)``: the heights ``y − Ly/2`` of
            the spheres (µm), per candidate the pair vector (µm, j's nearest image minus i), its
            image periods, distance, contact and relation flags, and the rate the images move
            with per replica (1/s; :meth:`image_shift`, :meth:`_image_rate`).
        """
        s, xp = self.s, self.xp
        self.neighbours()          # (positions at the start of the step)
        c = s.contacts
        C = c.C
        yc = s.y - self.hy_s                            # height above the cell's centre line
        raw = s.pos.take(C.aj, axis=1)
        raw -= s.pos.take(C.ai, axis=1)
        shift, image_rate = self.image_shift(), self._image_rate()
        dx, dy, ky, kx = self._images(raw[0], raw[1], spread(shift, C.rep, s.B))
        d = xp.sqrt(dx * dx + dy * dy)
        touching = d < C.d0
        active = C.perm | touching
        new = active & ~c.active
        xp.copyto(c.state_p, STICK, where=new)          # a new relation starts sticking
        if self.numbers_relations:
            self._number(new)
        c.xi = xp.where(active, c.xi, 0.0)              # an opened contact loses its history
        c.active = active
        return yc, dx, dy, ky, kx, d, touching, active, image_rate

    def _compiled_terms(self, C):
        """Whether the force terms of a NumPy force phase run in the compiled pair loop of :mod:`.numba_driver`.

        A NumPy force phase on the compiled backend is a step or phase the compiled step leaves to
        NumPy (a scene :func:`.numba_step.reason` names, with its note there).  Its terms run
        compiled for the default laws (the linear law and the tensile law of bonds, from prepared
        constants) of frictional replicas or bonds when the terms are not kept for a register;
        otherwise the NumPy terms run (the same bits).
        """
        return not self.keep_terms and self.s.contacts.free_p is None and force_phase_laws(self.s, C) == (None, None)

    def _central(self, K, d, vn, active, parts):
        """The central term of one visit (:func:`~particleShear.engine.terms.central_term`); with
        :attr:`keep_terms` its elastic and viscous scalars are appended to ``parts`` (the same sum)."""
        laws = force_phase_laws(self.s, K)        # the laws, looked up once per phase
        if not self.keep_terms:
            return central_term(K, d, vn, active, *laws)
        f_el, law = elastic_term(K, d, *laws)
        f_v = viscous_term(K, vn, active)
        parts += [f_el, f_v]
        return f_el + f_v, law

    def _number(self, new):
        """Give the relations formed in this step (``new``, per candidate) their creation numbers.

        As the classes number them (``PairTable.birth``, the order of ``sphere.neighbors``): the
        newly touching pairs of a replica take the next numbers of its counter (``state.contacts.next_birth``)
        in ``(i, j)`` order, which is the order of its contiguous segment of candidates.  Only
        when :attr:`numbers_relations` (a write-back into ensembles needs the numbers); on NumPy a
        step without new relations returns at once (then ≈ 2 % of a step of one replica, N = 150,
        median of 15 paired blocks of 200 steps)."""
        xp, c = self.xp, self.s.contacts
        C = c.C
        if self.backend.host and not new.any():
            return
        count = xp.cumsum(new)
        upto = xp.concatenate((xp.zeros(1, count.dtype), count))[self.backend.asarray(C.offsets)]
        before = upto[:-1]
        c.birth = xp.where(new, c.next_birth[C.rep] + (count - 1 - before[C.rep]), c.birth)
        c.next_birth = c.next_birth + (upto[1:] - before)

    def _tangential(self, C, vt, touching, xi, law, active):
        """The tangential term, left out for the replicas without friction and bonds.

        A replica with μ = 0 and no bond has no tangential force (its Coulomb bound is 0), so
        every relation slips and keeps ξ = 0 — what the documented classes do by skipping the
        term.  When every replica of the batch is such a replica the term, the slip speed and
        the ξ rule (:meth:`move`) are not evaluated.

        Returns ``(F, slip)`` as :func:`~particleShear.engine.terms.tangential_term`.
        """
        free = self.s.contacts.free_p
        if free is None:
            return tangential_term(C, vt, touching.astype(float), xi, law, C.Kj)
        if free is True:
            xi[...] = 0.0
            return self.xp.zeros((2, len(active))), active
        F, slip = tangential_term(C, vt, touching.astype(float), xi, law, C.Kj)
        self.xp.copyto(xi, 0.0, where=free)
        return F, slip | (free & active)

    def accelerate(self, cool, dt, g=None):
        """Kick (plates follow), rotational kick and damping of every replica (eqs. S1-10, S1-11).

        With velocity Verlet the half kick ``F·dt/(2m)`` of the mobile spheres becomes the state's
        predictor, which the next force phase sees (:func:`~particleShear.engine.integrate.half_kick`).

        Parameters
        ----------
        cool : float
            Damping factor of the velocity relative to the flow and of ω (1 = no damping).
        dt : float
            Time step (s).
        g : ForceRecord or None
            The record of the step's force phase (:meth:`force_phase`): its mobility mask and
            heights; None: a kick without a force phase, with those of now (the same numbers
            while the spheres have not moved since the force phase).
        """
        s = self.s
        # the force phase's mobility and heights (a kick without a force phase: those of now)
        mob, yc = (self.mobile(), s.y - self.hy_s) if g is None else (g.mob, g.yc)
        if self.integrator == "verlet":
            s.predictor.half = half_kick(s.frc, self.mmi, dt, mob)
        rate_s = spread(s.rate, s.rep, s.B)
        kick(s.vel, s.frc, self.mmi, dt)                    # (F_x/m, F_y/m, T/I)·dt
        if s.applying_shear:        # (without the plates every sphere is mobile)
            plates_follow(s.vx, s.vy, ~mob, yc, rate_s * self.Ly_s / 2)
        damp(s.vel, yc * rate_s, cool)

    def move(self, dt, g=None):
        """ξ of sticking contacts and bonds (sequential rule, Appendix B.2), drift, strain, wrap, clock.

        Ends with the step's one read of per-replica flags on the host: the lists due for a
        rebuild (and, on a device, the stability guard's verdict), and the step count.  On the
        compiled backend, after a compiled :meth:`force_phase` of the present candidates, the
        movement runs in the compiled step kernel, alone
        (:func:`~particleShear.engine.numba_step.move`: the kernel from
        :data:`~particleShear.engine.numba_step.MOVE_ONLY`, the same bits); else it is the NumPy
        step's movement (:meth:`move_spheres`, :meth:`advance_cells`), the one :meth:`step` runs
        on NumPy.

        Parameters
        ----------
        dt : float
            Time step (s).
        g : ForceRecord or None
            The record of the step's force phase (:meth:`force_phase`); None: a movement without
            a force phase (no ξ rule, no verdict).

        Raises
        ------
        EngineInstability
            On a device, if the force phase's guard verdict is not sound.
        """
        if not (self.backend.compiled and numba_step.move(self, dt, g)):
            self._move(dt, g)

    def _move(self, dt, g=None):
        """The NumPy step's movement (:meth:`move` where it does not run compiled, and the movement
        of :meth:`step` on NumPy): :meth:`move_spheres`, then :meth:`advance_cells`."""
        self.move_spheres(dt, g)
        self.advance_cells(dt, g)

    def move_spheres(self, dt, g=None):
        """The first part of :meth:`move`: ξ of sticking contacts and bonds (sequential rule,
        Appendix B.2; none without a force phase), the displacement since the lists were built, and
        the drift ``x, y, φ += (v_x, v_y, ω)·dt``.

        Parameters
        ----------
        dt : float
            Time step (s).
        g : ForceRecord or None
            The record of the step's force phase (:meth:`force_phase`): the relations, pair
            vectors, normals and image velocity the ξ rule reads, the heights; None: no ξ rule.
        """
        s, xp = self.s, self.xp
        c = s.contacts
        C = c.C
        vx, vy = s.vx, s.vy
        free = c.free_p
        if free is not True and g is not None:   # without friction and bonds no ξ (nor without a force phase)
            kd = xp.where(g.active & (c.state_p != SLIP), dt, 0.0)
            Vi = s.vel.take(C.ai, axis=1)

            def unit(Rx, Ry):
                """Unit vectors of R (a random one at |R| = 0, none drawn for a replica without ξ)."""
                d = xp.sqrt(Rx * Rx + Ry * Ry)
                return normals(Rx, Ry, d if free is None else xp.where(free, 1.0, d), C.rep_host, s.rng)

            inc_ij, inc_ji = xi_increments(Vi, s.vel.take(C.aj, axis=1), g.dvx, g.nx, g.ny, C.ri, C.rj,
                                           Vi[0] * dt - g.dx, Vi[1] * dt - g.dy, unit)
            xi = c.xi
            xi[0] += inc_ij * kd
            xi[1] += inc_ji * kd
        # drift, strain, wrap, clock (the displacement relative to the flow the images follow)
        image_rate = self._image_rate()
        rate_s = spread(image_rate, s.rep, s.B)
        u = c.u
        u[0] += (vx - (s.y - self.hy_s if g is None else g.yc) * rate_s) * dt
        u[1] += vy * dt
        # (the largest length is the root of the largest square: the root is monotonic and correctly rounded)
        c.u_max = xp.maximum(c.u_max, xp.sqrt((u[0] * u[0] + u[1] * u[1]).reshape(s.B, s.N).max(axis=1)))
        c.strain += abs(image_rate) * dt
        c.bound = verlet_bound(c.u_max, c.strain, self.r_max)
        drift(s.pos, s.phi, s.vel, dt)

    def advance_cells(self, dt, g=None):
        """The second part of :meth:`move`: strain, Lees-Edwards wrap, clock, and the step's one read
        of per-replica flags (see there).

        Parameters
        ----------
        dt : float
            Time step (s) by which the strain and the clock advance.
        g : ForceRecord or None
            The record of the step's force phase: on a device its guard verdict, read with the
            flags; None: no verdict.

        Raises
        ------
        EngineInstability
            On a device, when the guard verdict read with the flags is not sound.
        """
        s, xp = self.s, self.xp
        rate_s = spread(self._image_rate(), s.rep, s.B)
        s.gamma += s.rate * dt if self.strain_advances is None else s.rate * dt * self.strain_advances
        wrap(s.x, s.y, s.vx, self.Lx_s, self.Ly_s, spread(self.image_shift(), s.rep, s.B), rate_s)
        s.t += dt
        # the step's one read of per-replica flags: lists due for a rebuild (and the guard's verdict)
        verdict = None if g is None else g.verdict
        c = s.contacts
        due = c.bound >= self.skin
        flags = to_host(due if verdict is None else xp.concatenate((due, verdict[0] != 0)), "flags")
        c.need = c.need | flags[:s.B]      # (a list due and not rebuilt since, e.g. none before a first force phase, stays due)
        if verdict is not None and flags[s.B:].any():
            self.report_verdict(verdict, self.step_count)
        self.step_count += 1

    def _check(self, d, active):
        """The stability guard's verdict (:func:`~particleShear.engine.guard.verdict`), on the state's backend.

        Returns ``(code, ke, bound, closest)``, arrays (B,): ``code`` 0 for a sound (or unguarded)
        replica, 1 non-finite state, 2 kinetic energy above its bound, 3 interpenetration."""
        s, xp = self.s, self.xp
        self.rate_max = xp.maximum(self.rate_max, abs(s.rate))
        closest = closest_transient(s.contacts.C, d, active)
        code, ke, bound = guard_verdict(s.B, s.x, s.y - self.hy_s, s.vx, s.vy, s.omega, s.rate[s.rep], s.m, s.inertia,
                                        s.r, s.k, s.Ly, self.rate_max, closest, self.min_distance_ratio,
                                        self.max_kinetic_energy)
        return code * self.guard_dev, ke, bound, closest

    def report_verdict(self, verdict, step):
        """Raise :class:`EngineInstability` for the first guarded replica whose verdict is not sound
        (the step-by-step loop's check, and the compiled blocks' report of theirs).

        Parameters
        ----------
        verdict : tuple of array
            ``(code, kinetic energy, its bound, closest contact ratio)`` per replica
            (:func:`~particleShear.engine.guard.verdict_code`; code 0: sound).
        step : int
            The step the verdict is of (reported in the exception).

        Raises
        ------
        EngineInstability
            For the first replica whose code is not 0.
        """
        code = to_host(verdict[0], "guard")
        bad = np.flatnonzero(code)
        if not len(bad):
            return
        b = int(bad[0])
        ke, bound, closest = (to_host(a, "guard") for a in verdict[1:])
        if code[b] == NON_FINITE:
            reason = "non-finite state"
        elif code[b] == KINETIC_ENERGY:
            reason = f"kinetic energy {ke[b]:.3g} exceeds the bound {bound[b]:.3g}"
        else:
            reason = f"two spheres interpenetrate to d/(r_i + r_j) = {closest[b]:.3g}"
        raise EngineInstability(f"replica {b}: {reason} at step {step} of phase {self.phase!r}",
                                replica=b, step=step, phase=self.phase)


# the measurement's loops, re-exported here (where they were first written)
from .loops import pre_equilibrate, pre_equilibration_blocks, protocol  # noqa: E402
