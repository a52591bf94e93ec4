// SPDX-License-Identifier: Apache-2.0
// enc_qei -- the quadrature encoder interface peripheral, 1 .. 16 channels, behind a one-clock
// request/response port; enc_qei_wb (Wishbone B4 classic) and enc_qei_axil (AXI4-Lite) are thin
// bus adapters around it.
//
//   req/resp <-> enc_qei_regs (generated from rtl/enc_qei.rdl): the global registers, and one
//                page of registers per channel (page k: channel k; page 0 also the globals)
//   enc_qei_timebase   one timebase for every channel (TB_PRESCALE, TIMEBASE)
//   enc_qei_snaptrig   the global snapshot (GSNAP_CTRL, GSNAP_PERIOD): one request, the same
//                      clock in every channel, and GSNAP_TIME
//   enc_qei_channel    x CHANNELS: conditioners, counting core, timing unit of one encoder
//
// The register block meets the rest through bundles: reg2hw_g / hw2reg_g for the global
// registers (fields by name: rtl/enc_qei_regs_fields.vh) and one pair per channel. irq is the OR
// of the channels' registered pending bits (IRQ_SUMMARY): high from the clock after an enabled
// event is pending until the clock after it is cleared or disabled.
// Request/response port: see enc_qei_regs (response two clocks after the request).
//
// Build options (defaults: one channel, the contract's full peripheral):
//   CHANNELS   channels, each with its own encoder inputs, cmp_out bit and register page
//   ADDR_W     byte address bits: at least 8 + ceil(log2(CHANNELS)) (the default)
//   PROFILE    which units every channel has (CAPS.PROFILE; a unit left out reads 0, no bus error):
//                2 full      everything
//                1 counting  no timing unit (TIMEBASE .. STALL_TIMEOUT, PROBE_TIME read 0)
//                3 lean      count functions, free count, index, timebase, snapshots with edge
//                            time and deltas, QERR / GLITCH; no probe, compare, range modes,
//                            period capture, stall or per-channel unit timer; COUNT_W >= 32
//   EFIFO_LOG2 0: no edge-capture FIFO; 1 .. 8: every channel has one of 2^EFIFO_LOG2 entries
//              (CAPS.EFIFO_LOG2, EFIFO_* registers); needs the timing unit (PROFILE full or lean)
//   ENGINE     0 per_channel: enc_qei_channel x CHANNELS, as above; 1 shared: enc_qei_engine, one
//              engine that keeps every channel's registers in block RAM and visits them in turn,
//              with a small lane per channel for what must see every clock (CAPS.ENGINE; the
//              RDL gives what it shows later, and by how many clocks at most); with EFIFO_LOG2
//              > 0 the channels' edge FIFOs sit beside it (enc_qei_efifo_bank, one FIFO per
//              channel fed by its lane, their EFIFO_* registers answered there)
//   FUNC_MASK  the count functions built, bit F for CTRL.FUNC value F (default: all). With one
//              bit set the function is fixed: CTRL.FUNC reads it and ignores writes, and the
//              decode logic of the others is left out. With several, a CTRL.FUNC value outside
//              the mask counts nothing.
`default_nettype none
`include "enc_params.vh"

