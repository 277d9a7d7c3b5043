"""See the bearing move: an animation (MP4 or GIF) of a multibody run's stored motion (docs/animation.md).

A multibody run stores every body's pose over a window of cage rotations (``[output] motion_*``, the
``/observables/motion_*`` time series of docs/archive.md). :func:`render` draws one frame per
``1 / fps`` s of video, the video showing each cage rotation in :data:`SECONDS_PER_ROTATION` s, from the
archive alone:

* the bearing in the plane, the clearances drawn ``K`` times their size (the radial clearance of the
  raceways, each roller's offset in its pocket and the pocket's clearance, the cage's and the inner ring's
  offsets from the axis; the parts themselves at their size), ``K`` stated on the frame;
* each roller with a mark that turns with it (its spin);
* each pocket face coloured by the mean circumferential force on it since the previous pose (the scale ends
  at :data:`FORCE_SCALE_PERCENTILE` of the window's forces, the larger drawn in its top colour, as it says);
* impacts (``/results/impacts``) flashing on their face for three frames, larger for a larger impulse;
* the cage centre's trail over the last cage rotation in an inset (before the window: ``cage_centre``),
  time, cage rotation, pocket 0's angle theta from the load-zone centre and the cage slip as text.

Frames are drawn by matplotlib's Agg canvas (the user's backend is never touched), MP4 written by the
ffmpeg binary that ``imageio-ffmpeg`` packages (H.264), GIF by Pillow; the file appears complete or not at
all (:func:`bearingsim.outputs.atomic_file`) and carries bearingsim's mark (:data:`bearingsim.outputs.MARK`):
only a file with it is replaced.
"""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from bearingsim.errors import UserError
from bearingsim.outputs import printable

__all__ = ["has_motion", "max_exaggeration", "render_result", "SECONDS_PER_ROTATION"]

#: seconds of video per cage rotation: at 30 fps a frame every 3 deg of cage travel, slow enough to follow
#: a roller across its pocket (at 6000 rpm a rotation takes 23 ms: the video is ~170 times slower)
SECONDS_PER_ROTATION = 4.0
#: frames an impact flashes for, and its opacity in each
FLASH_ALPHA = (1.0, 0.55, 0.25)
#: the automatic exaggeration makes the drawn pocket play (K s / 2) about this fraction of the roller radius
AUTO_PLAY_FRACTION = 0.3
MAX_EXAGGERATION = 1000.0
#: the fraction of the cage bar's narrowest width (between neighbouring pockets' centres) that the drawn pockets
#: must leave: it sets the largest exaggeration a bearing is drawn at (:func:`max_exaggeration`)
BAR_KEPT = 0.25
MAX_FPS = 120.0
#: highest frame rate of a GIF: it stores each frame's delay in hundredths of a second, and browsers show a
#: delay under 2 of them (20 ms) as 100 ms, so a GIF above 50 fps would play several times too slowly
MAX_GIF_FPS = 50.0
#: the frame: pixels (multiples of 16, as H.264's macro blocks) and the bearing's square view in it
WIDTH_PX, HEIGHT_PX, DPI = 1024, 768, 100
VIEW_RECT = (0.0, 0.0, HEIGHT_PX / WIDTH_PX, 1.0)  # figure fraction: the left 768 x 768 px
#: colours; the cage's is not used by any other part, so a test can find the cage in a frame
CAGE_COLOUR = "#c9a227"
TRAIL_COLOUR = "#d95f02"
RING_COLOUR = "#b4bcc6"
ROLLER_COLOUR = "#5f6b78"
FORCE_COLOURS = ("#d0d0d0", "#4292c6", "#08306b")  # face force colour scale: no force light grey, then blues
#: the face force colour scale ends at this percentile of the window's face forces (a few impacts' peaks would
#: leave every other force pale); the forces above it are drawn in its top colour, which the scale says
FORCE_SCALE_PERCENTILE = 99.5
FLASH_COLOUR = "#e4002b"
MOTION = "motion_roller_position"  # the series whose presence means an archive holds motion
#: the archive paths an animation reads (besides the scenario and the summary)
ANIMATION_DATA = ("observables", "results/impacts")


def has_motion(path) -> bool:
    """True when the archive at ``path`` holds the bodies' motion (a one-line UserError for a bad file)."""
    from bearingsim import archive

    return archive.has_observable(path, MOTION)


