"""Cage life with the clearance it wears: simulate, wear the pockets, simulate again (docs/wear.md).

A life study is a sequence of ``stages``. Stage ``j`` runs the scenario in the pockets the wear of the
stages before it left, reads the wear rate of every face from its wear profile
(:func:`bearingsim.wear.wear_report` per inner-ring rotation), and runs it on for as many rotations as
bring the limited quantity from ``j / stages`` to ``(j + 1) / stages`` of the limit at that rate (so the
last stage ends at the limit). The rates can change from stage to stage: the wear acts back through the
worn pockets.

How the wear maps onto the next stage's geometry (``mapping``, :data:`MAPPINGS`):

* ``shape`` (the default): the worn depth is added to each face where it wore. The depth accumulated by
  the stages before stage ``j``, per pocket, face and bin of psi, is stage ``j``'s ``[wear]
  worn_depth_front_um`` / ``worn_depth_rear_um``: each arc face is the pocket circle pushed outwards by it
  (:func:`bearingsim.multibody.loop.worn_contact`), a flat face by its mean (a uniform shift);
  ``bearing.pocket_clearance_mm`` stays as given. The pocket the next stage runs in is the worn one;
* ``uniform``: the pockets stay arcs and every pocket's clearance ``s`` grows by the worn depth of the
  worst pocket, front plus rear, each face's depth its mean over the face (worn volume / face area, so the
  model's pocket removes as much brass as wore): the clearance growth alone, without where the wear is.
  A scenario's own worn depth stays on its faces in every stage; ``s`` grows by the stages' wear only.

The stages split the way from the limited quantity at the start (the scenario's own worn faces, if
any; refused when they reach the limit already) to the limit into equal steps. Limits: ``depth`` (the
deepest point of any face), ``clearance`` (the effective pocket clearance of the worst pocket, ``s`` plus its front and rear
**mean** worn depth: worn volume / face area), ``volume`` (the largest worn volume of one face). A clearance
limit is absolute (``clearance=0.4mm``) or relative to the effective clearance at the start (``clearance=2x``:
the play doubles), which the study turns into the absolute value it means (:meth:`Limit.of_start`).

The stages are the cases of a staged study on the study engine (:mod:`bearingsim.studies.engine`), run in
sequence in one folder: ``cases/<hash>.h5`` (each a normal archive, named by its scenario's content hash),
the case index ``sweep.csv``/``sweep.h5``, and ``life.h5`` (the history, written atomically at the end)
with ``life.png``. A stage archive that stores exactly its stage's scenario and was computed by the
present model version is reused: an interrupted study resumes where it stopped.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.studies.engine import Study, case_of, load_result
from bearingsim.wording import by_kind, counted, run_notes

LIFE_FORMAT = "bearingsim life"
#: the root attribute of a life study's case index (``sweep.h5``) that holds the study's options from its start
#: (:meth:`LifeStudy.index_attrs`, JSON), which its folder check reads while no ``life.h5`` is written
INDEX_ATTR = "life_study"
#: limit kinds and the unit of each in the --limit text (SI factor)
LIMIT_UNITS = {"depth": {"mm": 1e-3, "um": 1e-6}, "clearance": {"mm": 1e-3, "um": 1e-6},
               "volume": {"mm3": 1e-9}}


@dataclass(frozen=True)
class Limit:
    kind: str  #: "depth", "clearance" or "volume"
    value: float  #: SI [m] or [m^3]; a relative limit's NaN until a study sets it (:meth:`of_start`)
    text: str  #: as given
    #: a relative clearance limit's factor (``clearance=2x``: the effective clearance twice its value at the
    #: study's start); None for an absolute limit
    factor: float | None = None

    @property
    def shown(self) -> str:
        """The limit as asked and, for a relative one set for a study, the absolute value it means there:
        ``clearance=2x (0.4 mm)`` (an absolute limit: as given)."""
        if self.factor is None or not math.isfinite(self.value):
            return self.text
        return f"{self.text} ({self.value * 1e3:.6g} mm)"

    def of_start(self, start: float) -> Limit:
        """A relative limit set for a study whose effective clearance at the start is ``start`` [m]: its factor
        times that; an absolute limit as it is."""
        return self if self.factor is None else replace(self, value=self.factor * start)

    def same_as(self, other: Limit) -> bool:
        """Whether ``other`` asks for this limit: the same kind, both absolute and of one value (in any unit:
        depth=100um is depth=0.1mm) or both relative and of one factor; an absolute limit is not the relative
        one, even where they meet."""
        if other.kind != self.kind or (other.factor is None) != (self.factor is None):
            return False
        if self.factor is None:
            return math.isclose(other.value, self.value, rel_tol=1e-12)
        return math.isclose(float(other.factor), self.factor, rel_tol=1e-12)


#: how the wear of a stage acts back on the next (docs/wear.md, *Life*)
MAPPINGS = {
    "shape": "the worn depth added to each face where it wore (per pocket, face and bin of psi); flat faces "
             "shifted by their mean",
    "uniform": "every pocket's clearance grows by the worst pocket's mean worn depth, front + rear (the "
               "pockets stay arcs)",
}


def depth_limit_note(scenario, limit: Limit) -> str | None:
    """For a ``depth`` limit: the deepest point is an end bin's, and the wear at a face's edge is a line,
    whose depth doubles each time the bins of psi halve (docs/wear.md, *Discretization errors*), so the
    rotations to a depth limit are those of the recorder's bin width; None for the other limits, which
    read volumes."""
    if limit.kind != "depth":
        return None
    from bearingsim.multibody.recorder import FACE_BINS

    lo, hi = scenario.parameters.multibody.pocket_face_extent
    return (f"--limit {limit.text} reads the deepest worn point, in the runs measured a face's edge, an end bin "
            f"({math.degrees(hi - lo) / FACE_BINS:.3g} deg of psi wide): the wear at a face's edge is a line, whose "
            "depth doubles each time the bins halve, so the rotations to a depth limit are those of this bin "
            "width (docs/wear.md); clearance= and volume= limits read volumes, which do not depend on it")


#: the fewest stages whose life, with the worn shape fed back, the measured study puts within 2 % of twice as
#: many (docs/wear.md, *The life depends on the stage count*: 10 stages read it 11-16 % long against 40)
STAGES_RESOLVED = 20


def stage_count_note(stages: int, mapping: str) -> str | None:
    """With the worn shape fed back and fewer than :data:`STAGES_RESOLVED` stages: the life is read long, by
    the measured amount (docs/wear.md); None otherwise (the uniform growth moves it by at most 1.2 %)."""
    if mapping != "shape" or stages >= STAGES_RESOLVED:
        return None
    return (f"{counted(stages, 'stage')} with the worn shape fed back: each stage wears at the rate its run "
            "measured at its start, and the rate grows as the edges wear, so few stages read the life long (on the "
            "wear-test bearing 10 stages gave 11-16 % more rotations than 40, and 20 stages within 2 % of 40; "
            f"docs/wear.md); give --stages {STAGES_RESOLVED} or more")


#: the forms of --limit, as its refusals name them
LIMIT_FORMS = "depth=<x>mm, clearance=<x>mm, clearance=<f>x (f times the clearance at the start) or volume=<x>mm3"


def parse_limit(text: str) -> Limit:
    """``depth=0.1mm``, ``clearance=0.5mm`` or ``volume=2mm3`` (also ``um`` for lengths), or a relative clearance
    limit, ``clearance=2x``: the effective pocket clearance ``f`` (above 1) times its value at the study's start,
    whose value a study sets (:meth:`Limit.of_start`)."""
    rel = re.fullmatch(r"\s*(\w+)\s*=\s*(.*?)\s*x\s*", text or "")
    if rel and rel.group(1) in LIMIT_UNITS:
        return _relative_limit(text, *rel.groups())
    m = re.fullmatch(r"\s*(\w+)\s*=\s*([0-9.eE+-]+)\s*(\w+)\s*", text or "")
    if not m or m.group(1) not in LIMIT_UNITS:
        raise UserError(f"--limit {text!r}: give {LIMIT_FORMS}")
    kind, num, unit = m.groups()
    if unit not in LIMIT_UNITS[kind]:
        also = " or <f>x (f times the clearance at the start)" if kind == "clearance" else ""
        raise UserError(f"--limit {text!r}: the unit of {kind} is one of {', '.join(LIMIT_UNITS[kind])}{also}")
    try:
        value = float(num) * LIMIT_UNITS[kind][unit]
    except ValueError:
        raise UserError(f"--limit {text!r}: {num!r} is not a number") from None
    if not (math.isfinite(value) and value > 0):
        raise UserError(f"--limit {text!r}: must be a finite positive number")
    return Limit(kind, value, text.strip())


def _relative_limit(text: str, kind: str, num: str) -> Limit:
    """``clearance=<f>x`` (:func:`parse_limit`): refused for another kind, and unless ``f`` is a finite number
    above 1 (at 1 or below the clearance is there at the start)."""
    if kind != "clearance":
        raise UserError(f"--limit {text!r}: a relative limit (<f>x) is for the clearance only; give "
                        f"{kind}=<x>{next(iter(LIMIT_UNITS[kind]))} or clearance=<f>x")
    try:
        factor = float(num)
    except ValueError:
        factor = math.nan
    if not (math.isfinite(factor) and factor > 1.0):
        raise UserError(f"--limit {text!r}: give a finite factor above 1 before the x (clearance=2x: the effective "
                        f"pocket clearance twice its value at the start)")
    return Limit(kind, math.nan, text.strip(), factor)


def recorded_options(meta: dict) -> dict | None:
    """The options of a life study that a case index's attributes ``meta`` record (:data:`INDEX_ATTR`), as a
    ``life.h5``'s attributes hold them (:meth:`LifeStudy.options`); None when it records none (another sweep or
    study, or a life study of a bearingsim that did not record them) or none that reads."""
    import json

    try:
        held = json.loads(str(meta.get(INDEX_ATTR) or ""))
    except ValueError:
        return None
    keys = ("limit", "stages", "rotations", "scenario", "mapping")
    return held if isinstance(held, dict) and all(k in held for k in keys) else None


def held_limit(text: str) -> Limit | None:
    """The limit a history's attribute ``limit`` holds (:attr:`Limit.shown`: a relative limit with the absolute
    value it meant, ``clearance=2x (0.4 mm)``, whose factor is what it asked), or None when it says none."""
    try:
        return parse_limit(re.sub(r"\s*\(.*\)\s*$", "", str(text or "")))
    except UserError:
        return None


class _State:
    """The wear accumulated up to a stage: depth profiles and volumes of every face, running time."""

    def __init__(self, s0: float, start=None):
        self.s0 = s0
        self.depth = start  # (2, bins, pockets) front, rear [m]; the scenario's own worn depth or None
        self.volume = None  # (2, pockets) [m^3]
        self.start_volume = None  # (2, pockets) [m^3]: the scenario's own worn depth's volume (0 without one)
        self.shaft = 0.0
        self.hours = 0.0
        self.area = 0.0  # one face's area [m^2]

    def quantity(self, kind: str, depth, volume):
        """The limited quantity of a (depth, volume) state: per element, the one that reaches it first."""
        if kind == "depth":
            return depth.reshape(-1)
        if kind == "volume":
            return volume.reshape(-1)
        return self.s0 + volume.sum(axis=0) / self.area  # clearance of each pocket worn so

    def clearance(self) -> float:
        if self.volume is None:
            return self.s0
        return float(self.s0 + self.volume.sum(axis=0).max() / self.area)

    def grown_clearance(self) -> float:
        """The pocket clearance of the uniform mapping's next stage: ``s`` grown by the worst pocket's mean
        worn depth (front + rear) of the stages run, without the scenario's own worn depth, which every
        stage's scenario keeps on its faces (counted once, not again in ``s``)."""
        if self.volume is None:
            return self.s0
        return float(self.s0 + (self.volume - self.start_volume).sum(axis=0).max() / self.area)


