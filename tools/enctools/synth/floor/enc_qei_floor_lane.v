// SPDX-License-Identifier: Apache-2.0
// enc_qei_floor_lane -- a measurement model, not part of the IP: the smallest lane a shared
// engine can read its channel through, for `make synth` to count (enctools.synth.channels). It
// keeps only what must see every clock, and nothing the engine could rebuild:
//   A, B, Z -> enc_filter_rt (FILTER_LEN 1 .. 16 at run time, as the register map has it) ->
//   an x4 decode only (the lean profile's other count functions left out) -> here:
//     acc     the steps, free-running modulo 2^ACC_W (the engine differences two reads)
//     since   timebase ticks since the last step, saturating (the last edge's time = now - since)
//     an index edge (EDGE, the (A, B) gate, ARM, ONESHOT) latches acc; a snapshot request latches
//     acc and since; each waits, pending, until the next read
//     free-running counts of quadrature errors and rejected A / B levels; STATUS A, B, Z, DIR; the
//     window's index and direction-change events
// What it leaves out, and a lean lane of the IP (enc_qei_lane) has: the other count functions,
// SWAP_AB and INV_*, the count's own low bits with their loads (an index preset, a COUNT write)
// and the exact OVERFLOW / UNDERFLOW of the full count (here the engine could only tell them from
// two reads), the snapshot's own timebase bits (here the engine would time every request), the
// last edge's motion, and the glitch count of Z. So it is a floor: a lane that does what the
// register map asks costs more.
// The record is 0 except in a clock with rd (the engine ORs every lane's record); a read starts
// the next window: the pending captures and the events clear.
`default_nettype none

module enc_qei_floor_lane #(
    // the widths for P clocks between two reads (enc_qei_floor_bank sets them): the steps, errors
    // and rejected levels of one window (at most P: one a clock) told apart modulo 2^W, since
    // from 0 to P ticks and "more"
    parameter integer ACC_W  = 6,  // $clog2(2 P + 1)
    parameter integer ERR_W  = 5,  // $clog2(P + 1)
    parameter integer TIME_W = 5   // $clog2(P + 2)
) (
    input  wire            clk,
    input  wire            rst,       // synchronous, active high
    input  wire            a_in,      // encoder channel A, asynchronous
    input  wire            b_in,      // encoder channel B, asynchronous
    input  wire            z_in,      // index channel, asynchronous
    input  wire            tick,      // the timebase advances at the end of this clock
    input  wire            snap,      // a snapshot request in this clock
    input  wire            rd,        // read: the record shows the lane in this clock
    input  wire            cfg_we,    // load the configuration (cfg) at the end of this clock
    input  wire [9:0]      cfg,       // {ONESHOT, ARM, EDGE, GATE_EN, GATE_A, GATE_B, FILTER_LEN-1}
    output wire [3*ACC_W+2*TIME_W+2*ERR_W+7:0] rec  // 0 but with rd
);

  localparam integer REC_W = 3 * ACC_W + 2 * TIME_W + 2 * ERR_W + 8;

  reg  [8:0] cfg_q;  // cfg but ARM (arm_q below)
  wire [3:0] last    = cfg_q[3:0];
  wire       gate_b  = cfg_q[4];
  wire       gate_a  = cfg_q[5];
  wire       gate_en = cfg_q[6];
  wire       iedge   = cfg_q[7];  // 1: rising Z
  wire       oneshot = cfg_q[8];

  always @(posedge clk) begin
    if (rst) begin
      cfg_q <= 9'd0;
    end else if (cfg_we) begin
      cfg_q <= {cfg[9], cfg[7:0]};
    end
  end

  // ---- filters and the x4 decode ------------------------------------------------------------------
  wire a_c, b_c, z_c, rej_a, rej_b, unused_rej_z;

  enc_filter_rt u_filt_a (.clk(clk), .rst(rst), .last(last), .in(a_in), .level(a_c), .reject(rej_a));
  enc_filter_rt u_filt_b (.clk(clk), .rst(rst), .last(last), .in(b_in), .level(b_c), .reject(rej_b));
  enc_filter_rt u_filt_z (.clk(clk), .rst(rst), .last(last), .in(z_in), .level(z_c),
                          .reject(unused_rej_z));

  reg  [1:0] s_q;  // the quadrature state before: 0, 1, 2, 3 along the forward direction
  reg        z_q;
  wire [1:0] s_d  = {a_c, a_c ^ b_c};
  wire [1:0] ds   = s_d - s_q;
  wire       up   = ds == 2'd1;
  wire       dn   = ds == 2'd3;
  wire       qerr = ds == 2'd2;

  always @(posedge clk) begin
    if (rst) begin
      s_q <= 2'd0;
      z_q <= 1'b0;
    end else begin
      s_q <= s_d;
      z_q <= z_c;
    end
  end

  // ---- the motion, the time since the last step, the error counts --------------------------------
  reg  [ACC_W-1:0]  acc_q;
  reg  [TIME_W-1:0] since_q;
  reg  [ERR_W-1:0]  qcnt_q, gcnt_q;
  reg               dir_q;
  wire [ACC_W-1:0]  acc_d   = acc_q + {{(ACC_W - 1){dn}}, up | dn};
  wire [TIME_W-1:0] since_d = (up | dn) ? {TIME_W{1'b0}} :
                              (tick & ~&since_q) ? since_q + 1'b1 : since_q;

  always @(posedge clk) begin
    if (rst) begin
      acc_q   <= {ACC_W{1'b0}};
      since_q <= {TIME_W{1'b1}};
      qcnt_q  <= {ERR_W{1'b0}};
      gcnt_q  <= {ERR_W{1'b0}};
      dir_q   <= 1'b1;
    end else begin
      acc_q   <= acc_d;
      since_q <= since_d;
      qcnt_q  <= qcnt_q + {{(ERR_W - 1){1'b0}}, qerr};
      gcnt_q  <= gcnt_q + {{(ERR_W - 1){1'b0}}, rej_a | rej_b};
      if (up | dn) dir_q <= up;
    end
  end

  // ---- the index (EDGE, gate, ARM, ONESHOT) and its latch; the snapshot ---------------------------
  wire zedge = iedge ? (z_c & ~z_q) : (~z_c & z_q);
  wire gated = ~gate_en | ({a_c, b_c} == {gate_a, gate_b});
  wire hit   = zedge & gated;
  reg  arm_q, lpend_q, spend_q, eidx_q, edch_q;
  reg  [ACC_W-1:0]  lcap_q, scap_q;
  reg  [TIME_W-1:0] ssince_q;

  always @(posedge clk) begin
    if (rst) begin
      arm_q <= 1'b0;
    end else if (cfg_we) begin
      arm_q <= cfg[8];
    end else if (hit & oneshot) begin
      arm_q <= 1'b0;
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      lpend_q <= 1'b0;
      spend_q <= 1'b0;
      eidx_q  <= 1'b0;
      edch_q  <= 1'b0;
    end else begin
      lpend_q <= (lpend_q & ~rd) | (hit & arm_q);
      spend_q <= (spend_q & ~rd) | snap;
      eidx_q  <= (eidx_q & ~rd) | hit;
      edch_q  <= (edch_q & ~rd) | (((up & ~dir_q) | (dn & dir_q)));
    end
  end

  always @(posedge clk) begin
    if (hit & arm_q) lcap_q <= acc_d;
  end

  always @(posedge clk) begin
    if (snap) begin
      scap_q   <= acc_d;
      ssince_q <= since_d;
    end
  end

  // ---- the record ---------------------------------------------------------------------------------
  assign rec = {REC_W{rd}} & {acc_q, since_q, qcnt_q, gcnt_q, lcap_q, lpend_q, scap_q, ssince_q,
                              spend_q, a_c, b_c, z_c, dir_q, eidx_q, edch_q};

endmodule

`default_nettype wire