def _no_motion(result, where) -> UserError:
    if result.model != "multibody":
        return UserError(f"{where}: an archive of the {result.model} model holds no motion (only multibody runs "
                         f"store it); run a multibody scenario")
    return UserError(f"{where}: holds no motion; run it again with output.motion_rotations > 0 (e.g. 'bearingsim "
                     f"run SCENARIO --set output.motion_rotations=2')")


def render_result(result, out, *, rotations=None, exaggerate=None, fps=30, progress=None, where="result",
                  last=None) -> Path:
    """:func:`render` of a result in memory (``Result.animate``) or read back; ``last``: only the last so many
    cage rotations of the window (a short clip, as the report embeds)."""
    out = check_output(out)
    if MOTION not in result.series:
        raise _no_motion(result, where)
    fps = check_number(fps, "fps", 1.0, MAX_FPS)
    if out.suffix.lower() == ".gif" and fps > MAX_GIF_FPS:
        raise UserError(f"fps {fps:g}: a GIF plays at most {MAX_GIF_FPS:g} frames per second (browsers show a frame "
                        f"shorter than 20 ms for 100 ms); give a lower fps, or write an .mp4")
    if last is not None and not _as_number(last, "last") > 0:  # NaN too
        raise UserError(f"last: {last!r} is not a positive number of cage rotations")
    motion = _Motion(result)
    a, b = motion.window(rotations, where)
    if last is not None:
        a = max(a, b - float(last))
    n_frames = max(1, int(round((b - a) * SECONDS_PER_ROTATION * fps)))
    frame_rot = a + (b - a) * np.arange(n_frames) / n_frames
    rows = motion.rows_at(frame_rot)
    k = _exaggeration(result.parameters, exaggerate)
    drawing = _Drawing(result, motion, k, rows)
    frames = (drawing.draw(f) for f in range(n_frames))
    from bearingsim import outputs

    with outputs.exclusive_output(out, "animation"):  # one command writes it; folders it made go if unwritten
        try:
            (_write_gif if out.suffix.lower() == ".gif" else _write_mp4)(out, frames, fps, n_frames, progress)
        except OSError as exc:  # its temporary file: found before the first frame is drawn
            raise UserError(f"{out}: cannot write the animation ({exc.strerror or exc})") from None
    return out


# --- inputs --------------------------------------------------------------------------------------------
def check_output(out) -> Path:
    """``out`` as a Path, refused in one line unless it ends in .mp4 or .gif, its folder is a folder or
    can be made one (a missing folder is created when the animation is written, as a run's is) and it is
    not a file bearingsim did not write (one without its mark, :data:`bearingsim.outputs.MARK`: a user's
    GIF or MP4 is kept)."""
    from bearingsim import outputs
    from bearingsim.errors import check_path

    out = Path(check_path(out, "out", "the animation (.mp4 or .gif)"))
    suffix = out.suffix.lower()
    if suffix not in (".mp4", ".gif"):
        raise UserError(f"{out}: animation path must end in .mp4 or .gif (got {out.suffix or 'no suffix'!r})")
    outputs.check_folder_can_be_made(out, "animation")
    if suffix == ".gif":
        outputs.check_replaceable(out, outputs.is_own_gif, "GIF animation")
    else:
        outputs.check_replaceable(out, outputs.is_own_mp4, "MP4 animation")
    return out


def check_number(value, name, lo, hi) -> float:
    """``value`` as a float in ``[lo, hi]``, else a one-line UserError naming it ``name`` (the API's keyword,
    or the command line's option)."""
    v = _as_number(value, name)
    if not (lo <= v <= hi):
        raise UserError(f"{name}: {value!r} is outside {lo:g} .. {hi:g}")
    return v


def _as_number(value, name) -> float:
    """``value`` as a float, else a one-line UserError naming it ``name``."""
    try:
        return float(value)
    except (TypeError, ValueError):
        raise UserError(f"{name}: expected a number, got {value!r}") from None


def _exaggeration(p, given) -> float:
    """The factor K the clearances are drawn at: ``given``, or the 1-2-5 number at or below the one that
    makes the drawn pocket play K s / 2 :data:`AUTO_PLAY_FRACTION` of the roller radius (10 for the NU214);
    either at most :func:`max_exaggeration` of the bearing (a larger ``given`` is refused in one line)."""
    top = max_exaggeration(p)
    if given is not None:
        k = check_number(given, "exaggerate", 1.0, MAX_EXAGGERATION)
        if k > top:
            raise UserError(f"exaggerate {k:g}: at most {top:g} for this archive's bearing: at a larger K its drawn "
                            f"pockets leave less than {BAR_KEPT:.0%} of the cage bar between them "
                            f"(docs/animation.md)")
        return k
    g = p.bearing
    want = min(AUTO_PLAY_FRACTION * g.roller_radius / (0.5 * g.pocket_clearance), top)
    if want <= 1.0:
        return 1.0
    decade = 10.0 ** math.floor(math.log10(want))
    return max(m * decade for m in (1.0, 2.0, 5.0) if m * decade <= want)


