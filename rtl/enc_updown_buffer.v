// SPDX-License-Identifier: Apache-2.0
// enc_updown_buffer -- Figure 17, the 2X up/down buffer a microprocessor reads.
//
// Built as the figure builds it: the encoder channels go through the input conditioner (the
// 74LS14's job), the Figure 15 XOR edge detector turns every transition of A into a count pulse
// with its direction, and DIGITS ls168 stages cascaded ripple-carry-out to ENT count it:
//   a_in, b_in -> enc_conditioner -> enc_x2_xor -> ls168[0] -RCO_n-> ENT_n ls168[1] -> ...
// The count moves +-1 per transition of A (2 x code wheel count per revolution) and wraps modulo
// MODULUS**DIGITS both ways (BCD with MODULUS = 10, binary with 16). rst loads zeros (the part
// has no reset pin). Digit 0 is count[3:0]. The decoder is held in reset until the conditioner
// shows the real input levels (FILTER_LEN + 2 clocks after rst falls): the state then is the
// reference, and motion before it is not counted.
//
// Coherent read, as the HCTL-2016's inhibit latch: rd_data follows count (one clock behind) while
// hold = 0; while hold = 1 it is frozen and counting goes on underneath. It catches up on the
// first clock after hold falls.
// Extra outputs: `glitch` (a level rejected by the conditioner) and `error` (A and B changed
// together, direction unknown): whenever the count may be wrong, one of them has pulsed.
// `rco_n`, the last stage's ripple carry, is low during the clock in which a count wraps the
// whole counter (overflow counting up, borrow counting down): the note's overflow flag, and the
// cascade input for more stages.
`default_nettype none
`include "enc_params.vh"

