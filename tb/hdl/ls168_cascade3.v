// SPDX-License-Identifier: Apache-2.0
// Test wrapper: three ls168 stages cascaded the way the data sheet (and Figure 17) does it:
// ENP_n common, ENT_n of stage 0 is the count enable, RCO_n of each stage drives ENT_n of the next.
`default_nettype none

module ls168_cascade3 #(
    parameter integer MODULUS = 10  // passed to every stage
) (
    input  wire        clk,
    input  wire        load_n,
    input  wire        en_n,
    input  wire        up,
    input  wire [11:0] d,
    output wire [11:0] q,
    output wire        rco_n
);

  wire [3:0] carry_n  /* verilator split_var */;  // carry_n[0] = en_n, carry_n[k+1] = RCO_n of stage k
  assign carry_n[0] = en_n;

  genvar k;
  generate
    for (k = 0; k < 3; k = k + 1) begin : g_stage
      ls168 #(
          .MODULUS(MODULUS)
      ) u_ls168 (
          .clk   (clk),
          .load_n(load_n),
          .enp_n (en_n),
          .ent_n (carry_n[k]),
          .up    (up),
          .d     (d[4*k+:4]),
          .q     (q[4*k+:4]),
          .rco_n (carry_n[k+1])
      );
    end
  endgenerate

  assign rco_n = carry_n[3];

endmodule

`default_nettype wire
