// SPDX-License-Identifier: Apache-2.0
// Test-only: the naive 1X counter the note warns about (the multiple-count problem). It counts on
// every rising edge of A, with B giving the direction, and has no hysteresis, so a shaft
// dithering about A's rising edge counts up again and again. The hysteresis test must fail on it.
`default_nettype none

module naive_x1 (
    input  wire clk,
    input  wire rst,
    input  wire a,
    input  wire b,
    output wire up_pulse,
    output wire dn_pulse
);

  reg a_prev_q;
  reg up_q;
  reg dn_q;

  always @(posedge clk) begin
    if (rst) begin
      a_prev_q <= 1'b0;
      up_q     <= 1'b0;
      dn_q     <= 1'b0;
    end else begin
      a_prev_q <= a;
      up_q     <= a & ~a_prev_q & ~b;
      dn_q     <= a & ~a_prev_q & b;
    end
  end

  assign up_pulse = up_q;
  assign dn_pulse = dn_q;

endmodule

`default_nettype wire
