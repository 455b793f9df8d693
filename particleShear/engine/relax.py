"""The constitution's relaxation in the engine: free relaxation of a batch and the write-back.

The builders of ``particleShear.linkable`` relax an ensemble with
:meth:`~particleShear.linkable.compact.EnsembleCompactParticles.free_pre_equilibration`: shear
and plates off, frictionless damped levels from ``dt_max`` halving down to ``dt`` (each level
ending with the removal of the mean velocity), one frictionless block at ``dt``, one block at
``dt`` with the ensemble's μ.  :func:`free_relaxation` runs exactly these steps on every replica
of a :class:`~particleShear.engine.step.BatchEngine`; :func:`remove_linear_drift` is the classes'
``correct_linear_drift`` per replica; :func:`write_back` puts a relaxed replica back into its
ensemble (spheres, clock, and the relations, states and ξ of its pair table) so that the
bookkeeping that follows (crosslinking, cutting, link removal, joining isolated spheres) runs
through the documented classes on the contacts the engine ended with, and
:class:`RelationAges` gives the relations the creation numbers the classes would give them.
:func:`relax_ensembles` does all of it for a list of ensembles (docs/design.md, "Batches of
replicas", "Constitution of a batch").

A replica's relaxation does not depend on its batch (every operation of the step is per
replica, see :mod:`.step`; the drift is removed per replica), so a run constituted in a batch
is bit-identical to the same run constituted alone.  Against the classes the engine computes
the same equations with sums in another order: the two agree to rounding over short blocks
(tested), while a long relaxation of a random packing, being chaotic, amplifies rounding.

Units: µm, s, mg per m depth (docs/parameters.md).
"""
__docformat__ = "numpy"

import math
import numbers

import numpy as np

from .state import PERMANENT, STICK, BatchState
from .step import BatchEngine
from .xp import to_host

__all__ = ["free_relaxation", "remove_linear_drift", "write_back", "relax_ensembles", "relaxation_levels",
           "RelationAges"]

#: most coarse levels of one relaxation (halving a finite step reaches any dt > 0 in fewer)
MAX_LEVELS = 2100

#: Verlet skin of the relaxation engine, in units of each replica's largest radius.  The
#: contacts of every step are exact for any skin (the list is rebuilt before a pair can have
#: come into contact); in a compressed packing ~0.9 of the candidates are in contact at
#: 0.2 r_max against ~0.6 at 0.5 r_max, so a step works on 30 % fewer pairs, and the extra
#: rebuilds cost less than that (measured: a batch of 32 default constitutions takes ~40 % less
#: CPU time than at 0.5).
RELAX_SKIN = 0.2


def relaxation_levels(dt, dt_max):
    """Coarse levels of ``free_pre_equilibration``: ``(level_dt, cool)`` from ``dt_max`` halving while above ``dt``.

    The damping factor starts at 0.5 and moves halfway to 1 at every halving (the classes'
    rule, repeated halving of ``dt_max``).

    Parameters
    ----------
    dt : float
        Final time step (s), > 0.
    dt_max : float
        Step of the first level (s), finite.

    Returns
    -------
    list of tuple
        ``(level_dt, cool)`` per level; empty when ``dt_max <= dt``.

    Raises
    ------
    ValueError
        If ``dt`` is not a finite number > 0 or ``dt_max`` is not finite.
    """
    if isinstance(dt, bool) or not (isinstance(dt, numbers.Real) and math.isfinite(dt) and dt > 0):
        raise ValueError(f"dt={dt!r} is out of range: allowed a finite number > 0 (free_pre_equilibration)")
    if not math.isfinite(dt_max):
        raise ValueError(f"dt_max={dt_max!r} is out of range: allowed a finite number (free_pre_equilibration)")
    levels = []
    level_dt, cf = dt_max, 0.5
    while level_dt > dt and len(levels) < MAX_LEVELS:
        levels.append((level_dt, cf))
        level_dt /= 2
        cf = (1 + cf) / 2
    return levels


