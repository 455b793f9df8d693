"""The observers of a run: live particle window, snapshots and movie, live stress window.

Each is an :class:`~particleShear.engine.observers.Observer` (an int ``every`` and
``observe(engine, phase, step, total)``) that the loops of the measurement call after the steps
of its period (:func:`~particleShear.engine.observers.notify`).  They draw with the renderers of
:mod:`.drawing` and never change the state, so a drawn run gives the numbers of the same seed
headless, bit for bit.

What they draw comes from a *scene* callable ``scene(engine)``: for the engine, a
:class:`ReplicaView` of replica b (:class:`ReplicaScene`), which shows the renderers the
attributes they read of an ensemble, taken from the engine's state; for the documented
classes' own loop (:meth:`~.experiment.OscillatoryShearExperiment.run_protocol`) the ensemble
itself.  :meth:`~.experiment.OscillatoryShearExperiment.observers` builds the observers of an
experiment.
"""
__docformat__ = "numpy"

import numpy as np

from ..engine.observers import Observer
from ..engine.xp import to_host

__all__ = ["ReplicaView", "ReplicaScene", "LiveDrawing", "SnapshotWriter", "StressWindow"]


class _Pairs:
    """The pair table a renderer reads: ``i, j`` (local sphere indices), ``state`` (stick/slip/permanent)
    and ``active`` (a relation), host copies."""
    __slots__ = ("i", "j", "state", "active")

    def __init__(self, i, j, state, active):
        self.i, self.j, self.state, self.active = i, j, state, active


class ReplicaView:
    """Replica ``b`` of an engine's state, seen as the ensemble the renderers of :mod:`.drawing` draw.

    It offers what they read — ``_a`` (host copies of ``x, y, r, phi``, µm and rad), ``_pairs``
    (``i, j, state, active`` of the replica's candidates; both also as the public, read-only
    :attr:`sphere_arrays` and :attr:`pair_table`), ``_le_shift()`` (L_y·γ, µm),
    ``size_x``, ``size_y`` (µm), ``t`` (s), ``shear`` (γ) and ``graphical_output_configuration`` —
    as copies read from ``engine.s`` and the engine's pair history when first asked after a step
    (one read per step at most, however often a picture reads them).  Nothing of the engine is
    written.

    Parameters
    ----------
    engine : BatchEngine
        The engine whose state is shown.
    b : int
        The replica (0 … B−1).
    graphical_output_configuration : Graphical_output_configuration, optional
        Colours and drawing options (the documented ensemble's), None for the built-in ones.
    """

    def __init__(self, engine, b, graphical_output_configuration=None):
        self.engine, self.b = engine, int(b)
        self.graphical_output_configuration = graphical_output_configuration
        self._key = None
        self._read = {}

    def _current(self):
        e = self.engine
        key = (e.phase, e.step_count)
        if key != self._key:
            self._key, self._read = key, {}
        return self._read

    def _replica_value(self, name):
        cur = self._current()
        if name not in cur:
            cur[name] = float(np.asarray(to_host(getattr(self.engine.s, name)[self.b], "state")))
        return cur[name]

    @property
    def _a(self):
        cur = self._current()
        if "_a" not in cur:
            s = self.engine.s
            rows = s.replica(self.b)
            cur["_a"] = {name: np.array(to_host(getattr(s, name)[rows], "state")) for name in ("x", "y", "r", "phi")}
        return cur["_a"]

    @property
    def _pairs(self):
        cur = self._current()
        if "_pairs" not in cur:
            e, b = self.engine, self.b
            p, c = e.s.pairs[b], e.s.contacts
            if c.C is None:           # before the first step: the lists as constituted
                state, active = p.state, p.active
            else:                     # the flat history of the running phase, replica b's segment
                lo, hi = int(c.C.offsets[b]), int(c.C.offsets[b + 1])
                state, active = (to_host(a[lo:hi], "state") for a in (c.state_p, c.active))
            cur["_pairs"] = _Pairs(np.array(p.i), np.array(p.j), np.array(state), np.array(active))
        return cur["_pairs"]

    @property
    def sphere_arrays(self):
        """``x, y, r, phi`` of the replica's spheres (µm, rad), named as an ensemble's
        :attr:`~particleShear.base.canvas.CanvasPoints.sphere_arrays`.

        Returns
        -------
        dict of str to numpy.ndarray
            Read-only views of the host copies this view read after the engine's last step.
        """
        out = {}
        for name, row in self._a.items():
            out[name] = row.view()
            out[name].flags.writeable = False
        return out

    @property
    def pair_table(self):
        """The replica's candidate pairs: ``i, j`` (local sphere indices), ``state`` (stick / slip /
        permanent) and ``active`` (a relation), host copies (the fields a picture reads of an
        ensemble's :attr:`~particleShear.base.pair_canvas.CanvasPointsNeighbors.pair_table`).

        Returns
        -------
        object
            With array attributes ``i, j, state, active``.
        """
        return self._pairs

    @property
    def size_x(self):
        """Box width L_x (µm)."""
        return self._replica_value("Lx")

    @property
    def size_y(self):
        """Box height L_y (µm)."""
        return self._replica_value("Ly")

    @property
    def t(self):
        """Clock of the replica (s)."""
        return self._replica_value("t")

    @property
    def shear(self):
        """Strain γ of the replica."""
        return self._replica_value("gamma")

    def _le_shift(self):
        """Lees-Edwards shift L_y·γ of the image above the cell (µm)."""
        return self.size_y * self.shear


