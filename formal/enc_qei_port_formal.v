// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei's request / response port (read by formal/enc_qei_port.sby;
// `make formal`): the contract the abstract enc_qei of formal/enc_qei_abstract.v stands in for
// in the bus-adapter proofs, proven on the real peripheral (rtl/enc_qei.v with its register
// block, core, timing unit and conditioners), port-level only.
//
// The only assumption: the first clock is a reset. Every input is free at every clock after
// it, rst and the request port included: requests may come in consecutive clocks (the adapters
// send one at a time; the port is pipelined and these properties hold either way).
// Proven (k-induction), with a shadow of the requests of the last two clocks:
//   - resp_valid exactly two clocks after req_valid, none for a request in a clock with rst
//     high or in flight when rst rises: one response per request, none without one;
//   - resp_err exactly when that request's offset is unmapped (!enc_qei_mapped(req_addr,
//     CHANNELS) of rtl/enc_qei_regs.vh);
//   - resp_rdata 0 for a read of an unmapped offset and for every write (the port's rule).
// Not here (the register block's own properties): what a mapped read returns, that an unmapped
// write changes nothing, byte enables.
`default_nettype none
`include "enc_params.vh"

module enc_qei_port_formal #(
    parameter integer COUNT_W   = 32,
    parameter integer TS_W      = 32,
    parameter integer PROFILE   = 2,
    parameter integer FUNC_MASK = `ENC_QEI_FUNC_ALL,
    parameter integer CHANNELS  = 1,
    parameter integer AW        = `ENC_QEI_ADDR_W(CHANNELS)  // byte address bits
) (
    input wire        clk,
    input wire        rst,
    input wire        req_valid,
    input wire        req_write,
    input wire [AW-1:0] req_addr,
    input wire [31:0] req_wdata,
    input wire [3:0]  req_wstrb,
    input wire [CHANNELS-1:0] a_in,
    input wire [CHANNELS-1:0] b_in,
    input wire [CHANNELS-1:0] z_in,
    input wire [CHANNELS-1:0] probe_in,
    input wire        snap_in
);

`include "enc_qei_regs.vh"

  wire        resp_valid, resp_err, irq;
  wire [CHANNELS-1:0] cmp_out;
  wire [31:0] resp_rdata;

  enc_qei #(
      .CHANNELS (CHANNELS),
      .ADDR_W   (AW),
      .COUNT_W  (COUNT_W),
      .TS_W     (TS_W),
      .PROFILE  (PROFILE),
      .FUNC_MASK(FUNC_MASK)
  ) dut (
      .clk       (clk),
      .rst       (rst),
      .req_valid (req_valid),
      .req_write (req_write),
      .req_addr  (req_addr),
      .req_wdata (req_wdata),
      .req_wstrb (req_wstrb),
      .resp_valid(resp_valid),
      .resp_rdata(resp_rdata),
      .resp_err  (resp_err),
      .a_in      (a_in),
      .b_in      (b_in),
      .z_in      (z_in),
      .probe_in  (probe_in),
      .snap_in   (snap_in),
      .irq       (irq),
      .cmp_out   (cmp_out)
  );

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume (rst);

  wire [15:0] f_addr16 = req_addr;  // zero-extended for the map's function

  // the requests of one and two clocks ago: valid, unmapped, write
  reg f_v1 = 1'b0, f_v2 = 1'b0;
  reg f_u1, f_u2, f_w1, f_w2;
  always @(posedge clk) begin
    f_v1 <= !rst && req_valid;
    f_v2 <= !rst && f_v1;
    f_u1 <= !enc_qei_mapped(f_addr16, CHANNELS);
    f_u2 <= f_u1;
    f_w1 <= req_write;
    f_w2 <= f_w1;
  end

  always @(*) begin
    if (f_past_valid) begin
      assert (resp_valid == f_v2);
      if (resp_valid) begin
        assert (resp_err == f_u2);
        if (f_u2 || f_w2) assert (resp_rdata == 32'd0);
      end
    end
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      cover (resp_valid && resp_err && !f_w2);                  // an unmapped read
      cover (resp_valid && resp_err && f_w2);                   // an unmapped write
      cover (resp_valid && !resp_err && !f_w2 && resp_rdata != 32'd0);  // a mapped read, data
      cover (resp_valid && f_v1 && req_valid);                  // three in consecutive clocks
    end
  end

endmodule

`default_nettype wire
