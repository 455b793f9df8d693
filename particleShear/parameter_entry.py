"""One entry of the parameter table: :class:`Parameter` (below the engine and the table).

The contact laws of :mod:`particleShear.engine.contact_laws` declare their parameters with it where
they are written, and :mod:`particleShear.parameters` composes the table of the run from the base
entries and every law's; both import this module, which imports only :mod:`particleShear.checks`.
"""
__docformat__ = "numpy"
import dataclasses

from .checks import range_text as _range_text

__all__ = ["Parameter", "ROLES", "KINDS"]

#: the roles of a parameter (module docstring); ``law:<name>`` and ``protocol:<a>,<b>`` carry names
ROLES = ("model", "law", "protocol", "numerics", "output", "display", "call", "observer")
#: the value types: ``float``, ``int``, ``bool``, ``str`` (with ``choices``), ``float_list``, ``seed``
#: (None, an integer, a SeedSequence or a Generator), ``path``, ``callable``
KINDS = ("float", "int", "bool", "str", "float_list", "seed", "path", "callable")


@dataclasses.dataclass(frozen=True)
class Parameter:
    """One keyword of ``doParticleShearSimulation`` (module docstring).

    Parameters
    ----------
    name : str
        The keyword (1.0.2's name).
    default : object
        Its default.
    kind : str
        One of :data:`KINDS`.
    unit : str, default ""
        Unit of a number ("1" dimensionless, "" for the other kinds and the integers).
    low, high : float or None, default None
        Allowed range of a number (None: no limit here; limits that depend on other parameters —
        ``N``, ``cut_lines``, the steps per period — are the validation's).
    low_open, high_open : bool, default False
        The limit itself is excluded.
    choices : tuple of str or None, default None
        The allowed values of a ``str`` parameter.
    role : str, default "model"
        One of :data:`ROLES`, with ``:<names>`` for a law's or a protocol's own parameters.
    batch : {"replica", "schedule", "shared"}, default "replica"
        How runs that differ in it share a batch (module docstring).
    keyword_only : bool, default False
        Keyword-only in the signature (the options added after 1.0.2).
    nullable : bool, default False
        None is a value (its default, meaning "derived" or "required by its protocol").
    doc : str, default ""
        One line: what it is, with units.
    extra : bool, default False
        Not a keyword of ``doParticleShearSimulation``'s signature: a parameter of a contact law
        other than the plateau law, taken by its ``**law_parameters`` (and by every run entry
        point, the command line and the SPEC keys, all derived from the table).
    since : str, default ""
        The version that added it ("" for the parameters of 2.0.0).  A parameter added later is
        in a run's identity only when it differs from its default, so the runs of a folder written
        before it existed keep their ids (and a missing column of it means its default).
    """

    name: str
    default: object
    kind: str
    unit: str = ""
    low: object = None
    high: object = None
    low_open: bool = False
    high_open: bool = False
    choices: object = None
    role: str = "model"
    batch: str = "replica"
    keyword_only: bool = False
    nullable: bool = False
    doc: str = ""
    extra: bool = False
    since: str = ""

    @property
    def base_role(self):
        """The role without its names (``"protocol:creep"`` → ``"protocol"``)."""
        return self.role.partition(":")[0]

    @property
    def role_names(self):
        """The names after the role's colon (``"protocol:relaxation,creep"`` → ``("relaxation", "creep")``)."""
        return tuple(n for n in self.role.partition(":")[2].split(",") if n)

    @property
    def has_range(self):
        """True when the table states a range (``low`` or ``high``)."""
        return self.low is not None or self.high is not None

    def range_text(self):
        """The allowed range in the one wording of every range message (:func:`particleShear.checks.range_text`)."""
        return _range_text(self.low, self.high, self.low_open, self.high_open)
