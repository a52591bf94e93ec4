// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_conditioner_rt (read by formal/enc_conditioner_rt.sby; `make formal`):
// the conditioner that ships inside enc_qei, with its filter length free at run time.
//
// a_in, b_in and filter_len are free on every clock (filter_len may change at any clock, to any
// 5-bit value); the first clock is a reset, rst is free afterwards. The wrapper keeps its own
// model: a two-stage synchronizer copy (reset to 0 like the RTL's), the history of the
// synchronized samples the filter has taken since rst, and the length in force L: filter_len
// clamped to 1 .. MAX_FILTER_LEN (0 acts as 1), as of the clock before (the block registers it).
// Per channel, proven (k-induction):
//   - the output changes exactly when the last L synchronized samples (all taken after rst)
//     showed the new level: never sooner, never on fewer, never missed, whatever the length did
//     before (a candidate level already seen on L samples is taken at the next differing sample)
//   - glitch (one clock later) exactly when a sample went back to the output level right after
//     samples of the other level that were not accepted, on either channel (one pulse for both);
//     with L = 1 in force no level can be rejected
//   - valid exactly from L + 2 clocks after rst on (L as it is then), and with valid and the last
//     L samples agreeing, the output shows them
//   - a, b, glitch and valid are 0 the clock after rst
`default_nettype none

module enc_conditioner_rt_formal #(
    parameter integer MAX_FILTER_LEN = 16
) (
    input wire       clk,
    input wire       rst,
    input wire [4:0] filter_len,
    input wire       a_in,
    input wire       b_in
);

  wire a;
  wire b;
  wire glitch;
  wire valid;

  enc_conditioner_rt #(
      .MAX_FILTER_LEN(MAX_FILTER_LEN)
  ) dut (
      .clk       (clk),
      .rst       (rst),
      .filter_len(filter_len),
      .a_in      (a_in),
      .b_in      (b_in),
      .a         (a),
      .b         (b),
      .glitch    (glitch),
      .valid     (valid)
  );

  localparam integer HW = (MAX_FILTER_LEN < 2) ? 2 : MAX_FILTER_LEN;  // history kept
  localparam integer MAX = MAX_FILTER_LEN;

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  always @(*) begin
    if (!f_past_valid) assume (rst);
  end

  // ---- model -----------------------------------------------------------------------------------
  // the length in force: filter_len of the clock before, clamped to 1 .. MAX_FILTER_LEN
  wire [4:0] f_len_d = (filter_len == 5'd0) ? 5'd1 :
                       (filter_len > MAX[4:0]) ? MAX[4:0] : filter_len;
  reg  [4:0] f_len = 5'd1;
  always @(posedge clk) f_len <= f_len_d;

  wire [HW-1:0] f_win = ({{(HW - 1) {1'b0}}, 1'b1} << f_len) - {{(HW - 1) {1'b0}}, 1'b1};

  reg  [   1:0] f_m = 2'b00;  // {b, a} synchronizer copy, first stage
  reg  [   1:0] f_s = 2'b00;  // second stage: the sample the filter takes at the next clock
  reg           f_m_real = 1'b0;  // the stage holds a sample of the inputs (not a reset 0)
  reg           f_s_real = 1'b0;
  reg  [HW-1:0] f_ha = {HW{1'b0}};  // samples taken by the filter, bit 0 the latest: A ...
  reg  [HW-1:0] f_hb = {HW{1'b0}};  // ... and B
  reg  [   4:0] f_taken = 5'd0;  // samples taken since rst (saturating)
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
      f_since <= 5'd0;
    end else begin
      if (f_taken != 5'd31) f_taken <= f_taken + 5'd1;
      if (f_since != 5'd31) f_since <= f_since + 5'd1;
    end
  end

  // the length in force at the clock that produced the outputs now, and the samples it saw
  reg  [4:0]    f_l      = 5'd1;
  reg  [HW-1:0] f_w      = {{(HW - 1) {1'b0}}, 1'b1};
  always @(posedge clk) begin
    f_l <= f_len;
    f_w <= f_win;
  end
  wire          f_full   = (f_taken >= f_l);  // the last L samples were taken after rst
  wire          f_a_all1 = f_full && ((f_ha & f_w) == f_w);
  wire          f_a_all0 = f_full && ((f_ha & f_w) == {HW{1'b0}});
  wire          f_b_all1 = f_full && ((f_hb & f_w) == f_w);
  wire          f_b_all0 = f_full && ((f_hb & f_w) == {HW{1'b0}});
  // a rejection at the last clock: that sample is the output level, the one before was not
  wire f_rej_a = (f_taken >= 2) && (f_ha[0] == f_pa) && (f_ha[1] != f_pa);
  wire f_rej_b = (f_taken >= 2) && (f_hb[0] == f_pb) && (f_hb[1] != f_pb);

  // ---- properties ------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid) begin
      if ($past(rst)) begin
        assert (!a && !b && !glitch && !valid);
      end else if ($past(f_past_valid)) begin
        assert ((a != $past(a)) == ($past(a) ? f_a_all0 : f_a_all1));
        assert ((b != $past(b)) == ($past(b) ? f_b_all0 : f_b_all1));
        assert (glitch == (f_rej_a || f_rej_b));
        assert (valid == (f_since >= f_l + 2));
        if (valid && f_a_all1) assert (a);
        if (valid && f_a_all0) assert (!a);
        if (valid && f_b_all1) assert (b);
        if (valid && f_b_all0) assert (!b);
      end
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && !$past(rst)) begin
      cover (a && !$past(a));  // accepted rise and fall, on both channels
      cover (!a && $past(a));
      cover (b && !$past(b) && f_l == 5'd1);
      cover (b && !$past(b) && f_l == MAX[4:0]);
      cover (valid && !$past(valid));
      cover (glitch && f_rej_a && f_rej_b);  // both channels rejected: one pulse
      // a shorter length takes a candidate level already seen on that many samples at once
      cover (a && !$past(a) && $past(f_l) > f_l + 1);
      // a longer length makes a level that would have been taken wait
      cover (!a && $past(!a) && f_l > $past(f_l) && f_ha[1:0] == 2'b11);
      cover (filter_len == 5'd0 && $past(filter_len) == 5'd31);
    end
  end

endmodule

`default_nettype wire
