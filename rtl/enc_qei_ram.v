// SPDX-License-Identifier: Apache-2.0
// enc_qei_ram -- the shared engine's state memory: one write port with a bit mask and two read
// ports, each read registered (one clock: the data of the address given in one clock comes in
// the next). Written for block RAM inference (iCE40 SB_RAM40_4K, ECP5 DP16KD): Yosys gives each
// read port its own copy of the memory, so the engine (port a) and the bus (port b) never wait
// for each other. A read in the clock of a write to the same address is undefined (no_rw_check:
// no bypass logic); the engine never does it (enc_qei_engine's schedule, and its bus reads wait a
// clock on a collision).
// No reset: the engine writes every word it reads before it reads it (enc_qei_engine clears the
// memory after rst).
`default_nettype none

module enc_qei_ram #(
    parameter integer W  = 64,  // word width in bits
    parameter integer AW = 8    // address bits: 2^AW words
) (
    input  wire          clk,
    input  wire          we,      // write ...
    input  wire [AW-1:0] waddr,   // ... this word,
    input  wire [W-1:0]  wdata,
    input  wire [W-1:0]  wmask,   // ... these bits of it (a bit mask the block RAM takes)
    input  wire [AW-1:0] raddr_a, // read port a: the word, ...
    output wire [W-1:0]  rdata_a, // ... one clock later
    input  wire [AW-1:0] raddr_b, // read port b
    output wire [W-1:0]  rdata_b
);

  (* no_rw_check *) reg [W-1:0] mem [0:(1 << AW) - 1];
  reg [W-1:0] rdata_a_q, rdata_b_q;
  integer     i;

  always @(posedge clk) begin
    if (we) begin
      for (i = 0; i < W; i = i + 1) begin
        if (wmask[i]) mem[waddr][i] <= wdata[i];
      end
    end
  end

  always @(posedge clk) begin
    rdata_a_q <= mem[raddr_a];
    rdata_b_q <= mem[raddr_b];
  end

  assign rdata_a = rdata_a_q;
  assign rdata_b = rdata_b_q;

`ifdef FORMAL
  // A proof's view of F_PEEK words (formal/enc_qei_engine.sby, its data tasks, which read
  // this file with FORMAL defined and drive f_peek_addr after flatten): word i of f_peek is
  // mem[f_peek_addr[i]] now, no clock.
  localparam integer F_PEEK = 12;
  wire [F_PEEK*AW-1:0] f_peek_addr;
  (* keep *) wire [F_PEEK*W-1:0] f_peek;
  genvar f_i;
  generate
    for (f_i = 0; f_i < F_PEEK; f_i = f_i + 1) begin : g_f_peek
      assign f_peek[f_i*W +: W] = mem[f_peek_addr[f_i*AW +: AW]];
    end
  endgenerate
`endif

endmodule

`default_nettype wire
