/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_velocity.h -- host-side velocity estimators for enc_qei snapshot readings (C99).
 *
 * The same estimators as python/src/hedsmodel/velocity.py, operation for operation, so the two
 * agree (tb/velocity/test_velocity_estimators.py compiles this file with gcc -std=c99 -Wall
 * -Werror and compares them on the same vectors). Arithmetic: integer wrap handling (timebase
 * modulo 2^TS_W, count modulo 2^COUNT_W), then one division in double precision per method. No
 * other floating point, no libm. Build with any C99 compiler; on an FPU-less target the three
 * divisions per reading go through the soft-float library: there use the fixed-point version,
 * enc_qei_velocity_fx.h (the same rules, readings within one unit of 2^-F count/s; on the
 * simulated VexRiscv a channel's cycles drop from thousands to hundreds: doc/results/soc_sim.md).
 *
 * Input: one qei_vel_snap_t per read of the snapshot registers (rtl/enc_qei.rdl):
 *   count       SNAP_COUNT (COUNT_W bits, as read: {SNAP_COUNT_HI, SNAP_COUNT_LO})
 *   time        SNAP_TIME, timebase ticks (TS_W bits)
 *   edge_time   SNAP_EDGE_TIME, timebase at the last edge of the selected type (SNAP_CTRL.EDGE)
 *   delta       SNAP_DELTA, signed count steps since the previous snapshot
 *   edge_delta  SNAP_EDGE_DELTA, signed count steps between the last selected edges
 *   period      PERIOD, ticks spanned by the last period_n edges (PERIOD_CTRL.N); 0 = none yet
 *   period_ovf, period_dir_change   PERIOD_CTRL.OVERFLOW, PERIOD_CTRL.DIR_CHANGE
 *   stalled     STATUS.STALLED (or 0 to rely on stall_ticks alone)
 * Output: velocities in count steps per second, signed (qei_vel_rpm converts).
 *
 * Methods (cpe = count steps per selected edge: 1 for any edge with x4 counting, 4 for A-rising
 * edges; since = time - edge_time modulo 2^TS_W; "new edge" = edge_delta != 0 or edge_time
 * changed since the previous snapshot):
 *   M  (unit time):  delta / (time - prev time). No standstill rule: it reads 0 whenever no
 *                    count arrives in a read period (below 30 rpm at 1 kHz reads on a
 *                    HEDS-5000, 500 cycles/rev, x4).
 *   T  (period):     period_n * cpe / period, in the direction of the last non-zero delta; 0
 *                    with no measurement, on overflow, across a direction change, and from a
 *                    snapshot whose delta reverses the direction until the next new edge in a
 *                    later snapshot.
 *   MT (timestamp, hostmot2): on a new edge, edge_delta / (edge_time - prev edge_time).
 *                    Reversal rule: a new edge whose edge_delta has the sign opposite to the
 *                    last one reads 0 and becomes the new reference; so does a new edge with
 *                    edge_delta == 0 (there and back). When delta goes against the last
 *                    direction before a selected edge confirms it (A rising at low speed), the
 *                    reading is 0 at once, the direction follows the counts and the next new
 *                    edge is a reference only (its interval spans the reversal). The first new
 *                    edge after qei_vel_init is a reference only too.
 *   Standstill rule (T, MT): no new edge since the previous snapshot -> magnitude =
 *                    min(last magnitude, cpe / since), in the last direction: a slowly turning
 *                    shaft never reads 0 between edges, a stopped one decays like 1/t.
 *   Stall (T, MT):   0 when since >= stall_ticks (stall_ticks > 0) or the snapshot is stalled.
 * The first snapshot after qei_vel_init only initialises (all readings 0).
 *
 * Choose the timebase so that 2^TS_W ticks exceed both the read period and stall_ticks (times
 * are only known modulo 2^TS_W), and stall_ticks above one cycle at the lowest speed that must
 * not read 0 (A rising at 6 rpm: 20 ms).
 */
#ifndef ENC_QEI_VELOCITY_H
#define ENC_QEI_VELOCITY_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    uint64_t count;
    uint32_t time;
    uint32_t edge_time;
    int32_t  delta;
    int32_t  edge_delta;
    uint32_t period;
    uint32_t period_n;
    uint8_t  period_ovf;
    uint8_t  period_dir_change;
    uint8_t  stalled;
} qei_vel_snap_t;

