/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_velocity_fx.h -- the velocity estimators of enc_qei_velocity.h in fixed point (C99):
 * integer arithmetic only, no floating point, no libm, no 64-bit division routine; for CPUs
 * without an FPU (a VexRiscv in a LiteX SoC: doc/litex.md).
 *
 * Same inputs (qei_vel_snap_t, one per read of a channel's snapshot registers), same methods and
 * the same rules as qei_vel_update() -- M (unit time), T (period), MT (timestamp), the reversal
 * rules, the standstill rule (no new edge: at most one edge's counts over the time since the
 * last edge), the stall timeout -- decided with the same integer comparisons, so only the
 * divisions differ.
 *
 * Readings: int32_t in units of 2^-F count steps per second, F = cfg.frac_bits (0 .. 31):
 *   resolution  2^-F count/s         (F = 8: 1/256 = 0.0039 count/s)
 *   range       +-(2^31 - 1) * 2^-F  (F = 8: +-8,388,607.996 count/s; F = 16: +-32,767.99998)
 * A reading is the exact quotient of the double version (count steps * tick_hz * 2^F over the
 * ticks) rounded to the nearest unit, ties away from zero, so it differs from the double
 * version's reading * 2^F by at most 1/2 unit (plus the double's own rounding, below 1e-5
 * unit); tb/velocity/test_velocity_fixed.py fails when any reading is off by more than one unit.
 * A speed beyond the range reads +-(2^31 - 1) (QEI_VELFX_MAX): saturated, never wrapped. Pick F
 * for the fastest speed the axis can reach: count steps per second < 2^(31 - F).
 *
 * Time: tick_hz timebase ticks per second, a whole number: f_clk / (TB_PRESCALE + 1) must be an
 * integer number of Hz (50 MHz with TB_PRESCALE 0, 4, 9, ...; the double version takes any
 * tick). Intervals are taken modulo 2^TS_W as in the double version.
 *
 * Cost: at most three 64-by-32-bit divisions per qei_velfx_update() (M when the counts moved,
 * MT on a new edge or else the standstill bound, T with a period), at most one per
 * qei_velfx_update_mt(), each by two 32-bit hardware divisions (RV32M's divu); none where a
 * reading is 0 by rule. The first snapshot after qei_velfx_init only initialises (all readings
 * 0).
 */
#ifndef ENC_QEI_VELOCITY_FX_H
#define ENC_QEI_VELOCITY_FX_H

#include <stdint.h>

#include "enc_qei_velocity.h"   /* qei_vel_snap_t: the snapshot registers */

#ifdef __cplusplus
extern "C" {
#endif

#define QEI_VELFX_MAX INT32_MAX   /* |reading| of a saturated speed */

typedef struct {
    uint32_t tick_hz;          /* timebase ticks per second, > 0: f_clk / (TB_PRESCALE + 1) */
    unsigned frac_bits;        /* F, 0 .. 31: readings in 2^-F count steps per second */
    unsigned ts_w;             /* timebase width, 1 .. 32 (CAPS.TS_W) */
    unsigned count_w;          /* counter width, 1 .. 64 (CAPS.COUNT_W) */
    unsigned counts_per_edge;  /* count steps per selected edge: x4 any edge 1, A rising 4 */
    uint32_t stall_ticks;      /* stall timeout in ticks since the last selected edge, 0 = off */
    int      delta_from_count; /* 1: M uses the wrapped SNAP_COUNT difference, not SNAP_DELTA */
} qei_velfx_cfg_t;

typedef struct {
    int32_t m;   /* unit-time method, 2^-F count/s */
    int32_t t;   /* period method */
    int32_t mt;  /* timestamp method */
} qei_velfx_reading_t;

typedef struct {
    qei_velfx_cfg_t cfg;
    uint64_t edge_num;   /* counts_per_edge * tick_hz: the standstill bound's numerator */
    uint64_t num_max;    /* the largest numerator whose 2^F multiple fits 64 bits */
    uint64_t count_mask; /* 2^COUNT_W - 1 */
    uint32_t ts_mask;    /* 2^TS_W - 1 */
    uint64_t prev_count;
    uint32_t prev_time, prev_edge_time;
    int      have_prev;
    int      mt_dir;     /* direction of motion for MT */
    uint32_t mt_mag;     /* magnitude of the last MT measurement, 2^-F count/s */
    int      mt_ref;     /* the next new edge is a reference only */
    int      t_dir;      /* direction of the last non-zero delta */
    int      t_hold;     /* T reads 0: delta reversed, no new edge since */
} qei_velfx_t;

/* Returns 0, or -1 when the configuration is out of range (the state is then unusable). */
int qei_velfx_init(qei_velfx_t *st, const qei_velfx_cfg_t *cfg);
/* One snapshot in, three readings (2^-F count steps per second) out. */
qei_velfx_reading_t qei_velfx_update(qei_velfx_t *st, const qei_vel_snap_t *snap);
/* The timestamp method alone: qei_velfx_update(st, snap).mt without computing M and T (none of
 * their divisions), for a servo loop that reads only MT. Feed a state with one of the two
 * functions, not both: this one leaves T's state alone. */
int32_t qei_velfx_update_mt(qei_velfx_t *st, const qei_vel_snap_t *snap);

#ifdef __cplusplus
}
#endif

#endif /* ENC_QEI_VELOCITY_FX_H */
