"""The rheometer's protocols, one file each: every module of this folder is a protocol, found at import.

A protocol's file holds everything particular to it (docs/design.md, "Adding a protocol"):

- ``PARAMETERS``: its own parameters, :class:`particleShear.parameter_entry.Parameter` entries of
  role ``protocol:<name>`` (default, unit, range, one-line doc; a parameter several protocols read
  is declared by each with the same entry, and the table joins their roles);
- ``check(q)`` and ``check_steps(q, steps)``: the protocol's own validation of its values and of
  its step counts, raising ``ValueError`` naming the parameter, its value and the allowed range;
- ``steps(q, dt_over_tau)``: its step counts (``{"steps": n, ...}``, from the run's arguments and
  ``dt_over_tau(amplitude=None)``, the protocol time step in units of τ);
- its drive: ``schedule(kws, steps, tau, dt, backend)`` for a protocol run by the one recording
  loop :func:`particleShear.engine.rheometer.shear_record` (a rate schedule ``rate_of(i)`` or a
  controller with its ``after_step``), or ``segments(kws, steps, tau, f)`` for a sequence of
  oscillations on one packing (the sweeps);
- ``COLUMNS``: its result columns ``name -> (type, unit, description)`` (the results table and its
  schema), ``CHECKS``: the names of its verdict checks;
- ``summary(kw, series, tau, steps, stats)``: its scalars, curves and checks from one replica's
  record (``stats``: :data:`particleShear.run.rheometer_analysis.STATS`, the statistics of
  :mod:`particleShear.analysis.rheometry` and the checks of :mod:`particleShear.analysis.verdicts`),
  ``values(summary)``: what ``doParticleShearSimulation`` returns without ``return_result``;
- its registration ``PROTOCOL = register_protocol(...)``.

Importing this package imports every module of the folder (:mod:`pkgutil`; a name starting with
``_`` is a helper, not a protocol), so the shipped protocols — and a file saved here — are known in
every process that imports particleShear, spawn workers included.  :mod:`particleShear.parameters`
composes their parameters into the run's table (:func:`declared_parameters`), from which the
validation, the command line, the SPEC keys, the results columns and the run identity follow.

Optional module constants: ``POSITION`` (the order of ``protocol``'s choices: lowest first, then
by name) and ``SIGNATURE`` (True: the parameters are keywords of ``doParticleShearSimulation``'s
signature — the shipped protocols', as in 2.0.0; another protocol's parameters are taken by its
``**law_parameters``).

Every protocol is measured by the one driver, :func:`particleShear.simulation.driver.measure_sessions`,
whose part for it is that of its :attr:`Protocol.loop`.

Shipped: ``oscillatory`` (the default, the reference's experiment), ``steady``, ``relaxation``, ``creep``, ``amplitude_sweep``,
``frequency_sweep``.
"""
__docformat__ = "numpy"

import dataclasses
import importlib
import math
import pkgutil

import numpy as np

from ..parameter_entry import Parameter

__all__ = ["Protocol", "PROTOCOLS", "LOOPS", "MODULES", "MAX_STRAIN_PER_STEP", "MIN_STEPS_PER_PERIOD",
           "MIN_STEPS_PER_PERIOD_COARSENED", "register_protocol", "get_protocol",
           "declared_parameters", "result_columns", "positive", "monotonic_values"]

#: largest strain increment |γ̇|·dt of one step (≈ 9× the default oscillation's peak, 5.6e-4):
#: neighbours 2r apart then move by at most 1 % of r relative to each other per step
MAX_STRAIN_PER_STEP = 0.005
#: fewest protocol steps per excitation period at the reference time step: the demodulation
#: integrates one sine period with the rectangle rule, whose error on G′, G″ is O(1/n²)
#: (~1e-4 relative at n = 100), and the explicit step stays far below the period
MIN_STEPS_PER_PERIOD = 100
#: fewest protocol steps per period that a coarsened time step (``time_step_factor`` > 1) may
#: leave: below 2 samples a period the excitation cannot be represented at all (Nyquist)
MIN_STEPS_PER_PERIOD_COARSENED = 2


