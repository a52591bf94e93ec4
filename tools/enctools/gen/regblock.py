# SPDX-License-Identifier: Apache-2.0
"""rtl/enc_qei_regs.v: the register block of enc_qei, generated from the compiled RDL: the global
registers once, the channel registers once per channel (a generate loop), the paged address
decode, and the read multiplexer. Field logic: enctools.gen.fields.

The map is paged (enctools.regmap): page k holds channel k's registers; page 0 also the global
registers. The request register decodes the offset one-hot for each group and the page one-hot;
a channel register of page k is selected by both.
"""

from __future__ import annotations

from . import HEADER_V
from .bundle import build, group_regs
from .fields import Fields

HEAD = """// enc_qei_regs -- the register block of enc_qei: paged address decode, storage, byte enables,
// write-1-to-clear events, saturating counters, the coherent count and the read multiplexer, for
// the global registers and for CHANNELS channel pages (page k: channel k; page 0 also holds the
// global registers). It meets the rest of the peripheral through bundles: reg2hw_g / hw2reg_g
// (global; fields by name: rtl/enc_qei_regs_fields.vh) and, per channel k, bits
// [k * W +: W] of reg2hw_ch / hw2reg_ch (rtl/enc_qei_chan_fields.vh).
//
// Request/response port: a request is one clock of req_valid with req_write, req_addr (byte
// address, bits 1:0 ignored), req_wdata and req_wstrb. The response comes two clocks later: one
// clock of resp_valid with resp_rdata (0 for writes) and resp_err (no register at that address:
// reads 0, writes nothing). The request is registered first (its offset and page decoded
// one-hot): writes and read side effects take effect in the clock after the request, and a read
// takes its data in that clock too (every path starts from a register). One request at a time: a
// new one may start in the clock after resp_valid (the bus adapters see to it)."""

FEATURES = ("TIMING", "RANGE", "PROBE", "PERIOD", "EFIFO")


