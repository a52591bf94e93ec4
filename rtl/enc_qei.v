// SPDX-License-Identifier: Apache-2.0
// enc_qei -- the quadrature encoder interface peripheral behind a one-clock request/response
// port; enc_qei_wb (Wishbone B4 classic) and enc_qei_axil (AXI4-Lite) are thin bus adapters
// around it.
//
//   a_in, b_in  -> enc_conditioner_rt (CTRL.FILTER_LEN) --+
//   z_in, probe_in -> enc_conditioner_rt (same length) ---+-> enc_qei_core (decode, count, range,
//                                                         |   index, probe, compare)
//                                      enc_qei_timing ----+   timebase, snapshots, period, stall
//   req/resp <-> enc_qei_regs (generated from rtl/enc_qei.rdl) <-> configuration, state, events
//
// Z and probe_in go through their own synchronizer and filter of the same length as A and B, so
// the index lines up with the channels clock for clock. irq is registered: high from the clock
// after an enabled event is pending until the clock after it is cleared or disabled.
// Request/response port: see enc_qei_regs (response two clocks after the request).
//
// Build options (defaults: the contract's full peripheral):
//   PROFILE = 1     issue 12's peripheral: the timing unit (enc_qei_timing) is left out:
//                   TIMEBASE .. STALL_TIMEOUT read 0 and ignore writes (no bus error), PROBE_TIME
//                   reads 0, STATUS.STALLED and the STALL, SNAP_READY, PERIOD_READY and PERIOD_OVF
//                   events stay 0; CAPS.TIMING reads 0. PROFILE = 2 (default): everything.
//   FUNC_MASK       the count functions built, bit F for CTRL.FUNC value F (x4 = bit 0 .. x1_hyst
//                   = bit 8; default 511: all). With one bit set the function is fixed: CTRL.FUNC
//                   reads it and ignores writes, and the decode logic of the others is left out.
//                   With several, a CTRL.FUNC value outside the mask counts nothing.
`default_nettype none
`include "enc_params.vh"

