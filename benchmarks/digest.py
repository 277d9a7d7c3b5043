"""Digest of every number each scenario gives, to check a refactor bit for bit against the code before it.

    python -m benchmarks.digest [--model reduced|multibody] [--rotations N] [--leave-out NAME,...] [SCENARIO ...]

prints one line per run: the scenario, the overrides, a SHA-256 of the summary (repr of each value),
every per-rotation array and the impact table, and I_dec. Only the scenarios of one model run (``--model``,
default reduced): check both. The reduced model runs each scenario with the event method and with the euler
method at dt = 2 µs; the multibody model runs N recorded rotations (default 3). Run it on the code before and
after a change and ``diff`` the two outputs. ``--leave-out`` leaves per-rotation arrays out of the hash: those
a change adds, so that the rest is checked against the code before it. Default scenarios: ``scenarios/*.toml``
and ``scenarios/hard/*.toml`` of the checkout.
"""
from __future__ import annotations

import argparse
import glob
import hashlib
import json

import numpy as np

import bearingsim


def digest(result, leave_out=()) -> str:
    h = hashlib.sha256()
    h.update(json.dumps({k: repr(v) for k, v in sorted(result.summary.items())}).encode())
    for i, table in enumerate((result.per_rotation, result.impacts)):
        for key in sorted(table):
            if i == 0 and key in leave_out:
                continue
            h.update(key.encode())
            h.update(np.ascontiguousarray(np.asarray(table[key])).tobytes())
    return h.hexdigest()[:16]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenarios", nargs="*")
    ap.add_argument("--model", choices=("reduced", "multibody"), default="reduced")
    ap.add_argument("--rotations", type=int, default=3)
    ap.add_argument("--leave-out", default="", help="per-rotation arrays to leave out of the hash, comma-separated")
    a = ap.parse_args(argv)
    leave_out = {k.strip() for k in a.leave_out.split(",") if k.strip()}
    files = a.scenarios or sorted(glob.glob("scenarios/*.toml") + glob.glob("scenarios/hard/*.toml"))
    for f in files:
        try:
            model = bearingsim.load_scenario(f).model
        except bearingsim.UserError as exc:
            print(f, "refused:", exc)
            continue
        if model != a.model:
            continue
        runs = ([{}, {"reduced.method": "euler", "numerics.dt_s": 2e-6}] if model == "reduced"
                else [{"numerics.rotations": a.rotations}])
        for overrides in runs:
            try:
                r = bearingsim.run(bearingsim.load_scenario(f, set=overrides))
            except (bearingsim.UserError, bearingsim.SimulationUnstable) as exc:
                print(f, overrides, type(exc).__name__, str(exc)[:100])
                continue
            print(f, overrides, digest(r, leave_out), r.summary.get("I_dec_mean_Ns"), flush=True)


if __name__ == "__main__":
    main()