def pocket_rates(rate, kind: str) -> tuple[np.ndarray, np.ndarray, dict]:
    """The wear rates a stage wears on with, from its wear report per rotation ``rate``: ``(depth (2, bins,
    pockets) [m], volume (2, pockets) [m^3], its history columns)``: every pocket's as read (``kind``, the
    limit's, changes none). Of each pocket's front + rear worn volume per rotation: ``pocket_worst_read``, the
    worst pocket's rate over the pockets' mean; ``pocket_worst_scatter``, what the worst of identical pockets
    reads from the rotations' scatter alone (1 + :func:`bearingsim.stats.scatter_lead`; the worst of 16 noisy
    estimates leads by 1.77 of their standard errors: docs/wear.md, *The worst pocket*); ``pocket_uneven``, 1 when
    the pockets differ beyond that scatter (:func:`bearingsim.plausibility.face_spread`, the test of a run's note
    of uneven pockets); ``rate_sem_rel``, the relative batch-means error (:func:`bearingsim.stats.batch_sem`) of the
    rate the limit follows: for a clearance limit the worst pocket's (front + rear), for a volume limit the worst
    face's; NaN for a depth limit (a point's depth per rotation is not kept)."""
    from bearingsim.plausibility import face_spread
    from bearingsim.stats import batch_sem, scatter_lead

    d = np.stack([rate.depth_front, rate.depth_rear])
    v = np.stack([rate.volume_front, rate.volume_rear])
    per = rate.volume_rotations("front") + rate.volume_rotations("rear")  # (rotations, pockets)
    total = v.sum(axis=0)
    read = float(total.max() / total.mean()) if total.mean() > 0.0 else math.nan
    sem, uneven = math.nan, False
    if per.ndim == 2 and per.shape[0] >= 2 and per.shape[1] >= 2 and per.mean() > 0.0:
        worst = per[:, int(np.argmax(total))]
        if kind == "volume":  # the face that reaches a volume limit first: the largest rate of any face
            face, pocket = np.unravel_index(int(np.argmax(v)), v.shape)
            worst = rate.volume_rotations(("front", "rear")[face])[:, pocket]
        sem = batch_sem(worst) / worst.mean() if kind != "depth" and worst.mean() > 0.0 else math.nan
        cov, sampling, crit = face_spread(per)
        uneven = bool(cov > crit * sampling)
    return d, v, {"pocket_worst_read": read, "pocket_worst_scatter": 1.0 + scatter_lead(per),
                  "pocket_uneven": int(uneven), "rate_sem_rel": sem}