def remove_linear_drift(state):
    """Subtract each replica's unweighted mean velocity from its spheres (``correct_linear_drift``).

    ``v_x ← v_x − Σ v_x / N`` and ``v_y ← v_y − Σ v_y / N`` over the N spheres of each replica,
    with the sums of the classes (each replica's contiguous rows), so the mean velocity of every
    replica becomes zero to rounding.  The classes' definition is the unweighted mean: with
    unequal masses the mean momentum is not removed exactly.

    Parameters
    ----------
    state : BatchState
        The batch; its velocities are changed in place.
    """
    N = state.N
    if not N:
        return
    for b in range(state.B):
        rows = state.replica(b)
        state.vx[rows] -= state.vx[rows].sum() / N
        state.vy[rows] -= state.vy[rows].sum() / N


class RelationAges:
    """Creation numbers of the relations of a batch, given as the classes give them.

    The classes number relations in the order they form: at every step the newly touching pairs
    take the next numbers of their ensemble's counter in ``(i, j)`` order (``PairTable.birth``;
    it orders ``sphere.neighbors`` and so which relation ``join_isolated_spheres`` draws).  This
    tracker does the same per replica after every engine step, follows the candidates through
    the engine's list rebuilds, and :func:`write_back` puts the numbers and the counter into the
    ensemble.

    Parameters
    ----------
    engine : BatchEngine
        The engine before its first step; its ``s.pairs`` were copied from ``ensembles``.
    ensembles : sequence of ensemble
        The ensembles of the replicas, in order (their pair tables give the numbers so far).
    """

    def __init__(self, engine, ensembles):
        s = engine.s
        self.B, self.BN = s.B, s.B * s.N
        keys, numbers = [], []
        for b, (p, e) in enumerate(zip(s.pairs, ensembles)):
            keys.append(self._keys(p.i + b * s.N, p.j + b * s.N))
            pt = e._pairs
            slot = pt.find(p.i, p.j) if len(p.i) else np.zeros(0, np.intp)
            known = p.active & (slot >= 0)
            numbers.append(np.where(known, pt.birth[np.where(known, slot, 0)] if len(pt.birth) else 0, 0))
        self.key = np.concatenate(keys).astype(np.int64)
        self.number = np.concatenate(numbers).astype(np.int64)
        self.active = np.concatenate([p.active for p in s.pairs]).astype(bool)
        self.next = np.array([e._pairs._births for e in ensembles], dtype=np.int64)
        self.C = None

    def _keys(self, ai, aj):
        return np.asarray(ai, dtype=np.int64) * self.BN + np.asarray(aj, dtype=np.int64)

    def after_step(self, engine):
        """Number the relations formed in the step the engine has just made.

        Parameters
        ----------
        engine : BatchEngine
            The engine, right after a step.
        """
        C = engine.C
        if C is not self.C:   # the candidate lists were rebuilt: carry the records over by pair
            key = self._keys(C.ai, C.aj)
            if len(self.key):
                at = np.minimum(np.searchsorted(self.key, key), len(self.key) - 1)
                found = self.key[at] == key
                self.number = np.where(found, self.number[at], 0)
                self.active = found & self.active[at]
            else:
                self.number = np.zeros(len(key), np.int64)
                self.active = np.zeros(len(key), bool)
            self.key, self.C = key, C
        newly = engine.active & ~self.active
        if newly.any():
            idx = np.flatnonzero(newly)               # replica by replica, (i, j) order within each
            reps = C.rep[idx]
            counts = np.bincount(reps, minlength=self.B)
            first = np.cumsum(counts) - counts
            self.number[idx] = self.next[reps] + (np.arange(len(idx)) - first[reps])
            self.next += counts
        self.active = engine.active

    def births(self, b, pt):
        """Creation numbers of replica ``b``'s candidates; sets the counter of ``pt`` (its pair table).

        Parameters
        ----------
        b : int
            Replica index.
        pt : PairTable
            The replica's ensemble's pair table.

        Returns
        -------
        ndarray of int64
            One number per candidate of replica b in the engine's canonical order (0 where the
            candidate is not a relation).
        """
        lo, hi = self.C.offsets[b], self.C.offsets[b + 1]
        pt._births = int(self.next[b])
        return np.where(self.active[lo:hi], self.number[lo:hi], 0)


def _steps(engine, n, cool, dt, ages=None):
    for _ in range(n):
        engine.step(cool, dt)
        if ages is not None:
            ages.after_step(engine)


