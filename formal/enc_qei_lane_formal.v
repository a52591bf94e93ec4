// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_lane, the shared engine's per-channel lane (read by
// formal/enc_qei_lane.sby; `make formal`): its accumulators are wide enough for the engine's
// schedule, so no step, error, rejected level or tick is lost between two reads.
//
// The wrapper plays the engine (rtl/enc_qei_engine.v) towards one lane, with the engine's widths
// for CHANNELS (P = 24 * max(CHANNELS, 2), MOT_W, TIM_W, ERR_W as enc_qei_engine sizes them): it
// reads the lane (rd) every L clocks, L free in 2 .. P for every window (the engine reads every P
// clocks exactly: formal/enc_qei_engine.sby proves that), pushes any configuration in the clock
// before each read (and may push one in the clock before that, as a COUNT write's value does),
// with ld, arm_we, pen_we, st_we, u_we and snap_cmd free at the push. Free at every clock: rst
// (the first clock is a reset), valid, the pins, snap_in, the timebase's tick, snap_hold, gsnap
// (raised only when no capture waits, or in the clock of its read: the engine's rule).
// From each record the wrapper rebuilds what the engine rebuilds, with the engine's formulas (the
// engine's own functions lane_sdiff and lane_tstamp, rtl/enc_qei_lane.vh):
// the motion M += the signed difference of mpos and its value at the read before; the error and
// glitch counts += the difference of qcnt / gcnt (mod 2^ERR_W); a timestamp = the timebase at the
// read - (its low bits at the read - the TIM_W bits kept), mod 2^16; a snapshot's motion = M at
// the read before + the signed difference of smpos and mpos then.
// Proven (k-induction) at every read, against the wrapper's wide counts of the lane's own decode
// (step_up / step_dn, qerr) and filters (glitch_q), and its own timebase: M equals the steps
// counted (each +1 / -1), the error and glitch counts equal the errors and rejected levels
// counted; a snapshot waiting at the read has the timebase and the motion of its clock, a probe
// latch the timebase of its clock; a global snapshot (gsnap) is taken in its clock; the last
// selected edge (the lane's sel_q) as the engine keeps it from the records (W_EDGE) is the last
// one, with its timebase and motion, at every read, and a waiting snapshot's edge as the engine
// makes it (te_s, me_s: its own clock's, the window's last before it, or the one kept) is the
// last selected edge at or before its clock. With three
// bits less of MOT_W or two of ERR_W (the wrapper's MOT_CUT / ERR_CUT, deliberate breaks) it
// fails; with two and one it passes (MOT_W is sized for the reach of lo, not for the motion).
// With the define EDGES (task edges): which transitions are selected edges, which index and probe
// edges qualify, and ARM / PROBE_CTRL.EN, against a reference from the pins (section at the end).
// Not here: the lane's count (lo) and its ranges, compare and latches against enc_qei_core (see
// formal/README.md: that comparison did not finish within the time a task may take).
`default_nettype none
`include "enc_qei_lane_w.vh"

