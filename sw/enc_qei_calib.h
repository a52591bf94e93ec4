/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_calib.h -- a self-calibrating velocity estimator fed by enc_qei's edge-capture FIFO
 * (C99, no malloc, no libm but sqrt).
 *
 * The same algorithm as python/src/hedsmodel/calibration.py, operation for operation, in double
 * precision; tb/velocity/test_velocity_calibration.py compiles this file with gcc -std=c99 -Wall
 * -Wextra -Werror -pedantic and requires both to agree to 1e-12 on the same entry streams. The
 * full description (what is learnt, how, the reference, the rules) is that module's docstring;
 * doc/velocity.md has the user's summary.
 *
 * Use:
 *   static double buf[QEI_CAL_BUF_LEN(500)];        2 x 4N doubles: table + one revolution
 *   qei_cal_cfg_t cfg = {tick_s, 32, 500, 1, 8, stall_ticks, 0.06, 2};
 *   qei_cal_init(&st, &cfg, buf, QEI_CAL_BUF_LEN(500));
 *   once per servo period: pop every FIFO entry (until the FIFO is empty) into qei_cal_push(),
 *   then read the TIMEBASE and call qei_cal_read(): r.mt_a (calibrated M/T on A-rising edges)
 *   and r.any (calibrated any-edge), count steps per second.
 *
 * Learning: the time of 4N consecutive edges is one revolution, free of wheel errors; the
 * distance travelled is fitted as a quadratic through three revolution boundaries (constant
 * acceleration: exact on ramps) and each edge's angle in the revolution is read off it; the
 * table is the mean of learn_revs revolutions (learn_revs + 1 whole ones after boundary 0). The
 * reference is the first IDX entry (use_index) or the first entry. LOST: with an index, the
 * phase is unknown until the next IDX (table kept); without one, the table is relearnt. An IDX
 * in another state than before (per direction): re-index, relearn. change_revs consecutive
 * revolutions whose high-passed state extents differ from the table by more than
 * change_threshold counts rms: changed wheel, relearn. Readings: angle between the latest
 * selected edge and the latest one at the previous read (calibrated when the table is learnt
 * and phased) over their time; a reversal or LOST reads 0 and the next selected edge is a
 * reference only; with no new edge min(last, ext / since), ext = the
 * (calibrated) angle to the next selected edge; 0 after stall_ticks.
 */
#ifndef ENC_QEI_CALIB_H
#define ENC_QEI_CALIB_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* doubles the caller provides for N cycles per revolution */
#define QEI_CAL_BUF_LEN(cycles) ((size_t)8u * (size_t)(cycles))

typedef struct {
    uint32_t time;  /* TIMEBASE at the step, TS_W bits */
    uint8_t  a, b;  /* A/B state after the step */
    uint8_t  up;    /* 1: +1 step, 0: -1 */
    uint8_t  lost;  /* entries were lost before this one */
    uint8_t  idx;   /* a qualified index edge came up to this step */
} qei_cal_entry_t;

typedef struct {
    double   tick_s;           /* seconds per timebase tick */
    unsigned ts_w;             /* timebase width, 1 .. 32 */
    uint32_t cycles;           /* N, cycles per revolution (4N states), 1 .. 2^20 */
    int      use_index;        /* 1: phase the table on IDX entries */
    uint32_t learn_revs;       /* revolutions averaged, >= 1 */
    uint64_t stall_ticks;      /* stall timeout in ticks since the last selected edge, 0 = off */
    double   change_threshold; /* counts rms (high-passed state extents), > 0; 0.06 typical */
    uint32_t change_revs;      /* consecutive disagreeing revolutions = changed wheel, >= 1 */
} qei_cal_cfg_t;

typedef struct {
    double mt_a;     /* calibrated M/T on A-rising edges, count steps per second */
    double any;      /* calibrated any-edge, count steps per second */
    int calibrated;  /* the table was in use */
} qei_cal_reading_t;

typedef struct {
    unsigned cpe;
    int has_last, has_ref, new_edge, dir;
    int64_t last_b, ref_b;
    uint64_t last_t, ref_t;
    double mag;
} qei_cal_method_t;

typedef struct {
    qei_cal_cfg_t cfg;
    double *table, *work;
    int64_t S;
    uint32_t mask, t_raw;
    uint64_t t;
    int started, dir, phase_ok, valid, rev_dir;
    int64_t pos, ref, idx_state[2], rev_next;
    uint32_t acc_revs, bad;
    uint64_t rev_t0, t_prev;
    double last_check;
    uint32_t n_learned, n_changes, n_reindex, n_lost;
    qei_cal_method_t m[2];   /* [0] A rising, [1] any edge */
} qei_cal_t;

/* 0, or -1 when the configuration is out of range or buf_len < QEI_CAL_BUF_LEN(cycles) */
int qei_cal_init(qei_cal_t *st, const qei_cal_cfg_t *cfg, double *buf, size_t buf_len);
void qei_cal_push(qei_cal_t *st, const qei_cal_entry_t *e);
qei_cal_reading_t qei_cal_read(qei_cal_t *st, uint32_t time);
int qei_cal_calibrated(const qei_cal_t *st);

#ifdef __cplusplus
}
#endif
#endif
