"""The one place the project reaches past numba's public API (issue 56 item 2).

:mod:`opnav.core.compiled` makes every kernel through :func:`dispatcher`; nothing else in the
package touches numba's internals or rewrites a module's namespace. What is here, and why:

* **The cache stamp** (numba private: ``Dispatcher._cache``, ``FunctionCache._impl_class``,
  ``CompileResultCacheImpl._locator_classes``, ``get_source_stamp``). numba keys a cached
  function by its own file only, so a kernel that calls a kernel of another module would be
  loaded with the callee's old code after the callee's file changed. The dispatcher's cache
  here stamps each entry with a digest of the kernel set as well
  (:func:`opnav.core.compiled.kernel_set_digest`): a stale entry is recompiled, once.
* **One signature per argument type** (numba private: ``Dispatcher.get_call_template``). A
  kernel calling another kernel with a constant (``cholesky_in_place(L, 3)``) would make numba
  compile the callee once more for ``Literal[int](3)``, each copy a full compile, and with the
  size a constant LLVM unrolls the callee's loops completely (most of the landing kernels'
  compile, docs/performance.md). The call template sees the argument types made non-literal;
  the arithmetic is the same IEEE operations in the same order (no fastmath): the same bits.
* **The rebinding of a lazy kernel** (Python, not numba: module ``__dict__`` entries). A kernel
  is a proxy until first called (importing a kernel module does not import numba); its first
  call puts the dispatcher where the proxy is a module global (its module, and every loaded
  ``opnav`` module that imported it by name), so later calls go to numba straight: a call
  through the proxy costs about 0.2-0.6 us more (measured: 413 ns straight, 596-990 ns through
  a proxy, a two-argument kernel, the 2-core VM loaded), which matters to the microsecond
  planning calls the timing claims time.

Public API used beside them: ``numba.njit``, ``numba.extending.typeof_impl`` (the type of a
proxy met as a global of a kernel being compiled), the dispatcher's ``stats``, and numba's event
API (``numba.core.event``, documented for applications: the ``"numba:compile"`` event) for the
CPU a compile takes. Loading from the cache is timed in the cache class above (it is the
cache's own ``load_overload``).

Pinned: numba 0.68.1 (requirements.lock); ``tests/test_numba_adapter.py`` checks the version,
that each private name still exists with the signature used, and what each part buys (a stale
stamp recompiles, a constant argument makes no second signature, a rebound global).
"""
from __future__ import annotations

import functools
import sys
from typing import Callable

#: The numba version this module was written against (requirements.lock).
NUMBA_VERSION = "0.68.1"


@functools.lru_cache(maxsize=None)
def cache_type(stamp: str, on_load: Callable[[Callable[[], object]], object]):
    """numba's ``FunctionCache`` whose entries are stamped with ``stamp`` beside numba's own
    stamp (the function's file), and whose loads run through ``on_load(load)`` (a timer).
    One class per (stamp, on_load)."""
    from numba.core import caching

    class Stamp:
        def get_source_stamp(self):
            return (super().get_source_stamp(), stamp)

    class Impl(caching.CompileResultCacheImpl):
        # numba's own order: NUMBA_CACHE_DIR, else __pycache__ beside the source if
        # writable, else the user-wide cache directory
        _locator_classes = [type(f"KernelSet{c.__name__}", (Stamp, c), {})
                            for c in (caching.UserProvidedCacheLocator, caching.InTreeCacheLocator,
                                      caching.UserWideCacheLocator)]

    class KernelCache(caching.FunctionCache):
        _impl_class = Impl

        def load_overload(self, sig, target_context):
            return on_load(lambda: super(KernelCache, self).load_overload(sig, target_context))

    return KernelCache


def _unliteral_calls(get_call_template):
    """numba's typing of a call to this kernel from another kernel, its argument types made
    non-literal (module docstring)."""
    from numba.core import types

    @functools.wraps(get_call_template)
    def typed(args, kws):
        return get_call_template(tuple(types.unliteral(a) for a in args),
                                 {k: types.unliteral(v) for k, v in kws.items()})

    return typed


def dispatcher(f, settings: dict, stamp: str, on_load: Callable[[Callable[[], object]], object]):
    """``numba.njit(**settings)(f)``, its on-disk cache (``settings["cache"]``) stamped with
    ``stamp`` and loaded through ``on_load`` (:func:`cache_type`), its calls from other kernels
    typed non-literal (:func:`_unliteral_calls`)."""
    from numba import njit

    d = njit(**settings)(f)
    if settings.get("cache"):
        d._cache = cache_type(stamp, on_load)(d.py_func)
    d.get_call_template = _unliteral_calls(d.get_call_template)
    return d


def register_proxy_type(cls: type, to_dispatcher: Callable[[object], object]) -> None:
    """numba's ``typeof`` of a ``cls`` instance (a kernel proxy met as a global of a kernel being
    compiled, or as an argument): the type of ``to_dispatcher(proxy)`` (public extension API)."""
    from numba.extending import typeof_impl

    if cls in typeof_impl.registry:
        return

    @typeof_impl.register(cls)
    def _typeof_proxy(val, c):
        return typeof_impl(to_dispatcher(val), c)


def rebind(proxy, d, home: str, prefix: str = "opnav") -> int:
    """Put ``d`` where ``proxy`` is a module global: in module ``home`` and in every loaded
    module of package ``prefix`` (``from home import k``). Returns the number of names rebound."""
    n = 0
    for name, mod in list(sys.modules.items()):
        if mod is None or not (name == home or name.split(".", 1)[0] == prefix):
            continue
        ns = getattr(mod, "__dict__", None)
        if ns is None:
            continue
        for key, value in list(ns.items()):
            if value is proxy:
                ns[key] = d
                n += 1
    return n


class CompileTimer:
    """CPU seconds numba spends compiling (outermost ``"numba:compile"`` events: a callee
    compiled for its caller counts once, in the caller's), reported to ``on_compile(start,
    stop)`` callables: ``start()`` as the outermost compile begins, ``stop()`` as it ends.
    Installed once a process (:func:`install_compile_timer`)."""

    def __init__(self, start: Callable[[], None], stop: Callable[[], None]):
        from numba.core import event

        class _Listener(event.Listener):
            depth = 0

            def on_start(self, ev):
                self.depth += 1
                if self.depth == 1:
                    start()

            def on_end(self, ev):
                self.depth -= 1
                if self.depth == 0:
                    stop()

        self.listener = _Listener()
        event.register("numba:compile", self.listener)


@functools.lru_cache(maxsize=None)
def install_compile_timer(start: Callable[[], None], stop: Callable[[], None]) -> CompileTimer:
    """One :class:`CompileTimer` per (start, stop) for the process."""
    return CompileTimer(start, stop)
