// SPDX-License-Identifier: Apache-2.0
// icebreaker_top -- the encoder interface on a 1BitSquared iCEBreaker (iCE40UP5K-SG48, 12 MHz).
//
// A HEDS-5000 on PMOD1A drives the library's blocks side by side:
//   enc_a/enc_b/enc_i -> enc_qei_wb (the QEI peripheral: FUNC x4, RANGE free, COUNT_W =
//                  POS_WIDTH, so COUNT_LO is the POS_WIDTH-bit two's complement 4X position), read
//                  over Wishbone by a small master in this top, the way firmware would
//   enc_a/enc_b -> enc_conditioner -> enc_phase_meter (Figure 11): red LED = A leads, green = B
//   enc_a/enc_b -> enc_updown_buffer (Figure 17: its own conditioner, 2X XOR, four 'LS168 BCD
//                  stages), read through rd_data with `hold` up for the whole report line, the
//                  way a microprocessor reads an HCTL-2016.
// The Wishbone master (B4 classic, one access at a time) writes CTRL once after reset (EN = 1,
// FUNC = x4, RANGE = free, FILTER_LEN = this top's FILTER_LEN), then at the start of every report
// line reads COUNT_LO, reads EVENTS and writes back to EVENTS the QERR, GLITCH and INDEX bits it
// read (write 1 to clear: an event arriving between the read and the write stays pending for the
// next line). An access ends with wb_ack_o or wb_err_o (an error reads 0; none is expected, the
// offsets are mapped).
// LINE_HZ times a second (default 10) a line goes out on the FTDI serial port (115200 8N1):
//   P=+0001234 B=0617 PH=-001.25 F=EGI<CR><LF>
//   P   4X position (COUNT_LO), signed decimal (sign and ND digits: 7 for POS_WIDTH = 24)
//   B   the 2X BCD buffer (4 digits, counts modulo 10000)
//   PH  the phase meter's last reading, phase - 90 degrees, in degrees with two decimals
//       ("the phase meter reads zero at the adjustment point"; 0 until the first window ends)
//   F   the peripheral's events since the previous line, '-' when clear: E = EVENTS.QERR
//       (illegal transition, the 4X count may be wrong), G = EVENTS.GLITCH (a level rejected by
//       the peripheral's input filter), I = EVENTS.INDEX (rising edge of the filtered index)
// Phase is sampled and B frozen by `hold` at the start of the line; COUNT_LO and EVENTS are read
// in the next few clocks (the bus accesses take 2 clocks each).
//
// Pins (boards/icebreaker/icebreaker.pcf): clk 35 (12 MHz oscillator), btn_n 10 (user button, reset
// while pressed), tx 9 (FTDI channel B RX, i.e. the board's UART output), led_r_n 11 and
// led_g_n 37 (active low), PMOD1A: enc_a = P1A1 (pin 4), enc_b = P1A2 (pin 2),
// enc_i = P1A3 (pin 47); encoder ground on PMOD1A pin 5/11. The HEDS-5000 needs 5 V and has
// TTL outputs; the iCE40's I/O banks are 3.3 V and not 5 V tolerant, so bring A, B and I in
// through a 3.3 V buffer with 5 V tolerant inputs (e.g. 74LVC125) or a resistor divider.
//
// Reset: at configuration every iCE40 flip-flop is 0; a 4-bit power-on counter holds `rst` for
// 16 clocks, and the user button asserts it while pressed (synchronized). All blocks reset
// synchronously from that.
`default_nettype none
`include "enc_params.vh"

module icebreaker_top #(
    parameter integer CLK_HZ            = 12_000_000,  // clk frequency: >= 2 * BAUD
    parameter integer BAUD              = 115_200,     // UART bit rate (8N1)
    parameter integer LINE_HZ           = 10,          // report lines per second: 1 .. CLK_HZ/64
    parameter integer FILTER_LEN        = 3,           // input filters and CTRL.FILTER_LEN, 1 .. 16
    parameter integer PHASE_WINDOW_LOG2 = 20,          // phase meter window 2^N clocks, 8 .. 24
    parameter integer POS_WIDTH         = 24           // 4X position bits (enc_qei COUNT_W): 8 .. 31
) (
    input  wire clk,      // 12 MHz oscillator, pin 35
    input  wire btn_n,    // user button, active low: reset
    input  wire enc_a,    // encoder channel A (PMOD1A pin 1), asynchronous
    input  wire enc_b,    // encoder channel B (PMOD1A pin 2), asynchronous
    input  wire enc_i,    // encoder index (PMOD1A pin 3), asynchronous
    output wire tx,       // UART to the host, 8N1
    output wire led_r_n,  // red LED, active low: A leads (Figure 11)
    output wire led_g_n   // green LED, active low: B leads
);

  generate
    // (BAUD and LINE_HZ are bounded by CLK_HZ, a relation enc_ip.core's ranges cannot hold)
    if (CLK_HZ < 2 * BAUD || BAUD < 1) begin : g_bad_baud
