"""Microstructure per excitation cycle: the stroboscopic observer and its measures (issue 49).

:class:`Stroboscope` is an observer (:mod:`.observers`) of the oscillatory protocol
(:func:`~.loops.protocol`).  At the same phase of every excitation period — the start of every
shear period, ``t_n = (pre + n)/f`` for ``n = 0 … periods`` — it takes a snapshot of every
replica of the batch (positions, strain, contacts and their normal forces), and between
consecutive snapshots it computes

- the non-affine displacement of every sphere (:func:`non_affine_displacement`, Lees-Edwards
  unwrapped, affine part removed), its mean square and the fraction of spheres that moved more
  than ``threshold·r_i``;
- D²_min of every sphere (:func:`d2min`, Falk & Langer, PRE 57, 7192, 1998) over its neighbours
  within ``cutoff`` mean radii;
- the contacts made and broken;

and per snapshot the contact number Z with rattlers removed (:func:`rattler_free`) and the
histogram of the normal contact forces ``P(f/⟨f⟩)`` (:func:`force_histogram`).

Everything is computed with arrays per replica (a loop over the B replicas, none over spheres);
each replica's numbers use its own rows only, so a replica of a batch gives the numbers of its
single run.  The observer only reads the state (it draws no random number, writes nothing of the
engine), so a run watched by it has the moduli of the same run unwatched, bit for bit; a run
without it computes nothing.  Definitions, thresholds and references: docs/microstructure.md.

Units: lengths µm, squared lengths µm², forces mg·µm·s⁻² per m depth (the engine's), Z per sphere.
"""
__docformat__ = "numpy"

import math
import time

import numpy as np

from .box import min_image
from .phase_laws import force_phase_laws
from .terms import elastic_term
from .xp import to_host

__all__ = ["Stroboscope", "non_affine_displacement", "d2min", "rattler_free", "contact_keys", "contact_changes",
           "force_histogram", "snapshot_steps", "irreversibility", "MOVED_THRESHOLD", "D2MIN_CUTOFF",
           "MIN_CONTACTS", "FORCE_BINS", "TRANSIENT_CYCLES"]

#: a sphere "moved" in a cycle when its non-affine displacement exceeds this fraction of its radius
MOVED_THRESHOLD = 0.1
#: neighbours of D²_min: centres within this many mean radii of the sphere at the reference snapshot
D2MIN_CUTOFF = 2.5 * 2
#: a sphere with fewer contacts is a rattler (removed iteratively): 3 = the frictional 2D isostatic
#: value d + 1 (frictionless: 2d = 4)
MIN_CONTACTS = 3
#: bin edges of P(f/⟨f⟩): 30 bins of width 0.2 over [0, 6) (forces above 6⟨f⟩ are counted in the last bin)
FORCE_BINS = np.linspace(0.0, 6.0, 31)
#: cycles left out as transient before the per-run averages (:func:`irreversibility`)
TRANSIENT_CYCLES = 1


def snapshot_steps(dt, f, pre, periods):
    """Protocol step counts at which the stroboscopic snapshots are taken.

    The snapshot n is taken after the step whose end is nearest to ``t_n = (pre + n)/f``, the
    start of shear period n (``n = 0 … periods``): the same phase of the excitation in every
    period (to within dt/2 when a period is not a whole number of steps; the strain difference
    that leaves is removed as affine motion, :func:`non_affine_displacement`).

    Parameters
    ----------
    dt : float
        Protocol time step (s), > 0.
    f : float
        Excitation frequency (Hz), > 0.
    pre : float
        Baseline periods before the shear.
    periods : float
        Shear periods; ``floor(periods) + 1`` snapshots.

    Returns
    -------
    list of int
        Step counts (≥ 1, increasing, distinct).
    """
    steps = []
    for n in range(int(math.floor(periods + 1e-9)) + 1):
        k = max(1, int(round((pre + n) / (f * dt))))
        if not steps or k > steps[-1]:
            steps.append(k)
    return steps


