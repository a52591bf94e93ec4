/* SPDX-License-Identifier: Apache-2.0 */
/* Test driver: sw/enc_qei_calib.c (double) and sw/enc_qei_calib_fx.c (integer) on the same
 * entry stream, in one process (built by tb/velocity/test_velocity_calib_fx.py).
 * stdin:  line 1  the double configuration: tick_s ts_w cycles use_index learn_revs stall_ticks
 *                 motion_tol shape_tol line_tol edge_tol, then the integer one's own fields:
 *                 tick_hz frac_bits motion_ppm shape_uc line_uc edge_uc
 *         then    "E time a b up lost idx" (an entry) or "R time" (a read)
 * stdout: per read "mt_a any calibrated" of the double (%.17g) and of the integer version;
 *         "M entry field double integer" once, at the first entry after which a counter, a
 *         flag or a vote fraction (by more than 1e-9) differs (comparing stops there),
 *         except a vote decided within TIE of a threshold by the double version (a tie):
 *         "T entry field margin", the integer version's fraction set to the double's, and on; followed by "F" and both versions' figures
 *         then (shape line edge motion frac_fine frac_coarse, the integer's scaled to doubles
 *         here, in the test driver); at the end "S entries" and the figures line "F". */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "enc_qei_calib.h"
#include "enc_qei_calib_fx.h"

static const char *const NAMES[] = {"learned", "changes", "rejected", "disagree", "unclean",
                                    "reindex", "suspect", "lost", "missed", "edge_alarms",
                                    "jolts", "valid", "phase_ok", "pending", "rev_ok", "edge_ok",
                                    "cand_n", "calibrated"};
#define NFIELDS (sizeof NAMES / sizeof NAMES[0])

static void fields_dbl(const qei_cal_t *s, long v[NFIELDS])
{
    const uint32_t *c = &s->n.learned;
    int i;
    for (i = 0; i < 11; i++)
        v[i] = (long)c[i];
    v[11] = s->valid;
    v[12] = s->phase_ok;
    v[13] = s->pending;
    v[14] = s->rev_ok;
    v[15] = s->edge_ok;
    v[16] = (long)s->cand_n;
    v[17] = qei_cal_calibrated(s);
}

static void fields_fx(const qei_calfx_t *s, long v[NFIELDS])
{
    const uint32_t *c = &s->n.learned;
    int i;
    for (i = 0; i < 11; i++)
        v[i] = (long)c[i];
    v[11] = s->valid;
    v[12] = s->phase_ok;
    v[13] = s->pending;
    v[14] = s->rev_ok;
    v[15] = s->edge_ok;
    v[16] = (long)s->cand_n;
    v[17] = qei_calfx_calibrated(s);
}

#define TIE 1e-7   /* a vote decided within this (relative, or counts) of its threshold */

/* angle(b2) - angle(b1) with the double's table */
static double cal_diff(const qei_cal_t *s, int64_t b2, int64_t b1)
{
    int64_t j2 = ((b2 - s->ref) % s->S + s->S) % s->S, j1 = ((b1 - s->ref) % s->S + s->S) % s->S;
    return (double)(b2 - b1 - (j2 - j1)) + (s->table[j2] - s->table[j1]);
}

static double gap(double a, double b)
{
    double m = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    return fabs(a - b) / (m > 1.0 ? m : 1.0);
}

/* how close the double's edge-check sample of spacing k at (b, t), from the state before the
 * entry, came to each of its thresholds (jolt, no objection, seen, worse): the least gap */
static double vote_margin(const qei_cal_t *s, int k, int64_t b, uint64_t t)
{
    const int64_t *hb = s->ea_b[k];
    const uint64_t *ht = s->ea_t[k];
    double tau1 = (double)(ht[1] - ht[0]), tau2 = (double)(ht[2] - ht[0]),
           tau3 = (double)(t - ht[0]), l1, l2, er, ec, eff, m;
    l1 = tau3 * (tau3 - tau2) / (tau1 * (tau1 - tau2));
    l2 = tau3 * (tau3 - tau1) / (tau2 * (tau2 - tau1));
    er = (double)(b - hb[0]) - ((double)(hb[1] - hb[0]) * l1 + (double)(hb[2] - hb[0]) * l2);
    ec = cal_diff(s, b, hb[0]) - (cal_diff(s, hb[1], hb[0]) * l1 + cal_diff(s, hb[2], hb[0]) * l2);
    eff = fabs(er - ec);
    m = gap(fabs(ec), 0.5);
    if (gap(eff, 4.0 * fabs((double)(b - hb[0])) / tau3) < m)
        m = gap(eff, 4.0 * fabs((double)(b - hb[0])) / tau3);
    if (gap(fabs(er) < fabs(ec) ? fabs(er) : fabs(ec), 3.0 * eff) < m)
        m = gap(fabs(er) < fabs(ec) ? fabs(er) : fabs(ec), 3.0 * eff);
    if (gap(fabs(ec), fabs(er)) < m)
        m = gap(fabs(ec), fabs(er));
    return m;
}

static double q32(uint64_t x)
{
    return x == UINT64_MAX ? -1.0 : (double)x / 4294967296.0;
}

