"""The one measurement driver: the runs of one schedule, any protocol, measured in one engine.

Every measurement runs through :func:`measure_sessions` — ``runSimulation`` (one session),
:func:`~particleShear.run.measurement.measure` (a batch: ``doParticleShearSimulation``,
``run_batch``, the series and sweeps) — whatever its protocol: the constitution of every replica
(relaxations in the engine, :func:`_constitute`), the pre-equilibration of all replicas in one engine
(:func:`pre_equilibrated`), then the protocol's part (:data:`PARTS`, chosen by the protocol's
:attr:`~particleShear.protocols.Protocol.loop`, data of the registry): the reference's oscillation
with its observers, snapshots and file (:class:`Oscillation`), the one recording loop driven by a
rate schedule or a controller (:class:`Recording`), or oscillations on one packing
(:class:`Segments`); then each replica's result.  It lies in the simulation layer, below the run
layer that builds the sessions and gives the result type and the analysis (:class:`Conclusion`;
``docs/design.md``, "Layers").
"""
__docformat__ = "numpy"
import dataclasses
import logging
import time

import numpy as np

from ..base.compiled_phases import compile_tensor_kernel
from ..base.stability import SimulationInstabilityError
from ..engine.microstructure import Stroboscope
from ..engine.numba_step import compile_kernels
from ..engine.rheometer import shear_record
from ..engine.state import BatchState
from ..engine.step import BatchEngine, EngineInstability, pre_equilibrate, protocol
from ..engine.xp import auto_without_numba, get_backend
from ..linkable.builders import MAX_RELAXATIONS, Relaxation, time_steps_from_model
from ..protocols import PROTOCOLS
from .observers import ReplicaScene

__all__ = ["ENGINE_SKIN_FACTOR", "PARTS", "Conclusion", "Oscillation", "Recording", "Segments", "dt_over_tau",
           "measure_sessions", "pre_equilibrated", "protocol_steps", "replica_record"]

#: the logger of the batch phases' messages (the run layer's name, as before the move)
_log = logging.getLogger("particleShear.run.batch")

#: Verlet skin of the engines of a batch (constitution and measurement), in units of each
#: replica's largest radius.  The contacts of every step are exact for any skin and the zero
#: terms of candidates out of contact change no force sum, so the trajectories do not depend on
#: it (the stress samples, pairwise sums over the candidates, agree to rounding, ~1e-15
#: relative: test_engine_neighbours.TestSkin); at
#: 0.2 r_max a compressed packing has ~0.9 of its candidates in contact against ~0.6 at 0.5, and
#: a step of 32 default replicas costs ~30 % less (measured: protocol 95–100 → 65–68 µs per
#: replica-step, constitution ~40 % less CPU time), the extra rebuilds included.
ENGINE_SKIN_FACTOR = 0.2


def dt_over_tau(p, amplitude=None):
    """The protocol time step in units of τ (the time-step rule is linear in τ).

    Parameters
    ----------
    p : dict
        The run's arguments (defaults filled in).
    amplitude : float, optional
        The strain amplitude the rule is evaluated at (default ``p["theAmplitude"]``).

    Returns
    -------
    float
    """
    A = p["theAmplitude"] if amplitude is None else amplitude
    return time_steps_from_model(1.0, p["bimodal_factor"], p["theMu"], p["relative_transversal_link_strength"], A,
                                 p["relative_viscosity"])[0] * p["time_step_factor"]


def protocol_steps(q):
    """Step counts of a (normalized, checked) protocol: its ``steps`` at this run's time step.

    Parameters
    ----------
    q : dict
        The arguments of the run (:func:`~particleShear.run.rheometer.normalize_protocol`).

    Returns
    -------
    dict
        ``dt_over_tau``; ``steps`` (steady, relaxation, creep: all steps), ``ramp`` (relaxation);
        ``segments`` (sweeps: the oscillatory steps of each step of the sweep) and ``dts`` (sweeps:
        each step's dt/τ).
    """
    return PROTOCOLS[q.get("protocol", "oscillatory")].steps(q, lambda amplitude=None: dt_over_tau(q, amplitude))


