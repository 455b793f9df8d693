"""The package version, in a module of its own so that every layer may import it at the top."""
__docformat__ = "numpy"
__version__ = "2.0.0"
