// SPDX-License-Identifier: Apache-2.0
// enc_qei_timebase -- the timebase of enc_qei, one for every channel: a TS_W-bit counter that
// advances once every PRESCALE + 1 clocks (TB_PRESCALE), wrapping. `tick` is high in the clock
// before each advance; every time of the peripheral (timestamps, periods, timeouts, unit timers)
// is counted in these ticks, so every timestamp of every channel is comparable.
//
// The prescaler counts down from PRESCALE to 0 (a tick at 0), with a registered zero flag. A
// change of PRESCALE is seen one clock after the new value (restart, a register: Fmax) and
// restarts it then.
`default_nettype none

module enc_qei_timebase #(
    parameter integer TS_W = 32  // timebase width (checked by enc_qei)
) (
    input  wire            clk,
    input  wire            rst,       // synchronous, active high
    input  wire [15:0]     prescale,  // TB_PRESCALE.PRESCALE: clocks per tick, minus 1
    output wire [TS_W-1:0] timebase,  // the timebase now
    output wire            tick       // the timebase advances at the end of this clock
);

  localparam [TS_W-1:0] TS_ONE = {{(TS_W-1){1'b0}}, 1'b1};

  reg [15:0]     pre_q;
  reg            pre_zero_q;  // pre_q == 0
  reg [15:0]     prescale_q;  // last clock's PRESCALE
  reg            restart_q;   // PRESCALE changed at the last clock edge
  reg [TS_W-1:0] tb_q;

  assign tick = ~restart_q & pre_zero_q;

  always @(posedge clk) begin
    if (rst) begin
      pre_q      <= 16'd0;
      pre_zero_q <= 1'b1;
      prescale_q <= 16'd0;
      restart_q  <= 1'b0;
      tb_q       <= {TS_W{1'b0}};
    end else begin
      prescale_q <= prescale;
      restart_q  <= (prescale != prescale_q);
      if (restart_q | tick) begin
        pre_q      <= prescale;
        pre_zero_q <= (prescale == 16'd0);
      end else begin
        pre_q      <= pre_q - 16'd1;
        pre_zero_q <= (pre_q == 16'd1);
      end
      if (tick) begin
        tb_q <= tb_q + TS_ONE;
      end
    end
  end

  assign timebase = tb_q;

endmodule

`default_nettype wire
