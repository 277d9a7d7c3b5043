"""Worn shape and volume of the pocket faces from a multibody result's wear profile (docs/wear.md).

The step loop records, per pocket, face and bin of ``psi`` (the angle of the contact point seen from the
pocket centre, from the face's middle towards the cage rim), the normal impulse and the sliding work
``sum J_n |v_slide|`` of the recorded rotations (:mod:`bearingsim.multibody.recorder`). Archard's law
(:func:`bearingsim.laws.archard_volume_from_work`) turns the sliding work of a bin into a worn volume,
and that volume spread over the bin's face area (arc length ``R dpsi`` times the roller length ``l``,
the axial width of the line contact) into a worn depth. The recorded rotations are scaled to a running
time: ``rotations`` counts **inner-ring (shaft) rotations**, what a test rig counts (the paper's
1.6e5 in Table 3); the cage turns ``cage speed / inner-ring speed`` times as often (the measured mean
cage speed of the run).

Results only: a result read from an archive is enough (every number here is drawn from the archive).
"""
from __future__ import annotations

import math
import numbers
from dataclasses import dataclass

import numpy as np

from bearingsim import laws
from bearingsim.errors import UserError
from bearingsim.stats import with_error
from bearingsim.wording import counted


@dataclass(frozen=True)
class WearReport:
    """Worn depth profile and volume of every pocket face after a running time. SI."""

    psi_deg: np.ndarray  #: (bins,) bin centres of psi [deg]
    depth_front: np.ndarray  #: (bins, pockets) worn depth, front face [m]
    depth_rear: np.ndarray  #: (bins, pockets) worn depth, rear face [m]
    volume_front: np.ndarray  #: (pockets,) worn volume, front face [m^3]
    volume_rear: np.ndarray  #: (pockets,) worn volume, rear face [m^3]
    shaft_rotations: float  #: inner-ring rotations of the running time
    hours: float  #: running time [h]
    cage_rotations: float  #: cage rotations of the running time
    wear_coefficient: float  #: Archard's k [-]
    hardness: float  #: H [Pa]
    bin_area: float  #: face area of one bin [m^2]
    #: (recorded rotations, pockets) worn volume of each recorded rotation scaled to the running time, front face
    #: [m^3]: ``volume_front`` is its mean over rotations; None: not given (a report made without it)
    rotations_front: np.ndarray | None = None
    rotations_rear: np.ndarray | None = None  #: the same, rear face [m^3]
    #: width of the cage bar between two pockets [m] (:func:`bar_width`); NaN: not given
    bar_width: float = float("nan")
    #: (bins, pockets) the depth the front face starts with, the scenario's own (``[wear] worn_depth_front_um``,
    #: :func:`start_depth`) [m]: ``depth_front`` is worn on top of it; None: an unworn start
    start_front: np.ndarray | None = None
    start_rear: np.ndarray | None = None  #: the same, rear face [m]

    def total_depth(self, face: str) -> np.ndarray:
        """(bins, pockets) the depth of one face after the running time: the starting depth plus the wear [m]."""
        d, s = (self.depth_front, self.start_front) if face == "front" else (self.depth_rear, self.start_rear)
        return d if s is None else s + d

    @property
    def max_depth(self) -> float:
        """The deepest point of any face after the running time, its starting depth included [m]."""
        return float(max(self.total_depth("front").max(), self.total_depth("rear").max()))

    @property
    def max_new_depth(self) -> float:
        """The deepest point of the wear of the running time alone, without the starting depth [m]."""
        return float(max(self.depth_front.max(), self.depth_rear.max()))

    @property
    def max_start_depth(self) -> float:
        """The deepest point of the starting depth (0: an unworn start) [m]."""
        return float(max(0.0 if s is None else s.max() for s in (self.start_front, self.start_rear)))

    def cov(self, face: str) -> float:
        """Coefficient of variation (std / mean) of the worn volume over the pockets of one face [-]
        (:func:`bearingsim.stats.pocket_cov`)."""
        from bearingsim.stats import pocket_cov

        return pocket_cov(self.volume_front if face == "front" else self.volume_rear)

    @property
    def recorded_rotations(self) -> int:
        """The recorded cage rotations the report extrapolates from (0: not given)."""
        return 0 if self.rotations_front is None else int(self.rotations_front.shape[0])

    def volume_rotations(self, face: str) -> np.ndarray:
        """(recorded rotations, pockets) worn volume of each recorded rotation, scaled to the running time [m^3]."""
        v = self.rotations_front if face == "front" else self.rotations_rear
        return np.zeros((0, len(self.volume_front))) if v is None else v

    def volume_sem(self, face: str) -> float:
        """Standard error of the worn volume mean over pockets of one face [m^3]: the batch-means error
        (:func:`bearingsim.stats.batch_sem`) of the per-rotation face totals (the pockets' mean) over the
        recorded rotations; NaN with fewer than 2."""
        from bearingsim.stats import batch_sem, pocket_means

        return batch_sem(pocket_means(self.volume_rotations(face)))

    def sampling_cov(self, face: str) -> float:
        """The coefficient of variation over pockets that identical pockets would show from the recorded
        rotations' scatter alone [-] (:func:`bearingsim.stats.pocket_sampling_cov` of the per-rotation volumes):
        the pockets' mean standard error of their worn volume over the mean volume; NaN with fewer than 2
        recorded rotations. The pockets are identical in geometry, but the cage's motion can lock into a pattern
        that loads them unevenly: :meth:`cov` far above this is that (a run's note says when, docs/wear.md,
        *Uneven pockets*), near it the scatter; both fall as 1/sqrt(recorded rotations) when it is scatter."""
        from bearingsim.stats import pocket_sampling_cov

        return pocket_sampling_cov(self.volume_rotations(face))

    def worn_through(self) -> tuple[int, float] | None:
        """``(i, depth)`` when the two faces on a cage bar, pocket ``i``'s front face and pocket ``i - 1``'s rear
        face (:func:`bearingsim.laws.worn_bar_depth`, as a life study's stages and a worn scenario are checked),
        together as deep as the bar is wide in a bin of psi, their starting depths included (:meth:`total_depth`):
        the deepest such bar and its depth [m]; None when no bar is (or no bar width is given). Past it the
        linear extrapolation means nothing."""
        on_bar = self.bar_depth()  # (bins, bars)
        if not on_bar.max() >= self.bar_width:
            return None
        return int(on_bar.max(axis=0).argmax()), float(on_bar.max())

    def bar_depth(self) -> np.ndarray:
        """(bins, bars) the depth the two faces on each cage bar reach together after the running time, their
        starting depths included (:func:`bearingsim.laws.worn_bar_depth`) [m]."""
        return laws.worn_bar_depth(self.total_depth("front"), self.total_depth("rear"))

    def mean_depth(self, face: str) -> np.ndarray:
        """(pockets,) worn depth averaged over the face's extent (volume / face area) [m]."""
        v = self.volume_front if face == "front" else self.volume_rear
        return v / (self.bin_area * len(self.psi_deg))