def non_affine_displacement(pos0, pos1, gamma0, gamma1, Lx, Ly):
    """Non-affine displacement of every sphere between two snapshots of a Lees-Edwards cell.

    A sphere's unwrapped position is its image ``(x + k·Ly·γ, y + k·Ly)`` (the image rows move
    with the flow), so its displacement from snapshot 0 to 1 less the affine displacement
    ``(γ₁ − γ₀)·(Y₀ − Ly/2)`` is ``Δx − (γ₁ − γ₀)(y₀ − Ly/2) + k′·Ly·γ₁ (+ m·Lx)`` with the
    boundary crossings ``k′`` (and ``m``) those of the minimum image at the strain of snapshot 1
    (:func:`~particleShear.engine.box.min_image`); the crossings before snapshot 0 cancel.  Exact
    when the non-affine displacement is shorter than half the cell on each axis.

    Parameters
    ----------
    pos0, pos1 : ndarray (2, n)
        Wrapped positions (µm) at the two snapshots.
    gamma0, gamma1 : float
        Strain of the cell at the two snapshots.
    Lx, Ly : float
        Cell lengths (µm).

    Returns
    -------
    ndarray (2, n)
        Non-affine displacements (µm).
    """
    pos0, pos1 = np.asarray(pos0, float), np.asarray(pos1, float)
    dx = pos1[0] - pos0[0] - (gamma1 - gamma0) * (pos0[1] - Ly / 2)
    dy = pos1[1] - pos0[1]
    ux, uy = min_image(dx, dy, Lx, Ly, Ly * gamma1)[:2]
    return np.array((ux, uy))


def _pair_vectors(pos, Lx, Ly, shift):
    """Minimum-image vectors (2, n, n) from every sphere i to every sphere j (µm)."""
    dx = pos[0][None, :] - pos[0][:, None]
    dy = pos[1][None, :] - pos[1][:, None]
    ux, uy = min_image(dx, dy, Lx, Ly, shift)[:2]
    return np.array((ux, uy))


def d2min(pos0, disp, Lx, Ly, gamma0, cutoff, dgamma=0.0):
    """D²_min of every sphere: the residual of the best local affine map (Falk & Langer 1998).

    For sphere i with the neighbours j within ``cutoff`` at the reference snapshot (minimum image
    at strain ``gamma0``), separations ``d⁰_ij`` and, after the motion, ``d¹_ij = d⁰_ij + u_j − u_i
    + Δγ·(d⁰_ij,y, 0)``:  ``D²_min(i) = min_J (1/n_i) Σ_j |d¹_ij − J d⁰_ij|²`` with J the 2 × 2 map
    ``X Y⁻¹`` (``X = Σ d¹ d⁰ᵀ``, ``Y = Σ d⁰ d⁰ᵀ``).  The shear of the cell acts on the pair vector
    itself, so a neighbour seen through the sheared boundary (an image ``k·Ly`` away) moves with
    its image, as in the unwrapped packing.  Falk & Langer sum over the neighbours; the mean over
    them used here does not grow with the cutoff.  Zero for any affine map of the neighbourhood,
    rigid translations and rotations included.

    Parameters
    ----------
    pos0 : ndarray (2, n)
        Wrapped positions at the reference snapshot (µm).
    disp : ndarray (2, n)
        Displacements to the current snapshot less the cell's shear ``Δγ·(y − Ly/2)`` (µm): the
        non-affine displacements of :func:`non_affine_displacement`, or any displacement field
        when ``dgamma`` is 0.
    Lx, Ly : float
        Cell lengths (µm).
    gamma0 : float
        Strain at the reference snapshot.
    cutoff : float
        Neighbour radius (µm), > 0.
    dgamma : float, default 0
        Strain change Δγ of the cell between the snapshots.

    Returns
    -------
    ndarray (n,)
        D²_min (µm²); NaN for a sphere whose neighbours do not span the plane (fewer than two
        not on one line).
    """
    pos0, disp = np.asarray(pos0, float), np.asarray(disp, float)
    d0 = _pair_vectors(pos0, Lx, Ly, Ly * gamma0)
    r2 = d0[0] ** 2 + d0[1] ** 2
    w = (r2 < cutoff * cutoff).astype(float)
    np.fill_diagonal(w, 0.0)
    d1 = d0 + (disp[:, None, :] - disp[:, :, None])
    d1[0] += dgamma * d0[1]
    X = np.einsum("ij,aij,bij->iab", w, d1, d0)
    Y = np.einsum("ij,aij,bij->iab", w, d0, d0)
    det = Y[:, 0, 0] * Y[:, 1, 1] - Y[:, 0, 1] * Y[:, 1, 0]
    scale = np.einsum("ij,ij->i", w, r2)
    ok = det > 1e-12 * scale * scale
    Yinv = np.empty_like(Y)
    safe = np.where(ok, det, 1.0)
    Yinv[:, 0, 0], Yinv[:, 1, 1] = Y[:, 1, 1] / safe, Y[:, 0, 0] / safe
    Yinv[:, 0, 1], Yinv[:, 1, 0] = -Y[:, 0, 1] / safe, -Y[:, 1, 0] / safe
    J = np.einsum("iab,ibc->iac", X, Yinv)
    res = d1 - np.einsum("iab,bij->aij", J, d0)
    n = w.sum(axis=1)
    out = np.einsum("ij,aij,aij->i", w, res, res) / np.where(n > 0, n, 1.0)
    return np.where(ok, out, np.nan)


