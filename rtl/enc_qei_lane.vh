// SPDX-License-Identifier: Apache-2.0
// How a shared-engine lane (enc_qei_lane) and the engine (enc_qei_engine) talk: the bit
// positions of the record the lane hands over when it is read, and of the configuration the
// engine pushes into it. Include it inside a module body that has the parameters MOT_W, TIM_W
// and ERR_W (the lane's widths). Every position is a localparam computed from those widths; a
// field of width 1 has only its position, wider ones also _W.
//
// The record (REC_W bits):
//   R_MPOS     mpos: the count function's steps while CTRL.EN = 1 (the motion), mod 2^MOT_W, as
//              of the read
//   R_ICAP     mpos just after the last acting index edge of the window (its step included), and
//   R_IPEND    1: there was one; R_IPRE: it was a preset (else a latch)
//   R_SPEND    1: a snapshot was taken in the window, with what the lane held in its clock:
//   R_SMPOS      mpos; R_SICAP, R_SIPEND, R_SIPRE: the index capture; R_STIME: timebase low bits;
//   R_SET, R_SEMP, R_SNEW: the last selected edge's time and mpos, and whether it is in the
//   window; R_SEDGE: a selected edge in the snapshot's own clock (time R_STIME, mpos R_SMPOS)
//   R_ET, R_EMP, R_ENEW  the last selected edge (SNAP_CTRL.EDGE) of the window
//   R_OVF, R_UNF, R_IDX, R_DCH  events of the window: overflow, underflow, a qualified index
//              edge (armed or not), a direction change
//   R_QCNT, R_GCNT  free-running counts of quadrature errors and of rejected levels, mod 2^ERR_W
//   R_A, R_B, R_Z, R_DIR, R_ARMED  STATUS.A, B, Z, DIR, INDEX_ARMED now
// verilator lint_off UNUSEDPARAM
localparam integer R_MPOS   = 0,                R_MPOS_W  = MOT_W;
localparam integer R_ICAP   = R_MPOS + MOT_W,   R_ICAP_W  = MOT_W;
localparam integer R_IPEND  = R_ICAP + MOT_W;
localparam integer R_IPRE   = R_IPEND + 1;
localparam integer R_SPEND  = R_IPRE + 1;
localparam integer R_SMPOS  = R_SPEND + 1,      R_SMPOS_W = MOT_W;
localparam integer R_SICAP  = R_SMPOS + MOT_W,  R_SICAP_W = MOT_W;
localparam integer R_SIPEND = R_SICAP + MOT_W;
localparam integer R_SIPRE  = R_SIPEND + 1;
localparam integer R_STIME  = R_SIPRE + 1,      R_STIME_W = TIM_W;
localparam integer R_SET    = R_STIME + TIM_W,  R_SET_W   = TIM_W;
localparam integer R_SEMP   = R_SET + TIM_W,    R_SEMP_W  = MOT_W;
localparam integer R_SNEW   = R_SEMP + MOT_W;
localparam integer R_SEDGE  = R_SNEW + 1;
localparam integer R_ET     = R_SEDGE + 1,      R_ET_W    = TIM_W;
localparam integer R_EMP    = R_ET + TIM_W,     R_EMP_W   = MOT_W;
localparam integer R_ENEW   = R_EMP + MOT_W;
localparam integer R_OVF    = R_ENEW + 1;
localparam integer R_UNF    = R_OVF + 1;
localparam integer R_IDX    = R_UNF + 1;
localparam integer R_DCH    = R_IDX + 1;
localparam integer R_QCNT   = R_DCH + 1,        R_QCNT_W  = ERR_W;
localparam integer R_GCNT   = R_QCNT + ERR_W,   R_GCNT_W  = ERR_W;
localparam integer R_A      = R_GCNT + ERR_W;
localparam integer R_B      = R_A + 1;
localparam integer R_Z      = R_B + 1;
localparam integer R_DIR    = R_Z + 1;
localparam integer R_ARMED  = R_DIR + 1;
localparam integer REC_W    = R_ARMED + 1;   // the record's width

// The configuration (CFG_W bits): the channel's registers as the lane counts with them. CTRL:
// EN, SWAP_AB, INV_A, INV_B, INV_Z, FUNC (as counted: a code no function has where FUNC_MASK
// leaves it out), C_LAST = FILTER_LEN clamped to 1 .. 16, minus 1 (enc_filter_rt's last); INDEX_CTRL: ACTION, ONESHOT, EDGE, GATE_EN, GATE_A, GATE_B, ARM
// (taken only with the lane's arm_we: the lane clears ARM itself); SNAP_CTRL: IN_EN, EDGE;
// from PRESET: C_NEGP = -PRESET mod 2^MOT_W and C_VBP = 1 when PRESET is within the lane's reach
// of the end of the free range (so an index preset knows where the count wraps).
localparam integer C_EN      = 0;
localparam integer C_SWAP    = 1;
localparam integer C_INV_A   = 2;
localparam integer C_INV_B   = 3;
localparam integer C_INV_Z   = 4;
localparam integer C_FUNC    = 5,             C_FUNC_W = 4;
localparam integer C_LAST    = C_FUNC + 4,    C_LAST_W = 4;
localparam integer C_ACT     = C_LAST + 4,    C_ACT_W  = 2;
localparam integer C_ONESHOT = C_ACT + 2;
localparam integer C_IEDGE   = C_ONESHOT + 1;
localparam integer C_GATE_EN = C_IEDGE + 1;
localparam integer C_GATE_A  = C_GATE_EN + 1;
localparam integer C_GATE_B  = C_GATE_A + 1;
localparam integer C_ARM     = C_GATE_B + 1;
localparam integer C_SIN_EN  = C_ARM + 1;
localparam integer C_SEDGE   = C_SIN_EN + 1;
localparam integer C_NEGP    = C_SEDGE + 1,   C_NEGP_W = MOT_W;
localparam integer C_VBP     = C_NEGP + MOT_W;
localparam integer CFG_W     = C_VBP + 1;     // the configuration's width
// verilator lint_on UNUSEDPARAM
