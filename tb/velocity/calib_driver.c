/* SPDX-License-Identifier: Apache-2.0 */
/* Test driver for sw/enc_qei_calib.c (built by tb/velocity/test_velocity_calibration.py).
 * stdin:  line 1  tick_s ts_w cycles use_index learn_revs stall_ticks motion_tol shape_tol
 *                 line_tol edge_tol
 *         then    "E time a b up lost idx" (an entry) or "R time" (a read)
 * stdout: per read "mt_a any calibrated" (%.17g), at the end "S" and the counters (learned
 *         changes rejected disagree unclean reindex suspect lost missed edge_alarms jolts),
 *         the flags (valid phase_ok pending rev_ok edge_ok cand_n) and the figures (shape line
 *         edge motion frac_fine frac_coarse). */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>

#include "enc_qei_calib.h"

int main(void)
{
    qei_cal_cfg_t cfg;
    qei_cal_t st;
    double *buf;
    unsigned ts_w, ui;
    char kind[2];
    if (scanf("%lf %u %" SCNu32 " %u %" SCNu32 " %" SCNu64 " %lf %lf %lf %lf", &cfg.tick_s,
              &ts_w, &cfg.cycles, &ui, &cfg.learn_revs, &cfg.stall_ticks, &cfg.motion_tol,
              &cfg.shape_tol, &cfg.line_tol, &cfg.edge_tol) != 10) {
        fprintf(stderr, "calib_driver: bad configuration line\n");
        return 2;
    }
    cfg.ts_w = ts_w;
    cfg.use_index = (int)ui;
    buf = malloc(QEI_CAL_BUF_LEN(cfg.cycles) * sizeof *buf);
    if (buf == NULL || qei_cal_init(&st, &cfg, buf, QEI_CAL_BUF_LEN(cfg.cycles)) != 0) {
        fprintf(stderr, "calib_driver: configuration out of range\n");
        return 2;
    }
    while (scanf("%1s", kind) == 1) {
        uint32_t time;
        if (kind[0] == 'E') {
            unsigned a, b, up, lost, idx;
            qei_cal_entry_t e;
            if (scanf("%" SCNu32 " %u %u %u %u %u", &time, &a, &b, &up, &lost, &idx) != 6)
                return 3;
            e.time = time;
            e.a = (uint8_t)a;
            e.b = (uint8_t)b;
            e.up = (uint8_t)up;
            e.lost = (uint8_t)lost;
            e.idx = (uint8_t)idx;
            qei_cal_push(&st, &e);
        } else {
            qei_cal_reading_t r;
            if (scanf("%" SCNu32, &time) != 1)
                return 3;
            r = qei_cal_read(&st, time);
            printf("%.17g %.17g %d\n", r.mt_a, r.any, r.calibrated);
        }
    }
    printf("S %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32
           " %" PRIu32 " %" PRIu32 " %" PRIu32 " %" PRIu32 " %d %d %d %d %d %" PRIu32
           " %.17g %.17g %.17g %.17g %.17g %.17g\n",
           st.n.learned, st.n.changes, st.n.rejected, st.n.disagree, st.n.unclean, st.n.reindex,
           st.n.suspect, st.n.lost, st.n.missed, st.n.edge_alarms, st.n.jolts, st.valid,
           st.phase_ok, st.pending, st.rev_ok, st.edge_ok, st.cand_n, st.last_shape,
           st.last_line, st.last_edge, st.last_motion, st.frac[0], st.frac[1]);
    free(buf);
    return 0;
}
