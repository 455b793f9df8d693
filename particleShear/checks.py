"""Checks of single parameter values, written once for every layer.

Each check raises ``TypeError`` for a value that is not a real number (a bool is not one) and
``ValueError`` for one out of range, with one message form: ``name=value is out of range: allowed
…`` (a huge integer abbreviated: :func:`show_value`).  Integers of any size are compared exactly,
never converted to float first.  The run's own limits (the tables of
:mod:`particleShear.run.validation`) are applied there on top of these checks.
"""
__docformat__ = "numpy"

import math
import numbers
import sys

import numpy as np

__all__ = ["SHOW_DIGITS", "MESSAGE_VALUE_LIMIT", "cut_text", "show_value", "real_type", "as_float", "finite", "in_range", "positive", "non_negative",
           "integer", "range_text"]

#: integers with more digits than this are abbreviated in messages (:func:`show_value`)
SHOW_DIGITS = 20
_MAX = sys.float_info.max

#: the most characters of one value that a message shows (:func:`cut_text`)
MESSAGE_VALUE_LIMIT = 200


def cut_text(text, limit=MESSAGE_VALUE_LIMIT):
    """``text`` if it has at most ``limit`` characters, else its head, how much is left out, and its tail.

    Parameters
    ----------
    text : str
        A value as a message writes it.
    limit : int, default :data:`MESSAGE_VALUE_LIMIT`
        The most characters shown (the count of those left out comes on top).

    Returns
    -------
    str
        ``text``, or its first ``limit - 50`` characters, ``…(N characters)…`` and its last 20.
    """
    if len(text) <= limit:
        return text
    head, tail = text[:limit - 50], text[-20:]
    return f"{head}…({len(text) - len(head) - len(tail):,} characters)…{tail}"


def show_value(v):
    """``repr(v)``, with an integer of more than :data:`SHOW_DIGITS` digits abbreviated to one short word,
    and any value longer than :data:`MESSAGE_VALUE_LIMIT` characters cut (:func:`cut_text`).

    A power of ten reads ``10**400``, any other such integer ``123456…(401 digits)`` (no conversion
    to text of the whole number, so integers beyond Python's digit limit are shown too); used for
    every value a validation message quotes, so a message stays one readable line.

    Parameters
    ----------
    v : object
        The value to show.

    Returns
    -------
    str
    """
    if isinstance(v, numbers.Integral) and not isinstance(v, (bool, np.bool_)):
        i = int(v)
        a = abs(i)
        if a >= 10 ** SHOW_DIGITS:
            n = int(math.log10(a)) + 1          # number of digits, corrected where log10 rounds
            if 10 ** (n - 1) > a:
                n -= 1
            elif 10 ** n <= a:
                n += 1
            sign = "-" if i < 0 else ""
            if a == 10 ** (n - 1):
                return f"{sign}10**{n - 1}"
            return f"{sign}{a // 10 ** (n - 6)}…({n} digits)"
    if isinstance(v, str) and len(v) > 2 * MESSAGE_VALUE_LIMIT:   # no repr of a 50 MB string
        head, tail = v[:MESSAGE_VALUE_LIMIT - 50], v[-20:]
        return f"{repr(head)[:-1]}…({len(v) - len(head) - len(tail):,} characters)…{repr(tail)[1:]}"
    return cut_text(repr(v))


def _scalar(v):
    """A 0-d array's value (NumPy's reductions return them), else ``v``."""
    return v.item() if isinstance(v, np.ndarray) and v.ndim == 0 else v


def real_type(name, v):
    """Raise TypeError unless ``v`` is a real number (not a bool).

    Parameters
    ----------
    name : str
        The parameter, named in the message.
    v : object
    """
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real):
        raise TypeError(f"{name}={show_value(v)} is invalid: allowed a real number")


def as_float(v):
    """``float(v)``, or None when ``v`` (an integer or a rational beyond ~1.8e308) has no finite float.

    Parameters
    ----------
    v : numbers.Real
    """
    try:
        return float(v)
    except OverflowError:
        return None


