/* SPDX-License-Identifier: Apache-2.0 */
/*
 * main.c -- enc_qei firmware for the simulated LiteX SoC (doc/litex.md).
 *
 * Uses, for the peripheral, only the generated register header (sw/enc_qei_regs.h) and the
 * velocity estimators (sw/enc_qei_velocity.c); from LiteX only the console, the interrupt
 * controller and the SoC's generated headers (ENC_QEI_BASE, ENC_QEI_INTERRUPT,
 * CONFIG_CLOCK_FREQUENCY).
 *
 * 1. Finds the build in ID and CAPS (channel count, profile, widths; it needs the timing unit:
 *    full or lean) and sets up every channel: x4, FILTER_LEN 3, free range, index latch on every
 *    index, snapshots timing A-rising edges; with an edge FIFO (CAPS.EFIFO_LOG2 > 0) each
 *    channel's FIFO is cleared and enabled.
 * 2. Runs the global unit timer at 1 kHz (GSNAP_PERIOD, PERIOD_EN): one snapshot of all channels
 *    per millisecond, one interrupt (EVENTS.SNAP_READY of channel 0, found through IRQ_SUMMARY).
 * 3. The interrupt handler reads every channel's snapshot registers (SNAP_COUNT, SNAP_TIME,
 *    SNAP_EDGE_TIME, SNAP_DELTA, SNAP_EDGE_DELTA: one instant), computes position and velocity
 *    (qei_vel_update: the timestamp method, with its stall rule at 20 ms), counts its own CPU
 *    cycles (mcycle) after each channel, and stores one record. Meanwhile the main loop drains
 *    the edge FIFOs (if any) and keeps statistics of their entries. After ENC_FW_SNAPSHOTS
 *    snapshots the main loop stops the timer and the FIFOs, drains them, prints the records as
 *    a table, the cycle summary, the FIFO statistics, reads one unmapped offset (what the bus
 *    does with it), prints DONE and ends the simulation.
 *
 * Lines of the output (tools/enctools/litex/check.py parses them):
 *   BUILD <channels> <profile> <count_w> <ts_w> <clock_hz> <period_ticks> <efifo_log2>
 *   S <n> <gsnap_time> <latency> <cycles> | <pos_k> <vel_k> | ...
 *        one per snapshot: GSNAP_TIME, TIMEBASE at the handler's entry minus GSNAP_TIME (the
 *        interrupt latency: trap entry and LiteX's dispatch, in clocks), the handler's cycles,
 *        and per channel the position (count steps) and the velocity (count steps per second,
 *        timestamp method)
 *   C <k> <min> <mean> <max>     handler cycles from its entry to channel k - 1 done
 *   X <k> <count> <index_latch> <qerr_count> <glitch_count>    channel k at the end
 *   M <missed> <torn> <skewed>   snapshots missed; read while the next one landed; a channel's
 *                                SNAP_TIME other than GSNAP_TIME
 *   E <k> <entries> <net> <dir_changes> <idx> <lost> <nonmono> <ab_bad> <t_first> <t_last>
 *     <sum_t> <efifo_lost> <cycles>      channel k's edge FIFO, every entry drained: their
 *        number, the sum of their directions (+1/-1), direction changes between consecutive
 *        entries, entries marked IDX and LOST, times not after the previous entry's, entries
 *        whose (A, B) is not the quadrature successor of the previous one in their direction,
 *        the first and last entry's time, the sum of the times (mod 2^32), EFIFO_LOST at the
 *        end, and the CPU cycles spent on the entries (two reads and this bookkeeping)
 *   U <offset> <value> <cycles> <bus_errors>   one read of an unmapped offset of page 0: what
 *        it returned, the cycles it took, LiteX's bus-error count (ctrl) it added
 *   DONE
 * Build flag ENC_FW_FAULT_page: read channel k's SNAP_COUNT from channel k + 1's page (a
 * deliberately wrong register address, which the test must catch). ENC_FW_FAULT_efifo: take an
 * entry's direction from its A bit instead of DIR (a wrong field, which the test must catch).
 */
#include <stdint.h>
#include <stdio.h>

