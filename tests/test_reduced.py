"""Physics tests of the reduced single-pocket model (Suzuki et al. 2023, §2.3; docs/physics.md).

Paper numbers are cited where they are used. The event solver is the reference; the euler solver is
the paper's own scheme (Eqs. 7-8) and must converge to it.
"""
import math
import re

import numpy as np
import pytest

from .conftest import SCENARIOS, si
from scipy.integrate import quad

from bearingsim.simulation import run as simulate
from bearingsim.reduced.core import PassInputs
from bearingsim.reduced.euler import max_stable_dt, solve_euler
from bearingsim.reduced.event import solve_event
from bearingsim.studies.fig9 import idec_per_rotation, paper_scenario


SCENARIO_6000 = SCENARIOS / "paper_6000rpm.toml"


def _inputs(rpm, **kw):
    return PassInputs.from_parameters(si(paper_scenario(rpm, **kw)))


@pytest.fixture(scope="module")
def pass_6000():
    return solve_event(_inputs(6000))


def test_first_rear_impact_speed_table4(pass_6000):
    """Table 4: first rear impact at 6000 rpm hits at 0.112 m/s. Tolerance 0.5 %: the paper prints three
    digits (0.1115-0.1125). s = 0.20 mm was reconstructed from this very number (docs/physics.md, reference
    bearing), so this checks that the reconstruction and the model agree to the printed digits; a 2 % window
    let a rolling speed 6 % off (Eq. 4 with the pitch radius) through at 0.1106 m/s."""
    rear = pass_6000.impacts["face"] == 0
    u = pass_6000.impacts["approach_speed"][rear][0]
    assert u == pytest.approx(0.112, rel=0.005)


def test_first_rear_impact_energy_table4():
    """Table 4: e_k = 8.15e-5 J at 6000 rpm, checked on the number a run reports (``first_impact_energy_J``,
    the value docs/validation.md quotes) and on its definition, e_k = m u^2 / 2 with the run's roller mass and
    first impact speed (to round-off). e_k = m u^2 / 2 doubles the speed's 0.5 % tolerance: 1 % (the paper's
    8.15e-5 J is its rounded speed squared times its roller mass; the preset's mass gives 8.17e-5 J)."""
    from bearingsim import load_scenario

    r = simulate(load_scenario(SCENARIO_6000))
    e, u = r.summary["first_impact_energy_J"], r.summary["first_impact_speed_m_s"]
    assert e == pytest.approx(8.15e-5, rel=0.01, abs=0)
    assert e == pytest.approx(0.5 * r.scenario.parameters.bearing.roller_mass * u**2, rel=1e-12, abs=0)


def test_idec_flat_above_2000rpm_fig9():
    """§3.1 and Fig. 9: I_dec per rotation hardly changes between 2000 and 6000 rpm (±10 % of the mean).

    The paper puts no number on it ("almost the same", docs/validation.md), and its Fig. 9 is not in the
    repository to be read, so the band is not a reading precision. It is the size of what moves a flat
    curve of this model pointwise: the roller's momentum when the pass is cut at 2π − φ (mid-bounce), m v_end,
    a sawtooth in speed (test_previous_model_departs_at_low_speed_agrees_at_high_speed). Measured every
    250 rpm from 2000 to 6000 rpm: m v_end from −0.55 mN s (4750 rpm) to +0.36 mN s, up to 9.9 % of the
    plateau's 5.53 mN s; a narrower band would test the cut's phase, not the plateau. Measured here
    (1000-rpm steps, the Fig. 9 study's speeds): 5.55 / 5.28 / 5.75 / 5.34 / 5.75 mN s, at most −4.6 %
    (3000 rpm) off their mean of 5.53. Not every speed is inside: the smooth part of I_dec (its braking
    impulse, without the sawtooth) rises 17 % from 2000 to 6000 rpm, and at 4500 rpm, where the sawtooth
    adds to it, I_dec is 6.12 mN s, +10.9 % off the 250-rpm grid's mean."""
    values = np.array([idec_per_rotation(n) for n in (2000, 3000, 4000, 5000, 6000)])
    assert np.all(np.abs(values / values.mean() - 1.0) <= 0.10), values