def life_error(cols: dict) -> float:
    """The sampling error of a history's life [h]: each stage's time times the relative error of the worst
    pocket's rate it wore on with (``rate_sem_rel``, :func:`pocket_rates`; a stage's length goes as 1 / that
    rate), the stages' errors independent and added in quadrature; NaN for a history written before it held
    the column, or of a depth limit. Not in it: how the trajectory's pocket differences grow
    through the worn shape fed back (docs/wear.md, *The worst pocket*: 27.6-35.2 h over four rotation counts
    per stage of multibody_6000rpm, where this error is 0.4-1.3 h)."""
    if "rate_sem_rel" not in cols:
        return math.nan
    hours = np.diff(np.concatenate([[0.0], np.asarray(cols["hours_end"], dtype=float)]))
    return float(np.sqrt(np.sum((hours * np.asarray(cols["rate_sem_rel"], dtype=float)) ** 2)))


def _stage_length(q_now, q_rate, target) -> float:
    """Inner-ring rotations until the first element of ``q_now + q_rate N`` reaches ``target``."""
    grow = q_rate > 0
    if not grow.any():
        raise UserError("no wear at this stage (no sliding work on any face): the limit is never reached")
    return float(np.min((target - q_now[grow]) / q_rate[grow]))


def stage_scenario(scenario, depth, index: int, rotations: int | None, clearance: float | None = None):
    """The scenario of stage ``index``: ``scenario`` with the worn depth ``depth`` ((2, bins, pockets) front,
    rear [m]; None: as it is) as its ``[wear] worn_depth_front_um`` and ``worn_depth_rear_um`` (rounded to
    1e-6 um), or (the uniform mapping) at pocket clearance ``clearance`` [m]."""
    over = {"name": f"{scenario.name}_stage{index:02d}"}
    if clearance is not None:
        over["bearing.pocket_clearance_mm"] = float(round(clearance * 1e3, 9))
    if depth is not None:
        for f, face in enumerate(("front", "rear")):
            over[f"wear.worn_depth_{face}_um"] = [[float(round(x * 1e6, 6)) for x in col] for col in depth[f].T]
    if rotations is not None:
        over["numerics.rotations"] = int(rotations)
    return scenario.replace(**over)


def _start_depth(scenario) -> np.ndarray | None:
    """The scenario's own worn depth as the start of the accumulated wear ((2, bins, pockets) [m]), or None;
    refused unless its bins are the wear profile's."""
    from bearingsim.multibody.recorder import FACE_BINS
    worn = scenario.parameters.wear.worn_depth
    if worn is None:
        return None
    arr = np.array(worn, dtype=np.float64)  # (pockets, 2, bins)
    if arr.shape[2] != FACE_BINS:
        raise UserError(f"{scenario.source}: wear.worn_depth_front_um: a life study adds the wear profile's "
                        f"{FACE_BINS} bins of psi to it; give {FACE_BINS} bins per pocket (got {arr.shape[2]})")
    return arr.transpose(1, 2, 0).copy()


def _bar(scenario) -> float:
    """The width of the cage bar between two pockets [m] (:func:`bearingsim.wear.bar_width`, which the wear
    report shares)."""
    from bearingsim.wear import bar_width

    return bar_width(scenario)


def _check_reachable(scenario, limit: Limit) -> None:
    """Refuse a limit that no wear can reach: with no wear (a wear coefficient of 0), or one that a face
    reaches only through a cage bar on its face: the deepest point of one face, or one face's volume over
    its area (its mean depth), at the bar's width or beyond; for a clearance, the mean worn depth of a
    pocket's front and rear faces at twice the bar's width or beyond, the two faces lying on the two bars
    either side of the pocket (:func:`bearingsim.laws.worn_bar_depth`), so that one of them alone is through
    its bar. A limit short of that may still come after a bar has worn through, which the stages find (the
    end of the life, not a refusal: :meth:`LifeStudy._bar_reached`)."""
    from bearingsim.wear import face_area

    if scenario.wear.wear_coefficient <= 0.0:
        raise UserError(f"{scenario.source}: wear.wear_coefficient = 0: nothing wears, so no limit is ever reached; "
                        f"give the pocket faces' wear coefficient (docs/wear.md)")
    b = scenario.bearing
    bar = _bar(scenario)
    if limit.kind == "depth":
        depth, what = limit.value, "a face worn that deep is through its bar on its own"
    elif limit.kind == "clearance":  # front + rear mean depth of one pocket, whose faces lie on two bars
        grown = limit.value - b.pocket_clearance_mm * 1e-3
        depth = 0.5 * grown
        what = (f"a pocket worn {grown * 1e3:.4g} mm wider, at least twice the bar's width (its front and rear "
                f"faces lie on the two bars either side of it), has a face through its bar on its own")
    else:
        depth = limit.value / face_area(scenario.parameters)
        what = f"a face worn that much ({depth * 1e3:.4g} mm deep on the mean) is through its bar on its own"
    if depth >= bar:
        raise UserError(f"--limit {limit.shown}: the cage bar between two pockets is {bar * 1e3:.4g} mm wide: {what}; "
                        f"give a smaller limit")


def _start_value(scenario, limit: Limit, s0: float, start) -> float:
    """The limited quantity before the first stage (SI): 0 (depth, volume) or ``s0`` (clearance) for unworn
    faces; with the scenario's own worn depth ``start`` ((2, bins, pockets) [m]) its deepest point, largest
    face volume or worst pocket's effective clearance, as the stages measure them."""
    if start is None:
        return s0 if limit.kind == "clearance" else 0.0
    from bearingsim.wear import face_area

    st = _State(s0, start)
    st.area = face_area(scenario.parameters)
    volume = start.sum(axis=1) * face_area(scenario.parameters, start.shape[1])  # (2, pockets)
    return float(st.quantity(limit.kind, start, volume).max())


def _limit_text(kind: str, value: float) -> str:
    """A limited quantity in the units of its limit: ``deepest 50 um`` and the like."""
    if kind == "depth":
        return f"deepest point {value * 1e6:.4g} um"
    if kind == "volume":
        return f"largest face volume {value * 1e9:.4g} mm3"
    return f"effective pocket clearance {value * 1e3:.4g} mm"


