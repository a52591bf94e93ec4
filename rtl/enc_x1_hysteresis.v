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

`ifdef FORMAL
  // ---- formal only (formal/enc_x1_hysteresis.sby): invariants, asserts only --------------------
  // A shadow of the header's d = p - 4n, kept from the ports alone (p: the 4X position of the
  // valid transitions of a, b since rst, illegal changes ignored; n: #up_pulse - #dn_pulse since
  // rst), is asserted to stay in -1 .. 3 (so |4n - p| <= 3) and to be what s_q / top_q / bot_q
  // encode. And the dither property: once a pulse fired on a transition between two states X and
  // Y, no pulse fires on a transition between X and Y until a valid transition between another
  // pair (or an illegal change, or rst) ends the dither. These need the shadow (history), so they
  // live here and not in the port-level wrapper: Yosys has no hierarchical references.
  reg              f_rst_seen = 1'b0;  // a rst has happened: the RTL state is defined
  reg        [1:0] f_cur;              // {a, b} sampled at the last clock (the RTL's prev_q)
  reg              f_real;             // f_cur is a real sample, i.e. rst was low at that clock
  reg signed [4:0] f_q;                // p - 4 * (n counted before this clock's outputs)
  reg              f_t_valid;          // this clock's outputs belong to a valid transition ...
  reg              f_t_illegal;        // ... or to an illegal change (both channels)
  reg              f_t_fwd;            // ... and its direction
  reg        [3:0] f_t_pair;           // one-hot {from, to} states of that transition
  reg              f_blk;              // a dither is going on in which a pulse has fired ...
  reg        [3:0] f_blk_pair;         // ... about this pair of states

  wire       [1:0] f_ab = {a, b};
  wire             f_a_ch = f_real & (a ^ f_cur[1]);
  wire             f_b_ch = f_real & (b ^ f_cur[0]);
  wire             f_step = f_a_ch ^ f_b_ch;                    // valid transition at this clock
  wire             f_fwd = (f_ab == {~f_cur[0], f_cur[1]});   // forward: next {a, b} = {~b, a}
  wire             f_pulse = up_pulse | dn_pulse;
  wire signed [4:0] f_e = f_q - (up_pulse ? 5'sd4 : 5'sd0) + (dn_pulse ? 5'sd4 : 5'sd0);  // p - 4n
  wire signed [4:0] f_d = (s_q == 2'b00) ? 5'sd0 : (s_q == 2'b01) ? 5'sd1 :
                          (s_q == 2'b11) ? 5'sd2 : top_q ? 5'sd3 : -5'sd1;  // d as the RTL holds it
  wire       [3:0] f_cur_hot = 4'b0001 << f_cur;
  wire       [3:0] f_next_hot = 4'b0001 << {~f_cur[0], f_cur[1]};  // forward neighbour of f_cur
  wire       [3:0] f_back_hot = 4'b0001 << {f_cur[0], ~f_cur[1]};  // reverse neighbour
  // the dither state after this clock's transition and pulses
  wire             f_blk_now = f_t_valid ? (f_pulse | (f_blk & (f_t_pair == f_blk_pair))) :
                               (f_blk & ~f_t_illegal);
  wire       [3:0] f_pair_now = (f_t_valid & f_pulse) ? f_t_pair : f_blk_pair;

  always @(posedge clk) begin
    f_cur <= f_ab;
    f_real <= ~rst;
    f_t_valid <= ~rst & f_step;
    f_t_illegal <= ~rst & f_a_ch & f_b_ch;
    f_t_fwd <= f_fwd;
    f_t_pair <= f_cur_hot | (4'b0001 << f_ab);
    if (rst) begin
      f_rst_seen <= 1'b1;
      f_q <= 5'sd0;
      f_blk <= 1'b0;
      f_blk_pair <= 4'b0000;
    end else begin
      f_q <= f_q + (f_step ? (f_fwd ? 5'sd1 : -5'sd1) : 5'sd0) - (up_pulse ? 5'sd4 : 5'sd0) +
             (dn_pulse ? 5'sd4 : 5'sd0);
      f_blk <= f_blk_now;
      f_blk_pair <= f_pair_now;
    end
  end

  always @(*) begin
    if (f_rst_seen) begin
      // |4n - p| <= 3, and d is what the header says it is
      assert (f_e >= -5'sd1 && f_e <= 5'sd3);
      assert (!(top_q && bot_q));
      assert ((top_q | bot_q) == (s_q == 2'b10));
      assert (f_d == f_e);
      assert (prev_q == f_cur && nref_q == !f_real);
      // pulses only on a valid transition, in its direction; never both
      if (f_pulse) assert (f_t_valid && (up_pulse ? f_t_fwd : !f_t_fwd) && !(up_pulse && dn_pulse));
      // dither about one transition: at most one pulse in total
      assert (!(f_blk && f_t_valid && f_t_pair == f_blk_pair && f_pulse));
      if (f_blk_now) begin
        assert (f_pair_now == (f_cur_hot | f_next_hot) || f_pair_now == (f_cur_hot | f_back_hot));
        if (f_pair_now == (f_cur_hot | f_next_hot)) assert (f_e != 5'sd3);  // forward won't fire
        if (f_pair_now == (f_cur_hot | f_back_hot)) assert (f_e != -5'sd1);  // reverse won't fire
      end
    end
  end
`endif

endmodule

`default_nettype wire
