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
// e-degrees, i.e. 11776) to screen units. The conversion is one sequential shift-subtract
// divider, shared by the eight extremes (8 x (WIDE_W) clocks); `valid` pulses when all outputs
// are updated, and they hold until the next window's results.
//
// Windows: the first window opens on the first rising edge of A after rst; each later window on
// the first rising edge of A after the previous window's conversion. A window is abandoned (and
// a new one opens on the next rising edge of A) on a direction reversal, on a double transition
// (both channels changed between two samples: a state narrower than the sampling could resolve)
// or when a state lasts 2^CNT_W - 1 clocks or more (shaft too slow or stopped).
//
// Inputs a and b must be synchronous to clk (from enc_conditioner).
`default_nettype none

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
    if (CNT_W < 8 || CNT_W > 24) begin : g_bad_cnt_w
`ifdef __ICARUS__
      enc_characterizer__parameter_CNT_W_must_be_8_to_24 u_stop ();
`else
      $error("enc_characterizer: parameter CNT_W must be in 8 .. 24");
`endif
    end
    if (WINDOW_CYCLES < 1 || WINDOW_CYCLES > 16384) begin : g_bad_window_cycles
`ifdef __ICARUS__
      enc_characterizer__parameter_WINDOW_CYCLES_must_be_1_to_16384 u_stop ();
`else
      $error("enc_characterizer: parameter WINDOW_CYCLES must be in 1 .. 16384");