module enc_qei_lane_formal #(
    parameter integer CHANNELS = 2,   // the engine's channels: P and the widths from them
    parameter integer MOT_CUT  = 0,   // bits taken off MOT_W (a deliberate break)
    parameter integer ERR_CUT  = 0,   // bits taken off ERR_W (a deliberate break)
    parameter integer PERIOD   = 0    // the lane's period capture (PERIOD_CTRL): the task edges
) (
    input wire clk,
    input wire rst,
    input wire valid,
    input wire a_in,
    input wire b_in,
    input wire z_in,
    input wire probe_in,
    input wire snap_in,
    input wire tick,
    input wire gsnap,
    input wire snap_hold
);

  // ---- the engine's widths (rtl/enc_qei_lane_w.vh, as enc_qei_engine sizes them) ----------
  localparam integer P      = `ENC_QEI_ENGINE_P(CHANNELS);
  localparam integer MOT_W  = `ENC_QEI_ENGINE_MOT_W(CHANNELS) - MOT_CUT;
  localparam integer TIM_W  = `ENC_QEI_ENGINE_TIM_W(CHANNELS);
  localparam integer ERR_W  = `ENC_QEI_ENGINE_ERR_W(CHANNELS) - ERR_CUT;
  `include "enc_qei_regs.vh"  // (REC_RST's reset values)
  `include "enc_qei_lane.vh"

  localparam integer WW = 16;  // the wrapper's wide counts

  // ---- the schedule: windows, pushes and reads -------------------------------------------------
  reg f_past = 1'b0;
  always @(posedge clk) f_past <= 1'b1;
  always @(*) if (!f_past) assume (rst);

  (* anyseq *) reg [9:0]       len_in;   // the next window's length
  (* anyseq *) reg [CFG_W-1:0] cfg_in;   // a configuration pushed
  (* anyseq *) reg             push1_in, ld_in, arm_in, pen_in, scmd_in, st_in, u_in;
  always @(*) assume (len_in >= 10'd2 && len_in <= P);

  reg  [9:0] cd_q;  // clocks to the next read (0: read in this clock)
  reg  [9:0] el_q;  // clocks since the last read (or rst)
  wire       rd    = ~rst & (cd_q == 10'd0);
  wire       push  = ~rst & (cd_q == 10'd1);
  wire       push1 = ~rst & (cd_q == 10'd2) & push1_in;

  always @(posedge clk) begin
    if (rst) begin
      cd_q <= len_in - 10'd1;
      el_q <= 10'd1;
    end else begin
      cd_q <= rd ? len_in - 10'd1 : cd_q - 10'd1;
      el_q <= rd ? 10'd1 : el_q + 10'd1;
    end
  end

  // ---- the lane -----------------------------------------------------------------------------------
  reg  [WW-1:0]    f_tb;   // the timebase (TS_W bits kept: the wrapper's)
  wire [REC_W-1:0] rec;
  wire             snap_pend, cmp_out;
  wire             step_up, step_dn, idx_hit;  // (for an edge FIFO: none here, EFIFO 0)
  wire [1:0]       step_ab;

  always @(posedge clk) begin
    if (!f_past) f_tb <= {WW{1'b0}};
    else if (tick) f_tb <= f_tb + {{(WW-1){1'b0}}, 1'b1};
  end

  enc_qei_lane #(
      .MOT_W (MOT_W),
      .TIM_W (TIM_W),
      .ERR_W (ERR_W),
      .TIMING(1),
      .RANGE (1),
      .PROBE (1),
      .PERIOD(PERIOD)
  ) lane (
      .clk      (clk),
      .rst      (rst),
      .valid    (valid),
      .a_in     (a_in),
      .b_in     (b_in),
      .z_in     (z_in),
      .probe_in (probe_in),
      .snap_in  (snap_in),
      .tb_lo    (f_tb[TIM_W-1:0]),
      .tick     (tick),
      .gsnap    (gsnap),
      .snap_hold(snap_hold),
      .cfg_we   (push | push1),
      .arm_we   (push & arm_in),
      .pen_we   (push & pen_in),
      .st_we    (push & st_in),
      .u_we     (push & u_in),
      .cfg      (cfg_in),
      .ld       (push & ld_in),
      .snap_cmd (push & scmd_in),
      .rd       (rd),
      .rec      (rec),
      .snap_pend(snap_pend),
      .cmp_out  (cmp_out),
      .step_up  (step_up),
      .step_dn  (step_dn),
      .step_ab  (step_ab),
      .idx_hit  (idx_hit),
      .ef_thresh(1'b0),
      .ef_ovf   (1'b0)
  );

  // the engine raises gsnap only when the lane has no capture waiting, or in its read's clock
  always @(*) if (gsnap) assume (!snap_pend || rd);

  // ---- probes into the lane, connected by the .sby after flatten ---------------------------------
  (* keep *) wire             p_up;      // lane.step_up: a step of the count function (EN on)
  (* keep *) wire             p_dn;      // lane.step_dn
  (* keep *) wire             p_qerr;    // lane.qerr: a quadrature error
  (* keep *) wire             p_glitch;  // lane.glitch_q: a rejected level
  (* keep *) wire             p_take;    // lane.g_snap.take: a snapshot taken in this clock
  (* keep *) wire             p_phit;    // lane.g_probe.phit_q: a probe latch in this clock
  (* keep *) wire [MOT_W-1:0] p_mpos;    // lane.mpos_q
  (* keep *) wire [ERR_W-1:0] p_qcnt;    // lane.qcnt_q
  (* keep *) wire [ERR_W-1:0] p_gcnt;    // lane.gcnt_q
  (* keep *) wire             p_spend;   // lane.g_snap.spend_q
  (* keep *) wire             p_ppend;   // lane.g_probe.ppend_q
  (* keep *) wire [MOT_W-1:0] p_smpos;   // lane.g_snap.smpos_q
  (* keep *) wire [TIM_W-1:0] p_stime;   // lane.g_snap.stime_q
  (* keep *) wire [TIM_W-1:0] p_ptime;   // lane.g_probe.ptime_q
  (* keep *) wire             p_sel;     // lane.g_snap.sel_q: a selected edge (SNAP_CTRL.EDGE),
                                         // its step in mpos from this clock
  (* keep *) wire [TIM_W-1:0] p_et;      // lane.g_snap.et_q: the last selected edge's time
  (* keep *) wire [MOT_W-1:0] p_emp;     // lane.g_snap.emp_q: ... and mpos with it
  (* keep *) wire             p_enew;    // lane.g_snap.enew_q: one in this window
  (* keep *) wire [TIM_W-1:0] p_set;     // lane.g_snap.set_q: at the snapshot, the last edge's time
  (* keep *) wire [MOT_W-1:0] p_semp;    // lane.g_snap.semp_q: ... its mpos
  (* keep *) wire             p_snew;    // lane.g_snap.snew_q: ... in the snapshot's window
  (* keep *) wire             p_sedge;   // lane.g_snap.sedge_q: an edge in the snapshot's clock

  // ---- the wrapper's wide counts (as the lane's registers take them) ------------------------------
  reg [WW-1:0] f_m, f_q, f_g;       // steps (+1 / -1), errors, rejected levels
  reg [WW-1:0] f_sm, f_st, f_pt;    // a snapshot's motion and timebase, a probe latch's timebase
  // the last selected edge: its timebase and the motion with its step (0, 0 after rst), and
  // whether one came since the last read (a selected edge in a read's clock is the next
  // window's); at a snapshot: that edge as it was before the snapshot's clock, whether it was in
  // the snapshot's window, whether the snapshot's own clock had one, and the last edge at or
  // before the snapshot's clock (what SNAP_EDGE_TIME and the motion SNAP_EDGE_DELTA counts to mean)
  reg [WW-1:0] f_et, f_em;
  reg          f_en;
  reg [WW-1:0] f_sset, f_sem, f_sxt, f_sxm;
  reg          f_snw, f_sed;

  always @(posedge clk) begin
    if (rst) begin
      f_m  <= {WW{1'b0}};
      f_q  <= {WW{1'b0}};
      f_g  <= {WW{1'b0}};
      f_et <= {WW{1'b0}};
      f_em <= {WW{1'b0}};
      f_en <= 1'b0;
    end else begin
      f_m  <= f_m + (p_dn ? {WW{1'b1}} : {{(WW-1){1'b0}}, p_up});
      f_q  <= f_q + {{(WW-1){1'b0}}, p_qerr};
      f_g  <= f_g + {{(WW-1){1'b0}}, p_glitch};
      if (p_sel) begin
        f_et <= f_tb;
        f_em <= f_m;
      end
      f_en <= p_sel | (f_en & ~rd);
    end
    if (p_take) begin
      f_sm   <= f_m;
      f_st   <= f_tb;
      f_sset <= f_et;
      f_sem  <= f_em;
      f_snw  <= f_en & ~rd;
      f_sed  <= p_sel;
      f_sxt  <= p_sel ? f_tb : f_et;
      f_sxm  <= p_sel ? f_m : f_em;
    end
    if (p_phit) f_pt <= f_tb;
  end

  // ---- the engine's view: what it rebuilds at each read -------------------------------------------
  // (with the engine's own functions, lane_sdiff and lane_tstamp of rtl/enc_qei_lane.vh, kept to
  // the wrapper's WW bits: the same values mod 2^WW)
  function [WW-1:0] sdiff;  // a - b, MOT_W bits, sign-extended
    input [MOT_W-1:0] a;
    input [MOT_W-1:0] b;
    reg   [63:0]      d;
    begin
      d     = lane_sdiff(a, b);
      sdiff = d[WW-1:0];
    end
  endfunction

  function [WW-1:0] tstamp;  // a timestamp from its low bits, at the timebase now
    input [TIM_W-1:0] t;
    input [WW-1:0]    now;
    reg   [31:0]      v;
    begin
      v      = lane_tstamp(t, {{(32 - WW){1'b0}}, now});
      tstamp = v[WW-1:0];
    end
  endfunction

  wire [MOT_W-1:0] x_mpos  = rec[R_MPOS +: R_MPOS_W];
  wire [MOT_W-1:0] x_smpos = rec[R_SMPOS +: R_SMPOS_W];
  wire [ERR_W-1:0] x_qcnt  = rec[R_QCNT +: R_QCNT_W];
  wire [ERR_W-1:0] x_gcnt  = rec[R_GCNT +: R_GCNT_W];
  wire [TIM_W-1:0] x_stime = rec[R_STIME +: R_STIME_W];
  wire [TIM_W-1:0] x_ptime = rec[R_PTIME +: R_PTIME_W];
  wire [TIM_W-1:0] x_et    = rec[R_ET +: R_ET_W];
  wire [MOT_W-1:0] x_emp   = rec[R_EMP +: R_EMP_W];
  wire [TIM_W-1:0] x_set   = rec[R_SET +: R_SET_W];
  wire [MOT_W-1:0] x_semp  = rec[R_SEMP +: R_SEMP_W];

  reg  [WW-1:0]    e_m, e_q, e_g;  // M, the error and glitch counts, as of the last read
  reg  [MOT_W-1:0] e_mb;           // mpos at the last read
  reg  [ERR_W-1:0] e_qb, e_gb;     // qcnt, gcnt at the last read
  wire [WW-1:0]    e_m_n = e_m + sdiff(x_mpos, e_mb);
  wire [WW-1:0]    e_q_n = e_q + {{(WW - ERR_W){1'b0}}, x_qcnt - e_qb};
  wire [WW-1:0]    e_g_n = e_g + {{(WW - ERR_W){1'b0}}, x_gcnt - e_gb};
  // the last selected edge as the engine keeps it (W_EDGE: TE, ME), from the records: the
  // window's when it has one (R_ENEW), else the one kept; at a snapshot the engine's SNAP_EDGE
  // time and motion: the snapshot's own when its clock had one (R_SEDGE), the window's last
  // before it (R_SNEW), else the one kept (enc_qei_engine's te_s, me_s)
  reg  [WW-1:0]    e_et, e_em;
  wire [WW-1:0]    e_et_n = rec[R_ENEW] ? tstamp(x_et, f_tb) : e_et;
  wire [WW-1:0]    e_em_n = rec[R_ENEW] ? e_m + sdiff(x_emp, e_mb) : e_em;
  wire [WW-1:0]    e_st   = tstamp(x_stime, f_tb);
  wire [WW-1:0]    e_sm   = e_m + sdiff(x_smpos, e_mb);
  wire [WW-1:0]    e_sxt  = rec[R_SEDGE] ? e_st : rec[R_SNEW] ? tstamp(x_set, f_tb) : e_et;
  wire [WW-1:0]    e_sxm  = rec[R_SEDGE] ? e_sm : rec[R_SNEW] ? e_m + sdiff(x_semp, e_mb) : e_em;

  always @(posedge clk) begin
    if (rst) begin
      e_m  <= {WW{1'b0}};
      e_q  <= {WW{1'b0}};
      e_g  <= {WW{1'b0}};
      e_mb <= {MOT_W{1'b0}};
      e_qb <= {ERR_W{1'b0}};
      e_gb <= {ERR_W{1'b0}};
      e_et <= {WW{1'b0}};
      e_em <= {WW{1'b0}};
    end else if (rd) begin
      e_et <= e_et_n;
      e_em <= e_em_n;
      e_m  <= e_m_n;
      e_q  <= e_q_n;
      e_g  <= e_g_n;
      e_mb <= x_mpos;
      e_qb <= x_qcnt;
      e_gb <= x_gcnt;
    end
  end

  // distance of two wide counts
  function [WW-1:0] wdist;
    input [WW-1:0] a;
    input [WW-1:0] b;
    reg   [WW-1:0] d;
    begin
      d     = a - b;
      wdist = d[WW-1] ? {WW{1'b0}} - d : d;
    end
  endfunction

  // ---- the properties -----------------------------------------------------------------------------
  wire [WW-1:0] el_w   = {6'd0, el_q};
  wire [WW-1:0] age_st = f_tb - f_st;  // ticks since the snapshot
  wire [WW-1:0] age_pt = f_tb - f_pt;  // ... since the probe latch
  wire [WW-1:0] age_et = f_tb - f_et;  // ... since the last selected edge
  wire [WW-1:0] age_ss = f_tb - f_sset; // ... since the last one before the snapshot

  always @(*) begin
    if (f_past && !rst) begin
      // zero skew, the lane's half: a global snapshot is taken in its clock (every lane sees
      // the one gsnap: formal/enc_qei_engine.sby), so every lane's capture is of that clock
      if (gsnap) assert (p_take);
      // the schedule: windows of 2 .. P clocks
      assert (el_q >= 10'd1 && el_q <= P && cd_q < P && {1'b0, cd_q} + {1'b0, el_q} <= P);
      // the lane's registers are the low bits of the wide counts; the engine's values are the
      // wide counts at the last read, which are at most el_q (one a clock) behind
      assert (p_mpos == f_m[MOT_W-1:0] && p_qcnt == f_q[ERR_W-1:0] && p_gcnt == f_g[ERR_W-1:0]);
      assert (e_mb == e_m[MOT_W-1:0] && e_qb == e_q[ERR_W-1:0] && e_gb == e_g[ERR_W-1:0]);
      assert (wdist(f_m, e_m) <= el_w && f_q - e_q <= el_w && f_g - e_g <= el_w);
      // a capture waiting: taken in this window (or in the clock of the last read)
      if (p_spend) assert (wdist(f_m, f_sm) <= el_w && wdist(f_sm, e_m) <= el_w && age_st <= el_w &&
                           p_smpos == f_sm[MOT_W-1:0] && p_stime == f_st[TIM_W-1:0]);
      if (p_ppend) assert (age_pt <= el_w && p_ptime == f_pt[TIM_W-1:0]);
      // the last selected edge: the lane's low bits of it; one in this window is at most el_q
      // clocks old; without one the engine's kept edge is it
      assert (p_et == f_et[TIM_W-1:0] && p_emp == f_em[MOT_W-1:0] && p_enew == f_en);
      if (f_en) assert (age_et <= el_w && wdist(f_em, e_m) <= el_w);
      else assert (e_et == f_et && e_em == f_em);
      // a capture waiting: the last edge as before its clock, in its window or kept by the
      // engine; the edge at or before its clock
      if (p_spend) begin
        assert (p_set == f_sset[TIM_W-1:0] && p_semp == f_sem[MOT_W-1:0] && p_snew == f_snw &&
                p_sedge == f_sed);
        assert (f_sxt == (f_sed ? f_st : f_sset) && f_sxm == (f_sed ? f_sm : f_sem));
        if (f_snw) assert (age_ss <= el_w && wdist(f_sem, e_m) <= el_w);
        else if (!f_sed) assert (e_et == f_sset && e_em == f_sem);
      end
      if (rd) begin
        // the motion, the error and glitch counts: not a step lost
        assert (e_m_n == f_m);
        assert (e_q_n == f_q);
        assert (e_g_n == f_g);
        // a snapshot: its timebase and its motion; a probe latch: its timebase
        if (rec[R_SPEND]) assert (tstamp(x_stime, f_tb) == f_st && e_m + sdiff(x_smpos, e_mb) == f_sm);
        if (rec[R_PPEND]) assert (tstamp(x_ptime, f_tb) == f_pt);
        // the last selected edge: its timebase and motion; a snapshot's last edge at or before
        // its clock (SNAP_EDGE_TIME, the motion SNAP_EDGE_DELTA counts to)
        assert (e_et_n == f_et && e_em_n == f_em);
        if (rec[R_SPEND]) assert (e_sxt == f_sxt && e_sxm == f_sxm);
      end
    end
  end

  // ---- covers -------------------------------------------------------------------------------------
  always @(*) begin
    if (f_past && !rst) begin
      cover (rd && e_m_n != e_m && rec[R_SPEND] && rec[R_PPEND]);  // motion, a snapshot, a probe
      cover (rd && e_q_n != e_q && e_g_n != e_g);                   // errors and glitches counted
    end
  end

  // ---- the record as rst leaves it ---------------------------------------------------------------
  (* keep *) wire [REC_W-1:0] p_rec_d;   // lane.rec_d: the record, read or not
  // the clock after a reset (the first clock is one)
  reg f_rst1 = 1'b1;
  always @(posedge clk) f_rst1 <= rst;

  always @(*) begin
    // the record as rst leaves it is REC_RST (rtl/enc_qei_lane.vh) but for the captures' data
    // (REC_CAP: no reset, read only with R_SPEND, R_PPEND, R_GRST, R_NB or R_BST, and R_UARM,
    // which REC_RST holds at 0; the task edges builds the timers and the period), whatever
    // the pins and the pushes do in that clock: the engine takes REC_RST as channel 0's first
    // record
    if (f_past && f_rst1 && !rst) assert ((p_rec_d & ~REC_CAP) == REC_RST);
  end

`ifdef EDGES
  // ---- which edges count (task edges): the decode's edges, index and probe from the pins -------
  // The per-channel core's reference (formal/enc_qei_core_formal.v: the decode's stages of
  // rtl/enc_qei_decode.v's header, which formal/enc_qei_core.sby proves for enc_qei_core), checked
  // against the RDL's CTRL, INDEX_CTRL, PROBE_CTRL, SNAP_CTRL.EDGE, PERIOD_CTRL.EDGE and
  // edge_type_e, fed from the conditioned levels the lane's filters give (their own proof:
  // formal/enc_conditioner_rt.sby) and the configuration in force (the lane's cfg_q; its fields
  // used here equal in every clock the registers' reset values until the first push, then the
  // last push's):
  //   sample s (clock t)  A, B after SWAP_AB / INV_A / INV_B, Z after INV_Z; the decoders held in
  //                       reset while rst, !valid, or {FUNC, SWAP_AB, INV_A, INV_B} differs from
  //                       the clock before (cleared by rst); the first sample after it is the
  //                       reference. A valid transition: exactly one of A, B changed.
  //   clock t + 2         the count takes it (edge_any, edge_a_rise) and the qualified index's
  //                       edge: Z AND, with GATE_EN, (A, B) = (GATE_A, GATE_B); its EDGE; held in
  //                       reset by rst | !valid; none in a clock whose {SWAP_AB, INV_A, INV_B,
  //                       INV_Z} differs from the clock before (re-referenced, not an edge); a
  //                       gate change is an edge like any other
  //   clock t + 3         a selected edge (sel_q): every valid transition (any) or only those
  //                       where A rose (a_rising), by SNAP_CTRL.EDGE in force at t + 2
  // The same for PERIOD_CTRL.EDGE's edges (psel_q: the task builds the period capture).
  // An armed index (ARM, ACTION not none) presets or latches at its hit; ONESHOT clears ARM
  // after acting; a push with arm_we sets ARM as written (after what the clock did). The probe:
  // PROBE_CTRL.EDGE of the conditioned probe_in, a hit one clock after the sample while EN (held
  // in reset by rst | !valid); ONCE clears EN after it; a push with pen_we sets EN as written.
  (* keep *) wire             p_ac, p_bc, p_zc, p_prc;  // lane.a_c, b_c, z_c, g_probe.probe_c
  (* keep *) wire [CFG_W-1:0] p_cfg;                    // lane.cfg_q: the configuration in force
  (* keep *) wire             p_arm;                    // lane.arm_q: INDEX_CTRL.ARM
  (* keep *) wire             p_pen;                    // lane.g_probe.pen_q: PROBE_CTRL.EN
  (* keep *) wire             p_preset, p_latch;        // lane.preset, lane.latch
  (* keep *) wire             p_psel;                   // lane.g_period.psel_q (PERIOD 1)

  localparam ARM_RST = ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ARM];
  localparam PEN_RST = ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_EN];

  wire       g_a  = (p_cfg[C_SWAP] ? p_bc : p_ac) ^ p_cfg[C_INV_A];
  wire       g_b  = (p_cfg[C_SWAP] ? p_ac : p_bc) ^ p_cfg[C_INV_B];
  wire       g_z  = p_zc ^ p_cfg[C_INV_Z];
  wire [7:0] g_c  = {p_cfg[C_FUNC +: C_FUNC_W], p_cfg[C_SWAP], p_cfg[C_INV_A], p_cfg[C_INV_B],
                     p_cfg[C_INV_Z]};
  reg  [7:0] g_cq = 8'd0;                                 // g_c the clock before (rst: 0)
  wire       g_drst = rst | ~valid | (g_c[7:1] != g_cq[7:1]);
  wire       g_zref = (g_c[3:0] != g_cq[3:0]);
  reg        g_ref = 1'b0;                                // the previous sample is a reference
  reg  [1:0] g_prev = 2'b00;                              // ... its {A, B}
  wire       g_tr = ~g_drst & g_ref & ((g_a ^ g_prev[1]) ^ (g_b ^ g_prev[0]));
  wire       g_ar = g_tr & g_a & ~g_prev[1];              // ... with A rising
  wire       g_iq = g_z & (~p_cfg[C_GATE_EN] | ((g_a == p_cfg[C_GATE_A]) &
                                                 (g_b == p_cfg[C_GATE_B])));
  reg  [1:0] g_e1 = 2'b00, g_e2 = 2'b00;                 // {g_tr, g_ar} one and two clocks on
  reg        g_sel = 1'b0, g_psel = 1'b0;
  reg        g_iprev = 1'b0, g_iok = 1'b0, g_ih1 = 1'b0, g_ih = 1'b0;
  reg        g_pprev = 1'b0, g_pok = 1'b0, g_ph = 1'b0;
  reg        g_arm = 1'b0, g_pen = 1'b0;
  wire       g_armed = g_arm & (p_cfg[C_ACT +: C_ACT_W] != ENC_QEI_INDEX_ACTION_NONE);

  always @(posedge clk) begin
    g_cq   <= rst ? 8'd0 : g_c;
    g_ref  <= ~g_drst;
    g_prev <= {g_a, g_b};
    g_e1   <= {g_tr, g_ar};
    if (rst) begin
      g_e2  <= 2'b00;
      g_sel <= 1'b0;
      g_psel <= 1'b0;
      g_arm <= ARM_RST;
      g_pen <= PEN_RST;
    end else begin
      g_e2  <= g_e1;
      g_sel <= p_cfg[C_SEDGE] ? g_e2[0] : g_e2[1];
      g_psel <= p_cfg[C_PER_EDGE] ? g_e2[0] : g_e2[1];
      if (push & arm_in) g_arm <= cfg_in[C_ARM];
      else if (g_ih & g_armed & p_cfg[C_ONESHOT]) g_arm <= 1'b0;
      if (push & pen_in) g_pen <= cfg_in[C_PEN];
      else if (g_ph & p_cfg[C_PONCE]) g_pen <= 1'b0;
    end
    if (rst | ~valid) begin
      g_iprev <= 1'b0;
      g_iok   <= 1'b0;
      g_ih1   <= 1'b0;
      g_ih    <= 1'b0;
      g_pprev <= 1'b0;
      g_pok   <= 1'b0;
      g_ph    <= 1'b0;
    end else begin
      g_iprev <= g_iq;
      g_iok   <= 1'b1;
      g_ih1   <= g_iok & ~g_zref & (p_cfg[C_IEDGE] ? (g_iprev & ~g_iq) : (~g_iprev & g_iq));
      g_ih    <= g_ih1;
      g_pprev <= p_prc;
      g_pok   <= 1'b1;
      g_ph    <= g_pok & g_pen & (p_cfg[C_PEDGE] ? (g_pprev & ~p_prc) : (~g_pprev & p_prc));
    end
  end

  // the configuration's fields used here: the registers' reset values (rtl/enc_qei_regs.vh, from
  // the RDL) after rst, a push's from the clock after it
  function [18:0] efields;
    input [CFG_W-1:0] c;
    efields = {c[C_SWAP], c[C_INV_A], c[C_INV_B], c[C_INV_Z], c[C_FUNC +: C_FUNC_W],
               c[C_ACT +: C_ACT_W], c[C_ONESHOT], c[C_IEDGE], c[C_GATE_EN], c[C_GATE_A],
               c[C_GATE_B], c[C_SEDGE], c[C_PEDGE], c[C_PONCE], c[C_PER_EDGE]};
  endfunction
  localparam [18:0] E_RST = {ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_SWAP_AB],
                             ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_A],
                             ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_B],
                             ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_INV_Z],
                             ENC_QEI_CTRL_RESET[ENC_QEI_CTRL_FUNC +: 4],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ACTION +: 2],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ONESHOT],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_EDGE],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_EN],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_A],
                             ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_GATE_B],
                             ENC_QEI_SNAP_CTRL_RESET[ENC_QEI_SNAP_CTRL_EDGE],
                             ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_EDGE],
                             ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_ONCE],
                             ENC_QEI_PERIOD_CTRL_RESET[ENC_QEI_PERIOD_CTRL_EDGE]};
  reg [18:0] g_ef = 19'd0;
  always @(posedge clk) begin
    if (rst) g_ef <= E_RST;
    else if (push | push1) g_ef <= efields(cfg_in);
  end

  always @(*) begin
    if (f_past && !rst) begin
      assert (efields(p_cfg) == g_ef);         // the configuration in force
      assert (p_sel == g_sel);                 // the selected edges (SNAP_CTRL.EDGE)
      assert (idx_hit == g_ih);                // the qualified index edges (INDEX event)
      assert (p_arm == g_arm && p_pen == g_pen);
      assert (p_preset == (g_ih & g_armed &
                           (p_cfg[C_ACT +: C_ACT_W] == ENC_QEI_INDEX_ACTION_PRESET)));
      assert (p_latch == (g_ih & g_armed &
                          (p_cfg[C_ACT +: C_ACT_W] == ENC_QEI_INDEX_ACTION_LATCH)));
      assert (p_phit == g_ph);                 // the probe's latches
      assert (p_psel == g_psel);               // the period's edges (PERIOD_CTRL.EDGE)
    end
  end

  always @(*) begin
    if (f_past && !rst) begin
      cover (p_sel && p_cfg[C_SEDGE]);                          // an A-rising edge selected
      cover (p_latch && p_cfg[C_GATE_EN] && p_cfg[C_IEDGE]);   // a gated falling index latches
      cover (p_phit && p_cfg[C_PEDGE] && p_cfg[C_PONCE]);      // a falling probe, once
      cover (p_psel && p_cfg[C_PER_EDGE]);                      // an A-rising period edge
    end
  end
`endif

endmodule

`default_nettype wire
