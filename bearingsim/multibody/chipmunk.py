"""The compiled step loop: chipmunk's C functions called from numba, behind a version guard.

This is the only module that uses pymunk's private C interface (``pymunk._chipmunk_cffi``: the cffi
``ffi`` and ``lib``, chipmunk's ``cpSpaceStep``, ``cpSpaceEachBody`` and ``cpSpaceEachCachedArbiter``,
pymunk's batched iterator functions ``pmSpaceBody{Get,Set}IteratorFuncBatched`` and
``pmSpaceArbiterIteratorFuncBatched``, and its C array structs ``pmFloatArray``/``pmIntArray``/
``pmBatchedData``), and writes the bodies' forces, positions and velocities straight into chipmunk's
``struct cpBody`` (offsets checked on a probe body, :func:`body_layout`; otherwise pymunk's batched
setter does it). Two more struct accesses take work out of chipmunk's step and change no number
(``docs/fast_scene.md``, *What pymunk is spared*): each roller's collision mask in its ``cpShape``,
narrowed to the face segments it can touch in the step from the bodies' bias velocities in their
``cpBody`` (:func:`mask_layout`); and, with rigid raceways, the length and accumulated impulse of a
``cpSlideJoint`` whose roller touches nothing in the step: the joint is left slack in chipmunk and
solved here, the same arithmetic (:func:`joint_solve`, checked against chipmunk by :func:`joint_layout`).

:func:`advance` calls them through their function pointers, so no Python runs
between steps; per step it calls the same kernels as the plain loop
(:func:`bearingsim.multibody.loop.before_step`, then the bodies' set, ``cpSpaceStep(h)`` timed with
``clock_gettime(CLOCK_MONOTONIC)``, the batched reads, then
:func:`bearingsim.multibody.loop.after_step`).

Nothing in the scene is added or removed during a run and there are no collision callbacks, so
calling ``cpSpaceStep`` directly (without pymunk's Python wrapper around the step) is what
``Space.step`` does for this space. The C arrays are sized so that pymunk never has to grow them;
if it ever did, :func:`advance` stops with ``CODE_BUFFER_GREW`` rather than read a stale pointer.

Which loop runs
---------------
:func:`open_step_loop` gives the compiled loop when :func:`guard` passes: pymunk's version is one this
module is known to work with (``SUPPORTED_PYMUNK``, checked against ``pymunk.version``) and the
symbols and struct layout it relies on are there. Otherwise, or when asked for with
``run(..., step_loop="plain")`` or the environment variable ``BEARINGSIM_PLAIN_PYMUNK=1``, it gives
:class:`bearingsim.multibody.loop.PlainLoop`, a Python loop over ``Space.step`` and the public
``pymunk.batch`` functions that calls the same kernels in the same order on the same inputs: the same
numbers bit for bit, slower. A run records which loop ran (``raw.step_loop``) and why
(``raw.step_loop_reason``).
"""
from __future__ import annotations

import ctypes
import functools
import math
import os
from typing import NamedTuple

import numba.experimental.function_type  # noqa: F401  (registers typeof for WrapperAddressProtocol)
import numpy as np
import pymunk
import pymunk.batch as pb
from numba import carray, njit, types
from numba.extending import intrinsic

from bearingsim import compiled_laws, laws
from bearingsim._jit import drop_stale_caches
from bearingsim.multibody import forces as fk
from bearingsim.multibody import loop as lp
from bearingsim.multibody import recorder as rk
from bearingsim.reduced import core as _reduced_core

try:
    from pymunk._chipmunk_cffi import ffi, lib
except ImportError:  # pragma: no cover - a pymunk without its cffi module
    ffi = lib = None

#: pymunk major versions the compiled loop is known to work with (checked: 7.3.1); pyproject.toml pins
#: pymunk to the same major version (tests/test_multibody_kernels.py checks that they agree)
SUPPORTED_PYMUNK = (7,)
PLAIN_ENV = "BEARINGSIM_PLAIN_PYMUNK"
#: how much slower the plain loop is, measured: the step loop of scenarios/multibody_3000rpm.toml
#: (1 warm-up + 2 rotations, 34364 steps, kernels compiled beforehand) took 2.46 s plain against
#: 0.53 s compiled (multibody.core.run(p, step_loop=...), one machine shared with other jobs)
PLAIN_SLOWDOWN = 4.6
_announced = False  # the fallback to the plain loop is announced once per process
_FUNCTIONS = ("cpSpaceStep", "cpSpaceEachBody", "cpSpaceEachCachedArbiter", "pmSpaceBodyGetIteratorFuncBatched",
              "pmSpaceBodySetIteratorFuncBatched", "pmSpaceArbiterIteratorFuncBatched", "pmFloatArrayNew",
              "pmFloatArrayFree", "pmIntArrayNew", "pmIntArrayFree", "cpConstraintGetImpulse",
              "cpShapeSetElasticity", "cpSegmentShapeSetEndpoints")
CLOCK_MONOTONIC = 1  # Linux and macOS


def _announce_plain(why: str) -> None:
    """Warn, once per process, that the compiled loop was refused and what that costs."""
    global _announced
    if _announced:
        return
    _announced = True
    import warnings

    from bearingsim.errors import SlowLoopWarning

    warnings.warn(f"bearingsim: the multibody model's compiled step loop cannot run ({why}); the plain loop "
                  f"runs instead: the same numbers, about {PLAIN_SLOWDOWN:g} times slower (install pymunk "
                  f"{' or '.join(f'{v}.x' for v in SUPPORTED_PYMUNK)} for the compiled loop)",
                  SlowLoopWarning, stacklevel=3)


