"""The documented step as the engine's phases on the ensemble's own state (docs/classes.md, "The documented classes").

A canvas keeps one :class:`~particleShear.engine.step.BatchEngine` on a batch of one
(:func:`~particleShear.base.engine_adapter.state_of_ensemble`) whose sphere arrays are the ensemble's
rows, whose clock, strain, rate and μ are the ensemble's replica cells and whose pairs are its pair
table.  Before each force phase the engine is told what changed from outside (a strain or μ set on
the ensemble, an edited pair table) and given the plates' flag; the relations come back after each
phase.  The engine is kept under one key and dropped at :meth:`EngineStep._drop_engine`.

The documented step's three phases are three calls of the canvas, so the record a force phase
returns (:class:`~particleShear.engine.step.ForceRecord`) is kept here, on the canvas, until its
step's movement: the engine passes it as a value and keeps none.
"""
__docformat__ = "numpy"
import numpy as np

from ..engine.guard import transient_ratios
from ..engine.step import BatchEngine
from .engine_adapter import state_of_ensemble
from .register import KeptTerms

__all__ = ["EngineStep", "ForcePhaseGeometry"]


class EngineStep:
    """Mixin of the documented canvases: the step's phases on the ensemble's engine (a batch of one).

    Hooks, read when an engine is made (its configuration, :class:`~particleShear.engine.config.EngineConfig`):
    :meth:`_lees_edwards` (images offset by ``Ly·γ``; part of the engine's key, so a change of
    ``use_lees_edwards`` makes a new engine) and :attr:`_strain_only_while_shearing` (γ += γ̇·dt only
    while ``applyingShear``; a class attribute, also in the key).
    """

    _engine_pairs = None    # (table, version) after the last write-back of the engine's relations
    #: the strain γ and μ as the kept engine last had them (its own strain after a movement): a value
    #: set on the ensemble from outside differs
    _engine_strain = _engine_mu = None
    #: the record of the last force phase of the kept engine (ForceRecord), for the acceleration and
    #: movement phases of its step; None before one, after the step's movement and with the engine dropped
    _force_record = None
    #: the relations of the last force phase (:class:`ForcePhaseGeometry`); None before one
    _g = None

    #: the strain advances only while the plates shear (``applyingShear``; the frictionless canvases)
    _strain_only_while_shearing = True

    def _lees_edwards(self):
        return bool(self.use_lees_edwards)

    @property
    def _engine(self):
        """The engine kept in the canvas's memo (None before the first phase and after a drop)."""
        return self._memo.peek("engine")

    def _engine_view_key(self):
        return (self._block_version, self._params_version, self._rng, float(getattr(self, "k", 0.0)),
                float(getattr(self, "nu", 0.0)), float(getattr(self, "k_t", 0.0)), float(getattr(self, "nu_t", 0.0)),
                float(self.size_x), float(self.size_y), getattr(self, "integrator", "euler"), self._lees_edwards(),
                bool(self._strain_only_while_shearing))

    def _step_engine(self):
        """The ensemble's engine, kept in the memo under :meth:`_engine_view_key` (the block fitted
        first, as ``state_of_ensembles`` fits it: the key holds the block the engine is made on)."""
        self._fit_block()
        return self._memo.get("engine", self._engine_view_key(), self._new_engine)

    def _new_engine(self):
        """A new engine on the ensemble's state (which holds the ensemble's Verlet predictor: the
        new engine continues the one it replaces, :mod:`particleShear.engine.predictor`)."""
        self._drop_engine()
        self._kept_terms = KeptTerms()        # (what the force phases hand out, for the force register)
        eng = BatchEngine(state_of_ensemble(self, backend="auto"), skin_factor=self.neighbour_skin, guard=False,
                          integrator=getattr(self, "integrator", "euler"), keep_terms=True, terms_to=self._kept_terms,
                          numbers_relations=True,          # (the creation numbers order the neighbours)
                          lees_edwards=self._lees_edwards(),
                          strain_only_while_shearing=self._strain_only_while_shearing)
        self._engine_pairs = (self._pairs, self._pairs.version)
        self._engine_strain, self._engine_mu = eng.s.gamma.item(0), eng.s.mu.item(0)
        return eng

    def _drop_engine(self):
        """Forget the engine (the one invalidation point; the Verlet predictor is the ensemble's own, kept)."""
        eng = self._memo.drop("engine")
        self._force_record = None       # (the record is the dropped engine's)
        if eng is not None:
            self._engine_pairs = None

    def _hand_to_engine(self, eng):
        """Bring the engine up to what was changed on the ensemble from outside (before a force phase).

        Clock, strain, rate and μ are the engine's own cells; what follows from a change of them
        is done here, found against the values the engine last had: a strain set from outside moves
        the boundary images by ``Ly·Δγ`` (the lists are rebuilt), a μ set from outside renews the
        candidates' constants (:meth:`~particleShear.engine.step.BatchEngine.set_mu`).  The plates'
        flag ``applyingShear`` is copied (the state has one for its whole batch), and an edited pair
        table gives the engine its candidates anew.
        """
        s = eng.s
        s.applying_shear = bool(getattr(self, "applyingShear", False))
        gamma, mu = s.gamma.item(0), s.mu.item(0)
        if gamma != self._engine_strain:
            s.contacts.need[:] = True
        if mu != self._engine_mu:
            eng.set_mu(mu)
        self._engine_strain, self._engine_mu = gamma, mu
        pairs = self._pairs
        if self._engine_pairs != (pairs, pairs.version) or s.pairs[0] is not pairs:
            # edited since the engine's last write-back: candidates and constants anew from the table
            s.pairs[0] = pairs
            s.contacts.reload(s)
        elif s.contacts.C is not None:
            self._share_history(eng)

    def _share_history(self, eng):
        """Make the engine's relation history the pair table's own arrays (a batch of one has one segment)."""
        pairs = self._pairs
        eng.s.contacts.use_history(pairs.state, pairs.xi, pairs.active, pairs.birth)

    def _engine_force_phase(self):
        """Force phase on the engine: neighbours, terms, scatter, the register."""
        eng = self._step_engine()
        self._hand_to_engine(eng)
        extra = self._frc.copy() if self._frc.any() else None     # forces put on before the phase add up
        g = self._force_record = eng.force_phase()[0]     # (compiled on the Numba backend)
        if extra is not None:
            self._frc += extra
        self.force_register.set_from_engine(self, eng, self._kept_terms.last, current=True)
        self._g = ForcePhaseGeometry(eng, g)
        self._take_relations(eng)
        return eng

    def _take_relations(self, eng):
        """The relations, states and ξ of the engine's last phase into the pair table."""
        eng.flush()
        self._share_history(eng)
        self._engine_pairs = (self._pairs, self._pairs.version)

    def _engine_accelerate(self, cool, dt):
        eng = self._engine
        if eng is None:          # a kick without a force phase before it
            eng = self._step_engine()
            self._hand_to_engine(eng)
        eng.accelerate(cool, dt, self._force_record)

    def _engine_move(self, dt):
        """Movement on the engine (the ensemble's clock and strain advance in their cells)."""
        eng = self._engine
        if eng is None:
            eng = self._step_engine()
            self._hand_to_engine(eng)
        # where the drift takes the spheres: non-finite or far outside the cell stops the run (before the wrap)
        self._check_positions(self._pos + self._vel[:2] * dt)
        outside = eng.s.gamma.item(0) != self._engine_strain     # a strain set since the force phase
        eng.move(dt, self._force_record)      # (compiled after a compiled force phase)
        self._force_record = None       # (the step's record ends with its movement, as in BatchEngine.step)
        if outside:             # the boundary images moved by Ly·Δγ: the lists anew at the next force phase
            eng.s.contacts.need[:] = True
        self._engine_strain = eng.s.gamma.item(0)      # (the engine's own advance)
        self._pos_version += 1

    def _engine_move_spheres(self, dt):
        """The documented ``move(dt)``: ξ rule, drift of x, y, φ (no strain, wrap or clock)."""
        eng = self._engine
        if eng is None:
            eng = self._step_engine()
            self._hand_to_engine(eng)
        eng.move_spheres(dt, self._force_record)
        eng.s.contacts.need[:] = True
        self._pos_version += 1

    def _closest_contact(self):
        """``(ratio, i, j)``: the smallest ``d/(r_i + r_j)`` of a transient contact of the last force phase
        (:func:`~particleShear.engine.guard.transient_ratios`, inf without one), or None without candidates."""
        eng, g = self._engine, self._force_record
        if eng is None or g is None or not eng.s.contacts.C.P:
            return None
        C = eng.s.contacts.C
        ratio = transient_ratios(C, np.sqrt(g.dx * g.dx + g.dy * g.dy), g.active)
        k = int(np.argmin(ratio))
        return float(ratio[k]), int(C.ai[k]), int(C.aj[k])


