"""Whole-bearing numbers docs/multibody.md, docs/whatif.md and docs/geometry.md quote, measured on the default (exact-face) scene.

    python benchmarks/whole_bearing.py whatif   # the what-if table: cage guidance, rig (1 warm-up + 20 rotations)
    python benchmarks/whole_bearing.py orbit    # cage whirl against pocket clearance and speed (1 warm-up + 10 rotations)
    python benchmarks/whole_bearing.py wear     # the wear-test scene: front / rear wear totals (1 warm-up + 40 rotations)
    python benchmarks/whole_bearing.py extent   # I_dec against the pocket faces' extent at 3000 rpm (1 warm-up + 20 rotations)
    python benchmarks/whole_bearing.py checks   # the numbers of tests/test_multibody.py's fixtures (3000 rpm, 970 N)
    python benchmarks/whole_bearing.py rig      # the rig's flat pocket 0 against the reduced model between the scenario files' speeds

Each prints a markdown table; every run is an ordinary ``bearingsim.run`` of a scenario in ``scenarios/``
with the ``--set`` overrides shown in its row. Each table is several such runs, minutes or more; nothing is
written. Also runs as ``python -m benchmarks.whole_bearing TABLE``.
"""
from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import bearingsim
from bearingsim.scenario import load_scenario

SCENARIOS = Path(__file__).resolve().parents[1] / "scenarios"


def _run(name, sets):
    return bearingsim.run(load_scenario(SCENARIOS / f"{name}.toml", list(sets)))


def _orbit(r):
    """(mean, max) distance of the cage centre from the axis over the recorded samples [m]."""
    o = np.asarray(r.get("cage_orbit"))
    o = o[np.isfinite(o[:, 1])]
    rad = np.hypot(o[:, 1], o[:, 2])
    return float(rad.mean()), float(r.summary["cage_orbit_max_m"])


def whatif():
    print("| rpm | cage | I_dec [mN s] | I_acc [mN s] | orbit mean / max [µm] | cage slip | land [mN s] |")
    print("|---|---|---|---|---|---|---|")
    for rpm in (3000, 6000):
        for guidance in ("rollers", "outer_land", "inner_land"):
            r = _run(f"multibody_{rpm}rpm", ["numerics.rotations=20", f"bearing.cage_guidance={guidance}"])
            _row(rpm, guidance, r)
    for guidance in ("rollers", "outer_land"):
        r = _run("rig_3000rpm", ["numerics.rotations=20", f"bearing.cage_guidance={guidance}"])
        per = np.asarray(r.get("per_rotation/I_dec"))
        print(f"| 3000 | rig, {guidance}: pocket 0 (flat) / the 15 arc pockets | {per[:, 0].mean() * 1e3:.2f} ± "
              f"{per[:, 0].std() * 1e3:.2f} / {per[:, 1:].mean() * 1e3:.2f} | | | | |")
        _row(3000, f"rig, {guidance}, all 16 pockets", r)


def _row(rpm, label, r):
    s = r.summary
    land = s.get("land_normal_impulse_mean_Ns", s.get("land_normal_impulse_Ns"))
    land_txt = "–" if land is None or not math.isfinite(land) else f"{land * 1e3:.1f}"
    om, ox = _orbit(r)
    print(f"| {rpm} | {label} | {s['I_dec_mean_Ns'] * 1e3:.2f} ± {s['I_dec_std_Ns'] * 1e3:.2f} | "
          f"{s['I_acc_mean_Ns'] * 1e3:.2f} ± {s['I_acc_std_Ns'] * 1e3:.2f} | {om * 1e6:.0f} / {ox * 1e6:.0f} | "
          f"{s['cage_slip'] * 100:.3f} % | {land_txt} |", flush=True)


def _whirl(r):
    """The cage centre's mean angular speed about the axis over the kept samples, as a fraction of the
    cage's own speed (1: whirl with the cage, forward; 0: a centre that stays at one angle)."""
    o = np.asarray(r.get("cage_orbit"))
    o = o[np.isfinite(o[:, 1])]
    ang = np.unwrap(np.arctan2(o[:, 2], o[:, 1]))
    rate = (ang[-1] - ang[0]) / (o[-1, 0] - o[0, 0])
    return float(rate / (r.parameters.operating.sign * r.parameters.operating.omega_c))


