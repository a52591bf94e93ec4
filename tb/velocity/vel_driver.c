/* SPDX-License-Identifier: Apache-2.0 */
/* Test driver for sw/enc_qei_velocity.c (built by tb/velocity/test_velocity_estimators.py).
 * stdin:  line 1  tick_s ts_w count_w counts_per_edge stall_ticks delta_from_count
 *         then    count time edge_time delta edge_delta period period_n ovf dir_change stalled
 * stdout: per snapshot "m t mt" in count steps per second, %.17g. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

#include "enc_qei_velocity.h"

int main(void)
{
    qei_vel_cfg_t cfg;
    qei_vel_t st;
    qei_vel_snap_t s;
    unsigned ovf, dchg, stalled, ts_w, count_w, cpe, dfc;
    uint32_t stall;
    if (scanf("%lf %u %u %u %" SCNu32 " %u", &cfg.tick_s, &ts_w, &count_w, &cpe, &stall, &dfc) != 6) {
        fprintf(stderr, "vel_driver: bad configuration line\n");
        return 2;
    }
    cfg.ts_w = ts_w;
    cfg.count_w = count_w;
    cfg.counts_per_edge = cpe;
    cfg.stall_ticks = stall;
    cfg.delta_from_count = (int)dfc;
    if (qei_vel_init(&st, &cfg) != 0) {
        fprintf(stderr, "vel_driver: configuration out of range\n");
        return 2;
    }
    while (scanf("%" SCNu64 " %" SCNu32 " %" SCNu32 " %" SCNd32 " %" SCNd32 " %" SCNu32 " %" SCNu32
                 " %u %u %u",
                 &s.count, &s.time, &s.edge_time, &s.delta, &s.edge_delta, &s.period, &s.period_n,
                 &ovf, &dchg, &stalled) == 10) {
        qei_vel_reading_t r;
        s.period_ovf = (uint8_t)ovf;
        s.period_dir_change = (uint8_t)dchg;
        s.stalled = (uint8_t)stalled;
        r = qei_vel_update(&st, &s);
        printf("%.17g %.17g %.17g\n", r.m, r.t, r.mt);
    }
    return 0;
}
