# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei_regs.vh: the register map for Verilog, included inside a module body by every
Verilog reader of the map (the core, the top, the formal wrappers, the board):

  ENC_QEI_<REG>            byte offset of a register
  ENC_QEI_<REG>_<FIELD>    the field's lsb, and ..._W its width
  ENC_QEI_<ENUM>_<MEMBER>  an enum member's code, sized to its field (ENUM = the RDL enum type
                           without _e: FUNC, RANGE, INDEX_ACTION, Z_EDGE, PROBE_EDGE, EDGE_TYPE);
                           ENC_QEI_<ENUM>_N the number of members
  ENC_QEI_R2H_W, _H2R_W    the widths of the register block's bundles (enc_qei_regs_fields.vh)
  enc_qei_mapped(addr)     1 for a byte address that is a register (bits 1:0 ignored)
"""

from __future__ import annotations

from . import HEADER_V
from .bundle import build


def enum_types(top) -> dict[str, tuple[int, list]]:
    """RDL enum type name (without _e, upper case) -> (field width, members), over every field
    that uses it."""
    out: dict[str, tuple[int, list]] = {}
    for r in top.registers():
        for f in r.fields():
            enc = f.get_property("encode")
            if enc is None:
                continue
            name = enc.type_name.removesuffix("_e").upper()
            width = max(f.width, out.get(name, (0, None))[0])
            out[name] = (width, list(enc))
    return out


def render(top) -> str:
    regs = list(top.registers())
    lines = [*HEADER_V, "// The enc_qei register map for Verilog. Include it inside a module body:",
             '//   `include "enc_qei_regs.vh"',
             "// verilator lint_off UNUSEDPARAM", "",
             "// Register byte offsets"]
    for r in regs:
        lines.append(f"localparam [7:0] ENC_QEI_{r.inst_name} = 8'h{r.address_offset:02X};")
    lines += ["", "// Field positions: lsb, and _W the width"]
    for r in regs:
        for f in r.fields():
            n = f"ENC_QEI_{r.inst_name}_{f.inst_name}"
            lines.append(f"localparam integer {n} = {f.lsb}, {n}_W = {f.width};")
    lines += ["", "// Enum codes (RDL enum types), sized to their fields"]
    for name, (width, members) in enum_types(top).items():
        for m in members:
            lines.append(f"localparam [{width - 1}:0] ENC_QEI_{name}_{m.name.upper()} = "
                         f"{width}'d{m.value};")
        lines.append(f"localparam integer ENC_QEI_{name}_N = {len(members)};")
    b = build(top)
    lines += ["", "// The register block's bundles (rtl/enc_qei_regs.v; the fields by name:",
              "// enc_qei_regs_fields.vh): widths, and the lsb of each field",
              f"localparam integer ENC_QEI_R2H_W = {b.r2h_w}, ENC_QEI_H2R_W = {b.h2r_w};"]
    lines += [f"localparam integer ENC_QEI_R2H_{e.name.upper()} = {e.lsb};" for e in b.r2h]
    lines += [f"localparam integer ENC_QEI_H2R_{e.name.upper()} = {e.lsb};" for e in b.h2r]
    idx = sorted(r.address_offset >> 2 for r in regs)
    lines += ["// verilator lint_on UNUSEDPARAM", "",
              "// 1: the byte address is a register of the map (bits 1:0 ignored)",
              "// verilator lint_off UNUSEDSIGNAL",
              "function enc_qei_mapped;", "  input [7:0] addr;", "  begin",
              "    case (addr[7:2])",
              "      " + ", ".join(f"6'd{i}" for i in idx) + ": enc_qei_mapped = 1'b1;",
              "      default: enc_qei_mapped = 1'b0;", "    endcase", "  end", "endfunction",
              "// verilator lint_on UNUSEDSIGNAL", ""]
    return "\n".join(lines)
