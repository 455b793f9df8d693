"""Signals of the commands: SIGTERM turned into an exception, and whether a process of this host lives.

A scheduler's walltime or ``kill`` sends SIGTERM, whose default action ends the process at once:
temporary files and half-published sets would stay behind.  Each command (a run, a sweep,
``analyse``) therefore turns SIGTERM into an exception of its own within its work
(:func:`sigterm_raises`), so the cleanup that Ctrl-C runs also runs for it.
"""
__docformat__ = "numpy"
import contextlib
import os
import re
import signal
import socket

__all__ = ["sigterm_raises", "signals_held", "process_gone"]


@contextlib.contextmanager
def sigterm_raises(exc_type):
    """Within the block SIGTERM raises ``exc_type("signal 15")``; outside the main thread it is left alone.

    Parameters
    ----------
    exc_type : type
        The exception raised (best a ``BaseException`` that no ``except Exception`` swallows).
    """
    def stop(signum, frame):
        raise exc_type(f"signal {signum}")

    try:
        previous = signal.signal(signal.SIGTERM, stop)
    except ValueError:   # not the main thread
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


@contextlib.contextmanager
def signals_held():
    """Within the block SIGINT and SIGTERM are recorded, not acted on (main thread only); yields their list.

    For a few renames that must all happen (``analyse`` publishing its set): the caller acts on
    the signals afterwards.

    Yields
    ------
    list of int
        The signals that arrived, in order.
    """
    got = []

    def hold(signum, frame):
        got.append(signum)

    previous = {}
    try:
        for s in (signal.SIGINT, signal.SIGTERM):
            previous[s] = signal.signal(s, hold)
    except ValueError:       # not the main thread: signals go to the main thread anyway
        pass
    try:
        yield got
    finally:
        for s, h in previous.items():
            signal.signal(s, h)


def process_gone(pid):
    """True when no process ``pid`` exists on this host (one that may not be signalled counts as alive).

    Parameters
    ----------
    pid : int or str
        The process id (as written in a temporary name).

    Returns
    -------
    bool
    """
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return True
    except (PermissionError, OverflowError, ValueError):
        return False
    return False


def dead_leftovers(folder, stem=None):
    """The names in ``folder`` of temporary files or folders that dead processes of this host left.

    A temporary name is ``<stem>.<host>-<pid>-<8 hex digits>.part``, ``stem`` hidden (a leading
    "."): the package's ``.part`` files and staging folders.  It is left over when its host is
    this one and no process ``pid`` exists here (:func:`process_gone`; a live process, or another
    user's, keeps it).

    Parameters
    ----------
    folder : str
        The folder (an unreadable one has none).
    stem : str, optional
        The one stem to look for (``".analysis"``); None: any hidden stem (``".results.csv"``, …).

    Returns
    -------
    list of str
        The names, not removed: the caller removes them (a file or a folder).
    """
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    pattern = re.compile(r"^(?P<stem>\..*)\." + re.escape(socket.gethostname()) + r"-(?P<pid>\d+)-[0-9a-f]{8}\.part$")
    out = []
    for name in names:
        m = pattern.match(name)
        if m and (stem is None or m.group("stem") == stem) and process_gone(m.group("pid")):
            out.append(name)
    return out
