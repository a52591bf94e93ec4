// SPDX-License-Identifier: Apache-2.0
// enc_qei_core -- the counting core of enc_qei: decode, count function, range, index, probe,
// compare and the events they raise.
//
// Inputs are the conditioned channels (enc_conditioner_rt outputs). Channel A and B go through
// SWAP_AB then INV_A / INV_B, then into the library's decoders, held in reset while the
// conditioner is not valid and for one clock after FUNC, SWAP_AB, INV_A or INV_B change:
//   enc_x4_decoder    -> every valid transition (cnt, up) and the quadrature error
//   enc_x1_hysteresis -> FUNC = x1_hyst (Figure 14)
// The Linux count functions come from the x4 decoder's transitions and the levels of the
// transition's present and previous sample (a1/a2, b1/b2 below, aligned with its outputs):
//   x4 every transition; x2a/x2b transitions of A/B; x1a: A rising forward (+1), A falling
//   backward (-1); x1b the same on B; pulse_dir / increase / decrease: rising edges of A (B = up).
// Count priority in one clock: COUNT write > index preset > count step. Range modes: free,
// modulo (0 .. CEILING), limit (stops at 0 / CEILING), non_recycle (stops until COUNT is
// written). Every decoder output has latency 1 from its sample and the count step one more
// register; the index edge detector is delayed the same, so an index acts in the clock of the
// transition it sees.
// For Fmax, the comparisons with CEILING and the zero tests of the loads are flag registers:
// CEILING acts two clocks after it changes, a COUNT_LO write loads the count one clock after
// its strobe (with the COUNT_HI word staged as of the strobe), and an index preset loads PRESET
// as it was one clock earlier. A bus access takes longer than these delays: software cannot tell.
`default_nettype none

module enc_qei_core #(
    parameter integer COUNT_W = 32,  // counter width, 8 .. 64 (checked by enc_qei)
    parameter integer TS_W    = 32   // timebase width, 16 .. 32 (checked by enc_qei)
) (
    input  wire               clk,
    input  wire               rst,            // synchronous, active high
    // conditioned inputs
    input  wire               a_c,            // channel A from the conditioner
    input  wire               b_c,            // channel B
    input  wire               z_c,            // index channel Z
    input  wire               probe_c,        // probe input
    input  wire               valid,          // conditioner outputs show the inputs
    // configuration (CTRL, PRESET, CEILING, COMPARE, INDEX_CTRL, PROBE_CTRL)
    input  wire               en,
    input  wire               swap_ab,
    input  wire               inv_a,
    input  wire               inv_b,
    input  wire               inv_z,
    input  wire [3:0]         func,
    input  wire [1:0]         range,
    input  wire [COUNT_W-1:0] preset,
    input  wire [COUNT_W-1:0] ceiling,
    input  wire [COUNT_W-1:0] compare,
    input  wire [1:0]         idx_action,
    input  wire               idx_oneshot,
    input  wire               idx_edge,       // 0 rising, 1 falling
    input  wire               idx_gate_en,
    input  wire               idx_gate_a,
    input  wire               idx_gate_b,
    input  wire               idx_arm,
    input  wire               probe_en,
    input  wire               probe_edge,     // 0 rising, 1 falling
    input  wire               probe_once,
    input  wire [TS_W-1:0]    timebase,
    // COUNT_LO / COUNT_HI (external registers)
    input  wire               count_lo_rd,    // read of COUNT_LO: latch the high word
    input  wire               count_lo_wr,    // write of COUNT_LO: load the count
    input  wire [31:0]        count_lo_wdata,
    input  wire               count_hi_wr,    // write of COUNT_HI: stage the high word
    input  wire [31:0]        count_hi_wdata,
    output wire [31:0]        count_lo_rdata,
    output wire [31:0]        count_hi_rdata,
    // state
    output wire [COUNT_W-1:0] count,
    output wire [COUNT_W-1:0] idx_latch,
    output wire [COUNT_W-1:0] probe_latch,
    output wire [TS_W-1:0]    probe_time,
    output wire               a_eff,          // A, B, Z as the decoders see them
    output wire               b_eff,
    output wire               z_eff,
    output wire               dir,            // direction of the last count step, 1 = up
    output wire               idx_armed,
    output wire               stopped,        // non_recycle stopped
    output wire               idx_disarm,     // one-shot index acted: clear INDEX_CTRL.ARM
    output wire               probe_disarm,   // once-probe latched: clear PROBE_CTRL.EN
    // for the timing unit
    output wire               step_up,        // count function step (enabled, before the range)
    output wire               step_dn,
    output wire               applied_up,     // a step the count took
    output wire               applied_dn,
    output wire               edge_any,       // valid quadrature transition (latency as cnt)
    output wire               edge_a_rise,    // rising edge of A
    // events (one clock each)
    output wire               ev_overflow,
    output wire               ev_underflow,
    output wire               ev_index,
    output wire               ev_probe,
    output wire               ev_cmp,
    output wire               ev_qerr,
    output wire               ev_dir_change,
    output wire               cmp_out
);

  localparam [3:0] F_X4 = 4'd0, F_X2A = 4'd1, F_X2B = 4'd2, F_X1A = 4'd3, F_X1B = 4'd4,
                   F_PULSE_DIR = 4'd5, F_INCREASE = 4'd6, F_DECREASE = 4'd7, F_X1_HYST = 4'd8;
  localparam [1:0] R_FREE = 2'd0, R_MODULO = 2'd1, R_LIMIT = 2'd2, R_NON_RECYCLE = 2'd3;
  localparam [1:0] I_PRESET = 2'd1, I_LATCH = 2'd2;

  function [63:0] zext64;
    input [COUNT_W-1:0] v;
    begin
      zext64 = 64'd0;
      zext64[COUNT_W-1:0] = v;
    end
  endfunction

  // ---- channel selection and decoder reset ----------------------------------------------------
  wire a_sw = swap_ab ? b_c : a_c;
  wire b_sw = swap_ab ? a_c : b_c;
  assign a_eff = a_sw ^ inv_a;
  assign b_eff = b_sw ^ inv_b;
  assign z_eff = z_c ^ inv_z;

  reg  [6:0] cfg_q;  // {func, swap_ab, inv_a, inv_b} last clock
  wire [6:0] cfg   = {func, swap_ab, inv_a, inv_b};
  wire       dec_rst = rst | ~valid | (cfg != cfg_q);

  always @(posedge clk) begin
    if (rst) begin
      cfg_q <= 7'd0;
    end else begin
      cfg_q <= cfg;
    end
  end

  wire x4_cnt, x4_up, x4_err;
  wire h_up, h_dn, h_err_unused;

  enc_x4_decoder u_x4 (
      .clk      (clk),
      .rst      (dec_rst),
      .a        (a_eff),
      .b        (b_eff),
      .cnt_pulse(x4_cnt),
      .up       (x4_up),
      .error    (x4_err)
  );

  enc_x1_hysteresis u_x1h (
      .clk     (clk),
      .rst     (dec_rst),
      .a       (a_eff),
      .b       (b_eff),
      .up_pulse(h_up),
      .dn_pulse(h_dn),
      .error   (h_err_unused)  // the same condition as x4_err
  );

  // Levels of the present (1) and previous (2) sample of the transition the decoders report now,
  // and A's rising edge for the pulse functions (registered like the decoders' outputs).
  reg a1_q, a2_q, b1_q, b2_q, ok1_q, arise_q;

  always @(posedge clk) begin
    if (dec_rst) begin
      ok1_q   <= 1'b0;
      arise_q <= 1'b0;
    end else begin
      ok1_q   <= 1'b1;
      arise_q <= ok1_q & a_eff & ~a1_q;
    end
    a1_q <= a_eff;
    a2_q <= a1_q;
    b1_q <= b_eff;
    b2_q <= b1_q;
  end

  // ---- count function ---------------------------------------------------------------------------
  wire a_moved = a1_q ^ a2_q;
  wire b_moved = b1_q ^ b2_q;
  reg  fup, fdn, quad;

  always @(*) begin
    fup  = 1'b0;
    fdn  = 1'b0;
    quad = 1'b1;
    case (func)
      F_X4: begin
        fup = x4_cnt & x4_up;
        fdn = x4_cnt & ~x4_up;
      end
      F_X2A: begin
        fup = x4_cnt & a_moved & x4_up;
        fdn = x4_cnt & a_moved & ~x4_up;
      end
      F_X2B: begin
        fup = x4_cnt & b_moved & x4_up;
        fdn = x4_cnt & b_moved & ~x4_up;
      end
      F_X1A: begin
        fup = x4_cnt & a_moved & x4_up & a1_q;
        fdn = x4_cnt & a_moved & ~x4_up & ~a1_q;
      end
      F_X1B: begin
        fup = x4_cnt & b_moved & x4_up & b1_q;
        fdn = x4_cnt & b_moved & ~x4_up & ~b1_q;
      end
      F_PULSE_DIR: begin
        fup  = arise_q & b1_q;
        fdn  = arise_q & ~b1_q;
        quad = 1'b0;
      end
      F_INCREASE: begin
        fup  = arise_q;
        quad = 1'b0;
      end
      F_DECREASE: begin
        fdn  = arise_q;
        quad = 1'b0;
      end
      F_X1_HYST: begin
        fup = h_up;
        fdn = h_dn;
      end
      default: quad = 1'b0;
    endcase
  end

  // One register stage between the count function and the count (for Fmax): the steps, the
  // edges and the index hit below are all delayed alike.
  reg step_up_q, step_dn_q, edge_any_q, edge_a_rise_q;

  always @(posedge clk) begin
    if (rst) begin
      step_up_q     <= 1'b0;
      step_dn_q     <= 1'b0;
      edge_any_q    <= 1'b0;
      edge_a_rise_q <= 1'b0;
    end else begin
      step_up_q     <= en & fup;
      step_dn_q     <= en & fdn;
      edge_any_q    <= x4_cnt;
      edge_a_rise_q <= x4_cnt & a_moved & a1_q;
    end
  end

  assign step_up     = step_up_q;
  assign step_dn     = step_dn_q;
  assign edge_any    = edge_any_q;
  assign edge_a_rise = edge_a_rise_q;
  assign ev_qerr     = quad & x4_err;

  // ---- range ---------------------------------------------------------------------------------------
  reg  [COUNT_W-1:0] count_q;
  reg  [COUNT_W-1:0] count_d;
  reg                stopped_q;
  reg                stopped_d;
  reg  [31:0]        hi_stage_q;
  reg  [31:0]        hi_latch_q;

  reg  zero_q;  // count_q == 0: a flag register, set from the next count's candidates (Fmax)
  wire at_zero = zero_q;
  wire at_max  = (count_q == {COUNT_W{1'b1}});

  // a >= b for COUNT_W-bit values, from 16-bit slices compared side by side (short carry chains;
  // the slices' > and >= are carry chains too, no equality trees)
  localparam integer NSL = (COUNT_W + 15) / 16;

  function ge_w;
    input [COUNT_W-1:0] a;
    input [COUNT_W-1:0] b;
    reg   [63:0] a64, b64;
    integer      k;
    begin
      a64  = zext64(a);
      b64  = zext64(b);
      ge_w = (a64[15:0] >= b64[15:0]);
      for (k = 1; k < NSL; k = k + 1) begin  // (slice equal: both >= and not >)
        ge_w = (a64[16*k +: 16] > b64[16*k +: 16]) | ((a64[16*k +: 16] >= b64[16*k +: 16]) & ge_w);
      end
    end
  endfunction

  // ---- CEILING pipeline (Fmax) ----------------------------------------------------------------------
  // The count uses CEILING as it was two clocks earlier (ceil_q), so that at_ceil = (count >=
  // CEILING) can be a flag register (at_ceil_q), set like zero_q from the next count's candidates,
  // each compared with the next clock's ceiling (ceil_nx_q) by a comparator between registers.
  // Not reset: a pure delay of the CEILING register.
  reg [COUNT_W-1:0] ceil_nx_q;       // CEILING one clock ago: the ceiling of the next clock
  reg [COUNT_W-1:0] ceil_nx_m1_q;    // ... minus one
  reg               ceil_nx_zero_q;  // ... is 0
  reg [COUNT_W-1:0] ceil_q;          // CEILING two clocks ago: the ceiling the count uses now
  reg               ceil_zero_q;     // ... is 0
  reg               ceil_wrap_ge_q;  // ceil_q >= ceil_nx_q (a modulo wrap down to ceil_q)

  always @(posedge clk) begin
    ceil_nx_q      <= ceiling;
    ceil_nx_m1_q   <= ceiling - {{(COUNT_W-1){1'b0}}, 1'b1};
    ceil_nx_zero_q <= (ceiling == {COUNT_W{1'b0}});
    ceil_q         <= ceil_nx_q;
    ceil_zero_q    <= ceil_nx_zero_q;
    ceil_wrap_ge_q <= ge_w(ceil_nx_q, ceiling);
  end

  reg  at_ceil_q;  // count_q >= ceil_q
  wire at_ceil = at_ceil_q;


  reg               ovf, unf, took;

  always @(*) begin
    ovf     = 1'b0;
    unf     = 1'b0;
    took    = 1'b0;
    stopped_d = stopped_q;
    case (range)
      R_FREE: begin
        if (step_up) begin
          ovf     = at_max;
          took    = 1'b1;
        end else if (step_dn) begin
          unf     = at_zero;
          took    = 1'b1;
        end
      end
      R_MODULO: begin
        if (step_up) begin
          ovf     = at_ceil;
          took    = 1'b1;
        end else if (step_dn) begin
          unf     = at_zero;
          took    = 1'b1;
        end
      end
      R_LIMIT: begin
        if (step_up) begin
          ovf     = at_ceil;
          took    = ~at_ceil;
        end else if (step_dn) begin
          unf     = at_zero;
          took    = ~at_zero;
        end
      end
      R_NON_RECYCLE: begin
        if (!stopped_q) begin
          if (step_up) begin
            ovf       = at_ceil;
            took      = ~at_ceil;
            stopped_d = at_ceil;
          end else if (step_dn) begin
            unf       = at_zero;
            took      = ~at_zero;
            stopped_d = at_zero;
          end
        end
      end
    endcase
    if (wr_q) begin
      stopped_d = 1'b0;
    end
  end

  // ---- index ---------------------------------------------------------------------------------------
  // Qualified index: Z and, with the gate, (A, B) = (GATE_A, GATE_B); the chosen edge of it acts.
  wire idx_q      = z_eff & (~idx_gate_en | ((a_eff == idx_gate_a) & (b_eff == idx_gate_b)));
  wire armed      = idx_arm & (idx_action != 2'd0);
  reg  idx_prev_q, idx_ok_q, idx_hit1_q, idx_hit_q;

  always @(posedge clk) begin
    if (rst | ~valid) begin
      idx_prev_q <= 1'b0;
      idx_ok_q   <= 1'b0;
      idx_hit1_q <= 1'b0;
      idx_hit_q  <= 1'b0;
    end else begin
      idx_prev_q <= idx_q;
      idx_ok_q   <= 1'b1;
      idx_hit1_q <= idx_ok_q & (idx_edge ? (idx_prev_q & ~idx_q) : (~idx_prev_q & idx_q));
      idx_hit_q  <= idx_hit1_q;  // aligned with the step register above
    end
  end

  wire idx_act    = idx_hit_q & armed;
  wire idx_preset = idx_act & (idx_action == I_PRESET);
  wire idx_latch_en = idx_act & (idx_action == I_LATCH);

  // ---- count register ----------------------------------------------------------------------------
  // verilator lint_off UNUSEDSIGNAL
  wire [63:0] wr_value = {hi_stage_q, count_lo_wdata};  // (the bits above COUNT_W are dropped)
  // verilator lint_on UNUSEDSIGNAL

  // COUNT_LO writes and PRESET, registered (Fmax): a COUNT_LO write loads the count one clock
  // later, and an index preset loads PRESET as it was one clock earlier, so that their
  // comparisons with the ceiling and their zero tests are flag registers too.
  reg               wr_q;        // a COUNT_LO write to apply this clock
  reg [COUNT_W-1:0] wr_val_q;    // ... its value
  reg               wr_ge_q;     // ... >= ceil_nx_q
  reg               wr_zero_q;   // ... == 0
  reg [COUNT_W-1:0] preset_q;    // PRESET one clock ago
  reg               pre_ge_q;    // ... >= ceil_nx_q
  reg               pre_zero_q;  // ... == 0

  always @(posedge clk) begin
    if (rst) begin
      wr_q <= 1'b0;
    end else begin
      wr_q <= count_lo_wr;
    end
  end

  always @(posedge clk) begin
    wr_val_q   <= wr_value[COUNT_W-1:0];
    wr_ge_q    <= ge_w(wr_value[COUNT_W-1:0], ceiling);
    wr_zero_q  <= (wr_value[COUNT_W-1:0] == {COUNT_W{1'b0}});
    preset_q   <= preset;
    pre_ge_q   <= ge_w(preset, ceiling);
    pre_zero_q <= (preset == {COUNT_W{1'b0}});
  end

  wire        load     = wr_q | idx_preset;

  // ---- next count, zero_q and at_ceil_q ---------------------------------------------------------------
  // The cases of a clock without a load (an index latch stores the count of this case):
  wire bounded = (range != R_FREE) & ~((range == R_NON_RECYCLE) & stopped_q);
  wire modulo  = (range == R_MODULO);
  wire c_stop  = (range == R_NON_RECYCLE) & stopped_q;           // non_recycle stopped: held
  wire c_ceil  = step_up & bounded & at_ceil;                    // up at CEILING: wrap or hold
  wire c_up    = ~c_stop & step_up & ~c_ceil;
  wire c_dn    = ~c_stop & ~step_up & step_dn;
  wire c_dwrap = c_dn & at_zero & (range != R_FREE);             // down at 0: wrap or hold
  wire k_inc   = c_up;                                           // count_q + 1
  wire k_dec   = c_dn & ~c_dwrap;                                // count_q - 1
  wire k_zero  = c_ceil & modulo;                                // 0
  wire k_ceil  = c_dwrap & modulo;                               // the ceiling
  wire k_hold  = ~k_inc & ~k_dec & ~k_zero & ~k_ceil;            // count_q
  // ... and with the loads (COUNT write first, then an index preset): one-hot selects. (keep:
  // Yosys leaves them as nets, so that the late signals below are not folded into their logic.)
  wire s_wr    = wr_q;
  wire s_pre   = ~wr_q & idx_preset;
  (* keep *) wire s_inc;
  assign s_inc  = ~load & k_inc;
  (* keep *) wire s_dec;
  assign s_dec  = ~load & k_dec;
  (* keep *) wire s_zero;
  assign s_zero = ~load & k_zero;
  (* keep *) wire s_ceil;
  assign s_ceil = ~load & k_ceil;
  (* keep *) wire s_hold;
  assign s_hold = ~load & k_hold;

  // Every value is an AND-OR of (select & candidate): the selects are early signals, the adders,
  // comparators and zero tests of count_q the late ones, which enter the last logic levels only
  // (Fmax). The next count:
  wire [COUNT_W-1:0] count_inc = count_q + {{(COUNT_W-1){1'b0}}, 1'b1};
  wire [COUNT_W-1:0] count_dec = count_q - {{(COUNT_W-1){1'b0}}, 1'b1};
  wire [COUNT_W-1:0] stepped   =  // the count after this clock's step, before the loads
      ({COUNT_W{k_inc}} & count_inc) | ({COUNT_W{k_dec}} & count_dec) |
      ({COUNT_W{k_hold}} & count_q) | ({COUNT_W{k_ceil}} & ceil_q);

  (* keep *) wire [COUNT_W-1:0] count_other;  // every case but the adders' (early signals)
  assign count_other =
      ({COUNT_W{s_hold}} & count_q) | ({COUNT_W{s_ceil}} & ceil_q) |
      ({COUNT_W{s_wr}} & wr_val_q) | ({COUNT_W{s_pre}} & preset_q);

  always @(*) begin
    count_d = ({COUNT_W{s_inc}} & count_inc) | ({COUNT_W{s_dec}} & count_dec) | count_other;
  end

  // zero_d = (count_d == 0)
  wire is_one  = (count_q == {{(COUNT_W-1){1'b0}}, 1'b1});
  wire zero_d  = (s_wr & wr_zero_q) | (s_pre & pre_zero_q) |
                 (s_hold & zero_q) | (s_inc & at_max) | (s_dec & is_one) | s_zero |
                 (s_ceil & ceil_zero_q);

  // at_ceil_d = (count_d >= ceil_nx_q): each candidate compared with the next clock's ceiling N
  wire ge_hold = ge_w(count_q, ceil_nx_q);                // count_q     >= N
  wire ge_m1   = ge_w(count_q, ceil_nx_m1_q);             // count_q + 1 >= N (N > 0, no wrap)
  wire gt_hold = ~ge_w(ceil_nx_q, count_q);               // count_q - 1 >= N (count_q > 0)
  // count_q + 1 wraps to 0 only from the maximum (then in the free range: a bounded range stops
  // or wraps there first, the maximum being >= every ceiling); N = 0: every count is >= N.
  // count_q - 1 from 0 is the maximum, >= every N.
  wire at_ceil_d = (s_wr & wr_ge_q) | (s_pre & pre_ge_q) | (s_hold & ge_hold) |
                   (s_inc & (ceil_nx_zero_q | (ge_m1 & ~at_max))) |
                   (s_dec & (at_zero | gt_hold)) | (s_zero & ceil_nx_zero_q) |
                   (s_ceil & ceil_wrap_ge_q);

  reg upd_q;  // the count changed (step or load) at the last clock edge

  always @(posedge clk) begin
    if (rst) begin
      count_q   <= {COUNT_W{1'b0}};
      zero_q    <= 1'b1;
      at_ceil_q <= ceil_nx_zero_q;
      stopped_q <= 1'b0;
      upd_q     <= 1'b0;
    end else begin
      count_q   <= count_d;
      zero_q    <= zero_d;
      at_ceil_q <= at_ceil_d;
      stopped_q <= stopped_d;
      upd_q     <= load | took;
    end
  end

  // COUNT_HI: the high word latched by a COUNT_LO read; the staged word for a COUNT_LO write.
  wire [63:0] count64 = zext64(count_q);

  always @(posedge clk) begin
    if (rst) begin
      hi_latch_q <= 32'd0;
      hi_stage_q <= 32'd0;
    end else begin
      if (count_lo_rd) begin
        hi_latch_q <= count64[63:32];
      end
      if (count_hi_wr) begin
        hi_stage_q <= count_hi_wdata;
      end
    end
  end

  assign count_lo_rdata = count64[31:0];
  assign count_hi_rdata = hi_latch_q;

  // ---- direction -----------------------------------------------------------------------------------
  reg dir_q;

  always @(posedge clk) begin
    if (rst) begin
      dir_q <= 1'b1;
    end else if (step_up | step_dn) begin
      dir_q <= step_up;
    end
  end

  assign ev_dir_change = (step_up & ~dir_q) | (step_dn & dir_q);

  // ---- latches ---------------------------------------------------------------------------------------
  reg [COUNT_W-1:0] idx_latch_q;
  reg [COUNT_W-1:0] probe_latch_q;
  reg [TS_W-1:0]    probe_time_q;
  reg               probe_prev_q, probe_ok_q, probe_hit_q;

  always @(posedge clk) begin
    if (rst | ~valid) begin
      probe_prev_q <= 1'b0;
      probe_ok_q   <= 1'b0;
      probe_hit_q  <= 1'b0;
    end else begin
      probe_prev_q <= probe_c;
      probe_ok_q   <= 1'b1;
      probe_hit_q  <= probe_ok_q & probe_en &
                      (probe_edge ? (probe_prev_q & ~probe_c) : (~probe_prev_q & probe_c));
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      idx_latch_q   <= {COUNT_W{1'b0}};
      probe_latch_q <= {COUNT_W{1'b0}};
      probe_time_q  <= {TS_W{1'b0}};
    end else begin
      if (idx_latch_en) begin
        idx_latch_q <= stepped;
      end
      if (probe_hit_q) begin
        probe_latch_q <= count_q;
        probe_time_q  <= timebase;
      end
    end
  end

  // ---- compare ---------------------------------------------------------------------------------------
  reg cmp_q;

  always @(posedge clk) begin
    if (rst) begin
      cmp_q <= 1'b0;
    end else begin
      cmp_q <= upd_q & (count_q == compare);
    end
  end

  // ---- outputs ---------------------------------------------------------------------------------------
  assign count        = count_q;
  assign idx_latch    = idx_latch_q;
  assign probe_latch  = probe_latch_q;
  assign probe_time   = probe_time_q;
  assign dir          = dir_q;
  assign idx_armed    = armed;
  assign stopped      = stopped_q;
  assign idx_disarm   = idx_act & idx_oneshot;
  assign probe_disarm = probe_hit_q & probe_once;
  assign applied_up   = took & step_up & ~load;
  assign applied_dn   = took & step_dn & ~load;
  assign ev_overflow  = ovf;
  assign ev_underflow = unf;
  assign ev_index     = idx_hit_q;
  assign ev_probe     = probe_hit_q;
  assign ev_cmp       = cmp_q;
  assign cmp_out      = cmp_q;

`ifdef FORMAL
  // zero_q is a registered copy of (count_q == 0) (Fmax): the invariant k-induction needs to
  // prove the count properties of formal/enc_qei_core.sby. Formal-only initial values make the
  // state before the first clock agree with it too. Assert only: a parent proof re-checks it.
  initial count_q = {COUNT_W{1'b0}};
  initial zero_q = 1'b1;
  always @(*) assert (zero_q == (count_q == {COUNT_W{1'b0}}));
  // ... and the CEILING pipeline's flags agree with its values (initial values: CEILING 0)
  initial ceil_nx_q = {COUNT_W{1'b0}};
  initial ceil_nx_m1_q = {COUNT_W{1'b1}};
  initial ceil_nx_zero_q = 1'b1;
  initial ceil_q = {COUNT_W{1'b0}};
  initial ceil_zero_q = 1'b1;
  initial ceil_wrap_ge_q = 1'b1;
  initial at_ceil_q = 1'b1;
  initial wr_q = 1'b0;
  initial wr_val_q = {COUNT_W{1'b0}};
  initial wr_ge_q = 1'b1;
  initial wr_zero_q = 1'b1;
  initial preset_q = {COUNT_W{1'b0}};
  initial pre_ge_q = 1'b1;
  initial pre_zero_q = 1'b1;
  always @(*) begin
    assert (ceil_nx_m1_q == ceil_nx_q - {{(COUNT_W-1){1'b0}}, 1'b1});
    assert (ceil_nx_zero_q == (ceil_nx_q == {COUNT_W{1'b0}}));
    assert (ceil_zero_q == (ceil_q == {COUNT_W{1'b0}}));
    assert (ceil_wrap_ge_q == (ceil_q >= ceil_nx_q));
    assert (at_ceil_q == (count_q >= ceil_q));
    assert (wr_ge_q == (wr_val_q >= ceil_nx_q));
    assert (wr_zero_q == (wr_val_q == {COUNT_W{1'b0}}));
    assert (pre_ge_q == (preset_q >= ceil_nx_q));
    assert (pre_zero_q == (preset_q == {COUNT_W{1'b0}}));
  end
`endif

endmodule

`default_nettype wire
