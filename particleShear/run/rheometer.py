"""The rheometer's protocols of a run: ``protocol=`` of :func:`~particleShear.run.api.doParticleShearSimulation`.

``"oscillatory"`` (the default) is the reference's experiment (:mod:`particleShear.run.batch`).
The others constitute and pre-equilibrate exactly as it does (the same functions, so one seed
gives the same packing), then drive the engine with another rate schedule
(:mod:`particleShear.engine.rheometer`, docs/protocols.md):

``"steady"``
    γ̇ = ``relative_rate``/τ until the strain ``total_strain``; the steady shear stress (mean and
    standard error by blocking after the detected transient), the viscosity σ/γ̇ and the first
    normal-stress difference N1 of the overall tensor.
``"relaxation"``
    One step at rest (the residual stress σ_res), a ramp to γ₀ = ``theAmplitude`` over
    ``ramp_time``·τ, then ``hold_time``·τ at constant strain; G(t) = (σ(t) − σ_res)/γ₀ (t from
    the end of the ramp) on a log-spaced grid and its plateau.
``"creep"``
    One step at rest (the residual stress σ_res), then the plate stress held at
    ``creep_stress`` (Pa) for ``hold_time``·τ by a PI controller on the strain rate; J(t) = γ(t)/σ₀ on a log grid, the final creep rate, σ₀/γ̇ and the strain plateau.
``"amplitude_sweep"`` / ``"frequency_sweep"``
    One packing, then the oscillatory protocol (``pre_periods``, ``periods``, ``post_periods``)
    for each amplitude of ``sweep_amplitudes`` (or relative frequency of ``sweep_frequencies``)
    in the given order, each after the previous one; one G′/G″ (with standard errors and LAOS
    measures) per step.  The constitution and the first step are those of the independent run
    with the first amplitude (frequency): ``theAmplitude`` (``relative_frequency``) is set to it.

τ is the model time constant (docs/parameters.md): γ̇ in 1/s is ``relative_rate / τ``.
"""
__docformat__ = "numpy"
import difflib
import math
import time

import numpy as np

from .._version import __version__
from ..analysis.measures import MEASURE_COLUMNS
from ..analysis.verdicts import CHECKS, PROTOCOL_CHECKS, verdict, verdict_lines
from ..checks import show_value
from ..engine.rheometer import shear_record
from ..engine.step import protocol as oscillation
from ..hooks import entry
from ..linkable.builders import time_steps_from_model
from ..parameters import BY_NAME, PARAMETERS, spec_defaults
from ..protocols import MAX_STRAIN_PER_STEP, PROTOCOLS as REGISTRY, result_columns
from ..protocols.creep import CREEP_MODULUS_FRACTION
from ..protocols.steady import N1_EVERY
from ..simulation.driver import _console, _constitute, _guarded, pre_equilibrated
from ..simulation.provenance import run_identity
from .sessions import build_sessions
from .rheometer_analysis import analyse_record, analyse_sweep
from .rheometer_files import write_protocol_file
from .limits import MAX_TOTAL_STEPS, _protocol_room

__all__ = ["PROTOCOLS", "PROTOCOL_DEFAULTS", "PROTOCOL_COLUMNS", "LIST_PARAMETERS", "STEP_COLUMNS", "MAX_STRAIN_PER_STEP", "RheometerResult", "check_protocol",
           "check_sweep_resolution", "normalize_protocol", "protocol_steps", "measure_rheometer"]

#: the protocols' names, in the order of ``protocol``'s choices (:mod:`particleShear.protocols`)
PROTOCOLS = tuple(REGISTRY)

#: the protocol's selector and the protocols' own parameters with their defaults (roles "protocol" of
#: :mod:`particleShear.parameters`)
PROTOCOL_DEFAULTS = {p.name: p.default for p in PARAMETERS if p.base_role == "protocol"}

#: the result columns of the protocols, in table order (the summaries, the checks; the results
#: table's :data:`particleShear.sweep.schema.PROTOCOL_COLUMNS`), name → unit
_COLUMN_UNITS = {name: spec[1] for name, spec in result_columns(CHECKS)[0].items()}
_COLUMN_UNITS.update((name, "") for name in result_columns(CHECKS)[1])
PROTOCOL_COLUMNS = tuple(_COLUMN_UNITS)

