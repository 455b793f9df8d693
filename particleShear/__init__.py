"""particleShear: 2D soft, frictional, crosslinkable particles under oscillatory Lees-Edwards shear.

``from particleShear import *`` exposes the documented classes and functions of
every layer (base → objects → linkable → simulation → run).
"""
__docformat__ = "numpy"
from .base import *  # noqa: F401,F403
from .base import __all__ as _base_all
from .objects import *  # noqa: F401,F403
from .objects import __all__ as _objects_all
from .linkable import *  # noqa: F401,F403
from .linkable import __all__ as _linkable_all

__version__ = "2.0.0"
__all__ = list(_base_all) + list(_objects_all) + list(_linkable_all)

try:
    from .simulation import *  # noqa: F401,F403
    from .simulation import __all__ as _simulation_all
    __all__ += list(_simulation_all)
    from .run import *  # noqa: F401,F403
    from .run import __all__ as _run_all
    __all__ += list(_run_all)
    from .sweep import Sweep, run_sweep  # noqa: F401
    __all__ += ["Sweep", "run_sweep"]
except ImportError:  # pragma: no cover - during development only
    pass