def max_exaggeration(p) -> float:
    """The largest K, to 0.1 below, at which the bearing of ``p`` is drawn as it is: the pockets drawn K s / 2
    wider (radius r + K s / 2) leave at least :data:`BAR_KEPT` of the cage bar between neighbours, whose
    narrowest width (along the line of their centres) is w = 2 r_p sin(pi / Z) - 2 r - s, i.e.
    K <= 1 + (1 - BAR_KEPT) w / s (22.8 for the NU214). Towards K = 1 + w / s the bars vanish, neighbouring
    rollers (each drawn up to K s / 2 off its pocket's centre) may touch, and a roller drawn K times its
    tangential offset t drifts outwards by about
    K^2 t^2 / 2 r_p, cutting into the outer ring (0.9 mm at K = 30 in the NU214). At least 1, at most
    :data:`MAX_EXAGGERATION`."""
    g = p.bearing
    bar = 2.0 * g.pitch_radius * math.sin(math.pi / g.roller_count) - 2.0 * g.roller_radius - g.pocket_clearance
    k = 1.0 + (1.0 - BAR_KEPT) * bar / g.pocket_clearance if g.pocket_clearance > 0.0 else MAX_EXAGGERATION
    return min(MAX_EXAGGERATION, max(1.0, math.floor(10.0 * k + 1e-9) / 10.0))


class _Motion:
    """The stored motion of a result, with each pose's place in the recorded cage rotations."""

    def __init__(self, result):
        s = result.series
        p = result.parameters
        self.sign = p.operating.sign
        self.time = s["motion_cage_angle"].time
        self.cage_angle = s["motion_cage_angle"].value
        self.cage_xy = s["motion_cage_position"].value
        self.rollers_xy = s["motion_roller_position"].value
        self.rollers_angle = s["motion_roller_angle"].value
        self.force = s["motion_pocket_force"].value  # (M, n, [rear, front])
        ring = s.get("motion_inner_ring_centre")
        self.ring_xy = None if ring is None else ring.value
        # recorded cage rotations: the cage's travel from t = 0, less the warm-up
        self.rotation = self.sign * self.cage_angle / (2.0 * math.pi) - p.numerics.warmup_rotations
        # the cage centre before the window (the observables' samples from t = 0), for the trail of a frame
        # less than a cage rotation into the window; a rotation taken as the window's mean time per rotation
        centre = s.get("cage_centre")
        span = self.rotation[-1] - self.rotation[0]
        self.period = (self.time[-1] - self.time[0]) / span if span > 0.0 else 0.0
        early = (None if centre is None or not len(centre.time) else
                 (centre.time < self.time[0]) & (centre.time >= self.time[0] - self.period))
        self.before_time = None if early is None else np.asarray(centre.time)[early]
        self.before_xy = None if early is None else np.asarray(centre.value)[early]
        slip = s.get("cage_slip")
        self.slip = (None if slip is None or not len(slip.time)
                     else np.interp(self.time, slip.time, slip.value))

    def window(self, rotations, where) -> tuple[float, float]:
        lo, hi = float(self.rotation[0]), float(self.rotation[-1])
        if rotations is None:
            return lo, hi
        try:
            a, b = (float(v) for v in rotations)
        except (TypeError, ValueError):
            raise UserError(f"rotations: expected two numbers a, b (recorded cage rotations), got {rotations!r}") from None
        tol = 0.5 * float(np.median(np.diff(self.rotation))) if len(self.rotation) > 1 else 0.0
        if not (math.isfinite(a) and math.isfinite(b) and a < b):
            raise UserError(f"rotations {a:g}:{b:g}: expected a < b")
        if a < lo - tol or b > hi + tol:
            raise UserError(f"rotations {a:g}:{b:g}: outside the stored motion of {where} (recorded rotations "
                            f"{lo:.3f} .. {hi:.3f}; output.motion_* set what a run stores)")
        return a, b

    def rows_at(self, rot) -> np.ndarray:
        """Index of the pose nearest to each of the recorded rotations ``rot``."""
        j = np.clip(np.searchsorted(self.rotation, rot), 1, len(self.rotation) - 1)
        before = rot - self.rotation[j - 1] < self.rotation[j] - rot
        return np.where(before, j - 1, j)


