"""Time per call of the fast scene's step kernels, on a state of a real run (docs/fast_scene.md).

``python -m benchmarks.step_kernels [RPM ...]`` runs the reference bearing with rigid raceways (1 warm-up
+ 1 rotation, default 1000 rpm), keeps the step loop's inputs and its last state, and times each kernel
the compiled loop calls before a step, called 20 000 times from compiled code on that state:
``forces.raceway_forces`` (the raceway contacts, the inner ring's Newton solve, the race's share),
``forces.race_orbit`` (on a copy of the state, which it changes; the copy's cost printed apart),
``loop.arc_faces`` (placing the exact faces) and ``loop.face_masks``. Beside them: the whole step per
rotation and pymunk's share, from the same run. The kernels' arithmetic is that of the run; only the
state stays the same from call to call (the ring's Newton solve starts at its solution, so it takes
no iteration here: a real step takes one or two). Most of its time is compiling: the timing loops
are not cached and compile on every start; the runs are 1 warm-up + 1 rotation per speed. It writes nothing
(the table is printed).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from bearingsim.multibody import forces as fk
from bearingsim.multibody import loop as lp

CALLS = 20_000


@njit
def _forces(state, inp, wk, calls):
    for _ in range(calls):
        fk.raceway_forces(state, inp.h, inp.prm, wk.ring_c, wk.ring_c_prev, wk.ring_v, wk.hold, wk.out_f, wk.diag,
                          wk.n_out, wk.n_held)


@njit
def _copy(state, calls):
    for _ in range(calls):
        state.copy()


@njit
def _race_orbit(state, inp, wk, calls):
    for _ in range(calls):
        fk.race_orbit(state.copy(), inp.h, inp.prm, wk.hold, wk.n_extra, wk.diag)


@njit
def _arc_faces(state, inp, wk, calls):
    for _ in range(calls):
        lp.arc_faces(state, inp.h, inp.arc, wk.arc_ends, wk.arc_todo)


@njit
def _face_masks(state, vb, inp, fm, wk, want, calls):
    for _ in range(calls):
        lp.face_masks(state, vb, inp.h, fm, wk.arc_ends, want)


def _per_call(fn, *args) -> float:
    fn(*args, 10)  # compile
    t0 = time.perf_counter()
    fn(*args, CALLS)
    return (time.perf_counter() - t0) / CALLS


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.step_kernels", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("rpm", nargs="*", type=float, help="inner-ring speeds [rpm] (default: 1000)")
    return ap


def main(argv=None) -> int:
    speeds = parser().parse_args(argv).rpm or [1000.0]
    from benchmarks.multibody_bench import reference_scenario
    from bearingsim.multibody import core
    from bearingsim.parameters import Parameters

    kept = {}
    raw_of = core._raw

    def keep(su, pl, acc, st, loop_s, t_wall0):  # the loop's inputs and state at the end of the run
        kept.update(pl=pl, cur=int(st["cur"]))
        return raw_of(su, pl, acc, st, loop_s, t_wall0)

    core._raw = keep
    try:
        print("| rpm | steps per rotation | step [us] | pymunk's step [us] | raceway_forces [us] | race_orbit [us] "
              "| arc_faces [us] | face_masks [us] |")
        print("|---|---|---|---|---|---|---|---|")
        for rpm in speeds:
            raw = core.run(Parameters.from_scenario(reference_scenario(rpm, 1, 1, raceway_contact="rigid")))
            pl = kept["pl"]
            state = pl.io.states[kept["cur"]].copy()
            inp, wk = pl.inp, pl.wk
            fm = getattr(pl.io, "fm", None)
            forces = _per_call(_forces, state, inp, wk)
            orbit = _per_call(_race_orbit, state, inp, wk) - _per_call(_copy, state)
            arc = _per_call(_arc_faces, state, inp, wk) if inp.arc.active else float("nan")
            masks = float("nan")
            if fm is not None and fm.active:
                want = np.zeros(state.shape[0] - 1, dtype=np.uint32)
                masks = _per_call(_face_masks, state, np.zeros((state.shape[0], 3)), inp, fm, wk, want)
            step = raw.loop_s / raw.steps
            pym = raw.pymunk_step_s / raw.steps
            print(f"| {rpm:g} | {raw.steps / 2:.0f} | {step * 1e6:.1f} | {pym * 1e6:.1f} | {forces * 1e6:.2f} | "
                  f"{orbit * 1e6:.2f} | {arc * 1e6:.2f} | {masks * 1e6:.2f} |", flush=True)
    finally:
        core._raw = raw_of
        kept.clear()  # the run's pymunk space goes before the interpreter's shutdown
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