static void figures(const qei_cal_t *d, const qei_calfx_t *f)
{
    printf("F %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
           d->last_shape, d->last_line, d->last_edge, d->last_motion, d->frac[0], d->frac[1],
           q32(f->last_shape), q32(f->last_line), q32(f->last_edge), q32(f->last_motion),
           (double)f->frac[0] / 4611686018427387904.0, (double)f->frac[1] / 4611686018427387904.0);
}

int main(void)
{
    qei_cal_cfg_t cfg;
    qei_calfx_cfg_t fx;
    qei_cal_t st, before;
    qei_calfx_t sf;
    double *buf;
    int64_t *fbuf;
    unsigned ts_w, ui;
    char kind[2];
    long entries = 0;
    int same = 1;
    if (scanf("%lf %u %" SCNu32 " %u %" SCNu32 " %" SCNu64 " %lf %lf %lf %lf", &cfg.tick_s,
              &ts_w, &cfg.cycles, &ui, &cfg.learn_revs, &cfg.stall_ticks, &cfg.motion_tol,
              &cfg.shape_tol, &cfg.line_tol, &cfg.edge_tol) != 10 ||
        scanf("%" SCNu32 " %u %" SCNu32 " %" SCNu32 " %" SCNu32 " %" SCNu32, &fx.tick_hz,
              &fx.frac_bits, &fx.motion_ppm, &fx.shape_uc, &fx.line_uc, &fx.edge_uc) != 6) {
        fprintf(stderr, "calibfx_driver: bad configuration line\n");
        return 2;
    }
    cfg.ts_w = ts_w;
    cfg.use_index = (int)ui;
    fx.ts_w = ts_w;
    fx.cycles = cfg.cycles;
    fx.use_index = (int)ui;
    fx.learn_revs = cfg.learn_revs;
    fx.stall_ticks = cfg.stall_ticks;
    buf = malloc(QEI_CAL_BUF_LEN(cfg.cycles) * sizeof *buf);
    fbuf = malloc(QEI_CALFX_BUF_LEN(cfg.cycles) * sizeof *fbuf);
    if (buf == NULL || fbuf == NULL ||
        qei_cal_init(&st, &cfg, buf, QEI_CAL_BUF_LEN(cfg.cycles)) != 0 ||
        qei_calfx_init(&sf, &fx, fbuf, QEI_CALFX_BUF_LEN(cfg.cycles)) != 0) {
        fprintf(stderr, "calibfx_driver: configuration out of range\n");
        return 2;
    }
    while (scanf("%1s", kind) == 1) {
        uint32_t time;
        if (kind[0] == 'E') {
            unsigned a, b, up, lost, idx;
            qei_cal_entry_t e;
            qei_calfx_entry_t ef;
            if (scanf("%" SCNu32 " %u %u %u %u %u", &time, &a, &b, &up, &lost, &idx) != 6)
                return 3;
            e.time = ef.time = time;
            e.a = ef.a = (uint8_t)a;
            e.b = ef.b = (uint8_t)b;
            e.up = ef.up = (uint8_t)up;
            e.lost = ef.lost = (uint8_t)lost;
            e.idx = ef.idx = (uint8_t)idx;
            before = st;
            qei_cal_push(&st, &e);
            qei_calfx_push(&sf, &ef);
            if (same) {
                long vd[NFIELDS], vf[NFIELDS];
                size_t i;
                fields_dbl(&st, vd);
                fields_fx(&sf, vf);
                for (i = 0; i < NFIELDS; i++)
                    if (vd[i] != vf[i]) {
                        printf("M %ld %s %ld %ld\n", entries, NAMES[i], vd[i], vf[i]);
                        figures(&st, &sf);
                        same = 0;
                        break;
                    }
                for (i = 0; same && i < 2; i++)   /* the vote fractions: a vote taken apart */
                    if (fabs(st.frac[i] - (double)sf.frac[i] / 4611686018427387904.0) > 1e-9) {
                        double m = vote_margin(&before, (int)i, st.m[1].last_b, st.m[1].last_t);
                        if (m <= TIE) {       /* a tie at a threshold: count it, then resync */
                            printf("T %ld %s %.3g\n", entries, i ? "frac_coarse" : "frac_fine", m);
                            sf.frac[i] = (uint64_t)(st.frac[i] * 4611686018427387904.0 + 0.5);
                            continue;
                        }
                        printf("M %ld %s %ld %ld\n", entries, i ? "frac_coarse" : "frac_fine",
                               (long)(st.frac[i] * 1e9), (long)(sf.frac[i] >> 32));
                        figures(&st, &sf);
                        same = 0;
                    }
            }
            entries++;
        } else {
            qei_cal_reading_t r;
            qei_calfx_reading_t rf;
            if (scanf("%" SCNu32, &time) != 1)
                return 3;
            r = qei_cal_read(&st, time);
            rf = qei_calfx_read(&sf, time);
            printf("%.17g %.17g %d %" PRId32 " %" PRId32 " %d\n", r.mt_a, r.any, r.calibrated,
                   rf.mt_a, rf.any, rf.calibrated);
        }
    }
    printf("S %ld\n", entries);
    figures(&st, &sf);
    free(buf);
    free(fbuf);
    return 0;
}