@dataclasses.dataclass(frozen=True)
class Conclusion:
    """What the run layer gives the driver to make a replica's result (the layers above this one).

    Parameters
    ----------
    result : type
        The result type (:class:`~particleShear.run.result.SimulationResult`): called with the
        fields of an oscillatory run, its ``of_protocol`` with those of another protocol's run.
    analyse_record : callable
        ``analyse_record(protocol, kw, series, tau, steps) -> (summary, curves)`` of a recorded
        protocol's replica (:func:`~particleShear.run.rheometer_analysis.analyse_record`).
    analyse_sweep : callable
        ``analyse_sweep(kw, segments, tau) -> steps`` of a sweep's replica
        (:func:`~particleShear.run.rheometer_analysis.analyse_sweep`).
    write : callable
        ``write(sim, result)``: the file of another protocol's run (``saveData``;
        :func:`~particleShear.run.rheometer_files.write_protocol_file`).
    """

    result: type
    analyse_record: object
    analyse_sweep: object
    write: object


def measure_sessions(sessions, constituted=False, conclusion=None):
    """Constitute, pre-equilibrate and measure sessions that share a protocol and a schedule.

    The one driver of every measurement: the constitution (relaxations in the engine,
    :func:`_constitute`), the protocol part's plan per session (:meth:`Oscillation.plan`: the
    reservation of the output file, the experiment and the schedule), for each group of equal
    protocol schedule the pre-equilibration of its replicas in one engine
    (:func:`pre_equilibrated`) and the part's loop on that engine, then each replica's result
    (:meth:`Oscillation.conclude`).  The part is :data:`PARTS` of the protocol's
    :attr:`~particleShear.protocols.Protocol.loop` (the protocol of the sessions' run parameters;
    "oscillatory" for a session without them, as ``runSimulation``'s).  An interrupt
    (``KeyboardInterrupt``) removes every reservation and is re-raised with
    ``position = (phase, step, total)``.

    Parameters
    ----------
    sessions : list of RunSession
        The sessions of runs that share one protocol and one schedule (their ``sim.parameters``:
        the checked run parameters, or None for ``runSimulation``'s).
    constituted : bool, default False
        The sessions' ensembles are built already (their constitution is skipped).
    conclusion : Conclusion, optional
        The run layer's result type and analysis; None: the oscillatory protocol's
        ``[G′_surface, G″_surface]`` per session (``runSimulation``).

    Returns
    -------
    list
        One result per session, in order (``conclusion.result``), or ``[G′_surface, G″_surface]``
        (Pa) of each when ``conclusion`` is None.
    """
    params = sessions[0].sim.parameters or {}
    part = PARTS[PROTOCOLS[params.get("protocol", "oscillatory")].loop](sessions)
    where = ["constitution", 0, 0]
    try:
        if not constituted:
            _constitute(sessions)
        plan = part.plan()
        for run in sessions:        # the one read of the ensembles: each becomes its session's state
            run.hand_over()
        for key in dict.fromkeys(k for k, _ in plan):
            members = [b for b, (k, _) in enumerate(plan) if k == key]
            engine, order = pre_equilibrated(sessions, members, [plan[b][1] for b in members], part.dt(key),
                                             part.cool(key), where, part.observers, part.timings)
            part.measure(engine, order, key, where)
            del engine
        return part.conclude(conclusion)
    except KeyboardInterrupt as exc:
        exc.position = tuple(where)
        raise
    finally:
        for run in sessions:
            run.close()


