"""One folder, one sweep: the SPEC a sweep folder was made with, recorded in ``DIR/sweep.json``.

The first run of a sweep into a folder records its SPEC in canonical form (numbers as floats,
parameters sorted, grid and zip keys in file order) with the SHA-256 of that form.  A later
sweep into the folder with another SPEC is refused before any work, naming what changed
(``parameters.N: 30 -> 32``), so the rows of two different sweeps are never mixed in one table.

Asked explicitly (``extend=True``, ``--extend``), the folder's sweep grows instead: the new SPEC is
recorded as a further *segment*.  The runs of the folder are then those of every segment:

* a run of the new SPEC whose point (parameter values) and repetition — with the same seed
  root — is a run of an earlier segment *is* that run (same seed, same id, its row kept);
* every other run of the new SPEC is new and gets the next unused spawn keys (its index counts
  on after the earlier segments), so no two runs of the folder share a seed.

So adding a grid value or repetitions runs only the new points; nothing recorded is lost.
"""
__docformat__ = "numpy"
import hashlib
import json
import os

from .._version import __version__
from ..simulation.provenance import identity_parameters, run_identity
from .table import atomic_text

__all__ = ["RECORD_NAME", "canonical_spec", "spec_hash", "spec_changes", "read_record", "write_record",
           "extended_runs", "check_record"]

#: the record of a sweep folder
RECORD_NAME = "sweep.json"
_FORMAT = "particleShear sweep record 1"


def _num(v):
    if isinstance(v, list):          # one value of sweep_amplitudes / sweep_frequencies
        return [_num(x) for x in v]
    return v if isinstance(v, (bool, str)) else float(v)


def canonical_spec(spec):
    """The canonical, JSON-safe form of a :class:`~particleShear.sweep.spec.SweepSpec`.

    Parameters
    ----------
    spec : SweepSpec

    Returns
    -------
    dict
        ``{"parameters": {name: value} (sorted), "grid": [[name, [values]], ...],
        "zip": [[[name, [values]], ...], ...], "seeds": {"root", "repetitions"}}``; numbers as floats.
    """
    return {"parameters": {k: _num(v) for k, v in sorted(spec.parameters.items())},
            "grid": [[k, [_num(x) for x in vals]] for k, vals in spec.grid.items()],
            "zip": [[[k, [_num(x) for x in vals]] for k, vals in g.items()] for g in spec.zips],
            "seeds": {"root": int(spec.root), "repetitions": int(spec.repetitions)}}


def spec_hash(canonical):
    """SHA-256 (hex) of a canonical SPEC's compact JSON.

    Parameters
    ----------
    canonical : dict
        A canonical SPEC (:func:`canonical_spec`).

    Returns
    -------
    str
    """
    return hashlib.sha256(json.dumps(canonical, separators=(",", ":")).encode("utf-8")).hexdigest()


def _plain(v):
    """Whole floats shown as integers (``30.0`` → ``30``) in messages; the canonical form keeps floats."""
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e16:
        return int(v)
    if isinstance(v, list):
        return [_plain(x) for x in v]
    return v


def _short(v, n=60):
    s = json.dumps(_plain(v))
    return s if len(s) <= n else s[:n - 1] + "…"


def spec_changes(old, new):
    """What differs between two canonical SPECs, one ``"where: old -> new"`` string per change.

    Parameters
    ----------
    old, new : dict
        Canonical SPECs (:func:`canonical_spec`).

    Returns
    -------
    list of str
    """
    out = []
    for name in sorted(set(old["parameters"]) | set(new["parameters"])):
        a, b = old["parameters"].get(name, "(unset)"), new["parameters"].get(name, "(unset)")
        if a != b:
            out.append(f"parameters.{name}: {_short(a)} -> {_short(b)}")
    og, ng = dict(map(tuple, old["grid"])), dict(map(tuple, new["grid"]))
    for name in list(og) + [n for n in ng if n not in og]:
        a, b = og.get(name, "(unset)"), ng.get(name, "(unset)")
        if a != b:
            out.append(f"grid.{name}: {_short(a)} -> {_short(b)}")
    if [k for k, _ in old["grid"]] != [k for k, _ in new["grid"]] and not out:
        out.append(f"grid order: {[k for k, _ in old['grid']]} -> {[k for k, _ in new['grid']]}")
    if old["zip"] != new["zip"]:
        out.append(f"zip: {_short(old['zip'])} -> {_short(new['zip'])}")
    for key in ("root", "repetitions"):
        if old["seeds"][key] != new["seeds"][key]:
            out.append(f"seeds.{key}: {old['seeds'][key]} -> {new['seeds'][key]}")
    return out