class LifeStudy(Study):
    """A life study (module docstring) as a staged study: stage ``j + 1``'s case is made from stage ``j``'s
    archive (:meth:`next_cases`), each run by the study engine (:func:`bearingsim.studies.run_studies`);
    :meth:`finish` writes ``life.h5`` and ``life.png``. Refused here, before anything is created: a
    scenario of the reduced model, an unknown ``mapping``, the ``shape`` mapping with polyline pocket faces
    (``multibody.pocket_face_segments`` not 0), ``stages`` outside 1..100, ``rotations`` below
    1, a clearance limit at or below the pocket clearance, a worn depth of the wrong bins. ``progress``: a
    callable given one line per stage when its wear is known (the command line prints them)."""

    name = "life"
    staged = True

    def __init__(self, scenario, limit: Limit, *, stages: int = STAGES_RESOLVED, rotations: int | None = None,
                 mapping: str = "shape", progress=None):
        from bearingsim import archive
        from bearingsim.outputs import is_own_png

        if scenario.model != "multibody":
            raise UserError(f"{scenario.source}: model = {scenario.model!r}: wear profiles need the whole bearing "
                            f"(model = \"multibody\")")
        if mapping not in MAPPINGS:
            raise UserError(f"--mapping {mapping}: give one of {', '.join(MAPPINGS)}")
        segments = scenario.parameters.multibody.pocket_face_segments
        if mapping == "shape" and segments != 0:
            raise UserError(f"{scenario.source}: multibody.pocket_face_segments = {segments}: --mapping shape (the "
                            f"default) feeds the worn depths back into the faces, which needs the exact arc faces "
                            f"(multibody.pocket_face_segments = 0); give that, or --mapping uniform, which works "
                            f"with polyline faces")
        if not 1 <= stages <= 100:
            raise UserError(f"--stages {stages}: give 1 to 100 stages")
        if rotations is not None and rotations < 1:
            raise UserError(f"--rotations {rotations}: give at least 1 recorded rotation per stage")
        s0 = scenario.bearing.pocket_clearance_mm * 1e-3
        if limit.factor is not None:  # clearance=2x: twice the effective clearance at the start
            limit = limit.of_start(_start_value(scenario, limit, s0, _start_depth(scenario)))
        if limit.kind == "clearance" and limit.value <= s0:
            raise UserError(f"--limit {limit.text}: the pocket clearance is {s0 * 1e3:g} mm already "
                            f"(bearing.pocket_clearance_mm); give a larger one")
        _check_reachable(scenario, limit)
        start = _start_depth(scenario)
        self.start_value = _start_value(scenario, limit, s0, start)
        if self.start_value >= limit.value:
            raise UserError(f"--limit {limit.text}: {scenario.source}'s own worn faces ([wear] worn_depth_*_um) are "
                            f"there already ({_limit_text(limit.kind, self.start_value)}); give a larger limit")
        # the history keeps the scenario with the stages' recorded rotations ('bearingsim show life.h5' gives
        # what the stages ran); a history written before it did kept the scenario as given
        self.given_toml = scenario.to_toml()
        if rotations is not None:
            scenario = scenario.replace(**{"numerics.rotations": int(rotations)})
        self.scenario, self.limit, self.planned = scenario, limit, stages
        self.rotations, self.mapping, self.progress = rotations, mapping, progress
        self.state = _State(s0, start)
        self.rows: list[dict] = []
        #: why the life ended before the limit, when a pocket's faces wore through the cage bar (None: it did not)
        self.worn_through: str | None = None
        self.stage_cases = [self._case(0)]
        self.cases = list(self.stage_cases)
        self.outputs = [("life.h5", lambda p: archive.is_table_file(p, LIFE_FORMAT), "life history"),
                        ("life.png", is_own_png, "figure")]

    def _case(self, j: int):
        st = self.state
        sc = (stage_scenario(self.scenario, st.depth if j else None, j, self.rotations) if self.mapping == "shape"
              else stage_scenario(self.scenario, None, j, self.rotations, clearance=st.grown_clearance()))
        return case_of(sc, {"stage": j})

    def _bar_reached(self, d_rate, n_stage: float, psi_deg) -> float | None:
        """The inner-ring rotations into the present stage (``d_rate`` per rotation on the depth the stages
        before it left, for at most ``n_stage``) at which a cage bar wears through: the two faces on it, one
        pocket's front face and its neighbour's rear face, worn as deep together in a bin of psi (``psi_deg``,
        the bins' centres) as the bar is wide (:func:`bearingsim.laws.worn_bar_depth`, as a worn scenario is
        checked); None when none does within the stage. The depths grow linearly in it: bisection to 1e-9 of
        the stage."""
        from bearingsim.laws import worn_bar_depth

        bar = _bar(self.scenario)
        depth = self.state.depth

        def on_bar(n):
            d = depth + d_rate * n
            return worn_bar_depth(d[0], d[1])  # (bins, bars)

        if on_bar(n_stage).max() < bar:
            return None
        lo, hi = 0.0, n_stage
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if on_bar(mid).max() < bar else (lo, mid)
        k, i = np.unravel_index(np.argmax(on_bar(hi)), depth.shape[1:])
        self.worn_through = (f"pocket {i}'s front face and pocket {(i - 1) % depth.shape[2]}'s rear face, either "
                             f"side of the bar between them, reach its {bar * 1e3:.4g} mm together at psi = "
                             f"{float(psi_deg[k]):.3g} deg")
        return hi

    def next_cases(self, outdir: Path, records: dict[str, dict]) -> list:
        """The wear of the last stage run (its archive's wear rate, for as many rotations as bring the
        limited quantity to its next step), then the next stage's case; none after the last stage."""
        from bearingsim.wear import wear_report

        j = len(self.rows)
        record = records[self.stage_cases[j].hash]
        res = load_result(outdir, record)
        st = self.state
        rate = wear_report(res, rotations=1.0)
        d_rate, v_rate, spread = pocket_rates(rate, self.limit.kind)
        if st.volume is None:
            st.area = rate.bin_area * len(rate.psi_deg)
            st.depth = np.zeros_like(d_rate) if st.depth is None else st.depth
            st.volume = st.depth.sum(axis=1) * rate.bin_area
            st.start_volume = st.volume.copy()
        clearance = st.clearance()
        start = self.start_value  # the limited quantity at the start: the scenario's own worn faces, if any
        goal = start + (self.limit.value - start) * (j + 1) / self.planned
        q_now = st.quantity(self.limit.kind, st.depth, st.volume)
        q_rate = st.quantity(self.limit.kind, d_rate, v_rate) - (st.s0 if self.limit.kind == "clearance" else 0.0)
        n_stage = _stage_length(q_now, q_rate, goal)
        n_bar = self._bar_reached(d_rate, n_stage, rate.psi_deg)  # the bar wears through first: the life ends there
        n_stage = n_stage if n_bar is None else n_bar
        st.depth = st.depth + d_rate * n_stage
        st.volume = st.volume + v_rate * n_stage
        st.shaft += n_stage
        st.hours += n_stage * rate.hours
        self.rows.append(_row(j, clearance, res, rate, n_stage, st, record["status"] == "cached") | spread)
        if self.progress:
            self.progress(f"stage {j:02d} of {self.planned}: {'reused' if self.rows[-1]['reused'] else 'run'}, "
                          f"I_dec {res.summary['I_dec_mean_Ns'] * 1e3:.4g} mN s; worn on for {n_stage:.4g} inner-ring "
                          f"(shaft) rotations, deepest worn point {st.depth.max() * 1e6:.4g} um"
                          + ("; the cage bar wears through: the life ends here" if self.worn_through else ""))
        if j + 1 == self.planned or self.worn_through:
            return []
        self.stage_cases.append(self._case(j + 1))
        return [self.stage_cases[-1]]

    def cases_to_come(self, known: set[str]) -> int:
        """The stages not among ``known`` (each is made from the one before it); none after the stage in which
        the cage bar wore through."""
        if self.worn_through:
            return 0
        return self.planned - sum(c.hash in known for c in self.stage_cases)

    def columns(self) -> dict:
        """The history's columns, one row per stage run so far."""
        return {k: np.array([r[k] for r in self.rows]) for k in self.rows[0]}

    def finish(self, outdir: Path, records: dict[str, dict]) -> list[Path]:
        """``life.h5`` (written atomically) and ``life.png``, once every stage has run or a stage has worn the
        cage bar through (after a failed stage: nothing, the failure is the engine's to tell)."""
        from bearingsim import archive
        from bearingsim.plotting import save_figure

        if len(self.rows) < self.planned and not self.worn_through:
            return []
        cols, attrs = self.columns(), self.attrs()
        archive.write_table_file(outdir / "life.h5", cols, LIFE_UNITS, attrs, LIFE_DESCRIPTIONS)
        return [outdir / "life.h5", save_figure(plot_life(cols, attrs), outdir / "life.png")]

    def options(self) -> dict:
        """The study's options, as its history's attributes hold them and :meth:`_differs` compares them: the limit
        (:attr:`Limit.shown`), the stages, the recorded rotations per stage, the scenario (with those rotations)
        and the wear mapping."""
        return {"limit": self.limit.shown, "stages": self.planned, "rotations": self.stage_rotations,
                "scenario": self.scenario.to_toml(), "mapping": self.mapping}

    def index_attrs(self) -> dict:
        """The study's options (:meth:`options`, as JSON) in the case index's root attribute :data:`INDEX_ATTR`,
        written before its first stage runs: a folder whose ``life.h5`` is not written yet (the study interrupted,
        or a stage failed) is resumed with these options only (:meth:`check_folder`)."""
        import json

        return {INDEX_ATTR: json.dumps(self.options(), sort_keys=True)}

    def attrs(self) -> dict:
        """The history's attributes (``life.h5``): the study (:meth:`options`), ``worn_through`` when the cage bar
        wore through before the limit (what reached its width; the time is the last stage's end), and for a
        clearance limit ``life_error_h``, the life's sampling error (:func:`life_error`)."""
        attrs = {"format": LIFE_FORMAT, **self.options(), "mapping_text": MAPPINGS[self.mapping]}
        if self.worn_through:
            attrs["worn_through"] = self.worn_through
        error = life_error(self.columns()) if self.rows else math.nan
        if math.isfinite(error):  # a clearance limit's (docs/wear.md, The worst pocket)
            attrs["life_error_h"] = error
        return attrs

    def _differs(self, attrs: dict) -> str:
        """What of a ``life.h5``'s study (its attributes) is not this one's: "" when the same, else what
        differs (the scenario, the limit, the number of stages, the rotations per stage; a limit is the
        same in other units: depth=100um is depth=0.1mm; a relative clearance limit, clearance=2x, is not an
        absolute one of the value it means: :meth:`Limit.same_as`). The scenario is the one with the stages'
        rotations, or, in a history written before it held that, the one given with ``--rotations``."""
        held = held_limit(attrs.get("limit", ""))
        ours = {self.scenario.to_toml(), self.given_toml}
        if "rotations" in attrs and int(attrs["rotations"]) != self.stage_rotations:  # told below, not as a scenario
            ours.add(self.scenario.replace(**{"numerics.rotations": int(attrs["rotations"])}).to_toml())
        if attrs.get("scenario") not in ours:
            return "scenario or limit"
        if held is None or not held.same_as(self.limit):
            return f"limit ({attrs.get('limit', 'none')}; this one: --limit {self.limit.shown})"
        if int(attrs.get("stages", self.planned)) != self.planned:
            return f"number of stages ({attrs['stages']}; this one: --stages {self.planned})"
        if "rotations" in attrs and int(attrs["rotations"]) != self.stage_rotations:
            return f"number of rotations per stage ({attrs['rotations']}; this one: --rotations {self.stage_rotations})"
        return ""

    def _other_study(self, path: Path, attrs: dict, study: str) -> str | None:
        """The refusal of the life study whose options ``attrs`` holds (a ``life.h5``'s attributes, or those its
        case index recorded: :func:`recorded_options`; ``path``: the file, ``study``: what it holds) when it is not
        this one (:meth:`_differs`, the mapping), naming the option and the value that resumes it; None when it is
        this one."""
        what = self._differs(attrs)
        held = attrs.get("mapping", "uniform")  # a history without one predates the shape mapping
        again = "to resume it, another folder, or --force to replace it"
        limit = held_limit(attrs.get("limit", ""))
        if what.startswith("number of stages") and "stages" in attrs:  # e.g. one of the earlier default, 10
            return f"{path}: holds {study} of another {what}; give --stages {int(attrs['stages'])} {again}"
        if what.startswith("number of rotations"):
            return f"{path}: holds {study} of another {what}; give --rotations {int(attrs['rotations'])} {again}"
        if what.startswith("limit") and limit is not None:
            return f"{path}: holds {study} of another {what}; give --limit {limit.text} {again}"
        if what:
            return f"{path}: holds {study} of another {what}; give another folder or --force"
        if held != self.mapping:
            return (f"{path}: holds {study} with another wear mapping (--mapping {held}; this one: "
                    f"{self.mapping}); give --mapping {held} {again}")
        return None

    @property
    def stage_rotations(self) -> int:
        """The recorded cage rotations of each stage (``--rotations``, or the scenario's)."""
        return int(self.rotations or self.scenario.numerics.rotations)

    def check_folder(self, outdir: Path, force: bool) -> None:
        """Refuse a folder that holds another life study (another scenario, limit, number of stages, rotations per
        stage or mapping in its ``life.h5``, or, before that is written, in its case index's :data:`INDEX_ATTR`,
        which the study records at its start) or another sweep or study (a case index without this study's first
        stage), unless ``force``: then that study's files are removed. This study interrupted before its
        ``life.h5`` was written resumes. A refusal names the option that differs and, where one value resumes the
        folder's study, that value."""
        from bearingsim import archive
        from bearingsim.sweeps.index import INDEX_FORMAT, read_index

        path = outdir / "life.h5"
        index = outdir / "sweep.h5"
        other = None
        if path.exists():
            other = self._other_study(path, archive.read_table_file(path, LIFE_FORMAT)[1], "a life study")
        elif archive.is_table_file(index, INDEX_FORMAT):
            cols, meta = read_index(index)
            held = recorded_options(meta)
            if held is not None:  # the options the study recorded at its start
                other = self._other_study(index, held, "an unfinished life study")
            elif self.stage_cases[0].hash not in {str(h) for h in cols["case"]}:
                other = (f"{outdir}: holds another sweep or study (its case index has not this life study's first "
                         f"stage); not mixed in: give another folder, or add --force to replace it")
        if other is None:
            return
        if not force:
            raise UserError(other)
        from bearingsim.sweeps.run import remove_other_study

        remove_other_study(outdir)  # bearingsim's case archives only: a user's file in cases/ stays


