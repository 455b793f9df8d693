"""The parameters of a run as data: one table, read by everything that needs them.

Each :class:`Parameter` of :data:`PARAMETERS` holds a keyword of
:func:`~particleShear.run.api.doParticleShearSimulation` (in its signature's order, then the contact
laws' parameters outside the signature, :data:`EXTRA`): its default, type, unit, allowed range,
role and a one-line description.  The contact laws declare their parameters in their own files
(:mod:`particleShear.engine.contact_laws`), the protocols likewise (:mod:`particleShear.protocols`);
the table is the base entries written here composed with every discovered law's and protocol's (the
plateau law's after ``contact_law``, the shipped protocols' after ``protocol``, as in the signature).  The signature and the docstring of
``doParticleShearSimulation`` keep particleShear 1.0.2's order, names and defaults; the suite checks
them against this table, never the other way round (particleShearTest/test_parameter_table.py).
What is derived from it: the range checks of the validation (:mod:`particleShear.run.validation`),
the command line's types, choices and help (:mod:`particleShear.run.cli`), the results table's
parameter columns, types and units (:mod:`particleShear.sweep.schema`), the SPEC keys
(:mod:`particleShear.sweep.spec`), the run identity (:mod:`particleShear.simulation.provenance`),
the batch grouping (:mod:`particleShear.run.batch`) and the protocols' parameters
(:mod:`particleShear.run.rheometer`).

Roles
-----
``model``
    The physics of the packing and of its excitation (in the run identity).
``law``, ``law:<name>``
    The contact law's selector (``contact_law``) and the parameters of law ``<name>`` (in the run
    identity only when that law is selected; the selector only when it is not the default).
``protocol``, ``protocol:<a>,<b>``
    The protocol's selector and the parameters the protocols ``<a>``, ``<b>`` read (in the run
    identity only for those protocols; the selector only when it is not "oscillatory").
``numerics``
    How the measurement is integrated and evaluated (in the identity).
``output``
    What a run writes (in the identity: the row names the file).
``display``, ``call``, ``observer``
    What a run shows, what the caller chooses for this call (folder, seed, return type, error
    policy) and observers that only read a run: not in the identity.

Batch classes (``batch``): ``schedule`` parameters fix the step schedule (runs share a batch only
with equal values), ``replica`` parameters may differ between the replicas of one batch, ``shared``
ones must be equal within a batch.
"""
__docformat__ = "numpy"
import dataclasses
import math

from .engine.contact_laws import declared_parameters
from .parameter_entry import KINDS, ROLES, Parameter
from .protocols import declared_parameters as declared_protocol_parameters

__all__ = ["Parameter", "PARAMETERS", "SIGNATURE", "EXTRA", "BY_NAME", "ROLES", "KINDS", "defaults", "names",
           "law_parameters", "SPEC_RESERVED", "spec_defaults", "protocol_parameters", "identity_excluded"]

#: the contact laws of the laws folder: name → (their declared parameters, in the signature or not)
_LAWS = declared_parameters()
#: the protocols of the protocols folder: name → (their declared parameters, in the signature or not)
_PROTOCOLS = declared_protocol_parameters()

