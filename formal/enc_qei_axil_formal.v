// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_axil (read by formal/enc_qei_axil.sby; `make formal`).
//
// The adapter around the abstract enc_qei of formal/enc_qei_abstract.v (read instead of
// rtl/enc_qei.v): responses exactly two clocks after a request, resp_err = unmapped offset (for
// the wrapper's CHANNELS), read data f_qei_rdata(addr) (0 unmapped). The adapter logic does not
// depend on COUNT_W, TS_W, PROFILE or FUNC_MASK, and on CHANNELS only through ADDR_W; the real
// enc_qei's side of the contract is proven by formal/enc_qei_port.sby.
//
// Assumptions: the first clock is a reset; formal/faxil_slave.v's master (valids low after a
// reset clock, a VALID held with a stable payload until its READY) with the fairness bound: BREADY
// / RREADY low for at most STALL clocks in a row while BVALID / RVALID. Everything else is free at
// every clock, rst included; AW, W and AR may come in any order and with any gaps.
// Proven (k-induction):
//   - faxil_slave: B / R only for accepted requests, one per request, held with a stable payload
//     until taken, never EXOKAY; at most two requests per channel accepted and unanswered; a
//     complete write / a read answered within DELAY clocks and every VALID accepted within WAIT
//     clocks (AWVALID / WVALID when the other half of that write is there);
//   - BRESP / RRESP is SLVERR exactly when the address of the request it answers (the oldest
//     unanswered one of its channel) is unmapped (!enc_qei_mapped), OKAY otherwise;
//   - RDATA is what enc_qei returned for that address (f_qei_rdata), 0 when unmapped;
//   - every accepted request reaches enc_qei exactly once, as it was accepted: the enc_qei port
//     (probes) shows a write with the address, data and byte enables of the oldest unanswered
//     AW and W, a read with the address of the oldest unanswered AR; requests given to enc_qei
//     and not yet answered on the bus number the accepted requests that are no longer held in
//     the adapter's skid registers (READY low), per channel, and at most one at a time;
//   - while a skid register holds a request (its READY low) it holds the newest accepted one;
//     the adapter waits for a response (pend_q) exactly while a request given to enc_qei has no
//     B / R up yet, and its last-issued flag (reads and writes alternate) is the kind of the
//     request being served (probes of the adapter's awaddr_q, wdata_q / wstrb_q, araddr_q,
//     pend_q, pend_wr_q, last_rd_q: the k-induction needs them, that state being invisible at
//     the ports for as long as the master withholds the other half of a write).
`default_nettype none
`include "enc_params.vh"

