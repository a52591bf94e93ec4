// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for ls168 (read by formal/ls168.sby; `make formal`), MODULUS 10 and 16.
//
// No assumptions at all: every input is free on every clock, and the counter starts in any of
// its 16 states (the part has no reset pin). Proven (k-induction):
//   - load_n low: q <- d; else enp_n = ent_n = 0: count up (MAX -> 0) / down (0 -> MAX) from any
//     state in 0..MAX; else hold
//   - q never leaves 0..MAX from 0..MAX (except by loading a d outside it)
//   - rco_n == ~(~ent_n & (up ? q == MAX : q == 0)) at all times (independent of enp_n)
//   - a state outside 0..MAX rejoins 0..MAX within two counting clocks, either direction
//     (counting clocks taken while outside the range, no load in between)
`default_nettype none

module ls168_formal #(
    parameter integer MODULUS = 10
) (
    input wire       clk,
    input wire       load_n,
    input wire       enp_n,
    input wire       ent_n,
    input wire       up,
    input wire [3:0] d
);

  wire [3:0] q;
  wire       rco_n;

  ls168 #(
      .MODULUS(MODULUS)
  ) dut (
      .clk   (clk),
      .load_n(load_n),
      .enp_n (enp_n),
      .ent_n (ent_n),
      .up    (up),
      .d     (d),
      .q     (q),
      .rco_n (rco_n)
  );

  localparam integer MAX_INT = MODULUS - 1;
  localparam [3:0] MAX = MAX_INT[3:0];

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  wire       f_counting = load_n & ~enp_n & ~ent_n;
  wire       f_in_range = (q <= MAX);
  wire [3:0] f_next_up = (q == MAX) ? 4'd0 : q + 4'd1;
  wire [3:0] f_next_dn = (q == 4'd0) ? MAX : q - 4'd1;

  // counting clocks taken from outside 0..MAX since the counter last was inside it (or loaded)
  reg  [1:0] f_oor = 2'd0;
  always @(posedge clk) begin
    if (!load_n || f_in_range) f_oor <= 2'd0;
    else if (f_counting && f_oor != 2'd3) f_oor <= f_oor + 2'd1;
  end

  // ---- properties ------------------------------------------------------------------------------
  always @(*) begin
    assert (rco_n == ~(~ent_n & (up ? (q == MAX) : (q == 4'd0))));
    if (!f_in_range) assert (f_oor < 2'd2);
  end

  always @(posedge clk) begin
    if (f_past_valid) begin
      if (!$past(load_n)) assert (q == $past(d));
      if ($past(load_n) && !$past(f_counting)) assert (q == $past(q));
      if ($past(f_counting && f_in_range)) assert (q == ($past(up) ? $past(f_next_up) : $past(f_next_dn)));
      if ($past(f_in_range && (load_n || d <= MAX))) assert (f_in_range);
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid) begin
      cover (!$past(load_n) && q == MAX);
      cover ($past(f_counting && up) && $past(q) == MAX && q == 4'd0);  // wrap up
      cover ($past(f_counting && !up) && $past(q) == 4'd0 && q == MAX);  // wrap down
      cover ($past(f_counting && up) && q == 4'd5);
      cover ($past(f_counting && !up) && q == 4'd5);
      cover (!rco_n && up && enp_n);  // carry out while this stage itself is not counting
      cover (!rco_n && !up);
      cover ($past(load_n && !f_counting) && q == 4'd7);  // hold
    end
  end

  generate
    if (MODULUS == 10) begin : g_decade_covers
      always @(posedge clk) begin
        if (f_past_valid) begin
          cover ($past(!load_n) && q == 4'd15);  // out of range ...
          cover ($past(f_counting && up && !f_in_range) && f_in_range);  // ... rejoins counting up
          cover ($past(f_counting && !up && !f_in_range) && f_in_range);  // ... and down
          cover ($past(load_n && !f_counting && !f_in_range) && !f_in_range);  // held outside
        end
      end
    end
  endgenerate

endmodule

`default_nettype wire
