"""Measured rheometer data beside simulated data (docs/experiment.md).

:class:`~particleShear.experiment.tables.MeasuredTest` is the one typed table of a measured (or an
exported simulated) rheometer test; readers turn files into it, writers turn it and sweep folders
into the files rheologists' tools open, and :mod:`~particleShear.experiment.calibration` ranks a
simulated campaign against a measured amplitude sweep.
"""
__docformat__ = "numpy"
from .tables import KINDS, QUANTITIES, MeasuredTest

__all__ = ["KINDS", "QUANTITIES", "MeasuredTest"]
