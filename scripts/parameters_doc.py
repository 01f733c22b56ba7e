"""Print the docs/parameters.md tables of registered parameters kinds, from the code.

For each group of a kind (``body.appearance``, ``topview.exclusion``, ...): a heading with the
group's docstring, then one row per field: its default, its range (what the check enforces) and
why, which is the comment written above the field in its ``params.py`` ("with the row above" for a
field that shares the previous one's comment, "see the group" for one without any).

    python scripts/parameters_doc.py topview limbs3d      # paste below "## Every field"

``tests/tracking/test_parameters_doc.py`` fails when a field is missing from docs/parameters.md.
"""

from __future__ import annotations

import inspect
import re
import sys
from dataclasses import MISSING, fields
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from partlab.tracking import registry  # noqa: E402

FIELD = re.compile(r"^\s+(\w+)\s*:\s*[^=]+=")


def groups(key: str) -> list[tuple[str, type]]:
    """``(name, class)`` of every group of parameters kind ``key``, in declaration order."""
    return [(f.name, f.metadata["group"]) for f in fields(registry.params_class(key)) if "group" in f.metadata]


def comments(cls: type) -> dict[str, str | None]:
    """Field name -> the comment lines right above its declaration: None for a field declared
    right after a commented one without a comment of its own (they share it), "" for none."""
    out, pending, shared = {}, [], ""  # shared: the comment an uncommented next field shares
    for line in inspect.getsource(cls).splitlines():
        stripped = line.strip()
        if stripped.startswith("#"):
            pending.append(stripped.lstrip("#:").strip())
            continue
        m = FIELD.match(line)
        if m:
            own = " ".join(pending)
            out[m.group(1)] = own or (None if shared else "")
            shared = own or shared
        else:
            shared = ""
        pending = []
    return out


def _default(f) -> str:
    value = f.default if f.default is not MISSING else f.default_factory()
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:g}"
    if isinstance(value, tuple):
        return "(" + ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in value) + ")"
    if isinstance(value, dict):
        return "per name: " + ", ".join(value)
    return str(value)


def _range(f) -> str:
    rule = f.metadata.get("rule")
    if rule == "bool":
        return "true or false"
    if rule is None:
        values = f.metadata.get("values", {})
        return f"a table of `{values['cls'].__name__}`" if values.get("cls") else "a table of numbers"
    text = rule.describe().removeprefix("must be ")
    return f"{f.metadata['tuple']} numbers, each {text}" if "tuple" in f.metadata else text


def _why(comment: str | None) -> str:
    if comment is None:
        return "with the row above"
    return comment.replace("|", "/") or "see the group"


def markdown(key: str) -> str:
    cls = registry.params_class(key)
    lines = [f"## `{cls.__name__}` (key `{key}`)", ""]
    for name, group in groups(key):
        doc = " ".join((inspect.getdoc(group) or "").split("\n\n")[0].split())
        lines += ["", f"### `{key}.{name}`: {doc}", "", "| field | default | range | why |", "|---|---|---|---|"]
        why = comments(group)
        lines += [f"| `{f.name}` | {_default(f)} | {_range(f)} | {_why(why.get(f.name, ''))} |" for f in fields(group)]
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> None:
    keys = argv or list(registry.PARAMETERS)
    unknown = [k for k in keys if k not in registry.PARAMETERS]
    if unknown:
        sys.exit(f"parameters_doc: unknown key(s) {', '.join(unknown)}; expected {', '.join(registry.PARAMETERS)}")
    print("\n".join(markdown(k) for k in keys))


if __name__ == "__main__":
    main(sys.argv[1:])
