// SPDX-License-Identifier: Apache-2.0
// fwb_slave -- formal properties of a Wishbone B4 classic (non-pipelined) slave port.
//
// A reusable property checker, written in the style of ZipCPU's fwb_slave / fwbc_slave (these are
// our own): instantiate it inside a formal wrapper with every signal of the slave's bus port as an
// input. It holds no design logic. Assumptions describe a legal classic master, assertions the
// slave. Synchronous active-high reset; in a clock with rst high nothing is checked (the master
// is being reset too, RULE 3.00) and no request is in progress after it.
//
// A request is the master's (cyc & stb); it starts in a clock with cyc & stb and none in progress,
// and is answered by one clock of ack or err (the answer ends it; with stb still high in the next
// clock the master starts its next request). At most one request is in progress (classic).
//
// Master (assumed):
//   - stb only with cyc;
//   - cyc and stb low in the clock after a reset clock (RULE 3.20);
//   - while its request is unanswered the master keeps cyc and stb high and we, adr, sel (and
//     dat_w of a write) stable; with F_OPT_ABORT it may instead drop cyc (and stb), which
//     abandons the request (no answer is then owed; the wrapper decides what else must hold).
// Slave (asserted):
//   - never ack and err together; no err unless F_OPT_ERR;
//   - ack / err only while a request is presented: cyc & stb in that clock (RULE 3.35), so never
//     without a request in progress, after an abort, or in the clock after a reset;
//   - each answer comes F_MIN_DELAY .. F_MAX_DELAY clocks after its request started (0: in the
//     same clock), so every request is answered exactly once within the bound: with
//     F_MIN_DELAY > 0 a second answer to one request (which would be an answer to the master's
//     next request in its first clock) fails;
//   - the counters: requests started and answered in this bus cycle (cyc high; they count
//     modulo 2^F_LGDEPTH), f_outstanding = started - answered, at most one.
// Outputs, for the wrapper's own properties and covers: f_start (a request starts this clock),
// f_busy (a request started in an earlier clock is still unanswered), f_delay (clocks since the
// presented request started: 0 in its first clock), f_nreqs, f_nacks, f_outstanding.
`default_nettype none

module fwb_slave #(
    parameter integer AW          = 8,   // address width
    parameter integer DW          = 32,  // data width, a multiple of 8
    parameter integer F_MIN_DELAY = 0,   // fewest clocks from a request's start to its answer
    parameter integer F_MAX_DELAY = 4,   // most clocks from a request's start to its answer
    parameter [0:0]   F_OPT_ABORT = 1'b0,  // 1: the master may drop cyc in a request (abort)
    parameter [0:0]   F_OPT_ERR   = 1'b1,  // 0: the slave never answers err
    parameter integer F_LGDEPTH   = 4,   // width of the request counters
    parameter integer F_DLY_W       = $clog2(F_MAX_DELAY + 2)  // width of f_delay (derived)
) (
    input  wire                 clk,
    input  wire                 rst,
    // the bus, master to slave
    input  wire                 cyc,
    input  wire                 stb,
    input  wire                 we,
    input  wire [AW-1:0]        adr,
    input  wire [DW-1:0]        dat_w,
    input  wire [DW/8-1:0]      sel,
    // slave to master
    input  wire                 ack,
    input  wire                 err,
    // for the wrapper
    output wire                 f_start,
    output wire                 f_busy,
    output wire [F_DLY_W-1:0]     f_delay,
    output reg  [F_LGDEPTH-1:0] f_nreqs,
    output reg  [F_LGDEPTH-1:0] f_nacks,
    output wire [F_LGDEPTH-1:0] f_outstanding
);

  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;

  wire f_req    = cyc & stb;   // a request is presented
  wire f_answer = ack | err;

  // ---- request tracking ---------------------------------------------------------------------
  reg             busy_q = 1'b0;  // a request started in an earlier clock, not answered
  reg [F_DLY_W-1:0] age_q  = {F_DLY_W{1'b0}};  // clocks since it started

  assign f_busy  = busy_q;
  assign f_start = ~rst & f_req & ~busy_q;
  assign f_delay = busy_q ? age_q : {F_DLY_W{1'b0}};

  always @(posedge clk) begin
    if (rst) begin
      busy_q <= 1'b0;
      age_q  <= {F_DLY_W{1'b0}};
    end else begin
      busy_q <= f_req & ~f_answer;
      // saturates one above the bound (a late answer has already failed)
      if (f_delay <= F_MAX_DELAY) age_q <= f_delay + 1'b1;
    end
  end

  always @(posedge clk) begin
    if (rst | ~cyc) begin
      f_nreqs <= {F_LGDEPTH{1'b0}};
      f_nacks <= {F_LGDEPTH{1'b0}};
    end else begin
      f_nreqs <= f_nreqs + f_start;
      f_nacks <= f_nacks + (f_req & f_answer);
    end
  end
  assign f_outstanding = f_nreqs - f_nacks;

  // ---- master: assumptions -------------------------------------------------------------------
  always @(*) begin
    if (stb) assume (cyc);
  end

  always @(posedge clk) begin
    if (f_past_valid && $past(rst)) begin
      assume (!cyc);
      assume (!stb);
    end
    // an unanswered request is held (or, with F_OPT_ABORT, abandoned by dropping cyc)
    if (f_past_valid && !rst && busy_q) begin
      if (!F_OPT_ABORT || cyc) begin
        assume (cyc);
        assume (stb);
        assume (we == $past(we));
        assume (adr == $past(adr));
        assume (sel == $past(sel));
        if (we) assume (dat_w == $past(dat_w));
      end
    end
  end

  // ---- slave: assertions ---------------------------------------------------------------------
  always @(*) begin
    if (f_past_valid && !rst) begin
      assert (!(ack && err));
      if (!F_OPT_ERR) assert (!err);
      // answers only to a presented request
      if (f_answer) assert (f_req);
      // within the bounds
      if (f_answer) assert (f_delay >= F_MIN_DELAY);
      if (f_req) assert (f_delay <= F_MAX_DELAY);
      if (f_req && f_delay == F_MAX_DELAY) assert (f_answer);
      // at most one request outstanding; the counters agree with the tracking
      assert (f_outstanding <= 1);
      assert (f_outstanding == {{(F_LGDEPTH-1){1'b0}}, busy_q});
    end
  end

  always @(posedge clk) begin
    if (f_past_valid && $past(rst)) begin
      assert (!ack);
      assert (!err);
    end
  end

endmodule

`default_nettype wire