class ForcePhaseGeometry:
    """The relations of the last force phase as the canvas's ``_g`` (for guards and tests), made when read.

    Per relation (``P`` of them): ``slots`` (pair-table rows), ``ai, aj``, ``ri, rj`` (µm), the
    minimum-image vector ``dx, dy``, distance ``d``, ``d0 = r_i + r_j``, unit normal ``nx, ny``, image
    velocity ``dvx`` (µm/s), ``perm`` (bond), ``trans`` (transient contact), ``active`` (all true).

    Parameters
    ----------
    engine : BatchEngine
        The ensemble's engine after its force phase (a batch of one).
    record : ForceRecord
        What that force phase returned (:meth:`~particleShear.engine.step.BatchEngine.force_phase`).
    """

    NAMES = ("P", "slots", "ai", "aj", "ri", "rj", "d", "d0", "nx", "ny", "dx", "dy", "dvx", "perm", "trans",
             "active")

    def __init__(self, engine, record):
        self._engine = engine
        self._record = record

    def __getattr__(self, name):
        if name not in self.NAMES:
            raise AttributeError(name)
        eng = self._engine
        g, C = self._record, eng.s.contacts.C
        m = np.asarray(g.active, dtype=bool)
        dx, dy = g.dx[m], g.dy[m]
        ai, aj = C.ai[m], C.aj[m]
        values = {"P": int(m.sum()), "slots": eng.s.pairs[0].find(ai, aj), "ai": ai, "aj": aj, "ri": C.ri[m],
                  "rj": C.rj[m], "d": np.sqrt(dx * dx + dy * dy), "d0": C.d0[m], "nx": g.nx[m], "ny": g.ny[m],
                  "dx": dx, "dy": dy, "dvx": np.broadcast_to(g.dvx, m.shape)[m], "perm": C.perm[m],
                  "trans": C.trans[m], "active": np.ones(int(m.sum()), bool)}
        self.__dict__.update(values)
        return values[name]
