// SPDX-License-Identifier: Apache-2.0
// enc_qei_core -- the counting core of enc_qei: decode, count function, range, index, probe,
// compare and the events they raise.
//
// Inputs are the conditioned channels (enc_conditioner_rt outputs). enc_qei_decode turns them
// into the count function's steps (through SWAP_AB / INV_*, the library's decoders and the
// Linux count functions), the edges and the qualified index edge; this module counts them.
// Count priority in one clock: COUNT write > index preset > count step. Range modes: free,
// modulo (0 .. CEILING), limit (stops at 0 / CEILING), non_recycle (stops until COUNT is
// written). Every decoder output has latency 1 from its sample and the count step one more
// register; the index edge is delayed the same, so an index acts in the clock of the transition
// it sees.
// For Fmax, the range's decisions (wrap, stop, hold at CEILING or 0), the zero test and the
// loads are flag registers, set a clock ahead from the next count's candidates: CEILING acts two
// clocks after it changes, RANGE and INDEX_CTRL one clock after, a load (a COUNT write) loads the
// count two clocks after its strobe (its value as of the strobe), and an index preset loads
// PRESET as it was one clock earlier. A bus access takes longer than these delays: software
// cannot tell. CTRL.EN gates count steps only: loads and index presets act whatever EN is.
// RANGE = 0 (the lean channel) leaves the ranges out: the count is free (range, ceiling unused),
// with no range flags, comparators or compare (cmp never fires, stopped stays 0); PROBE = 0
// leaves the probe latch out (probe inputs unused, its outputs 0).
`default_nettype none

module enc_qei_core #(
    parameter integer COUNT_W = 32,  // counter width (checked by enc_qei)
    parameter integer TS_W    = 32,  // timebase width (checked by enc_qei)
    parameter integer RANGE   = 1,   // 1: ranges (CEILING) and compare; 0: free count, no compare
    parameter integer PROBE   = 1    // 1: the probe latch; 0: without it
) (
    input  wire               clk,
    input  wire               rst,            // synchronous, active high
    // conditioned inputs
    input  wire               a_c,            // channel A from the conditioner
    input  wire               b_c,            // channel B
    input  wire               z_c,            // index channel Z
    input  wire               probe_c,        // probe input
    input  wire               valid,          // conditioner outputs show the inputs
    // configuration (CTRL, PRESET, CEILING, COMPARE, INDEX_CTRL, PROBE_CTRL)
    input  wire               en,
    input  wire               swap_ab,
    input  wire               inv_a,
    input  wire               inv_b,
    input  wire               inv_z,
    input  wire [3:0]         func,
    input  wire [1:0]         range,
    input  wire [COUNT_W-1:0] preset,
    input  wire [COUNT_W-1:0] ceiling,
    input  wire [COUNT_W-1:0] compare,
    input  wire               cmp_en,         // CTRL.CMP_EN: compare on
    input  wire [1:0]         idx_action,
    input  wire               idx_oneshot,
    input  wire               idx_edge,       // 0 rising, 1 falling
    input  wire               idx_gate_en,
    input  wire               idx_gate_a,
    input  wire               idx_gate_b,
    input  wire               idx_arm,
    input  wire               probe_en,
    input  wire               probe_edge,     // 0 rising, 1 falling
    input  wire               probe_once,
    input  wire [TS_W-1:0]    timebase,
    // a COUNT write (the register block assembles the value from its 32-bit words)
    input  wire               load,           // load the count, two clocks later
    input  wire [COUNT_W-1:0] load_value,     // ... with this value (taken with the strobe)
    // state
    output wire [COUNT_W-1:0] count,
    output wire [COUNT_W-1:0] idx_latch,
    output wire [COUNT_W-1:0] probe_latch,
    output wire [TS_W-1:0]    probe_time,
    output wire               a_eff,          // A, B, Z as the decoders see them
    output wire               b_eff,
    output wire               z_eff,
    output wire               dir,            // direction of the last count step, 1 = up
    output wire               idx_armed,
    output wire               stopped,        // non_recycle stopped
    output wire               idx_disarm,     // one-shot index acted: clear INDEX_CTRL.ARM
    output wire               probe_disarm,   // once-probe latched: clear PROBE_CTRL.EN
    // for the timing unit
    output wire               step_up,        // count function step (enabled, before the range)
    output wire               step_dn,
    output wire               applied_up,     // a step the count took
    output wire               applied_dn,
    output wire               edge_any,       // valid quadrature transition (latency as cnt)
    output wire               edge_a_rise,    // rising edge of A
    output wire [1:0]         step_ab,        // {A, B} after the transition of this clock's step
    // events (one clock each)
    output wire               ev_overflow,
    output wire               ev_underflow,
    output wire               ev_index,
    output wire               ev_probe,
    output wire               ev_cmp,
    output wire               ev_qerr,
    output wire               ev_dir_change,
    output wire               cmp_out
);

  `include "enc_qei_regs.vh"  // the codes of CTRL.FUNC, CTRL.RANGE and INDEX_CTRL.ACTION

  function [63:0] zext64;
    input [COUNT_W-1:0] v;
    begin
      zext64 = 64'd0;
      zext64[COUNT_W-1:0] = v;
    end
  endfunction

  // ---- decode: the pins' transitions, the count function's steps and the index edge -------------
  wire fdn, idx_hit1, idx_hit;  // (idx_hit1: the index edge one clock before idx_hit)

  enc_qei_decode u_dec (
      .clk        (clk),
      .rst        (rst),
      .a_c        (a_c),
      .b_c        (b_c),
      .z_c        (z_c),
      .valid      (valid),
      .en         (en),
      .swap_ab    (swap_ab),
      .inv_a      (inv_a),
      .inv_b      (inv_b),
      .inv_z      (inv_z),
      .func       (func),
      .idx_edge   (idx_edge),
      .idx_gate_en(idx_gate_en),
      .idx_gate_a (idx_gate_a),
      .idx_gate_b (idx_gate_b),
      .a_eff      (a_eff),
      .b_eff      (b_eff),
      .z_eff      (z_eff),
      .fdn        (fdn),
      .step_up    (step_up),
      .step_dn    (step_dn),
      .edge_any   (edge_any),
      .edge_a_rise(edge_a_rise),
      .step_ab    (step_ab),
      .qerr       (ev_qerr),
      .idx_hit1   (idx_hit1),
      .idx_hit    (idx_hit)
  );

  // a copy of step_dn for the count's adder alone ((* keep *): Yosys would merge it back; Fmax:
  // one register driving the adder's carry chains and the range logic is a long net)
  reg step_dn_add_q;

  (* keep *) always @(posedge clk) begin
    step_dn_add_q <= ~rst & en & fdn;
  end


  // ---- configuration, one clock late (Fmax) ---------------------------------------------------------
  // RANGE and INDEX_CTRL act one clock after they change, so that the decisions of the range
  // (wrap, stop, hold) and of the index preset can be flag registers below. Not reset: a pure
  // delay of the registers (which rst clears).
  reg [1:0] range_q;
  reg       idx_arm_q;
  reg [1:0] idx_action_q;
  reg       idx_oneshot_q;

  always @(posedge clk) begin
    range_q       <= (RANGE != 0) ? range : ENC_QEI_RANGE_FREE;
    idx_arm_q     <= idx_arm;
    idx_action_q  <= idx_action;
    idx_oneshot_q <= idx_oneshot;
  end

  wire r_free   = (range_q == ENC_QEI_RANGE_FREE);
  wire r_nr     = (range_q == ENC_QEI_RANGE_NON_RECYCLE);

  // ---- range ---------------------------------------------------------------------------------------
  reg  [COUNT_W-1:0] count_q;
  reg  [COUNT_W-1:0] count_d;
  reg                stopped_q;

  reg  zero_q;  // count_q == 0: a flag register, set from the next count's candidates (Fmax)
  wire at_zero = zero_q;
  wire at_max  = (count_q == {COUNT_W{1'b1}});

  // a >= b for COUNT_W-bit values, from 16-bit slices compared side by side (short carry chains;
  // the slices' > and >= are carry chains too, no equality trees)
  localparam integer NSL = (COUNT_W + 15) / 16;

  function ge_w;
    input [COUNT_W-1:0] a;
    input [COUNT_W-1:0] b;
    reg   [63:0] a64, b64;
    integer      k;
    begin
      a64  = zext64(a);
      b64  = zext64(b);
      ge_w = (a64[15:0] >= b64[15:0]);
      for (k = 1; k < NSL; k = k + 1) begin  // (slice equal: both >= and not >)
        ge_w = (a64[16*k +: 16] > b64[16*k +: 16]) | ((a64[16*k +: 16] >= b64[16*k +: 16]) & ge_w);
      end
    end
  endfunction

  // a > K for COUNT_W-bit values, given kn = ~K (a register: no inverters in front of the carry
  // chains): the carry out of a + ~K. 16-bit slices side by side (short chains), each upper slice
  // as > (carry in 0) and >= (carry in 1: the {x, 1} + {y, 1} form), chosen by the slice below.
  function gt_n;
    input [COUNT_W-1:0] a;
    input [COUNT_W-1:0] kn;
    reg   [63:0] a64, k64;
    // verilator lint_off UNUSEDSIGNAL
    reg   [16:0] gt_s;  // (only the carry out, bit 16 / 17, is used)
    reg   [17:0] ge_s;
    // verilator lint_on UNUSEDSIGNAL
    integer      k;
    begin
      a64              = zext64(a);
      k64              = {64{1'b1}};  // ~K: ones above COUNT_W
      k64[COUNT_W-1:0] = kn;
      gt_s = {1'b0, a64[15:0]} + {1'b0, k64[15:0]};
      gt_n = gt_s[16];
      for (k = 1; k < NSL; k = k + 1) begin
        gt_s = {1'b0, a64[16*k +: 16]} + {1'b0, k64[16*k +: 16]};
        ge_s = {1'b0, a64[16*k +: 16], 1'b1} + {1'b0, k64[16*k +: 16], 1'b1};
        gt_n = gt_s[16] | (ge_s[17] & gt_n);
      end
    end
  endfunction

  // ---- index ---------------------------------------------------------------------------------------
  // The qualified index edge comes from the decode (idx_hit, aligned with the steps; idx_hit1 one
  // clock earlier); here it acts on the count.
  wire armed = idx_arm_q & (idx_action_q != 2'd0);
  // a latch hit, registered with the hit (from INDEX_CTRL as the next clock's idx_*_q show it)
  reg  lat_hit_q;  // idx_hit & armed & ACTION = latch

  always @(posedge clk) begin
    if (rst | ~valid) begin
      lat_hit_q <= 1'b0;
    end else begin
      lat_hit_q <= idx_hit1 & idx_arm & (idx_action == ENC_QEI_INDEX_ACTION_LATCH);
    end
  end

  wire idx_act = idx_hit & armed;

  // ---- loads -----------------------------------------------------------------------------------------
  // COUNT writes and index presets, registered (Fmax): a COUNT write loads the count two clocks
  // after its strobe (its value taken at the strobe), and an index preset loads PRESET as it was
  // one clock earlier; the value to load, its comparison with the ceiling and its zero test are
  // registers.
  reg               wr_pend_q;    // a COUNT write strobe one clock ago
  reg [COUNT_W-1:0] wr_val_q;     // ... its value
  reg               wr_q;         // a COUNT write to apply this clock
  reg               load_q;       // a load this clock: a COUNT write or an index preset
  reg [COUNT_W-1:0] load_val_q;   // ... its value (the write first)
  reg               load_ge_q;    // ... >= the next clock's ceiling
  reg               load_zero_q;  // ... == 0

  always @(posedge clk) begin
    if (rst) begin
      wr_pend_q <= 1'b0;
      wr_q      <= 1'b0;
      load_q    <= 1'b0;
    end else begin
      wr_pend_q <= load;
      wr_q      <= wr_pend_q;
      load_q    <= wr_pend_q | (valid & idx_hit1 & idx_arm & (idx_action == ENC_QEI_INDEX_ACTION_PRESET));
    end
  end

  always @(posedge clk) begin
    wr_val_q    <= load_value;
    load_val_q  <= wr_pend_q ? wr_val_q : preset;
    load_ge_q   <= (RANGE != 0) & (wr_pend_q ? ge_w(wr_val_q, ceiling) : ge_w(preset, ceiling));
    load_zero_q <= wr_pend_q ? (wr_val_q == {COUNT_W{1'b0}}) : (preset == {COUNT_W{1'b0}});
  end

  // the ceiling as the count uses it now (RANGE; see the CEILING pipeline below)
  wire [COUNT_W-1:0] ceil_now;
  wire               ceil_now_zero;

  // ---- range decisions: flag registers (Fmax) ------------------------------------------------------
  // What an up / down step does this clock, decided from the flags of the clock before (each set
  // from the next range, STOPPED, at-ceiling and zero values):
  //   up:   up_wrap    modulo at CEILING -> 0           down: dn_wrap_q  modulo at 0 -> CEILING
  //         up_lim     limit / non_recycle at CEILING         dn_lim_q   limit / non_recycle at 0
  //         stop_q     non_recycle stopped: no step, no wrap, in any range until a COUNT write
  //                    (the same stop_q)
  //         up_blk     = up_wrap | up_lim | stop_q            dn_blk_q = dn_wrap_q | dn_lim_q | stop_q
  // A free range blocks nothing (the count wraps by itself; overflow / underflow at the ends).
  wire [1:0] up_wrap_q, up_lim_q, up_blk_q;  // (each: partial flags, see parts() below)
  wire       dn_wrap_q, dn_lim_q, dn_blk_q, stop_q;
  wire       up_wrap = |up_wrap_q;
  wire       up_lim  = |up_lim_q;
  wire       up_blk  = stop_q | (|up_blk_q);

  // The cases of this clock (step_up and step_dn never come together: every count function gives
  // one or the other, formal/enc_qei_core.sby asserts it):
  wire u_step  = step_up & ~stop_q;
  wire d_step  = ~step_up & step_dn & ~stop_q;
  wire k_inc   = step_up & ~up_blk;                   // count_q + 1
  wire k_zero  = step_up & up_wrap;                   // 0
  wire k_dec   = step_dn & ~dn_blk_q;                 // count_q - 1
  wire k_ceil  = step_dn & dn_wrap_q;                 // the ceiling
  (* keep *) wire k_move;  // (keep: the adder's select, one LUT before the count / latch)
  assign k_move = k_inc | k_dec;
  wire k_hold  = ~k_move & ~k_zero & ~k_ceil;         // count_q
  // ... and with the loads (a load wins over the step): one-hot selects. (keep: Yosys leaves
  // s_move as a net, so that the late adder output is not folded into its logic.)
  (* keep *) wire s_move;
  assign s_move = ~load_q & k_move;
  wire s_inc  = ~load_q & k_inc;
  wire s_dec  = ~load_q & k_dec;
  wire s_zero = ~load_q & k_zero;
  wire s_ceil = ~load_q & k_ceil;
  wire s_hold = ~load_q & k_hold;

  // events and STOPPED (a load does not hide the step's event)
  wire ovf       = u_step & (r_free ? at_max : (up_wrap | up_lim));
  wire unf       = d_step & (r_free ? at_zero : (dn_wrap_q | dn_lim_q));
  wire stopped_d = ~wr_q & (stopped_q | (r_nr & ((u_step & up_lim) | (d_step & dn_lim_q))));

  // Every value is an AND-OR of (select & candidate): the selects are early signals, the adder,
  // comparators and zero tests of count_q the late ones, which enter the last logic levels only
  // (Fmax). The step: one adder, count_q + 1 or count_q - 1 by step_dn (its copy step_dn_add_q).
  wire [COUNT_W-1:0] count_step;

  generate
    if (COUNT_W > 16) begin : g_step_split
      // carry select: the low 16 bits' carry out picks the high part with carry in 0 or 1
      // (two short chains side by side instead of one long one; Fmax)
      localparam integer HI_W = COUNT_W - 16;
      wire [16:0]     lo_sum = {1'b0, count_q[15:0]} + {1'b0, {15{step_dn_add_q}}, 1'b1};
      wire [HI_W-1:0] hi     = count_q[COUNT_W-1:16];
      wire [HI_W-1:0] hi_c0  = hi + {HI_W{step_dn_add_q}};
      // verilator lint_off UNUSEDSIGNAL
      wire [HI_W:0]   hi_c1x = {hi, 1'b1} + {{HI_W{step_dn_add_q}}, 1'b1};  // (hi + ... + 1) << 1 | 1
      // verilator lint_on UNUSEDSIGNAL
      assign count_step = {lo_sum[16] ? hi_c1x[HI_W:1] : hi_c0, lo_sum[15:0]};
    end else begin : g_step
      assign count_step = count_q + {{(COUNT_W-1){step_dn_add_q}}, 1'b1};
    end
  endgenerate

  // the count after this clock's step, before the loads: the adder's, or else (early signals)
  // the ceiling, 0 or the count itself
  (* keep *) wire [COUNT_W-1:0] stepped_other;
  assign stepped_other = ({COUNT_W{k_ceil}} & ceil_now) | ({COUNT_W{~k_ceil & ~k_zero}} & count_q);
  wire [COUNT_W-1:0] stepped = k_move ? count_step : stepped_other;

  // The next count: the adder's, or else a load or stepped_other (early signals; keep: the late
  // adder output enters the last LUT level only, Fmax)
  (* keep *) wire [COUNT_W-1:0] count_other;
  assign count_other = load_q ? load_val_q : stepped_other;

  always @(*) begin
    count_d = s_move ? count_step : count_other;
  end

  // The next clock's flags, each an AND-OR over the cases of this clock (the select, early; the
  // case's candidate value of the flag, late), with rst as one more case (count 0, STOPPED 0).
  // +1 wraps to 0 at the maximum (in the free range only: a bounded range stops or wraps there
  // first, the maximum being >= every ceiling); whether it does is in +1's candidates (at_max,
  // late), not in the selects (Fmax: the 32-bit comparison stays off the select paths).
  // Cases:         6 rst   5 load   4 hold   3 +1   2 -1   1 ->0   0 ->CEILING
  wire [6:0] sel = rst ? 7'b100_0000 : {1'b0, load_q, s_hold, s_inc, s_dec, s_zero, s_ceil};
  // zero: count_d == 0
  wire is_one = (count_q == {{(COUNT_W-1){1'b0}}, 1'b1});
  wire [6:0] z_cand = {1'b1, load_zero_q, zero_q, at_max, is_one, 1'b1, ceil_now_zero};
  // zero: the next count is 0 (every range)
  always @(posedge clk) begin
    zero_q <= |(sel & z_cand);
  end

  generate
    if (RANGE != 0) begin : g_range
      // ---- CEILING pipeline (Fmax) ----------------------------------------------------------------------
      // The count uses CEILING as it was two clocks earlier (ceil_q), so that (count >= CEILING) can
      // be flag registers (up_wrap_q, up_lim_q, up_blk_q below), set like zero_q from the next count's
      // candidates, each compared with the next clock's ceiling N (kept inverted, as N - 1 and N - 2
      // as well, for gt_n) by a comparator between registers.
      // Not reset: a pure delay of the CEILING register.
      reg [COUNT_W-1:0] ceil_nx_n_q;     // ~N, N = CEILING one clock ago: the ceiling of the next clock
      reg [COUNT_W-1:0] ceil_nx_m1n_q;   // ~(N - 1)
      reg [COUNT_W-1:0] ceil_nx_m2n_q;   // ~(N - 2)
      reg               ceil_nx_zero_q;  // N == 0
      reg               ceil_nx_le1_q;   // N <= 1
      reg [COUNT_W-1:0] ceil_q;          // CEILING two clocks ago: the ceiling the count uses now
      reg               ceil_zero_q;     // ... is 0
      reg               ceil_wrap_ge_q;  // ceil_q >= N (a modulo wrap down to ceil_q)
      wire [COUNT_W-1:0] ceil_nx = ~ceil_nx_n_q;

      always @(posedge clk) begin
        ceil_nx_n_q    <= ~ceiling;
        ceil_nx_m1n_q  <= ~(ceiling - {{(COUNT_W-1){1'b0}}, 1'b1});
        ceil_nx_m2n_q  <= ~(ceiling - {{(COUNT_W-2){1'b0}}, 2'd2});
        ceil_nx_zero_q <= (ceiling == {COUNT_W{1'b0}});
        ceil_nx_le1_q  <= (ceiling[COUNT_W-1:1] == {(COUNT_W-1){1'b0}});
        ceil_q         <= ceil_nx;
        ceil_zero_q    <= ceil_nx_zero_q;
        ceil_wrap_ge_q <= ge_w(ceil_nx, ceiling);
      end

      assign ceil_now      = ceil_q;
      assign ceil_now_zero = ceil_zero_q;

      // at CEILING: count_d >= N, N the next clock's ceiling (ceil_nx); N = 0: every count is >= N.
      // count_q - 1 from 0 is the maximum, >= every N. (keep: each comparator's candidate is one LUT
      // after its carry chains, and its flag one LUT later)
      (* keep *) wire cand_hold;  // count_q >= N
      assign cand_hold = ceil_nx_zero_q | gt_n(count_q, ceil_nx_m1n_q);
      (* keep *) wire cand_inc;   // count_q + 1 >= N; at the maximum it wraps to 0, >= N only for N = 0
      assign cand_inc = (ceil_nx_le1_q | gt_n(count_q, ceil_nx_m2n_q)) & (~at_max | ceil_nx_zero_q);
      (* keep *) wire cand_dec;   // count_q - 1 >= N (count_q > 0), or the maximum (count_q = 0)
      assign cand_dec = at_zero | gt_n(count_q, ceil_nx_n_q);
      wire [6:0] c_cand = {ceil_nx_zero_q, load_ge_q, cand_hold, cand_inc, cand_dec, ceil_nx_zero_q,
                           ceil_wrap_ge_q};
      // The range gates the selects (early), not the flags (late). The at-CEILING flags are each
      // kept as two partial registers (their OR is the flag), so that a comparator's carry chains
      // feed two LUT levels only, the candidate and its flag: (Fmax)
      //   [0] hold | +1 (the late ones)   [1] -1 (late) | the rest (early)
      function [1:0] parts;
        input [2:0] late;   // the gated selects of hold, +1 and -1
        input       early;  // the OR of the early cases' terms
        begin
          parts[0] = (late[2] & cand_hold) | (late[1] & cand_inc);
          parts[1] = (late[0] & cand_dec) | early;
        end
      endfunction

      wire       stop_n  = ~rst & stopped_d;
      // (a stop holds in any RANGE until COUNT is written, and a stopped count does not wrap: the
      // modulo selects are gated by it, early, so that the wrap flags' late candidates meet no
      // gate after them; Fmax)
      wire [6:0] sel_mod = sel & {7{(range == ENC_QEI_RANGE_MODULO) & ~stop_n}};                // next: modulo, not stopped
      wire [6:0] sel_lim = sel & {7{(range == ENC_QEI_RANGE_LIMIT) | (range == ENC_QEI_RANGE_NON_RECYCLE)}}; // limit, n_r
      wire [6:0] sel_bnd = sel & {7{range != ENC_QEI_RANGE_FREE}};                              // bounded
      // (keep: the late candidates' selects are nets, so that each partial flag is one LUT)
      (* keep *) wire [2:0] late_mod;
      assign late_mod = {sel_mod[4], sel_mod[3], sel_mod[2]};
      (* keep *) wire [2:0] late_lim;
      assign late_lim = {sel_lim[4], sel_lim[3], sel_lim[2]};
      (* keep *) wire [2:0] late_bnd;
      assign late_bnd = {sel_bnd[4], sel_bnd[3], sel_bnd[2]};
      // (keep: the early cases' terms are ORed apart from the late ones, for the same reason)
      localparam [6:0] EARLY = 7'b110_0011;   // rst, load, ->0, ->CEILING
      (* keep *) wire [2:0] early_g;           // {modulo, limit, bounded}
      assign early_g = {|(sel_mod & c_cand & EARLY), |(sel_lim & c_cand & EARLY),
                        |(sel_bnd & c_cand & EARLY)};

      reg [1:0] up_wrap_r, up_lim_r, up_blk_r;
      reg       dn_wrap_r, dn_lim_r, dn_blk_r, stop_r;

      always @(posedge clk) begin
        up_wrap_r <= parts(late_mod, early_g[2]);
        up_lim_r  <= parts(late_lim, early_g[1]);
        up_blk_r  <= parts(late_bnd, early_g[0]);
        dn_wrap_r <= |(sel_mod & z_cand);
        dn_lim_r  <= |(sel_lim & z_cand);
        dn_blk_r  <= stop_n | (|(sel_bnd & z_cand));
        stop_r    <= stop_n;
      end

      assign up_wrap_q = up_wrap_r;
      assign up_lim_q  = up_lim_r;
      assign up_blk_q  = up_blk_r;
      assign dn_wrap_q = dn_wrap_r;
      assign dn_lim_q  = dn_lim_r;
      assign dn_blk_q  = dn_blk_r;
      assign stop_q    = stop_r;
    end else begin : g_free
      // the free range: nothing wraps early, stops or blocks (overflow / underflow at the ends)
      wire unused_range = &{1'b0, ceiling, load_ge_q, rst};
      assign ceil_now      = {COUNT_W{1'b0}};
      assign ceil_now_zero = 1'b0;
      assign up_wrap_q     = 2'd0;
      assign up_lim_q      = 2'd0;
      assign up_blk_q      = 2'd0;
      assign dn_wrap_q     = 1'b0;
      assign dn_lim_q      = 1'b0;
      assign dn_blk_q      = 1'b0;
      assign stop_q        = 1'b0;
    end
  endgenerate

  reg upd_q;  // the count changed (step or load) at the last clock edge

  always @(posedge clk) begin
    if (rst) begin
      count_q   <= {COUNT_W{1'b0}};
      stopped_q <= 1'b0;
      upd_q     <= 1'b0;
    end else begin
      count_q   <= count_d;
      stopped_q <= stopped_d;
      upd_q     <= ~s_hold;
    end
  end

  // ---- direction -----------------------------------------------------------------------------------
  reg dir_q;

  always @(posedge clk) begin
    if (rst) begin
      dir_q <= 1'b1;
    end else if (step_up | step_dn) begin
      dir_q <= step_up;
    end
  end

  assign ev_dir_change = (step_up & ~dir_q) | (step_dn & dir_q);

  // ---- latches ---------------------------------------------------------------------------------------
  reg [COUNT_W-1:0] idx_latch_q;
  reg [COUNT_W-1:0] probe_latch_q;
  reg [TS_W-1:0]    probe_time_q;
  reg               probe_prev_q, probe_ok_q, probe_hit_q;

  always @(posedge clk) begin
    if (rst | ~valid) begin
      probe_prev_q <= 1'b0;
      probe_ok_q   <= 1'b0;
      probe_hit_q  <= 1'b0;
    end else begin
      probe_prev_q <= probe_c;
      probe_ok_q   <= 1'b1;
      probe_hit_q  <= (PROBE != 0) & probe_ok_q & probe_en &
                      (probe_edge ? (probe_prev_q & ~probe_c) : (~probe_prev_q & probe_c));
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      idx_latch_q   <= {COUNT_W{1'b0}};
      probe_latch_q <= {COUNT_W{1'b0}};
      probe_time_q  <= {TS_W{1'b0}};
    end else begin
      if (lat_hit_q) begin
        idx_latch_q <= stepped;
      end
      if (probe_hit_q) begin
        probe_latch_q <= count_q;
        probe_time_q  <= timebase;
      end
    end
  end

  // ---- compare ---------------------------------------------------------------------------------------
  reg cmp_q;

  always @(posedge clk) begin
    if (rst) begin
      cmp_q <= 1'b0;
    end else begin
      cmp_q <= (RANGE != 0) & cmp_en & upd_q & (count_q == compare);
    end
  end

  // ---- outputs ---------------------------------------------------------------------------------------
  assign count        = count_q;
  assign idx_latch    = idx_latch_q;
  assign probe_latch  = probe_latch_q;
  assign probe_time   = probe_time_q;
  assign dir          = dir_q;
  assign idx_armed    = armed;
  assign stopped      = stopped_q;
  assign idx_disarm   = idx_act & idx_oneshot_q;
  assign probe_disarm = probe_hit_q & probe_once;
  assign applied_up   = s_inc | s_zero;
  assign applied_dn   = s_dec | s_ceil;
  assign ev_overflow  = ovf;
  assign ev_underflow = unf;
  assign ev_index     = idx_hit;
  assign ev_probe     = probe_hit_q;
  assign ev_cmp       = cmp_q;
  assign cmp_out      = cmp_q;

`ifdef FORMAL
  // zero_q is a registered copy of (count_q == 0) (Fmax): the invariant k-induction needs to
  // prove the count properties of formal/enc_qei_core.sby. Formal-only initial values make the
  // state before the first clock agree with it too. Assert only: a parent proof re-checks it.
  initial count_q = {COUNT_W{1'b0}};
  initial zero_q = 1'b1;
  always @(*) assert (zero_q == (count_q == {COUNT_W{1'b0}}));
  // ... the registered loads and configuration (initial: free range, not stopped, no index hit)
  initial wr_q = 1'b0;
  initial wr_pend_q = 1'b0;
  initial wr_val_q = {COUNT_W{1'b0}};
  initial load_q = 1'b0;
  initial load_val_q = {COUNT_W{1'b0}};
  initial load_ge_q = (RANGE != 0);
  initial load_zero_q = 1'b1;
  initial range_q = ENC_QEI_RANGE_FREE;
  initial idx_arm_q = 1'b0;
  initial idx_action_q = 2'd0;
  initial idx_oneshot_q = 1'b0;
  initial stopped_q = 1'b0;
  initial lat_hit_q = 1'b0;
  initial step_dn_add_q = 1'b0;
  always @(*) begin
    assert (load_zero_q == (load_val_q == {COUNT_W{1'b0}}));
    assert (step_dn_add_q == step_dn);
    assert (load_q == (wr_q | (idx_hit & idx_arm_q & (idx_action_q == ENC_QEI_INDEX_ACTION_PRESET))));
    assert (lat_hit_q == (idx_hit & idx_arm_q & (idx_action_q == ENC_QEI_INDEX_ACTION_LATCH)));
    if (RANGE == 0) assert (range_q == ENC_QEI_RANGE_FREE && !stopped_q && !load_ge_q);
  end

  // ... and with the ranges, the CEILING pipeline's flags agree with its values (initial values:
  // CEILING 0) and the range flags with the range, the count and the ceiling
  generate
    if (RANGE != 0) begin : g_range_invariants
      initial g_range.ceil_nx_n_q = {COUNT_W{1'b1}};
      initial g_range.ceil_nx_m1n_q = {COUNT_W{1'b0}};
      initial g_range.ceil_nx_m2n_q = {{(COUNT_W-1){1'b0}}, 1'b1};
      initial g_range.ceil_nx_le1_q = 1'b1;
      initial g_range.ceil_nx_zero_q = 1'b1;
      initial g_range.ceil_q = {COUNT_W{1'b0}};
      initial g_range.ceil_zero_q = 1'b1;
      initial g_range.ceil_wrap_ge_q = 1'b1;
      initial g_range.up_wrap_r = 2'd0;
      initial g_range.up_lim_r = 2'd0;
      initial g_range.up_blk_r = 2'd0;
      initial g_range.dn_wrap_r = 1'b0;
      initial g_range.dn_lim_r = 1'b0;
      initial g_range.dn_blk_r = 1'b0;
      initial g_range.stop_r = 1'b0;
      wire [COUNT_W-1:0] f_nx = g_range.ceil_nx;
      wire f_at_ceil = (count_q >= ceil_now);
      always @(*) begin
        assert (g_range.ceil_nx_m1n_q == ~(f_nx - {{(COUNT_W-1){1'b0}}, 1'b1}));
        assert (g_range.ceil_nx_m2n_q == ~(f_nx - {{(COUNT_W-2){1'b0}}, 2'd2}));
        assert (g_range.ceil_nx_zero_q == (f_nx == {COUNT_W{1'b0}}));
        assert (g_range.ceil_nx_le1_q == (f_nx <= {{(COUNT_W-1){1'b0}}, 1'b1}));
        assert (ceil_now_zero == (ceil_now == {COUNT_W{1'b0}}));
        assert (g_range.ceil_wrap_ge_q == (ceil_now >= f_nx));
        assert (load_ge_q == (load_val_q >= f_nx));
        assert (stop_q == stopped_q);
        assert (up_wrap == ((range_q == ENC_QEI_RANGE_MODULO) & f_at_ceil & ~stopped_q));
        assert (up_lim == (((range_q == ENC_QEI_RANGE_LIMIT) | r_nr) & f_at_ceil));
        assert (up_blk == (stop_q | (~r_free & f_at_ceil)));
        assert (dn_wrap_q == ((range_q == ENC_QEI_RANGE_MODULO) & zero_q & ~stopped_q));
        assert (dn_lim_q == (((range_q == ENC_QEI_RANGE_LIMIT) | r_nr) & zero_q));
        assert (dn_blk_q == (stop_q | (~r_free & zero_q)));
      end
    end
  endgenerate
`endif

endmodule

`default_nettype wire