def read_record(out_dir):
    """The record of ``out_dir`` (dict with ``segments``), or None when the folder has none.

    Parameters
    ----------
    out_dir : str
        The sweep folder.

    Returns
    -------
    dict or None

    Raises
    ------
    ValueError
        When ``sweep.json`` exists but is not a readable record (it is never guessed).
    """
    path = os.path.join(out_dir, RECORD_NAME)
    if not os.path.exists(path):
        return None
    try:
        with open(path, encoding="utf-8") as fh:
            rec = json.load(fh)
        if rec.get("format") != _FORMAT or not rec.get("segments"):
            raise ValueError("not a sweep record")
        for seg in rec["segments"]:
            if spec_hash(seg["spec"]) != seg["sha256"]:
                raise ValueError("its checksum does not match")
    except (OSError, ValueError, KeyError, TypeError, AttributeError) as exc:
        raise ValueError(f"the sweep record {path!r} is unreadable ({exc}): restore it, or use another "
                         "--out DIR") from None
    return rec


def write_record(out_dir, segments, docs):
    """Write ``DIR/sweep.json`` atomically: the canonical SPECs ``segments`` (oldest first) and their documents.

    Parameters
    ----------
    out_dir : str
        The sweep folder.
    segments : list of dict
        Canonical SPECs (:func:`canonical_spec`), oldest first.
    docs : list of dict
        The same SPECs as documents of their tables with the original value types (from which
        an earlier segment's runs are rebuilt when the folder is extended).
    """
    rec = {"format": _FORMAT, "package_version": __version__,
           "segments": [{"spec": c, "sha256": spec_hash(c), "doc": d} for c, d in zip(segments, docs)]}
    with atomic_text(os.path.join(out_dir, RECORD_NAME)) as fh:   # a temporary name per process: tasks race
        json.dump(rec, fh, indent=1)


def check_record(out_dir, segments, canonical, extend):
    """Whether ``canonical`` runs into a folder of the recorded ``segments`` as a new segment; refuse another SPEC.

    Parameters
    ----------
    out_dir : str
        The sweep folder (for the message).
    segments : list of dict
        The canonical SPECs the folder records, oldest first (:func:`read_record`).
    canonical : dict
        The canonical SPEC about to run.
    extend : bool
        True: a SPEC that is none of the segments becomes a further one (see the module docstring).

    Returns
    -------
    bool
        True when ``canonical`` is to be recorded as a new segment; False when it is the newest
        segment (or, with ``extend``, an earlier one).

    Raises
    ------
    ValueError
        When the folder records another SPEC and ``extend`` is False; the message lists the
        changes and names ``--extend``.
    """
    h = spec_hash(canonical)
    if spec_hash(segments[-1]) == h or (extend and any(spec_hash(s) == h for s in segments)):
        return False
    if not extend:
        changes = "; ".join(spec_changes(segments[-1], canonical)) or "the SPEC differs"
        raise ValueError(f"out_dir={out_dir!r} (--out) holds a sweep of another SPEC ({changes}); use another "
                         "--out DIR, or pass --extend (extend=True) to add the new runs to this folder's sweep and "
                         "keep its rows")
    return True


def extended_runs(segment_specs, segment_runs):
    """The runs of a folder of several segments (see the module docstring), in order.

    Parameters
    ----------
    segment_specs : list of SweepSpec
        The segments' SPECs, oldest first.
    segment_runs : list of sequence of SweepRun
        Each segment's own runs (:func:`~particleShear.sweep.spec.spec_runs`).

    Returns
    -------
    list of SweepRun
        Segment 0's runs, then each later segment's runs that are not runs of an earlier one,
        indexed (spawn key) on from the runs before them.
    """
    import dataclasses
    seen = set()
    out = []
    for spec, runs in zip(segment_specs, segment_runs):
        for run in runs:
            key = (json.dumps(identity_parameters(run.parameters), sort_keys=True), run.repetition, spec.root)
            if key in seen:
                continue
            seen.add(key)
            k = len(out)
            if run.index != k:
                run = dataclasses.replace(run, index=k, spawn_key=(k,),
                                          run_id=run_identity(run.parameters, run.seed_entropy, (k,)))
            out.append(run)
    return out
