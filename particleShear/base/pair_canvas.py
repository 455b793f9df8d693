"""Canvases with pairs: the pair table, the neighbour update and the Lees-Edwards cell (docs/classes.md)."""
__docformat__ = "numpy"
import numpy as np
from ..engine import box as _box
from ..engine.integrate import kick, mobile_mask, plates_follow
from ..engine.predictor import Predictor
from .neighbours import PERMANENT, STICK, PairTable
from .relations import _BaseRelationView

from .canvas_base import CanvasPointsMass, ReplicaValue
from .engine_view import EngineStep
from .point_base import PointLeesEdwards

__all__ = ["CanvasPointsNeighbors", "CanvasPointsShear"]


class CanvasPointsNeighbors(EngineStep, CanvasPointsMass):
    """Adds the pair table (the engine's ``PairTable``) and the neighbour update (contacts ∪ links).

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing, m
        As for :class:`~particleShear.base.canvas.CanvasPointsMass`.
    """

    #: Verlet skin of the neighbour lists in units of the largest radius (``run.batch.ENGINE_SKIN_FACTOR``)
    neighbour_skin = 0.2

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsMass.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self._pairs = PairTable()
        self._predictor = Predictor()     # the Verlet predictor its engines continue (state_of_ensembles)
        self._g = None
        self._relation_view_class = _BaseRelationView

    def _invalidate_neighbours(self):
        self._pos_version += 1
        self._drop_engine()

    def invalidate_caches(self):
        """Forget everything derived from the spheres and the pair table (neighbour list, the step's
        engine, the links' count, the last force phase's geometry), after they were changed in
        place from outside the ensemble: by an engine on its own state
        (:func:`~particleShear.base.engine_adapter.state_of_ensembles`) or when such a run is undone
        (:func:`~particleShear.base.engine_adapter.untouched_on_failure`).  The next step starts
        from the spheres and the table as they are."""
        self._invalidate_neighbours()
        self._links_changed()
        self._relations_edited()
        self._g = None

    def _links_changed(self):
        self._pairs.n_permanent = int((self._pairs.state == PERMANENT).sum())
        self._engine_pairs = None       # the step's engine rebuilds its candidates from the table

    def move(self, dt=1):
        self._engine_move_spheres(dt)

    def test_neighbor_relation(self):
        """Neighbour update: activate touching pairs (sticking, ξ = 0), drop transient ones that separated."""
        eng = self._step_engine()
        self._hand_to_engine(eng)
        eng.relations()
        self._take_relations(eng)

    # -- views and scalar helpers for the API ------------------------------------------------------
    def _relations_of(self, p):
        pt = self._pairs
        slots = pt.relations_of(p)
        partners = np.where(pt.i[slots] == p, pt.j[slots], pt.i[slots])
        return [self._relation_view_class(self, p, int(q)) for q in partners]

    def _relations_edited(self):
        """Relations were changed outside the step: the next force phase takes the candidates from the table."""
        self._engine_pairs = None

    def _drop_relations_of(self, p):
        self._relations_edited()
        self._pairs.close_relations(self._pairs.relations_of(p))

    def _image(self, dx, dy):
        """``(dx, dy, ky, kx)`` of one raw difference (µm): its minimum image and the periods removed."""
        return _box.min_image(np.array([dx]), np.array([dy]), self.size_x, self.size_y, self._le_shift())

    def _test_pair(self, p, q):
        """Neighbour test of one pair (the per-sphere ``test_neighbor_relation(theSphere)``)."""
        self._relations_edited()
        a = self._a
        dx, dy = self._image(a["x"][q] - a["x"][p], a["y"][q] - a["y"][p])[:2]
        touching = float(np.sqrt(dx * dx + dy * dy)[0]) < a["r"][p] + a["r"][q]
        pt = self._pairs
        s = int(pt.find(p, q))
        if touching:      # a new relation starts sticking, without history (as in the step)
            new = pt.open_relations(pt.ensure(p, q))
            pt.state[new] = STICK
            pt.xi[:, new] = 0.0
        elif s >= 0:
            pt.close_relations(s)

    @property
    def pair_table(self):
        """A copy of the ensemble's pair table: its candidate pairs and their relation history.

        Returns
        -------
        PairTable
            An independent :class:`~particleShear.engine.state.PairTable` (sphere indices
            ``i < j``, ``state``, ``xi`` (µm), ``d_eq`` (µm), ``active``, ``birth`` and the counter
            :attr:`~particleShear.engine.state.PairTable.birth_count`) as of this read; editing
            it leaves the ensemble alone (relations are edited through the spheres and their
            ``neighbors``).
        """
        return self._pairs.copy()

    def contact_pairs(self):
        """Sphere indices (i, j), i < j, of the current relations (contacts and links)."""
        pt = self._pairs
        return pt.i[pt.active].copy(), pt.j[pt.active].copy()


class CanvasPointsShear(CanvasPointsNeighbors):
    """Adds the shear strain ``shear`` (γ), its rate ``shear_rate`` (1/s) and the moving plates.

    Parameters
    ----------
    size_x, size_y, theCanvas, doDrawing, m
        As for :class:`~particleShear.base.canvas.CanvasPointsMass`.
    """

    use_lees_edwards = True
    #: the strain γ and its rate γ̇ (1/s)
    shear = ReplicaValue()
    shear_rate = ReplicaValue()

    def __init__(self, size_x, size_y, theCanvas=False, doDrawing=False, m=1):
        CanvasPointsNeighbors.__init__(self, size_x, size_y, theCanvas, doDrawing, m)
        self.applyingShear = False
        self.shear_rate = 0
        self.shear = 0

    def canMove(self, theSphere):
        return not self.applyingShear or bool(mobile_mask(theSphere.r, theSphere.y, self.size_y))

    def _mobile_mask(self):
        """The mask ``r < y < Ly − r`` while shearing, else None."""
        return mobile_mask(self._a["r"], self._pos[1], self.size_y) if self.applyingShear else None

    def do_linear_acceleration(self, dt):
        kick(self._vel[:2], self._frc[:2], self._a["m"], dt)
        mob = self._mobile_mask()
        if mob is not None:     # plate spheres take the velocity ±γ̇·Ly/2 of their plate and no y velocity
            a = self._a
            plates_follow(a["xspeed"], a["yspeed"], ~mob, self._y_centred(), self.shear_rate * self.size_y / 2)

    transmit_lees_edwards_parameters = PointLeesEdwards.transmit_lees_edwards_parameters   # reads attributes only

    def _le_shift(self):
        return self.size_y * self.shear if self.use_lees_edwards else 0.0

    def _through_boundary(self, target, source):
        # the visit's own image from target to source, as the per-sphere terms take it (MODEL_SPEC 3.5)
        ky, kx = self._image(source.x - target.x, source.y - target.y)[2:]
        return bool(ky[0] != 0 or kx[0] != 0)
