"""The state of a batch of replicas as explicit arrays (docs/design.md, "Runs").

Spheres of replica b occupy rows ``b·N … b·N + N − 1`` of every per-sphere array; per-replica
values (box, strain, rate, model constants) are arrays of length B and are gathered to spheres
or pairs where a kernel needs them.  Pairs are kept per replica (:class:`ReplicaPairs`, sorted by
``(i, j)``) and concatenated in replica order into the flat arrays a step works on.

The arrays live on the state's backend (:attr:`BatchState.backend`, NumPy by default, CuPy with
``backend="cupy"``; :mod:`.xp`); the per-replica pair lists and the random generators stay on the
host (the candidate search and the draws at ``d = 0`` run there).

Units: µm, s, mg per m depth (reference units, docs/parameters.md).
"""
__docformat__ = "numpy"

import numpy as np

from .xp import get_backend

__all__ = ["STICK", "SLIP", "PERMANENT", "ReplicaPairs", "BatchState", "PER_SPHERE_PARAMETERS", "uniform_parameters"]

STICK, SLIP, PERMANENT = 0, 1, 2

#: per-sphere model parameters of the documented spheres, in the order of :attr:`BatchState.visit`'s rows:
#: a pair's visit from i sees sphere i's values, its visit from j sphere j's (1.0.2's per-visit rule)
PER_SPHERE_PARAMETERS = ("central_repulsion_coefficient", "permanent_ratio_central", "permanent_ratio_tangential",
                         "keep_viscosity_coefficients_constant")
#: the per-replica arrays of :class:`BatchState` that hold these parameters when a replica's spheres share them
_PER_REPLICA = ("c", "prc", "prt", "keep")


def uniform_parameters(ensemble):
    """Whether every parameter of :data:`PER_SPHERE_PARAMETERS` is one value in ``ensemble`` (then the
    batch state holds it once per replica, else per sphere in :attr:`BatchState.visit`).

    Parameters
    ----------
    ensemble : ensemble
        A documented ensemble (its ``_a`` rows are read).

    Returns
    -------
    bool
    """
    a, n = ensemble._a, len(ensemble.sphereList)
    return all(np.all(np.asarray(a[name][:n]) == a[name][0]) for name in PER_SPHERE_PARAMETERS) if n else True


class ReplicaPairs:
    """Candidate pairs of one replica: local indices ``i < j`` in canonical order and their history.

    ``state`` (stick / slip / permanent), ``xi`` (2, C: ξ_ij, ξ_ji in µm), ``d_eq`` (µm, bonds),
    ``active`` (a relation of the reference: touching at the last neighbour update, or a bond) and
    ``birth``, the creation number of each relation (the order of ``sphere.neighbors``; the
    classes' ``PairTable.birth``).  The arguments are converted (not validated) to the dtypes below.

    Parameters
    ----------
    i, j : array_like of int (C,)
        Local sphere indices (0 … N−1) of each candidate, ``i < j``, sorted by ``(i, j)``.
    state : array_like of int (C,)
        :data:`STICK`, :data:`SLIP` or :data:`PERMANENT` per candidate.
    xi : array_like (2, C) or (2·C,)
        Tangential displacement histories ξ_ij (row 0) and ξ_ji (row 1), µm.
    d_eq : array_like (C,)
        Equilibrium distance of each bond (µm; unused for transient contacts).
    active : array_like of bool (C,)
        The candidate is a relation (touching at the last update, or a bond).
    birth : array_like of int (C,), optional
        Creation number of each relation (unused where ``active`` is False); default 0.
    """
    __slots__ = ("i", "j", "state", "xi", "d_eq", "active", "birth")

    def __init__(self, i, j, state, xi, d_eq, active, birth=None):
        self.i = np.asarray(i, dtype=np.intp)
        self.j = np.asarray(j, dtype=np.intp)
        self.state = np.asarray(state, dtype=np.int8)
        self.xi = np.asarray(xi, dtype=float).reshape(2, -1)
        self.d_eq = np.asarray(d_eq, dtype=float)
        self.active = np.asarray(active, dtype=bool)
        self.birth = np.zeros(len(self.i), np.int64) if birth is None else np.asarray(birth, dtype=np.int64)


