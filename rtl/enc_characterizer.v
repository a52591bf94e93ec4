// SPDX-License-Identifier: Apache-2.0
// enc_characterizer -- the encoding characteristics of Figure 3 of the note, measured in logic.
//
// For every encoder cycle (rising edge of A to the next one) it measures, in clocks, the widths
// of the four states (S10, S11, S01, S00 in forward order), and from them
//   period        P  = S10 + S11 + S01 + S00
//   pulse widths  HA, HB: the two states of the pulse of A (of B) that ended in the cycle,
//                      measured when the channel falls (in reverse rotation a B pulse spans
//                      the end of one cycle and the start of the next, so it is taken whole)
//   phase x 2     F  = S10 + S01: A rise to B rise plus A fall to B fall, i.e. twice the phase
//                      between the pulse centres, the note's definition of phase (in reverse
//                      rotation the same two states hold B rise to A rise and B fall to A fall).
// Over a window of WINDOW_CYCLES whole cycles it keeps the minimum and maximum of P, of the pulse
// widths (both channels), of F and of the state widths, and the total of the periods. At the end
// of the window each extreme is converted to electrical degrees against the mean period of the
// window, deg = 360 * x / (total / WINDOW_CYCLES) (the constant-speed normalization of an encoder
// test stand; "all cycles contain 360 electrical degrees", so the cycle error is the deviation of
// a period from the mean), and the errors are reported as the note defines them, the maximum
// deviation from nominal, signed (the extreme that lies farther from nominal), in 1/256 e-degree:
//   cycle_err = P  - 360,  pulse_err = HA, HB - 180,  phase_err = F/2 - 90,  state_err = S - 90
// `state_min` is the narrowest state in 1/256 e-degree and `pass` = (state_min >= min_state): set
// min_state to the room-temperature test limit of the note's guard-band example (90 - 44 = 46
// e-degrees, i.e. 11776) to screen units. The conversion is sequential, one extreme at a time
// in WIDE_W clocks (WIDE_W = CNT_W + 2 + bits of 92160 * WINDOW_CYCLES; 2 more for CNT_W = 8,
// 1 more for CNT_W = 9): x * 45 * WINDOW_CYCLES by shift-and-add, then a shift-subtract divider
// for the 19 quotient bits that matter (results of 2^18 / 256 e-degrees or more saturate, which
// leaves every output as it would be exact; the multiply and the divide share one adder), then
// one shared error datapath. `valid` pulses 8 x WIDE_W + 3 clocks after the clock that samples the
// window's last rising edge of A (as in the earlier, combinational-multiplier version), when all
// outputs are updated, and they hold until the next window's results.
//
// Windows: the first window opens on the first rising edge of A after rst; each later window on
// the first rising edge of A after the previous window's conversion. A window is abandoned (and
// a new one opens on the next rising edge of A) on a direction reversal, on a double transition
// (both channels changed between two samples: a state narrower than the sampling could resolve)
// or when a state lasts 2^CNT_W - 1 clocks or more (shaft too slow or stopped).
//
// Inputs a and b must be synchronous to clk (from enc_conditioner).
`default_nettype none
`include "enc_params.vh"