def guard() -> str | None:
    """None when the compiled loop can run with this pymunk, else the reason it cannot."""
    version = getattr(pymunk, "version", "")
    try:
        major = int(version.split(".")[0])
    except ValueError:
        return f"pymunk version {version!r} not understood"
    if major not in SUPPORTED_PYMUNK:
        return f"pymunk {version} is not a version the compiled loop is known to work with ({SUPPORTED_PYMUNK})"
    if lib is None:
        return "pymunk._chipmunk_cffi is missing"
    missing = [f for f in _FUNCTIONS if not hasattr(lib, f)]
    if missing:
        return f"pymunk's C library lacks {', '.join(missing)}"
    if not all(hasattr(pb.Buffer, a) for a in ("_float_arr", "_int_arr")):
        return "pymunk.batch.Buffer has no _float_arr/_int_arr"
    try:
        layout_ok = (ffi.sizeof("cpFloat") == 8 and ffi.sizeof("uintptr_t") == 8
                     and ffi.offsetof("pmFloatArray", "num") == 0 and ffi.offsetof("pmFloatArray", "max") == 4
                     and ffi.offsetof("pmFloatArray", "arr") == 8
                     and ffi.offsetof("pmIntArray", "num") == 0 and ffi.offsetof("pmIntArray", "max") == 4
                     and ffi.offsetof("pmIntArray", "arr") == 8
                     and {"fields", "floatArray", "intArray"} <= {f for f, _ in ffi.typeof("pmBatchedData").fields})
    except (ffi.error, KeyError, TypeError) as exc:
        return f"pymunk's C structs are not as expected ({exc})"
    if not layout_ok:
        return "pymunk's C array structs do not have the expected layout"
    return None


#: cpBody fields the compiled loop writes directly, as float64 indices into the struct: position p and
#: velocity v (2 each), force f (2), torque t; chipmunk 7's ``struct cpBody`` (opaque in pymunk's cdef,
#: so checked on a probe body by :func:`body_layout`)
BODY_P, BODY_V, BODY_F, BODY_T = 8, 10, 12, 16
_BODY_PROBE_DOUBLES = BODY_T + 1


#: chipmunk 7's ``struct cpBody`` holds the bias velocities (v_bias (2), w_bias) of the overlap correction
#: here (float64 indices); ``struct cpShape`` holds its filter's mask here (uint32 index); checked by
#: :func:`mask_layout`
BODY_VBIAS, BODY_WBIAS = 24, 26
SHAPE_MASK = 41


@functools.lru_cache(maxsize=1)
def mask_layout() -> str | None:
    """None when a ``cpShape``'s filter mask and a ``cpBody``'s bias velocities are where :func:`advance`
    reads and writes them (for the narrowed face masks), else why not. Once per process.

    The mask: set through pymunk, read back from the struct, then written into the struct and read
    through pymunk. The bias velocities: a circle left overlapping a static segment by 0.1 m gets
    ``v_bias = 0.1 / dt`` from chipmunk's overlap correction in one step, which the next step's position
    update adds to its velocity (``p + (v + v_bias) dt``)."""
    b = pymunk.Body(1.0, 1.0)
    c = pymunk.Circle(b, 1.0)
    c.filter = pymunk.ShapeFilter(group=0, categories=0x5A5A5A5A, mask=0x3C3C3C3C)
    u = np.frombuffer(ffi.buffer(c._shape, 4 * (SHAPE_MASK + 1)), dtype=np.uint32)
    if u[SHAPE_MASK - 1] != 0x5A5A5A5A or u[SHAPE_MASK] != 0x3C3C3C3C:
        return "pymunk's cpShape does not hold its filter where chipmunk 7 does"
    u[SHAPE_MASK] = 0x0F0F0F0F
    if c.filter.mask != 0x0F0F0F0F or c.filter.categories != 0x5A5A5A5A:
        return "pymunk's cpShape does not hold its filter where chipmunk 7 does"
    space = pymunk.Space()
    space.collision_bias = 0.0
    space.collision_slop = 0.0
    body = pymunk.Body(1.0, 1.0)
    body.position = (0.0, 0.9)
    space.add(body, pymunk.Circle(body, 1.0), pymunk.Segment(space.static_body, (-5.0, 0.0), (5.0, 0.0), 0.0))
    dt = 0.01
    space.step(dt)
    d = np.frombuffer(ffi.buffer(body._body, 8 * (BODY_WBIAS + 1)), dtype=np.float64).copy()
    p1, v1 = body.position, body.velocity
    space.step(dt)
    moved = (body.position.y - p1.y) / dt - v1.y
    if not (abs(d[BODY_VBIAS + 1] - 10.0) < 1e-6 and abs(moved - d[BODY_VBIAS + 1]) < 1e-6):
        return "pymunk's cpBody does not hold its bias velocities where chipmunk 7 does"
    return None


#: chipmunk 7's ``struct cpSlideJoint`` (float64 indices): its length ``max`` and accumulated impulse
#: ``jnAcc``; ``struct cpBody``: the inverse mass; checked by :func:`joint_layout`
SLIDE_MAX, SLIDE_JNACC = 18, 26
BODY_MINV = 3
_DBL_MIN = 2.2250738585072014e-308  # CPFLOAT_MIN, added to a length by chipmunk's cpvnormalize


