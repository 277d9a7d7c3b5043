"""Where cases run: a local process pool, or an existing dask.distributed cluster.

Both take batches of ``(hash, resolved TOML)`` pairs and yield each batch's records as it finishes
(:func:`bearingsim.sweeps.worker.run_batch`); ``stop()`` cancels what has not started. The local pool
also ends its worker processes at once (they never outlive the sweep: they are terminated on
interruption, and on Linux the kernel kills them if the sweep process itself dies).
"""
from __future__ import annotations

import contextlib
import os
import signal
import sys
import time
from collections.abc import Iterator

from bearingsim.errors import UserError
from bearingsim.sweeps import worker as _worker

#: how long LocalEngine.stop waits for the workers to exit before it ends them directly [s]: a worker
#: exits within milliseconds of its SIGTERM, unless the signal's handler cannot run (a worker inside a
#: long call into compiled code, numba compiling a kernel on a cold cache) or its exception was swallowed
#: where it landed; a worker killed then leaves at most a temporary file, which the sweep removes
STOP_WAIT_S = 3.0


#: the signals a sweep process acts on; blocked while it forks workers, until they have their own handlers
_STOP_SIGNALS = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}


def _exit_worker(signum, frame):
    if _worker.warming:  # nothing of the sweep's held: end now, nothing unwound (worker.warming)
        os._exit(128 + signum)
    _worker.ending = True  # a worker's: SIGTERM came, the worker is ending
    raise _worker.WorkerStop(128 + signum)


def _stop_again(unraisable, previous=sys.unraisablehook) -> None:
    """A worker's ``sys.unraisablehook``: a SIGTERM whose exception Python could not raise (its handler ran
    inside a weakref callback, say) is set pending again 20 ms later, from a helper thread, when the worker
    has left the callback. Once a worker is ending, what its objects say as they go is dropped (the stop's
    exception, raised wherever the worker was, can leave an object half made: llvmlite's ``OutputString``
    then failed in ``__del__`` with a traceback on the sweep's stderr); before, it goes on to ``previous``."""
    if not isinstance(unraisable.exc_value, _worker.WorkerStop):
        if not _worker.ending:
            previous(unraisable)
        return
    import _thread
    import threading

    threading.Timer(0.02, _thread.interrupt_main, (signal.SIGTERM,)).start()


def _pool_worker_init() -> None:
    # Ctrl-C reaches the whole process group: only the sweep process acts on it and then ends the
    # pool, so a worker must not die half-way through writing on its own
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)  # so does a terminal's hang-up
    # SIGTERM (the pool's terminate, or a batch system's to the process group) ends a worker by an
    # exception, not at once: an idle worker waits for its next task holding the pool's task queue lock,
    # and a worker killed holding it left the lock taken, so the pool could not be ended (the sweep waited
    # STOP_WAIT_S, then killed) and a worker the pool started in its place waited for it for ever
    signal.signal(signal.SIGTERM, _exit_worker)
    sys.unraisablehook = _stop_again
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _STOP_SIGNALS)  # blocked by the sweep process while it forked
    # Linux: end with the parent even if it is killed with SIGKILL. The signal is SIGTERM, whose handler ends
    # the worker cleanly: the kernel sends it when the *thread* that forked the worker ends, and a worker the
    # pool started in place of a dead one was forked by the pool's maintenance thread, which ends when the
    # pool is terminated; SIGKILL then killed it while it waited for a task holding the task queue's lock,
    # and terminate waited on that lock (STOP_WAIT_S)
    try:
        import ctypes

        ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)  # PR_SET_PDEATHSIG
        if os.getppid() == 1:
            os._exit(0)
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass


def _failed(batch, error: str) -> list[dict]:
    """The records of a batch none of whose cases came back: each failed with ``error``."""
    return [{"hash": h, "status": "failed", "error": error, "wall_s": float("nan"), "summary": {}} for h, *_ in batch]


def _recording_pool(context, processes: int, procs: list):
    """A process pool of ``context`` whose worker processes, each one it starts (in place of a dead one
    too), are appended to ``procs``."""
    from multiprocessing.pool import Pool

    class RecordingPool(Pool):
        @staticmethod
        def Process(ctx, *args, **kwds):  # noqa: N802 - multiprocessing's name
            proc = ctx.Process(*args, **kwds)
            procs.append(proc)
            return proc

    return RecordingPool(processes, initializer=_pool_worker_init, context=context)


def _run_marked(started_fd: int, token: int, batch, cases_dir, archives):
    """A pool worker's task: say on the engine's pipe which batch (``token``) this process (its pid) has
    started, then run it. A 16-byte write to a pipe is atomic (POSIX: below PIPE_BUF), so no lock is held
    that a worker killed here could leave taken."""
    import struct

    os.write(started_fd, struct.pack("qq", token, os.getpid()))
    return _worker.run_batch(batch, cases_dir, archives)


