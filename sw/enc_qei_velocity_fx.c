/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_velocity_fx.c -- see enc_qei_velocity_fx.h. qei_vel_update() (enc_qei_velocity.c) in
 * integers: the same decisions, each double division replaced by rate() or ratio(). The helpers
 * of the interrupt path are inline: on a soft CPU a call costs as much as a few lines of it. */
#include "enc_qei_velocity_fx.h"

#include <string.h>

/* a - b modulo 2^TS_W */
static uint32_t ts_diff(const qei_velfx_t *st, uint32_t a, uint32_t b)
{
    return (uint32_t)(a - b) & st->ts_mask;
}

/* count - prev modulo 2^COUNT_W, as a signed number */
static int64_t count_diff(const qei_velfx_t *st, uint64_t count, uint64_t prev)
{
    uint64_t d = (count - prev) & st->count_mask;
    if (d > (st->count_mask >> 1))
        return -(int64_t)(st->count_mask - d) - 1;
    return (int64_t)d;
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
 * two 32-bit divisions (Hacker's Delight, divlu). An estimated digit is at most 4 too large (v
 * normalised) and is corrected by comparing products, not through a remainder: a CPU like
 * VexRiscv takes as long for a remu as for a divu. */
static inline uint32_t divlu(uint32_t u1, uint32_t u0, uint32_t v)
{
    uint32_t vn1, un32, un21, un10, q1, q0;
    unsigned s = nlz(v);

    v <<= s;
    vn1 = v >> 16;
    un32 = s ? (u1 << s) | (u0 >> (32u - s)) : u1;
    un10 = u0 << s;
    q1 = un32 / vn1;                          /* Knuth 4.3.1, theorem B, with un32 < v */
    while ((uint64_t)q1 * v > (((uint64_t)un32 << 16) | (un10 >> 16)))
        q1--;
    un21 = (un32 << 16) + (un10 >> 16) - q1 * v;   /* modulo 2^32: the true value is < v */
    q0 = un21 / vn1;
    while ((uint64_t)q0 * v > (((uint64_t)un21 << 16) | (un10 & 0xFFFFu)))
        q0--;
    return (q1 << 16) | q0;
}

/* x << f for f < 32, in 32-bit shifts (no library call on a 32-bit CPU) */
static uint64_t shl(uint64_t x, unsigned f)
{
    uint32_t hi = (uint32_t)(x >> 32), lo = (uint32_t)x;
    if (f == 0u)
        return x;
    hi = (hi << f) | (lo >> (32u - f));
    return ((uint64_t)hi << 32) | (uint32_t)(lo << f);
}

/* num * 2^F / den rounded to the nearest (ties up), saturated at QEI_VELFX_MAX; den > 0 */
static inline uint32_t ratio(const qei_velfx_t *st, uint64_t num, uint32_t den)
{
    uint64_t n;
    uint32_t q;
    if (num > st->num_max)                  /* num * 2^F >= 2^63: a quotient >= 2^31 */
        return QEI_VELFX_MAX;
    n = shl(num, st->cfg.frac_bits) + (den >> 1);     /* < 2^63 + 2^31: no overflow */
    if ((uint32_t)(n >> 32) >= den)         /* quotient >= 2^32 */
        return QEI_VELFX_MAX;
    q = divlu((uint32_t)(n >> 32), (uint32_t)n, den);
    return q > QEI_VELFX_MAX ? QEI_VELFX_MAX : q;
}

/* x * tick_hz * 2^F / den for a magnitude x */
static inline uint32_t rate(const qei_velfx_t *st, uint64_t x, uint32_t den)
{
    uint64_t num, hi;
    if (x <= 0xFFFFFFFFu)                   /* the usual case: the product fits 64 bits */
        return x ? ratio(st, x * st->cfg.tick_hz, den) : 0u;
    hi = (x >> 32) * st->cfg.tick_hz;       /* a 64-bit count difference */
    if (hi >= (uint64_t)1 << 31)
        return QEI_VELFX_MAX;               /* x * tick_hz >= 2^63 */
    /* no overflow: hi < 2^31 with x >= 2^32 means tick_hz < 2^31, so both terms are < 2^63 */
    num = (hi << 32) + (x & 0xFFFFFFFFu) * st->cfg.tick_hz;
    return ratio(st, num, den);
}

int qei_velfx_init(qei_velfx_t *st, const qei_velfx_cfg_t *cfg)
{
    memset(st, 0, sizeof *st);
    if (cfg->tick_hz == 0u || cfg->frac_bits > 31u || cfg->ts_w < 1u || cfg->ts_w > 32u ||
        cfg->count_w < 1u || cfg->count_w > 64u || cfg->counts_per_edge < 1u)
        return -1;
    st->cfg = *cfg;
    st->edge_num = (uint64_t)cfg->counts_per_edge * cfg->tick_hz;
    st->num_max = (~(uint64_t)0 >> 1) >> cfg->frac_bits;
    st->ts_mask = cfg->ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)(((uint32_t)1 << cfg->ts_w) - 1u);
    st->count_mask = cfg->count_w >= 64u ? ~(uint64_t)0 : ((uint64_t)1 << cfg->count_w) - 1u;
    st->mt_ref = 1;
    return 0;
}

/* The first snapshot only initialises: keeps its times and count, returns 1 then. cdir: the
 * direction of its counts (SNAP_DELTA, or the count difference), |delta| into *dmag. */
