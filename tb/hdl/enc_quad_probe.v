// SPDX-License-Identifier: Apache-2.0
// Test-only wrapper: one enc_conditioner feeding all three decoders, with accumulators so a test
// can play a long waveform and read the results at the end instead of watching every clock.
//   pos4  signed net count of enc_x4_decoder (4X position)
//   pos2  signed net count of enc_x2_xor     (2X position)
//   pos1  signed net count of enc_x1_hysteresis (cycles)
//   n_err4, n_err2, n_err1, n_glitch: how many times each flag pulsed since reset
`default_nettype none

module enc_quad_probe #(
    parameter integer FILTER_LEN = 3  // passed to enc_conditioner
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        a_in,
    input  wire        b_in,
    output wire        a,
    output wire        b,
    output reg  [31:0] pos4,
    output reg  [31:0] pos2,
    output reg  [31:0] pos1,
    output reg  [31:0] n_err4,
    output reg  [31:0] n_err2,
    output reg  [31:0] n_err1,
    output reg  [31:0] n_glitch
);

  wire glitch;
  wire valid;
  wire dec_rst = rst | ~valid;  // decoders start from the real state, once the conditioner settled
  wire cnt4, up4, err4;
  wire cnt2, up2, err2;
  wire up1, dn1, err1;

  enc_conditioner #(
      .FILTER_LEN(FILTER_LEN)
  ) u_cond (
      .clk   (clk),
      .rst   (rst),
      .a_in  (a_in),
      .b_in  (b_in),
      .a     (a),
      .b     (b),
      .glitch(glitch),
      .valid (valid)
  );

  enc_x4_decoder u_x4 (
      .clk      (clk),
      .rst      (dec_rst),
      .a        (a),
      .b        (b),
      .cnt_pulse(cnt4),
      .up       (up4),
      .error    (err4)
  );

  enc_x2_xor u_x2 (
      .clk      (clk),
      .rst      (dec_rst),
      .a        (a),
      .b        (b),
      .cnt_pulse(cnt2),
      .up       (up2),
      .error    (err2)
  );

  enc_x1_hysteresis u_x1 (
      .clk     (clk),
      .rst     (dec_rst),
      .a       (a),
      .b       (b),
      .up_pulse(up1),
      .dn_pulse(dn1),
      .error   (err1)
  );

  always @(posedge clk) begin
    if (rst) begin
      pos4     <= 32'd0;
      pos2     <= 32'd0;
      pos1     <= 32'd0;
      n_err4   <= 32'd0;
      n_err2   <= 32'd0;
      n_err1   <= 32'd0;
      n_glitch <= 32'd0;
    end else begin
      if (cnt4) pos4 <= up4 ? pos4 + 32'd1 : pos4 - 32'd1;
      if (cnt2) pos2 <= up2 ? pos2 + 32'd1 : pos2 - 32'd1;
      if (up1) pos1 <= pos1 + 32'd1;
      if (dn1) pos1 <= pos1 - 32'd1;
      n_err4   <= n_err4 + {31'd0, err4};
      n_err2   <= n_err2 + {31'd0, err2};
      n_err1   <= n_err1 + {31'd0, err1};
      n_glitch <= n_glitch + {31'd0, glitch};
    end
  end

endmodule

`default_nettype wire
