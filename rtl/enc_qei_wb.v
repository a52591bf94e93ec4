// SPDX-License-Identifier: Apache-2.0
// enc_qei_wb -- enc_qei with a Wishbone B4 classic slave port (32-bit data, byte address).
//
// A thin adapter: a strobe of the bus (wb_cyc_i & wb_stb_i) is one request to enc_qei, whose
// response two clocks later is the acknowledge -- wb_ack_o, or wb_err_o for an unmapped offset
// (which reads 0 and writes nothing). So every access takes three clocks and always completes.
// No new request starts until that response (the master still holds its strobe in its clock).
// A master that abandons a request (drops cyc before the answer) gets no answer for it; its
// next request is answered after the abandoned one has completed (at most four clocks).
// wb_sel_i are the byte enables of a write. All the peripheral's behaviour is in enc_qei.
`default_nettype none
`include "enc_params.vh"

module enc_qei_wb #(
    parameter integer CHANNELS   = 1,   // encoder channels (see enc_qei)
    parameter integer ADDR_W     = `ENC_QEI_ADDR_W(CHANNELS),  // byte address bits (see enc_qei)
    parameter integer COUNT_W    = 32,  // counter width in bits
    parameter integer TS_W       = 32,  // timebase / timestamp width in bits
    parameter integer PROFILE    = 2,   // 2 full, 1 counting, 3 lean (see enc_qei)
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL, // count functions built: bit F = CTRL.FUNC value F (see enc_qei)
    parameter integer EFIFO_LOG2 = 0,    // edge-capture FIFO of 2^EFIFO_LOG2 entries per channel, 0: none (see enc_qei)
    parameter integer ENGINE     = 0     // 0: a datapath per channel, 1: one shared engine (see enc_qei)
) (
    input  wire        clk,
    input  wire        rst,       // synchronous, active high
    // Wishbone B4 classic slave
    input  wire [ADDR_W-1:0] wb_adr_i,  // byte address (bits 1:0 ignored)
    input  wire [31:0] wb_dat_i,
    output wire [31:0] wb_dat_o,
    input  wire [3:0]  wb_sel_i,
    input  wire        wb_we_i,
    input  wire        wb_stb_i,
    input  wire        wb_cyc_i,
    output wire        wb_ack_o,
    output wire        wb_err_o,
    // encoder and system
    input  wire [CHANNELS-1:0] a_in,     // encoder channel A, asynchronous
    input  wire [CHANNELS-1:0] b_in,     // encoder channel B, asynchronous
    input  wire [CHANNELS-1:0] z_in,     // index channel, asynchronous
    input  wire [CHANNELS-1:0] probe_in, // external latch input, asynchronous
    input  wire        snap_in,   // synchronous snapshot strobe
    output wire        irq,       // level: any enabled pending event
    output wire [CHANNELS-1:0] cmp_out   // one-clock pulse on a compare match
);

  generate
    `ENC_CHECK_CHANNELS
    `ENC_CHECK_ADDR_W
    `ENC_CHECK_COUNT_W
    `ENC_CHECK_TS_W
    `ENC_CHECK_PROFILE
    `ENC_CHECK_FUNC_MASK
    `ENC_CHECK_EFIFO_LOG2
    `ENC_CHECK_ENGINE
  endgenerate

  wire resp_valid, resp_err;
  reg  busy_q;  // a request is in enc_qei: from the clock after it until its response
  reg  held_q;  // ... and cyc has stayed high since: the master still waits for its answer
  wire req_valid = wb_cyc_i & wb_stb_i & ~busy_q;

  always @(posedge clk) begin
    if (rst) begin
      busy_q <= 1'b0;
      held_q <= 1'b0;
    end else if (req_valid) begin
      busy_q <= 1'b1;
      held_q <= 1'b1;
    end else begin
      if (resp_valid) begin
        busy_q <= 1'b0;
      end
      if (resp_valid | ~wb_cyc_i) begin
        held_q <= 1'b0;
      end
    end
  end

  enc_qei #(
      .CHANNELS  (CHANNELS),
      .ADDR_W    (ADDR_W),
      .COUNT_W   (COUNT_W),
      .TS_W      (TS_W),
      .PROFILE   (PROFILE),
      .FUNC_MASK (FUNC_MASK),
      .EFIFO_LOG2(EFIFO_LOG2),
      .ENGINE    (ENGINE)
  ) u_qei (
      .clk       (clk),
      .rst       (rst),
      .req_valid (req_valid),
      .req_write (wb_we_i),
      .req_addr  (wb_adr_i),
      .req_wdata (wb_dat_i),
      .req_wstrb (wb_sel_i),
      .resp_valid(resp_valid),
      .resp_rdata(wb_dat_o),
      .resp_err  (resp_err),
      .a_in      (a_in),
      .b_in      (b_in),
      .z_in      (z_in),
      .probe_in  (probe_in),
      .snap_in   (snap_in),
      .irq       (irq),
      .cmp_out   (cmp_out)
  );

  // A request the master abandoned (cyc dropped before its answer) is still carried out, but its
  // answer is not given: the next request waits for it and is answered itself.
  assign wb_ack_o = wb_cyc_i & held_q & resp_valid & ~resp_err;
  assign wb_err_o = wb_cyc_i & held_q & resp_valid & resp_err;

endmodule

`default_nettype wire