def _constitute(sessions):
    """Constitute every replica: bookkeeping per replica through the classes, relaxations in the engine.

    Each session's constitution (:meth:`~particleShear.simulation.oscillatory.RunSession.constitution`:
    the documented simulation's on the engine's state, with the run's law, its host backend and
    :data:`ENGINE_SKIN_FACTOR`) yields its relaxation requests; the pending requests of equal
    batch key (steps, ``dt``, ``dt_max``, and for states their backend, law and skin:
    :attr:`~particleShear.linkable.builders.Relaxation.batch_key`) run together in one engine
    (:meth:`~particleShear.linkable.builders.Relaxation.run_together`: the states joined,
    :func:`particleShear.base.engine_adapter.relax_states`; a subclass's ensembles by
    :func:`~particleShear.base.engine_adapter.relax_ensembles`), the key of the first waiting
    replica first, until every constitution is done.  A replica's gel does not depend on its
    companions (each has its own generator, and the engine's relaxation is per replica).  Each
    replica's ``constitution`` timing is its own bookkeeping plus its share of the relaxations it
    took part in."""

    # the backend of each replica's relaxations: its run's, where that keeps the host's arrays (the
    # compiled step is compiled, or loaded from the cache, here: not counted in the timings)
    backends = [_host_backend(run) for run in sessions]
    compiled = [b for b, be in enumerate(backends) if be.compiled]
    if compiled:
        say = _console([run.sim for run in sessions], [0], "constitution", ["constitution", 0, 0])[0]
        requested = {(sessions[b].sim.parameters or {}).get("backend", "auto") for b in compiled}
        if not all(_compiled(requested, say, law) for law in {(run.sim.contact_law or (None,))[0] for run in sessions}):
            backends = [_host_backend(run) for run in sessions]        # ("auto": NumPy now)
    steps = [run.constitution(relaxation_law=run.sim.contact_law, relaxation_backend=backends[b],
                              skin_factor=ENGINE_SKIN_FACTOR) for b, run in enumerate(sessions)]
    pending = {}            # replica -> its waiting Relaxation
    since = {}              # replica -> when it was suspended

    def advance(b, share=0.0):
        if b in since:
            sessions[b].waited += time.perf_counter() - since.pop(b) - share
        try:
            pending[b] = next(steps[b])
            since[b] = time.perf_counter()
        except StopIteration:
            pending.pop(b, None)

    for b in range(len(sessions)):
        advance(b)
    for _ in range(MAX_RELAXATIONS * max(len(sessions), 1)):   # each round serves at least one request
        if not pending:
            return
        key = pending[min(pending)].batch_key
        group = [b for b in sorted(pending) if pending[b].batch_key == key]
        t0 = time.perf_counter()
        Relaxation.run_together([pending[b] for b in group], skin_factor=ENGINE_SKIN_FACTOR,
                                laws=[sessions[b].sim.contact_law for b in group], backend=backends[group[0]])
        share = (time.perf_counter() - t0) / len(group)
        for b in group:
            advance(b, share)
    raise RuntimeError("the constitutions of a batch yielded more relaxations than allowed")


