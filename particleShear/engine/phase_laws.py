"""The laws of one force phase: the run's contact law, or the law callbacks the state was given.

:func:`force_phase_laws` looks the central and tensile laws of a force phase up once: the state's
``contact_law`` of the registry (:data:`.laws.LAWS`, its parameters per replica), else what the
state's ``callback_laws`` says (the documented classes' law callbacks, given by the adapter that
built the state from ensembles, :mod:`particleShear.base.callbacks`); a state without either runs
the built-in laws from the prepared constants.  The engine imports no layer of the documented
classes (docs/classes.md, "The documented classes").

Forces in mg·µm·s⁻² per m depth; negative = repulsion.
"""
__docformat__ = "numpy"

from .contact_laws import get_law

__all__ = ["force_phase_laws", "run_law", "law_function", "law_arguments", "cached"]


def cached(C, key, make):
    """The per-candidate arguments of a law, kept with the candidates' constants ``C`` under ``key``
    (dropped with ``C`` at the one invalidation point, a rebuild of the candidate lists).

    Parameters
    ----------
    C : PairConstants or VisitConstants
        The constants of one visit of the candidates (holds the entry ``law_args``).
    key : hashable
        What the arguments depend on besides ``C`` (the law's name and its parameters).
    make : callable
        ``make()`` builds the arguments when the kept ones are for another key.

    Returns
    -------
    object
        What ``make()`` returned for ``key``.
    """
    got = C.__dict__.get("law_args")
    if got is None or got[0] != key:
        got = (key, make())
        C.__dict__["law_args"] = got
    return got[1]


def force_phase_laws(s, C):
    """The central and tensile laws of one force phase of the engine, looked up once per phase.

    The central law is the state's ``s.law`` (a run's ``contact_law``, its parameters per
    replica in ``s.law_params``) when set, else the central law of ``s.callback_laws``; the
    tensile law of bonds is that of ``s.callback_laws``.  ``s.callback_laws`` is None (the
    built-in laws) or ``callback_laws(C, central)`` returning ``(central or None, tensile or None)``
    (the documented classes' callbacks: :func:`particleShear.base.callbacks.callback_phase_laws`).

    Parameters
    ----------
    s : BatchState
        The batch (``law``, ``law_params``, ``callback_laws``).
    C : PairConstants or VisitConstants
        The constants of one visit of its candidates (``rep``, ``k``, ``c``, ``d_law``, ``d_eq``,
        ``perm``; :class:`~particleShear.engine.forces.VisitConstants` for the visit from j of
        spheres with parameters of their own).

    Returns
    -------
    central : callable or None
        ``central(d)``: the compressive law of every candidate as if in contact; None for the
        linear law, which :func:`~particleShear.engine.terms.elastic_term` evaluates from the
        prepared constants of ``C``.
    tensile : callable or None
        ``tensile(d)``: the tensile law on the stretched bonds (0 elsewhere); None for the
        built-in one (prepared constants).
    """
    given = getattr(s, "callback_laws", None)
    central, tensile = (None, None) if given is None else given(C, s.law is None)
    if s.law is not None:
        got = run_law(s, C)
        central = None if got is None else _bound(*got)
    return central, tensile


def _bound(function, arguments):
    """``function(d, *arguments)`` as a function of ``d``."""
    return lambda d: function(d, *arguments)


def run_law(s, C):
    """The run's contact law on the candidates ``C`` as ``(function, arguments)``: the compressive law
    of every candidate at ``d`` is ``function(d, *arguments)``; None for the linear law (evaluated
    from the prepared constants of ``C``) or a state without a run's law.

    For a law with ``prepared`` constants, ``function`` is its ``inside`` and ``arguments`` the
    constants (kept with ``C``, :func:`cached`); otherwise the law's function and
    :func:`law_arguments` with its parameters per candidate.  The NumPy force phase and the
    compiled step (:mod:`.numba_step`) both evaluate the law from these.

    Parameters
    ----------
    s : BatchState
        The batch (``law``, ``law_params``).
    C : PairConstants or VisitConstants
        The constants of one visit of its candidates.

    Returns
    -------
    tuple or None
    """
    if s.law is None:
        return None
    law = get_law(s.law)
    if law.name == "linear" and not law.parameters:
        return None
    return law_function(law, C, (law.name, id(s.law_params)),
                        lambda: law_arguments(law, C) + tuple(s.law_params[:, C.rep]))


def law_arguments(law, C):
    """The arguments of a central law after ``d`` and before its own parameters, per candidate:
    ``(d0, r_i, r_j, k, c)`` for a law of the laws folder (``law.radii``), else ``(d0, k, c)``.

    Parameters
    ----------
    law : ContactLaw
        A registered law (:data:`~particleShear.engine.laws.LAWS`).
    C : PairConstants or VisitConstants
        The constants of one visit of the candidates.

    Returns
    -------
    tuple of ndarray
        Contact distance d0 (µm), radii (µm) when the law reads them, k (mg·s⁻² per m depth), c.
    """
    return (C.d_law, C.ri, C.rj, C.k, C.c) if law.radii else (C.d_law, C.k, C.c)


def law_function(law, C, key, arguments):
    """``law`` on the candidates ``C`` as ``(function, arguments)``: ``inside`` and its constants kept
    with ``C`` under ``key`` when the law is prepared, else ``law.function`` and ``arguments()``.

    Parameters
    ----------
    law : ContactLaw
        A registered law.
    C : PairConstants or VisitConstants
        The constants of one visit of the candidates.
    key : hashable
        The key of the kept arguments (:func:`cached`).
    arguments : callable
        ``arguments()``: :func:`law_arguments` and the law's parameters, per candidate.

    Returns
    -------
    tuple
        ``(function, arguments)``: the central force of every candidate at ``d`` is
        ``function(d, *arguments)`` (mg·µm·s⁻² per m depth, negative repels).
    """
    if law.prepared is None:
        return law.function, cached(C, key, arguments)
    constants, inside = law.prepared
    return inside, cached(C, key, lambda: constants(*arguments()))
