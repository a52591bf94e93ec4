/* SPDX-License-Identifier: Apache-2.0 */
/*
 * main.c -- enc_qei firmware for the simulated LiteX SoC (doc/litex.md).
 *
 * Uses, for the peripheral, the driver API (sw/enc_qei_drv.c over the generated register header
 * sw/enc_qei_regs.h) and one velocity estimator: the fixed-point one (sw/enc_qei_velocity_fx.c,
 * readings in 2^-ENC_FW_FRAC count/s) or, built with ENC_FW_VEL_double, the double one
 * (sw/enc_qei_velocity.c, software floating point on this CPU); from LiteX only the console, the
 * interrupt controller and the SoC's generated headers (ENC_QEI_BASE, ENC_QEI_INTERRUPT,
 * CONFIG_CLOCK_FREQUENCY).
 *
 * 1. Finds the build (enc_qei_drv_init: ID, CAPS; it needs the timing unit: full or lean) and
 *    sets up every channel: x4, FILTER_LEN 3, free range, index latch on every index, snapshots
 *    timing A-rising edges; with an edge FIFO (CAPS.EFIFO_LOG2 > 0) each channel's FIFO is
 *    cleared and enabled.
 * 2. Runs the global unit timer at 1 kHz (GSNAP_PERIOD, PERIOD_EN): one snapshot of all channels
 *    per millisecond, one interrupt (EVENTS.SNAP_READY of channel 0, found through IRQ_SUMMARY).
 * 3. The interrupt handler reads every channel's part of the snapshot (enc_qei_drv_snap_read:
 *    wait for its SNAP_READY, clear it, SNAP_COUNT, SNAP_TIME, SNAP_EDGE_TIME, SNAP_DELTA,
 *    SNAP_EDGE_DELTA), computes position and velocity (the timestamp method, with its stall rule
 *    at 20 ms), counts its own CPU cycles (mcycle) after each channel, and stores one record.
 *    Meanwhile the main loop drains the edge FIFOs (if any) and keeps statistics of their
 *    entries. After ENC_FW_SNAPSHOTS snapshots the main loop stops the timer and the FIFOs,
 *    drains them, takes one global snapshot by command (enc_qei_drv_gsnap_take), prints the
 *    records as a table, the cycle summary, the FIFO statistics, reads one unmapped offset (what
 *    the bus does with it), prints DONE and ends the simulation.
 *
 * Lines of the output (tools/enctools/litex/check.py parses them):
 *   BUILD <channels> <profile> <count_w> <ts_w> <clock_hz> <period_ticks> <efifo_log2> <engine>
 *         <vel>
 *        engine: CAPS.ENGINE (1: the channels share one engine); vel: "double" (velocities
 *        printed to 0.001 count/s) or "fx<F>" (the fixed-point reading printed exactly: F
 *        decimals)
 *   S <n> <gsnap_time> <latency> <cycles> | <pos_k> <vel_k> | ...
 *        one per snapshot: GSNAP_TIME, TIMEBASE at the handler's entry minus GSNAP_TIME (the
 *        interrupt latency: trap entry and LiteX's dispatch, in clocks), the handler's cycles,
 *        and per channel the position (count steps) and the velocity (count steps per second,
 *        timestamp method)
 *   C <k> <min> <mean> <max>     handler cycles from its entry to channel k - 1 done
 *   F <min> <mean> <max>         handler cycles from its entry to the first channel's read (the
 *                                fixed part: TIMEBASE, IRQ_SUMMARY, EVENTS)
 *   D <k> <min> <mean> <max>     cycles of channel k - 1 alone: its snapshot read, velocity and
 *                                record
 *   X <k> <count> <index_latch> <qerr_count> <glitch_count>    channel k at the end
 *   M <missed> <torn> <skewed> <errors>   snapshots missed; GSNAP_TIME after the reads other
 *                                than channel 0's SNAP_TIME (a newer snapshot landed meanwhile);
 *                                channels whose SNAP_TIME differs from channel 0's; driver
 *                                calls that failed
 *   G <err> <gsnap_time> <pos_0> ... <pos_k>   the global snapshot by command at the end
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

#include "enc_qei_drv.h"
#ifdef ENC_FW_VEL_double
#include "enc_qei_velocity.h"
#else
#include "enc_qei_velocity_fx.h"
#endif

#ifndef ENC_FW_SNAPSHOTS
#define ENC_FW_SNAPSHOTS 100
#endif
#ifndef ENC_FW_FRAC
#define ENC_FW_FRAC 8u          /* fixed point: 1/256 count/s, up to 8,388,607 count/s */
#endif
#define SNAP_HZ 1000u
#define STALL_MS 20u
#define SNAP_READY ENC_QEI__EVENTS__SNAP_READY_bm

