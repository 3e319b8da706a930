"""opnav.core.numba_adapter pinned to the numba it was written for (issue 56 item 2): the
version, each private name it reaches with the signature it uses, and what each part buys,
in this process on a scratch cache (tiny kernels: about a second of compiling).

An upgrade of numba fails the first test until the adapter is checked against the new
version (and the pin in requirements.lock and NUMBA_VERSION moved together)."""

import importlib.util
import inspect
import re
import sys
import textwrap
import types

import pytest
from conftest import REPO

numba = pytest.importorskip("numba")

from numba.core import caching, dispatcher, event  # noqa: E402

from opnav.core import compiled, numba_adapter, startup  # noqa: E402


def test_numba_is_the_pinned_version():
    lock = re.search(r"^numba==(\S+)", (REPO / "requirements.lock").read_text(), re.M).group(1)
    assert numba.__version__ == numba_adapter.NUMBA_VERSION == lock


def test_the_private_names_used_exist_with_their_signatures():
    assert list(inspect.signature(dispatcher.Dispatcher.get_call_template).parameters) == ["self", "args", "kws"]
    assert caching.FunctionCache._impl_class is caching.CompileResultCacheImpl
    assert caching.FunctionCache.__mro__[1] is caching.Cache
    assert list(inspect.signature(caching.Cache.load_overload).parameters) == ["self", "sig", "target_context"]
    assert caching.CompileResultCacheImpl._locator_classes[:3] == [
        caching.UserProvidedCacheLocator, caching.InTreeCacheLocator, caching.UserWideCacheLocator]
    for loc in caching.CompileResultCacheImpl._locator_classes[:3]:
        assert "get_source_stamp" in dir(loc)
    assert issubclass(event.Listener, object) and callable(event.register)
    # the dispatcher's cache is an instance attribute the compile path reads
    assert "self._cache.load_overload(sig, self.targetctx)" in inspect.getsource(dispatcher.Dispatcher.compile)
    assert 'ev.trigger_event("numba:compile"' in inspect.getsource(dispatcher.Dispatcher.compile)


MODULE = textwrap.dedent("""\
    def add(x, n):
        return x + n


    def twice(x):
        return add(x, 3) * 2.0
""")


def _module(tmp_path, name):
    path = tmp_path / f"{name}.py"
    path.write_text(MODULE)
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_the_stamp_keys_the_cache(tmp_path, monkeypatch):
    """Same source, same stamp: the next dispatcher loads; another stamp: it compiles again
    (mutation: without the stamp the third dispatcher loads a stale entry)."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "cache"))
    mod = _module(tmp_path, "pin_stamp")
    loads = []

    def on_load(load):
        got = load()
        loads.append(got is not None)
        return got

    def hits_misses(stamp):
        d = numba_adapter.dispatcher(mod.add, {"cache": True}, stamp, on_load)
        assert d(1.0, 2.0) == 3.0
        return sum(d.stats.cache_hits.values()), sum(d.stats.cache_misses.values())

    assert hits_misses("A") == (0, 1)
    assert hits_misses("A") == (1, 0)
    assert hits_misses("B") == (0, 1)
    assert loads == [False, True, False]


def test_a_constant_argument_makes_no_second_signature(tmp_path):
    """``twice`` calls ``add(x, 3)``: numba alone compiles ``add`` for ``Literal[int](3)`` too;
    through the adapter, ``add`` keeps the one signature its own call made."""
    mod = _module(tmp_path, "pin_literal")
    add = numba_adapter.dispatcher(mod.add, {"cache": False}, "", lambda load: load())
    mod.add = add
    twice = numba_adapter.dispatcher(mod.twice, {"cache": False}, "", lambda load: load())
    assert add(1.0, 3) == 4.0 and twice(1.0) == 8.0
    assert [str(s) for s in add.signatures] == ["(float64, int64)"]
    plain_add = numba.njit(_module(tmp_path, "pin_literal_plain").add)
    plain = _module(tmp_path, "pin_literal_plain2")
    plain.add = plain_add
    plain_add(1.0, 3)
    numba.njit(plain.twice)(1.0)
    assert len(plain_add.signatures) == 2, "numba itself no longer types the constant as a literal"


def test_a_lazy_kernel_is_rebound_where_it_was_imported(monkeypatch):
    """After its first call the dispatcher stands where the proxy stood: its home module and a
    module that imported it by name (``from m import k``)."""
    home = types.ModuleType("opnav._pin_home")
    user = types.ModuleType("opnav._pin_user")
    monkeypatch.setitem(sys.modules, home.__name__, home)
    monkeypatch.setitem(sys.modules, user.__name__, user)

    def k(x):
        return x + 1.0

    k.__module__ = home.__name__
    proxy = compiled.LazyKernel(k, {"cache": False})
    home.k = user.k = proxy
    kept = (proxy,)
    assert proxy(1.0) == 2.0
    assert home.k is proxy._dispatcher and user.k is proxy._dispatcher
    assert kept[0] is proxy and kept[0](2.0) == 3.0  # a reference elsewhere still calls through


def test_compile_and_load_cpu_are_counted_apart(tmp_path, monkeypatch):
    """The compile timer (numba's "numba:compile" event) adds to compile_s, a load to kernels_s,
    a load inside a compile counts once, as compile."""
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "cache"))
    mod = _module(tmp_path, "pin_timer")
    before = startup.seconds()
    first = compiled._dispatcher(mod.add, {"cache": True})
    first(1.0, 2.0)
    mid = startup.seconds()
    assert mid["compile_s"] > before["compile_s"]
    second = compiled._dispatcher(mod.add, {"cache": True})
    second(1.0, 2.0)
    after = startup.seconds()
    assert after["compile_s"] == mid["compile_s"] and after["kernels_s"] > mid["kernels_s"]
    assert sum(second.stats.cache_hits.values()) == 1
