"""Console messages through :mod:`logging`.

Every module of the package logs on its own logger (``logging.getLogger(__name__)``, children of the
package logger ``"particleShear"``, which carries a :class:`logging.NullHandler`).  Nothing reaches the
console unless the application configures logging, or a call asks for it: ``verbose=True`` of
:func:`particleShear.doParticleShearSimulation` wraps the run in :func:`console_messages`, which shows
the INFO messages of the calling thread, text only (the reference's console text), on ``sys.stdout``
for the duration of the call.  Warnings (a display that is missing, forces that do not balance) go
through :mod:`warnings`.

The per-run messages are emitted only by calls with ``verbose=True`` (as the reference printed them
only then).  To collect them in your own handler as well, configure the ``"particleShear"`` logger at
INFO with that handler; the console still shows them during a ``verbose=True`` call.
"""
__docformat__ = "numpy"
import contextlib
import logging
import sys
import threading

__all__ = ["console_messages", "PACKAGE_LOGGER"]

#: name of the package logger; every module logs on a child of it
PACKAGE_LOGGER = "particleShear"

_lock = threading.Lock()
_lowered = [0, None]   # [number of active console_messages that lowered the level, saved (level, propagate)]


class _ThreadFilter(logging.Filter):
    """Pass only the records of one thread (parallel runs in threads do not mix their text)."""

    def __init__(self, ident):
        super().__init__()
        self.ident = ident

    def filter(self, record):
        return record.thread == self.ident


@contextlib.contextmanager
def console_messages(enabled=True, stream=None, level=logging.INFO):
    """Show the package's log messages of this thread on a console stream while the block runs.

    Parameters
    ----------
    enabled : bool, optional
        False: do nothing (so that ``with console_messages(verbose):`` reads naturally). Default True.
    stream : file-like, optional
        Where the text goes; default ``sys.stdout`` as it is when the block starts (so that a
        redirected or captured ``sys.stdout`` receives it).
    level : int, optional
        Lowest level shown, default ``logging.INFO``.

    Notes
    -----
    The handler writes ``%(message)s`` only, so the text is what the reference printed.  When
    the package logger would drop ``level`` (the default: nothing configured, effective level
    WARNING), its level is lowered for the block and its propagation switched off, so that the
    messages appear once (not a second time through a root handler that was configured for
    warnings only); both are restored when the last such block ends.
    """
    if not enabled:
        yield
        return
    logger = logging.getLogger(PACKAGE_LOGGER)
    handler = logging.StreamHandler(sys.stdout if stream is None else stream)
    handler.setFormatter(logging.Formatter("%(message)s"))
    handler.setLevel(level)
    handler.addFilter(_ThreadFilter(threading.get_ident()))
    lowered = False
    with _lock:
        if _lowered[0]:
            _lowered[0] += 1
            lowered = True
        elif logger.getEffectiveLevel() > level:
            _lowered[0], _lowered[1] = 1, (logger.level, logger.propagate)
            logger.setLevel(level)
            logger.propagate = False
            lowered = True
        logger.addHandler(handler)
    try:
        yield
    finally:
        with _lock:
            logger.removeHandler(handler)
            if lowered:
                _lowered[0] -= 1
                if _lowered[0] == 0:
                    logger.setLevel(_lowered[1][0])
                    logger.propagate = _lowered[1][1]
        handler.flush()