#: the protocol parameters whose value is a list (one value of a sweep is a whole list)
LIST_PARAMETERS = tuple(p.name for p in PARAMETERS if p.kind == "float_list")

#: key of a sweep step (``RheometerResult.steps``) -> its column in a results table (the other keys,
#: the moduli and measures, are columns of the same name)
STEP_COLUMNS = {"position": "sweep_position", "amplitude": "sweep_amplitude",
                "relative_frequency": "sweep_relative_frequency", "f": "frequency_Hz", "dt": "dt", "N_steps": "N_steps"}


def _dt_over_tau(p, amplitude=None):
    """Protocol time step in units of τ (the time-step rule is linear in τ)."""
    A = p["theAmplitude"] if amplitude is None else amplitude
    return time_steps_from_model(1.0, p["bimodal_factor"], p["theMu"], p["relative_transversal_link_strength"], A,
                                 p["relative_viscosity"])[0] * p["time_step_factor"]


def check_protocol(p):
    """Check the protocol parameters of one run (``p``: every argument, defaults filled in).

    Parameters
    ----------
    p : dict
        The arguments of the run.

    Returns
    -------
    dict
        The steps of the protocol (:func:`protocol_steps`).

    Raises
    ------
    ValueError, TypeError
        An unknown protocol (the closest name suggested), a missing or non-positive rate, strain,
        time or stress, a sweep list that is empty or not monotonic, a rate or ramp the time step
        cannot resolve (more than :data:`MAX_STRAIN_PER_STEP` strain per step), a controller
        response time shorter than 10 steps, a step of a sweep that its time step cannot resolve
        (:func:`check_sweep_resolution`), a protocol of more than
        :data:`~particleShear.run.validation.MAX_TOTAL_STEPS` steps (naming the parameter to
        shorten), or options of the drawing with a protocol other than "oscillatory".
    """
    proto = p.get("protocol", "oscillatory")
    if proto not in REGISTRY:
        near = difflib.get_close_matches(str(proto), PROTOCOLS, n=1)
        raise ValueError(f"protocol={proto!r} is invalid: allowed one of {PROTOCOLS}"
                         + (f"; did you mean {near[0]!r}?" if near else "") + " (flag --protocol)")
    if proto == "oscillatory":
        return {}
    if p.get("saveOutputImages") or p.get("saveOutputMovie"):
        raise ValueError(f"saveOutputImages=True is invalid with protocol={proto!r}: snapshots are taken of the "
                         "oscillatory protocol only")
    q = normalize_protocol(p)
    spec = REGISTRY[proto]
    if spec.check is not None:
        spec.check(q)
    steps = protocol_steps(q)
    if spec.check_steps is not None:
        spec.check_steps(q, steps)
    total = sum(steps["segments"]) if spec.segmented else steps["steps"]
    if total > MAX_TOTAL_STEPS:
        name, allowed = _protocol_room(q, steps, MAX_TOTAL_STEPS)
        raise ValueError(f"{name}={_shown(q[name])} is out of range: protocol={proto!r} needs {total:.3g} steps, more "
                         f"than the limit of {MAX_TOTAL_STEPS:.0e}; allowed {allowed} (flag --{name.replace('_', '-')})")
    return steps


def _shown(v):
    """A value for a message: a long list cut to its first and last values."""
    if isinstance(v, (list, tuple)) and len(v) > 6:
        return f"[{', '.join(f'{x:g}' for x in v[:3])}, ..., {v[-1]:g}] ({len(v)} values)"
    return show_value(v)


def check_sweep_resolution(q, steps=None):
    """Check every step of a one-packing sweep as the single oscillatory run is checked.

    Each step ``j`` (amplitude ``A_j``, relative frequency ``f_j``) has its own time step (the
    time-step rule depends on the amplitude) and must resolve its excitation period with at
    least :data:`~particleShear.run.validation.MIN_STEPS_PER_PERIOD` steps at the reference time
    step, and with at least
    :data:`~particleShear.run.validation.MIN_STEPS_PER_PERIOD_COARSENED` at the coarsened one
    (``time_step_factor``), the two rules of the oscillatory run's first step.

    Parameters
    ----------
    q : dict
        The arguments of the run (:func:`normalize_protocol`: a sweep's list as floats).
    steps : dict, optional
        :func:`protocol_steps` of ``q`` (computed when None).

    Raises
    ------
    ValueError
        Naming the step's value (``sweep_frequencies[j]`` or ``sweep_amplitudes[j]``), its steps
        per period, the limit, the allowed range and the CLI flag.
    """
    steps = protocol_steps(q) if steps is None else steps
    REGISTRY[q["protocol"]].check_steps(q, steps)


