"""Motion in the archive and ``bearingsim animate`` (issue 27, docs/animation.md). Each test says why its check
must hold.

One short run of the fast scene (rigid raceways, 6000 rpm, 1 warm-up + 1 recorded rotation, the motion of the
whole recorded rotation at 60 poses per rotation) is shared, with its twin that stores no motion.
"""
import dataclasses
import math
import subprocess

import numpy as np
import pytest

import bearingsim
from bearingsim import animation
from bearingsim.cli import main
from bearingsim.errors import UserError
from bearingsim.multibody.scene import pocket_angles
from tests.conftest import SCENARIOS
from .forked_cli import pythonpath as _path

pytestmark = pytest.mark.slow

SPR = 60  # poses per cage rotation of the shared run


def _scenario(motion_rotations):
    return bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={
        "multibody.raceway_contact": "rigid", "numerics.rotations": 1, "numerics.warmup_rotations": 1,
        "output.motion_rotations": motion_rotations, "output.motion_samples_per_rotation": SPR})


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """(result in memory, its archive, the archive of the same run without motion)."""
    folder = tmp_path_factory.mktemp("anim")
    res = bearingsim.run(_scenario(1.0))
    plain = bearingsim.run(_scenario(0.0))
    return res, res.save(folder / "motion.h5"), plain.save(folder / "plain.h5"), plain


def _gif_frames(path):
    from PIL import Image, ImageSequence

    with Image.open(path) as im:
        return [np.asarray(f.convert("RGB")) for f in ImageSequence.Iterator(im)]


def test_motion_changes_no_number_and_is_where_the_run_says(runs):
    """Recording poses only reads the bodies' states (and zeroes an accumulator nothing else reads): the
    per-rotation arrays and the summary must be bit-identical with and without motion. The poses must be
    one per 1/SPR cage rotation over the window (1 rotation: SPR + 1 poses, the first at the start of the
    recorded period, each at the first step past its due travel), and every roller i must sit in pocket i: its centre within s/2 of the pocket centre along
    the circumference (where both faces are, at psi = 0), plus the 1 % of s the model allows a roller to
    overlap a face (PENETRATION_LIMIT). (Radially a pocket holds a roller only as far as its arc faces
    reach: ~0.2 mm here, and the cage rides ~0.2 mm off the axis.)"""
    res, _, _, plain = runs
    for k, v in plain.per_rotation.items():
        assert np.array_equal(v, res.per_rotation[k], equal_nan=True), k
    assert res.summary == plain.summary
    assert not any(k.startswith("motion_") for k in plain.series)
    s = res.series
    angle = s["motion_cage_angle"].value
    assert len(angle) == SPR + 1
    p = res.parameters
    travel = p.operating.sign * angle / (2.0 * math.pi) - p.numerics.warmup_rotations
    # pose j is taken after the first step that reaches j / SPR: at most one step's travel later (the cage
    # turns ~omega_c dt per step; twice that bounds its speed's excursions)
    late = travel - np.arange(len(travel)) / SPR
    assert np.all(late >= 0.0)
    assert late.max() < 2.0 * p.operating.omega_c * res.summary["dt_s"] / (2.0 * math.pi)
    g = p.bearing
    a = angle[:, None] + pocket_angles(g.roller_count, p.operating.sign)[None, :]
    centres = s["motion_cage_position"].value[:, None, :] + g.pitch_radius * np.stack([np.cos(a), np.sin(a)], -1)
    e_t = p.operating.sign * np.stack([-np.sin(a), np.cos(a)], -1)
    along = np.abs(((s["motion_roller_position"].value - centres) * e_t).sum(-1))
    assert along.max() <= 0.5 * g.pocket_clearance * 1.01
    assert along.max() > 0.4 * g.pocket_clearance  # the rollers do cross their pockets
    # the face forces are the circumferential impulses of the steps between two poses over their time: summed
    # over the window (poses 1..SPR) they are the front and rear impulses of the steps whose cage travel lies
    # in the recorded rotation. Pocket 0's rotation is exactly that window (it starts at theta = 0), so they
    # are its I_acc and I_dec, to rounding (the other pockets' rotations start at other cage angles)
    force = s["motion_pocket_force"].value
    dt = np.diff(s["motion_cage_angle"].time)
    impulse = (force[1:, 0, :] * dt[:, None]).sum(0)
    assert impulse[1] == pytest.approx(res.per_rotation["I_acc"][0, 0], rel=1e-9)
    assert impulse[0] == pytest.approx(res.per_rotation["I_dec"][0, 0], rel=1e-9)
    assert impulse.min() > 0.0


