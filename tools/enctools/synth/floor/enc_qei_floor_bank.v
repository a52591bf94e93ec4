// SPDX-License-Identifier: Apache-2.0
// enc_qei_floor_bank -- a measurement model, not part of the IP: N floor lanes
// (enc_qei_floor_lane) read one after another, P clocks apart, through the one-hot AND-OR the
// shared engine uses, the record registered. `make synth` (enctools.synth.channels) counts its
// LUT4 for the floor of a lane; nothing here is an engine (no count, no bus).
`default_nettype none

module enc_qei_floor_bank #(
    parameter integer N = 16,  // lanes
    parameter integer P = 16   // clocks between two reads of a lane: a multiple of N
) (
    input  wire          clk,
    input  wire          rst,    // synchronous, active high
    input  wire [N-1:0]  a_in,   // the lanes' encoder inputs, asynchronous
    input  wire [N-1:0]  b_in,
    input  wire [N-1:0]  z_in,
    input  wire          tick,   // the timebase advances
    input  wire          snap,   // a snapshot request for every lane
    input  wire [9:0]    cfg,    // the configuration pushed to the lane read now
    output reg  [REC_W-1:0] rec_q  // the record read
);

  localparam integer ACC_W  = $clog2(2 * P + 1);
  localparam integer ERR_W  = $clog2(P + 1);
  localparam integer TIME_W = $clog2(P + 2);
  localparam integer REC_W  = 3 * ACC_W + 2 * TIME_W + 2 * ERR_W + 8;
  localparam integer V      = P / N;  // clocks a lane
  localparam integer VC_W   = (V > 1) ? $clog2(V) : 1;

  generate
    if (N < 2 || P < N || P % N != 0) begin : g_bad_params
`ifdef __ICARUS__
      enc_qei_floor_bank__P_must_be_a_multiple_of_N_and_N_at_least_2 u_stop ();
`else
      $error("enc_qei_floor_bank: P must be a multiple of N, and N at least 2");
`endif
    end
  endgenerate

  // the lane read now: a one-hot ring that moves every V clocks
  reg  [N-1:0]    rd_q;
  reg  [VC_W-1:0] vc_q;
  wire            adv = (V <= 1) || ({{(32 - VC_W){1'b0}}, vc_q} == V - 1);

  always @(posedge clk) begin
    if (rst) begin
      rd_q <= {{(N - 1){1'b0}}, 1'b1};
      vc_q <= {VC_W{1'b0}};
    end else begin
      vc_q <= adv ? {VC_W{1'b0}} : vc_q + 1'b1;
      if (adv) rd_q <= {rd_q[N-2:0], rd_q[N-1]};
    end
  end

  wire [N*REC_W-1:0] recs;
  genvar k;
  generate
    for (k = 0; k < N; k = k + 1) begin : g_lane
      enc_qei_floor_lane #(
          .ACC_W (ACC_W),
          .ERR_W (ERR_W),
          .TIME_W(TIME_W)
      ) u_lane (
          .clk   (clk),
          .rst   (rst),
          .a_in  (a_in[k]),
          .b_in  (b_in[k]),
          .z_in  (z_in[k]),
          .tick  (tick),
          .snap  (snap),
          .rd    (rd_q[k] & adv),
          .cfg_we(rd_q[k] & adv),
          .cfg   (cfg),
          .rec   (recs[k*REC_W +: REC_W])
      );
    end
  endgenerate

  reg [REC_W-1:0] rec_or;
  integer i;
  always @(*) begin
    rec_or = {REC_W{1'b0}};
    for (i = 0; i < N; i = i + 1) rec_or = rec_or | recs[i*REC_W +: REC_W];
  end

  always @(posedge clk) begin
    rec_q <= rec_or;
  end

endmodule

`default_nettype wire
