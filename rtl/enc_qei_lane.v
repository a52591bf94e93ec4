// SPDX-License-Identifier: Apache-2.0
// enc_qei_lane -- one channel of the shared engine (enc_qei parameter ENGINE = 1): only what must
// see every clock. The engine (enc_qei_engine) keeps the channel's registers and wide values in
// block RAM, visits the lanes one after another, reads what each did since its last read and
// pushes its configuration back.
//
//   a_in, b_in, z_in, probe_in -> enc_filter_rt (CTRL.FILTER_LEN) -> enc_qei_decode (the
//   per-channel core's own decode: SWAP_AB / INV_*, decoders, count function, index edge) -> here:
//     mpos   the count function's steps while CTRL.EN = 1 (the motion), MOT_W bits that wrap:
//            the engine keeps the full motion and adds what mpos moved between two reads
//     lo     the count's low MOT_W bits, exact: it steps, wraps and stops as enc_qei_core's count
//            does, and loads the low bits of PRESET (index preset), of a COUNT write (ld) or of
//            CEILING / 0 (modulo wraps). Where the full count is (the end of the range, CEILING,
//            COMPARE: within reach or not) comes from a validity set (rtl/enc_qei_lane.vh): the
//            configuration's set for the count at the last read, or, after an anchor (a load or
//            a wrap) since that read, the anchor's set. So OVERFLOW, UNDERFLOW, the range's
//            stops and wraps, STATUS.STOPPED and CMP / cmp_out are exact, in enc_qei_core's
//            clocks
//     captures, exact to the clock and kept until the engine reads them: an index latch, a
//            probe latch (lo, its anchor, the timebase's low bits), everything a snapshot needs in
//            its clock, the last selected edge (SNAP_CTRL.EDGE), the stall timer, the period
//            boundaries (every PERIOD_CTRL.N selected edges), the unit timer
//     events of the window, free-running counts of quadrature errors and rejected levels, and
//            the live STATUS bits
// The record (rtl/enc_qei_lane.vh) is 0 except in a clock with rd, so the engine ORs the records
// of all lanes (no multiplexer per lane) and registers the result: the lane's state in the
// clock of the read. A read starts the next window: flags and pending bits clear (an event in
// the read's clock belongs to the next window).
// Timing, as enc_qei_core and enc_qei_timing count: a step shows in lo and mpos one clock after
// step_up / step_dn; an index acts in the clock of its transition (a preset wins over that
// clock's step, a latch takes the count after it); a selected edge's and a step's timestamp is
// the timebase in the clock after the step (mpos then includes it).
// Snapshots: a request (gsnap: the global one, every lane in one clock; snap_cmd: SNAP_CTRL.CMD;
// the clock after a rising snap_in while SNAP_CTRL.IN_EN; the first clock of the unit timer's
// time) takes a capture in its clock when none waits to be read. Otherwise (or while snap_hold:
// a global snapshot waits for every lane's capture to be read) the request waits and is taken
// in the clock of the next read (a global snapshot in between takes its place); snap_pend tells
// the engine a capture waits.
// Configuration (cfg) is loaded at the end of the clock before each read (cfg_we; so every clock
// of a window counts with one configuration); a COUNT write loads in that clock (ld: from the
// configuration loaded a clock before, whose C_PLO and C_VS_LOAD hold the written value's).
// INDEX_CTRL.ARM and PROBE_CTRL.EN are taken from cfg only with arm_we / pen_we (their register
// written); otherwise the lane keeps its own (a one-shot clears them). st_we restarts the stall
// timer (a new STALL_TIMEOUT) in the next clock; u_we arms the unit timer for C_UD.
// Units (the profile's): TIMING (snapshots, edge times), RANGE (ranges, compare), PROBE (probe
// latch), PERIOD (period capture, stall, unit timer); a unit left out costs nothing and leaves
// its record fields 0.
`default_nettype none
`include "enc_qei_lane_w.vh"