#: the entries written here; the laws' parameters are composed into :data:`PARAMETERS` below
_BASE = (
    Parameter('root_folder', '', 'path', role='call', doc='Output folder (path) of the text file and of the image folder'),
    Parameter('theAmplitude', 0.2, 'float', unit='1', low=0, high=100, low_open=True, doc='Strain amplitude A, dimensionless (0.2 = 20 %)'),
    Parameter('theMu', 0.01, 'float', unit='1', low=0, high=1000000.0, doc='Coulomb friction coefficient μ of transient contacts, dimensionless'),
    Parameter('do_permanent_links', True, 'bool', doc='Crosslink all contacts after relaxation; False: frictional spheres only'),
    Parameter('cut_lines', 5, 'int', doc='Triangulation: number of particles (Voronoi seeds); line mode: number of straight cuts; <= 1 (triangulation) or 0 (lines) is an uncut bulk gel'),
    Parameter('Young_modulus_spheres', 8000, 'float', unit='Pa', low=1e-06, high=1000000000000.0, batch='schedule', doc='Young modulus E of the sphere material in Pa'),
    Parameter('N', 150, 'int', batch='schedule', doc='Number of spheres; allowed an integer from N_min (11 at the default packing fraction and bimodal factor: the largest sphere must be smaller than a quarter of the cell) to 1e6'),
    Parameter('packing_fraction', 1.5, 'float', unit='1', low=0, high=10, low_open=True, batch='schedule', doc='Nominal (uncompressed) area fraction φ that defines the radii (eq. S1-14), dimensionless'),
    Parameter('density', 50, 'float', unit='kg/m³', low=1e-06, high=1000000.0, batch='schedule', doc='Material density in kg/m³'),
    Parameter('bimodal_factor', 1.4, 'float', unit='1', low=0.01, high=100, batch='schedule', doc='Ratio of large to small radius (50/50 random), dimensionless'),
    Parameter('relative_viscosity', 0.1, 'float', unit='1', low=0, high=3.0, batch='schedule', doc='rv in the contact damping ν = rv·√(m k) (eq. S1-9), dimensionless'),
    Parameter('relative_transversal_link_strength', 1, 'float', unit='1', low=0, high=30.0, doc='k_t/k and ν_t/ν, dimensionless'),
    Parameter('relative_frequency', 0.025, 'float', unit='1', low=0, low_open=True, batch='schedule', doc='f·τ: excitation frequency in units of the characteristic frequency 1/τ, dimensionless'),
    Parameter('avoid_horizontal_angle_degree', 15, 'float', unit='degree', low=0, high=90, high_open=True, doc='Line-cut mode only: half-width in degrees of the forbidden band around horizontal cut lines'),
    Parameter('interface_reenforcement_central', 1, 'float', unit='1', low=1e-06, high=50.0, doc='Factor on k of transient contacts relative to permanent links, dimensionless'),
    Parameter('interface_reenforcement_tangential', 1, 'float', unit='1', low=1e-06, high=1000000.0, doc='The same factor for k_t, dimensionless'),
    Parameter('keep_viscosity_coefficients_constant', False, 'bool', doc='False: the contact viscosities follow the reinforcement factors; True: they stay'),
    Parameter('avoid_height_spanning_particles', True, 'bool', doc='Cut again while a particle is taller than 0.9 of the cell height'),
    Parameter('cut_top_bottom', False, 'bool', doc='Cut every link through the y-periodic boundary (emulates wall slip)'),
    Parameter('saveOutputImages', False, 'bool', role='output', doc='Save about 200 captioned snapshots of the protocol into an image folder beside the output file (needs ``root_folder``; works with or without ``doDrawing``)'),
    Parameter('imageFileType', 'jpg', 'str', choices=('jpg', 'png', 'ps', 'svg'), role='output', doc='Snapshot format; "ps" is vector Encapsulated PostScript (extension .ps), "svg" vector SVG'),
    Parameter('remove_link_fraction', 0, 'float', unit='1', low=0, high=1, doc='Target fraction of non-essential permanent links removed at random'),
    Parameter('edge_fuzziness', 0, 'float', unit='largest radius', low=0, high=1000.0, doc='Random roughening of the Voronoi borders in units of the largest radius'),
    Parameter('central_repulsion_coefficient', 1, 'float', unit='1', low=0, high=1, doc='c of the central force law, dimensionless (1 = divergent repulsion eq. S1-5b, 0 = linear eq. S1-5a)'),
    Parameter('doCutByTriangulation', True, 'bool', doc='Cut into particles by periodic Voronoi cells; False: by random straight lines'),
    Parameter('doDrawing', True, 'bool', role='display', doc='Draw: the live particle window when a display exists (snapshots do not need it)'),
    Parameter('saveData', False, 'bool', role='output', doc='Write the output file of the run (format ``output_format``; docs/output.md)'),
    Parameter('saveStressTensorData', True, 'bool', role='output', doc='With ``saveData``: also write the 42-column per-step table of the stress tensors'),
    Parameter('plotStress', True, 'bool', role='display', doc='Live stress/strain window (needs a display and ``doDrawing``); without a display, and with ``saveData``, it is saved as ``<output file>_stress.png`` (needs particleShear[plot])'),
    Parameter('relative_y_scale_force', 100000000.0, 'float', unit='1', low=-1e+300, high=1e+300, role='output', doc='Vertical scale of the live stress window only, dimensionless'),
    Parameter('pre_periods', 2, 'float', unit='excitation periods', low=0, batch='schedule', doc='Baseline before the excitation, in excitation periods (drift reference)'),
    Parameter('periods', 3, 'float', unit='excitation periods', low=0, low_open=True, batch='schedule', doc='Excitation periods (the first is skipped in the demodulation when >= 2)'),
    Parameter('post_periods', 1, 'float', unit='excitation periods', low=0, batch='schedule', doc='Recovery after the excitation, in excitation periods'),
    Parameter('cool_factor', 0.5, 'float', unit='1', low=0, high=1, low_open=True, batch='schedule', doc='Fraction of the peculiar velocity left after one excitation period (damping), dimensionless'),
    Parameter('seed', None, 'seed', role='call', nullable=True, doc='Drives every random choice; one seed gives a bit-identical run'),
    Parameter('return_result', False, 'bool', role='call', batch='shared', keyword_only=True, doc='Return the :class:`SimulationResult` instead of ``[G′_surface, G″_surface]``'),
    Parameter('verbose', True, 'bool', role='display', keyword_only=True, doc='Show the reference\'s console messages: INFO messages of the logger "particleShear" on stdout during the call (see :mod:`particleShear.messages`)'),
    Parameter('progress', None, 'callable', role='display', keyword_only=True, nullable=True, doc='``progress(phase, step, total, elapsed_s)``, called at most ~10 times per second, for the phases "constitution", "pre-equilibration" and "protocol"'),
    Parameter('correct_drift_sign', False, 'bool', role='numerics', keyword_only=True, doc="Demodulate with the mathematically correct drift correction (default: the reference's sign; docs/output.md)"),
    Parameter('reference_header', False, 'bool', role='output', keyword_only=True, doc="Reproduce the two defects of the reference's output header (docs/output.md)"),
    Parameter('renderer', 'auto', 'str', choices=('auto', 'tk', 'pillow', 'none'), role='display', keyword_only=True, doc='Drawing backend: "auto" (Tk when a display exists, else Pillow for the snapshots), "tk", "pillow" or "none"; also set by the environment variable PARTICLESHEAR_RENDERER'),
    Parameter('time_step_factor', 1.0, 'float', unit='1', role='numerics', batch='schedule', keyword_only=True, doc='Multiplies the time step (and the coarsest relaxation step) of the measurement: plate pre-equilibration and protocol (1 = the reference rule)'),
    Parameter('integrator', 'euler', 'str', choices=('euler', 'verlet'), role='numerics', batch='schedule', keyword_only=True, doc="Time integrator of the measurement: the reference's semi-implicit Euler, or velocity Verlet with a half-kick predictor for the velocity-dependent forces"),
    Parameter('stability_guard', True, 'bool', role='numerics', keyword_only=True, doc='Stop a diverging measurement with ``SimulationInstabilityError`` (step, phase, worst pair, suggested time step) instead of returning NaN moduli'),
    Parameter('saveOutputMovie', False, 'bool', role='output', batch='shared', keyword_only=True, doc='Also write the snapshots as the animated GIF ``movie.gif`` in the image folder (needs ``saveOutputImages``): 80 ms a frame, each snapshot scaled down to 320 px wide (kept as it is when narrower); every snapshot is a frame (201 by default) until 400 are kept, then every second kept frame is dropped and only every second later snapshot is kept, so a movie has fewer than 400 frames'),
    Parameter('output_format', 'text', 'str', choices=('text', 'text.gz', 'npz', 'parquet'), role='output', batch='shared', keyword_only=True, doc='File format of ``saveData``: the reference text, the same gzip-compressed, NumPy .npz, or Parquet (needs particleShear[parquet]); read any with :func:`particleShear.read_run` (docs/output.md)'),
    Parameter('strict_io', False, 'bool', role='call', batch='shared', keyword_only=True, doc='Raise the ``OSError`` of a failed write after the run; False: return the result with ``write_error`` set (``last_result`` holds it either way)'),
    Parameter('backend', 'auto', 'str', choices=('auto', 'numpy', 'numba', 'cupy'), role='numerics', batch='shared', keyword_only=True, doc='Array library of the measurement: "auto" (the environment variable PARTICLESHEAR_BACKEND when set, else "numba" where Numba can be imported, else "numpy"); "numpy"; "numba" (NumPy arrays, each step compiled from the NumPy engine\'s own functions, bit-identical; needs ``pip install particleShear[fast]``); or "cupy" to measure on a CUDA GPU (needs ``pip install cupy-cuda12x`` and a device; equal to the NumPy run to rounding, not bit for bit). The result, results.csv and the sidecar record the backend used; "numpy", "numba" and "auto" give one run identity'),
    Parameter('contact_law', 'linear', 'str', choices=tuple(_LAWS), role='law', batch='shared', keyword_only=True, doc='Central contact law, a law of the folder particleShear/engine/contact_laws (its parameters follow it in this table), a law added with ``register_law``, or ``"package.module:function"``: "linear" the blend of eqs'),
    Parameter('protocol', 'oscillatory', 'str', choices=tuple(_PROTOCOLS), role='protocol', batch='shared', keyword_only=True, doc="What the rheometer does after the pre-equilibration (docs/protocols.md): the reference's oscillation; a constant shear rate; a step strain to ``theAmplitude`` and hold; a constant applied stress; or, on one packing, the oscillation at each of ``sweep_amplitudes`` or ``sweep_frequencies`` in turn"),
    Parameter('stroboscopic', False, 'bool', role='observer', keyword_only=True, doc='Watch the oscillatory protocol with the stroboscopic observer (:class:`particleShear.engine.microstructure.Stroboscope`): a snapshot at the start of every shear period; per cycle the non-affine displacement, D²_min, contacts made and broken, Z without rattlers and P(f/⟨f⟩) in ``result.microstructure`` and the per-run columns ``irreversibility``, ``moved_fraction``, ``Z_rattler_free``, ``rattler_fraction``, ``contact_change_rate`` in ``result.measures`` (docs/microstructure.md)'),
)



