"""The compiled step loop of the multi-pocket model: pymunk's C functions called from numba.

The per-step work of :func:`bearingsim.multibody.core.run` is one numba function, :func:`advance`,
that calls chipmunk (pymunk's C library) directly through its function pointers, so no Python runs
between steps:

1. read the state of every body (pymunk's batched body iterator, into a fixed C array viewed by numpy;
   two arrays alternate so the state before and after a step are both at hand);
2. (reduced-equivalent scene) rollers inside the load zone are put at the front of their pockets;
3. raceway forces (:func:`bearingsim.multibody.forces.raceway_forces`) written into the batched
   set buffer, and handed to the bodies by pymunk's batched setter;
4. ``cpSpaceStep(h)``, timed on its own with ``clock_gettime(CLOCK_MONOTONIC)`` (that is the
   ``pymunk_step_s`` of a result);
5. the arbiters read by pymunk's batched arbiter iterator and attributed to pockets, faces and
   rotations (:func:`bearingsim.multibody.recorder.record_step`);
6. every ``out_every`` steps: a time-series sample into a fixed block, and the run's health checks.

:func:`advance` returns to Python with a code (``CODE_*``) when the run is done, when the sample block
is full or ``CHUNK_STEPS`` steps have passed (Python flushes the samples to the archive, moves the
progress bar and sees Ctrl-C), or when a check failed (Python raises the matching error). Loop state that lives across calls is kept in two small arrays
(``lsi`` integers, ``lsf`` floats; ``LI_*`` and ``LF_*`` name their slots).

Nothing in the scene is added or removed during a run and there are no collision callbacks, so
calling ``cpSpaceStep`` directly (without pymunk's Python wrapper around the step) is what
``Space.step`` does for this space. The C arrays are sized so that pymunk never has to grow them;
if it ever did, :func:`advance` stops with ``CODE_BUFFER_GREW`` rather than read a stale pointer.
"""
from __future__ import annotations

import ctypes
import math

import numba.experimental.function_type  # noqa: F401  (registers typeof for WrapperAddressProtocol)
import numpy as np
import pymunk.batch as pb
from numba import njit, types
from pymunk._chipmunk_cffi import ffi, lib

from bearingsim._jit import drop_stale_caches
from bearingsim.multibody import forces as fk
from bearingsim.multibody import recorder as rk

BODY_GET = (pb.BodyFields.POSITION | pb.BodyFields.ANGLE | pb.BodyFields.VELOCITY
            | pb.BodyFields.ANGULAR_VELOCITY)
BODY_SET_FORCE = pb.BodyFields.FORCE | pb.BodyFields.TORQUE
BODY_SET_ALL = (pb.BodyFields.POSITION | pb.BodyFields.VELOCITY | pb.BodyFields.FORCE
                | pb.BodyFields.TORQUE)
ARB_GET = (pb.ArbiterFields.BODY_A_ID | pb.ArbiterFields.BODY_B_ID | pb.ArbiterFields.CONTACT_COUNT
           | pb.ArbiterFields.TOTAL_IMPULSE | pb.ArbiterFields.NORMAL | pb.ArbiterFields.POINT_A_1
           | pb.ArbiterFields.POINT_B_1 | pb.ArbiterFields.DISTANCE_1)

# return codes of advance()
CODE_DONE, CODE_BLOCK_FULL, CODE_NONFINITE, CODE_PENETRATION, CODE_BLOWUP, CODE_STALLED = range(6)
CODE_BUFFER_GREW, CODE_CAGE_LOST = 6, 7
# integer loop state
LI_STEP, LI_CUR, LI_NIMP, LI_NSMP, LI_NORBIT, LI_REC, LI_NEWTON_FAIL, LI_OUT_EVERY, LI_MAX_STEPS = range(9)
N_LI = 9
# float loop state
LF_T, LF_PYMUNK_NS, LF_RING_SX, LF_RING_SY, LF_RING_N, LF_W_START, LF_T_REC0, LF_ORBIT_MAX = range(8)
N_LF = 8
# limits
LIM_TRAVEL_END, LIM_TRAVEL_REC, LIM_PEN, LIM_DELTA, LIM_OMEGA, LIM_OMEGA_NOM, LIM_ORBIT = range(7)
N_LIM = 7
# sample columns: t, cage speed along the rotation, slip, cage x, cage y, ring x, ring y
S_T, S_W, S_SLIP, S_CX, S_CY, S_RX, S_RY = range(7)
N_SCOL = 7
CHUNK_STEPS = 20_000  # return to Python at least this often (progress bar, Ctrl-C: ~0.3 s)
DELTA_LIMIT_M = 50e-6  # a raceway approach beyond this is an energy blow-up
CLOCK_MONOTONIC = 1  # Linux and macOS


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


