"""The one cache mechanism of the canvas classes: named values kept under an explicit key.

The key lists everything a value is computed from (version counters, parameters), so a kept value
is what recomputing it gives.  Only values worth ≥ ~10 % of a step are kept (docs/engine.md, "Caches").
"""
__docformat__ = "numpy"

__all__ = ["Memo"]


class Memo:
    """Named values, each kept under an explicit key until the key changes or :meth:`drop`.

    Examples
    --------
    >>> m = Memo()
    >>> m.get("sq", (3,), lambda: 3 * 3), m.get("sq", (3,), lambda: 0), m.get("sq", (4,), lambda: 16)
    (9, 9, 16)
    """

    __slots__ = ("_values",)

    def __init__(self):
        self._values = {}

    def get(self, name, key, compute):
        """Return the value of ``name`` kept for an equal ``key``, else ``compute()`` (then kept).

        Parameters
        ----------
        name : str
        key : tuple
            Everything the value depends on, compared with ``==`` (numbers, strings, version
            counters, objects compared by identity; never arrays).
        compute : callable
            Called without arguments when the value must be (re)computed.
        """
        entry = self._values.get(name)
        if entry is not None and entry[0] == key:
            return entry[1]
        value = compute()
        self._values[name] = (key, value)
        return value

    def drop(self, name):
        """Forget the value of ``name``; return it (None if none was kept).

        Parameters
        ----------
        name : str
        """
        return self._values.pop(name, (None, None))[1]

    def peek(self, name):
        """Return the value kept under ``name`` (whatever its key), or None: for inspection only.

        Parameters
        ----------
        name : str
        """
        return self._values.get(name, (None, None))[1]
