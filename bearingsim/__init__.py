"""bearingsim: roller/cage dynamics of rolling bearings and the cage-wear impulse.

SI units throughout the package; units appear in names only at the edges (scenario keys, plots).
"""
__version__ = "0.1.0"

from bearingsim.errors import UserError  # noqa: E402

__all__ = ["UserError", "__version__"]