def normalize_protocol(p):
    """The arguments of a run as its protocol measures them: a sweep's first value becomes
    ``theAmplitude`` (amplitude sweep) or ``relative_frequency`` (frequency sweep).

    Parameters
    ----------
    p : dict
        The arguments of the run (defaults filled in); not modified.

    Returns
    -------
    dict
        A copy with the sweep's first value put in (lists as lists of float).

    Raises
    ------
    ValueError
        For a sweep without its list, or a list that is empty or not monotonic.
    """
    q = dict(p)
    spec = REGISTRY.get(q.get("protocol", "oscillatory"))
    if spec is not None and spec.normalize is not None:
        spec.normalize(q)
    return q


def protocol_steps(q):
    """Step counts of a (normalized, checked) protocol.

    Parameters
    ----------
    q : dict
        The arguments of the run (:func:`normalize_protocol`).

    Returns
    -------
    dict
        ``dt_over_tau``; ``steps`` (steady, relaxation, creep: all steps), ``ramp`` (relaxation);
        ``segments`` (sweeps: the oscillatory steps of each step of the sweep) and ``dts`` (sweeps:
        each step's dt/τ).
    """
    return REGISTRY[q.get("protocol", "oscillatory")].steps(q, lambda amplitude=None: _dt_over_tau(q, amplitude))


