"""The reference's protocol: oscillatory shear at ``theAmplitude`` and ``relative_frequency``.

Its parameters are the model's (``theAmplitude``, ``relative_frequency``, ``pre_periods``,
``periods``, ``post_periods``: roles of the table, not ``protocol:``), its loop is
:func:`particleShear.engine.step.protocol`, and its run, summary (G′, G″, measures) and columns
are those of the driver's oscillation (:class:`particleShear.simulation.driver.Oscillation`) and of
:class:`particleShear.run.result.SimulationResult`.
"""
__docformat__ = "numpy"

from . import register_protocol

__all__ = ["PROTOCOL"]

POSITION = 0
SIGNATURE = True
PARAMETERS = ()


def steps(q, dt_over_tau):
    """No protocol steps of its own here (the oscillatory run counts its periods itself).

    Parameters
    ----------
    q : dict
        The run's arguments (defaults filled in; normalized by the protocol's ``normalize``).
    dt_over_tau : callable
        ``dt_over_tau(amplitude=None)``: the protocol time step in units of τ (at ``theAmplitude`` or the amplitude given).

    Returns
    -------
    dict
        ``dt_over_tau`` and the protocol's counts (module docstring of :mod:`particleShear.protocols`).
    """
    return {"dt_over_tau": dt_over_tau()}


PROTOCOL = register_protocol("oscillatory", parameters=PARAMETERS,
                             shown=("Gp_surface", "G'", "Pa"),
                             required=("Gp_surface", "Gpp_surface", "Gp_internal", "Gpp_internal"), steps=steps,
                             checks=("steady_state", "linear_response", "estimators_agree", "moduli_positive",
                                     "excitation_resolved"),
                             doc="the reference's oscillation")