def view_half_width(p, k: float) -> float:
    """Half the width [mm] of the square view of the bearing (:data:`VIEW_RECT`, centred on the bearing
    axis, x to the right, y up) at exaggeration ``k``: the drawn outer ring and a margin."""
    from bearingsim.parameters import paper_assumptions

    g = p.bearing
    pd = 0.0 if paper_assumptions(p.multibody.scene) else g.radial_clearance
    return (g.pitch_radius + 0.25 * k * pd + 1.5 * g.roller_radius) * 1e3 + 2.0


def _force_cmap():
    from matplotlib.colors import LinearSegmentedColormap

    return LinearSegmentedColormap.from_list("bearingsim_face_force", FORCE_COLOURS)


# --- frames --------------------------------------------------------------------------------------------
def _annulus(r_in: float, r_out: float, points: int = 360):
    """A matplotlib Path of the ring between ``r_in`` and ``r_out`` about the origin."""
    from matplotlib.path import Path as MplPath

    a = np.linspace(0.0, 2.0 * math.pi, points, endpoint=False)
    ring = [np.column_stack([r * np.cos(a), r * np.sin(a)]) for r in (r_out, r_in)]
    ring[1] = ring[1][::-1]  # the hole turns the other way (non-zero winding)
    verts, codes = [], []
    for v in ring:
        verts += [*v, v[0]]
        codes += [MplPath.MOVETO] + [MplPath.LINETO] * (len(v) - 1) + [MplPath.CLOSEPOLY]
    return MplPath(np.array(verts), codes)


def _face_forces(motion, rows) -> np.ndarray:
    """(frames, n, [rear, front]) mean face force over each frame's interval [N]: the poses' forces are
    means since the pose before, so their impulses are summed between two frames' poses."""
    t = motion.time
    dt = np.diff(t, prepend=t[0] - (t[1] - t[0] if len(t) > 1 else 0.0))
    cum = np.cumsum(motion.force * dt[:, None, None], axis=0)
    out = motion.force[rows].copy()
    span = t[rows[1:]] - t[rows[:-1]]
    ok = span > 0.0
    out[1:][ok] = (cum[rows[1:]] - cum[rows[:-1]])[ok] / span[ok, None, None]
    return out


def impact_marks_end(result, t_frames) -> str:
    """What the legend says when the archive's impact table (``/results/impacts``) filled up (provenance
    ``impacts_table_full``, the run's note) before the last frame's time of ``t_frames`` [s]: from when no impact
    is marked, and why; "" otherwise."""
    t_last = result.impacts_end_s
    if t_last is None or not len(t_frames) or t_last >= float(t_frames[-1]):
        return ""
    return f"★ none marked after t = {t_last:.4g} s:\nthe archive's impact table\nfilled up (its run's note)"


