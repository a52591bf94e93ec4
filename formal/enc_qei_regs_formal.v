// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_regs, the generated register block (formal/enc_qei_regs.sby;
// `make formal`).
//
// Every input is free after the first clock (a reset): requests in any clock (the block takes
// one per clock), any address (every page, mapped or not), data and byte enables, and every
// hw2reg bit of both groups and every channel (live values, event and counter strobes, hardware
// clears, the counts). The solver picks one register, f_k (any register of the map), and for a
// channel register one channel, f_c (any of CHANNELS; a global register lives in page 0), both
// fixed for the run; the wrapper keeps what that register must hold by the access rules of its
// fields (formal/enc_qei_regs_table.vh, generated from the RDL apart from the block), from the
// requests to its own address only and its own channel's hw2reg, and proves that the register
// holds, at every clock, and a read of it answers (so the pages are isolated: no request to
// another channel's page, and no other channel's hardware, changes it):
//   - storage fields (sw=rw): the reset value, then what the writes put there, byte lane by byte
//     lane (lanes not enabled keep their bytes), only in the bits the field holds (a sized field:
//     the value's bits), a hardware clear winning only over no write to its lane;
//   - read-only fields ignore writes: live fields read hw2reg as it is at the read, constants
//     their value, write-1 pulses 0;
//   - event bits (W1C): set by their strobe, cleared exactly by a write of 1 to them in an
//     enabled lane, a set in the clock of the clear wins;
//   - saturating counters: +1 per strobe up to all ones, any write clears (keeping a strobe of
//     its clock);
//   - a unit the build leaves out (TIMING, RANGE, PROBE, PERIOD, EFIFO = 0) reads 0 in its fields; a
//     fixed field (FIXED_FUNC >= 0) reads the fixed value;
//   - a write-1 pulse field (SNAP_CTRL.CMD, GSNAP_CTRL.CMD) gives one reg2hw pulse of its
//     channel (or of the global group) in the clock after a write of 1 to it in its lane, and
//     none otherwise;
//   - COUNT_LO / COUNT_HI: a COUNT_LO read returns the count's low word and latches its high word,
//     which every later COUNT_HI read returns until the next COUNT_LO read; a COUNT_HI write stages
//     a word (lanes not enabled keep the staged bytes); a COUNT_LO write with an enabled lane gives
//     one count_load pulse with {staged word, written word, the count's bytes in the lanes not
//     enabled}, and nothing else does (a write to another channel's COUNT_LO loads that one).
`default_nettype none
`include "enc_params.vh"

