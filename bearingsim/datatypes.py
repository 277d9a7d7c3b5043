"""The plain data a result is made of: arrays with units, attribute groups, time series. SI throughout."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["NamedArray", "AttrGroup", "Series"]


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
