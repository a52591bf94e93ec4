#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Generate everything that depends on the enc_qei register map from rtl/enc_qei.rdl.

Outputs (all committed):
  sw/enc_qei_regs.h    C header (peakrdl-cheader)
  doc/enc_qei_regs.md  register reference (peakrdl-markdown)
  rtl/enc_qei_regs.v   the register block of the peripheral: address decode, storage, byte
                       enables, write-1-to-clear, counters and read multiplexer, generated from the
                       compiled RDL (a Verilog module rather than an `include file: every flow
                       here compiles rtl/*.v without include paths)

  scripts/gen_regs.py           regenerate
  scripts/gen_regs.py --check   exit 1, naming the stale file(s), if a committed output differs

Field kinds the Verilog generator understands (anything else stops it with a message):
  sw=r  hw=na            constant (the reset value)
  sw=r  hw=w             live value from the hardware: input <reg>_<field>
  sw=rw hw=r             configuration storage: output <reg>_<field>
  ... with hwclr         plus input <reg>_<field>_hwclr (software write wins in the same clock)
  sw=w  singlepulse      output <reg>_<field>: a one-clock pulse when 1 is written
  intr, onwrite=woclr    event bit: input <reg>_<field>_set (wins over a clear in the same clock)
  counter incrsaturate onwrite=wclr   saturating counter: input <reg>_<field>_incr; a write clears
  external register      held by the hardware: input <reg>_rdata, outputs <reg>_rd (read strobe),
                         <reg>_wr (write strobe) and <reg>_wdata (written word merged with
                         <reg>_rdata on the byte lanes not enabled)
User property sized_by ("COUNT_W:0", "COUNT_W:1", "TS_W"): storage keeps only the bits of the
value; the others read 0 and ignore writes.
User property feature (on a register, e.g. "TIMING"): a module parameter of that name (default 1);
with 0 the register reads 0, ignores writes, its outputs are 0 (its storage is left out) and it
still answers without an error.
User property fixed_by (on a cfg field, e.g. "FIXED_FUNC"): a module parameter of that name
(default -1); when >= 0 the field reads and outputs that value and ignores writes.
"""

from __future__ import annotations

import argparse
import re
import difflib
import sys
import tempfile
from pathlib import Path

from ..paths import TOP
from ..regmap import compile_rdl, field_kind
RDL = TOP / "rtl" / "enc_qei.rdl"
OUT_H = TOP / "sw" / "enc_qei_regs.h"
OUT_MD = TOP / "doc" / "enc_qei_regs.md"
OUT_V = TOP / "rtl" / "enc_qei_regs.v"
OUT_VH = TOP / "rtl" / "enc_qei_regs.vh"
OUT_PARAMS = TOP / "rtl" / "enc_params.vh"

SIZE_MASKS = {"COUNT_W:0": "SZ_COUNT_LO", "COUNT_W:1": "SZ_COUNT_HI", "TS_W": "SZ_TS"}


def vname(*parts: str) -> str:
    return "_".join(p.lower() for p in parts)


def verilog(top) -> str:
    regs = list(top.registers())
    features = sorted({r.get_property("feature") for r in regs if r.get_property("feature")})
    fixers = sorted({f.get_property("fixed_by") for r in regs for f in r.fields()
                     if f.get_property("fixed_by")})
    ports: list[str] = []
    body: list[str] = []
    rd_cases: list[str] = []
    addr_params: list[str] = []

    for r in regs:
        idx = r.address_offset >> 2
        rn = r.inst_name
        feat = r.get_property("feature")
        if feat and r.external:
            raise SystemExit(f"gen_regs: external register {rn} cannot have a feature")
        addr_params.append(f"  localparam [5:0] A_{rn} = 6'd{idx};  // 0x{r.address_offset:02X}")
        rd_lines: list[str] = []
        if r.external:
            base = vname(rn)
            (fld,) = list(r.fields())
            if fld.lsb != 0 or fld.width != 32:
                raise SystemExit(f"gen_regs: external register {rn} must have one 32-bit field")
            ports += [f"    input  wire [31:0] {base}_rdata,  // {rn}: value held by the hardware",
                      f"    output wire        {base}_rd,     // {rn}: read strobe",
                      f"    output wire        {base}_wr,     // {rn}: write strobe",
                      f"    output wire [31:0] {base}_wdata,  // {rn}: written word (merged byte lanes)"]
            sz = SIZE_MASKS.get(fld.get_property("sized_by"), None)
            m = f"(bmask & {sz})" if sz else "bmask"
            body += [f"  assign {base}_rd    = rd_sel_q[A_{rn}];",
                     f"  assign {base}_wr    = wr_sel_q[A_{rn}] & (|wstrb_q);",
                     f"  assign {base}_wdata = ({base}_rdata & ~{m}) | (wdata_q & {m});", ""]
            rd_lines.append(f"        rd_d = {base}_rdata;")
            rd_cases.append((rn, rd_lines))
            continue
        for f in r.fields():
            kind = field_kind(f)
            w, lsb, msb = f.width, f.lsb, f.msb
            name = vname(rn, f.inst_name)
            rng = f"[{w - 1}:0] " if w > 1 else ""
            sl = f"[{msb}:{lsb}]"
            reset = f.get_property("reset")
            sz = SIZE_MASKS.get(f.get_property("sized_by"), None)
            desc = f"{rn}.{f.inst_name}"
            wmask = f"bmask{sl}" + (f" & {sz}{sl}" if sz else "")
            rst_val = f"{w}'h{(reset or 0):X}" + (f" & {sz}{sl}" if sz else "")
            if kind == "const":
                rd_lines.append(f"        rd_d{sl} = {w}'h{reset:X};  // {desc}")
            elif kind == "in":
                ports.append(f"    input  wire {rng}{name},  // {desc}")
                rd_lines.append(f"        rd_d{sl} = {name};")
            elif kind in ("cfg", "intr", "counter"):
                q = f"{name}_q"
                body.append(f"  reg {rng}{q};  // {desc}")
                ports.append(f"    output wire {rng}{name},  // {desc}")
                fix = f.get_property("fixed_by")
                if fix and kind != "cfg":
                    raise SystemExit(f"gen_regs: fixed_by on {desc}: only for sw=rw hw=r fields")
                rdval = q
                if fix:
                    rdval = f"(({fix} >= 0) ? {fix}[{w - 1}:0] : {q})"
                val = f"(({feat} != 0) ? {rdval} : {w}'d0)" if feat else rdval
                body.append(f"  assign {name} = {val};")
                wr = f"wr_req & (req_addr[7:2] == A_{rn})"
                body.append("  always @(posedge clk) begin")
                body.append(f"    if (rst) begin")
                body.append(f"      {q} <= {rst_val};")
                if kind == "cfg":
                    hwclr = f.get_property("hwclr")
                    if hwclr:
                        ports.append(f"    input  wire {name}_hwclr,  // {desc}: hardware clear")
                        body.append(f"    end else if ({wr} & (|({wmask}))) begin")
                        body.append(f"      {q} <= ({q} & ~({wmask})) | (req_wdata{sl} & {wmask});")
                        body.append(f"    end else if ({name}_hwclr) begin")
                        body.append(f"      {q} <= {w}'d0;")
                    else:
                        body.append(f"    end else if ({wr}) begin")
                        body.append(f"      {q} <= ({q} & ~({wmask})) | (req_wdata{sl} & {wmask});")
                elif kind == "intr":
                    ports.append(f"    input  wire {rng}{name}_set,  // {desc}: set (one clock)")
                    body.append("    end else begin")
                    body.append(f"      {q} <= ({q} & ~({{{w}{{{wr}}}}} & req_wdata{sl} & {wmask})) "
                                f"| {name}_set;")
                else:  # counter
                    ports.append(f"    input  wire {name}_incr,  // {desc}: count one (saturating)")
                    body.append(f"    end else if ({wr} & (|req_wstrb)) begin")
                    body.append(f"      {q} <= {{{{{w - 1}{{1'b0}}}}, {name}_incr}};")
                    body.append(f"    end else if ({name}_incr & ~(&{q})) begin")
                    body.append(f"      {q} <= {q} + {w}'d1;")
                body.append("    end")
                body.append("  end")
                body.append("")
                rd_lines.append(f"        rd_d{sl} = {rdval};")
            elif kind == "pulse":
                q = f"{name}_q"
                body.append(f"  reg {rng}{q};  // {desc}: one-clock pulse")
                ports.append(f"    output wire {rng}{name},  // {desc}: one-clock pulse on a write of 1")
                body.append(f"  assign {name} = " + (f"(({feat} != 0) ? {q} : {w}'d0);" if feat else f"{q};"))
                body.append("  always @(posedge clk) begin")
                # (an if, not an AND with the strobe: an unknown request in simulation leaves 0)
                body.append(f"    if (rst) {q} <= {w}'d0;")
                body.append(f"    else if (wr_req & (req_addr[7:2] == A_{rn})) {q} <= req_wdata{sl} & {wmask};")
                body.append(f"    else {q} <= {w}'d0;")
                body.append("  end")
                body.append("")
            else:
                raise AssertionError(kind)
        if feat and rd_lines:
            rd_lines = [f"        if ({feat} != 0) begin"] + ["  " + l for l in rd_lines] + ["        end"]
        rd_cases.append((rn, rd_lines))

    idxs = [r.address_offset >> 2 for r in regs]
    if sorted(idxs) != list(range(len(idxs))):
        raise SystemExit("gen_regs: register offsets must be contiguous from 0 (one-hot read select)")
    nsel = len(idxs)
    sel_lines = [f"  assign sel_d[A_{r.inst_name}] = (req_addr[7:2] == A_{r.inst_name});" for r in regs]

    params = [f"    parameter integer {p} = 1,  // 1: {p.lower()} registers present, 0: read 0 (checked by enc_qei)"
              for p in features]
    params += [f"    parameter integer {p} = -1,  // -1: the field is storage, >= 0: fixed to it (checked by enc_qei)"
               for p in fixers]

    lines = [
        "// SPDX-License-Identifier: Apache-2.0",
        "// enc_qei_regs -- the register block of enc_qei: address decode, storage, byte enables,",
        "// write-1-to-clear events, saturating counters and the read multiplexer.",
        "//",
        "// GENERATED by scripts/gen_regs.py from rtl/enc_qei.rdl -- do not edit; run `make regs`.",
        "//",
        "// Request/response port: a request is one clock of req_valid with req_write, req_addr (byte",
        "// address, bits 1:0 ignored), req_wdata and req_wstrb. The response comes two clocks later:",
        "// one clock of resp_valid with resp_rdata (0 for writes) and resp_err (unmapped offset: reads",
        "// 0, writes nothing). The request is registered first (its address decoded one-hot): writes",
        "// and read side effects (external registers' _rd / _wr strobes) take effect in the clock",
        "// after the request, and a read takes its data in that clock too (Fmax: every path starts",
        "// from a register). One request at a time: a new one may start in the clock after resp_valid",
        "// (the bus adapters see to it).",
        "`default_nettype none",
        "",
        "module enc_qei_regs #(",
        *params,
        "    parameter integer COUNT_W = 32,  // counter width, 8 .. 64 (checked by enc_qei)",
        "    parameter integer TS_W    = 32   // timebase width, 16 .. 32 (checked by enc_qei)",
        ") (",
        "    input  wire        clk,",
        "    input  wire        rst,         // synchronous, active high",
        "    input  wire        req_valid,   // one-clock request",
        "    input  wire        req_write,   // 1 = write, 0 = read",
        "    // verilator lint_off UNUSEDSIGNAL",
        "    input  wire [7:0]  req_addr,    // byte address (bits 1:0 ignored)",
        "    // verilator lint_on UNUSEDSIGNAL",
        "    input  wire [31:0] req_wdata,",
        "    input  wire [3:0]  req_wstrb,   // byte enables",
        "    output wire        resp_valid,  // two clocks after req_valid",
        "    output wire [31:0] resp_rdata,",
        "    output wire        resp_err,    // unmapped offset",
    ]
    ports[-1] = ports[-1].replace(",  //", "   //", 1)
    lines += ports
    lines += [
        ");",
        "",
        "  // Register offsets (word index = byte offset / 4)",
        *addr_params,
        "",
        "  // Bits of the value a sized field holds (the others read 0 and ignore writes)",
        "  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);",
        "  localparam [31:0] SZ_COUNT_LO = SZ_COUNT[31:0];",
        "  localparam [31:0] SZ_COUNT_HI = SZ_COUNT[63:32];",
        "  localparam [31:0] SZ_TS = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);",
        "",
        "  // ---- request register: the address decoded one-hot, data and byte enables -------------",
        f"  wire [{nsel - 1}:0] sel_d;  // bit A_x: the request's address is register x",
        *sel_lines,
        "",
        f"  reg [{nsel - 1}:0] rd_sel_q;  // bit A_x: a read of register x (this clock)",
        f"  reg [{nsel - 1}:0] wr_sel_q;  // bit A_x: a write of register x (this clock)",
        "  reg        err_q;       // the request was to an unmapped offset",
        "  reg        pend_q;      // a request was made last clock",
        "  reg [31:0] wdata_q;",
        "  reg [3:0]  wstrb_q;",
        "",
        "  always @(posedge clk) begin",
        "    if (rst) begin",
        f"      rd_sel_q <= {{{nsel}{{1'b0}}}};",
        f"      wr_sel_q <= {{{nsel}{{1'b0}}}};",
        "      err_q    <= 1'b0;",
        "      pend_q   <= 1'b0;",
        "    end else begin",
        f"      rd_sel_q <= (req_valid & ~req_write) ? sel_d : {{{nsel}{{1'b0}}}};",
        f"      wr_sel_q <= (req_valid & req_write) ? sel_d : {{{nsel}{{1'b0}}}};",
        f"      err_q    <= req_valid & (sel_d == {{{nsel}{{1'b0}}}});",
        "      pend_q   <= req_valid;",
        "    end",
        "  end",
        "",
        "  always @(posedge clk) begin",
        "    wdata_q <= req_wdata;",
        "    wstrb_q <= req_wstrb;",
        "  end",
        "",
        "  wire [31:0] bmask = {{8{wstrb_q[3]}}, {8{wstrb_q[2]}}, {8{wstrb_q[1]}}, {8{wstrb_q[0]}}};",
        "",
    ]
    body = [re.sub(r"wr_req & \(req_addr\[7:2\] == (A_\w+)\)", r"wr_sel_q[\1]", l)
            .replace("req_wdata", "wdata_q").replace("req_wstrb", "wstrb_q") for l in body]
    lines += body
    lines += [
        "  // ---- read multiplexer (one select bit at most: AND-OR) and response -------------------",
        "  reg [31:0] rd_d;",
        "",
        "  always @(*) begin",
        "    rd_d = 32'd0;",
    ]
    for rn, rd_lines in rd_cases:
        if not rd_lines:
            continue
        lines.append(f"    if (rd_sel_q[A_{rn}]) begin")
        lines += [re.sub(r"^(\s*)rd_d(\S*) = (.*?);(\s*//.*)?$", r"\1rd_d\2 = rd_d\2 | \3;\4", l[2:])
                  for l in rd_lines]
        lines.append("    end")
    lines += [
        "  end",
        "",
        "  reg        resp_valid_q;",
        "  reg [31:0] resp_rdata_q;",
        "  reg        resp_err_q;",
        "",
        "  always @(posedge clk) begin",
        "    if (rst) begin",
        "      resp_valid_q <= 1'b0;",
        "      resp_rdata_q <= 32'd0;",
        "      resp_err_q   <= 1'b0;",
        "    end else begin",
        "      resp_valid_q <= pend_q;",
        "      resp_rdata_q <= rd_d;",
        "      resp_err_q   <= err_q;",
        "    end",
        "  end",
        "",
        "  assign resp_valid = resp_valid_q;",
        "  assign resp_rdata = resp_rdata_q;",
        "  assign resp_err   = resp_err_q;",
        "",
        "endmodule",
        "",
        "`default_nettype wire",
        "",
    ]
    return "\n".join(lines)


