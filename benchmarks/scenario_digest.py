"""Digest and timing of scenario resolution, to check a change of the scenario layer bit for bit.

    python -m benchmarks.scenario_digest > after.txt

prints a SHA-256 of every shipped scenario's resolved TOML, raw table and SI parameters
(``scenarios/*.toml``, ``scenarios/hard/*.toml``), then, for each sweep file in ``scenarios/sweeps/``,
its case count, a SHA-256 of every case (hash, swept values, TOML, model, validated scenario model) and
the wall time :func:`bearingsim.sweeps.spec.resolve_cases` took. Run it on the code before and after
a change and compare the digests (the times are this machine's, at this moment). It takes no arguments and
writes nothing (the lines are printed); resolving the sweep files is most of its time (printed per file).
"""
from __future__ import annotations

import argparse
import glob
import hashlib
import time
from pathlib import Path

from bearingsim.scenario import load_scenario
from bearingsim.sweeps.spec import load_sweep_file, resolve_cases


def parser() -> argparse.ArgumentParser:
    return argparse.ArgumentParser(prog="python -m benchmarks.scenario_digest", description=__doc__,
                                   formatter_class=argparse.RawDescriptionHelpFormatter)


def main(argv=None) -> None:
    parser().parse_args(argv)
    h = hashlib.sha256()
    files = sorted(glob.glob("scenarios/*.toml") + glob.glob("scenarios/hard/*.toml"))
    for f in files:
        s = load_scenario(f)
        for part in (s.to_toml(), repr(s.raw), repr(s.parameters)):
            h.update(part.encode())
    print(f"{len(files)} scenarios {h.hexdigest()[:16]}")
    for f in sorted(Path("scenarios/sweeps").glob("*.toml")):
        t0 = time.perf_counter()
        cases = resolve_cases(load_sweep_file(f))
        wall = time.perf_counter() - t0
        h = hashlib.sha256()
        for c in cases:
            model = c.scenario.model_dump() if c.scenario is not None else None
            h.update(repr((c.hash, c.values, c.toml, c.model, model)).encode())
        print(f"{f.name}: {len(cases)} cases {h.hexdigest()[:16]}, resolved in {wall:.2f} s")


if __name__ == "__main__":
    main()