def _joined(declared):
    """The parameters of several laws or protocols in order, each once: a parameter two of them read
    (declared by each, the same entry but its role) carries both names in its role."""
    out = {}
    for p in declared:
        q = out.get(p.name)
        if q is None:
            out[p.name] = p
            continue
        if dataclasses.replace(q, role=p.role) != p:
            raise ValueError(f"parameter {p.name!r} is declared twice with different entries: {q} and {p}")
        out[p.name] = dataclasses.replace(q, role=f"{q.base_role}:{','.join(q.role_names + p.role_names)}")
    return tuple(out.values())


def _compose(base, laws, protocols):
    """The base entries with every law's and protocol's parameters: those in the signature (the
    plateau law's, the shipped protocols') right after their selector (``contact_law``,
    ``protocol``), the others (``extra``) after the base entries."""
    def signature(groups):
        return [dataclasses.replace(p, keyword_only=True)
                for p in _joined(p for params, in_signature in groups.values() if in_signature for p in params)]
    extra = [dataclasses.replace(p, keyword_only=True, extra=True)
             for groups in (laws, protocols)
             for p in _joined(p for params, in_signature in groups.values() if not in_signature for p in params)]
    names = [p.name for p in base]
    law_at, protocol_at = names.index("contact_law") + 1, names.index("protocol") + 1
    return tuple(base[:law_at]) + tuple(signature(laws)) + tuple(base[law_at:protocol_at]) \
        + tuple(signature(protocols)) + tuple(base[protocol_at:]) + tuple(extra)


