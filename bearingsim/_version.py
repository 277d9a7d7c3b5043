"""The package version (a leaf module: the archive writer stamps it without importing the package)."""

__version__ = "0.1.0"