def run_life(scenario, folder, limit: Limit, *, stages: int = STAGES_RESOLVED, rotations: int | None = None,
             force: bool = False, progress=None, mapping: str = "shape", engine=None) -> dict:
    """Run a life study (module docstring, :class:`LifeStudy`) into ``folder`` on the study engine (default:
    one local worker process); return the history's columns (also written as ``folder/life.h5``, with
    ``life.png``). When a pocket's faces wear through the cage bar before the limit, the life ends there: the
    history ends at that time, and ``life.h5``'s attribute ``worn_through`` says what reached the bar's
    width. A stage that fails raises :class:`bearingsim.errors.UserError` with its one-line error (the stages
    before it are kept); SIGINT/SIGTERM/SIGHUP raise KeyboardInterrupt (the same call resumes)."""
    import signal

    from bearingsim.studies.engine import run_studies

    study = LifeStudy(scenario, limit, stages=stages, rotations=rotations, mapping=mapping, progress=progress)
    out = run_studies([study], folder, engine=engine, progress=False, log=lambda line: None, force=force)
    if out.interrupted is not None:
        raise KeyboardInterrupt(signal.Signals(out.interrupted).name)
    if out.failed:
        r = out.failed[0]
        raise UserError(f"life stage {r['values']['stage']} failed: {r['error']}")
    return study.columns()


LIFE_UNITS = {"stage": "1", "clearance_start_mm": "mm", "stage_rotations": "1", "rotations_end": "1",
              "hours_end": "h", "max_depth_rate_um_per_h": "um/h", "max_volume_rate_mm3_per_h": "mm^3/h",
              "max_depth_um": "um", "max_volume_mm3": "mm^3", "clearance_end_mm": "mm", "I_dec_mean_mNs": "mN s",
              "reused": "1", "psi_deg": "deg", "worn_depth_front_um": "um", "worn_depth_rear_um": "um",
              "pocket_worst_read": "1", "pocket_worst_scatter": "1", "pocket_uneven": "1", "rate_sem_rel": "1"}
