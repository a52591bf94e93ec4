/* SPDX-License-Identifier: Apache-2.0 */
/*
 * drv_model.c -- sw/enc_qei_drv.c (compiled in here, its register accesses routed through
 * ENC_QEI_DRV_RD / ENC_QEI_DRV_WR) and sw/examples/enc_qei_servo.c against a model of enc_qei's
 * registers (built and run by tb/enc_qei_doc/test_c_driver.py).
 *
 * The model's clock advances one tick per bus access. A write takes effect LATENCY accesses
 * after it (0: before the next access, as in today's build); a snapshot taken at tick T shows in
 * channel k STAGGER * k + LATENCY accesses later: that channel's SNAP_* registers change to the
 * values of tick T and its EVENTS.SNAP_READY rises together (what CAPS.ENGINE = shared allows).
 * Until then SNAP_* hold the previous snapshot, so a driver that reads them early reads old
 * values. EVENTS is write-1-to-clear; IRQ_SUMMARY follows EVENTS & IRQ_EN; COUNT_LO latches
 * COUNT_HI; GSNAP_TIME changes when the last channel shows the snapshot. The count of channel k
 * moves at a constant speed from a start near the COUNT_W wrap, with an A-rising edge every
 * EDGE_EVERY(k) ticks.
 *
 * The checks compare what the driver returns with the model's own record (the instant of every
 * snapshot, the motion), not with anything the driver computed. Output: one line per failed
 * check ("FAIL ..."), then "checks <n> failures <f> accesses/channel <a>".
 *
 * Usage: drv_model init
 *        drv_model run <channels> <count_w> <ts_w> <timing 0|1> <full 0|1> <latency> <stagger>
 */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "enc_qei_regs.h"

static uint32_t model_rd(volatile uint32_t *reg);
static void model_wr(volatile uint32_t *reg, uint32_t v);
#define ENC_QEI_DRV_RD(reg) model_rd(&(reg))
#define ENC_QEI_DRV_WR(reg, v) model_wr(&(reg), (v))
#include "enc_qei_drv.c"
#include "enc_qei_servo.h"

#define NCH 16u
#define SNAP_READY_BM ENC_QEI__EVENTS__SNAP_READY_bm
#define MAXQ 4096u

static enc_qei_t space;   /* the addresses the driver uses; never read or written */

struct snapinfo { uint64_t t, due; int global; };
struct wr { uint64_t due; uint32_t off, v; };

static struct {
    uint32_t id, caps;
    unsigned channels, count_w, ts_w, timing, full, latency, stagger;
    uint64_t now;
    uint32_t events[NCH], irq_en[NCH], snap_ctrl[NCH], count_hi_latch[NCH];
    uint32_t gsnap_ctrl, gsnap_period, gsnap_time;
    uint64_t timer_next;
    /* the snapshot registers as they read now: the instant they hold */
    uint64_t snap_t[NCH];
    int have_snap[NCH];
    /* writes not yet in effect, snapshots not yet shown */
    struct wr wq[MAXQ];
    unsigned nwq;
    struct snapinfo sq[NCH][MAXQ];
    unsigned nsq[NCH];
    /* the record: every snapshot's instant, and per channel the instants it latched */
    uint64_t taken[MAXQ];
    unsigned ntaken;
    uint64_t hist[NCH][MAXQ];
    unsigned nhist[NCH];
    unsigned bad_access, accesses;
    uint64_t last_count_read_t[NCH];
} m;

static unsigned checks, failures;

#define CHECK(cond, ...) do { checks++; if (!(cond)) { failures++; printf("FAIL %s:%d: ", \
    __func__, __LINE__); printf(__VA_ARGS__); printf("\n"); } } while (0)

/* ---- the motion --------------------------------------------------------------------------- */

static uint64_t cmask(void)
{
    return m.count_w >= 64u ? ~(uint64_t)0 : ((uint64_t)1 << m.count_w) - 1u;
}

static uint32_t tmask(void)
{
    return m.ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)((1ul << m.ts_w) - 1ul);
}

