// SPDX-License-Identifier: Apache-2.0
// The read data of the abstract enc_qei (formal/enc_qei_abstract.v) for a read of a mapped
// offset: a function of the byte address (all 16 bits can be told from it) whose every bit takes
// both values and that is never 0, so a wrapper can tell which request a read answer belongs to,
// and an unmapped read (0) from a mapped one. Include it inside a module body (the stand-in and the adapter wrappers do).
function [31:0] f_qei_rdata;
  input [15:0] addr;  // the byte address, zero-extended
  begin
    f_qei_rdata = {~addr[7:0], addr[15:8] ^ 8'h5A, addr[7:0] ^ addr[15:8] ^ 8'hC3, addr[7:0]};
  end
endfunction
