// SPDX-License-Identifier: Apache-2.0
// The read data of the abstract enc_qei (formal/enc_qei_abstract.v) for a read of a mapped
// offset: a function of the byte address whose every bit takes both values and that is never 0,
// so a wrapper can tell which request a read answer belongs to, and an unmapped read (0) from a
// mapped one. Include it inside a module body (the stand-in and the adapter wrappers do).
function [31:0] f_qei_rdata;
  input [7:0] addr;
  begin
    f_qei_rdata = {~addr, addr ^ 8'h5A, addr ^ 8'hC3, addr};
  end
endfunction
