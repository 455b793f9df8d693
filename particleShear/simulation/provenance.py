"""Provenance of a run: its identity (a hash of every input and the seed) and header formatting.

Two runs with the same parameters and the same seed are the same run; :func:`run_identity`
gives them the same short id whatever the process, machine or order of the parameters.  The
id is written in the header of the text file, in the JSON sidecar and in
``SimulationResult.run_id`` (see ``docs/output.md``).

Header numbers are written with :func:`header_number`: Python's ``str()`` unless that uses
exponent notation, which the regular expressions of the downstream R package
(particleShearEvaluation) read as digits only (``1e-05`` would be read as 1).  Such numbers are
written positionally instead (``0.00001``), which reads back as the same float.
"""
__docformat__ = "numpy"
import hashlib
import json
import math
import numbers
import re

import numpy as np

from ..engine.contact_laws import get_law
from ..engine.xp import identity_backend
from ..parameters import identity_excluded
from ..parameters import names as _names
from .._version import __version__

__all__ = ["run_identity", "identity_parameters", "same_input", "header_number", "positional_numbers_in_call",
           "json_safe", "provenance_lines", "IDENTITY_EXCLUDED", "package_version"]

#: the parameters no run identity holds: what a run shows, what the caller chooses for the call and
#: the observers (roles "display", "call", "observer" of :mod:`particleShear.parameters`)
IDENTITY_EXCLUDED = frozenset(_names("display") + _names("call") + _names("observer"))


def package_version():
    """The installed particleShear version (``particleShear.__version__``)."""
    return __version__


def json_safe(value):
    """``value`` as plain JSON data: numbers, strings, booleans, None, lists and dicts.

    NumPy scalars become Python numbers, tuples lists, SeedSequences ``{"entropy", "spawn_key"}``,
    callables and other objects their qualified name (they cannot be stored, but their
    presence is recorded).

    Parameters
    ----------
    value : object
        Any value (nested lists, tuples and dicts are converted recursively).

    Returns
    -------
    object
        JSON-serialisable data.
    """
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else repr(v)
    if isinstance(value, np.random.SeedSequence):
        return {"entropy": json_safe(value.entropy), "spawn_key": [int(k) for k in value.spawn_key]}
    if isinstance(value, dict):
        return {str(k): json_safe(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, np.ndarray)):
        return [json_safe(v) for v in value]
    if hasattr(value, "__fspath__"):
        return str(value.__fspath__())
    name = getattr(value, "__qualname__", None) or type(value).__qualname__
    return "<" + str(name) + ">"


def _identity_value(value):
    """JSON form of one input for the run identity: every real number as a float, bools as bools.

    ``N = 30`` and ``N = 30.0`` describe the same run and hash alike; ``True`` and ``1`` stay apart.
    """
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, numbers.Real):
        return json_safe(float(value))
    return json_safe(value)


def _identity_form(name, value):
    """The input ``name`` as the identity sees it: ``backend`` through
    :func:`~particleShear.engine.xp.identity_backend` (the backends that give NumPy's bits are one
    run), every other input as it is."""
    return identity_backend(value) if name == "backend" else value


def identity_parameters(parameters):
    """The inputs that make a run what it is, in the form the run identity hashes them.

    The names :func:`particleShear.parameters.identity_excluded` gives are left out (those of
    :data:`IDENTITY_EXCLUDED`, the parameters of the laws and protocols the run does not use, and
    ``contact_law`` and ``protocol`` at their defaults: they change nothing of such a run, and a run
    keeps the id it had before the law or the protocol was a parameter); every real number is a float (``N = 30`` and
    ``N = 30.0``, ``0.2`` and ``numpy.float64(0.2)`` are the same input), bools stay bools, and
    ``backend`` is ``"numpy"`` for ``"numpy"``, ``"numba"`` and ``"auto"`` (bit-identical runs:
    :func:`~particleShear.engine.xp.identity_backend`).  This
    is the one rule of "the same run": :func:`run_identity` hashes it, a sweep compares a results
    row and matches the runs of an extended folder with it.

    Parameters
    ----------
    parameters : dict
        Inputs of :func:`doParticleShearSimulation` (any superset).

    Returns
    -------
    dict
    """
    unused = identity_excluded(parameters)
    return {k: _identity_value(_identity_form(k, v)) for k, v in parameters.items() if k not in unused}


def same_input(text, value, name=None):
    """True when the text ``text`` (a results-table cell) is the input ``value`` under :func:`identity_parameters`.

    Parameters
    ----------
    text : str or None
        The cell as read back.
    value : object
        The run's input.
    name : str, optional
        The input's name: a cell of ``backend`` (the backend used, e.g. ``"numba"``) is the input
        ``"auto"`` or ``"numpy"`` as the identity sees them.

    Returns
    -------
    bool
    """
    if text is None:
        return False
    text = _identity_form(name, text)
    want = _identity_value(_identity_form(name, value))
    if want is None:                 # an unset option (creep_modulus=None) is an empty cell
        return text == ""
    if isinstance(want, list):       # a list (sweep_amplitudes) is a JSON cell
        try:
            got = json.loads(text)
        except ValueError:
            return False
        return isinstance(got, list) and got == want
    if isinstance(want, bool):
        return text == str(want)
    if isinstance(want, float):
        try:
            return float(text) == want
        except ValueError:
            return False
    return text == str(want)


