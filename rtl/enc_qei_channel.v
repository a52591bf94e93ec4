// SPDX-License-Identifier: Apache-2.0
// enc_qei_channel -- one channel of enc_qei: its encoder inputs, counting core and timing unit,
// behind its page of the register block (the bundles reg2hw / hw2reg; fields by name:
// rtl/enc_qei_chan_fields.vh).
//
//   a_in, b_in     -> enc_conditioner_rt (CTRL.FILTER_LEN) --+
//   z_in, probe_in -> enc_conditioner_rt (same length) ------+-> enc_qei_core (decode, count,
//                                                            |   range, index, probe, compare)
//   snap_in, SNAP_CTRL -> enc_qei_snaptrig --(| gsnap)--> enc_qei_timing (snapshots, period,
//                                                            stall; on the shared timebase)
//   the core's steps -> enc_qei_efifo (EFIFO_LOG2 > 0: the edge-capture FIFO, EFIFO_*)
//
// Z and probe_in go through their own synchronizer and filter of the same length as A and B, so
// the index lines up with the channels clock for clock. A snapshot is taken in the clock of its
// request: the channel's own (SNAP_CTRL) or the global one (gsnap, the same clock in every
// channel). irq_pend: an event of this channel is pending and enabled (IRQ_EN), registered.
// The units (TIMING, RANGE, PROBE, PERIOD) and FIXED_FUNC come from enc_qei's PROFILE and
// FUNC_MASK; a unit left out reads 0 in the register block and its logic is not built here.
`default_nettype none
`include "enc_params.vh"

