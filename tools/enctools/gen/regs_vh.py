# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei_regs.vh: the register map for Verilog, included inside a module body by every
Verilog reader of the map (the block, the top, the core, the formal wrappers, the board):

  ENC_QEI_<REG>            byte offset of a register in its page (channel registers: the same in
                           every page; global registers: page 0)
  ENC_QEI_PAGE, ENC_QEI_CHANNELS_MAX   bytes per channel page, pages the map has room for
  ENC_QEI_<REG>_<FIELD>    the field's lsb, and ..._W its width
  ENC_QEI_<REG>_RESET      the register's reset value as the RDL gives it (every field's reset
                           at its lsb, 0 where a field has none), before COUNT_W / TS_W masking
  ENC_QEI_<ENUM>_<MEMBER>  an enum member's code, sized to its field (ENUM = the RDL enum type
                           without _e: FUNC, RANGE, INDEX_ACTION, Z_EDGE, PROBE_EDGE, EDGE_TYPE,
                           PROFILE); ENC_QEI_<ENUM>_N the number of members
  ENC_QEI_R2H_W, _H2R_W, _R2H_CH_W, _H2R_CH_W   bundle widths (global; one channel)
  ENC_QEI_R2H_<NAME>, ENC_QEI_H2R_<NAME>        a bundle field's lsb in its bundle
  enc_qei_mapped(addr, channels)   1 for a byte address (16 bits) that is a register of a build
                                   with that many channels (bits 1:0 ignored)
"""

from __future__ import annotations

from ..regmap import channels_max, nodes, PAGE
from . import HEADER_V
from .bundle import build


def enum_types() -> dict[str, tuple[int, list]]:
    """RDL enum type name (without _e, upper case) -> (field width, members), over every field
    that uses it."""
    out: dict[str, tuple[int, list]] = {}
    for _, _, r in nodes():
        for f in r.fields():
            enc = f.get_property("encode")
            if enc is None:
                continue
            name = enc.type_name.removesuffix("_e").upper()
            width = max(f.width, out.get(name, (0, None))[0])
            out[name] = (width, list(enc))
    return out


def render(top=None) -> str:
    regs = nodes()
    lines = [*HEADER_V, "// The enc_qei register map for Verilog. Include it inside a module body:",
             '//   `include "enc_qei_regs.vh"', "// verilator lint_off UNUSEDPARAM", "",
             "// Pages: channel k's registers at ENC_QEI_PAGE * k + their offset; page 0 also holds",
             "// the global registers",
             f"localparam integer ENC_QEI_PAGE = {PAGE}, ENC_QEI_CHANNELS_MAX = {channels_max()};", "",
             "// Register byte offsets in their page"]
    for g, off, r in regs:
        lines.append(f"localparam [7:0] ENC_QEI_{r.inst_name} = 8'h{off:02X};  // {g}")
    lines += ["", "// Field positions: lsb, and _W the width"]
    for _, _, r in regs:
        for f in r.fields():
            n = f"ENC_QEI_{r.inst_name}_{f.inst_name}"
            lines.append(f"localparam integer {n} = {f.lsb}, {n}_W = {f.width};")
    lines += ["", "// Reset values of the whole registers (before COUNT_W / TS_W masking)"]
    for _, _, r in regs:
        reset = sum((f.get_property("reset") or 0) << f.lsb for f in r.fields())
        lines.append(f"localparam [31:0] ENC_QEI_{r.inst_name}_RESET = 32'h{reset:08X};")
    lines += ["", "// Enum codes (RDL enum types), sized to their fields"]
    for name, (width, members) in enum_types().items():
        for m in members:
            lines.append(f"localparam [{width - 1}:0] ENC_QEI_{name}_{m.name.upper()} = "
                         f"{width}'d{m.value};")
        lines.append(f"localparam integer ENC_QEI_{name}_N = {len(members)};")
    g, c = build("glb"), build("chan")
    lines += ["", "// The register block's bundles (rtl/enc_qei_regs.v; the fields by name:",
              "// enc_qei_regs_fields.vh, enc_qei_chan_fields.vh): widths, and each field's lsb",
              f"localparam integer ENC_QEI_R2H_W = {g.r2h_w}, ENC_QEI_H2R_W = {g.h2r_w};",
              f"localparam integer ENC_QEI_R2H_CH_W = {c.r2h_w}, ENC_QEI_H2R_CH_W = {c.h2r_w};"]
    for b in (g, c):
        lines += [f"localparam integer ENC_QEI_R2H_{e.name.upper()} = {e.lsb};" for e in b.r2h]
        lines += [f"localparam integer ENC_QEI_H2R_{e.name.upper()} = {e.lsb};" for e in b.h2r]
    glb = sorted(off >> 2 for grp, off, _ in regs if grp == "glb")
    chan = sorted(off >> 2 for grp, off, _ in regs if grp == "chan")
    lines += ["// verilator lint_on UNUSEDPARAM", "",
              "// 1: the byte address is a register of a build with `channels` channels",
              "// verilator lint_off UNUSEDSIGNAL",
              "// verilator lint_off VARHIDDEN",
              "function enc_qei_mapped;", "  input [15:0] addr;", "  input integer channels;",
              "  reg glb, chan;", "  begin",
              "    case (addr[7:2])", "      " + ", ".join(f"6'd{i}" for i in glb) + ": glb = 1'b1;",
              "      default: glb = 1'b0;", "    endcase",
              "    case (addr[7:2])", "      " + ", ".join(f"6'd{i}" for i in chan) + ": chan = 1'b1;",
              "      default: chan = 1'b0;", "    endcase",
              "    enc_qei_mapped = (glb & (addr[15:8] == 8'd0)) | (chan & ({24'd0, addr[15:8]} < channels));",
              "  end", "endfunction", "// verilator lint_on VARHIDDEN",
              "// verilator lint_on UNUSEDSIGNAL", ""]
    return "\n".join(lines)