module enc_qei_lane #(
    parameter integer MOT_W  = 9,  // motion / count bits (set by the engine for its reach)
    parameter integer TIM_W  = 8,  // timebase low bits kept for a timestamp
    parameter integer ERR_W  = 7,  // error counter bits
    parameter integer TIMING = 1,  // 1: snapshots and edge times
    parameter integer RANGE  = 0,  // 1: ranges and compare
    parameter integer PROBE  = 0,  // 1: the probe latch
    parameter integer PERIOD = 0,  // 1: period capture, stall detection and the unit timer
    parameter integer EFIFO  = 0,  // 1: the channel has an edge FIFO (beside the engine): its steps
                                   // out, its events in
    parameter integer SMALL_W = 0  // COUNT_W when the engine counts it SMALL (COUNT_W <= MOT_W: the
                                   // free range pushed as modulo with CEILING all ones, from
                                   // reset on), else 0; below MOT_W lo holds the whole count and
                                   // is compared with CEILING as it is
) (
    input  wire             clk,
    input  wire             rst,        // synchronous, active high
    input  wire             valid,      // the input filters have settled (the engine's count)
    input  wire             a_in,       // encoder channel A, asynchronous
    input  wire             b_in,       // encoder channel B, asynchronous
    input  wire             z_in,       // index channel, asynchronous
    input  wire             probe_in,   // external latch input, asynchronous
    input  wire             snap_in,    // synchronous snapshot strobe
    input  wire [TIM_W-1:0] tb_lo,      // the timebase's low bits now
    input  wire             tick,       // the timebase advances at the end of this clock
    input  wire             gsnap,      // a global snapshot in this clock
    input  wire             snap_hold,  // a global snapshot waits: hold this lane's own requests
    // from the engine
    input  wire             cfg_we,     // load cfg at the end of this clock
    input  wire             arm_we,     // ... and INDEX_CTRL.ARM from it
    input  wire             pen_we,     // ... and PROBE_CTRL.EN from it
    input  wire             st_we,      // ... and restart the stall timer
    input  wire             u_we,       // ... and arm the unit timer for C_UD
    input  wire [`ENC_QEI_LANE_CFG_W(MOT_W, TIM_W)-1:0] cfg,
    input  wire             ld,         // a COUNT write loads the count now (with cfg_we)
    input  wire             snap_cmd,   // a SNAP_CTRL.CMD snapshot in this clock
    input  wire             rd,         // read: the record shows the lane in this clock
    // to the engine
    output wire [`ENC_QEI_LANE_REC_W(MOT_W, TIM_W, ERR_W)-1:0] rec,  // 0 but with rd
    output wire             snap_pend,  // a snapshot capture waits to be read
    output wire             cmp_out,    // one clock when the count changes to COMPARE (CMP_EN)
    // the channel's edge FIFO (enc_qei_efifo, EFIFO = 1; enc_qei_efifo_bank): the count
    // function's steps in the clock of the step, as enc_qei_core gives them to the per-channel
    // build's FIFO, and the FIFO's events
    output wire             step_up,    // a step up (while CTRL.EN = 1)
    output wire             step_dn,    // ... a step down
    output wire [1:0]       step_ab,    // ... {A, B} after it
    output wire             idx_hit,    // a qualified index edge, aligned with the steps
    input  wire             ef_thresh,  // the FIFO holds EFIFO_CTRL.THRESH entries or more
    input  wire             ef_ovf      // a step was lost to the full FIFO
);

  `include "enc_qei_regs.vh"
  `include "enc_qei_lane.vh"

  generate
    if (CFG_W != `ENC_QEI_LANE_CFG_W(MOT_W, TIM_W) ||
        REC_W != `ENC_QEI_LANE_REC_W(MOT_W, TIM_W, ERR_W)) begin : g_bad_layout
`ifdef __ICARUS__
      enc_qei_lane__layout_of_enc_qei_lane_vh_and_enc_qei_lane_w_vh_differ u_stop ();
`else
      $error("enc_qei_lane: rtl/enc_qei_lane.vh and rtl/enc_qei_lane_w.vh disagree on the widths");