class LocalEngine:
    """A pool of ``jobs`` worker processes on this machine; archives are written in place.

    Parameters
    ----------
    jobs : int
        Number of worker processes (at least 1).
    """

    should_stop = staticmethod(lambda: False)  # set by run_sweep: a signal arrived

    kind = "local"
    shared_fs = True

    def __init__(self, jobs: int = 1):
        if jobs < 1:
            raise UserError(f"--jobs: must be at least 1 (got {jobs})")
        self.jobs = jobs  #: the worker processes asked for
        self.workers = jobs  #: the pool's (at most one per case of the sweep it runs: start)
        self._pool = None
        self._procs = []  # every worker process the pool has started, the ones it has replaced too
        self._started = None  # (read fd, write fd) of the pipe on which a worker says which batch it started
        self._tokens = iter(range(1, 2**62))  # batch tokens, unique over the engine's runs

    def start(self, cases: int | None = None) -> None:
        """Start the pool: ``jobs`` worker processes, or as many as the sweep has ``cases`` when that is
        fewer (a worker with no case to run costs a process and its memory: ``-j 1000`` for two cases
        started a thousand)."""
        import multiprocessing as mp

        if self._pool is None:
            self.workers = min(self.jobs, cases) if cases else self.jobs
            # fork: workers start in milliseconds and inherit the imported package. With SIGINT and SIGTERM
            # blocked while the pool starts, its threads (which fork the workers that replace dead ones)
            # keep them blocked, and a worker gets a signal only once it has its own handlers (it ran the
            # sweep's handler, which raised SweepInterrupted in the worker, with a traceback)
            blocked = signal.pthread_sigmask(signal.SIG_BLOCK, _STOP_SIGNALS)
            try:
                if self._started is None:  # before the fork: every worker, and each one started later, has it
                    self._started = os.pipe()
                    os.set_blocking(self._started[0], False)
                self._procs = []
                self._pool = _recording_pool(mp.get_context("fork"), self.workers, self._procs)
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, blocked)

    def warm_up(self, spec, archives: str = "all") -> None:
        """Start the pool and, if the sweep's base scenario is a reduced-model one, have the workers run
        it once without an archive (loading the compiled model takes ~0.3 s a process), while the
        sweep process resolves the cases. Does nothing else: errors are left to the sweep to report."""
        from bearingsim.scenario import load_scenario
        from bearingsim.sweeps.worker import keeps_archive, warm_up

        try:
            base = load_scenario(spec.scenario, spec.sets)
        except Exception:  # noqa: BLE001 - resolve_cases names the problem
            return
        if base.model != "reduced":
            return
        self.start(spec.size)
        text = base.to_toml()
        for _ in range(self.workers):
            self._pool.apply_async(warm_up, (text, keeps_archive("reduced", archives)))

    def run(self, batches: list[list[tuple[str, str]]], cases_dir: str,
            archives: str = "all") -> Iterator[list[dict]]:
        """Yield the records of each batch as it finishes (in completion order); ``archives``: which
        cases get an archive (:func:`bearingsim.sweeps.worker.keeps_archive`)."""
        import queue

        from bearingsim.sweeps.worker import one_line_error

        self.start()
        done: queue.Queue = queue.Queue()
        tokens = {}  # token -> batch, until its records are taken
        for b in batches:
            token = next(self._tokens)
            tokens[token] = b

            def lost(exc, b=b, token=token):  # the batch itself failed: every case of it failed
                done.put((token, _failed(b, one_line_error(exc))))
            self._pool.apply_async(_run_marked, (self._started[1], token, b, cases_dir, archives),
                                   callback=lambda records, token=token: done.put((token, records)),
                                   error_callback=lost)
        running: dict[int, int] = {}  # pid -> token of the batch that worker started last, until its records come
        for _ in batches:
            while True:
                try:  # short waits: a signal handler runs between them
                    token, records = done.get(timeout=0.25)
                    if tokens.pop(token, None) is None:
                        continue  # its worker was found dead, its cases already said failed
                    self._lost_batches(tokens, running, done)  # the pipe read as the batches come
                    break
                except queue.Empty:
                    if self.should_stop():  # a signal whose exception was swallowed (raised in a callback)
                        return
                    self._lost_batches(tokens, running, done)
                    continue
            yield records

    def _lost_batches(self, tokens: dict, running: dict, done) -> None:
        """Fail the batches whose worker process ended while it ran them (killed, say by the kernel's
        out-of-memory killer or by hand): the pool starts another worker but never runs the batch again nor
        says it was lost, and the sweep waited for it for ever.

        A worker runs one batch at a time, so the batch it started last is the one it was running: a batch
        it started before has ended and its records are on their way (failing it too recorded a finished
        case as failed). The workers found ended are taken before the pipe is read, so every batch they
        started is on it. Their exit status is that of the pool's own record of the process, kept from its
        start (:func:`_recording_pool`): the pool forgets a worker it has reaped and replaced, which it can
        do before this looks, and the batch then said the worker ended "(gone)" instead of its signal."""
        import struct

        ended = {p.pid: p.exitcode for p in list(self._procs) if p.pid is not None}  # a pid reused: the latest
        ended = {pid: code for pid, code in ended.items() if code is not None}
        data = b""
        with contextlib.suppress(BlockingIOError, InterruptedError):
            while chunk := os.read(self._started[0], 16 * 4096):
                data += chunk
        for k in range(0, len(data) - len(data) % 16, 16):
            token, pid = struct.unpack_from("qq", data, k)
            running[pid] = token
        for pid, token in list(running.items()):
            if token not in tokens:  # its records came
                del running[pid]
            elif pid in ended:
                del running[pid]
                code = ended[pid]
                how = f"signal {-code}" if code < 0 else f"exit status {code}"
                done.put((token, _failed(tokens[token], f"the worker process running it ended ({how}); "
                                                        f"run the same command again to run it")))

    def stop(self) -> None:
        """End every worker process now (queued batches are dropped) and wait for them to exit.

        ``Pool.terminate`` can wait forever: a worker ended while it held the result queue's lock (sending
        a finished task's result, e.g. a warm-up's) leaves the lock taken, and the pool's task handler then
        waits for it before it exits, and terminate for the task handler. So the pool is ended in a
        thread of its own, and this returns when it has finished or every worker process has exited; if
        neither within :data:`STOP_WAIT_S`, the workers are ended (SIGKILL) and reaped here. A thread
        left waiting is a daemon: it holds nothing the process needs."""
        import threading

        pool, self._pool = self._pool, None
        self._procs = []
        started, self._started = self._started, None
        for fd in started or ():
            with contextlib.suppress(OSError):
                os.close(fd)
        if pool is None:
            return
        workers = list(pool._pool)  # the worker processes (multiprocessing.pool.Pool keeps them here)
        ended = threading.Event()

        def end():
            pool.terminate()
            pool.join()
            ended.set()

        threading.Thread(target=end, name="bearingsim-pool-stop", daemon=True).start()
        deadline = time.monotonic() + STOP_WAIT_S
        while not ended.wait(0.05):
            # every worker gone: nothing of the sweep runs any more. The pool's own threads may wait for
            # ever on a pipe no worker reads: terminate drains the task pipe once, and a task handler that
            # was half-way through sending a batch (larger than the pipe) then fills it again, and
            # terminate waits for it (it took STOP_WAIT_S in about a third of the interrupts of a large
            # sweep); that thread is a daemon and holds nothing the process needs
            if all(p.exitcode is not None for p in [*workers, *list(pool._pool)]):
                return
            if time.monotonic() > deadline:
                break
        else:
            return
        for p in workers:
            if p.is_alive():
                p.kill()
            p.join(STOP_WAIT_S)


