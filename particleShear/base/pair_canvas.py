"""Canvases with pairs: the pair table, the O(N) neighbour update and the Lees-Edwards cell (docs/design.md).

=========================================  ==============================================
``CanvasPointsNeighbors``                  pair table and the O(N) neighbour update
``CanvasPointsShear``                      Lees-Edwards offset, plates, shear rate
=========================================  ==============================================

The candidate search, the Verlet bound and the minimum image are the engine's
(:mod:`particleShear.engine.neighbours`, :mod:`particleShear.engine.box`); the geometry of a step's
pairs is computed once per force phase (:meth:`CanvasPointsNeighbors.test_neighbor_relation`).
"""
__docformat__ = "numpy"
import math
import numpy as np
from .kernels import le_wrap, min_image, pair_geometry
from .namespace import (bincount as _bincount, concatenate as _concat, copyto as _copyto,
                        count_nonzero as _nz, where as _where)
from ..engine.integrate import kick, plates_follow
from ..engine.forces import pair_roles
from ..engine.terms import pair_forces
from ..engine.neighbours import verlet_bound
from .neighbours import PERMANENT, STICK, PairTable, candidate_pairs
from .register import PairBlock
from .relations import _BaseRelationView

from .canvas import CanvasPointsMass, _max_reduce
from .points import PointLeesEdwards

__all__ = ["CanvasPointsNeighbors", "CanvasPointsShear"]


class _Structure:
    """Arrays over the pairs of the step that stay valid while the candidates, bonds and images do (and, for
    a compacted table, the set of relations); kept in the canvas's memo under ``key``."""
    __slots__ = ("key", "safe_images", "sel", "sel2", "ai", "aj", "d0", "ri", "rj", "w2", "idx6",
                 "ky", "kyf", "kx", "any_y", "perm", "trans", "deq", "perm_code", "shifted", "view")


class _Geometry:
    """Per-step arrays over the active pairs (positions at the start of the step).

    The per-structure arrays (``ai``, ``aj``, ``d0``, ``perm``, ``trans``, ``ri``, ``rj``) are copied in
    from the structure's ``view`` dictionary and the flags ``internal``, ``ext_i``, ``ext_j`` from the memo;
    what the force terms compute on first use starts as the class default None."""
    fn_i = fn_j = ft = vn = vt = fel = rv = None
    parts = None       # [(term, f_i, f_j)] of the central terms, for the register's per-visit lists
    ft_visits = None   # (2, P) scalar forces of the two tangential visits (0.0: all slipped at μ = 0)
    all_slip = False   # set when the μ = 0 tangential path made every relation slip (no ξ to integrate)

    # components of the pair vector and normal, for inspection (the kernels use the (2, P) arrays)
    dx = property(lambda self: self.D[0])
    dy = property(lambda self: self.D[1])
    nx = property(lambda self: self.n[0])
    ny = property(lambda self: self.n[1])