#: every parameter of a run: the keywords of ``doParticleShearSimulation`` in signature order, then the
#: parameters of the contact laws and protocols that are not in its signature (``extra``: its
#: ``**law_parameters``)
PARAMETERS = _compose(_BASE, _LAWS, _PROTOCOLS)
#: the keywords of ``doParticleShearSimulation``'s signature, in its order
SIGNATURE = tuple(p for p in PARAMETERS if not p.extra)
#: the parameters of contact laws and protocols outside the signature (taken by ``**law_parameters``)
EXTRA = tuple(p.name for p in PARAMETERS if p.extra)

#: name → :class:`Parameter`
BY_NAME = {p.name: p for p in PARAMETERS}


def _check_table():
    for p in PARAMETERS:
        assert p.kind in KINDS and p.base_role in ROLES and p.batch in ("replica", "schedule", "shared"), p
        assert p.kind != "str" or p.choices, p
        assert not p.has_range or all(x is None or math.isfinite(x) for x in (p.low, p.high)), p


_check_table()


def defaults():
    """``{name: default}`` of every parameter, signature order.

    Returns
    -------
    dict
    """
    return {p.name: p.default for p in PARAMETERS}


def names(role=None, batch=None):
    """The names of the parameters of a (base) role and/or batch class, signature order.

    Parameters
    ----------
    role : str, optional
        A base role (:data:`ROLES`) or a full role (``"law:plateau"``).
    batch : str, optional
        ``"replica"``, ``"schedule"`` or ``"shared"``.

    Returns
    -------
    tuple of str
    """
    return tuple(p.name for p in PARAMETERS
                 if (role is None or p.role == role or p.base_role == role)
                 and (batch is None or p.batch == batch))