static int64_t speed(unsigned k) { return (int64_t)k * 3 - 7; }   /* count steps per tick */
static uint64_t start(unsigned k) { return cmask() - 40u * k - 500u; } /* near the wrap */
#define EDGE_EVERY(k) (5u + (k))

/* the count at tick t (exact, then wrapped to COUNT_W bits) */
static uint64_t count_at(unsigned k, uint64_t t)
{
    return (start(k) + (uint64_t)(speed(k) * (int64_t)t)) & cmask();
}

static uint64_t edge_at(unsigned k, uint64_t t) { return t / EDGE_EVERY(k) * EDGE_EVERY(k); }

/* the snapshot registers of channel k for a snapshot at t, the previous one at prev */
static void expect(unsigned k, uint64_t t, uint64_t prev, int have_prev, qei_vel_snap_t *s)
{
    s->count = count_at(k, t);
    s->time = (uint32_t)t & tmask();
    s->edge_time = (uint32_t)edge_at(k, t) & tmask();
    s->delta = have_prev ? (int32_t)(speed(k) * (int64_t)(t - prev)) : 0;
    s->edge_delta = have_prev
        ? (int32_t)(speed(k) * (int64_t)(edge_at(k, t) - edge_at(k, prev))) : 0;
}

/* ---- the registers ------------------------------------------------------------------------ */

static void take(unsigned k, uint64_t t, uint64_t due, int global)
{
    struct snapinfo si;
    si.t = t;
    si.due = due;
    si.global = global;
    if (m.nsq[k] < MAXQ)
        m.sq[k][m.nsq[k]++] = si;
    if (m.nhist[k] < MAXQ)
        m.hist[k][m.nhist[k]++] = t;
}

/* channel k's snapshot before the one at t, and whether it had one */
static int before(unsigned k, uint64_t t, uint64_t *prev)
{
    unsigned i;
    int have = 0;
    for (i = 0; i < m.nhist[k]; i++)
        if (m.hist[k][i] < t)
            *prev = m.hist[k][i], have = 1;
    return have;
}

static void snapshot(uint64_t t, int global, unsigned only)
{
    unsigned k;
    if (m.ntaken < MAXQ)
        m.taken[m.ntaken++] = t;
    for (k = 0; k < m.channels; k++)
        if (global || k == only)
            take(k, t, t + m.latency + m.stagger * (global ? k : 0u), global);
}

static void apply_write(uint32_t off, uint32_t v)
{
    unsigned page = off / ENC_QEI_PAGE, reg = off % ENC_QEI_PAGE;
    if (page == 0u && reg == ENC_QEI_GSNAP_CTRL_OFFSET) {
        if (!m.timing) return;
        if ((v & ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm) &&
            !(m.gsnap_ctrl & ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm))
            m.timer_next = m.now + (m.gsnap_period ? m.gsnap_period : 1u);
        m.gsnap_ctrl = v & ~(uint32_t)ENC_QEI__GSNAP_CTRL__CMD_bm;
        if (v & ENC_QEI__GSNAP_CTRL__CMD_bm)
            snapshot(m.now, 1, 0);
    } else if (page == 0u && reg == ENC_QEI_GSNAP_PERIOD_OFFSET) {
        if (m.timing) m.gsnap_period = v;
    } else if (reg == ENC_QEI_EVENTS_OFFSET) {
        m.events[page] &= ~v;
    } else if (reg == ENC_QEI_IRQ_EN_OFFSET) {
        m.irq_en[page] = v;
    } else if (reg == ENC_QEI_SNAP_CTRL_OFFSET) {
        if (!m.timing) return;
        m.snap_ctrl[page] = v & ~(uint32_t)ENC_QEI__SNAP_CTRL__CMD_bm;
        if (v & ENC_QEI__SNAP_CTRL__CMD_bm)
            snapshot(m.now, 0, page);
    }
}