class CanvasPointsNeighbors(CanvasPointsMass):
    """Adds the pair table and the neighbour update (relations = contacts ∪ permanent links).

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    #: extra search distance of the candidate list, in units of the largest radius
    neighbour_skin = 0.5
    #: candidate tables at least this long are compacted to the active pairs each time relations change;
    #: shorter ones run every term over all candidates (per-call overhead dominates there)
    compact_pairs_from = 20000

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsMass.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self._pairs = PairTable()
        self._nl_valid = False
        self._g = None
        self._relation_view_class = _BaseRelationView
        self._disp = np.zeros((2, 0))
        self._nl_strain = 0.0
        self._nl_abs_strain = 0.0
        self._links_version = 0
        self._relations_version = 0   # changes whenever the step's neighbour update changes the relations
        self._images_token = 0

    def _invalidate_neighbours(self):
        self._nl_valid = False
        self._pos_version += 1
        self._in_cell = False
        self._images_valid = False
        self._drop_engine()

    def _links_changed(self):
        self._pairs.n_permanent = int((self._pairs.state == PERMANENT).sum())
        self._links_version += 1
        self._engine_pairs = None       # the step's engine rebuilds its candidates from the table

    def _drop_engine(self):
        """Forget the step's engine (canvases with a force law: :mod:`particleShear.base.engine_view`)."""

    def _spheres_changed(self):
        self._nl_valid = False
        self._in_cell = False
        self._pos_version += 1
        self._disp = np.zeros((2, self._n))

    def _drift(self, dt, spin=False):
        """Move every sphere by ``v·dt`` (and turn it by ``ω·dt`` with ``spin``) and accumulate its
        displacement relative to the affine flow.

        The Verlet criterion works with displacements *relative to the shear flow*
        ``γ̇ (y − Ly/2)``: under Lees-Edwards the flow carries neighbours along with
        each other, so only peculiar motion (plus the small affine stretch of a
        pair, bounded through the accumulated strain) can bring a far pair into contact.
        """
        rate = float(self._shear_rate_for_images())
        if rate:
            dg = rate * dt
            self._disp[0] -= self._y_centred() * dg
            self._nl_strain += dg
            self._nl_abs_strain += abs(dg)
        if spin:
            step = self._vel * dt
            self._coord += step
            self._disp += step[:2]
        else:
            step = self._vel[:2] * dt
            self._pos += step
            self._disp += step
        self._pos_version += 1

    def _skin(self):
        return self.neighbour_skin * float(self._a["r"].max()) if self._n else 0.0

    def _needs_rebuild(self):
        if not self._nl_valid:
            return True
        # how much a pair can have approached since the rebuild: the engine's bound of the peculiar
        # displacements U and the accumulated |strain| (engine.neighbours.verlet_bound), plus any strain
        # change not carried by the flow (e.g. γ set directly), which moves boundary images by Ly·Δγ
        d2 = self._disp * self._disp
        U = math.sqrt(float(_max_reduce(d2[0] + d2[1]))) if self._n else 0.0
        bound = verlet_bound(U, self._nl_abs_strain, self._nl_rmax)
        bound += abs(self._le_shift() - self._nl_shift - float(self.size_y) * self._nl_strain)
        return bound >= self._nl_skin or (self.size_x, self.size_y) != self._nl_box

    def _rebuild_candidates(self):
        a = self._a
        x = a["x"].copy()
        y = a["y"].copy()
        shift = self._le_shift()
        le_wrap(x, y, np.zeros(self._n), self.size_x, self.size_y, shift, 0.0)
        skin = self._skin()
        i, j = candidate_pairs(x, y, a["r"], self.size_x, self.size_y, shift, skin)
        self._pairs.replace(i, j)
        self._nl_valid = True
        self._nl_skin = skin
        self._nl_shift = shift
        self._nl_box = (self.size_x, self.size_y)
        self._nl_rmax = float(a["r"].max()) if self._n else 0.0
        self._nl_strain = 0.0
        self._nl_abs_strain = 0.0
        self._disp[:] = 0.0

    def _shear_rate_for_images(self):
        return 0.0

    def _store_images(self, ky, kx, n):
        """Keep the period counts of the candidates' minimum images while they stay valid.

        Valid until a sphere wraps, the candidates change or positions are set from
        outside; only for positions inside the cell, single periods, and cells much
        larger than the candidate reach (so the nearest image cannot change).
        """
        self._images_valid = False
        if not self._in_cell or not self._nl_valid:
            return
        reach = 2 * (2 * float(self._a["r"].max()) + 2 * self._nl_skin)
        if min(self.size_x, self.size_y) <= reach:
            return
        if ky is None:
            return
        # period counts as floats too: a float times a float array avoids a per-call cast
        self._images = (ky, ky.astype(float), kx, np.array((float(self.size_x) * kx, float(self.size_y) * ky)))
        self._images_any_y = bool(_nz(ky))
        self._images_version = self._pairs.version
        self._images_valid = True

    def test_neighbor_relation(self):
        """Neighbour update (docs/design.md): activate touching pairs, drop transient ones that separated.

        Also computes the geometry of the active pairs that every force term of
        this step uses.  What depends only on *which* pairs are active (indices,
        contact distances, bond flags, image periods, internal/external flags) is
        kept from the previous step while that set, the bonds and the images stay
        the same — most steps.
        """
        pt = self._pairs
        if self._needs_rebuild():
            self._rebuild_candidates()
        pos = self._pos
        C = len(pt.i)
        Lx, Ly = self.size_x, self.size_y
        r = self._a["r"]
        T = pos.take(_concat((pt.j, pt.i)), axis=1)
        D0 = T[:, :C] - T[:, C:]   # raw differences (x_j − x_i, y_j − y_i)
        cached_images = self._images_valid and self._images_version == pt.version
        dvx_rate = 0.0
        if cached_images:
            # no sphere wrapped since the images were found: reuse their period counts (minimum image,
            # one period at a time, so bit-identical to a fresh minimum image)
            ky, kyf, kx, LK = self._images
            D = D0   # fresh array; the raw differences are not needed again on this path
            if self._images_any_y:
                D[0] -= float(self._le_shift()) * kyf
                dvx_rate = float(self._shear_rate_for_images())
            D -= LK
            dvx = None
        else:
            dx, dy, dvx, ky, kx = min_image(D0[0], D0[1], Lx, Ly, self._le_shift(), self._shear_rate_for_images(),
                                            counts=True)
            D = np.array((dx, dy))
            self._store_images(ky, kx, C)
            self._images_token += 1
        DD = D * D
        d = np.sqrt(DD[0] + DD[1])
        d0 = r[pt.i] + r[pt.j]   # contact distances r_i + r_j
        touching = d < d0
        perm = pt.state == PERMANENT if pt.n_permanent else None
        new_active = touching if perm is None else (touching | perm)
        old = pt.active
        # most steps keep every relation: a byte comparison of the masks is cheaper than != and a count
        changed = new_active.tobytes() != old.tobytes()
        if changed:
            flip = new_active != old
            # relations born or ended: stick state, no history; the born ones get the next birth numbers
            pt.state[flip] = STICK
            _copyto(pt.xi, 0.0, where=flip)
            born = new_active & flip
            n_born = _nz(born)
            if n_born:
                pt.birth[born] = pt.next_births(n_born)
            pt.active = new_active
            self._relations_version += 1
        # Small tables (overhead-bound): every force term runs over all candidate pairs, inactive ones
        # getting exactly zero force (ξ = 0, law = 0 beyond contact, viscous terms masked), so nothing
        # is gathered per step.  Large tables (throughput-bound): the terms run over the active pairs only.
        compact = C >= self.compact_pairs_from
        # the pair structure depends on the candidates, the bonds, the image periods and, for a compacted
        # table, on the relations themselves
        key = (pt.version, self._links_version, self._images_token, compact,
               self._relations_version if compact else None)
        S = self._memo.get("pair_structure", key,
                           lambda: self._pair_structure(new_active if compact else None, d0, perm, ky, kx, D0, D, d,
                                                        cached_images, key))
        mob, mob_bytes = self._mobile()
        g = _Geometry()
        g.S = S
        g.__dict__.update(S.view)
        g.internal, g.ext_i, g.ext_j = self._memo.get("internal_flags", (key, mob_bytes),
                                                      lambda: self._internal_flags(S, mob))
        sel = S.sel
        if sel is None:
            g.slots = slice(None)
            g.active = new_active
            g.touching = touching
        else:
            g.slots = sel
            g.active = None            # every pair of the step is a relation
            D = D.take(sel, axis=1)
            d = d.take(sel)
            g.touching = touching.take(sel)
            if dvx is not None:
                dvx = dvx.take(sel)
        g.P = C = len(d)
        if _nz(d) != C:
            d, nx, ny = pair_geometry(D[0], D[1], self._rng)
            g.n = np.array((nx, ny))
        else:
            g.n = D / d
        g.t = t = np.empty((2, C))   # t_ij = (−n_y, n_x)
        np.negative(g.n[1], out=t[0])
        t[1] = g.n[0]
        g.D = D
        g.d = d
        if dvx is not None:
            g.dvx = dvx
        elif dvx_rate and S.any_y:
            g.dvx = -(float(Ly) * dvx_rate) * S.kyf
        else:
            g.dvx = None
        self._g = g
        return g

    @staticmethod
    def _internal_flags(S, mob):
        """(internal, ext_i, ext_j) of the pairs of structure ``S`` for mobility mask ``mob`` (None: all
        mobile), by the engine's rule (:func:`~particleShear.engine.forces.pair_roles`)."""
        if mob is None:
            return pair_roles(True, True, S.shifted)
        return pair_roles(mob.take(S.ai), mob.take(S.aj), S.shifted)

    def _pair_structure(self, active, d0, perm, ky, kx, D0, D, d, cached_images, key):
        """Per-pair data that change only when the candidates, bonds or images change — or, for a
        table compacted to its ``active`` pairs, when the set of relations changes (``key``, its memo key,
        is kept as ``S.key`` for the values derived from the structure)."""
        pt = self._pairs
        r = self._a["r"]
        n = self._n
        S = _Structure()
        S.key = key
        if active is None:
            S.sel = S.sel2 = None
            S.ai = pt.i
            S.aj = pt.j
        else:
            S.sel = sel = np.flatnonzero(active)
            S.sel2 = _concat((sel, sel + len(pt.i)))   # flat slots of (ξ_ij, ξ_ji) in the (2, C) table
            S.ai = pt.i.take(sel)
            S.aj = pt.j.take(sel)
            d0 = d0.take(sel)
            D0 = D0.take(sel, axis=1)
            D = D.take(sel, axis=1)
            d = d.take(sel)
            if ky is not None:
                ky = ky.take(sel)
                kx = kx.take(sel)
            if perm is not None:
                perm = perm.take(sel)
        S.d0 = d0
        S.ri = r.take(S.ai)
        S.rj = r.take(S.aj)
        S.w2 = np.array((S.ri, S.rj)) / S.d0   # torque lever fractions r_i/(r_i + r_j), r_j/(r_i + r_j) (S1-3)
        # flat bincount index of (x, y, torque) rows: one call accumulates every pair force on the spheres
        S.idx6 = _concat((S.ai, S.ai + n, S.aj, S.aj + n, S.ai + 2 * n, S.aj + 2 * n))
        S.ky = ky
        S.kyf = None if ky is None else ky.astype(float)
        S.kx = kx
        S.any_y = ky is not None and bool(_nz(ky))
        if perm is None or not _nz(perm):
            S.perm = S.trans = S.deq = S.perm_code = None
        else:
            S.perm = perm
            S.trans = ~perm
            S.deq = pt.d_eq.copy() if S.sel is None else pt.d_eq.take(S.sel)   # equilibrium distances of the bonds
            S.perm_code = perm.view(np.int8) * np.int8(PERMANENT)             # state code of a bond, 0 elsewhere
        # a pair interacts through the boundary iff its raw and minimum-image distances differ;
        # with cached images the cell is much larger than a contact, so any period applied means that
        if ky is None:
            shifted = (D != D0).any(axis=0)
        else:
            shifted = (ky != 0) | (kx != 0)
        if not cached_images and _nz(shifted):
            w = np.nonzero(shifted)[0]
            rx, ry = D0[0].take(w), D0[1].take(w)
            shifted[w] = np.sqrt(rx * rx + ry * ry) != d.take(w)
        S.shifted = shifted
        # what every step's geometry takes over from the structure
        # (not S itself: a structure referring to itself would wait for the cyclic collector)
        S.view = {"ai": S.ai, "aj": S.aj, "d0": S.d0, "perm": S.perm, "trans": S.trans,
                  "ri": S.ri, "rj": S.rj}
        # the cell is much larger than the candidate reach: a pair's nearest image cannot change within a step
        S.safe_images = bool(self._images_valid)
        return S

    # -- pair-force accumulation -----------------------------------------------------------------
    def _geometry(self):
        if not isinstance(self._g, _Geometry):     # none yet, or an engine force phase's
            self.test_neighbor_relation()
        return self._g

    def _add_normal(self, f_i, f_j=None, term="elastic"):
        """Add scalar central forces along n_ij: ``f_i`` on i, ``f_j`` (default ``f_i``) on j (reversed).

        The first term is kept by reference (terms never modify their results afterwards); each term is
        also noted by name for the register's per-visit lists (built only when read)."""
        g = self._g
        if g.parts is None:
            g.parts = []
        g.parts.append((term, f_i, f_j))
        if f_j is None and g.fn_j is None:
            g.fn_i = f_i if g.fn_i is None else g.fn_i + f_i
            return
        if g.fn_i is None:
            g.fn_i = np.zeros(g.P)
        if g.fn_j is None:
            g.fn_j = g.fn_i
        g.fn_i = g.fn_i + f_i
        g.fn_j = g.fn_j + (f_i if f_j is None else f_j)

    @staticmethod
    def _flush_arrays(P, spin):
        """The flat force array of a flush and its views: F_i, F_j (2, P), torques (2P,) and (2, P)."""
        W = np.empty((6 if spin else 4) * P)
        T = W[4 * P:] if spin else None
        return (W, W[:2 * P].reshape(2, P), W[2 * P:4 * P].reshape(2, P), T,
                None if T is None else T.reshape(2, P))

    def _flush_pair_forces(self):
        """Apply the collected pair forces to the spheres and put them into the force register.

        Forces on i and j and the tangential torques go into one flat array, in contiguous (2, P)
        blocks F_i, F_j, (t_i, t_j), that a single ``bincount`` adds to the (xforce, yforce, torque)
        rows of the state block.
        """
        g = self._g
        if g is None:
            return
        n = self._n
        P = g.P
        S = g.S
        spin = g.ft is not None
        fa = self._flush_arrays(P, spin)
        W = fa[0]
        Fi = fa[1]
        Fj = fa[2]
        antisymmetric = g.fn_j is None
        # F_i = f_n·n + f_t·t and the torques d·f_t·(r_i, r_j)/(r_i + r_j) (eq. S1-3): the engine's pair_forces
        nx, ny = g.n[0], g.n[1]
        fx, fy, _, tq = pair_forces(0.0 if g.fn_i is None else g.fn_i, g.ft, nx, ny, g.d, S.w2)
        Fi[0] = fx
        Fi[1] = fy
        if antisymmetric:
            np.negative(Fi, out=Fj)
        else:
            fx, fy = pair_forces(g.fn_j, g.ft, nx, ny, g.d, None)[:2]
            np.negative(fx, out=Fj[0])
            np.negative(fy, out=Fj[1])
        ti = tj = None
        if spin:
            Wt = fa[4]
            Wt[...] = tq
            ti = Wt[0]   # indexing, not tuple unpacking (iterating an array is slow)
            tj = Wt[1]
        if P:
            k = 3 if spin else 2
            idx = S.idx6 if spin else S.idx6[:4 * P]
            self._frc[:k] += _bincount(idx, W, k * n).reshape(k, n)
        self.force_register._set_pairs(self, PairBlock({
            "i": g.ai, "j": g.aj, "Fi": Fi, "Fj": Fj,
            "ti": ti, "tj": tj, "internal": g.internal, "ext_i": g.ext_i,
            "ext_j": g.ext_j, "active": g.active, "antisymmetric": antisymmetric, "engine": True, "D": g.D,
            "pos_version": self._pos_version,
            # per-visit terms for the reference lists of the register (read only when asked for)
            "visits": (g.parts, g.ft_visits, g.n, g.t, g.d, S.w2, g.touching, g.perm, self._pairs.birth,
                       g.slots)}))
        g.fn_i = None
        g.fn_j = None
        g.ft = None
        g.parts = None
        g.ft_visits = None

    def _term_done(self):
        self._flush_pair_forces()

    # -- views and scalar helpers for the API ------------------------------------------------------
    def _relations_of(self, p):
        pt = self._pairs
        m = pt.active & ((pt.i == p) | (pt.j == p))
        slots = np.flatnonzero(m)
        slots = slots[np.argsort(pt.birth[slots], kind="stable")]
        partners = _where(pt.i[slots] == p, pt.j[slots], pt.i[slots])
        cls = self._relation_view_class
        return [cls(self, p, int(q)) for q in partners]

    def _relations_edited(self):
        """The one place that drops every kept value (docs/design.md, "The documented classes"): relations were changed
        outside the step's neighbour update (the per-sphere API, a batched constitution), which no counter
        of the memo keys records."""
        self._memo.invalidate()
        self._engine_pairs = None

    @property
    def _struct(self):
        """The pair structure of the last neighbour update (None before the first one or after
        :meth:`_relations_edited`), for inspection."""
        return self._memo.peek("pair_structure")

    def _drop_relations_of(self, p):
        self._relations_edited()
        if self._g is not None:
            self._g.all_slip = False
        pt = self._pairs
        m = pt.active & ((pt.i == p) | (pt.j == p)) & (pt.state != PERMANENT)
        pt.active[m] = False
        pt.xi_ij[m] = 0.0
        pt.xi_ji[m] = 0.0

    def _pair_d(self, p, q):
        a = self._a
        dx, dy, _ = min_image(np.array([a["x"][q] - a["x"][p]]), np.array([a["y"][q] - a["y"][p]]),
                              self.size_x, self.size_y, self._le_shift())
        return float(np.sqrt(dx * dx + dy * dy)[0])

    def _test_pair(self, p, q):
        """Neighbour test of one pair (the scalar ``test_neighbor_relation(theSphere)`` API)."""
        self._relations_edited()
        if self._g is not None:
            self._g.all_slip = False
        a = self._a
        touching = self._pair_d(p, q) < a["r"][p] + a["r"][q]
        pt = self._pairs
        s = int(pt.find(p, q))
        if touching:
            s = int(pt.ensure(p, q)[0])
            if not pt.active[s]:
                pt.active[s] = True
                pt.state[s] = STICK
                pt.xi_ij[s] = pt.xi_ji[s] = 0.0
                pt.birth[s] = pt.next_births(1)[0]
        elif s >= 0 and pt.active[s] and pt.state[s] != PERMANENT:
            pt.active[s] = False
            pt.xi_ij[s] = pt.xi_ji[s] = 0.0

    def contact_pairs(self):
        """Sphere indices (i, j), i < j, of the current relations (contacts and links)."""
        pt = self._pairs
        return pt.i[pt.active].copy(), pt.j[pt.active].copy()