module enc_qei_regs_formal #(
    parameter integer TIMING     = 1,
    parameter integer RANGE      = 1,
    parameter integer PROBE      = 1,
    parameter integer PERIOD     = 1,
    parameter integer EFIFO      = 1,
    parameter integer FIXED_FUNC = -1,
    parameter integer CHANNELS   = 2,
    parameter integer COUNT_W    = 40,
    parameter integer TS_W       = 16,
    parameter integer AW         = `ENC_QEI_ADDR_W(CHANNELS)  // byte address bits
) (
    input wire          clk,
    input wire          rst,
    input wire          req_valid,
    input wire          req_write,
    input wire [AW-1:0] req_addr,
    input wire [31:0]   req_wdata,
    input wire [3:0]    req_wstrb
);

  `include "enc_qei_regs.vh"
  `include "enc_qei_regs_table.vh"

  localparam integer H2R_CH = ENC_QEI_H2R_CH_W, R2H_CH = ENC_QEI_R2H_CH_W;
  localparam integer VIEW_CH = 32 * ENC_QEI_T_NC;  // one channel's f_view

  // free in every clock
  (* anyseq *) reg [ENC_QEI_H2R_W-1:0]       hw2reg_g;
  (* anyseq *) reg [CHANNELS*H2R_CH-1:0]     hw2reg_ch;
  // the block's formal views (under FORMAL: every register's value as a read would answer it
  // now), connected by formal/enc_qei_regs.sby after flatten: the k-induction's invariant
  (* keep *) wire [32*ENC_QEI_T_NG-1:0]    p_view_g;
  (* keep *) wire [CHANNELS*VIEW_CH-1:0]   p_view_ch;
  (* keep *) wire [CHANNELS*32-1:0]        p_stage_ch;  // ... and the staged COUNT_HI words

  wire        resp_valid, resp_err;
  wire [31:0] resp_rdata;
  wire [ENC_QEI_R2H_W-1:0]   reg2hw_g;
  wire [CHANNELS*R2H_CH-1:0] reg2hw_ch;

  enc_qei_regs #(
      .TIMING    (TIMING),
      .RANGE     (RANGE),
      .PROBE     (PROBE),
      .PERIOD    (PERIOD),
      .EFIFO     (EFIFO),
      .FIXED_FUNC(FIXED_FUNC),
      .CHANNELS  (CHANNELS),
      .ADDR_W    (AW),
      .COUNT_W   (COUNT_W),
      .TS_W      (TS_W)
  ) dut (
      .clk       (clk),
      .rst       (rst),
      .req_valid (req_valid),
      .req_write (req_write),
      .req_addr  (req_addr),
      .req_wdata (req_wdata),
      .req_wstrb (req_wstrb),
      .resp_valid(resp_valid),
      .resp_rdata(resp_rdata),
      .resp_err  (resp_err),
      .reg2hw_g  (reg2hw_g),
      .hw2reg_g  (hw2reg_g),
      .reg2hw_ch (reg2hw_ch),
      .hw2reg_ch (hw2reg_ch)
  );

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume (rst);

  // ---- the register under scrutiny and its rules -------------------------------------------------
  (* anyconst *) reg [5:0] f_k;
  (* anyconst *) reg [3:0] f_c;
  wire        t_chan   = ENC_QEI_T_CHAN[f_k];
  always @(*) begin
    assume (f_k < ENC_QEI_T_N);
    assume ({28'd0, f_c} < CHANNELS);
    if (!t_chan) assume (f_c == 4'd0);  // a global register: page 0
  end

  wire [7:0]  t_off    = ENC_QEI_T_OFFSET[f_k*8 +: 8];
  wire [31:0] t_reset  = ENC_QEI_T_RESET[f_k*32 +: 32];
  wire [31:0] t_cfg    = ENC_QEI_T_CFG[f_k*32 +: 32];
  wire [31:0] t_w1c    = ENC_QEI_T_W1C[f_k*32 +: 32];
  wire [31:0] t_in     = ENC_QEI_T_IN[f_k*32 +: 32];
  wire [7:0]  t_in_lsb = ENC_QEI_T_IN_LSB[f_k*8 +: 8];
  wire [15:0] t_in_h2r = ENC_QEI_T_IN_H2R[f_k*16 +: 16];
  wire [31:0] t_const  = ENC_QEI_T_CONST[f_k*32 +: 32];
  wire [31:0] t_cnt    = ENC_QEI_T_CNT[f_k*32 +: 32];
  wire [15:0] t_cnt_h2r = ENC_QEI_T_CNT_H2R[f_k*16 +: 16];
  wire [31:0] t_clr    = ENC_QEI_T_CLR[f_k*32 +: 32];
  wire [15:0] t_clr_h2r = ENC_QEI_T_CLR_H2R[f_k*16 +: 16];
  wire [15:0] t_set_h2r = ENC_QEI_T_SET_H2R[f_k*16 +: 16];
  wire [1:0]  t_sized  = ENC_QEI_T_SIZED[f_k*2 +: 2];
  wire [7:0]  t_idx    = ENC_QEI_T_IDX[f_k*8 +: 8];
  wire [31:0] t_pulse  = ENC_QEI_T_PULSE[f_k*32 +: 32];
  wire [15:0] t_pulse_r2h = ENC_QEI_T_PULSE_R2H[f_k*16 +: 16];
  // the bits of units the build leaves out: they read 0
  wire [31:0] t_absent = ((TIMING == 0) ? ENC_QEI_T_F_TIMING[f_k*32 +: 32] : 32'd0) |
                         ((RANGE == 0) ? ENC_QEI_T_F_RANGE[f_k*32 +: 32] : 32'd0) |
                         ((PROBE == 0) ? ENC_QEI_T_F_PROBE[f_k*32 +: 32] : 32'd0) |
                         ((PERIOD == 0) ? ENC_QEI_T_F_PERIOD[f_k*32 +: 32] : 32'd0) |
                         ((EFIFO == 0) ? ENC_QEI_T_F_EFIFO[f_k*32 +: 32] : 32'd0);
  wire [31:0] t_fixed  = ENC_QEI_T_FIXED[f_k*32 +: 32];
  wire [1:0]  t_coh    = ENC_QEI_T_COH[f_k*2 +: 2];

  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);
  localparam [31:0] SZ_TS = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);
  wire [31:0] t_sz = (t_sized == 2'd1) ? SZ_COUNT[31:0] : (t_sized == 2'd2) ? SZ_COUNT[63:32] :
                     (t_sized == 2'd3) ? SZ_TS : 32'hFFFFFFFF;

  // the field a parameter fixes reads the parameter (CTRL.FUNC: FIXED_FUNC), at its lsb
  wire [31:0] t_fixed_lsb = t_fixed & ~(t_fixed << 1);
  wire [31:0] t_fixed_val = (FIXED_FUNC >= 0) ? (t_fixed_lsb * FIXED_FUNC) & t_fixed : 32'd0;
  wire [31:0] t_stored = (FIXED_FUNC >= 0) ? (t_cfg & ~t_fixed) : t_cfg;

  // the hw2reg / reg2hw of the register's group (a channel's: channel f_c's slice)
  localparam integer H2R_MAX = (H2R_CH > ENC_QEI_H2R_W) ? H2R_CH : ENC_QEI_H2R_W;
  localparam integer R2H_MAX = (R2H_CH > ENC_QEI_R2H_W) ? R2H_CH : ENC_QEI_R2H_W;
  // (selected by an AND-OR over the channels, and the view by register index first: a shift by
  // f_c * width over every channel's bits would make the solver's work grow many times)
  reg [H2R_CH-1:0]  h2r_c;
  reg [R2H_CH-1:0]  r2h_c;
  reg [31:0]        f_view_c, f_stage_c;
  integer c;
  always @(*) begin
    h2r_c     = {H2R_CH{1'b0}};
    r2h_c     = {R2H_CH{1'b0}};
    f_view_c  = 32'd0;
    f_stage_c = 32'd0;
    for (c = 0; c < CHANNELS; c = c + 1) begin
      if (f_c == c[3:0]) begin
        h2r_c     = hw2reg_ch[c*H2R_CH +: H2R_CH];
        r2h_c     = reg2hw_ch[c*R2H_CH +: R2H_CH];
        f_view_c  = p_view_ch[c*VIEW_CH + t_idx*32 +: 32];
        f_stage_c = p_stage_ch[c*32 +: 32];
      end
    end
  end
  wire [H2R_MAX-1:0] h2r   = t_chan ? h2r_c : hw2reg_g;  // (zero-extended)
  wire [R2H_MAX-1:0] r2h   = t_chan ? r2h_c : reg2hw_g;

  // hw2reg bits by index (a shift: an index past the bundle reads 0)
  function h2r_bit;
    input [15:0] idx;
    reg [H2R_MAX-1:0] shifted;
    begin
      shifted = h2r >> idx;
      h2r_bit = shifted[0];
    end
  endfunction

  reg [31:0] f_live, f_sets;
  integer i;
  always @(*) begin
    for (i = 0; i < 32; i = i + 1) begin
      f_live[i] = t_in[i] & h2r_bit(t_in_h2r + i[15:0] - {8'd0, t_in_lsb});
      f_sets[i] = t_w1c[i] & h2r_bit(t_set_h2r + i[15:0]);
    end
  end
  wire f_incr = |t_cnt & h2r_bit(t_cnt_h2r);
  wire f_clr  = |t_clr & h2r_bit(t_clr_h2r);
  wire [63:0] f_count = h2r_c[ENC_QEI_H2R_COUNT +: 64];  // channel f_c's count

  // ---- the request as the block registers it (one clock later) ---------------------------------
  reg        f1_valid = 1'b0, f1_write = 1'b0;
  reg [15:0] f1_addr = 16'd0;  // zero-extended
  reg [31:0] f1_wdata = 32'd0;
  reg [3:0]  f1_wstrb = 4'd0;
  always @(posedge clk) begin
    f1_valid <= !rst && req_valid;
    f1_write <= req_write;
    f1_addr  <= req_addr;
    f1_wdata <= req_wdata;
    f1_wstrb <= req_wstrb;
  end
  wire [31:0] f_bmask = {{8{f1_wstrb[3]}}, {8{f1_wstrb[2]}}, {8{f1_wstrb[1]}}, {8{f1_wstrb[0]}}};
  wire [7:0] f_page = t_chan ? {4'd0, f_c} : 8'd0;  // the register's page
  wire f_in_page = (f1_addr[15:8] == f_page);
  wire f_hit = f1_valid && f_in_page && (f1_addr[7:2] == t_off[7:2]);
  wire f_wr  = f_hit && f1_write;
  wire f_rd  = f_hit && !f1_write;

  // ---- what register f_k holds ---------------------------------------------------------------------
  reg [31:0] f_cfg = 32'd0, f_w1c = 32'd0, f_cnt = 32'd0;
  wire [31:0] f_m = f_bmask & t_sz;
  // storage: the written lanes; the hardware clear wins only over no write to its lane
  wire [31:0] f_cfg_wr   = f_wr ? ((f_cfg & ~(f_m & t_stored)) | (f1_wdata & f_m & t_stored)) : f_cfg;
  wire [31:0] f_cfg_next = (f_clr && !(f_wr && |(f_m & t_clr))) ? (f_cfg_wr & ~t_clr) : f_cfg_wr;
  always @(posedge clk) begin
    if (rst) begin
      f_cfg <= t_reset & t_stored & t_sz;
      f_w1c <= 32'd0;
      f_cnt <= 32'd0;
    end else begin
      f_cfg <= f_cfg_next;
      // events: write 1 to clear, a set in the same clock wins
      f_w1c <= (f_w1c & ~(f_wr ? (f1_wdata & f_bmask & t_w1c) : 32'd0)) | f_sets;
      // counters: any write clears (keeping this clock's strobe), else +1 saturating
      if (f_wr && |f1_wstrb) f_cnt <= {31'd0, f_incr} & t_cnt;
      else if (f_incr && ((f_cnt & t_cnt) != t_cnt)) f_cnt <= (f_cnt + 32'd1) & t_cnt;
    end
  end

  // ---- the coherent pair: COUNT_LO / COUNT_HI ------------------------------------------------------
  reg [31:0] f_latch = 32'd0, f_stage = 32'd0;
  // (channel f_c's, whichever register f_k is)
  wire f_c_page = (f1_addr[15:8] == {4'd0, f_c});
  wire f_lo_hit = f1_valid && f_c_page && (f1_addr[7:2] == ENC_QEI_COUNT_LO[7:2]);
  wire f_hi_hit = f1_valid && f_c_page && (f1_addr[7:2] == ENC_QEI_COUNT_HI[7:2]);
  wire [31:0] f_m_lo = f_bmask & SZ_COUNT[31:0];
  wire [31:0] f_m_hi = f_bmask & SZ_COUNT[63:32];
  always @(posedge clk) begin
    if (rst) begin
      f_latch <= 32'd0;
      f_stage <= 32'd0;
    end else begin
      if (f_lo_hit && !f1_write) f_latch <= f_count[63:32];
      // an enabled lane takes the written byte (bits above COUNT_W are 0: they hold nothing)
      if (f_hi_hit && f1_write) f_stage <= (f_stage & ~f_bmask) | (f1_wdata & f_m_hi);
    end
  end

  // ---- the data a read of register f_k must answer ---------------------------------------------
  wire [31:0] f_expect = (t_coh == 2'd1) ? f_count[31:0] :
                         (t_coh == 2'd2) ? f_latch :
                         ((f_cfg & t_stored & t_sz) | t_fixed_val | (f_w1c & t_w1c) |
                          (f_cnt & t_cnt) | f_live | (t_reset & t_const)) & ~t_absent;
  reg        f2_rd = 1'b0;
  reg [31:0] f2_expect = 32'd0;
  always @(posedge clk) begin
    f2_rd     <= !rst && f_rd;
    f2_expect <= f_expect;
  end

  wire        f_load   = r2h_c[ENC_QEI_R2H_COUNT_LOAD];
  wire [63:0] f_loaded = r2h_c[ENC_QEI_R2H_COUNT_LOAD_VALUE +: 64];

  // the pulse bit of register f_k, one clock after a write of 1 to it in its enabled lane
  wire [R2H_MAX-1:0] f_r2h_shifted = r2h >> t_pulse_r2h;
  reg  f2_pulse = 1'b0;
  always @(posedge clk) f2_pulse <= !rst && f_wr && |(f1_wdata & f_bmask & t_pulse & ~t_absent);

  wire [31:0] f_view = t_chan ? f_view_c : p_view_g[t_idx*32 +: 32];

  always @(*) begin
    if (f_past_valid && !rst) begin
      // the register holds what its rules say, at every clock; a read answers it
      assert (f_view == f_expect);
      assert (f_stage_c == f_stage);
      if (|t_pulse) assert (f_r2h_shifted[0] == f2_pulse);
      if (f2_rd) assert (resp_valid && !resp_err && resp_rdata == f2_expect);
      // a count load exactly for a COUNT_LO write with an enabled lane, with its value
      assert (f_load == (f_lo_hit && f1_write && |f1_wstrb));
      if (f_load) assert (f_loaded == {f_stage, (f_count[31:0] & ~f_m_lo) | (f1_wdata & f_m_lo)});
    end
  end

  // ---- covers --------------------------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid && !rst) begin
      cover (f2_rd && |(f2_expect & t_cfg) && t_coh == 2'd0);       // a stored value read back
      cover (f2_rd && |(f2_expect & t_w1c));                        // a pending event read
      cover (f_wr && |(f1_wdata & f_bmask & t_w1c & f_w1c));         // an event cleared
      cover (f2_rd && |(f2_expect & t_cnt) && f2_expect[0]);        // a counter read
      cover (f2_rd && t_coh == 2'd2 && f2_expect != 32'd0);         // COUNT_HI latched
      cover (f_load && f1_wstrb == 4'b0101 && f_stage != 32'd0);    // a load from a staged word
      cover (f_clr && |(f_cfg & t_clr));                            // a hardware clear
      cover (f2_pulse && t_chan && f_c == CHANNELS - 1);            // a pulse, last channel
      cover (f2_rd && t_chan && f_c != 4'd0 && |(f2_expect & t_cfg));  // another page's storage
    end
  end

endmodule

`default_nettype wire
