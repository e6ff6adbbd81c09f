"""The package version, in one place (imported by the package, the command line and reports)."""

__version__ = "0.1.0"
