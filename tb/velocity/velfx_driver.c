/* SPDX-License-Identifier: Apache-2.0 */
/* Test driver for sw/enc_qei_velocity_fx.c against sw/enc_qei_velocity.c (built by
 * tb/velocity/conftest.py): both estimators on the same snapshots.
 * stdin:  line 1  tick_hz frac_bits ts_w count_w counts_per_edge stall_ticks delta_from_count
 *         then    count time edge_time delta edge_delta period period_n ovf dir_change stalled
 * stdout: per snapshot "m t mt fm ft fmt": the double readings in count steps per second
 *         (%.17g, tick_s = 1 / tick_hz) and the fixed-point ones in 2^-F count steps per second. */
#include <inttypes.h>
#include <stdio.h>

#include "enc_qei_velocity.h"
#include "enc_qei_velocity_fx.h"

int main(void)
{
    qei_vel_cfg_t cfg;
    qei_velfx_cfg_t fcfg;
    qei_vel_t st;
    qei_velfx_t fst;
    qei_vel_snap_t s;
    unsigned ovf, dchg, stalled, frac, ts_w, count_w, cpe, dfc;
    uint32_t tick_hz, stall;
    if (scanf("%" SCNu32 " %u %u %u %u %" SCNu32 " %u", &tick_hz, &frac, &ts_w, &count_w, &cpe,
              &stall, &dfc) != 7) {
        fprintf(stderr, "velfx_driver: bad configuration line\n");
        return 2;
    }
    fcfg.tick_hz = tick_hz;
    fcfg.frac_bits = frac;
    cfg.tick_s = tick_hz ? 1.0 / (double)tick_hz : 0.0;
    cfg.ts_w = fcfg.ts_w = ts_w;
    cfg.count_w = fcfg.count_w = count_w;
    cfg.counts_per_edge = fcfg.counts_per_edge = cpe;
    cfg.stall_ticks = fcfg.stall_ticks = stall;
    cfg.delta_from_count = fcfg.delta_from_count = (int)dfc;
    if (qei_velfx_init(&fst, &fcfg) != 0) {
        fprintf(stderr, "velfx_driver: fixed-point configuration out of range\n");
        return 2;
    }
    if (qei_vel_init(&st, &cfg) != 0) {
        fprintf(stderr, "velfx_driver: configuration out of range\n");
        return 2;
    }
    while (scanf("%" SCNu64 " %" SCNu32 " %" SCNu32 " %" SCNd32 " %" SCNd32 " %" SCNu32 " %" SCNu32
                 " %u %u %u",
                 &s.count, &s.time, &s.edge_time, &s.delta, &s.edge_delta, &s.period, &s.period_n,
                 &ovf, &dchg, &stalled) == 10) {
        qei_vel_reading_t r;
        qei_velfx_reading_t f;
        s.period_ovf = (uint8_t)ovf;
        s.period_dir_change = (uint8_t)dchg;
        s.stalled = (uint8_t)stalled;
        r = qei_vel_update(&st, &s);
        f = qei_velfx_update(&fst, &s);
        printf("%.17g %.17g %.17g %" PRId32 " %" PRId32 " %" PRId32 "\n", r.m, r.t, r.mt, f.m, f.t,
               f.mt);
    }
    return 0;
}