def rattler_free(i, j, n, min_contacts=MIN_CONTACTS):
    """Contact number with rattlers removed: spheres with fewer than ``min_contacts`` contacts are
    removed, with their contacts, until every remaining sphere has at least ``min_contacts``.

    Parameters
    ----------
    i, j : array_like of int (c,)
        The contacts (sphere indices 0 … n−1, each contact once).
    n : int
        Number of spheres.
    min_contacts : int, default :data:`MIN_CONTACTS`
        The least contacts of a sphere that is not a rattler (≥ 1).

    Returns
    -------
    Z : float
        ``2·c′/n′``: mean contacts per remaining sphere (NaN when none remains).
    rattlers : ndarray of bool (n,)
        The spheres removed.

    Raises
    ------
    ValueError
        If ``min_contacts`` is not an integer ≥ 1 or an index is outside ``0 … n−1``.
    """
    if isinstance(min_contacts, bool) or not isinstance(min_contacts, (int, np.integer)) or min_contacts < 1:
        raise ValueError(f"min_contacts={min_contacts!r} is out of range: allowed an integer >= 1")
    i, j = np.asarray(i, np.intp), np.asarray(j, np.intp)
    if len(i) and (min(i.min(), j.min()) < 0 or max(i.max(), j.max()) >= n):
        raise ValueError(f"contact indices are out of range: allowed 0 ... {n - 1}")
    keep = np.ones(n, bool)
    live = np.ones(len(i), bool)
    while True:          # one round per layer of rattlers (at most n rounds)
        z = np.bincount(i[live], minlength=n) + np.bincount(j[live], minlength=n)
        drop = keep & (z < min_contacts)
        if not drop.any():
            break
        keep &= ~drop
        live &= keep[i] & keep[j]
    m = int(keep.sum())
    return (2.0 * live.sum() / m if m else math.nan), ~keep


def contact_keys(i, j, n):
    """Sorted integer keys ``min·n + max`` of contacts (one per unordered pair).

    Parameters
    ----------
    i, j : array_like of int (c,)
        The contacts' sphere indices (0 … n−1).
    n : int
        Number of spheres.

    Returns
    -------
    ndarray of int64
        The distinct keys, increasing.
    """
    i, j = np.asarray(i, np.int64), np.asarray(j, np.int64)
    return np.unique(np.minimum(i, j) * n + np.maximum(i, j))


def contact_changes(keys0, keys1):
    """Contacts made and broken between two snapshots.

    Parameters
    ----------
    keys0, keys1 : ndarray of int
        :func:`contact_keys` of the two snapshots.

    Returns
    -------
    made, broken : int
        Contacts in ``keys1`` not in ``keys0``, and in ``keys0`` not in ``keys1``.
    """
    return (int(len(np.setdiff1d(keys1, keys0, assume_unique=True))),
            int(len(np.setdiff1d(keys0, keys1, assume_unique=True))))


def force_histogram(fn, bins=FORCE_BINS):
    """Histogram P(f/⟨f⟩) of normal contact forces, a probability density in f/⟨f⟩.

    Parameters
    ----------
    fn : array_like
        Normal forces of the contacts (compressive > 0, any unit; the ratio is dimensionless).
    bins : ndarray, default :data:`FORCE_BINS`
        Bin edges in f/⟨f⟩; values at or above the last edge count in the last bin.

    Returns
    -------
    ndarray (len(bins) − 1,)
        Density (integrates to 1 over the bins); NaN when there is no positive force.
    """
    fn = np.asarray(fn, float)
    fn = fn[fn > 0]
    if not len(fn):
        return np.full(len(bins) - 1, np.nan)
    x = np.minimum(fn / fn.mean(), np.nextafter(bins[-1], bins[0]))
    return np.histogram(x, bins=bins, density=True)[0]


def irreversibility(msd, r_mean, transient=TRANSIENT_CYCLES):
    """Per-run irreversibility: the mean squared non-affine displacement per cycle after the
    transient, normalised by the squared mean radius.

    Parameters
    ----------
    msd : array_like (n_cycles,)
        Mean squared non-affine displacement of each cycle (µm²).
    r_mean : float
        Mean sphere radius (µm).
    transient : int, default :data:`TRANSIENT_CYCLES`
        Cycles left out at the start; when no cycle remains, the last cycle alone.

    Returns
    -------
    float
        Dimensionless; NaN without any cycle.
    """
    msd = np.asarray(msd, float)
    if not len(msd):
        return math.nan
    tail = msd[transient:] if len(msd) > transient else msd[-1:]
    return float(np.mean(tail) / (r_mean * r_mean))