class _Drawing:
    """The figure of an animation, made once; :meth:`draw` moves its parts to a frame's pose and returns
    the frame's RGB pixels. Lengths in mm; clearances drawn ``k`` times their size (module docstring)."""

    def __init__(self, result, motion, k: float, rows: np.ndarray):
        from matplotlib.collections import EllipseCollection, LineCollection
        from matplotlib.colors import Normalize
        from matplotlib.patches import PathPatch

        from bearingsim import laws
        from bearingsim.parameters import paper_assumptions, pocket_angles
        from bearingsim.plotting import figure

        p = result.parameters
        g = p.bearing
        self.m, self.k, self.n, self.sign = motion, k, g.roller_count, p.operating.sign
        self.rp, self.rr = g.pitch_radius * 1e3, g.roller_radius * 1e3
        pd = 0.0 if paper_assumptions(p.multibody.scene) else g.radial_clearance * 1e3
        self.pocket_a = pocket_angles(self.n, self.sign)
        self.R = self.rr + 0.5 * k * g.pocket_clearance * 1e3  # drawn pocket radius
        c_in = (g.cage_inner_radius or g.pitch_radius - 0.5 * g.roller_radius) * 1e3
        c_out = (g.cage_outer_radius or g.pitch_radius + 0.5 * g.roller_radius) * 1e3
        lo, hi = p.multibody.pocket_face_extent
        if p.multibody.pocket_face_rule == "cage wall" or not (math.isfinite(lo) and math.isfinite(hi)):
            lo, hi = laws.pocket_face_extent(self.rp, self.R, c_in, c_out)  # the drawn pocket in the drawn wall
        psi = np.linspace(lo, hi, 9)
        flat = np.isin(np.arange(self.n), list(p.multibody.flat_pockets))
        # each face's points as (along u, along e_r) in units of R: arcs, or planes for flat pockets
        self.face_u = np.where(flat[:, None], 1.0, np.cos(psi)[None, :])
        self.face_r = np.where(flat[:, None], np.tan(psi)[None, :], np.sin(psi)[None, :])
        r_outer = self.rp + 0.25 * k * pd + self.rr  # drawn raceways: a roller touching one touches it here
        r_inner = self.rp - 0.25 * k * pd - self.rr
        span = view_half_width(p, k)
        self.fig = fig = figure(figsize=(WIDTH_PX / DPI, HEIGHT_PX / DPI), dpi=DPI)
        fig.patch.set_facecolor("white")
        ax = self.ax = fig.add_axes(VIEW_RECT)
        ax.set_xlim(-span, span)
        ax.set_ylim(-span, span)
        ax.set_aspect("equal")
        ax.axis("off")
        self.span = span
        self.cage = ax.add_patch(PathPatch(_annulus(c_in, c_out), facecolor=CAGE_COLOUR, edgecolor="none", zorder=1))
        self.pockets = ax.add_collection(EllipseCollection(
            2 * self.R, 2 * self.R, 0.0, units="xy", offsets=np.zeros((self.n, 2)), offset_transform=ax.transData,
            facecolor="white", edgecolor="none", zorder=2))
        self.outer = ax.add_patch(PathPatch(_annulus(r_outer, r_outer + 0.5 * self.rr), facecolor=RING_COLOUR,
                                            edgecolor="0.45", lw=0.6, zorder=3))
        self.ring = None
        if motion.ring_xy is not None:
            self.ring = ax.add_patch(PathPatch(_annulus(r_inner - 0.6 * self.rr, r_inner), facecolor=RING_COLOUR,
                                               edgecolor="0.45", lw=0.6, zorder=3))
        self.rollers = ax.add_collection(EllipseCollection(
            2 * self.rr, 2 * self.rr, 0.0, units="xy", offsets=np.zeros((self.n, 2)), offset_transform=ax.transData,
            facecolor=ROLLER_COLOUR, edgecolor="0.2", linewidth=0.6, zorder=4))
        self.spin = ax.add_collection(LineCollection([], colors="white", linewidths=1.6, zorder=5))
        self.rows = rows
        self.forces = _face_forces(motion, rows)
        top = float(np.percentile(self.forces, FORCE_SCALE_PERCENTILE)) if self.forces.size else 0.0
        self.norm = Normalize(0.0, top if top > 0.0 else 1.0)
        self.force_max = float(self.forces.max()) if self.forces.size else 0.0
        self._flash_schedule(result)
        self.cmap = _force_cmap()
        self.faces = ax.add_collection(LineCollection([], cmap=self.cmap, norm=self.norm, linewidths=3.0,
                                                      capstyle="round", zorder=6))
        self.flash = ax.scatter(np.zeros(0), np.zeros(0), marker="*", s=[], zorder=7, linewidths=0)
        self.label0 = ax.text(0, 0, "0", ha="center", va="center", fontsize=9, color="black", zorder=8)
        self._static(result, p, k, pd, span)
        # blitting: what moves is drawn, in this order, over the rest drawn once (text costs ~0.1 s a frame)
        self.moving = [a for a in (self.cage, self.pockets, self.outer, self.ring, self.rollers, self.spin,
                                   self.faces, self.flash, self.label0, self.state, self.trail, self.trail_now)
                       if a is not None]
        for a in self.moving:
            a.set_animated(True)
        fig.canvas.draw()
        self.background = fig.canvas.copy_from_bbox(fig.bbox)

    def _flash_schedule(self, result) -> None:
        """Which frame each impact of the shown window first flashes in (the first frame at or after it)."""
        imp = result.impacts
        t_frames = self.m.time[self.rows]
        first_dt = t_frames[1] - t_frames[0] if len(t_frames) > 1 else 0.0
        if "time_s" not in imp or not len(t_frames):
            self.imp_frame = np.zeros(0, dtype=np.int64)
            return
        t = np.asarray(imp["time_s"], dtype=float)
        keep = (t > t_frames[0] - first_dt) & (t <= t_frames[-1])
        self.imp_frame = np.searchsorted(t_frames, t[keep], side="left")
        self.imp_pocket = np.asarray(imp["pocket"])[keep].astype(np.int64)
        self.imp_front = np.asarray(imp["face"])[keep] == "front"
        j = np.asarray(imp["impulse_Ns"], dtype=float)[keep]
        self.imp_size = 60.0 + 340.0 * np.sqrt(j / j.max()) if len(j) and j.max() > 0 else np.full(len(j), 60.0)

    def _static(self, result, p, k, pd, span) -> None:
        """What does not move: the load zone, the texts, the force scale, the trail's inset."""
        from matplotlib.cm import ScalarMappable

        ax, fig = self.ax, self.fig
        phi = result.summary.get("load_zone_half_angle_deg", float("nan"))
        if math.isfinite(phi) and phi > 0.0:
            for a in (-90.0 - phi, -90.0 + phi):
                r = np.array([0.35, 0.8]) * (self.rp - self.rr)
                ax.plot(r * math.cos(math.radians(a)), r * math.sin(math.radians(a)), color="0.6", lw=0.8, ls="--")
            ax.text(0.0, -0.5 * (self.rp - self.rr), f"load zone\n±{phi:.1f}°", ha="center", va="center",
                    fontsize=8, color="0.4")
        x0 = VIEW_RECT[2] + 0.01
        head = result.title().splitlines()[0]
        fig.text(x0, 0.975, head.replace(": ", ":\n", 1), fontsize=8.5, va="top", wrap=True)
        g = p.bearing
        fig.text(x0, 0.885, f"clearances drawn ×{k:g}\n(pocket s = {g.pocket_clearance * 1e3:.3g} mm, "
                            f"radial {pd:.3g} mm;\nparts at their size)", fontsize=8, va="top", color="0.15")
        self.state = fig.text(x0, 0.77, "", fontsize=9, va="top", family="monospace")
        fig.text(x0, 0.545, "pocket faces: mean circumferential\nforce on the face [N]", fontsize=8, va="top")
        cax = fig.add_axes((x0 + 0.005, 0.47, 0.21, 0.022))
        cut = self.force_max > self.norm.vmax  # the scale ends below the largest force: said, and its end drawn
        self.scale = fig.colorbar(ScalarMappable(self.norm, self.cmap), cax=cax, orientation="horizontal",
                                  extend="max" if cut else "neither")
        cax.tick_params(labelsize=7)
        if cut:
            fig.text(x0, 0.445, f"forces above {self.norm.vmax:.3g} N (up to {self.force_max:.3g} N)\n"
                                f"are drawn in the top colour", fontsize=7.5, va="top", color="0.15")
        fig.text(x0, 0.408, "★ impact (size ∝ impulse)", fontsize=8, va="top", color=FLASH_COLOUR)
        ended = impact_marks_end(result, self.m.time[self.rows])
        if ended:  # between the frame's numbers and the force scale, where the panel has room
            fig.text(x0, 0.615, ended, fontsize=7.5, va="top", color=FLASH_COLOUR)
        c_um = np.concatenate([self.m.cage_xy, self.m.before_xy if self.m.before_xy is not None
                               else np.zeros((0, 2))]) * 1e6
        lim = max(1.0, 1.15 * float(np.max(np.abs(c_um)))) if c_um.size else 1.0
        tax = self.trail_ax = fig.add_axes((x0 + 0.035, 0.05, 0.2, 0.3))
        tax.set_xlim(-lim, lim)
        tax.set_ylim(-lim, lim)
        tax.set_aspect("equal")
        tax.tick_params(labelsize=7)
        tax.plot([0.0], [0.0], "k+", ms=8)
        tax.set_title("cage centre [µm],\nlast cage rotation", fontsize=8)
        (self.trail,) = tax.plot([], [], lw=0.8, color=TRAIL_COLOUR)
        (self.trail_now,) = tax.plot([], [], "o", ms=4, color="black")

    def draw(self, f: int) -> np.ndarray:
        """The RGB pixels (HEIGHT_PX, WIDTH_PX, 3) of frame ``f``."""
        m, k, j = self.m, self.k, int(self.rows[f])
        cage = m.cage_xy[j] * 1e3
        alpha = m.cage_angle[j] + self.pocket_a
        e_r = np.column_stack([np.cos(alpha), np.sin(alpha)])
        e_t = self.sign * np.column_stack([-e_r[:, 1], e_r[:, 0]])
        centred = self.rp * e_r  # pocket centres of a cage on the axis
        pockets = k * cage + centred
        # every body at its place on the axis plus K times its offset from there: a roller's offset from its
        # pocket's centre (cage + centred) is then drawn K times from the drawn pocket's (K cage + centred), and
        # its offsets from the raceways K times from the drawn raceways
        rollers = centred + k * (m.rollers_xy[j] * 1e3 - centred)
        self.pockets.set_offsets(pockets)
        self.rollers.set_offsets(rollers)
        self.cage.set_transform(self._shift(k * cage))
        if self.ring is not None:
            self.ring.set_transform(self._shift(k * m.ring_xy[j] * 1e3))
        a = m.rollers_angle[j]
        mark = rollers + self.rr * np.column_stack([np.cos(a), np.sin(a)])
        self.spin.set_segments(np.stack([rollers, mark], axis=1))
        # faces: [pocket, rear/front, point, xy]; u = -e_t on the rear face, +e_t on the front
        u = np.stack([-e_t, e_t], axis=1)
        pts = (pockets[:, None, None, :] + self.R * (self.face_u[:, None, :, None] * u[:, :, None, :]
                                                     + self.face_r[:, None, :, None] * e_r[:, None, None, :]))
        self.faces.set_segments(pts.reshape(2 * self.n, -1, 2))
        self.faces.set_array(self.forces[f].reshape(-1))
        self._flashes(f, pockets, u)
        self.label0.set_position(pockets[0] - (self.R + 0.35 * self.rr) * e_r[0])
        self._text(f, j)
        canvas = self.fig.canvas
        canvas.restore_region(self.background)
        for a in self.moving:
            self.fig.draw_artist(a)
        return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()

    def _shift(self, xy):
        from matplotlib.transforms import Affine2D

        return Affine2D().translate(float(xy[0]), float(xy[1])) + self.ax.transData

    def _flashes(self, f, pockets, u) -> None:
        age = f - self.imp_frame
        on = (age >= 0) & (age < len(FLASH_ALPHA))
        i = self.imp_pocket[on] if on.any() else np.zeros(0, dtype=np.int64)
        face = self.imp_front[on].astype(np.int64) if on.any() else np.zeros(0, dtype=np.int64)
        self.flash.set_offsets(pockets[i] + self.R * u[i, face] if len(i) else np.zeros((0, 2)))
        colours = np.zeros((len(i), 4))
        colours[:, :3] = (0.894, 0.0, 0.169)
        colours[:, 3] = np.asarray(FLASH_ALPHA)[age[on]] if len(i) else []
        self.flash.set_facecolors(colours)
        self.flash.set_sizes(self.imp_size[on] if len(i) else [])

    def _text(self, f, j) -> None:
        m = self.m
        theta = math.degrees((self.sign * (m.cage_angle[j] + self.pocket_a[0] + 0.5 * math.pi)) % (2.0 * math.pi))
        slip = f"{100.0 * m.slip[j]:7.3f} %" if m.slip is not None else "      -"
        self.state.set_text(f"t          {m.time[j]:9.6f} s\ncage turn  {m.rotation[j]:9.3f}\n"
                            f"θ pocket 0 {theta:7.1f}°\ncage slip  {slip}\nframe      {f + 1:5d}")
        lo = int(np.searchsorted(m.rotation, m.rotation[j] - 1.0))
        c = m.cage_xy[lo:j + 1] * 1e6
        if lo == 0 and m.before_xy is not None:  # less than a rotation into the window: the rest before it
            c = np.concatenate([m.before_xy[m.before_time >= m.time[j] - m.period] * 1e6, c])
        self.trail.set_data(c[:, 0], c[:, 1])
        self.trail_now.set_data([c[-1, 0]], [c[-1, 1]])


