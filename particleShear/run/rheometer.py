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

from ..parameters import BY_NAME, PARAMETERS, spec_defaults
from .._version import __version__
from ..hooks import entry
from ..simulation.driver import _console, _constitute, _guarded, pre_equilibrated

__all__ = ["PROTOCOLS", "PROTOCOL_DEFAULTS", "LIST_PARAMETERS", "STEP_COLUMNS", "MAX_STRAIN_PER_STEP", "RheometerResult", "check_protocol",
           "check_sweep_resolution", "normalize_protocol", "protocol_steps", "measure_rheometer"]

PROTOCOLS = BY_NAME["protocol"].choices

#: the protocol's selector and the protocols' own parameters with their defaults (roles "protocol" of
#: :mod:`particleShear.parameters`)
PROTOCOL_DEFAULTS = {p.name: p.default for p in PARAMETERS if p.base_role == "protocol"}

#: the protocol parameters whose value is a list (one value of a sweep is a whole list)
LIST_PARAMETERS = tuple(p.name for p in PARAMETERS if p.kind == "float_list")

#: key of a sweep step (``RheometerResult.steps``) -> its column in a results table (the other keys,
#: the moduli and measures, are columns of the same name)
STEP_COLUMNS = {"position": "sweep_position", "amplitude": "sweep_amplitude",
                "relative_frequency": "sweep_relative_frequency", "f": "frequency_Hz", "dt": "dt", "N_steps": "N_steps"}

#: largest strain increment |γ̇|·dt of one step (≈ 9× the default oscillation's peak, 5.6e-4):
#: neighbours 2r apart then move by at most 1 % of r relative to each other per step
MAX_STRAIN_PER_STEP = 0.005

#: the controller's modulus scale, as a fraction of Young_modulus_spheres when creep_modulus is None
#: (the default packing has G′ ≈ 0.14 E, so the closed loop settles in about one response time)
CREEP_MODULUS_FRACTION = 0.125

#: N1 of the overall tensor is sampled every this many steps (the tensors cost about one step)
N1_EVERY = 10


def _dt_over_tau(p, amplitude=None):
    """Protocol time step in units of τ (the time-step rule is linear in τ)."""
    from ..linkable.builders import time_steps_from_model
    A = p["theAmplitude"] if amplitude is None else amplitude
    return time_steps_from_model(1.0, p["bimodal_factor"], p["theMu"], p["relative_transversal_link_strength"], A,
                                 p["relative_viscosity"])[0] * p["time_step_factor"]


def _positive(name, v, hi=math.inf):
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}={v!r} is invalid: allowed a real number > 0 (flag --{name.replace('_', '-')})")
    if not (math.isfinite(v) and 0 < v <= hi):
        raise ValueError(f"{name}={v!r} is out of range: allowed 0 < {name} <= {hi:g} "
                         f"(flag --{name.replace('_', '-')})")
    return float(v)


