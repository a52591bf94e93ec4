# SPDX-License-Identifier: Apache-2.0
"""The field logic of one register group of enc_qei_regs (the global registers, or one channel's
page): storage, its bundle outputs, and what a read answers.

Field kinds (enctools.regmap.field_kind; anything else stops the generator with a message):
  const    sw=r  hw=na          reads its reset value
  in       sw=r  hw=w           reads a live value from hw2reg; with swacc, reg2hw <reg>_rd is a
                                one-clock strobe in the clock a read of the register takes its data
  cfg      sw=rw hw=r           storage, to reg2hw; with hwclr, hw2reg <entry>_clr clears it
                                (a software write to its lane in the same clock wins)
  pulse    sw=w  singlepulse    a one-clock reg2hw pulse when 1 is written
  intr     intr, woclr          a pending event: set by hw2reg <reg>_set (wins over a clear in the
                                same clock), cleared by writing 1
  counter  counter, incrsaturate, wclr   saturating, +1 on hw2reg <entry>_incr; a write clears it
  coherent (user property, COUNT_LO / COUNT_HI): the count's 32-bit halves. Reading COUNT_LO
           returns the live count's low word and latches its high word, which COUNT_HI reads;
           a COUNT_HI write stages a word (byte lanes not enabled keep the staged bytes); a
           COUNT_LO write (at least one lane) pulses count_load with count_load_value = {staged
           word, written word}, the live count's bytes in the lanes not enabled.
User properties: sized_by (COUNT_W:0 / COUNT_W:1 / TS_W: storage keeps the value's bits only,
the others read 0 and ignore writes); feature (on a register or a field: a module parameter;
with 0 it reads 0, ignores writes and gives 0 to reg2hw, still without a bus error); fixed_by (a
module parameter: when >= 0 the field reads and gives that value and ignores writes).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..regmap import _udp, field_kind

SIZE_MASKS = {"COUNT_W:0": "SZ_COUNT_LO", "COUNT_W:1": "SZ_COUNT_HI", "TS_W": "SZ_TS"}


@dataclass
class Out:
    logic: list = field(default_factory=list)


class Fields:
    def __init__(self, regs, bundles, wr, rd, r2h: str, h2r: str):
        self.regs, self.b = regs, bundles
        self.wr, self.rd = wr, rd  # k -> the select expression of register k
        self.r2h_name, self.h2r_name = r2h, h2r
        self.decls: list[str] = []
        self.body: list[str] = []
        self.reads: list[tuple[str, list[str]]] = []
        self.driven: list[tuple[int, int]] = []  # reg2hw bit ranges driven (lo, hi)

    # ---- bundle slices -------------------------------------------------------------------------
    def r2h(self, reg, f) -> str:
        side, e, lsb = self.b.where[(reg.inst_name, f.inst_name)]
        lo = e.lsb + lsb
        self.driven.append((lo, lo + f.width - 1))
        return f"{self.r2h_name}[{lo + f.width - 1}:{lo}]" if f.width > 1 else f"{self.r2h_name}[{lo}]"

    def r2h_entry(self, name: str) -> str:
        e = self.b.entry("r2h", name)
        self.driven.append((e.lsb, e.lsb + e.width - 1))
        return f"{self.r2h_name}{e.rng}"

    def h2r(self, name: str, lo: int = 0, width: int | None = None) -> str:
        e = self.b.entry("h2r", name)
        w = e.width if width is None else width
        return f"{self.h2r_name}[{e.lsb + lo + w - 1}:{e.lsb + lo}]" if w > 1 else f"{self.h2r_name}[{e.lsb + lo}]"

    def emit(self, *lines: str) -> None:
        self.body += list(lines)

    @staticmethod
    def rng(w: int) -> str:
        return f"[{w - 1}:0] " if w > 1 else ""

    @staticmethod
    def gate(feat, val: str, w: int) -> str:
        return f"(({feat} != 0) ? {val} : {w}'d0)" if feat else val

    # ---- one register --------------------------------------------------------------------------
    def register(self, k: int, reg) -> None:
        rn = reg.inst_name
        reads: list[str] = []
        for f in reg.fields():
            kind = field_kind(f)
            feat = _udp(f, "feature") or _udp(reg, "feature")
            w, sl = f.width, f"[{f.msb}:{f.lsb}]"
            name = f"{rn}_{f.inst_name}".lower()
            sz = SIZE_MASKS.get(f.get_property("sized_by"))
            wmask = f"bmask{sl}" + (f" & {sz}{sl}" if sz else "")
            reset = f"{w}'h{(f.get_property('reset') or 0):X}" + (f" & {sz}{sl}" if sz else "")
            read = None
            if kind == "const":
                read = f"{w}'h{f.get_property('reset'):X}"
            elif kind == "in":
                side, e, lo = self.b.where[(rn, f.inst_name)]
                read = self.h2r(e.name, lo, w)
                if f.get_property("swacc"):
                    self.emit(f"  // {rn}: a read of it is a strobe to the hardware (swacc: a read side effect)",
                              f"  assign {self.r2h_entry(rn.lower() + '_rd')} = {self.gate(feat, self.rd(k), 1)};", "")
            elif kind == "coherent":
                read = self.coherent(k, f, wmask)
            elif kind == "pulse":
                q = f"{name}_q"
                self.emit(f"  reg {self.rng(w)}{q};  // {rn}.{f.inst_name}: one-clock pulse",
                          "  always @(posedge clk) begin", f"    if (rst) {q} <= {w}'d0;",
                          f"    else if ({self.wr(k)}) {q} <= wdata_q{sl} & {wmask};",
                          f"    else {q} <= {w}'d0;", "  end",
                          f"  assign {self.r2h(reg, f)} = {self.gate(feat, q, w)};", "")
            else:
                q = f"{name}_q"
                fix = f.get_property("fixed_by")
                val = f"(({fix} >= 0) ? {fix}[{w - 1}:0] : {q})" if fix else q
                self.emit(f"  reg {self.rng(w)}{q};  // {rn}.{f.inst_name}", "  always @(posedge clk) begin",
                          "    if (rst) begin", f"      {q} <= {reset};")
                self.emit(*self.update(kind, reg, f, q, w, sl, wmask, self.wr(k), sz))
                self.emit("    end", "  end")
                if kind != "counter":
                    self.emit(f"  assign {self.r2h(reg, f)} = {self.gate(feat, val, w)};")
                self.emit("")
                read = val
            if read is not None:
                line = f"rd{sl} = {read};  // {rn}.{f.inst_name}"
                reads.append(f"if ({feat} != 0) {line}" if feat else line)
        self.reads.append((rn, reads))

    @staticmethod
    def lanes(q: str, lsb: int, msb: int, sz: str | None, src: str = "wdata_q",
              indent: str = "      ") -> list[str]:
        """A write of bits [msb:lsb] of ``src`` into ``q`` (bit 0 of q = bit lsb), one byte lane
        at a time: each lane's bits are stored when its byte enable is set, so synthesis makes the
        enable the flip-flops' clock enable (one LUT per lane, not a multiplexer per bit). Bits
        outside ``sz`` (a width mask) are written 0, which they always hold."""
        out = []
        for b in range(lsb // 8, msb // 8 + 1):
            lo, hi = max(lsb, 8 * b), min(msb, 8 * b + 7)
            dst = f"{q}[{hi - lsb}:{lo - lsb}]" if msb > lsb else q
            val = f"{src}[{hi}:{lo}]" + (f" & {sz}[{hi}:{lo}]" if sz else "")
            out.append(f"{indent}if (wstrb_q[{b}]) {dst} <= {val};")
        return out

    def update(self, kind, reg, f, q, w, sl, wmask, wr, sz=None) -> list[str]:
        ename = f"{reg.inst_name}_{f.inst_name}".lower() if len(list(reg.fields())) > 1 \
            else reg.inst_name.lower()
        if kind == "cfg" and f.get_property("hwclr"):
            return ([f"    end else if ({wr} & (|({wmask}))) begin"] + self.lanes(q, f.lsb, f.msb, sz)
                    + [f"    end else if ({self.h2r(ename + '_clr')}) begin", f"      {q} <= {w}'d0;"])
        if kind == "cfg":
            return [f"    end else if ({wr}) begin"] + self.lanes(q, f.lsb, f.msb, sz)
        if kind == "intr":
            sets = self.h2r(f"{reg.inst_name.lower()}_set", f.lsb, w)
            return ["    end else begin",
                    f"      {q} <= ({q} & ~({{{w}{{{wr}}}}} & wdata_q{sl} & {wmask})) | {sets};"]
        if kind == "counter":
            incr = self.h2r(f"{ename}_incr")
            return [f"    end else if ({wr} & (|wstrb_q)) begin",
                    f"      {q} <= {{{{{w - 1}{{1'b0}}}}, {incr}}};",
                    f"    end else if ({incr} & ~(&{q})) begin", f"      {q} <= {q} + {w}'d1;"]
        raise ValueError(f"{reg.inst_name}.{f.inst_name}: field kind {kind} has no storage")

    def coherent(self, k: int, f, wmask: str) -> str:
        """COUNT_LO / COUNT_HI (see the module docstring); returns the read value."""
        if f.get_property("coherent") == "hi":
            self.emit("  // COUNT_HI: the high word latched by the last COUNT_LO read; the staged word",
                      "  always @(posedge clk) begin", "    if (rst) begin",
                      "      count_hi_latch_q <= 32'd0;", "      count_hi_stage_q <= 32'd0;", "    end else begin",
                      f"      if (count_lo_rd) count_hi_latch_q <= {self.h2r('count', 32, 32)};",
                      f"      if ({self.wr(k)}) begin",
                      *self.lanes("count_hi_stage_q", 0, 31, SIZE_MASKS.get(f.get_property("sized_by")),
                                  indent="        "),
                      "      end",
                      "    end", "  end", "")
            return "count_hi_latch_q"
        live = self.h2r("count", 0, 32)
        self.decls += ["  reg  [31:0] count_hi_latch_q;  // COUNT_HI: the high word latched by a COUNT_LO read",
                       "  reg  [31:0] count_hi_stage_q;  // the word a COUNT_HI write staged",
                       f"  wire        count_lo_rd = {self.rd(k)};  // a COUNT_LO read", ""]
        self.emit("  // COUNT_LO: a read latches the high word; a write loads {staged word, this word}",
                  f"  wire [31:0] count_lo_word = ({live} & ~({wmask})) | (wdata_q & {wmask});",
                  f"  assign {self.r2h_entry('count_load')} = {self.wr(k)} & (|wstrb_q);",
                  f"  assign {self.r2h_entry('count_load_value')} = {{count_hi_stage_q, count_lo_word}};", "")
        return live

    # ---- outputs -------------------------------------------------------------------------------
    def render(self) -> Out:
        for k, reg in enumerate(self.regs):
            self.register(k, reg)
        return Out(self.decls + self.body)

    def zero_unused(self) -> list[str]:
        """Bundle bits no field drives (the top halves of narrower entries) are 0."""
        used = [False] * self.b.r2h_w
        for lo, hi in self.driven:
            for bit in range(lo, hi + 1):
                used[bit] = True
        out, bit = [], 0
        while bit < len(used):
            if used[bit]:
                bit += 1
                continue
            end = bit
            while end + 1 < len(used) and not used[end + 1]:
                end += 1
            rng = f"[{end}:{bit}]" if end > bit else f"[{bit}]"
            out.append(f"  assign {self.r2h_name}{rng} = {end - bit + 1}'d0;  // (no field)")
            bit = end + 1
        return out + ([""] if out else [])

    def read_mux(self, sel: str, dst: str) -> list[str]:
        """The AND-OR of the group's registers into ``dst`` (one select bit at most)."""
        out = []
        for k, (rn, reads) in enumerate(self.reads):
            if reads:
                out.append(f"    if ({sel}[{k}]) begin  // {rn}")
                out += ["      " + self.or_in(r, dst) for r in reads]
                out.append("    end")
        return out

    @staticmethod
    def or_in(line: str, dst: str) -> str:
        """``[if (F) ]rd[x] = v;`` -> ``[if (F) ]dst[x] = dst[x] | v;``."""
        head, _, stmt = line.rpartition(") rd") if line.startswith("if (") else ("", "", line[2:])
        prefix = head + ") " if head else ""
        lhs, rest = stmt.split(" = ", 1)
        return f"{prefix}{dst}{lhs} = {dst}{lhs} | {rest}"

    def formal_view(self, name: str, sel: str) -> list[str]:
        """Under FORMAL: ``name``, every register's value as a read would answer it now (register k
        in bits [32k +: 32]); formal/enc_qei_regs.sby connects it to its wrapper, whose
        k-induction needs the stored values (the ports show them only when read)."""
        n = len(self.reads)
        out = ["`ifdef FORMAL", f"  reg [{32 * n - 1}:0] {name};", "  always @(*) begin",
               f"    {name} = {{{32 * n}{{1'b0}}}};"]
        for k, (rn, reads) in enumerate(self.reads):
            for r in reads:
                prefix, stmt = ("", r) if not r.startswith("if (") else (r[:r.index(") rd") + 2], r[r.index(") rd") + 2:])
                lhs, rest = stmt.split(" = ", 1)
                hi, _, lo = lhs[3:-1].partition(":")
                out.append(f"    {prefix}{name}[{32 * k + int(lo)} +: {int(hi) - int(lo) + 1}] = {rest}")
        return out + ["  end", "`endif", ""]
