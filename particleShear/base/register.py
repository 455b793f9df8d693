"""Force register: the forces and torques the stress tensors sum (eqs. S1-16 to S1-24; docs/classes.md).

The engine stores a force phase as arrays; the six reference lists (``pair_register`` …) are built
from them on demand, and manual ``record_*`` calls (scripts without an ensemble) append to them.
"""
__docformat__ = "numpy"

import collections
import itertools

import numpy as np

from ..engine.forces import pair_roles
from ..engine.terms import pair_forces
from ..engine.xp import to_host

__all__ = ["Force_register", "KeptTerms", "SphereSelection", "TermRecord", "register_block"]


class TermRecord(collections.namedtuple("TermRecord", "C parts F dx dy nx ny d touching active shifted mob fx_i fy_i "
                                                      "fx_j fy_j dF tq birth totals")):
    """The per-candidate terms of an engine's last force phase, as the force register reads them.

    Made from the terms an engine with :attr:`~particleShear.engine.step.BatchEngine.keep_terms`
    hands to its :attr:`~particleShear.engine.step.BatchEngine.terms_to` (a dict of the same names,
    held by :class:`KeptTerms`) by :meth:`Force_register.set_from_engine`.  The record type lives
    here, beside its only reader, rather than in the engine: the engine hands the arrays out as
    plain values and knows nothing of the register's layout (the layers go engine → base, never back).

    Attributes
    ----------
    C : PairConstants
        The candidates' constants of the phase (:class:`~particleShear.engine.forces.PairConstants`).
    parts : tuple of two lists
        Per visit (i's, j's; j's empty without per-sphere parameters), the elastic and viscous
        central scalars.
    F : array (2, P)
        The tangential forces of the two visits.
    dx, dy, nx, ny, d : array (P,)
        Pair vectors (µm), unit normals and distances (µm).
    touching, active : array of bool (P,)
        Contacts and relations.
    shifted : array of bool (P,)
        Pairs whose j is an image across a periodic boundary.
    mob : array of bool (B·N,)
        The mobility mask of the phase.
    fx_i, fy_i, fx_j, fy_j : array (P,) or None
        The forces on i and (per-sphere parameters only; else None) on j.
    dF, tq : array
        The tangential scalar and the torques (2, P) of the pair.
    birth : array of int (P,)
        The creation numbers of the relations.
    totals : array (3, B·N)
        The forces and torques of every sphere after the phase.
    """
    __slots__ = ()


