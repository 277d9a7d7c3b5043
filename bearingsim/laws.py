"""The physics laws both models use, each written once: pure float-in/float-out functions, SI throughout.

* kinematics of the bearing, Eqs. (10)-(12) and (4) of the seed paper;
* the outer-race normal load, Eq. (3), and the oil-film (EHL rolling) resistance, Eq. (2), with a
  scalar form for the kernels (:func:`oil_film_drag_scalar`);
* the Palmgren line contact ``Q = K delta^(10/9)`` (:func:`palmgren_stiffness`,
  :func:`palmgren_load`);
* the load-zone rule: the half angle ``psi_l = arccos(P_d / (2 delta_r))`` of a ring displaced by
  ``delta_r`` (:func:`load_zone_from_displacement`), the quasi-static displacement that carries a
  radial load (:func:`quasi_static_load_zone`), and the half angle a model uses
  (:func:`load_zone_half_angle`: the scenario's value or the quasi-static one);
* Archard's wear law in the paper's impulse form, Eq. (16) (:func:`archard_wear_volume`);
* gravity (:data:`STANDARD_GRAVITY`).

Equation numbers refer to Suzuki et al., Machines 11(6):594, 2023 (the seed paper).

Plain Python and numpy only: scenario loading and validation import this module, and it does not load
numba. The scalar laws the compiled kernels call (:func:`oil_film_drag_scalar`, :func:`palmgren_load`)
are compiled from these same functions by :mod:`bearingsim.compiled_laws`.
"""
from __future__ import annotations

import math

import numpy as np

STANDARD_GRAVITY = 9.80665  # m/s^2

# Exponents of the oil-film (EHL rolling) resistance, Eq. (2), after Zhou & Hoeprich (1991).
DRAG_LOAD_EXPONENT = 0.246
DRAG_SPEED_EXPONENT = 0.648


def inner_ring_angular_speed(inner_ring_speed_rpm: float) -> float:
    """Eq. (10): omega_i [rad/s] from n_i [rpm]."""
    return 2.0 * math.pi * inner_ring_speed_rpm / 60.0


def cage_angular_speed(omega_i: float, roller_radius: float, pitch_radius: float) -> float:
    """Eq. (11): epicyclic cage speed omega_c = (1 - gamma) omega_i / 2, gamma = r_r / r_p [rad/s]."""
    gamma = roller_radius / pitch_radius
    return (1.0 - gamma) * omega_i / 2.0


def roller_spin_speed(omega_i: float, roller_radius: float, pitch_radius: float) -> float:
    """Eq. (12): roller spin omega_r = (1/gamma - gamma) omega_i / 2 [rad/s] (magnitude, pure rolling)."""
    gamma = roller_radius / pitch_radius
    return (1.0 / gamma - gamma) * omega_i / 2.0


def rolling_speed(omega_r: float, omega_c: float, roller_radius: float, outer_race_radius: float) -> float:
    """Eq. (4): rolling velocity at the outer-race contact V = (r_r |omega_r| + r_o omega_c) / 2 [m/s]."""
    return 0.5 * (roller_radius * abs(omega_r) + outer_race_radius * abs(omega_c))


def outer_race_normal_load(mass, pitch_radius, omega_c, theta, gravity):
    """Eq. (3): N = m r_p omega_c^2 + m g cos(theta) [N]; theta from the load-zone centre (bottom).

    May be negative (below ~300 rpm near the top): the roller then leaves the outer race.
    """
    return mass * pitch_radius * omega_c**2 + mass * gravity * np.cos(theta)


def oil_film_drag(drag_coefficient, normal_load, rolling_velocity):
    """Eq. (2): F_o = c N^0.246 V^0.648 [N] (SI: N in N, V in m/s); zero where N <= 0 (no contact)."""
    n = np.maximum(normal_load, 0.0)
    return drag_coefficient * n**DRAG_LOAD_EXPONENT * np.abs(rolling_velocity) ** DRAG_SPEED_EXPONENT


def oil_film_drag_scalar(drag_coefficient, normal_load, rolling_velocity):
    """Eq. (2) for one contact (compiled for the kernels: :mod:`bearingsim.compiled_laws`): F_o = c N^0.246 V^0.648 [N] for N > 0, else 0.

    Parameters
    ----------
    drag_coefficient : float
        c of Eq. (2), SI.
    normal_load : float
        N [N].
    rolling_velocity : float
        V [m/s], >= 0.
    """
    if normal_load <= 0.0:
        return 0.0
    return drag_coefficient * normal_load**DRAG_LOAD_EXPONENT * rolling_velocity**DRAG_SPEED_EXPONENT


def palmgren_load(stiffness, approach):
    """Palmgren line contact: Q = K delta^(10/9) [N] for an approach delta [m] > 0, else 0 (compiled for
    the kernels: :mod:`bearingsim.compiled_laws`)."""
    if approach <= 0.0:
        return 0.0
    return stiffness * approach ** (10.0 / 9.0)


