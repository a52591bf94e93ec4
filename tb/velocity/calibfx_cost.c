/* SPDX-License-Identifier: Apache-2.0 */
/* Bare-metal RV32IM program that runs one entry stream through sw/enc_qei_calib_fx.c (or, built
 * with -DCOST_DOUBLE, sw/enc_qei_calib.c in software floating point) under
 * tools/enctools/velocity/rv32.py, which counts the instructions of every call.
 *
 * Input at IN_ADDR (words, written by the simulator): n_ops, tick_hz, frac_bits, ts_w, cycles,
 * use_index, learn_revs, stall_ticks (low, high), motion_ppm, shape_uc, line_uc, edge_uc, and
 * per op two words: flags (bit 31: a read; else bits 0..4 a, b, up, lost, idx) and the time.
 * Before op k it stores k to MARK, after the last op n_ops; after each push it stores to MARK
 * 0x80000000 | revolution boundaries crossed so far. Output at OUT_ADDR: per read mt_a, any,
 * calibrated (the double version's readings * 2^F, rounded). */
#include <stddef.h>
#include <stdint.h>

#ifdef COST_DOUBLE
#include "enc_qei_calib.h"
#else
#include "enc_qei_calib_fx.h"
#endif

#define MARK (*(volatile uint32_t *)0xF0000000u)
#define EXIT (*(volatile uint32_t *)0xF0000004u)
#define IN_ADDR 0x400000u
#define OUT_ADDR 0x600000u
#define MAX_CYCLES 500u

__asm__(".section .text.start\n"
        ".globl _start\n"
        "_start:\n"
        "  .option push\n"
        "  .option norelax\n"
        "  la gp, __global_pointer$\n"
        "  .option pop\n"
        "  li sp, 0x3FFFF0\n"
        "  call main\n"
        "  li t0, 0xF0000004\n"
        "  sw a0, 0(t0)\n"
        "1: j 1b\n"
        ".text\n");

void *memset(void *d, int c, size_t n)
{
    unsigned char *p = d;
    while (n--)
        *p++ = (unsigned char)c;
    return d;
}

#ifdef COST_DOUBLE
double sqrt(double x)   /* Newton's method: the double version's libm call, in soft float */
{
    double y = x > 1.0 ? x : 1.0;
    int i;
    if (!(x > 0.0))
        return 0.0;
    for (i = 0; i < 60; i++) {
        double z = 0.5 * (y + x / y);
        if (z >= y)
            break;
        y = z;
    }
    return y;
}
static double buf[QEI_CAL_BUF_LEN(MAX_CYCLES)];
static qei_cal_t st;
#else
static int64_t buf[QEI_CALFX_BUF_LEN(MAX_CYCLES)];
static qei_calfx_t st;
#endif

int main(void)
{
    const uint32_t *in = (const uint32_t *)IN_ADDR;
    int32_t *out = (int32_t *)OUT_ADDR;
    uint32_t n_ops = in[0], k, revs = 0;
    const uint32_t *op = in + 13;
    uint64_t rev_t0 = 0;
#ifdef COST_DOUBLE
    qei_cal_cfg_t cfg;
    double scale = 1.0;
    cfg.tick_s = 1.0 / (double)in[1];
    for (k = 0; k < in[2]; k++)
        scale *= 2.0;
    cfg.motion_tol = in[9] * 1e-6;
    cfg.shape_tol = in[10] * 1e-6;
    cfg.line_tol = in[11] * 1e-6;
    cfg.edge_tol = in[12] * 1e-6;
#else
    qei_calfx_cfg_t cfg;
    cfg.tick_hz = in[1];
    cfg.frac_bits = in[2];
    cfg.motion_ppm = in[9];
    cfg.shape_uc = in[10];
    cfg.line_uc = in[11];
    cfg.edge_uc = in[12];
#endif
    cfg.ts_w = in[3];
    cfg.cycles = in[4];
    cfg.use_index = (int)in[5];
    cfg.learn_revs = in[6];
    cfg.stall_ticks = in[7] | ((uint64_t)in[8] << 32);
    if (cfg.cycles > MAX_CYCLES)
        return 2;
#ifdef COST_DOUBLE
    if (qei_cal_init(&st, &cfg, buf, QEI_CAL_BUF_LEN(cfg.cycles)) != 0)
        return 2;
#else
    if (qei_calfx_init(&st, &cfg, buf, QEI_CALFX_BUF_LEN(cfg.cycles)) != 0)
        return 2;
#endif
    for (k = 0; k < n_ops; k++, op += 2) {
        MARK = k;
        if (op[0] >> 31) {
#ifdef COST_DOUBLE
            qei_cal_reading_t r = qei_cal_read(&st, op[1]);
            double a = r.mt_a * scale, n = r.any * scale;
            out[0] = (int32_t)(a < 0 ? a - 0.5 : a + 0.5);
            out[1] = (int32_t)(n < 0 ? n - 0.5 : n + 0.5);
#else
            qei_calfx_reading_t r = qei_calfx_read(&st, op[1]);
            out[0] = r.mt_a;
            out[1] = r.any;
#endif
            out[2] = r.calibrated;
            out += 3;
        } else {
#ifdef COST_DOUBLE
            qei_cal_entry_t e;
#else
            qei_calfx_entry_t e;
#endif
            e.time = op[1];
            e.a = (uint8_t)(op[0] & 1u);
            e.b = (uint8_t)((op[0] >> 1) & 1u);
            e.up = (uint8_t)((op[0] >> 2) & 1u);
            e.lost = (uint8_t)((op[0] >> 3) & 1u);
            e.idx = (uint8_t)((op[0] >> 4) & 1u);
#ifdef COST_DOUBLE
            qei_cal_push(&st, &e);
#else
            qei_calfx_push(&st, &e);
#endif
            if (st.rev_t0 != rev_t0) {
                rev_t0 = st.rev_t0;
                revs++;
            }
            MARK = 0x80000000u | revs;
        }
    }
    MARK = n_ops;
    return 0;
}