#: The longest running time a wear report scales the recorded rotations to [h]: 1e6 h, 114 years of
#: continuous running. The longest lives rolling bearings are designed for are ~1e5 h (the catalogues' guideline
#: values of the specification life: 100 000 h and more for machines in continuous operation with high reliability,
#: such as power stations and mine pumps), so this leaves ten times that; a longer time is a slip (a unit, an
#: exponent), not a bearing's. It bounds the time, not the worn depth: the report extrapolates linearly and may wear
#: through a cage bar (5.821 mm on the reference cage), which it says (:meth:`WearReport.worn_through`), within a
#: realistic time (3 rotations of multibody_6000rpm at the default k = 5e-6: 7.1 mm deep at an edge after 100 h),
#: which ``bearingsim life`` follows stage by stage instead. Within the bound every number is finite by far (that
#: run: at most 2.3e-4 m^3 per face after 1e6 h; the coefficient of variation squares the volumes, which overflows
#: above ~1e154 m^3: ``--rotations 1e300`` gave 4e284 m^3 and a variation of inf).
MAX_RUNNING_HOURS = 1e6


def has_profile(result) -> bool:
    """True when ``result`` holds a wear profile (multibody archives written since it exists)."""
    return "results/wear/profile_work_front" in result.data


def _is_number(value) -> bool:
    """A real number (numpy's too), not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def archard_values(wear_coefficient, hardness) -> tuple[float, float]:
    """(k, H) given to :func:`wear_report` checked as the scenario checks ``[wear]``: a one-line UserError
    naming the argument unless 0 < k <= :data:`bearingsim.scenario.MAX_WEAR_COEFFICIENT` and H within
    :data:`bearingsim.scenario.HARDNESS_RANGE_PA` (a negative k wore -0.0 m deep, H = 0 gave NaN). A k of 0,
    which a scenario takes (nothing wears), is refused here: a report of no wear has no spread or ratio."""
    from bearingsim.scenario import HARDNESS_RANGE_PA, MAX_WEAR_COEFFICIENT

    k_ok = _is_number(wear_coefficient) and 0.0 < wear_coefficient <= MAX_WEAR_COEFFICIENT
    if not k_ok:
        raise UserError(f"wear_coefficient {wear_coefficient!r}: must be an Archard wear coefficient above 0 and at "
                        f"most {MAX_WEAR_COEFFICIENT:g} (dimensionless; measured values are 1e-9..1e-2)")
    lo, hi = HARDNESS_RANGE_PA
    if not (_is_number(hardness) and lo <= hardness <= hi):
        raise UserError(f"hardness {hardness!r}: must be a hardness in Pa within that of solids ({lo:g}..{hi:g} Pa)")
    return float(wear_coefficient), float(hardness)


def given_time(value) -> str:
    """A running time as given, in a refusal: 1000000.4 not rounded to the bound it passes (``%g`` wrote
    "1e+06"), a whole number without ".0", an integer beyond any float (10**400) as "above 1e308"."""
    try:
        return repr(float(value)).removesuffix(".0")
    except OverflowError:
        return "above 1e308"


def running_time(result, *, hours: float | None = None, rotations: float | None = None) -> tuple[float, float, float]:
    """(shaft rotations, hours, cage rotations) of a running time given as ``hours`` or inner-ring
    ``rotations`` (exactly one); the cage rotations at the run's measured mean cage speed. A refusal starts
    with the keyword it is about (the command line names its option there)."""
    if (hours is None) == (rotations is None):
        raise UserError("give the running time as hours or as inner-ring rotations (exactly one)")
    value, name = (hours, "hours") if hours is not None else (rotations, "rotations")
    if not (_is_number(value) and value > 0):  # NaN is no number here; an infinite time is beyond the bound below
        raise UserError(f"{name} {value!r}: must be a positive number")
    try:
        amount = float(value)
    except OverflowError:  # an integer beyond any float (10**400): beyond the bound below
        amount = math.inf
    op = result.parameters.operating
    rot_per_hour = 3600.0 * op.omega_i / (2.0 * math.pi)
    shaft = amount if rotations is not None else amount * rot_per_hour
    if (amount if hours is not None else shaft / rot_per_hour) > MAX_RUNNING_HOURS:
        raise UserError(f"{name} {given_time(value)}: more than {MAX_RUNNING_HOURS:.10g} h of running "
                        f"({MAX_RUNNING_HOURS * rot_per_hour:.12g} inner-ring rotations at {rot_per_hour / 60:g} rpm), "
                        f"114 years, ten times the longest life a bearing is designed for; give a shorter running time")
    cage_speed = result.summary.get("cage_speed_mean_rad_s", float("nan"))
    if not (math.isfinite(cage_speed) and cage_speed > 0):
        raise UserError("the run has no measured cage speed (no recorded rotation): no running time can be scaled")
    return shaft, shaft / rot_per_hour, shaft * cage_speed / op.omega_i


def bar_width(scenario) -> float:
    """The width of the cage bar between two pockets of ``scenario`` [m] (:func:`bearingsim.laws.cage_bar_width`):
    what the two faces on a bar can wear together before it is worn through."""
    b = scenario.bearing
    return laws.cage_bar_width(b.pitch_diameter_mm, b.roller_diameter_mm, b.pocket_clearance_mm, b.roller_count) * 1e-3


def face_area(p, bins: int = 1) -> float:
    """The area of one arc pocket face of parameters ``p``, or of one of its ``bins`` equal bins of psi
    [m^2]: the face's arc on the pocket circle (its extent, ``multibody.pocket_face_extent``) times the
    roller length."""
    lo, hi = p.multibody.pocket_face_extent
    pocket_radius = p.bearing.roller_radius + 0.5 * p.bearing.pocket_clearance
    return pocket_radius * (hi - lo) / bins * p.bearing.roller_length


def start_depth(p, psi_deg) -> tuple[np.ndarray | None, np.ndarray | None]:
    """(front, rear) the depth the faces of parameters ``p`` start with, the scenario's own (``[wear]
    worn_depth_*_um``), at the wear profile's bins ``psi_deg`` ((bins, pockets) [m] each), or (None, None) for
    unworn faces. A profile of other bins (both span the faces' extent in equal bins) is read as the step loop
    reads it: linear in psi between its bin centres, constant in the half bins at the ends."""
    if p.wear.worn_depth is None:
        return None, None
    given = np.array(p.wear.worn_depth, dtype=np.float64)  # (pockets, 2, given bins)
    psi = np.asarray(psi_deg, dtype=np.float64)
    n = given.shape[2]
    if n != len(psi):
        width = (psi[-1] - psi[0]) / (len(psi) - 1) if len(psi) > 1 else 0.0
        lo, hi = psi[0] - 0.5 * width, psi[-1] + 0.5 * width
        centres = lo + (np.arange(n) + 0.5) * (hi - lo) / n
        given = np.array([[np.interp(psi, centres, row) for row in pocket] for pocket in given])
    return given[:, 0, :].T.copy(), given[:, 1, :].T.copy()


def wear_report(result, *, hours: float | None = None, rotations: float | None = None,
                wear_coefficient: float | None = None, hardness: float | None = None) -> WearReport:
    """The :class:`WearReport` of ``result`` after a running time (``hours`` or inner-ring ``rotations``),
    with Archard's k and H of the result's scenario (``[wear]``) unless given. A scenario's k of 0, which the
    scenario takes, is refused as a given k of 0 is (:func:`archard_values`), naming the scenario's key. The
    faces start at the scenario's own worn depth (:func:`start_depth`): the deepest point and the cage bar
    count it, the volumes and ``depth_*`` are the wear of the running time."""
    if not has_profile(result):
        raise UserError("this archive has no wear profile (written before bearingsim recorded one, or not a "
                        "multibody run): run its scenario again ('bearingsim rerun' or 'bearingsim run')")
    p = result.parameters
    k, h = p.wear.wear_coefficient, p.wear.hardness  # checked with the scenario (its k may be 0: no wear)
    if wear_coefficient is None and not k > 0.0:  # the refusal of archard_values, naming the scenario's key
        raise UserError(f"wear.wear_coefficient = {k:g} in the archive's scenario: nothing wears, so there is no "
                        f"worn shape, spread or ratio to report; run it with a wear coefficient above 0 "
                        f"(--set wear.wear_coefficient=5e-6)")
    if wear_coefficient is not None or hardness is not None:
        k, h = archard_values(k if wear_coefficient is None else wear_coefficient, h if hardness is None else hardness)
    shaft, hrs, cage_rot = running_time(result, hours=hours, rotations=rotations)
    recorded = result.per_rotation["I_dec"].shape[0]
    scale = cage_rot / recorded
    psi = result.get("wear/profile_psi_deg")
    area = face_area(p, len(psi))
    vols = {f: laws.archard_volume_from_work(k, result.get(f"wear/profile_work_{f}") * scale, h)
            for f in ("front", "rear")}
    per_rot = {f: laws.archard_volume_from_work(k, result.per_rotation[f"slide_work_{f}"] * cage_rot, h)
               for f in ("front", "rear")}  # its mean over rotations is the profile's sum (1e-12)
    return WearReport(psi, vols["front"] / area, vols["rear"] / area, vols["front"].sum(axis=0),
                      vols["rear"].sum(axis=0), shaft, hrs, cage_rot, k, h, area, per_rot["front"], per_rot["rear"],
                      bar_width(result.scenario), *start_depth(p, psi))


#: The wear rates a sweep's index holds for each case (docs/sweeps.md, *Wear in a sweep*), name -> description:
#: the worn volume of one face per hour of running at the case's speed [m^3/h], what ``bearingsim wear ARCHIVE
#: --hours 1`` gives (:func:`sweep_rates`)
SWEEP_RATES = {
    "wear_front_mean_m3_h": "worn volume of a front face per hour of running, mean over pockets",
    "wear_front_sem_m3_h": "standard error of wear_front_mean (batch means over the recorded rotations; 0 for the "
                           "reduced model, exact)",
    "wear_front_worst_m3_h": "worn volume per hour of the most worn front face (multibody model)",
    "wear_rear_mean_m3_h": "worn volume of a rear face per hour of running, mean over pockets",
    "wear_rear_sem_m3_h": "standard error of wear_rear_mean (batch means over the recorded rotations; 0 for the "
                          "reduced model, exact)",
    "wear_rear_worst_m3_h": "worn volume per hour of the most worn rear face (multibody model)",
}
#: the running time of :data:`SWEEP_RATES` [h]: the volumes after it are the rates per hour
RATE_HOURS = 1.0


def sweep_rates(result) -> dict[str, float]:
    """The wear rates of :data:`SWEEP_RATES` of ``result`` [m^3/h]. Multibody: the :class:`WearReport` after
    :data:`RATE_HOURS` (``bearingsim wear ARCHIVE --hours 1``, the same bits): each face's volume mean over pockets,
    its standard error (:meth:`WearReport.volume_sem`) and the largest; a wear coefficient of 0 wears nothing (0);
    {} for a result without a wear profile or a measured cage speed. Reduced: the no-load pass's Archard wear per
    hour (``/results/wear``, Eq. 16 of the impulses, one pocket; :data:`bearingsim.reduced.WEAR_DESCRIPTION`),
    standard error 0 (its rotations repeat one pass), no worst pocket; {} without that group."""
    if result.model == "reduced":
        group = result.groups.get("results/wear")
        return reduced_rates(group.attrs if group is not None else {})
    if not has_profile(result):
        return {}
    if not result.parameters.wear.wear_coefficient > 0.0:  # nothing wears: wear_report refuses to report it
        return dict.fromkeys(SWEEP_RATES, 0.0)
    try:
        rep = wear_report(result, hours=RATE_HOURS)
    except UserError:  # no measured cage speed: no running time
        return {}
    out = {}
    for f in ("front", "rear"):
        v = rep.volume_front if f == "front" else rep.volume_rear
        out.update({f"wear_{f}_mean_m3_h": float(v.mean()), f"wear_{f}_sem_m3_h": float(rep.volume_sem(f)),
                    f"wear_{f}_worst_m3_h": float(v.max())})
    return out


def reduced_rates(wear_attrs: dict) -> dict[str, float]:
    """The :data:`SWEEP_RATES` of a reduced-model result from its ``/results/wear`` attributes ``wear_attrs``: each
    face's wear per hour, standard error 0 (its rotations repeat one pass); {} without them."""
    if not all(f"{f}_per_hour_m3_h" in wear_attrs for f in ("front", "rear")):
        return {}
    out = {}
    for f in ("front", "rear"):
        out.update({f"wear_{f}_mean_m3_h": float(wear_attrs[f"{f}_per_hour_m3_h"]), f"wear_{f}_sem_m3_h": 0.0})
    return out


def format_report(rep: WearReport) -> str:
    """The report as text: running time, k and H, per pocket the worn volumes and deepest points, the
    spread over pockets, and the mean depth profile at the face's ends and middle."""
    lines = [f"running time: {rep.hours:.4g} h = {rep.shaft_rotations:.4g} inner-ring rotations = "
             f"{rep.cage_rotations:.4g} cage rotations; Archard k = {rep.wear_coefficient:.3g}, H = {rep.hardness:.3g} Pa",
             *start_note(rep),
             f"{'pocket':>6} {'V front [mm^3]':>15} {'V rear [mm^3]':>14} {'max depth front [um]':>21} "
             f"{'max depth rear [um]':>20}"]
    for i in range(len(rep.volume_front)):
        lines.append(f"{i:>6} {rep.volume_front[i] * 1e9:>15.4g} {rep.volume_rear[i] * 1e9:>14.4g} "
                     f"{rep.depth_front[:, i].max() * 1e6:>21.4g} {rep.depth_rear[:, i].max() * 1e6:>20.4g}")
    n = rep.recorded_rotations
    for f in ("front", "rear"):
        v = rep.volume_front if f == "front" else rep.volume_rear
        sem = rep.volume_sem(f)
        if math.isfinite(sem):  # as the tables show a value with its error (stats.with_error)
            lines.append(f"{f}: worn volume mean {with_error(v.mean() * 1e9, sem * 1e9)} mm^3 over pockets (standard "
                         f"error, batch means over the {n} recorded rotations it extrapolates from)")
        else:
            lines.append(f"{f}: worn volume mean {v.mean() * 1e9:.4g} mm^3 over pockets, no standard error "
                         f"({counted(n, 'recorded rotation')}: at least 2 give one)")
    for f in ("front", "rear"):
        lines.append(f"{f}: coefficient of variation over pockets {rep.cov(f):.3f}; " + (
            f"identical pockets would show {rep.sampling_cov(f):.3f} from the rotation-to-rotation scatter of the "
            f"{n} recorded rotations alone" if math.isfinite(rep.sampling_cov(f)) else
            f"no estimate of what the rotations' scatter alone gives ({counted(n, 'recorded rotation')})"))
    ratio = rep.volume_front / np.where(rep.volume_rear > 0, rep.volume_rear, np.nan)
    lines.append(f"front / rear volume per pocket: {np.nanmin(ratio):.3g} .. {np.nanmax(ratio):.3g} "
                 f"(mean {np.nanmean(ratio):.3g})")
    for f in ("front", "rear"):
        d = (rep.depth_front if f == "front" else rep.depth_rear).mean(axis=1)
        ends = shape_of(rep.psi_deg, d)
        lines.append(f"{f}: mean depth over pockets at the bore end {ends['bore'] * 1e6:.4g} um, middle "
                     f"{ends['middle'] * 1e6:.4g} um, rim end {ends['rim'] * 1e6:.4g} um")
    lines.append(f"deepest point of any face: {rep.max_depth * 1e6:.4g} um" + (
        f", the starting depth included (this running time's wear alone: {rep.max_new_depth * 1e6:.4g} um)"
        if rep.max_start_depth > 0.0 else "") + edge_caveat(rep))
    if rep.worn_through() is not None:
        lines.append(bar_line(rep))
    return "\n".join(lines)


def format_comparison(labels: dict[str, list[str]], reports: list, notes: list[str] = ()) -> str:
    """Several archives' :class:`WearReport` as one table, a row each, labelled by the columns ``labels`` (name
    -> a cell per report: the archive and the values of the scenario keys that differ,
    :func:`bearingsim.tables.archive_labels`): the running time, Archard's k and H of each, each face's worn
    volume mean over pockets with its standard error (batch means over the recorded rotations), the deepest
    point and whether a cage bar wears through; ``notes`` above it (the scenario keys that differ). A row given
    as its cells instead of a report (a sweep's case without an archive: :func:`rate_cells`) is shown as given."""
    head = (*labels, "hours", "k", "H [Pa]", "V front [mm^3]", "V rear [mm^3]", "deepest [um]",
            "recorded cage rotations", "cage bar")
    nlab = len(labels)
    rows = [(*(col[i] for col in labels.values()), *(report_cells(rep) if isinstance(rep, WearReport) else rep))
            for i, rep in enumerate(reports)]
    widths = [max(len(h), *(len(r[j]) for r in rows)) for j, h in enumerate(head)]
    line = lambda cells: "  ".join(c.ljust(w) if j < nlab else c.rjust(w)  # noqa: E731
                                   for j, (c, w) in enumerate(zip(cells, widths))).rstrip()
    out = [*notes, line(head), *(line(r) for r in rows)]
    out.append("V: worn volume of one face, mean over pockets \u00b1 its standard error (batch means over the "
               "recorded cage rotations the archive extrapolates from, 'recorded cage rotations'); deepest: any "
               "face's deepest point, an end bin's as a rule, the scenario's own starting depth included "
               "(docs/wear.md); cage bar: whether the two faces on one bar, starting depth included, wear through "
               "it ('bearingsim wear ARCHIVE' gives one archive's whole report)")
    return "\n".join(out)


def report_cells(rep: WearReport) -> tuple[str, ...]:
    """The cells of one report's row of :func:`format_comparison` after its labels."""
    def mean(face):
        v, e = (rep.volume_front if face == "front" else rep.volume_rear).mean(), rep.volume_sem(face)
        return with_error(v * 1e9, e * 1e9)

    through = rep.worn_through() if math.isfinite(rep.bar_width) else None
    return (f"{rep.hours:.4g}", f"{rep.wear_coefficient:g}", f"{rep.hardness:.3g}", mean("front"), mean("rear"),
            f"{rep.max_depth * 1e6:.4g}", str(rep.recorded_rotations),
            f"worn through (pocket {through[0]})" if through else "intact")


def rate_cells(rates: dict[str, float] | None, hours: float) -> tuple[str, ...]:
    """The cells of :func:`format_comparison`'s row of a case known by its wear rates alone (``rates``: a sweep
    index's :data:`SWEEP_RATES` of the case [m^3/h]) after ``hours``: each face's volume, the rate times the
    hours, and its standard error so; '-' where the rates do not tell (k, H, the deepest point, the recorded
    rotations, the cage bar), and every cell '-' for ``rates`` None (not available)."""
    if rates is None:
        return ("-",) * 8

    def mean(face):
        return with_error(rates[f"wear_{face}_mean_m3_h"] * hours * 1e9, rates[f"wear_{face}_sem_m3_h"] * hours * 1e9)

    return f"{hours:.4g}", "-", "-", mean("front"), mean("rear"), "-", "-", "-"


def bar_line(rep: WearReport) -> str:
    """The line that says where the extrapolated wear goes through a cage bar (:meth:`WearReport.worn_through`)."""
    i, depth = rep.worn_through()
    k = int(rep.bar_depth()[:, i].argmax())
    return (f"cage bar worn through: pocket {i}'s front face and pocket {(i - 1) % len(rep.volume_front)}'s rear "
            f"face, either side of the bar between them, are {depth * 1e3:.4g} mm deep together"
            f"{', their starting depth included,' if rep.max_start_depth > 0.0 else ''} at psi = "
            f"{rep.psi_deg[k]:.3g} deg, where the bar is {rep.bar_width * 1e3:.4g} mm wide: a linear extrapolation "
            f"past that is meaningless ('bearingsim life' follows the wear stage by stage to where a bar wears "
            f"through)")


def start_note(rep: WearReport) -> list[str]:
    """The line that says the faces start worn (the scenario's ``[wear] worn_depth_*_um``) and which numbers
    count it; none for an unworn start."""
    if not rep.max_start_depth > 0.0:
        return []
    return [f"the faces start worn (the scenario's [wear] worn_depth_*_um, deepest {rep.max_start_depth * 1e6:.4g} "
            f"um): the volumes and depths per pocket and face below are the wear of this running time; the deepest "
            f"point and the cage bar add the starting depth"]


def edge_caveat(rep: WearReport) -> str:
    """`` (an end bin's ...)`` when the deepest point of the running time's wear lies in a bin at an end of a
    face's extent: the wear there is that of the face's edge, a line, so its depth is the edge's volume over
    one bin's area and doubles each time the bins halve (docs/wear.md, *Discretization errors*); '' otherwise.
    A scenario's own starting depth is given, not binned by the report: it takes no part."""
    ends = [d[[0, -1]].max() for d in (rep.depth_front, rep.depth_rear)]
    if max(ends) < rep.max_new_depth:
        return ""
    width = float(np.diff(rep.psi_deg).mean()) if len(rep.psi_deg) > 1 else float("nan")
    return (f" (an end bin's, {width:.3g} deg of psi wide: the wear at a face's edge is a line, whose depth "
            "doubles each time the bins halve; the volumes and mean depths do not depend on the bins)")


def shape_of(psi_deg, depth) -> dict[str, float]:
    """The depth profile's bore end (first bin), rim end (last bin) and middle (the mean of the bins
    within +-5 deg of psi = 0, the face's middle) [m]."""
    mid = np.abs(psi_deg) <= 5.0
    return {"bore": float(depth[0]), "rim": float(depth[-1]),
            "middle": float(depth[mid].mean()) if mid.any() else float("nan")}


def plot_wear_profile(rep: WearReport, title: str = ""):
    """Fig. 13 analog: worn depth against psi on the front and the rear face, the mean over pockets and
    the band from the least to the most worn pocket at each psi. The first row draws the whole face, its
    end bins hatched (the wear at a face's edge is a line: their depth doubles each time the bins halve,
    :func:`edge_caveat`); the second the face within its end bins, on its own scale, whose deepest depth the
    title states (an end bin, hundreds of times deeper, hides it in the first row); each face in its house colour."""
    from bearingsim.plotting import FRONT, REAR, fixed_unit_axis, legend_outside, subplots

    fig, grid = subplots(2, 2, figsize=(10, 6.8), sharex=True, sharey="row", gridspec_kw={"height_ratios": (3, 2)})
    axes, inner = grid[0], grid[1]
    for k, (f, c) in enumerate((("front", FRONT), ("rear", REAR))):
        d = (rep.depth_front if f == "front" else rep.depth_rear) * 1e6
        for ax, rows in ((axes[k], slice(None)), (inner[k], slice(1, -1))):
            psi, dd = rep.psi_deg[rows], d[rows]
            ax.fill_between(psi, dd.min(axis=1), dd.max(axis=1), step="mid", color=c, alpha=0.25,
                            label="least to most worn pocket")
            ax.step(psi, dd.mean(axis=1), where="mid", color=c, lw=1.5, label="mean over pockets")
        axes[k].set_title(f"{f} face", fontsize=9)
        inner[k].set_title(f"{f} face within its edge bins", fontsize=9)
        inner[k].set_xlabel("ψ: bore end ← 0 (middle) → rim end [deg]")
    axes[0].set_ylim(bottom=0.0)  # shared: after both faces are drawn, so the deeper face's ends stay on the figure
    inner[0].set_ylim(0.0, 1.15 * max(_interior_depth(rep) * 1e6, 1e-9))
    _mark_edge_bins(axes, rep.psi_deg)
    if rep.bar_width * 1e6 <= axes[0].get_ylim()[1]:  # within the depth axis: the bar's width as a line
        for ax in axes:
            ax.axhline(rep.bar_width * 1e6, color="0.3", lw=0.8, ls="--",
                       label=f"cage bar width {rep.bar_width * 1e6:.4g} µm")  # the axis's unit
    for ax in grid[:, 0]:
        ax.set_ylabel("worn depth [µm]")
        fixed_unit_axis(ax)  # shared with the rear face's
    legend_outside(axes[1])
    fig.suptitle(_profile_title(rep, title), fontsize=9)
    fig.tight_layout()
    return fig


def _interior_depth(rep: WearReport) -> float:
    """The deepest point of the running time's wear within the faces' end bins (every pocket, both faces) [m]."""
    inner = [d[1:-1] for d in (rep.depth_front, rep.depth_rear) if d.shape[0] > 2]
    return float(max(d.max() for d in inner)) if inner else float("nan")


def _mark_edge_bins(axes, psi_deg) -> None:
    """Hatch the end bins of psi on ``axes``, labelled as depending on the bin width."""
    width = float(np.diff(psi_deg).mean()) if len(psi_deg) > 1 else 1.0
    for ax in axes:
        for j, end in enumerate((psi_deg[0], psi_deg[-1])):
            ax.axvspan(end - 0.5 * width, end + 0.5 * width, facecolor="none", edgecolor="0.45", hatch="///", lw=0.0,
                       label="edge bins: their depth depends on the bin width" if j == 0 else None)


def _profile_title(rep: WearReport, title: str) -> str:
    """The profile figure's title: the run, the running time and Archard's k and H, what the edge bins are and
    the deepest depth within them, the starting depth and the worn-through cage bar where there are."""
    from bearingsim.plotting import plain_number

    through = rep.worn_through()
    n = len(rep.volume_front)
    return (f"{title}\nworn depth after {_running(rep)}, {_law(rep)}" + (
                f", on the scenario's starting depth (deepest {rep.max_start_depth * 1e6:.4g} µm, not drawn)"
                if rep.max_start_depth > 0.0 else "")
            + f"\nedge bins (hatched): the wear at a face's edge is a line, whose depth doubles each time the bins "
              f"halve; deepest within the faces: {plain_number(_interior_depth(rep) * 1e6)} µm" + (
                "" if through is None else f"\nthe cage bar between pockets {(through[0] - 1) % n} and "
                f"{through[0]} worn through ({through[1] * 1e6:.0f} µm deep"
                f"{', starting depth included,' if rep.max_start_depth > 0.0 else ''} against "
                f"{rep.bar_width * 1e6:.0f} µm wide): a linear extrapolation past it is meaningless"))


def plot_wear_volume(rep: WearReport, title: str = ""):
    """Fig. 14 analog: worn volume of the front and the rear face of every pocket (each in its house colour),
    with the spread, and each
    face's mean over pockets ± its standard error (:meth:`WearReport.volume_sem`, what ``bearingsim wear``
    prints) as a line and band."""
    from bearingsim.plotting import FRONT, REAR, fixed_unit_axis, legend_outside, subplots

    x = np.arange(len(rep.volume_front))
    fig, ax = subplots(figsize=(9, 4))
    n = rep.recorded_rotations
    for f, dx, c in (("front", -0.2, FRONT), ("rear", 0.2, REAR)):
        v = (rep.volume_front if f == "front" else rep.volume_rear) * 1e9
        ax.bar(x + dx, v, 0.4, color=c,
               label=f"{f} face (CV {rep.cov(f):.3f}; sampling alone {rep.sampling_cov(f):.3f})")
        sem = rep.volume_sem(f) * 1e9
        if math.isfinite(sem):
            ax.axhspan(v.mean() - sem, v.mean() + sem, color=c, alpha=0.2, lw=0.0)
            label = f"{f} face, mean over pockets {with_error(v.mean(), sem)} mm³ (±1 standard error)"  # as the table
        else:
            label = (f"{f} face, mean over pockets {v.mean():.4g} mm³ "
                     f"(no standard error: {counted(n, 'recorded rotation')})")
        ax.axhline(v.mean(), color=c, lw=1.2, ls="--", label=label)
    ax.set_xticks(x)
    ax.set_xlabel("pocket")
    ax.set_ylabel("worn volume [mm³]")
    fixed_unit_axis(ax)
    ax.set_title(f"{title}\nworn volume after {_running(rep)}, {_law(rep)}\n"
                 f"CV: coefficient of variation over pockets; sampling alone: identical pockets' CV from the "
                 f"scatter of the {counted(n, 'recorded rotation')}; standard error: batch means over them", fontsize=9)
    legend_outside(ax)
    return fig


def _running(rep: WearReport) -> str:
    """``10 h (3.6 × 10⁶ inner-ring rotations)``: a figure's running time, numbers as engineers read them."""
    from bearingsim.plotting import plain_number

    return f"{plain_number(rep.hours)} h ({plain_number(rep.shaft_rotations)} inner-ring rotations)"


def _law(rep: WearReport) -> str:
    """The wear law of the report's volumes and depths, with its k and H, for a figure's title."""
    from bearingsim.plotting import plain_number

    return (f"Archard's law on the sliding work (V = k W / H), k = {plain_number(rep.wear_coefficient)}, "
            f"H = {plain_number(rep.hardness / 1e9)} GPa")
