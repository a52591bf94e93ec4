// SPDX-License-Identifier: Apache-2.0
// The widths of a shared-engine lane's configuration and record (rtl/enc_qei_lane.vh has their
// fields), as macros for port declarations. enc_qei_lane.vh's CFG_W / REC_W must equal them:
// enc_qei_lane checks it at elaboration.
`ifndef ENC_QEI_LANE_W_VH
`define ENC_QEI_LANE_W_VH
`define ENC_QEI_LANE_CFG_W(MOT, TIM) (3 * (MOT) + 3 * (TIM) + 64)
`define ENC_QEI_LANE_REC_W(MOT, TIM, ERR) (8 * (MOT) + 10 * (TIM) + 2 * (ERR) + 39)
`endif