module enc_qei #(
    parameter integer CHANNELS   = 1,    // encoder channels
    parameter integer ADDR_W     = `ENC_QEI_ADDR_W(CHANNELS),  // byte address bits
    parameter integer COUNT_W    = 32,   // counter width in bits
    parameter integer TS_W       = 32,   // timebase / timestamp width in bits
    parameter integer PROFILE    = 2,    // 2 full, 1 counting, 3 lean (see above)
    parameter integer FUNC_MASK  = `ENC_QEI_FUNC_ALL,  // count functions built: bit F = CTRL.FUNC value F
    parameter integer EFIFO_LOG2 = 0,    // edge-capture FIFO of 2^EFIFO_LOG2 entries per channel, 0: none
    parameter integer ENGINE     = 0     // 0: a datapath per channel, 1: one shared engine (see above)
) (
    input  wire                clk,
    input  wire                rst,         // synchronous, active high
    input  wire                req_valid,   // one-clock request
    input  wire                req_write,   // 1 = write
    input  wire [ADDR_W-1:0]   req_addr,    // byte address (bits 1:0 ignored)
    input  wire [31:0]         req_wdata,
    input  wire [3:0]          req_wstrb,   // byte enables
    output wire                resp_valid,  // two clocks after req_valid (one request at a time)
    output wire [31:0]         resp_rdata,
    output wire                resp_err,    // no register at that address
    input  wire [CHANNELS-1:0] a_in,        // encoder channel A of each channel, asynchronous
    input  wire [CHANNELS-1:0] b_in,        // encoder channel B, asynchronous
    input  wire [CHANNELS-1:0] z_in,        // index channel, asynchronous
    input  wire [CHANNELS-1:0] probe_in,    // external latch input, asynchronous
    input  wire                snap_in,     // synchronous snapshot strobe (every channel)
    output wire                irq,         // any channel has an enabled pending event
    output wire [CHANNELS-1:0] cmp_out      // one-clock pulse on a compare match, per channel
);

  generate
    `ENC_CHECK_CHANNELS
    `ENC_CHECK_ADDR_W
    `ENC_CHECK_COUNT_W
    `ENC_CHECK_TS_W
    `ENC_CHECK_PROFILE
    `ENC_CHECK_FUNC_MASK
    `ENC_CHECK_EFIFO_LOG2
    `ENC_CHECK_ENGINE
    // (ADDR_W must hold the pages: a relation enc_ip.core's ranges cannot hold)
    if ((1 << (ADDR_W - 8)) < CHANNELS) begin : g_bad_addr_w_pages
`ifdef __ICARUS__
      enc_qei__parameter_ADDR_W_must_be_at_least_8_plus_log2_CHANNELS u_stop ();
`else
      $error("enc_qei: parameter ADDR_W must be at least 8 + ceil(log2(CHANNELS))");
