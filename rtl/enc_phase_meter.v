// SPDX-License-Identifier: Apache-2.0
// enc_phase_meter -- Figure 11 of the note, the averaging phase meter, in logic.
//
// The meter of Figure 11 low-pass filters the exclusive-OR of the two channels: the XOR is high
// for (phase / 180) of every cycle, so its average reads the phase between A and B. This module
// reads the same quantity digitally and reports it relative to the 90 degree adjustment point:
//   phase     = 180 * X / T   electrical degrees
//   phase_err = phase - 90    signed, 1/256 electrical degree per LSB (zero at the 90 degree point)
// With pulse-width error the XOR is high from A rise to B rise and again from A fall to B fall,
// so the reading is the mean of the rising-edge and falling-edge phases, which is also the phase
// between the pulse centres (the note's definition of phase).
//
// What is averaged, exactly. A window opens on a rising edge of A (the sample on which `a` is
// first seen high) and covers the next 2^WINDOW_LOG2 samples. T is the number of samples after
// the opening edge up to and including the LAST rising edge of A inside the window (T <= 2^W),
// and X the number of those samples with a != b. In a steady direction the XOR level is the same
// on both edges, so X / T is the XOR duty cycle over a whole number of encoder cycles
// (at least one): no partial cycle at either end biases it, which a plain 2^WINDOW_LOG2-clock
// average would do by up to half a cycle per window (1.4 degrees at 64 cycles per window). The
// division is a restoring shift-subtract divider, one quotient bit per clock, floor(46080 X / T),
// 46080 = 180 * 256; X is counted in steps of 45 and the factor 1024 enters as shifted-in zeros.
// The next window opens on the first rising edge of A after the division, so readings land about
// every 2^WINDOW_LOG2 clocks plus at most one encoder cycle plus WINDOW_LOG2 + 18 clocks.
//
// How, cheaply (the logic is sized for a small FPGA). Two adders do all the arithmetic, each with
// two jobs, so there is no separate sample counter and no multiplexer in front of a register:
//   - the X adder counts 45 X while the window is open; a snapshot register takes its sum on every
//     rising edge of A. While the divider runs, the same LUTs shift that snapshot (the dividend,
//     a zero guard bit on top and ten zeros below it) out MSB first, and the quotient in.
//   - the divider's adder counts L - 1 while the window is open, L being the samples since the
//     last rising edge of A (so it is set to -1 on each edge). At the window's end L = 2^W - T,
//     so the divider adds L where it would subtract T: rem2 - T >= 0 exactly when rem2 + L >= 2^W.
//   - the window length and the divider's step count come from two LFSRs (window: Galois,
//     x^n + x^k + 1, primitive, n > W; steps: x^6 + x + 1) compared with constants that are
//     computed at elaboration (lfsr_pow below), one clock ahead so the compare is registered.
//
// Timing: `valid` rises WINDOW_LOG2 + 18 clocks after the last sample of the window (its 2^W-th);
// `phase_err` changes only with `valid` and holds between readings.
//
// No reading (no `valid`) from a window that holds no complete cycle of A (shaft too slow or
// stopped), nor from a window in which the direction reversed: a valid transition against the
// current direction abandons the window, and the next one opens on the next rising edge of A.
// A second `rst` likewise abandons the window in progress.
//
// Direction (the red LED of Figure 11, lit "when channel A is the leading waveform"): every valid
// transition (exactly one channel changed between two samples) sets the direction, forward
// (00 -> 10 -> 11 -> 01, A leads) or reverse. a_leads / b_leads show it; both are 0 after reset
// until the first valid transition. A double change (both channels in one clock: phase within a
// clock of 0 or 180 degrees) carries no direction and leaves it as it was.
//
// Accuracy: the sampling error of each edge is below one clock and, with edges asynchronous to
// clk, averages out over the cycles of a window; with >= 100 clocks per cycle and >= 64 cycles per
// window the reading is within 0.25 degree of the true phase (the divider's floor adds < 1 LSB).
// That needs the edges to fall at phases spread over the clock period. At a speed of exactly a
// whole or half-whole number of clocks per cycle every edge is sampled at the same phase, the
// sampling errors do not average out, and the error can reach about 2 clocks per cycle (3.6
// degrees at 100 clocks per cycle); no single-clock sampler avoids this (test commensurate_speed).
//
// Inputs a and b must be synchronous to clk (from enc_conditioner, which also filters glitches).
`default_nettype none
`include "enc_params.vh"

