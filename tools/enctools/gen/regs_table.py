# SPDX-License-Identifier: Apache-2.0
"""formal/enc_qei_regs_table.vh: the register map as tables for the register block's proof
(formal/enc_qei_regs_formal.v), which checks one register chosen by the solver (any of them)
against the access rules of its fields. Written from the compiled RDL by code apart from the
block's generator (gen/regblock.py), so the proof checks that generator too.

Per register k (address order), packed vectors indexed by k:
  T_OFFSET  byte offset            T_RESET   reset value of every field
  T_CFG     storage bits (sw=rw)   T_W1C     write-1-to-clear event bits
  T_IN      live bits: bit i reads hw2reg[T_IN_H2R + i - T_IN_LSB]
  T_CONST   constant bits          T_PULSE   write-1 pulse bits (read 0; one at most)
  T_PULSE_R2H  the pulse's reg2hw bit (in its group's bundle; a channel's: within its slice)
  T_CNT     saturating counter bits, +1 on hw2reg[T_CNT_H2R], a write clears
  T_CLR     the hardware-clear bit (one at most), cleared by hw2reg[T_CLR_H2R]
  T_SET_H2R the event bits' set strobes: hw2reg[T_SET_H2R + i] for bit i
  T_SIZED   0 full, 1 COUNT_W low word, 2 COUNT_W high word, 3 TS_W
  T_F_<U>   bits of the optional unit U (TIMING, RANGE, PROBE, PERIOD, EFIFO): they read 0 without it
  T_CHAN    a channel register (1, in every channel's page) or a global one (0, page 0)
  T_IDX     its index in its group (the block's formal views f_view_g / f_view_ch: bits
            [32*T_IDX +: 32] of its group's view)
  T_FIXED   bits of a field a parameter may fix (CTRL.FUNC: FIXED_FUNC)
The coherent pair (COUNT_LO / COUNT_HI) has its own properties: T_COH is 1 and 2 for them.
"""

from __future__ import annotations

from ..regmap import _udp, field_kind, nodes
from . import HEADER_V
from .bundle import build, entry_name

SIZED = {None: 0, "COUNT_W:0": 1, "COUNT_W:1": 2, "TS_W": 3}


def _mask(fields) -> int:
    return sum(((1 << f.width) - 1) << f.lsb for f in fields)