module enc_qei_channel #(
    parameter integer COUNT_W    = 32,   // counter width (checked by enc_qei)
    parameter integer TS_W       = 32,   // timebase width (checked by enc_qei)
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL,  // count functions built (checked by enc_qei)
    parameter integer FIXED_FUNC = -1,   // the one function FUNC_MASK builds, or -1 (from enc_qei)
    parameter integer TIMING     = 1,    // units, as enc_qei_regs's (checked by enc_qei)
    parameter integer RANGE      = 1,
    parameter integer PROBE      = 1,
    parameter integer PERIOD     = 1,
    parameter integer EFIFO_LOG2 = 0     // edge FIFO of 2^EFIFO_LOG2 entries, 0: none (checked by enc_qei)
) (
    input  wire             clk,
    input  wire             rst,       // synchronous, active high
    input  wire [`ENC_QEI_R2H_CH_W-1:0] reg2hw,  // this channel's page, to the hardware
    output wire [`ENC_QEI_H2R_CH_W-1:0] hw2reg,  // ... from the hardware
    input  wire             a_in,      // encoder channel A, asynchronous
    input  wire             b_in,      // encoder channel B, asynchronous
    input  wire             z_in,      // index channel, asynchronous
    input  wire             probe_in,  // external latch input, asynchronous
    input  wire             snap_in,   // synchronous snapshot strobe
    input  wire [TS_W-1:0]  timebase,  // the shared timebase
    input  wire             tick,      // ... advances at the end of this clock
    input  wire             gsnap,     // a global snapshot in this clock
    output wire             cmp_out,   // one-clock pulse on a compare match
    output wire             irq_pend   // an enabled event is pending (registered)
);

  `include "enc_qei_regs.vh"
  `include "enc_qei_chan_fields.vh"

  localparam integer FUNC_ALL    = (1 << ENC_QEI_FUNC_N) - 1;
  localparam [15:0]  FUNC_MASK16 = FUNC_MASK[15:0];

  function [63:0] zext_count;
    input [COUNT_W-1:0] v;
    begin
      zext_count = 64'd0;
      zext_count[COUNT_W-1:0] = v;
    end
  endfunction

  function [31:0] zext_ts;
    input [TS_W-1:0] v;
    begin
      zext_ts = 32'd0;
      zext_ts[TS_W-1:0] = v;
    end
  endfunction

  // ---- conditioners ------------------------------------------------------------------------------
  wire a_c, b_c, z_c, probe_c, glitch_ab, valid_ab, glitch_zp_unused, valid_zp_unused;

  enc_conditioner_rt #(
      .MAX_FILTER_LEN(16)
  ) u_cond_ab (
      .clk       (clk),
      .rst       (rst),
      .filter_len(r2h_ctrl_filter_len),
      .a_in      (a_in),
      .b_in      (b_in),
      .a         (a_c),
      .b         (b_c),
      .glitch    (glitch_ab),
      .valid     (valid_ab)
  );

  enc_conditioner_rt #(
      .MAX_FILTER_LEN(16)
  ) u_cond_zp (
      .clk       (clk),
      .rst       (rst),
      .filter_len(r2h_ctrl_filter_len),
      .a_in      (z_in),
      .b_in      ((PROBE != 0) & probe_in),
      .a         (z_c),
      .b         (probe_c),
      .glitch    (glitch_zp_unused),
      .valid     (valid_zp_unused)
  );

  assign h2r_status_valid      = valid_ab;
  assign h2r_glitch_count_incr = glitch_ab;

  // CTRL.FUNC as the core sees it: with some functions left out, the others count nothing (a code
  // no function has); with one (FIXED_FUNC: the register block reads it) or all, CTRL.FUNC.
  wire [3:0] func_eff = (FIXED_FUNC >= 0) ? FIXED_FUNC[3:0] :
                        (FUNC_MASK == FUNC_ALL || FUNC_MASK16[r2h_ctrl_func]) ? r2h_ctrl_func : 4'd15;

  // ---- core --------------------------------------------------------------------------------------
  wire [COUNT_W-1:0] count_q, idx_latch, probe_latch;
  wire [TS_W-1:0]    probe_time;
  wire step_up, step_dn, applied_up, applied_dn, edge_any, edge_a_rise;
  wire [1:0] step_ab;
  wire ev_overflow, ev_underflow, ev_index, ev_probe, ev_cmp, ev_qerr, ev_dir_change;

  enc_qei_core #(
      .COUNT_W(COUNT_W),
      .TS_W   (TS_W),
      .RANGE  (RANGE),
      .PROBE  (PROBE)
  ) u_core (
      .clk          (clk),
      .rst          (rst),
      .a_c          (a_c),
      .b_c          (b_c),
      .z_c          (z_c),
      .probe_c      (probe_c),
      .valid        (valid_ab),
      .en           (r2h_ctrl_en),
      .swap_ab      (r2h_ctrl_swap_ab),
      .inv_a        (r2h_ctrl_inv_a),
      .inv_b        (r2h_ctrl_inv_b),
      .inv_z        (r2h_ctrl_inv_z),
      .func         (func_eff),
      .range        (r2h_ctrl_range),
      .preset       (r2h_preset[COUNT_W-1:0]),
      .ceiling      (r2h_ceiling[COUNT_W-1:0]),
      .compare      (r2h_compare[COUNT_W-1:0]),
      .cmp_en       (r2h_ctrl_cmp_en),
      .idx_action   (r2h_index_ctrl_action),
      .idx_oneshot  (r2h_index_ctrl_oneshot),
      .idx_edge     (r2h_index_ctrl_edge),
      .idx_gate_en  (r2h_index_ctrl_gate_en),
      .idx_gate_a   (r2h_index_ctrl_gate_a),
      .idx_gate_b   (r2h_index_ctrl_gate_b),
      .idx_arm      (r2h_index_ctrl_arm),
      .probe_en     (r2h_probe_ctrl_en),
      .probe_edge   (r2h_probe_ctrl_edge),
      .probe_once   (r2h_probe_ctrl_once),
      .timebase     (timebase),
      .load         (r2h_count_load),
      .load_value   (r2h_count_load_value[COUNT_W-1:0]),
      .count        (count_q),
      .idx_latch    (idx_latch),
      .probe_latch  (probe_latch),
      .probe_time   (probe_time),
      .a_eff        (h2r_status_a),
      .b_eff        (h2r_status_b),
      .z_eff        (h2r_status_z),
      .dir          (h2r_status_dir),
      .idx_armed    (h2r_status_index_armed),
      .stopped      (h2r_status_stopped),
      .idx_disarm   (h2r_index_ctrl_arm_clr),
      .probe_disarm (h2r_probe_ctrl_en_clr),
      .step_up      (step_up),
      .step_dn      (step_dn),
      .applied_up   (applied_up),
      .applied_dn   (applied_dn),
      .edge_any     (edge_any),
      .edge_a_rise  (edge_a_rise),
      .step_ab      (step_ab),
      .ev_overflow  (ev_overflow),
      .ev_underflow (ev_underflow),
      .ev_index     (ev_index),
      .ev_probe     (ev_probe),
      .ev_cmp       (ev_cmp),
      .ev_qerr      (ev_qerr),
      .ev_dir_change(ev_dir_change),
      .cmp_out      (cmp_out)
  );

  // (the core's applied steps are for its proofs: the timing unit and the edge FIFO count the
  // function's steps, the motion, whatever loads and the range do to the count)
  wire unused_applied = &{1'b0, applied_up, applied_dn};

  assign h2r_count           = zext_count(count_q);
  assign h2r_index_latch     = zext_count(idx_latch);
  assign h2r_probe_latch     = zext_count(probe_latch);
  assign h2r_probe_time      = zext_ts(probe_time);
  assign h2r_qerr_count_incr = ev_qerr;

  // ---- timing: snapshots, period capture, stall ------------------------------------------------
  wire ev_snap, ev_period, ev_period_ovf, ev_stall, ev_efifo_thresh, ev_efifo_ovf;

  generate
    if (TIMING != 0) begin : g_timing
      wire               snap_own;
      wire [COUNT_W-1:0] snap_count;
      wire [TS_W-1:0]    snap_time, snap_edge_time, period;

      enc_qei_snaptrig #(
          .TS_W (TS_W),
          .TIMER(PERIOD)
      ) u_snaptrig (
          .clk      (clk),
          .rst      (rst),
          .tick     (tick),
          .cmd      (r2h_snap_ctrl_cmd),
          .snap_in  (snap_in),
          .in_en    (r2h_snap_ctrl_in_en),
          .period_en(r2h_snap_ctrl_period_en),
          .period   (r2h_snap_period[TS_W-1:0]),
          .req      (snap_own)
      );

      enc_qei_timing #(
          .COUNT_W(COUNT_W),
          .TS_W   (TS_W),
          .PERIOD (PERIOD)
      ) u_timing (
          .clk            (clk),
          .rst            (rst),
          .timebase       (timebase),
          .tick           (tick),
          .edge_any       (edge_any),
          .edge_a_rise    (edge_a_rise),
          .step_up        (step_up),
          .step_dn        (step_dn),
          .dir_change     (ev_dir_change),
          .count          (count_q),
          .snap_req       (snap_own | gsnap),
          .snap_edge      (r2h_snap_ctrl_edge),
          .period_en      (r2h_period_ctrl_en),
          .period_edge    (r2h_period_ctrl_edge),
          .period_n       (r2h_period_ctrl_n),
          .stall_timeout  (r2h_stall_timeout[TS_W-1:0]),
          .snap_count     (snap_count),
          .snap_time      (snap_time),
          .snap_edge_time (snap_edge_time),
          .snap_delta     (h2r_snap_delta),
          .snap_edge_delta(h2r_snap_edge_delta),
          .period         (period),
          .period_ovf_flag(h2r_period_ctrl_overflow),
          .period_dir_flag(h2r_period_ctrl_dir_change),
          .stalled        (h2r_status_stalled),
          .ev_snap        (ev_snap),
          .ev_period      (ev_period),
          .ev_period_ovf  (ev_period_ovf),
          .ev_stall       (ev_stall)
      );

      assign h2r_snap_count     = zext_count(snap_count);
      assign h2r_snap_time      = zext_ts(snap_time);
      assign h2r_snap_edge_time = zext_ts(snap_edge_time);
      assign h2r_period         = zext_ts(period);
    end else begin : g_no_timing
      wire unused_timing = &{1'b0, edge_any, edge_a_rise, step_up, step_dn,
                             snap_in, tick, gsnap};
      assign h2r_snap_count             = 64'd0;
      assign h2r_snap_time              = 32'd0;
      assign h2r_snap_edge_time         = 32'd0;
      assign h2r_snap_delta             = 32'd0;
      assign h2r_snap_edge_delta        = 32'd0;
      assign h2r_period                 = 32'd0;
      assign h2r_period_ctrl_overflow   = 1'b0;
      assign h2r_period_ctrl_dir_change = 1'b0;
      assign h2r_status_stalled         = 1'b0;
      assign ev_snap                    = 1'b0;
      assign ev_period                  = 1'b0;
      assign ev_period_ovf              = 1'b0;
      assign ev_stall                   = 1'b0;
    end
  endgenerate

  // the edge-capture FIFO (enc_qei allows it only with the timing unit: its timebase)
  generate
    if (EFIFO_LOG2 > 0) begin : g_efifo
      wire [TS_W-1:0] efifo_time;

      enc_qei_efifo #(
          .DEPTH_LOG2(EFIFO_LOG2),
          .TS_W      (TS_W)
      ) u_efifo (
          .clk      (clk),
          .rst      (rst),
          .timebase (timebase),
          .step_up  (step_up),
          .step_dn  (step_dn),
          .step_ab  (step_ab),
          .ev_index (ev_index),
          .en       (r2h_efifo_ctrl_en),
          .clear    (r2h_efifo_ctrl_clear),
          .thresh   (r2h_efifo_ctrl_thresh),
          .pop      (r2h_efifo_entry_rd),
          .entry    (h2r_efifo_entry),
          .pop_time (efifo_time),
          .level    (h2r_efifo_status_level),
          .ev_thresh(ev_efifo_thresh),
          .ev_ovf   (ev_efifo_ovf),
          .lost_incr(h2r_efifo_lost_incr)
      );

      assign h2r_efifo_time = zext_ts(efifo_time);
    end else begin : g_no_efifo
      wire unused_efifo = &{1'b0, step_ab, r2h_efifo_ctrl_en, r2h_efifo_ctrl_clear,
                            r2h_efifo_ctrl_thresh, r2h_efifo_entry_rd};
      assign h2r_efifo_entry        = 32'd0;
      assign h2r_efifo_time         = 32'd0;
      assign h2r_efifo_status_level = 9'd0;
      assign h2r_efifo_lost_incr    = 1'b0;
      assign ev_efifo_thresh        = 1'b0;
      assign ev_efifo_ovf           = 1'b0;
    end
  endgenerate

  // ---- events and interrupt --------------------------------------------------------------------------
  // EVENTS bits by their names in the map: each event's one-clock set strobe
  assign h2r_events_set[ENC_QEI_EVENTS_OVERFLOW]     = ev_overflow;
  assign h2r_events_set[ENC_QEI_EVENTS_UNDERFLOW]    = ev_underflow;
  assign h2r_events_set[ENC_QEI_EVENTS_INDEX]        = ev_index;
  assign h2r_events_set[ENC_QEI_EVENTS_PROBE]        = ev_probe;
  assign h2r_events_set[ENC_QEI_EVENTS_CMP]          = ev_cmp;
  assign h2r_events_set[ENC_QEI_EVENTS_QERR]         = ev_qerr;
  assign h2r_events_set[ENC_QEI_EVENTS_GLITCH]       = glitch_ab;
  assign h2r_events_set[ENC_QEI_EVENTS_DIR_CHANGE]   = ev_dir_change;
  assign h2r_events_set[ENC_QEI_EVENTS_STALL]        = ev_stall;
  assign h2r_events_set[ENC_QEI_EVENTS_SNAP_READY]   = ev_snap;
  assign h2r_events_set[ENC_QEI_EVENTS_PERIOD_READY] = ev_period;
  assign h2r_events_set[ENC_QEI_EVENTS_PERIOD_OVF]   = ev_period_ovf;
  assign h2r_events_set[ENC_QEI_EVENTS_EFIFO_THRESH] = ev_efifo_thresh;
  assign h2r_events_set[ENC_QEI_EVENTS_EFIFO_OVF]    = ev_efifo_ovf;

  reg irq_q;

  always @(posedge clk) begin
    if (rst) begin
      irq_q <= 1'b0;
    end else begin
      irq_q <= |(r2h_events & r2h_irq_en_en);
    end
  end

  assign irq_pend = irq_q;

endmodule

`default_nettype wire
