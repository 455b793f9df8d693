"""Layout of the per-sphere state block (fields × spheres): the engine's
(:data:`particleShear.engine.state.FIELDS`), which a batch of ensembles shares."""
__docformat__ = "numpy"

from ..engine.state import FIELDS, ROW

__all__ = ["FIELDS", "ROW"]