def c_header(top, path: Path) -> None:
    from peakrdl_cheader.c_standards import CStandard
    from peakrdl_cheader.exporter import CHeaderExporter

    # gnu99: valid C99 with GNU extensions (no C11 static_assert); gcc -std=c99 and later accept it
    CHeaderExporter().export(top, str(path), std=CStandard.gnu99)
    text = path.read_text()
    # peakrdl-cheader gives masks, positions and the register struct; add byte offsets and the
    # enum values (it exports neither) inside the include guard.
    extra = ["", "// Register byte offsets"]
    for r in top.registers():
        extra.append(f"#define ENC_QEI_{r.inst_name}_OFFSET 0x{r.address_offset:02X}u")
    extra += ["", "// Field enumerations: ENC_QEI__<REG>__<FIELD>__<member>"]
    for r, f, enum in enum_fields(top):
        for m in enum:
            extra.append(f"#define ENC_QEI__{r.inst_name}__{f.inst_name}__{m.name.upper()} {m.value}u")
    tail = "#ifdef __cplusplus\n}\n#endif\n\n#endif /* ENC_QEI_REGS_H */"
    assert text.rstrip().endswith(tail), "unexpected peakrdl-cheader output layout"
    text = text.rstrip()[: -len(tail)] + "\n".join(extra) + "\n\n" + tail + "\n"
    head = ("// SPDX-License-Identifier: Apache-2.0\n"
            "// GENERATED by scripts/gen_regs.py from rtl/enc_qei.rdl -- do not edit; run `make regs`.\n")
    path.write_text(head + text)