@njit(cache=True, inline="always")
def joint_solve(x, y, vx, vy, m_inv, r_max, h, dt_coef, jn_acc, iterations):
    """What chipmunk's step does to a body held by a slide joint (length 0 to ``r_max``, anchored at the
    origin on a static body, at the body's centre, ``error_bias`` 0, no limit on force or bias) when
    nothing else acts on it in the step: its preStep at the position after the position update
    ``(x, y)``, the cached impulse ``jn_acc`` (of the last step) times ``dt_coef``, then ``iterations``
    impulse iterations, on the velocity after the velocity update ``(vx, vy)``. The same operations in
    the same order as chipmunk 7's cpSlideJoint.c (and cpvnormalize, k_scalar, relative_velocity,
    apply_impulses with zero lever arms), so the same bytes; returns ``(vx, vy, jn_acc)``. An iteration
    that changes nothing ends them (the next would compute the same)."""
    dist = math.sqrt(x * x + y * y)
    if not dist > r_max:
        return vx, vy, 0.0  # slack: chipmunk zeroes its normal and accumulated impulse
    pdist = dist - r_max
    inv = 1.0 / (dist + _DBL_MIN)  # cpvnormalize (its own length is the same sqrt of the same sum)
    nx = x * inv
    ny = y * inv
    n_mass = 1.0 / (0.0 + m_inv)
    bias = (-1.0 * pdist) / h
    jc = jn_acc * dt_coef  # applyCachedImpulse
    vx = vx + (nx * jc) * m_inv
    vy = vy + (ny * jc) * m_inv
    for _ in range(iterations):
        vrn = vx * nx + vy * ny
        jn = (bias - vrn) * n_mass
        old = jn_acc
        acc = old + jn
        jn_acc = acc if acc < 0.0 else 0.0  # cpfclamp(acc, -maxForce dt = -inf, 0)
        jn = jn_acc - old
        vx = vx + (nx * jn) * m_inv
        vy = vy + (ny * jn) * m_inv
        if jn == 0.0:
            break  # the next iteration would compute the same (even the signs of zero are settled now)
    return vx, vy, jn_acc


@functools.lru_cache(maxsize=1)
def joint_layout() -> str | None:
    """None when :func:`joint_solve` reproduces chipmunk's slide joint bit for bit and the joint's
    ``max`` and ``jnAcc`` and the body's inverse mass are where :func:`advance` reads and writes them,
    else why not. Once per process: a body on a joint is stepped through pymunk (taut and slack, at
    two step sizes) and each step recomputed."""
    anchor = pymunk.Body(body_type=pymunk.Body.STATIC)
    space = pymunk.Space()
    space.iterations = 10
    space.gravity = (0.0, -9.81)
    b = pymunk.Body(0.3, 0.01)
    b.position = (0.0599, 0.0)  # on the circle, moving along it: taut, warm-started steps
    b.velocity = (0.0, 3.0)
    j = pymunk.SlideJoint(anchor, b, (0.0, 0.0), (0.0, 0.0), 0.0, 0.0599)
    j.error_bias = 0.0
    space.add(b, j)
    c = np.frombuffer(ffi.buffer(j._constraint, 8 * (SLIDE_JNACC + 1)), dtype=np.float64)
    body = np.frombuffer(ffi.buffer(b._body, 8 * (BODY_MINV + 1)), dtype=np.float64)
    if c[SLIDE_MAX] != 0.0599 or body[BODY_MINV] != 1.0 / 0.3:
        return "pymunk's cpSlideJoint or cpBody does not have chipmunk 7's layout"
    prev_h, jn = 0.0, 0.0
    # taut at 10 us, taut at 20 us (a new step size: the cached impulse scaled), pulled off (slack), taut again
    steps = ([(1e-5, (30.0, 5.0))] * 4 + [(2e-5, (30.0, -5.0))] * 3 + [(2e-5, (-3000.0, 0.0))]
             + [(2e-5, (3000.0, 0.0))] * 3)
    taut = 0
    for k, (h, force) in enumerate(steps):
        b.force = force
        v0 = b.velocity
        space.step(h)
        px, py = b.position
        vx = v0.x * 1.0 + (0.0 + force[0] * body[BODY_MINV]) * h
        vy = v0.y * 1.0 + (-9.81 + force[1] * body[BODY_MINV]) * h
        want = joint_solve(px, py, vx, vy, body[BODY_MINV], 0.0599, h, 0.0 if prev_h == 0.0 else h / prev_h, jn, 10)
        got = (b.velocity.x, b.velocity.y, c[SLIDE_JNACC])
        if want != got or abs(got[2]) != j.impulse:
            return f"chipmunk's slide joint does not compute what bearingsim reproduces (probe step {k})"
        prev_h, jn = h, got[2]
        taut += got[2] != 0.0
    if taut < len(steps) - 3:
        return "the slide-joint probe did not hold its body taut"  # pragma: no cover - a change of chipmunk's joint
    return None


@njit(cache=True)
def _set_endpoints(fn, ptr, ax, ay, bx, by):
    fn(ptr, ax, ay, bx, by)


@functools.lru_cache(maxsize=1)
def endpoints_layout() -> str | None:
    """None when ``cpSegmentShapeSetEndpoints`` called from numba with four doubles (:data:`_ENDPOINTS_SIG`)
    sets a segment's ends as pymunk's own call does (exact arc faces), else why not. Once per process."""
    b = pymunk.Body(1.0, 1.0)
    seg = pymunk.Segment(b, (0.0, 0.0), (1.0, 0.0), 0.0)
    want = ((0.125, -2.5), (3.75, 0.0625))
    _set_endpoints(_chipmunk("cpSegmentShapeSetEndpoints", _ENDPOINTS_SIG), _address(seg._shape),
                   want[0][0], want[0][1], want[1][0], want[1][1])
    got = (tuple(seg.a), tuple(seg.b))
    ref = pymunk.Segment(b, (0.0, 0.0), (1.0, 0.0), 0.0)
    ref.unsafe_set_endpoints(*want)
    if got != want or (tuple(seg.normal) != tuple(ref.normal)):
        return f"cpSegmentShapeSetEndpoints through numba set {got}, not {want}"
    return None


