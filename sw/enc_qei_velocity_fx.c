/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_velocity_fx.c -- see enc_qei_velocity_fx.h. qei_vel_update() (enc_qei_velocity.c) in
 * integers: the same decisions in the same order, each double division replaced by ratio(). */
#include "enc_qei_velocity_fx.h"

#include <string.h>

static uint32_t ts_mask(unsigned ts_w)
{
    return ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)((1ul << ts_w) - 1ul);
}

/* a - b modulo 2^TS_W */
static uint32_t ts_diff(const qei_velfx_cfg_t *c, uint32_t a, uint32_t b)
{
    return (uint32_t)(a - b) & ts_mask(c->ts_w);
}

/* count - prev modulo 2^COUNT_W, as a signed number */
static int64_t count_diff(const qei_velfx_cfg_t *c, uint64_t count, uint64_t prev)
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

/* Leading zeros of a non-zero word. */
static unsigned nlz(uint32_t x)
{
    unsigned n = 0;
    if (x <= 0x0000FFFFu) { n += 16u; x <<= 16; }
    if (x <= 0x00FFFFFFu) { n += 8u; x <<= 8; }
    if (x <= 0x0FFFFFFFu) { n += 4u; x <<= 4; }
    if (x <= 0x3FFFFFFFu) { n += 2u; x <<= 2; }
    if (x <= 0x7FFFFFFFu) { n += 1u; }
    return n;
}

/* (u1:u0) / v for u1 < v (the quotient fits 32 bits): Knuth's algorithm D with 16-bit digits,
 * two 32-bit divisions (Hacker's Delight, divlu). */
static uint32_t divlu(uint32_t u1, uint32_t u0, uint32_t v)
{
    const uint32_t b = 0x10000u;
    uint32_t vn1, vn0, un32, un21, un10, un1, un0, q1, q0, rhat;
    unsigned s = nlz(v);

    v <<= s;
    vn1 = v >> 16;
    vn0 = v & 0xFFFFu;
    un32 = s ? (u1 << s) | (u0 >> (32u - s)) : u1;
    un10 = u0 << s;
    un1 = un10 >> 16;
    un0 = un10 & 0xFFFFu;
    q1 = un32 / vn1;
    rhat = un32 - q1 * vn1;
    while (q1 >= b || q1 * vn0 > ((rhat << 16) | un1)) {
        q1--;
        rhat += vn1;
        if (rhat >= b)
            break;
    }
    un21 = (un32 << 16) + un1 - q1 * v;       /* modulo 2^32: the true value fits */
    q0 = un21 / vn1;
    rhat = un21 - q0 * vn1;
    while (q0 >= b || q0 * vn0 > ((rhat << 16) | un0)) {
        q0--;
        rhat += vn1;
        if (rhat >= b)
            break;
    }
    return (q1 << 16) | q0;
}

/* num * 2^F / den rounded to the nearest (ties up), saturated at QEI_VELFX_MAX; den > 0, and
 * num_ovf says that num itself did not fit 64 bits. */
static uint32_t ratio(uint64_t num, int num_ovf, unsigned f, uint32_t den)
{
    uint64_t n;
    if (num == 0u && !num_ovf)
        return 0u;
    /* num * 2^F >= 2^64 means a quotient >= 2^32 (den < 2^32): saturated */
    if (num_ovf || (f && (num >> (64u - f)) != 0u))
        return QEI_VELFX_MAX;
    n = num << f;
    if (n > ~(uint64_t)0 - (den >> 1))
        return QEI_VELFX_MAX;
    n += den >> 1;
    if ((uint32_t)(n >> 32) >= den)           /* quotient >= 2^32 */
        return QEI_VELFX_MAX;
    n = divlu((uint32_t)(n >> 32), (uint32_t)n, den);
    return n > QEI_VELFX_MAX ? QEI_VELFX_MAX : (uint32_t)n;
}

/* a * b, and whether it overflowed 64 bits */
static uint64_t mul64(uint64_t a, uint32_t b, int *ovf)
{
    uint64_t lo = (a & 0xFFFFFFFFu) * b, hi = (a >> 32) * b;
    *ovf = (hi >> 32) != 0u || lo > ~(uint64_t)0 - (hi << 32);
    return lo + (hi << 32);
}

