// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_x4_decoder (read by formal/enc_x4_decoder.sby; `make formal`).
//
// Inputs are free on every clock; the only assumption is that the first clock is a reset (rst is
// free afterwards, so resets anywhere are covered). The wrapper keeps its own model of the
// contract, independent of the RTL:
//   f_prev  the previous {a, b} sample, f_ref: it is a real sample (not the first after rst)
//   f_pos   the abstract 4X position: +1 per forward valid transition, -1 per reverse one,
//           illegal changes (both channels) ignored; 0 at rst
//   f_cnt   the decoder's count: the sum of its pulses (+1 up, -1 down) seen so far
// Proven (k-induction):
//   - at most one of cnt_pulse / error per clock
//   - cnt_pulse exactly for a valid transition, error exactly for an illegal one (both channels
//     changed), one clock after the sample; up = the direction of the valid transition
//   - f_cnt (including this clock's pulse) == f_pos at all times
//   - nothing counted (no pulse, no error) on the first sample after rst; outputs 0 after rst
// Equality is checked on 8-bit registers; both sides move by at most 1 per clock, so equality
// modulo 256 at every clock is equality.
`default_nettype none

module enc_x4_decoder_formal (
    input wire clk,
    input wire rst,
    input wire a,
    input wire b
);

  wire cnt_pulse;
  wire up;
  wire error;

  enc_x4_decoder dut (
      .clk      (clk),
      .rst      (rst),
      .a        (a),
      .b        (b),
      .cnt_pulse(cnt_pulse),
      .up       (up),
      .error    (error)
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

  // ---- model -----------------------------------------------------------------------------------
  reg  [1:0] f_prev = 2'b00;
  reg        f_ref = 1'b0;
  reg  [7:0] f_pos = 8'd0;
  reg  [7:0] f_cnt = 8'd0;

  wire [1:0] f_cur = {a, b};
  wire       f_a_changed = a ^ f_prev[1];
  wire       f_b_changed = b ^ f_prev[0];
  wire       f_valid = f_ref & (f_a_changed ^ f_b_changed);  // exactly one channel changed
  wire       f_illegal = f_ref & f_a_changed & f_b_changed;  // both changed
  // forward: 00 -> 10 -> 11 -> 01 -> 00, the next state of {a, b} is {~b, a}
  wire       f_fwd = (f_cur == {~f_prev[0], f_prev[1]});
  wire [7:0] f_pulse = cnt_pulse ? (up ? 8'd1 : 8'hff) : 8'd0;

  always @(posedge clk) begin
    f_prev <= f_cur;
    f_ref  <= ~rst;
    if (rst) begin
      f_pos <= 8'd0;
      f_cnt <= 8'd0;
    end else begin
      if (f_valid) f_pos <= f_fwd ? f_pos + 8'd1 : f_pos - 8'd1;
      f_cnt <= f_cnt + f_pulse;
    end
  end

  // ---- properties ------------------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid) begin
      assert (!(cnt_pulse && error));
      assert (f_cnt + f_pulse == f_pos);
    end
  end

  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (!cnt_pulse && !error && !up);
      end else begin
        assert (cnt_pulse == $past(f_valid));
        assert (error == $past(f_illegal));
        if (cnt_pulse) assert (up == $past(f_fwd));
      end
    end
    // the first sample after rst is the reference: not counted, no error
    if (f_past2_valid && $past(rst, 2) && !$past(rst)) assert (!cnt_pulse && !error);
  end

  // ---- covers: every property's situation is reached -----------------------------------------
  always @(posedge clk) begin
    cover (f_past_valid && cnt_pulse && up);
    cover (f_past_valid && cnt_pulse && !up);
    cover (f_past_valid && error);
    cover (f_past_valid && error && f_pos == 8'd2);  // an illegal change after moving: the position is kept
    cover (f_past_valid && f_pos == 8'd4 && f_cnt == 8'd4);  // one full forward cycle
    cover (f_past_valid && f_pos == 8'hfc);  // one full reverse cycle
    // a first sample after rst that differs from the reset value 00, and is not counted
    cover (f_past2_valid && $past(rst, 2) && !$past(rst) && $past(a | b));
    // a count right after the reference sample
    cover (f_past2_valid && $past(rst, 2) && !$past(rst) && cnt_pulse == 1'b0 && f_valid);
    // reset in the middle of a count
    cover (f_past_valid && $past(cnt_pulse) && rst);
  end

endmodule

`default_nettype wire
