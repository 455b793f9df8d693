"""The file of a rheometer protocol's run (``saveData=True``; docs/protocols.md, "Files").

One file per run, in the run's ``output_format``, complete or absent (an
:class:`~particleShear.simulation.output.AtomicOutputFile` with its JSON sidecar, as the
oscillatory files; :func:`~particleShear.simulation.formats.read_run` reads and verifies it):

- the text header: block 1 of the oscillatory file (ensemble, provenance, function call), the
  block "Rheometer protocol experiment" (protocol, τ, time step, the protocol's parameters) and
  "Summary data" (the summary, or one line per sweep step), ending with "Detailed rheometer
  protocol data";
- the table, one row per step: ``index``, ``t`` (s), ``strain``, ``strain_rate`` (1/s),
  ``stress_measured_at_surface``, ``shear_stress_internal_stress-tensor`` (Pa) — the first six
  columns of the oscillatory table, so a reader of those reads these — and ``N1`` (Pa, NaN where
  not sampled; steady) or ``sweep_position`` (sweeps: the step, each with its own clock);
- the metadata (sidecar; embedded in npz/parquet): the run's parameters and provenance as an
  oscillatory file's, plus ``protocol``, ``tau``, ``summary``, ``steps`` and the log-grid
  ``curves``.

The name is ``<ensemble><mu>_<protocol>_<value>_nr_<k><suffix>`` (value: the protocol's ``file_name``
parameter, :mod:`particleShear.protocols`: the rate, γ₀ or σ₀; none for sweeps) in ``root_folder``.
"""
__docformat__ = "numpy"
import io
import json
import os

import numpy as np

from ..protocols import PROTOCOLS
from ..simulation.formats import FORMAT_SUFFIXES, RHEOMETER_DETAILED, RHEOMETER_TITLE, write_columns
from ..simulation.output import TABLE_COLUMNS, reserve_numbered_path, sidecar_path
from ..simulation.provenance import json_safe

__all__ = ["record_columns", "protocol_header", "write_protocol_file"]


def record_columns(result):
    """``{column: 1-D array}`` of a protocol run's table (module docstring), ``index`` first.

    Parameters
    ----------
    result : SimulationResult

    Returns
    -------
    dict
    """
    s = result.series
    n = len(s["t"])
    cols = {"index": np.arange(n, dtype=np.int64)}
    for key, col in zip(("t", "strain", "strain_rate", "stress_surface", "stress_internal"), TABLE_COLUMNS[1:6]):
        cols[col] = np.asarray(s[key], dtype=float)
    if "N1" in s:
        cols["N1"] = np.asarray(s["N1"], dtype=float)
    if "sweep_position" in s:
        cols["sweep_position"] = np.asarray(s["sweep_position"], dtype=np.int64)
    return cols


def _line(name, value):
    return f"{name} = {value!r}"


def protocol_header(block1, result):
    """The text header of a protocol file: ``block1``, the protocol block, the summary.

    Parameters
    ----------
    block1 : str
        Block 1 of the oscillatory file (``write_information_on_simulation_to_file``).
    result : SimulationResult

    Returns
    -------
    str
        Ending with the line "Detailed rheometer protocol data".
    """
    p = result.parameters
    lines = [RHEOMETER_TITLE, "", "Protocol = " + result.protocol,
             f"Characteristic time constant = {result.tau!r}s", f"Time step = {result.dt!r}s"]
    lines += [_line(name, p.get(name)) for name in PROTOCOLS[result.protocol].header_parameters]
    lines += ["", "", "Output data", "Summary data"]
    if result.steps:
        lines += ["step " + str(st["position"]) + ": " + ", ".join(f"{k}={v!r}" for k, v in st.items()
                                                                   if k != "position") for st in result.steps]
    else:
        lines += [_line(k, v) for k, v in result.summary.items()]
    lines += ["", "", RHEOMETER_DETAILED]
    return block1 + "\n".join(lines)


def _json_curves(curves):
    return {name: [np.asarray(v, dtype=float).tolist() for v in c] for name, c in curves.items()}


def _stem(sim, result):
    """``root/<ensemble><mu>_<protocol>[_<what>_<value>]_nr_``."""
    base = os.path.basename(sim._file_stem())
    ensemble = base.split("_f_", 1)[0]
    name = ensemble + "_" + result.protocol
    if PROTOCOLS[result.protocol].file_name is not None:
        what, key = PROTOCOLS[result.protocol].file_name
        name += f"_{what}_{result.parameters[key]:g}"
    return os.path.join(str(sim.root_folder), name + "_nr_")


def write_protocol_file(sim, result):
    """Write ``result`` into a new numbered file beside the oscillatory ones; set its ``output_path``.

    A failure does not lose the result: the partial file and sidecar are removed, the exception
    is kept in ``result.write_error`` and ``output_path`` stays None.  An interruption (Ctrl-C,
    SIGTERM under the CLI) removes them too and is raised again: the file is complete or absent.

    Parameters
    ----------
    sim : Simulation_interlocking_rheology
        The run's simulation (block 1, ``root_folder``, provenance).
    result : SimulationResult
    """
    fmt = getattr(sim, "output_format", "text")
    out = None
    try:
        out = reserve_numbered_path(_stem(sim, result), FORMAT_SUFFIXES[fmt])
        block1 = io.StringIO()
        sim.write_information_on_simulation_to_file(block1)
        cols = record_columns(result)
        metadata = sim.run_metadata(fmt, out.path)
        metadata.update(protocol=result.protocol, tau=float(result.tau), dt=float(result.dt),
                        summary=json_safe(result.summary), steps=json_safe(result.steps),
                        curves=_json_curves(result.curves), n_rows=len(cols["index"]))
        write_columns(out.binary, fmt, protocol_header(block1.getvalue(), result), cols, metadata)
        metadata["size_bytes"], metadata["sha256"] = out.digest()
        out.add_companion("json", json.dumps(metadata, indent=1, allow_nan=True).encode("utf-8"),
                          sidecar_path(out.path))
        out.commit()
        result.output_path = out.path
    except BaseException as exc:  # noqa: BLE001 - complete or absent, Ctrl-C and SIGTERM included
        if out is not None:
            out.abort()
        if not isinstance(exc, Exception):
            raise                  # KeyboardInterrupt, SystemExit, a terminating signal: after the cleanup
        result.write_error = exc   # a failed write keeps the result (docs/output.md)