@functools.lru_cache(maxsize=1)
def body_layout() -> str | None:
    """None when a ``cpBody`` holds p, v, f and t where :func:`advance` writes them, else why not.

    Sets them on a probe body through pymunk and reads the struct's first bytes back; once per process
    (no probe body is freed while a run, or a signal handler, is under way)."""
    b = pymunk.Body(1.0, 1.0)
    b.position, b.velocity, b.force, b.torque = (1.25, -2.5), (3.75, 4.0), (5.0, -6.0), -8.25
    a = np.frombuffer(ffi.buffer(b._body, 8 * _BODY_PROBE_DOUBLES), dtype=np.float64)
    want = {BODY_P: 1.25, BODY_P + 1: -2.5, BODY_V: 3.75, BODY_V + 1: 4.0, BODY_F: 5.0, BODY_F + 1: -6.0,
            BODY_T: -8.25}
    if any(a[k] != v for k, v in want.items()):
        return "pymunk's cpBody does not have chipmunk 7's layout"
    return None


def open_step_loop(space, nb, set_fields, set_arr, arb_cap, step_loop=None, joints=(), roller_shapes=(), bodies=(),
                   masks=None, arc_shapes=None):
    """(loop, reason): the compiled loop (:class:`BatchIO`) or the plain one (``PlainLoop``).

    Parameters
    ----------
    space : the run's ``pymunk.Space``.
    nb : number of bodies (rollers and cage).
    set_fields : ``pymunk.batch.BodyFields`` that the set buffer holds per body.
    set_arr : float64 set buffer (``nb`` rows of ``set_fields``).
    arb_cap : arbiters the compiled loop's buffers hold.
    step_loop : "compiled", "plain" or None (compiled unless ``BEARINGSIM_PLAIN_PYMUNK=1`` or the guard fails).
    joints : rigid raceways: the rollers' outer-race joints, in roller order; after each step their
        impulses over ``h`` go into ``StepWork.n_out``.
    roller_shapes : the rollers' circles, in roller order (their elasticity is set between steps when
        ``StepInputs.onset_restitution``).
    bodies : the space's bodies in the order of its batched read (rollers, then the cage): the compiled
        loop writes the set buffer into them directly (:class:`BatchIO`); empty: pymunk's batched setter.
    masks : :class:`bearingsim.multibody.loop.FaceMasks` of the scene: the compiled loop narrows the
        rollers' collision masks (when it writes the bodies directly and :func:`mask_layout` holds);
        None: it does not (the plain loop never does: the same contacts, more narrow-phase tests).
    arc_shapes : exact arc faces: [pocket][face] the segments placed before each step
        (:func:`bearingsim.multibody.loop.arc_faces`; None for a flat pocket's); None: static faces.
    """
    if step_loop not in (None, "compiled", "plain"):
        raise ValueError(f"step_loop = {step_loop!r}: 'compiled', 'plain' or None")
    why_not = guard()
    if step_loop is None:
        if os.environ.get(PLAIN_ENV, "") not in ("", "0"):
            step_loop, reason = "plain", f"{PLAIN_ENV}={os.environ[PLAIN_ENV]}"
        elif why_not is not None:
            step_loop, reason = "plain", why_not
            _announce_plain(why_not)
        elif arc_shapes is not None and endpoints_layout() is not None:
            step_loop, reason = "plain", endpoints_layout()
            _announce_plain(reason)
        else:
            step_loop, reason = "compiled", f"pymunk {pymunk.version}"
    elif step_loop == "compiled":
        if why_not is not None:
            raise RuntimeError(f"the compiled step loop cannot run: {why_not}")
        reason = "asked for"
    else:
        reason = "asked for"
    if step_loop == "plain":
        return lp.PlainLoop(space, nb, set_fields, set_arr, joints, roller_shapes, arc_shapes), reason
    io = BatchIO(space, nb, set_fields, set_arr, arb_cap, joints, roller_shapes, bodies, masks, arc_shapes)
    if io.direct_why is not None:
        reason += f"; bodies set through pymunk's batched setter ({io.direct_why})"
    if io.masks_why is not None:
        reason += f"; face masks not narrowed ({io.masks_why})"
    if joints and io.joints_why is not None:
        reason += f"; every joint left to pymunk ({io.joints_why})"
    return io, reason


class _CFunction(types.WrapperAddressProtocol):
    """A C function pointer that numba code can take as an argument and call (first-class function).

    Passed as an argument (not a global), it keeps the compiled loop cacheable on disk."""

    def __init__(self, address: int, signature):
        self._address = int(address)
        self._signature = signature

    def __wrapper_address__(self):
        return self._address

    def signature(self):
        return self._signature


def _chipmunk(name: str, signature) -> _CFunction:
    return _CFunction(int(ffi.cast("intptr_t", ffi.addressof(lib, name))), signature)


def _address(cdata) -> int:
    return int(ffi.cast("intptr_t", cdata))


