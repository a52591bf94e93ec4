// SPDX-License-Identifier: Apache-2.0
// enc_qei_timing -- the timing unit of enc_qei: the timebase with its prescaler.
//
// TIMEBASE is a free-running TS_W-bit counter that advances once every PRESCALE + 1 clocks and
// wraps. A write of TB_PRESCALE restarts the prescaler's clock count.
`default_nettype none

module enc_qei_timing #(
    parameter integer TS_W = 32  // timebase width, 16 .. 32 (checked by enc_qei)
) (
    input  wire            clk,
    input  wire            rst,           // synchronous, active high
    input  wire [15:0]     prescale,      // TB_PRESCALE.PRESCALE
    output wire [TS_W-1:0] timebase,
    output wire            tick           // the timebase advances at this clock edge
);

  reg [15:0]     pre_q;
  reg [15:0]     prescale_q;  // last clock's PRESCALE: a change restarts the prescaler
  reg [TS_W-1:0] tb_q;

  wire restart = (prescale != prescale_q);
  wire tick_d  = ~restart & (pre_q >= prescale);

  always @(posedge clk) begin
    if (rst) begin
      pre_q      <= 16'd0;
      prescale_q <= 16'd0;
      tb_q       <= {TS_W{1'b0}};
    end else begin
      prescale_q <= prescale;
      pre_q      <= (restart | tick_d) ? 16'd0 : pre_q + 16'd1;
      if (tick_d) begin
        tb_q <= tb_q + {{(TS_W-1){1'b0}}, 1'b1};
      end
    end
  end

  assign timebase = tb_q;
  assign tick     = tick_d;

endmodule

`default_nettype wire