# --- writers -------------------------------------------------------------------------------------------
#: x264's constant rate factor of the MP4 (imageio-ffmpeg's quality 7 of 10: int((1 - 7 / 10) * 51))
MP4_CRF = 15


def _write_mp4(out: Path, frames, fps: float, total: int, progress) -> None:
    """H.264 MP4 through the ffmpeg binary of ``imageio-ffmpeg`` (the command its ``write_frames`` builds),
    with the comment tag :data:`bearingsim.outputs.MARK`, into a temporary file renamed at the end. ffmpeg's
    own messages are read, not shown: a failure (a full disk) is one :class:`UserError` naming ``out`` and
    the cause (:func:`_ffmpeg_failure`)."""
    import subprocess
    import threading
    from fractions import Fraction

    import imageio_ffmpeg

    from bearingsim.outputs import MARK, atomic_file, temporary_name

    with atomic_file(out):  # ffmpeg writes the temporary file by its name; renamed when complete
        cmd = [imageio_ffmpeg.get_ffmpeg_exe(), "-y", "-f", "rawvideo", "-vcodec", "rawvideo",
               "-s", f"{WIDTH_PX:d}x{HEIGHT_PX:d}", "-pix_fmt", "rgb24", "-r", str(Fraction(fps).limit_denominator()),
               "-i", "-", "-an", "-vcodec", "libx264", "-pix_fmt", "yuv420p", "-crf", str(MP4_CRF),
               "-v", "error", "-preset", "veryfast", "-metadata", f"comment={MARK}", "-f", "mp4",
               str(temporary_name(out))]
        proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                process_group=0)  # its own group: a terminal's Ctrl-C reaches this process only
        said = []
        reader = threading.Thread(target=lambda: said.append(proc.stderr.read()), daemon=True)
        reader.start()
        try:
            try:
                for i, frame in enumerate(frames):
                    proc.stdin.write(np.ascontiguousarray(frame, dtype=np.uint8).data)
                    if progress is not None:
                        progress(i + 1, total)
                proc.stdin.close()
            except BrokenPipeError:  # ffmpeg has ended: its exit status and its words say why
                pass
            code = proc.wait()
        finally:
            if proc.poll() is None:  # interrupted, or a frame failed to draw
                proc.kill()
                proc.wait()
            reader.join()
            for stream in (proc.stdin, proc.stderr):
                try:
                    stream.close()
                except OSError:  # the frames ffmpeg did not take: nothing to flush them to
                    pass
        if code != 0:
            raise _ffmpeg_failure(out, code, b"".join(said).decode("utf-8", "replace"))


