// SPDX-License-Identifier: Apache-2.0
// enc_qei (formal stand-in) -- an abstract enc_qei for the bus-adapter proofs
// (formal/enc_qei_wb.sby, formal/enc_qei_axil.sby read it instead of rtl/enc_qei.v).
//
// Same module name, parameters and ports as rtl/enc_qei.v; it honours exactly the request /
// response contract of enc_qei's port and nothing else (formal/enc_qei_port.sby proves that
// contract on the real enc_qei):
//   - resp_valid exactly two clocks after req_valid (a request in a clock with rst high, or in
//     flight when rst rises, gets none);
//   - resp_err = the request's offset is unmapped (enc_qei_mapped(addr, CHANNELS) of
//     rtl/enc_qei_regs.vh);
//   - resp_rdata: a read of a mapped offset f_qei_rdata(addr) (formal/enc_qei_abstract.vh), an
//     unmapped read or a write 0;
//   - outside resp_valid, resp_err and resp_rdata take any value at every clock (the adapters
//     must not look at them then); irq and cmp_out are free as well.
// The adapters pass ENGINE on; this stand-in answers as the per_channel build (ENGINE 0) does,
// so the adapter proofs are of that build (a shared engine answers 4 or more clocks after a
// request).
// It asserts the one rule enc_qei sets its user (rtl/enc_qei_regs.v): one request at a time, a
// new one only from the clock after the previous one's resp_valid.
`default_nettype none
`include "enc_params.vh"

module enc_qei #(
    parameter integer CHANNELS   = 1,
    parameter integer ADDR_W     = 8,
    parameter integer COUNT_W    = 32,
    parameter integer TS_W       = 32,
    parameter integer PROFILE    = 2,
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL,
    parameter integer EFIFO_LOG2 = 0,
    parameter integer ENGINE     = 0   // taken, not modelled: the answers are per_channel's (ENGINE 0)
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        req_valid,
    input  wire        req_write,
    input  wire [ADDR_W-1:0] req_addr,
    input  wire [31:0] req_wdata,
    input  wire [3:0]  req_wstrb,
    output wire        resp_valid,
    output wire [31:0] resp_rdata,
    output wire        resp_err,
    input  wire [CHANNELS-1:0] a_in,
    input  wire [CHANNELS-1:0] b_in,
    input  wire [CHANNELS-1:0] z_in,
    input  wire [CHANNELS-1:0] probe_in,
    input  wire        snap_in,
    output wire        irq,
    output wire [CHANNELS-1:0] cmp_out
);

`include "enc_qei_regs.vh"
`include "enc_qei_abstract.vh"

  reg        v1_q = 1'b0, v2_q = 1'b0;  // a request one / two clocks ago
  reg        w1_q;
  reg [15:0] a1_q;  // the request's address, zero-extended
  reg        err2_q;
  reg [31:0] rdata2_q;

  always @(posedge clk) begin
    if (rst) begin
      v1_q <= 1'b0;
      v2_q <= 1'b0;
    end else begin
      v1_q <= req_valid;
      v2_q <= v1_q;
    end
    w1_q     <= req_write;
    a1_q     <= req_addr;  // zero-extended
    err2_q   <= ~enc_qei_mapped(a1_q, CHANNELS);
    rdata2_q <= (w1_q | ~enc_qei_mapped(a1_q, CHANNELS)) ? 32'd0 : f_qei_rdata(a1_q);
  end

  wire [31:0]         any_rdata = $anyseq;
  wire        any_err   = $anyseq;

  assign resp_valid = v2_q;
  assign resp_err   = v2_q ? err2_q : any_err;
  assign resp_rdata = v2_q ? rdata2_q : any_rdata;
  assign irq        = $anyseq;
  wire [CHANNELS-1:0] any_cmp   = $anyseq;
  assign cmp_out    = any_cmp;

  always @(*) begin
    if (!rst && req_valid) assert (!v1_q && !v2_q);
  end

endmodule

`default_nettype wire