static enc_qei_dev_t dev;
static volatile enc_qei_t *q;   /* dev.regs: the registers the driver does not cover */
static uint32_t period_ticks;
#ifdef ENC_FW_VEL_double
static qei_vel_t vel_state[ENC_QEI_CHANNELS_MAX];
#else
static qei_velfx_t vel_state[ENC_QEI_CHANNELS_MAX];
#endif

/* the records, one per snapshot */
static uint32_t rec_time[ENC_FW_SNAPSHOTS];
static uint32_t rec_latency[ENC_FW_SNAPSHOTS];
static uint32_t rec_fix[ENC_FW_SNAPSHOTS];                        /* cycles before channel 0 */
static int32_t rec_pos[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];
static int64_t rec_vel[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];   /* the printing's unit */
static uint32_t rec_cyc[ENC_FW_SNAPSHOTS][ENC_QEI_CHANNELS_MAX];  /* cycles after channel k */
static volatile unsigned n_rec;
static unsigned missed, torn, skewed, drv_errors;

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

/* the velocity of channel k from its snapshot: count steps per second x 1000 (double) or in
 * 2^-ENC_FW_FRAC count steps per second (fixed point), the timestamp method */
#ifdef ENC_FW_VEL_double
static int64_t velocity(unsigned k, const qei_vel_snap_t *s)
{
    double m = qei_vel_update(&vel_state[k], s).mt * 1000.0;
    return (int64_t)(m < 0.0 ? m - 0.5 : m + 0.5);
}
#else
static int64_t velocity(unsigned k, const qei_vel_snap_t *s)
{
    return qei_velfx_update_mt(&vel_state[k], s);   /* the timestamp method only */
}
#endif

static int read_channel(unsigned k, qei_vel_snap_t *s)
{
    int err = enc_qei_drv_snap_read(&dev, k, s, 0u);
#ifdef ENC_FW_FAULT_page
    s->count = q->chan[(k + 1u) % dev.channels].SNAP_COUNT_LO;
#endif
    return err;
}

/* One global snapshot: every channel's registers, position and velocity, cycles per channel.
 * c0 and entry: mcycle and TIMEBASE at the handler's first instructions. */
static void snapshot(uint32_t c0, uint32_t entry)
{
    unsigned n = n_rec;
    uint32_t t, t0 = 0u, fix;
    static uint32_t last_t;
    static int have_last;

    if (n >= ENC_FW_SNAPSHOTS) {      /* done recording: only acknowledge it */
        enc_qei_drv_events_clear(&dev, 0u, SNAP_READY);
        return;
    }
    fix = cycles() - c0;
    for (unsigned k = 0; k < dev.channels; k++) {
        qei_vel_snap_t s;
        if (read_channel(k, &s) != ENC_QEI_DRV_OK)
            drv_errors++;
        if (k == 0u)
            t0 = s.time;
        else if (s.time != t0)
            skewed++;
        rec_pos[n][k] = (int32_t)enc_qei_drv_signed(&dev, s.count);
        rec_vel[n][k] = velocity(k, &s);
        rec_cyc[n][k] = cycles() - c0;
    }
    t = q->glb.GSNAP_TIME;       /* after the channels: each has shown this snapshot */
    if (t != t0)
        torn++;
    if (have_last && (uint32_t)(t - last_t) != period_ticks)
        missed += (uint32_t)(t - last_t) / period_ticks - 1u;
    last_t = t;
    have_last = 1;
    rec_time[n] = t;
    rec_latency[n] = entry - t;
    rec_fix[n] = fix;
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
    uint32_t pending = enc_qei_drv_irq_pending(&dev);
    for (unsigned k = 0; pending != 0u; k++, pending >>= 1) {
        if (!(pending & 1u))
            continue;
        if (k == 0u && (enc_qei_drv_events(&dev, 0u) & dev.irq_en[0] & SNAP_READY))
            snapshot(c0, entry);              /* clears SNAP_READY of every channel */
        (void)enc_qei_drv_events_take(&dev, k);   /* any other enabled event: none here */
    }
}

static int discover(void)
{
    int err = enc_qei_drv_init(&dev, (volatile enc_qei_t *)ENC_QEI_BASE);
    if (err != ENC_QEI_DRV_OK) {
        printf("enc_qei: %s at 0x%08lx (ID 0x%08lx)\n", enc_qei_drv_strerror(err),
               (unsigned long)ENC_QEI_BASE, (unsigned long)dev.id);
        return -1;
    }
    if (!dev.has_timing) {
        printf("enc_qei: CAPS 0x%08lx: this firmware needs the timing unit\n",
               (unsigned long)dev.caps);
        return -1;
    }
    q = dev.regs;
    return 0;
}