class Oscillation:
    """The reference's oscillatory protocol, as the driver runs it (:data:`PARTS` ``"oscillation"``).

    Each session prepares its run (:meth:`~particleShear.simulation.oscillatory.RunSession.prepare`:
    output file reserved, experiment, schedule); replicas of equal schedule
    ``(dt, f, cool, pre_periods, periods, post_periods)`` are measured together by
    :func:`~particleShear.engine.step.protocol`, each replica's drawing (live window, snapshots,
    movie, stress window:
    :meth:`~particleShear.simulation.experiment.OscillatoryShearExperiment.observers`) observing its
    own replica in both loops, with the stroboscope of the runs that ask for it; each experiment
    then adopts its replica's record and its session writes the file
    (:meth:`~particleShear.simulation.oscillatory.RunSession.finish`).

    Parameters
    ----------
    sessions : list of RunSession
        The sessions of the batch.
    """

    def __init__(self, sessions):
        self.sessions = sessions
        self.timings = [dict() for _ in sessions]
        self.records = [None] * len(sessions)

    def plan(self):
        """Prepare every session; ``(schedule key, (dt_max, N_pre))`` of each, in order.

        Returns
        -------
        list of tuple
            The key ``(dt, f, cool, pre_periods, periods, post_periods)`` of the replica's protocol
            and its pre-equilibration schedule.
        """
        plan = []
        for run in self.sessions:
            run.prepare()
            sc = run.schedule        # the schedule of the replica: the one function of the measurement
            plan.append(((sc.dt, sc.f, sc.cool, run.exp.baseline_pre_periods, run.exp.periods,
                          run.exp.baseline_post_periods), (sc.dt_max, sc.N_pre)))
        self.cools = [key[2] for key, _ in plan]
        self.scenes = self.watch = None       # (made at the first observers(): after the hand-over)
        return plan

    @staticmethod
    def dt(key):
        """The protocol time step of a group.

        Parameters
        ----------
        key : tuple
            The group's schedule key (:meth:`plan`).

        Returns
        -------
        float
            dt (s).
        """
        return key[0]

    @staticmethod
    def cool(key):
        """The damping factor per step of a group.

        Parameters
        ----------
        key : tuple
            The group's schedule key (:meth:`plan`).

        Returns
        -------
        float
        """
        return key[2]

    def observers(self, engine, members):
        """Each member's observers (its drawing), shown its replica in ``engine``.

        Parameters
        ----------
        engine : BatchEngine
            The engine the members are replicas of, in the order of ``members``.
        members : list of int
            The sessions of the engine's replicas.

        Returns
        -------
        list
            The observers of every member.
        """
        if self.scenes is None:    # each replica's scene, of the configuration its session handed over
            self.scenes = [ReplicaScene(run.scene_configuration) for run in self.sessions]
            self.watch = [run.exp.observers(sc, sc.samples) for run, sc in zip(self.sessions, self.scenes)]
        for col, b in enumerate(members):
            self.scenes[b].bind(engine, col)
        return [ob for b in members for ob in self.watch[b]]

    def measure(self, engine, order, key, where):
        """The oscillatory protocol of the replicas of ``engine``; each replica's record
        (:func:`replica_record`) and its share of the wall time are kept for :meth:`conclude`.

        Parameters
        ----------
        engine : BatchEngine
            The pre-equilibrated engine of the group.
        order : list of int
            The session of each replica of ``engine``.
        key : tuple
            The group's schedule key ``(dt, f, cool, pre_periods, periods, post_periods)``.
        where : list
            ``[phase, step, total]``, followed for an interrupt's position.
        """
        sessions = self.sessions
        dt, f, cool, pre_p, periods, post = key
        t0 = time.perf_counter()
        say, report = _console([run.sim for run in sessions], order, "protocol", where)
        keep = [bool(sessions[b].exp.keep_tensor_history) for b in order]
        strobe = _stroboscope(sessions, order, dt, f, pre_p, periods)
        out = _guarded(protocol, engine, dt, f, [sessions[b].exp.amplitude for b in order], cool, pre_p, periods,
                       post, any(keep), say, report, self.observers(engine, order) + ([strobe] if strobe else []),
                       dt=dt)
        for col, b in enumerate(order):
            sessions[b].microstructure = strobe.replica(col) if strobe else None
            self.records[b] = replica_record(out, col, keep[col])
            self.timings[b]["protocol"] = (time.perf_counter() - t0) / len(order)

    def conclude(self, conclusion):
        """Each experiment adopts its record (demodulation: G′, G″) and its session writes the file.

        Parameters
        ----------
        conclusion : Conclusion or None
            None: ``[G′_surface, G″_surface]`` per session.

        Returns
        -------
        list
            One ``conclusion.result`` per session (a replica's wall time is its share of the batch:
            its own phases and its part of the shared ones), or the G of each.
        """
        G = []
        for b, run in enumerate(self.sessions):
            run.exp.adopt_measurement(self.cools[b], self.records[b], self.timings[b])
            self.records[b] = None  # the experiment's recording holds it now
            G.append(run.finish())
        if conclusion is None:
            return G
        results = []
        for run in self.sessions:
            sim = run.sim
            info = sim.result_info
            info["timings"]["total"] = sum(info["timings"].get(k, 0.0) for k in
                                           ("constitution", "pre_equilibration", "protocol", "demodulation", "output"))
            results.append(conclusion.result(
                G_surface=info["G_surface"], G_internal=info["G_internal"], stress_surface=info["stress_surface"],
                stress_internal=info["stress_internal"], parameters=sim.parameters_record(), seed=sim.seed_entropy,
                spawn_key=sim.spawn_key, timings=info["timings"], output_path=info["output_path"],
                image_folder=info["image_folder"], n_images=info["n_images"], dt=info["dt"], f=info["f"],
                N_steps=info["N_steps"], damping_factor=info["damping_factor"],
                removed_fraction=run.removed_fraction,
                series=run.exp.plotter.arrays(), run_id=sim.run_id, write_error=info.get("write_error"),
                microstructure=getattr(run, "microstructure", None)))
        return results


