// SPDX-License-Identifier: Apache-2.0
// enc_filter_rt -- the synchronizer and digital filter of one input, with the filter length as
// a run-time input: the 74LS14's job of the note, in clocked logic. enc_conditioner_rt puts two
// of them behind one filter length (channels A and B); the shared engine's lanes use them for A,
// B and Z.
//
//   in -> two flip-flops (synchronizer) -> filter -> level
// The filter takes a new level only after the synchronized input has shown it on last + 1
// consecutive clocks; a level that goes back sooner is rejected (reject: one clock, combinational,
// in the clock the synchronized input returns). level changes last + 2 clocks after the rising
// edge that first samples the new level. A new `last` acts at once: a candidate level already
// seen on more than `last` samples is accepted at the next differing sample, so a change never
// loses or invents a level.
`default_nettype none

module enc_filter_rt #(
    parameter integer CW       = 4,  // run counter bits: holds MAX_LAST
    // verilator lint_off UNUSEDPARAM
    parameter integer MAX_LAST = 15  // the largest `last` the caller gives (< 2^CW; for the proofs)
    // verilator lint_on UNUSEDPARAM
) (
    input  wire          clk,
    input  wire          rst,     // synchronous, active high
    input  wire [CW-1:0] last,    // samples a new level must persist, minus 1 (<= MAX_LAST)
    input  wire          in,      // the input, asynchronous
    output wire          level,   // the accepted level, synchronous to clk
    output wire          reject   // a candidate level went back before it was accepted
);

  // ---- synchronizer: two flip-flops -------------------------------------------------------------
  reg meta_q, sync_q;

  always @(posedge clk) begin
    if (rst) begin
      meta_q <= 1'b0;
      sync_q <= 1'b0;
    end else begin
      meta_q <= in;
      sync_q <= meta_q;
    end
  end

  // ---- filter: run = consecutive samples (so far) that differ from the accepted level ------------
  reg          level_q, level_d;
  reg [CW-1:0] run_q, run_d;
  reg          reject_d;

  always @(*) begin
    level_d  = level_q;
    run_d    = run_q;
    reject_d = 1'b0;
    if (sync_q != level_q) begin
      if (run_q >= last) begin
        level_d = sync_q;  // the last + 1-th consecutive sample of the new level: accept
        run_d   = {CW{1'b0}};
      end else begin
        run_d = run_q + 1'b1;
      end
    end else if (run_q != {CW{1'b0}}) begin
      run_d    = {CW{1'b0}};  // back to the accepted level too soon: reject
      reject_d = 1'b1;
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      level_q <= 1'b0;
      run_q   <= {CW{1'b0}};
    end else begin
      level_q <= level_d;
      run_q   <= run_d;
    end
  end

  assign level  = level_q;
  assign reject = reject_d;

`ifdef FORMAL
  // formal only: the run counter stays at most MAX_LAST (the caller keeps last <= MAX_LAST; an
  // invariant for the induction of the callers' proofs). Assert only.
  reg f_rst_seen = 1'b0;
  always @(posedge clk) begin
    if (rst) f_rst_seen <= 1'b1;
  end

  always @(*) begin
    if (f_rst_seen) begin
      assert ({{(32 - CW){1'b0}}, run_q} <= MAX_LAST);
    end
  end
`endif

endmodule

`default_nettype wire
