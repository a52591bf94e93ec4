// SPDX-License-Identifier: Apache-2.0
// enc_qei_lane -- one channel of the shared engine (enc_qei parameter ENGINE = 1): only what must
// see every clock. The engine (enc_qei_engine) keeps the channel's registers and wide values in
// block RAM, visits the lanes one after another, reads what each did since its last visit and
// pushes its configuration back.
//
//   a_in, b_in, z_in -> enc_filter_rt (CTRL.FILTER_LEN) -> enc_qei_decode (the per-channel
//   core's own decode: SWAP_AB / INV_*, decoders, count function, index edge) -> here:
//     mpos   the count function's steps while CTRL.EN = 1 (the motion), an up/down counter of
//            MOT_W bits that wraps: the engine keeps the full count and motion and adds what
//            mpos moved between two visits (never more than 2^(MOT_W-1) - 1 steps: the engine
//            sizes MOT_W for the count-rate bound, one step a clock)
//     tgt    where mpos is when the count is 0 (tgt_vb: the end of the free range is within
//            reach): the count wraps between tgt - 1 and tgt, so OVERFLOW / UNDERFLOW are exact.
//            The engine sets it after each visit; an index preset sets it here (mpos + -PRESET),
//            and so does a COUNT write, in the clock the engine loads it (ld)
//     captures, exact to the clock and kept until the engine reads them: mpos at the last
//            acting index edge (a preset's anchor or a latch's value), everything a snapshot
//            needs in the clock it is taken (mpos, the index capture, the timebase's low bits,
//            the last selected edge), the last selected edge (SNAP_CTRL.EDGE: timebase low bits
//            and mpos) for SNAP_EDGE_TIME / SNAP_EDGE_DELTA
//     events of the window (overflow, underflow, index, direction change), free-running counts
//            of quadrature errors and rejected levels, and the live STATUS bits
// The record (rtl/enc_qei_lane.vh) leaves through a register that is 0 except in the clock after
// a read (rd), so the engine ORs the records of all lanes (no multiplexer per lane). A read
// restarts the window: the flags and the captures' pending bits clear (an event in the read's
// clock belongs to the next window).
// Timing, as enc_qei_core counts: a step shows in mpos one clock after step_up / step_dn, an
// index preset or latch acts in the clock of its transition (a preset wins over its step: the
// anchor is mpos after that step), and a selected edge's timestamp is the timebase in the clock
// after the step (mpos then includes it), so the engine rebuilds exactly the per-channel
// registers' values.
// Snapshots: a request (gsnap: the global one, every lane in one clock; snap_cmd: SNAP_CTRL.CMD
// in the clock of a read; a rising snap_in while SNAP_CTRL.IN_EN) takes a capture in its clock
// when none waits to be read. Otherwise (or while snap_hold: a global snapshot waits for every
// lane's capture to be read) the request waits and is taken in the clock of the next read (a
// global snapshot in between takes its place); snap_pend tells the engine a capture waits.
// Configuration (cfg, rtl/enc_qei.vh's C_*) is loaded in the clock before each read (cfg_we), so
// that every event of a window counted with one configuration. INDEX_CTRL.ARM is taken from cfg
// only with arm_we (INDEX_CTRL written); otherwise the lane keeps its own (a one-shot index
// clears it). The count starts at reset like the per-channel build's (EN = 1, x4, FILTER_LEN 3,
// ARM = 1): the registers' reset values.
`default_nettype none
`include "enc_qei_lane_w.vh"