# pointers are passed as int64 (same registers as a pointer in the C calling convention)
_STEP_SIG = types.void(types.int64, types.float64)
_EACH_SIG = types.void(types.int64, types.int64, types.int64)
_CLOCK_SIG = types.int32(types.int32, types.int64)
_IMPULSE_SIG = types.float64(types.int64)
_ELASTICITY_SIG = types.void(types.int64, types.float64)
#: cpSegmentShapeSetEndpoints(cpShape *, cpVect a, cpVect b): a cpVect (two doubles) passed by value goes in
#: two floating-point registers on x86-64 (System V) and AArch64, as two double arguments would; checked
#: on a probe segment by :func:`endpoints_layout`
_ENDPOINTS_SIG = types.void(types.int64, types.float64, types.float64, types.float64, types.float64)


def _clock_function():
    """``clock_gettime`` from the C library, or None where there is none (then no pymunk timing)."""
    try:
        fn = ctypes.CDLL(None).clock_gettime
    except (OSError, AttributeError, TypeError):  # pragma: no cover - platforms without clock_gettime
        return None
    return _CFunction(ctypes.cast(fn, ctypes.c_void_p).value, _CLOCK_SIG)


def _float_array(n):
    """A pymunk C float array of capacity n, freed with its Python object."""
    return ffi.gc(lib.pmFloatArrayNew(n), lib.pmFloatArrayFree)


def _int_array(n):
    return ffi.gc(lib.pmIntArrayNew(n), lib.pmIntArrayFree)


class Pointers(NamedTuple):
    """Addresses (int64) that :func:`advance` hands to chipmunk."""

    space: int  #: the cpSpace
    body_get: int  #: pmSpaceBodyGetIteratorFuncBatched
    body_set: int  #: pmSpaceBodySetIteratorFuncBatched
    arbiters: int  #: pmSpaceArbiterIteratorFuncBatched
    data_state0: int  #: pmBatchedData reading into state array 0
    data_state1: int  #: pmBatchedData reading into state array 1
    data_set: int  #: pmBatchedData of the set buffer
    data_arbiters: int  #: pmBatchedData of the arbiter buffers
    timespec: int  #: struct timespec for clock_gettime


class Headers(NamedTuple):
    """int32 (num, max) views of the headers of the C arrays (pymunk appends at ``num``)."""

    state0: np.ndarray
    state1: np.ndarray
    set: np.ndarray
    arb_f: np.ndarray
    arb_i: np.ndarray


