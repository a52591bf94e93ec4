// SPDX-License-Identifier: Apache-2.0
// ls168 -- a 74LS168 (decade) / 74LS169 (binary) synchronous 4-bit up/down counter.
//
// The counter stage of the note's Figures 15 and 17 ("an Up/Down counter such as the 74LS168"),
// modelled pin for pin with active-low controls as on the part:
//   load_n low          q <= d at the clock (synchronous, highest priority)
//   enp_n = ent_n = 0   count: up when up = 1 (MAX -> 0), down otherwise (0 -> MAX)
//   otherwise           hold
//   rco_n               combinational: low when ent_n is low and q = MAX counting up, or
//                       q = 0 counting down. It ignores enp_n, so stages cascade RCO_n -> ENT_n.
// MAX = MODULUS - 1. The part has no reset pin; load zeros to clear.
//
// Out-of-range states (10..15 in decade mode, reachable only by a load): counting up from
// q > MAX gives 0, counting down from q > MAX gives MAX, so the counter rejoins 0..MAX on the
// first counting clock in either direction (the contract allows two). No rco_n in those states.
`default_nettype none
`include "enc_params.vh"

module ls168 #(
    parameter integer MODULUS = 10  // 10: 'LS168 decade, 16: 'LS169 binary; nothing else
) (
    input  wire       clk,
    input  wire       load_n,  // synchronous parallel load, active low
    input  wire       enp_n,   // count enable (parallel), active low
    input  wire       ent_n,   // count enable (trickle), active low; gates rco_n
    input  wire       up,      // 1: count up, 0: count down
    input  wire [3:0] d,       // parallel load data
    output wire [3:0] q,       // count
    output wire       rco_n    // ripple carry out, active low
);

  generate
    `ENC_CHECK_MODULUS
  endgenerate

  localparam integer MAX_INT = MODULUS - 1;
  localparam [3:0] MAX = MAX_INT[3:0];  // top state: 9 or 15

  reg  [3:0] q_q;  // no reset, like the part: load zeros to clear
  reg  [3:0] q_d;

  wire       count_en = ~enp_n & ~ent_n;
  wire       at_max = (q_q == MAX);
  wire       at_zero = (q_q == 4'd0);
  wire       above_max;  // only reachable by loading 10..15 in decade mode

  generate
    if (MODULUS == 16) begin : g_binary
      assign above_max = 1'b0;
    end else begin : g_decade
      assign above_max = (q_q > MAX);
    end
  endgenerate

  always @(*) begin
    q_d = q_q;
    if (!load_n) begin
      q_d = d;
    end else if (count_en) begin
      if (up) begin
        q_d = (at_max || above_max) ? 4'd0 : q_q + 4'd1;
      end else begin
        q_d = (at_zero || above_max) ? MAX : q_q - 4'd1;
      end
    end
  end

  always @(posedge clk) begin
    q_q <= q_d;
  end

  assign q     = q_q;
  assign rco_n = ~(~ent_n & (up ? at_max : at_zero));

endmodule

`default_nettype wire
