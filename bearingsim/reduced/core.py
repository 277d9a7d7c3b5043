"""Pure kernels of the reduced single-pocket model (paper Sec. 2.3, Eqs. 1-13). SI throughout.

Frame and sign conventions (``docs/physics.md``):

* θ is the roller's angle from the load-zone centre (bottom of the bearing) measured in the direction
  of cage rotation; θ = ω_c t + φ (Eq. 13). One no-load pass runs from θ = φ to θ = 2π − φ.
* ``l_r`` ∈ [0, s] is the roller's position in its pocket: 0 touches the rear face, ``s`` the front face.
* Between contacts the roller's acceleration relative to the cage is (Eq. 1 with F_dec = 0)

      a(θ) = dl_r''  = −g sin θ − F_o(θ) / m,

  with the oil-film resistance F_o = c N^0.246 V^0.648 (Eq. 2), N = m r_p ω_c² + m g cos θ (Eq. 3),
  and F_o = 0 where N ≤ 0 (the roller has left the outer race; below ~313 rpm near the top).
  On 0 < θ < π gravity decelerates the roller relative to the cage (pushes it towards the rear face).
* Face impulses are reported as positive magnitudes: ``I_dec`` on the rear face (the cage pulls a
  lagging roller), ``I_acc`` on the front face (the roller pushes the cage forward). The momentum
  balance of one pass is therefore  I_dec − I_acc + m ∫ a dt = m (v_end − v_start).

The reduced model is mirror-symmetric: reverse rotation is the same motion seen in a mirror, with θ
still measured in the direction of cage rotation, so it needs no sign of its own here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit

from bearingsim import laws
from bearingsim.codes import FACE_FRONT, FACE_REAR  # noqa: F401  (the solvers' face codes)

# Mode codes shared by the solvers (numba kernels cannot use enums cheaply).
FREE = 0
REST_REAR = 1
REST_FRONT = 2
KIND_IMPACT = 0
KIND_ZENO = 1  # an impact that closes a Zeno bounce sequence (see event.py)


class PassConstants(NamedTuple):
    """The constants of one no-load pass as the compiled solvers take them (SI; one named tuple, no
    slot vector). ``zeno_height`` and ``zeno_floor`` are fractions of the pocket clearance."""

    mass: float
    clearance: float
    omega_c: float
    gravity: float
    restitution: float
    theta_start: float
    theta_end: float
    drag_scale: float
    centripetal: float
    resting_contact: bool
    zeno_height: float
    zeno_floor: float


@dataclass(frozen=True)
class PassInputs:
    """Everything one no-load pass of the reduced model depends on, in SI units.

    Attributes
    ----------
    mass : float
        Roller mass m [kg].
    pitch_radius : float
        Pitch-circle radius r_p [m].
    roller_radius : float
        Roller radius r_r [m].
    pocket_clearance : float
        Pocket clearance s [m] (pocket diameter minus roller diameter).
    omega_c : float
        Cage angular speed ω_c [rad/s], Eq. (11) (magnitude).
    omega_r : float
        Roller spin ω_r [rad/s], Eq. (12) (magnitude); informative, V already contains it.
    rolling_velocity : float
        Rolling velocity at the outer race V [m/s], Eq. (4).
    drag_coefficient : float
        c of Eq. (2) [N^(1-0.246) (m/s)^-0.648], SI.
    gravity : float
        g [m/s²]; 0 when gravity is switched off.
    restitution : float
        Coefficient of restitution e of a roller-cage impact [-], Eq. (6).
    theta_start, theta_end : float
        Start and end of the pass [rad]: φ and 2π − φ.
    resting_contact : bool
        Count the resting-contact impulse of Eq. (9), third case (paper's present model). False
        counts impact impulses only (the previous model, with ``gravity = 0``).
    """

    mass: float
    pitch_radius: float
    roller_radius: float
    pocket_clearance: float
    omega_c: float
    omega_r: float
    rolling_velocity: float
    drag_coefficient: float
    gravity: float
    restitution: float
    theta_start: float
    theta_end: float
    resting_contact: bool

    @classmethod
    def from_parameters(cls, p) -> "PassInputs":
        """The inputs of one pass from :class:`bearingsim.parameters.Parameters` ``p``.

        φ is ``p.reduced.load_zone_half_angle``: the scenario's ``reduced.load_zone_half_angle_deg`` or,
        for ``"auto"``, the quasi-static half angle (:func:`bearingsim.laws.load_zone_half_angle`).
        """
        b, op = p.bearing, p.operating
        phi = p.reduced.load_zone_half_angle
        return cls(
            mass=b.roller_mass,
            pitch_radius=b.pitch_radius,
            roller_radius=b.roller_radius,
            pocket_clearance=b.pocket_clearance,
            omega_c=abs(op.omega_c),
            omega_r=abs(op.omega_r),
            rolling_velocity=abs(op.rolling_velocity),
            drag_coefficient=p.contact.drag_coefficient,
            gravity=op.gravity,
            restitution=p.contact.restitution,
            theta_start=phi,
            theta_end=2.0 * math.pi - phi,
            resting_contact=p.reduced.resting_contact,
        )

    # ---- derived quantities ------------------------------------------------------------------
    @property
    def centripetal(self) -> float:
        """r_p ω_c² [m/s²]: the centrifugal part of N/m (Eq. 3)."""
        return self.pitch_radius * self.omega_c**2

    @property
    def drag_scale(self) -> float:
        """K such that F_o/m = K (r_p ω_c² + g cos θ)^0.246 where positive [SI]."""
        return (
            self.drag_coefficient
            * self.mass ** (laws.DRAG_LOAD_EXPONENT - 1.0)
            * self.rolling_velocity**laws.DRAG_SPEED_EXPONENT
        )

    @property
    def pass_duration(self) -> float:
        """Duration of the no-load pass [s]."""
        return (self.theta_end - self.theta_start) / self.omega_c

    def drag_force(self, theta):
        """F_o(θ) [N] through :func:`bearingsim.laws.oil_film_drag` (vectorised; reference)."""
        n = laws.outer_race_normal_load(self.mass, self.pitch_radius, self.omega_c, theta, self.gravity)
        return laws.oil_film_drag(self.drag_coefficient, n, self.rolling_velocity)

    def acceleration(self, theta):
        """Free-flight acceleration a(θ) = −g sin θ − F_o/m [m/s²] (vectorised; reference)."""
        return -self.gravity * np.sin(theta) - self.drag_force(theta) / self.mass

    def normal_load_roots(self) -> tuple[float, ...]:
        """Angles in (0, 2π) where N = 0 (empty above ~313 rpm on the reference bearing) [rad]."""
        if self.gravity <= 0.0:
            return ()
        ratio = self.centripetal / self.gravity
        if ratio > 1.0:
            return ()
        lo = math.acos(-ratio)
        return (lo, 2.0 * math.pi - lo) if lo < math.pi else (math.pi,)


# ---- scalar kernels (numba) -------------------------------------------------------------------
@njit(cache=True)
def drag_accel(theta, drag_scale, centripetal, gravity):
    """F_o(θ)/m [m/s²] = K (r_p ω_c² + g cos θ)^0.246, and 0 where N ≤ 0 (never NaN)."""
    n_over_m = centripetal + gravity * math.cos(theta)
    if n_over_m <= 0.0:
        return 0.0
    return drag_scale * n_over_m**laws.DRAG_LOAD_EXPONENT


@njit(cache=True)
def net_accel(theta, drag_scale, centripetal, gravity):
    """a(θ) = −g sin θ − F_o(θ)/m [m/s²], the roller's free-flight acceleration in the pocket."""
    return -gravity * math.sin(theta) - drag_accel(theta, drag_scale, centripetal, gravity)


@njit(cache=True)
def sin_minus_x(h):
    """sin h − h without cancellation [-] (series for |h| < 1, stopped once a term no longer changes
    the sum: the later terms are smaller still, so the result is that of the full series)."""
    if abs(h) >= 1.0:
        return math.sin(h) - h
    h2 = h * h
    term = -h * h2 / 6.0
    total = term
    k = 3
    while k < 25:
        term = -term * h2 / ((k + 1) * (k + 2))
        new = total + term
        if new == total:
            break
        total = new
        k += 2
    return total


@njit(cache=True)
def gravity_dv(theta0, theta, omega, gravity):
    """∫ −g sin θ dt from θ0 to θ [m/s], θ = ω t + const, written without cancellation."""
    h = theta - theta0
    return -2.0 * gravity / omega * math.sin(theta0 + 0.5 * h) * math.sin(0.5 * h)


@njit(cache=True)
def gravity_dl(theta0, theta, omega, gravity):
    """Displacement due to gravity from rest at θ0: ∫∫ −g sin θ dt dt [m], without cancellation."""
    h = theta - theta0
    one_minus_cos = 2.0 * math.sin(0.5 * h) ** 2
    return gravity / omega**2 * (math.cos(theta0) * sin_minus_x(h) - math.sin(theta0) * one_minus_cos)


from bearingsim._jit import drop_stale_caches  # noqa: E402

drop_stale_caches(__name__, (laws,))  # the kernels here compile in laws.py constants
