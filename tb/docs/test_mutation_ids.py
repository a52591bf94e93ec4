# SPDX-License-Identifier: Apache-2.0
"""The ids of scripts/mutate_reviewed.txt (enctools.mutation.data.Mutant.mutant_id).

Plain pytest, no Yosys. A mutant on a function's result wire
(`tstamp$func$<file>:<line>$<n>.$result`) keeps its id in another work directory
(build/mutate/<work>/src/...), with another Yosys counter and with its call site moved to another
line; two call sites with different text get different ids; a run directory that is gone leaves
the file and line, without the work directory; two calls of one function on one line share an
id, and the report's shared_ids names it.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

from enctools.mutation.data import Mutant, wire_key
from enctools.mutation.report import shared_ids

SRC = """module m;
  // a comment
  wire [31:0] te_n = x_enew ? tstamp(x_et, tv) : o_edge;
  wire [31:0] t_s  = tstamp(x_stime, tv);
endmodule
"""


def _write(tmp_path: Path, work: str, text: str) -> str:
    f = tmp_path / "build" / "mutate" / work / "src" / "rtl" / "e.v"
    f.parent.mkdir(parents=True, exist_ok=True)
    f.write_text(text)
    return str(f)


def _mutant(f: str, line: int, counter: int) -> Mutant:
    m = Mutant.__new__(Mutant)
    m.corner = SimpleNamespace(module="e", tag="default")
    m.opts = {"mode": "const0", "cell": f"$sub$x.v:1${counter + 7}", "port": "Y", "portbit": "3",
              "wire": f"tstamp$func${f}:{line}${counter}.$result", "wirebit": "3", "src": []}
    m.command = f"mutate -mode const0 -cell {m.opts['cell']} -wire {m.opts['wire']}"
    return m


def _id(f: str, line: int, counter: int) -> str:
    return _mutant(f, line, counter).mutant_id()


def test_work_directory_and_counter_do_not_matter(tmp_path):
    a = _write(tmp_path, "run_a", SRC)
    b = _write(tmp_path, "run_b", SRC)
    assert _id(a, 3, 2232) == _id(b, 3, 4410)


def test_moved_call_site_keeps_its_id(tmp_path):
    a = _write(tmp_path, "run_a", SRC)
    b = _write(tmp_path, "run_b", SRC.replace("  // a comment\n", "  // a comment\n  // another\n"))
    assert _id(a, 3, 2232) == _id(b, 4, 2232)


def test_call_sites_differ(tmp_path):
    a = _write(tmp_path, "run_a", SRC)
    assert _id(a, 3, 2232) != _id(a, 4, 2233)


def test_gone_file_keeps_line_not_work(tmp_path):
    gone_a = str(tmp_path / "build" / "mutate" / "gone_a" / "src" / "rtl" / "e.v")
    gone_b = str(tmp_path / "build" / "mutate" / "gone_b" / "src" / "rtl" / "e.v")
    key = wire_key(f"tstamp$func${gone_a}:963$2241.$result")
    assert key.endswith("rtl/e.v:963.$result") and "gone_a" not in key
    assert _id(gone_a, 963, 1) == _id(gone_b, 963, 2)


def test_plain_wire_unchanged():
    assert wire_key("x_set") == "x_set"
    assert wire_key("cfg_push_q") == "cfg_push_q"


def test_two_calls_on_one_line_are_reported(tmp_path):
    """Two calls of one function on one line share an id: the report names it."""
    a = _write(tmp_path, "run_a",
               SRC.replace("tstamp(x_stime, tv)", "tstamp(x_stime, tv) + tstamp(x_et, tv)"))
    first, second, other = _mutant(a, 4, 2233), _mutant(a, 4, 2234), _mutant(a, 3, 2232)
    assert first.mutant_id() == second.mutant_id()
    assert shared_ids([first, second, other]) == [first.mutant_id()]
    assert shared_ids([first, other]) == []
