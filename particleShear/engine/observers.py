"""Observers: what watches a measurement without changing it (HOOMD-blue's writers on triggers).

The loops of the measurement (:func:`~particleShear.engine.step.pre_equilibrate` and
:func:`~particleShear.engine.step.protocol`) take a sequence of observers.  An observer is any
object with

- an int attribute ``every`` (≥ 1): its call period in steps, and
- a method ``observe(engine, phase, step, total)``,

and the loops call it after every step whose count ``step`` (steps done in the phase, 1 … total)
is a multiple of ``every``, and after the last step of the phase (``step == total``).  ``phase``
is ``"pre-equilibration"`` or ``"protocol"``.  Drawing, snapshots, movies and the live stress
window of a run are observers (:mod:`particleShear.simulation.observers`).

An observer only reads: ``engine.s`` (the :class:`~particleShear.engine.state.BatchState`,
replica b in rows ``b·N … b·N + N − 1``), ``engine.record`` during the protocol (the series
recorded so far) and the pair history; it never writes into them and draws no random numbers,
so a watched run gives the numbers of the same run unwatched, bit for bit (tested in
``particleShearTest/test_observers.py``).  In a batch each replica's observers read their
replica only.
"""
__docformat__ = "numpy"

__all__ = ["Observer", "check_observers", "notify"]


class Observer:
    """Base class of the observers (any object with ``every`` and ``observe`` is one).

    Parameters
    ----------
    every : int, default 1
        Call period in steps (≥ 1): the loops call :meth:`observe` after every step whose count
        is a multiple of it, and after the last step of each phase.

    Raises
    ------
    ValueError
        If ``every`` is not an integer ≥ 1.
    """

    def __init__(self, every=1):
        self.every = every
        check_observers((self,))

    def observe(self, engine, phase, step, total):
        """Look at the state after ``step`` of ``total`` steps of ``phase`` (nothing in this base class).

        Parameters
        ----------
        engine : BatchEngine
            The engine of the running phase; read ``engine.s`` (and, in the protocol,
            ``engine.record``), never write.
        phase : {"pre-equilibration", "protocol"}
            The running phase.
        step : int
            Steps done in the phase (1 … ``total``).
        total : int
            Steps of the phase.
        """


def check_observers(observers):
    """Raise ValueError unless every observer has an int ``every`` ≥ 1 and an ``observe`` method.

    Parameters
    ----------
    observers : sequence
        The observers of a loop.

    Raises
    ------
    ValueError
        Naming the observer and its ``every`` (allowed: an integer ≥ 1), or an observer without
        ``observe``.
    """
    for ob in observers:
        every = getattr(ob, "every", None)
        if isinstance(every, bool) or not isinstance(every, int) or every < 1:
            raise ValueError(f"observer {ob!r}: every={every!r} is out of range: allowed an integer >= 1")
        if not callable(getattr(ob, "observe", None)):
            raise ValueError(f"observer {ob!r} has no observe(engine, phase, step, total) method")


def notify(observers, engine, phase, step, total):
    """Call the observers due after ``step`` of ``total``: ``step % every == 0`` or the last step.

    Parameters
    ----------
    observers : sequence
        Objects with ``every`` and ``observe`` (see the module docstring).
    engine : BatchEngine
        The engine of the running phase.
    phase : str
        ``"pre-equilibration"`` or ``"protocol"``.
    step : int
        Steps done in the phase (1 … ``total``).
    total : int
        Steps of the phase.
    """
    for ob in observers:
        if step % ob.every == 0 or step == total:
            ob.observe(engine, phase, step, total)
