// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_wb (read by formal/enc_qei_wb.sby; `make formal`).
//
// The adapter around the abstract enc_qei of formal/enc_qei_abstract.v (the .sby reads it
// instead of rtl/enc_qei.v): responses exactly two clocks after a request, resp_err = unmapped
// offset (for the wrapper's CHANNELS), read data f_qei_rdata(addr) (0 unmapped); the adapter
// logic does not depend on COUNT_W, TS_W, PROFILE or FUNC_MASK, and on CHANNELS only through
// ADDR_W. The real enc_qei's
// side of that contract is proven by formal/enc_qei_port.sby.
//
// Assumptions: the first clock is a reset; formal/fwb_slave.v's classic master (stb only with
// cyc, cyc low after a reset clock, a request held with its cyc, stb, we, adr, sel and write
// data until its answer: Wishbone B4's CYC_O is asserted for the duration of the cycle). Every
// input is free otherwise, rst included.
// Proven (k-induction):
//   - fwb_slave: every request answered by ack or err exactly two clocks after it started (an
//     access takes three clocks: F_MIN_DELAY = F_MAX_DELAY = 2), never both, never without a
//     presented request, one at a time;
//   - err exactly when the request's offset is unmapped (!enc_qei_mapped(wb_adr_i)), ack exactly
//     when it is mapped;
//   - a read answer carries the data enc_qei returned for that address (f_qei_rdata), an
//     unmapped read 0;
//   - the request reaches enc_qei exactly once, in its first clock, as it is on the bus: the
//     enc_qei port (req_valid, req_write, req_addr, req_wdata, req_wstrb, seen through probes
//     the .sby connects after flatten) shows it then and at no other clock; enc_qei's own rule
//     (one request at a time) is asserted in the stand-in;
//   - the adapter's busy_q (probe) is high exactly while its request is in enc_qei (the
//     induction needs it: while the bus is idle no port shows it).
// ABORT = 1 (task prove_abort): a master that may abandon a request by dropping cyc; then the
// answer may come up to four clocks after the request (the adapter first waits for the abandoned
// one, which it carries out but does not answer) and the request need not reach enc_qei in its
// first clock, everything else as above.
`default_nettype none
`include "enc_params.vh"

