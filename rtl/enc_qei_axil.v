// SPDX-License-Identifier: Apache-2.0
// enc_qei_axil -- enc_qei with an AXI4-Lite slave port (32-bit data, 8-bit byte address).
//
// A thin adapter: one skid register per address/data channel (AW, W, AR), one request to
// enc_qei at a time, issued from a register (the clock after the adapter picks it: Fmax), and
// the response held on B or R until the master takes it. A write is
// issued once both its address and data have arrived; reads and writes alternate when both
// wait. An unmapped offset answers SLVERR (reads 0, writes nothing); every access completes
// whatever the master's ready/valid timing. awprot/arprot are ignored. All the peripheral's
// behaviour is in enc_qei.
`default_nettype none
`include "enc_params.vh"

module enc_qei_axil #(
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
    input  wire        rst,            // synchronous, active high
    // AXI4-Lite slave
    input  wire [ADDR_W-1:0] s_axil_awaddr,  // byte address (bits 1:0 ignored)
    // verilator lint_off UNUSEDSIGNAL
    input  wire [2:0]  s_axil_awprot,  // ignored
    // verilator lint_on UNUSEDSIGNAL
    input  wire        s_axil_awvalid,
    output wire        s_axil_awready,
    input  wire [31:0] s_axil_wdata,
    input  wire [3:0]  s_axil_wstrb,
    input  wire        s_axil_wvalid,
    output wire        s_axil_wready,
    output wire [1:0]  s_axil_bresp,
    output wire        s_axil_bvalid,
    input  wire        s_axil_bready,
    input  wire [ADDR_W-1:0] s_axil_araddr,  // byte address (bits 1:0 ignored)
    // verilator lint_off UNUSEDSIGNAL
    input  wire [2:0]  s_axil_arprot,  // ignored
    // verilator lint_on UNUSEDSIGNAL
    input  wire        s_axil_arvalid,
    output wire        s_axil_arready,
    output wire [31:0] s_axil_rdata,
    output wire [1:0]  s_axil_rresp,
    output wire        s_axil_rvalid,
    input  wire        s_axil_rready,
    // encoder and system
    input  wire [CHANNELS-1:0] a_in,     // encoder channel A, asynchronous
    input  wire [CHANNELS-1:0] b_in,     // encoder channel B, asynchronous
    input  wire [CHANNELS-1:0] z_in,     // index channel, asynchronous
    input  wire [CHANNELS-1:0] probe_in, // external latch input, asynchronous
    input  wire        snap_in,        // synchronous snapshot strobe
    output wire        irq,            // level: any enabled pending event
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

  // ---- channel registers -------------------------------------------------------------------------
  reg        aw_v_q, w_v_q, ar_v_q;  // an address / data beat is held
  reg [ADDR_W-1:0] awaddr_q, araddr_q;
  reg [31:0] wdata_q;
  reg [3:0]  wstrb_q;
  reg        req_q;                  // the request to enc_qei (this clock)
  reg        req_wr_q;               // ... a write
  reg [ADDR_W-1:0] req_addr_q;       // ... its address
  reg        pend_q;                 // a request is issued and its response has not come
  reg        pend_wr_q;              // ... and it is a write
  reg        last_rd_q;              // the last request issued was a read (alternation)
  reg        bvalid_q, rvalid_q;
  reg        berr_q, rerr_q;
  reg [31:0] rdata_q;

  wire        resp_valid, resp_err;
  wire [31:0] resp_rdata;

  wire idle     = ~pend_q & ~bvalid_q & ~rvalid_q;
  wire wr_ready = aw_v_q & w_v_q;
  wire issue_rd = idle & ar_v_q & ~(wr_ready & last_rd_q);
  wire issue_wr = idle & wr_ready & ~issue_rd;

  always @(posedge clk) begin
    if (rst) begin
      aw_v_q    <= 1'b0;
      w_v_q     <= 1'b0;
      ar_v_q    <= 1'b0;
      awaddr_q  <= {ADDR_W{1'b0}};
      araddr_q  <= {ADDR_W{1'b0}};
      wdata_q   <= 32'd0;
      wstrb_q   <= 4'd0;
      req_q     <= 1'b0;
      req_wr_q  <= 1'b0;
      req_addr_q <= {ADDR_W{1'b0}};
      pend_q    <= 1'b0;
      pend_wr_q <= 1'b0;
      last_rd_q <= 1'b0;
      bvalid_q  <= 1'b0;
      rvalid_q  <= 1'b0;
      berr_q    <= 1'b0;
      rerr_q    <= 1'b0;
      rdata_q   <= 32'd0;
    end else begin
      if (s_axil_awvalid & ~aw_v_q) begin
        aw_v_q   <= 1'b1;
        awaddr_q <= s_axil_awaddr;
      end else if (issue_wr) begin
        aw_v_q <= 1'b0;
      end
      if (s_axil_wvalid & ~w_v_q) begin
        w_v_q   <= 1'b1;
        wdata_q <= s_axil_wdata;
        wstrb_q <= s_axil_wstrb;
      end else if (issue_wr) begin
        w_v_q <= 1'b0;
      end
      if (s_axil_arvalid & ~ar_v_q) begin
        ar_v_q   <= 1'b1;
        araddr_q <= s_axil_araddr;
      end else if (issue_rd) begin
        ar_v_q <= 1'b0;
      end
      req_q <= issue_rd | issue_wr;
      if (issue_rd | issue_wr) begin
        pend_q     <= 1'b1;
        pend_wr_q  <= issue_wr;
        last_rd_q  <= issue_rd;
        req_wr_q   <= issue_wr;
        req_addr_q <= issue_wr ? awaddr_q : araddr_q;
      end else if (resp_valid) begin
        pend_q <= 1'b0;
      end
      if (resp_valid & pend_wr_q) begin
        bvalid_q <= 1'b1;
        berr_q   <= resp_err;
      end else if (s_axil_bready) begin
        bvalid_q <= 1'b0;
      end
      if (resp_valid & ~pend_wr_q) begin
        rvalid_q <= 1'b1;
        rerr_q   <= resp_err;
        rdata_q  <= resp_rdata;
      end else if (s_axil_rready) begin
        rvalid_q <= 1'b0;
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
      .req_valid (req_q),
      .req_write (req_wr_q),
      .req_addr  (req_addr_q),
      .req_wdata (wdata_q),
      .req_wstrb (wstrb_q),
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

  assign s_axil_awready = ~aw_v_q;
  assign s_axil_wready  = ~w_v_q;
  assign s_axil_arready = ~ar_v_q;
  assign s_axil_bvalid  = bvalid_q;
  assign s_axil_bresp   = berr_q ? 2'b10 : 2'b00;
  assign s_axil_rvalid  = rvalid_q;
  assign s_axil_rresp   = rerr_q ? 2'b10 : 2'b00;
  assign s_axil_rdata   = rdata_q;

endmodule

`default_nettype wire