def enum_fields(top):
    """(register, field, enum type) for every field encoded by a SystemRDL enum."""
    out = []
    for r in top.registers():
        for f in r.fields():
            enum = f.get_property("encode")
            if enum is not None:
                out.append((r, f, enum))
    return out


def markdown(top, path: Path) -> None:
    from peakrdl_markdown import MarkdownExporter

    MarkdownExporter().export(top, str(path))
    text = path.read_text()
    head = ("<!-- SPDX-License-Identifier: Apache-2.0 -->\n"
            "<!-- GENERATED by scripts/gen_regs.py from rtl/enc_qei.rdl -- do not edit; run `make regs`. -->\n\n")
    enums = ["", "## Field enumerations", ""]
    for r, f, enum in enum_fields(top):
        enums += [f"### {r.inst_name}.{f.inst_name}", "", "| Value | Name | Meaning |", "|---|---|---|"]
        for m in enum:
            desc = (m.rdl_desc or "").replace("|", "/").replace("\n", " ")
            enums.append(f"| {m.value} | `{m.name}` | {desc} |")
        enums.append("")
    path.write_text(head + text.rstrip() + "\n" + "\n".join(enums))


def generate(out_dir: Path | None = None) -> dict[Path, Path]:
    """Write every output; with out_dir, into it instead of the tree. Returns {tree path: written}."""
    top = compile_rdl()
    targets = {OUT_H: c_header, OUT_MD: markdown}
    written = {}
    for dest, fn in targets.items():
        path = (out_dir / dest.name) if out_dir else dest
        path.parent.mkdir(parents=True, exist_ok=True)
        fn(top, path)
        written[dest] = path
    vpath = (out_dir / OUT_V.name) if out_dir else OUT_V
    vpath.write_text(verilog(top))
    written[OUT_V] = vpath
    from . import regs_vh
    vh = (out_dir / OUT_VH.name) if out_dir else OUT_VH
    vh.write_text(regs_vh.render(top))
    written[OUT_VH] = vh
    from . import params_vh
    pv = (out_dir / OUT_PARAMS.name) if out_dir else OUT_PARAMS
    pv.write_text(params_vh.render())
    written[OUT_PARAMS] = pv
    return written


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true",
                    help="do not write; exit 1 if a committed output differs from what the RDL generates")
    args = ap.parse_args()
    if not args.check:
        for dest in generate():
            print(f"gen_regs: wrote {dest.relative_to(TOP)}")
        return 0
    stale = check()
    if stale:
        print("gen_regs --check: stale (run `make regs`): " + ", ".join(stale), file=sys.stderr)
        return 1
    print("gen_regs --check: every output matches rtl/enc_qei.rdl")
    return 0


def check(outputs: dict[Path, Path] | None = None) -> list[str]:
    """Names of the committed outputs that differ from what the RDL generates (with a diff on
    stderr). ``outputs`` maps each output to the file to compare (default: itself)."""
    stale = []
    with tempfile.TemporaryDirectory() as tmp:
        for dest, fresh in generate(Path(tmp)).items():
            rel = dest.relative_to(TOP)
            dest = (outputs or {}).get(dest, dest)
            if not dest.exists():
                stale.append(f"{rel} (missing)")
                continue
            old, new = dest.read_text(), fresh.read_text()
            if old != new:
                diff = difflib.unified_diff(old.splitlines(), new.splitlines(), str(rel), "generated",
                                            lineterm="", n=1)
                print("\n".join(list(diff)[:40]), file=sys.stderr)
                stale.append(str(rel))
    return stale


if __name__ == "__main__":
    sys.exit(main())
