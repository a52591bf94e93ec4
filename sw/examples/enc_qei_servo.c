/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_servo.c -- see enc_qei_servo.h. Uses only the driver API and the fixed-point
 * estimator: every register access goes through sw/enc_qei_drv.c. */
#include "enc_qei_servo.h"

#include <string.h>

int enc_qei_servo_start(enc_qei_servo_t *s, volatile enc_qei_t *regs, uint32_t tick_hz,
                        uint32_t servo_hz, unsigned frac_bits, uint32_t stall_ticks)
{
    qei_velfx_cfg_t cfg;
    unsigned k;
    int err;

    memset(s, 0, sizeof *s);
    if ((err = enc_qei_drv_init(&s->dev, regs)) != ENC_QEI_DRV_OK)
        return err;
    if (!s->dev.has_timing)
        return ENC_QEI_DRV_ENOTSUP;
    if (servo_hz == 0u || servo_hz > tick_hz)
        return -1;
    cfg.tick_hz = tick_hz;
    cfg.frac_bits = frac_bits;
    cfg.ts_w = s->dev.ts_w;
    cfg.count_w = s->dev.count_w;
    cfg.counts_per_edge = 4u;          /* x4 counting, A-rising edges */
    cfg.stall_ticks = stall_ticks;
    cfg.delta_from_count = 0;
    for (k = 0; k < s->dev.channels; k++) {
        if (qei_velfx_init(&s->est[k], &cfg) != 0)
            return -1;
        (void)enc_qei_drv_snap_config(&s->dev, k, ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm);
    }
    (void)enc_qei_drv_events_clear(&s->dev, 0u, ENC_QEI__EVENTS__SNAP_READY_bm);
    (void)enc_qei_drv_irq_enable(&s->dev, 0u, ENC_QEI__EVENTS__SNAP_READY_bm);
    return enc_qei_drv_gsnap_config(&s->dev, ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm,
                                    tick_hz / servo_hz);
}

int enc_qei_servo_tick(enc_qei_servo_t *s)
{
    const enc_qei_dev_t *d = &s->dev;
    uint32_t ev = enc_qei_drv_events(d, 0u) & d->irq_en[0];
    unsigned k;
    int err;

    if (ev & ~(uint32_t)ENC_QEI__EVENTS__SNAP_READY_bm)
        (void)enc_qei_drv_events_clear(d, 0u, ev & ~(uint32_t)ENC_QEI__EVENTS__SNAP_READY_bm);
    if (!(ev & ENC_QEI__EVENTS__SNAP_READY_bm))
        return 1;
    err = enc_qei_drv_gsnap_read(d, &s->time, s->snap, 0u);   /* clears every SNAP_READY */
    if (err != ENC_QEI_DRV_OK && err != ENC_QEI_DRV_ESKEW)
        return err;
    for (k = 0; k < d->channels; k++) {
        s->pos[k] = enc_qei_drv_signed(d, s->snap[k].count);
        s->vel[k] = qei_velfx_update(&s->est[k], &s->snap[k]).mt;
    }
    return err;
}

void enc_qei_servo_stop(enc_qei_servo_t *s)
{
    (void)enc_qei_drv_gsnap_config(&s->dev, 0u, 0u);
    (void)enc_qei_drv_irq_disable(&s->dev, 0u, ENC_QEI__EVENTS__SNAP_READY_bm);
}
