"""The package version (one place; read by the summary writers and ``--version``)."""
__version__ = "0.2.0"