module enc_qei_wb_formal #(
    parameter [0:0] ABORT = 1'b0,  // 1: the master may abort a request by dropping cyc
    parameter integer CHANNELS = 1,  // the adapter's channels (its address decode)
    parameter integer AW = `ENC_QEI_ADDR_W(CHANNELS)  // its byte address bits
) (
    input wire        clk,
    input wire        rst,
    input wire [AW-1:0] wb_adr_i,
    input wire [31:0] wb_dat_i,
    input wire [3:0]  wb_sel_i,
    input wire        wb_we_i,
    input wire        wb_stb_i,
    input wire        wb_cyc_i,
    input wire [CHANNELS-1:0] a_in,
    input wire [CHANNELS-1:0] b_in,
    input wire [CHANNELS-1:0] z_in,
    input wire [CHANNELS-1:0] probe_in,
    input wire        snap_in
);

`include "enc_qei_regs.vh"
`include "enc_qei_abstract.vh"

  wire [31:0] wb_dat_o;
  wire        wb_ack_o, wb_err_o, irq;
  wire [CHANNELS-1:0] cmp_out;

  enc_qei_wb #(
      .CHANNELS(CHANNELS),
      .ADDR_W  (AW)
  ) dut (
      .clk     (clk),
      .rst     (rst),
      .wb_adr_i(wb_adr_i),
      .wb_dat_i(wb_dat_i),
      .wb_dat_o(wb_dat_o),
      .wb_sel_i(wb_sel_i),
      .wb_we_i (wb_we_i),
      .wb_stb_i(wb_stb_i),
      .wb_cyc_i(wb_cyc_i),
      .wb_ack_o(wb_ack_o),
      .wb_err_o(wb_err_o),
      .a_in    (a_in),
      .b_in    (b_in),
      .z_in    (z_in),
      .probe_in(probe_in),
      .snap_in (snap_in),
      .irq     (irq),
      .cmp_out (cmp_out)
  );

  // Probes, connected by the .sby after flatten: the adapter's enc_qei port (dut.u_qei.req_*)
  // and its one state register (dut.busy_q).
  (* keep *) wire        p_busy_q;
  (* keep *) wire        p_held_q;
  (* keep *) wire        p_req_valid;
  (* keep *) wire        p_req_write;
  (* keep *) wire [AW-1:0] p_req_addr;
  (* keep *) wire [31:0] p_req_wdata;
  (* keep *) wire [3:0]  p_req_wstrb;

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume (rst);

  wire       f_start, f_busy;
  wire [1:0] f_delay;
  wire [3:0] f_nreqs, f_nacks, f_outstanding;

  fwb_slave #(
      .AW         (AW),
      .DW         (32),
      .F_MIN_DELAY(ABORT ? 0 : 2),
      .F_MAX_DELAY(ABORT ? 4 : 2),
      .F_OPT_ABORT(ABORT),
      .F_OPT_ERR  (1'b1),
      .F_LGDEPTH  (4)
  ) f_bus (
      .clk          (clk),
      .rst          (rst),
      .cyc          (wb_cyc_i),
      .stb          (wb_stb_i),
      .we           (wb_we_i),
      .adr          (wb_adr_i),
      .dat_w        (wb_dat_i),
      .sel          (wb_sel_i),
      .ack          (wb_ack_o),
      .err          (wb_err_o),
      .f_start      (f_start),
      .f_busy       (f_busy),
      .f_delay      (f_delay),
      .f_nreqs      (f_nreqs),
      .f_nacks      (f_nacks),
      .f_outstanding(f_outstanding)
  );

  wire f_answer = wb_ack_o | wb_err_o;
  wire [15:0] f_adr16 = wb_adr_i;  // zero-extended for the map's functions
  wire f_mapped = enc_qei_mapped(f_adr16, CHANNELS);

  // requests on the enc_qei port one and two clocks ago: in flight (its response is due)
  reg f_q1 = 1'b0, f_q2 = 1'b0;
  always @(posedge clk) begin
    f_q1 <= !rst && p_req_valid;
    f_q2 <= !rst && f_q1;
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      // the adapter is busy exactly while its request is in enc_qei (the induction invariant)
      assert (p_busy_q == (f_q1 || f_q2));
      // held_q: the request in enc_qei is still wanted (always, unless the master aborts)
      assert (!p_held_q || p_busy_q);
      if (!ABORT) assert (p_held_q == p_busy_q);
      if (p_held_q && wb_cyc_i) assert (f_busy);
    end
    if (f_past_valid && !rst) begin
      // err exactly for an unmapped offset
      if (f_answer) assert (wb_err_o == !f_mapped);
      // read data: enc_qei's for that address, 0 unmapped
      if (f_answer && !wb_we_i) assert (wb_dat_o == (f_mapped ? f_qei_rdata(f_adr16) : 32'd0));
      // the request reaches enc_qei once, in its first clock, as it is on the bus
      if (!ABORT) assert (p_req_valid == f_start);
      if (p_req_valid) begin
        assert (p_req_write == wb_we_i);
        assert (p_req_addr == wb_adr_i);
        assert (p_req_wdata == wb_dat_i);
        assert (p_req_wstrb == wb_sel_i);
      end
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  reg f_rd_ok = 1'b0, f_wr_ok = 1'b0, f_rd_err = 1'b0, f_wr_err = 1'b0;
  always @(posedge clk) begin
    if (!rst && wb_ack_o && !wb_we_i) f_rd_ok <= 1'b1;
    if (!rst && wb_ack_o && wb_we_i) f_wr_ok <= 1'b1;
    if (!rst && wb_err_o && !wb_we_i) f_rd_err <= 1'b1;
    if (!rst && wb_err_o && wb_we_i) f_wr_err <= 1'b1;
  end

  always @(posedge clk) begin
    // back to back: the next request starts in the clock after an answer, stb held high
    if (f_past_valid && !rst && !$past(rst)) cover ($past(f_answer) && f_start && f_nacks == 4'd1);
  end


  always @(*) begin
    if (f_past_valid && !rst) begin
      cover (wb_ack_o && !wb_we_i);                      // a read
      cover (wb_ack_o && wb_we_i && wb_sel_i == 4'b0101);  // a write with some byte lanes
      cover (wb_err_o && !wb_we_i);                      // an error read
      cover (wb_err_o && wb_we_i);                       // an error write
      cover (f_answer && f_nacks == 4'd2);               // a third access in one bus cycle
      cover (f_rd_ok && f_wr_ok && f_rd_err && f_wr_err);  // all four kinds, one after another
      cover (f_start && wb_adr_i == ENC_QEI_STALL_TIMEOUT && wb_we_i);  // the last register
      cover (p_req_valid && wb_adr_i[1:0] != 2'b00 && f_mapped);       // low address bits ignored
    end
  end

endmodule

`default_nettype wire