module enc_updown_buffer #(
    parameter integer DIGITS     = 4,   // cascaded ls168 stages: 1 .. 8
    parameter integer MODULUS    = 10,  // 10: BCD ('LS168), 16: binary ('LS169)
    parameter integer FILTER_LEN = 3    // conditioner filter length: 1 .. 16
) (
    input  wire                clk,
    input  wire                rst,      // synchronous, active high: clears the count
    input  wire                a_in,     // channel A, asynchronous
    input  wire                b_in,     // channel B, asynchronous
    input  wire                hold,     // 1: freeze rd_data for a multi-byte read
    output wire [4*DIGITS-1:0] count,    // live count, DIGITS digits of 4 bits
    output wire [4*DIGITS-1:0] rd_data,  // count as the microprocessor reads it
    output wire                glitch,   // conditioner rejected a short level (one clock)
    output wire                error,    // A and B changed in one sample (one clock)
    output wire                rco_n     // top stage RCO_n: low while a count wraps the counter
);

  generate
    `ENC_CHECK_DIGITS
    `ENC_CHECK_MODULUS
    `ENC_CHECK_FILTER_LEN
  endgenerate

  wire a;
  wire b;
  wire cond_valid;
  wire cnt_pulse;
  wire up;

  enc_conditioner #(
      .FILTER_LEN(FILTER_LEN)
  ) u_conditioner (
      .clk   (clk),
      .rst   (rst),
      .a_in  (a_in),
      .b_in  (b_in),
      .a     (a),
      .b     (b),
      .glitch(glitch),
      .valid (cond_valid)
  );

  enc_x2_xor u_x2 (
      .clk      (clk),
      .rst      (rst | ~cond_valid),
      .a        (a),
      .b        (b),
      .cnt_pulse(cnt_pulse),
      .up       (up),
      .error    (error)
  );

  // Cascade: ENP_n common, ENT_n of stage 0 from the count pulse, RCO_n -> ENT_n of the next.
  wire [DIGITS:0] carry_n  /* verilator split_var */;
  assign carry_n[0] = ~cnt_pulse;

  genvar k;
  generate
    for (k = 0; k < DIGITS; k = k + 1) begin : g_digit
      ls168 #(
          .MODULUS(MODULUS)
      ) u_ls168 (
          .clk   (clk),
          .load_n(~rst),
          .enp_n (~cnt_pulse),
          .ent_n (carry_n[k]),
          .up    (up),
          .d     (4'd0),
          .q     (count[4*k+:4]),
          .rco_n (carry_n[k+1])
      );
    end
  endgenerate

  assign rco_n = carry_n[DIGITS];

  // Read latch (HCTL-2016 style inhibit).
  reg [4*DIGITS-1:0] rd_q;

  always @(posedge clk) begin
    if (rst) begin
      rd_q <= {4 * DIGITS{1'b0}};
    end else if (!hold) begin
      rd_q <= count;
    end
  end

  assign rd_data = rd_q;

`ifdef FORMAL
  // ---- formal only (formal/enc_updown_buffer.sby): invariants, asserts only --------------------
  // The count against a shadow position of the conditioned channels a, b (which the ports do not
  // show, so this lives here), kept digit by digit modulo MODULUS**DIGITS: from the first sample
  // the decoder takes as reference (after rst and the conditioner's settling) it moves +1 / -1
  // per valid transition of A (B unchanged) in its 4X direction, and per A transition with B
  // changed too (direction unknown) as Figure 15's XOR says, up = A ^ B. Asserted: count equals
  // it at every clock, error pulses exactly for those illegal A transitions (so the count is the
  // 2X position exactly unless error pulsed), every digit stays in 0 .. MODULUS-1, and rco_n is
  // low exactly while a count wraps the whole counter.
  localparam integer F_W = 4 * DIGITS;
  localparam [3:0] F_MAX = MODULUS - 1;

  // digits +1 (up) or -1 (down) modulo MODULUS**DIGITS, digit 0 least significant
  function [F_W-1:0] f_step;
    input [F_W-1:0] digits;
    input up_dir;
    integer k;
    reg carry;
    begin
      f_step = digits;
      carry  = 1'b1;
      for (k = 0; k < DIGITS; k = k + 1) begin
        if (carry) begin
          if (up_dir) begin
            if (digits[4*k+:4] == F_MAX) f_step[4*k+:4] = 4'd0;
            else begin
              f_step[4*k+:4] = digits[4*k+:4] + 4'd1;
              carry = 1'b0;
            end
          end else begin
            if (digits[4*k+:4] == 4'd0) f_step[4*k+:4] = F_MAX;
            else begin
              f_step[4*k+:4] = digits[4*k+:4] - 4'd1;
              carry = 1'b0;
            end
          end
        end
      end
    end
  endfunction

  wire [F_W-1:0] f_all_max = {DIGITS{F_MAX}};
  wire           f_x2_rst = rst | ~cond_valid;

  reg            f_rst_seen = 1'b0;
  reg            f_pa;  // the conditioned A, B at the last clock
  reg            f_pb;
  reg            f_ref;  // the decoder took that sample (as its reference or counted it)
  reg            f_illegal;  // the sample taken at the last clock was an A edge with B changed
  reg  [F_W-1:0] f_pos;  // the shadow position, including the sample taken at the last clock
  reg  [F_W-1:0] f_pos_q;  // ... one clock later (the count's latency)

  wire           f_a_edge = ~f_x2_rst & f_ref & (a ^ f_pa);
  wire           f_b_changed = (b != f_pb);
  // forward valid A transition: {a, b} == {~prev b, prev a}; with B changed too: A ^ B
  wire           f_dir = f_b_changed ? (a ^ b) : (a == ~f_pb);

  always @(posedge clk) begin
    f_pa <= a;
    f_pb <= b;
    f_ref <= ~f_x2_rst;
    f_illegal <= f_a_edge & f_b_changed;
    f_pos_q <= rst ? {F_W{1'b0}} : f_pos;
    if (rst) begin
      f_rst_seen <= 1'b1;
      f_pos <= {F_W{1'b0}};
    end else if (f_a_edge) begin
      f_pos <= f_step(f_pos, f_dir);
    end
  end

  integer f_k;
  always @(*) begin
    if (f_rst_seen) begin
      for (f_k = 0; f_k < DIGITS; f_k = f_k + 1) begin
        assert (count[4*f_k+:4] <= F_MAX && f_pos[4*f_k+:4] <= F_MAX);
      end
      assert (count == f_pos_q);
      assert (error == f_illegal);
      assert (rco_n == ~(cnt_pulse & (up ? (count == f_all_max) : (count == {F_W{1'b0}}))));
    end
  end
`endif

endmodule

`default_nettype wire