module enc_characterizer #(
    parameter integer CNT_W = 16,  // state width counter bits: states up to 2^CNT_W - 2 clocks; 8 .. 24
    parameter integer WINDOW_CYCLES = 500  // cycles per window (500 = one HEDS-5000 revolution); 1 .. 16384
) (
    input  wire               clk,
    input  wire               rst,        // synchronous, active high
    input  wire               a,          // channel A, synchronous to clk
    input  wire               b,          // channel B, synchronous to clk
    input  wire        [15:0] min_state,  // pass limit: narrowest state allowed, 1/256 e-degree
    output wire signed [15:0] cycle_err,  // period vs the window mean (360), 1/256 e-degree
    output wire signed [15:0] pulse_err,  // high time of A and B vs 180
    output wire signed [15:0] phase_err,  // phase between pulse centres vs 90
    output wire signed [15:0] state_err,  // state widths vs 90
    output wire        [15:0] state_min,  // narrowest state, 1/256 e-degree (saturates)
    output wire               pass,       // state_min >= min_state (for the last window)
    output wire               valid       // one-clock pulse when a window's results land
);

  generate
    `ENC_CHECK_CNT_W
    `ENC_CHECK_WINDOW_CYCLES
  endgenerate

  localparam integer NC_W = $clog2(WINDOW_CYCLES + 1);  // cycle counter bits
  localparam integer X_W = CNT_W + 2;  // a period: four states
  localparam integer T_W = X_W + NC_W;  // total of the periods of a window
  localparam integer M_INT = 45 * WINDOW_CYCLES;  // K = 360 * 256 * cycles = M * 2^11
  localparam integer M_W = $clog2(M_INT + 1);
  localparam integer K_W = M_W + 11;
  localparam integer WIDE_W = X_W + K_W;  // dividend x * K; also the clocks per conversion
  localparam integer Q_W = 18;  // quotient bits kept (saturating: above 2 x 360 deg, all alike)
  localparam integer RW = T_W + Q_W + 1;  // x * K < 2^(X_W+K_W) <= 2^(RW-2): fits
  localparam integer AW = RW - 9;  // adder bits: s = r << 1, bits 11 .. RW + 1
  localparam [M_W-1:0] M_BITS = M_INT[M_W-1:0];
  localparam [CNT_W-1:0] CNT_MAX = {CNT_W{1'b1}};
  localparam [CNT_W-1:0] CNT_ONE = 1;
  localparam [NC_W-1:0] NC_LAST = WINDOW_CYCLES[NC_W-1:0];
  localparam [NC_W-1:0] NC_ONE = 1;
  // clocks per extreme: WIDE_W (one or two more when CNT_W < 10: room for the steps below)
  localparam integer JOB_CLKS = (WIDE_W > M_W + Q_W + 5) ? WIDE_W : M_W + Q_W + 5;
  localparam integer STEP_LAST_INT = JOB_CLKS - 1;
  localparam [5:0] STEP_LAST = STEP_LAST_INT[5:0];
  localparam integer MUL_END_INT = JOB_CLKS - 1 - M_W;
  localparam [5:0] MUL_END = MUL_END_INT[5:0];  // last multiply step
  localparam integer DIV_FIRST_INT = Q_W + 3;
  localparam [5:0] DIV_FIRST = DIV_FIRST_INT[5:0];
  localparam [Q_W-1:0] DEG360 = 18'd92160;
  localparam [Q_W-1:0] DEG180 = 18'd46080;
  localparam [Q_W-1:0] DEG90 = 18'd23040;

  // ------------------------------------------------------------------------------------------
  // Transitions and direction
  // ------------------------------------------------------------------------------------------
  reg a_q, b_q;
  always @(posedge clk) begin
    a_q <= a;
    b_q <= b;
  end
  wire changed_a = a ^ a_q;
  wire changed_b = b ^ b_q;
  wire step = changed_a ^ changed_b;  // a valid transition
  wire double = changed_a & changed_b;  // both channels at once: abandon the window
  wire step_fwd = a ^ b_q;
  wire a_rise = step & changed_a & a;

  reg known_q, dir_q;
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
  // State widths: samples spent in the state just left (only S10 and S01 are kept: F = S10 + S01;
  // the period is counted directly, and the state and pulse extremes are tracked as they end)
  // ------------------------------------------------------------------------------------------
  reg [CNT_W-1:0] cnt_q;  // samples in the current state so far
  reg [CNT_W-1:0] s10_q, s01_q;
  reg [3:0] seen_q;  // states stored since the cycle began: {00, 01, 11, 10}
  wire stall = (cnt_q == CNT_MAX);

  always @(posedge clk) begin
    if (rst || step || double) cnt_q <= CNT_ONE;
    else if (!stall) cnt_q <= cnt_q + CNT_ONE;
  end

  wire [3:0] left_bit = {~a_q & ~b_q, ~a_q & b_q, a_q & b_q, a_q & ~b_q};
  // pulses: at a falling edge, the state just left plus the one before it
  reg [CNT_W-1:0] prev_w_q;  // width of the state left at the previous transition
  reg entered_q;  // the current state was entered by a transition (its width is whole)
  reg prev_ok_q;  // so was the previous one
  reg ha_ok_q, hb_ok_q;  // the last pulse of A (of B) was whole
  wire [X_W-1:0] pulse_w = {2'b00, cnt_q} + {2'b00, prev_w_q};
  wire fall = step & ((changed_a & ~a) | (changed_b & ~b));
  always @(posedge clk) begin
    if (rst || double) begin
      entered_q <= 1'b0;
      prev_ok_q <= 1'b0;
      ha_ok_q   <= 1'b0;
      hb_ok_q   <= 1'b0;
    end else if (step) begin
      entered_q <= 1'b1;
      prev_ok_q <= entered_q;
      if (changed_a && !a) ha_ok_q <= entered_q & prev_ok_q;
      if (changed_b && !b) hb_ok_q <= entered_q & prev_ok_q;
    end
  end
  always @(posedge clk) begin
    if (step) begin
      prev_w_q <= cnt_q;
      if (left_bit[0]) s10_q <= cnt_q;
      if (left_bit[2]) s01_q <= cnt_q;
    end
  end

  // period: clocks from one rising edge of A to the next (= S10 + S11 + S01 + S00 of the cycle:
  // every state of a cycle that is folded in is narrower than 2^CNT_W - 1, so no wrap)
  // Kept complemented (pcn = ~count, pern = ~period, and below ~total and the period extremes),
  // so the total is built, and the divider subtracts it, with plain adders.
  reg [X_W-1:0] pcn_q, pern_q;
  always @(posedge clk) begin
    if (a_rise) begin
      pcn_q  <= {{(X_W - 1) {1'b1}}, 1'b0};
      pern_q <= pcn_q;
    end else pcn_q <= pcn_q - {{(X_W - 1) {1'b0}}, 1'b1};
  end

  // ------------------------------------------------------------------------------------------
  // Cycle and window control
  // ------------------------------------------------------------------------------------------
  localparam [1:0] ST_WAIT = 2'd0, ST_MEAS = 2'd1, ST_CONV = 2'd2;
  reg [1:0] st_q;
  reg eval_q;  // the cycle that ended on the previous clock is complete: fold it in
  reg [NC_W-1:0] ncyc_q;
  wire abandon = reversal | double | stall;
  wire cycle_done = (st_q == ST_MEAS) & a_rise & ((seen_q | left_bit) == 4'b1111) & ha_ok_q &
                    hb_ok_q & ~abandon;
  wire window_full = eval_q & (ncyc_q == NC_LAST - NC_ONE);  // folding in the last cycle
  reg conv_done;
  reg conv_go_q;  // the window's extremes are final: start the conversion
  // A cycle that ends in ST_MEAS without being folded in (its pulses were not whole: only the
  // first cycle of a window, after rst or a double transition) restarts the state and pulse
  // extremes, which are tracked as each state and pulse ends, inside the window's cycles.
  wire skip = (st_q == ST_MEAS) & a_rise & ~abandon & ~cycle_done;
  wire in_win = (st_q == ST_MEAS) & ~window_full;

  always @(posedge clk) begin
    if (rst) st_q <= ST_WAIT;
    else begin
      case (st_q)
        ST_WAIT: if (a_rise && !abandon) st_q <= ST_MEAS;
        ST_MEAS:
        if (window_full) st_q <= ST_CONV;
        else if (abandon) st_q <= ST_WAIT;
        ST_CONV: if (conv_done) st_q <= ST_WAIT;
        default: st_q <= ST_WAIT;
      endcase
    end
  end

  always @(posedge clk) begin
    if (rst || a_rise) seen_q <= 4'b0000;
    else if (step) seen_q <= seen_q | left_bit;
  end

  always @(posedge clk) begin
    if (rst) begin
      eval_q    <= 1'b0;
      conv_go_q <= 1'b0;
    end else begin
      eval_q    <= cycle_done;
      conv_go_q <= (st_q == ST_MEAS) & window_full;
    end
  end

  // ------------------------------------------------------------------------------------------
  // Window extremes
  // ------------------------------------------------------------------------------------------
  wire [X_W-1:0] f2 = {2'b00, s10_q} + {2'b00, s01_q};

  reg [X_W-1:0] pn_lo_q, pn_hi_q;  // ~maximum and ~minimum period
  reg [X_W-1:0] h_min_q, h_max_q, f_min_q, f_max_q;
  reg [CNT_W-1:0] s_min_q, s_max_q;
  reg [T_W-1:0] totn_q;  // ~total
  // minimum and maximum start at the top and the bottom of their range, so the first value
  // folded in replaces both
  // v < lo: carry of lo + ~v; v > hi: no carry of hi + ~v + 1 (both on ~v: one set of inverters)
  wire [X_W-1:0] per_t = ~pern_q;
  wire [X_W:0] lt_p = {1'b0, pn_lo_q} + {1'b0, per_t};
  wire [X_W+1:0] ge_p = {1'b0, pn_hi_q, 1'b1} + {1'b0, per_t, 1'b1};
  wire [T_W+1:0] totn_next = {totn_q, 1'b1} + {{NC_W{1'b1}}, pern_q, 1'b1};  // ~(total + period)
  wire [X_W:0] lt_f = {1'b0, f_min_q} + {1'b0, ~f2};
  wire [X_W+1:0] ge_f = {1'b0, f_max_q, 1'b1} + {1'b0, ~f2, 1'b1};
  wire [X_W:0] lt_h = {1'b0, h_min_q} + {1'b0, ~pulse_w};
  wire [X_W+1:0] ge_h = {1'b0, h_max_q, 1'b1} + {1'b0, ~pulse_w, 1'b1};
  wire [CNT_W:0] lt_s = {1'b0, s_min_q} + {1'b0, ~cnt_q};
  wire [CNT_W+1:0] ge_s = {1'b0, s_max_q, 1'b1} + {1'b0, ~cnt_q, 1'b1};

  always @(posedge clk) begin
    if (st_q == ST_WAIT) begin
      ncyc_q  <= {NC_W{1'b0}};
      totn_q  <= {T_W{1'b1}};
      pn_lo_q <= {X_W{1'b1}};
      pn_hi_q <= {X_W{1'b0}};
      f_min_q <= {X_W{1'b1}};
      f_max_q <= {X_W{1'b0}};
    end else if (eval_q) begin
      ncyc_q  <= ncyc_q + NC_ONE;
      totn_q  <= totn_next[T_W:1];
      if (lt_p[X_W]) pn_lo_q <= pern_q;
      if (!ge_p[X_W+1]) pn_hi_q <= pern_q;
      if (lt_f[X_W]) f_min_q <= f2;
      if (!ge_f[X_W+1]) f_max_q <= f2;
    end
  end

  always @(posedge clk) begin
    if (st_q == ST_WAIT || skip) begin
      s_min_q <= {CNT_W{1'b1}};
      s_max_q <= {CNT_W{1'b0}};
      h_min_q <= {X_W{1'b1}};
      h_max_q <= {X_W{1'b0}};
    end else if (in_win) begin
      if (step) begin  // a state of the window's cycles ends
        if (lt_s[CNT_W]) s_min_q <= cnt_q;
        if (!ge_s[CNT_W+1]) s_max_q <= cnt_q;
      end
      if (fall) begin  // a pulse ends
        if (lt_h[X_W]) h_min_q <= pulse_w;
        if (!ge_h[X_W+1]) h_max_q <= pulse_w;
      end
    end
  end

  // ------------------------------------------------------------------------------------------
  // Conversion to degrees: r = floor(x * K / total) for the eight extremes, one at a time, in
  // J = JOB_CLKS clocks each (step counter c = J-1 .. 0; J = WIDE_W unless CNT_W < 10; at c = J-1
  // the extreme is registered). K = M * 2^11 (M = 45 * WINDOW_CYCLES):
  //   c = J-2 .. J-1-M_W           r = x * K by shift-and-add (x * 2^11 added, MSB of M first);
  //                                then r[RW-1:Q_W+1] = (x * K) >> (Q_W + 1) is the remainder
  //   c = Q_W+3 .. 3               Q_W+1 restoring divide steps bring in the rest of x * K;
  //                                the quotient bits shift into r[Q_W:0] (bit Q_W: saturate)
  // One adder does both: in the divide steps it adds ~total + 1 at bit Q_W+1 (and all ones plus
  // a carry-in below it, which passes those bits through).
  //   c = 2                        d = result - nominal (and the minimum's result kept)
  //   c = 1, 0                     maximum: the d farther from nominal, then halved, saturated
  // ------------------------------------------------------------------------------------------
  reg  [       2:0] job_q;  // which extreme
  reg  [       5:0] c_q;  // step counter
  reg               conv_q;  // converting
  reg  [    RW-1:0] r_q;  // {remainder, dividend bits / quotient}
  reg  [     Q_W:0] r_lo_q;  // the minimum's result of the current pair
  reg  [   X_W-1:0] x_sel;

  always @(*) begin
    case (job_q)
      3'd0: x_sel = ~pn_hi_q;
      3'd1: x_sel = ~pn_lo_q;
      3'd2: x_sel = h_min_q;
      3'd3: x_sel = h_max_q;
      3'd4: x_sel = f_min_q;
      3'd5: x_sel = f_max_q;
      3'd6: x_sel = {2'b00, s_min_q};
      default: x_sel = {2'b00, s_max_q};
    endcase
  end

  reg  [X_W-1:0] x_q;  // the extreme being converted (registered: off the adder's path)
  reg  [M_W-1:0] ms_q;  // bits of M still to multiply by, MSB first
  reg             mul_ph;  // multiply step
  always @(posedge clk) begin
    x_q <= x_sel;
    if (c_q == STEP_LAST) begin
      ms_q   <= M_BITS;
      mul_ph <= conv_q;
    end else begin
      ms_q <= {ms_q[M_W-2:0], 1'b0};
      if (c_q == MUL_END) mul_ph <= 1'b0;
    end
  end
  wire        div_ph = (c_q <= DIV_FIRST) & (c_q >= 6'd3);
  wire        res_ph = (c_q == 6'd2);
  wire        pick_ph = (c_q == 6'd1);
  wire        last_bit = (c_q == 6'd0);
  // adder on bits 11 .. RW of s = r << 1, plus one bit on top (the divide step's sign)
  wire [AW-1:0] a_op = {1'b0, r_q[RW-1:10]};
  wire [AW-1:0] b_op = mul_ph ? {{(AW - X_W) {1'b0}}, x_q & {X_W{ms_q[M_W-1]}}} :
                                {2'b11, totn_q, 8'hff};
  wire [AW:0] sum_c = {a_op, 1'b1} + {b_op, ~mul_ph};
  wire [AW-1:0] sum = sum_c[AW:1];
  wire        ge = ~sum[AW-1];  // divide: rem2 >= total
  wire        conv_start = conv_go_q;
  // carry-in bits of the adders;
  // sum bit AW-2 (bit RW of s): zero after a multiply step, dropped by a divide step (rem < total)
  wire        _unused_ok = &{1'b0, sum_c[0], totn_next[0], totn_next[T_W+1], sum[AW-2]};
  wire [RW-1:0] r_next;
  assign r_next[RW-1:Q_W+1] = (mul_ph | ge) ? sum[AW-3:8] : r_q[RW-2:Q_W];
  assign r_next[Q_W:11] = sum[7:0];
  assign r_next[10:1] = r_q[9:0];
  assign r_next[0] = ~mul_ph & ge;

  always @(posedge clk) begin
    if (rst) begin
      conv_q <= 1'b0;
      conv_done <= 1'b0;
    end else begin
      conv_done <= conv_q & last_bit & (job_q == 3'd7);
      if (conv_start) conv_q <= 1'b1;
      else if (conv_q && last_bit && job_q == 3'd7) conv_q <= 1'b0;
    end
  end

  always @(posedge clk) begin
    if (conv_start) begin
      job_q <= 3'd0;
      c_q   <= STEP_LAST;
      r_q   <= {RW{1'b0}};
    end else if (conv_q) begin
      if (last_bit) begin  // next job
        job_q <= job_q + 3'd1;
        c_q   <= STEP_LAST;
        r_q   <= {RW{1'b0}};
      end else begin
        c_q <= c_q - 6'd1;
        if (mul_ph || div_ph) r_q <= r_next;
      end
    end
  end


  // ------------------------------------------------------------------------------------------
  // Errors: the extreme farther from nominal, signed, saturated to 16 bits. With lo <= hi, hi is
  // at least as far from nominal as lo exactly when hi + lo >= 2 * nominal. One datapath, shared
  // by the four pairs; the results wait in e_q until the last pair is done.
  // ------------------------------------------------------------------------------------------
  wire [Q_W:0] q_res = r_q[Q_W:0];  // bit Q_W: 2^Q_W or more (the rest may be garbage)
  reg  [Q_W-1:0] nom;
  always @(*) begin
    case (job_q[2:1])
      2'd0: nom = DEG360;
      2'd1: nom = DEG180;
      2'd2: nom = DEG180;
      default: nom = DEG90;
    endcase
  end
  wire halve = (job_q[2:1] == 2'd2);  // phase: the extremes are of twice the phase
  wire signed [Q_W+1:0] d_res = $signed({1'b0, q_res}) - $signed({2'b00, nom});
  reg signed [Q_W+1:0] d_lo_q, d_hi_q;
  wire signed [Q_W+2:0] d_sum = {d_hi_q[Q_W+1], d_hi_q} + {d_lo_q[Q_W+1], d_lo_q};
  reg signed [Q_W+1:0] dev_q;
  wire signed [Q_W+1:0] dev_h = halve ? (dev_q >>> 1) : dev_q;
  wire [15:0] dev_sat = (dev_h > 32767) ? 16'h7fff : (dev_h < -32768) ? 16'h8000 : dev_h[15:0];

  reg [15:0] e_q[0:3];
  always @(posedge clk) begin
    if (conv_q && res_ph) begin
      if (!job_q[0]) begin
        r_lo_q <= q_res;
        d_lo_q <= d_res;
      end else d_hi_q <= d_res;
    end
    if (conv_q && pick_ph) dev_q <= d_sum[Q_W+2] ? d_lo_q : d_hi_q;
    if (conv_q && last_bit && job_q[0]) e_q[job_q[2:1]] <= dev_sat;
  end

  reg [15:0] cyc_e_q, pul_e_q, pha_e_q, sta_e_q, smin_q;
  reg pass_q, valid_q;
  always @(posedge clk) begin
    if (rst) begin
      cyc_e_q <= 16'd0;
      pul_e_q <= 16'd0;
      pha_e_q <= 16'd0;
      sta_e_q <= 16'd0;
      smin_q  <= 16'd0;
      pass_q  <= 1'b0;
      valid_q <= 1'b0;
    end else begin
      valid_q <= conv_done;
      if (conv_done) begin  // r_lo_q: the narrowest state's result
        cyc_e_q <= e_q[0];
        pul_e_q <= e_q[1];
        pha_e_q <= e_q[2];
        sta_e_q <= e_q[3];
        smin_q  <= (|r_lo_q[Q_W:16]) ? 16'hffff : r_lo_q[15:0];
        pass_q  <= (r_lo_q >= {{(Q_W - 15) {1'b0}}, min_state});
      end
    end
  end

  assign cycle_err = cyc_e_q;
  assign pulse_err = pul_e_q;
  assign phase_err = pha_e_q;
  assign state_err = sta_e_q;
  assign state_min = smin_q;
  assign pass      = pass_q;
  assign valid     = valid_q;

endmodule

`default_nettype wire