class DaskEngine:
    """Batches sent to a dask.distributed cluster; archives come back as bytes.

    Parameters
    ----------
    address : str or None
        Scheduler address (``tcp://127.0.0.1:8786``), or None with ``cluster`` given.
    cluster : distributed.deploy.Cluster, optional
        A cluster object (e.g. a ``LocalCluster``) to connect to instead of an address.
    timeout_s : float
        How long to try to reach the scheduler.
    """

    should_stop = staticmethod(lambda: False)  # set by run_sweep: a signal arrived

    kind = "dask"
    shared_fs = False

    def __init__(self, address: str | None = None, cluster=None, timeout_s: float = 10.0):
        self.address, self.cluster, self.timeout_s = address, cluster, timeout_s
        self.client = None
        self._futures: list = []
        self.workers = 0
        self.lost = False  #: the client lost its scheduler mid-sweep (run)

    def _scheduler_lost(self, exc) -> bool:
        """Whether ``exc``, from a batch's future, says the client lost the scheduler (it ended, or the
        network went): dask then cancels every future of the client."""
        return (getattr(exc, "reason", None) == "scheduler-connection-lost"
                or getattr(self.client, "status", "running") in ("connecting", "closing", "closed"))

    def start(self, cases: int | None = None) -> None:
        """Connect to the cluster (``cases``: the sweep's, unused: the cluster's workers are the user's)."""
        if self.client is not None:
            return
        try:
            from distributed import Client
        except ImportError:
            raise UserError("--scheduler: dask.distributed is not installed; it is the optional extra 'cluster': "
                            "pip install 'bearingsim[cluster]'") from None
        if self.cluster is None:
            self._check_address()
        target = self.cluster if self.cluster is not None else self.address
        try:
            self.client = Client(target, timeout=f"{self.timeout_s}s", set_as_default=False)
        except (OSError, TimeoutError, ValueError) as exc:
            raise UserError(f"--scheduler {self.address}: cannot reach a dask scheduler ({exc.__class__.__name__}: "
                            f"{' '.join(str(exc).split())[:200]})") from None
        self.workers = max(1, sum(w.get("nthreads", 1) for w in self.client.scheduler_info()["workers"].values()))

    def _check_address(self) -> None:
        """Refuse an address no client can connect to before a ``Client`` is made: one made with a
        malformed address ('foo', 'tcp://host:notaport'), an in-process one ('inproc://') or a TLS one
        with no TLS configured raised in its constructor, and the half-made client, closed as it was
        collected, printed a traceback after the one-line error and held the command for 20 s."""
        from distributed.comm import parse_address, resolve_address

        address = self.address or ""
        where = f"--scheduler {address!r}" if not address.strip() else f"--scheduler {address}"
        try:
            scheme = parse_address(address)[0] if address.strip() else ""
            if not scheme:
                raise ValueError("no address")
            if scheme == "inproc":
                raise ValueError("an in-process address; a sweep needs a scheduler it can connect to, "
                                 "e.g. tcp://127.0.0.1:8786")
            resolve_address(address)
            if scheme in ("tls", "wss"):
                from distributed.security import Security

                if Security().get_connection_args("client").get("ssl_context") is None:
                    raise ValueError(f"{scheme}:// needs TLS configured for the client "
                                     "(dask's distributed.comm.tls settings)")
        except Exception as exc:  # noqa: BLE001 - any reason the address is unusable, said in one line
            raise UserError(f"{where}: not a dask scheduler address ({exc.__class__.__name__}: "
                            f"{' '.join(str(exc).split())[:200]})") from None

    def run(self, batches: list[list[tuple[str, str]]], cases_dir: str,
            archives: str = "all") -> Iterator[list[dict]]:
        """Yield the records of each batch as it finishes; archives are in ``record["archive"]`` (bytes);
        ``archives``: which cases get one (:func:`bearingsim.sweeps.worker.keeps_archive`)."""
        from distributed import as_completed

        from bearingsim.archive import command_line
        from bearingsim.sweeps.worker import run_batch

        self.start()
        stamp = f"{os.getpid()}-{time.time_ns()}"
        # the text only: a worker elsewhere resolves it with its own bearingsim (no pickled models)
        batches = [[(h, text) for h, text, *_ in b] for b in batches]
        command = command_line()  # each case's provenance records the sweep's command, not the worker's
        self._futures = [self.client.submit(run_batch, b, None, archives, command, key=f"bearingsim-sweep-{stamp}-{i}",
                                            pure=False) for i, b in enumerate(batches)]
        for fut in as_completed(self._futures, loop=self.client.loop):
            if self.should_stop():
                return
            try:
                yield fut.result()
            except Exception as exc:  # noqa: BLE001 - a lost worker or a task the cluster gave up on
                from bearingsim.sweeps.worker import one_line_error

                if self._scheduler_lost(exc):
                    # every queued batch was cancelled with it: not a failure of its cases, which stay
                    # pending (each was recorded failed, a line apiece: 8800 lines for the 100 x 100 map)
                    self.lost = True
                    raise UserError(f"--scheduler {self.address or 'cluster'}: lost the connection to the dask "
                                    f"scheduler; the finished cases are kept in the sweep's index, the others not "
                                    f"run: run the same command again to resume") from None
                yield _failed(batches[self._futures.index(fut)], f"dask: {one_line_error(exc)}")

    def stop(self) -> None:
        """Cancel every queued batch and disconnect (the cluster itself is the user's and stays up)."""
        if self.client is None:
            return
        import logging

        lost = self.lost or getattr(self.client, "status", "running") in ("connecting", "closing", "closed")
        log = logging.getLogger("distributed.client")
        level = log.level
        try:
            if self._futures and not lost:  # a lost scheduler has no queue left to cancel
                self.client.cancel(self._futures, force=True)
        finally:
            self._futures = []
            if lost:  # closing ends the client's attempt to reconnect, which dask logs with a traceback
                log.setLevel(logging.CRITICAL)
            try:
                self.client.close(timeout=5)
            finally:
                log.setLevel(level)
                self.client = None