module enc_qei_lane #(
    parameter integer MOT_W = 8,  // motion counter bits (set by the engine for the count-rate bound)
    parameter integer TIM_W = 7,  // timebase low bits kept for a timestamp
    parameter integer ERR_W = 7   // error counter bits
) (
    input  wire             clk,
    input  wire             rst,        // synchronous, active high
    input  wire             valid,      // the input filters have settled (the engine's chain)
    input  wire             a_in,       // encoder channel A, asynchronous
    input  wire             b_in,       // encoder channel B, asynchronous
    input  wire             z_in,       // index channel, asynchronous
    input  wire             snap_in,    // synchronous snapshot strobe
    input  wire [TIM_W-1:0] tb_lo,      // the timebase's low bits now
    input  wire             gsnap,      // a global snapshot in this clock
    input  wire             snap_hold,  // a global snapshot waits: hold this lane's own requests
    // from the engine
    input  wire             cfg_we,     // load cfg at the end of this clock (the clock before rd)
    input  wire             arm_we,     // ... and INDEX_CTRL.ARM from it
    input  wire [`ENC_QEI_LANE_CFG_W(MOT_W)-1:0] cfg,
    input  wire             rd,         // read: the record leaves at the end of this clock
    input  wire             ld,         // a COUNT write: the count is loaded now (with cfg_we; tgt
                                        // and tgt_vb from the configuration now: C_NEGP = -COUNT)
    input  wire             snap_cmd,   // a SNAP_CTRL.CMD snapshot in this clock
    input  wire             tgt_we,     // set tgt / tgt_vb (ignored after an index preset since rd)
    input  wire             tgt_vb,     // the end of the range is within reach
    input  wire [MOT_W-1:0] tgt,        // mpos where the count is 0
    // to the engine
    output wire [`ENC_QEI_LANE_REC_W(MOT_W, TIM_W, ERR_W)-1:0] rec,  // 0 but in the clock after rd
    output wire             snap_pend   // a snapshot capture waits to be read
);

  `include "enc_qei_regs.vh"
  `include "enc_qei_lane.vh"

  generate
    if (CFG_W != `ENC_QEI_LANE_CFG_W(MOT_W) || REC_W != `ENC_QEI_LANE_REC_W(MOT_W, TIM_W, ERR_W)) begin : g_bad_layout
`ifdef __ICARUS__
      enc_qei_lane__layout_of_enc_qei_lane_vh_and_enc_qei_lane_w_vh_differ u_stop ();
`else
      $error("enc_qei_lane: rtl/enc_qei_lane.vh and rtl/enc_qei_lane_w.vh disagree on the widths");