def register_block(t, N, b, tangential=True):
    """The force register's block of replica ``b`` of a force phase whose terms an engine kept
    (what :attr:`~particleShear.engine.step.BatchEngine.terms_to` received with
    :attr:`~particleShear.engine.step.BatchEngine.keep_terms` on), in the layout the
    documented classes' register (:class:`Force_register`) reads.

    Per candidate of the replica (local sphere indices ``i < j``): the forces on i and j, the
    torques, the internal and external flags (:func:`~particleShear.engine.forces.pair_roles`),
    the relations, the pair vectors, and per visit the elastic and viscous scalars, the two
    tangential visits' forces, normals, tangents, distances, lever fractions, contacts, bonds
    and creation numbers, from which the six reference lists are built when read.

    Parameters
    ----------
    t : TermRecord or None
        The record of the force phase (:class:`TermRecord` of the terms the engine handed out).
    N : int
        Spheres per replica.
    b : int
        Replica index (0 … B−1).
    tangential : bool, default True
        The replica's ensemble has the tangential term (its register lists tangential visits
        and torques, zero forces where μ = 0 and no bond).

    Returns
    -------
    dict
        The block's arrays (on the host); None before a force phase that kept its terms.  The
        replica's totals and mobility the register takes from ``t.totals`` and ``t.mob`` itself.
    """
    if t is None:
        return None
    C = t.C
    lo, hi = int(C.offsets[b]), int(C.offsets[b + 1])
    h = lambda a: None if a is None else to_host(a, "register")[..., lo:hi]   # noqa: E731
    ai, aj = h(C.ai) - b * N, h(C.aj) - b * N
    mob = to_host(t.mob, "register")[b * N:(b + 1) * N]
    internal, ext_i, ext_j = pair_roles(mob[ai], mob[aj], h(t.shifted))
    Fi = np.array((h(t.fx_i), h(t.fy_i)))
    Fj = -Fi if t.fx_j is None else -np.array((h(t.fx_j), h(t.fy_j)))
    nx, ny = h(t.nx), h(t.ny)
    el_i, v_i = (h(a) for a in t.parts[0])
    el_j, v_j = (h(a) for a in t.parts[1]) if t.parts[1] else (None, None)
    tq = h(t.tq) if tangential else None
    return {"i": ai, "j": aj, "Fi": Fi, "Fj": Fj, "ti": None if tq is None else tq[0],
            "tj": None if tq is None else tq[1], "internal": internal, "ext_i": ext_i, "ext_j": ext_j,
            "active": h(t.active), "antisymmetric": t.fx_j is None, "engine": True,
            "D": np.array((h(t.dx), h(t.dy))),
            "visits": ([("elastic", el_i, el_j), ("viscous", v_i, v_j)], h(t.F) if tangential else None,
                       np.array((nx, ny)), np.array((-ny, nx)), h(t.d), h(C.w), h(t.touching), h(C.perm),
                       h(t.birth), slice(None))}


class PairBlock(dict):
    """Engine register block of per-pair arrays; ``fix`` … ``fjy`` are rows of ``Fi``/``Fj``, made on first use."""

    _ROWS = {"fix": ("Fi", 0), "fiy": ("Fi", 1), "fjx": ("Fj", 0), "fjy": ("Fj", 1)}

    def __missing__(self, key):
        if key in self._ROWS:
            name, row = self._ROWS[key]
            value = self[name][row]
            self[key] = value
            return value
        raise KeyError(key)


class KeptTerms:
    """The receiver of an engine's kept terms: ``BatchEngine(..., keep_terms=True, terms_to=KeptTerms())``.

    The engine hands the per-term arrays of its force phases to it as they end (a value, as
    HOOMD-blue's writers take theirs; the engine keeps none); it holds the last, for a documented
    ensemble's force register (:meth:`Force_register.set_from_engine`).

    Attributes
    ----------
    last : dict or None
        The terms of the last force phase handed over (None before the first).
    """
    __slots__ = ("last",)

    def __init__(self):
        self.last = None

    def __call__(self, terms):
        """Hold ``terms`` (a dict of arrays by name), the last force phase's."""
        self.last = terms


class EngineForcePhase:
    """Force phase of replica ``b`` of an engine, held by a register (which does not keep the engine alive).

    ``block``: its register block (:func:`register_block`), made when read.

    Parameters
    ----------
    terms : TermRecord
        The record of the terms the engine handed out for the phase (made from what a
        :class:`KeptTerms` holds).
    N, b, pos_version : int
        Spheres per replica; the replica; the ensemble's position version of the phase (−1: moved since).
    tangential, one_host_replica : bool
        The ensemble has the tangential term; the engine is a host batch of one (arrays are the replica's rows).
    """
    __slots__ = ("terms", "N", "b", "tangential", "pos_version", "one_host_replica", "block")

    def __init__(self, terms, N, b, tangential, pos_version, one_host_replica):
        self.terms, self.N, self.b, self.tangential = terms, N, b, tangential
        self.pos_version, self.one_host_replica = pos_version, one_host_replica
        self.block = None


def _invalidating(name):
    method = getattr(list, name)

    def changed(self, *args, **kwargs):
        """The ``list`` method of this name; afterwards the selection no longer follows its mask.

        Parameters
        ----------
        *args, **kwargs
            Those of the ``list`` method.
        """
        self._valid = False   # contents no longer follow the mask: evaluated sphere by sphere
        return method(self, *args, **kwargs)

    changed.__name__ = name
    return changed


