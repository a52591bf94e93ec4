// SPDX-License-Identifier: Apache-2.0
// How a shared-engine lane (enc_qei_lane) and the engine (enc_qei_engine) talk: the bit
// positions of the record the lane hands over when it is read, and of the configuration the
// engine pushes into it. Include it inside a module body that has the parameters MOT_W, TIM_W
// and ERR_W (the lane's widths). Every position is a localparam computed from those widths; a
// field of width 1 has only its position, wider ones also _W. Fields of units a profile leaves
// out are 0 (and cost nothing).
//
// The count in a lane: lo = the count's low MOT_W bits, exact; its anchor: what lo counts from
// since the last read: A_NONE the count the engine had at that read, A_LOAD a load (an index
// preset: PRESET; a COUNT write: its value), A_ZERO a modulo wrap up (0), A_CEIL a modulo wrap
// down (CEILING). The engine rebuilds a count as anchor value + (lo - the anchor value's low
// bits), signed.
//
// The record (REC_W bits):
//   R_MPOS    mpos: the count function's steps while CTRL.EN = 1 (the motion), mod 2^MOT_W
//   R_LO, R_ANC   lo and the last anchor since the read
//   R_LPEND, R_LCAP, R_LANC   an index latch in the window: lo (after its step) and its anchor
//   R_SPEND   a snapshot capture waits, with what the lane held in its clock: R_SMPOS, R_SLO,
//             R_SANC mpos, lo, the anchor; R_STIME the timebase's low bits; R_SET, R_SEMP,
//             R_SNEW the last selected edge's time and mpos and whether it is in the window;
//             R_SEDGE a selected edge in the snapshot's own clock (then R_STIME, R_SMPOS)
//   R_ET, R_EMP, R_ENEW   the last selected edge (SNAP_CTRL.EDGE) and whether it is in the window
//   R_OVF, R_UNF, R_IDX, R_DCH, R_CMP   events of the window: overflow, underflow, a qualified
//             index edge (armed or not), a direction change, a compare match; R_EFT, R_EFO the
//             edge FIFO's (EFIFO_THRESH, EFIFO_OVF: a channel with a FIFO)
//   R_QCNT, R_GCNT   free-running counts of quadrature errors and of rejected levels
//   R_A, R_B, R_Z, R_DIR, R_ARMED, R_STOPPED   the STATUS bits now; R_ARM INDEX_CTRL.ARM now
//   R_PPEND, R_PLO, R_PANC, R_PTIME   a probe latch in the window: lo, its anchor, the timebase's
//             low bits; R_PEN PROBE_CTRL.EN now
//   R_G       timebase ticks since the last restart of the stall timer (a step, or a new
//             STALL_TIMEOUT), saturating; R_GRST a restart in the window, R_FST the time of the
//             first one; R_SEV a stall the lane saw (STALL_TIMEOUT within its reach, C_STO);
//             R_STALLED its STATUS.STALLED
//   R_NB      period boundaries (every PERIOD_CTRL.N selected edges) in the window, 0 .. 3
//   R_BST     a period measurement started in the window (the first edge after PERIOD_CTRL.EN)
//   R_PRUN    a period measurement runs now
//   R_BF, R_BT, R_BT0   the times of the window's first boundary or start, of its last one, and
//             of the one before the last (when in the window); R_BDIR: the measurement that
//             ended at the last boundary saw a direction change
//   R_UHIT    the unit timer (SNAP_CTRL.PERIOD_EN) expired in the window; R_UARM, R_UD: it is
//             armed now, for the time with these low bits
// verilator lint_off UNUSEDPARAM
localparam integer A_NONE = 0, A_LOAD = 1, A_ZERO = 2, A_CEIL = 3;
localparam integer R_MPOS    = 0,                 R_MPOS_W  = MOT_W;
localparam integer R_LO      = R_MPOS + MOT_W,    R_LO_W    = MOT_W;
localparam integer R_ANC     = R_LO + MOT_W,      R_ANC_W   = 2;
localparam integer R_LPEND   = R_ANC + 2;
localparam integer R_LCAP    = R_LPEND + 1,       R_LCAP_W  = MOT_W;
localparam integer R_LANC    = R_LCAP + MOT_W,    R_LANC_W  = 2;
localparam integer R_SPEND   = R_LANC + 2;
localparam integer R_SMPOS   = R_SPEND + 1,       R_SMPOS_W = MOT_W;
localparam integer R_SLO     = R_SMPOS + MOT_W,   R_SLO_W   = MOT_W;
localparam integer R_SANC    = R_SLO + MOT_W,     R_SANC_W  = 2;
localparam integer R_STIME   = R_SANC + 2,        R_STIME_W = TIM_W;
localparam integer R_SET     = R_STIME + TIM_W,   R_SET_W   = TIM_W;
localparam integer R_SEMP    = R_SET + TIM_W,     R_SEMP_W  = MOT_W;
localparam integer R_SNEW    = R_SEMP + MOT_W;
localparam integer R_SEDGE   = R_SNEW + 1;
localparam integer R_ET      = R_SEDGE + 1,       R_ET_W    = TIM_W;
localparam integer R_EMP     = R_ET + TIM_W,      R_EMP_W   = MOT_W;
localparam integer R_ENEW    = R_EMP + MOT_W;
localparam integer R_OVF     = R_ENEW + 1;
localparam integer R_UNF     = R_OVF + 1;
localparam integer R_IDX     = R_UNF + 1;
localparam integer R_DCH     = R_IDX + 1;
localparam integer R_CMP     = R_DCH + 1;
localparam integer R_EFT     = R_CMP + 1;
localparam integer R_EFO     = R_EFT + 1;
localparam integer R_QCNT    = R_EFO + 1,         R_QCNT_W  = ERR_W;
localparam integer R_GCNT    = R_QCNT + ERR_W,    R_GCNT_W  = ERR_W;
localparam integer R_A       = R_GCNT + ERR_W;
localparam integer R_B       = R_A + 1;
localparam integer R_Z       = R_B + 1;
localparam integer R_DIR     = R_Z + 1;
localparam integer R_ARM     = R_DIR + 1;
localparam integer R_ARMED   = R_ARM + 1;
localparam integer R_STOPPED = R_ARMED + 1;
localparam integer R_PPEND   = R_STOPPED + 1;
localparam integer R_PLO     = R_PPEND + 1,       R_PLO_W   = MOT_W;
localparam integer R_PANC    = R_PLO + MOT_W,     R_PANC_W  = 2;
localparam integer R_PTIME   = R_PANC + 2,        R_PTIME_W = TIM_W;
localparam integer R_PEN     = R_PTIME + TIM_W;
localparam integer R_G       = R_PEN + 1,         R_G_W     = TIM_W;
localparam integer R_GRST    = R_G + TIM_W;
localparam integer R_FST     = R_GRST + 1,        R_FST_W   = TIM_W;
localparam integer R_SEV     = R_FST + TIM_W;
localparam integer R_STALLED = R_SEV + 1;
localparam integer R_NB      = R_STALLED + 1,     R_NB_W    = 2;
localparam integer R_BST     = R_NB + 2;
localparam integer R_PRUN    = R_BST + 1;
localparam integer R_BF      = R_PRUN + 1,        R_BF_W    = TIM_W;
localparam integer R_BT      = R_BF + TIM_W,      R_BT_W    = TIM_W;
localparam integer R_BT0     = R_BT + TIM_W,      R_BT0_W   = TIM_W;
localparam integer R_BDIR    = R_BT0 + TIM_W;
localparam integer R_UHIT    = R_BDIR + 1;
localparam integer R_UARM    = R_UHIT + 1;
localparam integer R_UD      = R_UARM + 1,        R_UD_W    = TIM_W;
localparam integer REC_W     = R_UD + TIM_W;      // the record's width
// The record in the clock after rst (the lane as rst leaves it, but for the bits of REC_CAP:
// formal/enc_qei_lane.sby proves it): 0 but for STATUS.DIR (1: up), INDEX_CTRL.ARM and
// PROBE_CTRL.EN at their reset values. The engine takes it as channel 0's record for its first
// visit, which comes before that lane's first read. Needs enc_qei_regs.vh included before this
// file. REC_CAP: the captures' data, the snapshot's R_SMPOS .. R_SEDGE, the probe latch's
// R_PLO .. R_PTIME, the stall timer's R_FST, the period's R_BF .. R_BT0 and the unit timer's
// R_UD, registers without a reset, read only with R_SPEND, R_PPEND, R_GRST, R_NB or R_BST, and
// R_UARM.
localparam [REC_W-1:0] REC_ONE   = {{(REC_W-1){1'b0}}, 1'b1};
localparam [REC_W-1:0] REC_CAP   = ((REC_ONE << (R_SEDGE + 1)) - (REC_ONE << R_SMPOS)) |
                                   ((REC_ONE << R_PEN) - (REC_ONE << R_PLO)) |
                                   ((REC_ONE << R_SEV) - (REC_ONE << R_FST)) |
                                   ((REC_ONE << R_BDIR) - (REC_ONE << R_BF)) |
                                   ~((REC_ONE << R_UD) - REC_ONE);
localparam [REC_W-1:0] REC_RST   =
    (ENC_QEI_INDEX_CTRL_RESET[ENC_QEI_INDEX_CTRL_ARM] ? (REC_ONE << R_ARM) : {REC_W{1'b0}}) |
    (ENC_QEI_PROBE_CTRL_RESET[ENC_QEI_PROBE_CTRL_EN] ? (REC_ONE << R_PEN) : {REC_W{1'b0}}) |
    (REC_ONE << R_DIR);

// The configuration (CFG_W bits): the channel's registers as the lane counts with them. CTRL:
// EN, SWAP_AB, INV_A, INV_B, INV_Z, FUNC (as counted: a code no function has where FUNC_MASK
// leaves it out), C_LAST = FILTER_LEN clamped to 1 .. 16, minus 1 (enc_filter_rt's last),
// RANGE, CMP_EN; INDEX_CTRL: ACTION, ONESHOT, EDGE, GATE_EN, GATE_A, GATE_B, ARM (taken only with
// the lane's arm_we: the lane clears ARM itself); SNAP_CTRL: IN_EN, EDGE, PERIOD_EN (C_UEN);
// PROBE_CTRL: EN (taken only with pen_we), EDGE, ONCE; PERIOD_CTRL: EN, EDGE, N - 1 (0 for 0);
// C_STO: STALL_TIMEOUT when the lane times it (1 .. 2^TIM_W - 1), else 0 (off, or the engine
// times it); C_UPER: SNAP_PERIOD (0 acts as 1) when the lane reloads its unit timer itself
// (< 2^TIM_W), else 0; C_UD: the unit timer's time (low bits; taken only with u_we, which arms it);
// C_PLO: PRESET's low bits (a COUNT write's value's, in the clock before its load); C_CLO, C_MLO:
// CEILING's and COMPARE's low bits; the validity sets (V_*): C_VS_CNT for the count the engine
// had at the lane's last read, C_VS_LOAD for PRESET (a COUNT write's value), C_VS_ZERO for 0,
// C_VS_CEIL for CEILING, C_VSO_LOAD / C_VSO_CEIL for the PRESET / CEILING this configuration
// replaces (an anchor taken before it). Every set is for this configuration's CEILING and
// COMPARE. A validity set says, for a count near its value, which of these the lane's low bits
// may stand for: V_B the end of the range (0 / all ones, within reach either way round), V_C
// CEILING (within reach modulo 2^COUNT_W), V_AC the count is above CEILING (used when neither
// V_B nor V_C), V_P COMPARE (within reach modulo 2^COUNT_W). The counts in reach of a value near
// the end of the free range (V_B) may lie on both sides of it, so CEILING and COMPARE are taken
// modulo 2^COUNT_W, and the lane tells the sides apart by the top bit of the low bits.
localparam integer V_B = 0, V_C = 1, V_AC = 2, V_P = 3, VS_W = 4;
localparam integer C_EN       = 0;
localparam integer C_SWAP     = 1;
localparam integer C_INV_A    = 2;
localparam integer C_INV_B    = 3;
localparam integer C_INV_Z    = 4;
localparam integer C_FUNC     = 5,                C_FUNC_W  = 4;
localparam integer C_LAST     = C_FUNC + 4,       C_LAST_W  = 4;
localparam integer C_RANGE    = C_LAST + 4,       C_RANGE_W = 2;
localparam integer C_CMP_EN   = C_RANGE + 2;
localparam integer C_ACT      = C_CMP_EN + 1,     C_ACT_W   = 2;
localparam integer C_ONESHOT  = C_ACT + 2;
localparam integer C_IEDGE    = C_ONESHOT + 1;
localparam integer C_GATE_EN  = C_IEDGE + 1;
localparam integer C_GATE_A   = C_GATE_EN + 1;
localparam integer C_GATE_B   = C_GATE_A + 1;
localparam integer C_ARM      = C_GATE_B + 1;
localparam integer C_SIN_EN   = C_ARM + 1;
localparam integer C_SEDGE    = C_SIN_EN + 1;
localparam integer C_UEN      = C_SEDGE + 1;
localparam integer C_PEN      = C_UEN + 1;
localparam integer C_PEDGE    = C_PEN + 1;
localparam integer C_PONCE    = C_PEDGE + 1;
localparam integer C_PER_EN   = C_PONCE + 1;
localparam integer C_PER_EDGE = C_PER_EN + 1;
localparam integer C_PER_N    = C_PER_EDGE + 1,   C_PER_N_W = 8;
localparam integer C_STO      = C_PER_N + 8,      C_STO_W   = TIM_W;
localparam integer C_UPER     = C_STO + TIM_W,    C_UPER_W  = TIM_W;
localparam integer C_UD       = C_UPER + TIM_W,   C_UD_W    = TIM_W;
localparam integer C_PLO      = C_UD + TIM_W,     C_PLO_W   = MOT_W;
localparam integer C_CLO      = C_PLO + MOT_W,    C_CLO_W   = MOT_W;
localparam integer C_MLO      = C_CLO + MOT_W,    C_MLO_W   = MOT_W;
localparam integer C_VS_CNT   = C_MLO + MOT_W;
localparam integer C_VS_LOAD  = C_VS_CNT + VS_W;
localparam integer C_VS_ZERO  = C_VS_LOAD + VS_W;
localparam integer C_VS_CEIL  = C_VS_ZERO + VS_W;
localparam integer C_VSO_LOAD = C_VS_CEIL + VS_W;
localparam integer C_VSO_CEIL = C_VSO_LOAD + VS_W;
localparam integer CFG_W      = C_VSO_CEIL + VS_W;  // the configuration's width
// verilator lint_on UNUSEDPARAM

// How the engine rebuilds wide values from a record (enc_qei_engine's arithmetic; the lane's
// proof, formal/enc_qei_lane_formal.v, calls the same functions, so it proves these formulas):
// lane_sdiff, the signed difference a - b of two MOT_W-bit lane positions, sign-extended (a
// motion since a base, if within +-2^(MOT_W-1)); lane_tstamp, the timestamp whose low TIM_W bits
// are t, taken at most 2^TIM_W - 1 ticks before the timebase now (the caller masks it to TS_W).
function [63:0] lane_sdiff;
  input [MOT_W-1:0] a;
  input [MOT_W-1:0] b;
  reg   [MOT_W-1:0] d;
  begin
    d          = a - b;
    lane_sdiff = {{(64 - MOT_W){d[MOT_W-1]}}, d};
  end
endfunction

function [31:0] lane_tstamp;
  input [TIM_W-1:0] t;
  input [31:0]      now;
  reg   [TIM_W-1:0] age;
  begin
    age         = now[TIM_W-1:0] - t;
    lane_tstamp = now - {{(32 - TIM_W){1'b0}}, age};
  end
endfunction

// How the engine rebuilds a count from a lane's low bits lo and their anchor anc (the last since
// the read before; enc_qei_engine's rebuild, which the lane's count proof calls too): the count
// within +-2^(MOT_W-1) of the anchor's value whose low bits are lo, kept to the mask sz. The
// anchor's value: ld_base for A_LOAD (PRESET, or a COUNT write's value), 0 for A_ZERO, ceil for
// A_CEIL, cnt (the count at the read before) for A_NONE.
function [63:0] lane_rebuild;
  input [MOT_W-1:0] lo;
  input [1:0]       anc;
  input [63:0]      ld_base;
  input [63:0]      ceil;
  input [63:0]      cnt;
  input [63:0]      sz;
  reg   [63:0]      base;
  begin
    case (anc)
      A_LOAD[1:0]: base = ld_base;
      A_ZERO[1:0]: base = 64'd0;
      A_CEIL[1:0]: base = ceil;
      default:     base = cnt;
    endcase
    lane_rebuild = (base + lane_sdiff(lo, base[MOT_W-1:0])) & sz;
  end
endfunction

// How the engine makes a validity set (V_* above) for its pushes (enc_qei_engine's vs_of; the
// lane's count proof, formal/enc_qei_lane_count_formal.v, calls the same function): lane_vs_of
// is the set of a count value x for CEILING c and COMPARE m, in a build whose counts are kept to
// the mask sz (2^COUNT_W - 1), for the counts within reach (the engine's REACH = 2 P + 4 steps)
// of x. V_B: x within reach of 0 modulo 2^COUNT_W (0 and all ones, the ends of the free range,
// either way round); V_C: x within reach of c modulo 2^COUNT_W; V_AC: x > c; V_P: x within
// reach of m modulo 2^COUNT_W. V_C, V_AC and V_P are 0 without ranges (rng 0).
function lane_near_mod;  // |a - b| <= reach modulo sz + 1
  input [63:0] a;
  input [63:0] b;
  input [63:0] sz;
  input [63:0] reach;
  reg   [63:0] d;
  begin
    d             = (a - b) & sz;
    lane_near_mod = (d <= reach) | (((~d + 64'd1) & sz) <= reach);
  end
endfunction

function [3:0] lane_vs_of;
  input [63:0] x;
  input [63:0] c;
  input [63:0] m;
  input [63:0] sz;
  input [63:0] reach;
  input        rng;
  begin
    lane_vs_of[V_B]  = lane_near_mod(x, 64'd0, sz, reach);
    lane_vs_of[V_C]  = rng & lane_near_mod(x, c, sz, reach);
    lane_vs_of[V_AC] = rng & (x > c);
    lane_vs_of[V_P]  = rng & lane_near_mod(x, m, sz, reach);
  end
endfunction