module enc_qei #(
    parameter integer COUNT_W    = 32,  // counter width: 8 .. 64
    parameter integer TS_W       = 32,  // timebase / timestamp width: 16 .. 32
    parameter integer PROFILE    = 2,   // 2: full (with the timing unit), 1: counting only
    parameter integer FUNC_MASK  = 511  // count functions built: bit F = CTRL.FUNC value F: 1 .. 511
) (
    input  wire        clk,
    input  wire        rst,         // synchronous, active high
    input  wire        req_valid,   // one-clock request
    input  wire        req_write,   // 1 = write
    input  wire [7:0]  req_addr,    // byte address (bits 1:0 ignored)
    input  wire [31:0] req_wdata,
    input  wire [3:0]  req_wstrb,   // byte enables
    output wire        resp_valid,  // two clocks after req_valid (one request at a time)
    output wire [31:0] resp_rdata,
    output wire        resp_err,    // unmapped offset
    input  wire        a_in,        // encoder channel A, asynchronous
    input  wire        b_in,        // encoder channel B, asynchronous
    input  wire        z_in,        // index channel, asynchronous
    input  wire        probe_in,    // external latch input, asynchronous
    input  wire        snap_in,     // synchronous snapshot strobe
    output wire        irq,         // any enabled pending event
    output wire        cmp_out      // one-clock pulse on a compare match
);

  generate
    `ENC_CHECK_COUNT_W
    `ENC_CHECK_TS_W
    `ENC_CHECK_PROFILE
    `ENC_CHECK_FUNC_MASK
  endgenerate

  // PROFILE and FUNC_MASK as the register block's options
  localparam integer TIMING     = (PROFILE >= 2) ? 1 : 0;
  localparam integer FIXED_FUNC = (FUNC_MASK == 1)   ? 0 : (FUNC_MASK == 2)   ? 1 :
                                  (FUNC_MASK == 4)   ? 2 : (FUNC_MASK == 8)   ? 3 :
                                  (FUNC_MASK == 16)  ? 4 : (FUNC_MASK == 32)  ? 5 :
                                  (FUNC_MASK == 64)  ? 6 : (FUNC_MASK == 128) ? 7 :
                                  (FUNC_MASK == 256) ? 8 : -1;
  localparam [15:0] FUNC_MASK16 = FUNC_MASK[15:0];

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

  localparam [7:0] COUNT_W8 = COUNT_W[7:0];
  localparam [7:0] TS_W8    = TS_W[7:0];

  // ---- register block <-> core wiring -------------------------------------------------------------
  wire        ctrl_en, ctrl_swap_ab, ctrl_inv_a, ctrl_inv_b, ctrl_inv_z;
  wire [3:0]  ctrl_func;
  wire [1:0]  ctrl_range;
  wire [4:0]  ctrl_filter_len;
  wire [31:0] count_lo_rdata, count_hi_rdata, count_lo_wdata, count_hi_wdata;
  wire        count_lo_rd, count_lo_wr, count_hi_wr;
  wire        count_hi_rd_unused;
  wire [31:0] preset_lo, preset_hi, ceiling_lo, ceiling_hi, compare_lo, compare_hi;
  wire [1:0]  idx_action;
  wire        idx_oneshot, idx_edge, idx_gate_en, idx_gate_a, idx_gate_b, idx_arm;
  wire        probe_en, probe_edge, probe_once;
  wire [11:0] events, irq_en;
  wire [15:0] qerr_count_unused, glitch_count_unused;
  wire [15:0] tb_prescale;
  wire        snap_cmd, snap_in_en, snap_period_en, snap_edge;
  // verilator lint_off UNUSEDSIGNAL
  wire [31:0] snap_period, stall_timeout;  // (bits TS_W and up are always 0)
  // verilator lint_on UNUSEDSIGNAL
  wire        period_en, period_edge;
  wire [7:0]  period_n;

  // ---- conditioners -------------------------------------------------------------------------------
  wire a_c, b_c, z_c, probe_c, glitch_ab, valid_ab, glitch_zp_unused, valid_zp_unused;

  enc_conditioner_rt #(
      .MAX_FILTER_LEN(16)
  ) u_cond_ab (
      .clk       (clk),
      .rst       (rst),
      .filter_len(ctrl_filter_len),
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
      .filter_len(ctrl_filter_len),
      .a_in      (z_in),
      .b_in      (probe_in),
      .a         (z_c),
      .b         (probe_c),
      .glitch    (glitch_zp_unused),
      .valid     (valid_zp_unused)
  );

  // CTRL.FUNC as the core sees it: with several functions left out, the others count nothing
  // (15); with one (FIXED_FUNC) or all, the register block's CTRL.FUNC as it is.
  wire [3:0] func_eff = (FIXED_FUNC >= 0 || FUNC_MASK == 511 || FUNC_MASK16[ctrl_func]) ?
                        ctrl_func : 4'd15;

  // ---- core ---------------------------------------------------------------------------------------------
  wire [COUNT_W-1:0] count_q, idx_latch, probe_latch;
  wire [TS_W-1:0]    probe_time;
  wire [TS_W-1:0]    timebase;
  wire a_eff, b_eff, z_eff, dir, idx_armed, stopped, idx_disarm, probe_disarm;
  wire step_up, step_dn, applied_up, applied_dn, edge_any, edge_a_rise;
  wire ev_overflow, ev_underflow, ev_index, ev_probe, ev_cmp, ev_qerr, ev_dir_change;

  enc_qei_core #(
      .COUNT_W(COUNT_W),
      .TS_W   (TS_W)
  ) u_core (
      .clk           (clk),
      .rst           (rst),
      .a_c           (a_c),
      .b_c           (b_c),
      .z_c           (z_c),
      .probe_c       (probe_c),
      .valid         (valid_ab),
      .en            (ctrl_en),
      .swap_ab       (ctrl_swap_ab),
      .inv_a         (ctrl_inv_a),
      .inv_b         (ctrl_inv_b),
      .inv_z         (ctrl_inv_z),
      .func          (func_eff),
      .range         (ctrl_range),
      .preset        (zext_count_hi_lo(preset_hi, preset_lo)),
      .ceiling       (zext_count_hi_lo(ceiling_hi, ceiling_lo)),
      .compare       (zext_count_hi_lo(compare_hi, compare_lo)),
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
      .count_lo_rd   (count_lo_rd),
      .count_lo_wr   (count_lo_wr),
      .count_lo_wdata(count_lo_wdata),
      .count_hi_wr   (count_hi_wr),
      .count_hi_wdata(count_hi_wdata),
      .count_lo_rdata(count_lo_rdata),
      .count_hi_rdata(count_hi_rdata),
      .count         (count_q),
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

  // ---- timing: timebase, snapshots, period capture, stall ------------------------------------------
  wire [COUNT_W-1:0] snap_count;
  wire [TS_W-1:0]    snap_time, snap_edge_time, period;
  wire [31:0]        snap_delta, snap_edge_delta;
  wire               period_ovf_flag, period_dir_flag, stalled;
  wire               ev_snap, ev_period, ev_period_ovf, ev_stall;

  generate
    if (TIMING != 0) begin : g_timing
    enc_qei_timing #(
        .COUNT_W(COUNT_W),
        .TS_W   (TS_W)
    ) u_timing (
        .clk            (clk),
        .rst            (rst),
        .prescale       (tb_prescale),
        .edge_any       (edge_any),
        .edge_a_rise    (edge_a_rise),
        .step           (step_up | step_dn),
        .applied_up     (applied_up),
        .applied_dn     (applied_dn),
        .dir_change     (ev_dir_change),
        .count          (count_q),
        .snap_cmd       (snap_cmd),
        .snap_in        (snap_in),
        .snap_in_en     (snap_in_en),
        .snap_period_en (snap_period_en),
        .snap_edge      (snap_edge),
        .snap_period    (snap_period[TS_W-1:0]),
        .period_en      (period_en),
        .period_edge    (period_edge),
        .period_n       (period_n),
        .stall_timeout  (stall_timeout[TS_W-1:0]),
        .timebase       (timebase),
        .snap_count     (snap_count),
        .snap_time      (snap_time),
        .snap_edge_time (snap_edge_time),
        .snap_delta     (snap_delta),
        .snap_edge_delta(snap_edge_delta),
        .period         (period),
        .period_ovf_flag(period_ovf_flag),
        .period_dir_flag(period_dir_flag),
        .stalled        (stalled),
        .ev_snap        (ev_snap),
        .ev_period      (ev_period),
        .ev_period_ovf  (ev_period_ovf),
        .ev_stall       (ev_stall)
    );
    end else begin : g_no_timing
      wire unused_timing = &{1'b0, edge_any, edge_a_rise, step_up, step_dn, applied_up, applied_dn,
                             count_q, snap_cmd, snap_in, snap_in_en, snap_period_en, snap_edge, snap_period,
                             period_en, period_edge, period_n, stall_timeout, tb_prescale};
      assign timebase        = {TS_W{1'b0}};
      assign snap_count      = {COUNT_W{1'b0}};
      assign snap_time       = {TS_W{1'b0}};
      assign snap_edge_time  = {TS_W{1'b0}};
      assign snap_delta      = 32'd0;
      assign snap_edge_delta = 32'd0;
      assign period          = {TS_W{1'b0}};
      assign period_ovf_flag = 1'b0;
      assign period_dir_flag = 1'b0;
      assign stalled         = 1'b0;
      assign ev_snap         = 1'b0;
      assign ev_period       = 1'b0;
      assign ev_period_ovf   = 1'b0;
      assign ev_stall        = 1'b0;
    end
  endgenerate

  // verilator lint_off UNUSEDSIGNAL
  function [COUNT_W-1:0] zext_count_hi_lo;
    input [31:0] hi;
    input [31:0] lo;
    reg   [63:0] v;
    begin
      v = {hi, lo};
      zext_count_hi_lo = v[COUNT_W-1:0];
    end
  endfunction
  // verilator lint_on UNUSEDSIGNAL

  wire [63:0] idx_latch64   = zext_count(idx_latch);
  wire [63:0] probe_latch64 = zext_count(probe_latch);
  wire [63:0] snap_count64  = zext_count(snap_count);

  // ---- register block -------------------------------------------------------------------------------
  enc_qei_regs #(
      .TIMING    (TIMING),
      .FIXED_FUNC(FIXED_FUNC),
      .COUNT_W   (COUNT_W),
      .TS_W      (TS_W)
  ) u_regs (
      .clk                    (clk),
      .rst                    (rst),
      .req_valid              (req_valid),
      .req_write              (req_write),
      .req_addr               (req_addr),
      .req_wdata              (req_wdata),
      .req_wstrb              (req_wstrb),
      .resp_valid             (resp_valid),
      .resp_rdata             (resp_rdata),
      .resp_err               (resp_err),
      .caps_count_w           (COUNT_W8),
      .caps_ts_w              (TS_W8),
      .caps_index             (1'b1),
      .caps_probe             (1'b1),
      .caps_timing            (TIMING != 0),
      .ctrl_en                (ctrl_en),
      .ctrl_swap_ab           (ctrl_swap_ab),
      .ctrl_inv_a             (ctrl_inv_a),
      .ctrl_inv_b             (ctrl_inv_b),
      .ctrl_inv_z             (ctrl_inv_z),
      .ctrl_func              (ctrl_func),
      .ctrl_range             (ctrl_range),
      .ctrl_filter_len        (ctrl_filter_len),
      .status_a               (a_eff),
      .status_b               (b_eff),
      .status_z               (z_eff),
      .status_dir             (dir),
      .status_index_armed     (idx_armed),
      .status_stalled         (stalled),
      .status_stopped         (stopped),
      .status_valid           (valid_ab),
      .count_lo_rdata         (count_lo_rdata),
      .count_lo_rd            (count_lo_rd),
      .count_lo_wr            (count_lo_wr),
      .count_lo_wdata         (count_lo_wdata),
      .count_hi_rdata         (count_hi_rdata),
      .count_hi_rd            (count_hi_rd_unused),
      .count_hi_wr            (count_hi_wr),
      .count_hi_wdata         (count_hi_wdata),
      .preset_lo_value        (preset_lo),
      .preset_hi_value        (preset_hi),
      .ceiling_lo_value       (ceiling_lo),
      .ceiling_hi_value       (ceiling_hi),
      .compare_lo_value       (compare_lo),
      .compare_hi_value       (compare_hi),
      .index_ctrl_action      (idx_action),
      .index_ctrl_oneshot     (idx_oneshot),
      .index_ctrl_edge        (idx_edge),
      .index_ctrl_gate_en     (idx_gate_en),
      .index_ctrl_gate_a      (idx_gate_a),
      .index_ctrl_gate_b      (idx_gate_b),
      .index_ctrl_arm         (idx_arm),
      .index_ctrl_arm_hwclr   (idx_disarm),
      .index_latch_lo_value   (idx_latch64[31:0]),
      .index_latch_hi_value   (idx_latch64[63:32]),
      .probe_ctrl_en          (probe_en),
      .probe_ctrl_en_hwclr    (probe_disarm),
      .probe_ctrl_edge        (probe_edge),
      .probe_ctrl_once        (probe_once),
      .probe_latch_lo_value   (probe_latch64[31:0]),
      .probe_latch_hi_value   (probe_latch64[63:32]),
      .probe_time_value       (zext_ts(probe_time)),
      .events_overflow        (events[0]),
      .events_overflow_set    (ev_overflow),
      .events_underflow       (events[1]),
      .events_underflow_set   (ev_underflow),
      .events_index           (events[2]),
      .events_index_set       (ev_index),
      .events_probe           (events[3]),
      .events_probe_set       (ev_probe),
      .events_cmp             (events[4]),
      .events_cmp_set         (ev_cmp),
      .events_qerr            (events[5]),
      .events_qerr_set        (ev_qerr),
      .events_glitch          (events[6]),
      .events_glitch_set      (glitch_ab),
      .events_dir_change      (events[7]),
      .events_dir_change_set  (ev_dir_change),
      .events_stall           (events[8]),
      .events_stall_set       (ev_stall),
      .events_snap_ready      (events[9]),
      .events_snap_ready_set  (ev_snap),
      .events_period_ready    (events[10]),
      .events_period_ready_set(ev_period),
      .events_period_ovf      (events[11]),
      .events_period_ovf_set  (ev_period_ovf),
      .irq_en_en              (irq_en),
      .qerr_count_value       (qerr_count_unused),
      .qerr_count_value_incr  (ev_qerr),
      .glitch_count_value     (glitch_count_unused),
      .glitch_count_value_incr(glitch_ab),
      .timebase_value         (zext_ts(timebase)),
      .tb_prescale_prescale   (tb_prescale),
      .snap_ctrl_cmd          (snap_cmd),
      .snap_ctrl_in_en        (snap_in_en),
      .snap_ctrl_period_en    (snap_period_en),
      .snap_ctrl_edge         (snap_edge),
      .snap_period_value      (snap_period),
      .snap_count_lo_value    (snap_count64[31:0]),
      .snap_count_hi_value    (snap_count64[63:32]),
      .snap_time_value        (zext_ts(snap_time)),
      .snap_edge_time_value   (zext_ts(snap_edge_time)),
      .snap_delta_value       (snap_delta),
      .snap_edge_delta_value  (snap_edge_delta),
      .period_ctrl_en         (period_en),
      .period_ctrl_edge       (period_edge),
      .period_ctrl_n          (period_n),
      .period_ctrl_overflow   (period_ovf_flag),
      .period_ctrl_dir_change (period_dir_flag),
      .period_value           (zext_ts(period)),
      .stall_timeout_value    (stall_timeout)
  );

  // ---- interrupt ---------------------------------------------------------------------------------
  reg irq_q;

  always @(posedge clk) begin
    if (rst) begin
      irq_q <= 1'b0;
    end else begin
      irq_q <= |(events & irq_en);
    end
  end

  assign irq = irq_q;

endmodule

`default_nettype wire