def test_idec_larger_at_low_speed_fig9():
    """§3.1 and Fig. 9: I_dec is larger below 1000 rpm than in the 2000-6000 rpm plateau.

    The paper says "larger", no number. Measured: 12.89 mN s at 500 rpm against a plateau of 5.68 (mean of
    2000, 4000, 6000 rpm), 2.27 times. The threshold, 1.5 times, must lie above what the plateau alone
    reaches, 1.11 times its mean (6.12 mN s at 4500 rpm against 5.52, the mean of a 250-rpm grid from 2000
    to 6000 rpm: the pass-cut sawtooth, see the test above), so that a rise is not the sawtooth; it lies about midway (on a log scale) between that and
    the measured 2.27, a third below the measurement. The paper's previous model (no gravity, no resting
    contact: 2.72 mN s at 500 rpm, 0.48 times) fails it, as its physics should."""
    plateau = np.mean([idec_per_rotation(n) for n in (2000, 4000, 6000)])
    assert idec_per_rotation(500) > 1.5 * plateau


def test_previous_model_departs_at_low_speed_agrees_at_high_speed():
    """§3.1 / Fig. 9: the previous model (no gravity, no resting contact) departs from the present model
    below 1000 rpm (> 30 % at 500 rpm) and agrees at 2000 rpm and above.

    "Agrees" is checked where physics makes it exact. By the momentum balance of a pass,
    I_dec - I_acc = m v_end - m ∫ a dt: the braking part -m ∫ a dt is smooth in speed, while m v_end (the
    roller's momentum when the pass is cut at 2π - φ, mid-bounce) is a sawtooth in speed whose phase
    differs between the two models. Above 2000 rpm gravity integrates to ~0 over the symmetric pass, so
    the braking parts must agree within 1 %, and the I_dec curves (mean over 2000-6000 rpm) within 10 %.
    Pointwise the sawtooth alone separates them by up to m|Δv_end| ≈ 14 % of I_dec (5500 rpm)."""
    m = 0.013

    def both(n):
        cur = solve_event(_inputs(n), trace_points=0)
        prev = solve_event(_inputs(n, previous=True), trace_points=0)
        return cur, prev

    cur, prev = both(500)
    assert abs(prev.I_dec / cur.I_dec - 1.0) > 0.30
    speeds = np.arange(2000, 6001, 500)
    cur_i, prev_i = [], []
    for n in speeds:
        cur, prev = both(n)
        braking_cur = cur.I_dec - cur.I_acc - m * cur.v_end
        braking_prev = prev.I_dec - prev.I_acc - m * prev.v_end
        assert abs(braking_prev / braking_cur - 1.0) < 0.01, n
        cur_i.append(cur.I_dec)
        prev_i.append(prev.I_dec)
    assert abs(np.mean(prev_i) / np.mean(cur_i) - 1.0) < 0.10


@pytest.mark.parametrize("rpm", [500, 3000])
def test_forward_and_reverse_identical(rpm):
    """Fig. 7: forward and reverse rotation give the same I_dec. The reduced model's pass is written in the
    pocket's frame, θ measured along the cage's rotation from the load-zone centre (the bottom), and reads
    no direction: its equation, a(θ) = -g sin θ - F_o(N(θ))/m with N = m (r_p ω_c² + g cos θ) (Eqs. 1-3),
    must then be what the lab frame gives for either sense of rotation. Derived here independently: a pocket
    at lab angle α = -π/2 + sθ moving in the sense s = ±1 has the unit vector of its motion
    e_t = s (-sin α, cos α) and the outward radius e_r = (cos α, sin α); gravity (0, -g) pushes the roller
    along the motion by g·e_t and onto the outer race by g·e_r. The model's a(θ) and N(θ) equal those for
    both senses to rounding (1e-12 of g), and the whole pass run through the scenario layer with
    direction = reverse equals the forward one to rounding (1e-12)."""
    from bearingsim import laws

    fwd = simulate(paper_scenario(rpm, direction="forward"))
    rev = simulate(paper_scenario(rpm, direction="reverse"))
    assert rev.summary["I_dec_mean_Ns"] == pytest.approx(fwd.summary["I_dec_mean_Ns"], rel=1e-12, abs=0)
    assert rev.summary["I_acc_mean_Ns"] == pytest.approx(fwd.summary["I_acc_mean_Ns"], rel=1e-12, abs=1e-18)
    theta = np.linspace(0.0, 2.0 * np.pi, 721)
    for direction, sense in (("forward", 1.0), ("reverse", -1.0)):
        inp = _inputs(rpm, direction=direction)
        alpha = -0.5 * np.pi + sense * theta
        g_t = -inp.gravity * sense * np.cos(alpha)  # (0, -g) · s (-sin α, cos α)
        g_r = -inp.gravity * np.sin(alpha)  # (0, -g) · (cos α, sin α)
        n_lab = inp.mass * (inp.centripetal + g_r)
        drag = laws.oil_film_drag(inp.drag_coefficient, n_lab, inp.rolling_velocity) / inp.mass
        assert np.max(np.abs(inp.acceleration(theta) - (g_t - drag))) <= 1e-12 * inp.gravity, direction
        n_model = laws.outer_race_normal_load(inp.mass, inp.pitch_radius, inp.omega_c, theta, inp.gravity)
        assert np.max(np.abs(n_model - n_lab)) <= 1e-12 * inp.mass * inp.gravity, direction


