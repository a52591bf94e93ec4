// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_x2_xor (read by formal/enc_x2_xor.sby; `make formal`).
//
// Inputs are free on every clock; the first clock is a reset (rst is free afterwards). The
// wrapper's model of the contract, independent of the RTL:
//   f_prev, f_ref  the previous {a, b} sample and whether it is a real one (not the first after rst)
//   f_pos          the abstract 2X position: +1 per forward valid transition of A, -1 per reverse
//                  one (B unchanged); B alone and illegal changes (both channels) ignored
//   f_cnt          the sum of the circuit's pulses (+1 up, -1 down)
// Proven (k-induction):
//   - one cnt_pulse per transition of A (both edges), one clock after the sample; none for B alone
//   - up = A ^ B after the edge (Figure 15); for a valid A transition that is its direction
//   - error exactly when A and B changed in the same sample (the RTL header), and only with a count
//   - f_cnt (this clock's pulse included) - f_pos changes only in a clock with error: every
//     miscount is flagged, and without errors since rst the count is the 2X position exactly
//   - nothing counted on the first sample after rst; all outputs 0 the clock after rst
`default_nettype none

module enc_x2_xor_formal (
    input wire clk,
    input wire rst,
    input wire a,
    input wire b
);

  wire cnt_pulse;
  wire up;
  wire error;

  enc_x2_xor dut (
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
  reg  [7:0] f_off = 8'd0;  // (count - position) at the previous clock
  reg        f_clean = 1'b0;  // no error since rst

  wire [1:0] f_cur = {a, b};
  wire       f_a_changed = f_ref & (a ^ f_prev[1]);
  wire       f_b_changed = f_ref & (b ^ f_prev[0]);
  wire       f_a_valid = f_a_changed & ~f_b_changed;  // a valid transition of A
  // forward: 00 -> 10 -> 11 -> 01 -> 00, the next state of {a, b} is {~b, a}
  wire       f_fwd = (f_cur == {~f_prev[0], f_prev[1]});
  wire [7:0] f_pulse = cnt_pulse ? (up ? 8'd1 : 8'hff) : 8'd0;
  wire [7:0] f_off_now = f_cnt + f_pulse - f_pos;

  always @(posedge clk) begin
    f_prev <= f_cur;
    f_ref  <= ~rst;
    if (rst) begin
      f_pos   <= 8'd0;
      f_cnt   <= 8'd0;
      f_off   <= 8'd0;
      f_clean <= 1'b1;
    end else begin
      if (f_a_valid) f_pos <= f_fwd ? f_pos + 8'd1 : f_pos - 8'd1;
      f_cnt <= f_cnt + f_pulse;
      f_off <= f_off_now;
      if (error) f_clean <= 1'b0;
    end
  end

  // ---- properties ------------------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid) begin
      if (error) assert (cnt_pulse);
      if (!error) assert (f_off_now == f_off);
      if (f_clean && !error) assert (f_cnt + f_pulse == f_pos);
    end
  end

  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (!cnt_pulse && !error && !up);
      end else begin
        assert (cnt_pulse == $past(f_a_changed));
        assert (error == $past(f_a_changed && f_b_changed));
        if (cnt_pulse) assert (up == $past(a ^ b));
        if (cnt_pulse && !error) assert (up == $past(f_fwd));
      end
    end
    if (f_past2_valid && $past(rst, 2) && !$past(rst)) assert (!cnt_pulse && !error);
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid) begin
      cover (cnt_pulse && up && $past(a));  // forward, A rising
      cover (cnt_pulse && up && !$past(a));  // forward, A falling
      cover (cnt_pulse && !up && $past(a));  // reverse, A rising
      cover (cnt_pulse && !up && !$past(a));  // reverse, A falling
      cover (!$past(rst) && $past(f_b_changed && !f_a_changed));  // B alone: no count
      cover (error);
      cover (error && up);
      cover (f_clean && f_pos == 8'd4);  // two forward cycles, counted exactly
      cover (f_clean && f_pos == 8'hfe);  // one reverse cycle
      cover (!f_clean && f_off_now == 8'd1);  // a miscount, flagged by error
      cover (f_past2_valid && $past(rst, 2) && !$past(rst) && $past(a));  // reference A=1
    end
  end

endmodule

`default_nettype wire
