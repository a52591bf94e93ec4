# SPDX-License-Identifier: Apache-2.0
"""doc/results/synth_results.md agrees with itself, and a partial `scripts/synth.py --update`
keeps it so.

Plain pytest, no synthesis. The table file holds the measured rows and a section derived from
them (the edge FIFO's cost: each EFIFO_LOG2 row against the same build without it). The derived
section must be what enctools.synth.report computes from the whole table; a run that replaces
some rows (--update) must write it from the kept rows and the new ones alike, not from the new
ones alone.
"""

from __future__ import annotations

import copy
from pathlib import Path

from enctools.synth.blocks import BLOCKS, RESULTS_MD
from enctools.synth.report import efifo_table, kept_rows, markdown, previous_rows

TOP = Path(__file__).resolve().parents[2]


def table_rows(path: Path) -> list[dict]:
    kept = kept_rows(path)
    rows = [kept.get((b.name, b.param_text, b.part)) for b in BLOCKS]
    return [r for r in rows if r is not None]


def test_results_file_is_what_its_rows_give():
    """The committed file, written again from its own rows, is unchanged (derived section
    included): no hand edits, no derived rows from a partial run."""
    assert RESULTS_MD.exists(), f"{RESULTS_MD.relative_to(TOP)} is missing: run `make synth`"
    rows = table_rows(RESULTS_MD)
    assert markdown(rows) == RESULTS_MD.read_text(), (
        f"{RESULTS_MD.relative_to(TOP)} differs from what its rows give (enctools.synth.report.markdown): "
        "a hand edit, or a --update that wrote the derived FIFO section from part of the table")


def test_every_fifo_row_has_its_base():
    """Each EFIFO_LOG2 row of the table is in the FIFO section (its build without the FIFO is a row)."""
    rows = table_rows(RESULTS_MD)
    fifo_rows = [r for r in rows if "EFIFO_LOG2=" in r["params"] and r["LUT4"].isdigit()]
    section = [l for l in efifo_table(rows) if l.startswith("| enc_qei")]
    assert fifo_rows, "the table has no edge FIFO rows"
    assert len(section) == len(fifo_rows)


def test_partial_update_keeps_the_derived_section(tmp_path):
    """What --update does (kept rows plus the replaced ones): replacing one engine row changes its
    FIFO line and keeps every other one (a section written from the replaced rows alone would lose
    the others)."""
    rows = table_rows(RESULTS_MD)
    before = [l for l in efifo_table(rows) if l.startswith("| enc_qei")]
    i = next(i for i, r in enumerate(rows) if "ENGINE=1" in r["params"] and "EFIFO_LOG2" not in r["params"]
             and r["part"].startswith("HX8K"))
    changed = copy.deepcopy(rows)
    changed[i]["LUT4"] = str(int(changed[i]["LUT4"]) - 100)
    out = tmp_path / "synth_results.md"
    out.write_text(markdown(changed))
    after = [l for l in efifo_table(table_rows(out)) if l.startswith("| enc_qei")]
    assert len(after) == len(before)
    differ = [(a, b) for a, b in zip(before, after) if a != b]
    assert len(differ) == 1, differ
    assert "ENGINE=1" in differ[0][0] and "HX8K" in differ[0][0]


def test_previous_rows_are_the_results_rows():
    """What a run compares its rows with (report.previous_rows): the results table's LUT4, not the
    FIFO section's entries, whose rows share the module, params and part."""
    before = previous_rows(RESULTS_MD)
    for r in table_rows(RESULTS_MD):
        if r["LUT4"].isdigit():
            assert before[(r["module"], r["params"], r["part"])][0] == int(r["LUT4"])
