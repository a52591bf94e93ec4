// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_efifo_bank, the shared engine's edge FIFOs (read by
// formal/enc_qei_efifo_bank.sby; `make formal`).
//
// The bank answers the EFIFO_* registers of every channel page in place of the register block,
// so the wrapper holds it to what the RDL says of them (rtl/enc_qei.rdl, EFIFO_*; and CAPS.ENGINE
// shared, clause (4): as a per_channel build, in its clocks). Free on every clock: rst (the first
// clock is a reset), the lanes' steps (not both ways at once), their index edges and A/B, the
// timebase, and the bus requests under the register port's rule (one request at a time: none in
// the two clocks after one; a channel below CHANNELS; one of the five EFIFO_* words).
// The wrapper's model is written from the RDL, from the requests alone: per channel EN and THRESH
// (EFIFO_CTRL: EN from lane 0, THRESH[7:0] from lane 1, THRESH[8] from lane 2; reset 0 and 1) and
// the request in flight. Proven (k-induction):
//   - every request is answered exactly two clocks after it, resp_rdata is 0 when there is no
//     answer and for a write
//   - a read of EFIFO_CTRL answers the model's EN and THRESH, CLEAR as 0
//   - each channel's FIFO is given the model's EN and THRESH in every clock; its clear is one clock,
//     the clock after a write of EFIFO_CTRL to that channel with lane 0 and CLEAR = 1, and never
//     otherwise; it pops only in the clock after a read of that channel's EFIFO_ENTRY
//   - a read of EFIFO_STATUS answers the addressed FIFO's level, EFIFO_ENTRY its entry, EFIFO_TIME
//     its last pop's time, each as it is in the clock after the request (the clock of the pop)
//   - EFIFO_LOST counts each channel's losses (lost_incr), saturating at 0xFFFF, and a write with
//     any lane clears it (a loss in the clock the write acts makes it 1); a read answers it
// The FIFOs' own storage, level and marks: formal/enc_qei_efifo.sby (its properties under FORMAL
// are read here too).
`default_nettype none

module enc_qei_efifo_bank_formal #(
    parameter integer CHANNELS   = 2,
    parameter integer DEPTH_LOG2 = 2,
    parameter integer TS_W       = 16
) (
    input wire                  clk,
    input wire                  rst,
    input wire [TS_W-1:0]       timebase,
    input wire                  req_valid,
    input wire                  req_write,
    input wire [3:0]            req_ch,
    input wire [5:0]            req_word,
    input wire [31:0]           req_wdata,
    input wire [3:0]            req_wstrb,
    input wire [CHANNELS-1:0]   step_up,
    input wire [CHANNELS-1:0]   step_dn,
    input wire [2*CHANNELS-1:0] step_ab,
    input wire [CHANNELS-1:0]   idx_hit
);

  `include "enc_qei_regs.vh"

  wire                resp_valid;
  wire [31:0]         resp_rdata;
  wire [CHANNELS-1:0] ev_thresh, ev_ovf;

  enc_qei_efifo_bank #(
      .CHANNELS  (CHANNELS),
      .DEPTH_LOG2(DEPTH_LOG2),
      .TS_W      (TS_W)
  ) bank (
      .clk       (clk),
      .rst       (rst),
      .timebase  (timebase),
      .req_valid (req_valid),
      .req_write (req_write),
      .req_ch    (req_ch),
      .req_word  (req_word),
      .req_wdata (req_wdata),
      .req_wstrb (req_wstrb),
      .resp_valid(resp_valid),
      .resp_rdata(resp_rdata),
      .step_up   (step_up),
      .step_dn   (step_dn),
      .step_ab   (step_ab),
      .idx_hit   (idx_hit),
      .ev_thresh (ev_thresh),
      .ev_ovf    (ev_ovf)
  );

  // ---- probes, connected by the .sby after flatten: the two FIFOs' ports (g_ch[k].u_efifo) -----
  (* keep *) wire            p_en0, p_en1, p_clear0, p_clear1, p_pop0, p_pop1;  // .en .clear .pop
  (* keep *) wire            p_lost0, p_lost1;                                  // .lost_incr
  (* keep *) wire [8:0]      p_thresh0, p_thresh1, p_level0, p_level1;          // .thresh .level
  (* keep *) wire [31:0]     p_entry0, p_entry1;                                // .entry
  (* keep *) wire [TS_W-1:0] p_ptime0, p_ptime1;                                // .pop_time
  // ... and the bank's request stage and EFIFO_LOST counters (for the induction: each equals the
  // model's)
  (* keep *) wire            p_qv, p_qw, p_rv;        // bank.q_valid, q_write, r_valid
  (* keep *) wire [3:0]      p_qch, p_qstrb;          // bank.q_ch, q_wstrb
  (* keep *) wire [5:0]      p_qword;                 // bank.q_word
  (* keep *) wire [31:0]     p_qwdata;                // bank.q_wdata
  (* keep *) wire [15:0]     p_lostq0, p_lostq1;      // bank.g_ch[k].lost_q
  wire [CHANNELS-1:0]      p_en     = {p_en1, p_en0};
  wire [CHANNELS-1:0]      p_clear  = {p_clear1, p_clear0};
  wire [CHANNELS-1:0]      p_pop    = {p_pop1, p_pop0};
  wire [CHANNELS-1:0]      p_lost   = {p_lost1, p_lost0};
  wire [9*CHANNELS-1:0]    p_thresh = {p_thresh1, p_thresh0};
  wire [9*CHANNELS-1:0]    p_level  = {p_level1, p_level0};
  wire [32*CHANNELS-1:0]   p_entry  = {p_entry1, p_entry0};
  wire [TS_W*CHANNELS-1:0] p_ptime  = {p_ptime1, p_ptime0};

  generate
    if (CHANNELS != 2) begin : g_bad_channels
      enc_qei_efifo_bank_formal__probes_are_for_two_channels u_stop ();
    end
  endgenerate

  // ---- the rules --------------------------------------------------------------------------------
  reg f_past = 1'b0;
  reg f_req1 = 1'b0, f_req2 = 1'b0;  // a request one / two clocks ago (since rst)

  always @(posedge clk) begin
    f_past <= 1'b1;
    f_req1 <= ~rst & req_valid;
    f_req2 <= ~rst & f_req1;
  end

  wire f_ctrl_w  = (req_word == ENC_QEI_EFIFO_CTRL[7:2]);
  wire f_stat_w  = (req_word == ENC_QEI_EFIFO_STATUS[7:2]);
  wire f_entry_w = (req_word == ENC_QEI_EFIFO_ENTRY[7:2]);
  wire f_time_w  = (req_word == ENC_QEI_EFIFO_TIME[7:2]);
  wire f_lost_w  = (req_word == ENC_QEI_EFIFO_LOST[7:2]);

  always @(*) begin
    if (!f_past) assume (rst);
    assume ((step_up & step_dn) == {CHANNELS{1'b0}});
    if (req_valid) begin
      assume (!f_req1 && !f_req2);
      assume (req_ch < CHANNELS);
      assume (f_ctrl_w || f_stat_w || f_entry_w || f_time_w || f_lost_w);
    end
  end

  // ---- the model: the request in flight, EN, THRESH, EFIFO_LOST ---------------------------------
  reg        m_write;
  reg [3:0]  m_ch;
  reg [5:0]  m_word;
  reg [31:0] m_wdata;
  reg [3:0]  m_wstrb;

  always @(posedge clk) begin
    if (req_valid) begin
      m_write <= req_write;
      m_ch    <= req_ch;
      m_word  <= req_word;
      m_wdata <= req_wdata;
      m_wstrb <= req_wstrb;
    end
  end

  // the request, one clock later (f_req1): it acts now, a read takes its data now
  wire m_rd    = f_req1 & ~m_write;
  wire m_wr    = f_req1 & m_write;
  wire m_ctrl  = (m_word == ENC_QEI_EFIFO_CTRL[7:2]);
  wire m_stat  = (m_word == ENC_QEI_EFIFO_STATUS[7:2]);
  wire m_entry = (m_word == ENC_QEI_EFIFO_ENTRY[7:2]);
  wire m_time  = (m_word == ENC_QEI_EFIFO_TIME[7:2]);
  wire m_lost  = (m_word == ENC_QEI_EFIFO_LOST[7:2]);

  reg  [CHANNELS-1:0]   f_en;
  reg  [9*CHANNELS-1:0] f_thresh;
  reg  [16*CHANNELS-1:0] f_lostc;
  reg  [31:0]           f_answer;  // what the read in flight must answer (0 for a write)
  integer k;

  function [31:0] zext;
    input [TS_W-1:0] v;
    begin
      zext = 32'd0;
      zext[TS_W-1:0] = v;
    end
  endfunction

  always @(posedge clk) begin
    if (rst) begin
      f_en     <= {CHANNELS{1'b0}};
      f_thresh <= {CHANNELS{9'd1}};
      f_lostc  <= {(16*CHANNELS){1'b0}};
    end else begin
      for (k = 0; k < CHANNELS; k = k + 1) begin
        if (m_wr && m_ctrl && m_ch == k) begin
          if (m_wstrb[0]) f_en[k] <= m_wdata[0];
          if (m_wstrb[1]) f_thresh[9*k +: 8] <= m_wdata[15:8];
          if (m_wstrb[2]) f_thresh[9*k + 8] <= m_wdata[16];
        end
        if (m_wr && m_lost && m_ch == k && m_wstrb != 4'd0) begin
          f_lostc[16*k +: 16] <= {15'd0, p_lost[k]};
        end else if (p_lost[k] && f_lostc[16*k +: 16] != 16'hFFFF) begin
          f_lostc[16*k +: 16] <= f_lostc[16*k +: 16] + 16'd1;
        end
      end
    end
  end

  always @(posedge clk) begin
    f_answer <= 32'd0;
    for (k = 0; k < CHANNELS; k = k + 1) begin
      if (m_rd && m_ch == k) begin
        if (m_ctrl)  f_answer <= {15'd0, f_thresh[9*k +: 9], 7'd0, f_en[k]};
        if (m_stat)  f_answer <= {23'd0, p_level[9*k +: 9]};
        if (m_entry) f_answer <= p_entry[32*k +: 32];
        if (m_time)  f_answer <= zext(p_ptime[TS_W*k +: TS_W]);
        if (m_lost)  f_answer <= {16'd0, f_lostc[16*k +: 16]};
      end
    end
  end

  // ---- the properties ------------------------------------------------------------------------------
  always @(*) begin
    if (f_past && !rst) begin
      assert (p_en == f_en);
      assert (p_thresh == f_thresh);
      for (k = 0; k < CHANNELS; k = k + 1) begin
        assert (p_pop[k] == (m_rd && m_entry && m_ch == k));
      end
      // (the induction's invariants: the bank holds the request the model holds, and its counts)
      assert (p_qv == f_req1 && p_rv == f_req2);
      if (f_req1) assert (p_qw == m_write && p_qch == m_ch && p_qword == m_word &&
                          p_qwdata == m_wdata && p_qstrb == m_wstrb);
      assert ({p_lostq1, p_lostq0} == f_lostc);
    end
  end

  always @(posedge clk) begin
    if (f_past && !rst && !$past(rst)) begin
      assert (resp_valid == f_req2);
      if (!resp_valid) assert (resp_rdata == 32'd0);
      if (resp_valid) assert (resp_rdata == f_answer);
      for (k = 0; k < CHANNELS; k = k + 1) begin
        assert (p_clear[k] == ($past(m_wr && m_ctrl && m_ch == k) && $past(m_wstrb[0]) &&
                               $past(m_wdata[1])));
      end
    end
  end

  // ---- covers: each register read with something in it --------------------------------------------
  always @(posedge clk) begin
    if (f_past && !rst) begin
      cover (resp_valid && m_word == ENC_QEI_EFIFO_ENTRY[7:2] && resp_rdata[0] && m_ch == 1);
      cover (resp_valid && m_word == ENC_QEI_EFIFO_LOST[7:2] && resp_rdata != 32'd0);
      cover (resp_valid && m_word == ENC_QEI_EFIFO_CTRL[7:2] && resp_rdata[16]);
    end
  end

endmodule

`default_nettype wire
