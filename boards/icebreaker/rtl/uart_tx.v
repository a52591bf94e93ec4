// SPDX-License-Identifier: Apache-2.0
// uart_tx -- 8N1 UART transmitter with a valid/ready byte input (board helper, not a contract
// block; used by icebreaker_top to print the count on the iCEBreaker's FTDI serial port).
//
// A byte is taken when `valid` and `ready` are both 1 at a clock edge; the line then carries one
// start bit (0), the eight data bits LSB first and one stop bit (1), each CLKS_PER_BIT clocks
// long, and `ready` returns high once the stop bit has been sent. `tx` idles high, and is high
// from the clock after `rst` (a synchronous reset, active high).
`default_nettype none
`include "enc_params.vh"

module uart_tx #(
    parameter integer CLKS_PER_BIT = 104  // clocks per bit (clock / baud): 2 .. 65535
) (
    input  wire       clk,
    input  wire       rst,    // synchronous, active high
    input  wire [7:0] data,   // byte to send, taken with valid & ready
    input  wire       valid,  // a byte is offered
    output wire       ready,  // idle: the next byte would be taken now
    output wire       tx      // serial line, idle high
);

  generate
    `ENC_CHECK_CLKS_PER_BIT
  endgenerate

  localparam integer DW = (CLKS_PER_BIT <= 2) ? 1 : $clog2(CLKS_PER_BIT);  // bit-timer width
  localparam integer LAST_INT = CLKS_PER_BIT - 1;
  localparam [DW-1:0] LAST = LAST_INT[DW-1:0];

  reg [8:0] shift_q;  // {data, start bit} still to send, LSB first; stop bit follows
  reg [8:0] shift_d;
  reg [3:0] bits_q;   // bits left in the frame, including the one on the line (0 = idle)
  reg [3:0] bits_d;
  reg [DW-1:0] div_q;  // clocks spent on the current bit
  reg [DW-1:0] div_d;
  reg tx_q;
  reg tx_d;

  wire idle = (bits_q == 4'd0);
  wire take = idle & valid;
  wire bit_end = (div_q == LAST);

  always @(*) begin
    shift_d = shift_q;
    bits_d  = bits_q;
    div_d   = div_q;
    tx_d    = tx_q;
    if (take) begin
      shift_d = {data, 1'b0};
      bits_d  = 4'd10;  // start + 8 data + stop
      div_d   = {DW{1'b0}};
      tx_d    = 1'b0;   // start bit
    end else if (!idle) begin
      if (bit_end) begin
        div_d   = {DW{1'b0}};
        bits_d  = bits_q - 4'd1;
        shift_d = {1'b1, shift_q[8:1]};  // shift in ones: the stop bit and then idle
        tx_d    = (bits_q == 4'd1) ? 1'b1 : shift_q[1];
      end else begin
        div_d = div_q + {{(DW - 1) {1'b0}}, 1'b1};
      end
    end
  end

  always @(posedge clk) begin
    if (rst) begin
      shift_q <= 9'h1ff;
      bits_q  <= 4'd0;
      div_q   <= {DW{1'b0}};
      tx_q    <= 1'b1;
    end else begin
      shift_q <= shift_d;
      bits_q  <= bits_d;
      div_q   <= div_d;
      tx_q    <= tx_d;
    end
  end

  assign ready = idle;
  assign tx    = tx_q;

endmodule

`default_nettype wire