class ReplicaScene:
    """What the observers of one replica draw and plot, in whichever engine runs its phase.

    :meth:`bind` names the engine and the replica's index there (a batch's phases may order
    the replicas differently); calling the scene returns the :class:`ReplicaView` of that
    replica, and :meth:`samples` reads its rows of the protocol's ``engine.record``.

    Parameters
    ----------
    graphical_output_configuration : Graphical_output_configuration, optional
        Colours and drawing options of the views.
    """

    def __init__(self, graphical_output_configuration=None):
        self.graphical_output_configuration = graphical_output_configuration
        self.view = None

    def bind(self, engine, b):
        """Show replica ``b`` of ``engine`` from now on.

        Parameters
        ----------
        engine : BatchEngine
            The engine of the next phase.
        b : int
            The replica's index in it (0 … B−1).
        """
        self.view = ReplicaView(engine, b, self.graphical_output_configuration)

    def __call__(self, engine):
        """The view of the bound replica (``engine`` must be the bound engine).

        Parameters
        ----------
        engine : BatchEngine
            The engine calling the observer.

        Returns
        -------
        ReplicaView

        Raises
        ------
        ValueError
            If ``engine`` is not the engine of the last :meth:`bind`.
        """
        if self.view is None or self.view.engine is not engine:
            raise ValueError("engine is not the engine this scene is bound to (call bind(engine, b) first)")
        return self.view

    def samples(self, engine, lo, hi):
        """Rows ``lo … hi − 1`` of the bound replica in ``engine.record`` (during the protocol).

        Parameters
        ----------
        engine : BatchEngine
            The engine running the protocol.
        lo, hi : int
            Protocol steps (0-based, ``hi`` excluded).

        Returns
        -------
        numpy.ndarray (hi − lo, 4)
            ``t`` (s), strain γ, τ_surface and τ_internal (Pa) of each step.
        """
        b = self(engine).b
        rec = engine.record
        return np.stack([np.asarray(to_host(rec[k][lo:hi, b], "state"))
                         for k in ("t", "strain", "stress_surface", "stress_internal")], axis=1)