@dataclasses.dataclass(frozen=True)
class Protocol:
    """A registered protocol (module docstring; made by :func:`register_protocol`); each parameter
    is the attribute of the same name.

    Parameters
    ----------
    name : str
        The value of ``protocol=``.
    parameters : tuple of Parameter
        Its own parameters (role ``protocol:<name>``).
    steps : callable
        ``steps(q, dt_over_tau) -> dict`` with ``"steps"`` (recorded protocols) or ``"segments"``
        and ``"dts"`` (sweeps).
    check : callable or None
        ``check(q)``: raises ``ValueError`` for values the protocol cannot run.
    check_steps : callable or None
        ``check_steps(q, steps)``: raises ``ValueError`` for step counts the protocol cannot run
        (a rate the time step cannot resolve).
    normalize : callable or None
        ``normalize(q)``: puts the values the protocol derives into the run's arguments (in place).
    schedule : callable or None
        ``schedule(kws, steps, tau, dt, backend) -> dict`` with ``n_steps``, ``rate_of`` and
        optionally ``after_step``, ``tensors_every`` (:func:`~particleShear.engine.rheometer.shear_record`).
    segments : callable or None
        ``segments(kws, steps, tau, f) -> [(f, amplitudes, dt), ...]``: the oscillations of a sweep.
    summary : callable or None
        ``summary(kw, series, tau, steps, stats) -> (scalars, curves, checks)``.
    values : callable or None
        ``values(summary) -> list``: the return value without ``return_result``.
    columns : dict
        Result columns, name → (type, unit, description).
    checks : tuple of str
        Its verdict checks.
    room : callable or None
        ``room(q, steps, steps_ok) -> (name, allowed text)``: the parameter to shorten when the
        protocol needs more than ``steps_ok`` steps.
    label : callable or None
        ``label(step) -> str`` of a sweep's step (the summary's row label).
    shorten : callable or None
        ``shorten(q, steps, n, steps_of) -> dict``: the parameters that cut the protocol to about
        ``n`` steps, never longer (a sweep's cost calibration, :mod:`particleShear.sweep.calibration`;
        ``steps_of(q)`` the step counts of other arguments); None: the protocol is not cut.
    n_rows : callable or None
        ``n_rows(q)``: rows of a run in a results table (a sweep's steps); None: one.
    step_value : tuple or None
        ``(parameter column, step column)``: the column a step row's value of a sweep's list
        stands for (``analyse`` groups steps by it); None for a protocol without steps.
    shown : tuple or None
        ``(column, label, unit)`` a sweep's progress line shows for a run; None: the first of
        :attr:`required_numbers`.
    header : tuple of str or None
        The parameters the header of the run's file lists (:mod:`particleShear.run.rheometer_files`);
        None: its own parameters.
    file_name : tuple or None
        ``(word, parameter)`` the file name carries (``<protocol>_<word>_<value>``); None: none.
    required : tuple of str or None
        The columns an ``ok`` row of the protocol must hold a number in (a row without one is run
        again on resume); None: its float ``columns``.
    record_bytes : int
        Memory a run plans per protocol step (bytes; default: the recording loop's 5 series of
        8 bytes and as much again for the run's series, analysis and file columns,
        :data:`particleShear.run.validation.PROTOCOL_RECORD_BYTES_PER_STEP`).
    quantities : dict
        The quantities ``python -m particleShear analyse`` summarises over a group of runs
        (name, ``{est}`` the estimator → unit).
    doc : str
        One line: what the protocol does.
    """

    name: str
    parameters: tuple = ()
    steps: object = None
    check: object = None
    check_steps: object = None
    normalize: object = None
    schedule: object = None
    segments: object = None
    summary: object = None
    values: object = None
    columns: dict = dataclasses.field(default_factory=dict)
    checks: tuple = ()
    room: object = None
    label: object = None
    shorten: object = None
    n_rows: object = None
    step_value: tuple = None
    shown: tuple = None
    header: tuple = None
    file_name: tuple = None
    required: tuple = None
    record_bytes: int = 2 * 5 * 8
    quantities: dict = dataclasses.field(default_factory=dict)
    doc: str = ""

    @property
    def header_parameters(self):
        """:attr:`header`, or the names of its own parameters when None."""
        return tuple(self.header) if self.header is not None else tuple(p.name for p in self.parameters)

    @property
    def required_numbers(self):
        """:attr:`required`, or the float columns when None."""
        if self.required is not None:
            return tuple(self.required)
        return tuple(name for name, (kind, *_) in self.columns.items() if kind == "float")

    @property
    def recorded(self):
        """True when the one recording loop runs it (a rate schedule or a controller)."""
        return self.schedule is not None

    @property
    def segmented(self):
        """True for a sequence of oscillations on one packing (a sweep)."""
        return self.segments is not None

    @property
    def loop(self):
        """The part of the measurement driver that runs it (:data:`LOOPS`): ``"record"`` (the one
        recording loop, driven by :attr:`schedule`), ``"segments"`` (oscillations on one packing,
        :attr:`segments`) or ``"oscillation"`` (neither: the reference's experiment, its observers,
        snapshots and file)."""
        return "record" if self.recorded else "segments" if self.segmented else "oscillation"


#: the parts of the measurement driver a protocol is run by (:attr:`Protocol.loop`;
#: :func:`particleShear.simulation.driver.measure_sessions` keeps one for each)
LOOPS = ("oscillation", "record", "segments")

#: the registered protocols, name → :class:`Protocol`
PROTOCOLS = {}


def register_protocol(name, **fields):
    """Register protocol ``name`` (the call at the end of a protocol's file).

    Parameters
    ----------
    name : str
        The value of ``protocol=``: an identifier.
    **fields
        The :class:`Protocol` attributes.

    Returns
    -------
    Protocol

    Raises
    ------
    ValueError
        For a name that is not an identifier, or a parameter whose role does not name the protocol.
    """
    if not (isinstance(name, str) and name.isidentifier()):
        raise ValueError(f"protocol name {name!r} is invalid: allowed a Python identifier")
    proto = Protocol(name, **fields)
    for p in proto.parameters:
        if not isinstance(p, Parameter) or p.base_role != "protocol" or name not in p.role_names:
            raise ValueError(f"parameter {getattr(p, 'name', p)!r} of protocol {name!r} is invalid: allowed a "
                             f"Parameter of role 'protocol:{name}'")
    PROTOCOLS[name] = proto
    return proto


