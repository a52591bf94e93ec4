// SPDX-License-Identifier: Apache-2.0
// Test-only wrapper for `make demo`: every circuit of the library driven from one pair of encoder
// channels, as the reader of the application note would wire them on one bench.
//
//   a_in, b_in (asynchronous, from the modeled HEDS-5000)
//     -> enc_conditioner (the 74LS14's job) -> a, b
//          -> enc_x1_hysteresis  Figure 14, 1X cycle count   (up/down pulses, x1_count)
//          -> enc_x2_xor         Figure 15, 2X edge detector (pulse + direction, x2_count)
//          -> enc_x4_decoder     look-up-table 4X decode      (pulse + direction, x4_count)
//          -> enc_phase_meter    Figure 11, averaging phase meter (reading and the two LEDs)
//          -> enc_characterizer  Figure 3 encoding characteristics, per window of cycles
//     -> enc_updown_buffer       Figure 17, BCD up/down buffer (its own conditioner, as built)
//     -> enc_qei_wb              the bus peripheral (its own conditioner), read over Wishbone by
//                                the bench: count, and the snapshot registers for velocity
//
// The x*_count accumulators (signed, 32 bits) only sum the decoders' pulses so the bench and the
// waveform viewer can read the counts; they are not part of any circuit. The decoders are held in
// reset until the conditioner shows the real input levels (its `valid`). `meas_rst` restarts the
// phase meter and the characterizer (the bench presses it when the motor has reached constant
// speed, so their first window holds constant-speed cycles only). enc_qei_wb runs at the reset
// defaults (x4, free range, FILTER_LEN 3 at run time) with no index, probe or snap_in; the bench
// drives its Wishbone port (wb_*). Everything the waveform review needs is a signal of this
// module, so the VCD can stop at this level (Verilator --trace-depth).
`default_nettype none

module demo_top #(
    parameter integer FILTER_LEN    = 3,      // enc_conditioner / enc_updown_buffer filter
    parameter integer WINDOW_LOG2   = 15,     // enc_phase_meter window: 2^WINDOW_LOG2 clocks
    parameter integer CNT_W         = 16,     // enc_characterizer state-width counter bits
    parameter integer WINDOW_CYCLES = 64,     // enc_characterizer cycles per window
    parameter integer MIN_STATE     = 11776   // enc_characterizer pass limit: 46 e-degrees x 256
) (
    input  wire               clk,
    input  wire               rst,
    input  wire               meas_rst,    // restart phase meter and characterizer
    input  wire               a_in,        // channel A from the encoder (asynchronous)
    input  wire               b_in,        // channel B from the encoder (asynchronous)
    input  wire               hold,        // up/down buffer read inhibit
    // enc_qei_wb: Wishbone B4 classic slave (driven by the bench's WishboneMaster)
    input  wire        [7:0]  wb_adr_i,
    input  wire        [31:0] wb_dat_i,
    output wire        [31:0] wb_dat_o,
    input  wire        [3:0]  wb_sel_i,
    input  wire               wb_we_i,
    input  wire               wb_stb_i,
    input  wire               wb_cyc_i,
    output wire               wb_ack_o,
    output wire               wb_err_o,
    output wire               qei_irq,     // enc_qei_wb irq (the demo enables no event)
    output wire               qei_cmp,     // enc_qei_wb cmp_out (COMPARE at its reset value)
    // conditioner
    output wire               a,
    output wire               b,
    output wire               glitch,
    output wire               cond_valid,  // conditioner outputs show the inputs (after rst)
    // 1X (Figure 14)
    output wire               x1_up,
    output wire               x1_dn,
    output wire               x1_err,
    output reg  signed [31:0] x1_count,
    // 2X (Figure 15)
    output wire               x2_pulse,
    output wire               x2_up,
    output wire               x2_err,
    output reg  signed [31:0] x2_count,
    // 4X (look-up table)
    output wire               x4_pulse,
    output wire               x4_up,
    output wire               x4_err,
    output reg  signed [31:0] x4_count,
    // BCD up/down buffer (Figure 17), 4 decades
    output wire        [15:0] bcd_count,
    output wire        [15:0] bcd_rd,
    output wire               bcd_glitch,
    output wire               bcd_err,
    output wire               bcd_rco_n,
    // phase meter (Figure 11)
    output wire               pm_a_leads,  // red LED: channel A leads
    output wire               pm_b_leads,
    output wire signed [15:0] pm_phase_err,
    output wire               pm_valid,
    // characterizer
    output wire signed [15:0] ch_cycle_err,
    output wire signed [15:0] ch_pulse_err,
    output wire signed [15:0] ch_phase_err,
    output wire signed [15:0] ch_state_err,
    output wire        [15:0] ch_state_min,
    output wire               ch_pass,
    output wire               ch_valid,
    // error-flag totals since reset (for the bench)
    output reg         [15:0] n_glitch,
    output reg         [15:0] n_x1_err,
    output reg         [15:0] n_x2_err,
    output reg         [15:0] n_x4_err,
    output reg         [15:0] n_bcd_flag
);

  localparam [31:0] MIN_STATE_32 = MIN_STATE;
  localparam [15:0] MIN_STATE_W = MIN_STATE_32[15:0];
  // The decoders take their reference state only once the conditioner shows the real inputs.
  wire drst = rst | ~cond_valid;
  wire mrst = drst | meas_rst;

  enc_conditioner #(
      .FILTER_LEN(FILTER_LEN)
  ) u_cond (
      .clk   (clk),
      .rst   (rst),
      .a_in  (a_in),
      .b_in  (b_in),
      .a     (a),
      .b     (b),
      .glitch(glitch),
      .valid (cond_valid)
  );

  enc_x1_hysteresis u_x1 (
      .clk     (clk),
      .rst     (drst),
      .a       (a),
      .b       (b),
      .up_pulse(x1_up),
      .dn_pulse(x1_dn),
      .error   (x1_err)
  );

  enc_x2_xor u_x2 (
      .clk      (clk),
      .rst      (drst),
      .a        (a),
      .b        (b),
      .cnt_pulse(x2_pulse),
      .up       (x2_up),
      .error    (x2_err)
  );

  enc_x4_decoder u_x4 (
      .clk      (clk),
      .rst      (drst),
      .a        (a),
      .b        (b),
      .cnt_pulse(x4_pulse),
      .up       (x4_up),
      .error    (x4_err)
  );

  enc_updown_buffer #(
      .DIGITS    (4),
      .MODULUS   (10),
      .FILTER_LEN(FILTER_LEN)
  ) u_buf (
      .clk    (clk),
      .rst    (rst),
      .a_in   (a_in),
      .b_in   (b_in),
      .hold   (hold),
      .count  (bcd_count),
      .rd_data(bcd_rd),
      .glitch (bcd_glitch),
      .error  (bcd_err),
      .rco_n  (bcd_rco_n)
  );

  enc_phase_meter #(
      .WINDOW_LOG2(WINDOW_LOG2)
  ) u_pm (
      .clk      (clk),
      .rst      (mrst),
      .a        (a),
      .b        (b),
      .a_leads  (pm_a_leads),
      .b_leads  (pm_b_leads),
      .phase_err(pm_phase_err),
      .valid    (pm_valid)
  );

  enc_characterizer #(
      .CNT_W        (CNT_W),
      .WINDOW_CYCLES(WINDOW_CYCLES)
  ) u_char (
      .clk      (clk),
      .rst      (mrst),
      .a        (a),
      .b        (b),
      .min_state(MIN_STATE_W),
      .cycle_err(ch_cycle_err),
      .pulse_err(ch_pulse_err),
      .phase_err(ch_phase_err),
      .state_err(ch_state_err),
      .state_min(ch_state_min),
      .pass     (ch_pass),
      .valid    (ch_valid)
  );

  enc_qei_wb #(
      .COUNT_W(32),
      .TS_W   (32)
  ) u_qei (
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
      .z_in    (1'b0),
      .probe_in(1'b0),
      .snap_in (1'b0),
      .irq     (qei_irq),
      .cmp_out (qei_cmp)
  );

  always @(posedge clk) begin
    if (rst) begin
      x1_count   <= 32'sd0;
      x2_count   <= 32'sd0;
      x4_count   <= 32'sd0;
      n_glitch   <= 16'd0;
      n_x1_err   <= 16'd0;
      n_x2_err   <= 16'd0;
      n_x4_err   <= 16'd0;
      n_bcd_flag <= 16'd0;
    end else begin
      if (x1_up) x1_count <= x1_count + 32'sd1;
      else if (x1_dn) x1_count <= x1_count - 32'sd1;
      if (x2_pulse) x2_count <= x2_up ? x2_count + 32'sd1 : x2_count - 32'sd1;
      if (x4_pulse) x4_count <= x4_up ? x4_count + 32'sd1 : x4_count - 32'sd1;
      n_glitch   <= n_glitch + {15'd0, glitch};
      n_x1_err   <= n_x1_err + {15'd0, x1_err};
      n_x2_err   <= n_x2_err + {15'd0, x2_err};
      n_x4_err   <= n_x4_err + {15'd0, x4_err};
      n_bcd_flag <= n_bcd_flag + {15'd0, bcd_glitch | bcd_err};
    end
  end

endmodule

`default_nettype wire