#: arguments a sweep SPEC may not set: the sweep chooses them (its folder, its seeds, the result
#: type, its console)
SPEC_RESERVED = ("root_folder", "seed", "return_result", "verbose", "progress")


def spec_defaults(protocols=False):
    """Every parameter that is a sweep's table column, with its default (dict, signature order).

    The parameters less :data:`SPEC_RESERVED` and the observers (a SPEC may set those, but they
    are columns only where it does); the protocols' own parameters only with ``protocols``.

    Parameters
    ----------
    protocols : bool, default False
        With the protocols' selector and parameters (role ``protocol…``).

    Returns
    -------
    dict
    """
    return {p.name: p.default for p in PARAMETERS
            if p.name not in SPEC_RESERVED and p.base_role != "observer" and (protocols or p.base_role != "protocol")}


def law_parameters(law):
    """The parameters of contact law ``law`` (role ``law:<law>``), signature order.

    Parameters
    ----------
    law : str

    Returns
    -------
    tuple of str
    """
    return tuple(p.name for p in PARAMETERS if p.base_role == "law" and law in p.role_names)


def protocol_parameters(protocol):
    """The parameters protocol ``protocol`` reads (role ``protocol:…`` naming it), signature order.

    Parameters
    ----------
    protocol : str

    Returns
    -------
    tuple of str
    """
    return tuple(p.name for p in PARAMETERS if p.base_role == "protocol" and protocol in p.role_names)


def identity_excluded(parameters):
    """The names a run's identity leaves out: display, call and observer parameters; the parameters
    of the laws and protocols the run does not use; a selector, and a parameter added after 2.0.0
    (``since``), at its default (so a run keeps the id it had before the law, the protocol or the
    parameter existed).

    Parameters
    ----------
    parameters : dict
        The run's inputs (``contact_law`` and ``protocol`` read; defaults when absent).

    Returns
    -------
    frozenset of str
    """
    out = set()
    for p in PARAMETERS:
        base = p.base_role
        if base in ("display", "call", "observer"):
            out.add(p.name)
        elif p.role_names:
            chosen = parameters.get("contact_law" if base == "law" else "protocol", BY_NAME[
                "contact_law" if base == "law" else "protocol"].default)
            if chosen not in p.role_names:
                out.add(p.name)
        elif (base in ("law", "protocol") or p.since) and parameters.get(p.name, p.default) == p.default:
            out.add(p.name)
    return frozenset(out)
