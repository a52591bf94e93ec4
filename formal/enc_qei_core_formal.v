// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_core (read by formal/enc_qei_core.sby; `make formal`).
//
// Port-level only: the core is instantiated with named ports and nothing inside it is referenced,
// so its internals may change as long as its ports and their cycle timing do not. The only
// assumption (outside the X4FREE task) is that the first clock is a reset; every input, rst
// included, is free after that: FUNC, RANGE, CEILING, SWAP/INV, EN, COUNT writes and index
// controls may change at any clock.
//
// The wrapper keeps a reference model written from the header of rtl/enc_qei_core.v, the enc_qei
// section of the module contract and the register descriptions of rtl/enc_qei.rdl:
//   sample s (clock t)  channels after SWAP_AB / INV_A / INV_B; the decoders are held in reset
//                       while rst, !valid, or {FUNC, SWAP_AB, INV_A, INV_B} differs from its value
//                       of the clock before (that value is cleared by rst, the CTRL reset value);
//                       the first sample out of that reset is the reference, not counted
//   clock t + 1         the count function's step of sample s (x4, x2a, x2b, x1a, x1b, pulse_dir,
//                       increase, decrease) and ev_qerr (both channels changed; quadrature
//                       functions only)
//   clock t + 2         step_up / step_dn (gated by EN of clock t + 1), edge_any / edge_a_rise and
//                       the index hit of sample s (ev_index); the range applies the step: the
//                       count, STOPPED, applied_up/dn, overflow/underflow are those of this clock
//   clock t + 3         count shows it; ev_cmp / cmp_out one clock later if it equals COMPARE
// RANGE and the index controls (INDEX_CTRL: ACTION, ARM, ONESHOT) act one clock after they change.
// CEILING: the range uses the ceiling input as of two clocks earlier (a CEILING write acts two
// clocks after it; the core keeps a pipeline of it so that count >= CEILING is a flag register).
// A load (a COUNT write: the register block assembles the value) loads the count two clocks after
// its strobe, with the value given with the strobe; an index preset loads PRESET of the clock
// before (both registered in the core with their comparisons, for Fmax). Loads and presets act
// whatever EN is.
// x1_hyst (Figure 14) is proven in formal/enc_x1_hysteresis.sby; here its steps are taken from the
// core's step ports (only "never both" and EN gating are checked), the range model still applies
// them independently.
// Index: Z after INV_Z, qualified by the (A, B) gate, edge detector held in reset by rst | !valid;
// no edge in a clock where {SWAP_AB, INV_A, INV_B, INV_Z} differs from the clock before (the level
// change a configuration write makes is not an index edge); its hit in clock t + 2 (with the step
// of the same sample); an armed preset wins over the step, a latch stores the count after the step. Probe: edge of probe_c, hit one clock after the sample
// (held in reset likewise), latches the count and the timebase of that clock.
// Checked: count, STOPPED, dir, step and edge outputs, every event output (overflow, underflow,
// index, probe, cmp, qerr, dir_change), applied_up/dn, idx_armed, idx_disarm, probe_disarm,
// INDEX_LATCH, PROBE_LATCH and PROBE_TIME equal the model at every clock; plus model-free
// one-step properties (applied steps move the count by exactly one in the range; the count
// changes only by a step, a load or an index preset; a bounded range is never left; non_recycle
// stays stopped until a load). Task X4FREE (define) assumes x4, free range, EN, no load, no index
// preset and checks count == a plain 4X position of the sample stream directly. (The 32-bit LO/HI
// words of the count are the register block's: formal/enc_qei_regs.sby.)
// Defines: PIPE_ONLY keeps only what does not depend on the count register (k-induction closes on
// it from the ports alone); the count's induction needs the core's internal zero_q flag to agree
// with count_q, an invariant the ports cannot show, so those properties run bounded (see the .sby).
// Codes of CTRL.FUNC, CTRL.RANGE and INDEX_CTRL.ACTION: rtl/enc_qei_regs.vh (generated from the
// RDL).
`default_nettype none

module enc_qei_core_formal #(
    parameter integer COUNT_W = 8,
    parameter integer TS_W    = 16
) (
    input wire               clk,
    input wire               rst,
    input wire               a_c,
    input wire               b_c,
    input wire               z_c,
    input wire               probe_c,
    input wire               valid,
    input wire               en,
    input wire               swap_ab,
    input wire               inv_a,
    input wire               inv_b,
    input wire               inv_z,
    input wire [3:0]         func,
    input wire [1:0]         range,
    input wire [COUNT_W-1:0] preset,
    input wire [COUNT_W-1:0] ceiling,
    input wire [COUNT_W-1:0] compare,
    input wire               cmp_en,
    input wire [1:0]         idx_action,
    input wire               idx_oneshot,
    input wire               idx_edge,
    input wire               idx_gate_en,
    input wire               idx_gate_a,
    input wire               idx_gate_b,
    input wire               idx_arm,
    input wire               probe_en,
    input wire               probe_edge,
    input wire               probe_once,
    input wire [TS_W-1:0]    timebase,
    input wire               load,
    input wire [COUNT_W-1:0] load_value
);

  wire [COUNT_W-1:0] count;
  wire [COUNT_W-1:0] idx_latch;
  wire [COUNT_W-1:0] probe_latch;
  wire [TS_W-1:0]    probe_time;
  wire a_eff, b_eff, z_eff, dir, idx_armed, stopped, idx_disarm, probe_disarm;
  wire step_up, step_dn, applied_up, applied_dn, edge_any, edge_a_rise;
  wire ev_overflow, ev_underflow, ev_index, ev_probe, ev_cmp, ev_qerr, ev_dir_change, cmp_out;

  enc_qei_core #(
      .COUNT_W(COUNT_W),
      .TS_W   (TS_W)
  ) dut (
      .clk           (clk),
      .rst           (rst),
      .a_c           (a_c),
      .b_c           (b_c),
      .z_c           (z_c),
      .probe_c       (probe_c),
      .valid         (valid),
      .en            (en),
      .swap_ab       (swap_ab),
      .inv_a         (inv_a),
      .inv_b         (inv_b),
      .inv_z         (inv_z),
      .func          (func),
      .range         (range),
      .preset        (preset),
      .ceiling       (ceiling),
      .compare       (compare),
      .cmp_en        (cmp_en),
      .idx_action    (idx_action),
      .idx_oneshot   (idx_oneshot),
      .idx_edge      (idx_edge),
      .idx_gate_en   (idx_gate_en),
      .idx_gate_a    (idx_gate_a),
      .idx_gate_b    (idx_gate_b),
      .idx_arm       (idx_arm),
      .probe_en      (probe_en),
      .probe_edge    (probe_edge),
      .probe_once    (probe_once),
      .timebase      (timebase),
      .load          (load),
      .load_value    (load_value),
      .count         (count),
      .idx_latch     (idx_latch),
      .probe_latch   (probe_latch),
      .probe_time    (probe_time),
      .a_eff         (a_eff),
      .b_eff         (b_eff),
      .z_eff         (z_eff),
      .dir           (dir),
      .idx_armed     (idx_armed),
      .stopped       (stopped),
      .idx_disarm    (idx_disarm),
      .probe_disarm  (probe_disarm),
      .step_up       (step_up),
      .step_dn       (step_dn),
      .applied_up    (applied_up),
      .applied_dn    (applied_dn),
      .edge_any      (edge_any),
      .edge_a_rise   (edge_a_rise),
      .ev_overflow   (ev_overflow),
      .ev_underflow  (ev_underflow),
      .ev_index      (ev_index),
      .ev_probe      (ev_probe),
      .ev_cmp        (ev_cmp),
      .ev_qerr       (ev_qerr),
      .ev_dir_change (ev_dir_change),
      .cmp_out       (cmp_out)
  );

  `include "enc_qei_regs.vh"
  localparam [COUNT_W-1:0] ONE = {{(COUNT_W-1){1'b0}}, 1'b1};
  localparam [COUNT_W-1:0] ZERO = {COUNT_W{1'b0}};
  localparam [COUNT_W-1:0] ALL1 = {COUNT_W{1'b1}};

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  always @(*) begin
    if (!f_past_valid) assume (rst);
  end

  // RANGE and INDEX_CTRL act one clock after they change (the core registers them: its range and
  // index decisions are flag registers, for Fmax): the model uses them as of the clock before.
  reg [1:0] f_range = 2'd0, f_act = 2'd0;
  reg       f_arm = 1'b0, f_oneshot = 1'b0;
  always @(posedge clk) begin
    f_range   <= range;
    f_act     <= idx_action;
    f_arm     <= idx_arm;
    f_oneshot <= idx_oneshot;
  end

`ifdef X4FREE
  // Task prove_x4free: x4, free range, counting enabled, no COUNT write, no index preset.
  always @(*) begin
    assume (func == ENC_QEI_FUNC_X4 && range == ENC_QEI_RANGE_FREE && en && !load &&
            idx_action != ENC_QEI_INDEX_ACTION_PRESET);
  end
`endif

  // ---- sample level (clock t) ----------------------------------------------------------------------
  wire       f_a = (swap_ab ? b_c : a_c) ^ inv_a;
  wire       f_b = (swap_ab ? a_c : b_c) ^ inv_b;
  wire       f_z = z_c ^ inv_z;
  wire [7:0] f_cfg = {func, swap_ab, inv_a, inv_b, inv_z};
  reg  [7:0] f_cfg_q = 8'd0;  // the clock before (cleared by rst)
  wire       f_drst = rst | ~valid | (f_cfg[7:1] != f_cfg_q[7:1]);  // decoders held in reset
  wire       f_zref = (f_cfg[3:0] != f_cfg_q[3:0]);  // the index re-referenced: no edge

  reg        f_ref = 1'b0;      // the previous sample is a real one (decoders out of reset)
  reg  [1:0] f_prev = 2'b00;    // previous {a, b}
  wire       f_ach = f_a ^ f_prev[1];
  wire       f_bch = f_b ^ f_prev[0];
  wire       f_valid = ~f_drst & f_ref & (f_ach ^ f_bch);  // a valid transition at this sample
  wire       f_illegal = ~f_drst & f_ref & f_ach & f_bch;  // both channels changed
  wire       f_fwd = ({f_a, f_b} == {~f_prev[0], f_prev[1]});  // 00 -> 10 -> 11 -> 01 -> 00
  wire       f_arise = ~f_drst & f_ref & f_a & ~f_prev[1];   // A rising (pulse functions)

  // index: Z qualified by the gate; edge detector held in reset by rst | !valid only
  wire       f_iq = f_z & (~idx_gate_en | ((f_a == idx_gate_a) & (f_b == idx_gate_b)));
  reg        f_iprev = 1'b0, f_iok = 1'b0, f_ihit1 = 1'b0, f_ihit = 1'b0;

  // stage 1: the decoders' view of the sample, one clock later
  reg f1_valid = 1'b0, f1_illegal = 1'b0, f1_fwd = 1'b0, f1_amov = 1'b0, f1_bmov = 1'b0;
  reg f1_a = 1'b0, f1_b = 1'b0, f1_arise = 1'b0;

  always @(posedge clk) begin
    f_cfg_q    <= rst ? 8'd0 : f_cfg;
    f_ref      <= ~f_drst;
    f_prev     <= {f_a, f_b};
    f1_valid   <= f_valid;
    f1_illegal <= f_illegal;
    f1_fwd     <= f_fwd;
    f1_amov    <= f_ach;
    f1_bmov    <= f_bch;
    f1_a       <= f_a;
    f1_b       <= f_b;
    f1_arise   <= f_arise;
    if (rst | ~valid) begin
      f_iprev <= 1'b0;
      f_iok   <= 1'b0;
      f_ihit1 <= 1'b0;
      f_ihit  <= 1'b0;
    end else begin
      f_iprev <= f_iq;
      f_iok   <= 1'b1;
      f_ihit1 <= f_iok & ~f_zref & (idx_edge ? (f_iprev & ~f_iq) : (~f_iprev & f_iq));
      f_ihit  <= f_ihit1;
    end
  end

  // ---- stage 1 (clock t + 1): the count function -----------------------------------------------------
  reg f_fup, f_fdn, f_quad;
  always @(*) begin
    f_fup  = 1'b0;
    f_fdn  = 1'b0;
    f_quad = 1'b0;
    case (func)
      ENC_QEI_FUNC_X4: begin
        f_fup = f1_valid & f1_fwd;
        f_fdn = f1_valid & ~f1_fwd;
        f_quad = 1'b1;
      end
      ENC_QEI_FUNC_X2A: begin  // both edges of A
        f_fup = f1_valid & f1_amov & f1_fwd;
        f_fdn = f1_valid & f1_amov & ~f1_fwd;
        f_quad = 1'b1;
      end
      ENC_QEI_FUNC_X2B: begin
        f_fup = f1_valid & f1_bmov & f1_fwd;
        f_fdn = f1_valid & f1_bmov & ~f1_fwd;
        f_quad = 1'b1;
      end
      ENC_QEI_FUNC_X1A: begin  // +1 on A rising forward, -1 on A falling backward
        f_fup = f1_valid & f1_amov & f1_fwd & f1_a;
        f_fdn = f1_valid & f1_amov & ~f1_fwd & ~f1_a;
        f_quad = 1'b1;
      end
      ENC_QEI_FUNC_X1B: begin
        f_fup = f1_valid & f1_bmov & f1_fwd & f1_b;
        f_fdn = f1_valid & f1_bmov & ~f1_fwd & ~f1_b;
        f_quad = 1'b1;
      end
      ENC_QEI_FUNC_PULSE_DIR: begin  // A rising, B = direction (1 = up)
        f_fup = f1_arise & f1_b;
        f_fdn = f1_arise & ~f1_b;
      end
      ENC_QEI_FUNC_INCREASE: f_fup = f1_arise;
      ENC_QEI_FUNC_DECREASE: f_fdn = f1_arise;
      ENC_QEI_FUNC_X1_HYST: f_quad = 1'b1;  // steps: see f_hyst_q
      default: ;
    endcase
  end

  // stage 2 registers
  reg f2_up = 1'b0, f2_dn = 1'b0, f2_edge = 1'b0, f2_arise_edge = 1'b0, f_hyst_q = 1'b0;
  always @(posedge clk) begin
    if (rst) begin
      f2_up         <= 1'b0;
      f2_dn         <= 1'b0;
      f2_edge       <= 1'b0;
      f2_arise_edge <= 1'b0;
      f_hyst_q      <= 1'b0;
    end else begin
      f2_up         <= en & f_fup;
      f2_dn         <= en & f_fdn;
      f2_edge       <= f1_valid;
      f2_arise_edge <= f1_valid & f1_amov & f1_a;
      f_hyst_q      <= en & (func == ENC_QEI_FUNC_X1_HYST);
    end
  end

  // ---- stage 2 (clock t + 2): the range applies the step -----------------------------------------
  wire f_su = f_hyst_q ? step_up : f2_up;  // the step this clock (x1_hyst: the core's)
  wire f_sd = f_hyst_q ? step_dn : f2_dn;

  reg  [COUNT_W-1:0] f_count = {COUNT_W{1'b0}};
  reg                f_stopped = 1'b0;
  reg                f_dir = 1'b1;
  reg                f_upd_q = 1'b0;
  reg                f_cmp = 1'b0;

  wire f_at_zero = (f_count == ZERO);
  // CEILING acts two clocks after it is set (the core's ceiling pipeline, for Fmax): f_ceil
  reg  [COUNT_W-1:0] f_ceil1 = {COUNT_W{1'b0}}, f_ceil = {COUNT_W{1'b0}};
  always @(posedge clk) begin
    f_ceil1 <= ceiling;
    f_ceil  <= f_ceil1;
  end
  wire f_at_ceil = (f_count >= f_ceil);
  reg  [COUNT_W-1:0] f_stepped;
  reg  f_ovf, f_unf, f_took, f_stop_d;

  always @(*) begin
    f_stepped = f_count;
    f_ovf     = 1'b0;
    f_unf     = 1'b0;
    f_took    = 1'b0;
    f_stop_d  = f_stopped;
    // (stopped by non_recycle: no step in any range until a COUNT write)
    if (f_su && !f_stopped) begin
      case (f_range)
        ENC_QEI_RANGE_FREE: begin
          f_stepped = f_count + ONE;
          f_ovf = (f_count == ALL1);
          f_took = 1'b1;
        end
        ENC_QEI_RANGE_MODULO: begin
          f_stepped = f_at_ceil ? ZERO : f_count + ONE;
          f_ovf = f_at_ceil;
          f_took = 1'b1;
        end
        default: begin  // limit, non_recycle
          f_stepped = f_at_ceil ? f_count : f_count + ONE;
          f_ovf = f_at_ceil;
          f_took = ~f_at_ceil;
          if (f_range == ENC_QEI_RANGE_NON_RECYCLE) f_stop_d = f_at_ceil;
        end
      endcase
    end else if (f_sd && !f_stopped) begin
      case (f_range)
        ENC_QEI_RANGE_FREE: begin
          f_stepped = f_count - ONE;
          f_unf = f_at_zero;
          f_took = 1'b1;
        end
        ENC_QEI_RANGE_MODULO: begin
          f_stepped = f_at_zero ? f_ceil : f_count - ONE;
          f_unf = f_at_zero;
          f_took = 1'b1;
        end
        default: begin
          f_stepped = f_at_zero ? f_count : f_count - ONE;
          f_unf = f_at_zero;
          f_took = ~f_at_zero;
          if (f_range == ENC_QEI_RANGE_NON_RECYCLE) f_stop_d = f_at_zero;
        end
      endcase
    end
    if (f_lw_q) f_stop_d = 1'b0;  // a COUNT write releases non_recycle
  end

  wire               f_armed = f_arm & (f_act != ENC_QEI_INDEX_ACTION_NONE);
  wire               f_preset = f_ihit & f_armed & (f_act == ENC_QEI_INDEX_ACTION_PRESET);
  // a load loads the count two clocks after its strobe (f_lw_q, f_wr_q), an index preset loads
  // PRESET as it was one clock earlier (f_pre_q)
  reg                f_lw1_q = 1'b0, f_lw_q = 1'b0;
  reg  [COUNT_W-1:0] f_wr1_q = {COUNT_W{1'b0}}, f_wr_q = {COUNT_W{1'b0}};
  reg  [COUNT_W-1:0] f_pre_q = {COUNT_W{1'b0}};
  always @(posedge clk) begin
    f_lw1_q <= ~rst & load;
    f_lw_q  <= ~rst & f_lw1_q;
    f_wr1_q <= load_value;
    f_wr_q  <= f_wr1_q;
    f_pre_q <= preset;
  end
  wire               f_load = f_lw_q | f_preset;
  wire [COUNT_W-1:0] f_next = f_lw_q ? f_wr_q : f_preset ? f_pre_q : f_stepped;

  always @(posedge clk) begin
    if (rst) begin
      f_count    <= ZERO;
      f_stopped  <= 1'b0;
      f_dir      <= 1'b1;
      f_upd_q    <= 1'b0;
      f_cmp      <= 1'b0;
    end else begin
      f_count   <= f_next;
      f_stopped <= f_stop_d;
      if (f_su | f_sd) f_dir <= f_su;
      f_upd_q   <= f_load | f_took;  // the count was set (changed or reloaded) at this edge
      f_cmp     <= cmp_en & f_upd_q & (f_count == compare);
    end
  end

  // ---- latches: INDEX_LATCH (the count after the transition's step), probe (latency 1) ---------
  reg  f_pprev = 1'b0, f_pok = 1'b0, f_phit = 1'b0;
  reg  [COUNT_W-1:0] f_idx_latch = {COUNT_W{1'b0}}, f_probe_latch = {COUNT_W{1'b0}};
  reg  [TS_W-1:0]    f_probe_time = {TS_W{1'b0}};
  wire f_ilatch = f_ihit & f_armed & (f_act == ENC_QEI_INDEX_ACTION_LATCH);
  always @(posedge clk) begin
    if (rst | ~valid) begin
      f_pprev <= 1'b0;
      f_pok   <= 1'b0;
      f_phit  <= 1'b0;
    end else begin
      f_pprev <= probe_c;
      f_pok   <= 1'b1;
      f_phit  <= f_pok & probe_en & (probe_edge ? (f_pprev & ~probe_c) : (~f_pprev & probe_c));
    end
    if (rst) begin
      f_idx_latch   <= ZERO;
      f_probe_latch <= ZERO;
      f_probe_time  <= {TS_W{1'b0}};
    end else begin
      if (f_ilatch) f_idx_latch <= f_stepped;
      if (f_phit) begin
        f_probe_latch <= f_count;
        f_probe_time  <= timebase;
      end
    end
  end


  // ---- properties: the core equals the model at every clock ---------------------------------------
  always @(*) begin
    if (f_past_valid) begin
      assert (a_eff == f_a && b_eff == f_b && z_eff == f_z);
      assert (ev_qerr == (f_quad & f1_illegal));
      assert (!(step_up && step_dn));
      if (!f_hyst_q) assert (step_up == f2_up && step_dn == f2_dn);
      assert (edge_any == f2_edge && edge_a_rise == f2_arise_edge);
      assert (ev_index == f_ihit);
      assert (idx_armed == f_armed);
      assert (idx_disarm == (f_ihit & f_armed & f_oneshot));
`ifndef PIPE_ONLY
      assert (count == f_count);
      assert (stopped == f_stopped);
`endif
      assert (dir == f_dir);
`ifndef PIPE_ONLY
      assert (applied_up == (f_took & f_su & ~f_load));
      assert (applied_dn == (f_took & f_sd & ~f_load));
      assert (ev_overflow == f_ovf && ev_underflow == f_unf);
`endif
      assert (ev_dir_change == ((f_su & ~f_dir) | (f_sd & f_dir)));
`ifndef PIPE_ONLY
      assert (ev_cmp == f_cmp && cmp_out == f_cmp);
`endif
      assert (ev_probe == f_phit && probe_disarm == (f_phit & probe_once));
      assert (probe_time == f_probe_time);
`ifndef PIPE_ONLY
      assert (idx_latch == f_idx_latch);
      assert (probe_latch == f_probe_latch);
`endif
    end
  end

`ifndef PIPE_ONLY
  // ---- model-free one-step properties ---------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && !$past(rst)) begin
      // an applied step moves the count by exactly one, in the range
      if ($past(applied_up))
        assert (count == (($past(f_range) == ENC_QEI_RANGE_MODULO && $past(count) >= $past(f_ceil)) ? ZERO :
                          $past(count) + ONE));
      if ($past(applied_dn))
        assert (count == (($past(f_range) == ENC_QEI_RANGE_MODULO && $past(count) == ZERO) ? $past(f_ceil) :
                          $past(count) - ONE));
      assert (!$past(applied_up && applied_dn));
      // the count changes only by a step, a load or an index preset
      if (!$past(applied_up || applied_dn || f_lw_q || f_preset)) assert (count == $past(count));
      if ($past(f_lw_q)) assert (count == $past(f_wr_q));
      // a bounded range is never left by counting
      if ($past(f_range) != ENC_QEI_RANGE_FREE && $past(count) <= $past(f_ceil) && !$past(f_load))
        assert (count <= $past(f_ceil));
      // limit / non_recycle: never past the bounds, the stop raises the event and is no step (a
      // counter stopped by non_recycle, in any range: no event either)
      if ($past(f_range) == ENC_QEI_RANGE_LIMIT || $past(f_range) == ENC_QEI_RANGE_NON_RECYCLE) begin
        if ($past(step_up) && $past(count) >= $past(f_ceil))
          assert (!$past(applied_up) && $past(ev_overflow) == !$past(stopped));
        if ($past(step_dn) && !$past(step_up) && $past(count) == ZERO)
          assert (!$past(applied_dn) && $past(ev_underflow) == !$past(stopped));
      end
      // non_recycle: stopped stays stopped (and the count still) until a load
      if ($past(stopped) && !$past(f_lw_q)) assert (stopped);
      if ($past(stopped) && $past(f_range) == ENC_QEI_RANGE_NON_RECYCLE && !$past(f_load))
        assert (count == $past(count) && !$past(applied_up || applied_dn));
      if ($past(f_lw_q)) assert (!stopped);
    end
  end

`endif

`ifdef X4FREE
  // ---- x4 in the free range: count == a plain 4X position of the sample stream ---------------------
  // f_pos: +1 per forward valid transition, -1 per reverse one, illegal changes ignored, from the
  // reference sample after each decoder reset; the count shows a sample 3 clocks later.
  reg [COUNT_W-1:0] f_pos = {COUNT_W{1'b0}}, f_pos1 = {COUNT_W{1'b0}}, f_pos2 = {COUNT_W{1'b0}};
  always @(posedge clk) begin
    if (rst) begin
      f_pos  <= ZERO;
      f_pos1 <= ZERO;
      f_pos2 <= ZERO;
    end else begin
      if (f_valid) f_pos <= f_fwd ? f_pos + ONE : f_pos - ONE;
      f_pos1 <= f_pos;
      f_pos2 <= f_pos1;
    end
  end
  always @(*) begin
    if (f_past_valid) assert (count == f_pos2);
    if (f_past_valid) assert (!stopped);  // (the free range never stops; a stop would hold)
  end
  always @(posedge clk) begin
    cover (f_past_valid && count == 8'd3 && !rst);
    cover (f_past_valid && count == ALL1 && !rst);
  end
`endif

  // ---- covers: every property's situation is reached ---------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && !rst) begin
      cover (func == ENC_QEI_FUNC_X4 && f_range == ENC_QEI_RANGE_FREE && applied_up && count == ONE);
      cover (func == ENC_QEI_FUNC_X4 && f_range == ENC_QEI_RANGE_FREE && applied_dn && count == ZERO);
      cover (f_range == ENC_QEI_RANGE_FREE && ev_overflow && applied_up);
      cover (f_range == ENC_QEI_RANGE_FREE && ev_underflow && applied_dn);
      cover (f_range == ENC_QEI_RANGE_MODULO && ev_overflow && applied_up && count != ZERO);
      cover (f_range == ENC_QEI_RANGE_MODULO && ev_underflow && applied_dn && f_ceil != ALL1);
      cover (f_range == ENC_QEI_RANGE_LIMIT && ev_overflow && step_up && count == f_ceil && f_ceil != ALL1);
      cover (f_range == ENC_QEI_RANGE_LIMIT && ev_underflow && step_dn);
      cover (f_range == ENC_QEI_RANGE_NON_RECYCLE && ev_overflow && !stopped && f_ceil != ALL1);
      cover (f_range == ENC_QEI_RANGE_NON_RECYCLE && stopped && step_dn);  // a step while stopped: ignored
      cover ($past(stopped) && f_lw_q && !rst);               // released by a COUNT_LO write
      cover (ev_qerr && func == ENC_QEI_FUNC_X4);
      cover (ev_dir_change && step_dn);
      cover (ev_dir_change && step_up);
      cover (ev_cmp && $past(applied_up));
      cover (ev_cmp && $past(f_lw_q, 2));
      cover (ev_cmp && $past(f_preset, 2));
      cover (f_preset && (step_up | step_dn));                 // a preset wins over the step
      cover (func == ENC_QEI_FUNC_X2A && applied_dn);
      cover (func == ENC_QEI_FUNC_X2B && applied_up);
      cover (func == ENC_QEI_FUNC_X1A && applied_dn);
      cover (func == ENC_QEI_FUNC_X1B && applied_up);
      cover (func == ENC_QEI_FUNC_PULSE_DIR && applied_dn);
      cover (func == ENC_QEI_FUNC_INCREASE && applied_up);
      cover (func == ENC_QEI_FUNC_DECREASE && applied_dn);
      cover (f_hyst_q && applied_up);
      cover (load && count != ZERO);
      cover (f_ilatch && (step_up | step_dn));  // INDEX_LATCH takes the stepped count
      cover (ev_probe && count != ZERO && probe_time != {TS_W{1'b0}});
    end
  end

endmodule

`default_nettype wire
