/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_calib_fx.h -- the self-calibrating velocity estimator of enc_qei_calib.h in integer
 * arithmetic (C99, int32/int64 and a 192-bit integer of its own; no float, no double, no libm,
 * no malloc), for CPUs without an FPU such as a VexRiscv in a LiteX SoC.
 *
 * The same algorithm as sw/enc_qei_calib.c (specification: python/src/hedsmodel/calibration.py's
 * docstring): the same entries in, the same learning (clean revolutions, the acceptance rule),
 * the same checks in use, the same fallback to uncalibrated readings, the same IDX / LOST / missed
 * handling, every integer step taken in the same order. tb/velocity/test_velocity_calib_fx.py
 * runs both on the same entry streams and compares every reading and, after every entry, every
 * counter, flag and vote fraction.
 *
 * Readings (qei_calfx_reading_t): int32_t in units of 2^-F count steps per second, F =
 * cfg.frac_bits (0 .. 31), rounded to the nearest unit (ties up), as sw/enc_qei_velocity_fx.h:
 *   resolution  2^-F count/s         (F = 8: 1/256 = 0.0039 count/s)
 *   range       +-(2^31 - 1) * 2^-F  (F = 8: +-8,388,607.996 count/s); beyond it a reading is
 *               +-(2^31 - 1) (QEI_CALFX_MAX), saturated, never wrapped.
 * Angles are in 2^-32 counts (the table: each boundary's deviation from its nominal place), so
 * a reading is the double version's rounded to the unit, plus the table's difference from the
 * double table (a few 2^-32 counts) over the reading's time: at most
 *   1/2 unit + 2^-30 count * tick_hz * 2^F / (ticks between the reading's two edges),
 * within one unit whenever those edges are 2^(F-1) * tick_hz / 2^28 ticks apart or more
 * (F = 8, 100 MHz: 48 ticks; F = 16: 12,208 ticks, 122 us). Uncalibrated readings are the exact
 * quotient rounded: within 1/2 unit.
 *
 * Decisions are exact integer comparisons: the motion check on the three periods, the agreement
 * figures (sums of squares of the deviations in 2^-32 counts, against the tolerances given in
 * millionths), the edge check (the residuals of the constant-acceleration extrapolation as exact
 * rationals) and the vote fractions (2^-62). They can differ from the double version's only
 * where a figure lies within the tables' difference (about 1e-9 counts) or the double's own
 * rounding (1e-16 relative) of its threshold. With a coarse tick (a count a few ticks long) the
 * deviations are simple fractions and an edge-check vote can land exactly on its threshold:
 * such ties go either way (the vote fractions differ by 1/32 until later votes bring them back
 * together); tb/velocity counts them. At the bench's 10 ns tick there were none. Where the
 * double version has no limit this one has these:
 *   - a revolution of 2^32 ticks or more (43 s at 100 MHz: below 1.4 rpm) is not clean;
 *   - a revolution whose fit needs an acceleration term beyond 2^30 counts (only with a motion
 *     tolerance far above 1e-3) is not clean;
 *   - a boundary that deviates from its reference by 256 counts or more disagrees;
 *   - the learning pass's sums saturate at +-2^31 counts per boundary, the table at 2^29;
 *   - an angle of 2^31 counts or more between two edges saturates.
 *
 * Use (N = 500 cycles, 100 MHz timebase, readings in 1/256 count/s):
 *   static int64_t buf[QEI_CALFX_BUF_LEN(500)];       3 x 4N int64_t: table, pass, revolution
 *   qei_calfx_cfg_t cfg = {100000000u, 8, 32, 500, 1, 8, stall_ticks, 1000, 50000, 5000, 150000};
 *   qei_calfx_init(&st, &cfg, buf, QEI_CALFX_BUF_LEN(500));
 *   once per servo period: pop every FIFO entry into qei_calfx_push(), then read the TIMEBASE
 *   and call qei_calfx_read().
 *
 * Memory: 12N int64_t (24 kB per 1,000 cycles: the same as the double version) plus the struct.
 * Cost on RV32IM: doc/velocity.md (per entry, per revolution, per read; measured by
 * scripts/calib_fx_check.py).
 */
#ifndef ENC_QEI_CALIB_FX_H
#define ENC_QEI_CALIB_FX_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* int64_t elements the caller provides for N cycles per revolution */
#define QEI_CALFX_BUF_LEN(cycles) ((size_t)12u * (size_t)(cycles))
#define QEI_CALFX_MAX INT32_MAX   /* |reading| of a saturated speed */

typedef struct {
    uint32_t time;  /* TIMEBASE at the step, TS_W bits */
    uint8_t  a, b;  /* A/B state after the step */
    uint8_t  up;    /* 1: +1 step, 0: -1 */
    uint8_t  lost;  /* entries were lost before this one */
    uint8_t  idx;   /* a qualified index edge came up to this step */
} qei_calfx_entry_t;

typedef struct {
    uint32_t tick_hz;     /* timebase ticks per second, > 0: f_clk / (TB_PRESCALE + 1) */
    unsigned frac_bits;   /* F, 0 .. 31: readings in 2^-F count steps per second */
    unsigned ts_w;        /* timebase width, 1 .. 32 */
    uint32_t cycles;      /* N, cycles per revolution (4N states), 2 .. 2^20 */
    int      use_index;   /* 1: phase the table on IDX entries */
    uint32_t learn_revs;  /* agreeing clean revolutions averaged into a table, >= 1 */
    uint64_t stall_ticks; /* stall timeout in ticks since the last selected edge, 0 = off */
    uint32_t motion_ppm;  /* relative speed mismatch of a clean revolution, millionths,
                             1 .. 1,000,000: 1000 (1e-3) */
    uint32_t shape_uc;    /* agreement, millionths of a count rms, >= 1: smooth shape 50000 */
    uint32_t line_uc;     /*   cycle-to-cycle at the A edges 5000 */
    uint32_t edge_uc;     /*   within the cycles 150000 */
} qei_calfx_cfg_t;

typedef struct {
    int32_t mt_a;    /* M/T on A-rising edges, 2^-F count steps per second */
    int32_t any;     /* any-edge, 2^-F count steps per second */
    int calibrated;  /* the table was in use */
} qei_calfx_reading_t;

typedef struct {
    uint32_t learned, changes, rejected, disagree, unclean, reindex, suspect, lost, missed,
             edge_alarms, jolts;   /* as qei_cal_counts_t */
} qei_calfx_counts_t;

typedef struct {
    unsigned cpe;
    int has_last, has_ref, new_edge, dir;
    int64_t last_b, ref_b;
    uint64_t last_t, ref_t;
    uint32_t mag;            /* 2^-F count/s */
} qei_calfx_method_t;

typedef struct {
    qei_calfx_cfg_t cfg;
    int64_t *table, *acc, *work;  /* deviations from nominal, 2^-32 counts (work: ticks first) */
    int64_t S;
    uint32_t mask, t_raw;
    uint64_t t;
    int started, dir, ab, framed, phase_ok, a_par, pending, valid, rev_ok, edge_ok, rev_dir;
    int64_t pos, ref, alt_ref, idx_off[2], idx_cand[2], rev_next;
    uint32_t cand_n, coarse, ea_k;
    uint64_t rev_t0, t_prev, t_prev2;
    int ea_n[2];             /* edge check, [fine, coarse] */
    int64_t ea_b[2][3];
    uint64_t ea_t[2][3];
    uint64_t frac[2];        /* vote fractions, 2^-62 */
    uint64_t last_shape, last_line, last_edge;  /* 2^-32 counts; UINT64_MAX: beyond range */
    uint64_t last_motion;    /* 2^-32 (relative); UINT64_MAX: beyond range */
    qei_calfx_counts_t n;
    qei_calfx_method_t m[2]; /* [0] A rising, [1] any edge */
} qei_calfx_t;

/* 0, or -1 when the configuration is out of range or buf_len < QEI_CALFX_BUF_LEN(cycles) */
int qei_calfx_init(qei_calfx_t *st, const qei_calfx_cfg_t *cfg, int64_t *buf, size_t buf_len);
void qei_calfx_push(qei_calfx_t *st, const qei_calfx_entry_t *e);
qei_calfx_reading_t qei_calfx_read(qei_calfx_t *st, uint32_t time);
int qei_calfx_calibrated(const qei_calfx_t *st);

#ifdef __cplusplus
}
#endif
#endif
