/* SPDX-License-Identifier: Apache-2.0 */
/* qei_vel_read_snapshot() against a register block in memory laid out by the generated
 * sw/enc_qei_regs.h (one channel's page; built by tb/velocity/test_velocity_estimators.py). Prints
 * the snapshot it read. */
#include <stdio.h>
#include <string.h>

#include "enc_qei_regs.h"
#include "enc_qei_velocity.h"

int main(void)
{
    enc_qei_chan_t q;
    qei_vel_snap_t s;
    memset(&q, 0, sizeof q);
    q.SNAP_CTRL = ENC_QEI__SNAP_CTRL__EDGE_bm;
    q.SNAP_COUNT_LO = 0xFFFFFFF0u;
    q.SNAP_COUNT_HI = 2u;
    q.SNAP_TIME = 1000u;
    q.SNAP_EDGE_TIME = 900u;
    q.SNAP_DELTA = (uint32_t)-5;
    q.SNAP_EDGE_DELTA = (uint32_t)-4;
    q.PERIOD = 77u;
    q.PERIOD_CTRL = (3u << ENC_QEI__PERIOD_CTRL__N_bp) | ENC_QEI__PERIOD_CTRL__DIR_CHANGE_bm;
    q.STATUS = ENC_QEI__STATUS__STALLED_bm;
    qei_vel_read_snapshot(&q, 64u, &s);
    printf("%u %llx %u %u %d %d %u %u %u %u %u\n", (unsigned)q.SNAP_CTRL,
           (unsigned long long)s.count, (unsigned)s.time, (unsigned)s.edge_time, (int)s.delta,
           (int)s.edge_delta, (unsigned)s.period, (unsigned)s.period_n, (unsigned)s.period_ovf,
           (unsigned)s.period_dir_change, (unsigned)s.stalled);
    qei_vel_read_snapshot(&q, 32u, &s);
    printf("%llx\n", (unsigned long long)s.count);
    return 0;
}