class RheometerResult:
    """What a run of a protocol other than "oscillatory" produced (docs/protocols.md).

    The constructor's parameters are the attributes below of the same names (``values`` is derived).

    Parameters
    ----------
    protocol, parameters, seed, spawn_key, run_id, tau, dt, series, summary, curves, steps, timings
        See Attributes.

    Attributes
    ----------
    protocol : str
        The protocol.
    parameters : dict
        Every argument of the run (normalized: a sweep's first value in ``theAmplitude`` or
        ``relative_frequency``).
    seed, spawn_key, run_id
        As :class:`~particleShear.run.api.SimulationResult`.
    tau : float
        Model time constant τ (s).
    dt : float
        Time step (s; of the first step for sweeps).
    series : dict of numpy.ndarray
        The record of every step: "t" (s), "strain", "strain_rate" (1/s), "stress_internal",
        "stress_surface" (Pa), for "steady" "N1" (Pa, NaN where not sampled); for sweeps the
        steps' records one after the other with "sweep_position" (each step's clock from 0).
    output_path : str or None
        The run's file (``saveData=True``; :mod:`particleShear.run.rheometer_files`), else None.
    write_error : Exception or None
        Why writing the file failed (the result is kept), else None.
    summary : dict
        Scalar results by name (units in docs/protocols.md).
    curves : dict
        ``name -> (t, y, y_sem)`` on log-spaced grids: "G" (relaxation, Pa), "J" (creep, 1/Pa).
    steps : list of dict
        Sweeps: one dict per step (position, amplitude, relative_frequency, f, G′/G″ of both
        estimators with standard errors, LAOS measures).
    timings : dict
        Wall times (s) of "constitution", "pre_equilibration", "protocol", "analysis".
    values : list of float
        What ``doParticleShearSimulation`` returns without ``return_result``: steady ``[σ, η]``
        (surface), relaxation ``[G_plateau]``, creep ``[final creep rate, σ₀/γ̇]``, sweeps
        ``[[G′, G″], …]`` per step (surface).
    """

    def __init__(self, protocol, parameters, seed, spawn_key, run_id, tau, dt, series, summary, curves, steps,
                 timings):
        self.protocol, self.parameters, self.seed, self.spawn_key, self.run_id = (protocol, parameters, seed,
                                                                                  spawn_key, run_id)
        self.tau, self.dt, self.series, self.summary, self.curves, self.steps = tau, dt, series, summary, curves, steps
        self.timings = timings
        self.output_path = None
        self.write_error = None

    @property
    def verdict(self):
        """``"ok"`` or ``"flagged: …"`` (:mod:`particleShear.analysis.verdicts`); a sweep's is that of its
        steps together (None when not judged)."""
        if not self.steps:
            return self.summary.get("verdict")
        names = PROTOCOL_CHECKS[self.protocol]
        return verdict({n: (False if any(st.get(n) is False for st in self.steps) else None) for n in names})

    @property
    def values(self):
        """The main numbers of the protocol (see the class docstring)."""
        values = REGISTRY[self.protocol].values
        if values is not None:
            return values(self.summary)
        return [[st["Gp_surface"], st["Gpp_surface"]] for st in self.steps]

    def rows(self):
        """The rows of this run in a sweep's results table: one, or one per step of a sweep.

        Keys as :func:`particleShear.sweep.table.table_columns` of a protocol sweep: ``run_id``,
        ``status`` ("ok"), ``error``, the moduli and measures (sweep steps), the run columns
        (``repetition``, ``frequency_Hz`` and ``omega`` of a sweep step, ``dt``, ``N_steps``), the
        protocol columns (:data:`PROTOCOL_COLUMNS`: the summary, or
        ``sweep_position``, ``sweep_amplitude``, ``sweep_relative_frequency`` of a step), every
        parameter, ``seed_entropy``, ``spawn_key``, ``package_version``, ``wall_time_s`` (s),
        ``output_path``.  Columns a protocol does not produce are absent (empty cells).

        Returns
        -------
        list of dict
        """
        params = spec_defaults(protocols=True)
        params.update({k: v for k, v in self.parameters.items() if k in params})
        base = {"run_id": run_identity(params, self.seed, self.spawn_key), "status": "ok", "error": "",
                "repetition": int(getattr(self, "repetition", 0)), "dt": float(self.dt)}
        base.update({k: v for k, v in self.summary.items() if k in PROTOCOL_COLUMNS or k == "verdict"})
        if REGISTRY[self.protocol].recorded:
            base["N_steps"] = int(len(self.series["t"])) if "t" in self.series else None
        base.update(params)
        base.update(seed_entropy=self.seed, spawn_key=list(self.spawn_key), package_version=__version__,
                    wall_time_s=float(sum(self.timings.values())), output_path=self.output_path or "")
        if not self.steps:
            return [base]
        out = []
        for st in self.steps:
            row = dict(base, **{STEP_COLUMNS.get(k, k): v for k, v in st.items()})
            row["omega"] = 2 * math.pi * float(st["f"])
            out.append(row)
        return out

    @classmethod
    def from_rows(cls, rows, parameters, seed, spawn_key, output_path=None):
        """The result of a finished run rebuilt from its table rows (no series, no curves).

        Used when a series or a sweep resumes: the summary, or the steps of a sweep, are the
        rows' values (the inverse of :meth:`rows`).

        Parameters
        ----------
        rows : list of dict
            The run's typed rows (:func:`particleShear.sweep.schema.typed_row`), in step order.
        parameters : dict
            The run's parameters.
        seed, spawn_key
            The run's seed entropy and spawn key.
        output_path : str, optional
            The run's file.

        Returns
        -------
        RheometerResult
        """
        first = rows[0]
        proto = parameters["protocol"]
        inverse = {c: k for k, c in STEP_COLUMNS.items()}
        moduli = ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal") + tuple(MEASURE_COLUMNS)
        steps = [{inverse.get(c, c): r.get(c) for c in tuple(STEP_COLUMNS.values()) + moduli}
                 for r in rows] if REGISTRY[proto].segmented else []
        summary = {} if steps else {c: first[c] for c in PROTOCOL_COLUMNS + ("verdict",)
                                    if first.get(c) is not None}
        dt = float(first["dt"])
        res = cls(proto, dict(parameters), seed, tuple(spawn_key), first["run_id"], dt / _dt_over_tau(parameters), dt,
                  {}, summary, {}, steps, {"total": float(first.get("wall_time_s") or 0.0)})
        res.output_path = output_path
        return res

    def plot(self, path=None):
        """The protocol's figure (needs ``particleShear[plot]``): the stress against strain of a
        steady run, G(t), J(t), or G′/G″ of a sweep's steps
        (:func:`particleShear.rheometer_plot.plot_rheometer_result`).

        Parameters
        ----------
        path : str or os.PathLike, optional
            File to write (PNG, PDF, SVG or EPS, chosen by the extension); None writes nothing.

        Returns
        -------
        matplotlib.figure.Figure
        """
        return entry("plot_rheometer_result")(self, path)

    def _summary(self):
        """(run fields, rows) of :meth:`__repr__` and :meth:`_repr_html_`.

        Fields: ``(label, text)`` of protocol, N, μ, seed and run id.  Rows ``(name, value text,
        unit)``: the summary's numbers with their standard errors (``name_se``) where finite, and
        the units of the results-table columns of the same names; for sweeps one row per step
        (G′, G″ of both estimators in Pa).
        """
        p = self.parameters or {}
        seed = "None" if self.seed is None else str(self.seed)
        if self.spawn_key:
            seed += " spawn " + ",".join(str(k) for k in self.spawn_key)
        fields = [("protocol", self.protocol), ("N", str(p.get("N", "?"))), ("μ", str(p.get("theMu", "?"))),
                  ("seed", seed), ("run_id", self.run_id or "–")]

        def num(v, se=None):
            text = f"{v:.4g}" if isinstance(v, (float, int)) and not isinstance(v, bool) else str(v)
            if isinstance(se, float) and math.isfinite(se):
                text += f" ± {se:.2g}"
            return text

        rows = []
        if self.steps:
            for st in self.steps:
                label = REGISTRY[self.protocol].label(st)
                for est in ("surface", "internal"):
                    rows.append((f"{label} ({est})",
                                 f"G′ = {num(st.get('Gp_' + est, float('nan')), st.get('Gp_' + est + '_se'))}, "
                                 f"G″ = {num(st.get('Gpp_' + est, float('nan')), st.get('Gpp_' + est + '_se'))}",
                                 "Pa"))
        else:
            for name, v in self.summary.items():
                if name.endswith("_se") or name in CHECKS or name == "verdict":
                    continue
                unit = _unit(name)
                rows.append((name, num(v, self.summary.get(name + "_se")), "" if unit == "1" else unit))
        return fields, rows

    def __repr__(self):
        """A short summary: protocol, N, μ, seed, run id, then each summary number with its standard
        error and unit (sweeps: G′, G″ of both estimators per step) — not the records.

        Returns
        -------
        str
        """
        fields, rows = self._summary()
        lines = ["RheometerResult(" + ", ".join(f"{k}={v}" for k, v in fields)]
        lines += [f"  {name}: {text}" + (f" {unit}" if unit else "") for name, text, unit in rows]
        lines += ["  " + line for line in self._verdict_lines()]
        return "\n".join(lines) + ")"

    def _verdict_lines(self):
        """The verdict of the run (:func:`~particleShear.analysis.verdicts.verdict_lines`); a sweep's per step."""
        if not self.steps:
            return verdict_lines(self.summary, self.protocol) if "verdict" in self.summary else []
        return [f"step {st.get('position', j)}: {st.get('verdict') or 'not judged'}" for j, st in enumerate(self.steps)]

    def _repr_html_(self):
        """The summary of :meth:`__repr__` as a small HTML table (Jupyter); all text HTML-escaped.

        Returns
        -------
        str
        """
        import html
        esc = html.escape
        fields, rows = self._summary()
        cap = ", ".join(f"{esc(k)} = {esc(v)}" for k, v in fields)
        out = ["<table>", f"<caption>RheometerResult: {cap}</caption>",
               "<tr><th>quantity</th><th>value</th><th>unit</th></tr>"]
        out += [f"<tr><td>{esc(name)}</td><td>{esc(text)}</td><td>{esc(unit)}</td></tr>" for name, text, unit in rows]
        out += [f'<tr><td colspan="3">{esc(line.strip())}</td></tr>' for line in self._verdict_lines()]
        out.append("</table>")
        return "\n".join(out)


