// SPDX-License-Identifier: Apache-2.0
// Formal wrapper for enc_qei_efifo (read by formal/enc_qei_efifo.sby; `make formal`).
//
// Inputs are free on every clock (steps, index, en, clear, thresh, pop: any sequence, a push
// and a pop in the same clock included); the first clock is a reset (rst is free afterwards).
// The module's own properties (under FORMAL in rtl/enc_qei_efifo.v) cover the storage: the level
// and the pointers, the head, a picked entry returned unchanged and in order, the LOST mark, the
// time of the last pop. The wrapper checks the port contract, independent of the storage:
//   - no silent loss: the level after a clock is the level before, plus the step of the clock
//     before (registered on the way in, while en), minus a loss (lost_incr), minus a pop of a
//     nonempty FIFO; a clear empties it; ev_ovf and lost_incr are the same pulse and come only
//     with a step while the FIFO is full and not popped
//   - EFIFO_ENTRY: 0 while empty; VALID and LEFT = level - 1 otherwise
//   - ev_thresh exactly while level >= max(thresh, 1)
`default_nettype none

module enc_qei_efifo_formal #(
    parameter integer DEPTH_LOG2 = 2,
    parameter integer TS_W       = 16
) (
    input wire            clk,
    input wire            rst,
    input wire [TS_W-1:0] timebase,
    input wire            step_up,
    input wire            step_dn,
    input wire [1:0]      step_ab,
    input wire            ev_index,
    input wire            en,
    input wire            clear,
    input wire [8:0]      thresh,
    input wire            pop
);

  wire [31:0]     entry;
  wire [TS_W-1:0] pop_time;
  wire [8:0]      level;
  wire            ev_thresh, ev_ovf, lost_incr;

  enc_qei_efifo #(
      .DEPTH_LOG2(DEPTH_LOG2),
      .TS_W      (TS_W)
  ) dut (
      .clk      (clk),
      .rst      (rst),
      .timebase (timebase),
      .step_up  (step_up),
      .step_dn  (step_dn),
      .step_ab  (step_ab),
      .ev_index (ev_index),
      .en       (en),
      .clear    (clear),
      .thresh   (thresh),
      .pop      (pop),
      .entry    (entry),
      .pop_time (pop_time),
      .level    (level),
      .ev_thresh(ev_thresh),
      .ev_ovf   (ev_ovf),
      .lost_incr(lost_incr)
  );

  localparam [8:0] DEPTH = 9'd1 << DEPTH_LOG2;

  reg f_past_valid = 1'b0;
  reg f_step_q;  // a step last clock while en: it is pushed this clock

  always @(posedge clk) begin
    f_past_valid <= 1'b1;
    f_step_q     <= ~rst & en & (step_up | step_dn);
  end

  always @(*) begin
    if (!f_past_valid) assume (rst);
    // the core never steps both ways at once
    assume (!(step_up && step_dn));
  end

  wire [8:0] f_thr = (thresh == 9'd0) ? 9'd1 : thresh;

  always @(*) begin
    if (f_past_valid && !rst) begin
      assert (level <= DEPTH);
      assert (ev_ovf == lost_incr);
      if (lost_incr) assert (f_step_q && !clear && level == DEPTH && !pop);
      if (level == 9'd0) begin
        assert (entry == 32'd0);
      end else begin
        assert (entry[0] == 1'b1);
        assert ({1'b0, entry[15:8]} == ((level - 9'd1) & 9'h0FF));
        assert (entry[7:6] == 2'b00);
      end
      assert (ev_thresh == (level >= f_thr));
    end
  end

  always @(posedge clk) begin
    if (f_past_valid && !rst && !$past(rst)) begin
      if ($past(clear)) begin
        assert (level == 9'd0);
      end else begin
        assert (level == $past(level) + {8'd0, $past(f_step_q)} - {8'd0, $past(lost_incr)}
                         - {8'd0, $past(pop) && $past(level) != 9'd0});
      end
    end
  end

  always @(*) begin
    if (f_past_valid && !rst) begin
      cover (level == DEPTH && lost_incr);
      cover (level == DEPTH && pop && f_step_q);
    end
  end

endmodule

`default_nettype wire
