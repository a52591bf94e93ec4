// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_updown_buffer (read by formal/enc_updown_buffer.sby; `make formal`).
//
// a_in, b_in and hold are free on every clock; the first clock is a reset, rst is free
// afterwards. Proven here, at the ports (k-induction):
//   - rd_data never moves while hold is high (the clock before), whatever the count does
//   - with hold low the clock before, rd_data is the count of the clock before; so it has caught
//     up 2 clocks after hold falls: if the count stood still meanwhile, rd_data == count
//   - count and rd_data are 0 the clock after rst
//   - every digit of count stays in 0 .. MODULUS-1; the count moves by at most one
//     (mod MODULUS**DIGITS, digit by digit) per clock
// Proven by the asserts inside the RTL (`ifdef FORMAL), re-checked in this proof:
//   - rtl/enc_updown_buffer.v: the count tracks the 2X position of the conditioned channels, an
//     A transition with B changed too counts as Figure 15's XOR says and pulses error; rco_n is
//     low exactly while a count wraps the counter
//   - rtl/enc_x2_xor.v, rtl/enc_conditioner.v: their register invariants
`default_nettype none

module enc_updown_buffer_formal #(
    parameter integer DIGITS = 4,
    parameter integer MODULUS = 10,
    parameter integer FILTER_LEN = 3
) (
    input wire clk,
    input wire rst,
    input wire a_in,
    input wire b_in,
    input wire hold
);

  localparam integer W = 4 * DIGITS;
  localparam [3:0] MAX = MODULUS - 1;

  wire [W-1:0] count;
  wire [W-1:0] rd_data;
  wire         glitch;
  wire         error;
  wire         rco_n;

  enc_updown_buffer #(
      .DIGITS    (DIGITS),
      .MODULUS   (MODULUS),
      .FILTER_LEN(FILTER_LEN)
  ) dut (
      .clk    (clk),
      .rst    (rst),
      .a_in   (a_in),
      .b_in   (b_in),
      .hold   (hold),
      .count  (count),
      .rd_data(rd_data),
      .glitch (glitch),
      .error  (error),
      .rco_n  (rco_n)
  );

  reg f_past_valid = 1'b0;
  reg f_past2_valid = 1'b0;
  always @(posedge clk) begin
    f_past_valid  <= 1'b1;
    f_past2_valid <= f_past_valid;
  end

  always @(*) begin
    if (!f_past_valid) assume (rst);
  end

  // digits +1 (up) or -1 (down) modulo MODULUS**DIGITS, digit 0 least significant
  function [W-1:0] f_step;
    input [W-1:0] digits;
    input up_dir;
    integer k;
    reg carry;
    begin
      f_step = digits;
      carry  = 1'b1;
      for (k = 0; k < DIGITS; k = k + 1) begin
        if (carry) begin
          if (up_dir) begin
            if (digits[4*k+:4] == MAX) f_step[4*k+:4] = 4'd0;
            else begin
              f_step[4*k+:4] = digits[4*k+:4] + 4'd1;
              carry = 1'b0;
            end
          end else begin
            if (digits[4*k+:4] == 4'd0) f_step[4*k+:4] = MAX;
            else begin
              f_step[4*k+:4] = digits[4*k+:4] - 4'd1;
              carry = 1'b0;
            end
          end
        end
      end
    end
  endfunction

  wire [W-1:0] f_top = {DIGITS{MAX}};  // MODULUS**DIGITS - 1
  reg  [W-1:0] f_count_q = {W{1'b0}};
  always @(posedge clk) f_count_q <= count;

  // ---- properties ------------------------------------------------------------------------------
  integer k;
  always @(*) begin
    if (f_past_valid) begin
      for (k = 0; k < DIGITS; k = k + 1) assert (count[4*k+:4] <= MAX);
    end
  end

  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (count == {W{1'b0}} && rd_data == {W{1'b0}});
      end else begin
        if ($past(hold)) assert (rd_data == $past(rd_data));
        else assert (rd_data == $past(count));
        assert (count == f_count_q || count == f_step(f_count_q, 1'b1) ||
                count == f_step(f_count_q, 1'b0));
      end
    end
    if (f_past2_valid && !$past(rst) && !$past(rst, 2) && !$past(hold) && !$past(hold, 2) &&
        count == $past(count)) begin
      assert (rd_data == count);
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past2_valid && !$past(rst)) begin
      cover (count == 2);  // counting up ...
      cover (count == f_step(f_top, 1'b0));  // ... and down
      cover (count == {W{1'b0}} && f_count_q == f_top);  // wrap up
      cover (count == f_top && f_count_q == {W{1'b0}});  // wrap down
      cover (!rco_n);
      cover ($past(hold) && count != $past(count));  // counting under a frozen rd_data ...
      cover ($past(hold, 2) && !$past(hold) && rd_data != $past(rd_data));  // ... catching up
      cover (glitch || FILTER_LEN == 1);  // (FILTER_LEN 1 has no glitch)
      cover (error);
    end
  end

  // a carry and a borrow between digits (not the wrap): ten counts, about 10 * FILTER_LEN clocks
  generate
    if (FILTER_LEN <= 3) begin : g_carry_covers
      always @(posedge clk) begin
        if (f_past2_valid && !$past(rst)) begin
          cover (count[3:0] == 4'd0 && f_count_q[3:0] == MAX && count != {W{1'b0}});
          cover (count[3:0] == MAX && f_count_q[3:0] == 4'd0 && count != f_top);
        end
      end
    end
  endgenerate

endmodule

`default_nettype wire
