/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_drv.h -- a bare-metal driver API for the enc_qei peripheral (C99): no malloc, no OS,
 * the caller owns every buffer. Written over the generated register header sw/enc_qei_regs.h;
 * the walk-through is doc/enc_qei.md (section "Firmware: the driver API").
 *
 *   enc_qei_dev_t dev;
 *   if (enc_qei_drv_init(&dev, (volatile enc_qei_t *)ENC_QEI_BASE) != ENC_QEI_DRV_OK) ...
 *
 * Every build: enc_qei_drv_init() reads ID and CAPS and refuses a block that is not enc_qei
 * (ID.MAGIC), another major version of the register map, or a map older than 1.2 (CTRL.CMP_EN,
 * deltas that count the motion); it takes CHANNELS, PROFILE, COUNT_W, TS_W and EFIFO_LOG2 from
 * CAPS and touches pages 0 .. CHANNELS - 1 only. Snapshot functions need the timing unit (the
 * full and lean profiles): in a counting build they return ENC_QEI_DRV_ENOTSUP.
 *
 * Writes are not assumed visible to the next read. A build whose channels share one engine
 * (CAPS.ENGINE = shared) may show a write's effect, a snapshot and a count step up to a bounded
 * number of clocks late (the register descriptions give the bounds); only the snapshot registers
 * are exact. So the driver
 *   - reads SNAP_* only after that channel's EVENTS.SNAP_READY reads 1 (the hardware raises it
 *     once SNAP_* hold the new snapshot), never straight after a SNAP_CTRL.CMD or
 *     GSNAP_CTRL.CMD write;
 *   - after clearing EVENTS bits (write 1 to clear) reads EVENTS back until they read 0, so
 *     that the same event is not taken twice (an interrupt handler left before the clear lands
 *     would be entered again for it);
 *   - never read-modify-writes a register it configures: it keeps the values it wrote to
 *     GSNAP_CTRL, SNAP_CTRL and IRQ_EN in enc_qei_dev_t (shadows) and writes those. Change
 *     those three registers only through the driver, or call enc_qei_drv_init() again.
 * Every wait is bounded: dev.spin reads of EVENTS (ENC_QEI_DRV_SPIN_DEFAULT, set by init; each
 * read is a bus access of at least 3 peripheral clocks).
 *
 * Snapshots read into qei_vel_snap_t (enc_qei_velocity.h), the input of both velocity
 * estimators (qei_vel_update(), qei_velfx_update()). Without ENC_QEI_DRV_SNAP_LIVE the live
 * fields (period, period_n, period_ovf, period_dir_change, stalled) read as "no period
 * measurement, not stalled"; with it PERIOD and PERIOD_CTRL (full profile only) and
 * STATUS.STALLED are read right after the snapshot: live values, not latched with it.
 *
 * Concurrency: the functions that take a const enc_qei_dev_t * may run in an interrupt handler
 * while the main program is not inside a driver call for the same channel; nothing here
 * disables interrupts.
 *
 * Register access goes through ENC_QEI_DRV_RD(reg) and ENC_QEI_DRV_WR(reg, value) (default: a
 * volatile access). Define them when compiling enc_qei_drv.c to add bus barriers or to run the
 * driver against a model (tb/enc_qei_doc/drv_model.c does).
 *
 * Tested by tb/enc_qei_doc/test_c_driver.py against a register model that lands writes and
 * snapshots late, and by make soc-sim on the RTL of a per-channel and of a shared-engine build.
 */
#ifndef ENC_QEI_DRV_H
#define ENC_QEI_DRV_H

#include <stdint.h>

#include "enc_qei_regs.h"
#include "enc_qei_velocity.h"   /* qei_vel_snap_t */

