"""How a tracker's parameters object is built, checked, saved and read back.

A tracker's parameters are a frozen dataclass of *groups* (``appearance``, ``dynamics``, ...),
each a frozen dataclass of numbers. Every number is declared with :func:`number` (or
:func:`flag`, :func:`pair`), which records the range it must lie in; the top-level object checks
every value on construction (and so on :func:`dataclasses.replace` and ``from_dict``), and a bad one
is a ``ValueError`` naming it by its path: ``body.dynamics.noise.head.x: must be finite and >= 0,
got nan``.

``to_dict`` gives the nested form (what new bundles store); ``from_dict`` reads it, and also the
flat form of partlab 0.2 (``{"bins_per_channel": 8, ...}``, what the shipped bundle and users'
bundles hold), through each class's ``FLAT`` table of old name -> new path.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, fields, is_dataclass, replace
from typing import Any, ClassVar


@dataclass(frozen=True)
class Rule:
    """The range of one number: ``lo``/``hi`` bounds (``None``: none), open or closed."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False
    integer: bool = False

    def describe(self) -> str:
        kind = "an integer" if self.integer else "finite"
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {self.lo:g}")
        if self.hi is not None:
            parts.append(f"{'<' if self.hi_open else '<='} {self.hi:g}")
        return f"must be {kind}" + (" and " + " and ".join(parts) if parts else "")

    def ok(self, v: Any) -> bool:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            return False
        if self.integer and not isinstance(v, int):
            return False
        if not math.isfinite(v):
            return False
        if self.lo is not None and (v <= self.lo if self.lo_open else v < self.lo):
            return False
        return not (self.hi is not None and (v >= self.hi if self.hi_open else v > self.hi))


#: common ranges
NONNEG = Rule(lo=0)
POSITIVE = Rule(lo=0, lo_open=True)
FRACTION = Rule(lo=0, hi=1)
COUNT = Rule(lo=0, integer=True)
POSITIVE_COUNT = Rule(lo=1, integer=True)


def number(default: float | int, rule: Rule = NONNEG):
    """A number with its range (checked when the parameters object is built)."""
    return field(default=default, metadata={"rule": rule})


def flag(default: bool):
    return field(default=default, metadata={"rule": "bool"})


def pair(default: tuple, rule: Rule = POSITIVE, n: int = 2):
    """A tuple of ``n`` numbers, each within ``rule``."""
    return field(default=tuple(default), metadata={"rule": rule, "tuple": n})


def _check_value(path: str, v: Any, meta) -> None:
    rule = meta.get("rule")
    if rule is None:
        return
    if rule == "bool":
        if not isinstance(v, bool):
            raise ValueError(f"{path}: must be true or false, got {v!r}")
        return
    n = meta.get("tuple")
    if n is not None:
        if not isinstance(v, tuple) or len(v) != n:
            raise ValueError(f"{path}: must be {n} numbers, got {v!r}")
        for i, x in enumerate(v):
            if not rule.ok(x):
                raise ValueError(f"{path}[{i}]: {rule.describe()}, got {x!r}")
        return
    if not rule.ok(v):
        raise ValueError(f"{path}: {rule.describe()}, got {v!r}")


def validate(obj: Any, path: str) -> None:
    """Check every number of the dataclass ``obj`` (recursively); ``ValueError`` naming the first bad one."""
    extra = getattr(obj, "check", None)
    for f in fields(obj):
        v = getattr(obj, f.name)
        where = f"{path}.{f.name}"
        if is_dataclass(v):
            validate(v, where)
        elif isinstance(v, dict):
            inner = f.metadata.get("values")
            if not isinstance(v, dict):
                raise ValueError(f"{where}: must be a mapping, got {v!r}")
            for k, item in v.items():
                if is_dataclass(item):
                    validate(item, f"{where}.{k}")
                elif inner is not None:
                    _check_value(f"{where}.{k}", item, inner)
        else:
            _check_value(where, v, f.metadata)
    if callable(extra):
        extra(path)


