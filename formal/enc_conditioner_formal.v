// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_conditioner (read by formal/enc_conditioner.sby; `make formal`).
//
// a_in and b_in are free on every clock (asynchronous inputs are sampled by the clock: any
// sequence of samples is possible); the first clock is a reset, rst is free afterwards. The
// wrapper keeps its own model: a two-stage synchronizer copy (reset to 0 like the RTL's) and the
// history of the synchronized samples the filter has taken since rst. Per channel, proven
// (k-induction):
//   - the output changes exactly when the last FILTER_LEN synchronized samples (all taken after
//     rst) showed the new level: never sooner, never on fewer, and never missed
//   - glitch (one clock later) exactly when a sample went back to the output level right after
//     samples of the other level that were not accepted, on either channel (both channels in one
//     clock give one pulse); with FILTER_LEN = 1 glitch stays 0
//   - valid exactly from FILTER_LEN + 2 clocks after rst on (until the next rst), which is exactly
//     when the filter has taken FILTER_LEN samples of the real inputs; when valid and those
//     samples agree, the output shows them
//   - a, b, glitch and valid are 0 the clock after rst
`default_nettype none

module enc_conditioner_formal #(
    parameter integer FILTER_LEN = 3
) (
    input wire clk,
    input wire rst,
    input wire a_in,
    input wire b_in
);

  wire a;
  wire b;
  wire glitch;
  wire valid;

  enc_conditioner #(
      .FILTER_LEN(FILTER_LEN)
  ) dut (
      .clk   (clk),
      .rst   (rst),
      .a_in  (a_in),
      .b_in  (b_in),
      .a     (a),
      .b     (b),
      .glitch(glitch),
      .valid (valid)
  );

  localparam integer HW = (FILTER_LEN < 2) ? 2 : FILTER_LEN;  // history kept (glitch needs 2)
  localparam integer SETTLE = FILTER_LEN + 2;
  localparam [HW-1:0] WIN = {{(HW - FILTER_LEN) {1'b0}}, {FILTER_LEN{1'b1}}};  // last FILTER_LEN

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  always @(*) begin
    if (!f_past_valid) assume (rst);
  end

  // ---- model -----------------------------------------------------------------------------------
  reg  [   1:0] f_m = 2'b00;  // {b, a} synchronizer copy, first stage
  reg  [   1:0] f_s = 2'b00;  // second stage: the sample the filter takes at the next clock
  reg           f_m_real = 1'b0;  // the stage holds a sample of the inputs (not a reset 0)
  reg           f_s_real = 1'b0;
  reg  [HW-1:0] f_ha = {HW{1'b0}};  // samples taken by the filter, bit 0 the latest: A ...
  reg  [HW-1:0] f_hb = {HW{1'b0}};  // ... and B
  reg  [   4:0] f_taken = 5'd0;  // samples taken since rst (saturating)
  reg  [   4:0] f_real = 5'd0;  // real samples taken since rst (saturating)
  reg  [   4:0] f_since = 5'd0;  // clocks since rst (saturating)
  reg           f_pa = 1'b0;  // the outputs a clock ago
  reg           f_pb = 1'b0;

  always @(posedge clk) begin
    f_m <= rst ? 2'b00 : {b_in, a_in};
    f_s <= rst ? 2'b00 : f_m;
    f_m_real <= ~rst;
    f_s_real <= ~rst & f_m_real;
    f_pa <= a;
    f_pb <= b;
    f_ha <= {f_ha[HW-2:0], f_s[0]};
    f_hb <= {f_hb[HW-2:0], f_s[1]};
    if (rst) begin
      f_taken <= 5'd0;
      f_real  <= 5'd0;
      f_since <= 5'd0;
    end else begin
      if (f_taken != 5'd31) f_taken <= f_taken + 5'd1;
      if (f_s_real && f_real != 5'd31) f_real <= f_real + 5'd1;
      if (f_since != 5'd31) f_since <= f_since + 5'd1;
    end
  end

  wire f_full = (f_taken >= FILTER_LEN);  // the last FILTER_LEN samples were taken after rst
  wire f_a_all1 = f_full && ((f_ha & WIN) == WIN);
  wire f_a_all0 = f_full && ((f_ha & WIN) == {HW{1'b0}});
  wire f_b_all1 = f_full && ((f_hb & WIN) == WIN);
  wire f_b_all0 = f_full && ((f_hb & WIN) == {HW{1'b0}});
  // a rejection at the last clock: that sample is the output level, the one before was not
  wire f_rej_a = (f_taken >= 2) && (f_ha[0] == f_pa) && (f_ha[1] != f_pa);
  wire f_rej_b = (f_taken >= 2) && (f_hb[0] == f_pb) && (f_hb[1] != f_pb);

  // ---- properties ------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (!a && !b && !glitch && !valid);
      end else begin
        assert ((a != $past(a)) == ($past(a) ? f_a_all0 : f_a_all1));
        assert ((b != $past(b)) == ($past(b) ? f_b_all0 : f_b_all1));
        assert (glitch == (f_rej_a || f_rej_b));
      end
      assert (valid == (f_since >= SETTLE));
      assert (valid == (f_real >= FILTER_LEN));
      if (valid && f_a_all1) assert (a);
      if (valid && f_a_all0) assert (!a);
      if (valid && f_b_all1) assert (b);
      if (valid && f_b_all0) assert (!b);
      if (FILTER_LEN == 1) assert (!glitch);
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && !$past(rst)) begin
      cover (a && !$past(a));  // accepted rise and fall, on both channels
      cover (!a && $past(a));
      cover (b && !$past(b));
      cover (!b && $past(b));
      cover (a != $past(a) && b != $past(b));  // both channels in the same clock
      cover (valid && !$past(valid));  // valid rises
      cover (valid && !$past(valid) && a);  // ... with the real level already shown
      cover (valid && a && b && !$past(a) && $past(b, 2 * FILTER_LEN) && !$past(a || b, 4 * FILTER_LEN));
    end
  end

  generate
    if (FILTER_LEN > 1) begin : g_glitch_covers
      always @(posedge clk) begin
        if (f_past_valid && !$past(rst)) begin
          cover (glitch && f_rej_a && !f_rej_b);
          cover (glitch && f_rej_b && !f_rej_a);
          cover (glitch && f_rej_a && f_rej_b);  // both channels rejected: one pulse
          cover (a != f_pa && $past(glitch, 2));  // a level accepted right after a rejection
          // a level rejected after FILTER_LEN - 1 samples, the longest that is still rejected
          cover (glitch && f_taken >= FILTER_LEN + 1 && f_ha[FILTER_LEN-1:1] == {(FILTER_LEN - 1) {~f_ha[0]}});
        end
      end
    end
  endgenerate

endmodule

`default_nettype wire
