/* SPDX-License-Identifier: Apache-2.0 */
/* Test driver for sw/enc_qei_velocity_fx.c (included here, so that its internal arithmetic can be
 * tested too) against sw/enc_qei_velocity.c (built by tb/velocity/conftest.py).
 *
 * Without arguments: both estimators on the same snapshots.
 * stdin:  line 1  tick_hz frac_bits ts_w count_w counts_per_edge stall_ticks delta_from_count
 *         then    count time edge_time delta edge_delta period period_n ovf dir_change stalled
 * stdout: per snapshot "m t mt fm ft fmt fmt1": the double readings in count steps per second
 *         (%.17g, tick_s = 1 / tick_hz), the fixed-point ones in 2^-F count steps per second, and
 *         qei_velfx_update_mt()'s reading (a state of its own, fed the same snapshots).
 * With "units": one line per case, "div u1 u0 v" (divlu: (u1:u0) / v), "ratio F num den"
 * (round(num * 2^F / den), saturated) or "rate F tick_hz x den" (round(x * tick_hz * 2^F / den),
 * saturated); prints each result. */
#include <inttypes.h>
#include <stdio.h>
#include <string.h>

#include "enc_qei_velocity.h"
#include "enc_qei_velocity_fx.c"

static int units(void)
{
    char kind[8];
    uint64_t a, b, c, d;
    qei_velfx_t st;
    qei_velfx_cfg_t cfg = {1u, 0u, 32u, 32u, 1u, 0u, 0};
    while (scanf("%7s", kind) == 1) {
        if (strcmp(kind, "div") == 0 &&
            scanf("%" SCNu64 " %" SCNu64 " %" SCNu64, &a, &b, &c) == 3) {
            printf("%" PRIu32 "\n", divlu((uint32_t)a, (uint32_t)b, (uint32_t)c));
        } else if (strcmp(kind, "ratio") == 0 &&
                   scanf("%" SCNu64 " %" SCNu64 " %" SCNu64, &a, &b, &c) == 3) {
            cfg.frac_bits = (unsigned)a;
            qei_velfx_init(&st, &cfg);
            printf("%" PRIu32 "\n", ratio(&st, b, (uint32_t)c));
        } else if (strcmp(kind, "rate") == 0 &&
                   scanf("%" SCNu64 " %" SCNu64 " %" SCNu64 " %" SCNu64, &a, &b, &c, &d) == 4) {
            cfg.frac_bits = (unsigned)a;
            cfg.tick_hz = (uint32_t)b;
            qei_velfx_init(&st, &cfg);
            printf("%" PRIu32 "\n", rate(&st, c, (uint32_t)d));
        } else {
            fprintf(stderr, "velfx_driver: bad unit case\n");
            return 2;
        }
    }
    return 0;
}

int main(int argc, char **argv)
{
    qei_vel_cfg_t cfg;
    qei_velfx_cfg_t fcfg;
    qei_vel_t st;
    qei_velfx_t fst, fst_mt;
    qei_vel_snap_t s;
    unsigned ovf, dchg, stalled, frac, ts_w, count_w, cpe, dfc;
    uint32_t tick_hz, stall;
    if (argc == 2 && strcmp(argv[1], "units") == 0)
        return units();
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
    if (qei_velfx_init(&fst, &fcfg) != 0 || qei_velfx_init(&fst_mt, &fcfg) != 0) {
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
        printf("%.17g %.17g %.17g %" PRId32 " %" PRId32 " %" PRId32 " %" PRId32 "\n", r.m, r.t,
               r.mt, f.m, f.t, f.mt, qei_velfx_update_mt(&fst_mt, &s));
    }
    return 0;
}
