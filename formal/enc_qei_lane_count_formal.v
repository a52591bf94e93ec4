// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_lane's count (read by formal/enc_qei_lane_count.sby; `make
// formal`): the lane's low bits of the count, its range ends and stops, its compare, and the
// count the engine rebuilds from them, against a reference count written from the RDL
// (rtl/enc_qei.rdl: CTRL.RANGE's modes, EVENTS.OVERFLOW / UNDERFLOW / CMP, STATUS.STOPPED,
// CTRL.CMP_EN, COUNT and the index preset).
//
// The wrapper plays the engine towards one lane (RANGE 1), with the engine's widths for CHANNELS
// and COUNT_W CW (16; 8 and 9: the engine's SMALL counts, CW <= MOT_W, whose free range it pushes
// as the modulo range with CEILING all ones, as the lane also starts): it reads the lane every L
// clocks (L free in 2 .. P; the engine reads every P: formal/enc_qei_engine.sby), and pushes a
// configuration in the clock before each read with a CEILING, COMPARE, PRESET, CTRL.RANGE and
// CTRL.CMP_EN chosen freely (the other fields free
// too). A COUNT write of any value comes as the engine makes it: its value pushed in the clock
// before (push #1: the configuration as it was, with C_PLO and C_VS_LOAD the value's), then the
// push with ld, which loads it; the configuration does not change with it (a COUNT write is the
// only write of that push). Every validity set pushed is the engine's (lane_vs_of of
// rtl/enc_qei_lane.vh, with the engine's REACH): C_VS_CNT for the reference count at the last
// read, C_VS_LOAD / C_VS_ZERO / C_VS_CEIL for PRESET (a COUNT write's value), 0 and CEILING,
// C_VSO_LOAD / C_VSO_CEIL for the PRESET and CEILING it replaces, each for the pushed CEILING and
// COMPARE. Free at every clock: rst (the first clock is a reset), valid, the pins, the index, probe_in;
// PROBE_CTRL.EN and INDEX_CTRL.ARM written at any push.
//
// The reference (CW bits) steps with the lane's decode (step_up / step_dn, the per-channel
// core's own enc_qei_decode) in the configuration in force: free wraps modulo 2^CW; modulo wraps
// up from CEILING or above to 0, down from 0 to CEILING; limit drops a step at those ends;
// non_recycle stops there (and counts nothing until a COUNT write); an up step at the end raises
// OVERFLOW, a down step at 0 UNDERFLOW. A COUNT write loads its value (and releases a stop); an
// index preset (the lane's qualified index with ARM and ACTION preset) loads PRESET (not
// releasing a stop). CMP: the clock after the count changed (a step, a wrap or a load) onto
// COMPARE while CMP_EN = 1. The index latch (the lane's qualified index with ACTION latch) takes
// the count after its clock's step, the probe latch (the lane's probe hit) the count in its clock.
// Proven (k-induction), at every clock: the lane's lo is the reference's low MOT_W bits; its
// overflow and underflow (up_end, dn_end) and STATUS.STOPPED are the reference's; cmp_out is the
// reference's CMP; and the count the engine rebuilds from lo and its anchor (lane_rebuild of
// rtl/enc_qei_lane.vh, enc_qei_engine's formula, with the count at the last read, PRESET or the
// COUNT write's value, and CEILING as the engine has them stored until it reads the lane) is the
// reference count: the count the engine stores plus what the lane holds pending is the true
// count in every clock, and at each read the engine's new count is. An index or probe latch
// waiting to be read rebuilds (lane_rebuild, with PRESET and CEILING as stored) to the count at
// its edge.
// Helpers for the induction (also true): the validity set in force is the engine's set for the
// value it was made for (the count at the last read or the last anchor since), which the
// reference is within 2 P + 1 steps of; the lane's configuration fields are the pushed ones.
// Not here: whether the engine stores what it rebuilds (simulation: test_engine, test_channels),
// and when the index and probe edges are qualified (the decode's and the probe filter's timing).
`default_nettype none
`include "enc_qei_lane_w.vh"

