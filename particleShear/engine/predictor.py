"""The velocity Verlet predictor of a batch: the half kick the next force phase sees.

A :class:`Predictor` is part of the state (:attr:`~particleShear.engine.state.BatchState.predictor`),
as its contacts are (:mod:`.contacts`): with ``integrator="verlet"`` each step's kick keeps the half
kick ``F·dt/(2m)`` (and ``T·dt/(2I)``) of every sphere here
(:func:`~particleShear.engine.integrate.half_kick`), and the velocity-dependent terms of the next
force phase see the velocities moved by it.  The engine (:class:`~particleShear.engine.step.BatchEngine`)
and its compiled step (:mod:`.numba_step`) read and replace it; an engine keeps none of its own.

When it is kept and when dropped (None: the next force phase sees the velocities themselves):

* an engine built on a state continues the state's predictor (:meth:`Predictor.start`), unless
  its integrator is Euler or the predictor's rows are not the state's B·N spheres (an ensemble
  that gained or lost spheres since): then it is dropped; an engine given ``half=`` sets it;
* a relaxation (:func:`particleShear.base.engine_adapter.relax_state`, a constitution) and a
  measurement's pre-equilibration on an ensemble
  (:meth:`~particleShear.simulation.experiment.OscillatoryShearExperiment.engine_of_ensemble`)
  drop it first (:meth:`Predictor.drop`): the half kick of a constitution predates its bonds;
* a copy of the state keeps it: :meth:`~particleShear.engine.state.BatchState.to_backend` (its
  array copied to the target backend) and pickling; :meth:`~particleShear.engine.state.BatchState.concat`
  joins the states' predictors replica by replica (:meth:`Predictor.joined`: zeros for a state
  without one, none if no state has one);
* a state on documented ensembles (:func:`~particleShear.base.engine_adapter.state_of_ensembles`)
  holds a batch of one's own predictor (``ensemble._predictor``, as its pair table), so successive
  engines of an ensemble continue it; a batch of several holds their predictors joined, and
  :func:`~particleShear.base.engine_adapter.write_back` hands each its rows.

The engine replaces :attr:`Predictor.half` at every kick and never writes into it, so a reference
to the array is its value of then (:func:`~particleShear.base.engine_adapter.untouched_on_failure`
puts one back).

Shapes: B replicas, B·N sphere rows.  Units µm/s for the rows of ``vx, vy``, 1/s for ω.
"""
__docformat__ = "numpy"

from .xp import to_host

__all__ = ["Predictor"]


class Predictor:
    """The velocity Verlet predictor of a batch (see the module docstring for its life cycle).

    Parameters
    ----------
    half : ndarray (3, B·N) or None, optional
        The half kick ``F·dt/(2m)`` of (vx, vy, ω) of the last step (µm/s, µm/s, 1/s), on the
        state's backend; None (default): no step yet.

    Attributes
    ----------
    half : ndarray (3, B·N) or None
        As the parameter; replaced (never written into) by each Verlet kick.
    """

    def __init__(self, half=None):
        self.half = half

    def drop(self):
        """Forget the predictor: the next force phase sees the velocities themselves (as before a first step)."""
        self.half = None

    def start(self, integrator, rows, half=None):
        """The predictor an engine built on the state starts with: ``half`` when given, else the one
        carried, kept for a Verlet engine whose state has its rows and dropped otherwise.

        Parameters
        ----------
        integrator : {"euler", "verlet"}
            The engine's integrator (Euler has no predictor).
        rows : int
            The state's sphere rows, B·N.
        half : ndarray (3, B·N), optional
            A predictor to set instead (``BatchEngine(half=…)``), taken as it is.
        """
        if half is not None:
            self.half = half
        elif integrator != "verlet" or (self.half is not None and self.half.shape[-1] != rows):
            self.drop()

    def on(self, backend):
        """A copy of this predictor on ``backend`` (:meth:`~particleShear.engine.state.BatchState.to_backend`).

        Parameters
        ----------
        backend : Backend
            The target backend.

        Returns
        -------
        Predictor
        """
        return Predictor(None if self.half is None else backend.asarray(to_host(self.half, "state")))

    @classmethod
    def joined(cls, predictors, rows, xp):
        """The predictors of several states side by side, in their order: each one's rows, zeros
        where a state has none or one whose rows are not its state's (a replica that took no step
        yet sees its velocities, as with none; :meth:`start` drops such a predictor likewise).

        Parameters
        ----------
        predictors : sequence of Predictor
            One per state.
        rows : sequence of int
            The sphere rows B·N of each state.
        xp : module
            The states' array namespace.

        Returns
        -------
        Predictor
            With None when no state has a predictor.
        """
        if all(p.half is None for p in predictors):
            return cls()
        return cls(xp.concatenate([p.half if p.half is not None and p.half.shape[-1] == n else xp.zeros((3, n))
                                   for p, n in zip(predictors, rows)], axis=1))

    def rows_of(self, rows):
        """The predictor of the sphere rows ``rows`` on the host (a copy), or None without one.

        Parameters
        ----------
        rows : slice
            Sphere rows (e.g. :meth:`~particleShear.engine.state.BatchState.replica`).

        Returns
        -------
        numpy.ndarray (3, n) or None
        """
        return None if self.half is None else to_host(self.half[:, rows], "state").copy()
