"""The reference text output (docs/output.md): header blocks, summary, 42-column table, atomic files.

Values are formatted with ``str()`` as the reference does, except that numbers ``str()`` writes in
exponent notation are written positionally unless ``reference_header`` (the downstream R patterns
read digits only; see :mod:`.provenance`).  Files are reserved by a locked temporary file in the
target folder, streamed and renamed into place with ``os.replace`` when complete, so an
interrupted run never leaves a truncated file and the temporary files of killed runs are
recognised and removed by the next run (``docs/output.md``, "Files are complete or absent").
"""
__docformat__ = "numpy"
import hashlib
import math
import os
import shutil
import secrets
import tempfile
import time

try:
    import fcntl
    _HAVE_FLOCK = True
except ImportError:  # pragma: no cover - Windows
    fcntl = None
    _HAVE_FLOCK = False

import numpy as np

from ..base.stress import TENSOR_NAMES
from .provenance import header_number

#: suffix of a run's temporary output file (``.<name>.part``)
PART_SUFFIX = ".part"
#: suffix of a run's snapshot folder after the run's name without its format suffix (``x_nr_1`` →
#: ``x_nr_1_images``; docs/output.md, "Snapshots")
IMAGE_FOLDER_SUFFIX = "_images"
#: suffix of the snapshot folder after the text file name with ``reference_header=True``, as the
#: reference names it (``x_nr_1.txt`` → ``x_nr_1.txt_images_folder``)
REFERENCE_IMAGE_FOLDER_SUFFIX = "_images_folder"
#: ending of the private name a temporary file has before it is locked and linked to its ``.part`` name
_PRIVATE_SUFFIX = ".new"
#: the accepted values of ``output_format`` and their file suffixes (docs/output.md, "Output formats")
FORMAT_SUFFIXES = {"text": ".txt", "text.gz": ".txt.gz", "npz": ".npz", "parquet": ".parquet"}
#: suffix of a run's JSON sidecar, which replaces the run file's suffix (``x.txt`` → ``x.json``)
SIDECAR_SUFFIX = ".json"

__all__ = ["fsync_folder", "TABLE_COLUMNS", "FORMAT_SUFFIXES", "AtomicOutputFile", "run_file_stem", "format_of", "sidecar_path", "reserve_numbered_path", "remove_stale_parts", "number_is_free",
           "probe_writable", "iter_table_text", "iter_text_rows", "experiment_description_text",
           "output_summary_text", "NO_TENSOR_DATA_TEXT"]

#: output-table column name stems of the nine tensors, in the order of TENSOR_NAMES
_TENSOR_COLUMN_STEMS = (
    "stress_tensor_Love_Weber",
    "stress_tensor_peculiar_acceleration_otsuki",
    "stress_tensor_from_external_forces",
    "stress_tensor_linear_acceleration",
    "stress_tensor_unbalanced_linear_forces",
    "stress_tensor_tangential_torque",
    "stress_tensor_internal_tangential_torque",
    "stress_tensor_centrifugal",
    "stress_tensor_overall",
)
assert len(_TENSOR_COLUMN_STEMS) == len(TENSOR_NAMES)

#: the 42 column names of the detailed stress tensor table (docs/output.md, "Table columns")
TABLE_COLUMNS = (["index", "t", "strain", "strain_rate", "stress_measured_at_surface",
                  "shear_stress_internal_stress-tensor"]
                 + [stem + "_" + ab for stem in _TENSOR_COLUMN_STEMS for ab in ("00", "01", "10", "11")])

NO_TENSOR_DATA_TEXT = ("\tNot saving detailed stress tensor data. If you wish to save this data, pass \n"
                       "\t  saveStressTensorData=True")


def format_of(path):
    """The output format of a run file, by its suffix (``x.txt.gz`` → ``"text.gz"``).

    Parameters
    ----------
    path : str or os.PathLike
        A run file name ending with one of :data:`FORMAT_SUFFIXES`.

    Returns
    -------
    str
        A key of :data:`FORMAT_SUFFIXES`.

    Raises
    ------
    ValueError
        When ``path`` has none of the suffixes (the message lists them).
    """
    p = os.fspath(path)
    for fmt, suffix in sorted(FORMAT_SUFFIXES.items(), key=lambda kv: -len(kv[1])):  # ".txt.gz" before ".txt"
        if p.endswith(suffix):
            return fmt
    raise ValueError(f"path={p!r} is not a run file: allowed suffixes " + ", ".join(FORMAT_SUFFIXES.values()))