/* what happens before an access at tick m.now */
static void advance(void)
{
    unsigned i, j, k;
    for (i = j = 0; i < m.nwq; i++) {            /* writes in order, each at its due tick */
        if (m.wq[i].due <= m.now)
            apply_write(m.wq[i].off, m.wq[i].v);
        else
            m.wq[j++] = m.wq[i];
    }
    m.nwq = j;
    while (m.timing && (m.gsnap_ctrl & ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm) &&
           m.now >= m.timer_next) {
        snapshot(m.timer_next, 1, 0);
        m.timer_next += m.gsnap_period ? m.gsnap_period : 1u;
    }
    for (k = 0; k < m.channels; k++) {
        for (i = j = 0; i < m.nsq[k]; i++) {
            struct snapinfo si = m.sq[k][i];
            if (si.due <= m.now) {
                m.snap_t[k] = si.t;
                m.have_snap[k] = 1;
                m.events[k] |= SNAP_READY_BM;
                if (si.global && k == m.channels - 1u)
                    m.gsnap_time = (uint32_t)si.t & tmask();
            } else {
                m.sq[k][j++] = si;
            }
        }
        m.nsq[k] = j;
    }
}

static uint32_t offset_of(volatile uint32_t *reg)
{
    return (uint32_t)((uintptr_t)reg - (uintptr_t)&space);
}

/* the snapshot registers of channel k as they read now (the snapshot at m.snap_t[k]) */
static uint32_t snap_reg(unsigned k, unsigned reg)
{
    qei_vel_snap_t s;
    uint64_t prev = 0;
    int have_prev;
    if (!m.have_snap[k])
        return 0u;
    have_prev = before(k, m.snap_t[k], &prev);
    expect(k, m.snap_t[k], prev, have_prev, &s);
    switch (reg) {
    case ENC_QEI_SNAP_COUNT_LO_OFFSET: return (uint32_t)s.count;
    case ENC_QEI_SNAP_COUNT_HI_OFFSET: return m.count_w > 32u ? (uint32_t)(s.count >> 32) : 0u;
    case ENC_QEI_SNAP_TIME_OFFSET: return s.time;
    case ENC_QEI_SNAP_EDGE_TIME_OFFSET: return s.edge_time;
    case ENC_QEI_SNAP_DELTA_OFFSET: return (uint32_t)s.delta;
    default: return (uint32_t)s.edge_delta;
    }
}

static uint32_t model_rd(volatile uint32_t *reg)
{
    uint32_t off = offset_of(reg), v = 0u;
    unsigned page = off / ENC_QEI_PAGE, reg_off = off % ENC_QEI_PAGE, k;
    advance();
    m.accesses++;
    if (page >= m.channels && !(page == 0u)) {
        m.bad_access++;
    } else if (page == 0u && reg_off == ENC_QEI_ID_OFFSET) {
        v = m.id;
    } else if (page == 0u && reg_off == ENC_QEI_CAPS_OFFSET) {
        v = m.caps;
    } else if (page == 0u && reg_off == ENC_QEI_TIMEBASE_OFFSET) {
        v = (uint32_t)m.now & tmask();
    } else if (page == 0u && reg_off == ENC_QEI_GSNAP_CTRL_OFFSET) {
        v = m.gsnap_ctrl;
    } else if (page == 0u && reg_off == ENC_QEI_GSNAP_TIME_OFFSET) {
        v = m.gsnap_time;
    } else if (page == 0u && reg_off == ENC_QEI_IRQ_SUMMARY_OFFSET) {
        for (k = 0; k < m.channels; k++)
            if (m.events[k] & m.irq_en[k])
                v |= 1u << k;
    } else if (reg_off == ENC_QEI_EVENTS_OFFSET) {
        v = m.events[page];
    } else if (reg_off == ENC_QEI_IRQ_EN_OFFSET) {
        v = m.irq_en[page];
    } else if (reg_off == ENC_QEI_SNAP_CTRL_OFFSET) {
        v = m.snap_ctrl[page];
    } else if (reg_off == ENC_QEI_COUNT_LO_OFFSET) {
        uint64_t c = count_at(page, m.now);
        m.last_count_read_t[page] = m.now;
        m.count_hi_latch[page] = m.count_w > 32u ? (uint32_t)(c >> 32) : 0u;
        v = (uint32_t)c;
    } else if (reg_off == ENC_QEI_COUNT_HI_OFFSET) {
        v = m.count_hi_latch[page];
    } else if (reg_off >= ENC_QEI_SNAP_COUNT_LO_OFFSET &&
               reg_off <= ENC_QEI_SNAP_EDGE_DELTA_OFFSET) {
        v = m.timing ? snap_reg(page, reg_off) : 0u;
    } else if (reg_off == ENC_QEI_PERIOD_OFFSET) {
        v = m.full ? 1234u : 0u;
    } else if (reg_off == ENC_QEI_PERIOD_CTRL_OFFSET) {
        v = m.full ? ENC_QEI__PERIOD_CTRL__N_SET(3u) | ENC_QEI__PERIOD_CTRL__DIR_CHANGE_bm : 0u;
    } else if (reg_off == ENC_QEI_STATUS_OFFSET) {
        v = ENC_QEI__STATUS__STALLED_bm;
    }
    m.now++;
    return v;
}