def _unit(name):
    """The unit of a summary number: its result column's, or its parameter's ("" when none)."""
    if name in _COLUMN_UNITS:
        return _COLUMN_UNITS[name]
    par = BY_NAME.get(name)
    return par.unit if par is not None and par.kind in ("float", "int", "float_list") else ""


def _concatenated(records):
    """The records of a sweep's steps one after the other, with ``sweep_position`` (each step keeps
    its own clock ``t``)."""
    keys = ("t", "strain", "strain_rate", "stress_surface", "stress_internal")
    out = {key: np.concatenate([rec[key] for rec in records]) for key in keys}
    out["sweep_position"] = np.concatenate([np.full(len(rec["t"]), j, dtype=np.int64) for j, rec in enumerate(records)])
    return out


def measure_rheometer(runs):
    """Constitute, pre-equilibrate and measure runs of one protocol other than "oscillatory".

    The constitution and pre-equilibration are those of the oscillatory runs
    (:func:`~particleShear.run.batch.build_sessions`, ``_constitute``,
    :func:`~particleShear.simulation.driver.pre_equilibrated`); every replica then runs its rate
    schedule in one engine.  Replicas may differ in rate, strain, stress, γ₀ and amplitude list;
    the batch runs the longest and cuts each record at the replica's own length.

    Parameters
    ----------
    runs : list of dict
        Complete, validated, normalized keyword dicts sharing a protocol and a schedule.

    Returns
    -------
    list of RheometerResult
    """
    proto = runs[0]["protocol"]
    spec = REGISTRY[proto]
    sims, seeds, sessions = build_sessions(runs)
    where = ["constitution", 0, 0]
    _constitute(sessions)
    scheds, steps = [], []
    for run, kw in zip(sessions, runs):
        scheds.append(run.sim.measurement_schedule(kw["cool_factor"]))
        steps.append(protocol_steps(kw))
    sc = scheds[0]
    timings = [dict(constitution=run.sim.timings.get("constitution", 0.0)) for run in sessions]
    members = list(range(len(sessions)))
    engine, order = pre_equilibrated(sessions, members, [(s.dt_max, s.N_pre) for s in scheds], sc.dt, sc.cool,
                                     where, lambda e, m: [], timings)
    kws = [runs[b] for b in order]
    tau = sc.dt / steps[0]["dt_over_tau"]
    say, report = _console(sims, order, "protocol", where)
    t0 = time.perf_counter()
    recs, sweep_recs = None, None
    if spec.recorded:
        # the one recording loop, driven by the protocol's rate schedule or controller
        drive = spec.schedule(kws, [steps[b] for b in order], tau, sc.dt, engine.backend)
        recs = _guarded(lambda e: shear_record(e, sc.dt, sc.cool, drive["n_steps"], drive["rate_of"],
                                               drive.get("tensors_every", 0), say, report,
                                               after_step=drive.get("after_step")), engine, dt=sc.dt)
    else:
        sweep_recs = []
        for f, A, dt in spec.segments(kws, [steps[b] for b in order], tau, sc.f):
            cool = kws[0]["cool_factor"] ** (f * dt)
            out = _guarded(oscillation, engine, dt, f, A, cool, kws[0]["pre_periods"], kws[0]["periods"],
                           kws[0]["post_periods"], False, say, report, (), dt=dt)
            sweep_recs.append((f, A, dt, out))
    t_protocol = (time.perf_counter() - t0) / len(order)
    results = [None] * len(sessions)
    for col, b in enumerate(order):
        kw = runs[b]
        t1 = time.perf_counter()
        if sweep_recs is None:
            n = steps[b]["steps"]
            series = {key: np.ascontiguousarray(v[:n, col]) for key, v in recs.items()}
            summary, curves = analyse_record(proto, kw, series, tau, steps[b])
            sweep = []
        else:
            segments = [(f, A[col], dt, {key: np.ascontiguousarray(v[:, col]) for key, v in out.items()
                                         if not key.endswith("tensors")}) for f, A, dt, out in sweep_recs]
            sweep = analyse_sweep(kw, segments, tau)
            series, curves, summary = _concatenated([rec for *_, rec in segments]), {}, {}
        seed_entropy, spawn_key, _ = seeds[b]
        tm = dict(timings[b], protocol=t_protocol, analysis=time.perf_counter() - t1)
        results[b] = RheometerResult(proto, dict(kw), seed_entropy, spawn_key,
                                     run_identity(kw, seed_entropy, spawn_key), tau, sc.dt, series, summary, curves,
                                     sweep, tm)
        if kw["saveData"]:
            t2 = time.perf_counter()
            write_protocol_file(sessions[b].sim, results[b])
            tm["output"] = time.perf_counter() - t2
    for run in sessions:
        run.close()
    return results