def finite(name, v):
    """Return ``float(v)``; raise unless ``v`` is a finite real number.

    Parameters
    ----------
    name : str
        The parameter, named in the message.
    v : object
        A real number, or a 0-d array of one.
    """
    if isinstance(v, float) and v - v == 0.0:      # the common cases (float, numpy.float64) at once
        return float(v)
    if type(v) is int and -_MAX <= v <= _MAX:      # (int/float comparisons are exact)
        return float(v)
    v = _scalar(v)
    real_type(name, v)
    x = as_float(v)
    if x is None or not math.isfinite(x):
        raise ValueError(f"{name}={show_value(v)} is out of range: allowed a finite number")
    return x


def in_range(name, v, lo=None, hi=None, lo_open=False, hi_open=False):
    """Return ``float(v)``; raise unless ``v`` is a finite real number within the limits.

    The limits are compared exactly before any conversion (a huge integer included).

    Parameters
    ----------
    name : str
        The parameter, named in the message.
    v : object
    lo, hi : float or None
        Lower and upper limit (None: none).
    lo_open, hi_open : bool
        The limit itself is excluded.
    """
    v = _scalar(v)
    real_type(name, v)
    if not isinstance(v, numbers.Integral):
        x = as_float(v)
        if x is None or not math.isfinite(x):
            raise ValueError(f"{name}={show_value(v)} is out of range: allowed a finite number")
    if as_float(v) is None:       # an integer without a finite float: beyond every unbounded side
        if v > 0 and hi is None:
            hi = _MAX
        elif v < 0 and lo is None:
            lo = -_MAX
    w = v if isinstance(v, numbers.Integral) else float(v)   # int/float comparisons are exact in Python
    bad = ((lo is not None and (w <= lo if lo_open else w < lo))
           or (hi is not None and (w >= hi if hi_open else w > hi)))
    if bad:
        raise ValueError(f"{name}={show_value(v)} is out of range: allowed {range_text(lo, hi, lo_open, hi_open)}")
    return float(v)


def range_text(lo=None, hi=None, lo_open=False, hi_open=False, integers=False):
    """The allowed range as every range message states it (the one wording of a range).

    Parameters
    ----------
    lo, hi : float or int or None
        Lower and upper limit (None: none), in the parameter's own unit.
    lo_open, hi_open : bool
        The limit itself is excluded.
    integers : bool
        Only integers are allowed (limits written with thousands separators).

    Returns
    -------
    str
        ``"0 < value <= 100"``, ``"integers 11 <= value <= 1,000,000"``, ``"0 <= value"``.
    """
    def num(x):
        return f"{x:,}" if integers else f"{x:g}"
    left = "" if lo is None else f"{num(lo)} {'<' if lo_open else '<='} "
    right = "" if hi is None else f" {'<' if hi_open else '<='} {num(hi)}"
    return f"{'integers ' if integers else ''}{left}value{right}"


def positive(name, v):
    """Return ``float(v)``; raise unless ``v`` is a finite real number > 0.

    Parameters
    ----------
    name : str
    v : object
    """
    if isinstance(v, (float, int)) and not isinstance(v, bool) and 0 < v <= _MAX:
        return float(v)
    return in_range(name, v, lo=0, lo_open=True)


def non_negative(name, v):
    """Return ``float(v)``; raise unless ``v`` is a finite real number ≥ 0.

    Parameters
    ----------
    name : str
    v : object
    """
    if isinstance(v, (float, int)) and not isinstance(v, bool) and 0 <= v <= _MAX:
        return float(v)
    return in_range(name, v, lo=0)


def integer(name, v, lo, hi=None, why=""):
    """Return ``int(v)``; raise unless ``v`` is an integral real number in ``[lo, hi]``.

    Parameters
    ----------
    name : str
    v : object
        An int, or a float with an integral value.
    lo : int
    hi : int or None
    why : str
        Appended to the message after the range (what sets a limit that depends on other
        parameters, e.g. ``" for packing_fraction=1.5 …"``).
    """
    v = _scalar(v)
    real_type(name, v)
    if isinstance(v, numbers.Integral):
        ok = lo <= v and (hi is None or v <= hi)
    else:
        x = finite(name, v)
        ok = x.is_integer() and x >= lo and (hi is None or x <= hi)
    if not ok:
        raise ValueError(f"{name}={show_value(v)} is out of range: allowed {range_text(lo, hi, integers=True)}{why}")
    return int(v)
