# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei_regs.v: the register block of enc_qei, generated from the compiled RDL.

Field kinds (enctools.regmap.field_kind; anything else stops the generator with a message):
  const    sw=r  hw=na          reads its reset value
  in       sw=r  hw=w           reads a live value from hw2reg
  cfg      sw=rw hw=r           storage, to reg2hw; with hwclr, hw2reg <entry>_clr clears it
                                (a software write in the same clock wins)
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
the others read 0 and ignore writes); feature (a module parameter: with 0 the register reads 0,
ignores writes and gives 0 to reg2hw, still without a bus error); fixed_by (a module parameter:
when >= 0 the field reads and gives that value and ignores writes).
"""

from __future__ import annotations

from ..regmap import field_kind
from . import HEADER_V
from .bundle import build

SIZE_MASKS = {"COUNT_W:0": "SZ_COUNT_LO", "COUNT_W:1": "SZ_COUNT_HI", "TS_W": "SZ_TS"}

HEAD = """// enc_qei_regs -- the register block of enc_qei: address decode, storage, byte enables,
// write-1-to-clear events, saturating counters, the coherent count and the read multiplexer.
// It meets the rest of the peripheral through two bundles, reg2hw and hw2reg (their fields by
// name: rtl/enc_qei_regs_fields.vh).
//
// Request/response port: a request is one clock of req_valid with req_write, req_addr (byte
// address, bits 1:0 ignored), req_wdata and req_wstrb. The response comes two clocks later: one
// clock of resp_valid with resp_rdata (0 for writes) and resp_err (unmapped offset: reads 0,
// writes nothing). The request is registered first (its address decoded one-hot): writes and
// read side effects take effect in the clock after the request, and a read takes its data in
// that clock too (every path starts from a register). One request at a time: a new one may start
// in the clock after resp_valid (the bus adapters see to it)."""