class LiveDrawing(Observer):
    """The live particle window: ``renderer.update(scene)`` after the steps of the period, in both phases.

    A :class:`~.drawing.TkRenderer` redraws at most every ``min_interval`` seconds, so calling it
    every step costs a clock read when nothing is drawn.

    Parameters
    ----------
    renderer : Renderer
        A live renderer (``renderer.live``).
    scene : callable
        ``scene(engine)``: what is drawn (:class:`ReplicaScene`).
    every : int, default 1
        Call period in steps (≥ 1).
    """

    def __init__(self, renderer, scene, every=1):
        Observer.__init__(self, every)
        self.renderer, self.scene = renderer, scene

    def observe(self, engine, phase, step, total):
        """Redraw the window (if its renderer's interval has passed).

        Parameters
        ----------
        engine : BatchEngine or ensemble
            Passed to ``scene``.
        phase : str
            The running phase.
        step, total : int
            Steps done and steps of the phase.
        """
        self.renderer.update(self.scene(engine))


class SnapshotWriter(Observer):
    """Snapshots of the protocol at 1.0.2's cadence and names, and the movie after the last step.

    The snapshot of step index ``i`` (0-based: the state after ``i + 1`` steps, as the reference
    saved it after its step ``i``) is taken for every ``i`` that is a multiple of ``image_N``
    (docs/output.md, "Snapshots": ``image0000000``, ``image0000067``, …).  That cadence is offset
    by one step from a period, so the writer is called every step and decides itself.

    Parameters
    ----------
    save : callable
        ``save(i, scene)`` writes the snapshot of index ``i``
        (:meth:`~.experiment.OscillatoryShearExperiment.save_canvas_image`).
    scene : callable
        ``scene(engine)``: what is drawn.
    image_N : int
        Steps between two snapshots (≥ 1, :func:`~.experiment.image_cadence`).
    movie : callable or None
        Called once after the last protocol step (writes ``movie.gif``); None: no movie.
    """

    def __init__(self, save, scene, image_N, movie=None):
        Observer.__init__(self, 1)
        self.save, self.scene, self.image_N, self.movie = save, scene, int(image_N), movie

    def observe(self, engine, phase, step, total):
        """In the protocol: save the snapshot of index ``step − 1`` when due; the movie after the last step.

        Parameters
        ----------
        engine : BatchEngine or ensemble
            Passed to ``scene``.
        phase : str
            The running phase (nothing is saved in the pre-equilibration).
        step, total : int
            Steps done and steps of the phase.
        """
        if phase != "protocol":
            return
        if (step - 1) % self.image_N == 0:
            self.save(step - 1, self.scene(engine))
        if step == total and self.movie is not None:
            self.movie()


class StressWindow(Observer):
    """The live stress/strain window: three dots per protocol step (τ_internal, τ_surface, γ).

    Each call plots every sample recorded since the previous call, relative to the first
    sample (:meth:`~.evaluation.EvaluationHandlerPlotter.plot`), then lets the window process
    its events.

    Parameters
    ----------
    plotter : EvaluationHandlerPlotter
        Maps samples to dots on the window's canvas.
    window : StressPlotWindow
        The window (``update()`` processes its events).
    samples : callable
        ``samples(engine, lo, hi)`` → array (hi − lo, 4) of t (s), γ, τ_surface, τ_internal (Pa)
        of steps ``lo … hi − 1`` (:meth:`ReplicaScene.samples`).
    every : int, default 1
        Call period in steps (≥ 1); every sample is plotted whatever the period.
    """

    def __init__(self, plotter, window, samples, every=1):
        Observer.__init__(self, every)
        self.plotter, self.window, self.samples = plotter, window, samples
        self.done = 0
        self.first = None

    def observe(self, engine, phase, step, total):
        """Plot the samples of the protocol steps since the last call and update the window.

        Parameters
        ----------
        engine : BatchEngine or ensemble
            Passed to ``samples``.
        phase : str
            The running phase (nothing is plotted in the pre-equilibration).
        step, total : int
            Steps done and steps of the phase.
        """
        if phase != "protocol":
            return
        rows = self.samples(engine, self.done, step)
        if self.first is None and len(rows):
            self.first = rows[0].copy()
        for t, strain, surface, internal in rows.tolist():
            self.plotter.plot(t, strain, surface - self.first[2], internal - self.first[3])
        self.done = step
        self.window.update()
