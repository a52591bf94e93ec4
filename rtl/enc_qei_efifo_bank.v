// SPDX-License-Identifier: Apache-2.0
// enc_qei_efifo_bank -- the edge-capture FIFOs of a shared-engine enc_qei (ENGINE = 1 with
// EFIFO_LOG2 > 0): one enc_qei_efifo per channel and the EFIFO_* registers of every channel
// page. Where the note's Figure 17 buffer hands the microprocessor a count, each FIFO hands it
// every edge, as in a per-channel build (rtl/enc_qei_efifo.v).
//
// The engine keeps a channel's other registers in block RAM and visits the channels in turn;
// a FIFO cannot wait for a visit (it takes every step in its clock, and a read pops at once), so
// it stays beside the engine, one per channel: each is fed by its lane's count-function steps
// (enc_qei_lane: step_up / step_dn with step_ab, and the qualified index edge, in the clock of
// the step, from the same enc_qei_decode as the per-channel core's), so every entry, timestamp,
// LOST and IDX mark is the per-channel build's, in the same clock.
// Bus: enc_qei sends this block the requests for EFIFO_CTRL, EFIFO_STATUS, EFIFO_ENTRY,
// EFIFO_TIME and EFIFO_LOST of a channel page and nothing else. They are answered as the
// register block answers them in a per-channel build: resp_valid two clocks after req_valid;
// a write acts at the end of the clock after the request, a read of EFIFO_ENTRY pops in that
// clock and returns the entry it popped. Field semantics: rtl/enc_qei.rdl (EFIFO_*).
// Events: ev_thresh / ev_ovf go to the channel's lane, which keeps them until the engine's
// next read of it; EVENTS.EFIFO_THRESH / EFIFO_OVF and irq follow with the engine's latency.
`default_nettype none

module enc_qei_efifo_bank #(
    parameter integer CHANNELS   = 1,   // channels, 1 .. 16 (checked by enc_qei)
    parameter integer DEPTH_LOG2 = 4,   // 2^DEPTH_LOG2 entries a channel, 1 .. 8 (checked by enc_qei)
    parameter integer TS_W       = 32   // timebase width, 16 .. 32 (checked by enc_qei)
) (
    input  wire                  clk,
    input  wire                  rst,         // synchronous, active high
    input  wire [TS_W-1:0]       timebase,    // the shared timebase
    // EFIFO_* requests of a channel page (enc_qei decodes them), one at a time
    input  wire                  req_valid,   // one clock
    input  wire                  req_write,
    input  wire [3:0]            req_ch,      // the page (< CHANNELS)
    input  wire [5:0]            req_word,    // the register's offset / 4
    input  wire [31:0]           req_wdata,
    input  wire [3:0]            req_wstrb,
    output wire                  resp_valid,  // two clocks after req_valid
    output wire [31:0]           resp_rdata,
    // the lanes' steps (enc_qei_engine), in the clock of the step
    input  wire [CHANNELS-1:0]   step_up,
    input  wire [CHANNELS-1:0]   step_dn,
    input  wire [2*CHANNELS-1:0] step_ab,     // channel k's {A, B} after its step at [2k +: 2]
    input  wire [CHANNELS-1:0]   idx_hit,     // channel k's qualified index edge
    // the FIFOs' events, to the lanes
    output wire [CHANNELS-1:0]   ev_thresh,   // channel k's FIFO holds THRESH entries or more
    output wire [CHANNELS-1:0]   ev_ovf       // channel k's FIFO lost a step (one clock a step)
);

  `include "enc_qei_regs.vh"

  // ---- the request, registered: decoded in the clock after it ----------------------------------
  reg        q_valid, q_write;
  reg [3:0]  q_ch;
  reg [5:0]  q_word;
  reg [31:0] q_wdata;
  reg [3:0]  q_wstrb;

  always @(posedge clk) begin
    if (rst) begin
      q_valid <= 1'b0;
    end else begin
      q_valid <= req_valid;
    end
  end

  always @(posedge clk) begin
    if (req_valid) begin
      q_write <= req_write;
      q_ch    <= req_ch;
      q_word  <= req_word;
      q_wdata <= req_wdata;
      q_wstrb <= req_wstrb;
    end
  end

  wire q_ctrl  = (q_word == ENC_QEI_EFIFO_CTRL[7:2]);
  wire q_stat  = (q_word == ENC_QEI_EFIFO_STATUS[7:2]);
  wire q_entry = (q_word == ENC_QEI_EFIFO_ENTRY[7:2]);
  wire q_time  = (q_word == ENC_QEI_EFIFO_TIME[7:2]);
  wire q_lost  = (q_word == ENC_QEI_EFIFO_LOST[7:2]);
  wire q_rd    = q_valid & ~q_write;
  wire q_wr    = q_valid & q_write;

  function [31:0] zext_ts;
    input [TS_W-1:0] v;
    begin
      zext_ts = 32'd0;
      zext_ts[TS_W-1:0] = v;
    end
  endfunction

  // ---- one FIFO and its registers a channel ----------------------------------------------------
  wire [CHANNELS*32-1:0] rd_ch;  // channel k's answer to the request (0 but for q_ch)

  genvar k;
  generate
    for (k = 0; k < CHANNELS; k = k + 1) begin : g_ch
      wire       sel = (q_ch == k[3:0]);
      reg        en_q;          // EFIFO_CTRL.EN
      reg        clear_q;       // EFIFO_CTRL.CLEAR: one clock
      reg [8:0]  thresh_q;      // EFIFO_CTRL.THRESH
      reg [15:0] lost_q;        // EFIFO_LOST.VALUE
      wire [31:0]     entry;
      wire [TS_W-1:0] pop_time;
      wire [8:0]      level;
      wire            lost_incr;

      always @(posedge clk) begin
        if (rst) begin
          en_q     <= ENC_QEI_EFIFO_CTRL_RESET[ENC_QEI_EFIFO_CTRL_EN];
          clear_q  <= 1'b0;
          thresh_q <= ENC_QEI_EFIFO_CTRL_RESET[ENC_QEI_EFIFO_CTRL_THRESH +: 9];
        end else begin
          clear_q <= q_wr & sel & q_ctrl & q_wstrb[0] & q_wdata[ENC_QEI_EFIFO_CTRL_CLEAR];
          if (q_wr & sel & q_ctrl) begin
            if (q_wstrb[0]) en_q <= q_wdata[ENC_QEI_EFIFO_CTRL_EN];
            if (q_wstrb[1]) thresh_q[7:0] <= q_wdata[15:8];
            if (q_wstrb[2]) thresh_q[8] <= q_wdata[16];
          end
        end
      end

      // (saturating at 0xFFFF; a write with a byte enable clears it, a loss in its clock counts)
      always @(posedge clk) begin
        if (rst) begin
          lost_q <= 16'd0;
        end else if (q_wr & sel & q_lost & (|q_wstrb)) begin
          lost_q <= {15'd0, lost_incr};
        end else if (lost_incr & ~(&lost_q)) begin
          lost_q <= lost_q + 16'd1;
        end
      end

      enc_qei_efifo #(
          .DEPTH_LOG2(DEPTH_LOG2),
          .TS_W      (TS_W)
      ) u_efifo (
          .clk      (clk),
          .rst      (rst),
          .timebase (timebase),
          .step_up  (step_up[k]),
          .step_dn  (step_dn[k]),
          .step_ab  (step_ab[2*k +: 2]),
          .ev_index (idx_hit[k]),
          .en       (en_q),
          .clear    (clear_q),
          .thresh   (thresh_q),
          .pop      (q_rd & sel & q_entry),
          .entry    (entry),
          .pop_time (pop_time),
          .level    (level),
          .ev_thresh(ev_thresh[k]),
          .ev_ovf   (ev_ovf[k]),
          .lost_incr(lost_incr)
      );

      assign rd_ch[k*32 +: 32] =
          {32{q_rd & sel}} & (({32{q_ctrl}} & {15'd0, thresh_q, 7'd0, en_q}) |
                              ({32{q_stat}} & {23'd0, level}) |
                              ({32{q_entry}} & entry) |
                              ({32{q_time}} & zext_ts(pop_time)) |
                              ({32{q_lost}} & {16'd0, lost_q}));
    end
  endgenerate

  // ---- the answer ---------------------------------------------------------------------------------
  reg        r_valid;
  reg [31:0] r_data;
  reg [31:0] rd_or;
  integer    j;

  always @(*) begin
    rd_or = 32'd0;
    for (j = 0; j < CHANNELS; j = j + 1) begin
      rd_or = rd_or | rd_ch[j*32 +: 32];
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      r_valid <= 1'b0;
    end else begin
      r_valid <= q_valid;
    end
  end

  always @(posedge clk) begin
    r_data <= rd_or;
  end

  assign resp_valid = r_valid;
  assign resp_rdata = r_valid ? r_data : 32'd0;

endmodule

`default_nettype wire
