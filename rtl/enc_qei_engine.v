// SPDX-License-Identifier: Apache-2.0
// enc_qei_engine -- the shared channel engine of enc_qei (parameter ENGINE = 1): CHANNELS lanes
// (enc_qei_lane: filters, decode, the count's low bits, the captures that must see every clock)
// and one engine that keeps every channel's registers and wide values in block RAM
// (enc_qei_ram) and visits the channels one after another, V = 24 clocks each:
//
//   visit v processes channel c(v) = v mod CH_EFF (CH_EFF = max(CHANNELS, 2): one idle slot with
//   one channel) and prepares c(v + 1):
//     slots 0..19  write c(v - 1)'s results (20 words)
//     slots 1..9   read c(v + 1)'s configuration, count and COUNT_HI stage (each comes a clock
//                  later); slot 9: take its waiting bus write (if any)
//     slots 10..22 read c(v)'s state words
//     slots 11..20 c(v + 1)'s push: its configuration with its bus write applied, and the
//                  validity sets (rtl/enc_qei_lane.vh) for its CEILING and COMPARE
//     slot  21     c(v + 1)'s lane, when its bus write is a COUNT write: the value (C_PLO, C_VS_LOAD)
//     slot  22     c(v + 1)'s lane: its configuration (with its bus write; ld: the COUNT load)
//     slot  23     c(v + 1)'s lane is read: the end of its window, the start of the next; the
//                  timebase now (tv) is the time of the read. c(v)'s new state is computed from
//                  its old state, the record its lane gave at its read (the end of visit v - 1),
//                  its configuration and the bus write taken for it; registered at the end of
//                  the slot, written in visit v + 1's slots 0..19
// So a lane is read every P = V * CH_EFF clocks; its window (the clocks from one read to the
// clock before the next) is what the lane's counters hold, and a bus write takes effect in the
// window's last clock (the push: a COUNT write loads the count then, over that clock's step; a
// configuration counts from the read on). MOT_W, TIM_W and ERR_W below are sized from P.
//
// The bus (the channel pages; the global registers are enc_qei_regs'): a read reads the state
// memory's second port at once (the value as of the channel's last visit; answered in a fixed
// number of clocks, see B_RD1 below); a write is put in the channel's write slot (enc_qei_ram
// `u_pend`, one per channel) and answered at once. The
// engine takes a write of a register the lane uses at the channel's next push (it acts from the
// read after it) and writes its results at the visit after; a state write (EVENTS, QERR_COUNT,
// GLITCH_COUNT, IRQ_EN, COUNT_HI) at the channel's next visit, which applies it to the values a
// read showed (not to the window's new events). A second write to a channel, or a read of a
// channel, waits while a write of that channel waits or is being applied, so the bus sees its
// own writes in order. The bounds in clocks: rtl/enc_qei.rdl, CAPS.ENGINE = shared. COUNT_LO read with COUNT_W > 32:
// the high word goes to a latch (one, kept for the last channel read; the one before goes to its
// channel's memory through that channel's write slot), which COUNT_HI reads.
// After rst every channel's words are the registers' reset values: the first visit of each
// channel writes them (and the bus reads them until then).
// Edge FIFOs (EFIFO = 1): not here. enc_qei puts one per channel beside the engine
// (enc_qei_efifo_bank) and answers their registers there; the engine hands it the lanes' steps
// (step_up, step_dn, step_ab, idx_hit: each lane's decode, in the clock of the step) and takes
// the FIFOs' events back through the lanes (EVENTS.EFIFO_THRESH, EFIFO_OVF: R_EFT, R_EFO).
`default_nettype none
`include "enc_params.vh"
`include "enc_qei_lane_w.vh"

module enc_qei_engine #(
    parameter integer CHANNELS   = 1,   // channels (checked by enc_qei)
    parameter integer COUNT_W    = 32,  // counter width (checked by enc_qei: >= 16)
    parameter integer TS_W       = 32,  // timebase width (checked by enc_qei)
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL,  // count functions built (checked by enc_qei)
    parameter integer FIXED_FUNC = -1,  // the one function FUNC_MASK builds, or -1 (from enc_qei)
    parameter integer TIMING     = 1,   // units, as enc_qei_regs's (from enc_qei's PROFILE)
    parameter integer RANGE      = 0,
    parameter integer PROBE      = 0,
    parameter integer PERIOD     = 0,
    parameter integer EFIFO      = 0    // 1: every channel has an edge FIFO (enc_qei_efifo_bank)
) (
    input  wire                clk,
    input  wire                rst,        // synchronous, active high
    // channel-page requests (enc_qei decodes them: a register of a channel page), one at a time
    input  wire                req_valid,  // one clock
    input  wire                req_write,
    input  wire [3:0]          req_ch,     // the page
    input  wire [5:0]          req_word,   // the register's offset / 4
    input  wire [31:0]         req_wdata,
    input  wire [3:0]          req_wstrb,
    output wire                resp_valid, // the answer, 2 or more clocks after req_valid
    output wire [31:0]         resp_rdata,
    // encoder inputs
    input  wire [CHANNELS-1:0] a_in,
    input  wire [CHANNELS-1:0] b_in,
    input  wire [CHANNELS-1:0] z_in,
    input  wire [CHANNELS-1:0] probe_in,
    input  wire                snap_in,
    // the shared timebase and the global snapshot
    input  wire [TS_W-1:0]     timebase,
    input  wire                tick,       // the timebase advances at the end of this clock
    input  wire                gsnap_req,  // a global snapshot is requested in this clock
    output wire                gsnap,      // ... taken in this clock (every lane, GSNAP_TIME)
    output wire [CHANNELS-1:0] irq_pend,   // channel k has an enabled pending event
    output wire [CHANNELS-1:0] cmp_out,    // channel k's compare match (its lane's)
    // the channels' edge FIFOs (EFIFO = 1): the lanes' steps, the FIFOs' events (EVENTS)
    output wire [CHANNELS-1:0]   step_up,    // channel k steps up in this clock
    output wire [CHANNELS-1:0]   step_dn,    // ... down
    output wire [2*CHANNELS-1:0] step_ab,    // ... {A, B} after the step at [2k +: 2]
    output wire [CHANNELS-1:0]   idx_hit,    // channel k's qualified index edge (with the steps)
    input  wire [CHANNELS-1:0]   ef_thresh,  // channel k's FIFO holds THRESH entries or more
    input  wire [CHANNELS-1:0]   ef_ovf      // channel k's FIFO lost a step
);

  `include "enc_qei_regs.vh"

  // ---- the schedule and the lanes' widths ------------------------------------------------------
  localparam integer CH_EFF = (CHANNELS < 2) ? 2 : CHANNELS;  // channels visited (one idle)
  localparam integer CH_W   = 4;                              // channel number bits
  localparam integer V      = `ENC_QEI_ENGINE_V;               // clocks per visit (P = V * CH_EFF)

  // A validity set pushed for the count at one read is in force until the push before the read
  // after next: it must describe every count within 2 P + 4 steps (one a clock at most) of that
  // count, and the lane's low bits must tell such a count's distance from CEILING and COMPARE
  // (up to twice that) by their sign: 2^(MOT_W - 1) > 2 REACH. A capture is at most P + 1 clocks
  // (ticks) older than the read that hands it over; the unit timer is reloaded by the lane for a
  // SNAP_PERIOD below 2^TIM_W and armed by the engine (2^TIM_W ahead at most) above it, which
  // needs 2^TIM_W > 2 P + 64 to arm it in time. Error counts: at most one a clock.
  // (the formulas: rtl/enc_qei_lane_w.vh, which the lane proofs use too)
  localparam integer REACH = `ENC_QEI_ENGINE_REACH(CHANNELS);
  localparam [63:0]  REACH64 = {32'd0, REACH[31:0]};
  localparam integer MOT_W = `ENC_QEI_ENGINE_MOT_W(CHANNELS);
  localparam integer TIM_W = `ENC_QEI_ENGINE_TIM_W(CHANNELS);
  localparam integer ERR_W = `ENC_QEI_ENGINE_ERR_W(CHANNELS);
  `include "enc_qei_lane.vh"  // the lanes' configuration and record (CFG_W, REC_W, C_*, R_*)

  // A count no wider than the lane's low bits is all in them: the free range is then counted
  // as the modulo range with CEILING all ones (the same wraps and events), so that the lane never
  // needs the bits above COUNT_W.
  localparam integer SMALL = (COUNT_W <= MOT_W) ? 1 : 0;

  generate
    // (the lane's bases of motion and errors share one word)
    if (MOT_W + 2 * ERR_W > 32 || TIM_W >= 16) begin : g_bad_widths
`ifdef __ICARUS__
      enc_qei_engine__lane_widths_do_not_fit u_stop ();
`else
      $error("enc_qei_engine: the lanes' widths do not fit the state words");
`endif
    end
  endgenerate

  // ---- the lanes ----------------------------------------------------------------------------------
  reg  [CHANNELS-1:0]       rd_q, cfg_we_q;  // one-hot: the lane read / pushed
  reg                       arm_we_q, pen_we_q, st_we_q, u_we_q, snap_cmd_q, ld_q;
  reg  [CFG_W-1:0]          cfg_push_q;
  reg                       snap_hold_q;
  wire [CHANNELS*REC_W-1:0] recs;
  wire [CHANNELS-1:0]       snap_pend;
  reg  [2:0]                settle_q;  // the filters' settling after rst (FILTER_LEN 3 + 2)

  always @(posedge clk) begin
    if (rst) begin
      settle_q <= 3'd0;
    end else if (settle_q != 3'd5) begin
      settle_q <= settle_q + 3'd1;
    end
  end

  wire valid = (settle_q == 3'd5);

  genvar k;
  generate
    for (k = 0; k < CHANNELS; k = k + 1) begin : g_lane
      enc_qei_lane #(
          .MOT_W (MOT_W),
          .TIM_W (TIM_W),
          .ERR_W (ERR_W),
          .TIMING(TIMING),
          .RANGE (RANGE),
          .PROBE (PROBE),
          .PERIOD(PERIOD),
          .EFIFO (EFIFO),
          .SMALL_W((SMALL != 0) ? COUNT_W : 0)
      ) u_lane (
          .clk      (clk),
          .rst      (rst),
          .valid    (valid),
          .a_in     (a_in[k]),
          .b_in     (b_in[k]),
          .z_in     (z_in[k]),
          .probe_in (probe_in[k]),
          .snap_in  (snap_in),
          .tb_lo    (timebase[TIM_W-1:0]),
          .tick     (tick),
          .gsnap    (gsnap),
          .snap_hold(snap_hold_q),
          .cfg_we   (cfg_we_q[k]),
          .arm_we   (arm_we_q),
          .pen_we   (pen_we_q),
          .st_we    (st_we_q),
          .u_we     (u_we_q),
          .cfg      (cfg_push_q),
          .ld       (ld_q),
          .snap_cmd (snap_cmd_q & cfg_we_q[k]),
          .rd       (rd_q[k]),
          .rec      (recs[k*REC_W +: REC_W]),
          .snap_pend(snap_pend[k]),
          .cmp_out  (cmp_out[k]),
          .step_up  (step_up[k]),
          .step_dn  (step_dn[k]),
          .step_ab  (step_ab[2*k +: 2]),
          .idx_hit  (idx_hit[k]),
          .ef_thresh(ef_thresh[k]),
          .ef_ovf   (ef_ovf[k])
      );
    end
  endgenerate

  // the lanes' records, ORed (every record is 0 but the one read)
  reg [REC_W-1:0] rec_or;
  integer         j;

  always @(*) begin
    rec_or = {REC_W{1'b0}};
    for (j = 0; j < CHANNELS; j = j + 1) begin
      rec_or = rec_or | recs[j*REC_W +: REC_W];
    end
  end

  // ---- global snapshot: every lane captures in one clock, when none has a capture waiting ---------
  // (a lane read in this clock frees its capture in it)
  reg  gsnap_wait_q;
  wire gsnap_now = (gsnap_req | gsnap_wait_q) & ~(|(snap_pend & ~rd_q));

  always @(posedge clk) begin
    if (rst) begin
      gsnap_wait_q <= 1'b0;
      snap_hold_q  <= 1'b0;
    end else begin
      gsnap_wait_q <= (gsnap_req | gsnap_wait_q) & ~gsnap_now;
      snap_hold_q  <= (gsnap_req | gsnap_wait_q) & ~gsnap_now;
    end
  end

  assign gsnap = gsnap_now;

  // ---- schedule ---------------------------------------------------------------------------------------
  reg [4:0]      slot_q;   // 0 .. V - 1
  reg [CH_W-1:0] cp_q;     // the channel processed in this visit: c(v)
  reg [CH_W-1:0] cn_q;     // the next one: c(v + 1)
  reg [CH_W-1:0] cw_q;     // the channel whose results are written now: c(v - 1)

  function [CH_W-1:0] next_ch;
    input [CH_W-1:0] c;
    begin
      next_ch = (c == CH_EFF[CH_W-1:0] - 4'd1) ? {CH_W{1'b0}} : c + 4'd1;
    end
  endfunction

  localparam [4:0] S_LAST = V[4:0] - 5'd1;  // slot 23

  always @(posedge clk) begin
    if (rst) begin
      slot_q <= 5'd0;
      cp_q   <= {CH_W{1'b0}};
      cn_q   <= 4'd1;
      cw_q   <= CH_EFF[CH_W-1:0] - 4'd1;
    end else begin
      if (slot_q == S_LAST) begin
        slot_q <= 5'd0;
        cp_q   <= cn_q;
        cn_q   <= next_ch(cn_q);
        cw_q   <= cp_q;
      end else begin
        slot_q <= slot_q + 5'd1;
      end
    end
  end

  // ---- the state memory: 32 words of 64 bits per channel (20 used) -------------------------------------
  //   W_CNT    the count (COUNT_W bits)
  //   W_CFG    [31:0] CTRL, [40:32] INDEX_CTRL, [44:41] SNAP_CTRL, [58:45] IRQ_EN, [61:59] PROBE_CTRL
  //   W_UD     [31:0] the unit timer's next time (SNAP_CTRL.PERIOD_EN), [63:32] tv of the last read
  //            (read by the unit timer, the stall timer and period capture only: 0 without PERIOD)
  //   W_PCTL   [17:0] PERIOD_CTRL, [18] a measurement runs, [19] ... overflowed, [63:32] its start
  //   W_PRESET, W_CEIL, W_CMP   PRESET, CEILING, COMPARE
  //   W_TMO    [31:0] SNAP_PERIOD, [63:32] STALL_TIMEOUT
  //   W_HI     [31:0] COUNT_HI's latch, [63:32] its staged word (COUNT_W > 32)
  //   W_MOT    [31:0] M, the motion; [63:32] the lane's mpos, qcnt, gcnt at its last read
  //   W_EVT    [13:0] EVENTS, [23:16] STATUS, [47:32] QERR_COUNT, [63:48] GLITCH_COUNT
  //   W_EDGE   [31:0] TE, [63:32] ME: the last selected edge's time and motion
  //   W_SBASE  [31:0] MS, [63:32] MES: the motion and ME at the last snapshot
  //   W_SCNT   SNAP_COUNT; W_STIME [31:0] SNAP_TIME, [63:32] SNAP_EDGE_TIME;
  //   W_SDELTA [31:0] SNAP_DELTA, [63:32] SNAP_EDGE_DELTA; W_ILATCH INDEX_LATCH; W_PLATCH
  //            PROBE_LATCH; W_PTIME [31:0] PROBE_TIME, [63:32] PERIOD
  //   W_STL    [32:0] ticks since the stall timer's last restart at the last read (clamped; 0
  //            without PERIOD)
  // (The words of a unit the build leaves out are loaded as constants: see the loads below.)
  localparam [4:0] W_CNT = 5'd0, W_CFG = 5'd1, W_UD = 5'd2, W_PCTL = 5'd3, W_PRESET = 5'd4,
                   W_CEIL = 5'd5, W_CMP = 5'd6, W_TMO = 5'd7, W_HI = 5'd8, W_MOT = 5'd9,
                   W_EVT = 5'd10, W_EDGE = 5'd11, W_SBASE = 5'd12, W_SCNT = 5'd13, W_STIME = 5'd14,
                   W_SDELTA = 5'd15, W_ILATCH = 5'd16, W_PLATCH = 5'd17, W_PTIME = 5'd18,
                   W_STL = 5'd19;
  localparam integer AW = CH_W + 5;

  reg             we;
  reg  [AW-1:0]   waddr;
  reg  [63:0]     wdata, wmask;
  reg  [AW-1:0]   raddr_a;
  wire [63:0]     rdata_a, rdata_b;
  wire [AW-1:0]   raddr_b;

  enc_qei_ram #(
      .W (64),
      .AW(AW)
  ) u_mem (
      .clk    (clk),
      .we     (we),
      .waddr  (waddr),
      .wdata  (wdata),
      .wmask  (wmask),
      .raddr_a(raddr_a),
      .rdata_a(rdata_a),
      .raddr_b(raddr_b),
      .rdata_b(rdata_b)
  );

  // the engine's reads: slot s reads what comes in slot s + 1
  always @(*) begin
    case (slot_q)
      5'd1:    raddr_a = {cn_q, W_CNT};
      5'd2:    raddr_a = {cn_q, W_CFG};
      5'd3:    raddr_a = {cn_q, W_UD};
      5'd4:    raddr_a = {cn_q, W_PCTL};
      5'd5:    raddr_a = {cn_q, W_PRESET};
      5'd6:    raddr_a = {cn_q, W_CEIL};
      5'd7:    raddr_a = {cn_q, W_CMP};
      5'd8:    raddr_a = {cn_q, W_TMO};
      5'd9:    raddr_a = {cn_q, W_HI};
      5'd10:   raddr_a = {cp_q, W_CNT};
      5'd11:   raddr_a = {cp_q, W_MOT};
      5'd12:   raddr_a = {cp_q, W_EVT};
      5'd13:   raddr_a = {cp_q, W_EDGE};
      5'd14:   raddr_a = {cp_q, W_SBASE};
      5'd15:   raddr_a = {cp_q, W_HI};
      5'd16:   raddr_a = {cp_q, W_CFG};
      5'd17:   raddr_a = {cp_q, W_PRESET};
      5'd18:   raddr_a = {cp_q, W_CEIL};
      5'd19:   raddr_a = {cp_q, W_TMO};
      5'd20:   raddr_a = {cp_q, W_PCTL};
      5'd21:   raddr_a = {cp_q, W_UD};
      default: raddr_a = {cp_q, W_STL};  // (slot 22; the other slots read it unused)
    endcase
  end

  reg [63:0] n_cnt, n_cfg, n_ud, n_pctl, n_pre, n_ceil, n_cmp, n_tmo, n_hi;  // c(v + 1)'s
  // c(v)'s, as of the end of its window
  reg [63:0] o_cnt, o_mot, o_evt, o_edge, o_sbase, o_hi, o_cfg, o_pre, o_ceil, o_tmo, o_pctl, o_ud;

  wire [63:0] r_stl = rdata_a;  // (in slot 23, the compute's)

  // ---- bus writes wait in a slot per channel ------------------------------------------------------------
  // {word offset 6, byte enables 4, data 32}. A COUNT_LO write is put there whole: the bus merges
  // the lanes it does not write from COUNT (the value a read gives now). SAVE_LATCH: the COUNT_HI
  // latch of a channel, for its memory.
  localparam [5:0]   SAVE_LATCH = 6'h3F;  // (no register has this offset)
  localparam integer PW         = 42;
  reg  [CHANNELS-1:0] pend_q;             // channel k has a write waiting
  reg  [CHANNELS-1:0] busy_q;             // ... a write of channel k is being applied
  reg                 pend_we;
  reg  [CH_W-1:0]     pend_wch;
  reg  [PW-1:0]       pend_wdata;
  wire [PW-1:0]       pend_rdata, pend_rdata_b;
  reg  [CHANNELS-1:0] pend_st_q;          // ... of a register the lane does not use (a state write)
  reg  [CHANNELS-1:0] pend_set;           // this clock: the bus posts a write,
  reg                 pend_set_st;        // ... a state write
  reg  [CHANNELS-1:0] take_oh, done_oh;   // ... the engine took one; its results are written

  enc_qei_ram #(
      .W (PW),
      .AW(CH_W)
  ) u_pend (
      .clk    (clk),
      .we     (pend_we),
      .waddr  (pend_wch),
      .wdata  (pend_wdata),
      .wmask  ({PW{1'b1}}),
      .raddr_a(cn_q),
      .rdata_a(pend_rdata),
      .raddr_b(cp_q),
      .rdata_b(pend_rdata_b)
  );

  always @(posedge clk) begin
    if (rst) begin
      pend_q    <= {CHANNELS{1'b0}};
      busy_q    <= {CHANNELS{1'b0}};
      pend_st_q <= {CHANNELS{1'b0}};
    end else begin
      pend_q <= (pend_q & ~take_oh) | pend_set;
      busy_q <= (busy_q & ~done_oh) | take_oh;
      if (|pend_set) begin
        pend_st_q <= (pend_st_q & ~pend_set) | (pend_set & {CHANNELS{pend_set_st}});
      end
    end
  end

  function bit_of;
    input [CHANNELS-1:0] p;
    input [CH_W-1:0]     c;
    integer              i;
    begin
      bit_of = 1'b0;
      for (i = 0; i < CHANNELS; i = i + 1) begin
        if (c == i[CH_W-1:0]) bit_of = p[i];
      end
    end
  endfunction

  function [CHANNELS-1:0] onehot;
    input [CH_W-1:0] c;
    integer          i;
    begin
      onehot = {CHANNELS{1'b0}};
      for (i = 0; i < CHANNELS; i = i + 1) begin
        if (c == i[CH_W-1:0]) onehot[i] = 1'b1;
      end
    end
  endfunction

  // A write of a register the lane uses (its configuration, COUNT_LO, SNAP_CTRL.CMD) waits for
  // the channel's push: c(v + 1)'s is taken in slot 9 (its data comes in slot 10). Any other (a
  // state write: EVENTS, QERR_COUNT, GLITCH_COUNT, IRQ_EN, COUNT_HI, a saved COUNT_HI latch) is applied
  // by the channel's next visit: c(v)'s is taken in slot 21 (its data comes in slot 22), so that
  // it acts on what the bus could read when it was written and not on the window after it.
  reg          n_taken, e_taken;
  reg [PW-1:0] n_pend, e_pend;

  always @(posedge clk) begin
    if (rst) begin
      n_taken <= 1'b0;
      e_taken <= 1'b0;
    end else begin
      if (slot_q == 5'd9) begin
        n_taken <= bit_of(pend_q & ~pend_st_q, cn_q);
      end
      if (slot_q == 5'd21) begin
        e_taken <= bit_of(pend_q & pend_st_q, cp_q);
      end
    end
    if (slot_q == 5'd10) begin
      n_pend <= pend_rdata;
    end
    if (slot_q == 5'd22) begin
      e_pend <= pend_rdata_b;
    end
  end

  always @(*) begin
    take_oh = (slot_q == 5'd9) ? (pend_q & ~pend_st_q & onehot(cn_q)) :
              (slot_q == 5'd21) ? (pend_q & pend_st_q & onehot(cp_q)) : {CHANNELS{1'b0}};
  end

  // ---- reset values of the words --------------------------------------------------------------------
  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);
  localparam [31:0] SZ_TS    = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);
  localparam [32:0] TS_ONE_W = {1'b0, SZ_TS} + 33'd1;  // 2^TS_W
  localparam [63:0] CFG_RST  = {2'd0, ENC_QEI_PROBE_CTRL_RESET[2:0], ENC_QEI_IRQ_EN_RESET[13:0],
                                ENC_QEI_SNAP_CTRL_RESET[3:0], ENC_QEI_INDEX_CTRL_RESET[8:0],
                                ENC_QEI_CTRL_RESET};
  localparam [63:0] PRE_RST  = {ENC_QEI_PRESET_HI_RESET, ENC_QEI_PRESET_LO_RESET} & SZ_COUNT;
  localparam [63:0] CEIL_RST = {ENC_QEI_CEILING_HI_RESET, ENC_QEI_CEILING_LO_RESET} & SZ_COUNT;
  localparam [63:0] CMP_RST  = {ENC_QEI_COMPARE_HI_RESET, ENC_QEI_COMPARE_LO_RESET} & SZ_COUNT;
  localparam [63:0] TMO_RST  = {ENC_QEI_STALL_TIMEOUT_RESET & SZ_TS, ENC_QEI_SNAP_PERIOD_RESET & SZ_TS};
  localparam [63:0] PCTL_RST = {46'd0, ENC_QEI_PERIOD_CTRL_RESET[17:0]};
  localparam [63:0] EVT_RST  = 64'd1 << (16 + ENC_QEI_STATUS_DIR);

  reg                wr_on_q;  // the results of a visit are written (from visit 1 on)
  reg [CHANNELS-1:0] fresh_q;  // channel k not visited since rst: its words are the reset values
  // (with two channels visited, c(v + 1) is the channel written in slots 0 .. 19, before its reads)
  wire n_fresh = bit_of(fresh_q, cn_q) & ~(wr_on_q & (cw_q == cn_q));
  wire p_fresh = bit_of(fresh_q, cp_q);

  // The words are registered as read, or as their reset values for a channel not visited since
  // rst (the memory holds nothing for it yet). n_fresh and p_fresh hold for a whole visit (fresh_q
  // changes in slot 19, for c(v - 1), which is c(v + 1) only once it is written: then n_fresh is
  // 0 all along), so the reset value is loaded into the register itself: on the iCE40 and the
  // ECP5 a flip-flop's synchronous set / reset, not a multiplexer after it.
  // A word of a unit the build leaves out (RANGE: CEILING, COMPARE; PERIOD: W_UD, W_PCTL, W_TMO)
  // is loaded as its reset value: the memory holds nothing else for it (its writes are not taken,
  // see CTRL_WR .. PERC_WR; W_UD and W_STL are written 0), and a constant leaves out the
  // arithmetic on it, which synthesis cannot see through the memory.
  always @(posedge clk) begin
    case (slot_q)
      5'd2:  n_cnt   <= n_fresh ? 64'd0 : rdata_a;
      5'd3:  n_cfg   <= n_fresh ? CFG_RST : rdata_a;
      5'd4:  n_ud    <= (PERIOD == 0) ? 64'd0 : rdata_a;  // (read only when not fresh)
      5'd5:  n_pctl  <= (n_fresh || PERIOD == 0) ? PCTL_RST : rdata_a;
      5'd6:  n_pre   <= n_fresh ? PRE_RST : rdata_a;
      5'd7:  n_ceil  <= (n_fresh || RANGE == 0) ? CEIL_RST : rdata_a;
      5'd8:  n_cmp   <= (n_fresh || RANGE == 0) ? CMP_RST : rdata_a;
      5'd9:  n_tmo   <= (n_fresh || PERIOD == 0) ? TMO_RST : rdata_a;
      5'd10: n_hi    <= n_fresh ? 64'd0 : rdata_a;
      5'd11: o_cnt   <= p_fresh ? 64'd0 : rdata_a & SZ_COUNT;
      5'd12: o_mot   <= p_fresh ? 64'd0 : rdata_a;
      5'd13: o_evt   <= p_fresh ? EVT_RST : rdata_a;
      5'd14: o_edge  <= p_fresh ? 64'd0 : rdata_a;
      5'd15: o_sbase <= p_fresh ? 64'd0 : rdata_a;
      5'd16: o_hi    <= p_fresh ? 64'd0 : rdata_a;
      5'd17: o_cfg   <= p_fresh ? CFG_RST : rdata_a;
      5'd18: o_pre   <= p_fresh ? PRE_RST : rdata_a & SZ_COUNT;
      5'd19: o_ceil  <= (p_fresh || RANGE == 0) ? CEIL_RST : rdata_a & SZ_COUNT;
      5'd20: o_tmo   <= (p_fresh || PERIOD == 0) ? TMO_RST : rdata_a;
      5'd21: o_pctl  <= (p_fresh || PERIOD == 0) ? PCTL_RST : rdata_a;
      5'd22: o_ud    <= (p_fresh || PERIOD == 0) ? 64'd0 : rdata_a;
      default: ;
    endcase
  end

  // ---- a bus write, as the push and the visit apply it ---------------------------------------------
  function [31:0] lanes;  // byte enables -> bit mask
    input [3:0] st;
    begin
      lanes = {{8{st[3]}}, {8{st[2]}}, {8{st[1]}}, {8{st[0]}}};
    end
  endfunction

  localparam [31:0] CTRL_WR  = (32'h1 << ENC_QEI_CTRL_EN) | (32'h1 << ENC_QEI_CTRL_SWAP_AB) |
                               (32'h1 << ENC_QEI_CTRL_INV_A) | (32'h1 << ENC_QEI_CTRL_INV_B) |
                               (32'h1 << ENC_QEI_CTRL_INV_Z) | (32'h1F << ENC_QEI_CTRL_FILTER_LEN) |
                               ((FIXED_FUNC >= 0) ? 32'h0 : (32'hF << ENC_QEI_CTRL_FUNC)) |
                               ((RANGE != 0) ? ((32'h1 << ENC_QEI_CTRL_CMP_EN) |
                                                (32'h3 << ENC_QEI_CTRL_RANGE)) : 32'h0);
  localparam [8:0]  ICTRL_WR = 9'h17F;  // ACTION .. GATE_B, ARM
  localparam [3:0]  SCTRL_WR = (TIMING == 0) ? 4'h0 :
                               ((4'h1 << ENC_QEI_SNAP_CTRL_IN_EN) | (4'h1 << ENC_QEI_SNAP_CTRL_EDGE) |
                                ((PERIOD != 0) ? (4'h1 << ENC_QEI_SNAP_CTRL_PERIOD_EN) : 4'h0));
  localparam [2:0]  PCTRL_WR = (PROBE != 0) ? 3'h7 : 3'h0;  // PROBE_CTRL: EN, EDGE, ONCE
  localparam [17:0] PERC_WR  = (PERIOD != 0) ? 18'h0FF03 : 18'h0;  // PERIOD_CTRL: EN, EDGE, N

  // verilator lint_off UNUSEDSIGNAL
  function [5:0] off_of;  // a register's word offset
    input [7:0] a;
    begin
      off_of = a[7:2];
    end
  endfunction
  // verilator lint_on UNUSEDSIGNAL

  // a field (mask m) of a word written with w = {offset, strobes, data} at offset `at`, bit `sh`
  function [63:0] field_w;
    input [63:0] c;
    input [41:0] w;
    input [5:0]  at;
    input [63:0] m;      // the field's bits in the word
    input integer sh;    // the register's bit 0 in the word
    reg   [63:0] lm;
    begin
      lm      = ({32'd0, lanes(w[35:32])} << sh) & m;
      field_w = (w[41:36] == at) ? ((c & ~lm) | (({32'd0, w[31:0]} << sh) & lm)) : c;
    end
  endfunction

  // the configuration word with a write applied
  function [63:0] cfg_written;
    input [63:0] c;
    input [41:0] w;
    reg   [63:0] x;
    begin
      x = field_w(c, w, off_of(ENC_QEI_CTRL), {32'd0, CTRL_WR}, 0);
      x = field_w(x, w, off_of(ENC_QEI_INDEX_CTRL), {23'd0, ICTRL_WR, 32'd0}, 32);
      x = field_w(x, w, off_of(ENC_QEI_SNAP_CTRL), {19'd0, SCTRL_WR, 41'd0}, 41);
      x = field_w(x, w, off_of(ENC_QEI_IRQ_EN), {5'd0, 14'h3FFF, 45'd0}, 45);
      x = field_w(x, w, off_of(ENC_QEI_PROBE_CTRL), {2'd0, PCTRL_WR, 59'd0}, 59);
      cfg_written = x;
    end
  endfunction

  // PRESET, CEILING, COMPARE (lo at lo_at, hi at lo_at + 1) with a write applied
  function [63:0] wide_written;
    input [63:0] c;
    input [41:0] w;
    input [5:0]  lo_at;
    begin
      wide_written = field_w(field_w(c, w, lo_at, 64'hFFFFFFFF, 0), w, lo_at + 6'd1,
                             64'hFFFFFFFF_00000000, 32) & SZ_COUNT;
    end
  endfunction

  function [63:0] tmo_written;  // SNAP_PERIOD, STALL_TIMEOUT
    input [63:0] c;
    input [41:0] w;
    begin
      tmo_written = (PERIOD == 0) ? c :
                    field_w(field_w(c, w, off_of(ENC_QEI_SNAP_PERIOD), {32'd0, SZ_TS}, 0), w,
                            off_of(ENC_QEI_STALL_TIMEOUT), {SZ_TS, 32'd0}, 32);
    end
  endfunction

  function [63:0] pctl_written;
    input [63:0] c;
    input [41:0] w;
    begin
      pctl_written = field_w(c, w, off_of(ENC_QEI_PERIOD_CTRL), {46'd0, PERC_WR}, 0);
    end
  endfunction

  // ---- c(v + 1)'s push ---------------------------------------------------------------------------------
  localparam integer FUNC_ALL    = (1 << ENC_QEI_FUNC_N) - 1;
  localparam [15:0]  FUNC_MASK16 = FUNC_MASK[15:0];

  // FUNC as counted: the one FUNC_MASK builds, or CTRL.FUNC when built, or a code of no function
  function [3:0] func_eff;
    input [3:0] f;
    begin
      if (FIXED_FUNC >= 0) func_eff = FIXED_FUNC[3:0];
      else if (FUNC_MASK == FUNC_ALL || FUNC_MASK16[f]) func_eff = f;
      else func_eff = 4'd15;
    end
  endfunction

  // the filter length clamped to 1 .. 16, minus 1
  function [3:0] last_of;
    input [4:0] len;
    begin
      if (len == 5'd0) last_of = 4'd0;
      else if (len > 5'd16) last_of = 4'd15;
      else last_of = len[3:0] - 4'd1;
    end
  endfunction

  // the validity set of a count value x, for CEILING c and COMPARE m (lane_vs_of of
  // rtl/enc_qei_lane.vh, which the lane's count proof calls too)
  function [3:0] vs_of;
    input [63:0] x;
    input [63:0] c;
    input [63:0] m;
    begin
      vs_of = lane_vs_of(x, c, m, SZ_COUNT, REACH64, RANGE != 0);
    end
  endfunction

  wire [41:0] n_w     = n_taken ? n_pend : {SAVE_LATCH, 36'd0};  // (no write: an offset of nothing)
  wire        n_on    = n_taken & (|n_pend[35:32]);
  wire [5:0]  n_off   = n_pend[41:36];
  wire [63:0] n_cfg_w  = cfg_written(n_cfg, n_w);
  wire [63:0] n_pre_w  = wide_written(n_pre, n_w, off_of(ENC_QEI_PRESET_LO));
  wire [63:0] n_ceil_w = (RANGE != 0) ? wide_written(n_ceil, n_w, off_of(ENC_QEI_CEILING_LO)) : n_ceil;
  wire [63:0] n_cmp_w  = (RANGE != 0) ? wide_written(n_cmp, n_w, off_of(ENC_QEI_COMPARE_LO)) : n_cmp;
  wire [63:0] n_tmo_w  = tmo_written(n_tmo, n_w);
  wire [63:0] n_pctl_w = pctl_written(n_pctl, n_w);
  wire        n_cnt_wr   = n_on & (n_off == off_of(ENC_QEI_COUNT_LO));
  wire        n_ictrl_wr = n_on & (n_off == off_of(ENC_QEI_INDEX_CTRL));
  wire        n_pctrl_wr = n_on & (n_off == off_of(ENC_QEI_PROBE_CTRL)) & (PROBE != 0);
  wire        n_snap_cmd = n_on & (n_off == off_of(ENC_QEI_SNAP_CTRL)) & n_pend[32] &
                           n_pend[ENC_QEI_SNAP_CTRL_CMD] & (TIMING != 0);
  wire [63:0] n_val      = {n_hi[63:32], n_pend[31:0]} & SZ_COUNT;  // a COUNT write's value
  wire [31:0] n_sto      = n_tmo_w[63:32];
  wire        n_st_new   = (PERIOD != 0) & (n_sto != n_tmo[63:32]);
  wire        n_uen_old  = n_cfg[41 + ENC_QEI_SNAP_CTRL_PERIOD_EN];
  wire        n_uen      = n_cfg_w[41 + ENC_QEI_SNAP_CTRL_PERIOD_EN];
  localparam [31:0] TIM_LIM = 32'd1 << TIM_W;  // 2^TIM_W: what the lane times itself is below it

  // the range and the ceiling as the lane counts them (SMALL: the free range as a modulo one)
  // verilator lint_off UNUSEDSIGNAL
  function [63:0] lane_ceil;
    input [63:0] cf;  // (its CTRL.RANGE)
    input [63:0] ceil;
    begin
      lane_ceil = (SMALL != 0 && cf[ENC_QEI_CTRL_RANGE +: 2] == ENC_QEI_RANGE_FREE) ? SZ_COUNT : ceil;
    end
  endfunction
  // verilator lint_on UNUSEDSIGNAL

  wire [63:0] n_lc_w   = lane_ceil(n_cfg_w, n_ceil_w);
  wire [63:0] n_lc_eff = lane_ceil(n_cfg, n_ceil);

  // the validity sets, one a clock (slots 11 .. 17): the count at the last read, PRESET (and the
  // one it replaces), 0, CEILING (and the one it replaces), a COUNT write's value
  reg  [3:0]  vs_cnt_q, vs_load_q, vs_zero_q, vs_ceil_q, vso_load_q, vso_ceil_q, vs_val_q;
  reg  [63:0] vs_x;

  always @(*) begin
    case (slot_q)
      5'd11:   vs_x = n_cnt;
      5'd12:   vs_x = n_pre_w;
      5'd13:   vs_x = 64'd0;
      5'd14:   vs_x = n_lc_w;
      5'd15:   vs_x = n_pre;
      5'd16:   vs_x = n_lc_eff;
      default: vs_x = n_val;
    endcase
  end

  wire [3:0] vs_r = vs_of(vs_x, n_lc_w, n_cmp_w);

  always @(posedge clk) begin
    case (slot_q)
      5'd11: vs_cnt_q   <= vs_r;
      5'd12: vs_load_q  <= vs_r;
      5'd13: vs_zero_q  <= vs_r;
      5'd14: vs_ceil_q  <= vs_r;
      5'd15: vso_load_q <= vs_r;
      5'd16: vso_ceil_q <= vs_r;
      5'd17: vs_val_q   <= vs_r;
      default: ;
    endcase
  end

  // (push_of takes whole words: the lane keeps their low bits)
  // verilator lint_off UNUSEDSIGNAL
  function [CFG_W-1:0] push_of;
    input [63:0]      cf;     // the configuration word
    input [63:0]      pctl;   // PERIOD_CTRL's word
    input [63:0]      tmo;    // SNAP_PERIOD, STALL_TIMEOUT
    input [63:0]      pre;    // PRESET, or a COUNT write's value
    input [63:0]      ceil;
    input [63:0]      cmpv;
    input [3:0]       vs_load;
    input [TIM_W-1:0] ud;     // the unit timer's time
    reg   [31:0] ctrl;
    reg   [8:0]  ictrl;
    reg   [3:0]  sctrl;
    reg   [2:0]  prc;
    reg   [31:0] per, sto;
    begin
      ctrl  = cf[31:0];
      ictrl = cf[40:32];
      sctrl = cf[44:41];
      prc   = cf[61:59];
      per   = (tmo[31:0] == 32'd0) ? 32'd1 : tmo[31:0];
      sto   = tmo[63:32];
      push_of[C_EN]                 = ctrl[ENC_QEI_CTRL_EN];
      push_of[C_SWAP]               = ctrl[ENC_QEI_CTRL_SWAP_AB];
      push_of[C_INV_A]              = ctrl[ENC_QEI_CTRL_INV_A];
      push_of[C_INV_B]              = ctrl[ENC_QEI_CTRL_INV_B];
      push_of[C_INV_Z]              = ctrl[ENC_QEI_CTRL_INV_Z];
      push_of[C_FUNC +: C_FUNC_W]   = func_eff(ctrl[ENC_QEI_CTRL_FUNC +: 4]);
      push_of[C_LAST +: C_LAST_W]   = last_of(ctrl[ENC_QEI_CTRL_FILTER_LEN +: 5]);
      push_of[C_RANGE +: C_RANGE_W] = (SMALL != 0 && ctrl[ENC_QEI_CTRL_RANGE +: 2] == ENC_QEI_RANGE_FREE) ?
                                      ENC_QEI_RANGE_MODULO : ctrl[ENC_QEI_CTRL_RANGE +: 2];
      push_of[C_CMP_EN]             = ctrl[ENC_QEI_CTRL_CMP_EN];
      push_of[C_ACT +: C_ACT_W]     = ictrl[ENC_QEI_INDEX_CTRL_ACTION +: 2];
      push_of[C_ONESHOT]            = ictrl[ENC_QEI_INDEX_CTRL_ONESHOT];
      push_of[C_IEDGE]              = ictrl[ENC_QEI_INDEX_CTRL_EDGE];
      push_of[C_GATE_EN]            = ictrl[ENC_QEI_INDEX_CTRL_GATE_EN];
      push_of[C_GATE_A]             = ictrl[ENC_QEI_INDEX_CTRL_GATE_A];
      push_of[C_GATE_B]             = ictrl[ENC_QEI_INDEX_CTRL_GATE_B];
      push_of[C_ARM]                = ictrl[ENC_QEI_INDEX_CTRL_ARM];
      push_of[C_SIN_EN]             = sctrl[ENC_QEI_SNAP_CTRL_IN_EN];
      push_of[C_SEDGE]              = sctrl[ENC_QEI_SNAP_CTRL_EDGE];
      push_of[C_UEN]                = sctrl[ENC_QEI_SNAP_CTRL_PERIOD_EN];
      push_of[C_PEN]                = prc[ENC_QEI_PROBE_CTRL_EN];
      push_of[C_PEDGE]              = prc[ENC_QEI_PROBE_CTRL_EDGE];
      push_of[C_PONCE]              = prc[ENC_QEI_PROBE_CTRL_ONCE];
      push_of[C_PER_EN]             = pctl[ENC_QEI_PERIOD_CTRL_EN];
      push_of[C_PER_EDGE]           = pctl[ENC_QEI_PERIOD_CTRL_EDGE];
      push_of[C_PER_N +: C_PER_N_W] = (pctl[15:8] == 8'd0) ? 8'd0 : pctl[15:8] - 8'd1;
      push_of[C_STO +: C_STO_W]     = (sto < TIM_LIM) ? sto[TIM_W-1:0] : {TIM_W{1'b0}};
      push_of[C_UPER +: C_UPER_W]   = (per < TIM_LIM) ? per[TIM_W-1:0] : {TIM_W{1'b0}};
      push_of[C_UD +: C_UD_W]       = ud;
      push_of[C_PLO +: C_PLO_W]     = pre[MOT_W-1:0];
      push_of[C_CLO +: C_CLO_W]     = ceil[MOT_W-1:0];
      push_of[C_MLO +: C_MLO_W]     = cmpv[MOT_W-1:0];
      push_of[C_VS_CNT +: VS_W]     = vs_cnt_q;
      push_of[C_VS_LOAD +: VS_W]    = vs_load;
      push_of[C_VS_ZERO +: VS_W]    = vs_zero_q;
      push_of[C_VS_CEIL +: VS_W]    = vs_ceil_q;
      push_of[C_VSO_LOAD +: VS_W]   = vso_load_q;
      push_of[C_VSO_CEIL +: VS_W]   = vso_ceil_q;
    end
  endfunction
  // verilator lint_on UNUSEDSIGNAL

  // the unit timer: armed for its next time once that is within the lane's reach (at least 3
  // ticks ahead when computed: the lane has it 2 clocks later)
  wire [31:0] n_udist = (n_ud[31:0] - {{(32-TS_W){1'b0}}, timebase}) & SZ_TS;
  wire        n_uarm  = (PERIOD != 0) & ~n_fresh & n_uen_old & n_uen &
                        (n_udist >= 32'd3) & (n_udist < TIM_LIM);

  // slot 21: a COUNT write's value (push #1); slot 22: the configuration with the write
  always @(posedge clk) begin
    if (rst) begin
      cfg_we_q   <= {CHANNELS{1'b0}};
      rd_q       <= {CHANNELS{1'b0}};
      arm_we_q   <= 1'b0;
      pen_we_q   <= 1'b0;
      st_we_q    <= 1'b0;
      u_we_q     <= 1'b0;
      ld_q       <= 1'b0;
      snap_cmd_q <= 1'b0;
    end else begin
      cfg_we_q   <= ((slot_q == 5'd20 && n_cnt_wr) || slot_q == 5'd21) ? onehot(cn_q) : {CHANNELS{1'b0}};
      rd_q       <= (slot_q == 5'd22) ? onehot(cn_q) : {CHANNELS{1'b0}};
      arm_we_q   <= (slot_q == 5'd21) & n_ictrl_wr;
      pen_we_q   <= (slot_q == 5'd21) & n_pctrl_wr;
      st_we_q    <= (slot_q == 5'd21) & n_st_new;
      u_we_q     <= (slot_q == 5'd21) & n_uarm;
      ld_q       <= (slot_q == 5'd21) & n_cnt_wr;
      snap_cmd_q <= (slot_q == 5'd21) & n_snap_cmd;
    end
  end

  always @(posedge clk) begin
    if (slot_q == 5'd20) begin
      cfg_push_q <= push_of(n_cfg, n_pctl, n_tmo, n_val, n_lc_eff, n_cmp,
                            vs_val_q, n_ud[TIM_W-1:0]);
    end else if (slot_q == 5'd21) begin
      cfg_push_q <= push_of(n_cfg_w, n_pctl_w, n_tmo_w, n_pre_w, n_lc_w, n_cmp_w,
                            vs_load_q, n_ud[TIM_W-1:0]);
    end
  end

  // what the next visit needs of this push (the write's effects on the state)
  reg [PW-1:0] p_pend;
  reg          p_taken, p_st_new, p_uen_rise;

  always @(posedge clk) begin
    if (rst) begin  // (channel 0's first visit: it had no push)
      p_pend     <= {PW{1'b0}};
      p_taken    <= 1'b0;
      p_st_new   <= 1'b0;
      p_uen_rise <= 1'b0;
    end else if (slot_q == S_LAST) begin
      p_pend     <= n_pend;
      p_taken    <= n_taken;
      p_st_new   <= n_st_new & n_taken;
      p_uen_rise <= n_taken & n_uen & ~n_uen_old;
    end
  end

  // ---- the visit's computation for c(v) (slot 23) ----------------------------------------------------------
  // (channel 0's first visit, after rst: its lane as rst left it, at timebase 0: the record
  // REC_RST of enc_qei_lane.vh; its first write-back stores it)
  reg [REC_W-1:0] rec_q;      // c(v)'s record (its lane, in the clock of its read)
  reg [TS_W-1:0]  tv_q;       // the timebase in that clock

  always @(posedge clk) begin
    if (rst) begin
      rec_q <= REC_RST;
      tv_q  <= {TS_W{1'b0}};
    end else if (slot_q == S_LAST) begin
      rec_q <= rec_or;
      tv_q  <= timebase;
    end
  end

  // the words as of the end of the window (reset values on the first visit: see the loads)
  wire [63:0] o_stl   = p_fresh ? 64'd0 : r_stl;  // (read in this slot)

  wire [MOT_W-1:0] mb = o_mot[32 +: MOT_W];                  // mpos at the last read
  wire [ERR_W-1:0] qb = o_mot[32 + MOT_W +: ERR_W];          // qcnt ...
  wire [ERR_W-1:0] gb = o_mot[32 + MOT_W + ERR_W +: ERR_W];  // gcnt ...
  wire [31:0]      m0 = o_mot[31:0];                         // the motion at the last read
  wire [31:0]      tv = {{(32-TS_W){1'b0}}, tv_q};
  wire [31:0]      vt = o_ud[63:32] & SZ_TS;                 // the read before

  // the full timestamp of low bits t, taken at most 2^TIM_W - 1 ticks before now (functions take
  // every signal they use as an input: a continuous assignment follows only its inputs). It and
  // lane_sdiff, the signed difference of two lane positions, are rtl/enc_qei_lane.vh's, which
  // the lane's proof uses too.
  function [31:0] tstamp;
    input [TIM_W-1:0] t;
    input [31:0]      now;
    begin
      tstamp = lane_tstamp(t, now) & SZ_TS;
    end
  endfunction

  function [31:0] tdiff;  // a - b, ticks
    input [31:0] a;
    input [31:0] b;
    begin
      tdiff = (a - b) & SZ_TS;
    end
  endfunction

  wire [MOT_W-1:0] x_mpos  = rec_q[R_MPOS +: R_MPOS_W];
  wire [MOT_W-1:0] x_lo    = rec_q[R_LO +: R_LO_W];
  wire [1:0]       x_anc   = rec_q[R_ANC +: R_ANC_W];
  wire             x_lpend = rec_q[R_LPEND];
  wire [MOT_W-1:0] x_lcap  = rec_q[R_LCAP +: R_LCAP_W];
  wire [1:0]       x_lanc  = rec_q[R_LANC +: R_LANC_W];
  wire             x_spend = rec_q[R_SPEND];
  wire [MOT_W-1:0] x_smpos = rec_q[R_SMPOS +: R_SMPOS_W];
  wire [MOT_W-1:0] x_slo   = rec_q[R_SLO +: R_SLO_W];
  wire [1:0]       x_sanc  = rec_q[R_SANC +: R_SANC_W];
  wire [TIM_W-1:0] x_stime = rec_q[R_STIME +: R_STIME_W];
  wire [TIM_W-1:0] x_set   = rec_q[R_SET +: R_SET_W];
  wire [MOT_W-1:0] x_semp  = rec_q[R_SEMP +: R_SEMP_W];
  wire             x_snew  = rec_q[R_SNEW];
  wire             x_sedge = rec_q[R_SEDGE];
  wire [TIM_W-1:0] x_et    = rec_q[R_ET +: R_ET_W];
  wire [MOT_W-1:0] x_emp   = rec_q[R_EMP +: R_EMP_W];
  wire             x_enew  = rec_q[R_ENEW];
  wire [ERR_W-1:0] x_qcnt  = rec_q[R_QCNT +: R_QCNT_W];
  wire [ERR_W-1:0] x_gcnt  = rec_q[R_GCNT +: R_GCNT_W];
  wire             x_ppend = rec_q[R_PPEND];
  wire [MOT_W-1:0] x_plo   = rec_q[R_PLO +: R_PLO_W];
  wire [1:0]       x_panc  = rec_q[R_PANC +: R_PANC_W];
  wire [TIM_W-1:0] x_ptime = rec_q[R_PTIME +: R_PTIME_W];
  wire [TIM_W-1:0] x_g     = rec_q[R_G +: R_G_W];
  wire             x_grst  = rec_q[R_GRST];
  wire [TIM_W-1:0] x_fst   = rec_q[R_FST +: R_FST_W];
  wire [1:0]       x_nb    = rec_q[R_NB +: R_NB_W];
  wire             x_bst   = rec_q[R_BST];
  wire [TIM_W-1:0] x_bf    = rec_q[R_BF +: R_BF_W];
  wire [TIM_W-1:0] x_bt    = rec_q[R_BT +: R_BT_W];
  wire [TIM_W-1:0] x_bt0   = rec_q[R_BT0 +: R_BT0_W];
  wire [TIM_W-1:0] x_ud    = rec_q[R_UD +: R_UD_W];

  // c(v)'s write, applied at the end of the window
  // (a write the push took, or a state write taken now: never both, a taken write blocks the bus)
  wire [41:0] w_w      = p_taken ? p_pend : e_taken ? e_pend : {SAVE_LATCH, 36'd0};
  wire        w_on     = (p_taken | e_taken) & (|w_w[35:32]);
  wire [5:0]  w_off    = w_w[41:36];
  wire [31:0] w_mask   = lanes(w_w[35:32]);
  wire [31:0] w_data   = w_w[31:0];
  wire        w_cnt_lo = w_on & (w_off == off_of(ENC_QEI_COUNT_LO));
  wire        w_cnt_hi = w_on & (w_off == off_of(ENC_QEI_COUNT_HI));
  wire        w_events = w_on & (w_off == off_of(ENC_QEI_EVENTS));
  wire        w_qerr   = w_on & (w_off == off_of(ENC_QEI_QERR_COUNT));
  wire        w_glitch = w_on & (w_off == off_of(ENC_QEI_GLITCH_COUNT));
  wire        w_save   = w_on & (w_off == SAVE_LATCH);
  wire [63:0] w_val    = {o_hi[63:32], w_data} & SZ_COUNT;  // a COUNT_LO write's value (whole)

  // a count from a lane's low bits and their anchor (ld_base: the value of A_LOAD): lane_rebuild
  // of rtl/enc_qei_lane.vh, which the lane's count proof calls too
  function [63:0] rebuild;
    input [MOT_W-1:0] lo;
    input [1:0]       anc;
    input [63:0]      ld_base;  // the value of A_LOAD,
    input [63:0]      ceil;     // ... of A_CEIL,
    input [63:0]      cnt;      // ... of A_NONE
    begin
      rebuild = lane_rebuild(lo, anc, ld_base, ceil, cnt, SZ_COUNT);
    end
  endfunction

  // the count now (a COUNT write loaded in the window's last clock: its value is the anchor)
  wire [63:0] cnt_n = rebuild(x_lo, x_anc, w_cnt_lo ? w_val : o_pre, o_ceil, o_cnt);

  // the motion, the last selected edge, the snapshot
  wire [63:0] d_mpos = lane_sdiff(x_mpos, mb);   // the window's motion
  wire [63:0] d_emp  = lane_sdiff(x_emp, mb);    // ... up to its last selected edge
  wire [63:0] d_smp  = lane_sdiff(x_smpos, mb);  // ... up to the snapshot
  wire [63:0] d_semp = lane_sdiff(x_semp, mb);   // ... up to the snapshot's last selected edge
  wire [31:0] m_r    = m0 + d_mpos[31:0];
  wire [31:0] te_n   = x_enew ? tstamp(x_et, tv) : o_edge[31:0];
  wire [31:0] me_n   = x_enew ? m0 + d_emp[31:0] : o_edge[63:32];
  wire [31:0] ms_s   = m0 + d_smp[31:0];
  wire [63:0] cnt_s  = rebuild(x_slo, x_sanc, o_pre, o_ceil, o_cnt);
  wire [31:0] t_s    = tstamp(x_stime, tv);
  wire [31:0] te_s   = x_sedge ? t_s : x_snew ? tstamp(x_set, tv) : o_edge[31:0];
  wire [31:0] me_s   = x_sedge ? ms_s : x_snew ? m0 + d_semp[31:0] : o_edge[63:32];

  // the stall timer (PERIOD): the lane times a STALL_TIMEOUT below 2^TIM_W; a longer one is
  // timed here, from the ticks since its restart at the read before (el) and the window's
  wire [31:0] sto_win  = o_tmo[63:32] & SZ_TS;
  wire        st_small = (sto_win != 32'd0) & (sto_win < TIM_LIM);
  wire        st_large = (sto_win >= TIM_LIM);
  wire [32:0] el_prev  = o_stl[32:0];
  wire [32:0] el_tv    = el_prev + {1'b0, tdiff(tv, vt)};
  wire [32:0] el_gap   = el_prev + {1'b0, tdiff(tstamp(x_fst, tv), vt)};  // at the first restart
  wire        stalled_prev = o_evt[16 + ENC_QEI_STATUS_STALLED];
  wire        hit_a    = st_large & x_grst & ~stalled_prev & (el_gap >= {1'b0, sto_win});
  wire        hit_b    = st_large & ~x_grst & ~stalled_prev & (el_tv >= {1'b0, sto_win});
  wire        ev_stall = (PERIOD != 0) & (st_small ? rec_q[R_SEV] : (hit_a | hit_b));
  wire        stalled_n = (PERIOD != 0) & ~p_st_new &
                          (st_small ? rec_q[R_STALLED] : (st_large & ~x_grst & (stalled_prev | hit_b)));
  wire [32:0] el_n     = p_st_new ? 33'd0 :
                         x_grst ? {{(33 - TIM_W){1'b0}}, x_g} :
                         (el_tv > TS_ONE_W) ? TS_ONE_W : el_tv;

  // period capture (PERIOD): the measurement running at the window's start (m0: from pstart)
  // ends at its first boundary (x_bf); the last one (to x_bt) started at x_bt0 when in the window
  wire        per_en_win = o_pctl[ENC_QEI_PERIOD_CTRL_EN];
  wire        prun_prev  = o_pctl[18];
  wire        povf_prev  = o_pctl[19];
  wire [31:0] pstart     = o_pctl[63:32] & SZ_TS;
  wire        pm0        = (PERIOD != 0) & per_en_win & prun_prev;
  wire [31:0] pe_prev    = tdiff(vt, pstart);
  wire [31:0] t_bt       = tstamp(x_bt, tv);
  wire [32:0] pe_bf      = {1'b0, pe_prev} + {1'b0, tdiff(tstamp(x_bf, tv), vt)};
  wire [32:0] pe_tv      = {1'b0, pe_prev} + {1'b0, tdiff(tv, vt)};
  wire        pnb        = (PERIOD != 0) & (x_nb != 2'd0);
  wire        pm0_ovf    = povf_prev | (pe_bf >= TS_ONE_W);
  wire        ev_pover   = pm0 & ~povf_prev & (pnb ? (pe_bf >= TS_ONE_W) : (pe_tv >= TS_ONE_W));
  wire        plast_m0   = pm0 & (x_nb == 2'd1);  // the last measurement is m0
  wire        povf_last  = plast_m0 & pm0_ovf;
  wire [31:0] period_v   = povf_last ? SZ_TS : tdiff(t_bt, plast_m0 ? pstart : tstamp(x_bt0, tv));
  wire        prestart   = pnb | ((PERIOD != 0) & x_bst);
  wire [63:0] pctl_wr = pctl_written(o_pctl, w_w);
  wire [63:0] pctl_n;
  assign pctl_n[17:0]  = {pnb ? rec_q[R_BDIR] : o_pctl[17], pnb ? povf_last : o_pctl[16],
                          pctl_wr[15:0]};
  assign pctl_n[18]    = (PERIOD != 0) & rec_q[R_PRUN];
  assign pctl_n[19]    = ~prestart & (povf_prev | ev_pover);
  assign pctl_n[31:20] = 12'd0;
  assign pctl_n[63:32] = prestart ? t_bt : pstart;

  // the unit timer's next time (SNAP_CTRL.PERIOD_EN): the lane's when armed; else, after the time
  // the engine armed it for, that plus SNAP_PERIOD; PERIOD_EN set by the write: from the read
  wire [31:0] per_win = ((o_tmo[31:0] & SZ_TS) == 32'd0) ? 32'd1 : o_tmo[31:0] & SZ_TS;
  wire [63:0] tmo_n   = tmo_written(o_tmo, w_w);
  wire [31:0] per_new = ((tmo_n[31:0] & SZ_TS) == 32'd0) ? 32'd1 : tmo_n[31:0] & SZ_TS;
  wire [31:0] ud_prev = o_ud[31:0];
  wire [31:0] ud_n    = p_uen_rise ? ((tv + per_new) & SZ_TS) :
                        rec_q[R_UARM] ? ((tv + {{(32 - TIM_W){1'b0}}, x_ud - tv_q[TIM_W-1:0]}) & SZ_TS) :
                        rec_q[R_UHIT] ? ((ud_prev + per_win) & SZ_TS) : ud_prev;

  // events, error counts, status
  wire [ERR_W-1:0] dq = x_qcnt - qb;
  wire [ERR_W-1:0] dg = x_gcnt - gb;

  function [15:0] sat_add;
    input [15:0]      a;
    input [ERR_W-1:0] b;
    reg   [16:0]      sm;
    begin
      sm      = {1'b0, a} + {{(17 - ERR_W){1'b0}}, b};
      sat_add = sm[16] ? 16'hFFFF : sm[15:0];
    end
  endfunction

  wire [13:0] ev_new;
  assign ev_new[ENC_QEI_EVENTS_OVERFLOW]     = rec_q[R_OVF];
  assign ev_new[ENC_QEI_EVENTS_UNDERFLOW]    = rec_q[R_UNF];
  assign ev_new[ENC_QEI_EVENTS_INDEX]        = rec_q[R_IDX];
  assign ev_new[ENC_QEI_EVENTS_PROBE]        = x_ppend;
  assign ev_new[ENC_QEI_EVENTS_CMP]          = rec_q[R_CMP];
  assign ev_new[ENC_QEI_EVENTS_QERR]         = (dq != {ERR_W{1'b0}});
  assign ev_new[ENC_QEI_EVENTS_GLITCH]       = (dg != {ERR_W{1'b0}});
  assign ev_new[ENC_QEI_EVENTS_DIR_CHANGE]   = rec_q[R_DCH];
  assign ev_new[ENC_QEI_EVENTS_STALL]        = ev_stall;
  assign ev_new[ENC_QEI_EVENTS_SNAP_READY]   = x_spend;
  assign ev_new[ENC_QEI_EVENTS_PERIOD_READY] = pnb;
  assign ev_new[ENC_QEI_EVENTS_PERIOD_OVF]   = ev_pover;
  assign ev_new[ENC_QEI_EVENTS_EFIFO_THRESH] = rec_q[R_EFT];
  assign ev_new[ENC_QEI_EVENTS_EFIFO_OVF]    = rec_q[R_EFO];

  // (a clear acts on the events the bus could read, the window's new ones stay)
  wire [13:0] events_n = (o_evt[13:0] & ~(w_events ? w_mask[13:0] & w_data[13:0] : 14'd0)) | ev_new;
  wire [15:0] qerr_n   = sat_add(w_qerr ? 16'd0 : o_evt[47:32], dq);
  wire [15:0] glitch_n = sat_add(w_glitch ? 16'd0 : o_evt[63:48], dg);
  wire [7:0]  status_n;
  assign status_n[ENC_QEI_STATUS_A]           = rec_q[R_A];
  assign status_n[ENC_QEI_STATUS_B]           = rec_q[R_B];
  assign status_n[ENC_QEI_STATUS_Z]           = rec_q[R_Z];
  assign status_n[ENC_QEI_STATUS_DIR]         = rec_q[R_DIR];
  assign status_n[ENC_QEI_STATUS_INDEX_ARMED] = rec_q[R_ARMED];
  assign status_n[ENC_QEI_STATUS_STALLED]     = stalled_n;
  assign status_n[ENC_QEI_STATUS_STOPPED]     = rec_q[R_STOPPED];
  assign status_n[ENC_QEI_STATUS_VALID]       = valid;

  // the configuration word: the write, with INDEX_CTRL.ARM and PROBE_CTRL.EN as the lane has them
  // (its one-shots clear them; a write of them is the lane's since the push)
  wire [63:0] cfg_wr = cfg_written(o_cfg, w_w);
  wire [63:0] cfg_n  = {cfg_wr[63:60], rec_q[R_PEN] & (PROBE != 0), cfg_wr[58:41],
                        rec_q[R_ARM], cfg_wr[39:0]};

  // The words a write changes in place: PRESET, CEILING, COMPARE, SNAP_PERIOD / STALL_TIMEOUT
  // and COUNT_HI (its staged word: a COUNT_HI write; its latch: a saved latch). The memory takes
  // the write's bytes with its mask and keeps the rest; a fresh channel's word is written whole,
  // its reset value with the write's bytes (a write can be taken before a channel's first visit:
  // c(v + 1)'s push in visit v).
  wire w_pre_lo  = w_on & (w_off == off_of(ENC_QEI_PRESET_LO));
  wire w_pre_hi  = w_on & (w_off == off_of(ENC_QEI_PRESET_HI));
  wire w_ceil_lo = w_on & (w_off == off_of(ENC_QEI_CEILING_LO)) & (RANGE != 0);
  wire w_ceil_hi = w_on & (w_off == off_of(ENC_QEI_CEILING_HI)) & (RANGE != 0);
  wire w_cmp_lo  = w_on & (w_off == off_of(ENC_QEI_COMPARE_LO)) & (RANGE != 0);
  wire w_cmp_hi  = w_on & (w_off == off_of(ENC_QEI_COMPARE_HI)) & (RANGE != 0);
  wire w_sper    = w_on & (w_off == off_of(ENC_QEI_SNAP_PERIOD)) & (PERIOD != 0);
  wire w_stov    = w_on & (w_off == off_of(ENC_QEI_STALL_TIMEOUT)) & (PERIOD != 0);

  // ---- the results (registered at the end of slot 23) and their writes, slots 0 .. 19 ------------------
  reg [63:0] n_cnt_q, n_cfg_q, n_ud_q, n_pctl_q;
  reg [63:0] n_mot_q, n_evt_q, n_edge_q, n_sbase_q, n_scnt_q, n_stime_q, n_sdelta_q;
  // the write for the words it changes in place: its data and byte lanes, which halves of which
  // word it writes ({hi, lo}: PRESET, CEILING, COMPARE, SNAP_PERIOD / STALL_TIMEOUT, COUNT_HI's
  // stage / latch), and whether the channel is fresh
  reg [31:0] ip_data_q, ip_lanes_q;
  reg [1:0]  ip_pre_q, ip_ceil_q, ip_cmp_q, ip_tmo_q, ip_hi_q;
  reg        ip_fresh_q;
  reg [63:0] n_ilatch_q, n_platch_q, n_ptime_q, n_stl_q;
  reg        n_snap_q, n_latch_q, n_probe_q;  // the snapshot words / INDEX_LATCH / PROBE_* to write
  reg        n_irq_q;

  always @(posedge clk) begin
    if (slot_q == S_LAST) begin
      n_cnt_q    <= cnt_n;
      n_cfg_q    <= cfg_n;
      n_ud_q     <= (PERIOD != 0) ? {tv, ud_n} : 64'd0;  // (a build without PERIOD: 0, see W_UD)
      n_pctl_q   <= pctl_n;
      ip_data_q  <= w_data;
      ip_lanes_q <= w_mask;
      ip_pre_q   <= {w_pre_hi, w_pre_lo};
      ip_ceil_q  <= {w_ceil_hi, w_ceil_lo};
      ip_cmp_q   <= {w_cmp_hi, w_cmp_lo};
      ip_tmo_q   <= {w_stov, w_sper};
      ip_hi_q    <= {w_cnt_hi, w_save};
      ip_fresh_q <= p_fresh;
      n_mot_q    <= {{(32 - MOT_W - 2 * ERR_W){1'b0}}, x_gcnt, x_qcnt, x_mpos, m_r};
      n_evt_q    <= {glitch_n, qerr_n, 8'd0, status_n, 2'd0, events_n};
      n_edge_q   <= {me_n, te_n};
      n_sbase_q  <= x_spend ? {me_s, ms_s} : o_sbase;
      n_scnt_q   <= x_spend ? cnt_s : 64'd0;
      n_stime_q  <= x_spend ? {te_s, t_s} : 64'd0;
      n_sdelta_q <= x_spend ? {me_s - o_sbase[63:32], ms_s - o_sbase[31:0]} : 64'd0;
      n_ilatch_q <= x_lpend ? rebuild(x_lcap, x_lanc, o_pre, o_ceil, o_cnt) : 64'd0;
      n_platch_q <= x_ppend ? rebuild(x_plo, x_panc, o_pre, o_ceil, o_cnt) : 64'd0;
      n_ptime_q  <= {pnb ? period_v : 32'd0, x_ppend ? tstamp(x_ptime, tv) : 32'd0};
      n_stl_q    <= (PERIOD != 0) ? {31'd0, el_n} : 64'd0;
      n_snap_q   <= x_spend | p_fresh;  // (the first visit writes the reset values)
      n_latch_q  <= x_lpend | p_fresh;
      n_probe_q  <= x_ppend | p_fresh;
      n_irq_q    <= |(events_n & cfg_n[58:45]);
    end
  end

  // a word written in place: the write's bytes in the halves it writes, the reset value elsewhere
  // (what a fresh channel's word takes), within the word's size sz
  function [63:0] ip_bits;  // the bits the write writes: its byte lanes in the halves on = {hi, lo}
    input [1:0] on;
    begin
      ip_bits = {on[1] ? ip_lanes_q : 32'd0, on[0] ? ip_lanes_q : 32'd0};
    end
  endfunction

  function [63:0] ip_data;
    input [1:0]  on;
    input [63:0] r0;   // the reset value
    input [63:0] sz;
    begin
      ip_data = (({ip_data_q, ip_data_q} & ip_bits(on)) | (r0 & ~ip_bits(on))) & sz;
    end
  endfunction

  function [63:0] ip_mask;  // ... and the bits the memory takes (a fresh channel's: all)
    input [1:0] on;
    begin
      ip_mask = ip_fresh_q ? {64{1'b1}} : ip_bits(on);
    end
  endfunction

  // slot i writes word i of this order (slots 0 .. 19; the configuration words first: with two
  // channels visited the next push reads them in slots 1 .. 9)
  always @(*) begin
    wmask = {64{1'b1}};
    case (slot_q)
      5'd0:  begin waddr = {cw_q, W_CNT};    wdata = n_cnt_q;    end
      5'd1:  begin waddr = {cw_q, W_CFG};    wdata = n_cfg_q;    end
      5'd2:  begin waddr = {cw_q, W_UD};     wdata = n_ud_q;     end
      5'd3:  begin waddr = {cw_q, W_PCTL};   wdata = n_pctl_q;   end
      5'd4:  begin waddr = {cw_q, W_PRESET}; wdata = ip_data(ip_pre_q, PRE_RST, SZ_COUNT);
                   wmask = ip_mask(ip_pre_q); end
      5'd5:  begin waddr = {cw_q, W_CEIL};   wdata = ip_data(ip_ceil_q, CEIL_RST, SZ_COUNT);
                   wmask = ip_mask(ip_ceil_q); end
      5'd6:  begin waddr = {cw_q, W_CMP};    wdata = ip_data(ip_cmp_q, CMP_RST, SZ_COUNT);
                   wmask = ip_mask(ip_cmp_q); end
      5'd7:  begin waddr = {cw_q, W_TMO};    wdata = ip_data(ip_tmo_q, TMO_RST, {SZ_TS, SZ_TS});
                   wmask = ip_mask(ip_tmo_q); end
      5'd8:  begin waddr = {cw_q, W_HI};     wdata = ip_data(ip_hi_q, 64'd0, {SZ_COUNT[63:32], 32'hFFFFFFFF});
                   wmask = ip_mask(ip_hi_q); end
      5'd9:  begin waddr = {cw_q, W_MOT};    wdata = n_mot_q;    end
      5'd10: begin waddr = {cw_q, W_EDGE};   wdata = n_edge_q;   end
      5'd11: begin waddr = {cw_q, W_SBASE};  wdata = n_sbase_q;  end
      5'd12: begin waddr = {cw_q, W_SCNT};   wdata = n_scnt_q;   wmask = {64{n_snap_q}}; end
      5'd13: begin waddr = {cw_q, W_STIME};  wdata = n_stime_q;  wmask = {64{n_snap_q}}; end
      5'd14: begin waddr = {cw_q, W_SDELTA}; wdata = n_sdelta_q; wmask = {64{n_snap_q}}; end
      5'd15: begin waddr = {cw_q, W_ILATCH}; wdata = n_ilatch_q; wmask = {64{n_latch_q}}; end
      5'd16: begin waddr = {cw_q, W_PLATCH}; wdata = n_platch_q; wmask = {64{n_probe_q}}; end
      5'd17: begin waddr = {cw_q, W_PTIME};  wdata = n_ptime_q;  wmask = ptime_mask_q; end
      5'd18: begin waddr = {cw_q, W_STL};    wdata = n_stl_q;    end
      default: begin waddr = {cw_q, W_EVT}; wdata = n_evt_q;   end  // (last: an event shows
      // in EVENTS, and on irq, only when the values it announces are readable)
    endcase
  end

  // PROBE_TIME (low half) with a probe latch, PERIOD (high half) with a measurement
  reg [63:0] ptime_mask_q;

  always @(posedge clk) begin
    if (slot_q == S_LAST) begin
      ptime_mask_q <= {{32{pnb | p_fresh}}, {32{x_ppend | p_fresh}}};
    end
  end

  // writes run in slots 0 .. 19 of a visit for the channel computed at the end of the one before
  // (after rst: from visit 1), for channels that are built
  always @(posedge clk) begin
    if (rst) begin
      wr_on_q <= 1'b0;
    end else if (slot_q == S_LAST) begin
      wr_on_q <= 1'b1;
    end
  end

  always @(*) begin
    we = wr_on_q & (slot_q <= 5'd19) & ({1'b0, cw_q} < CHANNELS[CH_W:0]);
  end

  // when the writes are done (slot 19): the channel's first visit done, its write applied (reads
  // of it go on), its irq
  reg [CHANNELS-1:0] irq_q;
  reg                w_taken_q;  // the write of cw_q was applied

  always @(posedge clk) begin
    if (slot_q == S_LAST) begin
      w_taken_q <= p_taken | e_taken;
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      fresh_q <= {CHANNELS{1'b1}};
      irq_q   <= {CHANNELS{1'b0}};
    end else begin
      if (wr_on_q && slot_q == 5'd19) begin
        fresh_q <= fresh_q & ~onehot(cw_q);
      end
      if (wr_on_q && slot_q == 5'd19) begin
        irq_q <= (irq_q & ~onehot(cw_q)) | (onehot(cw_q) & {CHANNELS{n_irq_q}});
      end
    end
  end

  always @(*) begin
    done_oh = (wr_on_q && slot_q == 5'd19 && w_taken_q) ? onehot(cw_q) : {CHANNELS{1'b0}};
  end

  assign irq_pend = irq_q;

  // ---- the bus -------------------------------------------------------------------------------------------
  // A request is taken into b_* registers. A write goes into its channel's slot when the slot is
  // free and no write of the channel is being applied (a COUNT_LO write after reading COUNT and
  // the staged word: it is put there whole); a read waits alike, then reads the memory's port b.
  // A read takes two reads of port b (B_RD1, B_RD2) and uses the first unless the engine wrote
  // that word in the clock of its address (b_clash: the data is undefined); the engine never
  // writes one word in two clocks in a row, so the second is then good, and every read is
  // answered in the same number of clocks. A COUNT_LO write with some byte lanes off reads the
  // count alike; every other write reads nothing.
  localparam [2:0] B_IDLE = 3'd0, B_WAIT = 3'd1, B_RD1 = 3'd2, B_RD2 = 3'd3, B_POST = 3'd4,
                   B_DONE = 3'd5;
  reg  [2:0]      b_st_q;
  reg             b_wr_q;
  reg  [CH_W-1:0] b_ch_q;
  reg  [5:0]      b_word_q;
  reg  [31:0]     b_wdata_q;
  reg  [3:0]      b_wstrb_q;
  reg  [31:0]     b_rdata_q;
  reg             b_resp_q;
  reg             b_clash_q;   // the first read of port b met an engine write of its word
  reg  [4:0]      b_addr;      // the word port b reads
  reg  [31:0]     b_cnt_q;     // COUNT_LO write: the count's low word as read
  // COUNT_HI's latch (COUNT_W > 32): the high word of the last COUNT_LO read, and its channel
  reg             lat_valid_q;
  reg  [CH_W-1:0] lat_ch_q;
  reg  [31:0]     lat_q;

  wire b_pend      = bit_of(pend_q | busy_q, b_ch_q);
  wire b_fresh     = bit_of(fresh_q, b_ch_q);
  wire b_cnt_lo    = (b_word_q == off_of(ENC_QEI_COUNT_LO));
  // a COUNT_LO write that keeps some of the count's bytes: it reads COUNT first
  wire b_cnt_part  = b_wr_q & b_cnt_lo & (|b_wstrb_q) & ~(&b_wstrb_q);
  wire b_cnt_hi    = (b_word_q == off_of(ENC_QEI_COUNT_HI));
  // a COUNT_LO read first saves another channel's latch (through that channel's slot)
  wire b_save      = ~b_wr_q & (COUNT_W > 32) & b_cnt_lo & lat_valid_q & (lat_ch_q != b_ch_q);
  wire b_save_busy = bit_of(pend_q | busy_q, lat_ch_q);

  // the word a register is read from (registers a build does not have read 0: any word)
  function [4:0] word_of;
    input [5:0] off;
    begin
      case (off)
        off_of(ENC_QEI_CTRL), off_of(ENC_QEI_INDEX_CTRL), off_of(ENC_QEI_IRQ_EN),
        off_of(ENC_QEI_SNAP_CTRL), off_of(ENC_QEI_PROBE_CTRL):
          word_of = W_CFG;
        off_of(ENC_QEI_STATUS), off_of(ENC_QEI_EVENTS), off_of(ENC_QEI_QERR_COUNT),
        off_of(ENC_QEI_GLITCH_COUNT):
          word_of = W_EVT;
        off_of(ENC_QEI_COUNT_HI):
          word_of = W_HI;
        off_of(ENC_QEI_PRESET_LO), off_of(ENC_QEI_PRESET_HI):
          word_of = W_PRESET;
        off_of(ENC_QEI_CEILING_LO), off_of(ENC_QEI_CEILING_HI):
          word_of = W_CEIL;
        off_of(ENC_QEI_COMPARE_LO), off_of(ENC_QEI_COMPARE_HI):
          word_of = W_CMP;
        off_of(ENC_QEI_INDEX_LATCH_LO), off_of(ENC_QEI_INDEX_LATCH_HI):
          word_of = W_ILATCH;
        off_of(ENC_QEI_PROBE_LATCH_LO), off_of(ENC_QEI_PROBE_LATCH_HI):
          word_of = W_PLATCH;
        off_of(ENC_QEI_PROBE_TIME), off_of(ENC_QEI_PERIOD):
          word_of = W_PTIME;
        off_of(ENC_QEI_SNAP_PERIOD), off_of(ENC_QEI_STALL_TIMEOUT):
          word_of = W_TMO;
        off_of(ENC_QEI_PERIOD_CTRL):
          word_of = W_PCTL;
        off_of(ENC_QEI_SNAP_COUNT_LO), off_of(ENC_QEI_SNAP_COUNT_HI):
          word_of = W_SCNT;
        off_of(ENC_QEI_SNAP_TIME), off_of(ENC_QEI_SNAP_EDGE_TIME):
          word_of = W_STIME;
        off_of(ENC_QEI_SNAP_DELTA), off_of(ENC_QEI_SNAP_EDGE_DELTA):
          word_of = W_SDELTA;
        default:
          word_of = W_CNT;  // COUNT_LO
      endcase
    end
  endfunction

  always @(*) begin
    b_addr = (b_wr_q) ? W_CNT : word_of(b_word_q);  // (a COUNT_LO write merges the count)
  end

  assign raddr_b = {b_ch_q, b_addr};
  // port b must not read the word written in the same clock (enc_qei_ram: undefined); the bus
  // then reads it again in the next clock
  wire b_clash = we & (waddr == raddr_b);
  // the clock whose port-b data the bus takes: the first read's, or the second's after a clash
  wire b_take  = ((b_st_q == B_RD1) & ~b_clash_q) | ((b_st_q == B_RD2) & b_clash_q);

  // a register's value from its word (a unit the build leaves out: 0)
  localparam integer TIMING_ON = (TIMING != 0) ? 1 : 0;
  function [31:0] reg_of;
    input [5:0]  off;
    input [63:0] wd;
    begin
      case (off)
        off_of(ENC_QEI_CTRL):            reg_of = wd[31:0];
        off_of(ENC_QEI_STATUS):          reg_of = {24'd0, wd[23:16]};
        off_of(ENC_QEI_COUNT_LO):        reg_of = wd[31:0];
        off_of(ENC_QEI_COUNT_HI):        reg_of = wd[31:0];
        off_of(ENC_QEI_PRESET_LO):       reg_of = wd[31:0];
        off_of(ENC_QEI_PRESET_HI):       reg_of = wd[63:32];
        off_of(ENC_QEI_CEILING_LO):      reg_of = (RANGE != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_CEILING_HI):      reg_of = (RANGE != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_COMPARE_LO):      reg_of = (RANGE != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_COMPARE_HI):      reg_of = (RANGE != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_INDEX_CTRL):      reg_of = {23'd0, wd[40:32]};
        off_of(ENC_QEI_INDEX_LATCH_LO):  reg_of = wd[31:0];
        off_of(ENC_QEI_INDEX_LATCH_HI):  reg_of = wd[63:32];
        off_of(ENC_QEI_PROBE_CTRL):      reg_of = (PROBE != 0) ? {29'd0, wd[61:59]} : 32'd0;
        off_of(ENC_QEI_PROBE_LATCH_LO):  reg_of = (PROBE != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_PROBE_LATCH_HI):  reg_of = (PROBE != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_PROBE_TIME):      reg_of = (PROBE != 0 && TIMING_ON != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_EVENTS):          reg_of = {18'd0, wd[13:0]};
        off_of(ENC_QEI_IRQ_EN):          reg_of = {18'd0, wd[58:45]};
        off_of(ENC_QEI_QERR_COUNT):      reg_of = {16'd0, wd[47:32]};
        off_of(ENC_QEI_GLITCH_COUNT):    reg_of = {16'd0, wd[63:48]};
        off_of(ENC_QEI_SNAP_CTRL):       reg_of = {28'd0, wd[44:41]};
        off_of(ENC_QEI_SNAP_PERIOD):     reg_of = (PERIOD != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_SNAP_COUNT_LO):   reg_of = (TIMING_ON != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_SNAP_COUNT_HI):   reg_of = (TIMING_ON != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_SNAP_TIME):       reg_of = (TIMING_ON != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_SNAP_EDGE_TIME):  reg_of = (TIMING_ON != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_SNAP_DELTA):      reg_of = (TIMING_ON != 0) ? wd[31:0] : 32'd0;
        off_of(ENC_QEI_SNAP_EDGE_DELTA): reg_of = (TIMING_ON != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_PERIOD_CTRL):     reg_of = (PERIOD != 0) ? {14'd0, wd[17:0]} : 32'd0;
        off_of(ENC_QEI_PERIOD):          reg_of = (PERIOD != 0) ? wd[63:32] : 32'd0;
        off_of(ENC_QEI_STALL_TIMEOUT):   reg_of = (PERIOD != 0) ? wd[63:32] : 32'd0;
        default:                         reg_of = 32'd0;
      endcase
    end
  endfunction

  // a word's reset value: what the bus reads of a channel before its first visit
  function [63:0] word_rst;
    input [4:0] w;
    begin
      case (w)
        W_CFG:    word_rst = CFG_RST;
        W_PRESET: word_rst = PRE_RST;
        W_CEIL:   word_rst = CEIL_RST;
        W_CMP:    word_rst = CMP_RST;
        W_TMO:    word_rst = TMO_RST;
        W_PCTL:   word_rst = PCTL_RST;
        W_EVT:    word_rst = EVT_RST;
        default:  word_rst = 64'd0;
      endcase
    end
  endfunction

  // a register's reset value (what a read of a channel not visited since rst gives)
  function [31:0] reg_rst;
    input [5:0] off;
    begin
      reg_rst = reg_of(off, word_rst(word_of(off)));
    end
  endfunction
  // COUNT_LO write: the lanes not written from the count
  wire [31:0] b_cnt_w     = (b_cnt_q & ~lanes(b_wstrb_q)) | (b_wdata_q & lanes(b_wstrb_q));
  wire        b_cnt_whole = b_cnt_lo & (|b_wstrb_q);
  // a write of a register the lane does not use (applied by the channel's next visit)
  wire        b_state_wr  = (b_word_q == off_of(ENC_QEI_EVENTS)) |
                            (b_word_q == off_of(ENC_QEI_QERR_COUNT)) |
                            (b_word_q == off_of(ENC_QEI_GLITCH_COUNT)) |
                            (b_word_q == off_of(ENC_QEI_IRQ_EN)) | b_cnt_hi;

  always @(posedge clk) begin
    pend_we  <= 1'b0;
    pend_set <= {CHANNELS{1'b0}};
    if (rst) begin
      b_st_q      <= B_IDLE;
      b_resp_q    <= 1'b0;
      lat_valid_q <= 1'b0;
    end else begin
      b_resp_q <= 1'b0;
      case (b_st_q)
        B_IDLE: begin
          if (req_valid) begin
            b_st_q    <= B_WAIT;
            b_wr_q    <= req_write;
            b_ch_q    <= req_ch;
            b_word_q  <= req_word;
            b_wdata_q <= req_wdata;
            b_wstrb_q <= req_wstrb;
          end
        end
        B_WAIT: begin
          if (b_save) begin
            if (~b_save_busy) begin
              pend_we     <= 1'b1;
              pend_wch    <= lat_ch_q;
              pend_wdata  <= {SAVE_LATCH, 4'hF, lat_q};
              pend_set    <= onehot(lat_ch_q);
              pend_set_st <= 1'b1;
              lat_valid_q <= 1'b0;
            end
          end else if (~b_pend) begin
            // port b reads the register's word (a COUNT_LO write: COUNT) now and in the next
            // clock; a write that reads nothing is posted
            b_clash_q <= b_clash;
            b_st_q    <= (b_wr_q & ~b_cnt_part) ? B_POST : B_RD1;
          end
        end
        B_RD1: begin  // the first read's data (taken when good), the second read
          b_st_q <= B_RD2;
        end
        B_RD2: begin  // the second read's data (taken when the first was not good)
          b_st_q <= b_wr_q ? B_POST : B_DONE;
        end
        B_POST: begin
          pend_we    <= 1'b1;
          pend_wch   <= b_ch_q;
          pend_wdata <= b_cnt_whole ? {b_word_q, 4'hF, b_cnt_w} : {b_word_q, b_wstrb_q, b_wdata_q};
          pend_set    <= onehot(b_ch_q);
          pend_set_st <= b_state_wr;
          b_st_q      <= B_DONE;
        end
        default: begin  // B_DONE
          if (b_wr_q) begin
            b_rdata_q <= 32'd0;
          end
          b_resp_q <= 1'b1;
          b_st_q   <= B_IDLE;
        end
      endcase
      if (b_take & b_wr_q) begin  // (a COUNT_LO write keeping some bytes: the count's low word)
        b_cnt_q <= b_fresh ? 32'd0 : rdata_b[31:0];
      end
      if (b_take & ~b_wr_q) begin
        if ((COUNT_W > 32) & b_cnt_lo) begin
          lat_valid_q <= 1'b1;
          lat_ch_q    <= b_ch_q;
          lat_q       <= b_fresh ? 32'd0 : rdata_b[63:32];  // (COUNT's reset value: 0)
        end
        b_rdata_q <= ((COUNT_W > 32) & b_cnt_hi & lat_valid_q & (lat_ch_q == b_ch_q)) ? lat_q :
                     b_fresh ? reg_rst(b_word_q) : reg_of(b_word_q, rdata_b);
      end
    end
  end

  assign resp_valid = b_resp_q;
  assign resp_rdata = b_resp_q ? b_rdata_q : 32'd0;  // (enc_qei ORs it with the globals' answer)

  wire unused_engine = &{1'b0, o_mot[63:32], o_evt[31:14],
                         d_emp[63:32], d_semp[63:32], n_cfg_w[63:62], r_stl[63:33], o_pctl[31:20],
                         n_hi[31:0], o_cfg[63:62], n_ud[63:32], o_stl[63:33], d_mpos[63:32],
                         d_smp[63:32], cfg_wr[59], cfg_wr[40], n_pctl_w[63:18], pctl_wr[63:16],
                         tmo_n[63:32], o_hi[31:0], 1'b0};

endmodule

`default_nettype wire