`ifdef __ICARUS__
      icebreaker_top__parameter_BAUD_must_be_1_to_CLK_HZ_over_2 u_stop ();
`else
      $error("icebreaker_top: parameter BAUD must be in 1 .. CLK_HZ/2");
`endif
    end
    if (LINE_HZ < 1 || LINE_HZ > CLK_HZ / 64) begin : g_bad_line_hz
`ifdef __ICARUS__
      icebreaker_top__parameter_LINE_HZ_must_be_1_to_CLK_HZ_over_64 u_stop ();
`else
      $error("icebreaker_top: parameter LINE_HZ must be in 1 .. CLK_HZ/64");
`endif
    end
    `ENC_CHECK_POS_WIDTH
  endgenerate

  // ---- sizes -------------------------------------------------------------------------------------
  localparam integer CLKS_PER_BIT = (CLK_HZ + BAUD / 2) / BAUD;  // 104 at 12 MHz / 115200
  localparam integer LINE_CLKS = CLK_HZ / LINE_HZ;
  localparam integer LW = $clog2(LINE_CLKS);  // line timer width
  localparam integer LINE_LAST_INT = LINE_CLKS - 1;
  localparam [LW-1:0] LINE_LAST = LINE_LAST_INT[LW-1:0];
  // decimal digits of 2^(POS_WIDTH-1), the largest magnitude: floor(n * log10(2)) + 1
  localparam integer ND = (((POS_WIDTH - 1) * 1233) >> 12) + 1;
  localparam integer HW = 14;  // phase magnitude in 1/100 degree: <= 12800
  localparam integer CW = (POS_WIDTH > HW) ? POS_WIDTH : HW;  // converter input bits
  localparam integer NDC = (ND > 5) ? ND : 5;  // converter BCD digits
  localparam integer BUF_DIGITS = 4;

  // line template: index of each field
  localparam integer T_PSIGN = 2;  // "P=" then sign
  localparam integer T_PDIG = 3;  // ND digits
  localparam integer T_B = T_PDIG + ND;  // " B="
  localparam integer T_BDIG = T_B + 3;  // 4 digits
  localparam integer T_H = T_BDIG + BUF_DIGITS;  // " PH="
  localparam integer T_HSIGN = T_H + 4;
  localparam integer T_HDIG = T_HSIGN + 1;  // ddd.dd: 6 characters
  localparam integer T_F = T_HDIG + 6;  // " F="
  localparam integer T_FLAGS = T_F + 3;  // E G I
  localparam integer T_LAST = T_FLAGS + 4;  // CR at T_FLAGS + 3, LF at T_LAST

  // ---- reset -------------------------------------------------------------------------------------
  // Power-on values are the iCE40's configuration values (all flip-flops 0); they are given here
  // so that simulation starts the same way. Verilator's PROCASSINIT is waived for these three.
  /* verilator lint_off PROCASSINIT */
  reg  [3:0] por_q = 4'd0;  // power-on counter
  reg  [1:0] btn_q = 2'b00;  // button synchronizer, 1 = pressed
  reg        rst_n_q = 1'b0;  // 0 at configuration: reset active from the first clock
  /* verilator lint_on PROCASSINIT */
  wire       por_done = &por_q;
  wire       rst = ~rst_n_q;

  always @(posedge clk) begin
    if (!por_done) por_q <= por_q + 4'd1;
  end

  always @(posedge clk) begin
    btn_q   <= {btn_q[0], ~btn_n};
    rst_n_q <= por_done & ~btn_q[1];
  end

  // ---- QEI peripheral: the 4X position and the events ------------------------------------------
  // enc_qei registers: offsets, field positions and codes from the map (rtl/enc_qei_regs.vh,
  // generated from rtl/enc_qei.rdl)
  `include "enc_qei_regs.vh"
  localparam [31:0] FILTER_LEN32 = FILTER_LEN;
  localparam [31:0] CTRL_WORD = (32'd1 << ENC_QEI_CTRL_EN) |
                                ({28'd0, ENC_QEI_FUNC_X4} << ENC_QEI_CTRL_FUNC) |
                                ({30'd0, ENC_QEI_RANGE_FREE} << ENC_QEI_CTRL_RANGE) |
                                (FILTER_LEN32 << ENC_QEI_CTRL_FILTER_LEN);

  wire        wb_stb, wb_we, wb_ack, wb_err;
  reg  [ 7:0] wb_adr;
  reg  [31:0] wb_wdat;
  /* verilator lint_off UNUSEDSIGNAL */  // the master keeps COUNT_LO[POS_WIDTH-1:0] and 3 event bits
  wire [31:0] wb_rdat;
  /* verilator lint_on UNUSEDSIGNAL */

  /* verilator lint_off PINCONNECTEMPTY */
  enc_qei_wb #(
      .COUNT_W(POS_WIDTH),
      .TS_W   (16)         // the timing unit is not used: its smallest width
  ) u_qei (
      .clk     (clk),
      .rst     (rst),
      .wb_adr_i(wb_adr),
      .wb_dat_i(wb_wdat),
      .wb_dat_o(wb_rdat),
      .wb_sel_i(4'b1111),
      .wb_we_i (wb_we),
      .wb_stb_i(wb_stb),
      .wb_cyc_i(wb_stb),
      .wb_ack_o(wb_ack),
      .wb_err_o(wb_err),
      .a_in    (enc_a),
      .b_in    (enc_b),
      .z_in    (enc_i),
      .probe_in(1'b0),
      .snap_in (1'b0),
      .irq     (),          // the events are polled once per line
      .cmp_out ()
  );
  /* verilator lint_on PINCONNECTEMPTY */

  // ---- conditioner for the phase meter -------------------------------------------------------------
  wire a, b;

  /* verilator lint_off PINCONNECTEMPTY */
  enc_conditioner #(
      .FILTER_LEN(FILTER_LEN)
  ) u_cond (
      .clk   (clk),
      .rst   (rst),
      .a_in  (enc_a),
      .b_in  (enc_b),
      .a     (a),
      .b     (b),
      .glitch(),       // the G flag is the peripheral's EVENTS.GLITCH
      .valid ()        // the phase meter waits for its first window anyway
  );
  /* verilator lint_on PINCONNECTEMPTY */

  // ---- 2X BCD buffer (Figure 17) ----------------------------------------------------------------
  reg                     hold_q;
  wire [4*BUF_DIGITS-1:0] buf_rd;

  /* verilator lint_off PINCONNECTEMPTY */
  /* verilator lint_off PINMISSING */
  enc_updown_buffer #(
      .DIGITS    (BUF_DIGITS),
      .MODULUS   (10),
      .FILTER_LEN(FILTER_LEN)
  ) u_buf (
      .clk    (clk),
      .rst    (rst),
      .a_in   (enc_a),
      .b_in   (enc_b),
      .hold   (hold_q),
      .count  (),         // the live count is not shown: the report reads rd_data
      .rd_data(buf_rd)
  );
  /* verilator lint_on PINMISSING */
  /* verilator lint_on PINCONNECTEMPTY */

  // ---- phase meter (Figure 11) -----------------------------------------------------------------
  wire a_leads, b_leads, phase_valid;
  wire signed [15:0] phase_err;
  reg signed [15:0] phase_q;  // last reading, 1/256 degree

  enc_phase_meter #(
      .WINDOW_LOG2(PHASE_WINDOW_LOG2)
  ) u_phase (
      .clk      (clk),
      .rst      (rst),
      .a        (a),
      .b        (b),
      .a_leads  (a_leads),
      .b_leads  (b_leads),
      .phase_err(phase_err),
      .valid    (phase_valid)
  );

  always @(posedge clk) begin
    if (rst) begin
      phase_q <= 16'sd0;
    end else if (phase_valid) begin
      phase_q <= phase_err;
    end
  end

  assign led_r_n = ~a_leads;
  assign led_g_n = ~b_leads;

  // ---- line timer --------------------------------------------------------------------------------
  reg [LW-1:0] tick_q;
  reg          line_req_q;  // a line is due
  wire         tick = (tick_q == LINE_LAST);

  always @(posedge clk) begin
    if (rst || tick) tick_q <= {LW{1'b0}};
    else tick_q <= tick_q + {{(LW - 1) {1'b0}}, 1'b1};
  end

  // ---- report sequencer ---------------------------------------------------------------------------
  localparam [1:0] S_IDLE = 2'd0, S_BUS = 2'd1, S_CONV = 2'd2, S_SEND = 2'd3;

  reg [1:0] st_q, st_d;
  reg [5:0] ci_q, ci_d;  // template index of the character being sent
  reg conv_ok_q, conv_ok_d;  // the phase is in bcd_q (the position is converted at the start)
  reg [CW-1:0] sh_q, sh_d;  // binary -> BCD converter: bits still to shift in
  reg [4*NDC-1:0] bcd_q, bcd_d;
  reg [5:0] conv_n_q, conv_n_d;  // shifts left
  reg line_req_d, hold_d;
  // phase snapshot taken at the start of a line (the position and flags are the master's reads)
  reg ph_neg_q, ph_neg_d;
  reg [HW-1:0] ph_mag_q, ph_mag_d;

  // ---- Wishbone master: the firmware's part ----------------------------------------------------------
  // After reset: CTRL <= CTRL_WORD. Per line (the sequencer waits in S_BUS): cnt = COUNT_LO;
  // ev = EVENTS; EVENTS <= ev & (QERR | GLITCH | INDEX). cyc = stb for the whole access; each
  // access holds its address and data until wb_ack / wb_err, and the next one starts in the
  // following clock.
  localparam [2:0] M_CTRL = 3'd0, M_IDLE = 3'd1, M_CNT = 3'd2, M_EVR = 3'd3, M_EVW = 3'd4;

  reg [2:0] m_q, m_d;
  reg [POS_WIDTH-1:0] cnt_q, cnt_d;  // COUNT_LO of this line: the 4X position
  reg [2:0] ev_q, ev_d;  // {INDEX, GLITCH, QERR} read from EVENTS for this line
  wire wb_end = wb_ack | wb_err;
  wire bus_done = (m_q == M_EVW) & wb_end;  // the line's reads and the clear are done

  assign wb_stb = (m_q != M_IDLE);
  assign wb_we  = (m_q == M_CTRL) | (m_q == M_EVW);

  always @(*) begin
    m_d     = m_q;
    cnt_d   = cnt_q;
    ev_d    = ev_q;
    wb_adr  = ENC_QEI_EVENTS;
    wb_wdat = 32'd0;
    case (m_q)
      M_CTRL: begin
        wb_adr  = ENC_QEI_CTRL;
        wb_wdat = CTRL_WORD;
        if (wb_end) m_d = M_IDLE;
      end
      M_IDLE: begin
        if (st_q == S_BUS) m_d = M_CNT;
      end
      M_CNT: begin
        wb_adr = ENC_QEI_COUNT_LO;
        if (wb_end) begin
          cnt_d = wb_rdat[POS_WIDTH-1:0];
          m_d   = M_EVR;
        end
      end
      M_EVR: begin
        if (wb_end) begin
          ev_d = {wb_rdat[ENC_QEI_EVENTS_INDEX], wb_rdat[ENC_QEI_EVENTS_GLITCH], wb_rdat[ENC_QEI_EVENTS_QERR]};
          m_d  = M_EVW;
        end
      end
      default: begin  // M_EVW: write 1 to clear what was read
        wb_wdat[ENC_QEI_EVENTS_INDEX]  = ev_q[2];
        wb_wdat[ENC_QEI_EVENTS_GLITCH] = ev_q[1];
        wb_wdat[ENC_QEI_EVENTS_QERR]   = ev_q[0];
        if (wb_end) m_d = M_IDLE;
      end
    endcase
  end

  always @(posedge clk) begin
    if (rst) begin
      m_q  <= M_CTRL;
      ev_q <= 3'b000;
    end else begin
      m_q  <= m_d;
      ev_q <= ev_d;
    end
  end

  // read before it is shown on every line: no reset needed
  always @(posedge clk) begin
    cnt_q <= cnt_d;
  end

  // phase in 1/100 degree: |phase_err| * 100 / 256, rounded
  wire        ph_neg = phase_q[15];
  wire [15:0] ph_abs = (phase_q ^ {16{ph_neg}}) + {15'd0, ph_neg};  // |phase_q|
  /* verilator lint_off UNUSEDSIGNAL */  // bits 5:0 are the rounded-off fraction, 21:20 always 0
  wire [21:0] ph_x25 = {6'd0, ph_abs} * 22'd25 + 22'd32;
  /* verilator lint_on UNUSEDSIGNAL */
  wire [HW-1:0] ph_hund = ph_x25[6+HW-1:6];
  wire        pos_neg = cnt_q[POS_WIDTH-1];  // COUNT_LO as a POS_WIDTH-bit signed number
  wire [POS_WIDTH-1:0] pos_abs = (cnt_q ^ {POS_WIDTH{pos_neg}}) + {{(POS_WIDTH - 1) {1'b0}}, pos_neg};

  // the two numbers, zero-extended to the converter width
  wire [CW-1:0] pos_mag_cw, ph_mag_cw;
  generate
    if (CW > POS_WIDTH) begin : g_pos_ext
      assign pos_mag_cw = {{(CW - POS_WIDTH) {1'b0}}, pos_abs};
    end else begin : g_pos_same
      assign pos_mag_cw = pos_abs;
    end
    if (CW > HW) begin : g_ph_ext
      assign ph_mag_cw = {{(CW - HW) {1'b0}}, ph_mag_q};
    end else begin : g_ph_same
      assign ph_mag_cw = ph_mag_q;
    end
  endgenerate

  // double dabble: add 3 to every BCD digit >= 5 before each shift
  /* verilator lint_off UNUSEDSIGNAL */  // the top bit of the top digit is never 1 (digits <= 9)
  wire [4*NDC-1:0] bcd_adj;
  /* verilator lint_on UNUSEDSIGNAL */
  genvar gi;
  generate
    for (gi = 0; gi < NDC; gi = gi + 1) begin : g_dabble
      wire [3:0] dig = bcd_q[4*gi+:4];
      assign bcd_adj[4*gi+:4] = (dig >= 4'd5) ? dig + 4'd3 : dig;
    end
  endgenerate

  // character at template index ci_q; dig_q is the digit of the field being sent (most
  // significant first), loaded as the field starts and counted down
  wire [31:0] ci = {26'd0, ci_q};
  reg  [3:0] dig_q, dig_d;
  wire [3:0] bcd_dig = bcd_q[4*dig_q+:4];
  wire [3:0] buf_dig = buf_rd[4*dig_q[1:0]+:4];
  wire in_pos = (ci >= T_PDIG) && (ci < T_PDIG + ND);
  wire in_buf = (ci >= T_BDIG) && (ci < T_BDIG + BUF_DIGITS);
  wire in_ph = (ci >= T_HDIG) && (ci < T_HDIG + 6) && (ci != T_HDIG + 3);
  reg  [7:0] ch;
  wire       tx_ready;
  reg        tx_valid;

  always @(*) begin
    ch = " ";
    if (in_pos || in_ph) begin
      ch = {4'h3, bcd_dig};
    end else if (in_buf) begin
      ch = {4'h3, buf_dig};
    end else if (ci == T_PSIGN) begin
      ch = pos_neg ? "-" : "+";
    end else if (ci == T_HSIGN) begin
      ch = ph_neg_q ? "-" : "+";
    end else if (ci == T_HDIG + 3) begin
      ch = ".";
    end else if (ci == 0) begin
      ch = "P";
    end else if (ci == 1 || ci == T_B + 2 || ci == T_H + 3 || ci == T_F + 2) begin
      ch = "=";
    end else if (ci == T_B + 1) begin
      ch = "B";
    end else if (ci == T_H + 1) begin
      ch = "P";
    end else if (ci == T_H + 2) begin
      ch = "H";
    end else if (ci == T_F + 1) begin
      ch = "F";
    end else if (ci == T_FLAGS) begin
      ch = ev_q[0] ? "E" : "-";
    end else if (ci == T_FLAGS + 1) begin
      ch = ev_q[1] ? "G" : "-";
    end else if (ci == T_FLAGS + 2) begin
      ch = ev_q[2] ? "I" : "-";
    end else if (ci == T_FLAGS + 3) begin
      ch = 8'h0d;
    end else if (ci == T_LAST) begin
      ch = 8'h0a;
    end
  end

  // first digit of each field, as the field starts (after the sign, after "B=")
  localparam integer ND_TOP_INT = ND - 1;
  localparam [3:0] ND_TOP = ND_TOP_INT[3:0];


  always @(*) begin
    st_d       = st_q;
    ci_d       = ci_q;
    conv_ok_d  = conv_ok_q;
    dig_d      = dig_q;
    sh_d       = sh_q;
    bcd_d      = bcd_q;
    conv_n_d   = conv_n_q;
    line_req_d = line_req_q | tick;
    hold_d     = hold_q;
    ph_neg_d   = ph_neg_q;
    ph_mag_d   = ph_mag_q;
    tx_valid   = 1'b0;
    case (st_q)
      S_IDLE: begin
        if (line_req_q) begin
          line_req_d = tick;
          hold_d     = 1'b1;
          ci_d       = 6'd0;
          conv_ok_d  = 1'b0;
          ph_neg_d   = ph_neg;
          ph_mag_d   = ph_hund;
          st_d       = S_BUS;  // the master reads COUNT_LO and EVENTS
        end
      end
      S_BUS: begin
        if (bus_done) begin
          sh_d     = pos_mag_cw;  // convert the position right away
          bcd_d    = {4 * NDC{1'b0}};
          conv_n_d = CW[5:0];
          st_d     = S_CONV;
        end
      end
      S_CONV: begin
        bcd_d    = {bcd_adj[4*NDC-2:0], sh_q[CW-1]};
        sh_d     = {sh_q[CW-2:0], 1'b0};
        conv_n_d = conv_n_q - 6'd1;
        if (conv_n_q == 6'd1) begin
          conv_ok_d = 1'b1;
          st_d      = S_SEND;
        end
      end
      default: begin  // S_SEND
        if (ci == T_HSIGN && !conv_ok_q) begin
          sh_d     = ph_mag_cw;
          bcd_d    = {4 * NDC{1'b0}};
          conv_n_d = CW[5:0];
          st_d     = S_CONV;
        end else begin
          tx_valid = 1'b1;
          if (tx_ready) begin
            conv_ok_d = 1'b0;
            if (ci == T_PSIGN) dig_d = ND_TOP;
            else if (ci == T_B + 2) dig_d = 4'd3;
            else if (ci == T_HSIGN) dig_d = 4'd4;
            else if (in_pos || in_buf || in_ph) dig_d = dig_q - 4'd1;
            if (ci == T_LAST) begin
              hold_d = 1'b0;
              st_d   = S_IDLE;
            end else begin
              ci_d = ci_q + 6'd1;
            end
          end
        end
      end
    endcase
  end

  always @(posedge clk) begin
    if (rst) begin
      st_q       <= S_IDLE;
      ci_q       <= 6'd0;
      conv_ok_q  <= 1'b0;
      line_req_q <= 1'b0;
      hold_q     <= 1'b0;
    end else begin
      st_q       <= st_d;
      ci_q       <= ci_d;
      conv_ok_q  <= conv_ok_d;
      line_req_q <= line_req_d;
      hold_q     <= hold_d;
    end
  end

  // data path registers: no reset needed (written before they are read on every line)
  always @(posedge clk) begin
    sh_q      <= sh_d;
    bcd_q     <= bcd_d;
    conv_n_q  <= conv_n_d;
    dig_q     <= dig_d;
    ph_neg_q  <= ph_neg_d;
    ph_mag_q  <= ph_mag_d;
  end

  // ---- UART ----------------------------------------------------------------------------------------
  uart_tx #(
      .CLKS_PER_BIT(CLKS_PER_BIT)
  ) u_tx (
      .clk  (clk),
      .rst  (rst),
      .data (ch),
      .valid(tx_valid),
      .ready(tx_ready),
      .tx   (tx)
  );

endmodule

`default_nettype wire
