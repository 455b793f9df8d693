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

A sweep removes only what it made: an owner folder carries the marker file
:data:`SCRATCH_MARKER` naming the owner (and its lock file the same text), written by the sweep
that made it.  Anything else under ``DIR/runs`` — a user's folder or file, a folder of an older
layout, a symbolic link — is never removed (:func:`foreign_entries` lists it, the sweep names it),
and no link is followed: ``DIR/runs`` itself and the files a sweep writes in ``DIR`` must not be
symbolic links (:func:`refuse_links`).

POSIX record locks are shared by every thread of a process, so a second lock of the same file
in the same process is refused by an in-process registry as well.
"""
__docformat__ = "numpy"
import contextlib
import json
import os
import secrets
import shutil
import socket
import stat
import threading
import time

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no locks, nothing proved stale
    fcntl = None

__all__ = ["FolderBusyError", "folder_lock", "ScratchOwner", "remove_dead_scratch", "foreign_entries", "refuse_links",
           "LOCK_WAIT_S", "SCRATCH_MARKER"]

#: seconds a sweep waits for the table lock before refusing (another live sweep writes the table)
LOCK_WAIT_S = 2.0
_held = set()
_held_guard = threading.Lock()
#: the marker file of a scratch folder made by a sweep (``DIR/runs/<owner>/`` + this name)
SCRATCH_MARKER = ".particleShear-scratch"
_MARKER_FORMAT = "particleShear sweep scratch 1"
#: ``os.open`` flag that refuses a symbolic link as the last component (0 where the OS has none)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)


class FolderBusyError(RuntimeError):
    """Another live process holds the lock of a sweep table (the CLI exits with status 3)."""


def _try_lock(path):
    """Open and lock ``path`` (created when absent); the descriptor, or None when another process holds it.

    After the lock is taken the name must still be the locked file: a holder that released and
    removed it meanwhile leaves us a lock on a deleted file, so we try again.
    """
    for _ in range(100):   # each retry follows a removal by a releasing holder: bounded
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | _NOFOLLOW, 0o644)   # never through a link
        except OSError as exc:
            if os.path.islink(path):
                raise ValueError(_link_message(path)) from None
            raise exc
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


def _link_message(path):
    try:
        target = os.readlink(path)
    except OSError:
        target = "?"
    return (f"{path} is a symbolic link (to {target}): a sweep never writes or deletes through a link; "
            "remove the link, or use another --out DIR")


def refuse_links(paths):
    """Refuse a symbolic link at any of ``paths`` (files and folders a sweep writes, replaces or cleans).

    Parameters
    ----------
    paths : iterable of str
        Paths inside the sweep folder (absent ones are fine).

    Raises
    ------
    ValueError
        One line naming the first link and its target; also when ``DIR/runs`` exists and is not a folder.
    """
    for path in paths:
        if os.path.islink(path):
            raise ValueError(_link_message(path))
        if os.path.basename(path) == "runs" and os.path.lexists(path) and not os.path.isdir(path):
            raise ValueError(f"{path} is not a folder: a sweep keeps its scratch folders there; move it away, or "
                             "use another --out DIR")


def _marker_text(name):
    """What the marker of the owner folder ``name`` (and its lock file) holds."""
    return json.dumps({"format": _MARKER_FORMAT, "owner": name}) + "\n"


def _read_small(path):
    """The first 4 kB of the regular file ``path`` (never through a link), or None."""
    try:
        fd = os.open(path, os.O_RDONLY | _NOFOLLOW)
    except OSError:
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        return os.read(fd, 4096).decode("utf-8", errors="replace")
    finally:
        os.close(fd)


def _marked(text, name):
    try:
        doc = json.loads(text or "")
    except ValueError:
        return False
    return isinstance(doc, dict) and doc.get("format") == _MARKER_FORMAT and doc.get("owner") == name


def _is_scratch_dir(root, name):
    """True when ``root/name`` is a folder (not a link) whose marker names it: a sweep made it."""
    path = os.path.join(root, name)
    try:
        if not stat.S_ISDIR(os.lstat(path).st_mode):
            return False
    except OSError:
        return False
    return _marked(_read_small(os.path.join(path, SCRATCH_MARKER)), name)


def _is_scratch_lock(root, name):
    """True when ``root/name`` (``<owner>.lock``) is a regular file a sweep wrote for ``<owner>``."""
    return name.endswith(".lock") and _marked(_read_small(os.path.join(root, name)), name[:-len(".lock")])


def _is_empty_dir(path):
    try:
        return stat.S_ISDIR(os.lstat(path).st_mode) and not os.listdir(path)
    except OSError:
        return False


def _is_dead_owner(lock_path):
    """True when nobody holds ``lock_path`` (its owner died); never for an owner of this process."""
    if fcntl is None or os.path.abspath(lock_path) in _owned:
        return False
    owner_dir = lock_path[:-len(".lock")]
    if not os.path.basename(owner_dir).startswith(socket.gethostname() + "-"):
        try:
            newest = max([os.lstat(owner_dir).st_mtime] + [e.stat(follow_symlinks=False).st_mtime
                                                           for e in os.scandir(owner_dir)])
        except OSError:
            newest = 0.0
        if time.time() - newest < OTHER_HOST_IDLE_S:
            return False
    try:
        fd = os.open(lock_path, os.O_RDWR | _NOFOLLOW)
    except OSError:
        return not os.path.lexists(lock_path)
    try:
        fcntl.lockf(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(fd)
        return False
    os.close(fd)
    return True


def foreign_entries(scratch_root):
    """The names under ``DIR/runs`` that no sweep made: never removed, named by the sweep.

    Parameters
    ----------
    scratch_root : str
        ``DIR/runs``.

    Returns
    -------
    list of str
        Sorted; every entry that is neither a marked owner folder (:data:`SCRATCH_MARKER`) nor
        the lock file a sweep wrote for one (an empty folder of an owner whose lock is a sweep's
        counts as the sweep's: it died before writing the marker).
    """
    try:
        names = os.listdir(scratch_root)
    except OSError:
        return []
    out = []
    for n in names:
        if _is_scratch_dir(scratch_root, n) or _is_scratch_lock(scratch_root, n):
            continue
        if _is_scratch_lock(scratch_root, n + ".lock") and _is_empty_dir(os.path.join(scratch_root, n)):
            continue
        out.append(n)
    return sorted(out)


def remove_dead_scratch(scratch_root):
    """Remove the scratch folders of dead owners under ``DIR/runs``; return the names removed.

    Only what a sweep made is removed: an owner folder whose marker (:data:`SCRATCH_MARKER`)
    names it, and the lock file a sweep wrote for it.  An owner is dead when its ``<owner>.lock``
    can be locked; a marked folder without a lock file (its lock removed by hand) once it has been
    idle for 60 s.  Folders of live owners (lock held) are left alone, so this is safe while other
    sweeps run into the folder; anything else (:func:`foreign_entries`) is never touched, and no
    symbolic link is followed.

    Parameters
    ----------
    scratch_root : str
        ``DIR/runs`` (nothing happens when it does not exist or is a symbolic link).

    Returns
    -------
    list of str
    """
    if os.path.islink(scratch_root):
        return []
    try:
        names = os.listdir(scratch_root)
    except OSError:
        return []
    removed = []
    live = set()
    for n in names:
        if not _is_scratch_lock(scratch_root, n):
            continue
        owner = n[:-len(".lock")]
        folder = os.path.join(scratch_root, owner)
        if not _is_dead_owner(os.path.join(scratch_root, n)):
            live.add(owner)
            continue
        if _is_scratch_dir(scratch_root, owner):
            shutil.rmtree(folder, ignore_errors=True)
        elif _is_empty_dir(folder):
            with contextlib.suppress(OSError):
                os.rmdir(folder)            # died before writing its marker
        elif os.path.lexists(folder):
            continue                          # not the sweep's: left alone, with its lock
        with contextlib.suppress(OSError):
            os.remove(os.path.join(scratch_root, n))
        removed.append(owner)
    for n in names:
        p = os.path.join(scratch_root, n)
        if n not in live and n not in removed and fcntl is not None and not os.path.lexists(p + ".lock") \
                and _is_scratch_dir(scratch_root, n) and _idle(p, 60.0):
            shutil.rmtree(p, ignore_errors=True)   # a marked folder whose lock is gone: once idle
            removed.append(n)
    return removed


def _idle(path, seconds):
    try:
        return time.time() - os.lstat(path).st_mtime > seconds
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
        refuse_links([root])
        os.makedirs(root, exist_ok=True)
        remove_dead_scratch(root)
        name = f"{socket.gethostname()}-{os.getpid()}-{secrets.token_hex(4)}"
        self.path = os.path.join(root, name)
        self._lock_path = self.path + ".lock"
        self._fd = None
        marker = _marker_text(name).encode("utf-8")
        if fcntl is not None:
            self._fd = _try_lock(self._lock_path)
            _owned.add(os.path.abspath(self._lock_path))
            os.write(self._fd, marker)        # the lock file is the sweep's: see remove_dead_scratch
        else:  # pragma: no cover - Windows
            with open(self._lock_path, "wb") as fh:
                fh.write(marker)
        os.mkdir(self.path)
        fd = os.open(os.path.join(self.path, SCRATCH_MARKER), os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW, 0o644)
        try:
            os.write(fd, marker)
        finally:
            os.close(fd)

    def close(self):
        """Remove the scratch folder (its marker last; ``DIR/runs`` when empty) and release the lock."""
        with contextlib.suppress(OSError):
            for e in os.scandir(self.path):
                if e.name == SCRATCH_MARKER:
                    continue
                if e.is_dir(follow_symlinks=False):
                    shutil.rmtree(e.path, ignore_errors=True)
                else:
                    with contextlib.suppress(OSError):
                        os.remove(e.path)
        with contextlib.suppress(OSError):
            os.remove(os.path.join(self.path, SCRATCH_MARKER))
        with contextlib.suppress(OSError):
            os.rmdir(self.path)
        if self._fd is not None:
            _release(self._fd, self._lock_path)
            self._fd = None
        _owned.discard(os.path.abspath(self._lock_path))
        with contextlib.suppress(OSError):
            os.rmdir(os.path.dirname(self.path))   # only when empty
