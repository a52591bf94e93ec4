/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_example.h -- a firmware example for the enc_qei peripheral (C99), written against the
 * generated register header sw/enc_qei_regs.h only (enc_qei_t and enc_qei_chan_t; per field
 * ENC_QEI__<REG>__<FIELD>_bm, _SET(v) and _GET(w); per enum member ..._<MEMBER>_bm in place and
 * ..._<MEMBER>_VAL as a field value).
 *
 * Every function takes a pointer to the registers, so the same code runs on the target
 *   volatile enc_qei_t *q = (volatile enc_qei_t *)ENC_QEI_BASE;   (your SoC's address)
 *   volatile enc_qei_chan_t *ch = &q->chan[k];                    (channel k's page)
 * and on a host against a struct in memory (tb/enc_qei_doc/test_c_example.py does that).
 * The walk-through is doc/enc_qei.md; the register reference is doc/enc_qei_regs.md.
 */
#ifndef ENC_QEI_EXAMPLE_H
#define ENC_QEI_EXAMPLE_H

#include <stdint.h>

#include "enc_qei_regs.h"

#ifdef __cplusplus
extern "C" {
#endif

/* CTRL word for a count function (a field value, ENC_QEI__CTRL__FUNC__*_VAL), a range
 * (ENC_QEI__CTRL__RANGE__*_VAL) and an input filter length 1 .. 16, with EN = 1, no swap, no
 * inversion. Pure: touches no register. */
uint32_t enc_qei_ctrl_word(uint32_t func, uint32_t range, uint32_t filter_len);

/* Set up counting: CTRL.FUNC = x4, the given FILTER_LEN and RANGE, CEILING (used by the modulo,
 * limit and non_recycle ranges; e.g. counts per revolution - 1 with modulo), the count set to 0,
 * and stale events cleared. */
void enc_qei_setup_x4(volatile enc_qei_chan_t *q, uint32_t filter_len, uint32_t range, uint64_t ceiling);

/* CAPS.COUNT_W: the counter width of this build (8 .. 64). */
unsigned enc_qei_count_width(volatile enc_qei_t *q);

/* {hi, lo} as one 64-bit value. Pure. */
uint64_t enc_qei_combine64(uint32_t lo, uint32_t hi);

/* A COUNT_W-bit count as a signed position (two's complement in COUNT_W bits). Pure. */
int64_t enc_qei_to_signed(uint64_t count, unsigned count_w);

/* The count, coherently while the shaft turns: COUNT_LO first (which latches the high word),
 * then COUNT_HI. */
uint64_t enc_qei_read_count(volatile enc_qei_chan_t *q);

/* Set the count: COUNT_HI first (staged), then COUNT_LO (loads both). */
void enc_qei_write_count(volatile enc_qei_chan_t *q, uint64_t value);

/* Compare: EVENTS.CMP (and a cmp_out pulse) each time the count changes to `value`: COMPARE
 * written (HI first), the CMP interrupt enabled (a stale CMP cleared), then CTRL.CMP_EN set with
 * CTRL's other fields kept. CTRL.CMP_EN is in register maps from 1.2 (ID.VERSION 0x0102) on, in
 * builds with compare (not the lean profile). */
void enc_qei_compare_at(volatile enc_qei_chan_t *q, uint64_t value);

/* Homing, preset variant: load home_value into the count on the first index pulse, once
 * (INDEX_CTRL.ACTION = preset, ONESHOT, ARM), optionally gated by the (A, B) state gate_ab
 * (bit 1 = A, bit 0 = B; gate_ab < 0: no gate), and enable the INDEX interrupt. */
void enc_qei_home_preset(volatile enc_qei_chan_t *q, uint64_t home_value, int gate_ab);

/* Homing, latch variant: latch the count into INDEX_LATCH on the first index pulse, once
 * (ACTION = latch, ONESHOT, ARM), the count keeps running; enable the INDEX interrupt. */
void enc_qei_home_latch(volatile enc_qei_chan_t *q);

/* The interrupt handler's part for the index: if EVENTS.INDEX is pending, clear it (write 1 to
 * that bit only) and report whether the one-shot homing has happened (hardware cleared
 * INDEX_CTRL.ARM). Other pending events are left pending. Returns 1 when homed, 0 otherwise. */
int enc_qei_index_irq(volatile enc_qei_chan_t *q);

/* Position relative to the index latched by enc_qei_home_latch(): count - INDEX_LATCH, as a
 * signed COUNT_W-bit difference. */
int64_t enc_qei_position_from_latch(volatile enc_qei_chan_t *q, unsigned count_w);

/* The saturating error counters (QERR_COUNT, GLITCH_COUNT; 0xFFFF = at least that many). With
 * clear != 0 they are cleared after the read (any write clears). Returns 1 if either is non-zero:
 * the count may be off, re-home. */
int enc_qei_read_errors(volatile enc_qei_chan_t *q, uint32_t *qerr, uint32_t *glitch, int clear);

#ifdef __cplusplus
}
#endif

#endif /* ENC_QEI_EXAMPLE_H */
