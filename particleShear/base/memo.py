"""The one cache mechanism of the canvas classes: named values kept under an explicit key.

A canvas keeps a value between calls only through its :class:`Memo`: ``memo.get(name, key, compute)``
returns the value stored under ``name`` while the stored key equals ``key`` and otherwise calls
``compute()`` and stores its result under the new key.  The key lists everything the value is
computed from (version counters of the canvas's state, parameters, the key of a value it derives
from), so a cached value is by construction what recomputing it gives; :meth:`Memo.invalidate`
drops every value at once, for the changes no counter records (relations edited in place through
the per-sphere API, a constitution that replaces the pair table).

Only values that buy at least ~10 % of a step are kept this way (docs/design.md, "Caching of the
classes", has the measured tables); everything else is recomputed where it is used.
"""
__docformat__ = "numpy"

__all__ = ["Memo"]


class Memo:
    """Named values, each kept under an explicit key until the key changes or :meth:`invalidate`.

    Examples
    --------
    >>> m = Memo()
    >>> m.get("sq", (3,), lambda: 3 * 3)
    9
    >>> m.get("sq", (3,), lambda: 0)     # same key: the kept value, compute is not called
    9
    >>> m.get("sq", (4,), lambda: 4 * 4)  # new key: recomputed
    16
    """

    __slots__ = ("_values",)

    def __init__(self):
        self._values = {}

    def get(self, name, key, compute):
        """The value of ``name`` for ``key``: the kept one if it was computed for an equal key, else ``compute()``.

        Parameters
        ----------
        name : str
            Which value (one entry per name).
        key : tuple
            Everything the value depends on, compared with ``==`` (numbers, strings, bytes, tuples of them:
            never arrays, whose ``==`` is elementwise).
        compute : callable
            Called without arguments when the value must be (re)computed; its result is kept under ``key``.

        Returns
        -------
        object
            The value.
        """
        entry = self._values.get(name)
        if entry is not None and entry[0] == key:
            return entry[1]
        value = compute()
        self._values[name] = (key, value)
        return value

    def invalidate(self):
        """Drop every value: the next :meth:`get` of each name recomputes it."""
        self._values.clear()

    def peek(self, name):
        """The value kept under ``name`` (whatever its key), or None: for inspection, never for computing.

        Parameters
        ----------
        name : str
            Which value.

        Returns
        -------
        object or None
            The value, or None when none is kept.
        """
        entry = self._values.get(name)
        return None if entry is None else entry[1]
