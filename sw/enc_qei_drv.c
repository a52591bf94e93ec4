/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_drv.c -- see enc_qei_drv.h. */
#include "enc_qei_drv.h"

#ifndef ENC_QEI_DRV_RD
#define ENC_QEI_DRV_RD(reg) (reg)
#endif
#ifndef ENC_QEI_DRV_WR
#define ENC_QEI_DRV_WR(reg, value) ((reg) = (value))
#endif

#define RD(reg) ENC_QEI_DRV_RD(reg)
#define WR(reg, value) ENC_QEI_DRV_WR(reg, value)

#define SNAP_READY ENC_QEI__EVENTS__SNAP_READY_bm

int enc_qei_drv_init(enc_qei_dev_t *d, volatile enc_qei_t *regs)
{
    uint32_t id = RD(regs->glb.ID), caps = RD(regs->glb.CAPS);
    unsigned version = ENC_QEI__ID__VERSION_GET(id), k;

    d->regs = regs;
    d->id = id;
    d->caps = caps;
    d->version = version;
    d->channels = 0u;
    if (ENC_QEI__ID__MAGIC_GET(id) != ENC_QEI__ID__MAGIC_reset)
        return ENC_QEI_DRV_ENODEV;
    if ((version >> 8) != 1u || (version & 0xFFu) < 2u)
        return ENC_QEI_DRV_EVERSION;
    if (ENC_QEI__CAPS__CHANNELS_GET(caps) < 1u ||
        ENC_QEI__CAPS__CHANNELS_GET(caps) > ENC_QEI_CHANNELS_MAX ||
        ENC_QEI__CAPS__COUNT_W_GET(caps) < 1u || ENC_QEI__CAPS__COUNT_W_GET(caps) > 64u ||
        ENC_QEI__CAPS__TS_W_GET(caps) > 32u)
        return ENC_QEI_DRV_ECAPS;
    d->channels = ENC_QEI__CAPS__CHANNELS_GET(caps);
    d->profile = ENC_QEI__CAPS__PROFILE_GET(caps);
    d->count_w = ENC_QEI__CAPS__COUNT_W_GET(caps);
    d->count_mask = d->count_w >= 64u ? ~(uint64_t)0 : ((uint64_t)1 << d->count_w) - 1u;
    d->ts_w = ENC_QEI__CAPS__TS_W_GET(caps);
    d->efifo_log2 = ENC_QEI__CAPS__EFIFO_LOG2_GET(caps);
    d->has_timing = (int)ENC_QEI__CAPS__TIMING_GET(caps);
    d->spin = ENC_QEI_DRV_SPIN_DEFAULT;
    d->gsnap_ctrl = d->has_timing
        ? RD(regs->glb.GSNAP_CTRL) & ~(uint32_t)ENC_QEI__GSNAP_CTRL__CMD_bm : 0u;
    for (k = 0; k < ENC_QEI_CHANNELS_MAX; k++) {
        int here = k < d->channels;
        d->snap_ctrl[k] = here && d->has_timing
            ? RD(regs->chan[k].SNAP_CTRL) & ~(uint32_t)ENC_QEI__SNAP_CTRL__CMD_bm : 0u;
        d->irq_en[k] = here ? RD(regs->chan[k].IRQ_EN) : 0u;
    }
    return ENC_QEI_DRV_OK;
}

const char *enc_qei_drv_strerror(int err)
{
    switch (err) {
    case ENC_QEI_DRV_OK: return "ok";
    case ENC_QEI_DRV_ENODEV: return "no enc_qei (ID.MAGIC)";
    case ENC_QEI_DRV_EVERSION: return "register map not 1.2 or a later 1.x (ID.VERSION)";
    case ENC_QEI_DRV_ECAPS: return "CAPS out of range (CHANNELS 1..16, COUNT_W 1..64, TS_W <= 32)";
    case ENC_QEI_DRV_EINVAL: return "no such channel";
    case ENC_QEI_DRV_ENOTSUP: return "no timing unit in this build (CAPS.TIMING)";
    case ENC_QEI_DRV_ETIMEDOUT: return "no SNAP_READY";
    case ENC_QEI_DRV_ESKEW: return "SNAP_TIME differs from GSNAP_TIME";
    default: return "unknown error";
    }
}