module enc_phase_meter #(
    parameter integer WINDOW_LOG2 = 16  // averaging window of 2^WINDOW_LOG2 clocks; 8 .. 24
) (
    input  wire               clk,
    input  wire               rst,        // synchronous, active high
    input  wire               a,          // channel A, synchronous to clk
    input  wire               b,          // channel B, synchronous to clk
    output wire               a_leads,    // red LED of Figure 11: A is the leading waveform
    output wire               b_leads,    // B is the leading waveform
    output wire signed [15:0] phase_err,  // phase - 90 degrees, 1/256 electrical degree per LSB
    output wire               valid       // one-clock pulse when phase_err takes a new reading
);

  generate
    `ENC_CHECK_WINDOW_LOG2
  endgenerate

  localparam integer W = WINDOW_LOG2;
  localparam integer XW = W + 6;  // 45 * X < 45 * 2^W < 2^(W+6)
  localparam integer PAD = 10;  // dividend 46080 * X = (45 * X) << 10
  localparam integer NW = 1 + XW + PAD;  // divider steps (guard, 45 X, zeros), one bit each; <= 41
  localparam [15:0] NINETY = 16'd23040;  // 90 degrees in 1/256 degree
  localparam [XW-1:0] X_INC = 45;  // X is counted in 45ths of its weight (46080 = 45 * 1024)

  // Window LFSR x^NL + x^TAP + 1: primitive, so its period 2^NL - 1 exceeds 2^W.
  localparam integer NL = (W <= 8) ? 9 : (W == 9) ? 10 : (W == 10) ? 11 : (W <= 14) ? 15 :
                          (W <= 16) ? 17 : (W == 17) ? 18 : (W <= 19) ? 20 : (W == 20) ? 21 :
                          (W == 21) ? 22 : (W == 22) ? 23 : 25;
  localparam integer TAP = (NL == 9) ? 4 : (NL == 10) ? 3 : (NL == 11) ? 2 : (NL == 15) ? 1 :
                           (NL == 17) ? 3 : (NL == 18) ? 7 : (NL == 20) ? 3 : (NL == 21) ? 2 :
                           (NL == 22) ? 1 : (NL == 23) ? 5 : 3;
  // Divider step LFSR x^6 + x + 1 (period 63 > NW).
  localparam integer NS = 6;
  localparam integer STAP = 1;

  // A Galois LFSR holding s(x) steps to x * s(x) mod (x^n + x^tap + 1). lfsr_pow returns
  // x^(2^sq + lin) mod that polynomial: x squared sq times (squaring over GF(2) spreads the
  // bits apart), then lin more steps.
  function automatic [24:0] lfsr_pow(input integer n, input integer tap, input integer sq,
                                     input integer lin);
    reg [49:0] t;
    integer s, i;
    begin
      t = 50'd2;  // x
      for (s = 0; s < sq; s = s + 1) begin
        for (i = 24; i >= 0; i = i - 1) begin
          t[2*i] = t[i];
          t[2*i+1] = 1'b0;
        end
        for (i = 48; i >= 0; i = i - 1)
          if (i >= n && t[i]) begin
            t[i] = 1'b0;
            t[i-n+tap] = ~t[i-n+tap];
            t[i-n] = ~t[i-n];
          end
      end
      for (s = 0; s < lin; s = s + 1) begin
        t = {t[48:0], 1'b0};
        if (t[n]) begin
          t[n] = 1'b0;
          t[tap] = ~t[tap];
          t[0] = ~t[0];
        end
      end
      lfsr_pow = t[24:0];
    end
  endfunction

  // The window LFSR is seeded with x^2 on the opening edge, so it holds x^(k+1) on the k-th
  // sample after it and x^(2^W) on the one before the last (that is when last_q is set).
  localparam [NL-1:0] WIN_SEED = 4;  // x^2
  localparam [24:0] WIN_PRE_25 = lfsr_pow(NL, TAP, W, 0);  // x^(2^W)
  localparam [NL-1:0] WIN_PRE = WIN_PRE_25[NL-1:0];
  // The step LFSR is seeded with 1 as the divider starts: x^j on step j (0 .. NW-1).
  localparam [NS-1:0] STEP_SEED = 1;
  localparam [24:0] STEP_PRE_25 = lfsr_pow(NS, STAP, 0, NW - 3);  // x^(NW-2)
  localparam [NS-1:0] STEP_PRE = STEP_PRE_25[NS-1:0];

  // ------------------------------------------------------------------------------------------
  // Edges and direction
  // ------------------------------------------------------------------------------------------
  reg a_q, b_q;  // previous sample
  always @(posedge clk) begin
    a_q <= a;
    b_q <= b;
  end

  wire a_rise = a & ~a_q;
  wire xor_ab = a ^ b;
  wire step = (a ^ a_q) ^ (b ^ b_q);  // exactly one channel changed: a valid transition
  wire step_fwd = a ^ b_q;  // direction of that transition (1 = forward, A leads)

  reg al_q, bl_q;  // the LEDs: the last valid transition was forward / reverse
  always @(posedge clk) begin
    if (rst) begin
      al_q <= 1'b0;
      bl_q <= 1'b0;
    end else if (step) begin
      al_q <= step_fwd;
      bl_q <= ~step_fwd;
    end
  end
  wire reversal = step & (step_fwd ? bl_q : al_q);

  // ------------------------------------------------------------------------------------------
  // Window and sequencing. run and busy never overlap.
  // ------------------------------------------------------------------------------------------
  reg            run_q;  // a window is open
  reg            busy_q;  // divider running
  reg            have_q;  // a rising edge of A closed a whole cycle in this window
  reg            last_q;  // this sample is the window's last (its 2^W-th)
  reg            li_q;  // this is the divider's last step
  reg  [ NL-1:0] win_q;  // window LFSR
  reg  [ NS-1:0] stp_q;  // divider step LFSR

  wire           open_win = ~run_q & ~busy_q & a_rise;
  wire           close_win = run_q & last_q;
  wire           snap = run_q & a_rise;  // T, X: a whole cycle ends on this sample
  wire           div_go = close_win & (have_q | a_rise) & ~reversal;

  always @(posedge clk) begin
    if (open_win) win_q <= WIN_SEED;
    else begin
      win_q <= {win_q[NL-2:0], 1'b0};
      win_q[0] <= win_q[NL-1];
      win_q[TAP] <= win_q[TAP-1] ^ win_q[NL-1];
    end
  end

  always @(posedge clk) begin
    if (div_go) stp_q <= STEP_SEED;
    else begin
      stp_q <= {stp_q[NS-2:0], 1'b0};
      stp_q[0] <= stp_q[NS-1];
      stp_q[STAP] <= stp_q[STAP-1] ^ stp_q[NS-1];
    end
  end

  always @(posedge clk) begin
    last_q <= run_q & (win_q == WIN_PRE);
    li_q   <= busy_q & (stp_q == STEP_PRE);
  end

  always @(posedge clk) begin
    if (rst) run_q <= 1'b0;
    else if (open_win) run_q <= 1'b1;
    else if (close_win || reversal) run_q <= 1'b0;
  end

  always @(posedge clk) begin
    if (rst || open_win) have_q <= 1'b0;
    else if (snap) have_q <= 1'b1;
  end

  always @(posedge clk) begin
    busy_q <= ~rst & (div_go | (busy_q & ~li_q));
  end

  // ------------------------------------------------------------------------------------------
  // X adder. Its second operand is 45 while a != b, else 0, in the bits where 45 has a 1; in the
  // others it is busy_q (0 while the window is open), which is also the select of the shift
  // below, so each of those bits of adder and multiplexer fits one LUT. While busy, x_q ignores
  // the result and {xs_q, pad_q} shifts left: the guard bit xs_q[XW] goes to the divider first,
  // then 45 X MSB first, then the ten zeros; the quotient bits come in at pad_q[0].
  // ------------------------------------------------------------------------------------------
  reg  [ XW-1:0] x_q;  // 45 * (samples with a != b since the opening edge)
  reg  [   XW:0] xs_q;  // 0 and 45 * X at the last rising edge of A; then the shift register
  reg  [PAD-1:0] pad_q;  // below xs_q: zeros, then the quotient

  wire [ XW-1:0] x_step = (xor_ab ? X_INC : {XW{1'b0}}) | (~X_INC & {XW{busy_q}});
  wire [ XW-1:0] x_sum = x_q + x_step;
  wire [ XW-1:0] x_d = busy_q ? {xs_q[XW-2:0], pad_q[PAD-1]} : x_sum;

  always @(posedge clk) begin
    if (open_win) x_q <= {XW{1'b0}};
    else if (run_q) x_q <= x_d;
  end

  always @(posedge clk) begin
    if (snap || busy_q) xs_q[XW-1:0] <= x_d;
  end

  always @(posedge clk) begin
    if (snap) xs_q[XW] <= 1'b0;
    else if (busy_q) xs_q[XW] <= xs_q[XW-1];
  end

  // ------------------------------------------------------------------------------------------
  // Divider adder: rem2 + L (= rem2 - T + 2^W). While the window is open rem_q is 0 and the
  // guard bit is 0 after the first edge, so it counts L_q = L - 1 up by one (ge forced to 1):
  // -1 on each rising edge, 2^W - T - 1 at the window's end (W+1 bits, so that T = 2^W, L = 0
  // works). While busy: restoring division, floor((45 X << 10) / T), one quotient bit per clock;
  // rem2 < 2T, so rem2 + L < 2^(W+1) and bit W of the sum is rem2 >= T.
  // ------------------------------------------------------------------------------------------
  reg  [   W:0] l_q;  // (samples since the last rising edge of A) - 1
  reg  [ W-1:0] rem_q;  // partial remainder, < T <= 2^W

  wire [   W:0] rem2 = {rem_q, xs_q[XW]};
  wire [   W:0] dsum = rem2 + l_q + {{W{1'b0}}, 1'b1};
  wire          ge = dsum[W] | run_q;  // quotient bit while busy
  wire [ W-1:0] dsel = ge ? dsum[W-1:0] : rem2[W-1:0];

  always @(posedge clk) begin
    if (run_q) begin
      if (a_rise) l_q <= {(W + 1) {1'b1}};
      else l_q <= {1'b0, dsel};
    end
  end

  always @(posedge clk) begin
    if (run_q) rem_q <= {W{1'b0}};
    else rem_q <= dsel;
  end

  always @(posedge clk) begin
    if (snap) pad_q <= {PAD{1'b0}};
    else if (busy_q) pad_q <= {pad_q[PAD-2:0], ge};
  end

  reg done_q;
  always @(posedge clk) begin
    if (rst) done_q <= 1'b0;
    else done_q <= busy_q & li_q;
  end

  // ------------------------------------------------------------------------------------------
  // Outputs (46080 X / T < 2^16: the quotient's low 16 bits are all of it)
  // ------------------------------------------------------------------------------------------
  wire [15:0] quo = {xs_q[15-PAD:0], pad_q};
  reg  [15:0] perr_q;
  reg         valid_q;
  always @(posedge clk) begin
    if (rst) perr_q <= 16'd0;
    else if (done_q) perr_q <= quo - NINETY;
  end

  always @(posedge clk) begin
    if (rst) valid_q <= 1'b0;
    else valid_q <= done_q;
  end

  wire _unused_ok = &{1'b0, xs_q[XW:16-PAD], WIN_PRE_25, STEP_PRE_25};

  assign phase_err = perr_q;
  assign valid     = valid_q;
  assign a_leads   = al_q;
  assign b_leads   = bl_q;

endmodule

`default_nettype wire
