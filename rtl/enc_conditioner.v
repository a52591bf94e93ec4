// SPDX-License-Identifier: Apache-2.0
// enc_conditioner -- input synchronizer and digital filter for the two encoder channels.
//
// Does in logic what the note asks of the 74LS14 Schmitt buffer in front of every counting
// circuit (section CIRCUITS): it makes the asynchronous A and B outputs of the HEDS-5000 safe to
// sample and rejects short pulses. Per channel:
//   a_in -> two flip-flops (synchronizer) -> FILTER_LEN-sample filter -> a
// The filter output takes a new level only after the synchronized input has shown that level on
// FILTER_LEN consecutive clocks. A level that goes back before FILTER_LEN samples is rejected and
// `glitch` pulses for one clock. Both channels use identical paths, so their relative timing is
// kept to the clock: an output changes FILTER_LEN + 1 clocks after the rising edge that first
// samples the new level (so 1 + FILTER_LEN to 2 + FILTER_LEN clock periods after the input edge).
// With FILTER_LEN = 1 the filter is a plain register and glitch stays 0.
// Extra output `valid` (not in the contract's list): rst forces a and b to 0, and the outputs
// show the real input levels only FILTER_LEN + 2 clocks after rst falls; `valid` rises on that
// clock. A decoder behind the conditioner should be held in reset until then (rst | ~valid), or
// it would take 00 as its reference state and count the jump to the real state.
`default_nettype none
`include "enc_params.vh"

module enc_conditioner #(
    parameter integer FILTER_LEN = 3  // samples a new level must persist: 1 .. 16 (1 = no filter)
) (
    input  wire clk,
    input  wire rst,     // synchronous, active high
    input  wire a_in,    // channel A, asynchronous
    input  wire b_in,    // channel B, asynchronous
    output wire a,       // conditioned channel A, synchronous to clk
    output wire b,       // conditioned channel B, synchronous to clk
    output wire glitch,  // one-clock pulse per rejected level (either channel)
    output wire valid    // a and b reflect the inputs (FILTER_LEN + 2 clocks after rst)
);

  generate
    `ENC_CHECK_FILTER_LEN
  endgenerate

  // Run-length counter: number of consecutive samples (so far) that differ from the accepted level;
  // holds 0 .. FILTER_LEN-1.
  localparam integer CW = (FILTER_LEN <= 2) ? 1 : (FILTER_LEN <= 4) ? 2 :
                          (FILTER_LEN <= 8) ? 3 : 4;
  localparam integer LAST_INT = FILTER_LEN - 1;
  localparam [CW-1:0] LAST = LAST_INT[CW-1:0];  // a differing sample seen with run = LAST accepts

  // ---- synchronizer: two flip-flops per channel -----------------------------------------------
  reg [1:0] meta_q;  // {b, a} first stage
  reg [1:0] sync_q;  // {b, a} second stage

  always @(posedge clk) begin
    if (rst) begin
      meta_q <= 2'b00;
      sync_q <= 2'b00;
    end else begin
      meta_q <= {b_in, a_in};
      sync_q <= meta_q;
    end
  end

  // ---- filter: the same logic for each channel ------------------------------------------------
  wire [1:0] level;   // {b, a} accepted levels
  wire [1:0] reject;  // this clock a candidate level went back before it was accepted

  genvar ch;
  generate
    for (ch = 0; ch < 2; ch = ch + 1) begin : g_filter
      reg          level_q;
      reg          level_d;
      reg [CW-1:0] run_q;
      reg [CW-1:0] run_d;
      reg          reject_d;

      always @(*) begin
        level_d  = level_q;
        run_d    = run_q;
        reject_d = 1'b0;
        if (sync_q[ch] != level_q) begin
          if (run_q == LAST) begin
            level_d = sync_q[ch];  // FILTER_LEN-th consecutive sample of the new level: accept
            run_d   = {CW{1'b0}};
          end else begin
            run_d = run_q + 1'b1;
          end
        end else if (run_q != {CW{1'b0}}) begin
          run_d    = {CW{1'b0}};   // back to the accepted level too soon: reject
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

      assign level[ch]  = level_q;
      assign reject[ch] = reject_d;
    end
  endgenerate

  // ---- settling after reset: 2 synchronizer clocks + FILTER_LEN filter clocks ------------------
  // A chain of SETTLE flip-flops filling with ones after rst: valid is its last stage. (A
  // counter would need LUTs; these flip-flops need none.)
  localparam integer SETTLE = FILTER_LEN + 2;
  reg [SETTLE-1:0] settle_q;

  always @(posedge clk) begin
    if (rst) begin
      settle_q <= {SETTLE{1'b0}};
    end else begin
      settle_q <= {settle_q[SETTLE-2:0], 1'b1};
    end
  end

  reg glitch_q;

  always @(posedge clk) begin
    if (rst) begin
      glitch_q <= 1'b0;
    end else begin
      glitch_q <= |reject;
    end
  end

  assign a      = level[0];
  assign b      = level[1];
  assign glitch = glitch_q;
  assign valid  = settle_q[SETTLE-1];

`ifdef FORMAL
  // ---- formal only (formal/enc_conditioner.sby): invariants, asserts only ----------------------
  // The port-level properties are in formal/enc_conditioner_formal.v. These bound the registers
  // to their reachable values, so that induction (here and in a parent) needs no long traces:
  // each run-length counter stays in 0 .. FILTER_LEN-1 (it has spare codes unless FILTER_LEN is a
  // power of two), and the settling chain fills with ones from bit 0 (a thermometer code).
  reg f_rst_seen = 1'b0;  // a rst has happened: the registers are defined
  always @(posedge clk) begin
    if (rst) f_rst_seen <= 1'b1;
  end

  always @(*) begin
    if (f_rst_seen) begin
      assert (g_filter[0].run_q <= LAST && g_filter[1].run_q <= LAST);
      assert (((settle_q >> 1) & ~settle_q) == {SETTLE{1'b0}});
    end
  end
`endif

endmodule

`default_nettype wire
