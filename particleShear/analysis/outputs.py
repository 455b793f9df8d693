"""The files of ``python -m particleShear analyse``, published as one set.

An analysis writes every file of its set (:data:`SET_NAMES`: ``analysis.csv``, its schema, the
figure, the summaries of steady, relaxation and creep runs and their schema) into a staging
folder of its own inside the sweep folder, ``DIR/.analysis.<host>-<pid>-<random>.part/`` (names
unique to the process: two analyses never share a temporary), and only then publishes them:

* under the folder's analysis lock ``DIR/analysis.lock``
  (:func:`particleShear.sweep.locks.folder_lock`, a POSIX record lock the operating system
  releases when the process dies), so two analyses of one folder publish one after the other;
* with SIGINT and SIGTERM held back for the few renames, so the files on disk are the earlier
  set or the new one, never a mix; a file of the set that the new analysis does not write (the
  figure with ``--no-figure``) is removed, and said.

Before any work (:func:`check_targets`) the folder must be writable and no file of the set may
be a directory or read-only (its write permission bits cleared: checked by the mode, which also
holds for root) — such a file is never replaced, the analysis refuses with one line.  Staging
folders of dead processes of this host are removed by the next analysis.
"""
__docformat__ = "numpy"
import os
import secrets
import shutil
import socket
import stat

from ..signals import dead_leftovers, signals_held
from ..simulation.output import fsync_folder
from ..run.validation import check_folder_writable
from ..sweep.locks import folder_lock

__all__ = ["LOCK_NAME", "LOCK_WAIT_S", "PublishInterrupted", "check_targets", "make_staging", "publish",
           "remove_dead_staging"]

#: the analysis lock of a folder (``folder_lock`` adds ``.lock``)
LOCK_NAME = "analysis"
#: seconds an analysis waits for another one of the folder to finish publishing
LOCK_WAIT_S = 60.0


class PublishInterrupted(Exception):
    """SIGINT or SIGTERM arrived while the set was published: it was published whole, then this is raised.

    Parameters
    ----------
    signum : int
        The signal (also the attribute ``signum``).
    """

    def __init__(self, signum):
        super().__init__(f"signal {signum}")
        self.signum = signum


def _read_only(st):
    return stat.S_ISREG(st.st_mode) and not st.st_mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH)


def check_targets(folder, names):
    """Refuse, before any work, a set that cannot be published into ``folder``.

    Parameters
    ----------
    folder : str
        The sweep folder.
    names : iterable of str
        The file names of the set (:data:`SET_NAMES` of the CLI).

    Raises
    ------
    ValueError
        One line: the folder is not writable, a name of the set is a directory (or another
        non-file), or a file of the set is read-only (or not writable by this user).
    """
    check_folder_writable("DIR", folder)
    for name in names:
        path = os.path.join(folder, name)
        try:
            st = os.stat(path)       # through a link: a link is replaced by a file, but say what it points at
        except FileNotFoundError:
            continue
        except OSError as exc:
            raise ValueError(f"{path!r} cannot be checked ({exc.strerror or exc}): not replaced") from None
        if stat.S_ISDIR(st.st_mode):
            raise ValueError(f"{path!r} is a directory: the analysis would replace it; move it away, or analyse a "
                             "copy of the folder")
        if not stat.S_ISREG(st.st_mode):
            raise ValueError(f"{path!r} is not a regular file: not replaced; move it away")
        if _read_only(st) or not os.access(path, os.W_OK):
            raise ValueError(f"{path!r} is read-only: not replaced; make it writable (chmod u+w) or remove it "
                             "to write a new analysis")


def make_staging(folder):
    """A new, empty staging folder ``DIR/.analysis.<host>-<pid>-<random>.part`` (path).

    Parameters
    ----------
    folder : str
        The sweep folder.

    Returns
    -------
    str
    """
    remove_dead_staging(folder)
    path = os.path.join(folder, f".analysis.{socket.gethostname()}-{os.getpid()}-{secrets.token_hex(4)}.part")
    os.mkdir(path)
    return path


def remove_dead_staging(folder):
    """Remove the staging folders that dead processes of this host left in ``folder``; the names removed.

    Parameters
    ----------
    folder : str

    Returns
    -------
    list of str
    """
    removed = []
    for name in dead_leftovers(folder, ".analysis"):
        shutil.rmtree(os.path.join(folder, name), ignore_errors=True)
        removed.append(name)
    return removed


def publish(folder, staging, names, every_name):
    """Move the files ``names`` of ``staging`` into ``folder`` as one set; remove the set's other files.

    Parameters
    ----------
    folder : str
        The sweep folder.
    staging : str
        The staging folder holding the new files.
    names : list of str
        The new set's file names (each in ``staging``).
    every_name : iterable of str
        Every name a set can hold: those in ``folder`` that are not in ``names`` are removed.

    Returns
    -------
    removed : list of str
        Paths of files of an earlier set that were removed.

    Raises
    ------
    ValueError
        A target became a directory or read-only meanwhile (nothing published).
    particleShear.sweep.locks.FolderBusyError
        Another analysis held the lock for :data:`LOCK_WAIT_S` s.
    PublishInterrupted
        SIGINT or SIGTERM arrived during the publication, which completed first.
    """
    removed = []
    with folder_lock(os.path.join(folder, LOCK_NAME), wait_s=LOCK_WAIT_S):
        check_targets(folder, every_name)
        with signals_held() as got:
            for name in names:
                os.replace(os.path.join(staging, name), os.path.join(folder, name))
            for name in every_name:
                path = os.path.join(folder, name)
                if name not in names and os.path.lexists(path):
                    os.remove(path)
                    removed.append(path)
            fsync_folder(folder)                    # the renames on disk before we say so
    if got:
        raise PublishInterrupted(got[0])
    return removed
