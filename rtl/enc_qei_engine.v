// SPDX-License-Identifier: Apache-2.0
// enc_qei_engine -- the shared channel engine of enc_qei (parameter ENGINE = 1): CHANNELS lanes
// (enc_qei_lane: filters, decode, a motion counter and the captures that must see every clock)
// and one engine that keeps every channel's registers and wide values in block RAM
// (enc_qei_ram) and visits the channels one after another, V clocks each:
//
//   visit v processes channel c(v) = v mod CH_EFF (CH_EFF = max(CHANNELS, 2): one idle slot with
//   one channel) and prepares c(v + 1):
//     slot  0      the record c(v)'s lane handed over at the end of visit v - 1 arrives (its
//                  window: everything it did since its read before)
//     slots 0..5   read c(v)'s state words (each comes a clock later)
//     slots 6..7   read c(v + 1)'s configuration and PRESET; its waiting bus write is sampled
//     slot  7      compute c(v)'s new state from its old state, its record, its configuration
//                  and its bus write (all combinational, registered at the end of the slot)
//     slots 8..19  write the 12 words back (the last 8 in visit v + 1's slots 0..7)
//     slot  8      c(v)'s lane: where its count is 0 (tgt)
//     slot  9      c(v + 1)'s lane, when its bus write is a COUNT write: the value (C_NEGP, C_VBP)
//     slot  10     c(v + 1)'s lane: its configuration (with its bus write; ld: the COUNT load)
//     slot  11     c(v + 1)'s lane is read: the end of its window. Its bus write takes effect in
//                  slot 10 (a COUNT write: loaded in slot 10, over that clock's step; a
//                  configuration: counted with from slot 11)
// So a lane is read every P = V * CH_EFF clocks, and its window (the clocks between two reads)
// is what the lane's counters must hold: MOT_W, TIM_W and ERR_W below are sized from P.
//
// The bus (the channel pages; the global registers are enc_qei_regs'): a read reads the state
// memory's second port at once (the value as of the channel's last visit; the lane's live values
// reach the memory at each visit); a write is put in the channel's write slot (enc_qei_ram
// `u_pend`, one per channel) and answered at once, and the engine applies it in the channel's
// next processing visit, after what the lane did in the window before it (so a write takes
// effect at the clock of a read of the lane: the end of the window). A second write to a
// channel, or a read of a channel, waits while a write of that channel is in its slot, so that
// the bus sees its own writes in order. COUNT_LO read with COUNT_W > 32: the high word goes to a
// latch (one, kept for the last channel read; the one before goes to its channel's memory
// through that channel's write slot), which COUNT_HI reads.
// After rst every channel's words are the registers' reset values: the first visit of each
// channel writes them (and its reads answer them until then).
`default_nettype none
`include "enc_params.vh"
`include "enc_qei_lane_w.vh"

module enc_qei_engine #(
    parameter integer CHANNELS   = 1,   // channels (checked by enc_qei)
    parameter integer COUNT_W    = 32,  // counter width (checked by enc_qei)
    parameter integer TS_W       = 32,  // timebase width (checked by enc_qei)
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL,  // count functions built (checked by enc_qei)
    parameter integer FIXED_FUNC = -1   // the one function FUNC_MASK builds, or -1 (from enc_qei)
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
    input  wire                snap_in,
    // the shared timebase and the global snapshot
    input  wire [TS_W-1:0]     timebase,
    input  wire                gsnap_req,  // a global snapshot is requested in this clock
    output wire                gsnap,      // ... taken in this clock (every lane, GSNAP_TIME)
    output wire [CHANNELS-1:0] irq_pend    // channel k has an enabled pending event
);

  `include "enc_qei_regs.vh"

  // ---- the schedule and the lanes' widths ------------------------------------------------------
  localparam integer CH_EFF = (CHANNELS < 2) ? 2 : CHANNELS;  // channels visited (one idle)
  localparam integer CH_W   = 4;                              // channel number bits
  localparam integer V      = 12;                             // clocks per visit
  localparam integer P      = V * CH_EFF;                     // clocks between two reads of a lane
  // A lane's window holds at most P + 12 steps (one a clock), and its tgt is set 9 clocks after
  // its read: the motion counter must tell P + 12 steps forwards from backwards, and see 0 of
  // the count as near only within reach: 2 (P + 12) < 2^MOT_W. Timestamps are at most P + 12
  // ticks old when they are rebuilt: 2^TIM_W > P + 12. Error counts: at most one a clock.
  function integer clog2;
    input integer v;
    integer       n;
    begin
      clog2 = 0;
      for (n = 1; n < v; n = n * 2) begin
        clog2 = clog2 + 1;
      end
    end
  endfunction

  localparam integer REACH = P + 12;                 // the most a count moves between two reads
  localparam [63:0]  REACH64 = {32'd0, REACH[31:0]};
  localparam integer MOT_W = clog2(2 * REACH + 1) + 1;
  localparam integer TIM_W = clog2(REACH + 1) + 1;
  localparam integer ERR_W = clog2(REACH + 1) + 1;
  `include "enc_qei_lane.vh"  // the lanes' configuration and record (CFG_W, REC_W, C_*, R_*)

  // ---- the lanes ----------------------------------------------------------------------------------
  reg  [CHANNELS-1:0]       rd_q, cfg_we_q, tgt_we_q;  // one-hot: the lane read / pushed / aimed
  reg                       arm_we_q, snap_cmd_q, ld_q;
  reg  [CFG_W-1:0]          cfg_push_q;
  reg                       tgt_vb_q;
  reg  [MOT_W-1:0]          tgt_q;
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
          .MOT_W(MOT_W),
          .TIM_W(TIM_W),
          .ERR_W(ERR_W)
      ) u_lane (
          .clk      (clk),
          .rst      (rst),
          .valid    (valid),
          .a_in     (a_in[k]),
          .b_in     (b_in[k]),
          .z_in     (z_in[k]),
          .snap_in  (snap_in),
          .tb_lo    (timebase[TIM_W-1:0]),
          .gsnap    (gsnap),
          .snap_hold(snap_hold_q),
          .cfg_we   (cfg_we_q[k]),
          .arm_we   (arm_we_q),
          .cfg      (cfg_push_q),
          .rd       (rd_q[k]),
          .ld       (ld_q),
          .snap_cmd (snap_cmd_q & cfg_we_q[k]),
          .tgt_we   (tgt_we_q[k]),
          .tgt_vb   (tgt_vb_q),
          .tgt      (tgt_q),
          .rec      (recs[k*REC_W +: REC_W]),
          .snap_pend(snap_pend[k])
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
  reg gsnap_wait_q;
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
  reg [3:0]      slot_q;   // 0 .. V - 1
  reg [CH_W-1:0] cp_q;     // the channel processed in this visit: c(v)
  reg [CH_W-1:0] cn_q;     // the next one: c(v + 1)
  reg [CH_W-1:0] cw_q;     // the channel whose words are written now (c(v) from slot 8, c(v - 1) before)

  function [CH_W-1:0] next_ch;
    input [CH_W-1:0] c;
    begin
      next_ch = (c == CH_EFF[CH_W-1:0] - 4'd1) ? {CH_W{1'b0}} : c + 4'd1;
    end
  endfunction

  always @(posedge clk) begin
    if (rst) begin
      slot_q <= 4'd0;
      cp_q   <= {CH_W{1'b0}};
      cn_q   <= 4'd1;
      cw_q   <= CH_EFF[CH_W-1:0] - 4'd1;
    end else begin
      if (slot_q == V[3:0] - 4'd1) begin
        slot_q <= 4'd0;
        cp_q   <= cn_q;
        cn_q   <= next_ch(cn_q);
      end else begin
        slot_q <= slot_q + 4'd1;
      end
      if (slot_q == 4'd7) begin
        cw_q <= cp_q;
      end
    end
  end

  // ---- the state memory: 16 words of 64 bits per channel ----------------------------------------------
  //   W_CNT    the count (COUNT_W bits)                      (COUNT_LO, and COUNT_HI's live word)
  //   W_MOT    [31:0] M, the motion; [63:32] the lane's mpos, qcnt, gcnt at its last read
  //   W_EVT    [13:0] EVENTS, [23:16] STATUS, [47:32] QERR_COUNT, [63:48] GLITCH_COUNT
  //   W_EDGE   [31:0] TE, [63:32] ME: the last selected edge's time and motion
  //   W_SBASE  [31:0] MS, [63:32] MES: the motion and ME at the last snapshot
  //   W_SCNT   SNAP_COUNT; W_STIME [31:0] SNAP_TIME, [63:32] SNAP_EDGE_TIME;
  //   W_SDELTA [31:0] SNAP_DELTA, [63:32] SNAP_EDGE_DELTA; W_ILATCH INDEX_LATCH
  //   W_CFG    [31:0] CTRL, [40:32] INDEX_CTRL, [44:41] SNAP_CTRL, [58:45] IRQ_EN
  //   W_PRESET PRESET; W_HI [31:0] COUNT_HI's latch, [63:32] its staged word (COUNT_W > 32)
  localparam [3:0] W_CNT = 4'd0, W_MOT = 4'd1, W_EVT = 4'd2, W_EDGE = 4'd3, W_SBASE = 4'd4,
                   W_SCNT = 4'd5, W_STIME = 4'd6, W_SDELTA = 4'd7, W_ILATCH = 4'd8, W_CFG = 4'd9,
                   W_PRESET = 4'd10, W_HI = 4'd11;
  localparam integer AW = CH_W + 4;

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
      4'd0:    raddr_a = {cp_q, W_CNT};
      4'd1:    raddr_a = {cp_q, W_MOT};
      4'd2:    raddr_a = {cp_q, W_EVT};
      4'd3:    raddr_a = {cp_q, W_EDGE};
      4'd4:    raddr_a = {cp_q, W_SBASE};
      4'd5:    raddr_a = {cp_q, W_HI};
      4'd6:    raddr_a = {cn_q, W_CFG};
      default: raddr_a = {cn_q, W_PRESET};
    endcase
  end

  reg [63:0] r_cnt, r_mot, r_evt, r_edge, r_sbase, r_hi;  // c(v)'s words
  reg [63:0] n_cfg, n_pre;                                  // c(v + 1)'s configuration

  always @(posedge clk) begin
    case (slot_q)
      4'd1: r_cnt   <= rdata_a;
      4'd2: r_mot   <= rdata_a;
      4'd3: r_evt   <= rdata_a;
      4'd4: r_edge  <= rdata_a;
      4'd5: r_sbase <= rdata_a;
      4'd6: r_hi    <= rdata_a;
      4'd7: n_cfg   <= rdata_a;
      4'd8: n_pre   <= rdata_a;
      default: ;
    endcase
  end

  // ---- bus writes wait in a slot per channel ------------------------------------------------------------
  // {near_end, word offset 6, byte enables 4, data 32}. A COUNT_LO write is put there whole: the bus
  // merges the lanes it does not write from COUNT (the value a read gives now) and adds whether
  // {staged COUNT_HI, it} is near the end of the range (near_end, for the lane). SAVE_LATCH: the
  // COUNT_HI latch of a channel, for its memory.
  localparam [5:0]   SAVE_LATCH = 6'h3F;  // (no register has this offset)
  localparam integer PW         = 43;
  reg  [CHANNELS-1:0] pend_q;             // channel k has a write waiting
  reg                 pend_we;
  reg  [CH_W-1:0]     pend_wch;
  reg  [PW-1:0]       pend_wdata;
  wire [PW-1:0]       pend_rdata, unused_pend_b;
  reg  [CHANNELS-1:0] pend_set, pend_clr;  // this clock (the bus; the visit that applied it)

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
      .raddr_b(cn_q),
      .rdata_b(unused_pend_b)
  );

  always @(posedge clk) begin
    if (rst) begin
      pend_q <= {CHANNELS{1'b0}};
    end else begin
      pend_q <= (pend_q & ~pend_clr) | pend_set;
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

  // c(v + 1)'s write: taken into its push and its next visit when waiting at slot 6
  reg          n_taken;
  reg [PW-1:0] n_pend;

  always @(posedge clk) begin
    if (rst) begin
      n_taken <= 1'b0;
    end else if (slot_q == 4'd6) begin
      n_taken <= bit_of(pend_q, cn_q);
    end
    if (slot_q == 4'd7) begin
      n_pend <= pend_rdata;
    end
  end

  // ---- reset values of the words --------------------------------------------------------------------
  localparam [63:0] SZ_COUNT = (COUNT_W >= 64) ? {64{1'b1}} : ((64'd1 << COUNT_W) - 64'd1);
  localparam [31:0] SZ_TS    = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);
  localparam [63:0] CFG_RST  = {5'd0, ENC_QEI_IRQ_EN_RESET[13:0], ENC_QEI_SNAP_CTRL_RESET[3:0],
                                ENC_QEI_INDEX_CTRL_RESET[8:0], ENC_QEI_CTRL_RESET};
  localparam [63:0] PRE_RST  = {ENC_QEI_PRESET_HI_RESET, ENC_QEI_PRESET_LO_RESET} & SZ_COUNT;

  reg [CHANNELS-1:0] fresh_q;  // channel k not visited since rst: its words are the reset values
  wire n_fresh = bit_of(fresh_q, cn_q);
  wire [63:0] n_cfg_eff = n_fresh ? CFG_RST : n_cfg;
  wire [63:0] n_pre_eff = n_fresh ? PRE_RST : n_pre;

  // what c(v) was pushed with at the end of visit v - 1 (p_*), for its computation
  reg [63:0]   p_cfg, p_pre;
  reg [PW-1:0] p_pend;
  reg          p_taken;

  always @(posedge clk) begin
    if (rst) begin  // (channel 0's first visit: it had no push)
      p_cfg   <= CFG_RST;
      p_pre   <= PRE_RST;
      p_pend  <= {PW{1'b0}};
      p_taken <= 1'b0;
    end else if (slot_q == V[3:0] - 4'd1) begin
      p_cfg   <= n_cfg_eff;
      p_pre   <= n_pre_eff;
      p_pend  <= n_pend;
      p_taken <= n_taken;
    end
  end

  // ---- a waiting bus write, as a visit applies it -----------------------------------------------------
  function [31:0] lanes;  // byte enables -> bit mask
    input [3:0] st;
    begin
      lanes = {{8{st[3]}}, {8{st[2]}}, {8{st[1]}}, {8{st[0]}}};
    end
  endfunction

  localparam [31:0] CTRL_WR  = (32'h1 << ENC_QEI_CTRL_EN) | (32'h1 << ENC_QEI_CTRL_SWAP_AB) |
                               (32'h1 << ENC_QEI_CTRL_INV_A) | (32'h1 << ENC_QEI_CTRL_INV_B) |
                               (32'h1 << ENC_QEI_CTRL_INV_Z) | (32'h1F << ENC_QEI_CTRL_FILTER_LEN) |
                               ((FIXED_FUNC >= 0) ? 32'h0 : (32'hF << ENC_QEI_CTRL_FUNC));
  localparam [8:0]  ICTRL_WR = 9'h17F;  // ACTION .. GATE_B, ARM
  localparam [3:0]  SCTRL_WR = (4'h1 << ENC_QEI_SNAP_CTRL_IN_EN) | (4'h1 << ENC_QEI_SNAP_CTRL_EDGE);

  // the configuration word with a write applied
  function [63:0] cfg_written;
    input [63:0]   c;
    input [41:0]   w;  // {offset, strobes, data} of a waiting write
    reg   [31:0]   m;
    begin
      cfg_written = c;
      m = lanes(w[35:32]);
      case (w[41:36])
        ENC_QEI_CTRL[7:2]:
          cfg_written[31:0] = (c[31:0] & ~(m & CTRL_WR)) | (w[31:0] & m & CTRL_WR);
        ENC_QEI_INDEX_CTRL[7:2]:
          cfg_written[40:32] = (c[40:32] & ~(m[8:0] & ICTRL_WR)) | (w[8:0] & m[8:0] & ICTRL_WR);
        ENC_QEI_SNAP_CTRL[7:2]:
          cfg_written[44:41] = (c[44:41] & ~(m[3:0] & SCTRL_WR)) | (w[3:0] & m[3:0] & SCTRL_WR);
        ENC_QEI_IRQ_EN[7:2]:
          cfg_written[58:45] = (c[58:45] & ~m[13:0]) | (w[13:0] & m[13:0]);
        default: ;
      endcase
    end
  endfunction

  // PRESET with a write applied
  function [63:0] pre_written;
    input [63:0]   c;
    input [41:0]   w;
    reg   [63:0]   m;
    begin
      m = 64'd0;
      if (w[41:36] == ENC_QEI_PRESET_LO[7:2]) m[31:0] = lanes(w[35:32]);
      if (w[41:36] == ENC_QEI_PRESET_HI[7:2]) m[63:32] = lanes(w[35:32]);
      pre_written = ((c & ~m) | ({w[31:0], w[31:0]} & m)) & SZ_COUNT;
    end
  endfunction

  // ---- c(v + 1)'s push: its configuration, with its write ------------------------------------------------
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

  // a COUNT_W-bit value within REACH of 0, either way round the end of the free range
  function near_end;
    input [63:0] c;
    reg   [63:0] neg;
    begin
      neg      = (~c + 64'd1) & SZ_COUNT;
      near_end = (c <= REACH64) | (neg <= REACH64);
    end
  endfunction

  wire [63:0] n_cfg_w = n_taken ? cfg_written(n_cfg_eff, n_pend[41:0]) : n_cfg_eff;
  wire [63:0] n_pre_w = n_taken ? pre_written(n_pre_eff, n_pend[41:0]) : n_pre_eff;
  wire        n_on    = n_taken & (|n_pend[35:32]);
  wire        n_ictrl_wr = n_on & (n_pend[41:36] == ENC_QEI_INDEX_CTRL[7:2]);
  wire        n_cnt_wr   = n_on & (n_pend[41:36] == ENC_QEI_COUNT_LO[7:2]);
  wire        n_snap_cmd = n_on & (n_pend[41:36] == ENC_QEI_SNAP_CTRL[7:2]) & n_pend[32] &
                           n_pend[ENC_QEI_SNAP_CTRL_CMD];

  function [CFG_W-1:0] push_of;
    input [44:0]      cf;    // the configuration word (its CTRL, INDEX_CTRL, SNAP_CTRL)
    input [MOT_W-1:0] pre;   // the low bits of C_NEGP's value: PRESET, or a COUNT write's value
    input             near;  // ... near_end of it
    reg   [31:0] ctrl;
    reg   [8:0]  ictrl;
    reg   [3:0]  sctrl;
    begin
      ctrl  = cf[31:0];
      ictrl = cf[40:32];
      sctrl = cf[44:41];
      push_of[C_EN]               = ctrl[ENC_QEI_CTRL_EN];
      push_of[C_SWAP]             = ctrl[ENC_QEI_CTRL_SWAP_AB];
      push_of[C_INV_A]            = ctrl[ENC_QEI_CTRL_INV_A];
      push_of[C_INV_B]            = ctrl[ENC_QEI_CTRL_INV_B];
      push_of[C_INV_Z]            = ctrl[ENC_QEI_CTRL_INV_Z];
      push_of[C_FUNC +: C_FUNC_W] = func_eff(ctrl[ENC_QEI_CTRL_FUNC +: 4]);
      push_of[C_LAST +: C_LAST_W] = last_of(ctrl[ENC_QEI_CTRL_FILTER_LEN +: 5]);
      push_of[C_ACT +: C_ACT_W]   = ictrl[ENC_QEI_INDEX_CTRL_ACTION +: 2];
      push_of[C_ONESHOT]          = ictrl[ENC_QEI_INDEX_CTRL_ONESHOT];
      push_of[C_IEDGE]            = ictrl[ENC_QEI_INDEX_CTRL_EDGE];
      push_of[C_GATE_EN]          = ictrl[ENC_QEI_INDEX_CTRL_GATE_EN];
      push_of[C_GATE_A]           = ictrl[ENC_QEI_INDEX_CTRL_GATE_A];
      push_of[C_GATE_B]           = ictrl[ENC_QEI_INDEX_CTRL_GATE_B];
      push_of[C_ARM]              = ictrl[ENC_QEI_INDEX_CTRL_ARM];
      push_of[C_SIN_EN]           = sctrl[ENC_QEI_SNAP_CTRL_IN_EN];
      push_of[C_SEDGE]            = sctrl[ENC_QEI_SNAP_CTRL_EDGE];
      push_of[C_NEGP +: C_NEGP_W] = ~pre[MOT_W-1:0] + {{(MOT_W-1){1'b0}}, 1'b1};
      push_of[C_VBP]              = near;
    end
  endfunction

  // slot 9: a COUNT write's value (the configuration as it was); slot 10: the configuration
  always @(posedge clk) begin
    if (rst) begin
      cfg_we_q   <= {CHANNELS{1'b0}};
      rd_q       <= {CHANNELS{1'b0}};
      arm_we_q   <= 1'b0;
      ld_q       <= 1'b0;
      snap_cmd_q <= 1'b0;
    end else begin
      cfg_we_q   <= ((slot_q == 4'd8 && n_cnt_wr) || slot_q == 4'd9) ? onehot(cn_q) : {CHANNELS{1'b0}};
      rd_q       <= (slot_q == 4'd10) ? onehot(cn_q) : {CHANNELS{1'b0}};
      arm_we_q   <= (slot_q == 4'd9) & n_ictrl_wr;
      ld_q       <= (slot_q == 4'd9) & n_cnt_wr;
      snap_cmd_q <= (slot_q == 4'd9) & n_snap_cmd;
    end
  end

  always @(posedge clk) begin
    if (slot_q == 4'd8) begin
      cfg_push_q <= push_of(n_cfg_eff[44:0], n_pend[MOT_W-1:0], n_pend[42]);
    end else if (slot_q == 4'd9) begin
      cfg_push_q <= push_of(n_cfg_w[44:0], n_pre_w[MOT_W-1:0], near_end(n_pre_w));
    end
  end

  // ---- the visit's computation for c(v) (slot 7) ------------------------------------------------------------
  reg [REC_W-1:0] rec_q;  // c(v)'s record (read at the end of visit v - 1)

  always @(posedge clk) begin
    if (slot_q == 4'd0) begin
      rec_q <= rec_or;
    end
  end

  wire p_fresh = bit_of(fresh_q, cp_q);
  // the words as of the end of the window (reset values on the first visit)
  wire [63:0] o_cnt   = p_fresh ? 64'd0 : r_cnt;
  wire [63:0] o_mot   = p_fresh ? 64'd0 : r_mot;
  wire [63:0] o_evt   = p_fresh ? 64'd0 : r_evt;
  wire [63:0] o_edge  = p_fresh ? 64'd0 : r_edge;
  wire [63:0] o_sbase = p_fresh ? 64'd0 : r_sbase;
  wire [63:0] o_hi    = p_fresh ? 64'd0 : r_hi;

  wire [MOT_W-1:0] mb = o_mot[32 +: MOT_W];                  // mpos at the last read
  wire [ERR_W-1:0] qb = o_mot[32 + MOT_W +: ERR_W];          // qcnt ...
  wire [ERR_W-1:0] gb = o_mot[32 + MOT_W + ERR_W +: ERR_W];  // gcnt ...
  wire [31:0]      m0 = o_mot[31:0];                         // the motion at the last read

  // signed difference of two lane positions, sign-extended to 64 bits
  function [63:0] sdiff;
    input [MOT_W-1:0] a;
    input [MOT_W-1:0] b;
    reg   [MOT_W-1:0] d;
    begin
      d     = a - b;
      sdiff = {{(64 - MOT_W){d[MOT_W-1]}}, d};
    end
  endfunction

  // the full timestamp of low bits t, taken at most REACH ticks before now
  function [31:0] tstamp;
    input [TIM_W-1:0] t;
    reg   [TIM_W-1:0] age;
    begin
      age    = timebase[TIM_W-1:0] - t;
      tstamp = ({{(32 - TS_W){1'b0}}, timebase} - {{(32 - TIM_W){1'b0}}, age}) & SZ_TS;
    end
  endfunction

  wire [MOT_W-1:0] x_mpos  = rec_q[R_MPOS +: R_MPOS_W];
  wire [MOT_W-1:0] x_icap  = rec_q[R_ICAP +: R_ICAP_W];
  wire             x_ipend = rec_q[R_IPEND];
  wire             x_ipre  = rec_q[R_IPRE];
  wire             x_spend = rec_q[R_SPEND];
  wire [MOT_W-1:0] x_smpos = rec_q[R_SMPOS +: R_SMPOS_W];
  wire [MOT_W-1:0] x_sicap = rec_q[R_SICAP +: R_SICAP_W];
  wire             x_sipre = rec_q[R_SIPEND] & rec_q[R_SIPRE];
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
  wire             x_latch = x_ipend & ~x_ipre;

  // the count and the motion at the end of the window
  wire [63:0] cnt0  = o_cnt & SZ_COUNT;
  wire [63:0] cnt_r = ((x_ipend & x_ipre) ? p_pre + sdiff(x_mpos, x_icap) : cnt0 + d_mpos) & SZ_COUNT;
  wire [63:0] d_mpos = sdiff(x_mpos, mb);   // the window's motion
  wire [63:0] d_emp  = sdiff(x_emp, mb);    // ... up to its last selected edge
  wire [63:0] d_smp  = sdiff(x_smpos, mb);  // ... up to the snapshot
  wire [63:0] d_semp = sdiff(x_semp, mb);   // ... up to the snapshot's last selected edge
  wire [31:0] m_r    = m0 + d_mpos[31:0];

  // c(v)'s write, applied at the end of the window
  wire        w_on     = p_taken & (|p_pend[35:32]);
  wire [5:0]  w_off    = p_pend[41:36];
  wire [31:0] w_mask   = lanes(p_pend[35:32]);
  wire [31:0] w_data   = p_pend[31:0];
  wire        w_cnt_lo = w_on & (w_off == ENC_QEI_COUNT_LO[7:2]);
  wire        w_cnt_hi = w_on & (w_off == ENC_QEI_COUNT_HI[7:2]);
  wire        w_events = w_on & (w_off == ENC_QEI_EVENTS[7:2]);
  wire        w_qerr   = w_on & (w_off == ENC_QEI_QERR_COUNT[7:2]);
  wire        w_glitch = w_on & (w_off == ENC_QEI_GLITCH_COUNT[7:2]);
  wire        w_save   = w_on & (w_off == SAVE_LATCH);

  // COUNT_LO written (whole, the bus merged it): {staged high word, it}
  wire [63:0] cnt_n = w_cnt_lo ? ({o_hi[63:32], w_data} & SZ_COUNT) : cnt_r;

  // the lane's tgt: where its mpos is when the count is 0
  wire [MOT_W-1:0] tgt_n = x_mpos - cnt_n[MOT_W-1:0];

  // the last selected edge, and the snapshot
  wire [31:0] te_n  = x_enew ? tstamp(x_et) : o_edge[31:0];
  wire [31:0] me_n  = x_enew ? m0 + d_emp[31:0] : o_edge[63:32];
  wire [31:0] ms_s  = m0 + d_smp[31:0];
  wire [63:0] cnt_s = (x_sipre ? p_pre + sdiff(x_smpos, x_sicap) : cnt0 + d_smp) & SZ_COUNT;
  wire [31:0] t_s   = tstamp(x_stime);
  wire [31:0] te_s  = x_sedge ? t_s : x_snew ? tstamp(x_set) : o_edge[31:0];
  wire [31:0] me_s  = x_sedge ? ms_s : x_snew ? m0 + d_semp[31:0] : o_edge[63:32];

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
  assign ev_new[ENC_QEI_EVENTS_OVERFLOW]   = rec_q[R_OVF];
  assign ev_new[ENC_QEI_EVENTS_UNDERFLOW]  = rec_q[R_UNF];
  assign ev_new[ENC_QEI_EVENTS_INDEX]      = rec_q[R_IDX];
  assign ev_new[ENC_QEI_EVENTS_PROBE]      = 1'b0;
  assign ev_new[ENC_QEI_EVENTS_CMP]        = 1'b0;
  assign ev_new[ENC_QEI_EVENTS_QERR]       = (dq != {ERR_W{1'b0}});
  assign ev_new[ENC_QEI_EVENTS_GLITCH]     = (dg != {ERR_W{1'b0}});
  assign ev_new[ENC_QEI_EVENTS_DIR_CHANGE] = rec_q[R_DCH];
  assign ev_new[ENC_QEI_EVENTS_STALL]      = 1'b0;
  assign ev_new[ENC_QEI_EVENTS_SNAP_READY] = x_spend;
  assign ev_new[13:10]                     = 4'd0;

  wire [13:0] events_n = (o_evt[13:0] | ev_new) & ~(w_events ? w_mask[13:0] & w_data[13:0] : 14'd0);
  wire [15:0] qerr_n   = w_qerr ? 16'd0 : sat_add(o_evt[47:32], dq);
  wire [15:0] glitch_n = w_glitch ? 16'd0 : sat_add(o_evt[63:48], dg);
  wire [7:0]  status_n;
  assign status_n[ENC_QEI_STATUS_A]           = rec_q[R_A];
  assign status_n[ENC_QEI_STATUS_B]           = rec_q[R_B];
  assign status_n[ENC_QEI_STATUS_Z]           = rec_q[R_Z];
  assign status_n[ENC_QEI_STATUS_DIR]         = rec_q[R_DIR];
  assign status_n[ENC_QEI_STATUS_INDEX_ARMED] = rec_q[R_ARMED];
  assign status_n[ENC_QEI_STATUS_STALLED]     = 1'b0;
  assign status_n[ENC_QEI_STATUS_STOPPED]     = 1'b0;
  assign status_n[ENC_QEI_STATUS_VALID]       = valid;

  // the configuration word: a one-shot index acted (ARM cleared), then the write
  wire [63:0] cfg_dis = (x_ipend & p_cfg[32 + ENC_QEI_INDEX_CTRL_ONESHOT]) ?
                        (p_cfg & ~(64'd1 << (32 + ENC_QEI_INDEX_CTRL_ARM))) : p_cfg;
  wire [63:0] cfg_n   = p_taken ? cfg_written(cfg_dis, p_pend[41:0]) : cfg_dis;
  wire [63:0] pre_n   = p_taken ? pre_written(p_pre, p_pend[41:0]) : p_pre;

  // COUNT_HI: a write stages its word; a saved latch
  wire [31:0] hi_stage_n = w_cnt_hi ? ((o_hi[63:32] & ~w_mask) | (w_data & w_mask)) & SZ_COUNT[63:32] :
                           o_hi[63:32];
  wire [31:0] hi_latch_n = w_save ? w_data : o_hi[31:0];

  // ---- the results (registered at the end of slot 7) and their writes, slots 8 .. 19 ------------------
  reg [63:0] n_cnt_q, n_mot_q, n_evt_q, n_edge_q, n_sbase_q, n_scnt_q, n_stime_q, n_sdelta_q;
  reg [63:0] n_ilatch_q, n_cfg_q, n_pre_q, n_hi_q;
  reg        n_snap_q, n_latch_q;  // the snapshot words / INDEX_LATCH to write
  reg        n_irq_q;

  always @(posedge clk) begin
    if (slot_q == 4'd7) begin
      n_cnt_q    <= cnt_n;
      n_mot_q    <= {{(32 - MOT_W - 2 * ERR_W){1'b0}}, x_gcnt, x_qcnt, x_mpos, m_r};
      n_evt_q    <= {glitch_n, qerr_n, 8'd0, status_n, 2'd0, events_n};
      n_edge_q   <= {me_n, te_n};
      n_sbase_q  <= x_spend ? {me_s, ms_s} : o_sbase;
      n_scnt_q   <= x_spend ? cnt_s : 64'd0;
      n_stime_q  <= x_spend ? {te_s, t_s} : 64'd0;
      n_sdelta_q <= x_spend ? {me_s - o_sbase[63:32], ms_s - o_sbase[31:0]} : 64'd0;
      n_ilatch_q <= x_latch ? (cnt0 + sdiff(x_icap, mb)) & SZ_COUNT : 64'd0;
      n_cfg_q    <= cfg_n;
      n_pre_q    <= pre_n;
      n_hi_q     <= {hi_stage_n, hi_latch_n};
      n_snap_q   <= x_spend | p_fresh;  // (the first visit writes the reset values)
      n_latch_q  <= x_latch | p_fresh;
      n_irq_q    <= |(events_n & cfg_n[58:45]);
    end
  end

  // slot 8 + i writes word i of this order (slots 8 .. 11 of this visit, 0 .. 7 of the next)
  wire [3:0] wi = (slot_q >= 4'd8) ? slot_q - 4'd8 : slot_q + 4'd4;

  always @(*) begin
    case (wi)
      4'd0:    begin waddr = {cw_q, W_CFG};    wdata = n_cfg_q;    wmask = {64{1'b1}}; end
      4'd1:    begin waddr = {cw_q, W_PRESET}; wdata = n_pre_q;    wmask = {64{1'b1}}; end
      4'd2:    begin waddr = {cw_q, W_CNT};    wdata = n_cnt_q;    wmask = {64{1'b1}}; end
      4'd3:    begin waddr = {cw_q, W_MOT};    wdata = n_mot_q;    wmask = {64{1'b1}}; end
      4'd4:    begin waddr = {cw_q, W_EVT};    wdata = n_evt_q;    wmask = {64{1'b1}}; end
      4'd5:    begin waddr = {cw_q, W_EDGE};   wdata = n_edge_q;   wmask = {64{1'b1}}; end
      4'd6:    begin waddr = {cw_q, W_SBASE};  wdata = n_sbase_q;  wmask = {64{1'b1}}; end
      4'd7:    begin waddr = {cw_q, W_SCNT};   wdata = n_scnt_q;   wmask = {64{n_snap_q}}; end
      4'd8:    begin waddr = {cw_q, W_STIME};  wdata = n_stime_q;  wmask = {64{n_snap_q}}; end
      4'd9:    begin waddr = {cw_q, W_SDELTA}; wdata = n_sdelta_q; wmask = {64{n_snap_q}}; end
      4'd10:   begin waddr = {cw_q, W_ILATCH}; wdata = n_ilatch_q; wmask = {64{n_latch_q}}; end
      default: begin waddr = {cw_q, W_HI};     wdata = n_hi_q;     wmask = {64{1'b1}}; end
    endcase
  end

  // writes run from slot 8 of a visit to slot 7 of the next (after rst: from visit 0's slot 8), for
  // channels that are built
  reg wr_on_q;

  always @(posedge clk) begin
    if (rst) begin
      wr_on_q <= 1'b0;
    end else if (slot_q == 4'd7) begin
      wr_on_q <= 1'b1;
    end
  end

  always @(*) begin
    we = wr_on_q & ({1'b0, cw_q} < CHANNELS[CH_W:0]);
  end

  // the lane's tgt (slot 8); when the writes are done (slot 7 of the next visit): the channel's
  // first visit done, its write applied (its slot free, reads of it go on); its irq (slot 8)
  always @(posedge clk) begin
    if (rst) begin
      tgt_we_q <= {CHANNELS{1'b0}};
      fresh_q  <= {CHANNELS{1'b1}};
      irq_q    <= {CHANNELS{1'b0}};
    end else begin
      tgt_we_q <= (slot_q == 4'd7) ? onehot(cp_q) : {CHANNELS{1'b0}};
      if (wr_on_q && slot_q == 4'd7) begin
        fresh_q <= fresh_q & ~onehot(cw_q);
      end
      if (wr_on_q && slot_q == 4'd8) begin
        irq_q <= (irq_q & ~onehot(cw_q)) | (onehot(cw_q) & {CHANNELS{n_irq_q}});
      end
    end
  end

  always @(posedge clk) begin
    if (slot_q == 4'd7) begin
      tgt_q    <= tgt_n;
      tgt_vb_q <= near_end(cnt_n);
    end
  end

  reg [CHANNELS-1:0] irq_q;
  assign irq_pend = irq_q;

  // c(v)'s write is done when its words are (slot 7 of visit v + 1, cw_q still c(v))
  reg w_taken_q;  // the write of cw_q was applied

  always @(posedge clk) begin
    if (slot_q == 4'd7) begin
      w_taken_q <= p_taken;
    end
  end

  always @(*) begin
    pend_clr = (wr_on_q && slot_q == 4'd7 && w_taken_q) ? onehot(cw_q) : {CHANNELS{1'b0}};
  end

  // ---- the bus -------------------------------------------------------------------------------------------
  // A request is taken into b_* registers. A write goes into its channel's slot when the slot is
  // free (a COUNT_LO write after reading COUNT and the staged word: it is put there whole); a
  // read waits until the channel has no write waiting, then reads the memory's port b.
  localparam [2:0] B_IDLE = 3'd0, B_WAIT = 3'd1, B_READ = 3'd2, B_CNT = 3'd3, B_HIRD = 3'd4,
                   B_HI = 3'd5, B_POST = 3'd6, B_DONE = 3'd7;
  reg  [2:0]      b_st_q;
  reg             b_wr_q;
  reg  [CH_W-1:0] b_ch_q;
  reg  [5:0]      b_word_q;
  reg  [31:0]     b_wdata_q;
  reg  [3:0]      b_wstrb_q;
  reg  [31:0]     b_rdata_q;
  reg             b_resp_q;
  reg  [3:0]      b_addr;      // the word port b reads
  reg  [31:0]     b_cnt_q;     // COUNT_LO write: the count's low word as read
  // COUNT_HI's latch (COUNT_W > 32): the high word of the last COUNT_LO read, and its channel
  reg             lat_valid_q;
  reg  [CH_W-1:0] lat_ch_q;
  reg  [31:0]     lat_q;

  wire b_pend      = bit_of(pend_q, b_ch_q);
  wire b_fresh     = bit_of(fresh_q, b_ch_q);
  wire b_cnt_lo    = (b_word_q == ENC_QEI_COUNT_LO[7:2]);
  wire b_cnt_hi    = (b_word_q == ENC_QEI_COUNT_HI[7:2]);
  // a COUNT_LO read first saves another channel's latch (through that channel's slot)
  wire b_save      = ~b_wr_q & (COUNT_W > 32) & b_cnt_lo & lat_valid_q & (lat_ch_q != b_ch_q);
  wire b_save_busy = bit_of(pend_q, lat_ch_q);

  // the word a register is read from (registers a build does not have read 0: any word)
  function [3:0] word_of;
    input [5:0] off;
    begin
      case (off)
        ENC_QEI_CTRL[7:2], ENC_QEI_INDEX_CTRL[7:2], ENC_QEI_IRQ_EN[7:2], ENC_QEI_SNAP_CTRL[7:2]:
          word_of = W_CFG;
        ENC_QEI_STATUS[7:2], ENC_QEI_EVENTS[7:2], ENC_QEI_QERR_COUNT[7:2], ENC_QEI_GLITCH_COUNT[7:2]:
          word_of = W_EVT;
        ENC_QEI_COUNT_HI[7:2]:
          word_of = W_HI;
        ENC_QEI_PRESET_LO[7:2], ENC_QEI_PRESET_HI[7:2]:
          word_of = W_PRESET;
        ENC_QEI_INDEX_LATCH_LO[7:2], ENC_QEI_INDEX_LATCH_HI[7:2]:
          word_of = W_ILATCH;
        ENC_QEI_SNAP_COUNT_LO[7:2], ENC_QEI_SNAP_COUNT_HI[7:2]:
          word_of = W_SCNT;
        ENC_QEI_SNAP_TIME[7:2], ENC_QEI_SNAP_EDGE_TIME[7:2]:
          word_of = W_STIME;
        ENC_QEI_SNAP_DELTA[7:2], ENC_QEI_SNAP_EDGE_DELTA[7:2]:
          word_of = W_SDELTA;
        default:
          word_of = W_CNT;  // COUNT_LO
      endcase
    end
  endfunction

  always @(*) begin
    case (b_st_q)
      B_HIRD:  b_addr = W_HI;   // (a COUNT_LO write: B_WAIT reads W_CNT, B_HIRD the staged word)
      default: b_addr = (b_wr_q) ? W_CNT : word_of(b_word_q);
    endcase
  end

  assign raddr_b = {b_ch_q, b_addr};
  // port b must not read the word written in the same clock (enc_qei_ram: undefined); B_CNT then
  // reads its word again, with the count's low word it got last clock (not yet taken)
  wire b_clash = we & (waddr == raddr_b);

  // a register's value from its word
  function [31:0] reg_of;
    input [5:0]  off;
    input [63:0] wd;
    begin
      case (off)
        ENC_QEI_CTRL[7:2]:            reg_of = wd[31:0];
        ENC_QEI_STATUS[7:2]:          reg_of = {24'd0, wd[23:16]};
        ENC_QEI_COUNT_LO[7:2]:        reg_of = wd[31:0];
        ENC_QEI_COUNT_HI[7:2]:        reg_of = wd[31:0];
        ENC_QEI_PRESET_LO[7:2]:       reg_of = wd[31:0];
        ENC_QEI_PRESET_HI[7:2]:       reg_of = wd[63:32];
        ENC_QEI_INDEX_CTRL[7:2]:      reg_of = {23'd0, wd[40:32]};
        ENC_QEI_INDEX_LATCH_LO[7:2]:  reg_of = wd[31:0];
        ENC_QEI_INDEX_LATCH_HI[7:2]:  reg_of = wd[63:32];
        ENC_QEI_EVENTS[7:2]:          reg_of = {18'd0, wd[13:0]};
        ENC_QEI_IRQ_EN[7:2]:          reg_of = {18'd0, wd[58:45]};
        ENC_QEI_QERR_COUNT[7:2]:      reg_of = {16'd0, wd[47:32]};
        ENC_QEI_GLITCH_COUNT[7:2]:    reg_of = {16'd0, wd[63:48]};
        ENC_QEI_SNAP_CTRL[7:2]:       reg_of = {28'd0, wd[44:41]};
        ENC_QEI_SNAP_COUNT_LO[7:2]:   reg_of = wd[31:0];
        ENC_QEI_SNAP_COUNT_HI[7:2]:   reg_of = wd[63:32];
        ENC_QEI_SNAP_TIME[7:2]:       reg_of = wd[31:0];
        ENC_QEI_SNAP_EDGE_TIME[7:2]:  reg_of = wd[63:32];
        ENC_QEI_SNAP_DELTA[7:2]:      reg_of = wd[31:0];
        ENC_QEI_SNAP_EDGE_DELTA[7:2]: reg_of = wd[63:32];
        default:                      reg_of = 32'd0;
      endcase
    end
  endfunction

  // the word as the memory gives it, or its reset value before the channel's first visit
  wire [63:0] b_word = b_fresh ? ((word_of(b_word_q) == W_CFG) ? CFG_RST :
                                  (word_of(b_word_q) == W_PRESET) ? PRE_RST :
                                  (word_of(b_word_q) == W_EVT) ? (64'd1 << (16 + ENC_QEI_STATUS_DIR)) :
                                  64'd0) : rdata_b;
  // COUNT_LO write: the lanes not written from the count, {staged, it} near the end of the range
  wire [31:0] b_cnt_w  = (b_cnt_q & ~lanes(b_wstrb_q)) | (b_wdata_q & lanes(b_wstrb_q));
  wire [63:0] b_cnt_v  = {(b_fresh ? 32'd0 : rdata_b[63:32]), b_cnt_w} & SZ_COUNT;

  always @(posedge clk) begin
    pend_we <= 1'b0;
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
              pend_wdata  <= {1'b0, SAVE_LATCH, 4'hF, lat_q};
              pend_set    <= onehot(lat_ch_q);
              lat_valid_q <= 1'b0;
            end
          end else if (~b_pend & ~b_clash) begin
            // port b reads the register's word (a COUNT_LO write: COUNT) now, for the next clock
            if (b_wr_q & b_cnt_lo & (|b_wstrb_q)) begin
              b_st_q <= B_CNT;
            end else if (b_wr_q) begin
              b_st_q <= B_POST;
            end else begin
              b_st_q <= B_READ;
            end
          end
        end
        B_CNT: begin  // the count's low word is here
          b_cnt_q <= b_fresh ? 32'd0 : rdata_b[31:0];
          b_st_q  <= B_HIRD;
        end
        B_HIRD: begin  // port b reads the staged word now
          if (~b_clash) begin
            b_st_q <= B_HI;
          end
        end
        B_HI: begin  // the staged word is here
          pend_we    <= 1'b1;
          pend_wch   <= b_ch_q;
          pend_wdata <= {near_end(b_cnt_v), b_word_q, 4'hF, b_cnt_w};
          pend_set   <= onehot(b_ch_q);
          b_st_q     <= B_DONE;
        end
        B_POST: begin
          pend_we    <= 1'b1;
          pend_wch   <= b_ch_q;
          pend_wdata <= {1'b0, b_word_q, b_wstrb_q, b_wdata_q};
          pend_set   <= onehot(b_ch_q);
          b_st_q     <= B_DONE;
        end
        B_READ: begin
          if ((COUNT_W > 32) & b_cnt_lo) begin
            lat_valid_q <= 1'b1;
            lat_ch_q    <= b_ch_q;
            lat_q       <= b_word[63:32];
          end
          b_rdata_q <= ((COUNT_W > 32) & b_cnt_hi & lat_valid_q & (lat_ch_q == b_ch_q)) ? lat_q :
                       reg_of(b_word_q, b_word);
          b_st_q    <= B_DONE;
        end
        default: begin  // B_DONE
          if (b_wr_q) begin
            b_rdata_q <= 32'd0;
          end
          b_resp_q <= 1'b1;
          b_st_q   <= B_IDLE;
        end
      endcase
    end
  end

  assign resp_valid = b_resp_q;
  assign resp_rdata = b_resp_q ? b_rdata_q : 32'd0;  // (enc_qei ORs it with the globals' answer)

  wire unused_engine = &{1'b0, unused_pend_b, rec_q[R_SIPEND], o_mot[63:32 + MOT_W + 2 * ERR_W],
                         o_evt[31:14], d_emp[63:32], d_semp[63:32], n_cfg_w[63:45], p_pend[42]};

endmodule

`default_nettype wire