class BatchState:
    """Arrays of B replicas of N spheres each (see the module docstring).

    Attributes
    ----------
    B, N : int
        Replicas and spheres per replica.
    x, y, vx, vy, omega, phi, r, m, inertia : ndarray (B·N,)
        Sphere state (µm, µm/s, 1/s, rad, µm, mg/m, mg·µm²/m); ``x, y`` are the rows of ``pos``
        (2, B·N) and ``vx, vy, omega`` those of ``vel`` (3, B·N).
    Lx, Ly, gamma, rate, t : ndarray (B,)
        Box (µm), strain γ, strain rate γ̇ (1/s) and clock (s) of each replica.
    k, nu, k_t, nu_t, mu, c, prc, prt, keep : ndarray (B,)
        Ensemble constants of each replica (the values a step of its ensemble uses).
    pairs : list of ReplicaPairs
        Candidate pairs of each replica (NumPy arrays, on the host).
    rng : list of numpy.random.Generator
        Each replica's own generator (random normals at ``d = 0``).
    next_birth : numpy.ndarray of int64 (B,)
        The creation number the next relation of each replica gets (on the host; the engine numbers
        the relations that form in its steps, :meth:`~particleShear.engine.step.BatchEngine.flush`).
    applying_shear : bool
        Plates active (spheres overlapping ``y = 0`` or ``y = Ly`` are immobile).
    visit : ndarray (4, B·N) or None
        The parameters of :data:`PER_SPHERE_PARAMETERS` per sphere (c, permanent ratios, kept
        viscosities) when the spheres of some replica do not share them, else None (then the
        per-replica ``c, prc, prt, keep`` hold them; with ``visit`` they hold sphere 0's values).
        Each visit of a pair sees its own sphere's values (:meth:`~particleShear.engine.forces.PairConstants.set_visits`).
    law : str or None
        Central law of every replica, a name of :data:`~particleShear.engine.laws.LAWS` (one per
        batch), or None: the documented callback ``call_back_elastic_force_law`` (looked up once
        per force phase, :func:`~particleShear.engine.callbacks.force_phase_laws`).
    law_params : ndarray (n, B)
        The law's parameters per replica, in the order of its ``parameters`` (n = 0 for None).
    backend : Backend
        Where the arrays live (:func:`~particleShear.engine.xp.get_backend`).
    xp : module
        Its array namespace (``numpy`` or ``cupy``).

    Parameters
    ----------
    B : int
        Number of replicas (≥ 0).
    N : int
        Spheres per replica (≥ 0).  Every array starts at zero; :meth:`from_ensembles` fills them.
    backend : str or Backend, default "numpy"
        Array backend of the state (``"numpy"``, ``"cupy"``, or a registered one).

    Raises
    ------
    ValueError
        For an unknown backend, or ``"cupy"`` without CuPy or a CUDA device.
    """

    #: names of the per-sphere (B·N,) and per-replica (B,) arrays, in the order :meth:`concat` copies them
    SPHERE_ARRAYS = ("x", "y", "vx", "vy", "omega", "phi", "r", "m", "inertia", "fx", "fy", "torque")
    REPLICA_ARRAYS = ("Lx", "Ly", "gamma", "rate", "t", "k", "nu", "k_t", "nu_t", "mu", "c", "prc", "prt", "keep")

    #: per-sphere parameters (see above); a class default, so a state pickled without it loads as shared
    visit = None
    #: the ensemble whose sphere rows this state's per-sphere arrays are (:meth:`of_ensemble`), else None
    ensemble = None

    def __init__(self, B, N, backend="numpy"):
        self.backend = get_backend(backend)
        xp = self.xp = self.backend.xp
        self.B = int(B)
        self.N = int(N)
        n = self.B * self.N
        # positions and velocities as row views of two blocks: one gather fetches all rows of a pair side
        self.pos = xp.zeros((2, n))
        self.vel = xp.zeros((3, n))
        self.frc = xp.zeros((3, n))            # (F_x, F_y, torque) of the last force phase
        self._views()
        for name in ("phi", "r", "m", "inertia"):
            setattr(self, name, xp.zeros(n))
        for name in self.REPLICA_ARRAYS:
            setattr(self, name, xp.zeros(self.B))
        self.rep = xp.repeat(xp.arange(self.B), self.N)
        self.pairs = [None] * self.B
        self.rng = [None] * self.B
        self.next_birth = np.zeros(self.B, np.int64)
        self.applying_shear = True
        self.law = None
        self.law_params = xp.zeros((0, self.B))
        self.visit = None

    def __getstate__(self):
        """Pickle and copy by backend name (a module is not picklable); the row views are rebound on load."""
        state = dict(self.__dict__)
        state["backend"] = self.backend.name
        del state["xp"]
        state.pop("ensemble", None)      # a copy is no longer the ensemble's rows
        return state

    def __setstate__(self, state):
        self.__dict__.update(state)
        self.backend = get_backend(state["backend"])
        self.xp = self.backend.xp
        self._views()

    def _views(self):
        """Row views of the position, velocity and force blocks (indexing, not iteration: no host read)."""
        self.x, self.y = self.pos[0], self.pos[1]
        self.vx, self.vy, self.omega = self.vel[0], self.vel[1], self.vel[2]
        self.fx, self.fy, self.torque = self.frc[0], self.frc[1], self.frc[2]

    def to_backend(self, backend):
        """This state with its arrays copied to ``backend`` (the same object if it is there already).

        Pair lists and generators are shared (they stay on the host).

        Parameters
        ----------
        backend : str or Backend
            The target backend.

        Returns
        -------
        BatchState
        """
        target = get_backend(backend)
        if target is self.backend:
            return self
        from .xp import to_host
        out = object.__new__(type(self))
        out.__dict__.update(self.__dict__)
        out.backend, out.xp = target, target.xp
        out.ensemble = None        # copies, no longer an ensemble's rows
        for name in ("pos", "vel", "frc", "phi", "r", "m", "inertia", "rep", "law_params") + self.REPLICA_ARRAYS:
            out.__dict__[name] = target.asarray(to_host(getattr(self, name), "state"))
        if self.visit is not None:
            out.visit = target.asarray(to_host(self.visit, "state"))
        out._views()
        return out

    @classmethod
    def from_ensembles(cls, ensembles, backend="numpy", laws=None):
        """Copy B ensembles of equal N (after constitution) into one batch state.

        The ensembles are not modified; each replica keeps a reference to its ensemble's
        random generator, so the random normals of ``d = 0`` continue its stream.

        Parameters
        ----------
        ensembles : sequence of ensemble
            Constituted ensembles (``particleShear.objects`` or ``particleShear.linkable``
            ensembles), all with the same number of spheres.
        backend : str or Backend, default "numpy"
            Where the arrays of the state live: the ensembles are read on the host and the
            state is copied to the device once.
        laws : sequence, optional
            The central law of each ensemble: ``None`` (the documented callback) or
            ``(name, values)``, a name of :data:`~particleShear.engine.laws.LAWS` and its
            parameter values in order (:func:`~particleShear.engine.laws.law_values`).  One law
            per batch; the values may differ between replicas.  Default: None for every one.

        Returns
        -------
        BatchState
            Replica b holds ``ensembles[b]``: spheres, box, strain, rate, clock, constants and
            the relations and bonds of its pair table.

        Raises
        ------
        ValueError
            If the ensembles differ in N, or their laws differ, or for an unusable backend (before
            any copy).
        """
        target = get_backend(backend)
        laws = [None] * len(ensembles) if laws is None else list(laws)
        names = {None if law is None else law[0] for law in laws}
        if len(laws) != len(ensembles) or len(names) > 1:
            raise ValueError(f"laws={laws!r} is invalid: one law per ensemble, the same law for every one "
                             "(its parameters may differ)")
        Ns = {len(e.sphereList) for e in ensembles}
        if len(Ns) != 1:
            raise ValueError(f"ensembles have N = {sorted(Ns)}: a batch needs one N")
        B, N = len(ensembles), Ns.pop()
        s = cls(B, N)
        own = [not uniform_parameters(e) for e in ensembles]     # spheres with parameters of their own
        if any(own):
            s.visit = np.zeros((len(_PER_REPLICA), B * N))
        for b, e in enumerate(ensembles):
            a = e._a
            rows = slice(b * N, (b + 1) * N)
            for name, src in (("x", "x"), ("y", "y"), ("vx", "xspeed"), ("vy", "yspeed"), ("omega", "omega"),
                              ("phi", "phi"), ("r", "r"), ("m", "m"), ("inertia", "inertia"),
                              ("fx", "xforce"), ("fy", "yforce"), ("torque", "torque")):
                getattr(s, name)[rows] = a[src][:N]
            s.Lx[b], s.Ly[b] = float(e.size_x), float(e.size_y)
            s.gamma[b], s.rate[b], s.t[b] = float(e.shear), float(e.shear_rate), float(e.t)
            # a frictionless ensemble of particleShear.objects has no tangential constants: 0
            s.k[b], s.nu[b], s.k_t[b], s.nu_t[b], s.mu[b] = (float(e.k), float(e.nu), float(getattr(e, "k_t", 0.0)),
                                                             float(getattr(e, "nu_t", 0.0)), float(getattr(e, "mu", 0.0)))
            for name, src, empty in zip(_PER_REPLICA, PER_SPHERE_PARAMETERS, (0.0, 1.0, 1.0, 1.0)):
                getattr(s, name)[b] = float(a[src][0]) if N else empty
            if own[b]:
                s.visit[:, rows] = [np.asarray(a[src][:N], dtype=float) for src in PER_SPHERE_PARAMETERS]
            pt = e._pairs
            keep = pt.active | (pt.state == PERMANENT)
            s.pairs[b] = ReplicaPairs(pt.i[keep], pt.j[keep], pt.state[keep], pt.xi[:, keep], pt.d_eq[keep],
                                      pt.active[keep], pt.birth[keep])
            s.next_birth[b] = pt._births
            s.rng[b] = e._rng
        if any(own):
            shared = np.repeat(np.logical_not(own), N)
            s.visit[:, shared] = s.per_replica_parameters()[:, shared]
        s.law = names.pop() if names else None
        if s.law is not None:
            s.law_params = np.array([law[1] for law in laws], dtype=float).reshape(B, -1).T.copy()
        return s.to_backend(target)

    @classmethod
    def of_ensemble(cls, ensemble, laws=None):
        """The state of one ensemble as a batch of one whose per-sphere arrays are the ensemble's
        own rows (no copy): what the engine's steps write, the ensemble holds.

        Positions, φ, velocities, forces, radii, masses and moments of inertia are views of the
        ensemble's state block (``ens._pos``, ``_vel``, ``_frc`` and the rows of ``_a``); the box,
        strain, rate, clock, constants, per-sphere parameters (which a step only reads) and the
        pair list are copied as by :meth:`from_ensembles`.  The views stay valid while the
        ensemble gains no sphere (an append can move its block).

        Parameters
        ----------
        ensemble : ensemble
            A documented ensemble of ``particleShear.objects`` or ``particleShear.linkable``.
        laws : sequence, optional
            As :meth:`from_ensembles` (one entry).

        Returns
        -------
        BatchState
            B = 1 on NumPy, with :attr:`ensemble` set to ``ensemble``.
        """
        s = cls.from_ensembles([ensemble], laws=laws)
        a = ensemble._a
        s.pos, s.vel, s.frc = ensemble._pos, ensemble._vel, ensemble._frc
        s.phi, s.r, s.m, s.inertia = a["phi"], a["r"], a["m"], a["inertia"]
        s._views()
        s.ensemble = ensemble
        return s

    @classmethod
    def concat(cls, states):
        """One state holding the replicas of ``states`` in order (equal N).

        Parameters
        ----------
        states : sequence of BatchState
            States with the same N; their arrays are copied, their pair lists and generators
            shared.

        Returns
        -------
        BatchState
            ``sum(st.B)`` replicas; plates active only if they are in every state.

        Raises
        ------
        ValueError
            If the states differ in N or in backend.
        """
        Ns = {st.N for st in states}
        if len(Ns) != 1:
            raise ValueError(f"states have N = {sorted(Ns)}: a batch needs one N")
        backends = {st.backend.name for st in states}
        if len(backends) != 1:
            raise ValueError(f"states live on the backends {sorted(backends)}: a batch needs one backend")
        laws = {st.law for st in states}
        if len(laws) != 1:
            raise ValueError(f"states have the laws {sorted(map(str, laws))}: a batch needs one law")
        out = cls(sum(st.B for st in states), Ns.pop(), backend=states[0].backend)
        xp = out.xp
        for name in cls.SPHERE_ARRAYS + cls.REPLICA_ARRAYS:
            getattr(out, name)[...] = xp.concatenate([getattr(st, name) for st in states])
        out.pairs = [p for st in states for p in st.pairs]
        out.rng = [g for st in states for g in st.rng]
        out.next_birth = np.concatenate([st.next_birth for st in states])
        out.applying_shear = all(st.applying_shear for st in states)
        out.law = laws.pop()
        out.law_params = xp.concatenate([st.law_params for st in states], axis=1)
        if any(st.visit is not None for st in states):
            out.visit = xp.concatenate([st.visit_rows() for st in states], axis=1)
        return out

    def per_replica_parameters(self):
        """The per-replica parameters ``c, prc, prt, keep`` on every sphere row: a (4, B·N) array.

        Returns
        -------
        ndarray (4, B·N)
        """
        return self.xp.stack([getattr(self, name) for name in _PER_REPLICA])[:, self.rep]

    def visit_rows(self):
        """The parameters of :data:`PER_SPHERE_PARAMETERS` of every sphere: :attr:`visit`, or the
        per-replica values on every row when the spheres of each replica share them.

        Returns
        -------
        ndarray (4, B·N)
        """
        return self.per_replica_parameters() if self.visit is None else self.visit

    def replica(self, b):
        """Row slice of replica ``b`` in the per-sphere arrays.

        Parameters
        ----------
        b : int
            Replica index (0 … B−1; not checked).

        Returns
        -------
        slice
            Rows ``b·N … b·N + N − 1``.
        """
        return slice(b * self.N, (b + 1) * self.N)