class Recording:
    """A protocol of the one recording loop (:data:`PARTS` ``"record"``): a rate schedule or a controller.

    Every replica runs the protocol's ``schedule`` (:mod:`particleShear.protocols`) in one engine
    by :func:`~particleShear.engine.rheometer.shear_record`, at the first replica's time step and
    damping (one schedule: the batch's); replicas may differ in rate, strain, stress and γ₀: the
    batch runs the longest and each record is cut at the replica's own length, then analysed
    (:attr:`Conclusion.analyse_record`) and written (:attr:`Conclusion.write`, ``saveData``).

    Parameters
    ----------
    sessions : list of RunSession
        The sessions of the batch (their ``sim.parameters``: the checked run parameters).
    """

    def __init__(self, sessions):
        self.sessions = sessions
        self.kws = [run.sim.parameters for run in sessions]
        self.spec = PROTOCOLS[self.kws[0]["protocol"]]

    def plan(self):
        """Each replica's schedule and step counts (:func:`protocol_steps`); one group, that of the
        first replica's schedule.

        Returns
        -------
        list of tuple
            ``(None, (dt_max, N_pre))`` of each replica.
        """
        self.schedules = [run.sim.measurement_schedule(kw["cool_factor"]) for run, kw in zip(self.sessions, self.kws)]
        self.steps = [protocol_steps(kw) for kw in self.kws]
        self.sc = self.schedules[0]
        self.timings = [dict(constitution=run.sim.timings.get("constitution", 0.0)) for run in self.sessions]
        self.tau = self.sc.dt / self.steps[0]["dt_over_tau"]
        return [(None, (s.dt_max, s.N_pre)) for s in self.schedules]

    def dt(self, key):
        """The protocol time step: the batch's (its first replica's).

        Parameters
        ----------
        key : None
            The one group's key (:meth:`plan`).

        Returns
        -------
        float
            dt (s).
        """
        return self.sc.dt

    def cool(self, key):
        """The damping factor per step: the batch's (its first replica's).

        Parameters
        ----------
        key : None
            The one group's key (:meth:`plan`).

        Returns
        -------
        float
        """
        return self.sc.cool

    @staticmethod
    def observers(engine, members):
        """No observer: the drawing observes the oscillatory protocol only.

        Parameters
        ----------
        engine : BatchEngine
            The engine of the members.
        members : list of int
            The sessions of its replicas.

        Returns
        -------
        list
            Empty.
        """
        return []

    def measure(self, engine, order, key, where):
        """The protocol's loop (:meth:`run`) on ``engine``; its record and each replica's share of
        its wall time are kept for :meth:`conclude`.

        Parameters
        ----------
        engine : BatchEngine
            The pre-equilibrated engine of the batch.
        order : list of int
            The session of each replica of ``engine``.
        key : None
            The one group's key (:meth:`plan`).
        where : list
            ``[phase, step, total]``, followed for an interrupt's position.
        """
        self.order = order
        say, report = _console([run.sim for run in self.sessions], order, "protocol", where)
        t0 = time.perf_counter()
        self.out = self.run(engine, [self.kws[b] for b in order], [self.steps[b] for b in order], say, report)
        self.t_protocol = (time.perf_counter() - t0) / len(order)

    def run(self, engine, kws, steps, say, report):
        """The recording loop driven by the protocol's ``schedule`` (a rate schedule or a controller).

        Parameters
        ----------
        engine : BatchEngine
            The pre-equilibrated engine.
        kws : list of RunParameters
            The arguments of its replicas, in replica order.
        steps : list of dict
            Their step counts (:func:`protocol_steps`), in replica order.
        say, report : callable
            The phase's messages and progress (:func:`_console`).

        Returns
        -------
        dict of ndarray
            The batch's record (:func:`~particleShear.engine.rheometer.shear_record`).
        """
        sc = self.sc
        drive = self.spec.schedule(kws, steps, self.tau, sc.dt, engine.backend)
        return _guarded(lambda e: shear_record(e, sc.dt, sc.cool, drive["n_steps"], drive["rate_of"],
                                               drive.get("tensors_every", 0), say, report,
                                               after_step=drive.get("after_step")), engine, dt=sc.dt)

    def replica(self, col, b, conclusion):
        """One replica's record cut at its own length, and its analysis.

        Parameters
        ----------
        col : int
            The replica's column in the batch's record.
        b : int
            Its session.
        conclusion : Conclusion
            The analysis (:attr:`Conclusion.analyse_record`).

        Returns
        -------
        tuple
            ``(series, summary, curves, steps)``: the fields of its result.
        """
        n = self.steps[b]["steps"]
        series = {key: np.ascontiguousarray(v[:n, col]) for key, v in self.out.items()}
        summary, curves = conclusion.analyse_record(self.spec.name, self.kws[b], series, self.tau, self.steps[b])
        return series, summary, curves, []

    def conclude(self, conclusion):
        """Each replica's analysis, result and file (``saveData``), in session order.

        Parameters
        ----------
        conclusion : Conclusion

        Returns
        -------
        list
            One ``conclusion.result.of_protocol`` per session.
        """
        if conclusion is None:
            raise ValueError(f"protocol={self.spec.name!r} is measured with a Conclusion (run.measurement.measure)")
        results = [None] * len(self.sessions)
        for col, b in enumerate(self.order):
            sim, kw = self.sessions[b].sim, self.kws[b]
            t1 = time.perf_counter()
            series, summary, curves, steps = self.replica(col, b, conclusion)
            tm = dict(self.timings[b], protocol=self.t_protocol, analysis=time.perf_counter() - t1)
            results[b] = conclusion.result.of_protocol(self.spec.name, sim.parameters_record(), sim.seed_entropy,
                                                       sim.spawn_key, kw.run_id, self.tau, self.sc.dt, series,
                                                       summary, curves, steps, tm)
            if kw["saveData"]:
                t2 = time.perf_counter()
                conclusion.write(sim, results[b])
                tm["output"] = time.perf_counter() - t2
        return results