`endif
    end
  endgenerate

  `include "enc_qei_regs.vh"

  // the units of each profile (the register block's features)
  localparam integer P_FULL = {29'd0, ENC_QEI_PROFILE_FULL};
  localparam integer P_LEAN = {29'd0, ENC_QEI_PROFILE_LEAN};
  localparam integer P_CNT  = {29'd0, ENC_QEI_PROFILE_COUNTING};
  localparam integer TIMING = (PROFILE == P_FULL || PROFILE == P_LEAN) ? 1 : 0;
  localparam integer RANGE  = (PROFILE == P_FULL || PROFILE == P_CNT) ? 1 : 0;
  localparam integer PROBE  = RANGE;
  localparam integer PERIOD = (PROFILE == P_FULL) ? 1 : 0;
  localparam integer EFIFO  = (EFIFO_LOG2 > 0) ? 1 : 0;

  generate
    // (the lean profile's count is a free-running 32..64-bit count)
    if (PROFILE == P_LEAN && COUNT_W < 32) begin : g_bad_lean_count_w
`ifdef __ICARUS__
      enc_qei__parameter_COUNT_W_must_be_at_least_32_with_PROFILE_lean u_stop ();
`else
      $error("enc_qei: PROFILE lean (3) needs COUNT_W of at least 32");
`endif
    end
    // (the edge FIFO timestamps with the timing unit's timebase)
    if (EFIFO_LOG2 > 0 && TIMING == 0) begin : g_bad_efifo_profile
`ifdef __ICARUS__
      enc_qei__parameter_EFIFO_LOG2_needs_PROFILE_full_or_lean u_stop ();
`else
      $error("enc_qei: parameter EFIFO_LOG2 > 0 needs the timing unit (PROFILE 2 full or 3 lean)");
`endif
    end
  endgenerate

  // The code of the one count function FUNC_MASK builds, or -1 when it builds several.
  function integer single_func;
    input integer mask;
    integer f;
    begin
      single_func = -1;
      for (f = 0; f < ENC_QEI_FUNC_N; f = f + 1) begin
        if (mask == (1 << f)) begin
          single_func = f;
        end
      end
    end
  endfunction

  localparam integer FIXED_FUNC = single_func(FUNC_MASK);

  function [31:0] zext_ts;
    input [TS_W-1:0] v;
    begin
      zext_ts = 32'd0;
      zext_ts[TS_W-1:0] = v;
    end
  endfunction

  // ---- register block and its bundles ----------------------------------------------------------
  wire [ENC_QEI_R2H_W-1:0]             reg2hw_g;
  wire [ENC_QEI_H2R_W-1:0]             hw2reg_g;
  wire [CHANNELS*ENC_QEI_R2H_CH_W-1:0] reg2hw_ch;
  wire [CHANNELS*ENC_QEI_H2R_CH_W-1:0] hw2reg_ch;
  `include "enc_qei_regs_fields.vh"

  // With the shared engine, a request for a channel register of a built page goes to the engine;
  // everything else (the global registers, unmapped offsets: their error) to the register block.
  function [15:0] zext16;
    input [ADDR_W-1:0] a;
    begin
      zext16 = 16'd0;
      zext16[ADDR_W-1:0] = a;
    end
  endfunction

  wire [15:0] addr16 = zext16(req_addr);
  wire        is_glb = (addr16[15:8] == 8'd0) &
                       ((addr16[7:2] == ENC_QEI_ID[7:2]) | (addr16[7:2] == ENC_QEI_CAPS[7:2]) |
                        (addr16[7:2] == ENC_QEI_TIMEBASE[7:2]) | (addr16[7:2] == ENC_QEI_TB_PRESCALE[7:2]) |
                        (addr16[7:2] == ENC_QEI_GSNAP_CTRL[7:2]) | (addr16[7:2] == ENC_QEI_GSNAP_PERIOD[7:2]) |
                        (addr16[7:2] == ENC_QEI_GSNAP_TIME[7:2]) | (addr16[7:2] == ENC_QEI_IRQ_SUMMARY[7:2]));
  wire        is_ef  = (addr16[7:2] == ENC_QEI_EFIFO_CTRL[7:2]) | (addr16[7:2] == ENC_QEI_EFIFO_STATUS[7:2]) |
                       (addr16[7:2] == ENC_QEI_EFIFO_ENTRY[7:2]) | (addr16[7:2] == ENC_QEI_EFIFO_TIME[7:2]) |
                       (addr16[7:2] == ENC_QEI_EFIFO_LOST[7:2]);
  wire        to_pg  = (ENGINE != 0) & ~is_glb & enc_qei_mapped(addr16, CHANNELS);
  wire        to_ef  = to_pg & (EFIFO != 0) & is_ef;  // (the engine's edge FIFOs)
  wire        to_eng = to_pg & ~to_ef;
  wire        regs_resp_valid, regs_resp_err, eng_resp_valid, ef_resp_valid;
  wire [31:0] regs_resp_rdata, eng_resp_rdata, ef_resp_rdata;

  assign resp_valid = regs_resp_valid | eng_resp_valid | ef_resp_valid;
  assign resp_rdata = regs_resp_rdata | eng_resp_rdata | ef_resp_rdata;
  assign resp_err   = regs_resp_err;

  enc_qei_regs #(
      .CH_PAGES  ((ENGINE == 0) ? 1 : 0),
      .TIMING    (TIMING),
      .RANGE     (RANGE),
      .PROBE     (PROBE),
      .PERIOD    (PERIOD),
      .EFIFO     (EFIFO),
      .FIXED_FUNC(FIXED_FUNC),
      .CHANNELS  (CHANNELS),
      .ADDR_W    (ADDR_W),
      .COUNT_W   (COUNT_W),
      .TS_W      (TS_W)
  ) u_regs (
      .clk       (clk),
      .rst       (rst),
      .req_valid (req_valid & ~to_pg),
      .req_write (req_write),
      .req_addr  (req_addr),
      .req_wdata (req_wdata),
      .req_wstrb (req_wstrb),
      .resp_valid(regs_resp_valid),
      .resp_rdata(regs_resp_rdata),
      .resp_err  (regs_resp_err),
      .reg2hw_g  (reg2hw_g),
      .hw2reg_g  (hw2reg_g),
      .reg2hw_ch (reg2hw_ch),
      .hw2reg_ch (hw2reg_ch)
  );

  localparam [7:0] COUNT_W8   = COUNT_W[7:0];
  localparam [7:0] TS_W8      = TS_W[7:0];
  localparam [2:0] PROFILE3   = PROFILE[2:0];
  localparam [4:0] CHANNELS5  = CHANNELS[4:0];
  localparam [3:0] EFIFO_LOG24 = EFIFO_LOG2[3:0];
  localparam [0:0] ENGINE1     = ENGINE[0:0];

  assign h2r_caps_count_w  = COUNT_W8;
  assign h2r_caps_ts_w     = TS_W8;
  assign h2r_caps_index    = 1'b1;
  assign h2r_caps_probe    = (PROBE != 0);
  assign h2r_caps_timing   = (TIMING != 0);
  assign h2r_caps_profile  = PROFILE3;
  assign h2r_caps_channels = CHANNELS5;
  assign h2r_caps_efifo_log2 = EFIFO_LOG24;
  assign h2r_caps_engine     = ENGINE1;

  // ---- the timebase and the global snapshot: one for every channel -------------------------
  wire [TS_W-1:0] timebase;
  wire            tick, gsnap_req;
  wire            gsnap;  // the global snapshot is taken (the engine may take a request late)

  generate
    if (TIMING != 0) begin : g_timebase
      reg [TS_W-1:0] gsnap_time_q;

      enc_qei_timebase #(
          .TS_W(TS_W)
      ) u_timebase (
          .clk     (clk),
          .rst     (rst),
          .prescale(r2h_tb_prescale_prescale),
          .timebase(timebase),
          .tick    (tick)
      );

      enc_qei_snaptrig #(
          .TS_W (TS_W),
          .TIMER(1)
      ) u_gsnap (
          .clk      (clk),
          .rst      (rst),
          .tick     (tick),
          .cmd      (r2h_gsnap_ctrl_cmd),
          .snap_in  (snap_in),
          .in_en    (r2h_gsnap_ctrl_in_en),
          .period_en(r2h_gsnap_ctrl_period_en),
          .period   (r2h_gsnap_period[TS_W-1:0]),
          .req      (gsnap_req)
      );

      always @(posedge clk) begin
        if (rst) begin
          gsnap_time_q <= {TS_W{1'b0}};
        end else if (gsnap) begin
          gsnap_time_q <= timebase;
        end
      end

      assign h2r_gsnap_time = zext_ts(gsnap_time_q);
    end else begin : g_no_timebase
      wire unused_gsnap = &{1'b0, gsnap};
      assign timebase       = {TS_W{1'b0}};
      assign tick           = 1'b0;
      assign gsnap_req      = 1'b0;
      assign h2r_gsnap_time = 32'd0;
    end
  endgenerate

  assign h2r_timebase = zext_ts(timebase);

  // ---- the channels ----------------------------------------------------------------------------------
  wire [CHANNELS-1:0] irq_pend;

  genvar ch;
  generate
    if (ENGINE == 0) begin : g_per_channel
      assign gsnap          = gsnap_req;
      assign eng_resp_valid = 1'b0;
      assign eng_resp_rdata = 32'd0;
      assign ef_resp_valid  = 1'b0;
      assign ef_resp_rdata  = 32'd0;
      wire unused_to_eng    = &{1'b0, to_eng};  // (the register block takes every request)

      for (ch = 0; ch < CHANNELS; ch = ch + 1) begin : g_ch
        enc_qei_channel #(
            .COUNT_W   (COUNT_W),
            .TS_W      (TS_W),
            .FUNC_MASK (FUNC_MASK),
            .FIXED_FUNC(FIXED_FUNC),
            .TIMING    (TIMING),
            .RANGE     (RANGE),
            .PROBE     (PROBE),
            .PERIOD    (PERIOD),
            .EFIFO_LOG2(EFIFO_LOG2)
        ) u_chan (
            .clk     (clk),
            .rst     (rst),
            .reg2hw  (reg2hw_ch[ch*ENC_QEI_R2H_CH_W +: ENC_QEI_R2H_CH_W]),
            .hw2reg  (hw2reg_ch[ch*ENC_QEI_H2R_CH_W +: ENC_QEI_H2R_CH_W]),
            .a_in    (a_in[ch]),
            .b_in    (b_in[ch]),
            .z_in    (z_in[ch]),
            .probe_in(probe_in[ch]),
            .snap_in (snap_in),
            .timebase(timebase),
            .tick    (tick),
            .gsnap   (gsnap),
            .cmp_out (cmp_out[ch]),
            .irq_pend(irq_pend[ch])
        );
      end
    end else begin : g_engine
      wire [CHANNELS-1:0]   step_up, step_dn, idx_hit, ef_thresh, ef_ovf;
      wire [2*CHANNELS-1:0] step_ab;

      // (the channel pages are the engine's: the register block has none)
      wire unused_pages = &{1'b0, reg2hw_ch};
      for (ch = 0; ch < CHANNELS; ch = ch + 1) begin : g_no_page
        assign hw2reg_ch[ch*ENC_QEI_H2R_CH_W +: ENC_QEI_H2R_CH_W] = {ENC_QEI_H2R_CH_W{1'b0}};
      end

      enc_qei_engine #(
          .CHANNELS  (CHANNELS),
          .COUNT_W   (COUNT_W),
          .TS_W      (TS_W),
          .FUNC_MASK (FUNC_MASK),
          .FIXED_FUNC(FIXED_FUNC),
          .TIMING    (TIMING),
          .RANGE     (RANGE),
          .PROBE     (PROBE),
          .PERIOD    (PERIOD),
          .EFIFO     (EFIFO)
      ) u_engine (
          .clk       (clk),
          .rst       (rst),
          .req_valid (req_valid & to_eng),
          .req_write (req_write),
          .req_ch    (addr16[11:8]),
          .req_word  (addr16[7:2]),
          .req_wdata (req_wdata),
          .req_wstrb (req_wstrb),
          .resp_valid(eng_resp_valid),
          .resp_rdata(eng_resp_rdata),
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
          .ef_thresh (ef_thresh),
          .ef_ovf    (ef_ovf)
      );

      // the edge FIFOs: one per channel, beside the engine (their registers are answered there)
      if (EFIFO != 0) begin : g_efifo
        enc_qei_efifo_bank #(
            .CHANNELS  (CHANNELS),
            .DEPTH_LOG2(EFIFO_LOG2),
            .TS_W      (TS_W)
        ) u_efifo_bank (
            .clk       (clk),
            .rst       (rst),
            .timebase  (timebase),
            .req_valid (req_valid & to_ef),
            .req_write (req_write),
            .req_ch    (addr16[11:8]),
            .req_word  (addr16[7:2]),
            .req_wdata (req_wdata),
            .req_wstrb (req_wstrb),
            .resp_valid(ef_resp_valid),
            .resp_rdata(ef_resp_rdata),
            .step_up   (step_up),
            .step_dn   (step_dn),
            .step_ab   (step_ab),
            .idx_hit   (idx_hit),
            .ev_thresh (ef_thresh),
            .ev_ovf    (ef_ovf)
        );
      end else begin : g_no_efifo
        wire unused_steps = &{1'b0, step_up, step_dn, step_ab, idx_hit};
        assign ef_thresh     = {CHANNELS{1'b0}};
        assign ef_ovf        = {CHANNELS{1'b0}};
        assign ef_resp_valid = 1'b0;
        assign ef_resp_rdata = 32'd0;
      end
    end
  endgenerate

  // ---- interrupt summary --------------------------------------------------------------------------
  // irq_pend, bit k for channel k (a continuous assignment: a block of irq_pend alone would not
  // run in a simulation whose irq_pend starts at its final value, and would leave this undefined)
  generate
    if (CHANNELS < 16) begin : g_pending
      assign h2r_irq_summary_pending = {{(16 - CHANNELS){1'b0}}, irq_pend};
    end else begin : g_pending_all
      assign h2r_irq_summary_pending = irq_pend;
    end
  endgenerate
  assign irq = |irq_pend;

endmodule

`default_nettype wire