def run_file_stem(path):
    """``path`` without its run-file suffix (``x_nr_1.txt.gz`` → ``x_nr_1``).

    Parameters
    ----------
    path : str or os.PathLike
        A run file name ending with one of :data:`FORMAT_SUFFIXES`.

    Returns
    -------
    str

    Raises
    ------
    ValueError
        When ``path`` has none of the suffixes (the message lists them).
    """
    p = os.fspath(path)
    return p[: -len(FORMAT_SUFFIXES[format_of(p)])]


def sidecar_path(path):
    """The JSON sidecar of the run file ``path``: its stem + ``.json`` (``x.txt`` → ``x.json``).

    The sidecar does not end with the run file's name, so a folder reader that matches ``.txt``
    (the downstream R package) does not take it for a run file.  Files written before this rule
    have ``<file>.json``; :func:`~particleShear.simulation.formats.read_run` still reads those.

    Parameters
    ----------
    path : str or os.PathLike
        A run file name (one of :data:`FORMAT_SUFFIXES`).

    Returns
    -------
    str
    """
    return run_file_stem(path) + SIDECAR_SUFFIX


def _quietly(action):
    """Call ``action()`` and drop any ``Exception`` it raises (clean-up after a failure).

    Used when a write has already failed, or for what cannot matter any more: closing or
    removing what a failed write left must not raise a second exception in place of the first
    (a buffered file's close flushes again, which fails again on a full disk; a zip, gzip or
    Parquet trailer fails likewise, with the library's own exception type).
    """
    try:
        action()
    except Exception:  # noqa: BLE001 - the first failure is the one reported
        pass


def fsync_folder(folder):
    """Make a rename in ``folder`` durable (no-op where folders cannot be opened, e.g. Windows).

    Parameters
    ----------
    folder : str
        The folder whose entries were renamed.
    """
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


