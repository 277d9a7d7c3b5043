"""The plain data a result is made of: arrays with units, attribute groups, time series. SI throughout."""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["NamedArray", "AttrGroup", "Series", "ReadOnlyMapping"]


@dataclass
class NamedArray:
    """An array with its unit (``"1"`` for dimensionless or counts) and a one-line description."""

    data: np.ndarray
    unit: str = "1"
    description: str = ""


@dataclass
class AttrGroup:
    """Scalar attributes with the units of those that have one, and a description of the group."""

    attrs: dict[str, Any]
    units: dict[str, str] = field(default_factory=dict)
    description: str = ""


@dataclass
class Series:
    """A time series: sample ``step`` numbers, ``time`` [s] and ``value[T, ...]`` in ``unit``."""

    step: np.ndarray
    time: np.ndarray
    value: np.ndarray
    unit: str = "1"
    description: str = ""


class ReadOnlyMapping(Mapping):
    """A read-only copy of a dict: what a result hands out for its named values (the attributes and units of
    :attr:`bearingsim.results.Result.groups`, its provenance), as its arrays are read-only views. Reading is a
    dict's (``m[k]``, ``m.get(k)``, ``m.items()``, ``dict(m)``, ``{**m}``, ``==`` with a dict); ``m[k] = v`` and
    ``del m[k]`` raise a TypeError, and it has no ``update``, ``pop``, ``setdefault`` or ``clear``. It pickles
    (a result goes back from a process pool), unlike ``types.MappingProxyType``."""

    __slots__ = ("_d",)

    def __init__(self, values=()):
        self._d = dict(values)

    def __getitem__(self, key):
        return self._d[key]

    def __iter__(self):
        return iter(self._d)

    def __len__(self) -> int:
        return len(self._d)

    def __contains__(self, key) -> bool:
        return key in self._d

    def __setitem__(self, key, value):
        raise TypeError(f"cannot set {key!r}: read-only (a result's values stay as its run made them; "
                        f"dict(...) of it is a copy to change)")

    def __delitem__(self, key):
        raise TypeError(f"cannot delete {key!r}: read-only (a result's values stay as its run made them; "
                        f"dict(...) of it is a copy to change)")

    def __reduce__(self):
        return type(self), (self._d,)

    def __repr__(self) -> str:
        return repr(self._d)