@pytest.mark.parametrize("rpm", [500, 1000, 6000])
def test_momentum_balance_of_a_pass(rpm):
    """Newton's second law over the whole pass: m (v_end - v_start) = m ∫ a dt + I_dec - I_acc, with the
    free-flight acceleration a(θ) = -g sin θ - F_o/m integrated independently by adaptive quadrature
    (scipy quad, rel. 1e-12; it does not use the solver's Chebyshev tables). Both sides are O(1e-2) N s;
    they must agree to 1e-9 relative to I_dec (quadrature and rounding, many orders below physics)."""
    inp = _inputs(rpm)
    sol = solve_event(inp, trace_points=0)
    integral, _ = quad(lambda th: float(inp.acceleration(th)) / inp.omega_c, inp.theta_start, inp.theta_end,
                       epsabs=0.0, epsrel=1e-12, limit=400)
    lhs = inp.mass * (sol.v_end - 0.0)
    rhs = inp.mass * integral + sol.I_dec - sol.I_acc
    assert abs(lhs - rhs) <= 1e-9 * sol.I_dec


@pytest.mark.parametrize("e, u, window", [(0.8, 0.05, 1e-3), (0.5, 0.1, 2e-4), (0.9, 0.02, 5e-3), (0.8, 0.05, 1.0)])
def test_a_bounce_sequence_cut_by_the_windows_end_credits_the_bounces_inside_it(e, u, window):
    """Without resting contact (``resting_contact = false``, the previous model) a Zeno sequence closed at theta
    is credited the impulses of the bounces that land before the window's end, in closed form: bounce k hits at
    u e^k and lands 2 u e^(k+1) / a after the one before (a constant acceleration a towards the face), each
    impulse m u e^k (1 + e). Checked against the bounces summed one by one, for sequences the window cuts and
    one it holds whole (the geometric series' sum, the last case); 1e-12. No paper scenario reaches this
    branch, so a wrong power of e in it passed every other test."""
    from bearingsim.reduced.event import _zeno_credit

    m, a, omega, th = 0.013, 9.81, 100.0, 1.0
    wend = th + window * omega  # the time left in the window: (wend - th) / omega = window
    landed, total, k = 0.0, 0.0, 0
    while k < 10_000:
        if k > 0:
            landed += 2.0 * u * e ** k / a
        if landed > window:
            break
        total += m * u * e ** k * (1.0 + e)
        k += 1
    got = _zeno_credit(m, u, e, False, omega, a, th, wend)
    assert got == pytest.approx(total, rel=1e-12, abs=0), (k, got, total)
    assert _zeno_credit(m, u, e, True, omega, a, th, wend) == m * u  # resting contact: m u, the rest by momentum


@pytest.mark.parametrize("rpm", [500, 1000])
def test_zeno_closure_is_exact(rpm):
    """A bounce sequence closed into resting contact carries m u + ∫ m|a| dt by momentum balance, so the
    threshold at which it is closed must not change I_dec (beyond rounding, 1e-12), while it does change
    how many impacts are resolved one by one."""
    inp = _inputs(rpm)
    fine = solve_event(inp, trace_points=0, zeno_height=1e-7)
    coarse = solve_event(inp, trace_points=0, zeno_height=1e-2)
    assert coarse.impacts["theta"].size < fine.impacts["theta"].size
    assert coarse.I_dec == pytest.approx(fine.I_dec, rel=1e-12, abs=0)