#: what the history's columns are (their datasets' ``description`` in ``life.h5``, which ``inspect`` lists); the
#: rotations are the inner ring's, as the stage's time: the recorded cage rotations per stage are the root's
#: ``rotations``
LIFE_DESCRIPTIONS = {
    "stage_rotations": "inner-ring (shaft) rotations the stage wears on for",
    "rotations_end": "inner-ring (shaft) rotations from the start to the stage's end",
    "hours_end": "running time from the start to the stage's end",
    "clearance_start_mm": "effective pocket clearance at the stage's start (worst pocket: s + mean worn depth)",
    "clearance_end_mm": "effective pocket clearance at the stage's end (worst pocket: s + mean worn depth)",
    "max_depth_rate_um_per_h": "the fastest point's depth rate in the stage: the largest of any point of any face, "
                               "which drives a depth limit (not the deepest point's own rate)",
    "max_volume_rate_mm3_per_h": "the largest worn-volume rate of any face in the stage",
    "pocket_worst_read": "the worst pocket's worn-volume rate (front + rear) over the pockets' mean, as the stage's "
                         "rotations read it",
    "pocket_worst_scatter": "the same that identical pockets read from the rotations' scatter alone, on average "
                            "(1 + 1.77 standard errors for 16 pockets; docs/wear.md, The worst pocket)",
    "pocket_uneven": "1 when the pockets' spread is beyond the rotations' scatter (the test of the note of uneven "
                     "pockets)",
    "rate_sem_rel": "the relative batch-means standard error of the rate the limit follows: the worst pocket's "
                    "worn-volume rate (clearance limits) or the worst face's (volume limits); the life's error is "
                    "these times the stages' hours, in quadrature",
}


#: the history's column of the effective pocket clearance at a stage's start, under the name it had before
#: (``pocket_clearance_mm``, the name of the scenario's key ``bearing.pocket_clearance_mm``, which the shape
#: mapping keeps as given): :func:`read_life` reads it under its present name
OLD_COLUMNS = {"pocket_clearance_mm": "clearance_start_mm"}


def _row(j, clearance, res, rate, n_stage, st, reused) -> dict:
    """One stage's history row; ``clearance``: the effective pocket clearance it ran at [m] (the worst
    pocket's ``s`` plus its front and rear mean worn depth at the stage's start: ``clearance_start_mm``, not
    the scenario's ``s``, which the shape mapping keeps). The worn depth at the stage's end is
    ``worn_depth_*_um`` [bin, pocket], at the bins ``psi_deg``; ``notes``: the stage's run notes, one a
    line (:func:`bearingsim.sweeps.index.notes_text`)."""
    from bearingsim.sweeps.index import notes_text

    per_hour = 1.0 / rate.hours  # rate report is for one rotation
    return {
        "stage": j, "clearance_start_mm": clearance * 1e3, "stage_rotations": n_stage,
        "rotations_end": st.shaft, "hours_end": st.hours,
        "max_depth_rate_um_per_h": rate.max_new_depth * per_hour * 1e6,
        "max_volume_rate_mm3_per_h": float(max(rate.volume_front.max(), rate.volume_rear.max())) * per_hour * 1e9,
        "max_depth_um": float(st.depth.max()) * 1e6, "max_volume_mm3": float(st.volume.max()) * 1e9,
        "clearance_end_mm": st.clearance() * 1e3, "I_dec_mean_mNs": res.summary["I_dec_mean_Ns"] * 1e3,
        "reused": int(reused), "psi_deg": rate.psi_deg,
        "worn_depth_front_um": st.depth[0] * 1e6, "worn_depth_rear_um": st.depth[1] * 1e6,
        "notes": notes_text(res.notes),
    }


#: the history as a table, a row per stage (the command's, ``table``'s and the report's): (column, header,
#: width on the terminal, format); the worn-depth profiles of each stage are the figure's. s_eff: the effective
#: pocket clearance the stage ran at (the worst pocket's s plus its front and rear mean worn depth), not the
#: scenario's s, which the shape mapping keeps
HISTORY_TABLE = (("stage", "stage", 5, "d"), ("clearance_start_mm", "s_eff [mm]", 10, ".4f"),
                 ("stage_rotations", "shaft rotations", 15, ".4g"), ("hours_end", "h at end", 9, ".4g"),
                 ("max_depth_rate_um_per_h", "depth rate, fastest point [um/h]", 32, ".4g"),
                 ("max_depth_um", "deepest [um]", 13, ".4g"),
                 ("I_dec_mean_mNs", "I_dec [mN s]", 13, ".4g"),
                 ("pocket_worst_read", "worst/mean", 10, ".3f"),
                 ("pocket_worst_scatter", "of identical pockets", 20, ".3f"),
                 ("reused", "reused", 6, "d"))
#: the columns of a volume limit's quantity in place of the deepest point and the fastest point's depth rate
#: (:func:`history_table`)
VOLUME_COLUMNS = {"max_depth_rate_um_per_h": ("max_volume_rate_mm3_per_h", "volume rate [mm3/h]", 19, ".4g"),
                  "max_depth_um": ("max_volume_mm3", "largest volume [mm3]", 20, ".4g")}


def _is_volume(limit: str | None) -> bool:
    """Whether a study's limit as given (``volume=2mm3``, ``clearance=2x``, None) limits a face's worn volume."""
    return str(limit or "").split("=")[0].strip() == "volume"


def history_table(limit: str | None = None, cols: dict | None = None) -> tuple:
    """:data:`HISTORY_TABLE` for a study to ``limit`` (its text, ``volume=2mm3``): for a volume limit, the
    quantity it reads, the largest worn volume of a face, and its rate in place of the deepest point and the
    fastest point's depth rate (the largest of any point, which a depth limit reads); with a history's ``cols``,
    only the columns it holds (one written before the pockets' columns has none of them)."""
    table = HISTORY_TABLE
    if _is_volume(limit):
        table = tuple(VOLUME_COLUMNS.get(c[0], c) for c in HISTORY_TABLE)
    return table if cols is None else tuple(c for c in table if c[0] in cols)


def history_rows(cols: dict, table: tuple = HISTORY_TABLE) -> list[list[str]]:
    """The cells of ``table`` (:func:`history_table`), a row per stage."""
    return [[format(int(cols[c][i]) if f == "d" else float(cols[c][i]), f) for c, _, _, f in table]
            for i in range(len(cols["stage"]))]


def stage_notes(cols: dict) -> list[str]:
    """The stages' run notes (the history's ``notes`` column; none in a history written before it held
    them): each kind of note once, in the order they first come, with how many stages carry it. Notes of one
    kind differ in their numbers only (the warm-up note gives each stage's own rotations: 20 stages gave 20
    paragraphs that differ in a few digits); such a kind is given once, in the words of the first stage that
    carries it, and says so."""
    from bearingsim.sweeps.index import notes_of

    noted = [(int(stage), note) for stage, cell in zip(cols["stage"], cols.get("notes", ()))
             for note in dict.fromkeys(run_notes(notes_of(cell)))]  # each stage's notes, each once
    n = len(cols["stage"])
    return [f"note ({k} of {counted(n, 'stage')}"
            f"{f'; the numbers of stage {noted[i][0]}, the others differ in theirs' if differ else ''}): {noted[i][1]}"
            for i, k, differ in by_kind([note for _, note in noted]).values()]


