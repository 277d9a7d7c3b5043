"""Plausibility of a finished run, checked before anything is written (issue 14).

A run that finishes with non-finite numbers, an inner ring displaced further than the contact law
allows for its load, or too few time-series samples is not a result: :func:`check` raises
:class:`bearingsim.errors.SimulationUnstable` (exit 3) with advice naming the key to change, and the
caller writes no archive.
"""
from __future__ import annotations

import math

import numpy as np

from bearingsim import kinematics as kin
from bearingsim.errors import SimulationUnstable

# Palmgren's line-contact approach of one roller on one raceway, delta = 3.84e-5 Q^0.9 / l^0.8
# [mm; N, mm] (Palmgren, Ball and Roller Bearing Engineering, 3rd ed., 1959; Harris & Kotzalas,
# Essential Concepts of Bearing Technology, 5th ed., 2007, Eq. 6.40).
PALMGREN_COEFF_MM = 3.84e-5
# The mean inner-ring displacement along the load is at most half the diametral clearance plus the
# approach at the inner and the outer race of a roller that carries the whole load alone; twice that
# bound leaves room for vibration about the mean. A larger displacement means the ring has left the
# rollers (a blown-up or unloaded ring), not a result.
DISPLACEMENT_MARGIN = 2.0
# Fewest recorded samples of the cage orbit that make a figure and a mean of it.
MIN_ORBIT_SAMPLES = 2
# Steps in which the quasi-static inner ring's force balance (Newton iteration) did not converge: a
# few isolated steps are harmless (the next step starts again from the last iterate) and are reported
# as a note; in more than 1 % of the steps the ring equilibrium the model assumes is not met.
MAX_NEWTON_FAILURE_FRACTION = 0.01


def palmgren_approach_m(load_N: float, roller_length_m: float) -> float:
    """Approach [m] of one roller pressed on one raceway with ``load_N`` [N] (Palmgren line contact).

    Parameters
    ----------
    load_N : roller load [N]
    roller_length_m : effective roller length [m]
    """
    return PALMGREN_COEFF_MM * max(load_N, 0.0) ** 0.9 / (roller_length_m * 1e3) ** 0.8 * 1e-3


def max_ring_displacement_m(scenario) -> float:
    """Largest plausible mean inner-ring displacement [m] for the scenario's load (module constants)."""
    g = scenario.geometry
    load = float(scenario.operating.radial_load_N)
    ring_mass = scenario.multibody.inner_ring_mass_kg
    if ring_mass != "auto":  # a dynamic ring carries its own weight too
        load += float(ring_mass) * kin.STANDARD_GRAVITY
    bound = 0.5 * g.radial_clearance + 2.0 * palmgren_approach_m(load, g.roller_length)
    return DISPLACEMENT_MARGIN * bound


def _nonfinite(summary: dict) -> list[str]:
    bad = []
    for k, v in summary.items():
        if isinstance(v, (bool, np.bool_, str)):
            continue
        try:
            if not math.isfinite(float(v)):
                bad.append(k)
        except (TypeError, ValueError):
            continue
    return bad


def check(result, scenario, provenance: dict | None = None) -> list[str]:
    """Raise :class:`SimulationUnstable` if ``result`` is not a plausible run of ``scenario``.

    Parameters
    ----------
    result : a model result with ``summary`` and ``per_rotation_I_dec`` / ``per_rotation_I_acc``
    scenario : the resolved scenario it was run from
    provenance : the run's provenance (``ring_newton_failures``), if any

    Returns
    -------
    list of str
        One-line notes for the user about a run that is plausible but not clean.
    """
    notes = []
    summary = dict(result.summary)
    bad = _nonfinite(summary)
    if bad:
        if scenario.model == "reduced" and set(bad) <= {"first_impact_speed_m_s", "first_impact_energy_J"}:
            advice = ("the no-load pass has no rear-face impact; reduced.load_zone_half_angle_deg "
                      f"= {summary.get('load_zone_half_angle_deg', float('nan')):.4g} deg leaves too short a pass")
        else:
            advice = _advice(scenario)
        raise SimulationUnstable(f"non-finite result ({', '.join(sorted(bad))}); {advice}")
    for name in ("per_rotation_I_dec", "per_rotation_I_acc"):
        arr = np.asarray(getattr(result, name, np.zeros(0)))
        if arr.size and not np.all(np.isfinite(arr)):
            raise SimulationUnstable(f"non-finite {name[13:]} per rotation; {_advice(scenario)}")
    if scenario.model == "multibody":
        disp = abs(float(summary.get("inner_ring_displacement_m", 0.0)))
        limit = max_ring_displacement_m(scenario)
        if disp > limit:
            raise SimulationUnstable(
                f"inner ring displaced {disp:.3g} m, more than the {limit:.3g} m the Palmgren contact law allows "
                f"for this load and clearance; {_advice(scenario)}")
        orbit = getattr(result, "orbit", None)
        if orbit is not None:
            samples = int(np.sum(np.isfinite(np.asarray(orbit)[:, 0]))) if np.ndim(orbit) == 2 else 0
            if samples < MIN_ORBIT_SAMPLES:
                raise SimulationUnstable(
                    f"{samples} time-series samples recorded; raise numerics.output_rate_hz or numerics.rotations")
        # today in the provenance only; read from the summary too once the model puts it there
        fails = int(summary.get("ring_newton_failures", (provenance or {}).get("ring_newton_failures", 0)) or 0)
        steps = int(summary.get("steps", 0) or 0)
        if fails and steps:
            msg = (f"the inner ring's force balance did not converge in {fails} of {steps} steps "
                   f"({fails / steps:.2%}; provenance ring_newton_failures)")
            if fails > MAX_NEWTON_FAILURE_FRACTION * steps:
                raise SimulationUnstable(f"{msg}; set a smaller numerics.dt_s or multibody.inner_ring=dynamic")
            notes.append(f"bearingsim: note: {msg}")
    return notes


def _advice(scenario) -> str:
    if scenario.model == "multibody" and scenario.multibody.inner_ring != "quasi_static":
        return ("check multibody.inner_ring_mass_kg and operating.radial_load_N, or set "
                "multibody.inner_ring=quasi_static, or a smaller numerics.dt_s")
    if scenario.model == "multibody":
        return "check operating.radial_load_N and operating.inner_ring_speed_rpm, or set a smaller numerics.dt_s"
    return "check bearing.roller_mass_kg, lubrication.drag_coefficient and reduced.load_zone_half_angle_deg"
