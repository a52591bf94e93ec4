# SPDX-License-Identifier: Apache-2.0
"""`scripts/mutate.py --report --recheck`: equivalence stage 0 applied to a recorded run.

Plain pytest, no simulation. A survivor becomes equivalent only when its mNN.v, as the run wrote
it, is its corner's m00.v byte for byte; a missing or different file keeps it a survivor, and
--recheck without --report is a command-line error.
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import pytest

from enctools.mutation.cli import parse_args, written_unchanged


def _mutant(path: Path) -> SimpleNamespace:
    return SimpleNamespace(path=path)


def test_same_text_is_unchanged(tmp_path):
    (tmp_path / "m00.v").write_text("module m(input a, output y);\n  assign y = a;\nendmodule\n")
    (tmp_path / "m03.v").write_text((tmp_path / "m00.v").read_text())
    assert written_unchanged(_mutant(tmp_path / "m03.v"))


def test_one_character_differs(tmp_path):
    (tmp_path / "m00.v").write_text("module m(input a, output y);\n  assign y = a;\nendmodule\n")
    (tmp_path / "m04.v").write_text("module m(input a, output y);\n  assign y = ~a;\nendmodule\n")
    assert not written_unchanged(_mutant(tmp_path / "m04.v"))


@pytest.mark.parametrize("missing", ["m00.v", "m05.v"])
def test_missing_file_is_not_a_proof(tmp_path, missing):
    for name in ("m00.v", "m05.v"):
        if name != missing:
            (tmp_path / name).write_text("module m; endmodule\n")
    assert not written_unchanged(_mutant(tmp_path / "m05.v"))


def test_recheck_needs_report(capsys):
    with pytest.raises(SystemExit) as e:
        parse_args(["--recheck"])
    assert e.value.code == 2
    assert "--recheck goes with --report" in capsys.readouterr().err
    assert parse_args(["--report", "--recheck"]).recheck