#include <irq.h>
#include <libbase/uart.h>
#include <generated/csr.h>
#include <generated/mem.h>
#include <generated/soc.h>

#include "enc_qei_regs.h"
#include "enc_qei_velocity.h"

#ifndef ENC_FW_SNAPSHOTS
#define ENC_FW_SNAPSHOTS 100
#endif
#define SNAP_HZ 1000u
#define STALL_MS 20u

static volatile enc_qei_t *const q = (volatile enc_qei_t *)ENC_QEI_BASE;

static unsigned channels, profile, count_w, ts_w, efifo_log2;
static uint32_t period_ticks;
static qei_vel_t vel_state[ENC_QEI_CHANNELS_MAX];

/* the records, one per snapshot */
static uint32_t rec_time[ENC_FW_SNAPSHOTS];
static uint32_t rec_latency[ENC_FW_SNAPSHOTS];
static int32_t rec_pos[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];
static int64_t rec_vel[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];   /* count steps/s x 1000 */
static uint32_t rec_cyc[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];  /* cycles after channel k */
static volatile unsigned n_rec;
static unsigned missed, torn, skewed;

/* the edge FIFOs' statistics, one per channel (the E lines) */
struct efifo_stat {
    uint32_t n, dir_changes, idx, lost, nonmono, ab_bad, t_first, t_last, sum_t, cycles;
    int32_t net;
    unsigned phase, up;       /* the last entry's quadrature phase (0 .. 3) and direction */
};
static struct efifo_stat efifo[ENC_QEI_CHANNELS_MAX];
/* (A, B) as (A << 1) | B -> its phase in the forward sequence 00 -> 10 -> 11 -> 01 */
static const unsigned phase_of_ab[4] = {0u, 3u, 1u, 2u};

static inline uint32_t cycles(void)
{
    uint32_t c;
    __asm__ volatile("csrr %0, mcycle" : "=r"(c));
    return c;
}

static int64_t to_milli(double v)
{
    double m = v * 1000.0;
    return (int64_t)(m < 0.0 ? m - 0.5 : m + 0.5);
}

static void read_channel(unsigned k, qei_vel_snap_t *s)
{
    volatile enc_qei_chan_t *ch = &q->chan[k];
    volatile enc_qei_chan_t *cnt = ch;
#ifdef ENC_FW_FAULT_page
    cnt = &q->chan[(k + 1u) % channels];
#endif
    s->count = cnt->SNAP_COUNT_LO;
    if (count_w > 32u)
        s->count |= (uint64_t)cnt->SNAP_COUNT_HI << 32;
    s->time = ch->SNAP_TIME;
    s->edge_time = ch->SNAP_EDGE_TIME;
    s->delta = (int32_t)ch->SNAP_DELTA;
    s->edge_delta = (int32_t)ch->SNAP_EDGE_DELTA;
    s->period_n = 1u;                  /* no period capture: the timestamp method needs none */
    s->period = 0u;
    s->period_ovf = s->period_dir_change = 0u;
    s->stalled = 0u;                   /* the stall rule from the snapshot's own times */
}

static int64_t to_signed(uint64_t count)
{
    if (count_w < 64u && (count >> (count_w - 1u)) & 1u)
        return (int64_t)(count | (~(uint64_t)0 << count_w));
    return (int64_t)count;
}

/* One global snapshot: every channel's registers, position and velocity, cycles per channel.
 * c0 and entry: mcycle and TIMEBASE at the handler's first instructions. */
static void snapshot(uint32_t c0, uint32_t entry)
{
    uint32_t t = q->glb.GSNAP_TIME;
    unsigned n = n_rec;
    static uint32_t last_t;
    static int have_last;

    if (n >= ENC_FW_SNAPSHOTS)
        return;
    for (unsigned k = 0; k < channels; k++) {
        qei_vel_snap_t s;
        qei_vel_reading_t r;
        read_channel(k, &s);
        if (s.time != t)
            skewed++;
        r = qei_vel_update(&vel_state[k], &s);
        rec_pos[n][k] = (int32_t)to_signed(s.count);
        rec_vel[n][k] = to_milli(r.mt);
        rec_cyc[n][k] = cycles() - c0;
    }
    if (q->glb.GSNAP_TIME != t)
        torn++;
    if (have_last && (uint32_t)(t - last_t) != period_ticks)
        missed += (uint32_t)(t - last_t) / period_ticks - 1u;
    last_t = t;
    have_last = 1;
    rec_time[n] = t;
    rec_latency[n] = entry - t;
    n_rec = n + 1u;
}

