// SPDX-License-Identifier: Apache-2.0
// enc_qei_efifo -- the edge-capture FIFO of one enc_qei channel (part of its timing unit). Where
// the note's Figure 17 buffer hands the microprocessor a count, this hands it every edge: each
// count step pushes {timestamp, A/B state after the step, direction, LOST, IDX}, and the host
// pops the entries over the bus (EFIFO_ENTRY, then EFIFO_TIME), for velocity estimators that
// learn the code wheel's errors (hedsmodel.calibration, sw/enc_qei_calib.c).
//
// Timing: the core's step (step_up / step_dn with step_ab) is registered on the way in, so an
// entry's timestamp is the timebase in the clock after the count took the step: the value
// SNAP_EDGE_TIME holds for that edge (enc_qei_timing registers its edges the same way).
// Storage: 2^DEPTH_LOG2 words of TS_W + 5 bits, written at wr_ptr_q and read through a register
// (block RAM when Yosys chooses it) into head_q, which always holds the oldest entry (first-word
// fall-through): in a clock that pops, the read address is already the next entry, and an entry
// written in the same clock to the address being read goes to head_q directly.
// Nothing is lost silently: a step that finds the FIFO full (with no pop in the same clock) is
// dropped, pulses lost_incr (EFIFO_LOST) and ev_ovf (EVENTS.EFIFO_OVF), and marks the next entry
// stored (LOST). A qualified index edge marks the entry of its own clock, or the next one stored
// (IDX). clear empties the FIFO and forgets both marks (a step in its clock is not stored); while
// en = 0 nothing is pushed, an index marks nothing and a pending IDX mark is dropped (a pending
// LOST mark stays: the loss happened).
`default_nettype none

module enc_qei_efifo #(
    parameter integer DEPTH_LOG2 = 4,  // 2^DEPTH_LOG2 entries, 1 .. 8 (checked by enc_qei)
    parameter integer TS_W       = 32  // timebase width, 16 .. 32 (checked by enc_qei)
) (
    input  wire            clk,
    input  wire            rst,        // synchronous, active high
    input  wire [TS_W-1:0] timebase,   // the shared timebase
    input  wire            step_up,    // from the core, in the clock of the step: a step up
    input  wire            step_dn,    // ... a step down
    input  wire [1:0]      step_ab,    // ... {A, B} after it
    input  wire            ev_index,   // ... a qualified index edge (the same stage)
    input  wire            en,         // EFIFO_CTRL.EN
    input  wire            clear,      // EFIFO_CTRL.CLEAR, one clock
    input  wire [8:0]      thresh,     // EFIFO_CTRL.THRESH (0 acts as 1)
    input  wire            pop,        // a read of EFIFO_ENTRY takes its data in this clock
    output wire [31:0]     entry,      // EFIFO_ENTRY as a read now answers it
    output wire [TS_W-1:0] pop_time,   // EFIFO_TIME: the timestamp of the last entry popped
    output wire [8:0]      level,      // EFIFO_STATUS.LEVEL
    output wire            ev_thresh,  // the FIFO holds thresh entries or more (every such clock)
    output wire            ev_ovf,     // a step was lost (one clock per step)
    output wire            lost_incr   // ... count it (EFIFO_LOST)
);

  localparam integer DEPTH = 1 << DEPTH_LOG2;
  localparam integer W     = TS_W + 5;  // {timestamp, idx, lost, b, a, up}
  localparam [DEPTH_LOG2:0] LVL_FULL = DEPTH[DEPTH_LOG2:0];
  localparam [DEPTH_LOG2:0] LVL_ONE  = {{DEPTH_LOG2{1'b0}}, 1'b1};
  localparam [DEPTH_LOG2-1:0] PTR_ONE = {{(DEPTH_LOG2-1){1'b0}}, 1'b1};

  function [8:0] zext9;
    input [DEPTH_LOG2:0] v;
    begin
      zext9 = 9'd0;
      zext9[DEPTH_LOG2:0] = v;
    end
  endfunction

  // ---- the step, registered on the way in (its timestamp: the timebase now) --------------------
  reg       push_q;  // a step to store this clock
  reg       up_q;    // ... up
  reg [1:0] ab_q;    // ... {A, B} after it
  reg       idx_q;   // a qualified index edge, registered alike

  always @(posedge clk) begin
    if (rst) begin
      push_q <= 1'b0;
      idx_q  <= 1'b0;
    end else begin
      push_q <= en & (step_up | step_dn);
      idx_q  <= en & ev_index;
    end
  end

  always @(posedge clk) begin
    up_q <= step_up;
    ab_q <= step_ab;
  end

  // ---- pointers, level and marks ------------------------------------------------------------------
  reg [DEPTH_LOG2-1:0] wr_ptr_q, rd_ptr_q;
  reg [DEPTH_LOG2:0]   level_q;
  reg                  lost_pend_q;  // a step was lost since the last entry stored
  reg                  idx_pend_q;   // an index edge came since the last entry stored

  wire nonempty = (level_q != {(DEPTH_LOG2 + 1){1'b0}});
  wire full     = (level_q == LVL_FULL);
  wire pop_ok   = pop & nonempty;
  wire store    = push_q & ~clear & (~full | pop_ok);
  wire lose     = push_q & ~clear & full & ~pop_ok;
  wire idx_now  = idx_q | idx_pend_q;

  // the read address of the head register: the next entry in a clock that pops (in the clock of
  // a clear it does not matter: the FIFO is empty after it, and the next store bypasses memory)
  wire [DEPTH_LOG2-1:0] rd_ptr_d = pop_ok ? rd_ptr_q + PTR_ONE : rd_ptr_q;

  always @(posedge clk) begin
    if (rst) begin
      wr_ptr_q    <= {DEPTH_LOG2{1'b0}};
      rd_ptr_q    <= {DEPTH_LOG2{1'b0}};
      level_q     <= {(DEPTH_LOG2 + 1){1'b0}};
      lost_pend_q <= 1'b0;
      idx_pend_q  <= 1'b0;
    end else if (clear) begin
      wr_ptr_q    <= {DEPTH_LOG2{1'b0}};
      rd_ptr_q    <= {DEPTH_LOG2{1'b0}};
      level_q     <= {(DEPTH_LOG2 + 1){1'b0}};
      lost_pend_q <= 1'b0;
      idx_pend_q  <= 1'b0;
    end else begin
      rd_ptr_q <= rd_ptr_d;
      if (store) begin
        wr_ptr_q <= wr_ptr_q + PTR_ONE;
      end
      if (store & ~pop_ok) begin
        level_q <= level_q + LVL_ONE;
      end else if (pop_ok & ~store) begin
        level_q <= level_q - LVL_ONE;
      end
      if (store) begin
        lost_pend_q <= 1'b0;
      end else if (lose) begin
        lost_pend_q <= 1'b1;
      end
      if (~en | store) begin
        idx_pend_q <= 1'b0;
      end else if (idx_q) begin
        idx_pend_q <= 1'b1;
      end
    end
  end

  // ---- storage and the head register (first-word fall-through) --------------------------------
  reg  [W-1:0] mem [0:DEPTH-1];
  reg  [W-1:0] head_q;  // the entry at rd_ptr_q (valid while level_q != 0)
  wire [W-1:0] wdata = {timebase, idx_now, lost_pend_q, ab_q[0], ab_q[1], up_q};

  always @(posedge clk) begin
    if (store) begin
      mem[wr_ptr_q] <= wdata;
    end
  end

  always @(posedge clk) begin
    if (store && (wr_ptr_q == rd_ptr_d)) begin
      head_q <= wdata;
    end else begin
      head_q <= mem[rd_ptr_d];
    end
  end

  // ---- what the host reads --------------------------------------------------------------------------
  reg [TS_W-1:0] pop_time_q;

  always @(posedge clk) begin
    if (rst) begin
      pop_time_q <= {TS_W{1'b0}};
    end else if (pop_ok) begin
      pop_time_q <= head_q[W-1:5];
    end
  end

  wire [8:0] level9 = zext9(level_q);
  wire [7:0] left8  = level9[7:0] - 8'd1;  // entries behind the head, 0 .. 255 (read only while
                                           // nonempty; level 256 gives 255 modulo 256)
  wire [8:0] thr    = (thresh == 9'd0) ? 9'd1 : thresh;

  // {TIME_LO, LEFT, 2'b0, IDX, LOST, B, A, DIR, VALID}; all 0 while empty
  assign entry     = nonempty ? {head_q[20:5], left8, 2'b00, head_q[4:1], head_q[0], 1'b1}
                              : 32'd0;
  assign pop_time  = pop_time_q;
  assign level     = level9;
  assign ev_thresh = (level9 >= thr);
  assign ev_ovf    = lose;
  assign lost_incr = lose;

`ifdef FORMAL
  // ---- properties (formal/enc_qei_efifo.sby, with formal/enc_qei_efifo_formal.v driving the
  // ports and checking the port contract; these need the storage) -----------------------------
  // Data integrity: a stored entry the solver picks (f_pick, any clock) is what the head holds,
  // and what a read returns, when the pops reach it; the entries before it pop first.
  (* anyseq *) reg f_pick;
  reg                  f_past_valid = 1'b0;
  reg                  f_track;   // the picked entry is in the FIFO
  reg [DEPTH_LOG2-1:0] f_addr;    // ... at this address
  reg [W-1:0]          f_data;    // ... with this content
  reg                  f_lost;    // a step was lost since the last entry stored (restated)
  wire [DEPTH_LOG2-1:0] f_ahead = f_addr - rd_ptr_q;  // entries ahead of it

  always @(posedge clk) begin
    f_past_valid <= 1'b1;
    if (rst | clear) begin
      f_track <= 1'b0;
    end else if (f_track & pop_ok & (rd_ptr_q == f_addr)) begin
      f_track <= 1'b0;
    end else if (~f_track & store & f_pick) begin
      f_track <= 1'b1;
      f_addr  <= wr_ptr_q;
      f_data  <= wdata;
    end
    if (rst | clear | store) begin
      f_lost <= 1'b0;
    end else if (lose) begin
      f_lost <= 1'b1;
    end
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      // the level is what the pointers say (and never more than the depth)
      assert (level_q <= LVL_FULL);
      assert (level_q[DEPTH_LOG2-1:0] == wr_ptr_q - rd_ptr_q);
      // the head holds the oldest entry
      if (nonempty) assert (head_q == mem[rd_ptr_q]);
      // every step is stored or lost, never both (a clear drops it by design)
      assert (!(store && lose));
      if (push_q && !clear) assert (store || lose);
      // the LOST mark is set exactly by a loss since the last entry stored
      assert (lost_pend_q == f_lost);
      // the picked entry: stored unchanged, within the level, returned when it is the head
      if (f_track) begin
        assert (f_ahead < level_q);
        assert (mem[f_addr] == f_data);
        if (rd_ptr_q == f_addr) assert (head_q == f_data);
        if (pop_ok && rd_ptr_q == f_addr) begin
          assert (entry[31:16] == f_data[20:5]);
          assert (entry[5:1] == {f_data[4:1], f_data[0]});
        end
      end
    end
  end

  always @(posedge clk) begin
    if (f_past_valid && !rst && !$past(rst)) begin
      // EFIFO_TIME: the time of the entry the last pop took
      if ($past(pop_ok)) assert (pop_time_q == $past(head_q[W-1:5]));
      if (!$past(pop_ok)) assert (pop_time_q == $past(pop_time_q));
    end
  end

  always @(*) begin
    cover (f_track && pop_ok && rd_ptr_q == f_addr && level_q == LVL_FULL);  // a full FIFO drained to it
    cover (lose && pop == 1'b0);
    cover (store && pop_ok && full);  // a push and a pop in the same clock, the FIFO full
  end
`endif

endmodule

`default_nettype wire