`endif
    end
  endgenerate

  localparam integer NC_W = $clog2(WINDOW_CYCLES + 1);  // cycle counter bits
  localparam integer X_W = CNT_W + 2;  // a period: four states
  localparam integer T_W = X_W + NC_W;  // total of the periods of a window
  localparam integer K_INT = 92160 * WINDOW_CYCLES;  // 360 * 256 * cycles: deg = x * K / total
  localparam integer K_W = $clog2(K_INT + 1);
  localparam integer WIDE_W = X_W + K_W;  // dividend x * K; also the divider's step count
  localparam integer Q_W = 24;  // quotient bits kept (saturating): 1/256 e-degree up to 65535 deg
  localparam [K_W-1:0] K = K_INT[K_W-1:0];
  localparam [CNT_W-1:0] CNT_MAX = {CNT_W{1'b1}};
  localparam [CNT_W-1:0] CNT_ONE = 1;
  localparam [NC_W-1:0] NC_LAST = WINDOW_CYCLES[NC_W-1:0];
  localparam [NC_W-1:0] NC_ONE = 1;
  localparam integer STEP_LAST_INT = WIDE_W - 1;
  localparam [5:0] STEP_LAST = STEP_LAST_INT[5:0];
  localparam [Q_W-1:0] DEG360 = 24'd92160;
  localparam [Q_W-1:0] DEG180 = 24'd46080;
  localparam [Q_W-1:0] DEG90 = 24'd23040;

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
  // State widths: samples spent in the state just left, stored by state
  // ------------------------------------------------------------------------------------------
  reg [CNT_W-1:0] cnt_q;  // samples in the current state so far
  reg [CNT_W-1:0] s10_q, s11_q, s01_q, s00_q;
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
  reg [X_W-1:0] ha_q, hb_q;  // last whole pulse of A, of B
  reg ha_ok_q, hb_ok_q;
  wire [X_W-1:0] pulse_w = {2'b00, cnt_q} + {2'b00, prev_w_q};
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
      if (changed_a && !a) ha_q <= pulse_w;
      if (changed_b && !b) hb_q <= pulse_w;
    end
  end

  always @(posedge clk) begin
    if (step) begin
      if (left_bit[0]) s10_q <= cnt_q;
      if (left_bit[1]) s11_q <= cnt_q;
      if (left_bit[2]) s01_q <= cnt_q;
      if (left_bit[3]) s00_q <= cnt_q;
    end
  end

  // ------------------------------------------------------------------------------------------
  // Cycle and window control
  // ------------------------------------------------------------------------------------------
  localparam [1:0] ST_WAIT = 2'd0, ST_MEAS = 2'd1, ST_CONV = 2'd2;
  reg [1:0] st_q;
  reg eval_q;  // the cycle that ended on the previous clock is complete: fold it in
  reg first_q;  // no cycle folded in yet this window
  reg [NC_W-1:0] ncyc_q;
  wire abandon = reversal | double | stall;
  wire cycle_done = (st_q == ST_MEAS) & a_rise & ((seen_q | left_bit) == 4'b1111) & ha_ok_q &
                    hb_ok_q & ~abandon;
  wire window_full = eval_q & (ncyc_q == NC_LAST - NC_ONE);  // folding in the last cycle
  reg conv_done;
  reg conv_go_q;  // the window's extremes are final: start the conversion

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
  // Per-cycle quantities and window extremes
  // ------------------------------------------------------------------------------------------
  wire [X_W-1:0] s10 = {2'b00, s10_q}, s11 = {2'b00, s11_q}, s01 = {2'b00, s01_q}, s00 = {2'b00, s00_q};
  wire [X_W-1:0] per = s10 + s11 + s01 + s00;
  wire [X_W-1:0] ha = ha_q;
  wire [X_W-1:0] hb = hb_q;
  wire [X_W-1:0] f2 = s10 + s01;
  wire [X_W-1:0] h_lo = (ha < hb) ? ha : hb;
  wire [X_W-1:0] h_hi = (ha < hb) ? hb : ha;
  wire [X_W-1:0] s_lo_a = (s10 < s11) ? s10 : s11;
  wire [X_W-1:0] s_lo_b = (s01 < s00) ? s01 : s00;
  wire [X_W-1:0] s_hi_a = (s10 < s11) ? s11 : s10;
  wire [X_W-1:0] s_hi_b = (s01 < s00) ? s00 : s01;
  wire [X_W-1:0] s_lo = (s_lo_a < s_lo_b) ? s_lo_a : s_lo_b;
  wire [X_W-1:0] s_hi = (s_hi_a < s_hi_b) ? s_hi_b : s_hi_a;

  reg [X_W-1:0] p_min_q, p_max_q, h_min_q, h_max_q, f_min_q, f_max_q, s_min_q, s_max_q;
  reg [T_W-1:0] total_q;

  always @(posedge clk) begin
    if (st_q == ST_WAIT) begin
      first_q <= 1'b1;
      ncyc_q  <= {NC_W{1'b0}};
      total_q <= {T_W{1'b0}};
    end else if (eval_q) begin
      first_q <= 1'b0;
      ncyc_q  <= ncyc_q + NC_ONE;
      total_q <= total_q + {{NC_W{1'b0}}, per};
      if (first_q || per < p_min_q) p_min_q <= per;
      if (first_q || per > p_max_q) p_max_q <= per;
      if (first_q || h_lo < h_min_q) h_min_q <= h_lo;
      if (first_q || h_hi > h_max_q) h_max_q <= h_hi;
      if (first_q || f2 < f_min_q) f_min_q <= f2;
      if (first_q || f2 > f_max_q) f_max_q <= f2;
      if (first_q || s_lo < s_min_q) s_min_q <= s_lo;
      if (first_q || s_hi > s_max_q) s_max_q <= s_hi;
    end
  end

  // ------------------------------------------------------------------------------------------
  // Conversion to degrees: r = floor(x * K / total) for the eight extremes, one at a time
  // ------------------------------------------------------------------------------------------
  reg  [       2:0] job_q;  // which extreme
  reg  [       5:0] bit_q;  // dividend bit being brought down
  reg               conv_q;  // dividing
  reg  [   T_W-1:0] rem_q;
  reg  [   Q_W-1:0] quo_q;
  reg               ovf_q;  // quotient above Q_W bits: saturate
  reg  [   Q_W-1:0] r_q   [0:7];
  reg  [   X_W-1:0] x_sel;

  always @(*) begin
    case (job_q)
      3'd0: x_sel = p_min_q;
      3'd1: x_sel = p_max_q;
      3'd2: x_sel = h_min_q;
      3'd3: x_sel = h_max_q;
      3'd4: x_sel = f_min_q;
      3'd5: x_sel = f_max_q;
      3'd6: x_sel = s_min_q;
      default: x_sel = s_max_q;
    endcase
  end

  wire [WIDE_W-1:0] dividend = {{K_W{1'b0}}, x_sel} * {{X_W{1'b0}}, K};
  wire [      63:0] dividend64 = {{(64 - WIDE_W) {1'b0}}, dividend};
  wire [     T_W:0] rem2 = {rem_q, dividend64[bit_q]};
  wire [   T_W+1:0] diff = {1'b0, rem2} - {2'b00, total_q};
  wire              ge = ~diff[T_W+1];
  wire              last_bit = (bit_q == 6'd0);
  wire              conv_start = conv_go_q;

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
      bit_q <= STEP_LAST;
      rem_q <= {T_W{1'b0}};
      quo_q <= {Q_W{1'b0}};
      ovf_q <= 1'b0;
    end else if (conv_q) begin
      if (last_bit) begin  // store this job's result, start the next
        r_q[job_q] <= (ovf_q || quo_q[Q_W-1]) ? {Q_W{1'b1}} : {quo_q[Q_W-2:0], ge};
        job_q <= job_q + 3'd1;
        bit_q <= STEP_LAST;
        rem_q <= {T_W{1'b0}};
        quo_q <= {Q_W{1'b0}};
        ovf_q <= 1'b0;
      end else begin
        bit_q <= bit_q - 6'd1;
        rem_q <= ge ? diff[T_W-1:0] : rem2[T_W-1:0];
        quo_q <= {quo_q[Q_W-2:0], ge};
        ovf_q <= ovf_q | quo_q[Q_W-1];
      end
    end
  end

  // ------------------------------------------------------------------------------------------
  // Errors: the extreme farther from nominal, signed, saturated to 16 bits
  // ------------------------------------------------------------------------------------------
  function automatic [15:0] worst_dev;
    input [Q_W-1:0] lo, hi, nominal;
    input halve;  // phase: the extremes are of twice the phase
    reg signed [Q_W+1:0] d_lo, d_hi, d;
    begin
      d_lo = $signed({2'b00, lo}) - $signed({2'b00, nominal});
      d_hi = $signed({2'b00, hi}) - $signed({2'b00, nominal});
      d = ((d_hi < 0 ? -d_hi : d_hi) >= (d_lo < 0 ? -d_lo : d_lo)) ? d_hi : d_lo;
      if (halve) d = d >>> 1;
      if (d > 32767) worst_dev = 16'h7fff;
      else if (d < -32768) worst_dev = 16'h8000;
      else worst_dev = d[15:0];
    end
  endfunction

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
      if (conv_done) begin
        cyc_e_q <= worst_dev(r_q[0], r_q[1], DEG360, 1'b0);
        pul_e_q <= worst_dev(r_q[2], r_q[3], DEG180, 1'b0);
        pha_e_q <= worst_dev(r_q[4], r_q[5], DEG180, 1'b1);
        sta_e_q <= worst_dev(r_q[6], r_q[7], DEG90, 1'b0);
        smin_q  <= (|r_q[6][Q_W-1:16]) ? 16'hffff : r_q[6][15:0];
        pass_q  <= (r_q[6] >= {8'd0, min_state});
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
