// SPDX-License-Identifier: Apache-2.0
// faxil_slave -- formal properties of an AXI4-Lite slave port.
//
// A reusable property checker, written in the style of ZipCPU's faxil_slave (this one is our
// own): instantiate it inside a formal wrapper with every signal of the slave's AXI4-Lite port as
// an input. It holds no design logic. Assumptions describe a legal master, assertions the slave.
// Synchronous active-high reset (a wrapper of an ARESETn port passes !aresetn); in a clock with
// rst high nothing is checked and no handshake counts.
//
// Master (assumed):
//   - AWVALID, WVALID, ARVALID low in the clock after a reset clock;
//   - a VALID, once high, stays high until its READY, with its payload (AWADDR/AWPROT,
//     WDATA/WSTRB, ARADDR/ARPROT) stable meanwhile;
//   - fairness, with F_MAX_STALL > 0: BREADY (RREADY) is not low for more than F_MAX_STALL
//     clocks in a row while BVALID (RVALID) is high. This is what lets a bounded response time
//     be asserted at all; with F_MAX_STALL = 0 there is no such assumption and the bounds below
//     are not checked.
// Slave (asserted):
//   - BVALID / RVALID low in the clock after a reset clock;
//   - BVALID only while a write has both its AW and W handshakes done in earlier clocks and no
//     B yet; RVALID only while a read has had its AR handshake and no R yet (each response
//     answers an accepted request, and exactly one: the counters go down by one per response);
//   - BVALID / RVALID, once high, stay high until BREADY / RREADY, with BRESP (RRESP, RDATA)
//     stable meanwhile; BRESP / RRESP never EXOKAY (not in AXI4-Lite);
//   - at most F_MAX_OUTSTANDING requests of each channel accepted and not answered;
//   - with F_MAX_STALL > 0 and F_MAX_DELAY > 0: while a complete write (read) is unanswered,
//     BVALID (RVALID) rises within F_MAX_DELAY clocks (counting from the clock after the
//     request's last handshake, or after the previous response was taken);
//   - with F_MAX_STALL > 0 and F_MAX_WAIT > 0: a VALID is not left without READY for more than
//     F_MAX_WAIT clocks in a row: ARVALID always; AWVALID when the W of that write is already
//     accepted or presented with it (WVALID likewise with its AW), so a slave may wait for the
//     other half of a write for as long as the master takes to send it.
// In order: AXI4-Lite responses of a channel answer its requests in order. The checker keeps
// the accepted requests that have no response yet in order, oldest first, as outputs
// (f_awaddr_q, f_wdata_q / f_wstrb_q, f_araddr_q: entry 0 in the low bits is the one the next
// response answers), with their counts (f_awr_outstanding, f_wr_outstanding,
// f_rd_outstanding), so that a wrapper can check each response against its own request.
`default_nettype none

module faxil_slave #(
    parameter integer AW                = 8,   // address width
    parameter integer DW                = 32,  // data width, a multiple of 8
    parameter integer F_MAX_OUTSTANDING = 2,   // most requests per channel accepted, unanswered
    parameter integer F_MAX_STALL       = 3,   // master fairness (see above); 0: none
    parameter integer F_MAX_WAIT        = 16,  // slave: most clocks a request waits for READY
    parameter integer F_MAX_DELAY       = 16,  // slave: most clocks to a response
    parameter integer F_LGDEPTH         = $clog2(F_MAX_OUTSTANDING + 2),  // (derived)
    parameter integer F_CNT_W           = $clog2(F_MAX_STALL + F_MAX_WAIT + F_MAX_DELAY + 2)
) (
    input  wire                           clk,
    input  wire                           rst,
    // write address
    input  wire [AW-1:0]                  awaddr,
    input  wire [2:0]                     awprot,
    input  wire                           awvalid,
    input  wire                           awready,
    // write data
    input  wire [DW-1:0]                  wdata,
    input  wire [DW/8-1:0]                wstrb,
    input  wire                           wvalid,
    input  wire                           wready,
    // write response
    input  wire [1:0]                     bresp,
    input  wire                           bvalid,
    input  wire                           bready,
    // read address
    input  wire [AW-1:0]                  araddr,
    input  wire [2:0]                     arprot,
    input  wire                           arvalid,
    input  wire                           arready,
    // read data
    input  wire [DW-1:0]                  rdata,
    input  wire [1:0]                     rresp,
    input  wire                           rvalid,
    input  wire                           rready,
    // for the wrapper: accepted, unanswered requests, oldest first
    output reg  [F_LGDEPTH-1:0]           f_awr_outstanding,
    output reg  [F_LGDEPTH-1:0]           f_wr_outstanding,
    output reg  [F_LGDEPTH-1:0]           f_rd_outstanding,
    output reg  [F_MAX_OUTSTANDING*AW-1:0]     f_awaddr_q,
    output reg  [F_MAX_OUTSTANDING*DW-1:0]     f_wdata_q,
    output reg  [F_MAX_OUTSTANDING*DW/8-1:0]   f_wstrb_q,
    output reg  [F_MAX_OUTSTANDING*AW-1:0]     f_araddr_q
);

  localparam integer N = F_MAX_OUTSTANDING;
  localparam integer SW = DW / 8;
  localparam [1:0] EXOKAY = 2'b01;

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  wire aw_hs = ~rst & awvalid & awready;
  wire w_hs  = ~rst & wvalid & wready;
  wire b_hs  = ~rst & bvalid & bready;
  wire ar_hs = ~rst & arvalid & arready;
  wire r_hs  = ~rst & rvalid & rready;

  // ---- outstanding requests, in order --------------------------------------------------------
  integer i;
  reg [N*AW-1:0] awq_n, arq_n;
  reg [N*DW-1:0] wq_n;
  reg [N*SW-1:0] wsq_n;

  always @(*) begin
    awq_n = b_hs ? (f_awaddr_q >> AW) : f_awaddr_q;
    wq_n  = b_hs ? (f_wdata_q >> DW) : f_wdata_q;
    wsq_n = b_hs ? (f_wstrb_q >> SW) : f_wstrb_q;
    arq_n = r_hs ? (f_araddr_q >> AW) : f_araddr_q;
    for (i = 0; i < N; i = i + 1) begin
      if (aw_hs && i == f_awr_outstanding - b_hs) awq_n[i*AW +: AW] = awaddr;
      if (w_hs && i == f_wr_outstanding - b_hs) begin
        wq_n[i*DW +: DW]  = wdata;
        wsq_n[i*SW +: SW] = wstrb;
      end
      if (ar_hs && i == f_rd_outstanding - r_hs) arq_n[i*AW +: AW] = araddr;
    end
  end

  always @(posedge clk) begin
    f_awaddr_q <= awq_n;
    f_wdata_q  <= wq_n;
    f_wstrb_q  <= wsq_n;
    f_araddr_q <= arq_n;
    if (rst) begin
      f_awr_outstanding <= {F_LGDEPTH{1'b0}};
      f_wr_outstanding  <= {F_LGDEPTH{1'b0}};
      f_rd_outstanding  <= {F_LGDEPTH{1'b0}};
    end else begin
      f_awr_outstanding <= f_awr_outstanding + aw_hs - b_hs;
      f_wr_outstanding  <= f_wr_outstanding + w_hs - b_hs;
      f_rd_outstanding  <= f_rd_outstanding + ar_hs - r_hs;
    end
  end

  // ---- master: assumptions -------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && $past(rst)) begin
      assume (!awvalid);
      assume (!wvalid);
      assume (!arvalid);
    end
    if (f_past_valid && !$past(rst)) begin
      if ($past(awvalid && !awready)) begin
        assume (awvalid);
        assume (awaddr == $past(awaddr));
        assume (awprot == $past(awprot));
      end
      if ($past(wvalid && !wready)) begin
        assume (wvalid);
        assume (wdata == $past(wdata));
        assume (wstrb == $past(wstrb));
      end
      if ($past(arvalid && !arready)) begin
        assume (arvalid);
        assume (araddr == $past(araddr));
        assume (arprot == $past(arprot));
      end
    end
  end

  // fairness: consecutive earlier clocks in which a response waited for its READY
  reg [F_CNT_W-1:0] bstall_q = {F_CNT_W{1'b0}}, rstall_q = {F_CNT_W{1'b0}};
  always @(posedge clk) begin
    bstall_q <= (rst | ~(bvalid & ~bready)) ? {F_CNT_W{1'b0}} : bstall_q + 1'b1;
    rstall_q <= (rst | ~(rvalid & ~rready)) ? {F_CNT_W{1'b0}} : rstall_q + 1'b1;
  end
  always @(*) begin
    if (F_MAX_STALL > 0 && !rst) begin
      if (bvalid && !bready) assume (bstall_q < F_MAX_STALL);
      if (rvalid && !rready) assume (rstall_q < F_MAX_STALL);
    end
  end

  // ---- slave: assertions ---------------------------------------------------------------------
  always @(posedge clk) begin
    if (f_past_valid && $past(rst)) begin
      assert (!bvalid);
      assert (!rvalid);
    end
    if (f_past_valid && !$past(rst) && !rst) begin
      if ($past(bvalid && !bready)) begin
        assert (bvalid);
        assert (bresp == $past(bresp));
      end
      if ($past(rvalid && !rready)) begin
        assert (rvalid);
        assert (rresp == $past(rresp));
        assert (rdata == $past(rdata));
      end
    end
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      if (bvalid) begin
        assert (f_awr_outstanding != 0);
        assert (f_wr_outstanding != 0);
        assert (bresp != EXOKAY);
      end
      if (rvalid) begin
        assert (f_rd_outstanding != 0);
        assert (rresp != EXOKAY);
      end
      assert (f_awr_outstanding <= N);
      assert (f_wr_outstanding <= N);
      assert (f_rd_outstanding <= N);
    end
  end

  // ---- slave: bounded response and acceptance (given the fairness assumption) -----------------
  wire bwaiting  = (f_awr_outstanding != 0) & (f_wr_outstanding != 0) & ~bvalid;
  wire rwaiting  = (f_rd_outstanding != 0) & ~rvalid;
  wire awwaiting = awvalid & ~awready & ((f_wr_outstanding > f_awr_outstanding) |
                   ((f_wr_outstanding == f_awr_outstanding) & wvalid));
  wire wwaiting  = wvalid & ~wready & ((f_awr_outstanding > f_wr_outstanding) |
                   ((f_awr_outstanding == f_wr_outstanding) & awvalid));
  wire arwaiting = arvalid & ~arready;

  // consecutive earlier clocks in each waiting state (saturating)
  reg [F_CNT_W-1:0] bwait_q = {F_CNT_W{1'b0}}, rwait_q = {F_CNT_W{1'b0}};
  reg [F_CNT_W-1:0] awwait_q = {F_CNT_W{1'b0}}, wwait_q = {F_CNT_W{1'b0}};
  reg [F_CNT_W-1:0] arwait_q = {F_CNT_W{1'b0}};
  localparam [F_CNT_W-1:0] CNT_MAX = {F_CNT_W{1'b1}};

  always @(posedge clk) begin
    bwait_q  <= (rst | ~bwaiting)  ? {F_CNT_W{1'b0}} : bwait_q  + (bwait_q  != CNT_MAX);
    rwait_q  <= (rst | ~rwaiting)  ? {F_CNT_W{1'b0}} : rwait_q  + (rwait_q  != CNT_MAX);
    awwait_q <= (rst | ~awwaiting) ? {F_CNT_W{1'b0}} : awwait_q + (awwait_q != CNT_MAX);
    wwait_q  <= (rst | ~wwaiting)  ? {F_CNT_W{1'b0}} : wwait_q  + (wwait_q  != CNT_MAX);
    arwait_q <= (rst | ~arwaiting) ? {F_CNT_W{1'b0}} : arwait_q + (arwait_q != CNT_MAX);
  end

  always @(*) begin
    if (f_past_valid && !rst && F_MAX_STALL > 0) begin
      if (F_MAX_DELAY > 0) begin
        if (bwaiting) assert (bwait_q < F_MAX_DELAY);
        if (rwaiting) assert (rwait_q < F_MAX_DELAY);
      end
      if (F_MAX_WAIT > 0) begin
        if (awwaiting) assert (awwait_q < F_MAX_WAIT);
        if (wwaiting) assert (wwait_q < F_MAX_WAIT);
        if (arwaiting) assert (arwait_q < F_MAX_WAIT);
      end
    end
  end

endmodule

`default_nettype wire
