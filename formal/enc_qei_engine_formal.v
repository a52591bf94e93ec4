// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_engine, the shared channel engine (read by formal/enc_qei_engine.sby;
// `make formal`): its schedule and the discipline of its two memories.
//
// Every input is free after the first-clock reset (rst too): the encoder pins, snap_in, the
// timebase and its tick, the global snapshot's request, and channel-page requests of any
// register, data and byte enables to any built channel, one at a time (enc_qei's port: a request
// only while none is unanswered, or in the clock of the answer). The lanes are cut out (the .sby's
// `cutpoint enc_qei_lane`): their records and snap_pend are free at every clock, so nothing below
// depends on what a lane counts (formal/enc_qei_lane.sby checks the lane).
// Proven (k-induction), through probes the .sby connects after flatten:
//   - the visit order: slot 0 .. 23, c(v + 1) follows c(v) and c(v - 1) precedes it, modulo
//     CH_EFF = max(CHANNELS, 2);
//   - every lane is read (rd, one-hot or none) exactly every P = 24 * CH_EFF clocks, the first
//     time within P clocks of rst: a per-lane count of the clocks since its last read (or rst)
//     never exceeds P and is P at every read but the first;
//   - the push: a lane's configuration is pushed (cfg_we) in the clock before each of its reads
//     and at no other time but the clock before that, which only a COUNT write's value uses, and
//     then ld comes with the push after it (the value a clock ahead of its load);
//   - the state memory's port a never reads, in a slot whose data the engine uses (1 .. 22), the
//     word written in that clock (enc_qei_ram has no read-during-write bypass); the port-b data
//     the bus takes (the first of its two reads, or the second when the first met a write of
//     its word: b_clash) was not read in a clock that wrote that word; the write slots' memory
//     (u_pend) is never read for a taken write in the clock it is written, on either port;
//   - the global snapshot: lanes 0 and 1 see the engine's gsnap in its clock (one wire to
//     every lane); gsnap is raised only while no lane's capture waits unread (the lane proof's
//     assumption, so each lane takes its snapshot in that clock: formal/enc_qei_lane.sby); a
//     request (gsnap_req, or one waiting) is taken in the next clock or still waits;
//   - a bus write is taken once and applied once: per channel, a write waits (pend) or is being
//     applied (busy), never both; the bus posts a write only into a free slot of a channel with no
//     write unapplied; the engine takes only a waiting write and completes only a taken one; a
//     posted write stays waiting or busy until it is completed (the wrapper's own count of posted
//     minus completed writes is pend | busy);
//   - a write acts within the RDL's bounds (CAPS.ENGINE shared, (2)): P + 14 clocks after its
//     answer, P + 18 after its request (a state write: P + 22, P + 26), and a read right after it
//     is answered within P + 62 of its answer, P + 66 of its request (see that section);
//   - with COUNT_W > 32 (task prove_w40), COUNT_HI's latch: a COUNT_LO read of another channel
//     stores it first, as a state write of that channel, and the waits that makes stay within
//     the RDL's bounds (see that section).
// With ENGINE_DATA (tasks data, data_ch3, data_w40) also the data path of the count, its latches,
// PRESET, CEILING, COUNT_HI and the snapshot's words, for one channel f (any, fixed; the bus
// writes any of its registers): see the section at the end.
`default_nettype none
`ifdef ENGINE_DATA
`include "enc_qei_lane_w.vh"
`endif