class CanvasPointsShear(CanvasPointsNeighbors):
    """Adds the shear strain ``shear`` (γ), its rate ``shear_rate`` (1/s) and the moving plates.

    Parameters
    ----------
    size_x, size_y : float
        Cell size Lx, Ly (µm), finite and > 0.
    theCanvas : object or bool
        Tk canvas of the live window (False when none).
    doDrawing : bool
        Whether the spheres are drawn.
    m : float
        Default sphere mass (mg per m depth), stored as ``m`` (each sphere carries its own mass).

    Raises
    ------
    ValueError
        If ``size_x`` or ``size_y`` is not a finite number > 0.
    """

    use_lees_edwards = True

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsNeighbors.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self.t = 0
        self.applyingShear = False
        self.shear_rate = 0
        self.shear = 0

    def canMove(self, theSphere):
        """During shear, spheres overlapping y = 0 or y = Ly are glued to the plates (docs/design.md).

        Parameters
        ----------
        theSphere : object
            A sphere of this ensemble.

        Returns
        -------
        bool
            True if the sphere moves freely.
        """
        if not self.applyingShear:
            return True
        return theSphere.r < theSphere.y < self.size_y - theSphere.r

    def _mobile(self):
        """(mask of the mobile spheres ``r < y < Ly − r``, its bytes) while shearing, else (None, None).

        The bytes are the memo key of what is derived from the mask (the pairs' internal flags, the
        selection of the mobile spheres), kept while the plates hold the same spheres."""
        if not self.applyingShear:
            return None, None
        y = self._pos[1]
        r = self._a["r"]
        mob = r < y
        mob &= y < self.size_y - r
        return mob, mob.tobytes()

    def do_linear_acceleration(self, dt):
        """Kick mobile spheres; immobile ones take the velocity of their plate.

        Every sphere is kicked and the plate velocity then overwrites the
        immobile ones, which gives the mobile spheres exactly the reference kick.

        Parameters
        ----------
        dt : float
            Time step (s), finite and > 0.
        """
        kick(self._vel[:2], self._frc[:2], self._a["m"], dt)
        self._plates_follow()

    def _plates_follow(self):
        """Immobile (plate) spheres take the velocity ±γ̇·Ly/2 of their plate and no y velocity (docs/design.md)."""
        mob = self._mobile_mask()
        if mob is None:
            return
        a = self._a
        plates_follow(a["xspeed"], a["yspeed"], ~mob, self._y_centred(), self.shear_rate * self.size_y / 2)

    def transmit_lees_edwards_parameters(self, theSphere):
        """Copy the cell size, strain, rate and Lees-Edwards flag to a sphere.

        Parameters
        ----------
        theSphere : object
            The sphere that receives them.
        """
        PointLeesEdwards.transmit_lees_edwards_parameters(self, theSphere)   # the one hand-over (reads attributes only)

    def _le_shift(self):
        return self.size_y * self.shear if self.use_lees_edwards else 0.0

    def _shear_rate_for_images(self):
        return self.shear_rate if self.use_lees_edwards else 0.0

    def _source_is_external(self, target, source):
        dx = source.x - target.x
        dy = source.y - target.y
        return math.sqrt(dx ** 2 + dy ** 2) != target.d(source)