def orbit():
    print("| rpm | pocket clearance s [mm] | orbit mean / max [µm] | max / s | whirl rate / cage speed | rests at [deg] "
          "| I_dec [mN s] | cage slip |")
    print("|---|---|---|---|---|---|---|---|")
    cases = [(rpm, 0.2) for rpm in (500, 1000, 2000, 3000, 4000, 6000)]
    cases += [(rpm, s) for rpm in (1000, 3000, 6000) for s in (0.1, 0.3, 0.4)]
    for rpm, s in cases:
        r = _run("multibody_3000rpm", ["numerics.rotations=10", f"operating.inner_ring_speed_rpm={rpm}",
                                        f"bearing.pocket_clearance_mm={s}"])
        om, ox = _orbit(r)
        print(f"| {rpm} | {s} | {om * 1e6:.0f} / {ox * 1e6:.0f} | {ox / (s * 1e-3):.2f} | {_whirl(r):+.3f} | "
              f"{r.summary['cage_rest_angle_deg']:.0f} | {r.summary['I_dec_mean_Ns'] * 1e3:.2f} | "
              f"{r.summary['cage_slip'] * 100:.3f} % |",
              flush=True)


def wear():
    r = _run("wear_test_6000rpm", [])
    w = {k: float(np.sum(np.asarray(r.get(f"wear/{k}")))) for k in
         ("paper_index_front", "paper_index_rear", "sliding_work_front", "sliding_work_rear")}
    print(f"front / rear wear totals, impulse index (Eq. 16): {w['paper_index_front'] / w['paper_index_rear']:.3f}; "
          f"sliding work: {w['sliding_work_front'] / w['sliding_work_rear']:.3f}; I_dec {r.summary['I_dec_mean_Ns'] * 1e3:.2f} "
          f"mN s, I_acc {r.summary['I_acc_mean_Ns'] * 1e3:.2f} mN s")


def extent():
    print("| faces | I_dec mean ± std [mN s] | orbit mean / max [µm] | whirl rate / cage speed | cage slip |")
    print("|---|---|---|---|---|")
    for a in ("auto", 20.0, 26.0):
        r = _run("multibody_3000rpm", ["numerics.rotations=20", f"multibody.pocket_face_half_angle_deg={a!r}"
                                       if a == "auto" else f"multibody.pocket_face_half_angle_deg={a}"])
        om, ox = _orbit(r)
        label = "cage wall (-32.9 / +26.2 deg)" if a == "auto" else f"+-{a:g} deg"
        print(f"| {label} | {r.summary['I_dec_mean_Ns'] * 1e3:.2f} ± {r.summary['I_dec_std_Ns'] * 1e3:.2f} | "
              f"{om * 1e6:.0f} / {ox * 1e6:.0f} | {_whirl(r):+.3f} | {r.summary['cage_slip'] * 100:.3f} % |", flush=True)


def where_forces_act(r):
    """Where the forces act (paper Sec. 3.1, Fig. 5): (the share of the net drive F_acc - F_dec within
    phi + 15 deg of the load-zone centre, the F_dec onset after the load zone [deg], theta [deg], the mean
    F_dec over pockets per bin of theta) of a run, phi its load-zone half angle."""
    th = r.get("theta_deg")
    phi = r.summary["load_zone_half_angle_deg"]
    net = (r.get("force_vs_theta_acc") - r.get("force_vs_theta_dec")).mean(axis=1)
    pos = np.clip(net, 0, None)
    lz = (th <= phi + 15) | (th >= 360 - phi - 15)
    fdec = r.get("force_vs_theta_dec").mean(axis=1)
    nl = (th > phi) & (th < 180)
    onset = th[nl][np.argmax(fdec[nl] > 0.1 * fdec[nl].max())]
    return pos[lz].sum() / pos.sum(), onset, th, fdec