def _ffmpeg_failure(out: Path, code: int, said: str) -> UserError:
    """One line for ffmpeg that failed with exit status ``code`` having said ``said`` on its stderr: the
    system's error it names (a full disk: "No space left on device"), "File too large" when the file size
    limit ended it (SIGXFSZ), else its last line."""
    import errno
    import signal

    causes = [os.strerror(e) for e in (errno.ENOSPC, errno.EFBIG, errno.EDQUOT, errno.EIO, errno.EROFS, errno.EACCES)]
    cause = next((c for c in causes if c in said), None)
    if cause is None and code == -signal.SIGXFSZ:
        cause = os.strerror(errno.EFBIG)
    lines = [line.strip() for line in said.splitlines() if line.strip()]
    cause = cause or (f"ffmpeg: {lines[-1]}" if lines else f"ffmpeg ended with exit status {code}")
    return UserError(f"{out}: cannot write the animation ({printable(cause, keep_newlines=False)})")


def _write_gif(out: Path, frames, fps: float, total: int, progress) -> None:
    """GIF through Pillow (each frame on an adaptive palette) with the comment :data:`bearingsim.outputs.MARK`,
    written atomically."""
    from PIL import Image

    from bearingsim.outputs import MARK, atomic_file

    with atomic_file(out) as fh:  # the temporary file first: an unwritable folder is told before any frame
        images = []
        for i, frame in enumerate(frames):
            images.append(Image.fromarray(frame).quantize(colors=128, method=Image.Quantize.FASTOCTREE,
                                                          dither=Image.Dither.NONE))
            if progress is not None:
                progress(i + 1, total)
        images[0].save(fh, format="GIF", save_all=True, append_images=images[1:],
                       duration=gif_durations_ms(len(images), fps), loop=0, optimize=False, disposal=1,
                       comment=MARK)


def gif_durations_ms(frames: int, fps: float) -> list[int]:
    """Each frame's delay [ms] in a GIF, which stores delays in hundredths of a second: frame ``i`` ends at
    ``round((i + 1) x 100 / fps)`` cs, so that ``frames`` frames last ``frames / fps`` s to 10 ms (one delay of
    1000 / fps ms, which Pillow truncates to whole hundredths, played 15 fps as 60 ms frames: 10 % fast)."""
    ends = [round((i + 1) * 100.0 / fps) for i in range(frames)]
    return [10 * (e - s) for s, e in zip([0, *ends[:-1]], ends)]