def rows(top=None) -> list[dict]:
    bundles = {g: build(g) for g in ("glb", "chan")}
    out = []
    seen = {"glb": 0, "chan": 0}
    for group, offset, reg in nodes():
        b = bundles[group]
        h2r = {e.name: e.lsb for e in b.h2r}
        fs = list(reg.fields())
        kinds = {f.inst_name: field_kind(f) for f in fs}
        row = {"name": reg.inst_name, "offset": offset, "chan": int(group == "chan"),
               "idx": seen[group],
               "reset": sum((f.get_property("reset") or 0) << f.lsb for f in fs)}
        for k in ("cfg", "intr", "in", "const", "pulse", "counter"):
            row[k] = _mask([f for f in fs if kinds[f.inst_name] == k])
        ins = [f for f in fs if kinds[f.inst_name] == "in"]
        row["in_lsb"], row["in_h2r"] = 0, 0
        if ins:
            side, e, lo = b.where[(reg.inst_name, ins[0].inst_name)]
            row["in_lsb"], row["in_h2r"] = ins[0].lsb, e.lsb + lo
            for f in ins:  # every live bit of the register maps with the same offset
                side, e, lo = b.where[(reg.inst_name, f.inst_name)]
                if e.lsb + lo - f.lsb != row["in_h2r"] - row["in_lsb"]:
                    raise ValueError(f"{reg.inst_name}: live fields not contiguous in hw2reg")
        pulses = [f for f in fs if kinds[f.inst_name] == "pulse"]
        if len(pulses) > 1 or any(f.width != 1 for f in pulses):
            raise ValueError(f"{reg.inst_name}: more than one pulse bit")
        row["pulse_r2h"] = 0
        if pulses:
            side, e, lo = b.where[(reg.inst_name, pulses[0].inst_name)]
            row["pulse_r2h"] = e.lsb + lo
        cnts = [f for f in fs if kinds[f.inst_name] == "counter"]
        row["cnt_h2r"] = h2r[f"{entry_name(reg, cnts[0])}_incr"] if cnts else 0
        clr = [f for f in fs if kinds[f.inst_name] == "cfg" and f.get_property("hwclr")]
        if len(clr) > 1:
            raise ValueError(f"{reg.inst_name}: more than one hardware-cleared field")
        row["clr"] = _mask(clr)
        row["clr_h2r"] = h2r[f"{entry_name(reg, clr[0])}_clr"] if clr else 0
        row["set_h2r"] = h2r.get(f"{reg.inst_name.lower()}_set", 0)
        sized = {f.get_property("sized_by") for f in fs}
        if len(sized) > 1:
            raise ValueError(f"{reg.inst_name}: fields sized differently")
        row["sized"] = SIZED[sized.pop()]
        for n in ("TIMING", "RANGE", "PROBE", "PERIOD", "EFIFO"):
            row[f"f_{n.lower()}"] = _mask([f for f in fs if (_udp(f, "feature") or
                                                             _udp(reg, "feature")) == n])
        row["fixed"] = _mask([f for f in fs if f.get_property("fixed_by")])
        row["coh"] = {"lo": 1, "hi": 2}.get(next((f.get_property("coherent") for f in fs
                                                  if kinds[f.inst_name] == "coherent"), None), 0)
        seen[group] += 1
        out.append(row)
    return out


def _table(name: str, width: int, values: list[int]) -> str:
    n = len(values)
    body = ", ".join(f"{width}'h{v:0{(width + 3) // 4}X}" for v in reversed(values))
    return f"localparam [{width * n - 1}:0] ENC_QEI_T_{name} = {{{body}}};"


def render(top) -> str:
    rs = rows(top)
    lines = [*HEADER_V, "// The enc_qei register map as tables for formal/enc_qei_regs_formal.v: see",
             "// tools/enctools/gen/regs_table.py for what each holds. Entry k (address order) is",
             "// bits [k*W +: W] of each table; the first entry is the rightmost.",
             "// verilator lint_off UNUSEDPARAM",
             f"localparam integer ENC_QEI_T_N = {len(rs)};",
             f"localparam integer ENC_QEI_T_NG = {sum(1 - r['chan'] for r in rs)}, "
             f"ENC_QEI_T_NC = {sum(r['chan'] for r in rs)};  // global / channel registers"]
    for name, key, width in (("OFFSET", "offset", 8), ("RESET", "reset", 32), ("CFG", "cfg", 32),
                             ("W1C", "intr", 32), ("IN", "in", 32), ("IN_LSB", "in_lsb", 8),
                             ("IN_H2R", "in_h2r", 16), ("CONST", "const", 32),
                             ("PULSE", "pulse", 32), ("PULSE_R2H", "pulse_r2h", 16),
                             ("CNT", "counter", 32),
                             ("CNT_H2R", "cnt_h2r", 16), ("CLR", "clr", 32),
                             ("CLR_H2R", "clr_h2r", 16), ("SET_H2R", "set_h2r", 16),
                             ("SIZED", "sized", 2), ("F_TIMING", "f_timing", 32),
                             ("F_RANGE", "f_range", 32), ("F_PROBE", "f_probe", 32),
                             ("F_PERIOD", "f_period", 32), ("F_EFIFO", "f_efifo", 32), ("CHAN", "chan", 1), ("IDX", "idx", 8),
                             ("FIXED", "fixed", 32),
                             ("COH", "coh", 2)):
        lines.append(_table(name, width, [r[key] for r in rs]))
    lines += ["// verilator lint_on UNUSEDPARAM", ""]
    return "\n".join(lines)