class SphereSelection(list):
    """The spheres of an ensemble picked by ``mask``, as a list in index order (``movableSphereList()``).

    It also tells the stress evaluation which array rows it holds, so tensors are summed as
    arrays; changing it (``append``, ``sel[k] = …`` …) keeps it a list and drops that link.

    Parameters
    ----------
    ensemble : object
        The ensemble (a canvas of :mod:`particleShear.base.canvas`).
    mask : numpy.ndarray of bool or None
        One flag per sphere of ``sphereList``; None selects all.
    spheres : list or None
        The selected spheres when already known; None takes them from ``ensemble.sphereList``.
    """

    def __init__(self, ensemble, mask=None, spheres=None):
        if spheres is None:
            sl = ensemble.sphereList
            flags = None if mask is None else np.asarray(mask, dtype=bool).ravel()
            if flags is not None and flags[len(sl):].any():
                raise IndexError(f"mask selects sphere {int(np.flatnonzero(flags)[-1])} of {len(sl)} spheres")
            spheres = sl if flags is None else itertools.compress(sl, flags.tolist())
        list.__init__(self, spheres)
        self.ensemble = ensemble
        self.mask = mask
        self._valid = True

    def is_current(self):
        """True while the selection holds exactly the spheres of ``mask`` in the ensemble as it is now."""
        if not self._valid:
            return False
        n = len(self.ensemble.sphereList)
        if self.mask is None:
            return len(self) == n
        return len(self.mask) == n

    def copy(self):
        """A shallow copy: a selection with the same mask while still current, else a plain list."""
        return SphereSelection(self.ensemble, self.mask, self) if self._valid else list(self)

    for _name in ("append", "extend", "insert", "remove", "pop", "clear", "sort", "reverse", "__setitem__",
                  "__delitem__", "__iadd__", "__imul__"):
        locals()[_name] = _invalidating(_name)
    del _name


def record_method(name, owner, body, summary):
    """A ``record_*`` method of 1.0.2's signature that calls ``body(self, target, source, value)``.

    The signature is ``(self, target, source, value)`` for a pair entry (``record_individual_*``), else
    ``(self, target, value)`` (``body`` then gets ``source = None``), with the value named
    ``force_vector`` for a force (a name ending in ``force``) and ``moment`` for a torque, so keyword
    calls work as documented.

    Parameters
    ----------
    name, owner : str
        The method's name and its class's name.
    body : callable
        ``body(self, target, source, value)``: what the method does.
    summary : str
        The docstring's first paragraph; the parameters' section is added.

    Returns
    -------
    function
        The method, named and documented.
    """
    pair, force = name.startswith("record_individual"), name.endswith("force")
    if pair and force:
        def method(self, target, source, force_vector):
            body(self, target, source, force_vector)
    elif pair:
        def method(self, target, source, moment):
            body(self, target, source, moment)
    elif force:
        def method(self, target, force_vector):
            body(self, target, None, force_vector)
    else:
        def method(self, target, moment):
            body(self, target, None, moment)
    method.__name__, method.__qualname__ = name, f"{owner}.{name}"
    targets = ("target, source : Sphere\n    The sphere acted on; the sphere exerting the force or torque.\n" if pair
               else "target : Sphere\n    The sphere acted on.\n")
    value = ("force_vector : sequence of float\n    ``(F_x, F_y)`` (mg·µm·s⁻² per m depth).\n" if force
             else "moment : float\n    Torque (mg·µm²·s⁻² per m depth).\n")
    method.__doc__ = f"{summary}\n\nParameters\n----------\n{targets}{value}"
    return method


