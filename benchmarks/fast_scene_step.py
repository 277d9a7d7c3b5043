"""The rigid scene's automatic step at the overlap bound against 80 % of it, in one process.

``python -m benchmarks.fast_scene_step [RPM ...]`` runs the reference bearing (as ``bearingsim bench
--fast-scene``: 970 N, roller-guided, 1 warm-up + 40 rotations, rigid raceways) at each speed
(default 6000 rpm) with the automatic step's overlap fraction ``core.RIGID_IMPACT_OVERLAP_FRACTION`` set
to the bound (0.01, the rule before multibody model version 3) and to the present 0.008, alternating
the two three times. It prints, per run, the step kept, the restarts, the wall time per rotation of the
whole ``simulate`` call (restarts included) and of the kept run alone, the load average, and the
digest of the per-rotation impulses; then the median of each and the ratio of the medians (the
same-run comparison: both rules see the same machine load). Six runs of 1 warm-up + 40 rotations per
speed (and one short run that loads the kernels), minutes in all; it writes nothing (the table is printed).
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

from benchmarks.fast_scene_bench import impulse_digest
from benchmarks.multibody_bench import reference_scenario
from bearingsim.parameters import Parameters

ROTATIONS = 40
REPEATS = 3
FRACTIONS = (0.01, None)  # None: the module's own value


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.fast_scene_step", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rpm", nargs="*", type=float, help="inner-ring speeds [rpm] (default: 6000)")
    return ap


def main(argv=None) -> int:
    speeds = parser().parse_args(argv).rpm or [6000.0]
    from bearingsim.multibody import core, simulate

    present = core.RIGID_IMPACT_OVERLAP_FRACTION
    simulate(Parameters.from_scenario(reference_scenario(6000, 1, 0, raceway_contact="rigid")))  # load kernels
    for rpm in speeds:
        p = Parameters.from_scenario(reference_scenario(rpm, ROTATIONS, 1, raceway_contact="rigid"))
        calls = {f: [] for f in FRACTIONS}
        for _ in range(REPEATS):
            for f in FRACTIONS:
                core.RIGID_IMPACT_OVERLAP_FRACTION = present if f is None else f
                try:
                    t0 = time.perf_counter()
                    res = simulate(p)
                    call = (time.perf_counter() - t0) / (ROTATIONS + 1)
                finally:
                    core.RIGID_IMPACT_OVERLAP_FRACTION = present
                pv = res.provenance
                kept = float(pv["solver_wall_s"]) / (ROTATIONS + 1)
                calls[f].append((call, kept))
                print(f"{rpm:6.0f} rpm fraction {present if f is None else f:.3g}: dt {pv['dt_s'] * 1e6:.2f} us, "
                      f"restarts {pv['dt_choice'].count('restarted at dt')}, s per rotation {call:.4f} "
                      f"(kept run {kept:.4f}), load average {os.getloadavg()[0]:.2f}, "
                      f"impulses {impulse_digest(res)}", flush=True)
        med = {f: [statistics.median(c[k] for c in calls[f]) for k in (0, 1)] for f in FRACTIONS}
        print(f"{rpm:6.0f} rpm medians: bound {med[0.01][0]:.4f} s ({med[0.01][1]:.4f} kept), "
              f"{present:.3g}: {med[None][0]:.4f} s ({med[None][1]:.4f} kept); "
              f"ratio {med[None][0] / med[0.01][0]:.3f} (kept runs {med[None][1] / med[0.01][1]:.3f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