static void model_wr(volatile uint32_t *reg, uint32_t v)
{
    uint32_t off = offset_of(reg);
    advance();
    m.accesses++;
    if (off / ENC_QEI_PAGE >= m.channels && off / ENC_QEI_PAGE != 0u)
        m.bad_access++;
    else if (m.latency == 0u)
        apply_write(off, v);
    else if (m.nwq < MAXQ) {
        m.wq[m.nwq].due = m.now + m.latency;
        m.wq[m.nwq].off = off;
        m.wq[m.nwq++].v = v;
    }
    m.now++;
}

/* the hardware raising events of channel k (not through the bus) */
static void hw_event(unsigned k, uint32_t bits) { m.events[k] |= bits; }

/* let every pending write and snapshot land */
static void settle(void)
{
    uint64_t until = m.now + m.latency + m.stagger * NCH + 2u;
    while (m.now < until) {
        advance();
        m.now++;
    }
}

static void reset_model(unsigned channels, unsigned count_w, unsigned ts_w, unsigned timing,
                        unsigned full, unsigned latency, unsigned stagger)
{
    memset(&m, 0, sizeof m);
    m.id = ENC_QEI_ID_RESET;
    m.channels = channels;
    m.count_w = count_w;
    m.ts_w = ts_w;
    m.timing = timing;
    m.full = full;
    m.latency = latency;
    m.stagger = stagger;
    m.caps = ENC_QEI__CAPS__COUNT_W_SET(count_w) | ENC_QEI__CAPS__TS_W_SET(timing ? ts_w : 0u) |
             ENC_QEI__CAPS__INDEX_bm | (timing ? ENC_QEI__CAPS__TIMING_bm : 0u) |
             ENC_QEI__CAPS__PROFILE_SET(full ? ENC_QEI__CAPS__PROFILE__FULL_VAL :
                                        timing ? ENC_QEI__CAPS__PROFILE__LEAN_VAL :
                                                 ENC_QEI__CAPS__PROFILE__COUNTING_VAL) |
             ENC_QEI__CAPS__CHANNELS_SET(channels) | (latency ? 0x80000000u : 0u);
    m.now = 1000u;
}

/* ---- the checks --------------------------------------------------------------------------- */

static void check_snap(const char *what, unsigned k, const qei_vel_snap_t *got, uint64_t t,
                       uint64_t prev, int have_prev)
{
    qei_vel_snap_t want;
    expect(k, t, prev, have_prev, &want);
    CHECK(got->count == want.count && got->time == want.time &&
          got->edge_time == want.edge_time && got->delta == want.delta &&
          got->edge_delta == want.edge_delta,
          "%s channel %u: read count %" PRIx64 " time %" PRIu32 " edge %" PRIu32 " delta %" PRId32
          " edge_delta %" PRId32 "; the snapshot at tick %" PRIu64 " has %" PRIx64 " %" PRIu32
          " %" PRIu32 " %" PRId32 " %" PRId32, what, k, got->count, got->time, got->edge_time,
          got->delta, got->edge_delta, t, want.count, want.time, want.edge_time, want.delta,
          want.edge_delta);
}

