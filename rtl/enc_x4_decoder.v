// SPDX-License-Identifier: Apache-2.0
// enc_x4_decoder -- 4X quadrature decode by look-up table, in hardware.
//
// The note's programmed-input decode (MICROPROCESSOR INTERFACE, DECODE ROUTINE): keep the
// previous state, and look up "the expected word for the next state in a clockwise rotation".
// If the present state is that word the shaft moved forward; if the previous state is the
// expected next word of the present one it moved back; if the state is unchanged nothing
// happened; anything else (both channels changed between two samples) is an illegal transition.
//   forward (A leads B): 00 -> 10 -> 11 -> 01 -> 00, so next_fwd({a, b}) = {~b, a}
// One cnt_pulse per valid transition (4 counts per cycle), up = 1 forward. An illegal transition
// gives one `error` pulse and no count. The first sample after rst is the reference state and
// is not counted. Outputs are registered: latency 1 clock from the a/b sample. `up` is the
// direction of the count in the clock cnt_pulse is 1 (like the U/D pin of a 74LS168, it only
// matters while counting; between counts it is not held).
`default_nettype none

module enc_x4_decoder (
    input  wire clk,
    input  wire rst,        // synchronous, active high
    input  wire a,          // channel A, synchronous to clk (from enc_conditioner)
    input  wire b,          // channel B, synchronous to clk
    output wire cnt_pulse,  // one clock per valid transition
    output wire up,         // direction of this count (valid with cnt_pulse): 1 = forward
    output wire error       // one clock per illegal transition (both channels changed)
);

  reg  [1:0] prev_q;  // {a, b} at the previous sample
  reg        ref_q;   // prev_q holds a real sample (cleared by rst)
  reg        cnt_q;
  reg        up_q;
  reg        error_q;

  // Which channels changed since the previous sample. Exactly one: a valid transition; both: an
  // illegal one. For a valid transition the look-up "present == next_fwd(previous)" reduces to
  // a == ~prev_b (with b == prev_a implied), so the direction is a ^ prev_b.
  wire       a_moved = a ^ prev_q[1];
  wire       b_moved = b ^ prev_q[0];

  always @(posedge clk) begin
    if (rst) begin
      prev_q  <= 2'b00;
      ref_q   <= 1'b0;
      cnt_q   <= 1'b0;
      up_q    <= 1'b0;
      error_q <= 1'b0;
    end else begin
      prev_q  <= {a, b};
      ref_q   <= 1'b1;
      cnt_q   <= ref_q & (a_moved ^ b_moved);
      up_q    <= a ^ prev_q[0];
      error_q <= ref_q & a_moved & b_moved;
    end
  end

  assign cnt_pulse = cnt_q;
  assign up        = up_q;
  assign error     = error_q;

`ifdef FORMAL
  // ---- formal only (formal/enc_x4_decoder.sby): invariants, asserts only -------------------------
  // The port-level properties are in formal/enc_x4_decoder_formal.v. These state invariants of
  // the registers, so that a parent's induction can use them.
  reg f_rst_seen = 1'b0;  // a rst has happened: the registers are defined
  always @(posedge clk) begin
    if (rst) f_rst_seen <= 1'b1;
  end

  always @(*) begin
    if (f_rst_seen) begin
      if (!ref_q) assert (prev_q == 2'b00 && !cnt_q && !up_q && !error_q);  // the clock after rst
      assert (!(cnt_q && error_q));
    end
  end
`endif

endmodule

`default_nettype wire