static inline int take(qei_velfx_t *st, const qei_vel_snap_t *s, int *cdir, uint64_t *dmag)
{
    if (st->cfg.delta_from_count) {
        int64_t delta = count_diff(st, s->count, st->prev_count);
        *cdir = (delta > 0) - (delta < 0);
        *dmag = delta < 0 ? (uint64_t)0 - (uint64_t)delta : (uint64_t)delta;
    } else {
        *cdir = (s->delta > 0) - (s->delta < 0);
        *dmag = s->delta < 0 ? (uint32_t)0 - (uint32_t)s->delta : (uint32_t)s->delta;
    }
    st->prev_time = s->time;
    st->prev_edge_time = s->edge_time;
    st->prev_count = s->count;
    if (st->have_prev)
        return 0;
    st->have_prev = 1;
    return 1;
}

/* M/T: the direction and magnitude of the last measurement after this snapshot (its rules) */
static inline void mt_step(qei_velfx_t *st, const qei_vel_snap_t *s, int cdir, int new_edge,
                           uint32_t prev_edge_time)
{
    if (cdir != 0 && st->mt_dir != 0 && cdir != st->mt_dir) {
        st->mt_dir = cdir; /* the counts reversed: 0 until re-referenced */
        st->mt_mag = 0u;
        st->mt_ref = 1;
    }
    if (new_edge) {
        int d = (s->edge_delta > 0) - (s->edge_delta < 0);
        if (st->mt_ref || d == 0 || (st->mt_dir != 0 && d != st->mt_dir)) {
            if (d != 0 && !st->mt_ref)
                st->mt_dir = d; /* reversal rule: reads 0, new reference */
            else if (st->mt_dir == 0)
                st->mt_dir = d;
            st->mt_mag = 0u;
            st->mt_ref = 0;
        } else {
            uint32_t dte = ts_diff(st, s->edge_time, prev_edge_time);
            if (dte > 0u)
                st->mt_mag = rate(st, s->edge_delta < 0 ? (uint32_t)0 - (uint32_t)s->edge_delta
                                                        : (uint32_t)s->edge_delta, dte);
            st->mt_dir = d;
        }
    }
}

static int32_t with_dir(int dir, uint32_t mag)
{
    return dir < 0 ? -(int32_t)mag : dir > 0 ? (int32_t)mag : 0;
}

qei_velfx_reading_t qei_velfx_update(qei_velfx_t *st, const qei_vel_snap_t *s)
{
    const qei_velfx_cfg_t *c = &st->cfg;
    qei_velfx_reading_t r = {0, 0, 0};
    uint32_t prev_time = st->prev_time, prev_edge_time = st->prev_edge_time;
    uint32_t dt, since, t_mag = 0u, mt_mag, bound = 0u;
    uint64_t dmag;
    int stalled, new_edge, cdir;

    if (take(st, s, &cdir, &dmag))
        return r;
    /* M: unit time */
    dt = ts_diff(st, s->time, prev_time);
    if (dt > 0u)
        r.m = with_dir(cdir, rate(st, dmag, dt));
    since = ts_diff(st, s->time, s->edge_time);
    stalled = s->stalled || (c->stall_ticks > 0u && since >= c->stall_ticks);
    new_edge = s->edge_delta != 0 || s->edge_time != prev_edge_time;
    /* M/T: timestamp */
    mt_step(st, s, cdir, new_edge, prev_edge_time);
    /* T: period */
    if (cdir != 0 && st->t_dir != 0 && cdir != st->t_dir)
        st->t_hold = 1;
    else if (new_edge)
        st->t_hold = 0;
    if (cdir != 0)
        st->t_dir = cdir;
    if (!(st->t_hold || s->period == 0u || s->period_ovf || s->period_dir_change))
        t_mag = rate(st, (uint64_t)(s->period_n > 1u ? s->period_n : 1u) * c->counts_per_edge,
                     s->period);
    if (stalled)
        return r;                      /* MT and T read 0; mt_mag is kept */
    /* the standstill rule: at most one edge's counts over the time since the last edge */
    mt_mag = st->mt_mag;
    if (!new_edge && since > 0u && (mt_mag > 0u || t_mag > 0u)) {
        bound = ratio(st, st->edge_num, since);
        mt_mag = bound < mt_mag ? bound : mt_mag;
        t_mag = bound < t_mag ? bound : t_mag;
    }
    r.mt = with_dir(st->mt_dir, mt_mag);
    r.t = with_dir(st->t_dir, t_mag);
    return r;
}

int32_t qei_velfx_update_mt(qei_velfx_t *st, const qei_vel_snap_t *s)
{
    uint32_t prev_edge_time = st->prev_edge_time, since, mag;
    uint64_t dmag;
    int new_edge, cdir;

    if (take(st, s, &cdir, &dmag))
        return 0;
    since = ts_diff(st, s->time, s->edge_time);
    new_edge = s->edge_delta != 0 || s->edge_time != prev_edge_time;
    mt_step(st, s, cdir, new_edge, prev_edge_time);
    if (s->stalled || (st->cfg.stall_ticks > 0u && since >= st->cfg.stall_ticks))
        return 0;
    mag = st->mt_mag;
    if (!new_edge && since > 0u && mag > 0u) {
        uint32_t bound = ratio(st, st->edge_num, since);
        mag = bound < mag ? bound : mag;
    }
    return with_dir(st->mt_dir, mag);
}