static void test_init(void)
{
    struct { uint32_t id, caps; int want; } cases[] = {
        {0x51450102u, ENC_QEI__CAPS__CHANNELS_SET(4u), ENC_QEI_DRV_OK},
        {0x51450103u, ENC_QEI__CAPS__CHANNELS_SET(16u), ENC_QEI_DRV_OK},
        {0x514501FFu, ENC_QEI__CAPS__CHANNELS_SET(1u), ENC_QEI_DRV_OK},
        {0x51440102u, ENC_QEI__CAPS__CHANNELS_SET(4u), ENC_QEI_DRV_ENODEV},
        {0xFFFFFFFFu, 0xFFFFFFFFu, ENC_QEI_DRV_ENODEV},      /* an unmapped read on VexRiscv */
        {0x00000000u, 0x00000000u, ENC_QEI_DRV_ENODEV},
        {0x51450101u, ENC_QEI__CAPS__CHANNELS_SET(4u), ENC_QEI_DRV_EVERSION},
        {0x51450100u, ENC_QEI__CAPS__CHANNELS_SET(1u), ENC_QEI_DRV_EVERSION},
        {0x51450002u, ENC_QEI__CAPS__CHANNELS_SET(4u), ENC_QEI_DRV_EVERSION},
        {0x51450202u, ENC_QEI__CAPS__CHANNELS_SET(4u), ENC_QEI_DRV_EVERSION},
        {0x51450102u, ENC_QEI__CAPS__CHANNELS_SET(0u), ENC_QEI_DRV_ECAPS},
        {0x51450102u, ENC_QEI__CAPS__CHANNELS_SET(17u), ENC_QEI_DRV_ECAPS},
        {0x51450102u, ENC_QEI__CAPS__CHANNELS_SET(2u) | ENC_QEI__CAPS__COUNT_W_SET(65u),
         ENC_QEI_DRV_ECAPS},
        {0x51450102u, ENC_QEI__CAPS__CHANNELS_SET(2u) | ENC_QEI__CAPS__TS_W_SET(33u),
         ENC_QEI_DRV_ECAPS},
    };
    unsigned i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        enc_qei_dev_t d;
        int got;
        reset_model(16u, 32u, 32u, 1u, 1u, 0u, 0u);
        m.id = cases[i].id;
        m.caps = cases[i].caps | (ENC_QEI__CAPS__COUNT_W_GET(cases[i].caps) ? 0u
                                  : ENC_QEI__CAPS__COUNT_W_SET(32u));
        m.channels = ENC_QEI__CAPS__CHANNELS_GET(m.caps) ? ENC_QEI__CAPS__CHANNELS_GET(m.caps) : 1u;
        if (m.channels > NCH)
            m.channels = NCH;
        got = enc_qei_drv_init(&d, (volatile enc_qei_t *)&space);
        CHECK(got == cases[i].want,
              "ID 0x%08" PRIx32 " CAPS 0x%08" PRIx32 ": init returned %d (%s), "
              "want %d", cases[i].id, cases[i].caps, got, enc_qei_drv_strerror(got), cases[i].want);
        CHECK(got != ENC_QEI_DRV_OK || d.channels == ENC_QEI__CAPS__CHANNELS_GET(cases[i].caps),
              "channels %u", d.channels);
        CHECK(got == ENC_QEI_DRV_OK || m.accesses == 2u, "a refused init made %u accesses, not "
              "2 (ID, CAPS)", m.accesses);
    }
}

static void test_positions(enc_qei_dev_t *d)
{
    unsigned k;
    for (k = 0; k < d->channels; k++) {
        int64_t pos, want;
        uint64_t c;
        int err = enc_qei_drv_read_position(d, k, &pos);
        CHECK(err == ENC_QEI_DRV_OK, "read_position %d", err);
        c = count_at(k, m.last_count_read_t[k]);   /* COUNT_W bits: the sign is the top one */
        want = m.count_w < 64u && (c >> (m.count_w - 1u)) ? -(int64_t)(cmask() - c) - 1
                                                           : (int64_t)c;
        CHECK(pos == want, "channel %u: position %" PRId64 ", the count at the read %" PRId64, k,
              pos, want);
    }
    CHECK(enc_qei_drv_read_position(d, d->channels, NULL) == ENC_QEI_DRV_EINVAL,
          "channel >= CHANNELS");
}