static void setup(void)
{
    uint32_t clk = CONFIG_CLOCK_FREQUENCY;
#ifdef ENC_FW_VEL_double
    qei_vel_cfg_t cfg = {0};
    cfg.tick_s = 1.0 / (double)clk;     /* TB_PRESCALE = 0: one tick per clock */
#else
    qei_velfx_cfg_t cfg = {0};
    cfg.tick_hz = clk;                  /* TB_PRESCALE = 0: one tick per clock */
    cfg.frac_bits = ENC_FW_FRAC;
#endif
    cfg.ts_w = dev.ts_w;
    cfg.count_w = dev.count_w;
    cfg.counts_per_edge = 4u;           /* x4 counting, A-rising edges */
    cfg.stall_ticks = clk / 1000u * STALL_MS;
    q->glb.TB_PRESCALE = 0u;
    period_ticks = clk / SNAP_HZ;
    enc_qei_drv_gsnap_config(&dev, 0u, period_ticks);
    for (unsigned k = 0; k < dev.channels; k++) {
        volatile enc_qei_chan_t *ch = &q->chan[k];
        ch->CTRL = ENC_QEI__CTRL__EN_bm | ENC_QEI__CTRL__FUNC__X4_bm |
                   ENC_QEI__CTRL__RANGE__FREE_bm | ENC_QEI__CTRL__FILTER_LEN_SET(3u);
        ch->INDEX_CTRL = ENC_QEI__INDEX_CTRL__ACTION__LATCH_bm |
                         ENC_QEI__INDEX_CTRL__EDGE__RISING_bm | ENC_QEI__INDEX_CTRL__ARM_bm;
        enc_qei_drv_snap_config(&dev, k, ENC_QEI__SNAP_CTRL__EDGE__A_RISING_bm);
        enc_qei_drv_irq_disable(&dev, k, 0xFFFFFFFFu);
        enc_qei_drv_events_clear(&dev, k, 0xFFFFFFFFu);   /* what reset and setup raised */
        ch->QERR_COUNT = 0u;
        ch->GLITCH_COUNT = 0u;
        if (dev.efifo_log2) {
            uint32_t st = ch->STATUS;
            efifo[k].phase = ab_phase(ENC_QEI__STATUS__A_GET(st), ENC_QEI__STATUS__B_GET(st));
            /* a clean start: CLEAR with EN = 1 in the one write (THRESH at its reset value) */
            ch->EFIFO_CTRL = ENC_QEI_EFIFO_CTRL_RESET | ENC_QEI__EFIFO_CTRL__EN_bm |
                             ENC_QEI__EFIFO_CTRL__CLEAR_bm;
            ch->EFIFO_LOST = 0u;
        }
#ifdef ENC_FW_VEL_double
        qei_vel_init(&vel_state[k], &cfg);
#else
        qei_velfx_init(&vel_state[k], &cfg);
#endif
    }
    enc_qei_drv_irq_enable(&dev, 0u, SNAP_READY);   /* one interrupt per global snapshot */
}

/* a velocity record as printed: double x 1000 with 3 decimals, fixed point with F decimals
 * (2^-F = 5^F / 10^F: exact) */
static void print_vel(int64_t v)
{
    uint64_t a = v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v;
#ifdef ENC_FW_VEL_double
    printf(" %s%llu.%03u", v < 0 ? "-" : "", (unsigned long long)(a / 1000u),
           (unsigned)(a % 1000u));
#else
    uint64_t frac = a & ((1u << ENC_FW_FRAC) - 1u);
    for (unsigned i = 0; i < ENC_FW_FRAC; i++)
        frac *= 5u;
    printf(" %s%llu.%0*llu", v < 0 ? "-" : "", (unsigned long long)(a >> ENC_FW_FRAC),
           (int)ENC_FW_FRAC, (unsigned long long)frac);
#endif
}

/* min, mean, max of x[1 .. n-1] (the first record initialises the estimators and warms the
 * caches: left out) */
static void stats(const char *tag, unsigned k, const uint32_t *x, unsigned stride, unsigned n)
{
    uint32_t lo = UINT32_MAX, hi = 0u;
    uint64_t sum = 0u;
    for (unsigned i = 1; i < n; i++) {
        uint32_t c = x[i * stride];
        lo = c < lo ? c : lo;
        hi = c > hi ? c : hi;
        sum += c;
    }
    if (k)
        printf("%s %u %lu %lu %lu\n", tag, k, (unsigned long)lo,
               (unsigned long)(n > 1u ? sum / (n - 1u) : 0u), (unsigned long)hi);
    else
        printf("%s %lu %lu %lu\n", tag, (unsigned long)lo,
               (unsigned long)(n > 1u ? sum / (n - 1u) : 0u), (unsigned long)hi);
}