class AtomicOutputFile:
    """Binary file written under a temporary name and moved to ``path`` by :meth:`commit`.

    The temporary file ``.<name>.part`` (same folder) is created under a private name, locked
    (``fcntl.flock``, held until :meth:`commit` or :meth:`abort`) and only then linked to its
    public name, which fails if that name exists.  So the public ``.part`` name reserves
    ``path`` against concurrent runs choosing the same number, and a ``.part`` whose
    lock can be taken belongs to a process that died (SIGKILL, power loss): the next run in
    the folder removes it (:func:`remove_stale_parts`).

    ``abort()`` (or leaving a ``with`` block by an exception) removes the temporary file and
    its companions and never raises (it runs after a failure, e.g. a full disk, whose exception
    is the one to report).  Dependent temporary entries of the same run use the names
    :meth:`dependent` gives (``.<name>.part.<role>``) and are removed with a stale owner.
    Companion files (:meth:`add_companion`, the sidecar) are moved into place by
    :meth:`commit` just before the file and removed again if the file cannot follow, so a
    companion never exists without its file.

    Parameters
    ----------
    path : str or os.PathLike
        The final file name.
    exclusive : bool, optional
        True (default): fail with ``FileExistsError`` when ``.<name>.part`` exists already
        (the reservation of ``path`` by another run).
    """

    def __init__(self, path, exclusive=True):
        self.path = str(path)
        folder, name = os.path.split(self.path)
        self.folder = folder or "."
        self.tmp_path = os.path.join(folder, "." + name + PART_SUFFIX)
        self._fh = _create_locked(self.tmp_path, exclusive)
        self._companions = []    # (temporary path, final path), moved into place by commit()
        self.committed = False
        self.aborted = False

    @property
    def binary(self):
        """The open binary file object (writers stream into it)."""
        return self._fh

    def write(self, text):
        """Write ``text`` into the temporary file.

        Parameters
        ----------
        text : str or bytes
            A str is encoded as UTF-8.

        Returns
        -------
        int
            Bytes written.
        """
        return self._fh.write(text.encode("utf-8") if isinstance(text, str) else text)

    def flush(self):
        """Flush Python's buffer of the temporary file to the operating system."""
        self._fh.flush()

    def dependent(self, role):
        """Temporary path ``.<name>.part.<role>`` for a companion entry (sidecar, image folder).

        Parameters
        ----------
        role : str
            Suffix naming the companion (e.g. ``"json"``, ``"images"``).

        Returns
        -------
        str
        """
        return self.tmp_path + "." + role

    def digest(self):
        """Size and SHA-256 of the temporary file as written, read back from the file system.

        Called when the file is complete, before :meth:`commit`, so that a companion (the
        sidecar) can record what a reader must find.  Reads the file once (files are at most
        tens of MB).

        Returns
        -------
        tuple of (int, str)
            ``(size in bytes, SHA-256 as 64 lower-case hex digits)``.
        """
        self._fh.flush()
        h = hashlib.sha256()
        size = 0
        with open(self.tmp_path, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
                size += len(block)
        return size, h.hexdigest()

    def add_companion(self, role, data, path):
        """Write ``data`` durably into ``.<name>.part.<role>``, to be moved to ``path`` by :meth:`commit`.

        Written with unbuffered system calls and ``fsync``, so a failure (disk full) raises once
        and :meth:`abort` removes what was written.

        Parameters
        ----------
        role : str
            Names the temporary entry (:meth:`dependent`).
        data : bytes
            The companion's content.
        path : str or os.PathLike
            Its final name.
        """
        tmp = self.dependent(role)
        self._companions.append((tmp, os.fspath(path)))
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
            os.fsync(fd)
        finally:
            os.close(fd)

    def commit(self):
        """Make the complete file durable and move it (after its companions) into place.

        The file is flushed and ``fsync``-ed before the rename, so a committed file survives a
        power loss; the companions are renamed first and removed again if the file's rename
        fails.  The reservation is released.

        Returns
        -------
        str
            ``path``.
        """
        if self.committed:
            return self.path
        if self.aborted:
            raise ValueError(f"AtomicOutputFile({self.path!r}) was aborted: nothing to commit")
        self._fh.flush()
        os.fsync(self._fh.fileno())
        placed = []
        try:
            for tmp, final in self._companions:
                os.replace(tmp, final)
                placed.append(final)
            if not _HAVE_FLOCK:
                self._fh.close()
            # with flock: renamed while still locked, the .part is never seen unlocked by another run
            os.replace(self.tmp_path, self.path)
            self.committed = True
        except BaseException:
            for final in placed:
                _quietly(lambda f=final: os.remove(f))
            raise
        _quietly(self._fh.close)  # flushed and synced: nothing left that can fail
        fsync_folder(self.folder)
        return self.path

    def abort(self):
        """Delete the temporary file and its companions, release the reservation; never raises.

        Nothing appears under ``path``.  Errors while removing or closing (the buffered file's
        close flushes again, which fails again on a full disk) are dropped: an abort follows a
        failure, and that failure is the one to report.
        """
        if self.committed or self.aborted:
            return
        self.aborted = True
        for tmp, _ in self._companions:
            _quietly(lambda t=tmp: os.remove(t))
        _quietly(lambda: os.remove(self.tmp_path))
        if not self._fh.closed:
            _quietly(self._fh.close)

    @property
    def closed(self):
        """True once the temporary file is closed (after :meth:`commit` or :meth:`abort`)."""
        return self._fh.closed

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.abort()
        return False


def _create_locked(tmp_path, exclusive):
    """Open ``tmp_path`` for binary writing, locked before it is visible under that name."""
    folder, name = os.path.split(tmp_path)
    if not _HAVE_FLOCK:
        flags = os.O_WRONLY | os.O_CREAT | (os.O_EXCL if exclusive else os.O_TRUNC)
        return os.fdopen(os.open(tmp_path, flags, 0o644), "wb")
    private = os.path.join(folder, name + ".%d.%s%s" % (os.getpid(), secrets.token_hex(4), _PRIVATE_SUFFIX))
    fd = os.open(private, os.O_RDWR | os.O_CREAT | os.O_EXCL, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        try:
            os.link(private, tmp_path)  # atomic: fails when the name exists
        except FileExistsError:
            if exclusive:
                raise
            os.replace(private, tmp_path)
    except BaseException:
        os.close(fd)
        if os.path.exists(private):
            os.remove(private)
        raise
    os.remove(private)
    return os.fdopen(fd, "wb")


def _is_live(part_path):
    """True when the temporary file ``part_path`` is locked by a running process (or cannot be checked).

    Without ``fcntl`` (Windows) nothing can be proved stale, so every ``.part`` counts as live.
    """
    if not _HAVE_FLOCK:
        return True
    try:
        fd = os.open(part_path, os.O_RDONLY)
    except FileNotFoundError:
        return False
    except OSError:
        return True
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return True
        return False  # our lock is released on close below
    finally:
        os.close(fd)


def _age_s(path):
    try:
        return time.time() - os.stat(path).st_mtime
    except OSError:
        return 0.0


def _remove_entry(path):
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        try:
            os.remove(path)
        except FileNotFoundError:
            pass


def remove_stale_parts(folder):
    """Remove the temporary entries of killed runs in ``folder``; return the names removed.

    An owner ``.<name>.part`` is stale when no process holds its lock; its companions
    ``.<name>.part.<role>`` (sidecar, image folder) are stale with it or when the owner is gone.
    Entries of live runs (lock held) are left alone, so this is safe while other runs write
    into the same folder.

    Parameters
    ----------
    folder : str or os.PathLike
        The output folder (an unreadable folder removes nothing).

    Returns
    -------
    list of str
        The names removed.
    """
    try:
        names = os.listdir(folder)
    except OSError:
        return []
    removed = []
    owners = [n for n in names if n.startswith(".") and n.endswith(PART_SUFFIX)]
    live = set()
    for n in owners:
        p = os.path.join(folder, n)
        if _is_live(p):
            live.add(n)
        else:
            _remove_entry(p)
            removed.append(n)
    for n in names:
        if not n.startswith(".") or PART_SUFFIX + "." not in n:
            continue
        owner = n[: n.index(PART_SUFFIX + ".") + len(PART_SUFFIX)]
        if owner in live:
            continue
        p = os.path.join(folder, n)
        if n.endswith(_PRIVATE_SUFFIX) and (_is_live(p) or _age_s(p) < 60):
            continue  # a run between creating its private file and linking it (microseconds)
        if not _HAVE_FLOCK and os.path.exists(os.path.join(folder, owner)):
            continue
        _remove_entry(os.path.join(folder, n))
        removed.append(n)
    return removed


def _number_entries(path):
    """``(run files, other names)`` that take the number of ``path``: each format's file, the sidecar, the
    image folder (and, through each run file, the reference-named image folder)."""
    try:
        stem = run_file_stem(path)
    except ValueError:  # not a run file name: only itself
        return [str(path)], []
    return [stem + suffix for suffix in FORMAT_SUFFIXES.values()], [stem + SIDECAR_SUFFIX, stem + IMAGE_FOLDER_SUFFIX]


def _number_taken(path, own_part=None):
    """True when a run file, image folder, sidecar or live reservation (other than ``own_part``) holds the number."""
    files, others = _number_entries(path)
    if any(os.path.lexists(p) for p in others):
        return True
    for p in files:
        folder, name = os.path.split(p)
        part = os.path.join(folder, "." + name + PART_SUFFIX)
        if os.path.lexists(p) or os.path.lexists(p + REFERENCE_IMAGE_FOLDER_SUFFIX):
            return True
        if part != own_part and os.path.lexists(part) and _is_live(part):
            return True
    return False


def number_is_free(path):
    """True when no entry of the number of ``path`` exists, in any output format.

    The number ``<stem><k>`` is taken by the run file of any format (``.txt``, ``.txt.gz``,
    ``.npz``, ``.parquet``), its image folder (``<stem><k>_images`` or ``<file>_images_folder``), the shared sidecar ``<stem><k>.json`` or a live
    reservation of any of them: runs of different formats in one folder never share a sidecar.

    Parameters
    ----------
    path : str or os.PathLike
        A candidate output file name.

    Returns
    -------
    bool
    """
    return not _number_taken(path)


def reserve_numbered_path(stem, suffix=".txt", max_number=1_000_000):
    """Open an :class:`AtomicOutputFile` at ``stem + str(k) + suffix`` for the smallest k ≥ 1 free.

    Stale temporary files of killed runs in the folder are removed first, so they never take a
    number.  A number is free when :func:`number_is_free` says so; the reservation is atomic,
    and a reservation that finds a live reservation of the same number in another format
    (two runs reserving at once) is given up for the next number, so concurrent processes
    never pick the same number.

    Parameters
    ----------
    stem : str
        Path up to the number (``root/<name>_nr_``).
    suffix : str, optional
        What follows the number (default ``".txt"``).
    max_number : int, optional
        Largest number tried (default 1,000,000; the loop is bounded).

    Returns
    -------
    AtomicOutputFile
        The reserved, open file.

    Raises
    ------
    OSError
        When all numbers up to ``max_number`` are taken.
    """
    folder = os.path.dirname(stem) or "."
    remove_stale_parts(folder)
    for k in range(1, max_number + 1):
        path = stem + str(k) + suffix
        if number_is_free(path):
            try:
                out = AtomicOutputFile(path, exclusive=True)
            except FileExistsError:
                continue
            if _number_taken(path, own_part=out.tmp_path):  # a rival reserved the number meanwhile
                out.abort()
                continue
            return out
    raise OSError(f"no free file number below {max_number} for {stem}<k>{suffix}")


def probe_writable(folder):
    """Raise ``OSError`` unless a file can be created, written and removed in ``folder``.

    A real probe (``os.access`` says yes to root on a read-only mount or a full disk).

    Parameters
    ----------
    folder : str or os.PathLike
        The folder to probe.

    Raises
    ------
    OSError
        If creating, writing or removing the probe file fails.
    """
    fd, probe = tempfile.mkstemp(prefix=".particleShear-probe-", dir=folder)
    try:
        os.write(fd, b"probe")
    finally:
        os.close(fd)
        os.remove(probe)


def _particle_info(ens, reference):
    """The ensemble's description; the 1.0.2 text (with its reference defect #23 of docs/output.md) when ``reference``."""
    try:
        return ens.particle_info(reference=reference)
    except TypeError:
        return ens.particle_info()


def experiment_description_text(exp, reference_header=False):
    """Block 2 of the text file (docs/output.md, "Blocks"): the experiment's description.

    Parameters
    ----------
    exp : OscillatoryShearExperiment
        The experiment (its ensemble, dt, frequency, amplitude and periods are written).
    reference_header : bool, optional
        True reproduces the reference's bookkeeping defects #21 and #22 of docs/output.md:
        "Simulated time" = excitation time only and "Post-measurement periods" printing the
        pre value; also numbers with plain ``str()``.  False (default): both are correct
        (whole protocol time; post value).

    Returns
    -------
    str
        The block, ending with a newline.
    """
    _s = str if reference_header else header_number  # positional numbers for the R patterns
    ens = exp.theEnsemble
    L = ["Oscillatory shear experiment", ""]
    model = getattr(ens, "model", False)
    if model:
        L += ["Model parameters",
              "Width of simulation area size_x =" + _s(model.size_x) + "micrometers",
              "Height of simulation area size_y =" + _s(model.size_y) + "micrometers",
              "Nominal packing fraction = " + _s(model.packing_fraction),
              "Young modulus spheres = " + _s(model.Young_modulus_spheres) + "Pa",
              "Relative density spheres = " + _s(model.density) + "kg/m^3",
              "Characteristic time constant = " + _s(model.time_constant) + "s",
              "Characteristic spring constant = " + _s(model.k) + "mg/s^2",
              "Characteristic viscosity  = " + _s(model.k * model.time_constant) + "mg/s",
              ""]
    L += ["Ensemble parameters"]
    if model:
        L += ["Particle mass m = " + _s(model.m) + "mg"]
    L += ["Central spring constant k = " + _s(ens.k) + "mg*s^(-2)",
          "Central viscosity constant nu = " + _s(ens.nu) + "mg*s^(-1)",
          "Lateral spring constant k_t = " + _s(getattr(ens, "k_t", 0)) + "mg*s^(-2)",      # 0 without friction
          "Lateral viscosity constant nu_t = " + _s(getattr(ens, "nu_t", 0)) + "mg*s^(-1)",
          "Friction coefficient mu = " + _s(getattr(ens, "mu", 0)),
          "Sample width = " + _s(ens.size_x) + "micrometers",
          "Sample height = Gap height = " + _s(ens.size_y) + "micrometers",
          "Particle number = " + _s(ens.N if hasattr(ens, "N") else len(ens.sphereList)),
          "Particle information",
          "\t" + _particle_info(ens, reference_header)]
    if hasattr(ens, "central_repulsion_coefficient"):
        L.append("Nonlinear enhancement for repulsion near sphere center = " + _s(ens.central_repulsion_coefficient)
                 + "[-], 0=no enhancement, 1=maximum enhancement; see CircleBasicElasticity.get_elastic_force")
    if hasattr(ens, "permanent_ratio_central"):
        prc = ens.permanent_ratio_central
        L += ["Adjustment coefficient for central force in permanent links = " + _s(prc)
              + "[-], 0=no central force, 1=as in free interfaces; >1 re-enforcement of permanent over "
                "transient links",
              "\tk_permanent=" + _s(ens.k * prc) + "mg*s^(-2)"]
    if hasattr(ens, "permanent_ratio_tangential"):
        prt = ens.permanent_ratio_tangential
        L += ["Adjustment coefficient for tangential force in permanent links = " + _s(prt)
              + "[-], 0=no tangential force, 1=as in free interfaces; >1 re-enforcement of permanent over "
                "transient links",
              "\tk_t_permanent=" + _s(ens.k_t * prt) + "mg*s^(-2)"]
    if hasattr(ens, "keep_viscosity_coefficients_constant") and hasattr(ens, "permanent_ratio_central"):
        L.append("Viscosity adjustment for permanent links:")
        if ens.keep_viscosity_coefficients_constant:
            L += ["\tNo adjustment: Impose constant viscosity regardless of the permanent link adjustment ",
                  "\tnu_permanent=" + _s(ens.nu), "\tnu_t_permanent=" + _s(ens.nu_t)]
        else:
            L += ["\tAdjustment: Adjust viscosity (central and tangential) by same factor as the respective "
                  "spring constant (k and k_t)",
                  "\tnu_permanent=" + _s(ens.nu * ens.permanent_ratio_central),
                  "\tnu_t_permanent=" + _s(ens.nu_t * ens.permanent_ratio_tangential)]
    if hasattr(ens, "avoid_height_spanning_particles"):
        if ens.avoid_height_spanning_particles:
            L.append("avoid_height_spanning_particles: Ensembles with full height spanning particles discarded")
        else:
            L.append("avoid_height_spanning_particles: Full height spanning particles allowed")
    if hasattr(ens, "removed_fraction"):
        L += ["Actual fraction of randomly removed non-essential permanent bonds = " + _s(ens.removed_fraction)
              + "[-]", ""]
    if hasattr(ens, "edge_fuzziness"):
        L += ["Edge fuzziness for creating interlocking = " + _s(ens.edge_fuzziness) + "[-]", ""]
    pre, P, post, f = exp.baseline_pre_periods, exp.periods, exp.baseline_post_periods, exp.f
    simulated = P / f if reference_header else (pre + P + post) / f
    L += ["",
          "Rheology experiment information",
          "Simulated time = " + _s(simulated) + "s",
          "Time step = " + _s(exp.dt) + "s",
          "Frequency = " + _s(f) + "Hz",
          "Strain amplitude = " + _s(100 * exp.amplitude) + "%",
          "Damping factor = " + _s(exp.cool_factor) + " [1 = no damping]",
          "Pre-measurement periods = " + _s(pre) + " [-]",
          "Oscillatory shear periods = " + _s(P) + " [-]",
          "Post-measurement periods = " + _s(pre if reference_header else post) + " [-]"]
    return "\n".join(L) + "\n"


def output_summary_text(G_internal, G_surface, reference_header=False):
    """Block 3 up to and including the line "Detailed stress tensor data" (no newline at the end).

    Numbers in exponent notation are written positionally unless ``reference_header`` (the R
    patterns read G values as plain decimals).

    Parameters
    ----------
    G_internal : sequence of float
        Demodulation ``[SA, SB, G′, G″]`` (Pa) of τ_internal (overall stress tensor, eq. S1-24).
    G_surface : sequence of float
        Demodulation ``[SA, SB, G′, G″]`` (Pa) of τ_surface (plate forces).
    reference_header : bool, optional
        True: numbers written with ``str()`` exactly as the reference (default False).

    Returns
    -------
    str
    """
    _s = str if reference_header else header_number
    SA, SB, Gp, Gpp = G_internal
    L = ["", "", "Output data", "Summary data",
         "In phase stress = " + _s(SA) + "Pa",
         "Out of phase stress = " + _s(SB) + "Pa",
         "Stress = " + _s(math.sqrt(SA ** 2 + SB ** 2)) + "Pa",
         "G'=" + _s(Gp) + "Pa",
         "G''=" + _s(Gpp) + "Pa",
         "G'(by surface force)=" + _s(G_surface[2]) + "Pa",
         "G''(by surface force)=" + _s(G_surface[3]) + "Pa",
         "", "",
         "Detailed stress tensor data"]
    return "\n".join(L)


#: rows formatted and written at a time by the streaming writers (about 0.8 MB of text)
CHUNK_ROWS = 1024


def iter_text_rows(names, blocks, chunk_rows=CHUNK_ROWS):
    """A TAB-separated table in pieces of ``chunk_rows`` lines (bounded memory): the names line,
    then one line per row; the one writer of every text table (the 42-column reference table of
    :func:`iter_table_text`, the protocol tables of :func:`~.formats.write_columns`).

    Only one chunk of rows is converted to Python numbers and formatted at a time, so writing a
    231k-step table needs a few MB instead of the whole table as one string.  Each value is
    written as ``str`` of its Python number: floats round-trip exactly, integer arrays give
    integers.

    Parameters
    ----------
    names : sequence of str
        The column names (the names line).
    blocks : sequence of numpy.ndarray
        Each of shape (n,) (one column) or (n, ...) (its columns, row-major), one length n; the
        line of row i is the values of row i of every block, in this order.
    chunk_rows : int, optional
        Rows per piece (default :data:`CHUNK_ROWS`).

    Yields
    ------
    str
        The names line (preceded by a newline), then the data lines in chunks, each line
        preceded by a newline.
    """
    n = len(blocks[0]) if len(blocks) else 0
    yield "\n" + "\t".join(names)
    for a in range(0, n, chunk_rows):
        b = min(n, a + chunk_rows)
        parts = [["\t".join(map(str, row)) for row in block[a:b].reshape(b - a, -1).tolist()] for block in blocks]
        yield "".join("\n" + "\t".join(row) for row in zip(*parts))


def iter_table_text(scalars, tensors, chunk_rows=CHUNK_ROWS):
    """The text of the 42-column table in pieces of ``chunk_rows`` lines (:func:`iter_text_rows`).

    Parameters
    ----------
    scalars : numpy.ndarray
        Shape (n, 5): t (s), strain (–), strain rate (1/s), τ_surface and τ_internal (Pa).
    tensors : numpy.ndarray
        Shape (n, 9, 2, 2): the nine stress tensors of each step (Pa).
    chunk_rows : int, optional
        Rows per piece (default :data:`CHUNK_ROWS`).

    Yields
    ------
    str
        The header line (preceded by a newline), then the data lines in chunks.
    """
    n = len(scalars)
    return iter_text_rows(TABLE_COLUMNS, (np.arange(n), scalars, tensors.reshape(n, 36)), chunk_rows)