def run_identity(parameters, seed_entropy, spawn_key):
    """Short deterministic id of a run: 12 hex digits of SHA-256 over its inputs and seed.

    Parameters
    ----------
    parameters : dict
        Inputs of :func:`doParticleShearSimulation` (any superset is fine); keys in
        :data:`IDENTITY_EXCLUDED` (where the files go, console and drawing options, the seed
        object itself) are ignored, as is the order of the keys.
    seed_entropy : int or None
        ``SeedSequence.entropy`` of the run (None when a Generator was passed).
    spawn_key : sequence of int
        ``SeedSequence.spawn_key`` (empty for a single run, ``(k,)`` for run k of a series).

    Returns
    -------
    str
        12 lower-case hexadecimal digits (48 bits: collisions are negligible for campaigns of
        millions of runs).
    """
    payload = {"parameters": identity_parameters(parameters), "seed_entropy": json_safe(seed_entropy),
               "spawn_key": [int(k) for k in (spawn_key or ())]}
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:12]


def header_number(value):
    """``str(value)``, except that a float in exponent notation is written positionally.

    ``header_number(1e-05) == "0.00001"``, ``header_number(0.1) == "0.1"``,
    ``header_number(8000) == "8000"``; ``float(header_number(x)) == x`` for every finite float.
    Non-numbers (booleans, strings) are returned as ``str(value)``.

    Parameters
    ----------
    value : object
        A header value (float, int, bool, str, ...).

    Returns
    -------
    str
    """
    text = str(value)
    if isinstance(value, (float, np.floating)) and math.isfinite(value) and ("e" in text or "E" in text):
        return np.format_float_positional(float(value), trim="-")
    return text


# a number in exponent notation right after "=" (optionally one space) and before , ) or the line end;
# the value of root_folder (a path) is never touched
_CALL_EXPONENT = re.compile(r"(?<!root_folder=)(?<==)( ?)(-?\d+(?:\.\d*)?[eE][+-]?\d+)(?=[,)\n]|$)")


def positional_numbers_in_call(text):
    """The function-call lines of the header with every exponent-notation number written positionally.

    Parameters
    ----------
    text : str
        Header text with ``name=value`` arguments; a number in exponent notation after ``=``
        (not the ``root_folder`` path) is rewritten with :func:`header_number`.

    Returns
    -------
    str
    """
    return _CALL_EXPONENT.sub(lambda m: m.group(1) + header_number(float(m.group(2))), text)


def provenance_lines(run_id, seed_entropy, spawn_key, time_step_factor, integrator, correct_drift_sign,
                     contact_law=None):
    """The provenance lines of the header's first block (each TAB-indented, joined by newlines).

    The labels use ``:`` instead of ``=`` and none contains a label that the downstream R
    patterns search for, so they change nothing that particleShearEvaluation reads.

    Parameters
    ----------
    run_id : str
        :func:`run_identity` of the run.
    seed_entropy : int
        Entropy of the run's ``numpy.random.SeedSequence``.
    spawn_key : tuple of int
        Its spawn key (empty for a root sequence).
    time_step_factor : float
        Multiplier of the model's time step (``time_step_factor`` of ``doParticleShearSimulation``).
    integrator : str
        ``"euler"`` or ``"verlet"``.
    correct_drift_sign : bool
        Whether the demodulation's drift correction had the correct sign (docs/output.md).

    contact_law : tuple or None, optional
        ``(name, values)`` of the run's contact law (``contact_law_spec`` of the run layer), or
        None for "linear" (the documented callback).
    Returns
    -------
    str
        The lines, without a final newline.
    """
    key = ",".join(str(int(k)) for k in (spawn_key or ()))
    return "\n".join([
        "\tparticleShear version: " + package_version(),
        "\tRun id: " + str(run_id),
        "\tSeed entropy: " + str(seed_entropy),
        "\tSeed spawn key: [" + key + "]",
        "\tTime step factor: " + header_number(time_step_factor),
        "\tIntegrator: " + str(integrator),
        "\tCorrect drift sign: " + str(bool(correct_drift_sign)),
        "\tContact law: " + _law_text(contact_law),
    ])


def _law_text(spec):
    """``linear`` or e.g. ``plateau (plateau_begin 0.3, plateau_end 0.8, plateau_slope 0.1)``."""
    if spec is None:
        return "linear"
    name, values = spec
    pairs = ", ".join(f"{p} {header_number(v)}" for p, v in zip(get_law(name).parameters, values))
    return name + (f" ({pairs})" if pairs else "")