def test_euler_converges_to_event_at_first_order():
    """Eqs. 7-8 are first-order accurate, so the error of I_dec against the event solution halves as dt
    halves. Measured at 500 rpm (mostly resting contact, where the error is smooth in dt) over
    dt = 8, 4, 2, 1 µs: every observed order log2(err(dt)/err(dt/2)) must lie in [0.8, 1.25]."""
    inp = _inputs(500)
    ref = solve_event(inp, trace_points=0).I_dec
    dts = [8e-6, 4e-6, 2e-6, 1e-6]
    errs = [abs(solve_euler(inp, dt, trace_points=0).I_dec - ref) / ref for dt in dts]
    orders = [math.log2(errs[i] / errs[i + 1]) for i in range(len(errs) - 1)]
    assert all(0.8 <= p <= 1.25 for p in orders), (errs, orders)


@pytest.mark.parametrize("rpm", [2000, 6000])
def test_euler_error_shrinks_with_dt_at_speed(rpm):
    """Where impacts dominate, the euler error is first order but not monotone (impact instants fall
    between steps). Over two decades of dt (1e-5 to 1e-7 s) it must fall by at least 10x overall,
    and at dt = 1e-7 s it must be below 1e-4 (first-order bound: dt / pass time ~ 1e-5)."""
    inp = _inputs(rpm)
    ref = solve_event(inp, trace_points=0).I_dec
    e_big = abs(solve_euler(inp, 1e-5, trace_points=0).I_dec - ref) / ref
    e_small = abs(solve_euler(inp, 1e-7, trace_points=0).I_dec - ref) / ref
    assert e_small < e_big / 10 and e_small < 1e-4, (e_big, e_small)


def test_euler_refuses_a_step_that_is_too_large():
    """A step above the stability bound is refused with a message naming numerics.dt_s."""
    from bearingsim.errors import UserError

    inp = _inputs(6000)
    with pytest.raises(UserError, match=r"numerics\.dt_s.*at most"):
        solve_euler(inp, 10 * max_stable_dt(inp))


def test_a_step_given_to_run_is_recorded_as_the_scenarios_step():
    """``bearingsim.run(sc, dt=...)`` of the euler method stores the step as ``numerics.dt_s`` and says so
    in ``dt_choice`` (it said "event-driven: no time step"), as its archive's rerun takes it."""
    import bearingsim

    from .conftest import SCENARIOS

    sc = bearingsim.load_scenario(SCENARIOS / "paper_3000rpm.toml",
                                  set={"reduced.method": "euler", "numerics.rotations": 1})
    r = bearingsim.run(sc, dt=1e-6)
    assert (r.provenance["dt_s"], r.provenance["dt_choice"]) == (1e-6, "numerics.dt_s")
    assert r.scenario.numerics.dt_s == 1e-6


@pytest.mark.parametrize("dt", [-1.0, 0.0, float("nan")])
def test_euler_refuses_a_step_that_is_not_positive(dt):
    """A zero, negative or NaN step is no step (dt = -1 returned zero impulses; issue 30)."""
    from bearingsim.errors import UserError

    with pytest.raises(UserError, match=r"numerics\.dt_s"):
        solve_euler(_inputs(3000), dt)


def test_euler_refuses_a_pass_of_too_many_steps_before_running():
    """The step count of a pass is bounded up front, naming numerics.dt_s for a given step and the
    pocket clearance for the automatic one (1e-10 s at 3000 rpm: 4e8 steps; issue 30)."""
    from dataclasses import replace

    from bearingsim.errors import UserError
    from bearingsim.reduced import solve_pass
    from bearingsim.reduced.euler import MAX_STEPS_PER_PASS, steps_per_pass

    inp = _inputs(3000)
    assert steps_per_pass(inp, 1e-10) > MAX_STEPS_PER_PASS
    with pytest.raises(UserError, match=r"numerics\.dt_s.*steps"):
        solve_euler(inp, 1e-10)
    tight = replace(inp, pocket_clearance=1e-12)
    with pytest.raises(UserError, match=r"bearing\.pocket_clearance_mm.*automatic"):
        solve_pass(tight, "euler")


