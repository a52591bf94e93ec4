// SPDX-License-Identifier: Apache-2.0
// enc_qei_snaptrig -- when to take a snapshot: a command, a rising edge of snap_in while
// enabled, or a unit timer. enc_qei has one per channel (SNAP_CTRL, SNAP_PERIOD) and one for the
// global snapshot of all channels (GSNAP_CTRL, GSNAP_PERIOD): the same circuit, so a global
// snapshot and a channel's own take their values in the same clock relative to their request.
//
// `req` is registered: high for one clock, the clock after the command, after the clock snap_in
// is first high, or after the timer's last tick. The unit timer counts down from PERIOD to 1
// (PERIOD 0 acts as 1) once per timebase tick and restarts when period_en rises and at each of
// its requests, so a request comes every PERIOD ticks. PERIOD and its "at most 1" test are taken
// into registers first (PERIOD acts one clock after it changes; Fmax: no arithmetic on the load
// path). TIMER = 0 leaves the timer out (period_en and period unused).
`default_nettype none

module enc_qei_snaptrig #(
    parameter integer TS_W  = 32,  // timebase width (checked by enc_qei)
    parameter integer TIMER = 1    // 1: with the unit timer, 0: without (checked by enc_qei)
) (
    input  wire            clk,
    input  wire            rst,        // synchronous, active high
    input  wire            tick,       // the timebase advances at the end of this clock
    input  wire            cmd,        // a snapshot now (a register write)
    input  wire            snap_in,    // synchronous strobe, its rising edge requests ...
    input  wire            in_en,      // ... while this is 1
    // verilator lint_off UNUSEDSIGNAL
    input  wire            period_en,  // the unit timer runs
    input  wire [TS_W-1:0] period,     // its period in ticks (0 acts as 1)
    // verilator lint_on UNUSEDSIGNAL
    output wire            req         // take the snapshot in this clock
);

  localparam [TS_W-1:0] TS_ONE  = {{(TS_W-1){1'b0}}, 1'b1};
  localparam [TS_W-1:0] TS_TWO  = {{(TS_W-2){1'b0}}, 2'b10};
  localparam [TS_W-1:0] TS_ZERO = {TS_W{1'b0}};

  wire unit_hit;

  generate
    if (TIMER != 0) begin : g_timer
      reg  [TS_W-1:0] unit_q;           // ticks left in this period, PERIOD .. 1
      reg             unit_last_q;      // unit_q <= 1: the next tick ends the period
      reg  [TS_W-1:0] unit_load_q;      // PERIOD
      reg             unit_load_last_q; // PERIOD <= 1 (0 acts as 1)

      assign unit_hit = period_en & tick & unit_last_q;

      always @(posedge clk) begin
        unit_load_q      <= period;
        unit_load_last_q <= (period[TS_W-1:1] == {(TS_W-1){1'b0}});
      end

      always @(posedge clk) begin
        if (rst) begin
          unit_q      <= TS_ZERO;
          unit_last_q <= 1'b1;
        end else if (~period_en | unit_hit) begin
          unit_q      <= unit_load_q;
          unit_last_q <= unit_load_last_q;
        end else if (tick) begin
          unit_q      <= unit_q - TS_ONE;
          unit_last_q <= (unit_q == TS_TWO);
        end
      end
    end else begin : g_no_timer
      wire unused_timer = &{1'b0, tick};
      assign unit_hit = 1'b0;
    end
  endgenerate

  reg snap_in_q;
  reg req_q;

  always @(posedge clk) begin
    if (rst) begin
      snap_in_q <= 1'b0;
      req_q     <= 1'b0;
    end else begin
      snap_in_q <= snap_in;
      req_q     <= cmd | (in_en & snap_in & ~snap_in_q) | unit_hit;
    end
  end

  assign req = req_q;

endmodule

`default_nettype wire
