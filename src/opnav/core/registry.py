"""What both papers' registries of a user's own method share (``landing.custom_methods``,
``approach.custom_estimators``; issue 58): the config entry, the one-line error, importing a
``module:function`` or ``file.py:function`` path, the one-argument signature check, and the
files a method lives in (the workflow's inputs).

A relative ``file.py`` path starts at the checkout's root (:data:`CHECKOUT`); a dotted module
is imported from ``sys.path``, then from the checkout.
"""

from __future__ import annotations

import importlib
import importlib.util
import inspect
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

__all__ = ["CHECKOUT", "MethodError", "CustomSpec", "specs", "split", "import_target", "check_signature",
           "what", "is_numba", "load_function", "source_files", "strip_key"]

#: the checkout's root: a relative ``file.py:function`` path is read from here
CHECKOUT = Path(__file__).resolve().parents[3]


class MethodError(ValueError):
    """A registered method that cannot be used (preflight) or failed during a run: the message
    is one line naming the method by its config key (``landing.custom_methods.<name>``,
    ``approach.custom_estimators.<name>``)."""


@dataclass(frozen=True)
class CustomSpec:
    """One entry of a registry's config key (``section``: ``landing.custom_methods`` ...)."""

    name: str
    path: str
    label: str = ""
    color: str = ""
    section: str = "landing.custom_methods"

    @property
    def key(self) -> str:
        return f"{self.section}.{self.name}"


def specs(entries: Mapping | None, section: str) -> dict[str, CustomSpec]:
    """A registry's config entries (name -> ``{path, label, color}`` or name -> path) as
    :class:`CustomSpec`, in the config's order."""
    out = {}
    for name, v in dict(entries or {}).items():
        v = {"path": v} if isinstance(v, str) else dict(v)
        out[str(name)] = CustomSpec(str(name), str(v.get("path", "")), str(v.get("label", "") or ""),
                                    str(v.get("color", "") or ""), section)
    return out


def strip_key(msg: str, key: str) -> str:
    """``msg`` without its leading ``key`` (a preflight line names the key once)."""
    return msg[len(key):].lstrip(": ") if msg.startswith(key) else msg


def split(path: str, key: str) -> tuple[str, str]:
    target, sep, attr = str(path).rpartition(":")
    if not sep or not target or not attr.isidentifier():
        raise MethodError(f"{key}: path {path!r} is not 'module:function' or 'file.py:function'")
    return target, attr


def import_target(target: str, key: str):
    """The module of ``target``: a ``.py`` file (relative to :data:`CHECKOUT` or absolute) or a
    dotted module name (``sys.path``, then the checkout)."""
    if target.endswith(".py"):
        file = Path(target)
        file = file if file.is_absolute() else CHECKOUT / file
        if not file.is_file():
            raise MethodError(f"{key}: file {target} not found (relative paths start at {CHECKOUT})")
        name = "opnav_custom_" + "".join(c if c.isalnum() else "_" for c in str(file.resolve()))
        if name in sys.modules:
            return sys.modules[name]
        spec = importlib.util.spec_from_file_location(name, file)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        try:
            spec.loader.exec_module(mod)
        except (Exception, SystemExit) as exc:
            del sys.modules[name]
            raise MethodError(f"{key}: importing {target} raised {what(exc)}") from exc
        return mod
    try:
        return importlib.import_module(target)
    except ModuleNotFoundError as exc:
        first = exc
    except (Exception, SystemExit) as exc:
        raise MethodError(f"{key}: module {target!r} does not import: {what(exc)}") from exc
    if str(CHECKOUT) in sys.path:          # not under the checkout either
        raise MethodError(f"{key}: module {target!r} does not import: {what(first)}") from first
    sys.path.append(str(CHECKOUT))
    try:
        return importlib.import_module(target)
    except (Exception, SystemExit) as exc:
        raise MethodError(f"{key}: module {target!r} does not import: {what(exc)}") from exc
    finally:
        sys.path.remove(str(CHECKOUT))


def what(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".split())


def is_numba(fn) -> bool:
    return type(fn).__module__.startswith("numba") and hasattr(fn, "py_func")


def check_signature(fn, key: str, takes: str) -> None:
    """One required positional parameter (the record, ``takes``); optional ones are allowed, any
    other required one is refused."""
    py = fn.py_func if is_numba(fn) else fn
    try:
        sig = inspect.signature(py)
    except (TypeError, ValueError) as exc:
        raise MethodError(f"{key}: its signature cannot be read ({what(exc)})") from exc
    pos = [p for p in sig.parameters.values()
           if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD) and p.default is p.empty]
    other = [p for p in sig.parameters.values() if p not in pos and p.default is p.empty
             and p.kind is not p.VAR_KEYWORD and p.kind is not p.VAR_POSITIONAL]
    if len(pos) != 1 or other:
        raise MethodError(f"{key}: the function must take exactly one argument (a {takes}), it takes {sig}")


def load_function(spec: CustomSpec, builtin, takes: str, kind: str = "method"):
    """The function of ``spec``: its name not one of ``builtin`` (a built-in ``kind``'s), its path
    imported, a callable taking one argument (``takes`` names it in the error); :class:`MethodError`
    naming the key."""
    key = spec.key
    if spec.name in builtin:
        raise MethodError(f"{key}: the name {spec.name!r} is a built-in {kind}'s; choose another")
    target, attr = split(spec.path, key)
    mod = import_target(target, key)
    fn = getattr(mod, attr, None)
    if fn is None:
        raise MethodError(f"{key}: {target} has no attribute {attr!r}")
    if not callable(fn):
        raise MethodError(f"{key}: {spec.path} is not a function")
    check_signature(fn, key, takes)
    return fn


def source_files(entries: Mapping[str, CustomSpec]) -> list[str]:
    """The files the registered methods' functions live in (for the workflow's inputs, so an
    edit of one re-flies its Monte Carlo): a ``file.py`` path as given, resolved; a module's
    file where it can be found without importing it (else nothing)."""
    out = []
    for s in entries.values():
        target = s.path.rpartition(":")[0]
        if target.endswith(".py"):
            f = Path(target)
            out.append(str(f if f.is_absolute() else CHECKOUT / f))
            continue
        try:
            found = importlib.util.find_spec(target.split(".")[0]) and importlib.util.find_spec(target)
        except (ImportError, ValueError):
            found = None
        if found is None:
            sys.path.append(str(CHECKOUT))
            try:
                found = importlib.util.find_spec(target)
            except (ImportError, ValueError):
                found = None
            finally:
                sys.path.remove(str(CHECKOUT))
        if found is not None and found.origin and Path(found.origin).is_file():
            out.append(found.origin)
    return out