static unsigned ab_phase(uint32_t a, uint32_t b)
{
    return phase_of_ab[(a << 1) | b];
}

/* Pop channel k's edge FIFO until it reads empty; returns the entries popped. Interrupts are
 * off while one entry is handled, so that its cycle count is its own. */
static unsigned drain(unsigned k)
{
    volatile enc_qei_chan_t *ch = &q->chan[k];
    struct efifo_stat *f = &efifo[k];
    unsigned popped = 0, ie = irq_getie();
    for (;;) {
        irq_setie(ie);              /* a pending interrupt is taken here, between entries */
        irq_setie(0);
        uint32_t c0 = cycles();
        uint32_t e = ch->EFIFO_ENTRY;                 /* pops */
        if (!(e & ENC_QEI__EFIFO_ENTRY__VALID_bm))
            break;
        uint32_t t = ch->EFIFO_TIME;                  /* the popped entry's full timestamp */
#ifdef ENC_FW_FAULT_efifo
        unsigned up = ENC_QEI__EFIFO_ENTRY__A_GET(e);
#else
        unsigned up = ENC_QEI__EFIFO_ENTRY__DIR_GET(e);
#endif
        unsigned phase = ab_phase(ENC_QEI__EFIFO_ENTRY__A_GET(e), ENC_QEI__EFIFO_ENTRY__B_GET(e));
        if (phase != ((f->phase + (up ? 1u : 3u)) & 3u))
            f->ab_bad++;
        if (f->n == 0u) {
            f->t_first = t;
        } else {
            if ((int32_t)(t - f->t_last) <= 0)
                f->nonmono++;
            if (up != f->up)
                f->dir_changes++;
        }
        f->net += up ? 1 : -1;
        f->idx += ENC_QEI__EFIFO_ENTRY__IDX_GET(e);
        f->lost += ENC_QEI__EFIFO_ENTRY__LOST_GET(e);
        f->sum_t += t;
        f->t_last = t;
        f->phase = phase;
        f->up = up;
        f->n++;
        f->cycles += cycles() - c0;
        popped++;
    }
    irq_setie(ie);
    return popped;
}

static void qei_isr(void)
{
    uint32_t c0 = cycles();
    uint32_t entry = q->glb.TIMEBASE;
    uint32_t pending = q->glb.IRQ_SUMMARY;
    for (unsigned k = 0; pending != 0u; k++, pending >>= 1) {
        if (!(pending & 1u))
            continue;
        volatile enc_qei_chan_t *ch = &q->chan[k];
        uint32_t ev = ch->EVENTS & ch->IRQ_EN;
        ch->EVENTS = ev;                        /* W1C: exactly the bits handled */
        if (ev & ENC_QEI__EVENTS__SNAP_READY_bm)
            snapshot(c0, entry);
    }
}

static int discover(void)
{
    uint32_t id = q->glb.ID, caps = q->glb.CAPS;
    uint32_t version = ENC_QEI__ID__VERSION_GET(id);
    if (ENC_QEI__ID__MAGIC_GET(id) != ENC_QEI__ID__MAGIC_reset || (version >> 8) != 1u ||
        (version & 0xFFu) < 1u) {
        printf("enc_qei: no enc_qei 1.1+ at 0x%08lx (ID 0x%08lx)\n", (unsigned long)ENC_QEI_BASE,
               (unsigned long)id);
        return -1;
    }
    channels = ENC_QEI__CAPS__CHANNELS_GET(caps);
    profile = ENC_QEI__CAPS__PROFILE_GET(caps);
    count_w = ENC_QEI__CAPS__COUNT_W_GET(caps);
    ts_w = ENC_QEI__CAPS__TS_W_GET(caps);
    efifo_log2 = ENC_QEI__CAPS__EFIFO_LOG2_GET(caps);
    if (!(caps & ENC_QEI__CAPS__TIMING_bm) || channels < 1u || channels > ENC_QEI_CHANNELS_MAX) {
        printf("enc_qei: CAPS 0x%08lx: this firmware needs the timing unit\n", (unsigned long)caps);
        return -1;
    }
    return 0;
}