static void check_all(const char *what, const qei_vel_snap_t *s, unsigned channels, uint64_t when)
{
    unsigned k;
    for (k = 0; k < channels; k++) {
        uint64_t prev = 0;
        int have_prev = before(k, when, &prev);
        check_snap(what, k, &s[k], when, prev, have_prev);
    }
}

static void test_gsnap_take(enc_qei_dev_t *d)
{
    qei_vel_snap_t s[NCH];
    uint32_t t;
    unsigned n;
    uint64_t last = 0;
    for (n = 0; n < 5u; n++) {
        unsigned taken0 = m.ntaken;
        int err = enc_qei_drv_gsnap_take(d, &t, s, 0u);
        uint64_t when;
        CHECK(err == ENC_QEI_DRV_OK, "gsnap_take returned %d (%s)", err, enc_qei_drv_strerror(err));
        CHECK(m.ntaken == taken0 + 1u, "gsnap_take took %u snapshots", m.ntaken - taken0);
        when = m.taken[m.ntaken - 1u];
        CHECK(t == ((uint32_t)when & tmask()),
              "GSNAP_TIME %" PRIu32 ", the snapshot's tick %" PRIu64,
              t, when);
        CHECK(when > last, "not a new snapshot");
        last = when;
        check_all("gsnap_take", s, d->channels, when);
        if (n == 2u) {          /* a snapshot nobody read yet: the next take is not that one */
            snapshot(m.now, 1, 0);
            settle();
        }
    }
}

static void test_snap_take(enc_qei_dev_t *d)
{
    qei_vel_snap_t s[NCH];
    uint32_t t;
    unsigned k, taken0;
    int err;
    for (k = 0; k < d->channels; k += 3u) {
        taken0 = m.ntaken;
        err = enc_qei_drv_snap_config(d, k, ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm |
                                                ENC_QEI__SNAP_CTRL__CMD_bm);
        CHECK(err == ENC_QEI_DRV_OK, "snap_config %d", err);
        settle();
        CHECK(m.ntaken == taken0, "snap_config wrote SNAP_CTRL.CMD");
        err = enc_qei_drv_snap_take(d, k, &s[0], ENC_QEI_DRV_SNAP_LIVE);
        CHECK(err == ENC_QEI_DRV_OK, "snap_take %d", err);
        CHECK(m.ntaken == taken0 + 1u, "snap_take took %u snapshots", m.ntaken - taken0);
        {
            uint64_t when = m.taken[m.ntaken - 1u], prev = 0;
            check_snap("snap_take", k, &s[0], when, prev, before(k, when, &prev));
        }
        CHECK(s[0].stalled == 1u && s[0].period == (m.full ? 1234u : 0u) &&
              s[0].period_n == (m.full ? 3u : 1u) && s[0].period_dir_change == (m.full ? 1u : 0u),
              "live fields: stalled %u period %" PRIu32 " n %" PRIu32 " dir_change %u",
              s[0].stalled, s[0].period, s[0].period_n, s[0].period_dir_change);
        settle();
        CHECK(m.snap_ctrl[k] == ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm, "SNAP_CTRL 0x%" PRIx32
              " after the command: EDGE not kept", m.snap_ctrl[k]);
    }
    /* a global snapshot, then channel 0 takes one of its own before the global one is read */
    snapshot(m.now, 1, 0);
    settle();
    snapshot(m.now, 0, 0);
    settle();
    err = enc_qei_drv_gsnap_read(d, &t, s, 0u);
    CHECK(err == ENC_QEI_DRV_ESKEW, "gsnap_read of a global snapshot with one channel's own "
          "after it returned %d, not ENC_QEI_DRV_ESKEW", err);
    CHECK(s[0].time == ((uint32_t)m.taken[m.ntaken - 1u] & tmask()) &&
          (d->channels < 2u || s[1].time == t), "ESKEW: values");
}