def test_gif_has_the_frames_of_its_window_and_fps(runs, tmp_path):
    """Frames: one per 1/fps s of video, each cage rotation shown in SECONDS_PER_ROTATION s: rotations
    0.25..0.5 at 12 fps are round(0.25 x 4 x 12) = 12 frames. Also ``Result.animate`` of the result in
    memory (the same drawing)."""
    res = runs[0]
    out = res.animate(tmp_path / "a.gif", rotations=(0.25, 0.5), fps=12)
    assert len(_gif_frames(out)) == round(0.25 * animation.SECONDS_PER_ROTATION * 12)


@pytest.mark.parametrize("fps", [12, 15, 30])
def test_a_gif_plays_for_the_time_its_frames_and_fps_say(runs, tmp_path, fps):
    """A GIF stores each frame's delay in hundredths of a second: a window of 0.25 rotations must play
    0.25 x SECONDS_PER_ROTATION = 1 s at any fps (to one hundredth), not 12 x 80 ms, 15 x 60 ms or
    30 x 30 ms (a delay of 1000 / fps ms truncated to whole hundredths: up to 10 % fast, as the
    report's 15 fps clip of half a rotation played in 1.8 s instead of 2 s)."""
    from PIL import Image, ImageSequence

    out = runs[0].animate(tmp_path / "t.gif", rotations=(0.25, 0.5), fps=fps)
    with Image.open(out) as im:
        delays = [f.info["duration"] for f in ImageSequence.Iterator(im)]
    assert len(delays) == round(0.25 * animation.SECONDS_PER_ROTATION * fps)
    assert abs(sum(delays) - 1000.0 * 0.25 * animation.SECONDS_PER_ROTATION) <= 10.0, delays
    assert min(delays) >= 20  # browsers show shorter delays as 100 ms


def test_mp4_through_the_command_line(runs, tmp_path, capsys):
    """``bearingsim animate ... --rotations a:b --fps F``: decoded back to raw RGB by the same packaged
    ffmpeg, the MP4 has round((b - a) x 4 x F) frames of the frame's size, and the command says what it
    wrote."""
    import imageio_ffmpeg

    out = tmp_path / "a.mp4"
    assert main(["animate", str(runs[1]), "-o", str(out), "--rotations", "0.5:0.75", "--fps", "20"]) == 0
    assert capsys.readouterr().out.strip() == f"wrote {out}"
    raw = subprocess.run([imageio_ffmpeg.get_ffmpeg_exe(), "-v", "error", "-i", str(out), "-f", "rawvideo",
                          "-pix_fmt", "rgb24", "-"], capture_output=True, check=True, timeout=120).stdout
    frames = np.frombuffer(raw, np.uint8).reshape(-1, animation.HEIGHT_PX, animation.WIDTH_PX, 3)
    assert len(frames) * animation.HEIGHT_PX * animation.WIDTH_PX * 3 == len(raw)
    assert len(frames) == round(0.25 * animation.SECONDS_PER_ROTATION * 20)
    assert frames[-1].std() > 10.0  # a drawing, not a blank frame
    assert not [p for p in tmp_path.iterdir() if p.name != "a.mp4"]  # no temporary file left