static void setup(void)
{
    uint32_t clk = CONFIG_CLOCK_FREQUENCY;
    qei_vel_cfg_t cfg = {0};

    cfg.tick_s = 1.0 / (double)clk;     /* TB_PRESCALE = 0: one tick per clock */
    cfg.ts_w = ts_w;
    cfg.count_w = count_w;
    cfg.counts_per_edge = 4u;           /* x4 counting, A-rising edges */
    cfg.stall_ticks = clk / 1000u * STALL_MS;
    q->glb.TB_PRESCALE = 0u;
    for (unsigned k = 0; k < channels; k++) {
        volatile enc_qei_chan_t *ch = &q->chan[k];
        ch->CTRL = ENC_QEI__CTRL__EN_bm | ENC_QEI__CTRL__FUNC__X4_bm |
                   ENC_QEI__CTRL__RANGE__FREE_bm | ENC_QEI__CTRL__FILTER_LEN_SET(3u);
        ch->INDEX_CTRL = ENC_QEI__INDEX_CTRL__ACTION__LATCH_bm |
                         ENC_QEI__INDEX_CTRL__EDGE__RISING_bm | ENC_QEI__INDEX_CTRL__ARM_bm;
        ch->SNAP_CTRL = ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm;
        ch->IRQ_EN = 0u;
        ch->EVENTS = 0xFFFFFFFFu;      /* clear what reset and setup raised */
        ch->QERR_COUNT = 0u;
        ch->GLITCH_COUNT = 0u;
        if (efifo_log2) {
            uint32_t st = ch->STATUS;
            efifo[k].phase = ab_phase(ENC_QEI__STATUS__A_GET(st), ENC_QEI__STATUS__B_GET(st));
            /* a clean start: CLEAR with EN = 1 in the one write (THRESH at its reset value) */
            ch->EFIFO_CTRL = ENC_QEI_EFIFO_CTRL_RESET | ENC_QEI__EFIFO_CTRL__EN_bm |
                             ENC_QEI__EFIFO_CTRL__CLEAR_bm;
            ch->EFIFO_LOST = 0u;
        }
        qei_vel_init(&vel_state[k], &cfg);
    }
    period_ticks = clk / SNAP_HZ;
    q->glb.GSNAP_PERIOD = period_ticks;
    q->chan[0].IRQ_EN = ENC_QEI__EVENTS__SNAP_READY_bm;   /* one interrupt per global snapshot */
}

static void print_milli(int64_t v)
{
    uint64_t a = v < 0 ? (uint64_t)-v : (uint64_t)v;
    printf(" %s%llu.%03u", v < 0 ? "-" : "", (unsigned long long)(a / 1000u),
           (unsigned)(a % 1000u));
}

