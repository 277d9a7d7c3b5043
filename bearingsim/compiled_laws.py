"""The compiled forms of the scalar laws of :mod:`bearingsim.laws` that the numba kernels call.

:mod:`bearingsim.laws` is plain Python and numpy, so that loading and validating a scenario does not load
numba; the kernels (:mod:`bearingsim.multibody.forces`) call the compiled functions here, made from the
very same functions (one source for each law). Their on-disk caches sit beside ``laws.py`` and numba
checks that file; this file's decorator options are covered by :func:`bearingsim._jit.drop_stale_caches`,
and the kernel modules list this module among the sources they compile in.
"""
from __future__ import annotations

import sys

from numba import njit

from bearingsim import laws
from bearingsim._jit import drop_stale_caches

#: Eq. (2) for one contact, compiled (:func:`bearingsim.laws.oil_film_drag_scalar`)
oil_film_drag_scalar = njit(cache=True)(laws.oil_film_drag_scalar)

#: Palmgren line contact Q = K delta^(10/9), compiled (:func:`bearingsim.laws.palmgren_load`)
palmgren_load = njit(cache=True)(laws.palmgren_load)

# the compiled code follows laws.py (numba's own check) and the options above (this file)
drop_stale_caches(__name__, (laws, sys.modules[__name__]), dispatchers=(oil_film_drag_scalar, palmgren_load))