def get_protocol(name):
    """The registered protocol ``name``.

    Parameters
    ----------
    name : str
        The value of ``protocol=``.

    Returns
    -------
    Protocol

    Raises
    ------
    KeyError
        When no protocol of that name is registered.
    """
    return PROTOCOLS[name]


def positive(name, v, hi=math.inf):
    """``float(v)`` when ``0 < v <= hi``.

    Parameters
    ----------
    name : str
        The parameter (named in the message with its flag).
    v : object
        Its value.
    hi : float, default inf
        The upper limit (included).

    Returns
    -------
    float

    Raises
    ------
    TypeError
        When ``v`` is not a real number.
    ValueError
        Naming the parameter, the value, the allowed range and the flag.
    """
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name}={v!r} is invalid: allowed a real number > 0 (flag --{name.replace('_', '-')})")
    if not (math.isfinite(v) and 0 < v <= hi):
        raise ValueError(f"{name}={v!r} is out of range: allowed 0 < {name} <= {hi:g} "
                         f"(flag --{name.replace('_', '-')})")
    return float(v)


def monotonic_values(name, v, lo, hi):
    """The list ``v`` as floats: 1 to 10000 values in ``(lo, hi]``, strictly increasing or decreasing.

    Parameters
    ----------
    name : str
        The parameter (a sweep's list).
    v : object
        Its value.
    lo, hi : float
        The range of every value (``lo`` excluded, ``hi`` included; ``lo`` is 0 here).

    Returns
    -------
    list of float

    Raises
    ------
    ValueError
        Naming the parameter, the value and what is allowed.
    """
    if v is None or isinstance(v, (str, bytes)) or not hasattr(v, "__len__"):
        raise ValueError(f"{name}={v!r} is invalid: the sweep needs a list of values in ({lo:g}, {hi:g}]")
    vals = [positive(name, x, hi) for x in list(v)[:10001]]
    if not 1 <= len(vals) <= 10000:
        raise ValueError(f"{name} has {len(vals)} values: allowed 1 ... 10000")
    d = np.diff(vals)
    if len(vals) > 1 and not ((d > 0).all() or (d < 0).all()):
        raise ValueError(f"{name}={vals!r} is invalid: a sweep runs in one direction on one sample, so the values "
                         "must be strictly increasing or strictly decreasing (no repeats)")
    return vals


def _discover():
    """Import every module of this folder, in the order of ``POSITION`` then name; name → module."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        proto = getattr(module, "PROTOCOL", None)
        if not isinstance(proto, Protocol):
            raise ImportError(f"{module.__name__} is not a protocol: it defines no PROTOCOL = register_protocol(...) "
                              "(docs/design.md, 'Adding a protocol')")
        found.append((getattr(module, "POSITION", math.inf), proto.name, module))
    return {name: module for _, name, module in sorted(found, key=lambda t: t[:2])}


#: the protocol modules of this folder, protocol name → module, in the order of ``protocol``'s choices
MODULES = _discover()
# the registry in the same order (a protocol registered later follows)
_ORDERED = {name: PROTOCOLS[name] for name in MODULES}
PROTOCOLS.clear()
PROTOCOLS.update(_ORDERED)


def result_columns(check_order=()):
    """The result columns of the protocols, in table order.

    The step columns of the sweeps first, then the summaries of the other protocols (each column
    once, in the order of ``protocol``'s choices), then the checks of the recorded protocols (those
    of ``check_order`` in its order, then a protocol's own in protocol order).

    Parameters
    ----------
    check_order : sequence of str
        The known checks in table order (:data:`particleShear.analysis.verdicts.CHECKS`).

    Returns
    -------
    values : dict
        Column → ``(type, unit, description)`` of the protocols' ``columns``.
    checks : dict
        Check → the names of the protocols that judge it.
    """
    checks = {}
    for p in PROTOCOLS.values():
        if p.recorded:
            for c in p.checks:
                checks.setdefault(c, []).append(p.name)
    order = list(check_order)
    checks = {c: tuple(checks[c]) for c in sorted(checks, key=lambda c: order.index(c) if c in order else len(order))}
    values = {}
    for p in [p for p in PROTOCOLS.values() if p.segmented] + [p for p in PROTOCOLS.values() if not p.segmented]:
        values.update({k: v for k, v in p.columns.items() if k not in values and k not in checks})
    return values, checks


def declared_parameters():
    """Every discovered protocol's declared parameters: name → ``(parameters, in_signature)``.

    Returns
    -------
    dict
        Protocol name → ``(tuple of Parameter, bool)``, in the order of :data:`MODULES`.
    """
    return {name: (tuple(PROTOCOLS[name].parameters), bool(getattr(module, "SIGNATURE", False)))
            for name, module in MODULES.items()}