def _coerce(path: str, value: Any, f) -> Any:
    """A JSON value as the field ``f`` holds it: groups and dict values rebuilt, lists -> tuples,
    integers -> float where the field is a float (so a bundle's ``16`` and ``16.0`` read alike)."""
    sub = f.metadata.get("group")
    if sub is not None:
        if not isinstance(value, dict):
            raise ValueError(f"{path}: must be a mapping of its parameters, got {value!r}")
        return build(sub, value, path)
    inner = f.metadata.get("values")
    if inner is not None:
        if not isinstance(value, dict):
            raise ValueError(f"{path}: must be a mapping, got {value!r}")
        cls = inner.get("cls")
        out = {}
        for k, item in value.items():
            if cls is not None:
                if not isinstance(item, dict):
                    raise ValueError(f"{path}.{k}: must be a mapping, got {item!r}")
                out[k] = build(cls, item, f"{path}.{k}")
            else:
                out[k] = _plain(item, inner)
        return out
    return _plain(value, f.metadata)


def _plain(value: Any, meta) -> Any:
    rule = meta.get("rule")
    if isinstance(value, list):
        value = tuple(_plain(x, {"rule": rule}) for x in value)
    elif isinstance(rule, Rule) and not rule.integer and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    return value


def build(cls, data: dict, path: str):
    """``cls`` from its nested dict; unknown names are an error naming them."""
    known = {f.name: f for f in fields(cls)}
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ValueError(f"{path}: unknown parameter(s) {', '.join(unknown)}")
    kwargs = {name: _coerce(f"{path}.{name}", data[name], known[name]) for name in data}
    try:
        return cls(**kwargs)
    except TypeError as exc:
        raise ValueError(f"{path}: {exc}") from None


class Parameters:
    """Mixin of a tracker's top-level parameters object.

    Subclasses set ``KEY`` (the registry's parameter key, the first word of every path) and
    ``FLAT`` (partlab 0.2's flat field name -> dotted path of its group field, or ``None`` for a
    retired name that old bundles may hold and that is dropped)."""

    KEY: ClassVar[str] = ""
    FLAT: ClassVar[dict[str, str | None]] = {}

    def __post_init__(self):
        validate(self, self.KEY)

    def to_dict(self) -> dict:
        """The nested form, as plain JSON types (tuples stay tuples; JSON writes them as lists)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict):
        """Read the nested form, or partlab 0.2's flat one (every key a field name of ``FLAT``)."""
        if not isinstance(data, dict):
            raise ValueError(f"{cls.KEY}: parameters must be a mapping, got {type(data).__name__}")
        groups = {f.name for f in fields(cls)}
        if data and not set(data) <= groups:
            data = cls.unflatten(data)
        return build(cls, data, cls.KEY)

    @classmethod
    def unflatten(cls, flat: dict) -> dict:
        """partlab 0.2's flat dict -> the nested dict; an unknown name is an error naming it."""
        unknown = sorted(k for k in flat if k not in cls.FLAT)
        if unknown:
            raise ValueError(f"unknown {cls.KEY} parameter(s): {', '.join(unknown)}")
        nested: dict = {}
        for name, value in flat.items():
            where = cls.FLAT[name]
            if where is None:
                continue
            head, _, leaf = where.rpartition(".")
            node = nested
            for part in head.split("."):
                node = node.setdefault(part, {})
            node[leaf] = value
        return nested

    def get(self, dotted: str):
        """The value at ``"group.field"`` (``p.get("dynamics.noise")``)."""
        head, _, leaf = dotted.partition(".")
        return getattr(getattr(self, head), leaf)

    def updated(self, changes: dict[str, Any]):
        """A copy with ``{"group.field": value}`` changes (validated): ``p.updated({"states.lost_frames": 3})``."""
        out = self
        by_group: dict[str, dict] = {}
        for dotted, value in changes.items():
            head, _, leaf = dotted.partition(".")
            if not leaf or head not in {f.name for f in fields(self)}:
                raise ValueError(f"{self.KEY}.{dotted}: no such parameter (use group.field)")
            by_group.setdefault(head, {})[leaf] = value
        for head, kw in by_group.items():
            g = getattr(out, head)
            names = {f.name for f in fields(g)}
            bad = sorted(set(kw) - names)
            if bad:
                raise ValueError(f"{self.KEY}.{head}: no such parameter(s) {', '.join(bad)}")
            out = replace(out, **{head: replace(g, **kw)})
        return out


def group_field(cls):
    """A group of a top-level parameters object (rebuilt from dicts by ``from_dict``)."""
    return field(default_factory=cls, metadata={"group": cls})


def mapping(default_factory, cls=None, rule: Rule | None = None, n: int | None = None):
    """A ``{name: value}`` field: values are dataclasses ``cls`` or tuples of ``n`` numbers within ``rule``."""
    values = {"cls": cls} if cls is not None else {"rule": rule, "tuple": n}
    return field(default_factory=default_factory, metadata={"values": values})
