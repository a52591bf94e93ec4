// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_x1_hysteresis (read by formal/enc_x1_hysteresis.sby; `make formal`).
//
// Inputs are free on every clock; the first clock is a reset (rst is free afterwards).
// Proven here, at the ports (k-induction):
//   - never up_pulse and dn_pulse in one clock
//   - a pulse only for a valid transition sampled the clock before, up_pulse only forward,
//     dn_pulse only in reverse (so a monotone run never pulses the other way)
//   - error exactly when both channels changed between two samples (the RTL header)
//   - nothing counted on the first sample after rst; all outputs 0 the clock after rst
// Proven by the asserts inside rtl/enc_x1_hysteresis.v (`ifdef FORMAL), which need a history
// (a shadow of p - 4n and of the dither) that a wrapper cannot link to the RTL state:
//   - |4n - p| <= 3 at all times (the contract asks <= 4), p the 4X position of the valid
//     transitions since rst, n = #up - #dn since rst, for any input sequence
//   - dither about one transition, however long, gives at most one pulse in total
// The wrapper keeps its own p and n for the covers (they show those situations are reached).
`default_nettype none

module enc_x1_hysteresis_formal (
    input wire clk,
    input wire rst,
    input wire a,
    input wire b
);

  wire up_pulse;
  wire dn_pulse;
  wire error;

  enc_x1_hysteresis dut (
      .clk     (clk),
      .rst     (rst),
      .a       (a),
      .b       (b),
      .up_pulse(up_pulse),
      .dn_pulse(dn_pulse),
      .error   (error)
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
  reg  [7:0] f_pos = 8'd0;  // p
  reg  [7:0] f_n = 8'd0;  // n before this clock's pulse
  reg  [3:0] f_dither = 4'd0;  // pulses since the last transition that was not prev <-> cur ...
  reg  [1:0] f_dpair_lo = 2'b00;  // ... between these two states
  reg  [1:0] f_dpair_hi = 2'b00;

  wire [1:0] f_cur = {a, b};
  wire       f_a_changed = f_ref & (a ^ f_prev[1]);
  wire       f_b_changed = f_ref & (b ^ f_prev[0]);
  wire       f_valid = f_a_changed ^ f_b_changed;
  wire       f_fwd = (f_cur == {~f_prev[0], f_prev[1]});
  wire [7:0] f_n_now = f_n + (up_pulse ? 8'd1 : 8'd0) - (dn_pulse ? 8'd1 : 8'd0);
  wire [7:0] f_e = f_pos - {f_n_now[5:0], 2'b00};  // p - 4n (for the covers)
  wire       f_same_pair = (f_prev == f_dpair_lo && f_cur == f_dpair_hi) ||
                           (f_prev == f_dpair_hi && f_cur == f_dpair_lo);

  always @(posedge clk) begin
    f_prev <= f_cur;
    f_ref  <= ~rst;
    if (rst) begin
      f_pos <= 8'd0;
      f_n <= 8'd0;
      f_dither <= 4'd0;
    end else begin
      if (f_valid) f_pos <= f_fwd ? f_pos + 8'd1 : f_pos - 8'd1;
      f_n <= f_n_now;
      if (f_valid && !f_same_pair) begin
        f_dither   <= 4'd0;
        f_dpair_lo <= f_prev;
        f_dpair_hi <= f_cur;
      end else if ((up_pulse || dn_pulse) && f_dither != 4'hf) begin
        f_dither <= f_dither + 4'd1;
      end
    end
  end

  // ---- properties ------------------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid) assert (!(up_pulse && dn_pulse));
  end

  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (!up_pulse && !dn_pulse && !error);
      end else begin
        if (up_pulse) assert ($past(f_valid && f_fwd));
        if (dn_pulse) assert ($past(f_valid && !f_fwd));
        assert (error == $past(f_a_changed && f_b_changed));
      end
    end
    if (f_past2_valid && $past(rst, 2) && !$past(rst)) assert (!up_pulse && !dn_pulse && !error);
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid) begin
      cover (up_pulse);
      cover (dn_pulse);
      cover (error);
      cover (f_n_now == 8'd2);  // two forward cycles
      cover (f_n_now == 8'hfe);  // two reverse cycles
      cover (f_e == 8'd3);  // the extremes of p - 4n
      cover (f_e == 8'hff);
      cover (dn_pulse && f_n == 8'd1);  // a reversal after an up pulse: the hysteresis lag taken up
      // dither: a pulse fired, then the same transition crossed back and forth several times
      cover (f_dither == 4'd1 && f_valid && f_same_pair && $past(f_valid && f_same_pair, 1) &&
             $past(f_valid && f_same_pair, 2) && $past(f_valid && f_same_pair, 3));
      cover (f_past2_valid && $past(rst, 2) && !$past(rst) && $past(a | b));
    end
  end

endmodule

`default_nettype wire
