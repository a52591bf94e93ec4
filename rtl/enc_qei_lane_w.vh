// SPDX-License-Identifier: Apache-2.0
// The widths of a shared-engine lane's configuration and record (rtl/enc_qei_lane.vh has their
// fields), as macros for port declarations. enc_qei_lane.vh's CFG_W / REC_W must equal them:
// enc_qei_lane checks it at elaboration. Also the engine's schedule and the lanes' widths as
// functions of CHANNELS (enc_qei_engine explains them), one definition for the engine and for
// the lane proofs (formal/enc_qei_lane_formal.v, formal/enc_qei_lane_count_formal.v):
//   P      the clocks between two reads of a lane: V = 24 clocks a visit, max(CHANNELS, 2) visits
//   REACH  the steps a validity set must describe: 2 P + 4
//   MOT_W  the lane's count and motion bits: 2^(MOT_W - 1) > 2 REACH
//   TIM_W  the timebase bits a lane keeps: 2^TIM_W >= 2 P + 64
//   ERR_W  the error counters' bits: 2^(ERR_W - 1) >= P + 2
`ifndef ENC_QEI_LANE_W_VH
`define ENC_QEI_LANE_W_VH
`define ENC_QEI_LANE_CFG_W(MOT, TIM) (3 * (MOT) + 3 * (TIM) + 64)
`define ENC_QEI_LANE_REC_W(MOT, TIM, ERR) (8 * (MOT) + 10 * (TIM) + 2 * (ERR) + 39)
`define ENC_QEI_ENGINE_V 24
`define ENC_QEI_ENGINE_P(CH) (`ENC_QEI_ENGINE_V * (((CH) < 2) ? 2 : (CH)))
`define ENC_QEI_ENGINE_REACH(CH) (2 * `ENC_QEI_ENGINE_P(CH) + 4)
`define ENC_QEI_ENGINE_MOT_W(CH) ($clog2(2 * `ENC_QEI_ENGINE_REACH(CH) + 1) + 1)
`define ENC_QEI_ENGINE_TIM_W(CH) ($clog2(2 * `ENC_QEI_ENGINE_P(CH) + 64))
`define ENC_QEI_ENGINE_ERR_W(CH) ($clog2(`ENC_QEI_ENGINE_P(CH) + 2) + 1)
`endif