int enc_qei_drv_read_position(const enc_qei_dev_t *d, unsigned k, int64_t *pos)
{
    uint64_t count;
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    count = RD(d->regs->chan[k].COUNT_LO);             /* latches COUNT_HI */
    if (d->count_w > 32u)
        count |= (uint64_t)RD(d->regs->chan[k].COUNT_HI) << 32;
    *pos = enc_qei_drv_signed(d, count);
    return ENC_QEI_DRV_OK;
}

/* Read channel k's EVENTS until one of `bits` reads 1 (want 1) or all read 0 (want 0); returns
 * whether that happened within dev.spin reads. */
static int wait_events(const enc_qei_dev_t *d, unsigned k, uint32_t bits, int want)
{
    uint32_t n;
    for (n = 0; n < d->spin; n++)
        if (((RD(d->regs->chan[k].EVENTS) & bits) != 0u) == (want != 0))
            return 1;
    return 0;
}

static void clear_events(const enc_qei_dev_t *d, unsigned k, uint32_t bits)
{
    WR(d->regs->chan[k].EVENTS, bits);
    (void)wait_events(d, k, bits, 0);   /* still 1 after spin reads: raised again, pending */
}

int enc_qei_drv_snap_config(enc_qei_dev_t *d, unsigned k, uint32_t snap_ctrl)
{
    if (!d->has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    d->snap_ctrl[k] = snap_ctrl & ~(uint32_t)ENC_QEI__SNAP_CTRL__CMD_bm;
    WR(d->regs->chan[k].SNAP_CTRL, d->snap_ctrl[k]);
    return ENC_QEI_DRV_OK;
}

int enc_qei_drv_snap_read(const enc_qei_dev_t *d, unsigned k, qei_vel_snap_t *s, unsigned flags)
{
    volatile enc_qei_chan_t *ch;
    if (!d->has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    ch = &d->regs->chan[k];
    if (!wait_events(d, k, SNAP_READY, 1))
        return ENC_QEI_DRV_ETIMEDOUT;
    /* cleared before the reads: a snapshot landing during them raises it again */
    clear_events(d, k, SNAP_READY);
    s->count = RD(ch->SNAP_COUNT_LO);
    if (d->count_w > 32u)
        s->count |= (uint64_t)RD(ch->SNAP_COUNT_HI) << 32;
    s->time = RD(ch->SNAP_TIME);
    s->edge_time = RD(ch->SNAP_EDGE_TIME);
    s->delta = (int32_t)RD(ch->SNAP_DELTA);
    s->edge_delta = (int32_t)RD(ch->SNAP_EDGE_DELTA);
    s->period = 0u;
    s->period_n = 1u;
    s->period_ovf = s->period_dir_change = s->stalled = 0u;
    if (flags & ENC_QEI_DRV_SNAP_LIVE) {
        if (d->profile == ENC_QEI__CAPS__PROFILE__FULL_VAL) {
            uint32_t pc;
            s->period = RD(ch->PERIOD);
            pc = RD(ch->PERIOD_CTRL);
            s->period_n = ENC_QEI__PERIOD_CTRL__N_GET(pc);
            s->period_ovf = (uint8_t)ENC_QEI__PERIOD_CTRL__OVERFLOW_GET(pc);
            s->period_dir_change = (uint8_t)ENC_QEI__PERIOD_CTRL__DIR_CHANGE_GET(pc);
        }
        s->stalled = (uint8_t)ENC_QEI__STATUS__STALLED_GET(RD(ch->STATUS));
    }
    return ENC_QEI_DRV_OK;
}

int enc_qei_drv_snap_take(const enc_qei_dev_t *d, unsigned k, qei_vel_snap_t *s, unsigned flags)
{
    if (!d->has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    clear_events(d, k, SNAP_READY);
    WR(d->regs->chan[k].SNAP_CTRL, d->snap_ctrl[k] | ENC_QEI__SNAP_CTRL__CMD_bm);
    return enc_qei_drv_snap_read(d, k, s, flags);
}

int enc_qei_drv_gsnap_config(enc_qei_dev_t *d, uint32_t gsnap_ctrl, uint32_t period)
{
    if (!d->has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    d->gsnap_ctrl = gsnap_ctrl & ~(uint32_t)ENC_QEI__GSNAP_CTRL__CMD_bm;
    WR(d->regs->glb.GSNAP_PERIOD, period);
    WR(d->regs->glb.GSNAP_CTRL, d->gsnap_ctrl);
    return ENC_QEI_DRV_OK;
}

int enc_qei_drv_gsnap_read(const enc_qei_dev_t *d, uint32_t *time, qei_vel_snap_t *snaps,
                           unsigned flags)
{
    unsigned k;
    int err;
    for (k = 0; k < d->channels; k++)
        if ((err = enc_qei_drv_snap_read(d, k, &snaps[k], flags)) != ENC_QEI_DRV_OK)
            return err;
    /* read last: every channel has shown this snapshot, so GSNAP_TIME holds it too */
    *time = RD(d->regs->glb.GSNAP_TIME);
    for (k = 0; k < d->channels; k++)
        if (snaps[k].time != *time)
            return ENC_QEI_DRV_ESKEW;
    return ENC_QEI_DRV_OK;
}

int enc_qei_drv_gsnap_take(const enc_qei_dev_t *d, uint32_t *time, qei_vel_snap_t *snaps,
                           unsigned flags)
{
    unsigned k;
    if (!d->has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    for (k = 0; k < d->channels; k++)            /* all the writes first, then the reads */
        WR(d->regs->chan[k].EVENTS, SNAP_READY);
    for (k = 0; k < d->channels; k++)
        (void)wait_events(d, k, SNAP_READY, 0);
    WR(d->regs->glb.GSNAP_CTRL, d->gsnap_ctrl | ENC_QEI__GSNAP_CTRL__CMD_bm);
    return enc_qei_drv_gsnap_read(d, time, snaps, flags);
}

uint32_t enc_qei_drv_irq_pending(const enc_qei_dev_t *d)
{
    return ENC_QEI__IRQ_SUMMARY__PENDING_GET(RD(d->regs->glb.IRQ_SUMMARY));
}

int enc_qei_drv_irq_enable(enc_qei_dev_t *d, unsigned k, uint32_t events)
{
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    d->irq_en[k] |= events;
    WR(d->regs->chan[k].IRQ_EN, d->irq_en[k]);
    return ENC_QEI_DRV_OK;
}

int enc_qei_drv_irq_disable(enc_qei_dev_t *d, unsigned k, uint32_t events)
{
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    d->irq_en[k] &= ~events;
    WR(d->regs->chan[k].IRQ_EN, d->irq_en[k]);
    return ENC_QEI_DRV_OK;
}

uint32_t enc_qei_drv_events(const enc_qei_dev_t *d, unsigned k)
{
    return k < d->channels ? RD(d->regs->chan[k].EVENTS) : 0u;
}

int enc_qei_drv_events_clear(const enc_qei_dev_t *d, unsigned k, uint32_t events)
{
    if (k >= d->channels)
        return ENC_QEI_DRV_EINVAL;
    clear_events(d, k, events);
    return ENC_QEI_DRV_OK;
}

uint32_t enc_qei_drv_events_take(const enc_qei_dev_t *d, unsigned k)
{
    uint32_t ev = enc_qei_drv_events(d, k) & (k < d->channels ? d->irq_en[k] : 0u);
    if (ev != 0u)
        clear_events(d, k, ev);
    return ev;
}