def render(top=None) -> str:
    g, c = build("glb"), build("chan")
    regs_g, regs_c = group_regs("glb"), group_regs("chan")
    ng, nc = len(regs_g), len(regs_c)
    fg = Fields(regs_g, g, wr=lambda k: f"wr_g_q[{k}]", rd=lambda k: f"rd_g_q[{k}]",
                r2h="reg2hw_g", h2r="hw2reg_g")
    fc = Fields(regs_c, c, wr=lambda k: f"wr_c[{k}]", rd=lambda k: f"rd_c[{k}]",
                r2h="r2h", h2r="h2r")
    body_g, body_c = fg.render(), fc.render()
    fixers = sorted({f.get_property("fixed_by") for r in regs_g + regs_c for f in r.fields()
                     if f.get_property("fixed_by")})
    out = [*HEADER_V, HEAD, "`default_nettype none", "", "module enc_qei_regs #("]
    out += [f"    parameter integer {p} = 1,  // 1: unit {p} present, 0: its registers and fields "
            "read 0 (checked by enc_qei)" for p in FEATURES]
    out += [f"    parameter integer {p} = -1,  // -1: the field is storage, >= 0: fixed to it "
            "(checked by enc_qei)" for p in fixers]
    out += ["    parameter integer CH_PAGES = 1,  // 1: channel pages here; 0: none (the shared engine's)",
            "    parameter integer CHANNELS = 1,  // channel pages (checked by enc_qei)",
            "    parameter integer ADDR_W   = 8,  // byte address bits, 8 .. 16 (checked by enc_qei)",
            "    parameter integer COUNT_W  = 32, // counter width (checked by enc_qei)",
            "    parameter integer TS_W     = 32  // timebase width (checked by enc_qei)",
            ") (",
            "    input  wire        clk,",
            "    input  wire        rst,         // synchronous, active high",
            "    input  wire        req_valid,   // one-clock request",
            "    input  wire        req_write,   // 1 = write, 0 = read",
            "    // verilator lint_off UNUSEDSIGNAL",
            "    input  wire [ADDR_W-1:0] req_addr,  // byte address (bits 1:0 ignored)",
            "    // verilator lint_on UNUSEDSIGNAL",
            "    input  wire [31:0] req_wdata,",
            "    input  wire [3:0]  req_wstrb,   // byte enables",
            "    output wire        resp_valid,  // two clocks after req_valid",
            "    output wire [31:0] resp_rdata,",
            "    output wire        resp_err,    // no register at that address",
            f"    output wire [{g.r2h_w - 1}:0] reg2hw_g,  // global registers to the hardware",
            "    // verilator lint_off UNUSEDSIGNAL",
            f"    input  wire [{g.h2r_w - 1}:0] hw2reg_g,  // hardware to the global registers",
            f"    output wire [CHANNELS*{c.r2h_w}-1:0] reg2hw_ch,  // channel k: bits [k*{c.r2h_w} +: {c.r2h_w}]",
            f"    input  wire [CHANNELS*{c.h2r_w}-1:0] hw2reg_ch   // channel k: bits [k*{c.h2r_w} +: {c.h2r_w}]",
            "    // verilator lint_on UNUSEDSIGNAL",
            ");", "", '  `include "enc_qei_regs.vh"', "",
            "  // Bits of the value a sized field holds (the others read 0 and ignore writes)",
            "  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);",
            "  localparam [31:0] SZ_COUNT_LO = SZ_COUNT[31:0];",
            "  localparam [31:0] SZ_COUNT_HI = SZ_COUNT[63:32];",
            "  localparam [31:0] SZ_TS = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);", ""]
    out += decode(regs_g, regs_c)
    out += ["  // ---- global registers ----------------------------------------------------------------"]
    out += body_g.logic
    out += fg.zero_unused()
    out += ["  // ---- channel registers: one page per channel ----------------------------------------",
            "  wire [CHANNELS*32-1:0] rd_ch;  // channel k's read data (its selected register)",
            "`ifdef FORMAL",
            f"  // every channel's f_view (channel k: bits [k*{32 * nc} +: {32 * nc}]) and staged COUNT_HI",
            "  // word (bits [k*32 +: 32]), for formal/enc_qei_regs.sby to connect",
            f"  wire [CHANNELS*{32 * nc}-1:0] f_view_ch;",
            "  wire [CHANNELS*32-1:0] f_stage_ch;",
            "`endif",
            "  genvar ch;", "  generate", "    if (CH_PAGES == 0) begin : g_no_pages",
            "      wire unused_pages = &{1'b0, rd_c_q, wr_c_q, bmask, page_hit};",
            "      assign rd_ch = {CHANNELS*32{1'b0}};",
            "      assign reg2hw_ch = {CHANNELS*%d{1'b0}};" % c.r2h_w,
            "`ifdef FORMAL", "      assign f_view_ch = {CHANNELS*%d{1'b0}};" % (32 * nc),
            "      assign f_stage_ch = {CHANNELS*32{1'b0}};", "`endif",
            "    end else begin : g_pages",
            "    for (ch = 0; ch < CHANNELS; ch = ch + 1) begin : g_ch"]
    inner = ["      // verilator lint_off UNUSEDSIGNAL",
             f"      wire [{nc - 1}:0] wr_c = wr_c_q & {{{nc}{{page_hit[ch]}}}};  // writes to this page",
             f"      wire [{nc - 1}:0] rd_c = rd_c_q & {{{nc}{{page_hit[ch]}}}};  // reads of this page",
             "      // verilator lint_on UNUSEDSIGNAL",
             f"      wire [{c.r2h_w - 1}:0] r2h;",
             "      // verilator lint_off UNUSEDSIGNAL",
             f"      wire [{c.h2r_w - 1}:0] h2r = hw2reg_ch[ch*{c.h2r_w} +: {c.h2r_w}];  // (the unused "
             "bits of gapped live registers: EFIFO_ENTRY)",
             "      // verilator lint_on UNUSEDSIGNAL",
             f"      assign reg2hw_ch[ch*{c.r2h_w} +: {c.r2h_w}] = r2h;", ""]
    inner += ["    " + ln if ln else ln for ln in body_c.logic + fc.zero_unused()]
    inner += ["      reg [31:0] rd;", "      always @(*) begin", "        rd = 32'd0;"]
    inner += ["      " + ln for ln in fc.read_mux("rd_c_q", "rd")]
    inner += ["      end", "      assign rd_ch[ch*32 +: 32] = rd;"]
    inner += ["    " + ln if ln else ln for ln in fc.formal_view("f_view", "rd_c_q")]
    inner[-2:-2] = [f"      assign f_view_ch[ch*{32 * nc} +: {32 * nc}] = f_view;",
                    "      assign f_stage_ch[ch*32 +: 32] = count_hi_stage_q;"]
    out += inner + ["    end", "    end", "  endgenerate", ""]
    out += ["  // ---- read multiplexer (one select bit at most: AND-OR) and response -----------------",
            "  reg [31:0] rd_d;", "  integer k;", "", "  always @(*) begin", "    rd_d = 32'd0;"]
    out += fg.read_mux("rd_g_q", "rd_d")
    out += ["    for (k = 0; k < CHANNELS; k = k + 1) begin",
            "      rd_d = rd_d | (rd_ch[k*32 +: 32] & {32{page_hit[k]}});", "    end", "  end", ""]
    out += fg.formal_view("f_view_g", "rd_g_q")
    out += ["  reg        resp_valid_q;", "  reg [31:0] resp_rdata_q;", "  reg        resp_err_q;", "",
            "  always @(posedge clk) begin", "    if (rst) begin", "      resp_valid_q <= 1'b0;",
            "      resp_rdata_q <= 32'd0;", "      resp_err_q   <= 1'b0;", "    end else begin",
            "      resp_valid_q <= pend_q;", "      resp_rdata_q <= rd_d;", "      resp_err_q   <= err_q;",
            "    end", "  end", "", "  assign resp_valid = resp_valid_q;", "  assign resp_rdata = resp_rdata_q;",
            "  assign resp_err   = resp_err_q;", "", "endmodule", "", "`default_nettype wire", ""]
    return "\n".join(out)