`endif
    end
  endgenerate

  // ---- configuration (the registers' reset values until the engine's first push) ---------------
  localparam [4:0] FILT_RST = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_FILTER_LEN +: 5];
  localparam [7:0] PER_N_RST = ENC_QEI_PERIOD_CTRL_RESET[ENC_QEI_PERIOD_CTRL_N +: 8];
  // validity sets at reset: the count, PRESET and COMPARE are 0, CEILING is all ones, one step
  // from 0 modulo 2^COUNT_W: each is at the end of the range, at CEILING and at COMPARE
  localparam [3:0] VS_RST_0 = 4'b1011;  // 0
  localparam [3:0] VS_RST_C = 4'b1011;  // CEILING
  // a SMALL count below MOT_W bits: lo is the whole count (see ge_c), CEILING's reset value is
  // 2^COUNT_W - 1
  localparam         WHOLE = (SMALL_W != 0 && SMALL_W < MOT_W);
  localparam [MOT_W-1:0] C_RST = WHOLE ? {MOT_W{1'b1}} >> (MOT_W - SMALL_W) : {MOT_W{1'b1}};
  reg  [CFG_W-1:0] cfg_q;
  wire [CFG_W-1:0] cfg_rst;

  assign cfg_rst[C_EN]                 = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_EN];
  assign cfg_rst[C_SWAP]               = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_SWAP_AB];
  assign cfg_rst[C_INV_A]              = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_A];
  assign cfg_rst[C_INV_B]              = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_B];
  assign cfg_rst[C_INV_Z]              = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_Z];
  assign cfg_rst[C_FUNC +: C_FUNC_W]   = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_FUNC +: C_FUNC_W];
  assign cfg_rst[C_LAST +: C_LAST_W]   = FILT_RST[3:0] - 4'd1;  // (the reset FILTER_LEN is in 1 .. 16)
  // (a SMALL count: the free range as the engine pushes it, modulo with CEILING 2^COUNT_W - 1)
  assign cfg_rst[C_RANGE +: C_RANGE_W] = (SMALL_W != 0 &&
                                          ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_RANGE +: C_RANGE_W] == ENC_QEI_RANGE_FREE) ?
                                         ENC_QEI_RANGE_MODULO : ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_RANGE +: C_RANGE_W];
  assign cfg_rst[C_CMP_EN]             = ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_CMP_EN];
  assign cfg_rst[C_ACT +: C_ACT_W]     = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ACTION +: C_ACT_W];
  assign cfg_rst[C_ONESHOT]            = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ONESHOT];
  assign cfg_rst[C_IEDGE]              = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_EDGE];
  assign cfg_rst[C_GATE_EN]            = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_EN];
  assign cfg_rst[C_GATE_A]             = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_A];
  assign cfg_rst[C_GATE_B]             = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_B];
  assign cfg_rst[C_ARM]                = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ARM];
  assign cfg_rst[C_SIN_EN]             = ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_IN_EN];
  assign cfg_rst[C_SEDGE]              = ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_EDGE];
  assign cfg_rst[C_UEN]                = ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_PERIOD_EN];
  assign cfg_rst[C_PEN]                = ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_EN];
  assign cfg_rst[C_PEDGE]              = ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_EDGE];
  assign cfg_rst[C_PONCE]              = ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_ONCE];
  assign cfg_rst[C_PER_EN]             = ENC_QEI_PERIOD_CTRL_RESET[ENC_QEI_PERIOD_CTRL_EN];
  assign cfg_rst[C_PER_EDGE]           = ENC_QEI_PERIOD_CTRL_RESET[ENC_QEI_PERIOD_CTRL_EDGE];
  assign cfg_rst[C_PER_N +: C_PER_N_W] = (PER_N_RST == 8'd0) ? 8'd0 : PER_N_RST - 8'd1;
  assign cfg_rst[C_STO +: C_STO_W]     = {TIM_W{1'b0}};  // STALL_TIMEOUT 0: off
  assign cfg_rst[C_UPER +: C_UPER_W]   = {{(TIM_W-1){1'b0}}, 1'b1};  // SNAP_PERIOD 0 acts as 1
  assign cfg_rst[C_UD +: C_UD_W]       = {TIM_W{1'b0}};
  assign cfg_rst[C_PLO +: C_PLO_W]     = {MOT_W{1'b0}};  // PRESET 0
  assign cfg_rst[C_CLO +: C_CLO_W]     = C_RST;           // CEILING all ones
  assign cfg_rst[C_MLO +: C_MLO_W]     = {MOT_W{1'b0}};  // COMPARE 0
  assign cfg_rst[C_VS_CNT +: VS_W]     = VS_RST_0;
  assign cfg_rst[C_VS_LOAD +: VS_W]    = VS_RST_0;
  assign cfg_rst[C_VS_ZERO +: VS_W]    = VS_RST_0;
  assign cfg_rst[C_VS_CEIL +: VS_W]    = VS_RST_C;
  assign cfg_rst[C_VSO_LOAD +: VS_W]   = VS_RST_0;
  assign cfg_rst[C_VSO_CEIL +: VS_W]   = VS_RST_C;

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
  wire [3:0] last      = cfg_q[C_LAST +: C_LAST_W];
  reg        arm_q;
  wire       armed     = arm_q & (act != ENC_QEI_INDEX_ACTION_NONE);

  // ---- input filters (enc_conditioner_rt's, with the length the engine clamped) and decode ------
  wire a_c, b_c, z_c, rej_a, rej_b, unused_rej_z;

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

  wire a_eff, b_eff, z_eff, unused_fdn, edge_any, edge_a_rise, qerr;
  wire unused_idx_hit1;

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
      .step_ab    (step_ab),
      .qerr       (qerr),
      .idx_hit1   (unused_idx_hit1),
      .idx_hit    (idx_hit)
  );

  wire unused_dec = &{1'b0, unused_rej_z, unused_fdn, unused_idx_hit1};

  // ---- motion, index, direction ------------------------------------------------------------------
  reg  [MOT_W-1:0] mpos_q;
  wire             preset = idx_hit & armed & (act == ENC_QEI_INDEX_ACTION_PRESET);
  wire             latch  = idx_hit & armed & (act == ENC_QEI_INDEX_ACTION_LATCH);
  reg              dir_q;

  always @(posedge clk) begin
    if (rst) begin
      mpos_q <= {MOT_W{1'b0}};
      dir_q  <= REC_RST[R_DIR];  // up
    end else begin
      mpos_q <= mpos_q + {{(MOT_W-1){step_dn}}, step_up | step_dn};
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
    end else if (idx_hit & armed & oneshot) begin
      arm_q <= 1'b0;
    end
  end

  // ---- the count's low bits, its range, compare ------------------------------------------------------
  // The validity set in force: the one for the count at the last read (vs_q), or the last
  // anchor's since that read (lat_vs_q).
  reg  [MOT_W-1:0] lo_q;
  reg  [1:0]       anc_q;     // the last anchor since the read (A_NONE: none)
  reg              use_lat_q; // the set of the last anchor is in force
  reg  [3:0]       vs_q, lat_vs_q;
  reg              stop_q;    // non_recycle stopped (STATUS.STOPPED)
  wire [3:0]       vset   = use_lat_q ? lat_vs_q : vs_q;
  wire [1:0]       range  = (RANGE != 0) ? cfg_q[C_RANGE +: C_RANGE_W] : ENC_QEI_RANGE_FREE;
  wire             r_free = (range == ENC_QEI_RANGE_FREE);
  wire             r_mod  = (range == ENC_QEI_RANGE_MODULO);
  wire             r_nr   = (range == ENC_QEI_RANGE_NON_RECYCLE);
  wire [MOT_W-1:0] c_lo   = cfg_q[C_CLO +: C_CLO_W];
  wire [MOT_W-1:0] dc     = lo_q - c_lo;
  wire             at_0   = vset[V_B] & (lo_q == {MOT_W{1'b0}});
  wire             at_max = vset[V_B] & (lo_q == {MOT_W{1'b1}});
  // count >= CEILING. Near the end of the free range (V_B) the counts in reach may lie on both
  // sides of it (a count that crossed it since the set was made): lo's top bit tells the side
  // (set: just below 2^COUNT_W), and CEILING's low bits' top bit CEILING's when it is in reach too
  // (V_C, modulo 2^COUNT_W); a CEILING out of reach lies between the two sides.
  // With a SMALL count below MOT_W bits the count is all in lo (it never leaves 0 ..
  // 2^COUNT_W - 1, half of lo's range at most), so lo >= CEILING is the sign of their difference;
  // lo's top bit is then no side.
  wire             lo_hi  = lo_q[MOT_W-1];
  wire             c_hi   = c_lo[MOT_W-1];
  wire             ge_c   = WHOLE ? ~dc[MOT_W-1] :
                            (vset[V_B] & vset[V_C] & (lo_hi != c_hi)) ? lo_hi :
                            vset[V_C] ? ~dc[MOT_W-1] :
                            vset[V_B] ? lo_hi : vset[V_AC];
  wire             u_step = step_up & ~stop_q;
  wire             d_step = ~step_up & step_dn & ~stop_q;
  wire             up_end = u_step & (r_free ? at_max : ge_c);   // overflow
  wire             dn_end = d_step & at_0;                       // underflow
  wire             wrap_0 = up_end & r_mod;                      // modulo: to 0 ...
  wire             wrap_c = dn_end & r_mod;                      // ... to CEILING
  wire             blocked = (up_end | dn_end) & ~r_free & ~r_mod;
  wire             ldw    = cfg_we & ld;                         // a COUNT write's load
  wire             load   = ldw | preset;                        // (wins over a preset)
  // lo after this clock's step, before a load (an index latch takes it)
  wire [MOT_W-1:0] lo_st  = wrap_0 ? {MOT_W{1'b0}} : wrap_c ? c_lo :
                            ((u_step | d_step) & ~blocked) ? lo_q + {{(MOT_W-1){d_step}}, 1'b1} : lo_q;
  wire [1:0]       anc_st = wrap_0 ? A_ZERO[1:0] : wrap_c ? A_CEIL[1:0] : anc_q;
  wire [1:0]       anc_nx = load ? A_LOAD[1:0] : anc_st;         // the last anchor after this clock
  wire             moved  = load | wrap_0 | wrap_c | ((u_step | d_step) & ~blocked);
  reg              upd_q, cmp_q;

  // the set of an anchor taken in this clock: the configuration's for the value it loads
  // (with a new configuration: its set for the value this configuration replaces)
  reg [3:0] anc_vs;

  always @(*) begin
    if (ldw) begin
      anc_vs = cfg_q[C_VS_LOAD +: VS_W];
    end else if (cfg_we) begin
      case (anc_nx)
        A_LOAD[1:0]: anc_vs = cfg[C_VSO_LOAD +: VS_W];
        A_ZERO[1:0]: anc_vs = cfg[C_VS_ZERO +: VS_W];
        default:     anc_vs = cfg[C_VSO_CEIL +: VS_W];
      endcase
    end else begin
      case (anc_nx)
        A_LOAD[1:0]: anc_vs = cfg_q[C_VS_LOAD +: VS_W];
        A_ZERO[1:0]: anc_vs = cfg_q[C_VS_ZERO +: VS_W];
        default:     anc_vs = cfg_q[C_VS_CEIL +: VS_W];
      endcase
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      lo_q      <= {MOT_W{1'b0}};
      anc_q     <= A_NONE[1:0];
      use_lat_q <= 1'b0;
      vs_q      <= VS_RST_0;
      lat_vs_q  <= VS_RST_0;
      stop_q    <= 1'b0;
      upd_q     <= 1'b0;
      cmp_q     <= 1'b0;
    end else begin
      lo_q  <= load ? cfg_q[C_PLO +: C_PLO_W] : lo_st;
      anc_q <= (load | wrap_0 | wrap_c | ~rd) ? anc_nx : A_NONE[1:0];
      if (load | wrap_0 | wrap_c | (cfg_we & (anc_nx != A_NONE[1:0]))) begin
        use_lat_q <= 1'b1;
        lat_vs_q  <= anc_vs;
      end else if (cfg_we) begin
        use_lat_q <= 1'b0;  // the set for the count at the last read, for the new configuration
        vs_q      <= cfg[C_VS_CNT +: VS_W];
      end
      stop_q <= ~ldw & (stop_q | (r_nr & (up_end | dn_end)));
      upd_q  <= moved;
      cmp_q  <= (RANGE != 0) & cfg_q[C_CMP_EN] & upd_q & vset[V_P] & (lo_q == cfg_q[C_MLO +: C_MLO_W]);
    end
  end

  assign cmp_out = cmp_q;

  // ---- index latch ------------------------------------------------------------------------------------
  reg [MOT_W-1:0] lcap_q;
  reg [1:0]       lanc_q;
  reg             lpend_q;

  always @(posedge clk) begin
    if (rst) begin
      lcap_q  <= {MOT_W{1'b0}};
      lanc_q  <= A_NONE[1:0];
      lpend_q <= 1'b0;
    end else begin
      if (latch) begin
        lcap_q <= lo_st;
        lanc_q <= (wrap_0 | wrap_c | ~rd) ? anc_st : A_NONE[1:0];
      end
      lpend_q <= latch | (lpend_q & ~rd);
    end
  end

  // ---- the stall timer, the unit timer (PERIOD) ------------------------------------------------------
  reg  stq_q;  // a step is in mpos_q from this clock (the timing unit's step_q)
  wire unit;   // the unit timer's time: a snapshot request in this clock

  always @(posedge clk) begin
    if (rst) begin
      stq_q <= 1'b0;
    end else begin
      stq_q <= step_up | step_dn;
    end
  end

  wire [TIM_W-1:0] g, fst, ud;
  wire             grst, sev, stalled, uhit, uarm;

  generate
    if (PERIOD != 0) begin : g_timers
      // stall: g_q counts the ticks after the clock of the last restart (a step, registered;
      // a new STALL_TIMEOUT), saturating. With C_STO != 0 the lane raises the stall itself, as
      // enc_qei_timing: at the tick that makes g_q reach C_STO, not in a restart's clock.
      reg  [TIM_W-1:0] g_q, fst_q;
      reg              st_new_q, stalled_q, sev_q, grst_q;
      wire [TIM_W-1:0] sto     = cfg_q[C_STO +: C_STO_W];
      wire             restart = stq_q | st_new_q;
      wire             hit     = (sto != {TIM_W{1'b0}}) & ~stalled_q & ~restart & tick &
                                 (g_q == sto - {{(TIM_W-1){1'b0}}, 1'b1});

      always @(posedge clk) begin
        if (rst) begin
          g_q       <= {TIM_W{1'b0}};
          st_new_q  <= 1'b0;
          stalled_q <= 1'b0;
          sev_q     <= 1'b0;
          grst_q    <= 1'b0;
        end else begin
          st_new_q <= cfg_we & st_we;
          if (restart) begin
            g_q <= {TIM_W{1'b0}};
          end else if (tick & ~(&g_q)) begin
            g_q <= g_q + {{(TIM_W-1){1'b0}}, 1'b1};
          end
          stalled_q <= ~restart & (stalled_q | hit);
          sev_q     <= hit | (sev_q & ~rd);
          grst_q    <= restart | (grst_q & ~rd);
        end
      end

      always @(posedge clk) begin
        if (restart & (rd | ~grst_q)) begin
          fst_q <= tb_lo;  // the window's first restart
        end
      end

      // unit timer: armed for the time ud_q (low bits); it expires in the first clock the
      // timebase shows it, and reloads itself (+ C_UPER) when C_UPER != 0, else waits for the
      // engine (u_we). PERIOD_EN rising: the time is the timebase now + C_UPER.
      reg  [TIM_W-1:0] ud_q;
      reg              uarm_q, uen_q, uhit_q;
      wire             uen  = cfg_q[C_UEN];
      wire [TIM_W-1:0] uper = cfg_q[C_UPER +: C_UPER_W];
      wire             uexp = uen & uarm_q & (tb_lo == ud_q);

      always @(posedge clk) begin
        if (rst) begin
          uarm_q <= 1'b0;
          uen_q  <= 1'b0;
          uhit_q <= 1'b0;
        end else begin
          uen_q  <= uen;
          uhit_q <= uexp | (uhit_q & ~rd);
          if (cfg_we & u_we) begin
            uarm_q <= 1'b1;
          end else if (~uen) begin
            uarm_q <= 1'b0;
          end else if (~uen_q) begin
            uarm_q <= (uper != {TIM_W{1'b0}});
          end else if (uexp) begin
            uarm_q <= (uper != {TIM_W{1'b0}});
          end
        end
      end

      always @(posedge clk) begin
        if (cfg_we & u_we) begin
          ud_q <= cfg[C_UD +: C_UD_W];
        end else if (uen & ~uen_q) begin
          ud_q <= tb_lo + uper;
        end else if (uexp) begin
          ud_q <= ud_q + uper;
        end
      end

      assign g       = g_q;
      assign fst     = fst_q;
      assign grst    = grst_q;
      assign sev     = sev_q;
      assign stalled = stalled_q;
      assign ud      = ud_q;
      assign uarm    = uarm_q;
      assign uhit    = uhit_q;
      assign unit    = uexp;
    end else begin : g_no_timers
      wire unused_timers = &{1'b0, tick, st_we, u_we, stq_q};
      assign g       = {TIM_W{1'b0}};
      assign fst     = {TIM_W{1'b0}};
      assign grst    = 1'b0;
      assign sev     = 1'b0;
      assign stalled = 1'b0;
      assign ud      = {TIM_W{1'b0}};
      assign uarm    = 1'b0;
      assign uhit    = 1'b0;
      assign unit    = 1'b0;
    end
  endgenerate

  // ---- the last selected edge (SNAP_CTRL.EDGE) and snapshots (TIMING) -----------------------------------
  wire             spend, sedge, snew, enew;
  wire [MOT_W-1:0] smpos, slo, semp, emp;
  wire [1:0]       sanc;
  wire [TIM_W-1:0] stime, set_t, et;

  generate
    if (TIMING != 0) begin : g_snap
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
          sel_q  <= cfg_q[C_SEDGE] ? edge_a_rise : edge_any;
          if (sel_q) begin
            et_q  <= tb_lo;
            emp_q <= mpos_q;
          end
          enew_q <= sel_q | (enew_q & ~rd);
        end
      end

      reg  sprev_q;  // snap_in last clock
      reg  own_q;    // a rising snap_in last clock (IN_EN): a request now, as enc_qei_snaptrig's
      reg  spend_q;  // a capture waits to be read
      reg  sdef_q;   // a request waits for the capture to be read
      wire req     = snap_cmd | own_q | unit;
      wire free    = ~spend_q | rd;  // the capture can be taken in this clock
      wire take    = gsnap | (~snap_hold & free & (req | (sdef_q & rd)));

      reg [MOT_W-1:0] smpos_q, slo_q, semp_q;
      reg [TIM_W-1:0] stime_q, set_q;
      reg [1:0]       sanc_q;
      reg             snew_q, sedge_q;

      always @(posedge clk) begin
        if (rst) begin
          sprev_q <= 1'b0;
          own_q   <= 1'b0;
          spend_q <= 1'b0;
          sdef_q  <= 1'b0;
        end else begin
          sprev_q <= snap_in;
          own_q   <= cfg_q[C_SIN_EN] & snap_in & ~sprev_q;
          spend_q <= take | (spend_q & ~rd);
          sdef_q  <= ~take & (sdef_q | req);
        end
      end

      always @(posedge clk) begin
        if (take) begin
          smpos_q <= mpos_q;
          slo_q   <= lo_q;
          sanc_q  <= rd ? A_NONE[1:0] : anc_q;
          stime_q <= tb_lo;
          set_q   <= et_q;
          semp_q  <= emp_q;
          snew_q  <= enew_q & ~rd;
          sedge_q <= sel_q;
        end
      end

      assign spend = spend_q;
      assign smpos = smpos_q;
      assign slo   = slo_q;
      assign sanc  = sanc_q;
      assign stime = stime_q;
      assign set_t = set_q;
      assign semp  = semp_q;
      assign snew  = snew_q;
      assign sedge = sedge_q;
      assign et    = et_q;
      assign emp   = emp_q;
      assign enew  = enew_q;
    end else begin : g_no_snap
      wire unused_snap = &{1'b0, snap_in, gsnap, snap_hold, snap_cmd, unit, edge_a_rise,
                           edge_any, cfg_q[C_SIN_EN], cfg_q[C_SEDGE]};
      assign spend = 1'b0;
      assign smpos = {MOT_W{1'b0}};
      assign slo   = {MOT_W{1'b0}};
      assign sanc  = A_NONE[1:0];
      assign stime = {TIM_W{1'b0}};
      assign set_t = {TIM_W{1'b0}};
      assign semp  = {MOT_W{1'b0}};
      assign snew  = 1'b0;
      assign sedge = 1'b0;
      assign et    = {TIM_W{1'b0}};
      assign emp   = {MOT_W{1'b0}};
      assign enew  = 1'b0;
    end
  endgenerate

  // ---- events and error counts of the window ------------------------------------------------------
  reg             eovf_q, eunf_q, eidx_q, edch_q, ecmp_q;
  reg [ERR_W-1:0] qcnt_q, gcnt_q;
  wire            dch = (step_up & ~dir_q) | (step_dn & dir_q);

  always @(posedge clk) begin
    if (rst) begin
      eovf_q <= 1'b0;
      eunf_q <= 1'b0;
      eidx_q <= 1'b0;
      edch_q <= 1'b0;
      ecmp_q <= 1'b0;
      qcnt_q <= {ERR_W{1'b0}};
      gcnt_q <= {ERR_W{1'b0}};
    end else begin
      eovf_q <= up_end | (eovf_q & ~rd);
      eunf_q <= dn_end | (eunf_q & ~rd);
      eidx_q <= idx_hit | (eidx_q & ~rd);
      edch_q <= dch | (edch_q & ~rd);
      ecmp_q <= cmp_q | (ecmp_q & ~rd);
      qcnt_q <= qcnt_q + {{(ERR_W-1){1'b0}}, qerr};
      gcnt_q <= gcnt_q + {{(ERR_W-1){1'b0}}, glitch_q};
    end
  end

  // the edge FIFO's events of the window (EFIFO_THRESH: some clock of the window had the level)
  wire eeft, eefo;

  generate
    if (EFIFO != 0) begin : g_efifo_ev
      reg eeft_q, eefo_q;

      always @(posedge clk) begin
        if (rst) begin
          eeft_q <= 1'b0;
          eefo_q <= 1'b0;
        end else begin
          eeft_q <= ef_thresh | (eeft_q & ~rd);
          eefo_q <= ef_ovf | (eefo_q & ~rd);
        end
      end

      assign eeft = eeft_q;
      assign eefo = eefo_q;
    end else begin : g_no_efifo_ev
      wire unused_ef = &{1'b0, ef_thresh, ef_ovf};
      assign eeft = 1'b0;
      assign eefo = 1'b0;
    end
  endgenerate

  // ---- probe latch (PROBE) ------------------------------------------------------------------------
  wire             ppend, pen_now;
  wire [MOT_W-1:0] plo;
  wire [1:0]       panc;
  wire [TIM_W-1:0] ptime;

  generate
    if (PROBE != 0) begin : g_probe
      wire probe_c, unused_rej_p;

      enc_filter_rt u_filt_p (
          .clk   (clk),
          .rst   (rst),
          .last  (last),
          .in    (probe_in),
          .level (probe_c),
          .reject(unused_rej_p)
      );

      // the edge, registered like enc_qei_core's probe_hit_q (latency as the index)
      reg pen_q, pprev_q, pok_q, phit_q;
      reg [MOT_W-1:0] plo_q;
      reg [1:0]       panc_q;
      reg [TIM_W-1:0] ptime_q;
      reg             ppend_q;

      always @(posedge clk) begin
        if (rst | ~valid) begin
          pprev_q <= 1'b0;
          pok_q   <= 1'b0;
          phit_q  <= 1'b0;
        end else begin
          pprev_q <= probe_c;
          pok_q   <= 1'b1;
          phit_q  <= pok_q & pen_q &
                     (cfg_q[C_PEDGE] ? (pprev_q & ~probe_c) : (~pprev_q & probe_c));
        end
      end

      always @(posedge clk) begin
        if (rst) begin
          pen_q   <= cfg_rst[C_PEN];
          ppend_q <= 1'b0;
        end else begin
          if (cfg_we & pen_we) begin
            pen_q <= cfg[C_PEN];  // a write of PROBE_CTRL comes after what the window did
          end else if (phit_q & cfg_q[C_PONCE]) begin
            pen_q <= 1'b0;
          end
          ppend_q <= phit_q | (ppend_q & ~rd);
        end
      end

      always @(posedge clk) begin
        if (phit_q) begin
          plo_q   <= lo_q;
          panc_q  <= rd ? A_NONE[1:0] : anc_q;
          ptime_q <= tb_lo;
        end
      end

      wire unused_probe = &{1'b0, unused_rej_p};
      assign ppend   = ppend_q;
      assign plo     = plo_q;
      assign panc    = panc_q;
      assign ptime   = ptime_q;
      assign pen_now = pen_q;
    end else begin : g_no_probe
      wire unused_probe = &{1'b0, probe_in, pen_we, cfg_q[C_PEN], cfg_q[C_PEDGE], cfg_q[C_PONCE]};
      assign ppend   = 1'b0;
      assign plo     = {MOT_W{1'b0}};
      assign panc    = A_NONE[1:0];
      assign ptime   = {TIM_W{1'b0}};
      assign pen_now = 1'b0;
    end
  endgenerate

  // ---- period capture (PERIOD) ------------------------------------------------------------------
  wire             bst, bdir, prun;
  wire [TIM_W-1:0] bf, bt, bt0;
  wire [1:0]       nb;

  generate
    if (PERIOD != 0) begin : g_period
      reg             psel_q;   // a selected edge (PERIOD_CTRL.EDGE), registered as sel_q
      reg             dchq_q;   // a direction change, registered alike
      reg             pst_q;    // a measurement is running
      reg [7:0]       pcnt_q;   // selected edges since its start
      reg             pdir_q;   // a direction change inside it
      reg [1:0]       nb_q;     // boundaries in the window (saturating)
      reg             bst_q;    // a start in the window
      reg [TIM_W-1:0] bf_q, bt_q, bt0_q;
      reg             bdir_q;
      wire            per_en = cfg_q[C_PER_EN];
      // (at or above N - 1: a lower N ends the measurement in progress at its next edge)
      wire            plast  = (pcnt_q >= cfg_q[C_PER_N +: C_PER_N_W]);
      wire            pstart = per_en & psel_q & ~pst_q;          // the first edge after EN
      wire            pbound = per_en & psel_q & pst_q & plast;   // every N-th one after it
      wire            pany_q = (nb_q != 2'd0) | bst_q;            // one of them in the window

      always @(posedge clk) begin
        if (rst) begin
          psel_q <= 1'b0;
          dchq_q <= 1'b0;
          pst_q  <= 1'b0;
          pcnt_q <= 8'd0;
          pdir_q <= 1'b0;
          nb_q   <= 2'd0;
          bst_q  <= 1'b0;
          bdir_q <= 1'b0;
        end else begin
          psel_q <= cfg_q[C_PER_EDGE] ? edge_a_rise : edge_any;
          dchq_q <= dch;
          if (~per_en) begin
            pst_q <= 1'b0;
          end else if (pstart | pbound) begin
            pst_q  <= 1'b1;
            pcnt_q <= 8'd0;
            pdir_q <= 1'b0;
          end else if (pst_q) begin
            if (psel_q) begin
              pcnt_q <= pcnt_q + 8'd1;
            end
            pdir_q <= pdir_q | dchq_q;
          end
          nb_q  <= (rd ? 2'd0 : nb_q) + {1'b0, pbound & ~(~rd & (nb_q == 2'd3))};
          bst_q <= pstart | (bst_q & ~rd);
          if (pbound) begin
            bdir_q <= pdir_q | dchq_q;
          end
        end
      end

      always @(posedge clk) begin
        if (pstart | pbound) begin
          bt0_q <= bt_q;
          bt_q  <= tb_lo;
          if (rd | ~pany_q) begin
            bf_q <= tb_lo;
          end
        end
      end

      assign nb   = nb_q;
      assign bst  = bst_q;
      assign prun = pst_q;
      assign bf   = bf_q;
      assign bt   = bt_q;
      assign bt0  = bt0_q;
      assign bdir = bdir_q;
    end else begin : g_no_period
      wire unused_period = &{1'b0, cfg_q[C_PER_EN], cfg_q[C_PER_EDGE], cfg_q[C_PER_N +: C_PER_N_W],
                             cfg_q[C_STO +: C_STO_W], cfg_q[C_UPER +: C_UPER_W], cfg_q[C_UEN],
                             cfg[C_UD +: C_UD_W]};
      assign nb   = 2'd0;
      assign bst  = 1'b0;
      assign prun = 1'b0;
      assign bf   = {TIM_W{1'b0}};
      assign bt   = {TIM_W{1'b0}};
      assign bt0  = {TIM_W{1'b0}};
      assign bdir = 1'b0;
    end
  endgenerate

  // ---- the record: 0 unless read ------------------------------------------------------------------
  wire [REC_W-1:0] rec_d;

  assign rec_d[R_MPOS +: R_MPOS_W]     = mpos_q;
  assign rec_d[R_LO +: R_LO_W]         = lo_q;
  assign rec_d[R_ANC +: R_ANC_W]       = anc_q;
  assign rec_d[R_LPEND]                = lpend_q;
  assign rec_d[R_LCAP +: R_LCAP_W]     = lcap_q;
  assign rec_d[R_LANC +: R_LANC_W]     = lanc_q;
  assign rec_d[R_SPEND]                = spend;
  assign rec_d[R_SMPOS +: R_SMPOS_W]   = smpos;
  assign rec_d[R_SLO +: R_SLO_W]       = slo;
  assign rec_d[R_SANC +: R_SANC_W]     = sanc;
  assign rec_d[R_STIME +: R_STIME_W]   = stime;
  assign rec_d[R_SET +: R_SET_W]       = set_t;
  assign rec_d[R_SEMP +: R_SEMP_W]     = semp;
  assign rec_d[R_SNEW]                 = snew;
  assign rec_d[R_SEDGE]                = sedge;
  assign rec_d[R_ET +: R_ET_W]         = et;
  assign rec_d[R_EMP +: R_EMP_W]       = emp;
  assign rec_d[R_ENEW]                 = enew;
  assign rec_d[R_OVF]                  = eovf_q;
  assign rec_d[R_UNF]                  = eunf_q;
  assign rec_d[R_IDX]                  = eidx_q;
  assign rec_d[R_DCH]                  = edch_q;
  assign rec_d[R_CMP]                  = ecmp_q;
  assign rec_d[R_EFT]                  = eeft;
  assign rec_d[R_EFO]                  = eefo;
  assign rec_d[R_QCNT +: R_QCNT_W]     = qcnt_q;
  assign rec_d[R_GCNT +: R_GCNT_W]     = gcnt_q;
  assign rec_d[R_A]                    = a_eff;
  assign rec_d[R_B]                    = b_eff;
  assign rec_d[R_Z]                    = z_eff;
  assign rec_d[R_DIR]                  = dir_q;
  assign rec_d[R_ARM]                  = arm_q;
  assign rec_d[R_ARMED]                = armed;
  assign rec_d[R_STOPPED]              = stop_q;
  assign rec_d[R_PPEND]                = ppend;
  assign rec_d[R_PLO +: R_PLO_W]       = plo;
  assign rec_d[R_PANC +: R_PANC_W]     = panc;
  assign rec_d[R_PTIME +: R_PTIME_W]   = ptime;
  assign rec_d[R_PEN]                  = pen_now;
  assign rec_d[R_G +: R_G_W]           = g;
  assign rec_d[R_GRST]                 = grst;
  assign rec_d[R_FST +: R_FST_W]       = fst;
  assign rec_d[R_SEV]                  = sev;
  assign rec_d[R_STALLED]              = stalled;
  assign rec_d[R_NB +: R_NB_W]         = nb;
  assign rec_d[R_BST]                  = bst;
  assign rec_d[R_PRUN]                 = prun;
  assign rec_d[R_BF +: R_BF_W]         = bf;
  assign rec_d[R_BT +: R_BT_W]         = bt;
  assign rec_d[R_BT0 +: R_BT0_W]       = bt0;
  assign rec_d[R_BDIR]                 = bdir;
  assign rec_d[R_UHIT]                 = uhit;
  assign rec_d[R_UARM]                 = uarm;
  assign rec_d[R_UD +: R_UD_W]         = ud;

  assign rec       = rec_d & {REC_W{rd}};
  assign snap_pend = spend;

  wire unused_cfg = &{1'b0, (RANGE == 0) ? {cfg_q[C_RANGE +: C_RANGE_W], cfg_q[C_CMP_EN],
                                            cfg_q[C_MLO +: C_MLO_W]} : {(C_MLO_W + 3){1'b0}}};

endmodule

`default_nettype wire
