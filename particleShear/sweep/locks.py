"""Locks of a sweep folder: the table lock and the scratch folders of the processes that run into it.

Both use POSIX record locks (``fcntl.lockf``), which belong to the *process* that took them: a
worker forked by the sweep does not inherit them, and the operating system releases them when
the process dies, however it dies (SIGKILL, crash, power loss of a node).  So a lock that can be
taken belongs to nobody alive, and a sweep killed at any moment never blocks the next one:

* ``DIR/results.csv.lock`` — one driving process writes a table at a time (:func:`folder_lock`);
  the file holds ``pid@host`` of the holder for the message of a refused second sweep and is
  removed when the lock is released;
* ``DIR/runs/<owner>/`` with ``DIR/runs/<owner>.lock`` — the scratch folder of one driving process
  (:class:`ScratchOwner`); a run writes into ``DIR/runs/<owner>/<run id>/`` and its worker moves
  the finished files into ``DIR``.  Two processes running into one folder (a plain sweep and a
  job-array task, say) therefore never touch each other's scratch; the folders of dead owners are
  removed by the next process that starts (:func:`remove_dead_scratch`; an owner on another host
  only once its folder has been idle for :data:`OTHER_HOST_IDLE_S`, since some cluster file
  systems keep record locks local to a node).

POSIX record locks are shared by every thread of a process, so a second lock of the same file
in the same process is refused by an in-process registry as well.
"""
__docformat__ = "numpy"
import contextlib
import os
import secrets
import shutil
import socket
import threading
import time

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no locks, nothing proved stale
    fcntl = None

__all__ = ["FolderBusyError", "folder_lock", "ScratchOwner", "remove_dead_scratch", "LOCK_WAIT_S"]

#: seconds a sweep waits for the table lock before refusing (another live sweep writes the table)
LOCK_WAIT_S = 2.0
_held = set()
_held_guard = threading.Lock()


class FolderBusyError(RuntimeError):
    """Another live process holds the lock of a sweep table (the CLI exits with status 3)."""


def _try_lock(path):
    """Open and lock ``path`` (created when absent); the descriptor, or None when another process holds it.

    After the lock is taken the name must still be the locked file: a holder that released and
    removed it meanwhile leaves us a lock on a deleted file, so we try again.
    """
    for _ in range(100):   # each retry follows a removal by a releasing holder: bounded
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            return None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(path))
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)
    return None  # pragma: no cover - 100 removals in a row


def _holder(path):
    try:
        with open(path, encoding="utf-8") as fh:
            return fh.read(200).strip()
    except OSError:
        return ""


def _release(fd, path):
    with contextlib.suppress(OSError):
        os.remove(path)          # while locked: the next holder finds a new file (see _try_lock)
    os.close(fd)


@contextlib.contextmanager
def folder_lock(path, wait_s=None):
    """Exclusive lock on ``path + '.lock'`` for the block; refused when another live process holds it.

    Parameters
    ----------
    path : str
        The table (``DIR/results.csv`` or a job-array task table); the lock file is beside it.
    wait_s : float, optional
        Seconds to wait for a holder to finish (default :data:`LOCK_WAIT_S`).

    Raises
    ------
    FolderBusyError
        When another live process (or another sweep of this process) holds the lock; the message
        names the holder's ``pid@host``.
    """
    lock_path = path + ".lock"
    key = os.path.abspath(lock_path)
    with _held_guard:
        if key in _held:
            raise FolderBusyError(f"another sweep of this process is writing {path!r}; wait for it or use "
                                  "another --out DIR")
        _held.add(key)
    fd = None
    try:
        if fcntl is not None:
            deadline = time.monotonic() + (LOCK_WAIT_S if wait_s is None else wait_s)
            while True:
                fd = _try_lock(lock_path)
                if fd is not None:
                    break
                if time.monotonic() >= deadline:
                    who = _holder(lock_path)
                    raise FolderBusyError(f"another sweep{' (' + who + ')' if who else ''} is writing {path!r}; "
                                          "wait for it or use another --out DIR")
                time.sleep(0.05)
            os.ftruncate(fd, 0)
            os.write(fd, f"pid {os.getpid()}@{socket.gethostname()}\n".encode())
        yield
    finally:
        if fd is not None:
            _release(fd, lock_path)
        with _held_guard:
            _held.discard(key)