def free_relaxation(engine, N, dt, dt_max, mu, ages=None):
    """``free_pre_equilibration(N)`` of the classes on every replica of ``engine``.

    Shear and plates off.  μ = 0 during the coarse levels (:func:`relaxation_levels`: N steps
    each, :func:`remove_linear_drift` after each) and N undamped steps at ``dt``; then μ of
    each replica and N undamped steps at ``dt``.  ``engine.s.mu`` holds ``mu`` afterwards and the
    pair history is flushed into ``engine.s.pairs``.

    Parameters
    ----------
    engine : BatchEngine
        The batch (its γ̇ should be 0, as in a constitution); advanced in place.
    N : int
        Steps per level and per final block (>= 0).
    dt : float
        Final time step (s), > 0.
    dt_max : float
        Step of the first level (s).
    mu : array_like (B,)
        Friction coefficient of each replica for the last block.
    ages : RelationAges, optional
        Records when the relations form (for :func:`write_back`).

    Returns
    -------
    int
        Number of steps run (``N·(levels + 2)``).

    Raises
    ------
    ValueError
        If ``N`` is negative, ``dt`` is not > 0 or ``dt_max`` is not finite (before any step).
    """
    N = int(N)
    if N < 0:
        raise ValueError(f"N={N!r} is out of range: allowed integers >= 0")
    levels = relaxation_levels(dt, dt_max)
    s = engine.s
    mu = np.array(np.broadcast_to(np.asarray(mu, dtype=float), (s.B,)))
    s.applying_shear = False
    engine.set_mu(np.zeros(s.B))
    for level_dt, cf in levels:
        _steps(engine, N, cf, level_dt, ages)
        remove_linear_drift(s)
    _steps(engine, N, 1, dt, ages)
    engine.set_mu(mu)
    _steps(engine, N, 1, dt, ages)
    engine.flush()
    return N * (len(levels) + 2)


def write_back(engine, b, ensemble, steps=0, ages=None, constitution=True, dt=None):
    """Put replica ``b`` of a relaxed (or measured) engine back into its ensemble.

    Positions, angles φ, velocities, forces, clock and strain of the spheres; the candidate
    pairs of the replica become the ensemble's pair table with their relations, states, ξ and
    ``d_eq`` (inactive transient candidates: stick, ξ = 0, as the classes leave them), so the
    crosslinking sees the contacts of the engine's last neighbour update.  The creation numbers
    of the relations (the order of ``neighbors``) are the classes' when ``ages`` recorded the
    relaxation (:class:`RelationAges`); without it, a relation of the ensemble before keeps its
    number and new relations get the next numbers in ``(i, j)`` order.  The ensemble's neighbour
    list and caches are invalidated; its ``step_count`` and ``n_constitution_steps`` advance by
    ``steps``.

    Parameters
    ----------
    engine : BatchEngine
        The engine after :func:`free_relaxation`.
    b : int
        Replica index (0 … B−1).
    ensemble : ensemble of ``particleShear.linkable``
        The ensemble the replica was copied from (same N).
    steps : int, optional
        Steps the replica was advanced (bookkeeping of the classes).
    ages : RelationAges, optional
        The record of when the relations formed during the relaxation.
    constitution : bool, default True
        The steps were a relaxation of the constitution (plates off afterwards, the ensemble's
        ``n_constitution_steps`` advances); False: a measurement (plates as the engine had them,
        the shear rate of its last step; a Verlet engine's half kick becomes the ensemble's).
    dt : float, optional
        The time step of the last step (default: the ensemble's ``dt``).
    """
    s = engine.s
    rows = s.replica(b)
    a = ensemble._a
    for name, src in (("x", "x"), ("y", "y"), ("phi", "phi"), ("xspeed", "vx"), ("yspeed", "vy"),
                      ("omega", "omega"), ("xforce", "fx"), ("yforce", "fy"), ("torque", "torque")):
        a[name][...] = getattr(s, src)[rows]
    ensemble.t = float(s.t[b])
    ensemble.shear = float(s.gamma[b])
    ensemble.applyingShear = bool(s.applying_shear) and not constitution
    if not constitution:
        ensemble.shear_rate = float(s.rate[b])
    if hasattr(ensemble, "mu"):        # a frictionless ensemble of particleShear.objects has none
        ensemble.mu = float(s.mu[b])

    p = engine.pairs_of(b)
    pt = ensemble._pairs
    i = np.array(p.i, dtype=np.intp)
    j = np.array(p.j, dtype=np.intp)
    key = (i.astype(np.int64) << 32) | j.astype(np.int64)
    keep = p.active | (p.state == PERMANENT)
    active = np.array(p.active, dtype=bool)
    if ages is not None and ages.C is not None:
        birth = ages.births(b, pt)
    else:
        birth = np.zeros(len(i), dtype=np.int64)
        had = np.zeros(len(i), dtype=bool)
        if len(pt.key):
            at = np.minimum(np.searchsorted(pt.key, key), len(pt.key) - 1)
            had = (pt.key[at] == key) & pt.active[at] & active
            birth[had] = pt.birth[at[had]]
        born = active & ~had
        birth[born] = pt.next_births(int(born.sum()))
    pt.i, pt.j, pt.key = i, j, key
    pt.state = np.where(keep, p.state, STICK).astype(np.int8)
    pt.xi = np.where(active, p.xi, 0.0)
    pt.d_eq = np.array(p.d_eq, dtype=float)
    pt.active = active
    pt.birth = birth
    pt.version += 1

    ensemble._invalidate_neighbours()
    ensemble._links_changed()
    ensemble._relations_edited()
    ensemble._g = None
    ensemble._last_dt = float(ensemble.dt if dt is None else dt)
    if engine.half is not None and hasattr(ensemble, "_half_kick"):
        h = to_host(engine.half[:, rows], "state")
        ensemble._half_kick = (h[0].copy(), h[1].copy(), h[2].copy())
    ensemble.step_count += int(steps)
    if constitution and hasattr(ensemble, "n_constitution_steps"):
        ensemble.n_constitution_steps += int(steps)


