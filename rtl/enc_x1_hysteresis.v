// SPDX-License-Identifier: Apache-2.0
// enc_x1_hysteresis -- Figure 14, the cycle-count (1X) circuit with latched hysteresis.
//
// "The circuit depicted in Figure 14 provides an up or down pulse for every cycle. Due to the
// latched hysteresis configuration, the circuit avoids the multiple count problem which can occur
// in the event of a stationary shaft oscillating slightly about a transition." up_pulse is Q1
// (clockwise = forward), dn_pulse is Q2.
//
// How the hysteresis works. Let p be the 4X position since reset (+1 per forward transition) and
// n the net count (#up - #dn). The circuit keeps d = p - 4n, which it holds in -1 .. 3:
//   forward transition: d = 3  -> up_pulse, d = 0      otherwise d = d + 1
//   reverse transition: d = -1 -> dn_pulse, d = 2      otherwise d = d - 1
// With R the state sampled first after reset (d = 0 there) and the states numbered forward
// R, R+1, R+2, R+3:
//   up_pulse fires on the forward transition R+3 -> R, but only when R+3 was entered from R+2
//   (forward); dn_pulse fires on the reverse transition R+3 -> R+2, only when R+3 was entered
//   from R (reverse). The one latch bit is "how was R+3 entered", so the circuit re-arms for up
//   by passing R+2 -> R+3 forward and for down by passing R -> R+3 in reverse. The two firing
//   transitions are two states apart, so dither about any one transition gives at most one
//   pulse, and |4n - p| <= 3 at all times. A monotone run of 4m transitions from reset (or from
//   the end of a run in the same direction) gives exactly m pulses.
// Extra output `error` (not in Figure 14): both channels changed between two samples; d is not
// moved (the direction is unknown), so the position tracked from then on may be off by two.
// The first sample after rst is the reference. Outputs are registered: latency 1 clock.
// Implementation: d is held as s = d mod 4 (a 2-bit Gray up/down count of valid transitions,
// no adder) plus one-hot flags for d = 3 and d = -1 (the latch bit of the ambiguous state).
`default_nettype none

module enc_x1_hysteresis (
    input  wire clk,
    input  wire rst,       // synchronous, active high
    input  wire a,         // channel A, synchronous to clk
    input  wire b,         // channel B, synchronous to clk
    output wire up_pulse,  // Q1: one clock per forward cycle
    output wire dn_pulse,  // Q2: one clock per reverse cycle
    output wire error      // one clock per illegal transition (both channels changed)
);

  reg  [1:0] prev_q;   // {a, b} at the previous sample
  reg        nref_q;   // 1 in the clock after rst: prev_q holds no real sample yet
  reg  [1:0] s_q;      // s = d mod 4 = position of prev_q relative to R, Gray: 0 1 3 2 = 00 01 11 10
  reg        top_q;    // d = 3  (s = 3, entered forward): the next forward transition fires up
  reg        bot_q;    // d = -1 (s = 3, entered in reverse): the next reverse transition fires down
  reg        up_q;
  reg        dn_q;
  reg        error_q;

  // d is kept as s (two bits) plus the two one-hot flags for its ambiguous value (s = 3 is d = 3
  // or d = -1); no adder. Like enc_x4_decoder: a valid transition changes exactly one channel,
  // and its direction is a ^ prev_b (forward: next state {~b, a}).
  wire a_moved = a ^ prev_q[1];
  wire b_moved = b ^ prev_q[0];
  wire moved   = a_moved ^ b_moved;         // one channel changed (no reference check)
  wire dir     = a ^ prev_q[0];             // direction of that transition, 1 = forward
  wire step    = moved & ~nref_q;           // valid transition: d moves
  // top_q/bot_q are 0 in the first clock after rst, so the pulses need no reference check.
  wire no_up   = rst | ~(dir & top_q);      // up_q: D = moved, this as its synchronous reset
  wire no_dn   = rst | ~(~dir & bot_q);

  always @(posedge clk) begin
    nref_q <= rst;
    prev_q <= {a, b};
    if (rst) begin
      s_q   <= 2'b00;
      top_q <= 1'b0;
      bot_q <= 1'b0;
    end else if (step) begin
      // Gray up/down: forward 00 -> 01 -> 11 -> 10 -> 00 (3 -> 0 is the up pulse, d = 0)
      s_q   <= dir ? {s_q[0], ~s_q[1]} : {~s_q[0], s_q[1]};
      top_q <= dir & (s_q == 2'b11);        // forward from d = 2
      bot_q <= ~dir & (s_q == 2'b00);       // reverse from d = 0
    end
    up_q    <= no_up ? 1'b0 : moved;
    dn_q    <= no_dn ? 1'b0 : moved;
    error_q <= rst ? 1'b0 : ~nref_q & ~moved & a_moved;  // both channels changed
  end

  assign up_pulse = up_q;
  assign dn_pulse = dn_q;
  assign error    = error_q;

endmodule

`default_nettype wire