`endif
    end
  endgenerate

  // ---- configuration (the registers' reset values until the engine's first push) ---------------
  localparam [4:0] FILT_RST = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_FILTER_LEN +: 5];
  reg [CFG_W-1:0] cfg_q;
  reg             arm_q;
  wire [CFG_W-1:0] cfg_rst;

  assign cfg_rst[C_EN]                   = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_EN];
  assign cfg_rst[C_SWAP]                 = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_SWAP_AB];
  assign cfg_rst[C_INV_A]                = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_A];
  assign cfg_rst[C_INV_B]                = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_B];
  assign cfg_rst[C_INV_Z]                = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_Z];
  assign cfg_rst[C_FUNC +: C_FUNC_W]     = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_FUNC +: C_FUNC_W];
  assign cfg_rst[C_LAST +: C_LAST_W]     = FILT_RST[3:0] - 4'd1;  // (the reset FILTER_LEN, 3, is in 1 .. 16)
  assign cfg_rst[C_ACT +: C_ACT_W]       = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ACTION +: C_ACT_W];
  assign cfg_rst[C_ONESHOT]              = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ONESHOT];
  assign cfg_rst[C_IEDGE]                = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_EDGE];
  assign cfg_rst[C_GATE_EN]              = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_EN];
  assign cfg_rst[C_GATE_A]               = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_A];
  assign cfg_rst[C_GATE_B]               = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_B];
  assign cfg_rst[C_ARM]                  = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ARM];
  assign cfg_rst[C_SIN_EN]               = ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_IN_EN];
  assign cfg_rst[C_SEDGE]                = ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_EDGE];
  assign cfg_rst[C_NEGP +: C_NEGP_W]     = {MOT_W{1'b0}};  // PRESET 0: -0
  assign cfg_rst[C_VBP]                  = 1'b1;           // ... at the end of the range

  always @(posedge clk) begin
    if (rst) begin
      cfg_q <= cfg_rst;
    end else if (cfg_we) begin
      cfg_q <= cfg;
    end
  end

  wire       en        = cfg_q[C_EN];
  wire [1:0] act       = cfg_q[C_ACT +: C_ACT_W];
  wire       oneshot   = cfg_q[C_ONESHOT];
  wire       snap_edge = cfg_q[C_SEDGE];
  wire       armed     = arm_q & (act != ENC_QEI_INDEX_ACTION_NONE);

  // ---- input filters (enc_conditioner_rt's, with the length the engine clamped) and decode ------
  wire a_c, b_c, z_c, rej_a, rej_b, unused_rej_z;
  wire [3:0] last = cfg_q[C_LAST +: C_LAST_W];

  enc_filter_rt u_filt_a (
      .clk   (clk),
      .rst   (rst),
      .last  (last),
      .in    (a_in),
      .level (a_c),
      .reject(rej_a)
  );

  enc_filter_rt u_filt_b (
      .clk   (clk),
      .rst   (rst),
      .last  (last),
      .in    (b_in),
      .level (b_c),
      .reject(rej_b)
  );

  enc_filter_rt u_filt_z (
      .clk   (clk),
      .rst   (rst),
      .last  (last),
      .in    (z_in),
      .level (z_c),
      .reject(unused_rej_z)
  );

  // a rejected level of A or B, registered like enc_conditioner_rt's glitch
  reg glitch_q;

  always @(posedge clk) begin
    if (rst) begin
      glitch_q <= 1'b0;
    end else begin
      glitch_q <= rej_a | rej_b;
    end
  end

  wire a_eff, b_eff, z_eff, unused_fdn, step_up, step_dn, edge_any, edge_a_rise, qerr;
  wire idx_hit, unused_idx_hit1;
  wire [1:0] unused_step_ab;

  enc_qei_decode u_dec (
      .clk        (clk),
      .rst        (rst),
      .a_c        (a_c),
      .b_c        (b_c),
      .z_c        (z_c),
      .valid      (valid),
      .en         (en),
      .swap_ab    (cfg_q[C_SWAP]),
      .inv_a      (cfg_q[C_INV_A]),
      .inv_b      (cfg_q[C_INV_B]),
      .inv_z      (cfg_q[C_INV_Z]),
      .func       (cfg_q[C_FUNC +: C_FUNC_W]),
      .idx_edge   (cfg_q[C_IEDGE]),
      .idx_gate_en(cfg_q[C_GATE_EN]),
      .idx_gate_a (cfg_q[C_GATE_A]),
      .idx_gate_b (cfg_q[C_GATE_B]),
      .a_eff      (a_eff),
      .b_eff      (b_eff),
      .z_eff      (z_eff),
      .fdn        (unused_fdn),
      .step_up    (step_up),
      .step_dn    (step_dn),
      .edge_any   (edge_any),
      .edge_a_rise(edge_a_rise),
      .step_ab    (unused_step_ab),
      .qerr       (qerr),
      .idx_hit1   (unused_idx_hit1),
      .idx_hit    (idx_hit)
  );

  wire unused_dec = &{1'b0, unused_rej_z, unused_fdn, unused_idx_hit1, unused_step_ab};

  // ---- motion, index, direction ------------------------------------------------------------------
  reg  [MOT_W-1:0] mpos_q;
  wire [MOT_W-1:0] mpos_d = mpos_q + {{(MOT_W-1){step_dn}}, step_up | step_dn};
  wire             preset = idx_hit & armed & (act == ENC_QEI_INDEX_ACTION_PRESET);
  wire             acting = idx_hit & armed;  // a preset or a latch
  reg              dir_q;

  always @(posedge clk) begin
    if (rst) begin
      mpos_q <= {MOT_W{1'b0}};
      dir_q  <= 1'b1;
    end else begin
      mpos_q <= mpos_d;
      if (step_up | step_dn) begin
        dir_q <= step_up;
      end
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      arm_q <= cfg_rst[C_ARM];
    end else if (cfg_we & arm_we) begin
      arm_q <= cfg[C_ARM];  // a write of INDEX_CTRL comes after what the window did
    end else if (acting & oneshot) begin
      arm_q <= 1'b0;
    end
  end

  // ---- the end of the free range: OVERFLOW / UNDERFLOW to the clock ------------------------------
  // The count is 0 where mpos = tgt: an up step onto tgt wraps from the top of the range (mpos_d
  // is mpos after the step), a down step from tgt wraps under 0 (the tgt of before this clock's
  // preset, like the per-channel core: a load does not hide its step's event).
  reg              tgt_vb_q;
  reg  [MOT_W-1:0] tgt_q;
  reg              pre_rd_q;  // an index preset since the last read: the engine's tgt is stale
  wire             ovf = step_up & tgt_vb_q & (mpos_d == tgt_q);
  wire             unf = step_dn & tgt_vb_q & (mpos_q == tgt_q);

  // A COUNT write (ld) loads like a preset, from the value the engine put where PRESET's goes in
  // the clock before (and wins over an index preset in the same clock, as in enc_qei_core).
  wire load = (cfg_we & ld) | preset;

  always @(posedge clk) begin
    if (rst) begin
      tgt_vb_q <= 1'b1;  // count 0 at mpos 0
      tgt_q    <= {MOT_W{1'b0}};
      pre_rd_q <= 1'b0;
    end else begin
      if (load) begin
        tgt_vb_q <= cfg_q[C_VBP];
        tgt_q    <= mpos_d + cfg_q[C_NEGP +: C_NEGP_W];
      end else if (tgt_we & ~pre_rd_q) begin
        tgt_vb_q <= tgt_vb;
        tgt_q    <= tgt;
      end
      pre_rd_q <= load | (pre_rd_q & ~rd);
    end
  end

  // ---- the last selected edge (SNAP_CTRL.EDGE), registered like the timing unit's -----------------
  reg              sel_q;   // a selected edge's step is in mpos_q from this clock
  reg [TIM_W-1:0]  et_q;    // its timebase low bits
  reg [MOT_W-1:0]  emp_q;   // mpos with it
  reg              enew_q;  // one in this window

  always @(posedge clk) begin
    if (rst) begin
      sel_q  <= 1'b0;
      et_q   <= {TIM_W{1'b0}};
      emp_q  <= {MOT_W{1'b0}};
      enew_q <= 1'b0;
    end else begin
      sel_q  <= snap_edge ? edge_a_rise : edge_any;
      if (sel_q) begin
        et_q  <= tb_lo;
        emp_q <= mpos_q;
      end
      enew_q <= sel_q | (enew_q & ~rd);
    end
  end

  // ---- index capture ----------------------------------------------------------------------------
  reg [MOT_W-1:0] icap_q;
  reg             ipend_q, ipre_q;

  always @(posedge clk) begin
    if (rst) begin
      icap_q  <= {MOT_W{1'b0}};
      ipend_q <= 1'b0;
      ipre_q  <= 1'b0;
    end else begin
      if (acting) begin
        icap_q <= mpos_d;
        ipre_q <= preset;
      end
      ipend_q <= acting | (ipend_q & ~rd);
    end
  end

  // ---- snapshots --------------------------------------------------------------------------------
  reg  sprev_q;  // snap_in last clock
  reg  spend_q;  // a capture waits to be read
  reg  sdef_q;   // a request waits for the capture to be read
  wire own     = cfg_q[C_SIN_EN] & snap_in & ~sprev_q;
  wire free    = ~spend_q | rd;  // the capture can be taken in this clock
  wire take    = gsnap | (~snap_hold & free & (snap_cmd | own | (sdef_q & rd)));

  reg [MOT_W-1:0] smpos_q, sicap_q, semp_q;
  reg [TIM_W-1:0] stime_q, set_q;
  reg             sipend_q, sipre_q, snew_q, sedge_q;

  always @(posedge clk) begin
    if (rst) begin
      sprev_q <= 1'b0;
      spend_q <= 1'b0;
      sdef_q  <= 1'b0;
    end else begin
      sprev_q <= snap_in;
      spend_q <= take | (spend_q & ~rd);
      sdef_q  <= ~take & (sdef_q | snap_cmd | own);
    end
  end

  always @(posedge clk) begin
    if (take) begin
      smpos_q  <= mpos_q;
      sicap_q  <= icap_q;
      sipend_q <= ipend_q & ~rd;
      sipre_q  <= ipre_q;
      stime_q  <= tb_lo;
      set_q    <= et_q;
      semp_q   <= emp_q;
      snew_q   <= enew_q & ~rd;
      sedge_q  <= sel_q;
    end
  end

  // ---- events and error counts of the window ------------------------------------------------------
  reg             eovf_q, eunf_q, eidx_q, edch_q;
  reg [ERR_W-1:0] qcnt_q, gcnt_q;
  wire            dch = (step_up & ~dir_q) | (step_dn & dir_q);

  always @(posedge clk) begin
    if (rst) begin
      eovf_q <= 1'b0;
      eunf_q <= 1'b0;
      eidx_q <= 1'b0;
      edch_q <= 1'b0;
      qcnt_q <= {ERR_W{1'b0}};
      gcnt_q <= {ERR_W{1'b0}};
    end else begin
      eovf_q <= ovf | (eovf_q & ~rd);
      eunf_q <= unf | (eunf_q & ~rd);
      eidx_q <= idx_hit | (eidx_q & ~rd);
      edch_q <= dch | (edch_q & ~rd);
      qcnt_q <= qcnt_q + {{(ERR_W-1){1'b0}}, qerr};
      gcnt_q <= gcnt_q + {{(ERR_W-1){1'b0}}, glitch_q};
    end
  end

  // ---- the record, through a register that is 0 unless read ---------------------------------------
  wire [REC_W-1:0] rec_d;

  assign rec_d[R_MPOS +: R_MPOS_W]   = mpos_q;
  assign rec_d[R_ICAP +: R_ICAP_W]   = icap_q;
  assign rec_d[R_IPEND]              = ipend_q;
  assign rec_d[R_IPRE]               = ipre_q;
  assign rec_d[R_SPEND]              = spend_q;
  assign rec_d[R_SMPOS +: R_SMPOS_W] = smpos_q;
  assign rec_d[R_SICAP +: R_SICAP_W] = sicap_q;
  assign rec_d[R_SIPEND]             = sipend_q;
  assign rec_d[R_SIPRE]              = sipre_q;
  assign rec_d[R_STIME +: R_STIME_W] = stime_q;
  assign rec_d[R_SET +: R_SET_W]     = set_q;
  assign rec_d[R_SEMP +: R_SEMP_W]   = semp_q;
  assign rec_d[R_SNEW]               = snew_q;
  assign rec_d[R_SEDGE]              = sedge_q;
  assign rec_d[R_ET +: R_ET_W]       = et_q;
  assign rec_d[R_EMP +: R_EMP_W]     = emp_q;
  assign rec_d[R_ENEW]               = enew_q;
  assign rec_d[R_OVF]                = eovf_q;
  assign rec_d[R_UNF]                = eunf_q;
  assign rec_d[R_IDX]                = eidx_q;
  assign rec_d[R_DCH]                = edch_q;
  assign rec_d[R_QCNT +: R_QCNT_W]   = qcnt_q;
  assign rec_d[R_GCNT +: R_GCNT_W]   = gcnt_q;
  assign rec_d[R_A]                  = a_eff;
  assign rec_d[R_B]                  = b_eff;
  assign rec_d[R_Z]                  = z_eff;
  assign rec_d[R_DIR]                = dir_q;
  assign rec_d[R_ARMED]              = armed;

  reg [REC_W-1:0] rec_q;

  always @(posedge clk) begin
    if (rst | ~rd) begin
      rec_q <= {REC_W{1'b0}};
    end else begin
      rec_q <= rec_d;
    end
  end

  assign rec       = rec_q;
  assign snap_pend = spend_q;

endmodule

`default_nettype wire