module enc_qei_lane_count_formal #(
    parameter integer CHANNELS = 2,  // the engine's channels: P and the widths from them
    parameter integer CW       = 16  // COUNT_W (8 .. 16: 8 and 9 are the engine's SMALL counts)
) (
    input wire clk,
    input wire rst,
    input wire valid,
    input wire a_in,
    input wire b_in,
    input wire z_in,
    input wire probe_in
);

  // ---- the engine's widths (rtl/enc_qei_lane_w.vh, as enc_qei_engine sizes them) ----------
  localparam integer P      = `ENC_QEI_ENGINE_P(CHANNELS);
  localparam integer REACH  = `ENC_QEI_ENGINE_REACH(CHANNELS);
  localparam integer MOT_W  = `ENC_QEI_ENGINE_MOT_W(CHANNELS);
  localparam integer TIM_W  = `ENC_QEI_ENGINE_TIM_W(CHANNELS);
  localparam integer ERR_W  = `ENC_QEI_ENGINE_ERR_W(CHANNELS);
  `include "enc_qei_regs.vh"
  `include "enc_qei_lane.vh"

  localparam [63:0] SZ      = (64'd1 << CW) - 64'd1;
  // The engine's SMALL count (COUNT_W <= MOT_W): the free range is pushed as the modulo range
  // with CEILING all ones (enc_qei_engine's lane_ceil), so the lane takes its wraps as anchors;
  // with COUNT_W < MOT_W the lane also compares lo with CEILING as it is (its WHOLE).
  localparam integer SMALLF = (CW <= MOT_W) ? 1 : 0;
  localparam [63:0] REACH64 = REACH;
  localparam [CW-1:0] TOP   = {CW{1'b1}};

  // ---- the schedule: windows, pushes and reads -------------------------------------------------
  reg f_past = 1'b0;
  always @(posedge clk) f_past <= 1'b1;
  always @(*) if (!f_past) assume (rst);

  (* anyseq *) reg [9:0]       len_in;   // the next window's length
  (* anyseq *) reg [CFG_W-1:0] cfg_in;   // the configuration's other fields
  (* anyseq *) reg [CW-1:0]    ceil_in, cmp_in, pre_in, val_in;
  (* anyseq *) reg [1:0]       range_in;
  (* anyseq *) reg             cmpen_in, cw_in, arm_in, pen_in;
  always @(*) assume (len_in >= 10'd2 && len_in <= P);

  reg  [9:0] cd_q;   // clocks to the next read (0: read in this clock)
  reg  [9:0] el_q;   // clocks since the last read (or rst)
  reg        p1_q;   // push #1 was in the clock before: this push loads (ld)
  wire       rd    = ~rst & (cd_q == 10'd0);
  wire       push  = ~rst & (cd_q == 10'd1);
  wire       push1 = ~rst & (cd_q == 10'd2) & cw_in;  // a COUNT write's value

  always @(posedge clk) begin
    if (rst) begin
      cd_q <= len_in - 10'd1;
      el_q <= 10'd1;
      p1_q <= 1'b0;
    end else begin
      cd_q <= rd ? len_in - 10'd1 : cd_q - 10'd1;
      el_q <= rd ? 10'd1 : el_q + 10'd1;
      p1_q <= push1;
    end
  end

  wire ld = push & p1_q;

  // ---- the configuration in force (the registers' reset values until the first push) -----------
  reg [CW-1:0] f_c, f_m, f_pr;  // CEILING, COMPARE, PRESET
  reg [1:0]    f_rg;            // CTRL.RANGE
  reg          f_cen;           // CTRL.CMP_EN
  reg [CW-1:0] f_c0, f_pr0;     // CEILING and PRESET before the last push (the engine's until the read)
  reg [1:0]    f_rg0;           // ... and CTRL.RANGE
  reg [CW-1:0] f_val;           // the COUNT write's value (push #1 .. its load)

  // a push: the new configuration (unchanged with a COUNT write's load)
  wire [CW-1:0] n_c   = ld ? f_c : ceil_in;
  wire [CW-1:0] n_m   = ld ? f_m : cmp_in;
  wire [CW-1:0] n_pr  = ld ? f_pr : pre_in;
  wire [1:0]    n_rg  = ld ? f_rg : range_in;
  wire          n_cen = ld ? f_cen : cmpen_in;

  function [63:0] x64;  // a count, zero-extended
    input [CW-1:0] x;
    begin
      x64 = 64'd0;
      x64[CW-1:0] = x;
    end
  endfunction

  function [MOT_W-1:0] lowb;  // a count's low MOT_W bits (zero-extended when narrower)
    input [CW-1:0] x;
    reg   [63:0]   t;
    begin
      t    = x64(x);
      lowb = t[MOT_W-1:0];
    end
  endfunction

  function [1:0] lrg;  // the range as the lane counts it
    input [1:0] rg;
    begin
      lrg = (SMALLF != 0 && rg == ENC_QEI_RANGE_FREE) ? ENC_QEI_RANGE_MODULO : rg;
    end
  endfunction

  function [CW-1:0] lc;  // CEILING as the lane counts it, in range rg
    input [1:0]    rg;
    input [CW-1:0] c;
    begin
      lc = (SMALLF != 0 && rg == ENC_QEI_RANGE_FREE) ? TOP : c;
    end
  endfunction

  function [3:0] vs;  // the engine's validity set of x for CEILING c and COMPARE m
    input [CW-1:0] x;
    input [CW-1:0] c;
    input [CW-1:0] m;
    begin
      vs = lane_vs_of(x64(x), x64(c), x64(m), SZ, REACH64, 1'b1);
    end
  endfunction

  reg [CW-1:0] f_rread;  // the reference count at the last read (the engine's stored count)

  // the configuration pushed: push #1 the one in force with the COUNT write's value (its PRESET
  // field); the push the new one
  wire [CW-1:0] q_c   = push1 ? f_c : n_c;
  wire [CW-1:0] q_m   = push1 ? f_m : n_m;
  wire [CW-1:0] q_pr  = push1 ? val_in : n_pr;
  wire [1:0]    q_rg  = push1 ? f_rg : n_rg;
  wire          q_cen = push1 ? f_cen : n_cen;
  wire [CW-1:0] q_cl  = lc(q_rg, q_c);  // the lane's CEILING
  reg [CFG_W-1:0] cfg;
  always @(*) begin
    cfg = cfg_in;
    cfg[C_RANGE +: C_RANGE_W] = lrg(q_rg);
    cfg[C_CMP_EN]             = q_cen;
    cfg[C_PLO +: C_PLO_W]     = lowb(q_pr);
    cfg[C_CLO +: C_CLO_W]     = lowb(q_cl);
    cfg[C_MLO +: C_MLO_W]     = lowb(q_m);
    cfg[C_VS_CNT +: VS_W]     = vs(f_rread, q_cl, q_m);
    cfg[C_VS_LOAD +: VS_W]    = vs(q_pr, q_cl, q_m);
    cfg[C_VS_ZERO +: VS_W]    = vs({CW{1'b0}}, q_cl, q_m);
    cfg[C_VS_CEIL +: VS_W]    = vs(q_cl, q_cl, q_m);
    cfg[C_VSO_LOAD +: VS_W]   = vs(f_pr, q_cl, q_m);
    cfg[C_VSO_CEIL +: VS_W]   = vs(lc(f_rg, f_c), q_cl, q_m);
  end

  // ---- the lane -----------------------------------------------------------------------------------
  wire [REC_W-1:0] rec;
  wire             snap_pend, cmp_out;
  wire             step_up, step_dn, idx_hit;
  wire [1:0]       step_ab;

  enc_qei_lane #(
      .MOT_W (MOT_W),
      .TIM_W (TIM_W),
      .ERR_W (ERR_W),
      .TIMING(0),
      .RANGE (1),
      .PROBE (1),
      .PERIOD(0),
      .SMALL_W((SMALLF != 0) ? CW : 0)
  ) lane (
      .clk      (clk),
      .rst      (rst),
      .valid    (valid),
      .a_in     (a_in),
      .b_in     (b_in),
      .z_in     (z_in),
      .probe_in (probe_in),
      .snap_in  (1'b0),
      .tb_lo    ({TIM_W{1'b0}}),
      .tick     (1'b0),
      .gsnap    (1'b0),
      .snap_hold(1'b0),
      .cfg_we   (push | push1),
      .arm_we   (push & arm_in),
      .pen_we   (push & pen_in),
      .st_we    (1'b0),
      .u_we     (1'b0),
      .cfg      (cfg),
      .ld       (ld),
      .snap_cmd (1'b0),
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

  // ---- probes into the lane, connected by the .sby after flatten ---------------------------------
  (* keep *) wire             p_preset;  // lane.preset: the qualified index presets the count
  (* keep *) wire [MOT_W-1:0] p_lo;      // lane.lo_q
  (* keep *) wire [1:0]       p_anc;     // lane.anc_q: the last anchor since the read
  (* keep *) wire [1:0]       p_anc_nx;  // lane.anc_nx: ... after this clock
  (* keep *) wire             p_stop;    // lane.stop_q: STATUS.STOPPED
  (* keep *) wire             p_up_end;  // lane.up_end: an up step at the end (OVERFLOW)
  (* keep *) wire             p_dn_end;  // lane.dn_end: a down step at 0 (UNDERFLOW)
  (* keep *) wire [3:0]       p_vset;    // lane.vset: the validity set in force
  (* keep *) wire [CFG_W-1:0] p_cfg;     // lane.cfg_q
  (* keep *) wire             p_upd;     // lane.upd_q: the count changed in the clock before
  (* keep *) wire             p_latch;   // lane.latch: the qualified index latches the count
  (* keep *) wire [MOT_W-1:0] p_lcap;    // lane.lcap_q: the index latch's low bits
  (* keep *) wire [1:0]       p_lanc;    // lane.lanc_q: ... their anchor
  (* keep *) wire             p_lpend;   // lane.lpend_q: an index latch waits to be read
  (* keep *) wire             p_phit;    // lane.g_probe.phit_q: the probe latches the count
  (* keep *) wire [MOT_W-1:0] p_plo;     // lane.g_probe.plo_q: the probe latch's low bits
  (* keep *) wire [1:0]       p_panc;    // lane.g_probe.panc_q: ... their anchor
  (* keep *) wire             p_ppend;   // lane.g_probe.ppend_q: a probe latch waits to be read

  // ---- the reference count --------------------------------------------------------------------------
  reg  [CW-1:0] f_r;      // the count
  reg           f_s;      // non_recycle stopped
  reg           f_mv_q;   // the count changed in the clock before
  reg           f_cmp_q;  // CMP

  wire          r_free  = (f_rg == ENC_QEI_RANGE_FREE);
  wire          r_mod   = (f_rg == ENC_QEI_RANGE_MODULO);
  wire          r_nr    = (f_rg == ENC_QEI_RANGE_NON_RECYCLE);
  wire          u       = step_up & ~f_s;
  wire          d       = ~step_up & step_dn & ~f_s;
  wire          e_up    = u & (r_free ? (f_r == TOP) : (f_r >= f_c));  // OVERFLOW
  wire          e_dn    = d & (f_r == {CW{1'b0}});                      // UNDERFLOW
  wire          w0      = e_up & r_mod;
  wire          wc      = e_dn & r_mod;
  wire          drop    = (e_up | e_dn) & ~r_free & ~r_mod;
  wire [CW-1:0] r_st    = w0 ? {CW{1'b0}} : wc ? f_c :
                          (u & ~drop) ? f_r + 1'b1 : (d & ~drop) ? f_r - 1'b1 : f_r;
  wire          moved   = ld | p_preset | w0 | wc | ((u | d) & ~drop);
  wire [CW-1:0] r_n     = ld ? f_val : p_preset ? f_pr : r_st;
  // an anchor of the lane's: a load, or a wrap of the range the lane counts (SMALL: the free
  // range's too)
  wire          anchor  = ld | p_preset | w0 | wc | ((SMALLF != 0) & r_free & (e_up | e_dn));

  always @(posedge clk) begin
    if (rst) begin
      f_r     <= {CW{1'b0}};
      f_s     <= 1'b0;
      f_mv_q  <= 1'b0;
      f_cmp_q <= 1'b0;
    end else begin
      f_r     <= r_n;
      f_s     <= ~ld & (f_s | (r_nr & (e_up | e_dn)));
      f_mv_q  <= moved;
      f_cmp_q <= f_cen & f_mv_q & (f_r == f_m);
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      f_c    <= TOP;
      f_m    <= {CW{1'b0}};
      f_pr   <= {CW{1'b0}};
      f_rg   <= ENC_QEI_RANGE_FREE;
      f_cen  <= 1'b0;
      f_c0   <= TOP;
      f_pr0  <= {CW{1'b0}};
      f_rg0  <= ENC_QEI_RANGE_FREE;
      f_val  <= {CW{1'b0}};
      f_rread <= {CW{1'b0}};
    end else begin
      if (push1) f_val <= val_in;
      if (push) begin
        f_c   <= n_c;
        f_m   <= n_m;
        f_pr  <= n_pr;
        f_rg  <= n_rg;
        f_cen <= n_cen;
        f_c0  <= f_c;
        f_pr0 <= f_pr;
        f_rg0 <= f_rg;
      end
      if (rd) f_rread <= f_r;
    end
  end

  // the latches: the index latch takes the count after its clock's step (before a load in that
  // clock), the probe latch the count in the clock of its hit
  reg [CW-1:0] f_lat, f_plat;
  always @(posedge clk) begin
    if (p_latch) f_lat <= r_st;
    if (p_phit) f_plat <= f_r;
  end

  // ---- what the validity set in force was made for (helpers for the induction) -------------------
  // f_base: the count at the last read, or the last anchor since (the value the lane's set in
  // force describes); f_dist: a bound on the reference's distance from it; f_ld: the last anchor
  // was a COUNT write's load
  reg [CW-1:0] f_base;
  reg [9:0]    f_dist;
  reg          f_ld;

  always @(posedge clk) begin
    if (rst) begin
      f_base <= {CW{1'b0}};
      f_dist <= 10'd0;
      f_ld   <= 1'b0;
    end else if (anchor) begin
      f_base <= r_n;
      f_dist <= 10'd0;
      f_ld   <= ld;
    end else if ((push | push1) && p_anc_nx == A_NONE[1:0]) begin
      f_base <= f_rread;
      f_dist <= el_q + 10'd1;
    end else begin
      f_dist <= f_dist + 10'd1;
    end
  end

  function [CW-1:0] wdist;  // |a - b| modulo 2^CW
    input [CW-1:0] a;
    input [CW-1:0] b;
    reg   [CW-1:0] x;
    begin
      x     = a - b;
      wdist = x[CW-1] ? {CW{1'b0}} - x : x;
    end
  endfunction

  // the count the engine rebuilds now from lo and its anchor, with the values it has stored (the
  // configuration before the last push until the read: the engine applies a push's write at the
  // visit after the read)
  wire [CW-1:0] e_pre  = f_ld ? f_val : (rd ? f_pr0 : f_pr);
  wire [CW-1:0] e_ceil = rd ? f_c0 : f_c;
  wire [63:0]   e_cnt  = lane_rebuild(p_lo, p_anc, x64(e_pre), x64(e_ceil), x64(f_rread), SZ);
  // (the value of an A_CEIL anchor: the lane's CEILING)
  wire [CW-1:0] e_ceil_l = rd ? lc(f_rg0, f_c0) : lc(f_rg, f_c);

  // ... and a latch as the engine rebuilds it (its anchor is never a COUNT write's load: that
  // comes in the push's clock, after which the read starts a new window)
  wire [CW-1:0] e_lpre = rd ? f_pr0 : f_pr;
  wire [63:0]   e_lat  = lane_rebuild(p_lcap, p_lanc, x64(e_lpre), x64(e_ceil), x64(f_rread), SZ);
  wire [63:0]   e_plat = lane_rebuild(p_plo, p_panc, x64(e_lpre), x64(e_ceil), x64(f_rread), SZ);

  // ---- the properties -----------------------------------------------------------------------------
  always @(*) begin
    if (f_past && !rst) begin
      assert (el_q >= 10'd1 && el_q <= P && cd_q < P && {1'b0, cd_q} + {1'b0, el_q} <= P);
      // the count, its ends, its stop, its compare
      assert (p_lo == lowb(f_r));
      assert (p_up_end == e_up && p_dn_end == e_dn);
      assert (p_stop == f_s);
      assert (cmp_out == f_cmp_q);
      // stored + pending = the true count
      assert (e_cnt[CW-1:0] == f_r);
      // a latch waiting to be read: the count at its edge
      if (p_lpend) assert (e_lat[CW-1:0] == f_lat && p_lcap == lowb(f_lat));
      if (p_ppend) assert (e_plat[CW-1:0] == f_plat && p_plo == lowb(f_plat));
      // helpers
      assert (p_vset == vs(f_base, lc(f_rg, f_c), f_m));
      assert (f_dist <= P + el_q && wdist(f_r, f_base) <= {6'd0, f_dist});
      assert (wdist(f_r, f_rread) <= {6'd0, el_q} || p_anc != A_NONE[1:0]);
      assert (p_cfg[C_RANGE +: C_RANGE_W] == lrg(f_rg) && p_cfg[C_CMP_EN] == f_cen &&
              p_cfg[C_CLO +: C_CLO_W] == lowb(lc(f_rg, f_c)) && p_cfg[C_MLO +: C_MLO_W] == lowb(f_m) &&
              p_cfg[C_PLO +: C_PLO_W] == lowb(p1_q ? f_val : f_pr));
      assert (p_cfg[C_VS_LOAD +: VS_W] == vs(p1_q ? f_val : f_pr, lc(f_rg, f_c), f_m) &&
              p_cfg[C_VS_ZERO +: VS_W] == vs({CW{1'b0}}, lc(f_rg, f_c), f_m) &&
              p_cfg[C_VS_CEIL +: VS_W] == vs(lc(f_rg, f_c), lc(f_rg, f_c), f_m));
      if (p_anc != A_NONE[1:0]) assert (f_dist < el_q);
      if (p_anc == A_ZERO[1:0]) assert (f_base == {CW{1'b0}} && !f_ld);
      if (p_anc == A_CEIL[1:0]) assert (f_base == e_ceil_l && !f_ld);
      if (p_anc == A_LOAD[1:0]) assert (f_base == e_pre);
      if (p_anc == A_LOAD[1:0] && f_ld) assert (rd);  // a COUNT write's load: the push before the read
      assert (p_upd == f_mv_q);
    end
  end

  // ---- covers -------------------------------------------------------------------------------------
  always @(*) begin
    if (f_past && !rst) begin
      cover (w0 && f_cen);         // a modulo wrap with compare on
      cover (ld && p_preset);      // a COUNT write's load over an index preset
      cover (rd && p_lpend && p_lanc != A_NONE[1:0] && p_ppend);  // both latches read, one after an anchor
      cover (f_s && push && rd == 1'b0 && e_up == 1'b0 && f_cmp_q == 1'b0 && f_rg == ENC_QEI_RANGE_FREE);
    end
  end

endmodule

`default_nettype wire