class BatchIO:
    """The space's batched C buffers and function pointers, set up once for :func:`advance`.

    ``states``: the two (nb, 6) state arrays (numpy views of C arrays); ``arb_f``/``arb_i``: the
    arbiter buffers (``arb_cap`` arbiters); ``hdr``: int32 views of the (num, max) header of the C
    arrays: state 0, state 1, set buffer, arbiter floats, arbiter ints; ``ptr``: addresses of the
    space, the three batched iterator functions, their four data blocks and the timespec buffer.
    """

    def __init__(self, space, nb, set_fields, set_arr, arb_cap):
        self.nb = nb
        self._space = space._space
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
            d.fields = BODY_GET.value
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
        ad.fields = ARB_GET.value
        ad.floatArray = afa
        ad.intArray = aia
        arrays += [self.set_buf._float_arr, afa, aia]
        self._data = data
        self._keep += data + arrays + [sd, ad]
        self.arb_f = np.frombuffer(ffi.buffer(afa.arr, 8 * afa.max), dtype=np.float64)
        self.arb_i = np.frombuffer(ffi.buffer(aia.arr, 8 * aia.max), dtype=np.uint64)
        assert ffi.offsetof("pmFloatArray", "num") == 0 and ffi.offsetof("pmFloatArray", "max") == 4
        self.hdr = [np.frombuffer(ffi.buffer(a, 8), dtype=np.int32) for a in arrays]
        self.ptr = np.array([
            _address(space._space),
            _address(ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched")),
            _address(ffi.addressof(lib, "pmSpaceBodySetIteratorFuncBatched")),
            _address(ffi.addressof(lib, "pmSpaceArbiterIteratorFuncBatched")),
            _address(data[0]), _address(data[1]), _address(sd), _address(ad),
            self.ts.ctypes.data,
        ], dtype=np.int64)

    def read_states(self):
        """Fill state array 0 from the space (before the first step)."""
        cap = int(self.hdr[0][1])
        self.hdr[0][0] = 0
        lib.cpSpaceEachBody(self._space, ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched"), self._data[0])
        if self.hdr[0][1] != cap or self.hdr[0][0] != 6 * self.nb:
            raise RuntimeError("multibody step loop: pymunk's batched body read did not fit its buffer")
        return self.states[0]


@njit(cache=True)
def _hold_rollers(state, n, sign, phi, pocket_a, hold, radius, front_off, omega_cage):
    """Reduced-equivalent: rollers in the load zone ride at the front of their pockets with the cage."""
    phic = state[n, 2]
    for i in range(n):
        th = rk.pocket_theta(sign, phic, pocket_a[i])
        inside = th < phi or th > 2.0 * math.pi - phi
        hold[i] = inside
        if inside:
            a = phic + pocket_a[i]
            ca = math.cos(a)
            sa = math.sin(a)
            # pocket centre on the pitch circle; roller on the outer race, shifted by s/2 along e_t
            etx = -sign * sa
            ety = sign * ca
            px = radius * ca + front_off * etx
            py = radius * sa + front_off * ety
            # velocity of that point of the (kinematic) cage
            state[i, 0] = px
            state[i, 1] = py
            state[i, 3] = -omega_cage * py
            state[i, 4] = omega_cage * px


@njit(cache=True)
def _pack_all(state, out_f, set_arr, nb):
    a = set_arr.reshape(nb, 7)
    a[:, 0:2] = state[:, 0:2]
    a[:, 2:4] = state[:, 3:5]
    f = out_f.reshape(nb, 3)
    a[:, 4:7] = f


@njit(cache=True)
def _now_ns(clock, ptr_ts, ts):
    clock(np.int32(CLOCK_MONOTONIC), ptr_ts)
    return ts[0] * 1_000_000_000 + ts[1]


@njit(cache=True)
def advance(step_fn, each_body_fn, each_arb_fn, clock_fn, timed, ptr, hv0, hv1, hvs, hva, hvi, st0, st1, arb_f,
            arb_i, ts, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, set_arr, diag, reduced_eq, phi, pocket_a,
            hold_radius, front_off, omega_cage, ids_sorted, ids_index, cfg, theta0, win, first_imp, f_bin, t_bin,
            q_bin, tq_bin, j_int, glob, impacts, lim, lsi, lsf, smp_step, smp, orbit):
    """Advance the run until it is done, the sample block is full, or a check fails; return a CODE_*.

    ``hv0, hv1, hvs, hva, hvi`` are the int32 (num, max) headers of the C arrays (:class:`BatchIO`);
    the loop resets ``num`` before each batched call and stops if pymunk ever grew an array (``max``
    changed), which the sizes chosen in :class:`BatchIO` rule out. The other arguments are those of
    :func:`bearingsim.multibody.forces.raceway_forces` and
    :func:`bearingsim.multibody.recorder.record_step`, the limits ``lim`` (``LIM_*``), the loop state
    ``lsi``/``lsf`` and the sample block ``smp_step``/``smp`` (``S_*``) and orbit ring buffer.
    """
    sp = ptr[0]
    n = int(cfg[rk.C_N])
    nb = n + 1
    sign = cfg[rk.C_SIGN]
    cap0 = hv0[1]
    cap1 = hv1[1]
    capf = hva[1]
    capi = hvi[1]
    out_every = lsi[LI_OUT_EVERY]
    step = lsi[LI_STEP]
    cur = lsi[LI_CUR]
    n_imp = lsi[LI_NIMP]
    t = lsf[LF_T]
    step_return = step + CHUNK_STEPS
    code = CODE_DONE
    while True:
        prev = st0 if cur == 0 else st1
        travel = sign * prev[n, 2]
        if travel >= lim[LIM_TRAVEL_END]:
            code = CODE_DONE
            break
        if step > lsi[LI_MAX_STEPS]:
            code = CODE_STALLED
            break
        if lsi[LI_REC] == 0 and travel >= lim[LIM_TRAVEL_REC]:
            lsi[LI_REC] = 1
            lsf[LF_W_START] = prev[n, 5]
            lsf[LF_T_REC0] = t
        if reduced_eq:
            _hold_rollers(prev, n, sign, phi, pocket_a, hold, hold_radius, front_off, omega_cage)
        if fk.raceway_forces(prev, h, prm, ring_c, ring_c_prev, ring_v, hold, out_f, diag) < 0:
            lsi[LI_NEWTON_FAIL] += 1
        if lsi[LI_REC] == 1:
            lsf[LF_RING_SX] += ring_c[0]
            lsf[LF_RING_SY] += ring_c[1]
            lsf[LF_RING_N] += 1.0
        if reduced_eq:
            _pack_all(prev, out_f, set_arr, nb)
        hvs[0] = 0  # the setter reads the buffer from the start
        each_body_fn(sp, ptr[2], ptr[6])
        if timed:
            t0 = _now_ns(clock_fn, ptr[8], ts)
            step_fn(sp, h)
            lsf[LF_PYMUNK_NS] += _now_ns(clock_fn, ptr[8], ts) - t0
        else:
            step_fn(sp, h)
        t += h
        step += 1
        cur ^= 1
        if cur == 0:
            hv0[0] = 0
            each_body_fn(sp, ptr[1], ptr[4])
            now = st0
        else:
            hv1[0] = 0
            each_body_fn(sp, ptr[1], ptr[5])
            now = st1
        hva[0] = 0
        hvi[0] = 0
        each_arb_fn(sp, ptr[3], ptr[7])
        if hv0[1] != cap0 or hv1[1] != cap1 or hva[1] != capf or hvi[1] != capi:
            code = CODE_BUFFER_GREW
            break
        n_arb = hvi[0] // rk.ARB_I
        n_imp = rk.record_step(arb_f, arb_i, n_arb, ids_sorted, ids_index, prev, now, t, h, cfg, pocket_a, theta0,
                               diag, win, first_imp, f_bin, t_bin, q_bin, tq_bin, j_int, glob, impacts, n_imp)
        if step % out_every == 0:
            ok = True
            for i in range(nb):
                for j in range(6):
                    if not math.isfinite(now[i, j]):
                        ok = False
            if not ok:
                code = CODE_NONFINITE
                break
            if glob[rk.G_MAXPEN_ALL] > lim[LIM_PEN]:
                code = CODE_PENETRATION
                break
            dmax = 0.0
            for i in range(n):
                dmax = max(dmax, diag[i, fk.D_DELTA_OUT])
            if dmax > DELTA_LIMIT_M or abs(now[n, 5]) > lim[LIM_OMEGA]:
                code = CODE_BLOWUP
                break
            if math.hypot(now[n, 0], now[n, 1]) > lim[LIM_ORBIT]:
                code = CODE_CAGE_LOST
                break
            wc = sign * now[n, 5]
            if lsi[LI_REC] == 1:
                k = lsi[LI_NORBIT] % orbit.shape[0]
                orbit[k, 0] = t
                orbit[k, 1] = now[n, 0]
                orbit[k, 2] = now[n, 1]
                lsi[LI_NORBIT] += 1
                lsf[LF_ORBIT_MAX] = max(lsf[LF_ORBIT_MAX], math.hypot(now[n, 0], now[n, 1]))
            k = lsi[LI_NSMP]
            smp_step[k] = step
            smp[k, S_T] = t
            smp[k, S_W] = wc
            smp[k, S_SLIP] = 1.0 - wc / lim[LIM_OMEGA_NOM]
            smp[k, S_CX] = now[n, 0]
            smp[k, S_CY] = now[n, 1]
            smp[k, S_RX] = ring_c[0]
            smp[k, S_RY] = ring_c[1]
            lsi[LI_NSMP] = k + 1
            if k + 1 == smp.shape[0]:
                code = CODE_BLOCK_FULL
                break
        if step >= step_return:
            code = CODE_BLOCK_FULL
            break
    lsi[LI_STEP] = step
    lsi[LI_CUR] = cur
    lsi[LI_NIMP] = n_imp
    lsf[LF_T] = t
    return code


drop_stale_caches(__name__, (fk, rk))  # advance() compiles the force and recording kernels in