static void test_irq_and_events(enc_qei_dev_t *d)
{
    unsigned k = d->channels - 1u;
    uint32_t a = ENC_QEI__EVENTS__INDEX_bm, b = ENC_QEI__EVENTS__CMP_bm, got;
    /* two enables in a row: both, whatever the first write's latency (no read-modify-write) */
    enc_qei_drv_irq_enable(d, k, a);
    enc_qei_drv_irq_enable(d, k, b);
    settle();
    CHECK(m.irq_en[k] == (a | b),
          "IRQ_EN 0x%" PRIx32 " after enabling 0x%" PRIx32 " then 0x%" PRIx32,
          m.irq_en[k], a, b);
    enc_qei_drv_irq_disable(d, k, a);
    settle();
    CHECK(m.irq_en[k] == b, "IRQ_EN 0x%" PRIx32 " after disabling 0x%" PRIx32, m.irq_en[k], a);
    hw_event(k, a | b | ENC_QEI__EVENTS__QERR_bm);
    CHECK((enc_qei_drv_irq_pending(d) >> k) & 1u, "IRQ_SUMMARY without channel %u", k);
    got = enc_qei_drv_events_take(d, k);
    CHECK(got == b, "events_take returned 0x%" PRIx32 ", the enabled pending 0x%" PRIx32, got, b);
    CHECK((m.events[k] & b) == 0u, "the taken event is still pending in the hardware on return");
    CHECK((m.events[k] & (a | ENC_QEI__EVENTS__QERR_bm)) == (a | ENC_QEI__EVENTS__QERR_bm),
          "events not enabled were cleared");
    CHECK(!((enc_qei_drv_irq_pending(d) >> k) & 1u), "IRQ_SUMMARY still shows channel %u", k);
    CHECK(enc_qei_drv_events_take(d, k) == 0u, "the same event taken twice");
    CHECK(enc_qei_drv_events(d, k) == (a | ENC_QEI__EVENTS__QERR_bm), "events");
    enc_qei_drv_events_clear(d, k, 0xFFFFFFFFu);
    CHECK(m.events[k] == 0u, "events_clear left 0x%" PRIx32, m.events[k]);
    enc_qei_drv_irq_disable(d, k, 0xFFFFFFFFu);
}

static void test_timeout(enc_qei_dev_t *d)
{
    qei_vel_snap_t s[NCH];
    uint32_t t;
    unsigned a0 = m.accesses;
    int err;
    settle();
    d->spin = 50u;
    err = enc_qei_drv_gsnap_read(d, &t, s, 0u);
    CHECK(err == ENC_QEI_DRV_ETIMEDOUT, "gsnap_read with no snapshot pending returned %d", err);
    CHECK(m.accesses - a0 <= 60u, "the wait took %u accesses, spin 50", m.accesses - a0);
    d->spin = ENC_QEI_DRV_SPIN_DEFAULT;
}

