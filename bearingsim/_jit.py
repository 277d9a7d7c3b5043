"""numba on-disk caches that follow the kernels they inline from other files.

numba's ``cache=True`` checks only the source file of the cached function itself. A compiled function
that calls a kernel from another file carries that kernel's code inside its cache entry, so after an
edit of the other file it would keep running the old kernel. :func:`drop_stale_caches`, called at the
end of such a module, keeps a digest of the sources it depends on beside the cache and empties the
module's caches when the digest changes.

A module that compiles functions written in another file (``njit(cache=True)(other.f)``, as
:mod:`bearingsim.compiled_laws` does) passes them as ``dispatchers``: their ``__module__`` is the other
file's, and the decorator's options live in this one, which numba's check of the other file misses.
"""
from __future__ import annotations

import contextlib
import hashlib
import sys
from pathlib import Path

from numba.core.dispatcher import Dispatcher


def drop_stale_caches(module_name: str, dependencies, dispatchers=None) -> None:
    """Empty the numba caches of every compiled function of ``module_name`` (or of ``dispatchers``, when
    given) if any module in ``dependencies`` changed since the caches were written (a read-only install is
    left alone)."""
    if dispatchers is None:
        module = sys.modules[module_name]
        dispatchers = [v for v in vars(module).values()
                       if isinstance(v, Dispatcher) and getattr(v, "__module__", None) == module_name]
    dispatchers = list(dispatchers)
    if not dispatchers:
        return
    digest = hashlib.sha256(b"".join(Path(m.__file__).read_bytes() for m in dependencies)).hexdigest()
    try:
        stamp = Path(dispatchers[0]._cache._cache_path) / f"{module_name}.sources.sha256"
        if stamp.exists() and stamp.read_text() == digest:
            return
        for d in dispatchers:
            d._cache.flush()
        stamp.write_text(digest)
    except (OSError, AttributeError):  # read-only install, or a numba without these internals
        pass


@contextlib.contextmanager
def on_first_compile(call, package: str = "bearingsim"):
    """While the block runs, ``call(module)`` once, as numba starts to compile the first function of
    ``package`` (``module``: that function's module) because it found no copy of it in its cache for this
    machine; loading a cached copy calls nothing. numba's event API ("numba:compile" fires after a cache
    miss only); numba is imported here, not before. Once in all: the processes a sweep forks inside the
    block (they compile, not the sweep process) share one flag (shared memory), so the first of them to
    compile calls and the others do not."""
    from numba.core import event

    told = _shared_flag()

    class _First(event.Listener):
        def on_start(self, ev):
            if told.value:
                return
            module = getattr(getattr(ev.data.get("dispatcher"), "py_func", None), "__module__", None) or ""
            if module == package or module.startswith(package + "."):
                with told.get_lock():
                    first, told.value = not told.value, True
                if first:
                    call(module)

        def on_end(self, ev):
            pass

    listener = _First()
    event.register("numba:compile", listener)
    try:
        yield listener
    finally:
        event.unregister("numba:compile", listener)


def _shared_flag():
    """A boolean flag (``.value``, ``.get_lock()``) in memory that processes forked after it share; where
    the platform has no shared semaphores (some sandboxes), a flag of this process only."""
    import multiprocessing
    import threading

    try:
        return multiprocessing.Value("b", False)
    except (OSError, ImportError):  # no /dev/shm, no sem_open
        class _Local:
            value = False
            _lock = threading.Lock()

            def get_lock(self):
                return self._lock

        return _Local()