def test_an_mp4_on_a_full_disk_is_one_line_naming_the_cause(runs, tmp_path):
    """``bearingsim animate ... -o a.mp4`` whose writes fail past 4 KiB (``RLIMIT_FSIZE`` in the child, which
    ffmpeg inherits: it ends of SIGXFSZ, as on a full disk it fails with ENOSPC): one line naming the file
    and the cause, exit 2, no temporary file; ffmpeg's own words not on the terminal. It printed ffmpeg's
    lines, then "cannot write the animation ([Errno 32] Broken pipe" with ffmpeg's command on more lines."""
    import os
    import resource
    import sys

    import matplotlib.font_manager  # noqa: F401 - its cache written before the child's writes are limited

    from tests.conftest import ROOT

    def limited():
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))

    out = tmp_path / "out" / "a.mp4"
    out.parent.mkdir()
    proc = subprocess.run([sys.executable, "-m", "bearingsim", "animate", str(runs[1]), "-o", str(out),
                           "--rotations", "0.5:0.75", "--fps", "20"], capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": _path()}, preexec_fn=limited)
    assert (proc.returncode, proc.stderr) == (2, f"bearingsim: error: {out}: cannot write the animation (File too "
                                                 f"large)\n"), proc.stderr[-3000:]
    assert list(out.parent.iterdir()) == []


def test_ffmpegs_failure_is_named_by_its_cause(tmp_path):
    """What ffmpeg said on a full disk (its lines as ffmpeg 7 words them), a file size limit that ended it, or
    anything else: one line naming the animation and the cause, never ffmpeg's command."""
    import signal

    out = tmp_path / "a.mp4"
    said = ("[vost#0:0/libx264 @ 0x55] Error submitting a packet to the muxer: No space left on device\n"
            "[out#0/mp4 @ 0x56] Error writing trailer: No space left on device\n")
    assert str(animation._ffmpeg_failure(out, 228, said)) == (f"{out}: cannot write the animation (No space left "
                                                              f"on device)")
    too_large = animation._ffmpeg_failure(out, -signal.SIGXFSZ, "")
    assert str(too_large) == f"{out}: cannot write the animation (File too large)"
    assert str(animation._ffmpeg_failure(out, 1, "x\n\x1b[31mbad codec\n")) == (
        f"{out}: cannot write the animation (ffmpeg: \\x1b[31mbad codec)")


def _cage_centre_px(frame, guess):
    """Centre (col, row) [px] of the circle through the outer edges of the cage's bars in ``frame``: the
    outermost pixel of CAGE_COLOUR in each degree around ``guess``, a least-squares circle through them,
    fitted again without the points more than 2 px, then 1 px, off it (a bar whose edge an impact star or a face's
    end covers). The outer edge, unlike the bars' centroid, is not moved by what is drawn over the bars
    (rollers, face arcs, stars): it lies beyond the faces' ends."""
    rgb = np.array([int(animation.CAGE_COLOUR[i:i + 2], 16) for i in (1, 3, 5)])
    view = frame[:, :animation.HEIGHT_PX]  # the bearing's square
    rows, cols = np.nonzero(np.abs(view.astype(int) - rgb).max(axis=-1) <= 12)
    x, y = cols + 0.5 - guess[0], rows + 0.5 - guess[1]
    r = np.hypot(x, y)
    b = ((np.arctan2(y, x) + math.pi) / (2 * math.pi) * 360).astype(int) % 360
    best = np.full(360, -1.0)
    np.maximum.at(best, b, r)
    edge = (r == best[b]) & (r > 0.8 * r.max())
    px, py = x[edge], y[edge]
    for off in (2.0, 1.0, None):
        a = np.column_stack([2 * px, 2 * py, np.ones_like(px)])
        (cx, cy, c), *_ = np.linalg.lstsq(a, px**2 + py**2, rcond=None)
        if off is None:
            break
        keep = np.abs(np.hypot(px - cx, py - cy) - math.sqrt(c + cx**2 + cy**2)) < off
        px, py = px[keep], py[keep]
    return np.array([cx + guess[0], cy + guess[1]]), len(px)


def test_the_cage_is_drawn_where_the_archive_says(runs, tmp_path):
    """The cage is drawn in CAGE_COLOUR, which nothing else uses, as the ring between its inner and outer
    diameters less the pockets, centred on K times the archive's cage centre (the clearances drawn K
    times): the circle through its bars' outer edges must be centred there, to 2 px (anti-aliased edges on
    the GIF's palette and the 1-degree bins: measured up to 1.3 px; the cage moves 0.1 px per pose). The cage is
    ~200 um off the axis at 6000 rpm: K = 20 draws it ~24 px off, so a cage drawn on the axis (or not
    exaggerated) fails."""
    res, path = runs[0], runs[1]
    k, a, b, fps = 20.0, 0.4, 0.6, 10
    frames = _gif_frames(bearingsim.animate(path, tmp_path / "c.gif", rotations=(a, b), exaggerate=k, fps=fps))
    p = res.parameters
    s = res.series
    travel = p.operating.sign * s["motion_cage_angle"].value / (2 * math.pi) - p.numerics.warmup_rotations
    half = animation.view_half_width(p, k)
    side = animation.HEIGHT_PX  # the view is the left HEIGHT_PX x HEIGHT_PX square
    errors, shifts = [], []
    for f, frame in enumerate(frames):
        pose = int(np.argmin(np.abs(travel - (a + (b - a) * f / len(frames)))))
        c = k * s["motion_cage_position"].value[pose] * 1e3  # drawn cage centre [mm]
        want = np.array([(c[0] + half) / (2 * half) * side, (half - c[1]) / (2 * half) * side])  # (col, row) px
        got, points = _cage_centre_px(frame, (side / 2, side / 2))
        assert points > 30  # degrees of bar edge: about half of what the 16 bars show (~3.5 deg each)
        errors.append(np.hypot(*(got - want)))
        shifts.append(np.hypot(*(want - side / 2)))
    assert len(frames) == round((b - a) * animation.SECONDS_PER_ROTATION * fps)
    assert min(shifts) > 10.0
    assert max(errors) < 2.0, (errors, shifts)


def test_the_rollers_are_drawn_in_their_pockets_and_on_the_raceways(runs):
    """Every clearance is drawn K times: a roller's offset from its pocket's centre (the cage centre plus the
    pitch radius along the pocket's direction) must be drawn K times from the drawn pocket's centre, and its
    distance from the axis and from the inner ring's centre K times its offset from the pitch circle. The
    cage rides ~0.2 mm off the axis here: a roller drawn about its pocket's place on a centred cage instead
    is off by K times that (2 mm at K = 10), through the pocket faces (drawn play K s / 2 = 1 mm) and into a
    raceway. The drawn offsets are read from the frame's own artists (the collections the frame draws)."""
    res, path = runs[0], runs[1]
    p, g = res.parameters, res.parameters.bearing
    motion = animation._Motion(res)
    k = animation._exaggeration(p, None)
    rows = np.arange(0, len(motion.time), 6)
    drawing = animation._Drawing(res, motion, k, rows)
    rp, rr = g.pitch_radius * 1e3, g.roller_radius * 1e3
    play = drawing.R - rr
    excess_face, excess_outer, excess_inner, cage_off = [], [], [], []
    for f, j in enumerate(rows):
        drawing.draw(f)
        rollers = np.asarray(drawing.rollers.get_offsets())
        pockets = np.asarray(drawing.pockets.get_offsets())
        cage = motion.cage_xy[j] * 1e3
        a = motion.cage_angle[j] + pocket_angles(g.roller_count, p.operating.sign)
        e_r = np.column_stack([np.cos(a), np.sin(a)])
        e_t = p.operating.sign * np.column_stack([-e_r[:, 1], e_r[:, 0]])
        offset = motion.rollers_xy[j] * 1e3 - cage - rp * e_r  # the roller in its pocket [mm]
        np.testing.assert_allclose(rollers - pockets, k * offset, atol=1e-9)
        excess_face.append(np.abs(((rollers - pockets) * e_t).sum(1)).max() - play)
        pd = g.radial_clearance * 1e3
        excess_outer.append((np.hypot(*rollers.T) + rr - (rp + 0.25 * k * pd + rr)).max())
        ring = k * motion.ring_xy[j] * 1e3
        excess_inner.append(((rp - 0.25 * k * pd) - np.hypot(*(rollers - ring).T)).max())
        cage_off.append(np.hypot(*cage))
    assert min(cage_off) > 0.1  # the case this test is about: a cage well off the axis [mm]
    # along the circumference within the drawn play (1 % of it: the overlap the model allows); radially the
    # raceways' contact approach (a few um, drawn K times) and the second-order growth of the radius of a
    # roller drawn K times off its place along the circumference (K^2 offset^2 / 2 r_p) on the raceways
    assert max(excess_face) <= 0.01 * play
    assert max(excess_outer) < 0.15 and max(excess_inner) < 0.15, (max(excess_outer), max(excess_inner))


def test_an_archive_without_motion_is_refused_in_one_line(runs, tmp_path, capsys):
    """No motion: exit 2, one line naming the archive and the key to set, no traceback, no file left."""
    out = tmp_path / "x.mp4"
    assert not animation.has_motion(runs[2]) and animation.has_motion(runs[1])
    assert main(["animate", str(runs[2]), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "output.motion_rotations" in err and str(runs[2]) in err
    assert "Traceback" not in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("window, words", [("0.5-0.7", "expected a:b"), ("0.7:0.5", "a < b"),
                                           ("nan:1", "a < b"), ("3:4", "outside the stored motion")])
def test_bad_rotations_are_refused_in_one_line(runs, tmp_path, capsys, window, words):
    """A window that is not a:b, not increasing, or outside the stored poses (recorded rotations 0..1 here):
    exit 2, one line naming --rotations (the window outside the poses said "rotations 3:4"), nothing written."""
    out = tmp_path / "x.gif"
    assert main(["animate", str(runs[1]), "-o", str(out), "--rotations", window]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and words in err and err.startswith("bearingsim: error: --rotations")
    assert list(tmp_path.iterdir()) == []


def test_a_gif_faster_than_browsers_play_is_refused_and_an_mp4_is_not(runs, tmp_path, capsys):
    """A GIF's delays are whole hundredths of a second and browsers show one under 20 ms as 100 ms: at
    --fps 60 some frames got 10 ms, at 120 every frame 0 ms, a clip playing several times too slowly.
    Above MAX_GIF_FPS = 50 a GIF is refused in one line naming the option (the API: its keyword), nothing
    written; at 50 every frame is 20 ms; an MP4 takes up to MAX_FPS."""
    from PIL import Image, ImageSequence

    with pytest.raises(UserError, match=r"^fps 60: a GIF plays at most 50 frames per second"):
        runs[0].animate(tmp_path / "a.gif", rotations=(0.25, 0.3), fps=60)
    assert main(["animate", str(runs[1]), "-o", str(tmp_path / "b.gif"), "--fps", "120"]) == 2
    assert capsys.readouterr().err.startswith("bearingsim: error: --fps 120: a GIF plays at most 50")
    assert list(tmp_path.iterdir()) == []
    out = runs[0].animate(tmp_path / "c.gif", rotations=(0.25, 0.3), fps=50)
    with Image.open(out) as im:
        assert {f.info["duration"] for f in ImageSequence.Iterator(im)} == {20}
    assert runs[0].animate(tmp_path / "d.mp4", rotations=(0.25, 0.3), fps=120).stat().st_size > 0


def test_bad_output_and_options_are_refused(runs, tmp_path):
    """Only .mp4 and .gif; a user's file of another kind at the output path is kept; K and fps in range."""
    with pytest.raises(UserError, match=r"\.mp4 or \.gif"):
        bearingsim.animate(runs[1], tmp_path / "a.avi")
    mine = tmp_path / "mine.gif"
    mine.write_text("not a gif")
    with pytest.raises(UserError, match="not replaced"):
        bearingsim.animate(runs[1], mine)
    assert mine.read_text() == "not a gif"
    with pytest.raises(UserError, match="exaggerate"):
        bearingsim.animate(runs[1], tmp_path / "b.gif", exaggerate=0.5)
    with pytest.raises(UserError, match="fps"):
        bearingsim.animate(runs[1], tmp_path / "b.gif", fps=0)


def _users_video(path):
    """A user's own animation at ``path``: a GIF that Pillow wrote, or an MP4 (H.264) that the packaged
    ffmpeg wrote, outside bearingsim. Returns its bytes."""
    from PIL import Image

    frames = [np.full((48, 64, 3), 40 * i, np.uint8) for i in range(4)]
    if path.suffix == ".gif":
        images = [Image.fromarray(f) for f in frames]
        images[0].save(path, format="GIF", save_all=True, append_images=images[1:], duration=100, loop=0)
    else:
        import imageio_ffmpeg

        writer = imageio_ffmpeg.write_frames(str(path), (64, 48), fps=8, macro_block_size=16,
                                             output_params=["-f", "mp4"], ffmpeg_log_level="error")
        writer.send(None)
        for f in frames:
            writer.send(f)
        writer.close()
    return path.read_bytes()


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_only_an_animation_bearingsim_wrote_is_replaced(runs, tmp_path, capsys, suffix):
    """`animate -o user.gif` replaced any GIF (and any MP4, by its 'ftyp'), a user's own picture or video
    included: bearingsim marks what it writes (a GIF's comment, an MP4's comment tag) and replaces only a
    file with the mark; a user's file is refused in one line naming it, exit 2, kept, nothing written."""
    from bearingsim import outputs

    ours, mine = tmp_path / f"ours{suffix}", tmp_path / f"mine{suffix}"
    data = _users_video(mine)
    args = ["--rotations", "0:0.05", "--fps", "8", "-q"]
    for _ in range(2):  # written, then replaced
        assert main(["animate", str(runs[1]), "-o", str(ours), *args]) == 0, capsys.readouterr().err
    capsys.readouterr()
    assert main(["animate", str(runs[1]), "-o", str(mine), *args]) == 2
    what = "GIF" if suffix == ".gif" else "MP4"
    assert capsys.readouterr().err == (f"bearingsim: error: {mine}: {what} animation path is a file without "
                                       "bearingsim's mark (not written by it, or by a version before its files "
                                       "carried it); not replaced (remove it or choose another path)\n")
    assert mine.read_bytes() == data and sorted(p.name for p in tmp_path.iterdir()) == sorted([ours.name, mine.name])
    assert (outputs.is_own_gif if suffix == ".gif" else outputs.is_own_mp4)(ours)


@pytest.mark.parametrize("last, words", [(-1, "last: -1 is not a positive"), (0, "last: 0 is not a positive"),
                                         (float("nan"), "last: nan is not a positive"), ("x", "last: expected a number")])
def test_a_bad_last_is_refused_in_one_line(runs, tmp_path, last, words):
    """`bearingsim.animate(path, out, last=-1)` (or 0) wrote a one-frame animation of a pose past the stored
    window, `last=nan` the whole window, and `last="x"` raised ValueError: `last`, the cage rotations at the
    end of the window to show, is a positive number, else a UserError naming it; nothing is written."""
    with pytest.raises(UserError, match=f"^{words}"):
        bearingsim.animate(runs[1], tmp_path / "a.gif", last=last)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option, value", [("--fps", "0"), ("--exaggerate", "0.5")])
def test_the_command_line_names_the_option_given_out_of_range(runs, tmp_path, capsys, option, value):
    """`animate --fps 0` said "fps: 0.0 is outside ..." (the API's keyword): the command line names its
    option, in one line, exit 2, and writes nothing."""
    assert main(["animate", str(runs[1]), "-o", str(tmp_path / "a.gif"), option, value]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"bearingsim: error: {option}: {float(value)!r} is outside"), err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("suffix", [".gif", ".mp4"])
def test_the_output_folder_is_made_as_a_runs_is_and_an_unwritable_one_is_told_before_any_frame(runs, tmp_path,
                                                                                                  suffix):
    """A missing folder is created (as ``run`` and ``report`` do); a file where the folder should be, and a
    folder no file can be created in (/proc), are one-line errors naming the output, told before the first
    frame is drawn (a GIF drew every frame, then failed on its temporary file's name) and leaving nothing."""
    out = bearingsim.animate(runs[1], tmp_path / "new" / "sub" / f"a{suffix}", rotations=(0.0, 0.05), fps=8)
    assert out.is_file() and sorted(p.name for p in out.parent.iterdir()) == [f"a{suffix}"]
    (tmp_path / "afile").write_text("mine")
    with pytest.raises(UserError, match=r"afile: cannot create the animation's folder \(it is a file\)$"):
        bearingsim.animate(runs[1], tmp_path / "afile" / f"m{suffix}")
    assert (tmp_path / "afile").read_text() == "mine"
    drawn = []
    with pytest.raises(UserError, match=rf"^/proc/m{suffix}: cannot write the animation \("):
        bearingsim.animate(runs[1], f"/proc/m{suffix}", progress=lambda done, total: drawn.append(done))
    assert drawn == []

    def interrupt(done, total):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):  # stopped on the way: the folder made for it is removed again
        bearingsim.animate(runs[1], tmp_path / "gone" / f"m{suffix}", progress=interrupt)
    assert not (tmp_path / "gone").exists()


def test_motion_window_keys_are_checked():
    """A given start must leave the window inside the recorded rotations (naming the key); "last" with a
    window longer than the run stores the whole run; the pose count is bounded."""
    with pytest.raises(UserError, match="output.motion_start_rotation"):
        bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={
            "output.motion_start_rotation": 39.5, "output.motion_rotations": 1})
    with pytest.warns(bearingsim.UnreadKeyWarning, match="output.motion_rotations = 5 is longer than the run's 1"):
        sc = bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={
            "numerics.rotations": 1, "output.motion_rotations": 5})
    nu = bearingsim.parameters.Parameters.from_scenario(sc).numerics
    assert (nu.motion_start, nu.motion_rotations) == (0.0, 1.0)
    with pytest.raises(UserError, match="output.motion_rotations"):
        bearingsim.load_scenario(SCENARIOS / "multibody_6000rpm.toml", set={
            "output.motion_rotations": 40, "output.motion_samples_per_rotation": 10000})


@pytest.mark.parametrize("sig, code, said", [("SIGINT", 130, "bearingsim: interrupted, no animation written"),
                                             ("SIGTERM", 143, "bearingsim: terminated (SIGTERM), no animation written")])
def test_an_interrupted_animation_says_no_animation_is_written(runs, tmp_path, monkeypatch, capsys, sig, code, said):
    """SIGINT or SIGTERM while frames are drawn: exit 130 / 143, one line saying no animation was written (it
    said "no archive written", of a command that writes none), and nothing left in the folder."""
    import os
    import signal
    import time

    frames = animation._write_gif

    def signalled(out, frame_iter, *a, **kw):
        os.kill(os.getpid(), getattr(signal, sig))
        time.sleep(5)  # the handler raises here
        return frames(out, frame_iter, *a, **kw)

    monkeypatch.setattr(animation, "_write_gif", signalled)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        assert main(["animate", str(runs[1]), "-o", str(tmp_path / "m.gif"), "-q"]) == code
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err.strip().splitlines() == [said]
    assert list(tmp_path.iterdir()) == []


def test_an_exaggeration_the_drawing_cannot_hold_is_refused_in_one_line(runs, tmp_path, capsys):
    """`animate --exaggerate 100` (up to the cap of 1000) exited 0 and drew pockets wider than their pitch: the
    cage bars vanished and rollers overlapped. The largest K is the bearing's own: the pockets drawn K s / 2 wider
    leave a quarter of the cage bar (2 r_p sin(pi / Z) - 2 r - s at the pitch circle), 22.8 for the NU214, to 0.1
    below. Above it the command line refuses in one line naming --exaggerate and that K, exit 2, nothing written;
    the API refuses the same; at it the drawing is made."""
    g = runs[0].parameters.bearing
    bar = 2 * g.pitch_radius * math.sin(math.pi / g.roller_count) - 2 * g.roller_radius - g.pocket_clearance
    top = math.floor(10 * (1 + 0.75 * bar / g.pocket_clearance)) / 10
    assert top == 22.8
    for k in ("100", "1000", "22.9"):
        assert main(["animate", str(runs[1]), "-o", str(tmp_path / "a.gif"), "--exaggerate", k]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith(f"bearingsim: error: --exaggerate {float(k):g}: at most 22.8 "), err
    with pytest.raises(UserError, match="^exaggerate 30: at most 22.8 "):
        bearingsim.animate(runs[1], tmp_path / "b.gif", exaggerate=30)
    assert list(tmp_path.iterdir()) == []
    drawing = animation._Drawing(runs[0], animation._Motion(runs[0]), top, np.array([0]))
    drawing.draw(0)
    pockets = np.asarray(drawing.pockets.get_offsets())
    kept = np.hypot(*(pockets - np.roll(pockets, 1, axis=0)).T).min() - 2 * drawing.R
    assert 0.25 * bar * 1e3 <= kept < 0.26 * bar * 1e3
    fewer = dataclasses.replace(runs[0].parameters, bearing=dataclasses.replace(g, roller_count=12))
    assert animation.max_exaggeration(fewer) > 2 * top  # wider bars: a larger K fits


def test_forces_above_the_colour_scale_are_said_to_be_drawn_in_its_top_colour(runs):
    """The face-force scale ends at the 99.5th percentile of the window's forces, so that a few impacts' peaks
    do not leave every other face pale; the faces above it were drawn in its darkest colour without a word
    (a reviewer's window: 39 face-frames above the top, 28.6 N, up to 73 N). The scale's end is drawn as an
    arrow (extend="max") and a line says that forces above the top, up to the largest, take its colour."""
    res = runs[0]
    motion = animation._Motion(res)
    drawing = animation._Drawing(res, motion, 10.0, np.arange(0, len(motion.time), 2))
    top, biggest = drawing.norm.vmax, float(drawing.forces.max())
    assert biggest > top == pytest.approx(np.percentile(drawing.forces, 99.5))  # the case this test is about
    assert drawing.scale.extend == "max"
    said = [t.get_text() for t in drawing.fig.texts if f"above {top:.3g} N" in t.get_text()]
    assert len(said) == 1 and f"{biggest:.3g} N" in said[0] and "top colour" in said[0], said


def test_the_cage_trail_at_the_start_of_the_window_is_taken_from_before_it(runs):
    """The inset shows the cage centre's path over the last cage rotation; in a window's first rotation it was
    taken from the window alone, so the first frame showed a dot, though the archive's cage_centre holds the
    path from t = 0. There the trail is that path over the rotation before the frame (the window's mean time
    per rotation), the window's poses after it."""
    res = runs[0]
    motion = animation._Motion(res)
    drawing = animation._Drawing(res, motion, 10.0, np.arange(len(motion.time)))
    drawing.draw(0)
    x, y = drawing.trail.get_data()
    period = (motion.time[-1] - motion.time[0]) / (motion.rotation[-1] - motion.rotation[0])
    c = res.series["cage_centre"]
    before = (c.time < motion.time[0]) & (c.time >= motion.time[0] - period)
    assert before.sum() > 20  # the case this test is about: a rotation of path before the window
    want = np.vstack([c.value[before], motion.cage_xy[:1]]) * 1e6
    np.testing.assert_allclose(np.column_stack([x, y]), want)


@pytest.mark.slow
def test_frames_after_a_full_impact_tables_end_say_why_they_show_no_impacts(monkeypatch):
    """The impacts an animation marks come from the archive's impact table, which stops at its capacity
    (``multibody.core.IMPACT_CAPACITY``, about 600 recorded rotations at 3000 rpm; the run notes it). Frames after
    its last row showed no impact and said nothing; the legend now says from when no impact is marked and why.
    Shrunk to 20 rows here (the table fills within the window); a run whose table held every impact says
    nothing of it."""
    from bearingsim.multibody import core

    sc = _scenario(1.0).replace(**{"numerics.rotations": 2})
    full = bearingsim.run(sc)
    assert animation.impact_marks_end(full, np.array([0.0, 1.0])) == ""
    monkeypatch.setattr(core, "IMPACT_CAPACITY", 20)
    cut = bearingsim.run(sc)
    t_last = float(cut.impacts["time_s"][-1])
    text = animation.impact_marks_end(cut, np.array([t_last - 1e-3, t_last + 1e-3]))
    assert text == (f"★ none marked after t = {t_last:.4g} s:\nthe archive's impact table\nfilled up "
                    "(its run's note)"), text
    assert animation.impact_marks_end(cut, np.array([t_last - 2e-3, t_last])) == ""  # the window ends with it


def test_an_animation_another_command_is_writing_is_refused_and_kept(runs, tmp_path):
    """Two commands writing one animation: the second is refused in one line naming the file (the lock
    beside it, as a run's archive has), and the first one's file is neither replaced nor removed; no
    folder of the refused one is left."""
    from bearingsim.outputs import OutputLock

    _, archive, _, _ = runs
    out = bearingsim.animate(archive, tmp_path / "a.gif", fps=2)  # a file the refused command must leave alone
    first = out.read_bytes()
    with OutputLock(out, "animation"):
        with pytest.raises(bearingsim.UserError, match=r"a\.gif: another bearingsim command is writing this "
                                                       r"animation \(lock \.a\.gif\.lock is held\)"):
            bearingsim.animate(archive, out, fps=2, last=0.5)
    assert out.read_bytes() == first
    new = tmp_path / "new" / "b.gif"
    with OutputLock(new, "animation"):  # the lock made the folder: the refused command leaves it
        with pytest.raises(bearingsim.UserError, match="is writing this animation"):
            bearingsim.animate(archive, new, fps=2)
    assert not new.exists()
