"""Deterministic identity of a run: a short hash of its complete parameter set and seed.

Two runs with the same parameters (every argument of ``doParticleShearSimulation`` that
can change a number, see :func:`canonical_parameters`) and the same seed (entropy and
spawn key of the ``numpy.random.SeedSequence``) are the same run and get the same id,
whatever the order of the keys, the host or the Python session.  Sweeps name their output
files from it and resume by it (docs/sweeps.md).
"""
import hashlib
import json
import numbers

import numpy as np

__all__ = ["run_identity", "canonical_json", "RUN_ID_LENGTH", "NON_IDENTITY_PARAMETERS"]

#: hex characters of a run id (48 bits: a collision among 10^6 runs has probability ~2e-3 %)
RUN_ID_LENGTH = 12

#: parameters that say where or how a run is shown or written, never what it computes
NON_IDENTITY_PARAMETERS = ("root_folder", "seed", "return_result", "verbose", "progress")


def _canonical_value(name, v):
    """A JSON-stable form of one value: bools stay bools, every other real number becomes a float.

    ``N = 30`` and ``N = 30.0`` describe the same run, so both hash alike; ``True`` and ``1``
    are kept apart (a bool parameter is never numeric).
    """
    if isinstance(v, (bool, np.bool_)):
        return bool(v)
    if isinstance(v, numbers.Real):
        x = float(v)
        if x != x or x in (float("inf"), float("-inf")):
            raise ValueError(f"{name}={v!r} is invalid for a run identity: allowed a finite number")
        return x
    if v is None or isinstance(v, str):
        return v
    raise TypeError(f"{name}={v!r} is invalid for a run identity: allowed a bool, number, string or None")


def canonical_json(parameters, seed_entropy, spawn_key):
    """The canonical JSON text hashed by :func:`run_identity` (sorted keys, no spaces)."""
    params = {k: _canonical_value(k, v) for k, v in parameters.items() if k not in NON_IDENTITY_PARAMETERS}
    if seed_entropy is not None and not isinstance(seed_entropy, numbers.Integral):
        raise TypeError(f"seed_entropy={seed_entropy!r} is invalid: allowed an integer or None")
    doc = {"parameters": params,
           "seed_entropy": None if seed_entropy is None else int(seed_entropy),
           "spawn_key": [int(k) for k in spawn_key]}
    return json.dumps(doc, sort_keys=True, separators=(",", ":"), allow_nan=False)


def run_identity(parameters, seed_entropy, spawn_key):
    """Run id: the first 12 hex digits of the SHA-256 of :func:`canonical_json`.

    Parameters
    ----------
    parameters : dict
        Arguments of ``doParticleShearSimulation`` (reference names); ``root_folder``,
        ``seed``, ``verbose``, ``progress`` and ``return_result`` are ignored.
    seed_entropy : int or None
        ``SeedSequence.entropy`` of the run.
    spawn_key : sequence of int
        ``SeedSequence.spawn_key`` of the run (``(k,)`` for run k of a sweep).

    Returns
    -------
    str
        12 lowercase hex characters.
    """
    text = canonical_json(parameters, seed_entropy, spawn_key)
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:RUN_ID_LENGTH]