def format_history(cols: dict, title: str, attrs: dict | None = None) -> str:
    """The history for the terminal, as ``bearingsim life`` prints it: ``title`` (``life of X to LIMIT``)
    with the life reached, or where the cage bar wore through first (``attrs``' ``worn_through``), then one
    row per stage (:func:`history_table` of ``attrs``' limit), then the stages' run notes
    (:func:`stage_notes`)."""
    attrs = attrs or {}
    table = history_table(attrs.get("limit"), cols)
    # two spaces between columns: their headers are words ("shaft rotations", "of identical pockets")
    lines = [life_headline(cols, title, attrs), "  ".join(f"{head:>{width}}" for _, head, width, _ in table)]
    lines += ["  ".join(f"{cell:>{width}}" for cell, (_, _, width, _) in zip(row, table))
              for row in history_rows(cols, table)]
    return "\n".join(lines + depth_notes(cols, attrs) + stage_notes(cols))


def life_headline(cols: dict, title: str, attrs: dict | None = None) -> str:
    """The first line of the history (:func:`format_history`), the study's answer: ``title`` with the life reached
    and its sampling error (``life of X to LIMIT: 34.06 ± 1.1 h = 1.226e+07 inner-ring rotations in 5 stages
    (±: ...)``), or where the cage bar wore through first (``attrs``' ``worn_through``)."""
    attrs = attrs or {}
    n = len(cols["stage"])
    when = f"{cols['hours_end'][-1]:.4g} h = {cols['rotations_end'][-1]:.4g} inner-ring rotations"
    if attrs.get("worn_through"):
        return (f"{title}: not reached, the cage bar wears through first, after {when}, in stage "
                f"{int(cols['stage'][-1])} (of {attrs.get('stages', '?')}): {attrs['worn_through']}")
    e = life_error(cols)
    when = when if not math.isfinite(e) else when.replace(" h = ", f" ± {e:.2g} h = ", 1)
    return f"{title}: {when} in {counted(n, 'stage')}{_error_text(cols, attrs.get('limit'))}"


def _error_text(cols: dict, limit: str | None = None) -> str:
    """`` (±: ...)``, what the ± of a history's life (:func:`life_error`) is, and the worst pocket's lead read
    against the one identical pockets read from the scatter; "" without the error (a history written before it
    held the columns, or of a depth limit). ``limit``: the history's limit as given (``volume=...`` follows the
    worst face, the others the worst pocket)."""
    if not math.isfinite(life_error(cols)):
        return ""
    read, scatter = (np.asarray(cols[c], dtype=float) for c in ("pocket_worst_read", "pocket_worst_scatter"))
    what = "face" if _is_volume(limit) else "pocket"
    return (f" (±: the sampling error of the worst {what}'s rates, not the trajectories' scatter; the worst pocket "
            f"read "
            f"{_span(read)} x the pockets' mean, identical pockets {_span(scatter)} x from the scatter alone, the "
            f"pockets uneven beyond it in {int(np.sum(cols['pocket_uneven']))} of {counted(len(read), 'stage')}; "
            f"docs/wear.md, The worst pocket)")


def _span(values: np.ndarray) -> str:
    """``lo-hi`` of ``values`` to 3 significant digits, or the one value when both read alike."""
    lo, hi = f"{values.min():.3g}", f"{values.max():.3g}"
    return lo if lo == hi else f"{lo}-{hi}"


def _history_start(attrs: dict, shape) -> np.ndarray:
    """The worn depth the first stage started from ((2, bins, pockets) [um]): the history's scenario's own
    ``[wear] worn_depth_*_um``, or none (zeros)."""
    import tomllib

    try:
        wear = tomllib.loads(str(attrs.get("scenario") or "")).get("wear", {})
        start = np.array([np.asarray(wear[f"worn_depth_{f}_um"], dtype=float).T for f in ("front", "rear")])
    except (tomllib.TOMLDecodeError, KeyError, ValueError):
        return np.zeros(shape)
    return start if start.shape == tuple(shape) else np.zeros(shape)


def stage_points(cols: dict, attrs: dict) -> list[dict]:
    """Per stage, from the history's worn-depth profiles (none in a history written before it held them: []):
    the deepest point at its end (``deepest``: depth [um] and (face, bin, pocket)) and how much it wore in the
    stage (``deepest_wore``), and the fastest point, the one that wore most in it, whose depth rate the history's
    ``max_depth_rate_um_per_h`` is (``fastest``, ``fastest_wore``). They differ: an end bin worn deep may wear no
    more once the roller no longer reaches it, while another point wears on."""
    if "worn_depth_front_um" not in cols:
        return []
    ends = np.stack([np.asarray(cols["worn_depth_front_um"], dtype=float),
                     np.asarray(cols["worn_depth_rear_um"], dtype=float)], axis=1)  # (stages, 2, bins, pockets)
    before, out = _history_start(attrs, ends.shape[1:]), []
    for end in ends:
        wore = end - before
        d = np.unravel_index(np.argmax(end), end.shape)
        f = np.unravel_index(np.argmax(wore), wore.shape)
        out.append({"deepest": (float(end[d]), d), "deepest_wore": float(wore[d]),
                    "fastest": (float(end[f]), f), "fastest_wore": float(wore[f])})
        before = end
    return out


def _where(cols: dict, j: int, point) -> str:
    face, k, pocket = (int(i) for i in point)
    return f"{('front', 'rear')[face]} face of pocket {pocket}, psi {float(cols['psi_deg'][j][k]):.3g} deg"


def _stopped(point: dict) -> bool:
    """Whether a stage's deepest point (:func:`stage_points`) did not wear in it, less than 0.1 % of what its
    fastest point wore."""
    wore = point["fastest_wore"]
    return wore > 0.0 and point["deepest_wore"] <= 1e-3 * wore and point["deepest"][1] != point["fastest"][1]


def _stopped_runs(points: list[dict]) -> list[tuple[int, int]]:
    """The runs of consecutive stages whose deepest point did not wear (:func:`_stopped`), as (first, last)."""
    runs: list[tuple[int, int]] = []
    for j, p in enumerate(points):
        if not _stopped(p):
            continue
        if runs and runs[-1][1] == j - 1:
            runs[-1] = (runs[-1][0], j)
        else:
            runs.append((j, j))
    return runs


def depth_notes(cols: dict, attrs: dict) -> list[str]:
    """A line for each stage in which the deepest point did not wear (less than 0.1 % of what the fastest point
    wore, :func:`stage_points`): the table's 'deepest' stays put while its depth rate is another point's."""
    notes = []
    for j, pt in enumerate(stage_points(cols, attrs)):
        (deep, d), (end, f), wore = pt["deepest"], pt["fastest"], pt["fastest_wore"]
        if _stopped(pt):
            notes.append(f"stage {j}: the deepest point ({deep:.4g} um: {_where(cols, j, d)}) did not wear in this "
                         f"stage; the stage's depth rate, {float(cols['max_depth_rate_um_per_h'][j]):.4g} um/h, is the "
                         f"fastest point's ({_where(cols, j, f)}), which wore {wore:.4g} um, to {end:.4g} um")
    return notes


