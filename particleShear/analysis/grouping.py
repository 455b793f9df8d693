"""What a row of a sweep table measured: its protocol, and the amplitude and frequency of its step.

A sweep folder's ``results.csv`` holds one row per run of an oscillatory or a steady, relaxation or
creep run, and one row per *step* of a one-packing sweep (docs/protocols.md).  The parameter
columns of a step row are those of the call that made the whole sweep: ``theAmplitude`` of an
``amplitude_sweep`` row is its *first* amplitude, ``relative_frequency`` of a ``frequency_sweep``
row its first frequency; the step's own values are ``sweep_amplitude`` and
``sweep_relative_frequency``.  :func:`measured_row` rewrites a row so that its parameter columns
say what the row measured:

* ``protocol`` is the row's protocol; an empty cell (an oscillatory row of an older mixed
  table, or a table without protocols) reads as ``"oscillatory"``;
* ``theAmplitude`` of an ``amplitude_sweep`` row is its ``sweep_amplitude``, ``relative_frequency``
  of a ``frequency_sweep`` row its ``sweep_relative_frequency``;
* the protocol parameters the row's protocol does not read
  (their role in :mod:`particleShear.parameters`, the rule of the run identity) are
  empty, so that a default ``relative_rate`` never splits two oscillatory groups.

Grouping the rewritten rows by their parameter columns then keeps apart what differs — the
protocol and the parameters it reads split groups — and pools only seeds.
"""
__docformat__ = "numpy"
from ..parameters import names, protocol_parameters
from ..protocols import PROTOCOLS

__all__ = ["MODULI_PROTOCOLS", "SUMMARY_PROTOCOLS", "row_protocol", "measured_row", "short_value"]

#: protocols whose rows hold G′ and G″ (one amplitude and frequency each)
MODULI_PROTOCOLS = ("oscillatory",) + tuple(n for n, p in PROTOCOLS.items() if p.segmented)
#: protocols whose rows hold a summary of one run (docs/protocols.md): those of the recording loop
SUMMARY_PROTOCOLS = tuple(n for n, p in PROTOCOLS.items() if p.recorded)
#: the column of a step row that holds the step's value of a parameter column
_STEP_VALUE = {n: p.step_value for n, p in PROTOCOLS.items() if p.step_value is not None}


def row_protocol(row):
    """The protocol of a table row; an empty or missing ``protocol`` cell is ``"oscillatory"``.

    Parameters
    ----------
    row : dict
        A row of ``results.csv`` (values as text or typed).

    Returns
    -------
    str
    """
    text = row.get("protocol")
    text = "" if text is None else str(text).strip()
    return text or "oscillatory"


def measured_row(row):
    """A copy of ``row`` whose parameter columns are those of what it measured (module docstring).

    Parameters
    ----------
    row : dict
        A row of ``results.csv``.

    Returns
    -------
    dict
        The copy: ``protocol`` filled in (when the table has the column or the row is not
        oscillatory), the step's amplitude or frequency in ``theAmplitude`` /
        ``relative_frequency``, the protocol parameters its protocol does not read empty.
    """
    proto = row_protocol(row)
    q = dict(row)
    if "protocol" in q or proto != "oscillatory":
        q["protocol"] = proto
    if proto in _STEP_VALUE:
        column, step = _STEP_VALUE[proto]
        q[column] = row.get(step, "")
    reads = protocol_parameters(proto)
    for name in names("protocol"):
        if name != "protocol" and name in q and name not in reads:
            q[name] = ""
    return q


def short_value(text, limit=60):
    """``text`` for a label or message: at most ``limit`` characters, a longer one cut with "…".

    Parameters
    ----------
    text : object
        The value (a list of a one-packing sweep can have 10,000 entries).
    limit : int, optional
        Most characters shown (default 60).

    Returns
    -------
    str
    """
    s = str(text)
    return s if len(s) <= limit else s[:limit - 1] + "…"