def test_euler_automatic_step_refusal_at_a_crawl_names_the_speed_and_a_clearance_that_runs():
    """At 1 rpm the pass lasts minutes and the automatic step (set by the fastest approach across the pocket,
    which gravity keeps at any speed) needs 3.8e8 steps. Was: "bearing.pocket_clearance_mm: 0.2 mm makes the
    euler method's automatic step ... more than 1e+08; use reduced.method = "event" or a larger clearance",
    naming neither the speed that made the pass long nor how large a clearance would do (`bearingsim run
    scenarios/paper_3000rpm.toml --set reduced.method=euler --set operating.inner_ring_speed_rpm=1`). It names
    both; the clearance it gives is accepted."""
    from dataclasses import replace

    from bearingsim.errors import UserError
    from bearingsim.reduced import solve_pass
    from bearingsim.reduced.euler import check_step, default_dt

    inp = _inputs(1)
    with pytest.raises(UserError, match=r"^bearing\.pocket_clearance_mm: 0\.2 mm makes the euler method's automatic") as err:
        solve_pass(inp, "euler")
    msg = str(err.value)
    assert "operating.inner_ring_speed_rpm" in msg and "\n" not in msg, msg
    least = re.search(r"clearance of at least ([0-9.e+-]+) mm", msg)
    assert least, msg
    wide = replace(inp, pocket_clearance=float(least.group(1)) * 1e-3)
    check_step(wide, default_dt(wide), automatic=True)


def test_euler_impact_buffer_grows_without_changing_a_number():
    """A full impact buffer is grown between compiled chunks: the same pass as with room to spare."""
    inp = _inputs(500)
    a = solve_euler(inp, 1e-6, capacity=1)
    b = solve_euler(inp, 1e-6)
    assert a.impacts["theta"].size > 1
    assert (a.I_dec, a.I_acc, a.l_end, a.v_end) == (b.I_dec, b.I_acc, b.l_end, b.v_end)
    for k in a.impacts:
        assert np.array_equal(a.impacts[k], b.impacts[k])
    for k in a.trace:
        assert np.array_equal(a.trace[k], b.trace[k])


def test_roller_leaves_outer_race_without_nan():
    """Below ~313 rpm N = m r_p ω_c² + m g cos θ < 0 near the top (Eq. 3): the drag must be zero there,
    not NaN, and the pass must finish with finite impulses bounded by the impulse gravity and drag can
    supply, m ∫ |a| dt plus one impact from the largest possible speed, m (1 + e) sqrt(2 a_max s)."""
    inp = _inputs(150)
    assert inp.normal_load_roots(), "150 rpm must lift the roller off the outer race near the top"
    sol = solve_event(inp)
    assert np.isfinite(sol.I_dec) and np.isfinite(sol.I_acc)
    assert np.all(np.isfinite(sol.trace["l_r"]))
    bound, _ = quad(lambda th: abs(float(inp.acceleration(th))) / inp.omega_c, inp.theta_start, inp.theta_end,
                    limit=400)
    a_max = inp.gravity + inp.drag_scale * (inp.centripetal + inp.gravity) ** 0.246
    cap = inp.mass * bound + inp.mass * 1.8 * math.sqrt(2 * a_max * inp.pocket_clearance)
    assert 0 < sol.I_dec <= cap and 0 <= sol.I_acc <= cap
    assert np.all((sol.trace["l_r"] >= -1e-12) & (sol.trace["l_r"] <= inp.pocket_clearance + 1e-12))


def test_the_reduced_wear_says_it_is_of_the_no_load_pass_alone():
    """The reduced model's front-face wear is that of the no-load pass's front-face impacts, 0 from 3000 rpm up
    (I_acc = 0): read alone it said "no front-face wear", where the paper measured front and rear wear alike
    (Fig. 14). The group's description says what its numbers are of (Eq. 16 on the pass's impulses)."""
    res = simulate(paper_scenario(6000.0))
    wear = res.groups["results/wear"]
    assert wear.attrs["front_per_rotation_m3"] == 0.0 < wear.attrs["rear_per_rotation_m3"]
    assert "no-load pass" in wear.description and "F_acc" in wear.description and "not part of" in wear.description
