/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_servo.h -- the encoder side of a servo loop on bare metal (C99): once per servo period
 * every axis's position and velocity at one instant, from enc_qei's global snapshot, through the
 * driver API (sw/enc_qei_drv.h) and the fixed-point velocity estimator (timestamp method on
 * A-rising edges, sw/enc_qei_velocity_fx.h). No floating point, no malloc: the caller owns the
 * enc_qei_servo_t. Every channel is assumed to count x4 (CTRL.FUNC = x4, e.g. with
 * enc_qei_setup_x4() of enc_qei_example.h).
 *
 *   static enc_qei_servo_t servo;
 *   enc_qei_servo_start(&servo, (volatile enc_qei_t *)BASE, 100000000u, 1000u, 8u, 2000000u);
 *   ... in the interrupt handler of enc_qei's irq:
 *   if (enc_qei_servo_tick(&servo) == ENC_QEI_DRV_OK)
 *       use servo.pos[k] (count steps) and servo.vel[k] (1/256 count steps per second)
 *
 * Build: gcc -std=c99 -Wall -Wextra -Werror -I sw -I sw/examples -c sw/examples/enc_qei_servo.c
 * (link with sw/enc_qei_drv.c and sw/enc_qei_velocity_fx.c).
 */
#ifndef ENC_QEI_SERVO_H
#define ENC_QEI_SERVO_H

#include <stdint.h>

#include "enc_qei_drv.h"
#include "enc_qei_velocity_fx.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    enc_qei_dev_t dev;
    qei_velfx_t est[ENC_QEI_CHANNELS_MAX];     /* one velocity estimator per channel */
    qei_vel_snap_t snap[ENC_QEI_CHANNELS_MAX]; /* the last snapshot's registers */
    uint32_t time;                            /* its GSNAP_TIME */
    int64_t pos[ENC_QEI_CHANNELS_MAX];        /* positions, count steps */
    int32_t vel[ENC_QEI_CHANNELS_MAX];        /* velocities, 2^-frac_bits count steps / s */
} enc_qei_servo_t;

/* Find the build (enc_qei_drv_init), time every channel's snapshots on A-rising edges, set up
 * the estimators (tick_hz: timebase ticks per second, frac_bits: F, stall_ticks: the stall
 * timeout), and start the global unit timer at servo_hz (GSNAP_PERIOD = tick_hz / servo_hz)
 * with channel 0's SNAP_READY as the interrupt. Returns a driver return value; -1 for a
 * configuration the estimator refuses. */
int enc_qei_servo_start(enc_qei_servo_t *s, volatile enc_qei_t *regs, uint32_t tick_hz,
                        uint32_t servo_hz, unsigned frac_bits, uint32_t stall_ticks);

/* In the handler of enc_qei's irq: when channel 0's SNAP_READY is pending, read every channel
 * of that global snapshot, update pos[] and vel[], and return ENC_QEI_DRV_OK; other enabled
 * events of channel 0 are cleared and ignored. Returns 1 when no snapshot was pending, or a
 * driver error (ENC_QEI_DRV_ESKEW: pos[] and vel[] are updated from a snapshot that is not one
 * instant). */
int enc_qei_servo_tick(enc_qei_servo_t *s);

/* Stop the unit timer and the interrupt. */
void enc_qei_servo_stop(enc_qei_servo_t *s);

#ifdef __cplusplus
}
#endif

#endif /* ENC_QEI_SERVO_H */
