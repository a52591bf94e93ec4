// SPDX-License-Identifier: Apache-2.0
// enc_qei_decode -- the decode front of one enc_qei channel: what happened at the pins, clock by
// clock, before anything is counted. Shared by the per-channel counting core (enc_qei_core) and
// the shared engine's lane (enc_qei_lane), so that both count with the same circuit.
//
// Inputs are the conditioned channels (enc_conditioner_rt outputs). A and B go through SWAP_AB
// then INV_A / INV_B, Z through INV_Z, then into the library's decoders, held in reset while the
// conditioner is not valid and for one clock after FUNC, SWAP_AB, INV_A or INV_B change:
//   enc_x4_decoder    -> every valid transition (cnt, up) and the quadrature error
//   enc_x1_hysteresis -> FUNC = x1_hyst (the note's Figure 14)
// The Linux count functions come from the x4 decoder's transitions and the levels of the
// transition's present and previous sample (a1/a2, b1/b2 below, aligned with its outputs):
//   x4 every transition; x2a/x2b transitions of A/B; x1a: A rising forward (+1), A falling
//   backward (-1); x1b the same on B; pulse_dir / increase / decrease: rising edges of A (B = up).
// One register stage follows the count function (step_up / step_dn, gated by EN; the edges; the
// A/B state after the step), and the qualified index edge (Z and, with the gate, (A, B) =
// (GATE_A, GATE_B); its chosen EDGE) is delayed the same (idx_hit), so that an index acts in the
// clock of the transition it sees; idx_hit1 is the same edge one clock earlier. A change of
// SWAP_AB, INV_A, INV_B or INV_Z re-references the index too: the level change it makes (of Z,
// or of the gate's A/B state) is not an index edge.
`default_nettype none

module enc_qei_decode (
    input  wire       clk,
    input  wire       rst,          // synchronous, active high
    input  wire       a_c,          // channel A from the conditioner
    input  wire       b_c,          // channel B
    input  wire       z_c,          // index channel Z
    input  wire       valid,        // conditioner outputs show the inputs
    input  wire       en,           // CTRL.EN: gates the steps
    input  wire       swap_ab,      // CTRL.SWAP_AB
    input  wire       inv_a,        // CTRL.INV_A
    input  wire       inv_b,        // CTRL.INV_B
    input  wire       inv_z,        // CTRL.INV_Z
    input  wire [3:0] func,         // CTRL.FUNC as counted (a code no function has: nothing)
    input  wire       idx_edge,     // INDEX_CTRL.EDGE: 0 rising, 1 falling
    input  wire       idx_gate_en,  // INDEX_CTRL.GATE_EN
    input  wire       idx_gate_a,   // INDEX_CTRL.GATE_A
    input  wire       idx_gate_b,   // INDEX_CTRL.GATE_B
    output wire       a_eff,        // A, B, Z as the decoders see them
    output wire       b_eff,
    output wire       z_eff,
    output wire       fdn,          // the function's down step now, before its register (and EN)
    output wire       step_up,      // a count function step up (EN = 1), registered
    output wire       step_dn,      // ... down (never with step_up)
    output wire       edge_any,     // a valid quadrature transition (same stage)
    output wire       edge_a_rise,  // a rising edge of A (same stage)
    output wire [1:0] step_ab,      // {A, B} after the transition of this clock's step
    output wire       qerr,         // quadrature error (quadrature functions only), one clock
    output wire       idx_hit1,     // a qualified index edge, one clock before idx_hit
    output wire       idx_hit       // a qualified index edge, aligned with step_up / step_dn
);

  `include "enc_qei_regs.vh"  // the codes of CTRL.FUNC

  // ---- channel selection and decoder reset ----------------------------------------------------
  wire a_sw = swap_ab ? b_c : a_c;
  wire b_sw = swap_ab ? a_c : b_c;
  assign a_eff = a_sw ^ inv_a;
  assign b_eff = b_sw ^ inv_b;
  assign z_eff = z_c ^ inv_z;

  reg  [7:0] cfg_q;  // {func, swap_ab, inv_a, inv_b, inv_z} last clock
  wire [7:0] cfg   = {func, swap_ab, inv_a, inv_b, inv_z};
  wire       dec_rst = rst | ~valid | (cfg[7:1] != cfg_q[7:1]);
  // a change of SWAP_AB, INV_A, INV_B or INV_Z re-references the index too: the level change it
  // makes (of Z, or of the gate's A/B state) is not an index edge
  wire       chan_cfg_change = (cfg[3:0] != cfg_q[3:0]);

  always @(posedge clk) begin
    if (rst) begin
      cfg_q <= 8'd0;
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
  reg  fn_up, fn_dn, quad;  // the count function's step now (before EN and its register)

  always @(*) begin
    fn_up = 1'b0;
    fn_dn = 1'b0;
    quad  = 1'b1;
    case (func)
      ENC_QEI_FUNC_X4: begin
        fn_up = x4_cnt & x4_up;
        fn_dn = x4_cnt & ~x4_up;
      end
      ENC_QEI_FUNC_X2A: begin
        fn_up = x4_cnt & a_moved & x4_up;
        fn_dn = x4_cnt & a_moved & ~x4_up;
      end
      ENC_QEI_FUNC_X2B: begin
        fn_up = x4_cnt & b_moved & x4_up;
        fn_dn = x4_cnt & b_moved & ~x4_up;
      end
      ENC_QEI_FUNC_X1A: begin
        fn_up = x4_cnt & a_moved & x4_up & a1_q;
        fn_dn = x4_cnt & a_moved & ~x4_up & ~a1_q;
      end
      ENC_QEI_FUNC_X1B: begin
        fn_up = x4_cnt & b_moved & x4_up & b1_q;
        fn_dn = x4_cnt & b_moved & ~x4_up & ~b1_q;
      end
      ENC_QEI_FUNC_PULSE_DIR: begin
        fn_up = arise_q & b1_q;
        fn_dn = arise_q & ~b1_q;
        quad  = 1'b0;
      end
      ENC_QEI_FUNC_INCREASE: begin
        fn_up = arise_q;
        quad  = 1'b0;
      end
      ENC_QEI_FUNC_DECREASE: begin
        fn_dn = arise_q;
        quad  = 1'b0;
      end
      ENC_QEI_FUNC_X1_HYST: begin
        fn_up = h_up;
        fn_dn = h_dn;
      end
      default: quad = 1'b0;
    endcase
  end

  // One register stage between the count function and the count (for Fmax): the steps, the
  // edges and the index hit below are all delayed alike.
  reg step_up_q, step_dn_q, edge_any_q, edge_a_rise_q;
  reg [1:0] step_ab_q;  // {A, B} after the transition of this clock's step (not reset: a delay)

  always @(posedge clk) begin
    if (rst) begin
      step_up_q     <= 1'b0;
      step_dn_q     <= 1'b0;
      edge_any_q    <= 1'b0;
      edge_a_rise_q <= 1'b0;
    end else begin
      step_up_q     <= en & fn_up;
      step_dn_q     <= en & fn_dn;
      edge_any_q    <= x4_cnt;
      edge_a_rise_q <= x4_cnt & a_moved & a1_q;
    end
  end

  always @(posedge clk) begin
    step_ab_q <= {a1_q, b1_q};
  end

  assign fdn         = fn_dn;
  assign step_up     = step_up_q;
  assign step_dn     = step_dn_q;
  assign edge_any    = edge_any_q;
  assign edge_a_rise = edge_a_rise_q;
  assign step_ab     = step_ab_q;
  assign qerr        = quad & x4_err;

  // ---- index ---------------------------------------------------------------------------------------
  wire idx_q = z_eff & (~idx_gate_en | ((a_eff == idx_gate_a) & (b_eff == idx_gate_b)));
  reg  idx_prev_q, idx_ok_q, idx_hit1_q, idx_hit_q;
  wire idx_hit1_d = idx_ok_q & ~chan_cfg_change &
                    (idx_edge ? (idx_prev_q & ~idx_q) : (~idx_prev_q & idx_q));

  always @(posedge clk) begin
    if (rst | ~valid) begin
      idx_prev_q <= 1'b0;
      idx_ok_q   <= 1'b0;
      idx_hit1_q <= 1'b0;
      idx_hit_q  <= 1'b0;
    end else begin
      idx_prev_q <= idx_q;
      idx_ok_q   <= 1'b1;
      idx_hit1_q <= idx_hit1_d;
      idx_hit_q  <= idx_hit1_q;  // aligned with the step register above
    end
  end

  assign idx_hit1 = idx_hit1_q;
  assign idx_hit  = idx_hit_q;

`ifdef FORMAL
  // Formal-only initial values (the proofs of the modules above this one): no step, no index hit
  // before the first clock. Assert nothing here: the parents' proofs re-check what they use.
  initial step_up_q = 1'b0;
  initial step_dn_q = 1'b0;
  initial idx_hit1_q = 1'b0;
  initial idx_hit_q = 1'b0;
`endif

endmodule

`default_nettype wire