def _manual_entry(name, store):
    """What the register's manual ``record_*`` method ``name`` does: an entry ``[target, (source,) value]``
    appended to the list ``store`` (the total force and the net torque: set per target in the dict)."""
    force, pair = name.endswith("force"), name.startswith("record_individual")

    def body(self, target, source, value):
        self._manual = True
        entry = [target] + ([source] if pair else []) + [list(value) if force else value]
        if store in ("_m_tot", "_m_unb"):
            getattr(self, store)[id(target)] = entry
        else:
            getattr(self, store).append(entry)
    return body


class Force_register:
    """Per-step record of internal pair forces, external forces and torques."""

    def __init__(self):
        self.reset_force_register()

    def __reduce__(self):
        """Copy and pickle as an empty register (as at the start of a force phase): what it holds is
        the record of a force phase of the original's engine, which a copy does not have."""
        return Force_register, ()

    def reset_force_register(self):
        """Clear everything (start of each force phase)."""
        self._ens = None
        self._block_list = []
        self._phase = None      # the engine force phase held (EngineForcePhase), its block made when read
        self._tot = None
        self._mom = None
        self._lists = None
        if getattr(self, "_manual", True):     # the lists of the manual record_* calls, emptied once used
            self._manual = False
            self._m_pair, self._m_ext, self._m_imom, self._m_emom = [], [], [], []
            self._m_tot, self._m_unb = {}, {}

    # -- engine side -------------------------------------------------------------------------
    @property
    def _blocks(self):
        """The per-pair array blocks: that of the engine force phase held, made when first read."""
        ph = self._phase
        if ph is not None and ph.block is None:
            ph.block = PairBlock(register_block(ph.terms, ph.N, ph.b, tangential=ph.tangential))
            self._block_list.insert(0, ph.block)
        return self._block_list

    def engine_phase(self):
        """The engine force phase if it is all the register holds (the stresses then read arrays), else None."""
        ph = self._phase
        if ph is None or self._manual or len(self._block_list) != (ph.block is not None):
            return None
        return ph

    def _set_totals(self, ensemble, mobile, fx, fy, torque):
        self._ens = ensemble
        self._tot = (mobile, fx, fy)
        self._mom = torque

    def set_from_engine(self, ensemble, engine, terms, b=0, current=False):
        """Hold a force phase (pairs, totals) of replica ``b``; return False, changing nothing, if none.

        Parameters
        ----------
        ensemble : ensemble
            The ensemble of the replica (its spheres are the lists' entries).
        engine : BatchEngine
            The engine of the phase (its batch's N and B, its backend).
        terms : dict or None
            The terms the engine handed to its ``terms_to`` for the phase (:class:`KeptTerms`
            ``.last``; None: no phase).
        b : int, default 0
            The replica.
        current : bool, default False
            The phase is of the ensemble's present positions (a force phase just run on them, its
            spheres not moved since): the stresses may then read the phase's pair vectors.  False
            (after whole steps of the engine, whose last movement followed the phase): they are
            evaluated anew.  The caller says it, since the engine keeps no record of its phases.
        """
        if terms is None:
            return False
        t = TermRecord(**terms)
        spin = ensemble._torque_total() is not None
        N = engine.s.N
        mobile = to_host(t.mob, "register")[b * N:(b + 1) * N]
        tot = to_host(t.totals, "register")[:, b * N:(b + 1) * N]
        self.reset_force_register()
        # the register's pair vectors are those of the force phase, while the spheres have not moved
        self._phase = EngineForcePhase(t, N, b, spin, ensemble._pos_version if current else -1,
                                       engine.s.B == 1 and engine.backend.host)
        self._set_totals(ensemble, mobile, tot[0], tot[1], tot[2] if spin else None)
        return True

    # -- manual API (reference signatures) ----------------------------------------------------
    for _name, _store, _doc in (
            ("record_individual_internal_force", "_m_pair", "Append an internal pair force to "
             ":attr:`pair_register` (Love-Weber, eq. S1-19)."),
            ("record_total_particle_force", "_m_tot", "Set the total force of ``target`` in "
             ":attr:`total_particle_force_register` (eq. S1-17)."),
            ("record_external_force", "_m_ext", "Append a force from a plate sphere or through the boundary "
             "to :attr:`external_force_register` (eq. S1-16)."),
            ("record_external_torque", "_m_emom", "Append an external tangential torque to "
             ":attr:`external_moment_register` (unused by the tensors)."),
            ("record_individual_internal_torque", "_m_imom", "Append an internal tangential torque to "
             ":attr:`internal_moment_register` (eq. S1-22)."),
            ("record_unbalanced_moment", "_m_unb", "Set the net torque of ``target`` in "
             ":attr:`unbalanced_moment_register` (eq. S1-22).")):
        locals()[_name] = record_method(_name, "Force_register", _manual_entry(_name, _store), _doc)
    del _name, _store, _doc

    # -- reference lists, built on demand ---------------------------------------------------------
    def _engine_lists(self):
        """The engine part of the six reference lists, built once per force phase when first read."""
        cache = self.__dict__.get("_lists")
        if cache is not None and cache[0] is self._blocks and cache[1] == len(self._blocks):
            return cache[2]
        out = {"pair": [], "ext": [], "imom": [], "emom": []}
        for p in self._blocks:
            _visit_entries(p, self._ens.sphereList, out)
        self._lists = (self._blocks, len(self._blocks), out)
        return out

    @property
    def pair_register(self):
        """``[target, source, [F_x, F_y]]`` per internal pair force, in the reference's order (docs/classes.md)."""
        return self._engine_lists()["pair"] + self._m_pair

    @property
    def external_force_register(self):
        """``[target, [F_x, F_y]]`` per force from an immobile sphere or through the periodic boundary."""
        return self._engine_lists()["ext"] + self._m_ext

    @property
    def internal_moment_register(self):
        """``[target, source, M]`` per internal tangential torque, two per tangential visit."""
        return self._engine_lists()["imom"] + self._m_imom

    @property
    def external_moment_register(self):
        """``[target, M]`` per external tangential torque (stored, never used by a tensor)."""
        return self._engine_lists()["emom"] + self._m_emom

    @property
    def total_particle_force_register(self):
        """``[sphere, [F_x, F_y]]``: the total force of every mobile sphere, in ``sphereList`` order."""
        out = []
        if self._tot is not None:
            mobile, fx, fy = self._tot
            sl = self._ens.sphereList
            idx = range(len(fx)) if mobile is None else np.flatnonzero(mobile).tolist()
            fx, fy = fx.tolist(), fy.tolist()
            out = [[sl[k], [fx[k], fy[k]]] for k in idx]
        return out + list(self._m_tot.values())

    @property
    def unbalanced_moment_register(self):
        """``[sphere, T]``: the net torque of every sphere, immobile ones included (reference quirk)."""
        out = []
        if self._mom is not None:
            sl = self._ens.sphereList
            out = [[sl[k], t] for k, t in enumerate(self._mom.tolist())]
        return out + list(self._m_unb.values())


