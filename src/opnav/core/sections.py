"""Typed config sections: a (schema-validated) config mapping parsed once, at the edge, into
frozen dataclasses (paper B's :mod:`opnav.landing.setup`).

A :class:`Section` subclass declares one field per config key, its annotation saying how the
value converts (``float``, ``int``, ``str``, ``bool``, ``tuple`` of floats, ``tuple[str, ...]``,
``pairs``: a mapping kept as ``((key, value), ...)``, or a nested :class:`Section` class). A
workflow rule passes only the keys it uses, so a key absent from the mapping becomes the
field's default if it declares one, else :class:`Missing`, which fails on first use with one
line naming the dotted key: a rule whose params lack a key it needs stops at once instead of
falling back on a value nobody chose.
"""

from __future__ import annotations

import dataclasses
from typing import Any, Mapping

__all__ = ["Missing", "Section", "is_missing", "Pairs", "conversion", "register"]


class Missing:
    """A config key the rule did not pass: any use raises one line naming it."""

    def __init__(self, key: str):
        object.__setattr__(self, "_key", key)

    def _fail(self, *_a, **_k):
        raise KeyError(f"{object.__getattribute__(self, '_key')}: not among this rule's params "
                       "(add the key to the rule's params)")

    def __getattr__(self, name):
        if name.startswith("__"):
            raise AttributeError(name)
        self._fail()

    __iter__ = __len__ = __index__ = __int__ = __float__ = __getitem__ = __bool__ = _fail
    __add__ = __radd__ = __sub__ = __rsub__ = __mul__ = __rmul__ = __truediv__ = __rtruediv__ = _fail
    __lt__ = __le__ = __gt__ = __ge__ = __neg__ = __abs__ = __contains__ = _fail

    def __eq__(self, other):
        return isinstance(other, Missing) and other._key == self._key

    def __hash__(self):
        return hash(("Missing", self._key))

    def __repr__(self):
        return f"Missing({self._key!r})"

    def __reduce__(self):
        return (Missing, (self._key,))


def is_missing(x) -> bool:
    return isinstance(x, Missing)


def floats(x) -> tuple:
    return tuple(float(v) for v in x)


def strings(x) -> tuple:
    return tuple(str(v) for v in x)


def pairs(x) -> tuple:
    """A mapping as a hashable ``((key, value), ...)`` in its order (a mapping value likewise)."""
    return tuple((str(k), pairs(v) if isinstance(v, Mapping) else v) for k, v in dict(x or {}).items())


#: the annotation of a mapping field kept as :func:`pairs` (hashable, in the config's order)
Pairs = tuple

#: how a field's annotation converts its config value
CONVERT = {"float": float, "int": int, "str": str, "bool": bool, "tuple": floats,
           "tuple[str, ...]": strings, "Pairs": pairs}


def conversion(annotation: str, fn) -> None:
    """Declare how a field annotated ``annotation`` (a type alias's name) converts its value."""
    if CONVERT.get(annotation, fn) is not fn:
        raise ValueError(f"conversion for {annotation!r} declared twice")
    CONVERT[annotation] = fn


class Section:
    """A frozen config section (module docstring). Subclasses are frozen, keyword-only
    dataclasses; :attr:`KEY` is the section's dotted config key (for :class:`Missing`)."""

    KEY = ""

    @classmethod
    def from_config(cls, c: Mapping, key: str | None = None):
        """The section of the mapping ``c`` (``key``: its dotted config key, default :attr:`KEY`)."""
        key = cls.KEY if key is None else key
        if not isinstance(c, Mapping):
            raise TypeError(f"{key}: expected a mapping, got {type(c).__name__}")
        kw: dict[str, Any] = {}
        for f in dataclasses.fields(cls):
            if f.name not in c:
                if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                    kw[f.name] = Missing(f"{key}.{f.name}")
                continue
            kw[f.name] = convert(f.type, c[f.name], f"{key}.{f.name}")
        return cls(**kw)

    def replace(self, **changes):
        return dataclasses.replace(self, **changes)


def convert(annotation: str, value, key: str):
    """A config value converted by a field's annotation (a :data:`CONVERT` name, a nested
    :class:`Section` subclass named in :data:`SECTIONS`, or ``X | None``)."""
    ann = str(annotation)
    if ann.endswith(" | None"):
        return None if value is None else convert(ann[:-len(" | None")], value, key)
    if ann in CONVERT:
        return CONVERT[ann](value)
    cls = SECTIONS.get(ann)
    if cls is None:
        raise TypeError(f"{key}: no conversion for the annotation {ann!r}")
    return cls.from_config(value, key)


#: nested section classes by name (:func:`register`)
SECTIONS: dict[str, type] = {}


def register(cls):
    """Class decorator: make a :class:`Section` subclass usable as another section's field type."""
    SECTIONS[cls.__name__] = cls
    return cls
