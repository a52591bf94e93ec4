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
  reg        ref_q;    // prev_q holds a real sample
  reg  [2:0] d_q;      // d = p - 4n, two's complement, -1 .. 3
  reg  [2:0] d_d;
  reg        up_q;
  reg        dn_q;
  reg        error_q;

  localparam [2:0] D_MINUS1 = 3'b111;
  localparam [2:0] D_TOP = 3'd3;

  wire [1:0] cur = {a, b};
  wire       fwd = ref_q & (cur == {~prev_q[0], prev_q[1]});  // forward: next state {~b, a}
  wire       rev = ref_q & (prev_q == {~cur[0], cur[1]});
  wire       bad = ref_q & (cur != prev_q) & ~fwd & ~rev;
  wire       fire_up = fwd & (d_q == D_TOP);
  wire       fire_dn = rev & (d_q == D_MINUS1);

  always @(*) begin
    d_d = d_q;
    if (fire_up) begin
      d_d = 3'd0;
    end else if (fire_dn) begin
      d_d = 3'd2;
    end else if (fwd) begin
      d_d = d_q + 3'd1;
    end else if (rev) begin
      d_d = d_q - 3'd1;
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      prev_q  <= 2'b00;
      ref_q   <= 1'b0;
      d_q     <= 3'd0;
      up_q    <= 1'b0;
      dn_q    <= 1'b0;
      error_q <= 1'b0;
    end else begin
      prev_q  <= cur;
      ref_q   <= 1'b1;
      d_q     <= d_d;
      up_q    <= fire_up;
      dn_q    <= fire_dn;
      error_q <= bad;
    end
  end

  assign up_pulse = up_q;
  assign dn_pulse = dn_q;
  assign error    = error_q;

endmodule

`default_nettype wire
