// SPDX-License-Identifier: Apache-2.0
// A user's decoder under test, for the cocotbext-quadrature example: a two-flip-flop
// synchronizer and a 4X up/down counter (forward: 00 -> 10 -> 11 -> 01; A leads B).
`default_nettype none

module quad_counter (
    input  wire               clk,
    input  wire               rst,    // synchronous, active high
    input  wire               a_in,   // asynchronous channel A
    input  wire               b_in,   // asynchronous channel B
    output reg  signed [15:0] count   // 4X position since reset
);

  reg [1:0] meta_q, sync_q, prev_q;
  reg       ref_q;  // prev_q holds a real sample

  always @(posedge clk) begin
    if (rst) begin
      meta_q <= 2'b00;
      sync_q <= 2'b00;
      prev_q <= 2'b00;
      ref_q  <= 1'b0;
      count  <= 16'sd0;
    end else begin
      meta_q <= {a_in, b_in};
      sync_q <= meta_q;
      prev_q <= sync_q;
      ref_q  <= 1'b1;
      if (ref_q && ((sync_q[1] ^ prev_q[1]) != (sync_q[0] ^ prev_q[0])))
        count <= (sync_q[1] ^ prev_q[0]) ? count + 16'sd1 : count - 16'sd1;
    end
  end

endmodule

`default_nettype wire