class BatchIO:
    """The space's batched C buffers and function pointers, set up once for :func:`advance`.

    ``states``: the two (nb, 6) state arrays (numpy views of C arrays); ``arb_f``/``arb_i``: the
    arbiter buffers (``arb_cap`` arbiters); ``hdr``: :class:`Headers`; ``ptr``: :class:`Pointers`.
    """

    name = "compiled"

    def __init__(self, space, nb, set_fields, set_arr, arb_cap, joints=(), roller_shapes=(), bodies=(), masks=None,
                 arc_shapes=None):
        self.nb = nb
        self._space = space._space
        self.endpoints_fn = _chipmunk("cpSegmentShapeSetEndpoints", _ENDPOINTS_SIG)
        self._arc = [sh for pair in (arc_shapes or ()) for sh in pair if sh is not None]  # must outlive the run
        self.arc_ptrs = np.zeros((len(arc_shapes or ()), 2), dtype=np.int64)  # 0: a flat pocket's (never placed)
        for i, pair in enumerate(arc_shapes or ()):
            for f, sh in enumerate(pair):
                if sh is not None:
                    self.arc_ptrs[i, f] = _address(sh._shape)
        self.impulse_fn = _chipmunk("cpConstraintGetImpulse", _IMPULSE_SIG)
        self.elasticity_fn = _chipmunk("cpShapeSetElasticity", _ELASTICITY_SIG)
        self._joints = list(joints)  # the C objects must outlive the run
        self._shapes = list(roller_shapes)
        self.joint_ptrs = np.array([_address(j._constraint) for j in self._joints], dtype=np.int64)
        self.shape_ptrs = np.array([_address(c._shape) for c in self._shapes], dtype=np.int64)
        self.step_fn = _chipmunk("cpSpaceStep", _STEP_SIG)
        self.each_body_fn = _chipmunk("cpSpaceEachBody", _EACH_SIG)
        self.each_arb_fn = _chipmunk("cpSpaceEachCachedArbiter", _EACH_SIG)
        clock = _clock_function()
        self.timed = clock is not None
        self.clock_fn = clock if clock is not None else self.each_body_fn  # never called when untimed
        self.ts = np.zeros(2, dtype=np.int64)  # struct timespec
        ia = _int_array(nb)
        self._keep = [ia]  # the C objects must outlive the run
        self.states, data, arrays = [], [], []
        for _ in range(2):  # two state arrays, alternating
            fa = _float_array(2 * nb * 6 + 16)  # headroom: a push never reallocates
            d = ffi.new("pmBatchedData *")
            d.fields = lp.BODY_GET.value
            d.floatArray = fa
            d.intArray = ia
            self.states.append(np.frombuffer(ffi.buffer(fa.arr, 8 * nb * 6), dtype=np.float64).reshape(nb, 6))
            data.append(d)
            arrays.append(fa)
        self.set_buf = pb.Buffer()
        self.set_buf.set_float_buf(set_arr)
        sd = ffi.new("pmBatchedData *")
        sd.fields = set_fields.value
        sd.floatArray = self.set_buf._float_arr
        sd.intArray = self.set_buf._int_arr
        afa = _float_array(rk.ARB_F * arb_cap)
        aia = _int_array(rk.ARB_I * arb_cap)
        ad = ffi.new("pmBatchedData *")
        ad.fields = lp.ARB_GET.value
        ad.floatArray = afa
        ad.intArray = aia
        arrays += [self.set_buf._float_arr, afa, aia]
        self._data = data
        self._keep += data + arrays + [sd, ad]
        self.arb_f = np.frombuffer(ffi.buffer(afa.arr, 8 * afa.max), dtype=np.float64)
        self.arb_i = np.frombuffer(ffi.buffer(aia.arr, 8 * aia.max), dtype=np.uint64)
        self.hdr = Headers(*[np.frombuffer(ffi.buffer(a, 8), dtype=np.int32) for a in arrays])
        self.ptr = Pointers(
            _address(space._space),
            _address(ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched")),
            _address(ffi.addressof(lib, "pmSpaceBodySetIteratorFuncBatched")),
            _address(ffi.addressof(lib, "pmSpaceArbiterIteratorFuncBatched")),
            _address(data[0]), _address(data[1]), _address(sd), _address(ad),
            self.ts.ctypes.data,
        )
        self.set_pv = set_fields == lp.BODY_SET_ALL  # positions and velocities set too
        self.body_ptrs, self.direct_why = self._direct_bodies(bodies, set_fields)
        self.fm, self.masks_why = self._face_masks(masks)
        self.mask_now = np.array([c.filter.mask for c in self._shapes], dtype=np.uint32)  # as the shapes have them
        self.mask_want = self.mask_now.copy()
        self.vb = np.zeros((nb, 3))  # the bodies' bias velocities before a step
        self.iterations = int(space.iterations)
        self.joints_why = self._free_joints()
        self.free_on = self.joints_why is None
        self.joint_max = float(self._joints[0].max) if self._joints else 0.0  # their length, r_c
        self.jn_acc = np.zeros(len(self._joints))  # accumulated impulse of the joints advance() solves itself
        self.free_now = np.zeros(len(self._joints), dtype=np.bool_)  # those joints (left slack in pymunk)
        self.prev_h = np.zeros(1)  # the last cpSpaceStep's step (chipmunk scales the cached impulses by h / it)

    def _free_joints(self):
        """None when :func:`advance` solves the joints of rollers that touch nothing itself, else why not."""
        if not self._joints:
            return "no joints"
        if not self.fm.active:
            return "face masks not narrowed"
        if any(j.min != 0.0 or j.max != self._joints[0].max or j.error_bias != 0.0 or j.anchor_a != (0.0, 0.0)
               or j.anchor_b != (0.0, 0.0) or j.a.body_type != pymunk.Body.STATIC for j in self._joints):
            return "the joints are not the rigid raceways' (static anchor at the axis, 0 to r_c, error_bias 0)"
        return joint_layout()

    def _face_masks(self, masks):
        """(masks, None) when :func:`advance` narrows the rollers' masks, else (inactive masks, why not)."""
        off = lp.FaceMasks(False, np.zeros((0, 0, 5)), np.zeros((0, 0), dtype=np.uint32), np.zeros((0, 2)), -1.0, 0.0)
        if masks is None or not masks.active:
            return off, "the scene's face segments share one category"
        if self.body_ptrs.shape[0] == 0:
            return off, "bodies not written directly"
        if len(self._shapes) != masks.bits.shape[0]:
            return off, "no roller shapes given"
        why = mask_layout()
        if why is not None:
            return off, why
        return masks, None

    def _direct_bodies(self, bodies, set_fields):
        """(body addresses, None) when :func:`advance` can write the step's states and forces into the
        bodies directly, else (empty, why not): :func:`body_layout` holds, the set fields are p, v, f, t
        or f, t, and ``bodies`` are in the order of the batched read (checked on their p and v)."""
        none = np.zeros(0, dtype=np.int64)
        if set_fields not in (lp.BODY_SET_ALL, lp.BODY_SET_FORCE):
            return none, f"set fields {set_fields!r}"
        if len(bodies) != self.nb:
            return none, "no bodies given"
        why = body_layout()
        if why is not None:
            return none, why
        ptrs = np.array([_address(b._body) for b in bodies], dtype=np.int64)
        st = self.read_states()
        for k, b in enumerate(bodies):
            a = np.frombuffer(ffi.buffer(b._body, 8 * _BODY_PROBE_DOUBLES), dtype=np.float64)
            if not (np.array_equal(a[BODY_P:BODY_P + 2], st[k, 0:2]) and np.array_equal(a[BODY_V:BODY_V + 2], st[k, 3:5])):
                return none, "the bodies are not in the order of the batched read"
        return ptrs, None

    def read_states(self):
        """Fill state array 0 from the space (before the first step)."""
        cap = int(self.hdr.state0[1])
        self.hdr.state0[0] = 0
        lib.cpSpaceEachBody(self._space, ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched"), self._data[0])
        if self.hdr.state0[1] != cap or self.hdr.state0[0] != 6 * self.nb:
            raise RuntimeError("multibody step loop: pymunk's batched body read did not fit its buffer")
        return self.states[0]

    def advance(self, inp, wk, acc, ls):
        """Run :func:`advance` until it returns a code."""
        return advance(self.step_fn, self.each_body_fn, self.each_arb_fn, self.clock_fn, self.impulse_fn,
                       self.elasticity_fn, self.endpoints_fn, self.arc_ptrs, self.timed, self.ptr, self.joint_ptrs, self.shape_ptrs, self.body_ptrs,
                       self.set_pv, self.hdr, self.states[0], self.states[1], self.arb_f, self.arb_i, self.ts,
                       self.fm, self.vb, self.mask_now, self.mask_want, self.free_on, self.jn_acc, self.free_now,
                       self.prev_h, self.iterations, self.joint_max, inp, wk, acc, ls)


@njit(cache=True)
def _now_ns(clock, ptr_ts, ts):
    clock(np.int32(CLOCK_MONOTONIC), ptr_ts)
    return ts[0] * 1_000_000_000 + ts[1]


def _pointer_cast(item):
    """An intrinsic that turns an int64 address into an ``item *`` (for :func:`numba.carray`)."""

    @intrinsic
    def cast(typingctx, address):
        sig = types.CPointer(item)(types.int64)

        def codegen(context, builder, signature, args):
            return builder.inttoptr(args[0], context.get_value_type(types.CPointer(item)))

        return sig, codegen

    return cast


_as_float_ptr = _pointer_cast(types.float64)
_as_u32_ptr = _pointer_cast(types.uint32)


@njit(cache=True, inline="always")
def _narrow_masks(body_ptrs, shape_ptrs, state, h, fm, arc_ends, vb, now, want):
    """Read the bodies' bias velocities, compute the rollers' masks for the coming step
    (:func:`bearingsim.multibody.loop.face_masks`; ``arc_ends``: the exact faces' segments as placed for
    the step) and write those that changed into their ``cpShape``."""
    for k in range(body_ptrs.shape[0]):
        b = carray(_as_float_ptr(body_ptrs[k]), BODY_WBIAS + 1)
        vb[k, 0] = b[BODY_VBIAS]
        vb[k, 1] = b[BODY_VBIAS + 1]
        vb[k, 2] = b[BODY_WBIAS]
    lp.face_masks(state, vb, h, fm, arc_ends, want)
    for i in range(shape_ptrs.shape[0]):
        if want[i] != now[i]:
            carray(_as_u32_ptr(shape_ptrs[i]), SHAPE_MASK + 1)[SHAPE_MASK] = want[i]
            now[i] = want[i]


#: the length a joint that :func:`advance` solves itself is given in pymunk for the step (slack there)
FREE_JOINT_MAX = 1.0e300


@njit(cache=True, inline="always")
def _hand_over_joints(joint_ptrs, mask, jn_acc, free_now, r_max):
    """Before a step: a roller whose mask is empty touches nothing in the step, so its joint's solve has
    no other constraint in it; the joint is made slack in pymunk (length ``FREE_JOINT_MAX``) and its
    accumulated impulse kept in ``jn_acc``; a roller that may touch a face gets its joint back, length
    ``r_max`` and accumulated impulse restored (chipmunk's warm start)."""
    for k in range(joint_ptrs.shape[0]):
        fr = mask[k] == 0
        if fr != free_now[k]:
            c = carray(_as_float_ptr(joint_ptrs[k]), SLIDE_JNACC + 1)
            if fr:
                jn_acc[k] = c[SLIDE_JNACC]
                c[SLIDE_MAX] = FREE_JOINT_MAX
            else:
                c[SLIDE_JNACC] = jn_acc[k]
                c[SLIDE_MAX] = r_max
            free_now[k] = fr


@njit(cache=True, inline="always")
def _solve_free_joints(body_ptrs, state, h, dt_coef, jn_acc, free_now, r_max, iterations):
    """After a step: the joints :func:`_hand_over_joints` took out, solved on the bodies' states after
    the step (position after the position update, velocity after the velocity update: nothing else
    acted on them) by :func:`joint_solve`; their velocities and accumulated impulses updated."""
    for k in range(free_now.shape[0]):
        if free_now[k]:
            m_inv = carray(_as_float_ptr(body_ptrs[k]), BODY_MINV + 1)[BODY_MINV]
            vx, vy, jn = joint_solve(state[k, 0], state[k, 1], state[k, 3], state[k, 4], m_inv, r_max, h, dt_coef,
                                     jn_acc[k], iterations)
            state[k, 3] = vx
            state[k, 4] = vy
            jn_acc[k] = jn


@njit(cache=True, inline="always")
def _write_bodies(body_ptrs, state, out_f, set_pv):
    """Write each body's force and torque (``out_f`` rows of (fx, fy, t)) and, when ``set_pv``, its
    position and velocity (``state`` rows of (x, y, angle, vx, vy, omega)) into its ``cpBody``.

    What pymunk's batched setter does through ``cpBodySetPosition`` and the others, without their
    calls or a packed buffer: the step's position update recomputes each body's transform from p
    before anything reads it, and nothing in the space sleeps."""
    for k in range(body_ptrs.shape[0]):
        b = carray(_as_float_ptr(body_ptrs[k]), _BODY_PROBE_DOUBLES)
        if set_pv:
            b[BODY_P] = state[k, 0]
            b[BODY_P + 1] = state[k, 1]
            b[BODY_V] = state[k, 3]
            b[BODY_V + 1] = state[k, 4]
        b[BODY_F] = out_f[3 * k]
        b[BODY_F + 1] = out_f[3 * k + 1]
        b[BODY_T] = out_f[3 * k + 2]


@njit(cache=True)
def advance(step_fn, each_body_fn, each_arb_fn, clock_fn, impulse_fn, elasticity_fn, endpoints_fn, arc_ptrs, timed, ptr,
            joint_ptrs, shape_ptrs,
            body_ptrs, set_pv, hdr, st0, st1, arb_f, arb_i, ts, fm, vb, mask_now, mask_want, free_on, jn_acc, free_now,
            prev_h, iterations, joint_max, inp, wk, acc, ls):
    """Step until :func:`~bearingsim.multibody.loop.before_step` or ``after_step`` report a code, or
    ``inp.lim.chunk_steps`` steps have passed; return the ``CODE_*``.

    ``hdr`` (:class:`Headers`): the loop resets ``num`` before each batched call and stops if pymunk
    ever grew an array (``max`` changed), which the sizes chosen in :class:`BatchIO` rule out.
    ``joint_ptrs``: the rigid raceways' joints (``cpConstraint *``), whose impulses over ``h`` are the
    outer-race forces written into ``wk.n_out`` after each step (empty with Hertz contacts);
    ``shape_ptrs``: the rollers' circles (``cpShape *``), whose elasticity is set for the next step when
    ``inp.onset_restitution`` (:func:`~bearingsim.multibody.loop.onset_elasticity`). ``body_ptrs``:
    the bodies (``cpBody *``, state order) that :func:`_write_bodies` writes, or empty for pymunk's
    batched setter; ``set_pv``: their positions and velocities are set too, not only their forces.
    ``fm``: :class:`~bearingsim.multibody.loop.FaceMasks`; when active, the rollers' masks are narrowed
    before each step (:func:`_narrow_masks`; ``vb``, ``mask_now``, ``mask_want``: its scratch and the
    masks the shapes have). ``free_on``: the joint of a roller whose mask is empty (it touches nothing in
    the step) is left slack in pymunk and solved here after the step by :func:`joint_solve`, the same
    bytes as chipmunk's (``jn_acc``, ``free_now``: those joints' accumulated impulses and which they
    are; ``prev_h``: the last step size; ``iterations``: the space's; ``joint_max``: the joints' length).
    ``endpoints_fn``, ``arc_ptrs``: exact arc faces (``inp.arc.active``): each pocket's (front, rear) segment
    (``cpShape *``) placed before each step where :func:`~bearingsim.multibody.loop.arc_faces` says (before the masks are
    narrowed, which test the segments where they are placed).
    ``inp``, ``wk``, ``acc``, ``ls``: those of the step kernels.
    """
    sp = ptr.space
    cap0 = hdr.state0[1]
    cap1 = hdr.state1[1]
    capf = hdr.arb_f[1]
    capi = hdr.arb_i[1]
    s = ls[0]
    step_return = s.step + inp.lim.chunk_steps
    h = inp.h
    while True:
        cur = s.cur
        prev = st0 if cur == 0 else st1
        code = lp.before_step(prev, inp, wk, ls)
        if code != lp.CODE_CONTINUE:
            return code
        if inp.arc.active:  # the exact faces first: the narrowed masks test the segments where they are placed
            lp.arc_faces(prev, h, inp.arc, wk.arc_ends, wk.arc_todo)
            for i in range(arc_ptrs.shape[0]):
                for f in range(2):
                    if wk.arc_todo[i, f]:
                        e = wk.arc_ends[i, f]
                        endpoints_fn(arc_ptrs[i, f], e[0], e[1], e[2], e[3])
        if body_ptrs.shape[0]:
            _write_bodies(body_ptrs, prev, wk.out_f, set_pv)
            if fm.active:
                _narrow_masks(body_ptrs, shape_ptrs, prev, h, fm, wk.arc_ends, vb, mask_now, mask_want)
            if free_on:
                _hand_over_joints(joint_ptrs, mask_want, jn_acc, free_now, joint_max)
        else:
            if set_pv:
                lp.pack_all(prev, wk.out_f, wk.set_arr, prev.shape[0])
            hdr.set[0] = 0  # the setter reads the buffer from the start
            each_body_fn(sp, ptr.body_set, ptr.data_set)
        if timed:
            t0 = _now_ns(clock_fn, ptr.timespec, ts)
            step_fn(sp, h)
            s.pymunk_ns += _now_ns(clock_fn, ptr.timespec, ts) - t0
        else:
            step_fn(sp, h)
        if cur == 0:  # the state after the step goes into the other array
            hdr.state1[0] = 0
            each_body_fn(sp, ptr.body_get, ptr.data_state1)
        else:
            hdr.state0[0] = 0
            each_body_fn(sp, ptr.body_get, ptr.data_state0)
        if free_on:  # the joints pymunk left slack: their solve, on the velocities after the step
            _solve_free_joints(body_ptrs, st1 if cur == 0 else st0, h, 0.0 if prev_h[0] == 0.0 else h / prev_h[0],
                               jn_acc, free_now, joint_max, iterations)
        prev_h[0] = h
        for k in range(joint_ptrs.shape[0]):  # the race's force: the joint's and race_orbit's
            jn = abs(jn_acc[k]) if free_on and free_now[k] else impulse_fn(joint_ptrs[k])
            wk.n_out[k] = jn / h + wk.n_extra[k]
        hdr.arb_f[0] = 0
        hdr.arb_i[0] = 0
        each_arb_fn(sp, ptr.arbiters, ptr.data_arbiters)
        if hdr.state0[1] != cap0 or hdr.state1[1] != cap1 or hdr.arb_f[1] != capf or hdr.arb_i[1] != capi:
            return lp.CODE_BUFFER_GREW
        code = lp.after_step(st0, st1, arb_f, arb_i, hdr.arb_i[0] // rk.ARB_I, inp, wk, acc, ls)
        if code != lp.CODE_CONTINUE:
            return code
        if inp.onset_restitution:  # rigid raceways: elasticity of the roller shapes for the next step
            lp.onset_elasticity(arb_i, hdr.arb_i[0] // rk.ARB_I, inp, wk)
            for i in range(shape_ptrs.shape[0]):
                if wk.e_want[i] != wk.e_set[i]:
                    elasticity_fn(shape_ptrs[i], wk.e_want[i])
                    wk.e_set[i] = wk.e_want[i]
        if s.step >= step_return:
            return lp.CODE_BLOCK_FULL


drop_stale_caches(__name__, (fk, rk, lp, _reduced_core, laws, compiled_laws))  # advance() compiles in the step kernels