static void report(void)
{
    unsigned n = n_rec;
    printf("\n  snap   gsnap_time  lat   cyc");
    for (unsigned k = 0; k < channels; k++)
        printf(" | pos%u vel%u", k, k);
    printf("\n");
    for (unsigned i = 0; i < n; i++) {
        printf("S %4u %11lu %4lu %5lu", i, (unsigned long)rec_time[i],
               (unsigned long)rec_latency[i], (unsigned long)rec_cyc[i][channels - 1u]);
        for (unsigned k = 0; k < channels; k++) {
            printf(" | %ld", (long)rec_pos[i][k]);
            print_milli(rec_vel[i][k]);
        }
        printf("\n");
    }
    /* the first record initialises the estimators and warms the caches: leave it out */
    for (unsigned k = 0; k < channels; k++) {
        uint32_t lo = UINT32_MAX, hi = 0u;
        uint64_t sum = 0u;
        for (unsigned i = 1; i < n; i++) {
            uint32_t c = rec_cyc[i][k];
            lo = c < lo ? c : lo;
            hi = c > hi ? c : hi;
            sum += c;
        }
        printf("C %u %lu %lu %lu\n", k + 1u, (unsigned long)lo,
               (unsigned long)(n > 1u ? sum / (n - 1u) : 0u), (unsigned long)hi);
    }
    for (unsigned k = 0; k < channels; k++) {
        volatile enc_qei_chan_t *ch = &q->chan[k];
        uint32_t count = ch->COUNT_LO;
        printf("X %u %ld %ld %lu %lu\n", k, (long)(int32_t)count, (long)(int32_t)ch->INDEX_LATCH_LO,
               (unsigned long)ch->QERR_COUNT, (unsigned long)ch->GLITCH_COUNT);
    }
    printf("M %u %u %u\n", missed, torn, skewed);
    for (unsigned k = 0; efifo_log2 && k < channels; k++) {
        const struct efifo_stat *f = &efifo[k];
        printf("E %u %lu %ld %lu %lu %lu %lu %lu %lu %lu %lu %lu %lu\n", k, (unsigned long)f->n,
               (long)f->net, (unsigned long)f->dir_changes, (unsigned long)f->idx,
               (unsigned long)f->lost, (unsigned long)f->nonmono, (unsigned long)f->ab_bad,
               (unsigned long)f->t_first, (unsigned long)f->t_last, (unsigned long)f->sum_t,
               (unsigned long)q->chan[k].EFIFO_LOST, (unsigned long)f->cycles);
    }
}

/* One read of an offset no register uses (0xFC of page 0: unmapped in every build). The
 * peripheral answers wb_err_o; what the CPU gets is the SoC's business (doc/litex.md). */
static void unmapped_read(void)
{
    volatile uint32_t *page0 = (volatile uint32_t *)ENC_QEI_BASE;
    uint32_t off = ENC_QEI_PAGE - 4u, errors = 0u, c0, dt, v;
#ifdef CSR_CTRL_BUS_ERRORS_ADDR
    errors = ctrl_bus_errors_read();
#endif
    c0 = cycles();
    v = page0[off / 4u];
    dt = cycles() - c0;
#ifdef CSR_CTRL_BUS_ERRORS_ADDR
    errors = ctrl_bus_errors_read() - errors;
#endif
    printf("U 0x%02lx 0x%08lx %lu %lu\n", (unsigned long)off, (unsigned long)v, (unsigned long)dt,
           (unsigned long)errors);
}

int main(void)
{
    irq_setmask(0);
    irq_setie(0);
    uart_init();
    printf("\nenc_qei firmware on LiteX\n");
    if (discover() != 0) {
        printf("FAIL\n");
    } else {
        setup();
        printf("BUILD %u %u %u %u %lu %lu %u\n", channels, profile, count_w, ts_w,
               (unsigned long)CONFIG_CLOCK_FREQUENCY, (unsigned long)period_ticks, efifo_log2);
        irq_attach(ENC_QEI_INTERRUPT, qei_isr);
        enc_qei_ev_enable_write(1);
        irq_setmask(irq_getmask() | (1u << ENC_QEI_INTERRUPT));
        irq_setie(1);
        q->glb.GSNAP_CTRL = ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm;
        while (n_rec < ENC_FW_SNAPSHOTS)
            for (unsigned k = 0; efifo_log2 && k < channels; k++)
                drain(k);
        q->glb.GSNAP_CTRL = 0u;
        irq_setmask(irq_getmask() & ~(1u << ENC_QEI_INTERRUPT));
        if (efifo_log2) {
            unsigned popped;
            for (unsigned k = 0; k < channels; k++)
                q->chan[k].EFIFO_CTRL = ENC_QEI_EFIFO_CTRL_RESET;   /* EN = 0: no more entries */
            do {                    /* until a whole pass finds every FIFO empty */
                popped = 0u;
                for (unsigned k = 0; k < channels; k++)
                    popped += drain(k);
            } while (popped);
        }
        report();
        unmapped_read();
    }
    printf("DONE\n");
    uart_sync();
#ifdef CSR_SIM_FINISH_BASE
    sim_finish_finish_write(1);
#endif
    for (;;)
        ;
    return 0;
}
