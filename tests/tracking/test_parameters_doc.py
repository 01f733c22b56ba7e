"""docs/parameters.md lists every field of every registered parameters kind under its group."""

from __future__ import annotations

import re
import sys
from dataclasses import fields
from pathlib import Path

import pytest

from partlab.tracking import registry

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import parameters_doc  # noqa: E402


def _documented() -> dict[str, set[str]]:
    """``key.group`` heading -> the field names of its table."""
    out, current = {}, None
    for line in (ROOT / "docs" / "parameters.md").read_text().splitlines():
        heading = re.match(r"### `(\w+\.\w+)`", line)
        if heading:
            current = out.setdefault(heading.group(1), set())
        elif line.startswith("## "):
            current = None
        elif current is not None:
            row = re.match(r"\| `(\w+)` \|", line)
            if row:
                current.add(row.group(1))
    return out


@pytest.mark.parametrize("key", sorted(registry.PARAMETERS))
def test_every_field_of_every_kind_is_documented(key):
    documented = _documented()
    missing = [f"{key}.{name}.{f.name}" for name, group in parameters_doc.groups(key)
               for f in fields(group) if f.name not in documented.get(f"{key}.{name}", set())]
    assert not missing, f"not in docs/parameters.md (python scripts/parameters_doc.py {key}): {missing}"


def test_the_generator_reads_a_fields_comment_and_shares_it_with_the_next():
    from partlab.tracking.topview.params import TopViewParams

    [(_, dynamics)] = [g for g in parameters_doc.groups("topview") if g[0] == "dynamics"]
    why = parameters_doc.comments(dynamics)
    assert why["position_mm"] == "" and why["hidden_points"] is None and "hand" in why["hidden_scale"]
    table = parameters_doc.markdown("topview")
    assert "| `hidden_scale` | 0.25 | finite and >= 0 and <= 1 |" in table
    assert table.count("### `topview.") == len(parameters_doc.groups("topview")) == \
        len([f for f in fields(TopViewParams) if "group" in f.metadata])