/* the servo example on the unit timer, its interrupt polled */
/* the servo example on the unit timer, its interrupt polled */
static void test_servo(unsigned frac)
{
    static enc_qei_servo_t sv;
    const uint32_t tick_hz = 1000000u, period = 4000u;
    unsigned n, k, ticks = 0, first;
    uint64_t last = 0;
    int err;
    settle();
    first = m.ntaken;
    err = enc_qei_servo_start(&sv, (volatile enc_qei_t *)&space, tick_hz, tick_hz / period,
                              frac, 0u);
    CHECK(err == ENC_QEI_DRV_OK, "servo_start %d", err);
    for (n = 0; n < 200000u && ticks < 6u; n++) {
        uint64_t when;
        if (!(enc_qei_drv_irq_pending(&sv.dev) & 1u))     /* the interrupt line */
            continue;
        err = enc_qei_servo_tick(&sv);
        CHECK(err == ENC_QEI_DRV_OK, "servo_tick %d", err);
        when = m.taken[first + ticks];
        CHECK(sv.time == ((uint32_t)when & tmask()), "servo tick %u: GSNAP_TIME %" PRIu32
              ", the timer's snapshot %u was at tick %" PRIu64 " (one skipped or repeated)",
              ticks, sv.time, ticks, when);
        CHECK(when > last, "a repeated snapshot");
        last = when;
        check_all("servo", sv.snap, sv.dev.channels, when);
        for (k = 0; k < sv.dev.channels; k++) {
            /* constant speed, edges every EDGE_EVERY ticks: MT reads it exactly, once the first
             * tick has initialised and the first A-rising edge after it was a reference */
            int64_t vel = speed(k) * (int64_t)tick_hz * ((int64_t)1 << frac);
            vel = vel > INT32_MAX ? INT32_MAX : vel < -INT32_MAX ? -INT32_MAX : vel;
            CHECK(sv.pos[k] == enc_qei_drv_signed(&sv.dev, count_at(k, when)), "position");
            CHECK(ticks < 2u || sv.vel[k] == vel, "servo tick %u channel %u: velocity %" PRId32
                  " units, the motion's %" PRId64, ticks, k, sv.vel[k], vel);
        }
        CHECK(!(enc_qei_drv_irq_pending(&sv.dev) & 1u), "the interrupt is still pending after "
              "the handler");
        ticks++;
    }
    CHECK(ticks == 6u, "%u servo ticks in %u polls", ticks, n);
    enc_qei_servo_stop(&sv);
    settle();
    CHECK(!(m.gsnap_ctrl & ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm) && m.irq_en[0] == 0u, "servo_stop");
    for (k = 0; k < sv.dev.channels; k++)                 /* what the timer left */
        m.events[k] &= ~(uint32_t)SNAP_READY_BM;
}


static void test_no_timing(enc_qei_dev_t *d)
{
    qei_vel_snap_t s[NCH];
    uint32_t t;
    CHECK(enc_qei_drv_gsnap_take(d, &t, s, 0u) == ENC_QEI_DRV_ENOTSUP, "gsnap_take");
    CHECK(enc_qei_drv_gsnap_read(d, &t, s, 0u) == ENC_QEI_DRV_ENOTSUP, "gsnap_read");
    CHECK(enc_qei_drv_snap_take(d, 0u, s, 0u) == ENC_QEI_DRV_ENOTSUP, "snap_take");
    CHECK(enc_qei_drv_gsnap_config(d, 0u, 1u) == ENC_QEI_DRV_ENOTSUP, "gsnap_config");
    CHECK(enc_qei_drv_snap_config(d, 0u, 0u) == ENC_QEI_DRV_ENOTSUP, "snap_config");
}

int main(int argc, char **argv)
{
    enc_qei_dev_t d;
    unsigned a[7], i, a0;
    int err;
    if (argc == 2 && strcmp(argv[1], "init") == 0) {
        test_init();
    } else if (argc == 9 && strcmp(argv[1], "run") == 0) {
        for (i = 0; i < 7u; i++)
            a[i] = (unsigned)strtoul(argv[2 + i], NULL, 0);
        reset_model(a[0], a[1], a[2], a[3], a[4], a[5], a[6]);
        err = enc_qei_drv_init(&d, (volatile enc_qei_t *)&space);
        CHECK(err == ENC_QEI_DRV_OK, "init %d (%s)", err, enc_qei_drv_strerror(err));
        CHECK(d.channels == a[0] && d.count_w == a[1] && d.has_timing == (int)a[3],
              "init found %u channels, COUNT_W %u, timing %d", d.channels, d.count_w, d.has_timing);
        test_positions(&d);
        test_irq_and_events(&d);
        if (a[3]) {
            a0 = m.accesses;
            test_gsnap_take(&d);
            printf("gsnap_take accesses/channel %.1f\n",
                   (double)(m.accesses - a0) / 5.0 / d.channels);
            test_snap_take(&d);
            test_timeout(&d);
            test_servo(8u);
            test_servo(0u);
        } else {
            test_no_timing(&d);
        }
        CHECK(m.bad_access == 0u, "%u accesses to pages >= CHANNELS", m.bad_access);
    } else {
        fprintf(stderr, "usage: drv_model init | run channels count_w ts_w timing full latency "
                        "stagger\n");
        return 2;
    }
    printf("checks %u failures %u\n", checks, failures);
    return failures ? 1 : 0;
}