def _values(name, v, lo, hi):
    if v is None or isinstance(v, (str, bytes)) or not hasattr(v, "__len__"):
        raise ValueError(f"{name}={v!r} is invalid: the sweep needs a list of values in ({lo:g}, {hi:g}]")
    vals = [_positive(name, x, hi) for x in list(v)[:10001]]
    if not 1 <= len(vals) <= 10000:
        raise ValueError(f"{name} has {len(vals)} values: allowed 1 ... 10000")
    d = np.diff(vals)
    if len(vals) > 1 and not ((d > 0).all() or (d < 0).all()):
        raise ValueError(f"{name}={vals!r} is invalid: a sweep runs in one direction on one sample, so the values "
                         "must be strictly increasing or strictly decreasing (no repeats)")
    return vals


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
    if proto not in PROTOCOLS:
        near = difflib.get_close_matches(str(proto), PROTOCOLS, n=1)
        raise ValueError(f"protocol={proto!r} is invalid: allowed one of {PROTOCOLS}"
                         + (f"; did you mean {near[0]!r}?" if near else "") + " (flag --protocol)")
    if proto == "oscillatory":
        return {}
    if p.get("saveOutputImages") or p.get("saveOutputMovie"):
        raise ValueError(f"saveOutputImages=True is invalid with protocol={proto!r}: snapshots are taken of the "
                         "oscillatory protocol only")
    q = normalize_protocol(p)
    if proto == "steady":
        _positive("relative_rate", q["relative_rate"])
        _positive("total_strain", q["total_strain"], 1e6)
    if proto in ("relaxation", "creep"):
        _positive("hold_time", q["hold_time"], 1e9)
    if proto == "relaxation":
        _positive("ramp_time", q["ramp_time"], 1e9)
    if proto == "creep":
        if q["creep_stress"] is None:
            raise ValueError("creep_stress=None is invalid with protocol='creep': give the applied stress σ₀ in Pa "
                             "(> 0; flag --creep-stress)")
        _positive("creep_stress", q["creep_stress"], 1e12)
        if q["creep_modulus"] is not None:
            _positive("creep_modulus", q["creep_modulus"], 1e15)
        _positive("creep_response_time", q["creep_response_time"], 1e9)
    steps = protocol_steps(q)
    dtr = steps["dt_over_tau"]
    if proto == "steady":
        rate = float(q["relative_rate"])
        if rate * dtr > MAX_STRAIN_PER_STEP:
            raise ValueError(f"relative_rate={rate!r} is out of range: the time step (dt = {dtr:.3g} τ) resolves "
                             f"at most {MAX_STRAIN_PER_STEP} strain per step, i.e. relative_rate <= "
                             f"{MAX_STRAIN_PER_STEP / dtr:.4g} (flag --relative-rate)")
    if proto == "relaxation":
        per_step = q["theAmplitude"] / steps["ramp"]
        if per_step > MAX_STRAIN_PER_STEP:
            raise ValueError(f"ramp_time={q['ramp_time']!r} is out of range: a ramp to theAmplitude="
                             f"{q['theAmplitude']!r} in {steps['ramp']} steps is {per_step:.3g} strain per step, more "
                             f"than {MAX_STRAIN_PER_STEP}; allowed ramp_time >= "
                             f"{q['theAmplitude'] / MAX_STRAIN_PER_STEP * dtr:.4g} (flag --ramp-time)")
    if proto == "creep":
        T = float(q["creep_response_time"])
        if T < 10 * dtr:
            raise ValueError(f"creep_response_time={T!r} is out of range: the controller needs >= 10 steps per "
                             f"response time, allowed >= {10 * dtr:.4g} (flag --creep-response-time)")
    if proto.endswith("sweep"):
        check_sweep_resolution(q, steps)
    total = sum(steps["segments"]) if proto.endswith("sweep") else steps["steps"]
    from .limits import MAX_TOTAL_STEPS, _protocol_room
    if total > MAX_TOTAL_STEPS:
        name, allowed = _protocol_room(q, steps, MAX_TOTAL_STEPS)
        raise ValueError(f"{name}={_shown(q[name])} is out of range: protocol={proto!r} needs {total:.3g} steps, more "
                         f"than the limit of {MAX_TOTAL_STEPS:.0e}; allowed {allowed} (flag --{name.replace('_', '-')})")
    return steps