module enc_qei_axil_formal #(
    parameter integer STALL = 3,   // master fairness: BREADY / RREADY low at most this long
    parameter integer WAIT  = 15,  // slave: most clocks a VALID waits for its READY
    parameter integer DELAY = 12,  // slave: most clocks a complete request waits for B / R
    parameter integer CHANNELS = 1,  // the adapter's channels (its address decode)
    parameter integer AW = `ENC_QEI_ADDR_W(CHANNELS)  // its byte address bits
) (
    input wire        clk,
    input wire        rst,
    input wire [AW-1:0] s_axil_awaddr,
    input wire [2:0]  s_axil_awprot,
    input wire        s_axil_awvalid,
    input wire [31:0] s_axil_wdata,
    input wire [3:0]  s_axil_wstrb,
    input wire        s_axil_wvalid,
    input wire        s_axil_bready,
    input wire [AW-1:0] s_axil_araddr,
    input wire [2:0]  s_axil_arprot,
    input wire        s_axil_arvalid,
    input wire        s_axil_rready,
    input wire [CHANNELS-1:0] a_in,
    input wire [CHANNELS-1:0] b_in,
    input wire [CHANNELS-1:0] z_in,
    input wire [CHANNELS-1:0] probe_in,
    input wire        snap_in
);

`include "enc_qei_regs.vh"
`include "enc_qei_abstract.vh"

  wire        s_axil_awready, s_axil_wready, s_axil_bvalid, s_axil_arready, s_axil_rvalid;
  wire [1:0]  s_axil_bresp, s_axil_rresp;
  wire [31:0] s_axil_rdata;
  wire        irq;
  wire [CHANNELS-1:0] cmp_out;

  enc_qei_axil #(
      .CHANNELS(CHANNELS),
      .ADDR_W  (AW)
  ) dut (
      .clk           (clk),
      .rst           (rst),
      .s_axil_awaddr (s_axil_awaddr),
      .s_axil_awprot (s_axil_awprot),
      .s_axil_awvalid(s_axil_awvalid),
      .s_axil_awready(s_axil_awready),
      .s_axil_wdata  (s_axil_wdata),
      .s_axil_wstrb  (s_axil_wstrb),
      .s_axil_wvalid (s_axil_wvalid),
      .s_axil_wready (s_axil_wready),
      .s_axil_bresp  (s_axil_bresp),
      .s_axil_bvalid (s_axil_bvalid),
      .s_axil_bready (s_axil_bready),
      .s_axil_araddr (s_axil_araddr),
      .s_axil_arprot (s_axil_arprot),
      .s_axil_arvalid(s_axil_arvalid),
      .s_axil_arready(s_axil_arready),
      .s_axil_rdata  (s_axil_rdata),
      .s_axil_rresp  (s_axil_rresp),
      .s_axil_rvalid (s_axil_rvalid),
      .s_axil_rready (s_axil_rready),
      .a_in          (a_in),
      .b_in          (b_in),
      .z_in          (z_in),
      .probe_in      (probe_in),
      .snap_in       (snap_in),
      .irq           (irq),
      .cmp_out       (cmp_out)
  );

  // Probes, connected by the .sby after flatten: the adapter's skid registers, its pending flags
  // and its enc_qei port (dut.u_qei.req_*).
  (* keep *) wire [AW-1:0] p_awaddr_q;
  (* keep *) wire [31:0] p_wdata_q;
  (* keep *) wire [3:0]  p_wstrb_q;
  (* keep *) wire [AW-1:0] p_araddr_q;
  (* keep *) wire        p_pend_q;
  (* keep *) wire        p_pend_wr_q;
  (* keep *) wire        p_last_rd_q;
  (* keep *) wire        p_req_valid;
  (* keep *) wire        p_req_write;
  (* keep *) wire [AW-1:0] p_req_addr;
  (* keep *) wire [31:0] p_req_wdata;
  (* keep *) wire [3:0]  p_req_wstrb;

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume (rst);

  wire [1:0]  f_awr_out, f_wr_out, f_rd_out;
  wire [2*AW-1:0] f_awq, f_arq;
  wire [63:0] f_wq;
  wire [7:0]  f_wsq;

  faxil_slave #(
      .AW               (AW),
      .DW               (32),
      .F_MAX_OUTSTANDING(2),
      .F_MAX_STALL      (STALL),
      .F_MAX_WAIT       (WAIT),
      .F_MAX_DELAY      (DELAY),
      .F_LGDEPTH        (2)
  ) f_bus (
      .clk              (clk),
      .rst              (rst),
      .awaddr           (s_axil_awaddr),
      .awprot           (s_axil_awprot),
      .awvalid          (s_axil_awvalid),
      .awready          (s_axil_awready),
      .wdata            (s_axil_wdata),
      .wstrb            (s_axil_wstrb),
      .wvalid           (s_axil_wvalid),
      .wready           (s_axil_wready),
      .bresp            (s_axil_bresp),
      .bvalid           (s_axil_bvalid),
      .bready           (s_axil_bready),
      .araddr           (s_axil_araddr),
      .arprot           (s_axil_arprot),
      .arvalid          (s_axil_arvalid),
      .arready          (s_axil_arready),
      .rdata            (s_axil_rdata),
      .rresp            (s_axil_rresp),
      .rvalid           (s_axil_rvalid),
      .rready           (s_axil_rready),
      .f_awr_outstanding(f_awr_out),
      .f_wr_outstanding (f_wr_out),
      .f_rd_outstanding (f_rd_out),
      .f_awaddr_q       (f_awq),
      .f_wdata_q        (f_wq),
      .f_wstrb_q        (f_wsq),
      .f_araddr_q       (f_arq)
  );

  localparam [1:0] OKAY = 2'b00, SLVERR = 2'b10;

  // the oldest unanswered request of each channel (the one the next response answers) and the
  // newest accepted one (the one a skid register may hold)
  wire [AW-1:0] aw_old = f_awq[AW-1:0];
  wire [31:0] w_old  = f_wq[31:0];
  wire [3:0]  ws_old = f_wsq[3:0];
  wire [AW-1:0] ar_old = f_arq[AW-1:0];
  wire [AW-1:0] aw_new = (f_awr_out == 2'd2) ? f_awq[2*AW-1:AW] : f_awq[AW-1:0];
  wire [31:0] w_new  = (f_wr_out == 2'd2) ? f_wq[63:32] : f_wq[31:0];
  wire [3:0]  ws_new = (f_wr_out == 2'd2) ? f_wsq[7:4] : f_wsq[3:0];
  wire [AW-1:0] ar_new = (f_rd_out == 2'd2) ? f_arq[2*AW-1:AW] : f_arq[AW-1:0];
  // ... zero-extended for the map's functions
  wire [15:0] aw_old16 = aw_old;
  wire [15:0] ar_old16 = ar_old;

  // requests given to enc_qei (seen on its port) whose response has not been taken on the bus
  reg [1:0] f_wr_given = 2'd0, f_rd_given = 2'd0;
  wire b_hs = s_axil_bvalid & s_axil_bready;
  wire r_hs = s_axil_rvalid & s_axil_rready;
  always @(posedge clk) begin
    if (rst) begin
      f_wr_given <= 2'd0;
      f_rd_given <= 2'd0;
    end else begin
      f_wr_given <= f_wr_given + (p_req_valid & p_req_write) - b_hs;
      f_rd_given <= f_rd_given + (p_req_valid & ~p_req_write) - r_hs;
    end
  end
  // ... counting the one on the port in this clock
  wire [2:0] f_wr_in = {1'b0, f_wr_given} + (p_req_valid & p_req_write);
  wire [2:0] f_rd_in = {1'b0, f_rd_given} + (p_req_valid & ~p_req_write);

  always @(*) begin
    if (f_past_valid && !rst) begin
      // responses: SLVERR exactly for an unmapped address; read data
      if (s_axil_bvalid) begin
        assert (s_axil_bresp == (enc_qei_mapped(aw_old16, CHANNELS) ? OKAY : SLVERR));
      end
      if (s_axil_rvalid) begin
        assert (s_axil_rresp == (enc_qei_mapped(ar_old16, CHANNELS) ? OKAY : SLVERR));
        assert (s_axil_rdata == (enc_qei_mapped(ar_old16, CHANNELS) ? f_qei_rdata(ar_old16) : 32'd0));
      end
      // every accepted request given to enc_qei once: the accepted ones not held in a skid
      // register; one at a time
      assert (f_wr_in + f_rd_in <= 3'd1);
      assert (f_wr_in == {1'b0, f_awr_out} - !s_axil_awready);
      assert (f_wr_in == {1'b0, f_wr_out} - !s_axil_wready);
      assert (f_rd_in == {1'b0, f_rd_out} - !s_axil_arready);
      // ... as it was accepted (it is the oldest of its channel)
      if (p_req_valid && p_req_write) begin
        assert (p_req_addr == aw_old);
        assert (p_req_wdata == w_old);
        assert (p_req_wstrb == ws_old);
      end
      if (p_req_valid && !p_req_write) assert (p_req_addr == ar_old);
      // the skid registers hold the newest accepted request
      if (!s_axil_awready) assert (p_awaddr_q == aw_new);
      if (!s_axil_wready) begin
        assert (p_wdata_q == w_new);
        assert (p_wstrb_q == ws_new);
      end
      if (!s_axil_arready) assert (p_araddr_q == ar_new);
      // the adapter waits for enc_qei's response exactly while a request given to it has none
      // yet (neither B nor R up), and knows its kind
      assert (p_pend_q == ((f_wr_in + f_rd_in != 3'd0) && !s_axil_bvalid && !s_axil_rvalid));
      if (p_pend_q) assert (p_pend_wr_q == (f_wr_in != 3'd0));
      // the alternation's memory: the request in enc_qei or answered, not yet taken, is the
      // last one issued
      if (f_wr_in + f_rd_in != 3'd0) assert (p_last_rd_q == (f_rd_in != 3'd0));
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  reg f_rd_ok = 1'b0, f_wr_ok = 1'b0, f_rd_err = 1'b0, f_wr_err = 1'b0;
  reg [2:0] f_nresp = 3'd0;  // responses taken since reset (saturating)
  always @(posedge clk) begin
    if (!rst && r_hs && s_axil_rresp == OKAY) f_rd_ok <= 1'b1;
    if (!rst && b_hs && s_axil_bresp == OKAY) f_wr_ok <= 1'b1;
    if (!rst && r_hs && s_axil_rresp == SLVERR) f_rd_err <= 1'b1;
    if (!rst && b_hs && s_axil_bresp == SLVERR) f_wr_err <= 1'b1;
    if (rst) f_nresp <= 3'd0;
    else if ((b_hs || r_hs) && f_nresp != 3'd7) f_nresp <= f_nresp + 1'b1;
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      cover (r_hs && s_axil_rresp == OKAY);                         // a read
      cover (b_hs && s_axil_bresp == OKAY && w_old != 32'd0 && ws_old == 4'b0110);  // a write
      cover (r_hs && s_axil_rresp == SLVERR);                       // an error read
      cover (b_hs && s_axil_bresp == SLVERR);                       // an error write
      cover (f_rd_ok && f_wr_ok && f_rd_err && f_wr_err);           // all four, one after another
      // a write in enc_qei and all three skid registers full
      cover (f_wr_in == 3'd1 && !s_axil_awready && !s_axil_wready && !s_axil_arready);
      // a read in enc_qei and all three skid registers full
      cover (f_rd_in == 3'd1 && !s_axil_awready && !s_axil_wready && !s_axil_arready);
      cover (f_wr_out == 2'd1 && f_awr_out == 2'd0 && !s_axil_wready);  // W before its AW
      cover (s_axil_bvalid && !s_axil_bready && !s_axil_awready && !s_axil_arready);  // B stalled
      cover (s_axil_rvalid && !s_axil_rready && f_awr_out == 2'd1 && f_wr_out == 2'd1);  // R stalled
      cover (f_nresp == 3'd4);                                      // four accesses done
    end
  end

  // back to back: a request on the enc_qei port two clocks after the previous response was taken
  // (the earliest: the adapter issues in the clock after, from a register), of the other kind
  always @(posedge clk) begin
    if (f_past_valid && !rst && !$past(rst) && !$past(rst, 2))
      cover (p_req_valid && $past(b_hs || r_hs, 2) && p_req_write != $past(b_hs, 2));
  end

endmodule

`default_nettype wire