/* |x| * tick_hz * 2^F / den, signed like x */
static int32_t rate(const qei_velfx_cfg_t *c, int64_t x, uint32_t den)
{
    int ovf;
    uint64_t a = x < 0 ? (uint64_t)0 - (uint64_t)x : (uint64_t)x;
    uint64_t num = mul64(a, c->tick_hz, &ovf);
    int32_t mag = (int32_t)ratio(num, ovf, c->frac_bits, den);
    return x < 0 ? -mag : mag;
}

static uint32_t bounded(const qei_velfx_t *st, uint32_t mag, int new_edge, uint32_t since,
                        int stalled)
{
    if (stalled)
        return 0u;
    if (!new_edge && since > 0u && mag > 0u) {
        uint32_t bound = ratio(st->edge_num, 0, st->cfg.frac_bits, since);
        if (bound < mag)
            return bound;
    }
    return mag;
}

int qei_velfx_init(qei_velfx_t *st, const qei_velfx_cfg_t *cfg)
{
    memset(st, 0, sizeof *st);
    if (cfg->tick_hz == 0u || cfg->frac_bits > 31u || cfg->ts_w < 1u || cfg->ts_w > 32u ||
        cfg->count_w < 1u || cfg->count_w > 64u || cfg->counts_per_edge < 1u)
        return -1;
    st->cfg = *cfg;
    st->edge_num = (uint64_t)cfg->counts_per_edge * cfg->tick_hz;
    st->mt_ref = 1;
    return 0;
}

qei_velfx_reading_t qei_velfx_update(qei_velfx_t *st, const qei_vel_snap_t *s)
{
    const qei_velfx_cfg_t *c = &st->cfg;
    qei_velfx_reading_t r = {0, 0, 0};
    uint32_t prev_time = st->prev_time, prev_edge_time = st->prev_edge_time;
    uint64_t prev_count = st->prev_count;
    uint32_t dt, since, t_mag;
    int64_t delta;
    int stalled, new_edge, cdir;

    st->prev_time = s->time;
    st->prev_edge_time = s->edge_time;
    st->prev_count = s->count;
    if (!st->have_prev) {
        st->have_prev = 1;
        return r;
    }
    /* M: unit time */
    dt = ts_diff(c, s->time, prev_time);
    delta = c->delta_from_count ? count_diff(c, s->count, prev_count) : (int64_t)s->delta;
    r.m = dt > 0u ? rate(c, delta, dt) : 0;
    since = ts_diff(c, s->time, s->edge_time);
    stalled = s->stalled || (c->stall_ticks > 0u && since >= c->stall_ticks);
    new_edge = s->edge_delta != 0 || s->edge_time != prev_edge_time;
    cdir = sign_of(delta);
    /* M/T: timestamp */
    if (cdir != 0 && st->mt_dir != 0 && cdir != st->mt_dir) {
        st->mt_dir = cdir; /* the counts reversed: 0 until re-referenced */
        st->mt_mag = 0u;
        st->mt_ref = 1;
    }
    if (new_edge) {
        int d = sign_of(s->edge_delta);
        if (st->mt_ref || d == 0 || (st->mt_dir != 0 && d != st->mt_dir)) {
            if (d != 0 && !st->mt_ref)
                st->mt_dir = d; /* reversal rule: reads 0, new reference */
            else if (st->mt_dir == 0)
                st->mt_dir = d;
            st->mt_mag = 0u;
            st->mt_ref = 0;
        } else {
            uint32_t dte = ts_diff(c, s->edge_time, prev_edge_time);
            if (dte > 0u)
                st->mt_mag = (uint32_t)rate(c, s->edge_delta < 0 ? -(int64_t)s->edge_delta
                                                                  : (int64_t)s->edge_delta, dte);
            st->mt_dir = d;
        }
    }
    r.mt = st->mt_dir * (int32_t)bounded(st, st->mt_mag, new_edge, since, stalled);
    /* T: period */
    if (cdir != 0 && st->t_dir != 0 && cdir != st->t_dir)
        st->t_hold = 1;
    else if (new_edge)
        st->t_hold = 0;
    if (cdir != 0)
        st->t_dir = cdir;
    if (st->t_hold || s->period == 0u || s->period_ovf || s->period_dir_change)
        t_mag = 0u;
    else
        t_mag = (uint32_t)rate(c, (int64_t)(s->period_n > 1u ? s->period_n : 1u) *
                                      (int64_t)c->counts_per_edge, s->period);
    r.t = st->t_dir * (int32_t)bounded(st, t_mag, new_edge, since, stalled);
    return r;
}
