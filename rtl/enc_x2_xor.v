// SPDX-License-Identifier: Apache-2.0
// enc_x2_xor -- Figure 15, the 2X count circuit: XOR edge detector.
//
// "The edge detection circuit shown in Figure 15 provides a pulse for each transition of channel
// A. The Exclusive OR gate toggles at twice the channel frequency of each channel, but when
// observed coincident with the negative slope of the edge detector output, its state corresponds
// to the direction of rotation." Here the edge detector is the synchronous compare of A with its
// previous sample, and the XOR A ^ B is observed on the same clock:
//   forward  00 -> 10 (A rises, B = 0) and 11 -> 01 (A falls, B = 1): A ^ B = 1 after the edge
//   reverse  10 -> 00 and 01 -> 11:                                   A ^ B = 0 after the edge
// One cnt_pulse per transition of A, up = A ^ B; a change of B alone gives none. The first sample
// after rst is the reference. Extra output `error` (not in Figure 15): both channels changed
// between two samples, so the direction of that A edge is unknown and the count may be wrong.
// Outputs are registered: latency 1 clock from the a/b sample. `up` is the XOR itself, sampled
// every clock: it gives the direction in the clock cnt_pulse is 1 (the U/D of the 74LS168 only
// matters while it counts) and is not held between counts.
`default_nettype none

module enc_x2_xor (
    input  wire clk,
    input  wire rst,        // synchronous, active high
    input  wire a,          // channel A, synchronous to clk
    input  wire b,          // channel B, synchronous to clk
    output wire cnt_pulse,  // one clock per transition of A
    output wire up,         // direction (valid with cnt_pulse): A ^ B at the edge, 1 = forward
    output wire error       // one clock when A and B changed together (count direction unknown)
);

  reg a_prev_q;
  reg b_prev_q;
  reg nref_q;   // 1 in the clock after rst: the previous-sample registers hold no real sample
  reg cnt_q;
  reg up_q;
  reg error_q;

  // Mapping notes (iCE40): the reference flag is kept inverted so that its D input is rst itself
  // (no LUT); rst is folded into the A-edge term, so cnt_q needs no reset of its own; error_q
  // takes the A-edge term as D and "B unchanged" as its synchronous reset (error = a_edge &
  // b changed, and rst clears it through a_edge). Three LUTs: a_edge, b_same, a ^ b.
  wire a_edge = ~rst & ~nref_q & (a ^ a_prev_q);
  wire b_same = (b == b_prev_q);

  always @(posedge clk) begin
    nref_q   <= rst;
    a_prev_q <= a;
    b_prev_q <= b;
    cnt_q    <= a_edge;
    up_q     <= rst ? 1'b0 : (a ^ b);
    error_q  <= b_same ? 1'b0 : a_edge;
  end

  assign cnt_pulse = cnt_q;
  assign up        = up_q;
  assign error     = error_q;

`ifdef FORMAL
  // ---- formal only (formal/enc_x2_xor.sby): invariants, asserts only -----------------------------
  // The port-level properties are in formal/enc_x2_xor_formal.v. These state invariants of the
  // registers, so that a parent's induction (enc_updown_buffer) can use them.
  reg f_rst_seen = 1'b0;  // a rst has happened: the registers are defined
  always @(posedge clk) begin
    if (rst) f_rst_seen <= 1'b1;
  end

  always @(*) begin
    if (f_rst_seen) begin
      if (nref_q) assert (!cnt_q && !up_q && !error_q);  // the clock after rst
      if (error_q) assert (cnt_q);  // an error is an A edge with B changed too
    end
  end
`endif

endmodule

`default_nettype wire