def _shown(v):
    """A value for a message: a long list cut to its first and last values."""
    from ..checks import show_value
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
    from .limits import MIN_STEPS_PER_PERIOD, MIN_STEPS_PER_PERIOD_COARSENED
    proto = q["protocol"]
    steps = protocol_steps(q) if steps is None else steps
    factor = float(q["time_step_factor"])
    n = len(steps["dts"])
    freqs = q["sweep_frequencies"] if proto == "frequency_sweep" else [float(q["relative_frequency"])] * n
    for j, (fr, dtr) in enumerate(zip(freqs, steps["dts"])):
        spp = 1.0 / (fr * dtr / factor)        # steps per period at the reference time step
        if spp >= MIN_STEPS_PER_PERIOD and spp / factor >= MIN_STEPS_PER_PERIOD_COARSENED:
            continue
        if proto == "frequency_sweep":
            name, value, flag = f"sweep_frequencies[{j}]", fr, "--sweep-frequencies"
        else:
            name, value, flag = f"sweep_amplitudes[{j}]", q["sweep_amplitudes"][j], "--sweep-amplitudes"
        if spp < MIN_STEPS_PER_PERIOD:
            if proto == "frequency_sweep":
                allowed = (f"every value of sweep_frequencies <= {fr * spp / MIN_STEPS_PER_PERIOD:.4g} "
                           f"(flag {flag})")
            else:
                rf_max = min(1.0 / (MIN_STEPS_PER_PERIOD * d / factor) for d in steps["dts"])
                allowed = (f"relative_frequency <= {rf_max:.4g} for every amplitude of this sweep "
                           "(flag --relative-frequency)")
            raise ValueError(
                f"{name}={value:g} is out of range: this step of protocol={proto!r} (relative frequency {fr:g}, "
                f"dt = {dtr / factor:.3g} τ at the reference time step) would resolve an excitation period with "
                f"{spp:.3g} steps, fewer than {MIN_STEPS_PER_PERIOD}; allowed {allowed}")
        raise ValueError(
            f"time_step_factor={q['time_step_factor']!r} is out of range: it leaves {spp / factor:.3g} steps per "
            f"excitation period at {name}={value:g}, fewer than {MIN_STEPS_PER_PERIOD_COARSENED}; allowed "
            f"time_step_factor <= {spp / MIN_STEPS_PER_PERIOD_COARSENED:.3g} (flag --time-step-factor)")


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
    proto = q.get("protocol", "oscillatory")
    if proto == "amplitude_sweep":
        q["sweep_amplitudes"] = _values("sweep_amplitudes", q.get("sweep_amplitudes"), 0, 100)
        q["theAmplitude"] = q["sweep_amplitudes"][0]
    elif proto == "frequency_sweep":
        q["sweep_frequencies"] = _values("sweep_frequencies", q.get("sweep_frequencies"), 0, 1e6)
        q["relative_frequency"] = q["sweep_frequencies"][0]
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
    proto = q.get("protocol", "oscillatory")
    dtr = _dt_over_tau(q)
    out = {"dt_over_tau": dtr}
    if proto == "steady":
        out["steps"] = int(math.ceil(float(q["total_strain"]) / (float(q["relative_rate"]) * dtr)))
    elif proto == "relaxation":
        out["ramp"] = max(1, int(round(float(q["ramp_time"]) / dtr)))
        out["steps"] = 1 + out["ramp"] + int(math.ceil(float(q["hold_time"]) / dtr))   # a first step at rest
    elif proto == "creep":
        out["steps"] = int(math.ceil(float(q["hold_time"]) / dtr))
    elif proto.endswith("sweep"):
        amps = q["sweep_amplitudes"] if proto == "amplitude_sweep" else [q["theAmplitude"]] * len(q["sweep_frequencies"])
        freqs = q["sweep_frequencies"] if proto == "frequency_sweep" else [q["relative_frequency"]] * len(amps)
        out["dts"] = [_dt_over_tau(q, A) for A in amps]
        n_per = float(q["pre_periods"]) + float(q["periods"]) + float(q["post_periods"])
        out["segments"] = [int(n_per / fr / d) for fr, d in zip(freqs, out["dts"])]
    return out


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
        from ..analysis.verdicts import PROTOCOL_CHECKS, verdict
        names = PROTOCOL_CHECKS[self.protocol]
        return verdict({n: (False if any(st.get(n) is False for st in self.steps) else None) for n in names})

    @property
    def values(self):
        """The main numbers of the protocol (see the class docstring)."""
        s = self.summary
        if self.protocol == "steady":
            return [s["stress_surface"], s["viscosity_surface"]]
        if self.protocol == "relaxation":
            return [s["G_plateau_surface"]]
        if self.protocol == "creep":
            return [s["creep_rate"], s["creep_viscosity"]]
        return [[st["Gp_surface"], st["Gpp_surface"]] for st in self.steps]

    def rows(self):
        """The rows of this run in a sweep's results table: one, or one per step of a sweep.

        Keys as :func:`particleShear.sweep.table.table_columns` of a protocol sweep: ``run_id``,
        ``status`` ("ok"), ``error``, the moduli and measures (sweep steps), the run columns
        (``repetition``, ``frequency_Hz`` and ``omega`` of a sweep step, ``dt``, ``N_steps``), the
        protocol columns (:data:`particleShear.sweep.schema.PROTOCOL_COLUMNS`: the summary, or
        ``sweep_position``, ``sweep_amplitude``, ``sweep_relative_frequency`` of a step), every
        parameter, ``seed_entropy``, ``spawn_key``, ``package_version``, ``wall_time_s`` (s),
        ``output_path``.  Columns a protocol does not produce are absent (empty cells).

        Returns
        -------
        list of dict
        """
        from ..simulation.provenance import run_identity
        from .columns import PROTOCOL_COLUMNS
        params = spec_defaults(protocols=True)
        params.update({k: v for k, v in self.parameters.items() if k in params})
        base = {"run_id": run_identity(params, self.seed, self.spawn_key), "status": "ok", "error": "",
                "repetition": int(getattr(self, "repetition", 0)), "dt": float(self.dt)}
        base.update({k: v for k, v in self.summary.items() if k in PROTOCOL_COLUMNS or k == "verdict"})
        if self.protocol in ("steady", "relaxation", "creep"):
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
        from ..analysis.measures import MEASURE_COLUMNS
        from .columns import PROTOCOL_COLUMNS
        first = rows[0]
        proto = parameters["protocol"]
        inverse = {c: k for k, c in STEP_COLUMNS.items()}
        moduli = ("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal") + tuple(MEASURE_COLUMNS)
        steps = [{inverse.get(c, c): r.get(c) for c in tuple(STEP_COLUMNS.values()) + moduli}
                 for r in rows] if proto in ("amplitude_sweep", "frequency_sweep") else []
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
        from .columns import column_spec
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
                label = (f"A = {st.get('amplitude', float('nan')):.4g}" if self.protocol == "amplitude_sweep"
                         else f"f·τ = {st.get('relative_frequency', float('nan')):.4g}")
                for est in ("surface", "internal"):
                    rows.append((f"{label} ({est})",
                                 f"G′ = {num(st.get('Gp_' + est, float('nan')), st.get('Gp_' + est + '_se'))}, "
                                 f"G″ = {num(st.get('Gpp_' + est, float('nan')), st.get('Gpp_' + est + '_se'))}",
                                 "Pa"))
        else:
            from ..analysis.verdicts import CHECKS
            for name, v in self.summary.items():
                if name.endswith("_se") or name in CHECKS or name == "verdict":
                    continue
                unit = column_spec(name).get("unit") or ""
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
        from ..analysis.verdicts import verdict_lines
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
    from ..engine import rheometer as eng
    from ..engine.step import protocol as oscillatory
    from ..simulation.provenance import run_identity
    from .sessions import build_sessions
    from .rheometer_analysis import analyse_record, analyse_sweep
    from .rheometer_files import write_protocol_file

    proto = runs[0]["protocol"]
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
    loop = dict(say=say, report=report)
    t0 = time.perf_counter()
    recs, sweep_recs = None, None
    if proto == "steady":
        n = max(steps[b]["steps"] for b in order)
        recs = _guarded(lambda e: eng.steady_shear(e, sc.dt, sc.cool, [k["relative_rate"] / tau for k in kws], n,
                                                   N1_EVERY, **loop), engine, dt=sc.dt)
    elif proto == "relaxation":
        st = steps[order[0]]
        recs = _guarded(lambda e: eng.stress_relaxation(e, sc.dt, sc.cool, [k["theAmplitude"] for k in kws],
                                                        st["ramp"], st["steps"] - st["ramp"] - 1, **loop), engine, dt=sc.dt)
    elif proto == "creep":
        G_c = [k["creep_modulus"] if k["creep_modulus"] is not None else
               CREEP_MODULUS_FRACTION * k["Young_modulus_spheres"] for k in kws]
        rate_max = MAX_STRAIN_PER_STEP / sc.dt
        recs = _guarded(lambda e: eng.creep(e, sc.dt, sc.cool, [k["creep_stress"] for k in kws], G_c,
                                            kws[0]["creep_response_time"] * tau, steps[order[0]]["steps"], rate_max,
                                            **loop), engine, dt=sc.dt)
    else:
        sweep_recs = []
        st = steps[order[0]]
        for j, dtr in enumerate(st["dts"]):
            dt = dtr * tau
            if proto == "amplitude_sweep":
                f, A = sc.f, [k["sweep_amplitudes"][j] for k in kws]
            else:
                f, A = kws[0]["sweep_frequencies"][j] / tau, [k["theAmplitude"] for k in kws]
            cool = kws[0]["cool_factor"] ** (f * dt)
            out = _guarded(oscillatory, engine, dt, f, A, cool, kws[0]["pre_periods"], kws[0]["periods"],
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
            summary, curves = analyse_record(proto, kw, series, tau, steps[b], MAX_STRAIN_PER_STEP)
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