def archard_wear_volume(wear_coefficient, impulse, roller_radius, omega_r, hardness):
    """Archard wear volume [m^3] in the paper's impulse form, Eq. (16): V = k I_c r_r omega_r / H.

    ``W L_s = integral F_c dL_s ~ I_c r_r omega_r``: the sliding distance is the roller surface speed
    ``r_r omega_r`` times the contact time. ``impulse`` [N s] may be an array; k [-], H [Pa].
    """
    return wear_coefficient * impulse * (roller_radius * omega_r) / hardness


def archard_volume_from_work(wear_coefficient, sliding_work, hardness):
    """Archard wear volume [m^3] from the sliding work ``W L_s = sum F_c |v_slide| dt`` [J] (may be an
    array): V = k W L_s / H, the law of Eq. (16) before the paper's impulse approximation. k [-], H [Pa]."""
    return wear_coefficient * sliding_work / hardness


def load_zone_from_displacement(ring_displacement, radial_clearance):
    """Load-zone half angle [rad] of a ring displaced by ``delta_r`` along the load (Harris & Kotzalas,
    Sec. 7.2): ``psi_l = arccos(P_d / (2 delta_r))``; 0 when ``delta_r <= P_d / 2`` (no roller loaded),
    pi/2 for zero clearance; NaN for a non-finite displacement."""
    delta_r = float(ring_displacement)
    if not math.isfinite(delta_r):
        return float("nan")
    half_pd = 0.5 * radial_clearance
    if delta_r <= half_pd:
        return 0.5 * math.pi if half_pd == 0.0 and delta_r > 0.0 else 0.0
    return math.acos(half_pd / delta_r)


def load_zone_half_angle(given_deg, radial_load, roller_count, roller_length, radial_clearance):
    """The load-zone half angle phi [rad] a model uses: ``given_deg`` (degrees) when it is a number,
    else (``None``) the quasi-static half angle of :func:`quasi_static_load_zone` for the load."""
    if given_deg is not None:
        return math.radians(float(given_deg))
    phi, _ = quasi_static_load_zone(radial_load, roller_count, roller_length, radial_clearance)
    return float(phi)


def pocket_face_extent(pitch_radius, pocket_radius, wall_inner_radius, wall_outer_radius):
    """Angular extent ``(psi_in, psi_out)`` [rad] of an arc pocket face that the cage wall allows.

    A face is the arc ``c + R (cos psi u + sin psi e_r)`` of the pocket circle (centre ``c`` on the pitch
    circle ``r_p``, radius ``R``; ``u`` = +-e_t, along the circumference; ``psi`` > 0 outward). Its
    distance from the bearing axis is ``sqrt(r_p^2 + R^2 + 2 r_p R sin psi)``, and the cage material
    exists only between ``wall_inner_radius`` and ``wall_outer_radius``: the face ends where that
    distance reaches them, ``sin psi = (r_wall^2 - r_p^2 - R^2) / (2 r_p R)`` (clipped to +-90 deg: the
    wall then holds the whole half circle). ``psi_in`` <= 0 <= ``psi_out``; the extent is not symmetric
    (the ring's curvature: the same wall thickness spans a wider angle inside the pitch circle)."""
    den = 2.0 * pitch_radius * pocket_radius

    def edge(r_wall):
        return math.asin(min(1.0, max(-1.0, (r_wall * r_wall - pitch_radius**2 - pocket_radius**2) / den)))

    return edge(wall_inner_radius), edge(wall_outer_radius)


def cage_bar_width(pitch_diameter, roller_diameter, pocket_clearance, roller_count):
    """The narrowest width of the cage bar between two neighbouring pockets: the distance between their
    centres, ``d_p sin(pi / Z)``, less one pocket's width ``D + s``, along the line joining the centres (which
    meets the faces at psi = -pi / Z; any length unit in, the same out). What the two faces on a bar
    (:func:`worn_bar_depth`) can wear together before it is worn through, taken for every bin of psi:
    conservative elsewhere (the bar is wider along the pitch circle, and faces worn in the direction psi meet in
    the bar's middle at ``d_p sin(pi / Z) / cos(psi + pi / Z) - D - s``; docs/wear.md, *The cage bar*)."""
    return pitch_diameter * math.sin(math.pi / roller_count) - roller_diameter - pocket_clearance


