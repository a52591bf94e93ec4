// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei's global snapshot (read by formal/enc_qei_gsnap.sby; `make formal`):
// the zero-skew rule of the multi-axis peripheral, proven on the real enc_qei (register block,
// timebase, global trigger and every channel) with three channels.
//
// The only assumption: the first clock is a reset. Every input is free at every clock after it:
// the request port (any request, any page), every channel's encoder inputs, snap_in, rst.
// Proven (k-induction), through probes the .sby connects after flatten (the global trigger's
// request gsnap, the timebase, GSNAP_TIME's register, and per channel its count, its snapshot
// registers and its snapshot strobe):
//   - in the clock of a global snapshot every channel takes a snapshot (each one's SNAP_READY
//     strobe), and in the clock after it every channel's SNAP_COUNT holds that channel's count
//     of the snapshot's clock, every channel's SNAP_TIME and GSNAP_TIME the timebase of that
//     clock: one clock, no skew between the channels;
//   - a write of GSNAP_CTRL.CMD = 1 (page 0, byte lane 0 enabled) takes a global snapshot
//     exactly LAT clocks after the request (LAT = 3: the register block's request register,
//     its CMD pulse, the trigger's request register; the same path as a channel's SNAP_CTRL.CMD).
// Not here: what the snapshot registers read on the bus (enc_qei_regs.sby: live fields read
// hw2reg), the trigger's snap_in and timer sources (the cocotb tests of the snapshot features).
`default_nettype none
`include "enc_params.vh"

module enc_qei_gsnap_formal #(
    parameter integer PROFILE = 2,  // the channels' units (enc_qei's PROFILE)
    parameter integer COUNT_W = 8,
    parameter integer TS_W    = 16
) (
    input wire        clk,
    input wire        rst,
    input wire        req_valid,
    input wire        req_write,
    input wire [9:0]  req_addr,
    input wire [31:0] req_wdata,
    input wire [3:0]  req_wstrb,
    input wire [2:0]  a_in,
    input wire [2:0]  b_in,
    input wire [2:0]  z_in,
    input wire [2:0]  probe_in,
    input wire        snap_in
);

`include "enc_qei_regs.vh"

  localparam integer LAT = 3;  // clocks from a GSNAP_CTRL.CMD write request to the snapshot

  wire        resp_valid, resp_err, irq;
  wire [31:0] resp_rdata;
  wire [2:0]  cmp_out;

  enc_qei #(
      .CHANNELS(3),
      .ADDR_W  (10),
      .COUNT_W (COUNT_W),
      .TS_W    (TS_W),
      .PROFILE (PROFILE)
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

  // Probes, connected by the .sby after flatten
  (* keep *) wire              p_gsnap;       // dut.gsnap: a global snapshot in this clock
  (* keep *) wire [TS_W-1:0]   p_timebase;    // dut.timebase
  (* keep *) wire [TS_W-1:0]   p_gsnap_time;  // GSNAP_TIME's register
  (* keep *) wire [COUNT_W-1:0] p_count0, p_count1, p_count2;  // each channel's count
  (* keep *) wire [COUNT_W-1:0] p_snap0, p_snap1, p_snap2;     // ... its SNAP_COUNT register
  (* keep *) wire [TS_W-1:0]   p_stime0, p_stime1, p_stime2;   // ... its SNAP_TIME register
  (* keep *) wire              p_ev0, p_ev1, p_ev2;            // ... its SNAP_READY strobe

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume (rst);

  // the values of the last clock
  reg              f_gsnap1 = 1'b0;
  reg [TS_W-1:0]   f_tb1;
  reg [COUNT_W-1:0] f_c0, f_c1, f_c2;
  always @(posedge clk) begin
    f_gsnap1 <= !rst && p_gsnap;
    f_tb1    <= p_timebase;
    f_c0     <= p_count0;
    f_c1     <= p_count1;
    f_c2     <= p_count2;
  end

  // GSNAP_CTRL.CMD write requests of the last LAT clocks (none across a reset)
  wire [15:0] f_addr16 = req_addr;
  wire f_cmd_req = req_valid && req_write && req_wstrb[0] && req_wdata[0] &&
                   f_addr16[15:2] == {8'd0, ENC_QEI_GSNAP_CTRL[7:2]};
  reg [LAT-1:0] f_cmd_q = {LAT{1'b0}};
  always @(posedge clk) begin
    if (rst) f_cmd_q <= {LAT{1'b0}};
    else f_cmd_q <= {f_cmd_q[LAT-2:0], f_cmd_req};
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      // every channel takes it, in the same clock
      if (p_gsnap) assert (p_ev0 && p_ev1 && p_ev2);
      // ... the values of that clock, in every channel and GSNAP_TIME
      if (f_gsnap1) begin
        assert (p_snap0 == f_c0);
        assert (p_snap1 == f_c1);
        assert (p_snap2 == f_c2);
        assert (p_stime0 == f_tb1);
        assert (p_stime1 == f_tb1);
        assert (p_stime2 == f_tb1);
        assert (p_gsnap_time == f_tb1);
      end
      // a CMD write: the snapshot LAT clocks later
      if (f_cmd_q[LAT-1]) assert (p_gsnap);
    end
  end

  // ---- covers ----------------------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid && !rst) begin
      // a global snapshot with three different counts
      cover (f_gsnap1 && p_snap0 != p_snap1 && p_snap1 != p_snap2 && p_snap0 != p_snap2);
      cover (f_cmd_q[LAT-1]);            // one taken by a CMD write
      cover (p_gsnap && !f_cmd_q[LAT-1]);  // one taken otherwise (snap_in or the timer)
    end
  end

endmodule

`default_nettype wire
