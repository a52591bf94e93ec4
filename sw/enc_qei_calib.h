/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_calib.h -- a self-calibrating velocity estimator fed by enc_qei's edge-capture FIFO,
 * that uses what it has learnt only while the edges confirm it (C99, no malloc, no libm but
 * sqrt and fabs).
 *
 * The same algorithm as python/src/hedsmodel/calibration.py, operation for operation, in double
 * precision; tb/velocity/test_velocity_calibration.py compiles this file with gcc -std=c99 -Wall
 * -Wextra -Werror -pedantic and requires both to agree to 1e-12 on the same entry streams. The
 * full specification is that module's docstring; doc/velocity.md has the user's summary.
 *
 * Use:
 *   static double buf[QEI_CAL_BUF_LEN(500)];        3 x 4N doubles: table, pass, revolution
 *   qei_cal_cfg_t cfg = {tick_s, 32, 500, 1, 8, stall_ticks, 1e-3, 0.05, 0.005, 0.15};
 *   qei_cal_init(&st, &cfg, buf, QEI_CAL_BUF_LEN(500));
 *   once per servo period: pop every FIFO entry (until the FIFO is empty) into qei_cal_push(),
 *   then read the TIMEBASE and call qei_cal_read(): r.mt_a (M/T on A-rising edges) and r.any
 *   (any-edge), count steps per second, calibrated when r.calibrated, else exactly the
 *   uncalibrated readings.
 *
 * Learning: the time of 4N consecutive edges is one revolution, free of wheel errors; the
 * distance travelled is fitted as a quadratic through the revolution boundaries (constant
 * acceleration) and each edge's angle in the revolution read off it. A revolution is clean when
 * its period and the two before fit one constant acceleration within motion_tol; a clean
 * revolution the table does not explain joins the learning pass if it agrees with the pass's
 * mean (shape, line and edge figures within shape_tol, line_tol, edge_tol counts rms), else the
 * pass restarts from it; learn_revs agreeing revolutions become the table. Trust: the table is
 * used while its phase is known, no IDX disagreement is pending, the latest clean revolution
 * agreed with it and the A-rising edges' timing is no rougher with it than without it (at every
 * edge and every eighth of a revolution; a jolt makes it earn that again). IDX: the first sets
 * boundary 0; one in another place is pending until the next confirms either place (a second
 * in the new place re-indexes: the count slipped). LOST, or an entry whose A/B state does not
 * follow the previous one: the phase is unknown until the next IDX (without an index: the
 * table is relearnt).
 */
#ifndef ENC_QEI_CALIB_H
#define ENC_QEI_CALIB_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* doubles the caller provides for N cycles per revolution */
#define QEI_CAL_BUF_LEN(cycles) ((size_t)12u * (size_t)(cycles))

typedef struct {
    uint32_t time;  /* TIMEBASE at the step, TS_W bits */
    uint8_t  a, b;  /* A/B state after the step */
    uint8_t  up;    /* 1: +1 step, 0: -1 */
    uint8_t  lost;  /* entries were lost before this one */
    uint8_t  idx;   /* a qualified index edge came up to this step */
} qei_cal_entry_t;

typedef struct {
    double   tick_s;     /* seconds per timebase tick */
    unsigned ts_w;       /* timebase width, 1 .. 32 */
    uint32_t cycles;     /* N, cycles per revolution (4N states), 2 .. 2^20 */
    int      use_index;  /* 1: phase the table on IDX entries */
    uint32_t learn_revs; /* agreeing clean revolutions averaged into a table, >= 1 */
    uint64_t stall_ticks; /* stall timeout in ticks since the last selected edge, 0 = off */
    double   motion_tol; /* relative speed mismatch of a clean revolution, > 0; 1e-3 */
    double   shape_tol;  /* agreement, counts rms, > 0: smooth shape 0.05 */
    double   line_tol;   /*   cycle-to-cycle at the A edges 0.005 */
    double   edge_tol;   /*   within the cycles 0.15 */
} qei_cal_cfg_t;

typedef struct {
    double mt_a;     /* M/T on A-rising edges, count steps per second */
    double any;      /* any-edge, count steps per second */
    int calibrated;  /* the table was in use */
} qei_cal_reading_t;

typedef struct {
    uint32_t learned;     /* tables learnt with none before */
    uint32_t changes;     /* tables replaced by a pass that disagreed with them */
    uint32_t rejected;    /* learning passes restarted (a revolution disagreed with the pass) */
    uint32_t disagree;    /* clean revolutions that disagreed with the table */
    uint32_t unclean;     /* revolutions that failed the motion check */
    uint32_t reindex;     /* re-indexes (an IDX frame confirmed twice) */
    uint32_t suspect;     /* IDX steps that disagreed with the frame */
    uint32_t lost;        /* LOST entries */
    uint32_t missed;      /* entries whose A/B state did not follow the previous one */
    uint32_t edge_alarms; /* edge check failures */
    uint32_t jolts;       /* jolts */
} qei_cal_counts_t;

typedef struct {
    unsigned cpe;
    int has_last, has_ref, new_edge, dir;
    int64_t last_b, ref_b;
    uint64_t last_t, ref_t;
    double mag;
} qei_cal_method_t;

typedef struct {
    qei_cal_cfg_t cfg;
    double *table, *acc, *work;
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
    double frac[2];
    double last_shape, last_line, last_edge, last_motion;
    qei_cal_counts_t n;
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