def worn_bar_depth(front, rear):
    """The worn depth each cage bar carries, per bin of psi: ``front[..., i]`` plus ``rear[..., i - 1]``
    (pockets mod Z), from the worn depths ``front``, ``rear`` (..., pockets) of the pockets' front and rear
    faces in the same bins of psi. Bar ``i`` is the one between pocket ``i`` and pocket ``i - 1``: pocket
    ``i`` trails pocket 0 by ``i`` pitches (:func:`bearingsim.parameters.pocket_angles`), so pocket ``i - 1``
    lies ahead of it in the direction of rotation, and a pocket's front face is its side towards ``e_t``, the
    direction of rotation (the rear face the other), in either direction of rotation. So a bar carries one
    pocket's front face and its neighbour's rear face, not the front and rear faces of one pocket, which lie
    on the two bars either side of it. Psi counts from each face's middle towards the cage's rim on both
    faces, and the two faces' points at the same psi lie at the same distance from the cage's axis: their
    bins of the same index face each other across the bar."""
    return np.asarray(front) + np.roll(np.asarray(rear), 1, axis=-1)


def palmgren_approach(load: float, roller_length: float) -> float:
    """Approach [m] of one roller pressed on one raceway with ``load`` [N]: Palmgren's line contact
    ``Q = K delta^(10/9)`` (:func:`palmgren_stiffness`; Harris & Kotzalas Eq. 6.40 writes the same law as
    delta = 3.84e-5 Q^0.9 / l^0.8 in mm); 0 for no load."""
    return (max(load, 0.0) / palmgren_stiffness(roller_length)) ** 0.9


def palmgren_stiffness(roller_length: float) -> float:
    """Palmgren line-contact constant K of Q = K delta^(10/9), in SI (N / m^(10/9)).

    K = 8.06e4 l^(8/9) N/mm^(10/9) with l in mm (Palmgren, Ball and Roller Bearing Engineering, 1959;
    Harris & Kotzalas, Rolling Bearing Analysis, Eq. 6.49).
    """
    l_mm = roller_length * 1e3
    k_mm = 8.06e4 * l_mm ** (8.0 / 9.0)  # N / mm^(10/9)
    return k_mm * (1e3) ** (10.0 / 9.0)


def quasi_static_load_zone(radial_load, roller_count, roller_length, radial_clearance, *, n_points=3600):
    """Load-zone half angle [rad] and ring displacement [m] of a quasi-static line-contact bearing.

    Rollers are smeared over the circumference (continuous load distribution, Harris & Kotzalas
    Sec. 7.2), each with inner and outer Palmgren contacts in series; the diametral clearance
    P_d opens the load zone: psi_l = arccos(P_d / (2 delta_r)). Returns (pi/2, delta) for zero clearance
    and (0, 0) for zero load.
    """
    if radial_load <= 0.0:
        return 0.0, 0.0
    psi = np.linspace(-math.pi, math.pi, n_points, endpoint=False)
    half_pd = radial_clearance / 2.0
    # the smeared rollers: each grid point carries Z / n_points of a roller
    delta_r = _ring_displacement(radial_load, psi, roller_count / n_points, roller_length, half_pd)
    return load_zone_from_displacement(delta_r, radial_clearance), delta_r


def loaded_rollers_with_one_at_centre(radial_load, roller_count, roller_length, radial_clearance):
    """Number of rollers that carry load, quasi-statically, when one roller sits at the load-zone centre.

    Discrete rollers at ``psi_k = 2 pi k / Z``, inner and outer Palmgren contacts in series, ring
    displaced by ``delta_r`` along the load (by symmetry not sideways): a roller carries load where
    ``delta_r cos psi_k > P_d / 2``. This is the configuration with the fewest loaded rollers; if it has
    only one, the inner ring then rests on a single roller and its sideways position is undetermined
    (an unstable equilibrium, like a disc on a disc): a massless, quasi-static ring is not defined and the
    rotor's inertia must decide (``multibody.inner_ring = "dynamic"``). Returns 0 for zero load.
    """
    if radial_load <= 0.0:
        return 0
    psi = 2.0 * math.pi * np.arange(roller_count) / roller_count
    half_pd = radial_clearance / 2.0
    delta_r = _ring_displacement(radial_load, psi, 1.0, roller_length, half_pd)
    return int(np.count_nonzero(delta_r * np.cos(psi) - half_pd > 1e-12 * delta_r))


def _ring_displacement(radial_load, psi, weight, roller_length, half_pd):
    """Ring displacement delta_r [m] along the load that balances it on rollers at angles ``psi``
    (``weight`` rollers each), inner and outer Palmgren contacts in series:
    ``sum weight K_s (delta_r cos psi - P_d/2)_+^(10/9) cos psi = W``."""
    from scipy.optimize import brentq

    k_series = palmgren_stiffness(roller_length) / 2.0 ** (10.0 / 9.0)

    def residual(delta_r):
        d = np.clip(delta_r * np.cos(psi) - half_pd, 0.0, None)
        return weight * float(np.sum(k_series * d ** (10.0 / 9.0) * np.cos(psi))) - radial_load

    hi = half_pd + 1e-9
    while residual(hi) < 0.0:
        hi = 2.0 * hi + 1e-9
    return brentq(residual, half_pd, hi, xtol=1e-15, rtol=1e-13)