class Segments(Recording):
    """Oscillations on one packing (:data:`PARTS` ``"segments"``: the sweeps).

    The protocol's ``segments`` give each step's ``(f, amplitudes, dt)``; every step runs the
    oscillatory loop (:func:`~particleShear.engine.step.protocol`: ``pre_periods``, ``periods``,
    ``post_periods``) after the previous one on the same engine, and each replica's steps are
    analysed (:attr:`Conclusion.analyse_sweep`: G′/G″ and LAOS measures per step) and recorded one
    after the other (:func:`concatenated`).  Otherwise as :class:`Recording`.
    """

    def run(self, engine, kws, steps, say, report):
        """Every step of the sweep on ``engine``, one after the other.

        Parameters
        ----------
        engine : BatchEngine
            The pre-equilibrated engine.
        kws : list of RunParameters
            The arguments of its replicas, in replica order.
        steps : list of dict
            Their step counts (:func:`protocol_steps`), in replica order.
        say, report : callable
            The phase's messages and progress (:func:`_console`).

        Returns
        -------
        list of tuple
            ``(f, amplitudes, dt, record)`` of each step (:func:`~particleShear.engine.step.protocol`).
        """
        out = []
        for f, A, dt in self.spec.segments(kws, steps, self.tau, self.sc.f):
            cool = kws[0]["cool_factor"] ** (f * dt)
            rec = _guarded(protocol, engine, dt, f, A, cool, kws[0]["pre_periods"], kws[0]["periods"],
                           kws[0]["post_periods"], False, say, report, (), dt=dt)
            out.append((f, A, dt, rec))
        return out

    def replica(self, col, b, conclusion):
        """One replica's steps, analysed, and its record of them one after the other.

        Parameters
        ----------
        col : int
            The replica's column in each step's record.
        b : int
            Its session.
        conclusion : Conclusion
            The analysis (:attr:`Conclusion.analyse_sweep`).

        Returns
        -------
        tuple
            ``(series, summary, curves, steps)``: the fields of its result (no summary, no curves).
        """
        segments = [(f, A[col], dt, {key: np.ascontiguousarray(v[:, col]) for key, v in rec.items()
                                     if not key.endswith("tensors")}) for f, A, dt, rec in self.out]
        sweep = conclusion.analyse_sweep(self.kws[b], segments, self.tau)
        return concatenated([rec for *_, rec in segments]), {}, {}, sweep


#: the part of the driver of each :attr:`~particleShear.protocols.Protocol.loop`
#: (:data:`particleShear.protocols.LOOPS`)
PARTS = {"oscillation": Oscillation, "record": Recording, "segments": Segments}


