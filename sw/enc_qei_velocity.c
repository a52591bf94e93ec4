/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_velocity.c -- see enc_qei_velocity.h. Mirrors python/src/hedsmodel/velocity.py. */
#include "enc_qei_velocity.h"

#include <string.h>

static uint32_t ts_mask(unsigned ts_w)
{
    return ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)((1ul << ts_w) - 1ul);
}

/* a - b modulo 2^TS_W */
static uint32_t ts_diff(const qei_vel_cfg_t *c, uint32_t a, uint32_t b)
{
    return (uint32_t)(a - b) & ts_mask(c->ts_w);
}

/* count - prev modulo 2^COUNT_W, as a signed number */
static int64_t count_diff(const qei_vel_cfg_t *c, uint64_t count, uint64_t prev)
{
    uint64_t mask = c->count_w >= 64u ? ~(uint64_t)0 : (((uint64_t)1 << c->count_w) - 1u);
    uint64_t d = (count - prev) & mask;
    uint64_t half = (uint64_t)1 << (c->count_w - 1u);
    if (d >= half)
        return -(int64_t)(mask - d) - 1;
    return (int64_t)d;
}

static int sign_of(int64_t x)
{
    return (x > 0) - (x < 0);
}

static double bounded(const qei_vel_cfg_t *c, double mag, int new_edge, uint32_t since, int stalled)
{
    if (stalled)
        return 0.0;
    if (!new_edge && since > 0u) {
        double bound = (double)c->counts_per_edge / ((double)since * c->tick_s);
        if (bound < mag)
            return bound;
    }
    return mag;
}

int qei_vel_init(qei_vel_t *st, const qei_vel_cfg_t *cfg)
{
    memset(st, 0, sizeof *st);
    if (!(cfg->tick_s > 0.0) || cfg->ts_w < 1u || cfg->ts_w > 32u || cfg->count_w < 1u ||
        cfg->count_w > 64u || cfg->counts_per_edge < 1u)
        return -1;
    st->cfg = *cfg;
    st->mt_ref = 1;
    return 0;
}

qei_vel_reading_t qei_vel_update(qei_vel_t *st, const qei_vel_snap_t *s)
{
    const qei_vel_cfg_t *c = &st->cfg;
    qei_vel_reading_t r = {0.0, 0.0, 0.0};
    qei_vel_snap_t p = st->prev;
    uint32_t dt, since;
    int64_t delta;
    int stalled, new_edge, cdir;
    double t_mag;

    st->prev = *s;
    if (!st->have_prev) {
        st->have_prev = 1;
        return r;
    }
    /* M: unit time */
    dt = ts_diff(c, s->time, p.time);
    delta = c->delta_from_count ? count_diff(c, s->count, p.count) : (int64_t)s->delta;
    r.m = dt > 0u ? (double)delta / ((double)dt * c->tick_s) : 0.0;
    since = ts_diff(c, s->time, s->edge_time);
    stalled = s->stalled || (c->stall_ticks > 0u && since >= c->stall_ticks);
    new_edge = s->edge_delta != 0 || s->edge_time != p.edge_time;
    cdir = sign_of(delta);
    /* M/T: timestamp */
    if (cdir != 0 && st->mt_dir != 0 && cdir != st->mt_dir) {
        st->mt_dir = cdir; /* the counts reversed: 0 until re-referenced */
        st->mt_mag = 0.0;
        st->mt_ref = 1;
    }
    if (new_edge) {
        int d = sign_of(s->edge_delta);
        if (st->mt_ref || d == 0 || (st->mt_dir != 0 && d != st->mt_dir)) {
            if (d != 0 && !st->mt_ref)
                st->mt_dir = d; /* reversal rule: reads 0, new reference */
            else if (st->mt_dir == 0)
                st->mt_dir = d;
            st->mt_mag = 0.0;
            st->mt_ref = 0;
        } else {
            uint32_t dte = ts_diff(c, s->edge_time, p.edge_time);
            if (dte > 0u)
                st->mt_mag = (double)(s->edge_delta < 0 ? -(int64_t)s->edge_delta
                                                        : (int64_t)s->edge_delta) /
                             ((double)dte * c->tick_s);
            st->mt_dir = d;
        }
    }
    r.mt = (double)st->mt_dir * bounded(c, st->mt_mag, new_edge, since, stalled);
    /* T: period */
    if (cdir != 0 && st->t_dir != 0 && cdir != st->t_dir)
        st->t_hold = 1;
    else if (new_edge)
        st->t_hold = 0;
    if (cdir != 0)
        st->t_dir = cdir;
    if (st->t_hold || s->period == 0u || s->period_ovf || s->period_dir_change)
        t_mag = 0.0;
    else
        t_mag = (double)(s->period_n > 1u ? s->period_n : 1u) * (double)c->counts_per_edge /
                ((double)s->period * c->tick_s);
    r.t = (double)st->t_dir * bounded(c, t_mag, new_edge, since, stalled);
    return r;
}

double qei_vel_rpm(double counts_per_s, unsigned counts_per_rev)
{
    return counts_per_s * 60.0 / (double)counts_per_rev;
}
