# SPDX-License-Identifier: Apache-2.0
"""doc/testplan.md's "Gaps, in one list" is the list of the rows marked GAP.

Plain pytest, no simulator. A row of the plan's tables (``| ID | clause | tests | tools |``) whose
text says **GAP** or **partial GAP** must have a line in the list at the end (``- **ID** ...``),
and every line of the list must name a row that says so: a gap closed in its row and left in the
list fails, as does a row that owns up to a gap the list does not carry.
"""

from __future__ import annotations

import re
from pathlib import Path

TOP = Path(__file__).resolve().parents[2]
PLAN = TOP / "doc" / "testplan.md"
LIST = "## Gaps, in one list"


def rows_and_list(text: str) -> tuple[dict[str, str], list[str]]:
    """(row ID -> row text, the IDs the gap list names, in order)."""
    head, _, tail = text.partition(LIST)
    assert tail, f"{PLAN.name}: no '{LIST}' section"
    rows = {}
    for line in head.splitlines():
        m = re.match(r"\|\s*([A-Z][A-Za-z0-9.]*[0-9x])\s*\|", line)
        if m:
            assert m.group(1) not in rows, f"{PLAN.name}: row {m.group(1)} twice"
            rows[m.group(1)] = line
    section = tail.split("\n## ", 1)[0]
    named = [i.strip() for m in re.finditer(r"^- \*\*([^*]+)\*\*", section, re.M)
             for i in m.group(1).split(",")]
    return rows, named


def marks_gap(row: str) -> bool:
    return re.search(r"\*\*(partial )?GAP\b", row, re.I) is not None


def problems(rows: dict[str, str], named: list[str]) -> list[str]:
    """What is wrong between the rows and the gap list; [] when they agree."""
    out = []
    unknown = [i for i in named if i not in rows]
    if unknown:
        out.append(f"the gap list names rows that do not exist: {unknown}")
    closed = [i for i in named if i in rows and not marks_gap(rows[i])]
    if closed:
        out.append(f"the gap list names rows that no longer say GAP: {closed}")
    missing = [i for i, r in rows.items() if marks_gap(r) and i not in named]
    if missing:
        out.append(f"rows that say GAP but are not in the gap list: {missing}")
    twice = sorted({i for i in named if named.count(i) > 1})
    if twice:
        out.append(f"the gap list names rows twice: {twice}")
    return out


def test_gap_list_matches_the_rows():
    rows, named = rows_and_list(PLAN.read_text())
    assert len(rows) > 100, f"{PLAN.name}: only {len(rows)} rows found (the row pattern is wrong)"
    assert problems(rows, named) == []


def test_the_check_can_fail():
    """The check on a made-up plan: a closed gap left in the list, a gap missing from it, a row
    that does not exist and one named twice."""
    plan = ("| A1 | x | **Partial GAP:** y | z |\n| A2 | x | all | z |\n| A3 | x | **GAP** | z |\n"
            f"\n{LIST}\n\n- **A2** closed\n- **A3, A9** open\n- **A3** again\n")
    rows, named = rows_and_list(plan)
    assert named == ["A2", "A3", "A9", "A3"]
    found = problems(rows, named)
    assert any("do not exist: ['A9']" in p for p in found), found
    assert any("no longer say GAP: ['A2']" in p for p in found), found
    assert any("not in the gap list: ['A1']" in p for p in found), found
    assert any("twice: ['A3']" in p for p in found), found
