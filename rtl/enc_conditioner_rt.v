// SPDX-License-Identifier: Apache-2.0
// enc_conditioner_rt -- the input synchronizer and digital filter of the two encoder channels,
// with the filter length as a run-time input (enc_qei's CTRL.FILTER_LEN). enc_conditioner, the
// contract's fixed-length block, is this module with the length tied to its FILTER_LEN.
//
// Per channel (enc_filter_rt):
//   a_in -> two flip-flops (synchronizer) -> filter_len-sample filter -> a
// The filter output takes a new level only after the synchronized input has shown that level on
// filter_len consecutive clocks; a level that goes back sooner is rejected and `glitch` pulses
// for one clock (never with filter_len = 1). An output changes filter_len + 1 clocks after the
// rising edge that first samples the new level. `valid` rises filter_len + 2 clocks after rst
// falls (hold a decoder behind this block in reset while it is low).
// SETTLE = 0 leaves the settling chain out (valid is then 1): for a caller that knows when every
// input has settled from one shared chain (the shared engine's lanes, whose filter length cannot
// change before the chain's reset value has settled).
// filter_len is clamped to 1 .. MAX_FILTER_LEN (0 acts as 1) through a register, so a new value
// acts from the clock after it appears (the reset value is in place when rst falls, so the
// timings above hold from reset). It may change at any time: a
// candidate level already seen on at least the new length of samples is accepted at the next
// differing sample, so a change never loses or invents a level.
`default_nettype none
`include "enc_params.vh"

module enc_conditioner_rt #(
    parameter integer MAX_FILTER_LEN = 16,  // largest filter_len used: 1 .. 16 (sizes the counters)
    parameter integer SETTLE         = 1    // 1: valid from the settling chain; 0: no chain, valid = 1
) (
    input  wire       clk,
    input  wire       rst,         // synchronous, active high
    input  wire [4:0] filter_len,  // samples a new level must persist: 1 .. MAX_FILTER_LEN
    input  wire       a_in,        // channel A, asynchronous
    input  wire       b_in,        // channel B, asynchronous
    output wire       a,           // conditioned channel A, synchronous to clk
    output wire       b,           // conditioned channel B, synchronous to clk
    output wire       glitch,      // one-clock pulse per rejected level (either channel)
    output wire       valid        // a and b reflect the inputs (filter_len + 2 clocks after rst)
);

  generate
    `ENC_CHECK_MAX_FILTER_LEN
  endgenerate

  // Run-length counter: consecutive samples (so far) that differ from the accepted level.
  localparam integer CW = (MAX_FILTER_LEN <= 2) ? 1 : (MAX_FILTER_LEN <= 4) ? 2 :
                          (MAX_FILTER_LEN <= 8) ? 3 : 4;
  localparam integer MAX_LAST_INT = MAX_FILTER_LEN - 1;
  localparam [4:0] MAX_LAST5 = MAX_LAST_INT[4:0];

  // last = clamp(filter_len, 1, MAX_FILTER_LEN) - 1: a differing sample seen with run >= last
  // accepts. The clamp is registered (Fmax; updated in every clock, reset or not), so a new
  // filter_len acts from the clock after it appears.
  wire [4:0] len_m1  = (filter_len == 5'd0) ? 5'd0 : filter_len - 5'd1;
  reg  [4:0] last5_q;
  wire [4:0] last5   = last5_q;
  wire [CW-1:0] last = last5[CW-1:0];

  always @(posedge clk) begin
    last5_q <= (len_m1 > MAX_LAST5) ? MAX_LAST5 : len_m1;
  end

  // ---- synchronizer and filter of each channel ------------------------------------------------
  wire [1:0] level;   // {b, a} accepted levels
  wire [1:0] reject;  // this clock a candidate level went back before it was accepted

  enc_filter_rt #(
      .CW      (CW),
      .MAX_LAST(MAX_LAST_INT)
  ) u_filter_a (
      .clk   (clk),
      .rst   (rst),
      .last  (last),
      .in    (a_in),
      .level (level[0]),
      .reject(reject[0])
  );

  enc_filter_rt #(
      .CW      (CW),
      .MAX_LAST(MAX_LAST_INT)
  ) u_filter_b (
      .clk   (clk),
      .rst   (rst),
      .last  (last),
      .in    (b_in),
      .level (level[1]),
      .reject(reject[1])
  );

  // ---- settling after reset: 2 synchronizer clocks + filter_len filter clocks ------------------
  // A chain of flip-flops filling with ones after rst; valid is the stage filter_len + 1.
  generate
    if (SETTLE != 0) begin : g_settle
      localparam integer SETTLE_N = MAX_FILTER_LEN + 2;
      reg [SETTLE_N-1:0] settle_q;

      always @(posedge clk) begin
        if (rst) begin
          settle_q <= {SETTLE_N{1'b0}};
        end else begin
          settle_q <= {settle_q[SETTLE_N-2:0], 1'b1};
        end
      end

      // valid = settle_q[last5 + 2] (1 from the clock after edge filter_len + 2 after rst, the clock
      // the filter first shows the inputs), taken as a register of settle_q[last5 + 1] (the same
      // value, one stage on: the tap's multiplexer is not in front of the decoders' reset; Fmax). A
      // loop, so the index needs no width of its own.
      reg        tap_d;
      reg        valid_d;
      integer    i;

      always @(*) begin
        tap_d = 1'b0;
        for (i = 0; i < SETTLE_N - 1; i = i + 1) begin
          if (last5 == i[4:0]) tap_d = settle_q[i + 1];
        end
      end

      always @(posedge clk) begin
        if (rst) begin
          valid_d <= 1'b0;
        end else begin
          valid_d <= tap_d;
        end
      end

      assign valid = valid_d;
    end else begin : g_no_settle
      wire unused_last5 = &{1'b0, last5};  // (the filters use the low bits only)
      assign valid = 1'b1;
    end
  endgenerate

  reg glitch_q;

  always @(posedge clk) begin
    if (rst) begin
      glitch_q <= 1'b0;
    end else begin
      glitch_q <= |reject;
    end
  end

  assign a      = level[0];
  assign b      = level[1];
  assign glitch = glitch_q;

`ifdef FORMAL
  // ---- formal only (formal/enc_conditioner_rt.sby, enc_conditioner.sby): invariants, asserts
  // only. The port-level properties are in the formal wrappers. These bound the registers to
  // their reachable values so that induction (here and in a parent) needs no long traces: the
  // filter length stays below MAX_FILTER_LEN (each filter's run counter: enc_filter_rt), and the
  // settling chain fills with ones from bit 0 (a thermometer code).
  reg f_rst_seen = 1'b0;  // a rst has happened: the registers are defined
  always @(posedge clk) begin
    if (rst) f_rst_seen <= 1'b1;
  end

  always @(*) begin
    if (f_rst_seen) begin
      assert (last5_q <= MAX_LAST5);
    end
  end

  generate
    if (SETTLE != 0) begin : g_settle_invariant
      always @(*) begin
        if (f_rst_seen) begin
          assert (((g_settle.settle_q >> 1) & ~g_settle.settle_q) == {(MAX_FILTER_LEN + 2){1'b0}});
        end
      end
    end
  endgenerate
`endif

endmodule

`default_nettype wire
