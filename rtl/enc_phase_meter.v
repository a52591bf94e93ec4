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
//
// Inputs a and b must be synchronous to clk (from enc_conditioner, which also filters glitches).
`default_nettype none

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
    if (WINDOW_LOG2 < 8 || WINDOW_LOG2 > 24) begin : g_bad_window_log2
`ifdef __ICARUS__
      enc_phase_meter__parameter_WINDOW_LOG2_must_be_8_to_24 u_stop ();
`else
      $error("enc_phase_meter: parameter WINDOW_LOG2 must be in 8 .. 24");
`endif
    end
  endgenerate

  localparam integer W = WINDOW_LOG2;
  localparam integer XW = W + 6;  // 45 * X < 45 * 2^W < 2^(W+6)
  localparam integer NW = XW + 10;  // dividend 46080 * X = (45 * X) << 10: NW bits, <= 40
  localparam integer ITER_LAST_INT = NW - 1;  // divider steps NW-1 .. 0, one quotient bit each
  localparam [5:0] ITER_LAST = ITER_LAST_INT[5:0];
  localparam [15:0] NINETY = 16'd23040;  // 90 degrees in 1/256 degree
  localparam [XW-1:0] X_INC = 45;  // X is counted in 45ths of its weight (46080 = 45 * 1024)
  localparam [W:0] CNT_DEC = 1;

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

  reg known_q, dir_q;  // direction known / forward
  always @(posedge clk) begin
    if (rst) begin
      known_q <= 1'b0;
      dir_q   <= 1'b0;
    end else if (step) begin
      known_q <= 1'b1;
      dir_q   <= step_fwd;
    end
  end
  wire reversal = step & known_q & (step_fwd ^ dir_q);

  // ------------------------------------------------------------------------------------------
  // Window: sample count (counting down from all ones, so that a snapshot holds ~T, ready for
  // the subtractor) and 45 x XOR-high count, both snapshotted at each rising edge of A. The
  // counts cover the samples after the opening edge up to and including the closing one; in a
  // steady direction the XOR level on both edges is the same, so this is one whole-cycle span.
  // ------------------------------------------------------------------------------------------
  reg           run_q;  // a window is open
  reg           busy_q;  // divider running
  reg  [   W:0] cnt_q;  // ~(samples since the opening edge); cnt_q[W] falls at 2^W samples
  reg  [XW-1:0] x_q;  // 45 * (samples with a != b since the opening edge)
  reg  [   W:0] tn_q;  // ~T at the last rising edge of A (T <= 2^W)
  reg  [XW-1:0] xs_q;  // 45 * X at that edge; the divider's dividend shift register
  reg           have_q;  // tn_q / xs_q hold at least one whole cycle of this window

  wire          open_win = ~run_q & ~busy_q & a_rise;
  wire          close_win = run_q & ~cnt_q[W];
  wire [XW-1:0] x_step = xor_ab ? X_INC : {XW{1'b0}};
  wire [   W:0] cnt_d = cnt_q - CNT_DEC;
  wire [XW-1:0] x_d = x_q + x_step;
  wire          snap = run_q & cnt_q[W] & a_rise;  // not on the closing clock: T <= 2^W

  always @(posedge clk) begin
    if (rst) run_q <= 1'b0;
    else if (open_win) run_q <= 1'b1;
    else if (close_win || reversal) run_q <= 1'b0;
  end

  always @(posedge clk) begin
    if (open_win) begin
      cnt_q <= {(W + 1) {1'b1}};  // no sample counted yet
      x_q   <= {XW{1'b0}};
    end else if (run_q) begin
      cnt_q <= cnt_d;
      x_q   <= x_d;
    end
  end

  always @(posedge clk) begin
    if (rst || open_win) have_q <= 1'b0;
    else if (snap) have_q <= 1'b1;
  end

  // ------------------------------------------------------------------------------------------
  // Divider: floor((45 X << 10) / T), restoring, MSB first, one quotient bit per clock. xs_q
  // shifts its bits out MSB first (then the 10 zeros); run and busy never overlap.
  // ------------------------------------------------------------------------------------------
  wire          div_go = close_win & have_q & ~reversal;
  reg  [   5:0] iter_q;  // steps left - 1
  reg  [   W:0] rem_q;  // partial remainder, < T
  reg  [  15:0] quo_q;  // last 16 quotient bits (46080 X / T < 2^16, so the rest are 0)
  reg           done_q;

  wire [ W+1:0] rem2 = {rem_q, xs_q[XW-1]};
  wire [ W+2:0] diff = {1'b0, rem2} + {2'b01, tn_q} + {{(W + 2) {1'b0}}, 1'b1};  // rem2 - T + 2^(W+2)
  wire          ge = diff[W+2];
  wire          last_iter = (iter_q == 6'd0);

  always @(posedge clk) begin
    if (snap) begin
      tn_q <= cnt_d;
      xs_q <= x_d;
    end else if (busy_q) begin
      xs_q <= {xs_q[XW-2:0], 1'b0};
    end
  end

  always @(posedge clk) begin
    if (rst) busy_q <= 1'b0;
    else if (div_go) busy_q <= 1'b1;
    else if (last_iter) busy_q <= 1'b0;
  end

  always @(posedge clk) begin
    if (div_go) iter_q <= ITER_LAST;
    else if (busy_q) iter_q <= iter_q - 6'd1;
  end

  always @(posedge clk) begin
    if (div_go) rem_q <= {(W + 1) {1'b0}};
    else if (busy_q) rem_q <= ge ? diff[W:0] : rem2[W:0];
  end

  always @(posedge clk) begin
    if (busy_q) quo_q <= {quo_q[14:0], ge};
  end

  always @(posedge clk) begin
    if (rst) done_q <= 1'b0;
    else done_q <= busy_q & last_iter;
  end

  // ------------------------------------------------------------------------------------------
  // Outputs
  // ------------------------------------------------------------------------------------------
  reg [15:0] perr_q;
  reg        valid_q;
  always @(posedge clk) begin
    if (rst) perr_q <= 16'd0;
    else if (done_q) perr_q <= quo_q - NINETY;
  end

  always @(posedge clk) begin
    if (rst) valid_q <= 1'b0;
    else valid_q <= done_q;
  end

  wire _unused_ok = &{1'b0, diff[W+1], rem2[W+1]};

  assign phase_err = perr_q;
  assign valid     = valid_q;
  assign a_leads   = known_q & dir_q;
  assign b_leads   = known_q & ~dir_q;

endmodule

`default_nettype wire