def checks():
    base = ["reduced.load_zone_half_angle_deg=23.5", "numerics.warmup_rotations=1"]
    fwd = _run("multibody_3000rpm", [*base, "numerics.rotations=20"])
    rev = _run("multibody_3000rpm", [*base, "numerics.rotations=20", "operating.direction=reverse"])
    fr = _run("multibody_3000rpm", [*base, "numerics.rotations=10", "contact.cage_friction=0"])
    s = fwd.summary
    print(f"deepest overlap {s['max_penetration_all_m'] / fwd.parameters.bearing.pocket_clearance:.2%} of s; "
          f"angular-momentum residual {s['torque_balance_residual']:.2e}; frictionless I_acc / I_dec "
          f"{fr.summary['I_acc_mean_Ns'] / fr.summary['I_dec_mean_Ns']:.4f}; reverse / forward I_dec "
          f"{rev.summary['I_dec_mean_Ns'] / s['I_dec_mean_Ns']:.4f}; load-zone half angle "
          f"{s['load_zone_half_angle_deg']:.2f} deg, contact extent {s['load_zone_contact_half_angle_deg']:.2f} deg; "
          f"I_dec {s['I_dec_mean_Ns'] * 1e3:.2f} ± {s['I_dec_std_Ns'] * 1e3:.2f} mN s, slip {s['cage_slip']:.3%}")
    phi = s["load_zone_half_angle_deg"]
    drive, onset, th, fdec = where_forces_act(fwd)
    band = (th >= 240) & (th <= 300)
    facc = fwd.get("force_vs_theta_acc").mean(axis=1)
    lz = (th <= phi + 15) | (th >= 360 - phi - 15)
    print(f"drive within phi + 15 deg {drive:.1%} (F_acc itself {facc[lz].sum() / facc.sum():.1%}, at 60-180 deg "
          f"{facc[(th > 60) & (th < 180)].sum() / facc.sum():.1%}); F_dec onset {onset:.1f} deg (phi {phi:.2f}); "
          f"share of F_dec at 240-300 deg {fdec[band].sum() / fdec.sum():.2f}")
    # the reduced-equivalent scene against the event model, and its dt convergence
    from bearingsim.multibody.core import choose_dt
    from bearingsim.parameters import Parameters
    from bearingsim.reduced.core import PassInputs
    from bearingsim.reduced.event import solve_event
    from bearingsim.simulation import run as simulate

    rel = []
    for rpm in (1000, 3000, 6000):
        sc = load_scenario(SCENARIOS / "multibody_3000rpm.toml", [*base, "numerics.rotations=1",
                           "multibody.scene=reduced_equivalent", f"operating.inner_ring_speed_rpm={rpm}"])
        ref = solve_event(PassInputs.from_parameters(Parameters.from_scenario(sc))).I_dec
        rel.append(simulate(sc).per_rotation["I_dec"].mean() / ref - 1.0)
        if rpm == 3000:
            _, _, lim = choose_dt(Parameters.from_scenario(sc))
            vals = [simulate(sc, dt=lim * f).per_rotation["I_dec"].mean() for f in (0.5, 0.25, 0.125, 0.0625)]
    print("reduced-equivalent / event - 1 at 1000 / 3000 / 6000 rpm: " + " / ".join(f"{x:+.2%}" for x in rel)
          + f"; dt halved three times: spread {np.ptp(vals) / np.mean(vals):.1e} of I_dec")
    dyn = _run("multibody_3000rpm", [*base, "numerics.rotations=8", "multibody.inner_ring=dynamic"])
    print(f"dynamic ring against quasi-static: displacement {dyn.summary['inner_ring_displacement_m'] / s['inner_ring_displacement_m'] - 1:+.2%}, "
          f"I_dec {dyn.per_rotation['I_dec'].mean() / fwd.per_rotation['I_dec'].mean() - 1:+.1%}", flush=True)


def rig():
    """The rig study of ``bearingsim validate`` (bearingsim.studies.rig) at speeds between the scenario files'."""
    from bearingsim.studies.rig import rig_table

    print("| rpm | rig pocket 0 I_dec mean ± std [mN s] | reduced [mN s] | ratio | the 15 arc pockets [mN s] |")
    print("|---|---|---|---|---|")
    for r in rig_table(speeds=(750, 1500, 2500, 3500), rotations=20, jobs=2):
        print(f"| {r['rpm']:g} | {r['pocket0_I_dec_mean_Ns'] * 1e3:.2f} ± {r['pocket0_I_dec_std_Ns'] * 1e3:.2f} | "
              f"{r['reduced_I_dec_Ns'] * 1e3:.2f} | {r['pocket0_I_dec_mean_Ns'] / r['reduced_I_dec_Ns']:.2f} | "
              f"{r['arc_pockets_I_dec_mean_Ns'] * 1e3:.2f} |", flush=True)


TABLES = {"whatif": whatif, "orbit": orbit, "wear": wear, "extent": extent, "checks": checks, "rig": rig}


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python benchmarks/whole_bearing.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("table", choices=tuple(TABLES))
    return ap


def main(argv=None) -> None:
    TABLES[parser().parse_args(argv).table]()


if __name__ == "__main__":
    main()
