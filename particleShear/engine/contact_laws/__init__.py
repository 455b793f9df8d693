"""The contact laws, one file each: every module of this folder is a law, found at import.

A law's file holds the law ``law(d, d0, r_i, r_j, k, c, *own parameters)`` on arrays (the central
force on i along ``n_ij`` as if the pair were in contact, mg·µm·s⁻² per m depth, negative repels;
``d`` centre distance, ``d0`` contact distance, ``r_i``, ``r_j`` radii, all in µm; ``k`` spring
constant in mg·s⁻² per m depth; ``c`` repulsion coefficient), its parameters declared as
:class:`particleShear.parameter_entry.Parameter` entries of role ``law:<name>`` (``PARAMETERS``:
default, unit, range, one-line doc) and its registration (``LAW = register_law(...)``, with
``radii=True, built_in=True``).  Importing this package imports every module of the folder
(:mod:`pkgutil`), so the shipped laws — and a file saved here — are known in every process that
imports particleShear, spawn workers included; :mod:`particleShear.parameters` composes their
parameters into the run's table (:func:`declared_parameters`), from which validation, the command
line, the SPEC keys, the results columns and the run identity follow (docs/design.md, "Adding a
contact law").

Optional module constants: ``POSITION`` (the order of ``contact_law``'s choices: lowest first,
then by name) and ``SIGNATURE`` (True: the parameters are keywords of
``doParticleShearSimulation``'s signature — the plateau law's, as in 2.0.0; other laws' parameters
are taken by its ``**law_parameters``).

Shipped: ``linear`` (the default, 1.0.2's law), ``plateau``, ``hertz``.
"""
__docformat__ = "numpy"

import importlib
import math
import pkgutil

from ..laws import LAWS, ContactLaw, get_law, law_names, law_values, register_law

__all__ = ["LAWS", "ContactLaw", "get_law", "law_names", "law_values", "register_law", "MODULES",
           "declared_parameters"]


def _discover():
    """Import every module of this folder, in the order of ``POSITION`` then name; name → module."""
    found = []
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{__name__}.{info.name}")
        law = getattr(module, "LAW", None)
        if not isinstance(law, ContactLaw):
            raise ImportError(f"{module.__name__} is not a contact law: it defines no LAW = register_law(...) "
                              "(docs/design.md, 'Adding a contact law')")
        found.append((getattr(module, "POSITION", math.inf), law.name, module))
    return {name: module for _, name, module in sorted(found, key=lambda t: t[:2])}


#: the law modules of this folder, law name → module, in the order of ``contact_law``'s choices
MODULES = _discover()


def declared_parameters():
    """Every discovered law's declared parameters: name → ``(parameters, in_signature)``.

    Returns
    -------
    dict
        Law name → ``(tuple of Parameter, bool)``, in the order of :data:`MODULES`.
    """
    return {name: (tuple(LAWS[name].declared), bool(getattr(module, "SIGNATURE", False)))
            for name, module in MODULES.items()}
