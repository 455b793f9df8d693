"""particleShear: 2D soft, frictional, crosslinkable particles under oscillatory Lees-Edwards shear.

``from particleShear import *`` exposes the documented classes and functions of
every layer (base → objects → linkable → simulation → run).  Messages go through the
:mod:`logging` logger ``"particleShear"`` (see :mod:`particleShear.messages`).
"""
__docformat__ = "numpy"
import logging as _logging

_logging.getLogger(__name__).addHandler(_logging.NullHandler())

from .base import *  # noqa: F401,F403,E402
from .base import __all__ as _base_all  # noqa: E402
from .objects import *  # noqa: F401,F403,E402
from .objects import __all__ as _objects_all  # noqa: E402
from .linkable import *  # noqa: F401,F403,E402
from .linkable import __all__ as _linkable_all  # noqa: E402

from ._version import __version__  # noqa: E402
__all__ = list(_base_all) + list(_objects_all) + list(_linkable_all)

from .simulation import *  # noqa: F401,F403,E402
from .simulation import __all__ as _simulation_all  # noqa: E402
from .run import *  # noqa: F401,F403,E402
from .run import __all__ as _run_all  # noqa: E402
from .sweep import Sweep, run_sweep  # noqa: F401,E402

__all__ += list(_simulation_all) + list(_run_all) + ["Sweep", "run_sweep"]