def concatenated(records):
    """The records of a sweep's steps one after the other, with ``sweep_position``.

    Parameters
    ----------
    records : list of dict of ndarray
        Each step's record (:func:`~particleShear.engine.step.protocol`, one replica).

    Returns
    -------
    dict of ndarray
        ``t``, ``strain``, ``strain_rate``, ``stress_surface``, ``stress_internal`` (each step keeps
        its own clock ``t``) and ``sweep_position`` (the step of each row).
    """
    keys = ("t", "strain", "strain_rate", "stress_surface", "stress_internal")
    out = {key: np.concatenate([rec[key] for rec in records]) for key in keys}
    out["sweep_position"] = np.concatenate([np.full(len(rec["t"]), j, dtype=np.int64) for j, rec in enumerate(records)])
    return out


def _stroboscope(sessions, order, dt, f, pre, periods):
    """The stroboscopic observer of the replicas (columns of ``order``) whose run asks for it
    (``stroboscopic=True``), or None when none does (then nothing is computed)."""
    want = [col for col, b in enumerate(order) if (sessions[b].sim.parameters or {}).get("stroboscopic")]
    if not want:
        return None
    return Stroboscope(dt, f, pre, periods, replicas=want)


def replica_record(out, col, keep):
    """Replica ``col``'s own record out of a batch's :func:`~particleShear.engine.step.protocol` record.

    Parameters
    ----------
    out : dict of ndarray
        The batch's record: series (n_steps, B), "first_tensors"/"last_tensors" (B, 9, 2, 2) and,
        when kept, "tensors" (n_steps, B, 9, 2, 2).
    col : int
        The replica's column.
    keep : bool
        Keep its tensor history.

    Returns
    -------
    dict of ndarray
        The same keys for that replica alone (contiguous copies; "tensors" only with ``keep``).
    """
    return {key: (np.ascontiguousarray(v[col]) if key.endswith("_tensors") else np.ascontiguousarray(v[:, col]))
            for key, v in out.items() if key != "tensors" or keep}


def pre_equilibrated(sessions, members, pre, dt, cool, where, observers, timings):
    """The pre-equilibrated engine of the replicas ``members``, ready for a protocol at step ``dt``.

    Each group of equal pre-equilibration schedule ``(dt_max, N_pre)`` is pre-equilibrated in an
    engine of its own (:func:`~particleShear.engine.step.pre_equilibrate`); the states are then
    joined into one engine, the Verlet predictor carried on.  Each member's
    ``timings["pre_equilibration"]`` is its share of its group's wall time.

    Parameters
    ----------
    sessions : list of RunSession
        All sessions of the batch, handed over (their :attr:`~particleShear.simulation.oscillatory.RunSession.state`,
        which this function takes: no ensemble is read).
    members : list of int
        The sessions measured together (one protocol schedule).
    pre : list of tuple
        ``(dt_max, N_pre)`` of each member, in the order of ``members``.
    dt : float
        Final time step (s).
    cool : float
        Damping factor per step of the last N_pre steps.
    where : list
        ``[phase, step, total]``, followed for an interrupt's position.
    observers : callable
        ``observers(engine, members) -> list`` of the observers of those members in that engine.
    timings : list of dict
        Per session, filled with ``"pre_equilibration"``.

    Returns
    -------
    engine : BatchEngine
        The engine of the joined state (no step taken yet).
    order : list of int
        The session of each replica of ``engine``, in replica order.
    """

    sims = [run.sim for run in sessions]
    backend = (sims[members[0]].parameters or {}).get("backend", "auto")   # one backend per batch
    guard_of = [bool(run.sim.stability_guard) for run in sessions]
    integrator = sims[members[0]].integrator        # part of the schedule key
    states, order = [], []
    for key in dict.fromkeys(pre):
        group = [b for b, k in zip(members, pre) if k == key]
        t0 = time.perf_counter()
        host = BatchState.concat([sessions[b].state for b in group])     # (the sessions' states: no ensemble)
        for b in group:
            sessions[b].state = None            # handed to the engine
        st = host.to_backend(backend)
        for b in group:           # the backend used ("auto" resolved), as the result records it
            sims[b].backend_used = st.backend.name
        say, report = _console(sims, group, "pre-equilibration", where)
        if st.backend.compiled:       # compiled (or loaded from the cache) here, not counted in the timings
            tc = time.perf_counter()
            if not _compiled({backend}, say, st.law):       # ("auto" without a usable Numba: NumPy)
                st = host.to_backend(backend)
                for b in group:
                    sims[b].backend_used = st.backend.name
            t0 += time.perf_counter() - tc
        engine = BatchEngine(st, skin_factor=ENGINE_SKIN_FACTOR, guard=[guard_of[b] for b in group],
                             integrator=integrator)
        _guarded(pre_equilibrate, engine, key[1], dt, key[0], cool, say, report, observers(engine, group), dt=dt)
        for b in group:
            timings[b]["pre_equilibration"] = (time.perf_counter() - t0) / len(group)
        states.append(st)
        order += group
    # (the joined state carries the groups' Verlet predictors on, as in one ensemble: BatchState.concat)
    engine = BatchEngine(BatchState.concat(states), skin_factor=ENGINE_SKIN_FACTOR, guard=[guard_of[b] for b in order],
                         integrator=integrator)
    return engine, order