def decode(regs_g, regs_c) -> list[str]:
    ng, nc = len(regs_g), len(regs_c)
    out = ["  // ---- request register: offset one-hot per group, page one-hot -----------------------",
           "  function [15:0] zext16;  // req_addr as 16 bits (ADDR_W <= 16)",
           "    input [ADDR_W-1:0] a;", "    begin", "      zext16 = 16'd0;",
           "      zext16[ADDR_W-1:0] = a;", "    end", "  endfunction", "",
           "  // verilator lint_off UNUSEDSIGNAL",
           "  wire [15:0] addr16 = zext16(req_addr);  // (bits 1:0 unused)",
           "  // verilator lint_on UNUSEDSIGNAL",
           "  wire [7:0]  page_d = addr16[15:8];  // 0 when ADDR_W = 8",
           "  wire [5:0]  off_d  = addr16[7:2];",
           f"  wire [{ng - 1}:0] sel_g_d;  // bit k: the offset of global register k, in page 0",
           f"  wire [{nc - 1}:0] sel_c_d;  // bit k: the offset of channel register k"]
    out += [f"  assign sel_g_d[{k}] = (page_d == 8'd0) & (off_d == ENC_QEI_{r.inst_name}[7:2]);"
            for k, r in enumerate(regs_g)]
    out += [f"  assign sel_c_d[{k}] = (off_d == ENC_QEI_{r.inst_name}[7:2]);" for k, r in enumerate(regs_c)]
    out += ["  wire chan_page_d = (CH_PAGES != 0) & ({8'd0, page_d} < CHANNELS[15:0]);  // a channel's page",
            "",
            "  // verilator lint_off UNUSEDSIGNAL",
            f"  reg [{ng - 1}:0] rd_g_q, wr_g_q;  // a read / write of global register k (read-only ones: unused)",
            "  // verilator lint_on UNUSEDSIGNAL",
            f"  reg [{nc - 1}:0] rd_c_q, wr_c_q;  // a read / write of channel register k, in the page of page_q",
            "  // verilator lint_off UNUSEDSIGNAL",
            "  reg [CHANNELS-1:0] page_q;  // the request's page, one-hot (all 0: no channel's page)",
            "  // verilator lint_on UNUSEDSIGNAL",
            "  reg        err_q;       // the request was to no register", "  reg        pend_q;      // a request was made last clock",
            "  reg [31:0] wdata_q;", "  reg [3:0]  wstrb_q;", "  integer    p;", "",
            "  always @(posedge clk) begin", "    if (rst) begin",
            f"      rd_g_q <= {{{ng}{{1'b0}}}};", f"      wr_g_q <= {{{ng}{{1'b0}}}};",
            f"      rd_c_q <= {{{nc}{{1'b0}}}};", f"      wr_c_q <= {{{nc}{{1'b0}}}};",
            "      page_q <= {CHANNELS{1'b0}};", "      err_q  <= 1'b0;", "      pend_q <= 1'b0;", "    end else begin",
            f"      rd_g_q <= (req_valid & ~req_write) ? sel_g_d : {{{ng}{{1'b0}}}};",
            f"      wr_g_q <= (req_valid & req_write) ? sel_g_d : {{{ng}{{1'b0}}}};",
            f"      rd_c_q <= (req_valid & ~req_write & chan_page_d) ? sel_c_d : {{{nc}{{1'b0}}}};",
            f"      wr_c_q <= (req_valid & req_write & chan_page_d) ? sel_c_d : {{{nc}{{1'b0}}}};",
            "      for (p = 0; p < CHANNELS; p = p + 1) begin",
            "        page_q[p] <= req_valid & (page_d == p[7:0]);", "      end",
            f"      err_q  <= req_valid & (sel_g_d == {{{ng}{{1'b0}}}}) & ~(chan_page_d & (|sel_c_d));",
            "      pend_q <= req_valid;", "    end", "  end", "",
            "  always @(posedge clk) begin", "    wdata_q <= req_wdata;", "    wstrb_q <= req_wstrb;", "  end", "",
            "  wire [31:0] bmask = {{8{wstrb_q[3]}}, {8{wstrb_q[2]}}, {8{wstrb_q[1]}}, {8{wstrb_q[0]}}};", "",
            "  // The page gate of channel k's selects. With one channel, rd_c_q / wr_c_q are set only for",
            "  // requests to its page, so it needs no gate (and page_q is left unused).",
            "  wire [CHANNELS-1:0] page_hit = (CHANNELS == 1) ? {CHANNELS{1'b1}} : page_q;", ""]
    return out