class Stroboscope:
    """The stroboscopic observer of a batch's oscillatory protocol (see the module docstring).

    Hand it to :func:`~particleShear.engine.loops.protocol` among the observers; after the
    protocol :meth:`replica` gives each replica's per-cycle arrays.  It is called after every
    step (``every = 1``) and returns at once except after the steps of :func:`snapshot_steps`.

    Parameters
    ----------
    dt, f, pre, periods : float
        The protocol's time step (s), frequency (Hz), baseline periods before and shear periods.
    replicas : sequence of int, optional
        The replicas (columns of the batch) to watch; default every one.
    threshold : float, default :data:`MOVED_THRESHOLD`
        "Moved": non-affine displacement above ``threshold·r_i`` (> 0).
    cutoff : float, default :data:`D2MIN_CUTOFF`
        D²_min neighbours within ``cutoff`` mean radii (> 0).
    min_contacts : int, default :data:`MIN_CONTACTS`
        Rattler rule (:func:`rattler_free`).

    Raises
    ------
    ValueError
        If ``threshold`` or ``cutoff`` is not a finite number > 0 or ``min_contacts`` not an
        integer ≥ 1.
    """

    every = 1

    def __init__(self, dt, f, pre, periods, replicas=None, threshold=MOVED_THRESHOLD, cutoff=D2MIN_CUTOFF,
                 min_contacts=MIN_CONTACTS):
        for name, v in (("threshold", threshold), ("cutoff", cutoff)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"{name}={v!r} is out of range: allowed a finite number > 0")
        rattler_free((), (), 0, min_contacts)      # checks min_contacts
        self.threshold, self.cutoff, self.min_contacts = float(threshold), float(cutoff), int(min_contacts)
        self.steps = snapshot_steps(dt, f, pre, periods)
        self._due = set(self.steps)
        self.replicas = None if replicas is None else [int(b) for b in replicas]
        self.snaps = {}           # replica -> list of snapshot dicts
        self.cycles = {}          # replica -> list of per-cycle dicts
        #: wall time spent taking the snapshots and computing the measures (s; the cost of the observer
        #: beside its per-step check, benchmarks/stroboscopic_cost.py)
        self.seconds = 0.0

    def observe(self, engine, phase, step, total):
        """Take the snapshot due after ``step`` of the protocol (nothing otherwise).

        Parameters
        ----------
        engine : BatchEngine
            The running engine (read only).
        phase : str
            Only ``"protocol"`` is watched.
        step, total : int
            Steps done and steps of the phase.
        """
        # (a protocol of a whole number of periods may end one step short of its last snapshot)
        if phase != "protocol" or not (step in self._due or (step == total and total + 1 in self._due)):
            return
        t0 = time.perf_counter()
        s = engine.s
        B, N = s.B, s.N
        pos = to_host(s.pos, "microstructure")
        r = to_host(s.r, "microstructure")
        Lx, Ly, gamma = (to_host(a, "microstructure") for a in (s.Lx, s.Ly, s.gamma))
        shift = to_host(engine.image_shift(), "microstructure")
        mob = to_host(engine.mobile(), "microstructure")
        C = engine.s.contacts.C
        ai, aj, rep = C.ai_host, C.aj_host, C.rep_host
        # contacts and their normal forces over the engine's candidates (the Verlet list holds every
        # pair within contact distance), at the positions of now
        raw = pos[:, aj] - pos[:, ai]
        dx, dy = min_image(raw[0], raw[1], to_host(C.Lx, "microstructure"), to_host(C.Ly, "microstructure"),
                           shift[rep])[:2]
        d = np.sqrt(dx * dx + dy * dy)
        touching = d < to_host(C.d0, "microstructure")
        f_el = to_host(elastic_term(C, s.backend.asarray(d) if not s.backend.host else d,
                                    *force_phase_laws(s, C))[0], "microstructure")
        fn = -f_el                                  # compressive > 0 (the law is negative where it repels)
        for b in (range(B) if self.replicas is None else self.replicas):
            rows = slice(b * N, (b + 1) * N)
            sel = touching & (rep == b)
            ci, cj = ai[sel] - b * N, aj[sel] - b * N
            Z, rattlers = rattler_free(ci, cj, N, self.min_contacts)
            snap = {"step": step, "pos": pos[:, rows].copy(), "gamma": float(gamma[b]), "shift": float(shift[b]),
                    "Lx": float(Lx[b]),
                    "Ly": float(Ly[b]), "r": r[rows], "mobile": mob[rows].copy(), "i": ci, "j": cj,
                    "fn": fn[sel], "keys": contact_keys(ci, cj, N), "Z": Z,
                    "rattler_fraction": float(rattlers.mean()) if N else math.nan,
                    "force_pdf": force_histogram(fn[sel])}
            snaps = self.snaps.setdefault(b, [])
            if snaps:
                self.cycles.setdefault(b, []).append(self._cycle(snaps[-1], snap))
            snaps.append(snap)
        self.seconds += time.perf_counter() - t0

    def _cycle(self, a, b):
        """The per-cycle measures between snapshots ``a`` and ``b`` of one replica."""
        u = non_affine_displacement(a["pos"], b["pos"], a["gamma"], b["gamma"], a["Lx"], a["Ly"])
        u2 = u[0] ** 2 + u[1] ** 2
        both = a["mobile"] & b["mobile"]
        r = a["r"]
        D2 = d2min(a["pos"], u, a["Lx"], a["Ly"], a["gamma"], self.cutoff * float(r.mean()),
                   dgamma=b["gamma"] - a["gamma"])
        made, broken = contact_changes(a["keys"], b["keys"])
        m = max(int(both.sum()), 1)
        return {"u": u, "msd": float(u2[both].sum() / m), "moved": float((u2[both] > (self.threshold * r[both]) ** 2).sum() / m),
                "d2min": D2, "d2min_mean": float(np.nanmean(D2[both])) if both.any() and np.isfinite(D2[both]).any()
                else math.nan, "made": made, "broken": broken, "contacts": len(a["keys"])}

    def replica(self, b):
        """Replica ``b``'s per-cycle and per-snapshot arrays (``result.microstructure``).

        Parameters
        ----------
        b : int
            The replica's column in the batch.

        Returns
        -------
        dict
            Per cycle (n_c = snapshots − 1): "msd" (µm², mean over the spheres mobile at both
            snapshots), "moved" (fraction), "d2min" (n_c, N) and "d2min_mean" (µm²), "made",
            "broken" (contacts), "non_affine" (n_c, 2, N) (µm); per snapshot (n_c + 1): "step",
            "gamma", "Z", "rattler_fraction", "contacts", "force_pdf" (n_c + 1, bins), "positions"
            (n_c + 1, 2, N) (µm, wrapped), "contact_i", "contact_j", "normal_force" (lists of
            arrays per snapshot); "force_bins", "r_mean" (µm), "Lx", "Ly" (µm) and the settings
            "threshold", "cutoff" (mean radii), "min_contacts"; "seconds": the observer's wall time
            (s, of the whole batch).  None when the replica was not watched.
        """
        snaps = self.snaps.get(b)
        if snaps is None:
            return None
        cyc = self.cycles.get(b, [])
        col = lambda key, dtype=float: np.array([c[key] for c in cyc], dtype=dtype)   # noqa: E731
        N = snaps[0]["pos"].shape[1]
        return {"msd": col("msd"), "moved": col("moved"), "made": col("made", int), "broken": col("broken", int),
                "contacts_before": col("contacts", int),
                "d2min": np.array([c["d2min"] for c in cyc]).reshape(len(cyc), N),
                "d2min_mean": col("d2min_mean"),
                "non_affine": np.array([c["u"] for c in cyc]).reshape(len(cyc), 2, N),
                "step": np.array([sn["step"] for sn in snaps]), "gamma": np.array([sn["gamma"] for sn in snaps]),
                "shift": np.array([sn["shift"] for sn in snaps]),
                "Z": np.array([sn["Z"] for sn in snaps]),
                "rattler_fraction": np.array([sn["rattler_fraction"] for sn in snaps]),
                "contacts": np.array([len(sn["keys"]) for sn in snaps]),
                "force_pdf": np.array([sn["force_pdf"] for sn in snaps]),
                "positions": np.array([sn["pos"] for sn in snaps]),
                "contact_i": [sn["i"] for sn in snaps], "contact_j": [sn["j"] for sn in snaps],
                "normal_force": [sn["fn"] for sn in snaps], "radius": snaps[0]["r"].copy(),
                "force_bins": FORCE_BINS.copy(), "r_mean": float(snaps[0]["r"].mean()),
                "Lx": snaps[0]["Lx"], "Ly": snaps[0]["Ly"], "threshold": self.threshold, "cutoff": self.cutoff,
                "min_contacts": self.min_contacts, "seconds": self.seconds}