def read_life(path) -> tuple[dict, dict]:
    """The history's columns and attributes of a ``life.h5``, or of a life study's folder (its
    ``life.h5``); a column of an older history under its present name (:data:`OLD_COLUMNS`)."""
    from bearingsim import archive

    path = Path(path)
    cols, attrs = archive.read_table_file(path / "life.h5" if path.is_dir() else path, LIFE_FORMAT)
    return {OLD_COLUMNS.get(k, k): v for k, v in cols.items()}, attrs


def plot_life(cols: dict, attrs: dict):
    """Worn depth, effective pocket clearance and wear rate against running time, stage by stage, and the
    worn faces: the depth profile over psi (mean over pockets) at the end of each stage."""
    from bearingsim.plotting import subplots

    h_end = cols["hours_end"]
    h_start = np.concatenate([[0.0], h_end[:-1]])
    fig, axes = subplots(1, 4, figsize=(16, 3.8))
    _plot_depths(axes[0], cols, attrs)
    axes[1].plot(np.concatenate([[0.0], h_end]), np.concatenate([[cols["clearance_start_mm"][0]],
                                                                   cols["clearance_end_mm"]]), "o-", color="C2")
    axes[1].set_ylabel("effective pocket clearance [mm]\n(worst pocket: s + mean worn depth)")
    axes[2].hlines(cols["max_depth_rate_um_per_h"], h_start, h_end, color="C3")
    axes[2].set_ylabel("fastest point's depth rate [µm/h]\n(largest of any point, not the deepest's)")
    axes[2].set_ylim(bottom=0.0)
    for ax in axes[:3]:
        ax.set_xlabel("running time [h]")
    _plot_worn_faces(axes[3], cols)
    end = "the cage bar worn through first, after " if attrs.get("worn_through") else ""
    error = life_error(cols)  # a clearance or volume limit's sampling error (docs/wear.md, The worst pocket)
    pm, what = ("", "")
    if math.isfinite(error):
        face = "face" if _is_volume(attrs.get("limit")) else "pocket"
        pm, what = f" ± {error:.2g}", f" (±: the worst {face}'s rates' sampling error)"
    fig.suptitle(f"life to {attrs.get('limit', '?')}: {end}{h_end[-1]:.3g}{pm} h, {cols['rotations_end'][-1]:.3g} "
                 f"inner-ring rotations, {counted(len(h_end), 'stage')}{what}\n"
                 f"{_life_subtitle(attrs)}", fontsize=9)
    fig.tight_layout()
    return fig


def _plot_depths(ax, cols: dict, attrs: dict) -> None:
    """The deepest point of any face at each stage's end, and each stage's fastest point (:func:`stage_points`)
    as a segment from its depth at the stage's start to its end, whose slope is the rate the third panel gives;
    a stage in which the deepest point did not wear is marked so."""
    h_end = np.asarray(cols["hours_end"], dtype=float)
    h_start = np.concatenate([[0.0], h_end[:-1]])
    points = stage_points(cols, attrs)
    shape = (2, *np.shape(cols["worn_depth_front_um"][0])) if points else (1,)
    first = float(_history_start(attrs, shape).max())  # the scenario's own worn depth, if any
    ax.plot(np.concatenate([[0.0], h_end]), np.concatenate([[first], cols["max_depth_um"]]), "o-", color="C0",
            label="deepest point of any face")
    if points:
        x = np.array([[a, b, np.nan] for a, b in zip(h_start, h_end)]).ravel()
        y = np.array([[p["fastest"][0] - p["fastest_wore"], p["fastest"][0], np.nan] for p in points]).ravel()
        ax.plot(x, y, "--", color="C3", lw=1.5, label="fastest point of each stage\n(slope: the third panel's rate)")
    for a, b in _stopped_runs(points):  # one label per run of stages: one per stage overlapped into a blur
        which = f"stage {a}" if a == b else f"stages {a}–{b}"
        ax.annotate(f"{which}: the deepest\npoint wears no more", (0.5 * (h_start[a] + h_end[b]),
                    max(points[j]["deepest"][0] for j in range(a, b + 1))), xytext=(0, -6),
                    textcoords="offset points", ha="center", va="top", fontsize=7)
    ax.set_ylabel("worn depth [µm]")
    ax.set_ylim(bottom=0.0)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2))  # below the axes: no data covered


def _life_subtitle(attrs: dict) -> str:
    """What a life figure is of, from its history's attributes: the scenario's name, speed and load, Archard's
    k and H (the life scales as H / k), the mapping and the rotations per stage."""
    import tomllib

    try:
        sc = tomllib.loads(str(attrs.get("scenario") or ""))
    except tomllib.TOMLDecodeError:
        sc = {}
    op, wr = sc.get("operating", {}), sc.get("wear", {})

    def num(d, key, unit):
        v = d.get(key)
        return f"{v:g} {unit}" if isinstance(v, (int, float)) and not isinstance(v, bool) else "?"
    return (f"{sc.get('name', '?')}: {num(op, 'inner_ring_speed_rpm', 'rpm')}, {num(op, 'radial_load_N', 'N')}; "
            f"Archard k = {num(wr, 'wear_coefficient', '').strip()}, H = {num(wr, 'hardness_Pa', 'Pa')} (the life "
            f"scales as H / k); {attrs.get('mapping', '?')} mapping, {attrs.get('rotations', '?')} recorded cage "
            f"rotations per stage")


def _plot_worn_faces(ax, cols: dict) -> None:
    """The worn depth over psi at each stage's end, mean over pockets: front face solid, rear dashed, a colour per
    stage, named by a colour bar (the stage and when it ended); the earlier stages drawn over the later ones, which
    lie above them, and every colour dark enough to read on white (histories written before life.h5 held the
    profiles: a note instead)."""
    if "worn_depth_front_um" not in cols:
        ax.text(0.5, 0.5, "no worn-depth profiles in this life.h5", ha="center", va="center", transform=ax.transAxes)
        return
    import matplotlib
    from matplotlib.colors import BoundaryNorm, ListedColormap

    n = len(cols["stage"])
    # viridis from its green (the first stage) to its dark purple (the last): its lighter greens and yellows fade
    # on white (contrast below 3)
    colours = [matplotlib.colormaps["viridis"](0.58 * (n - 1 - j) / max(n - 1, 1)) for j in range(n)]
    for j in range(n):
        psi = cols["psi_deg"][j]
        for key, style in (("worn_depth_front_um", "-"), ("worn_depth_rear_um", "--")):
            ax.step(psi, cols[key][j].mean(axis=1), where="mid", color=colours[j], lw=1.2, ls=style, zorder=3 + n - j)
    for style, face in (("-", "front"), ("--", "rear")):
        ax.plot([], [], color="0.3", ls=style, label=f"{face} face")
    ax.set_xlabel("ψ on the face: bore end ← 0 → rim end [deg]")
    ax.set_ylabel("worn depth, mean over pockets [µm]")
    ax.set_title("worn faces at each stage's end", fontsize=8)
    ax.set_ylim(bottom=0.0)
    ax.legend(fontsize=7)
    mappable = matplotlib.cm.ScalarMappable(BoundaryNorm(np.arange(n + 1) - 0.5, n), ListedColormap(colours))
    ticks = [int(j) for j in np.unique(np.round(np.linspace(0, n - 1, min(n, 10))))]  # the first and last among
    bar = ax.figure.colorbar(mappable, ax=ax, ticks=ticks, fraction=0.08, pad=0.02)
    bar.ax.set_yticklabels([f"{j} (to {float(cols['hours_end'][j]):.3g} h)" for j in ticks], fontsize=7)
    bar.set_label("stage (its end)", fontsize=8)
