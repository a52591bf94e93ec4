// SPDX-License-Identifier: Apache-2.0
// enc_qei_timing -- the timing unit of one enc_qei channel: snapshots, period capture and stall
// detection (the velocity side of the peripheral: unit-time M, period T and timestamp M/T).
//
// Every time below is in ticks of the shared timebase (enc_qei_timebase: `timebase`, and `tick`
// in the clock before it advances). The core's edge and step pulses are
// registered on the way in (timing), so everything here sees the core one clock late, all alike:
// an edge's timestamp is the timebase in the clock after the count took it, and a snapshot holds
// the count register (`count`, which already includes the previous clock's step) with the edges
// and steps up to that same point. SNAP_CTRL.EDGE, PERIOD_CTRL.EDGE and SNAP_PERIOD act one
// clock after they change, PERIOD_CTRL.N two (registered on the way in: Fmax).
// Snapshot: a request (snap_req: the channel's own SNAP_CTRL request or a global snapshot, from
// enc_qei_snaptrig) latches in its clock:
//   SNAP_COUNT      the count register now (count)
//   SNAP_TIME       the timebase now
//   SNAP_EDGE_TIME  the timestamp of the last edge of the selected type (this clock's included)
//   SNAP_DELTA      the count function's steps since the previous snapshot (this clock's included)
//   SNAP_EDGE_DELTA the steps between the previous snapshot's last selected edge and this one's:
//                   `head` adds up, at each selected edge, the steps since the edge before
//                   (`tail` plus the edge's own step), and restarts at each snapshot
// Both deltas count the motion: every step of the count function while CTRL.EN = 1 (step_up /
// step_dn), whatever a COUNT write, an index preset or the range does to the count, so that a
// velocity across a preset or a range stop is the shaft's. They are 32-bit two's complement and
// wrap (2^31 steps between two snapshots).
// Period: while period_en, every period_n (0 acts as 1) selected edges the ticks since the edge
// that started the measurement go to PERIOD (timebase(end) - timebase(start)); the end edge starts
// the next one. A period_n lowered below the edges the measurement in progress has counted ends
// it at its next selected edge. The measurement's tick count saturates at all ones (overflow
// flag, PERIOD_OVF event when it saturates); the direction-change flag is set by a count step
// against the previous one inside the measurement (the start edge's own excluded, the end edge's
// included).
// Stall: no count step of the count function for stall_timeout ticks (0: off) raises the stall
// event once and sets `stalled` until the next step.
// PERIOD = 0 (PROFILE lean) leaves period capture and stall detection out: their outputs are 0.
`default_nettype none

module enc_qei_timing #(
    parameter integer COUNT_W = 32,  // counter width (checked by enc_qei)
    parameter integer TS_W    = 32,  // timebase width (checked by enc_qei)
    parameter integer PERIOD  = 1    // 1: period capture and stall detection, 0: without them
) (
    input  wire               clk,
    input  wire               rst,             // synchronous, active high
    input  wire [TS_W-1:0]    timebase,        // the shared timebase
    input  wire               tick,            // ... advances at the end of this clock
    // from the core, in the clock of the edge / step
    input  wire               edge_any,        // a valid quadrature transition
    input  wire               edge_a_rise,     // a rising edge of A
    input  wire               step_up,         // a +1 step of the count function (CTRL.EN = 1)
    input  wire               step_dn,         // a -1 step (never with step_up)
    input  wire               dir_change,      // a step against the previous step's direction
    input  wire [COUNT_W-1:0] count,           // the count register
    // snapshot
    input  wire               snap_req,        // take a snapshot in this clock
    input  wire               snap_edge,       // SNAP_CTRL.EDGE: 0 any edge, 1 A rising
    // period (PERIOD_CTRL)
    input  wire               period_en,
    input  wire               period_edge,     // 0 any edge, 1 A rising
    input  wire [7:0]         period_n,
    // stall
    input  wire [TS_W-1:0]    stall_timeout,
    // outputs
    output wire [COUNT_W-1:0] snap_count,
    output wire [TS_W-1:0]    snap_time,
    output wire [TS_W-1:0]    snap_edge_time,
    output wire [31:0]        snap_delta,
    output wire [31:0]        snap_edge_delta,
    output wire [TS_W-1:0]    period,
    output wire               period_ovf_flag,
    output wire               period_dir_flag,
    output wire               stalled,
    output wire               ev_snap,
    output wire               ev_period,
    output wire               ev_period_ovf,
    output wire               ev_stall
);

  localparam [TS_W-1:0] TS_ONE  = {{(TS_W-1){1'b0}}, 1'b1};
  localparam [TS_W-1:0] TS_ZERO = {TS_W{1'b0}};
  localparam [TS_W-1:0] TS_MAX  = {TS_W{1'b1}};
  // ---- inputs from the core, registered --------------------------------------------------------------
  // The edges come registered already chosen by SNAP_CTRL.EDGE / PERIOD_CTRL.EDGE (which thus act
  // a clock after they change), and the step (+1, -1 or 0: mv, dn) once for each of the three
  // step adders below: (* keep *) on their blocks keeps Yosys from merging the copies (Fmax: one
  // register driving all three adders' carry chains is a long net).
  reg sel_snap_q;  // an edge of type SNAP_CTRL.EDGE (0 any edge, 1 A rising)
  reg mv_d_q, dn_d_q;  // a step up or down (mv), down (dn): for delta_q's adder
  reg mv_t_q, dn_t_q;  // ... tail_q's
  reg mv_a_q, dn_a_q;  // ... acc_q's

  always @(posedge clk) begin
    if (rst) begin
      sel_snap_q <= 1'b0;
    end else begin
      sel_snap_q <= snap_edge ? edge_a_rise : edge_any;
    end
  end

  (* keep *) always @(posedge clk) begin
    mv_d_q <= ~rst & (step_up | step_dn);
    dn_d_q <= ~rst & step_dn;
  end

  (* keep *) always @(posedge clk) begin
    mv_t_q <= ~rst & (step_up | step_dn);
    dn_t_q <= ~rst & step_dn;
  end

  (* keep *) always @(posedge clk) begin
    mv_a_q <= ~rst & (step_up | step_dn);
    dn_a_q <= ~rst & step_dn;
  end

  // ---- snapshot ------------------------------------------------------------------------------------
  wire [TS_W-1:0] tb_q = timebase;
  wire        sel_snap  = sel_snap_q;
  // +1, -1 or 0 (step_up and step_dn never come together): straight from registers into
  // the adders' carry chains (Fmax)
  // x + 1, x - 1 or x (mv, dn: a step, down), by carry select: the low half's carry out picks the
  // high half with carry in 0 or 1 (two 16-bit chains side by side instead of one of 32; Fmax)
  function [31:0] step32;
    input [31:0] x;
    input        mv;
    input        dn;
    reg   [16:0] lo;
    reg   [15:0] hi_c0;
    // verilator lint_off UNUSEDSIGNAL
    reg   [16:0] hi_c1x;  // {hi + ... + 1, 1} (bit 0 unused)
    // verilator lint_on UNUSEDSIGNAL
    begin
      lo     = {1'b0, x[15:0]} + {1'b0, {15{dn}}, mv};
      hi_c0  = x[31:16] + {16{dn}};
      hi_c1x = {x[31:16], 1'b1} + {{16{dn}}, 1'b1};
      step32 = {lo[16] ? hi_c1x[16:1] : hi_c0, lo[15:0]};
    end
  endfunction

  reg  [31:0] delta_q;      // steps since the previous snapshot
  reg  [31:0] tail_q;       // steps since the last selected edge
  reg  [31:0] head_q;       // steps from the previous snapshot's last selected edge to the last one
  reg  [31:0] acc_q;        // head_q + tail_q, kept by its own adder (no adder chain for Fmax)
  reg  [TS_W-1:0] last_edge_q;  // timestamp of the last selected edge
  wire [31:0] delta_now = step32(delta_q, mv_d_q, dn_d_q);
  wire [31:0] tail_now  = sel_snap ? 32'd0 : step32(tail_q, mv_t_q, dn_t_q);
  wire [31:0] acc_now   = step32(acc_q, mv_a_q, dn_a_q);  // = head_q + tail_q + this step
  wire [31:0] head_now  = sel_snap ? acc_now : head_q;
  wire [TS_W-1:0] edge_now = sel_snap ? tb_q : last_edge_q;

  reg [COUNT_W-1:0] snap_count_q;
  reg [TS_W-1:0]    snap_time_q;
  reg [TS_W-1:0]    snap_edge_time_q;
  reg [31:0]        snap_delta_q;
  reg [31:0]        snap_edge_delta_q;

  always @(posedge clk) begin
    if (rst) begin
      delta_q           <= 32'd0;
      tail_q            <= 32'd0;
      head_q            <= 32'd0;
      acc_q             <= 32'd0;
      last_edge_q       <= TS_ZERO;
      snap_count_q      <= {COUNT_W{1'b0}};
      snap_time_q       <= TS_ZERO;
      snap_edge_time_q  <= TS_ZERO;
      snap_delta_q      <= 32'd0;
      snap_edge_delta_q <= 32'd0;
    end else begin
      tail_q      <= tail_now;
      last_edge_q <= edge_now;
      if (snap_req) begin
        delta_q           <= 32'd0;
        head_q            <= 32'd0;
        acc_q             <= tail_now;
        snap_count_q      <= count;
        snap_time_q       <= tb_q;
        snap_edge_time_q  <= edge_now;
        snap_delta_q      <= delta_now;
        snap_edge_delta_q <= head_now;
      end else begin
        delta_q <= delta_now;
        head_q  <= head_now;
        acc_q   <= acc_now;
      end
    end
  end

  // ---- period capture and stall detection (PERIOD) ---------------------------------------------------
  generate
    if (PERIOD != 0) begin : g_period
    reg sel_per_q;  // an edge of type PERIOD_CTRL.EDGE (registered like sel_snap_q)
    reg step_q, dir_change_q;

    always @(posedge clk) begin
      if (rst) begin
        sel_per_q    <= 1'b0;
        step_q       <= 1'b0;
        dir_change_q <= 1'b0;
      end else begin
        sel_per_q    <= period_edge ? edge_a_rise : edge_any;
        step_q       <= step_up | step_dn;
        dir_change_q <= dir_change;
      end
    end

    // ---- period ---------------------------------------------------------------------------------------
    // (n_last_q: n_q == PERIOD_CTRL.N - 1 as of two clocks ago, so a new N counts from the second
    // clock after the write; ticks_max_q: ticks_q == all ones; both registered flags: Fmax)
    wire       sel_per  = sel_per_q;
    reg        started_q, ovf_q, dir_q, ticks_max_q;
    reg [7:0]  n_q;
    reg [TS_W-1:0] ticks_q;
    reg [TS_W-1:0] period_q;
    reg        period_ovf_q, period_dir_q;

    reg        n_last_q;
    wire       n_last   = n_last_q;
    wire capture  = period_en & started_q & sel_per & n_last;
    wire saturate = period_en & started_q & ~(sel_per & n_last) & tick & ticks_max_q;

    wire [7:0] per_last_d = (period_n == 8'd0) ? 8'd0 : period_n - 8'd1;
    reg  [7:0] n_d;  // n_q's next value

    always @(*) begin
      if (!period_en) begin
        n_d = n_q;
      end else if (sel_per & (~started_q | n_last)) begin
        n_d = 8'd0;
      end else if (started_q & sel_per) begin
        n_d = n_q + 8'd1;
      end else begin
        n_d = n_q;
      end
    end

    // N - 1 and N - 2 as registers (Fmax: PERIOD_CTRL.N reaches the flag a clock later): n_last_q
    // is set from the next value's case, each compared with them
    reg [7:0] per_last_q;       // N - 1 (0 for N = 0)
    reg [7:0] per_last_m1_q;    // ... - 1
    reg       per_last_zero_q;  // ... == 0

    always @(posedge clk) begin
      per_last_q      <= per_last_d;
      per_last_m1_q   <= per_last_d - 8'd1;
      per_last_zero_q <= (per_last_d == 8'd0);
    end

    // n_last_d: n_d >= per_last_q. At or above, not equal: a write that lowers N below the edges
    // the measurement in progress has counted ends it at the next selected edge (an equality
    // would miss the lowered N until n_q wraps, 256 edges later)
    reg n_last_d;

    always @(*) begin
      if (!period_en) begin
        n_last_d = (n_q >= per_last_q);
      end else if (sel_per & (~started_q | n_last)) begin
        n_last_d = per_last_zero_q;
      end else if (started_q & sel_per) begin
        n_last_d = per_last_zero_q | (n_q >= per_last_m1_q);  // (n_q + 1 >= N - 1)
      end else begin
        n_last_d = (n_q >= per_last_q);
      end
    end

    always @(posedge clk) begin
      if (rst) begin
        n_q      <= 8'd0;
        n_last_q <= 1'b1;
      end else begin
        n_q      <= n_d;
        n_last_q <= n_last_d;
      end
    end

    always @(posedge clk) begin
      if (rst) begin
        started_q    <= 1'b0;
        ovf_q        <= 1'b0;
        dir_q        <= 1'b0;
        ticks_q      <= TS_ZERO;
        ticks_max_q  <= 1'b0;
        period_q     <= TS_ZERO;
        period_ovf_q <= 1'b0;
        period_dir_q <= 1'b0;
      end else if (!period_en) begin
        started_q <= 1'b0;
      end else if (sel_per & (~started_q | n_last)) begin
        // a start edge (the first, or the end edge of the last measurement)
        started_q   <= 1'b1;
        ovf_q       <= 1'b0;
        dir_q       <= 1'b0;
        ticks_q     <= tick ? TS_ONE : TS_ZERO;
        ticks_max_q <= 1'b0;
        if (started_q) begin  // (capture)
          period_q     <= ovf_q ? TS_MAX : ticks_q;
          period_ovf_q <= ovf_q;
          period_dir_q <= dir_q | dir_change_q;
        end
      end else if (started_q) begin
        dir_q <= dir_q | dir_change_q;
        if (tick) begin
          if (ticks_max_q) begin
            ovf_q <= 1'b1;
          end else begin
            ticks_q     <= ticks_q + TS_ONE;
            ticks_max_q <= (ticks_q == (TS_MAX - TS_ONE));
          end
        end
      end
    end

    // ---- stall ----------------------------------------------------------------------------------------
    // counts down from STALL_TIMEOUT - 1 once per tick after each step (or a change of
    // STALL_TIMEOUT); the tick at 0 stalls (stall_zero_q: stall_q == 0, a registered flag). A new
    // STALL_TIMEOUT (and 0 = off) is seen one clock after it appears (registered compares: Fmax).
    reg  [TS_W-1:0] stall_q;
    reg  [TS_W-1:0] stall_timeout_q;
    reg             stalled_q, stall_zero_q;
    reg             stall_off;  // STALL_TIMEOUT was 0 in the last clock
    reg             stall_new;  // STALL_TIMEOUT changed at the last clock edge
    wire            stall_hit = ~stall_off & ~stall_new & ~stalled_q & ~step_q & tick & stall_zero_q;

    always @(posedge clk) begin
      if (rst) begin
        stall_timeout_q <= TS_ZERO;
        stall_off       <= 1'b1;
        stall_new       <= 1'b0;
      end else begin
        stall_timeout_q <= stall_timeout;
        stall_off       <= (stall_timeout == TS_ZERO);
        stall_new       <= (stall_timeout != stall_timeout_q);
      end
    end

    always @(posedge clk) begin
      if (rst) begin
        stall_q      <= TS_ZERO;
        stall_zero_q <= 1'b1;
        stalled_q    <= 1'b0;
      end else if (step_q | stall_off | stall_new) begin
        stall_q      <= stall_timeout - TS_ONE;
        stall_zero_q <= (stall_timeout == TS_ONE);
        stalled_q    <= 1'b0;
      end else if (tick & ~stalled_q) begin
        stall_q      <= stall_q - TS_ONE;
        stall_zero_q <= (stall_q == TS_ONE);
        stalled_q    <= stall_hit;
      end
    end

    assign period          = period_q;
    assign period_ovf_flag = period_ovf_q;
    assign period_dir_flag = period_dir_q;
    assign stalled         = stalled_q;
    assign ev_period       = capture;
    assign ev_period_ovf   = saturate & ~ovf_q;
    assign ev_stall        = stall_hit;
    end else begin : g_no_period
      wire unused_period = &{1'b0, tick, dir_change, period_en, period_edge, period_n,
                             stall_timeout};
      assign period          = TS_ZERO;
      assign period_ovf_flag = 1'b0;
      assign period_dir_flag = 1'b0;
      assign stalled         = 1'b0;
      assign ev_period       = 1'b0;
      assign ev_period_ovf   = 1'b0;
      assign ev_stall        = 1'b0;
    end
  endgenerate

  // ---- outputs -----------------------------------------------------------------------------------------
  assign snap_count      = snap_count_q;
  assign snap_time       = snap_time_q;
  assign snap_edge_time  = snap_edge_time_q;
  assign snap_delta      = snap_delta_q;
  assign snap_edge_delta = snap_edge_delta_q;
  assign ev_snap         = snap_req;

endmodule

`default_nettype wire
