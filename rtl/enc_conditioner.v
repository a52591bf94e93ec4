// SPDX-License-Identifier: Apache-2.0
// enc_conditioner -- input synchronizer and digital filter for the two encoder channels.
//
// Does in logic what the note asks of the 74LS14 Schmitt buffer in front of every counting
// circuit (section CIRCUITS): it makes the asynchronous A and B outputs of the HEDS-5000 safe to
// sample and rejects short pulses. Per channel:
//   a_in -> two flip-flops (synchronizer) -> FILTER_LEN-sample filter -> a
// The filter output takes a new level only after the synchronized input has shown that level on
// FILTER_LEN consecutive clocks. A level that goes back before FILTER_LEN samples is rejected and
// `glitch` pulses for one clock. Both channels use identical paths, so their relative timing is
// kept to the clock: an output changes FILTER_LEN + 1 clocks after the rising edge that first
// samples the new level (so 1 + FILTER_LEN to 2 + FILTER_LEN clock periods after the input edge).
// With FILTER_LEN = 1 the filter is a plain register and glitch stays 0. The circuit is
// enc_conditioner_rt (the run-time-length conditioner inside enc_qei) with its length tied to
// FILTER_LEN: one implementation, proven with its length free (formal/enc_conditioner_rt.sby).
// Extra output `valid` (not in the contract's list): rst forces a and b to 0, and the outputs
// show the real input levels only FILTER_LEN + 2 clocks after rst falls; `valid` rises on that
// clock. A decoder behind the conditioner should be held in reset until then (rst | ~valid), or
// it would take 00 as its reference state and count the jump to the real state.
`default_nettype none
`include "enc_params.vh"

module enc_conditioner #(
    parameter integer FILTER_LEN = 3  // samples a new level must persist: 1 .. 16 (1 = no filter)
) (
    input  wire clk,
    input  wire rst,     // synchronous, active high
    input  wire a_in,    // channel A, asynchronous
    input  wire b_in,    // channel B, asynchronous
    output wire a,       // conditioned channel A, synchronous to clk
    output wire b,       // conditioned channel B, synchronous to clk
    output wire glitch,  // one-clock pulse per rejected level (either channel)
    output wire valid    // a and b reflect the inputs (FILTER_LEN + 2 clocks after rst)
);

  generate
    `ENC_CHECK_FILTER_LEN
  endgenerate

  // The circuit is enc_conditioner_rt's, with the length fixed: its run counter and settling chain
  // are then exactly as wide as this length needs, and the length's register is a constant.
  localparam [4:0] LEN5 = FILTER_LEN[4:0];

  enc_conditioner_rt #(
      .MAX_FILTER_LEN(FILTER_LEN)
  ) u_cond (
      .clk       (clk),
      .rst       (rst),
      .filter_len(LEN5),
      .a_in      (a_in),
      .b_in      (b_in),
      .a         (a),
      .b         (b),
      .glitch    (glitch),
      .valid     (valid)
  );

endmodule

`default_nettype wire