class Writer:
    """The Verilog of one register block, built register by register."""

    def __init__(self, top):
        self.top = top
        self.regs = list(top.registers())
        self.b = build(top)
        self.decls: list[str] = []  # declarations that must come before the field logic
        self.body: list[str] = []
        self.reads: list[tuple[str, list[str]]] = []

    # ---- helpers -----------------------------------------------------------------------------
    def r2h(self, reg, f, sub: str = "") -> str:
        side, e, lsb = self.b.where[(reg.inst_name, f.inst_name)]
        assert side == "r2h"
        return f"reg2hw[{e.lsb + lsb + f.width - 1}:{e.lsb + lsb}]" if f.width > 1 or sub else \
            f"reg2hw[{e.lsb + lsb}]"

    def h2r(self, name: str, lo: int = 0, width: int | None = None) -> str:
        e = next(x for x in self.b.h2r if x.name == name)
        w = e.width if width is None else width
        return f"hw2reg[{e.lsb + lo + w - 1}:{e.lsb + lo}]" if w > 1 else f"hw2reg[{e.lsb + lo}]"

    def r2h_entry(self, name: str) -> str:
        e = next(x for x in self.b.r2h if x.name == name)
        return f"reg2hw{e.rng}"

    def emit(self, *lines: str) -> None:
        self.body += list(lines)

    # ---- fields ------------------------------------------------------------------------------
    def register(self, k: int, reg) -> None:
        rn, feat = reg.inst_name, reg.get_property("feature")
        reads: list[str] = []
        for f in reg.fields():
            kind = field_kind(f)
            w, sl = f.width, f"[{f.msb}:{f.lsb}]"
            name = f"{rn}_{f.inst_name}".lower()
            sz = SIZE_MASKS.get(f.get_property("sized_by"))
            wmask = f"bmask{sl}" + (f" & {sz}{sl}" if sz else "")
            reset = f"{w}'h{(f.get_property('reset') or 0):X}" + (f" & {sz}{sl}" if sz else "")
            wr = f"wr_sel_q[{k}]"
            if kind == "const":
                reads.append(f"rd_d{sl} = {w}'h{f.get_property('reset'):X};  // {rn}.{f.inst_name}")
            elif kind == "in":
                side, e, lo = self.b.where[(rn, f.inst_name)]
                reads.append(f"rd_d{sl} = {self.h2r(e.name, lo, w)};")
            elif kind == "coherent":
                reads.append(self.coherent(k, reg, f, wmask))
            elif kind == "pulse":
                q = f"{name}_q"
                self.emit(f"  reg {self.rng(w)}{q};  // {rn}.{f.inst_name}: one-clock pulse",
                          "  always @(posedge clk) begin",
                          f"    if (rst) {q} <= {w}'d0;",
                          f"    else if ({wr}) {q} <= wdata_q{sl} & {wmask};",
                          f"    else {q} <= {w}'d0;", "  end",
                          f"  assign {self.r2h(reg, f)} = {self.gate(feat, q, w)};", "")
            else:
                q = f"{name}_q"
                fix = f.get_property("fixed_by")
                val = f"(({fix} >= 0) ? {fix}[{w - 1}:0] : {q})" if fix else q
                self.emit(f"  reg {self.rng(w)}{q};  // {rn}.{f.inst_name}", "  always @(posedge clk) begin",
                          f"    if (rst) begin", f"      {q} <= {reset};")
                self.emit(*self.update(kind, reg, f, q, w, sl, wmask, wr))
                self.emit("    end", "  end")
                if kind != "counter":
                    self.emit(f"  assign {self.r2h(reg, f)} = {self.gate(feat, val, w)};")
                self.emit("")
                reads.append(f"rd_d{sl} = {val};")
        if feat and reads:
            reads = [f"if ({feat} != 0) begin"] + ["  " + r for r in reads] + ["end"]
        self.reads.append((rn, reads))

    def update(self, kind, reg, f, q, w, sl, wmask, wr) -> list[str]:
        ename = f"{reg.inst_name}_{f.inst_name}".lower() if len(list(reg.fields())) > 1 \
            else reg.inst_name.lower()
        if kind == "cfg" and f.get_property("hwclr"):
            return [f"    end else if ({wr} & (|({wmask}))) begin",
                    f"      {q} <= ({q} & ~({wmask})) | (wdata_q{sl} & {wmask});",
                    f"    end else if ({self.h2r(ename + '_clr')}) begin", f"      {q} <= {w}'d0;"]
        if kind == "cfg":
            return [f"    end else if ({wr}) begin",
                    f"      {q} <= ({q} & ~({wmask})) | (wdata_q{sl} & {wmask});"]
        if kind == "intr":
            sets = self.h2r(f"{reg.inst_name.lower()}_set", f.lsb, w)
            return ["    end else begin",
                    f"      {q} <= ({q} & ~({{{w}{{{wr}}}}} & wdata_q{sl} & {wmask})) | {sets};"]
        if kind == "counter":
            incr = self.h2r(f"{ename}_incr")
            return [f"    end else if ({wr} & (|wstrb_q)) begin",
                    f"      {q} <= {{{{{w - 1}{{1'b0}}}}, {incr}}};",
                    f"    end else if ({incr} & ~(&{q})) begin", f"      {q} <= {q} + {w}'d1;"]
        raise AssertionError(kind)

    def coherent(self, k: int, reg, f, wmask: str) -> str:
        """COUNT_LO / COUNT_HI (see the module docstring); returns the read line."""
        if f.get_property("coherent") == "hi":
            self.emit("  // COUNT_HI: the high word latched by the last COUNT_LO read; the staged word",
                      "  always @(posedge clk) begin",
                      "    if (rst) begin", "      count_hi_latch_q <= 32'd0;", "      count_hi_stage_q <= 32'd0;",
                      "    end else begin",
                      f"      if (count_lo_rd) count_hi_latch_q <= {self.h2r('count', 32, 32)};",
                      f"      if (wr_sel_q[{k}]) count_hi_stage_q <= (count_hi_stage_q & ~({wmask})) |",
                      f"                                              (wdata_q & {wmask});",
                      "    end", "  end", "")
            return "rd_d = count_hi_latch_q;"
        live = self.h2r("count", 0, 32)
        self.decls += ["  reg [31:0] count_hi_latch_q;  // COUNT_HI: the high word latched by a COUNT_LO read",
                       "  reg [31:0] count_hi_stage_q;  // the word a COUNT_HI write staged",
                       f"  wire       count_lo_rd = rd_sel_q[{k}];  // a COUNT_LO read", ""]
        self.emit("  // COUNT_LO: a read latches the high word; a write loads {staged word, this word}",
                  f"  wire [31:0] count_lo_word = ({live} & ~({wmask})) | (wdata_q & {wmask});",
                  f"  assign {self.r2h_entry('count_load')} = wr_sel_q[{k}] & (|wstrb_q);",
                  f"  assign {self.r2h_entry('count_load_value')} = {{count_hi_stage_q, count_lo_word}};", "")
        return f"rd_d = {live};"

    @staticmethod
    def rng(w: int) -> str:
        return f"[{w - 1}:0] " if w > 1 else ""

    @staticmethod
    def gate(feat, val: str, w: int) -> str:
        return f"(({feat} != 0) ? {val} : {w}'d0)" if feat else val

    # ---- the module --------------------------------------------------------------------------
    def render(self) -> str:
        regs = self.regs
        for k, reg in enumerate(regs):
            self.register(k, reg)
        features = sorted({r.get_property("feature") for r in regs if r.get_property("feature")})
        fixers = sorted({f.get_property("fixed_by") for r in regs for f in r.fields()
                         if f.get_property("fixed_by")})
        n = len(regs)
        out = [*HEADER_V, HEAD, "`default_nettype none", "", "module enc_qei_regs #("]
        out += [f"    parameter integer {p} = 1,  // 1: its registers present, 0: they read 0 "
                "(checked by enc_qei)" for p in features]
        out += [f"    parameter integer {p} = -1,  // -1: the field is storage, >= 0: fixed to it "
                "(checked by enc_qei)" for p in fixers]
        out += ["    parameter integer COUNT_W = 32,  // counter width (checked by enc_qei)",
                "    parameter integer TS_W    = 32   // timebase width (checked by enc_qei)",
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
                f"    output wire [{self.b.r2h_w - 1}:0] reg2hw,  // to the hardware (fields: enc_qei_regs_fields.vh)",
                "    // verilator lint_off UNUSEDSIGNAL",
                f"    input  wire [{self.b.h2r_w - 1}:0] hw2reg   // from the hardware (a feature left out leaves some unread)",
                "    // verilator lint_on UNUSEDSIGNAL",
                ");", "", '  `include "enc_qei_regs.vh"', "",
                "  // Bits of the value a sized field holds (the others read 0 and ignore writes)",
                "  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);",
                "  localparam [31:0] SZ_COUNT_LO = SZ_COUNT[31:0];",
                "  localparam [31:0] SZ_COUNT_HI = SZ_COUNT[63:32];",
                "  localparam [31:0] SZ_TS = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);", "",
                "  // ---- request register: the address decoded one-hot, data and byte enables ---------",
                f"  wire [{n - 1}:0] sel_d;  // bit k: the request is to register k (address order)"]
        out += [f"  assign sel_d[{k}] = (req_addr[7:2] == ENC_QEI_{r.inst_name}[7:2]);" for k, r in enumerate(regs)]
        out += ["", f"  reg [{n - 1}:0] rd_sel_q;  // bit k: a read of register k (this clock)",
                "  // verilator lint_off UNUSEDSIGNAL",
                f"  reg [{n - 1}:0] wr_sel_q;  // bit k: a write of register k (read-only ones: unused)",
                "  // verilator lint_on UNUSEDSIGNAL",
                "  reg        err_q;       // the request was to an unmapped offset",
                "  reg        pend_q;      // a request was made last clock",
                "  reg [31:0] wdata_q;", "  reg [3:0]  wstrb_q;", "",
                "  always @(posedge clk) begin", "    if (rst) begin",
                f"      rd_sel_q <= {{{n}{{1'b0}}}};", f"      wr_sel_q <= {{{n}{{1'b0}}}};",
                "      err_q    <= 1'b0;", "      pend_q   <= 1'b0;", "    end else begin",
                f"      rd_sel_q <= (req_valid & ~req_write) ? sel_d : {{{n}{{1'b0}}}};",
                f"      wr_sel_q <= (req_valid & req_write) ? sel_d : {{{n}{{1'b0}}}};",
                f"      err_q    <= req_valid & (sel_d == {{{n}{{1'b0}}}});",
                "      pend_q   <= req_valid;", "    end", "  end", "",
                "  always @(posedge clk) begin", "    wdata_q <= req_wdata;", "    wstrb_q <= req_wstrb;", "  end", "",
                "  wire [31:0] bmask = {{8{wstrb_q[3]}}, {8{wstrb_q[2]}}, {8{wstrb_q[1]}}, {8{wstrb_q[0]}}};", ""]
        out += self.decls + self.body
        out += self.reg2hw_zero()
        out += ["  // ---- read multiplexer (one select bit at most: AND-OR) and response ---------------",
                "  reg [31:0] rd_d;", "", "  always @(*) begin", "    rd_d = 32'd0;"]
        for k, (rn, reads) in enumerate(self.reads):
            if reads:
                out.append(f"    if (rd_sel_q[{k}]) begin  // {rn}")
                out += ["      " + self.or_in(r) for r in reads]
                out.append("    end")
        out += ["  end", ""]
        out += self.formal_view()
        out += ["  reg        resp_valid_q;", "  reg [31:0] resp_rdata_q;", "  reg        resp_err_q;", "",
                "  always @(posedge clk) begin", "    if (rst) begin", "      resp_valid_q <= 1'b0;",
                "      resp_rdata_q <= 32'd0;", "      resp_err_q   <= 1'b0;", "    end else begin",
                "      resp_valid_q <= pend_q;", "      resp_rdata_q <= rd_d;", "      resp_err_q   <= err_q;",
                "    end", "  end", "", "  assign resp_valid = resp_valid_q;", "  assign resp_rdata = resp_rdata_q;",
                "  assign resp_err   = resp_err_q;", "", "endmodule", "", "`default_nettype wire", ""]
        return "\n".join(out)

    def reg2hw_zero(self) -> list[str]:
        """Bundle bits no field drives (the top halves of narrower entries) are 0."""
        used = [False] * self.b.r2h_w
        for line in self.body:
            if line.startswith("  assign reg2hw["):
                hi_lo = line.split("[", 1)[1].split("]", 1)[0]
                hi, _, lo = hi_lo.partition(":")
                for bit in range(int(lo or hi), int(hi) + 1):
                    used[bit] = True
        out = []
        bit = 0
        while bit < len(used):
            if used[bit]:
                bit += 1
                continue
            end = bit
            while end + 1 < len(used) and not used[end + 1]:
                end += 1
            rng = f"[{end}:{bit}]" if end > bit else f"[{bit}]"
            out.append(f"  assign reg2hw{rng} = {end - bit + 1}'d0;  // (no field)")
            bit = end + 1
        return out + ([""] if out else [])

    def formal_view(self) -> list[str]:
        """Under FORMAL: f_view, every register's value as a read would answer it now (register k
        in bits [32k +: 32]); formal/enc_qei_regs.sby connects it to its wrapper, whose
        k-induction needs the stored values (the ports show them only when read)."""
        n = len(self.reads)
        out = ["`ifdef FORMAL", f"  reg [{32 * n - 1}:0] f_view;", "  always @(*) begin",
               f"    f_view = {{{32 * n}{{1'b0}}}};"]
        for k, (rn, reads) in enumerate(self.reads):
            for r in reads:
                stripped = r.strip()
                if stripped.startswith("rd_d"):
                    lhs, rest = stripped.split(" = ", 1)
                    rng = lhs[4:] or "[31:0]"
                    hi, _, lo = rng.strip("[]").partition(":")
                    lo = lo or hi
                    w = int(hi) - int(lo) + 1
                    out.append(f"{' ' * (len(r) - len(r.lstrip()) + 4)}f_view[{32 * k + int(lo)} +: {w}] = {rest}")
                else:
                    out.append("    " + r)
        return out + ["  end", "`endif", ""]

    @staticmethod
    def or_in(line: str) -> str:
        """``rd_d[x] = v;`` -> ``rd_d[x] = rd_d[x] | v;`` (the AND-OR multiplexer)."""
        if not line.lstrip().startswith("rd_d"):
            return line
        lhs, rest = line.split(" = ", 1)
        return f"{lhs} = {lhs.strip()} | {rest}"


def render(top) -> str:
    return Writer(top).render()