typedef struct {
    double   tick_s;           /* seconds per timebase tick: (TB_PRESCALE + 1) / f_clk */
    unsigned ts_w;             /* timebase width, 1 .. 32 (CAPS.TS_W) */
    unsigned count_w;          /* counter width, 1 .. 64 (CAPS.COUNT_W) */
    unsigned counts_per_edge;  /* count steps per selected edge: x4 any edge 1, A rising 4 */
    uint32_t stall_ticks;      /* stall timeout in ticks since the last selected edge, 0 = off */
    int      delta_from_count; /* 1: M uses the wrapped SNAP_COUNT difference, not SNAP_DELTA */
} qei_vel_cfg_t;

typedef struct {
    double m;   /* unit-time method */
    double t;   /* period method */
    double mt;  /* timestamp method */
} qei_vel_reading_t;

typedef struct {
    qei_vel_cfg_t  cfg;
    int            have_prev;
    qei_vel_snap_t prev;
    int            mt_dir;   /* direction of motion for MT */
    double         mt_mag;   /* magnitude of the last MT measurement, counts/s */
    int            mt_ref;   /* the next new edge is a reference only */
    int            t_dir;    /* direction of the last non-zero delta */
    int            t_hold;   /* T reads 0: delta reversed, no new edge since */
} qei_vel_t;

/* Returns 0, or -1 when the configuration is out of range (the state is then unusable). */
int qei_vel_init(qei_vel_t *st, const qei_vel_cfg_t *cfg);
/* One snapshot in, three readings (count steps per second) out. */
qei_vel_reading_t qei_vel_update(qei_vel_t *st, const qei_vel_snap_t *snap);
/* Count steps per second -> shaft rpm, for counts_per_rev count steps per revolution (x4 on a
 * 500-cycle HEDS-5000: 2000). */
double qei_vel_rpm(double counts_per_s, unsigned counts_per_rev);

/*
 * Reading the registers. Include the generated sw/enc_qei_regs.h before this header and
 * qei_vel_read_snapshot() is defined for one channel's page (&q->chan[k]): it takes a snapshot of
 * that channel by bus command
 * (SNAP_CTRL.CMD, keeping the other SNAP_CTRL fields) and reads it, with PERIOD, PERIOD_CTRL and
 * STATUS right after (those three are live values, not latched with the snapshot). count_w is
 * CAPS.COUNT_W. It reads the snapshot straight after the command, so it needs the command to
 * act before the next read: true of the per-channel build on a bus that does not post writes,
 * not necessarily of a shared-engine build (CAPS.ENGINE), which may show it later. Firmware
 * for every build uses enc_qei_drv_snap_take() of sw/enc_qei_drv.h, which waits for
 * EVENTS.SNAP_READY.
 */
#ifdef ENC_QEI_REGS_H
static inline void qei_vel_read_snapshot(volatile enc_qei_chan_t *q, unsigned count_w,
                                         qei_vel_snap_t *s)
{
    uint32_t pc, st;
    q->SNAP_CTRL = (q->SNAP_CTRL & ~(uint32_t)ENC_QEI__SNAP_CTRL__CMD_bm) |
                   ENC_QEI__SNAP_CTRL__CMD_bm;
    s->count = q->SNAP_COUNT_LO;
    if (count_w > 32u)
        s->count |= (uint64_t)q->SNAP_COUNT_HI << 32;
    s->time = q->SNAP_TIME;
    s->edge_time = q->SNAP_EDGE_TIME;
    s->delta = (int32_t)q->SNAP_DELTA;
    s->edge_delta = (int32_t)q->SNAP_EDGE_DELTA;
    s->period = q->PERIOD;
    pc = q->PERIOD_CTRL;
    st = q->STATUS;
    s->period_n = (pc & ENC_QEI__PERIOD_CTRL__N_bm) >> ENC_QEI__PERIOD_CTRL__N_bp;
    s->period_ovf = (uint8_t)((pc & ENC_QEI__PERIOD_CTRL__OVERFLOW_bm) != 0u);
    s->period_dir_change = (uint8_t)((pc & ENC_QEI__PERIOD_CTRL__DIR_CHANGE_bm) != 0u);
    s->stalled = (uint8_t)((st & ENC_QEI__STATUS__STALLED_bm) != 0u);
}
#endif

#ifdef __cplusplus
}
#endif

#endif /* ENC_QEI_VELOCITY_H */