static void report(void)
{
    static uint32_t own[ENC_FW_SNAPSHOTS];
    unsigned n = n_rec, channels = dev.channels;
    printf("\n  snap   gsnap_time  lat   cyc");
    for (unsigned k = 0; k < channels; k++)
        printf(" | pos%u vel%u", k, k);
    printf("\n");
    for (unsigned i = 0; i < n; i++) {
        printf("S %4u %11lu %4lu %5lu", i, (unsigned long)rec_time[i],
               (unsigned long)rec_latency[i], (unsigned long)rec_cyc[i][channels - 1u]);
        for (unsigned k = 0; k < channels; k++) {
            printf(" | %ld", (long)rec_pos[i][k]);
            print_vel(rec_vel[i][k]);
        }
        printf("\n");
    }
    for (unsigned k = 0; k < channels; k++)
        stats("C", k + 1u, &rec_cyc[0][k], ENC_QEI_CHANNELS_MAX, n);
    stats("F", 0u, rec_fix, 1u, n);
    for (unsigned k = 0; k < channels; k++) {
        for (unsigned i = 0; i < n; i++)
            own[i] = rec_cyc[i][k] - (k ? rec_cyc[i][k - 1u] : rec_fix[i]);
        stats("D", k + 1u, own, 1u, n);
    }
    for (unsigned k = 0; k < channels; k++) {
        volatile enc_qei_chan_t *ch = &q->chan[k];
        int64_t pos = 0;
        if (enc_qei_drv_read_position(&dev, k, &pos) != ENC_QEI_DRV_OK)
            drv_errors++;
        printf("X %u %ld %ld %lu %lu\n", k, (long)pos,
               (long)enc_qei_drv_signed(&dev, ch->INDEX_LATCH_LO),
               (unsigned long)ch->QERR_COUNT, (unsigned long)ch->GLITCH_COUNT);
    }
    printf("M %u %u %u %u\n", missed, torn, skewed, drv_errors);
    for (unsigned k = 0; dev.efifo_log2 && k < channels; k++) {
        const struct efifo_stat *f = &efifo[k];
        printf("E %u %lu %ld %lu %lu %lu %lu %lu %lu %lu %lu %lu %lu\n", k, (unsigned long)f->n,
               (long)f->net, (unsigned long)f->dir_changes, (unsigned long)f->idx,
               (unsigned long)f->lost, (unsigned long)f->nonmono, (unsigned long)f->ab_bad,
               (unsigned long)f->t_first, (unsigned long)f->t_last, (unsigned long)f->sum_t,
               (unsigned long)q->chan[k].EFIFO_LOST, (unsigned long)f->cycles);
    }
}

/* One global snapshot by command, after the timer stopped: the G line. */
static void command_snapshot(void)
{
    qei_vel_snap_t s[ENC_QEI_CHANNELS_MAX];
    uint32_t t = 0u;
    int err = enc_qei_drv_gsnap_take(&dev, &t, s, 0u);
    printf("G %d %lu", err, (unsigned long)t);
    for (unsigned k = 0; k < dev.channels; k++)
        printf(" %ld", (long)enc_qei_drv_signed(&dev, s[k].count));
    printf("\n");
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
#ifdef ENC_FW_VEL_double
        const char *vel = "double";
#else
        const char *vel = "fx";
#endif
        printf("BUILD %u %u %u %u %lu %lu %u %lu %s", dev.channels, dev.profile, dev.count_w,
               dev.ts_w, (unsigned long)CONFIG_CLOCK_FREQUENCY, (unsigned long)period_ticks,
               dev.efifo_log2, (unsigned long)ENC_QEI__CAPS__ENGINE_GET(dev.caps), vel);
#ifndef ENC_FW_VEL_double
        printf("%u", ENC_FW_FRAC);
#endif
        printf("\n");
        irq_attach(ENC_QEI_INTERRUPT, qei_isr);
        enc_qei_ev_enable_write(1);
        irq_setmask(irq_getmask() | (1u << ENC_QEI_INTERRUPT));
        irq_setie(1);
        enc_qei_drv_gsnap_config(&dev, ENC_QEI__GSNAP_CTRL__PERIOD_EN_bm, period_ticks);
        while (n_rec < ENC_FW_SNAPSHOTS)
            for (unsigned k = 0; dev.efifo_log2 && k < dev.channels; k++)
                drain(k);
        enc_qei_drv_gsnap_config(&dev, 0u, period_ticks);
        irq_setmask(irq_getmask() & ~(1u << ENC_QEI_INTERRUPT));
        if (dev.efifo_log2) {
            unsigned popped;
            for (unsigned k = 0; k < dev.channels; k++)
                q->chan[k].EFIFO_CTRL = ENC_QEI_EFIFO_CTRL_RESET;   /* EN = 0: no more entries */
            do {                    /* until a whole pass finds every FIFO empty */
                popped = 0u;
                for (unsigned k = 0; k < dev.channels; k++)
                    popped += drain(k);
            } while (popped);
        }
        command_snapshot();
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