module enc_qei_engine_formal #(
    parameter integer CHANNELS = 2,   // the engine's channels
    parameter integer COUNT_W  = 16,  // the count's width
    parameter integer TS_W     = 16   // the timebase's width
) (
    input wire                clk,
    input wire                rst,
    input wire                req_valid,
    input wire                req_write,
    input wire [3:0]          req_ch,
    input wire [5:0]          req_word,
    input wire [31:0]         req_wdata,
    input wire [3:0]          req_wstrb,
    input wire [CHANNELS-1:0] a_in,
    input wire [CHANNELS-1:0] b_in,
    input wire [CHANNELS-1:0] z_in,
    input wire [CHANNELS-1:0] probe_in,
    input wire                snap_in,
    input wire [TS_W-1:0]     timebase,
    input wire                tick,
    input wire                gsnap_req
);

  localparam integer CH_EFF = (CHANNELS < 2) ? 2 : CHANNELS;
  localparam integer V      = 24;
  localparam integer P      = V * CH_EFF;
  localparam integer AW     = 9;  // the state memory's address bits (enc_qei_engine: CH_W + 5)
  `include "enc_qei_regs.vh"

  wire                resp_valid, gsnap;
  wire [31:0]         resp_rdata;
  wire [CHANNELS-1:0] irq_pend, cmp_out;
  wire [CHANNELS-1:0] step_up, step_dn, idx_hit;  // (for edge FIFOs: none here, EFIFO 0)
  wire [2*CHANNELS-1:0] step_ab;

  enc_qei_engine #(
      .CHANNELS(CHANNELS),
      .COUNT_W (COUNT_W),
      .TS_W    (TS_W),
      .TIMING  (1),
      .RANGE   (1),
      .PROBE   (1),
      .PERIOD  (1)
  ) eng (
      .clk       (clk),
      .rst       (rst),
      .req_valid (req_valid),
      .req_write (req_write),
      .req_ch    (req_ch),
      .req_word  (req_word),
      .req_wdata (req_wdata),
      .req_wstrb (req_wstrb),
      .resp_valid(resp_valid),
      .resp_rdata(resp_rdata),
      .a_in      (a_in),
      .b_in      (b_in),
      .z_in      (z_in),
      .probe_in  (probe_in),
      .snap_in   (snap_in),
      .timebase  (timebase),
      .tick      (tick),
      .gsnap_req (gsnap_req),
      .gsnap     (gsnap),
      .irq_pend  (irq_pend),
      .cmp_out   (cmp_out),
      .step_up   (step_up),
      .step_dn   (step_dn),
      .step_ab   (step_ab),
      .idx_hit   (idx_hit),
      .ef_thresh ({CHANNELS{1'b0}}),
      .ef_ovf    ({CHANNELS{1'b0}})
  );

  // ---- probes, connected by the .sby after flatten ------------------------------------------------
  (* keep *) wire [4:0]          p_slot;      // eng.slot_q
  (* keep *) wire [3:0]          p_cp;        // eng.cp_q: c(v)
  (* keep *) wire [3:0]          p_cn;        // eng.cn_q: c(v + 1)
  (* keep *) wire [3:0]          p_cw;        // eng.cw_q: c(v - 1)
  (* keep *) wire [CHANNELS-1:0] p_rd;        // eng.rd_q
  (* keep *) wire [CHANNELS-1:0] p_cfg_we;    // eng.cfg_we_q
  (* keep *) wire                p_ld;        // eng.ld_q
  (* keep *) wire                p_we;        // eng.we: the state memory's write
  (* keep *) wire [AW-1:0]       p_waddr;     // eng.waddr
  (* keep *) wire [AW-1:0]       p_raddr_a;   // eng.raddr_a
  (* keep *) wire [AW-1:0]       p_raddr_b;   // eng.raddr_b
  (* keep *) wire [2:0]          p_b_st;      // eng.b_st_q
  (* keep *) wire [3:0]          p_b_ch;      // eng.b_ch_q: the request's channel
  (* keep *) wire                p_b_take;    // eng.b_take: the bus takes port b's data now
  (* keep *) wire                p_b_wr;      // eng.b_wr_q: the request is a write
  (* keep *) wire [5:0]          p_b_word;    // eng.b_word_q: ... of this register
  (* keep *) wire [CHANNELS-1:0] p_pend;      // eng.pend_q
  (* keep *) wire [CHANNELS-1:0] p_busy;      // eng.busy_q
  (* keep *) wire [CHANNELS-1:0] p_pend_st;   // eng.pend_st_q
  (* keep *) wire [CHANNELS-1:0] p_pend_set;  // eng.pend_set
  (* keep *) wire [CHANNELS-1:0] p_take;      // eng.take_oh
  (* keep *) wire [CHANNELS-1:0] p_done;      // eng.done_oh
  (* keep *) wire                p_n_taken;   // eng.n_taken: c(v + 1)'s write taken (slot 9)
  (* keep *) wire                p_p_taken;   // eng.p_taken: c(v)'s, taken in the visit before
  (* keep *) wire                p_e_taken;   // eng.e_taken: c(v)'s state write taken (slot 21)
  (* keep *) wire                p_w_taken;   // eng.w_taken_q: c(v - 1)'s write is applied
  (* keep *) wire                p_wr_on;     // eng.wr_on_q: results are written
  (* keep *) wire                p_pend_we;   // eng.pend_we: the write slots' write
  (* keep *) wire [3:0]          p_pend_wch;  // eng.pend_wch
  (* keep *) wire [CHANNELS-1:0] p_spend;     // eng.snap_pend: a lane's capture waits (free)
  (* keep *) wire                p_lsnap0;    // eng.g_lane[0].u_lane.gsnap: lane 0's input
  (* keep *) wire                p_lsnap1;    // eng.g_lane[1].u_lane.gsnap: lane 1's input
  (* keep *) wire                p_lat_valid; // eng.lat_valid_q: COUNT_HI's latch is held (COUNT_W
  (* keep *) wire [3:0]          p_lat_ch;    // eng.lat_ch_q: ... of this channel  > 32 only: w40)

  localparam [2:0] B_IDLE = 3'd0, B_WAIT = 3'd1, B_RD1 = 3'd2, B_RD2 = 3'd3, B_POST = 3'd4,
                   B_DONE = 3'd5;

  // ---- the global snapshot's request, as the engine keeps it -------------------------------------
  (* keep *) wire p_gswait;  // eng.gsnap_wait_q: a request waits for the lanes' captures to be read
  reg f_past_gsreq = 1'b0, f_past_rst = 1'b1, f_past_gsnap = 1'b0;
  always @(posedge clk) begin
    f_past_gsreq <= gsnap_req | p_gswait;
    f_past_rst   <= rst;
    f_past_gsnap <= gsnap;
  end

  // ---- the port's rules ---------------------------------------------------------------------------
  reg f_past = 1'b0;
  reg f_out_q;  // a request is unanswered
  always @(posedge clk) f_past <= 1'b1;

  always @(posedge clk) begin
    if (rst) f_out_q <= 1'b0;
    else if (req_valid) f_out_q <= 1'b1;
    else if (resp_valid) f_out_q <= 1'b0;
  end

  always @(*) begin
    if (!f_past) assume (rst);
    if (req_valid) assume (req_ch < CHANNELS && (!f_out_q || resp_valid));
  end

  // ---- the schedule's reference ---------------------------------------------------------------------
  function [3:0] nxt;  // c + 1 mod CH_EFF
    input [3:0] c;
    begin
      nxt = (c == CH_EFF - 1) ? 4'd0 : c + 4'd1;
    end
  endfunction

  function [3:0] dist;  // (a - b) mod CH_EFF, a and b < CH_EFF
    input [3:0] a;
    input [3:0] b;
    begin
      dist = (a >= b) ? a - b : a + CH_EFF[3:0] - b;
    end
  endfunction

  // per lane: clocks since its last read (or rst), and whether it was read since rst
  reg [7:0]          f_cnt [0:CHANNELS-1];
  reg [CHANNELS-1:0] f_seen;
  reg [CHANNELS-1:0] f_cfg_we1;  // cfg_we the clock before
  reg                f_wclash_b; // a write to the word port b read in that clock
  reg                f_took1;    // the bus took port b's first read
  // per channel: writes posted and not completed (the wrapper's count)
  reg [1:0]          f_owed [0:CHANNELS-1];
  integer            k;

  always @(posedge clk) begin
    f_cfg_we1  <= rst ? {CHANNELS{1'b0}} : p_cfg_we;
    f_wclash_b <= p_we & (p_waddr == p_raddr_b);
    f_took1    <= (p_b_st == B_RD1) & p_b_take;
    for (k = 0; k < CHANNELS; k = k + 1) begin
      if (rst) begin
        f_cnt[k]  <= 8'd0;
        f_seen[k] <= 1'b0;
        f_owed[k] <= 2'd0;
      end else begin
        f_cnt[k]  <= p_rd[k] ? 8'd1 : (f_cnt[k] == 8'hFF) ? f_cnt[k] : f_cnt[k] + 8'd1;
        f_seen[k] <= f_seen[k] | p_rd[k];
        f_owed[k] <= f_owed[k] + {1'b0, p_pend_set[k]} - {1'b0, p_done[k]};
      end
    end
  end

  always @(*) begin
    if (f_past && !rst) begin
      // the visit order
      assert (p_slot < V && p_cp < CH_EFF && p_cn == nxt(p_cp) && nxt(p_cw) == p_cp);
      for (k = 0; k < CHANNELS; k = k + 1) begin
        // the reads: in slot 23 of the visit before the lane's (c(v + 1) = k), every P clocks
        assert (p_rd[k] == (p_slot == V - 1 && p_cn == k));
        assert (f_cnt[k] <= P);
        if (p_rd[k] && f_seen[k]) assert (f_cnt[k] == P);
        if (f_seen[k]) assert (f_cnt[k] == V * dist(p_cn, nxt(k)) + p_slot + 1);
        else assert (f_cnt[k] == V * dist(p_cn, 4'd1) + p_slot && dist(p_cn, 4'd1) <= dist(k, 4'd1));
        // the push: in the clock before each read, or (a COUNT write's value) the one before it
        assert (p_cfg_we[k] == (p_cn == k && (p_slot == V - 2 || (p_slot == V - 3 && p_cfg_we[k]))));
        if (p_slot == V - 2 && p_cn == k) assert (p_ld == f_cfg_we1[k]);
        // a write: waiting or being applied, never both; the count of unapplied writes
        assert (!(p_pend[k] && p_busy[k]));
        assert (f_owed[k] == {1'b0, p_pend[k] | p_busy[k]});
        if (p_pend_set[k]) assert (!p_pend[k] && !p_busy[k]);
        if (p_take[k]) assert (p_pend[k]);
        if (p_done[k]) assert (p_busy[k]);
        // (where a taken write is: taken for c(v + 1) in slot 9, its push; c(v)'s visit, where a
        // state write is taken in slot 21; written back in c(v - 1)'s slots 0 .. 19)
        assert (p_busy[k] == ((p_cw == k && p_wr_on && p_slot <= 5'd19 && p_w_taken) ||
                              (p_cn == k && p_slot >= 5'd10 && p_n_taken) ||
                              (p_cp == k && (p_p_taken || (p_slot >= 5'd22 && p_e_taken)))));
      end
      if (p_slot != V - 2) assert (!p_ld);
      if (p_slot <= 5'd9) assert (p_n_taken == p_p_taken);
      // (one write per channel in flight: c(v - 1) = c(v + 1) with two channels)
      if (p_slot >= 5'd10 && p_slot <= 5'd19 && p_cw == p_cn && p_wr_on) assert (!(p_w_taken && p_n_taken));
      if (p_slot >= 5'd22) assert (!(p_p_taken && p_e_taken));
      // (the bus: a write on its way to its slot found the channel with no write unapplied)
      assert (p_b_st <= B_DONE && (p_b_st == B_IDLE || p_b_ch < CHANNELS));
      if (p_b_st == B_RD1 || p_b_st == B_RD2 || p_b_st == B_POST)
        assert (!(|((p_pend | p_busy) & (1 << p_b_ch))));
      assert (p_pend_set == (f_save1 ? (1 << f_save_ch) :
                             (p_b_st == B_DONE && p_pend_we) ? (1 << p_b_ch) : 0));
      if (p_pend_we) assert (f_save1 ? (p_b_st == B_WAIT && p_pend_wch == f_save_ch) :
                                       (p_b_st == B_DONE && p_pend_wch == p_b_ch));
      // COUNT_W > 32, COUNT_HI's latch (task prove_w40): the store a COUNT_LO read of another
      // channel makes is one post, into a channel with no write in flight; it clears the latch
      if (f_save1) assert (p_pend_we && COUNT_W > 32 && !p_lat_valid && f_save_ch != p_b_ch);
      if (COUNT_W > 32 && p_lat_valid)
        assert (p_lat_ch < CHANNELS && !(f_wsave[p_lat_ch] && (p_pend[p_lat_ch] || p_busy[p_lat_ch])));
      if (f_lw_v && !f_after[f_lw]) assert (f_lw < CHANNELS && f_wage[f_lw] == f_lwage);
      // (the last request: a write, posted once; a read that stored a latch, posted once)
      if (f_pw && !f_out_q) assert (f_cur[f_pch]);
      if (f_pw) assert (f_pch < CHANNELS &&
                        f_cur == ((p_b_st == B_IDLE) ? (1 << f_pch) : {CHANNELS{1'b0}}));
      if (!f_pw) assert (f_cur == (f_psv ? (1 << f_psv_ch) : {CHANNELS{1'b0}}));
      if (f_out_q && p_b_st != B_IDLE) assert (p_b_wr == f_pw && p_b_ch == f_pch);
      if (f_pw && f_cur[f_pch]) assert (f_lw_v && f_lw == f_pch && !f_after[f_pch] && !f_psv);
      if (f_psv) assert (!f_pw && f_cur[f_psv_ch] && f_wsave[f_psv_ch] && f_after[f_psv_ch] &&
                         f_psv_ch < CHANNELS);
      assert ((f_after & ~f_wsave) == {CHANNELS{1'b0}});
      // (a COUNT_LO read holds its channel's latch from its take on)
      if (COUNT_W > 32 && !p_b_wr && p_b_word == OFF_CNT_LO &&
          (p_b_st == B_DONE || (p_b_st == B_RD2 && f_took1) || (p_b_st == B_IDLE && f_out_q)))
        assert (p_lat_valid && p_lat_ch == p_b_ch);
      if (f_psv) assert (!p_b_wr && p_b_word == OFF_CNT_LO && p_b_ch == f_pch);
      if (f_psv && !f_out_q) assert (p_lat_valid && p_lat_ch == f_pch && f_pch != f_psv_ch &&
                                     !(p_pend[f_pch] || p_busy[f_pch]));
      if (COUNT_W > 32 && f_rdw && f_rdw_sv && p_lat_valid && p_lat_ch != f_rdw_ch)
        assert (!(p_pend[p_lat_ch] || p_busy[p_lat_ch]));
      // (the store's age: 3 at least at the answer to the read that made it, which is of another
      // channel)
      if (f_psv && f_out_q)
        assert (f_psv_ch != p_b_ch && {1'b0, f_wage[f_psv_ch]} + {1'b0, f_rem} >= 9'd3);
      if (f_psv && !f_out_q) assert ({1'b0, f_wage[f_psv_ch]} >= {1'b0, f_ka} + 9'd3);
      // (COUNT_W <= 32: no latch, nothing stored; p_lat_valid and p_lat_ch are not connected)
      if (COUNT_W <= 32)
        assert (!f_save1 && !f_psv && !f_rdw_sv && !f_lwt && f_wsave == 0 && f_after == 0);
      // the order of the writes in flight: one posted before the last bus write's post is older
      // than it by 4 clocks at least (requests come one at a time); during a request, every write
      // in flight posted before it is older than the request
      for (k = 0; k < CHANNELS; k = k + 1) begin
        if (f_lw_v && k != f_lw && (p_pend[k] || p_busy[k]) && !f_after[k])
          assert ({1'b0, f_wage[k]} >= {1'b0, f_lwage} + 9'd4);
        if (f_out_q && (p_pend[k] || p_busy[k]) && !f_cur[k])
          assert (f_wage[k] >= {5'd0, f_rq_age} + 8'd1);
        if (f_wsave[k] && (p_pend[k] || p_busy[k])) assert (p_pend_st[k] && !f_nowait[k]);
      end
      // port a: a read whose data is used (slots 1 .. 22) is not of the word written in its clock
      if (p_slot >= 1 && p_slot <= V - 2) assert (!(p_we && p_waddr == p_raddr_a));
      // port b: the data the bus takes (B_RD1's, or B_RD2's after a clash) was not read in a
      // write's clock to that word; it takes one of its two reads, exactly one
      if (p_b_take) assert (!f_wclash_b && (p_b_st == B_RD1 || p_b_st == B_RD2));
      if (p_b_st == B_RD2) assert (p_b_take != f_took1);
      // the write slots: a taken write's word is not written in the clock it is read
      if (p_slot == 5'd9 && (|(p_pend & ~p_pend_st & (1 << p_cn))))
        assert (!(p_pend_we && p_pend_wch == p_cn));
      if (p_slot == 5'd21 && (|(p_pend & p_pend_st & (1 << p_cp))))
        assert (!(p_pend_we && p_pend_wch == p_cp));
      // the global snapshot (zero skew, with the lane's half in formal/enc_qei_lane.sby): every
      // lane sees gsnap in the clock the engine raises it, and the engine raises it only while
      // no lane has a capture waiting that is not read in this clock (what the lane proof
      // assumes); a request is not lost: it is taken, or waits
      assert (p_lsnap0 == gsnap && p_lsnap1 == gsnap);
      if (gsnap) assert ((p_spend & ~p_rd) == {CHANNELS{1'b0}});
      if (f_past_gsreq && !f_past_rst && !f_past_gsnap) assert (gsnap || p_gswait);
    end
  end

  // ---- when a write acts (CAPS.ENGINE shared, (2)): the bounds of the RDL, in clocks -------------
  // A write of channel k is posted by the bus in the clock before its answer (pend_set) and acts:
  // a write of a register the counting uses at the lane's read after the engine takes it (a
  // COUNT_LO write in the clock before that read, where it loads the count); a state write
  // (EVENTS, QERR_COUNT, GLITCH_COUNT, IRQ_EN) when its word is written back (done). The RDL's
  // words: at most P + 14 (state: P + 22) clocks after the answer, and P + 18 (P + 26) after the
  // request when it did not wait for an earlier write of the channel (its B_WAIT one clock).
  // The wrapper counts the clocks from the answer (f_wage) and keeps the answer's delay after
  // the request (f_wrq, 7: more) and whether it waited; its invariants place the write in the
  // schedule (where its take and act come).
  localparam [5:0] OFF_CNT_LO = ENC_QEI_COUNT_LO[7:2];
  reg  [7:0]          f_wage [0:CHANNELS-1];
  reg  [2:0]          f_wrq  [0:CHANNELS-1];
  reg  [CHANNELS-1:0] f_wlive;    // a posted write that has not acted yet
  reg  [CHANNELS-1:0] f_wcnt;     // ... a COUNT_LO write
  reg  [CHANNELS-1:0] f_nowait;   // ... that did not wait
  reg  [2:0]          f_rq_age;   // clocks since the bus's request, less 1 (7: more)
  reg  [1:0]          f_wc;       // ... its clocks in B_WAIT so far (2: more than one)
  reg  [CHANNELS-1:0] f_act;      // the write acts in this clock (combinational)
  // a read requested while a write of its channel is not stored yet: it waits for it (the
  // bounds: below)
  reg                 f_rdw;      // such a read is in flight
  reg  [3:0]          f_rdw_ch;   // ... of this channel
  reg                 f_rdw_sv;   // ... right after a COUNT_LO read that stored its channel's latch
  wire [7:0]          f_rem;      // clocks from now to the bus's answer, by its state, at most
  // a write requested while a write of its channel is not stored yet (COUNT_W <= 32; the bounds:
  // below)
  reg                 f_wdw;      // such a write is in flight
  reg  [3:0]          f_wdw_ch;   // ... of this channel
  reg                 f_wdw_pt;   // ... a COUNT_LO write with some but not all byte lanes
  reg  [7:0]          f_wdw_age;  // clocks since the answer of the channel's write it waits for
  reg                 f_wdw_st;   // ... that write is a state write
  reg                 f_wdw_nw;   // ... it did not wait
  reg  [2:0]          f_wdw_rq;   // ... its answer's delay after its request
  wire [7:0]          f_wrem;     // clocks from now to the write's answer, by the bus's state
  (* keep *) wire [3:0] p_b_wstrb;  // eng.b_wstrb_q: the bus request's byte enables
  reg                 f_lwt;      // COUNT_W > 32: the read waited for the write of the channel
  reg  [3:0]          f_lwt_ch;   // ... whose latch it stores
  reg  [7:0]          f_lwt_age;  // ... that write's clocks since its answer
  reg  [7:0]          f_stake [0:CHANNELS-1];  // a taken write's clocks since its take

  // clocks from now to the next clock with slot s and channel field (c(v + 1) or c(v)) k
  function [7:0] until;
    input [3:0] k;
    input [4:0] s;
    input [3:0] cur;
    input [4:0] slot;
    begin
      if (cur == k && slot <= s) until = {3'd0, s - slot};
      else until = V * ((cur == k) ? CH_EFF : dist(k, cur)) + s - slot;
    end
  endfunction

  always @(*) begin
    for (k = 0; k < CHANNELS; k = k + 1) begin
      f_act[k] = f_wlive[k] && (p_pend_st[k] ? p_done[k] :
                                p_busy[k] && p_cn == k && p_slot == (f_wcnt[k] ? 5'd22 : 5'd23));
    end
  end

  always @(*) begin
    for (k = 0; k < CHANNELS; k = k + 1) begin
      // a taken write's clocks since its take, from where it is (slot 9 of c(v + 1) = k; a state
      // write's slot 21 of c(v) = k; the write-back in c(v - 1) = k's slots 0 .. 19)
      if (!p_pend_st[k])
        f_stake[k] = (p_cn == k && p_n_taken && p_slot >= 5'd10) ? {3'd0, p_slot} - 8'd9 :
                     (p_cp == k && p_p_taken) ? 8'd15 + p_slot : 8'd39 + p_slot;
      else
        f_stake[k] = (p_cp == k && p_slot >= 5'd22) ? {3'd0, p_slot} - 8'd21 : 8'd3 + p_slot;
    end
  end

  // COUNT_W > 32: a COUNT_LO read of another channel than the latch's stores the latch (posts a
  // state write into that channel's slot, in B_WAIT, once that channel has no write unstored)
  wire                f_save_now = (COUNT_W > 32) && p_b_st == B_WAIT && !p_b_wr &&
                                   p_b_word == OFF_CNT_LO && p_lat_valid && p_lat_ch != p_b_ch;
  wire                f_save_go  = f_save_now && !(|((p_pend | p_busy) & (1 << p_lat_ch)));
  assign f_rem = (p_b_st == B_WAIT) ? (f_save_now ? 8'd6 : 8'd5) : (p_b_st == B_RD1) ? 8'd4 :
                 (p_b_st == B_RD2) ? 8'd3 : (p_b_st == B_DONE) ? 8'd2 : 8'd1;
  reg                 f_save1;    // the latch was stored in the clock before (its post: now)
  reg  [3:0]          f_save_ch;  // ... of this channel
  reg  [CHANNELS-1:0] f_wsave;    // the channel's write in flight is such a store
  reg  [CHANNELS-1:0] f_after;    // ... was posted after the last bus write's post
  reg  [CHANNELS-1:0] f_cur;      // ... was posted during the request under way (or the last)
  reg                 f_lw_v;     // a bus write was posted (since rst) ...
  reg  [3:0]          f_lw;       // ... the last one of this channel
  reg  [7:0]          f_lwage;    // ... its clocks since its answer (as f_wage)
  reg                 f_pw;       // the last request was a write (of f_pch)
  reg  [3:0]          f_pch;
  reg                 f_psv;      // a latch was stored during the last request (f_psv_ch's)
  reg  [3:0]          f_psv_ch;
  reg  [7:0]          f_ka;       // clocks since the last answer (to 252: a store's age less 3)

  always @(posedge clk) begin
    if (rst) begin
      f_save1 <= 1'b0;
      f_lw_v  <= 1'b0;
      f_pw    <= 1'b0;
      f_psv   <= 1'b0;
    end else begin
      f_save1   <= f_save_go;
      f_save_ch <= p_lat_ch;
      f_ka      <= resp_valid ? 8'd0 : (f_ka >= 8'd252) ? 8'd252 : f_ka + 8'd1;
      if (req_valid) begin
        f_pw  <= req_write;
        f_pch <= req_ch;
        f_psv <= 1'b0;
      end else if (f_save1) begin
        f_psv    <= 1'b1;
        f_psv_ch <= f_save_ch;
      end
      if (|p_pend_set && !f_save1) begin
        f_lw_v  <= 1'b1;
        f_lw    <= p_b_ch;
        f_lwage <= 8'd0;
      end else begin
        f_lwage <= (f_lwage == 8'hFF) ? f_lwage : f_lwage + 8'd1;
      end
    end
    for (k = 0; k < CHANNELS; k = k + 1) begin
      if (rst || req_valid) f_cur[k] <= 1'b0;
      else if (p_pend_set[k]) f_cur[k] <= 1'b1;
      if (rst) begin
        f_wsave[k] <= 1'b0;
        f_after[k] <= 1'b0;
      end else if (p_pend_set[k]) begin
        f_wsave[k] <= f_save1;
        f_after[k] <= f_save1;
      end else if (|p_pend_set && !f_save1) begin
        f_after[k] <= 1'b0;
      end
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      f_rdw    <= 1'b0;
      f_rdw_sv <= 1'b0;
      f_lwt    <= 1'b0;
    end else if (req_valid) begin
      // (COUNT_W > 32: a read right after a write of its channel, or right after a COUNT_LO read
      // that stored its channel's latch, as the RDL states them; with COUNT_W <= 32 any read
      // that finds a write of its channel unstored)
      f_rdw    <= !req_write && (f_owed[req_ch] != 2'd0) &&
                  (COUNT_W <= 32 || (f_pw && f_pch == req_ch) || (f_psv && f_psv_ch == req_ch));
      f_rdw_sv <= COUNT_W > 32 && !(f_pw && f_pch == req_ch) && f_psv && f_psv_ch == req_ch;
      f_rdw_ch <= req_ch;
      f_lwt    <= 1'b0;
    end else begin
      if (resp_valid) f_rdw <= 1'b0;
      if (f_save_now && (|((p_pend | p_busy) & (1 << p_lat_ch)))) begin
        f_lwt     <= 1'b1;
        f_lwt_ch  <= p_lat_ch;
        f_lwt_age <= f_wage[p_lat_ch] + 8'd1;
      end else begin
        f_lwt_age <= (f_lwt_age == 8'hFF) ? f_lwt_age : f_lwt_age + 8'd1;
      end
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      f_wdw <= 1'b0;
    end else if (req_valid) begin
      f_wdw     <= COUNT_W <= 32 && req_write && (f_owed[req_ch] != 2'd0);
      f_wdw_ch  <= req_ch;
      f_wdw_pt  <= req_word == OFF_CNT_LO && (|req_wstrb) && !(&req_wstrb);
      f_wdw_age <= (f_wage[req_ch] == 8'hFF) ? 8'hFF : f_wage[req_ch] + 8'd1;
      f_wdw_st  <= p_pend_st[req_ch];
      f_wdw_nw  <= f_nowait[req_ch];
      f_wdw_rq  <= f_wrq[req_ch];
    end else begin
      if (resp_valid) f_wdw <= 1'b0;
      f_wdw_age <= (f_wdw_age == 8'hFF) ? f_wdw_age : f_wdw_age + 8'd1;
    end
  end
  // (a write goes B_WAIT, B_POST, B_DONE; one that reads the count first B_WAIT, B_RD1, B_RD2,
  // B_POST, B_DONE)
  assign f_wrem = (p_b_st == B_WAIT) ? (f_wdw_pt ? 8'd6 : 8'd4) : (p_b_st == B_RD1) ? 8'd5 :
                  (p_b_st == B_RD2) ? 8'd4 : (p_b_st == B_POST) ? 8'd3 :
                  (p_b_st == B_DONE) ? 8'd2 : 8'd1;

  always @(posedge clk) begin
    if (rst) begin
      f_rq_age <= 3'd7;
      f_wc     <= 2'd0;
    end else if (req_valid) begin
      f_rq_age <= 3'd0;
      f_wc     <= 2'd0;
    end else begin
      f_rq_age <= (f_rq_age == 3'd7) ? f_rq_age : f_rq_age + 3'd1;
      if (p_b_st == B_WAIT) f_wc <= (f_wc == 2'd2) ? f_wc : f_wc + 2'd1;
    end
    for (k = 0; k < CHANNELS; k = k + 1) begin
      if (rst) begin
        f_wlive[k]  <= 1'b0;
        f_wage[k]   <= 8'd0;
        f_wrq[k]    <= 3'd7;
        f_wcnt[k]   <= 1'b0;
        f_nowait[k] <= 1'b0;
      end else if (p_pend_set[k]) begin
        f_wlive[k]  <= 1'b1;
        f_wage[k]   <= 8'd0;
        f_wrq[k]    <= (f_save1 || f_rq_age >= 3'd5) ? 3'd7 : f_rq_age + 3'd2;  // (the answer: a clock on)
        f_wcnt[k]   <= !f_save1 && p_b_wr && p_b_word == OFF_CNT_LO;
        f_nowait[k] <= !f_save1 && f_wc == 2'd1;
      end else begin
        if (f_act[k]) f_wlive[k] <= 1'b0;
        f_wage[k] <= (f_wage[k] == 8'hFF) ? f_wage[k] : f_wage[k] + 8'd1;
      end
    end
  end

  always @(*) begin
    if (f_past && !rst) begin
      // the bus's request: its clocks so far, by state, when it did not wait (B_WAIT one clock;
      // only a COUNT_LO write with some byte lanes off reads before it posts)
      assert (p_b_st == B_IDLE ? (!f_out_q || resp_valid) : f_out_q);
      if (p_b_st == B_WAIT && f_wc == 2'd0) assert (f_rq_age == 3'd0);
      assert (f_wc <= 2'd2 && (f_wc == 2'd0 || f_rq_age >= {1'b0, f_wc}));
      if (p_b_st == B_RD1 || p_b_st == B_RD2 || p_b_st == B_POST || p_b_st == B_DONE)
        assert (f_wc != 2'd0);
      if ((p_b_st == B_RD1 || p_b_st == B_RD2) && p_b_wr) assert (p_b_word == OFF_CNT_LO);
      if (f_wc == 2'd1) begin
        if (p_b_st == B_RD1) assert (f_rq_age == 3'd1);
        if (p_b_st == B_RD2) assert (f_rq_age == 3'd2);
        if (p_b_st == B_POST) assert (f_rq_age == 3'd1 || (f_rq_age == 3'd3 && p_b_word == OFF_CNT_LO));
        if (p_b_st == B_DONE && p_b_wr) assert (f_rq_age == 3'd2 || (f_rq_age == 3'd4 && p_b_word == OFF_CNT_LO));
      end
      for (k = 0; k < CHANNELS; k = k + 1) begin
        // a write is stored (neither waiting nor being applied) by P + 57 clocks after its answer
        // at the latest (a state write: P + 21), so an access of the channel requested P + 57
        // clocks or more after that answer (P + 21), whose B_WAIT is a clock later, does not
        // wait for it (the RDL)
        if ((p_pend[k] || p_busy[k]) && !f_wsave[k])
          assert (f_wage[k] <= (p_pend_st[k] ? P + 21 : P + 57));
        if (f_wlive[k]) begin
          // the RDL's bounds
          assert (f_wage[k] <= (p_pend_st[k] ? P + 22 : P + 14));
          if (f_act[k] && f_nowait[k])
            assert ({5'd0, f_wrq[k]} + f_wage[k] <= (p_pend_st[k] ? P + 26 : P + 18));
          // where the write is: waiting for its take (slot 9 of the visit before the lane's read,
          // a state write's slot 21 of the channel's visit), taken and waiting to act; a write
          // that did not wait was answered 4 clocks after its request (a COUNT_LO write with some
          // byte lanes off: 6, after it read the count)
          assert (p_pend[k] || p_busy[k]);
          if (!p_pend_st[k]) begin
            if (p_pend[k]) assert (f_wage[k] + until(k, 5'd9, p_cn, p_slot) <= P - 1);
            // (taken in slot 9, acts in slot 23 or 22 of that visit; its age: below)
            if (p_busy[k]) assert (p_cn == k && p_n_taken && p_slot >= 5'd10 &&
                                   p_slot <= (f_wcnt[k] ? 5'd22 : 5'd23));
          end else begin
            if (p_pend[k]) assert (f_wage[k] + until(k, 5'd21, p_cp, p_slot) <= P - 1);
            // (taken in slot 21, written back by slot 19 of the visit after; its age: below)
            if (p_busy[k]) assert ((p_cp == k && p_e_taken && p_slot >= 5'd22) ||
                                   (p_wr_on && p_cw == k && p_w_taken && p_slot <= 5'd19));
          end
        end else begin
          assert (!p_pend[k] && (!p_busy[k] || !p_pend_st[k]));
        end
        // the channel's last write: answered 4 clocks after its request when it did not wait (a
        // COUNT_LO write with some byte lanes off: 6)
        if (f_nowait[k]) assert (f_wrq[k] == 3'd4 || (f_wrq[k] == 3'd6 && f_wcnt[k]));
        if (f_wcnt[k]) assert (!p_pend_st[k]);
        // a taken write (acted or not): taken at most P - 1 clocks after its answer, stored by
        // its write-back (58 clocks after the take; a state write 22)
        if (p_busy[k]) begin
          assert (f_wage[k] <= P - 1 + f_stake[k]);
          assert (f_stake[k] <= (p_pend_st[k] ? 8'd22 : 8'd58));
          if (p_done[k]) assert (f_stake[k] == (p_pend_st[k] ? 8'd22 : 8'd58));
        end
        if (p_pend[k]) assert (f_wage[k] <= P - 1);
      end
      // a read that waited for a write of its channel: answered 5 clocks after the write is
      // stored at the latest (B_WAIT, B_RD1, B_RD2, B_DONE); by the RDL, P + 62 clocks after the
      // write's answer (a state write: P + 26), and when that write did not wait itself P + 66
      // after its request (a state write: P + 30; a COUNT_LO write with some byte lanes off, which
      // is answered 6 clocks after its request: P + 68)
      if (f_rdw) begin
        assert (f_rdw_ch < CHANNELS && (p_b_st == B_IDLE ? resp_valid :
                                         (p_b_ch == f_rdw_ch && !p_b_wr && p_b_st != B_POST)));
        if (p_b_st != B_WAIT) assert (!(|((p_pend | p_busy) & (1 << f_rdw_ch))));
        assert (f_wage[f_rdw_ch] <= P + 58 + {5'd0, f_rq_age} || f_lwt);
        if (f_lwt) assert (f_lwt_age <= 8'd230);
        // (the clocks to its answer, by state; a COUNT_LO read that still stores a latch: one
        // more. With COUNT_W > 32 it may come as the write is stored and take its own clocks, 6
        // with a latch to store: one more than the bounds below)
        if (!(|((p_pend | p_busy) & (1 << f_rdw_ch))) &&
            !(f_save_now && (|((p_pend | p_busy) & (1 << p_lat_ch)))))
          assert ((f_wage[f_rdw_ch] + f_rem <= (p_pend_st[f_rdw_ch] ? P + 27 : P + 63)) ||
                  (COUNT_W > 32 && {5'd0, f_rq_age} + f_rem <= 8'd6) ||
                  (f_lwt && !f_rdw_sv && f_lwt_age + f_rem <= P + 64));
        // (waiting for the write of the channel whose latch it stores: that write is older, and
        // the read is answered within P + 63 of its answer)
        if (f_lwt) assert (!f_rdw_sv && f_lwt_ch != f_rdw_ch && f_lwt_ch < CHANNELS &&
                           {1'b0, f_lwt_age} >= {1'b0, f_wage[f_rdw_ch]} + 9'd4 &&
                           {1'b0, f_lwt_age} <= {1'b0, f_wage[f_rdw_ch]} + P + 58 &&
                           !p_b_wr && p_b_word == OFF_CNT_LO);
        if (COUNT_W > 32 && f_lwt && !f_save_now &&
            (p_b_st == B_WAIT || p_b_st == B_RD1 || (p_b_st == B_RD2 && !f_took1)))
          assert (!p_lat_valid);
        if (f_lwt) assert (f_rq_age >= 3'd1 && (p_b_st == B_WAIT || (f_wc == 2'd2 && f_rq_age >= 3'd3)));
        if (f_lwt && (|((p_pend | p_busy) & (1 << f_lwt_ch))) && !(f_wsave[f_lwt_ch] && f_cur[f_lwt_ch]))
          assert (p_b_st == B_WAIT && f_save_now && p_lat_ch == f_lwt_ch &&
                  f_wage[f_lwt_ch] == f_lwt_age);
        if (f_rdw_sv) assert ({1'b0, f_wage[f_rdw_ch]} >= {1'b0, f_ka} + 9'd3 &&
                              f_wage[f_rdw_ch] <= P + 22 + {5'd0, f_rq_age});
        assert (p_b_st == B_RD1 ? f_rq_age >= 3'd1 : p_b_st == B_RD2 ? f_rq_age >= 3'd2 :
                p_b_st == B_DONE ? f_rq_age >= 3'd3 : 1'b1);
        // (COUNT_W > 32: it may store another channel's latch first, waiting for that channel's
        // write, which is older: the read came right after its own channel's write)
        if (f_save_now && (|((p_pend | p_busy) & (1 << p_lat_ch))))
          assert (!f_rdw_sv && f_lw_v && f_lw == f_rdw_ch && !f_after[p_lat_ch] &&
                  !f_after[f_rdw_ch]);
        if (f_rdw_sv) assert (f_wsave[f_rdw_ch] && p_pend_st[f_rdw_ch]);
      end
      // (after a store of its channel's latch: at most P + 23 clocks after the answer to the
      // COUNT_LO read that stored it, or 6 after its own request)
      if (f_rdw && f_rdw_sv && resp_valid) assert (f_ka <= P + 23 || f_rq_age <= 3'd5);
      if (f_rdw && !f_rdw_sv && resp_valid && !(COUNT_W > 32 && f_rq_age <= 3'd5)) begin
        assert (f_wage[f_rdw_ch] <= (p_pend_st[f_rdw_ch] ? P + 26 : P + 62) ||
                (f_lwt && f_lwt_age <= P + 63));
        if (f_nowait[f_rdw_ch])
          assert ({5'd0, f_wrq[f_rdw_ch]} + f_wage[f_rdw_ch] <=
                  (p_pend_st[f_rdw_ch] ? P + 30 : (f_wrq[f_rdw_ch] == 3'd6) ? P + 68 : P + 66) ||
                  (f_lwt && f_lwt_age <= P + 63));
      end
      // a write that waited for a write of its channel: as a read, one clock sooner (B_WAIT,
      // B_POST, B_DONE), or one later when it reads the count first; by the RDL, P + 61 clocks
      // after the earlier write's answer (a state write: P + 25), and when that write did not
      // wait itself P + 65 after its request (a state write: P + 29; after a COUNT_LO write with
      // some byte lanes off: P + 67); each 2 more for a COUNT_LO write with some byte lanes off
      if (f_wdw) begin
        assert (f_wdw_ch < CHANNELS && (p_b_st == B_IDLE ? resp_valid :
                                        (p_b_ch == f_wdw_ch && p_b_wr)));
        if (p_b_st == B_WAIT || p_b_st == B_RD1 || p_b_st == B_RD2)
          assert (f_wdw_age == f_wage[f_wdw_ch] && f_wdw_st == p_pend_st[f_wdw_ch] &&
                  f_wdw_nw == f_nowait[f_wdw_ch] && f_wdw_rq == f_wrq[f_wdw_ch]);
        if (p_b_st == B_RD1 || p_b_st == B_RD2 || p_b_st == B_POST)
          assert (!(|((p_pend | p_busy) & (1 << f_wdw_ch))));
        assert (f_wdw_pt == (p_b_word == OFF_CNT_LO && (|p_b_wstrb) && !(&p_b_wstrb)));
        if (p_b_st == B_RD1 || p_b_st == B_RD2) assert (f_wdw_pt);
        assert (f_wdw_age <= P + 58 + {5'd0, f_rq_age});
        if (!(p_b_st == B_WAIT && (|((p_pend | p_busy) & (1 << f_wdw_ch)))))
          assert (f_wdw_age + f_wrem <= (f_wdw_st ? P + 26 : P + 62) + (f_wdw_pt ? 8'd2 : 8'd0));
      end
      if (f_wdw && resp_valid) begin
        assert (f_wdw_age <= (f_wdw_st ? P + 25 : P + 61) + (f_wdw_pt ? 8'd2 : 8'd0));
        if (f_wdw_nw)
          assert ({5'd0, f_wdw_rq} + f_wdw_age <=
                  (f_wdw_st ? P + 29 : (f_wdw_rq == 3'd6) ? P + 67 : P + 65) +
                  (f_wdw_pt ? 8'd2 : 8'd0));
      end
    end
  end

`ifdef ENGINE_DATA
  // ---- the data path of the count, its latches, PRESET, CEILING and the snapshot (the data tasks)
  // For one channel f (any, fixed; the bus reads and writes any register of f),
  // with the lanes' records free: at each visit of f the engine rebuilds, from the record of f's
  // read and the count it stored before (lane_rebuild of rtl/enc_qei_lane.vh, with PRESET and
  // CEILING as stored at the visit, and for the anchor A_LOAD the value of a COUNT_LO write taken
  // at the push before the read; formal/enc_qei_lane_count.sby proves that this gives the true
  // count, and the count at a latch's edge), the count, and the index latch, snapshot count and
  // probe latch the record holds (pending: LPEND, SPEND, PPEND). In f's write-back (the visit
  // after, c(v - 1) = f) it writes the count in slot 0 (only then), PRESET in slot 4 and CEILING
  // in slot 5 (only then: the write the visit took, its bytes in its half, the rest as stored, a
  // fresh channel's word the reset value with the write's bytes), SNAP_COUNT in slot 12,
  // INDEX_LATCH in slot 15 and PROBE_LATCH in slot 16, each when its capture is pending (or f's
  // first write-back: reset values for those without one), and otherwise leaves the word; the
  // state memory keeps them; a bus read of COUNT_LO, SNAP_COUNT_LO, INDEX_LATCH_LO,
  // PROBE_LATCH_LO, PRESET_LO or CEILING_LO answers the word as stored in the clock of its port-b
  // read (the reset value until f's first write-back is complete). A COUNT_LO write carries its
  // bytes and, in those it leaves, COUNT_LO as read when it was written; a PRESET or CEILING write
  // (either half) carries its data and byte enables as written; no other write of f reaches
  // these words. The _HI halves' reads answer bits 63:32 of the words. COUNT_HI: a write of f
  // (a state write) is taken at f's visit and written by f's write-back in slot 8 into the
  // stage (W_HI[63:32]), its bytes merged; a COUNT_LO write loads {stage at the visit, value};
  // with COUNT_W > 32 the engine's latch, while it is f's, holds the high word of f's count at
  // f's last COUNT_LO read; a COUNT_LO read of another channel stores it into f's slot (a state
  // write, offset 0x3F), f's visit takes it and f's write-back writes it into W_HI[31:0] in slot
  // 8, and COUNT_HI of f answers that word from then on.
  // The snapshot's other words, the same way: from the record of f's read (its motion, last edge
  // and snapshot fields) with the timebase in the read's clock and the motion, last edge and last
  // snapshot as stored at the visit (W_MOT, W_EDGE, W_SBASE), through rtl/enc_qei_lane.vh's
  // lane_sdiff and lane_tstamp (formal/enc_qei_lane.sby proves them the motion and time of the
  // capture's clock), the write-back writes W_MOT, W_EDGE and W_SBASE whole in slots 9, 10, 11,
  // and SNAP_TIME / SNAP_EDGE_TIME (slot 13) and SNAP_DELTA / SNAP_EDGE_DELTA (slot 14) when the
  // snapshot is pending (or f's first write-back); the memory keeps them; a bus read of the four
  // registers answers its half of the word as stored.
  localparam integer MOT_W = `ENC_QEI_ENGINE_MOT_W(CHANNELS);
  localparam integer TIM_W = `ENC_QEI_ENGINE_TIM_W(CHANNELS);
  localparam integer ERR_W = `ENC_QEI_ENGINE_ERR_W(CHANNELS);
  `include "enc_qei_lane.vh"
  localparam [63:0] SZ       = (64'd1 << COUNT_W) - 64'd1;
  localparam [63:0] PRE_RST  = {ENC_QEI_PRESET_HI_RESET, ENC_QEI_PRESET_LO_RESET} & SZ;
  localparam [63:0] CEIL_RST = {ENC_QEI_CEILING_HI_RESET, ENC_QEI_CEILING_LO_RESET} & SZ;
  localparam [4:0]  W_CNT = 5'd0, W_PRESET = 5'd4, W_CEIL = 5'd5, W_SCNT = 5'd13, W_ILATCH = 5'd16,
                    W_PLATCH = 5'd17;
  localparam [4:0]  S_SCNT = 5'd12, S_ILATCH = 5'd15, S_PLATCH = 5'd16;  // their write slots
  // the snapshot's words and the words they are made from: the motion (W_MOT), the last edge
  // (W_EDGE), the motion and edge at the last snapshot (W_SBASE), SNAP_TIME / SNAP_EDGE_TIME
  // (W_STIME), SNAP_DELTA / SNAP_EDGE_DELTA (W_SDELTA), and their write slots
  localparam [4:0]  W_MOT = 5'd9, W_EDGE = 5'd11, W_SBASE = 5'd12, W_STIME = 5'd14,
                    W_SDELTA = 5'd15;
  localparam [4:0]  W_HI = 5'd8;  // COUNT_HI's latch [31:0] and stage [63:32] (see below)
  localparam [4:0]  S_MOT = 5'd9, S_EDGE = 5'd10, S_SBASE = 5'd11, S_STIME = 5'd13, S_SDELTA = 5'd14;
  localparam [31:0] SZ_T = (TS_W >= 32) ? 32'hFFFFFFFF : ((32'd1 << TS_W) - 32'd1);
  localparam integer NPEEK = 12;  // enc_qei_ram's F_PEEK
  localparam [5:0]  OFF_CNT = ENC_QEI_COUNT_LO[7:2], OFF_SCNT = ENC_QEI_SNAP_COUNT_LO[7:2],
                    OFF_ILAT = ENC_QEI_INDEX_LATCH_LO[7:2], OFF_PLAT = ENC_QEI_PROBE_LATCH_LO[7:2],
                    OFF_PRE = ENC_QEI_PRESET_LO[7:2], OFF_PRE_HI = ENC_QEI_PRESET_HI[7:2],
                    OFF_CEIL = ENC_QEI_CEILING_LO[7:2], OFF_CEIL_HI = ENC_QEI_CEILING_HI[7:2],
                    OFF_STIM = ENC_QEI_SNAP_TIME[7:2], OFF_SETIM = ENC_QEI_SNAP_EDGE_TIME[7:2],
                    OFF_SDEL = ENC_QEI_SNAP_DELTA[7:2], OFF_SEDEL = ENC_QEI_SNAP_EDGE_DELTA[7:2],
                    OFF_SAVE = 6'h3F;  // (no register: a stored COUNT_HI latch, see left_out)
  // the high halves (COUNT_W > 32: bits 63:32 of the word; 0 at COUNT_W <= 32) and COUNT_HI (the
  // high word of the count as COUNT_LO's last read of f took it)
  localparam [5:0]  OFF_CNT_HI = ENC_QEI_COUNT_HI[7:2], OFF_SCNT_HI = ENC_QEI_SNAP_COUNT_HI[7:2],
                    OFF_ILAT_HI = ENC_QEI_INDEX_LATCH_HI[7:2],
                    OFF_PLAT_HI = ENC_QEI_PROBE_LATCH_HI[7:2];

  (* anyconst *) reg [3:0] f_ch;
  wire [AW-1:0] a_cnt = {f_ch, W_CNT}, a_pre = {f_ch, W_PRESET}, a_ceil = {f_ch, W_CEIL};
  wire [AW-1:0] a_scnt = {f_ch, W_SCNT}, a_ilat = {f_ch, W_ILATCH}, a_plat = {f_ch, W_PLATCH};
  wire [AW-1:0] a_mot = {f_ch, W_MOT}, a_edge = {f_ch, W_EDGE}, a_sbase = {f_ch, W_SBASE};
  wire [AW-1:0] a_stim = {f_ch, W_STIME}, a_sdel = {f_ch, W_SDELTA};
  wire [AW-1:0] a_hi = {f_ch, W_HI};

  (* keep *) wire [REC_W-1:0]    p_rec_or;   // eng.rec_or: the record of the lane read now
  (* keep *) wire [REC_W-1:0]    p_rec_q;    // eng.rec_q: c(v)'s
  (* keep *) wire [63:0]         p_o_cnt;    // eng.o_cnt
  (* keep *) wire [63:0]         p_o_pre;    // eng.o_pre
  (* keep *) wire [63:0]         p_o_ceil;   // eng.o_ceil
  (* keep *) wire [63:0]         p_n_cnt;    // eng.n_cnt_q
  (* keep *) wire [63:0]         p_n_scnt;   // eng.n_scnt_q
  (* keep *) wire [63:0]         p_n_ilat;   // eng.n_ilatch_q
  (* keep *) wire [63:0]         p_n_plat;   // eng.n_platch_q
  (* keep *) wire                p_n_snap;   // eng.n_snap_q: SNAP_* are written
  (* keep *) wire                p_n_latch;  // eng.n_latch_q: INDEX_LATCH is
  (* keep *) wire                p_n_probe;  // eng.n_probe_q: PROBE_LATCH is
  (* keep *) wire [63:0]         p_wdata;    // eng.wdata
  (* keep *) wire [63:0]         p_wmask;    // eng.wmask
  (* keep *) wire [CHANNELS-1:0] p_fresh;    // eng.fresh_q
  (* keep *) wire [31:0]         p_b_rdata;  // eng.b_rdata_q
  (* keep *) wire                p_ip_fresh; // eng.ip_fresh_q: c(v - 1) was fresh at its visit
  (* keep *) wire [1:0]          p_ip_pre;   // eng.ip_pre_q: its write's PRESET halves
  (* keep *) wire [1:0]          p_ip_ceil;  // eng.ip_ceil_q: ... CEILING halves
  (* keep *) wire [31:0]         p_ip_data;  // eng.ip_data_q: ... its data
  (* keep *) wire [31:0]         p_ip_lanes; // eng.ip_lanes_q: ... its byte lanes (bit mask)
  (* keep *) wire [NPEEK*64-1:0] p_peek;     // eng.u_mem.f_peek: the words of f_peek_addr
  (* keep *) wire [NPEEK*42-1:0] p_slot_pk;  // eng.u_pend.f_peek: word 0 is f's write slot
  (* keep *) wire [41:0]         p_n_pend;   // eng.n_pend: c(v + 1)'s write, as taken
  (* keep *) wire [41:0]         p_p_pend;   // eng.p_pend: c(v)'s, taken at its push
  (* keep *) wire [41:0]         p_e_pend;   // eng.e_pend: c(v)'s state write
  (* keep *) wire [41:0]         p_pend_wd;  // eng.pend_wdata: the write into a write slot
  (* keep *) wire [31:0]         p_b_wdata;  // eng.b_wdata_q: the bus request's data
  (* keep *) wire [31:0]         p_b_cnt;    // eng.b_cnt_q: COUNT_LO as read for a write
  (* keep *) wire [63:0]         p_o_mot;    // eng.o_mot
  (* keep *) wire [63:0]         p_o_edge;   // eng.o_edge
  (* keep *) wire [63:0]         p_o_sbase;  // eng.o_sbase
  (* keep *) wire [63:0]         p_n_mot;    // eng.n_mot_q
  (* keep *) wire [63:0]         p_n_edge;   // eng.n_edge_q
  (* keep *) wire [63:0]         p_n_sbase;  // eng.n_sbase_q
  (* keep *) wire [63:0]         p_n_stime;  // eng.n_stime_q
  (* keep *) wire [63:0]         p_n_sdel;   // eng.n_sdelta_q
  (* keep *) wire [TS_W-1:0]     p_tv;       // eng.tv_q: the timebase at the read of c(v)
  (* keep *) wire [1:0]          p_ip_hi;    // eng.ip_hi_q: the write-back's COUNT_HI stage, latch
  (* keep *) wire [63:0]         p_n_hi;     // eng.n_hi: c(v + 1)'s W_HI (COUNT_W > 32 only:
  (* keep *) wire [63:0]         p_o_hi;     // eng.o_hi: c(v)'s           task data_w40)
  (* keep *) wire [31:0]         p_lat_q;      // eng.lat_q (COUNT_W > 32 only: task data_w40)
  (* keep *) wire [NPEEK*AW-1:0] f_peek_addr = {a_hi, a_sdel, a_stim, a_sbase, a_edge, a_mot,
                                                a_plat, a_ilat, a_scnt, a_ceil, a_pre, a_cnt};
  (* keep *) wire [NPEEK*4-1:0]  f_slot_addr = {NPEEK{f_ch}};  // -> eng.u_pend.f_peek_addr
  wire [63:0] m_cnt  = p_peek[0 +: 64],   m_pre  = p_peek[64 +: 64],  m_ceil = p_peek[128 +: 64];
  wire [63:0] m_scnt = p_peek[192 +: 64], m_ilat = p_peek[256 +: 64], m_plat = p_peek[320 +: 64];
  wire [63:0] m_mot  = p_peek[384 +: 64], m_edge = p_peek[448 +: 64], m_sbase = p_peek[512 +: 64];
  wire [63:0] m_stim = p_peek[576 +: 64], m_sdel = p_peek[640 +: 64], m_hi = p_peek[704 +: 64];

  // the reference: the record of f's last read (rst: channel 0's first visit takes the reset
  // record, 0); the count stored (f_sto) and the one stored before it (f_base: the count at the
  // read the record continues from); the latched words stored
  reg  [MOT_W-1:0] f_lo, f_scap, f_icap, f_pcap;
  reg  [1:0]       f_anc, f_sanc, f_ianc, f_panc;
  reg              f_spend, f_ipend, f_ppend;
  reg  [63:0]      f_sto, f_base, f_scnt, f_ilat, f_plat;
  reg  [63:0]      f_sto_d, f_scnt_d, f_ilat_d, f_plat_d;
  reg  [31:0]      f_exp;  // what the bus read of f under way answers
  reg              f_lat;   // a COUNT_LO read of f was taken: COUNT_HI answers its high word
  reg  [31:0]      f_latv;  // ... this one
  reg              f_chk;  // ... one is under way, past its take
  reg              f_pk;     // the write in f's slot (or on its way there) reaches a watched word
  reg  [41:0]      f_px;     // ... and the slot holds this ({offset, byte enables, data}: a
                             // COUNT_LO write whole, its bytes and COUNT as then read)
  reg  [31:0]      f_bcnt;   // COUNT_LO as read for a COUNT_LO write of f with some lanes off
  reg              f_lk;     // the read of the record took such a write (at its push)
  reg  [41:0]      f_lx;     // ... this one
  reg              f_hk;     // f's visit took a COUNT_HI write (a state write, slot 21)
  reg  [41:0]      f_hx;     // ... this one
  reg  [31:0]      f_stage;  // COUNT_HI's stage as stored (W_HI[63:32]; f's write-back writes it)
  reg  [31:0]      f_mlat;   // f's COUNT_HI latch as stored (W_HI[31:0]: a store of it writes it)
  reg  [31:0]      f_vmlat;  // ... at f's visit
  reg              f_svf;    // f's latch is being stored (its write: save_w(f_latv)): posted, in
                             // f's slot, or taken by f's visit until its last slot
  reg              f_svt;    // ... taken by f's visit, not yet written by its write-back
  reg  [31:0]      f_vstage; // ... at f's visit (a COUNT_LO write's high word)
  reg  [63:0]      f_pre, f_ceil;    // PRESET and CEILING as stored (f's write-back writes them)
  reg  [63:0]      f_vpre, f_vceil;  // ... at f's visit (the rebuild's)
  reg  [63:0]      f_pre_d, f_ceil_d;
  // the snapshot's words: the record of f's last read (its motion, last edge and snapshot
  // fields, error counts) and the timebase in its clock; the words as stored (f_mot .. f_sdel),
  // and W_MOT, W_EDGE, W_SBASE at f's visit (the rebuild's: f_vmot, f_vedge, f_vsbase)
  reg  [MOT_W-1:0] f_mpos, f_emp, f_smpos, f_semp;
  reg  [TIM_W-1:0] f_et, f_stime, f_set;
  reg  [ERR_W-1:0] f_qcnt, f_gcnt;
  reg              f_xenew, f_xsnew, f_xsedge;  // R_ENEW, R_SNEW, R_SEDGE
  reg  [31:0]      f_tv;
  reg  [63:0]      f_mot, f_edge, f_sbase, f_stim, f_sdel;
  reg  [63:0]      f_mot_d, f_edge_d, f_sbase_d, f_stim_d, f_sdel_d;
  reg  [63:0]      f_vmot, f_vedge, f_vsbase;
  wire             f_ld_ok = f_lk && f_lx[41:36] == OFF_CNT;  // a COUNT_LO write was loaded
  wire [63:0]      f_ldb   = f_ld_ok ? {f_vstage, f_lx[31:0]} & SZ : f_vpre;  // A_LOAD's value
  wire [63:0]      f_new   = lane_rebuild(f_lo, f_anc, f_ldb, f_vceil, f_base, SZ);
  wire [63:0]      f_snew  = f_spend ? lane_rebuild(f_scap, f_sanc, f_vpre, f_vceil, f_base, SZ) : 64'd0;
  wire [63:0]      f_inew  = f_ipend ? lane_rebuild(f_icap, f_ianc, f_vpre, f_vceil, f_base, SZ) : 64'd0;
  wire [63:0]      f_pnew  = f_ppend ? lane_rebuild(f_pcap, f_panc, f_vpre, f_vceil, f_base, SZ) : 64'd0;
  // what the visit makes of them, with the rebuild functions of rtl/enc_qei_lane.vh (whose
  // meaning formal/enc_qei_lane.sby proves: lane_sdiff the motion since the last read,
  // lane_tstamp the time of a capture): the motion M adds the window's; the last edge's time
  // and motion TE / ME when the window has one; at a snapshot SNAP_TIME, SNAP_EDGE_TIME (the
  // snapshot's clock if it was an edge, the window's last edge before it, or the edge before the
  // window), the motion MS and ME then, SNAP_DELTA and SNAP_EDGE_DELTA from the last snapshot's
  wire [MOT_W-1:0] g_mb   = f_vmot[32 +: MOT_W];  // the lane's mpos at the read before
  wire [31:0]      g_m0   = f_vmot[31:0];         // M then
  wire [63:0]      g_dm   = lane_sdiff(f_mpos, g_mb), g_de = lane_sdiff(f_emp, g_mb);
  wire [63:0]      g_dsm  = lane_sdiff(f_smpos, g_mb), g_dse = lane_sdiff(f_semp, g_mb);
  wire [31:0]      g_mr   = g_m0 + g_dm[31:0];
  wire [31:0]      g_ms   = g_m0 + g_dsm[31:0];
  wire [31:0]      g_ts   = lane_tstamp(f_stime, f_tv) & SZ_T;
  wire [31:0]      g_te_s = f_xsedge ? g_ts : f_xsnew ? lane_tstamp(f_set, f_tv) & SZ_T : f_vedge[31:0];
  wire [31:0]      g_me_s = f_xsedge ? g_ms : f_xsnew ? g_m0 + g_dse[31:0] : f_vedge[63:32];
  wire [63:0]      f_mot_new = {{(32 - MOT_W - 2 * ERR_W){1'b0}}, f_gcnt, f_qcnt, f_mpos, g_mr};
  wire [63:0]      f_edge_new = f_xenew ? {g_m0 + g_de[31:0], lane_tstamp(f_et, f_tv) & SZ_T} : f_vedge;
  wire [63:0]      f_sbase_new = f_spend ? {g_me_s, g_ms} : f_vsbase;
  wire [63:0]      f_stim_new = f_spend ? {g_te_s, g_ts} : 64'd0;
  wire [63:0]      f_sdel_new = f_spend ? {g_me_s - f_vsbase[63:32], g_ms - f_vsbase[31:0]} : 64'd0;
  wire             f_fresh = |(p_fresh & (1 << f_ch));
  wire             f_wbv   = p_wr_on && p_cw == f_ch;                    // f's write-back visit
  wire             f_wb    = f_wbv && p_slot == 5'd0;                    // ... its count's slot
  wire             f_rd_now = p_slot == V - 1 && p_cn == f_ch;           // f's lane is read
  wire             f_calc  = p_slot == V - 1 && p_cp == f_ch;            // f's visit computes
  wire             f_bus   = p_b_take && !p_b_wr && p_b_ch == f_ch;
  wire             f_watched = p_b_word == OFF_CNT || p_b_word == OFF_SCNT || p_b_word == OFF_ILAT ||
                               p_b_word == OFF_PLAT || p_b_word == OFF_PRE || p_b_word == OFF_CEIL ||
                               p_b_word == OFF_STIM || p_b_word == OFF_SETIM ||
                               p_b_word == OFF_SDEL || p_b_word == OFF_SEDEL ||
                               p_b_word == OFF_CNT_HI || p_b_word == OFF_SCNT_HI ||
                               p_b_word == OFF_ILAT_HI || p_b_word == OFF_PLAT_HI ||
                               p_b_word == OFF_PRE_HI || p_b_word == OFF_CEIL_HI;
  wire [63:0]      f_word_d = (p_b_word == OFF_CNT) ? f_sto_d : (p_b_word == OFF_SCNT) ? f_scnt_d :
                              (p_b_word == OFF_ILAT) ? f_ilat_d : (p_b_word == OFF_PLAT) ? f_plat_d :
                              (p_b_word == OFF_PRE) ? f_pre_d : (p_b_word == OFF_CEIL) ? f_ceil_d :
                              (p_b_word == OFF_STIM) ? f_stim_d :
                              (p_b_word == OFF_SETIM) ? {32'd0, f_stim_d[63:32]} :
                              (p_b_word == OFF_SDEL) ? f_sdel_d :
                              (p_b_word == OFF_SEDEL) ? {32'd0, f_sdel_d[63:32]} :
                              (p_b_word == OFF_SCNT_HI) ? {32'd0, f_scnt_d[63:32]} :
                              (p_b_word == OFF_ILAT_HI) ? {32'd0, f_ilat_d[63:32]} :
                              (p_b_word == OFF_PLAT_HI) ? {32'd0, f_plat_d[63:32]} :
                              (p_b_word == OFF_PRE_HI) ? {32'd0, f_pre_d[63:32]} :
                              {32'd0, f_ceil_d[63:32]};
  wire [31:0]      f_word_rst = (p_b_word == OFF_PRE) ? PRE_RST[31:0] :
                                (p_b_word == OFF_CEIL) ? CEIL_RST[31:0] :
                                (p_b_word == OFF_PRE_HI) ? PRE_RST[63:32] :
                                (p_b_word == OFF_CEIL_HI) ? CEIL_RST[63:32] :
                                (p_b_word == OFF_CNT_HI && f_lat) ? f_latv : 32'd0;

  // the offset the bus never writes: 0x3F, which no register has (enc_qei sends the engine mapped
  // offsets only) and the engine uses for a COUNT_HI latch it stores (save_w: all four byte
  // enables, the latch's word)
  function left_out;
    input [5:0] off;
    begin
      left_out = off == OFF_SAVE;
    end
  endfunction

  // a write {offset, byte enables, data} of a watched word: COUNT_LO, PRESET, CEILING, COUNT_HI
  // (its stage, a state write), with some
  // byte enable (a write of none changes nothing)
  function watched_w;
    input [41:0] w;
    begin
      watched_w = |w[35:32] && (w[41:36] == OFF_CNT || w[41:36] == OFF_PRE ||
                                w[41:36] == OFF_PRE_HI || w[41:36] == OFF_CEIL ||
                                w[41:36] == OFF_CEIL_HI || w[41:36] == OFF_CNT_HI ||
                                w[41:32] == {OFF_SAVE, 4'hF});
    end
  endfunction

  // a 64-bit word (PRESET, CEILING: lo at offset lo) after the write w of its half, kept to SZ
  function [63:0] wide_merge;
    input [63:0] c;
    input [41:0] w;
    input [5:0]  lo;
    reg   [63:0] m;
    begin
      m = (w[41:36] == lo) ? {32'd0, lanes_of(w[35:32])} :
          (w[41:36] == lo + 6'd1) ? {lanes_of(w[35:32]), 32'd0} : 64'd0;
      wide_merge = ((c & ~m) | ({w[31:0], w[31:0]} & m)) & SZ;
    end
  endfunction

  function [31:0] stage_merge;  // COUNT_HI's stage after the write w: the high half of the
    input [31:0] c;               // COUNT_LO / COUNT_HI pair, merged as PRESET's and CEILING's
    input [41:0] w;
    reg   [63:0] m;
    begin
      m = wide_merge({c, 32'd0}, w, OFF_CNT);
      stage_merge = m[63:32];
    end
  endfunction

  function [41:0] save_w;  // the write a store of f's COUNT_HI latch v puts in f's slot
    input [31:0] v;
    begin
      save_w = {OFF_SAVE, 4'hF, v};
    end
  endfunction

  function [31:0] lanes_of;  // byte enables -> bit mask
    input [3:0] st;
    begin
      lanes_of = {{8{st[3]}}, {8{st[2]}}, {8{st[1]}}, {8{st[0]}}};
    end
  endfunction

  // a write, {offset, byte enables, data}, as a write slot holds it: the watched write x when ok,
  // else a write that reaches no watched word
  function slot_ok;
    input [41:0] w;
    input        ok;
    input [41:0] x;
    begin
      slot_ok = watched_w(w) ? (ok && w == x) : (!ok && !left_out(w[41:36]));
    end
  endfunction

  always @(*) begin
    assume (f_ch < CHANNELS);
    if (req_valid && req_write && req_ch == f_ch) assume (!left_out(req_word));
  end

  always @(posedge clk) begin
    f_sto_d  <= f_sto;
    f_scnt_d <= f_scnt;
    f_ilat_d <= f_ilat;
    f_plat_d <= f_plat;
    f_pre_d  <= f_pre;
    f_ceil_d <= f_ceil;
    f_mot_d   <= f_mot;
    f_edge_d  <= f_edge;
    f_sbase_d <= f_sbase;
    f_stim_d  <= f_stim;
    f_sdel_d  <= f_sdel;
    if (rst) begin
      {f_lo, f_anc, f_spend, f_scap, f_sanc, f_ipend, f_icap, f_ianc, f_ppend, f_pcap, f_panc} <= 0;
      f_sto  <= 64'd0;
      f_base <= 64'd0;
      f_scnt <= 64'd0;
      f_ilat <= 64'd0;
      f_plat <= 64'd0;
      f_chk  <= 1'b0;
      f_lat  <= 1'b0;
      f_lk   <= 1'b0;
      f_hk   <= 1'b0;
      f_stage <= 32'd0;
      f_mlat <= 32'd0;
      f_svf  <= 1'b0;
      f_svt  <= 1'b0;
      f_pk   <= 1'b0;
      f_pre  <= PRE_RST;
      f_ceil <= CEIL_RST;
      {f_mpos, f_emp, f_smpos, f_semp, f_et, f_stime, f_set, f_qcnt, f_gcnt} <= 0;
      {f_xenew, f_xsnew, f_xsedge} <= 3'd0;
      f_tv    <= 32'd0;
      f_mot   <= 64'd0;
      f_edge  <= 64'd0;
      f_sbase <= 64'd0;
      f_stim  <= 64'd0;
      f_sdel  <= 64'd0;
    end else begin
      if (f_rd_now) begin
        f_lk    <= p_n_taken && f_pk;
        f_lx    <= f_px;
        f_lo    <= p_rec_or[R_LO +: R_LO_W];
        f_anc   <= p_rec_or[R_ANC +: R_ANC_W];
        f_spend <= p_rec_or[R_SPEND];
        f_scap  <= p_rec_or[R_SLO +: R_SLO_W];
        f_sanc  <= p_rec_or[R_SANC +: R_SANC_W];
        f_ipend <= p_rec_or[R_LPEND];
        f_icap  <= p_rec_or[R_LCAP +: R_LCAP_W];
        f_ianc  <= p_rec_or[R_LANC +: R_LANC_W];
        f_ppend <= p_rec_or[R_PPEND];
        f_pcap  <= p_rec_or[R_PLO +: R_PLO_W];
        f_panc  <= p_rec_or[R_PANC +: R_PANC_W];
        f_mpos  <= p_rec_or[R_MPOS +: R_MPOS_W];
        f_qcnt  <= p_rec_or[R_QCNT +: R_QCNT_W];
        f_gcnt  <= p_rec_or[R_GCNT +: R_GCNT_W];
        f_et    <= p_rec_or[R_ET +: R_ET_W];
        f_emp   <= p_rec_or[R_EMP +: R_EMP_W];
        f_xenew <= p_rec_or[R_ENEW];
        f_smpos <= p_rec_or[R_SMPOS +: R_SMPOS_W];
        f_stime <= p_rec_or[R_STIME +: R_STIME_W];
        f_set   <= p_rec_or[R_SET +: R_SET_W];
        f_semp  <= p_rec_or[R_SEMP +: R_SEMP_W];
        f_xsnew <= p_rec_or[R_SNEW];
        f_xsedge <= p_rec_or[R_SEDGE];
        f_tv    <= {{(32 - TS_W){1'b0}}, timebase};
      end
      if (f_calc) begin
        f_hk     <= p_e_taken && f_pk;
        f_hx     <= f_px;
        f_vstage <= f_stage;
        f_vmlat  <= f_mlat;
        f_base   <= f_sto;
        f_vpre   <= f_pre;
        f_vceil  <= f_ceil;
        f_vmot   <= f_mot;
        f_vedge  <= f_edge;
        f_vsbase <= f_sbase;
      end
      // PRESET and CEILING: f's write-back writes the write its visit took (slots 4, 5)
      if (f_wbv && p_slot == 5'd4 && f_lk) f_pre <= wide_merge(f_pre, f_lx, OFF_PRE);
      if (f_wbv && p_slot == 5'd5 && f_lk) f_ceil <= wide_merge(f_ceil, f_lx, OFF_CEIL);
      // COUNT_HI's stage: f's write-back writes the COUNT_HI write its visit took (slot 8)
      if (f_wbv && p_slot == W_HI && f_hk) f_stage <= stage_merge(f_stage, f_hx);
      // f's COUNT_HI latch: a COUNT_LO read of another channel stores it (posts it into f's slot)
      // while the engine holds it; f's write-back writes it (slot 8)
      if (f_save_go && p_lat_ch == f_ch) begin
        f_svf <= 1'b1;
        f_pk  <= 1'b1;
        f_px  <= save_w(f_latv);
      end
      if (f_calc && p_e_taken && f_svf) begin
        f_svf <= 1'b0;
        f_svt <= 1'b1;
      end
      if (f_wbv && p_slot == W_HI && f_hk && f_hx[41:36] == OFF_SAVE) begin
        f_mlat <= f_hx[31:0];
        f_svt  <= 1'b0;
      end
      if (f_wb) f_sto <= f_new;
      if (f_wbv && p_slot == S_SCNT && (f_spend || f_fresh)) f_scnt <= f_snew;
      if (f_wbv && p_slot == S_ILATCH && (f_ipend || f_fresh)) f_ilat <= f_inew;
      if (f_wbv && p_slot == S_PLATCH && (f_ppend || f_fresh)) f_plat <= f_pnew;
      if (f_wbv && p_slot == S_MOT) f_mot <= f_mot_new;
      if (f_wbv && p_slot == S_EDGE) f_edge <= f_edge_new;
      if (f_wbv && p_slot == S_SBASE) f_sbase <= f_sbase_new;
      if (f_wbv && p_slot == S_STIME && (f_spend || f_fresh)) f_stim <= f_stim_new;
      if (f_wbv && p_slot == S_SDELTA && (f_spend || f_fresh)) f_sdel <= f_sdel_new;
      if (p_b_take && p_b_wr && p_b_ch == f_ch) f_bcnt <= f_fresh ? 32'd0 : f_sto_d[31:0];
      if (p_b_st == B_POST && p_b_ch == f_ch) begin
        f_pk <= watched_w({p_b_word, p_b_wstrb, p_b_wdata});
        f_px <= (p_b_word == OFF_CNT) ?
                {OFF_CNT, 4'hF, (f_bcnt & ~lanes_of(p_b_wstrb)) | (p_b_wdata & lanes_of(p_b_wstrb))} :
                {p_b_word, p_b_wstrb, p_b_wdata};
      end
      if (f_bus && p_b_word == OFF_CNT && COUNT_W > 32) begin
        f_lat  <= 1'b1;
        f_latv <= f_fresh ? 32'd0 : f_sto_d[63:32];
      end
      if (f_bus && f_watched) begin
        f_exp <= (f_fresh || p_b_word == OFF_CNT_HI) ? f_word_rst : f_word_d[31:0];
        f_chk <= 1'b1;
      end else if (resp_valid) begin
        f_chk <= 1'b0;
      end
    end
  end

  // a stored word (the count, a latched value): written only in its slot of f's write-back, whole,
  // with its new value, when it is pending or f is fresh; stored from then on (or while f is not
  // fresh), 0 before
  task stored_word;
    input [AW-1:0] a;
    input [4:0]    slot;
    input          pend;
    input [63:0]   nv;     // its new value
    input [63:0]   m;      // the memory's word
    input [63:0]   f;      // the reference's
    input [63:0]   n_q;    // the engine's new value
    input          n_on;   // ... and its write enable
    begin
      if (f_wbv && p_slot <= slot) assert (n_on == (pend || f_fresh) && n_q == nv);
      if (p_we && p_waddr == a) begin
        assert (f_wbv && p_slot == slot);
        assert (p_wmask == {64{pend || f_fresh}} && p_wdata == nv);
      end
      if (!f_fresh || (f_wbv && p_slot > slot)) assert (m == f);
      else assert (f == 64'd0);
    end
  endtask

  always @(*) begin
    if (f_past && !rst) begin
      // a write of f on its way: the bus's request, f's write slot while the write waits or is
      // applied, the write as taken for the push (slot 10 on), at the visit, and as a state write
      // (slot 22 on). A write of COUNT_LO, PRESET or CEILING is the one the wrapper keeps (f_px):
      // COUNT_LO's with its bytes and, in the others, COUNT as read at the write (when some are
      // off), to f's read after its push, whose rebuild takes it as the value of the anchor
      // A_LOAD; PRESET's and CEILING's as written, to f's write-back. Any other write is none of
      // them.
      if (p_b_st != B_IDLE && p_b_ch == f_ch && p_b_wr) assert (!left_out(p_b_word));
      if (p_b_st == B_POST && p_b_ch == f_ch && p_b_wr && p_b_word == OFF_CNT && |p_b_wstrb &&
          !(&p_b_wstrb)) assert (p_b_cnt == f_bcnt);
      if (p_pend_we && p_pend_wch == f_ch) assert (slot_ok(p_pend_wd, f_pk, f_px));
      if (|((p_pend | p_busy) & (1 << f_ch))) assert (slot_ok(p_slot_pk[41:0], f_pk, f_px));
      // (a state write: none of them but COUNT_HI and a store of f's latch)
      if (|((p_pend | p_busy) & p_pend_st & (1 << f_ch)))
        assert (!f_pk || f_px[41:36] == OFF_CNT_HI || f_px[41:36] == OFF_SAVE);
      if (|((p_pend | p_busy) & ~p_pend_st & (1 << f_ch)))
        assert (!f_pk || (f_px[41:36] != OFF_CNT_HI && f_px[41:36] != OFF_SAVE));
      if (p_cn == f_ch && p_slot >= 5'd11 && p_n_taken) assert (slot_ok(p_n_pend, f_pk, f_px));
      if (p_cp == f_ch) begin
        assert (p_p_taken ? slot_ok(p_p_pend, f_lk, f_lx) : !f_lk);
        if (p_slot >= V - 2 && p_e_taken) assert (!f_pk || f_px[41:36] == OFF_CNT_HI || f_px[41:36] == OFF_SAVE);
        if (p_slot == V - 1 && p_e_taken) assert (slot_ok(p_e_pend, f_pk, f_px));
        if (p_p_taken && f_lk) assert (f_lx[41:36] != OFF_CNT_HI && f_lx[41:36] != OFF_SAVE);
      end
      // the count word of f: written whole in slot 0 of each of f's write-backs (always pending)
      stored_word(a_cnt, 5'd0, 1'b1, f_new, m_cnt, f_sto, p_n_cnt, 1'b1);
      // PRESET and CEILING of f: written only in their slots of f's write-back; the memory holds
      // them from then on (or while f is not fresh), within SZ; the reset values before
      if (p_we && p_waddr == a_pre) assert (f_wbv && p_slot == 5'd4);
      if (p_we && p_waddr == a_ceil) assert (f_wbv && p_slot == 5'd5);
      if (!f_fresh || (f_wbv && p_slot >= 5'd5)) assert (m_pre == f_pre);
      else assert (f_pre == PRE_RST);
      if (!f_fresh || (f_wbv && p_slot >= 5'd6)) assert (m_ceil == f_ceil);
      else assert (f_ceil == CEIL_RST);
      assert ((f_sto & ~SZ) == 64'd0 && (f_pre & ~SZ) == 64'd0 && (f_ceil & ~SZ) == 64'd0);
      stored_word(a_scnt, S_SCNT, f_spend, f_snew, m_scnt, f_scnt, p_n_scnt, p_n_snap);
      stored_word(a_ilat, S_ILATCH, f_ipend, f_inew, m_ilat, f_ilat, p_n_ilat, p_n_latch);
      stored_word(a_plat, S_PLATCH, f_ppend, f_pnew, m_plat, f_plat, p_n_plat, p_n_probe);
      // the snapshot's words and those they are made from
      stored_word(a_mot, S_MOT, 1'b1, f_mot_new, m_mot, f_mot, p_n_mot, 1'b1);
      stored_word(a_edge, S_EDGE, 1'b1, f_edge_new, m_edge, f_edge, p_n_edge, 1'b1);
      stored_word(a_sbase, S_SBASE, 1'b1, f_sbase_new, m_sbase, f_sbase, p_n_sbase, 1'b1);
      stored_word(a_stim, S_STIME, f_spend, f_stim_new, m_stim, f_stim, p_n_stime, p_n_snap);
      stored_word(a_sdel, S_SDELTA, f_spend, f_sdel_new, m_sdel, f_sdel, p_n_sdel, p_n_snap);
      // (f is fresh until the end of slot 19 of its first write-back; the first visit writes nothing)
      if (f_wbv && p_slot >= 5'd20) assert (!f_fresh);
      if (!p_wr_on) assert (p_cp == 4'd0 && f_fresh && f_sto == 64'd0);
      // f's write-back: fresh as f was at the visit; PRESET's and CEILING's halves, data and byte
      // lanes those of the write the visit took; the count at the read before is the one its
      // visit rebuilt from
      if (f_wbv) begin
        if (p_slot <= 5'd19) assert (p_ip_fresh == f_fresh);
        assert (p_ip_pre == {f_lk && f_lx[41:36] == OFF_PRE_HI, f_lk && f_lx[41:36] == OFF_PRE});
        assert (p_ip_hi == {f_hk && f_hx[41:36] == OFF_CNT_HI, f_hk && f_hx[41:36] == OFF_SAVE});
        if (f_hk) assert ((f_hx[41:36] == OFF_CNT_HI || f_hx[41:32] == {OFF_SAVE, 4'hF}) && !f_lk);
        if (|p_ip_hi) assert (p_ip_data == f_hx[31:0] && p_ip_lanes == lanes_of(f_hx[35:32]));
        assert (f_stage == ((p_slot > W_HI && f_hk) ? stage_merge(f_vstage, f_hx) : f_vstage));
        assert (f_mlat == ((p_slot > W_HI && f_hk && f_hx[41:36] == OFF_SAVE) ? f_hx[31:0] : f_vmlat));
        assert (p_ip_ceil == {f_lk && f_lx[41:36] == OFF_CEIL_HI, f_lk && f_lx[41:36] == OFF_CEIL});
        if (|p_ip_pre || |p_ip_ceil)
          assert (p_ip_data == f_lx[31:0] && p_ip_lanes == lanes_of(f_lx[35:32]));
        if (p_slot == 5'd0) assert (f_base == f_sto);
        if (p_slot <= S_MOT) assert (f_vmot == f_mot);
        if (p_slot <= S_EDGE) assert (f_vedge == f_edge);
        if (p_slot <= S_SBASE) assert (f_vsbase == f_sbase);
        // PRESET and CEILING as the visit had them, then with its write
        assert (f_pre == ((p_slot >= 5'd5 && f_lk) ? wide_merge(f_vpre, f_lx, OFF_PRE) : f_vpre));
        assert (f_ceil == ((p_slot >= 5'd6 && f_lk) ? wide_merge(f_vceil, f_lx, OFF_CEIL) : f_vceil));
      end
      // f's visit: the record of its read, the loads of the stored words
      if (p_cp == f_ch) begin
        assert (p_rec_q[R_LO +: R_LO_W] == f_lo && p_rec_q[R_ANC +: R_ANC_W] == f_anc);
        assert (p_rec_q[R_SPEND] == f_spend && p_rec_q[R_SLO +: R_SLO_W] == f_scap &&
                p_rec_q[R_SANC +: R_SANC_W] == f_sanc);
        assert (p_rec_q[R_LPEND] == f_ipend && p_rec_q[R_LCAP +: R_LCAP_W] == f_icap &&
                p_rec_q[R_LANC +: R_LANC_W] == f_ianc);
        assert (p_rec_q[R_PPEND] == f_ppend && p_rec_q[R_PLO +: R_PLO_W] == f_pcap &&
                p_rec_q[R_PANC +: R_PANC_W] == f_panc);
        assert (p_rec_q[R_MPOS +: R_MPOS_W] == f_mpos && p_rec_q[R_QCNT +: R_QCNT_W] == f_qcnt &&
                p_rec_q[R_GCNT +: R_GCNT_W] == f_gcnt);
        assert (p_rec_q[R_ET +: R_ET_W] == f_et && p_rec_q[R_EMP +: R_EMP_W] == f_emp &&
                p_rec_q[R_ENEW] == f_xenew);
        assert (p_rec_q[R_SMPOS +: R_SMPOS_W] == f_smpos && p_rec_q[R_STIME +: R_STIME_W] == f_stime &&
                p_rec_q[R_SET +: R_SET_W] == f_set && p_rec_q[R_SEMP +: R_SEMP_W] == f_semp &&
                p_rec_q[R_SNEW] == f_xsnew && p_rec_q[R_SEDGE] == f_xsedge);
        assert ({{(32 - TS_W){1'b0}}, p_tv} == f_tv);
        if (p_slot >= 5'd12) assert (p_o_cnt == f_sto);
        if (p_slot >= 5'd13) assert (p_o_mot == f_mot);
        if (p_slot >= 5'd15) assert (p_o_edge == f_edge);
        if (p_slot >= 5'd16) assert (p_o_sbase == f_sbase);
        if (p_slot >= 5'd19) assert (p_o_pre == f_pre);
        if (p_slot >= 5'd20) assert (p_o_ceil == f_ceil);
      end
      // the bus: a read of f's COUNT_LO, SNAP_COUNT_LO, INDEX_LATCH_LO, PROBE_LATCH_LO, PRESET_LO,
      // CEILING_LO, SNAP_TIME, SNAP_EDGE_TIME, SNAP_DELTA or SNAP_EDGE_DELTA answers the word (its
      // half) as stored in the clock of its port-b read
      if (f_chk) assert ((p_b_st == B_RD2 || p_b_st == B_DONE || (p_b_st == B_IDLE && resp_valid)) &&
                         p_b_ch == f_ch && !p_b_wr && f_watched && p_b_rdata == f_exp);
      if (f_chk && resp_valid) assert (resp_rdata == f_exp);
      // W_HI of f: the stage and the latch as stored; 0 before f's first write-back (which
      // writes it whole); as the visits read it
      assert ((f_stage & ~SZ[63:32]) == 32'd0);
      if (!f_fresh || (f_wbv && p_slot > W_HI)) assert (m_hi == {f_stage, f_mlat});
      else assert (f_stage == 32'd0 && f_mlat == 32'd0);
      // COUNT_W > 32 (n_hi, o_hi and the latch are built then only): the visits' copies of W_HI;
      // the engine's one COUNT_HI latch, when it is f's, holds the high word of f's count as the
      // last COUNT_LO read of f took it; when it is not, that word is being stored (f_svf: the
      // write is posted, in f's slot or taken by f's visit) or is the stored one
      if (COUNT_W <= 32)  // (COUNT_HI reads 0; no latch, nothing stored)
        assert (!f_lat && !f_svf && !f_svt && f_mlat == 32'd0 && !(f_pk && f_px[41:36] == OFF_SAVE) &&
                !(f_hk && f_hx[41:36] == OFF_SAVE));
      if (COUNT_W > 32) begin
        if (p_cn == f_ch && p_slot >= 5'd11) assert (p_n_hi == {f_stage, f_mlat});
        if (p_cp == f_ch && p_slot >= 5'd17) assert (p_o_hi == {f_stage, f_mlat});
        if (p_lat_valid && p_lat_ch == f_ch) assert (f_lat && p_lat_q == f_latv && !f_svf && !f_svt);
        if (!f_lat) assert (!f_svf && !f_svt && f_mlat == 32'd0);
        if (f_lat && !(p_lat_valid && p_lat_ch == f_ch) && !f_svf && !f_svt) assert (f_mlat == f_latv);
        assert (!(f_svf && f_svt));
        if (f_fresh) assert (f_mlat == 32'd0 && (!f_lat || f_latv == 32'd0));  // (fresh: COUNT 0)
        // (a store of f's latch: posted, in f's slot or taken at f's visit (f_svf), then in f's
        // write-back until slot 8 writes it (f_svt))
        if (f_save1 && f_save_ch == f_ch) assert (f_svf);
        if ((p_pend[f_ch] || (p_busy[f_ch] && p_cp == f_ch)) && f_pk && f_px[41:36] == OFF_SAVE) assert (f_svf);
        if (f_wbv && p_slot <= W_HI && f_hk && f_hx[41:36] == OFF_SAVE) assert (f_svt);
        if (f_svf) begin
          assert (f_lat && f_pk && f_px == save_w(f_latv));
          assert ((f_save1 && f_save_ch == f_ch) || p_pend[f_ch] || (p_busy[f_ch] && p_cp == f_ch));
        end
        if (f_svt) assert (f_lat && f_wbv && p_busy[f_ch] && p_slot <= W_HI && f_hk && f_hx == save_w(f_latv));
      end
    end
  end
`endif

endmodule

`default_nettype wire