def _compiled(requested, say, law):
    """Compile (or load) the compiled backend's loops before the timings (:func:`~particleShear.engine.numba_step.compile_kernels`,
    and the documented classes' tensor sums, :func:`~particleShear.base.compiled_phases.compile_tensor_kernel`).

    Returns False when the compile failed for runs that asked for ``"auto"`` (which then stands for
    NumPy in this process: :func:`~particleShear.engine.xp.auto_without_numba`); a run that asked
    for ``"numba"`` gets the error."""
    try:
        compile_kernels(say=say, law=law)
        compile_tensor_kernel()
        return True
    except Exception as exc:
        if not requested <= {"auto", None}:
            raise
        auto_without_numba(f"{type(exc).__name__}: {exc}")
        return False


def _host_backend(run):
    """The backend of a session's constitution: its run's backend where that works on the host's
    arrays (NumPy, Numba), else NumPy (the ensembles' own rows are relaxed in place)."""
    be = get_backend((run.sim.parameters or {}).get("backend", "auto"))
    return be if be.host else get_backend("numpy")


def _console(sims, members, phase, where):
    """``say`` and ``report`` callbacks of a batch phase: the reference's messages when any member is
    verbose, each member's progress callback at most ~10 times per second (and at the end);
    ``where`` follows ``[phase, step, total]``."""
    verbose = any(sims[b].verbose for b in members)
    callbacks = [sims[b].progress for b in members if sims[b].progress is not None]
    say = (lambda *a: _log.info(" ".join(str(x) for x in a))) if verbose else (lambda *a: None)
    t0 = time.perf_counter()
    last = [0.0]

    def report(step, total):
        where[:] = [phase, step, total]
        if not callbacks:
            return
        now = time.perf_counter()
        if step == total or now - last[0] >= 0.1:
            last[0] = now
            for cb in callbacks:
                cb(phase, step, total, now - t0)
    return say, report


def _guarded(phase, engine, *args, dt, **kwargs):
    """Run an engine phase; a diverging replica raises SimulationInstabilityError (step, phase, suggested dt)."""
    try:
        return phase(engine, *args, **kwargs)
    except EngineInstability as e:
        if e.step == 0 and e.phase == "pre-equilibration":   # the state the constitution left (its step ignores time_step_factor)
            raise SimulationInstabilityError(
                f"{e}: the packing diverged during the constitution (before the measurement's first step), whose "
                "time step time_step_factor does not change; relative_viscosity, relative_transversal_link_strength "
                "or interface_reenforcement_central/_tangential are beyond what the time-step rule integrates "
                "stably: use smaller values (docs/parameters.md, Limits)", step=e.step, phase=e.phase,
                pair=(e.replica,), suggested_dt=None, reason=str(e)) from e
        raise SimulationInstabilityError(
            f"{e} (time step {dt:.3g} s, try dt <= {dt / 2:.3g} s)", step=e.step, phase=e.phase,
            pair=(e.replica,), suggested_dt=dt / 2, reason=str(e)) from e