def _visit_entries(p, sl, out):
    """Append the reference entries of one engine register block to the lists in ``out`` (docs/classes.md).

    Each pair is visited from i (side 0) and from j (side 1), ordered by visitor, relation birth,
    partner.  Central terms give one entry per visit on the visitor, a tangential visit ``±F/2·t``
    on the visitor and its neighbour (torques of eq. S1-3 likewise).  An entry on an immobile target
    is dropped; one from an immobile source or through the boundary is external.
    """
    i_all, j_all = p["i"], p["j"]
    if not len(i_all) or "visits" not in p:
        return
    parts, F, n, _, d, w2, touching, perm, birth, slots = p["visits"]
    active = p.get("active")
    ks = np.arange(len(i_all)) if active is None else np.flatnonzero(active)
    if not len(ks):
        return
    b = (birth[slots] if isinstance(slots, slice) else birth.take(slots))[ks]
    i, j = i_all[ks], j_all[ks]
    visitor = np.concatenate((i, j))
    partner = np.concatenate((j, i))
    side = np.repeat((0, 1), len(ks))
    order = np.lexsort((partner, np.concatenate((b, b)), visitor))
    vk = np.concatenate((ks, ks))[order]      # pair of each visit, in visit order
    vs = side[order]                          # 0: visit from i, 1: visit from j
    internal, ext_i, ext_j = p["internal"], p["ext_i"], p["ext_j"]
    interacting = touching if perm is None else (touching | perm)   # elastic and tangential visits happen
    # per (pair, side-of-target): where an entry on that target goes (1 internal, 2 external, 0 dropped)
    dest = np.zeros((2, len(i_all)), dtype=np.int8)
    dest[0][ext_i] = 2
    dest[1][ext_j] = 2
    dest[0][internal] = 1
    dest[1][internal] = 1
    dest = dest.tolist()

    def emit(kind, k, s_target, target, source, value):
        dd = dest[s_target][k]
        if dd == 1:
            out["pair" if kind == "F" else "imom"].append([sl[target], sl[source], value])
        elif dd == 2:
            out["ext" if kind == "F" else "emom"].append([sl[target], value])

    nx, ny = n[0].tolist(), n[1].tolist()
    ii, jj = i_all.tolist(), j_all.tolist()
    visits = list(zip(vk.tolist(), vs.tolist()))
    inter = interacting.tolist()
    for term, f_i, f_j in (parts or ()):
        scal_i = _as_list(f_i, len(i_all))
        scal_j = scal_i if f_j is None else _as_list(f_j, len(i_all))
        for k, s in visits:
            if term == "elastic" and not inter[k]:
                continue   # transient relation beyond contact: no elastic force applied, nothing registered
            if s == 0:
                f = scal_i[k]
                emit("F", k, 0, ii[k], jj[k], [nx[k] * f, ny[k] * f])
            else:
                f = scal_j[k]
                emit("F", k, 1, jj[k], ii[k], [-nx[k] * f, -ny[k] * f])
    if F is None:
        return
    # each visit applies half its force: +F/2·t_ij on i, −F/2·t_ij on j, torques d·F/2·r/(r_i + r_j) (eq. S1-3)
    F = np.broadcast_to(F, (2, len(i_all)))
    halves = []
    for side in (0, 1):
        fx, fy, _, tq = pair_forces(0.0, F[side] * 0.5, n[0], n[1], d, w2)
        halves.append((fx.tolist(), fy.tolist(), tq[0].tolist(), tq[1].tolist()))
    for k, s in visits:
        if not inter[k]:
            continue   # transient relation beyond contact: no tangential force
        fx, fy, ti, tj = halves[s]
        fi = [fx[k], fy[k]]
        fj = [-fx[k], -fy[k]]
        mi, mj = ti[k], tj[k]
        if s == 0:   # visit from i: the entry on i, then on its neighbour j
            emit("F", k, 0, ii[k], jj[k], fi)
            emit("F", k, 1, jj[k], ii[k], fj)
            emit("M", k, 0, ii[k], jj[k], mi)
            emit("M", k, 1, jj[k], ii[k], mj)
        else:        # visit from j (force along t_ji = −t_ij on j): j first, then i
            emit("F", k, 1, jj[k], ii[k], fj)
            emit("F", k, 0, ii[k], jj[k], fi)
            emit("M", k, 1, jj[k], ii[k], mj)
            emit("M", k, 0, ii[k], jj[k], mi)


def _as_list(f, P):
    """Per-pair scalars of a term as a Python list (zeros for a term noted without force)."""
    if f is None:
        return [0.0] * P
    return np.broadcast_to(np.asarray(f, dtype=float), (P,)).tolist()