def relax_ensembles(ensembles, N, skin_factor=RELAX_SKIN, laws=None):
    """``free_pre_equilibration(N)`` of every ensemble, all in one engine, written back.

    Parameters
    ----------
    ensembles : sequence of ensemble
        Ensembles of ``particleShear.linkable`` with equal N, ``dt`` and ``dt_max`` (their μ may
        differ); shear rate 0, as in a constitution.
    N : int
        Steps per level and per final block (>= 0).
    skin_factor : float, optional
        Verlet skin of the engine in units of each replica's largest radius (> 0).  The result
        does not depend on it: the contacts are exact for any skin, and the zero terms of the
        candidates out of contact change no sum.
    laws : sequence, optional
        The central law of each ensemble, as :meth:`~particleShear.engine.state.BatchState.from_ensembles`
        takes them (default: the documented callback for every one).

    Returns
    -------
    int
        Steps run per ensemble.

    Raises
    ------
    ValueError
        If the ensembles differ in N, ``dt``, ``dt_max`` or integrator, or a step is not usable
        (before any step).
    """
    ensembles = list(ensembles)
    if not ensembles:
        return 0
    dts = {(float(e.dt), float(e.dt_max)) for e in ensembles}
    if len(dts) != 1:
        raise ValueError(f"ensembles have (dt, dt_max) = {sorted(dts)}: one engine relaxes one schedule")
    (dt, dt_max), = dts
    relaxation_levels(dt, dt_max)   # checks the steps before any work
    integrators = {getattr(e, "integrator", "euler") for e in ensembles}
    if len(integrators) != 1:
        raise ValueError(f"ensembles use the integrators {sorted(integrators)}: one engine relaxes with one")
    state = BatchState.from_ensembles(ensembles, laws=laws)
    mu = state.mu.copy()
    # the guard where an ensemble has one (a script's; the builders guard the measurement only)
    engine = BatchEngine(state, skin_factor=skin_factor, integrator=integrators.pop(),
                         guard=[getattr(e, "stability_guard", None) is not None for e in ensembles])
    engine.phase = "constitution"
    ages = RelationAges(engine, ensembles)
    steps = free_relaxation(engine, N, dt, dt_max, mu, ages)
    for b, e in enumerate(ensembles):
        write_back(engine, b, e, steps, ages)
    return steps