#ifdef __cplusplus
extern "C" {
#endif

/* Return values: 0 or one of these (negative). */
#define ENC_QEI_DRV_OK        0
#define ENC_QEI_DRV_ENODEV   (-1)  /* ID.MAGIC is not 0x5145: no enc_qei at this address */
#define ENC_QEI_DRV_EVERSION (-2)  /* register map not 1.x with x >= 2 */
#define ENC_QEI_DRV_ECAPS    (-3)  /* CAPS.CHANNELS 0 or above 16, COUNT_W 0 or above 64, or
                                      TS_W above 32 */
#define ENC_QEI_DRV_EINVAL   (-4)  /* a channel number >= CAPS.CHANNELS */
#define ENC_QEI_DRV_ENOTSUP  (-5)  /* the build has no timing unit (CAPS.TIMING = 0) */
#define ENC_QEI_DRV_ETIMEDOUT (-6) /* SNAP_READY did not come within dev.spin reads */
#define ENC_QEI_DRV_ESKEW    (-7)  /* a channel's SNAP_TIME is not GSNAP_TIME: not one global
                                      snapshot (a newer one landed during the reads, or the
                                      channel took one of its own); the values are filled in */

#define ENC_QEI_DRV_SPIN_DEFAULT 1000u

/* flags of the snapshot functions */
#define ENC_QEI_DRV_SNAP_LIVE 1u   /* also read PERIOD, PERIOD_CTRL and STATUS.STALLED */

typedef struct {
    volatile enc_qei_t *regs;
    uint32_t id, caps;      /* as read by init */
    unsigned version;       /* ID.VERSION: major << 8 | minor */
    unsigned channels;      /* CAPS.CHANNELS, 1 .. 16 */
    unsigned profile;       /* CAPS.PROFILE: ENC_QEI__CAPS__PROFILE__*_VAL */
    unsigned count_w;       /* CAPS.COUNT_W */
    uint64_t count_mask;    /* 2^COUNT_W - 1 */
    unsigned ts_w;          /* CAPS.TS_W */
    unsigned efifo_log2;    /* CAPS.EFIFO_LOG2: 0 = no edge FIFO */
    int      has_timing;    /* CAPS.TIMING: snapshots and the global snapshot */
    uint32_t spin;          /* reads of EVENTS before a wait gives up */
    /* shadows: what the driver last wrote (CMD bits not included) */
    uint32_t gsnap_ctrl;
    uint32_t snap_ctrl[ENC_QEI_CHANNELS_MAX];
    uint32_t irq_en[ENC_QEI_CHANNELS_MAX];
} enc_qei_dev_t;

/* Find the build at regs: ID, CAPS; the shadows from the registers' present values (call it
 * before anything else writes GSNAP_CTRL, SNAP_CTRL or IRQ_EN). Writes nothing. */
int enc_qei_drv_init(enc_qei_dev_t *d, volatile enc_qei_t *regs);
/* A short name for a return value: "ok", "no enc_qei (ID.MAGIC)", ... */
const char *enc_qei_drv_strerror(int err);

/* A COUNT_W-bit count (COUNT, SNAP_COUNT, a latch) as a signed position: two's complement in
 * COUNT_W bits. */
static inline int64_t enc_qei_drv_signed(const enc_qei_dev_t *d, uint64_t count)
{
    count &= d->count_mask;
    if (count > d->count_mask >> 1)          /* bit COUNT_W - 1 set */
        count |= ~d->count_mask;
    return (int64_t)count;   /* two's complement on every C99 target with int64_t */
}
/* Channel k's count as a signed position (two's complement in COUNT_W bits): COUNT_LO, which
 * latches the high word, then COUNT_HI when COUNT_W > 32. On a shared-engine build a count
 * step shows up to the bound late; a snapshot is exact. */
int enc_qei_drv_read_position(const enc_qei_dev_t *d, unsigned k, int64_t *pos);

/* SNAP_CTRL of channel k (the edge type, its own unit timer and snap_in), CMD left out; kept
 * for the CMD writes of enc_qei_drv_snap_take(). */
int enc_qei_drv_snap_config(enc_qei_dev_t *d, unsigned k, uint32_t snap_ctrl);
/* Channel k's snapshot by command: clear its SNAP_READY (and see it clear), SNAP_CTRL.CMD,
 * then enc_qei_drv_snap_read(). */
int enc_qei_drv_snap_take(const enc_qei_dev_t *d, unsigned k, qei_vel_snap_t *s, unsigned flags);
/* Wait for channel k's EVENTS.SNAP_READY (at most dev.spin reads), clear it (and see it
 * clear), read the snapshot registers into *s. For a snapshot something else took: the unit
 * timer, snap_in, or a global snapshot in an interrupt handler. */
int enc_qei_drv_snap_read(const enc_qei_dev_t *d, unsigned k, qei_vel_snap_t *s, unsigned flags);

/* GSNAP_PERIOD (timebase ticks between unit-timer snapshots; 0 acts as 1), then GSNAP_CTRL
 * (PERIOD_EN, IN_EN; CMD left out). */
int enc_qei_drv_gsnap_config(enc_qei_dev_t *d, uint32_t gsnap_ctrl, uint32_t period);
/* One global snapshot by command: every channel's SNAP_READY cleared (and seen clear),
 * GSNAP_CTRL.CMD (the configured fields kept), then enc_qei_drv_gsnap_read(). */
int enc_qei_drv_gsnap_take(const enc_qei_dev_t *d, uint32_t *time, qei_vel_snap_t *snaps,
                           unsigned flags);
/* Every channel's part of one global snapshot: enc_qei_drv_snap_read() of channels
 * 0 .. CHANNELS - 1 into snaps[0 .. CHANNELS - 1], then GSNAP_TIME into *time; returns
 * ENC_QEI_DRV_ESKEW when a channel's SNAP_TIME differs from it. In the handler of the
 * SNAP_READY interrupt, call it before clearing SNAP_READY (it clears every channel's). */
int enc_qei_drv_gsnap_read(const enc_qei_dev_t *d, uint32_t *time, qei_vel_snap_t *snaps,
                           unsigned flags);

/* IRQ_SUMMARY.PENDING: bit k = channel k has an enabled event pending. */
uint32_t enc_qei_drv_irq_pending(const enc_qei_dev_t *d);
/* IRQ_EN of channel k |= events, &= ~events (EVENTS bit masks); from the shadow, no read. */
int enc_qei_drv_irq_enable(enc_qei_dev_t *d, unsigned k, uint32_t events);
int enc_qei_drv_irq_disable(enc_qei_dev_t *d, unsigned k, uint32_t events);
/* EVENTS of channel k: every pending event, enabled or not (0 for a bad channel). */
uint32_t enc_qei_drv_events(const enc_qei_dev_t *d, unsigned k);
/* Clear these EVENTS bits of channel k (write 1 to clear) and read EVENTS until they read 0
 * (at most dev.spin reads: a bit still 1 then was raised again). */
int enc_qei_drv_events_clear(const enc_qei_dev_t *d, unsigned k, uint32_t events);
/* The handler's step: channel k's pending events that IRQ_EN enables, cleared as above, and
 * returned (0: none). Other pending events stay pending. */
uint32_t enc_qei_drv_events_take(const enc_qei_dev_t *d, unsigned k);

#ifdef __cplusplus
}
#endif

#endif /* ENC_QEI_DRV_H */