#: the scratch-owner locks this process holds (POSIX locks do not exclude the process itself)
_owned = set()
#: an owner on another host is taken for dead only when its lock is free *and* its folder has not
#: changed for this long (s): some cluster file systems keep record locks local to a node
OTHER_HOST_IDLE_S = 3600.0


def _is_dead_owner(lock_path):
    """True when nobody holds ``lock_path`` (its owner died); never for an owner of this process."""
    if fcntl is None or os.path.abspath(lock_path) in _owned:
        return False
    owner_dir = lock_path[:-len(".lock")]
    if not os.path.basename(owner_dir).startswith(socket.gethostname() + "-"):
        try:
            newest = max([os.stat(owner_dir).st_mtime] + [e.stat().st_mtime for e in os.scandir(owner_dir)])
        except OSError:
            newest = 0.0
        if time.time() - newest < OTHER_HOST_IDLE_S:
            return False
    try:
        fd = os.open(lock_path, os.O_RDWR)
    except OSError:
        return not os.path.exists(lock_path)
    try:
        fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return False
    os.close(fd)
    return True


def remove_dead_scratch(scratch_root):
    """Remove the scratch folders of dead owners under ``DIR/runs``; return the names removed.

    An owner folder ``<owner>/`` is dead when its ``<owner>.lock`` can be locked, or when it has no
    lock file at all (a crash between the two, or a folder of another layout); folders of live
    owners (lock held) are left alone, so this is safe while other sweeps run into the folder.

    Parameters
    ----------
    scratch_root : str
        ``DIR/runs`` (nothing happens when it does not exist).

    Returns
    -------
    list of str
    """
    try:
        names = os.listdir(scratch_root)
    except OSError:
        return []
    removed = []
    live = set()
    for n in names:
        if n.endswith(".lock"):
            owner = n[:-len(".lock")]
            if _is_dead_owner(os.path.join(scratch_root, n)):
                shutil.rmtree(os.path.join(scratch_root, owner), ignore_errors=True)
                with contextlib.suppress(OSError):
                    os.remove(os.path.join(scratch_root, n))
                removed.append(owner)
            else:
                live.add(owner)
    for n in names:
        p = os.path.join(scratch_root, n)
        if not n.endswith(".lock") and n not in live and n not in removed and os.path.isdir(p) \
                and fcntl is not None and not os.path.exists(p + ".lock") and _idle(p, 60.0):
            shutil.rmtree(p, ignore_errors=True)   # no lock at all (a crash between the two): once idle
            removed.append(n)
    return removed


def _idle(path, seconds):
    try:
        return time.time() - os.stat(path).st_mtime > seconds
    except OSError:
        return False


class ScratchOwner:
    """The scratch folder ``DIR/runs/<owner>/`` of one driving process, locked while it lives.

    Parameters
    ----------
    out_dir : str
        The sweep folder.

    Attributes
    ----------
    path : str
        ``DIR/runs/<host>-<pid>-<random>``: runs of this process write into ``path/<run id>/``.
    """

    def __init__(self, out_dir):
        root = os.path.join(out_dir, "runs")
        os.makedirs(root, exist_ok=True)
        remove_dead_scratch(root)
        name = f"{socket.gethostname()}-{os.getpid()}-{secrets.token_hex(4)}"
        self.path = os.path.join(root, name)
        self._lock_path = self.path + ".lock"
        self._fd = None
        if fcntl is not None:
            self._fd = _try_lock(self._lock_path)
            _owned.add(os.path.abspath(self._lock_path))
        os.makedirs(self.path)

    def close(self):
        """Remove the scratch folder (and ``DIR/runs`` when empty) and release the lock."""
        shutil.rmtree(self.path, ignore_errors=True)
        if self._fd is not None:
            _release(self._fd, self._lock_path)
            self._fd = None
        _owned.discard(os.path.abspath(self._lock_path))
        with contextlib.suppress(OSError):
            os.rmdir(os.path.dirname(self.path))   # only when empty
