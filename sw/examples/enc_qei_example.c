/* SPDX-License-Identifier: Apache-2.0 */
/*
 * enc_qei_example.c -- configure enc_qei for x4 counting, read the position coherently, home on
 * the first index pulse with the index interrupt, read the error counters. C99; uses only the
 * names of the generated sw/enc_qei_regs.h. See enc_qei_example.h and doc/enc_qei.md.
 *
 * Build: gcc -std=c99 -Wall -Wextra -Werror -I sw -I sw/examples -c sw/examples/enc_qei_example.c
 */
#include "enc_qei_example.h"

uint32_t enc_qei_ctrl_word(uint32_t func, uint32_t range, uint32_t filter_len)
{
    return ENC_QEI__CTRL__EN_bm |
           ENC_QEI__CTRL__FUNC_SET(func) |
           ENC_QEI__CTRL__RANGE_SET(range) |
           ENC_QEI__CTRL__FILTER_LEN_SET(filter_len);
}

void enc_qei_setup_x4(volatile enc_qei_chan_t *q, uint32_t filter_len, uint32_t range, uint64_t ceiling)
{
    /* CEILING first, so the range never sees a stale bound */
    q->CEILING_HI = (uint32_t)(ceiling >> 32);
    q->CEILING_LO = (uint32_t)ceiling;
    /* a FUNC change re-references the decoder at the present state: nothing is counted for it */
    q->CTRL = enc_qei_ctrl_word(ENC_QEI__CTRL__FUNC__X4_VAL, range, filter_len);
    enc_qei_write_count(q, 0u);
    /* clear whatever is pending: write 1 to clear, every bit (bits without an event ignore it) */
    q->EVENTS = 0xFFFFFFFFu;
    /* any write clears the saturating error counters */
    q->QERR_COUNT = 0u;
    q->GLITCH_COUNT = 0u;
}

unsigned enc_qei_count_width(volatile enc_qei_t *q)
{
    return (unsigned)ENC_QEI__CAPS__COUNT_W_GET(q->glb.CAPS);
}

uint64_t enc_qei_combine64(uint32_t lo, uint32_t hi)
{
    return ((uint64_t)hi << 32) | (uint64_t)lo;
}

int64_t enc_qei_to_signed(uint64_t count, unsigned count_w)
{
    uint64_t sign, mask;
    if (count_w == 0u)
        return 0;
    if (count_w >= 64u)
        return (int64_t)count; /* two's complement on every C99 target with int64_t */
    mask = ((uint64_t)1 << count_w) - 1u;
    sign = (uint64_t)1 << (count_w - 1u);
    count &= mask;
    if (count & sign)
        return -(int64_t)(((~count) & mask) + 1u);
    return (int64_t)count;
}

uint64_t enc_qei_read_count(volatile enc_qei_chan_t *q)
{
    /* Two separate volatile accesses, in this order: reading COUNT_LO latches the high word of
     * the same count into COUNT_HI. (COUNT_HI reads 0 when COUNT_W <= 32.) */
    uint32_t lo = q->COUNT_LO;
    uint32_t hi = q->COUNT_HI;
    return enc_qei_combine64(lo, hi);
}

void enc_qei_write_count(volatile enc_qei_chan_t *q, uint64_t value)
{
    q->COUNT_HI = (uint32_t)(value >> 32); /* staged */
    q->COUNT_LO = (uint32_t)value;         /* loads {staged HI, LO}, clears STATUS.STOPPED */
}

void enc_qei_compare_at(volatile enc_qei_chan_t *q, uint64_t value)
{
    q->COMPARE_HI = (uint32_t)(value >> 32);
    q->COMPARE_LO = (uint32_t)value;
    q->EVENTS = ENC_QEI__EVENTS__CMP_bm;
    q->IRQ_EN = q->IRQ_EN | ENC_QEI__EVENTS__CMP_bm;
    /* last: compare on, COMPARE already in place (turning it on while the count equals COMPARE
     * raises nothing) */
    q->CTRL = ENC_QEI__CTRL__CMP_EN_UPDATE(q->CTRL, 1u);
}

/* pending INDEX cleared, INDEX enabled onto irq (other enables kept) */
static void enable_index_irq(volatile enc_qei_chan_t *q)
{
    q->EVENTS = ENC_QEI__EVENTS__INDEX_bm;
    q->IRQ_EN = q->IRQ_EN | ENC_QEI__EVENTS__INDEX_bm; /* IRQ_EN bit n enables EVENTS bit n */
}

void enc_qei_home_preset(volatile enc_qei_chan_t *q, uint64_t home_value, int gate_ab)
{
    uint32_t ic;
    q->PRESET_HI = (uint32_t)(home_value >> 32);
    q->PRESET_LO = (uint32_t)home_value;
    ic = ENC_QEI__INDEX_CTRL__ACTION__PRESET_bm |
         ENC_QEI__INDEX_CTRL__ONESHOT_bm |
         ENC_QEI__INDEX_CTRL__EDGE__RISING_bm |
         ENC_QEI__INDEX_CTRL__ARM_bm;
    if (gate_ab >= 0) {
        /* act only while (A, B) is this state inside the index pulse: the same shaft position
         * forward and backward */
        ic |= ENC_QEI__INDEX_CTRL__GATE_EN_bm |
              ENC_QEI__INDEX_CTRL__GATE_A_SET(((unsigned)gate_ab >> 1) & 1u) |
              ENC_QEI__INDEX_CTRL__GATE_B_SET((unsigned)gate_ab & 1u);
    }
    enable_index_irq(q);
    q->INDEX_CTRL = ic; /* armed from here on */
}

void enc_qei_home_latch(volatile enc_qei_chan_t *q)
{
    enable_index_irq(q);
    q->INDEX_CTRL = ENC_QEI__INDEX_CTRL__ACTION__LATCH_bm |
                    ENC_QEI__INDEX_CTRL__ONESHOT_bm |
                    ENC_QEI__INDEX_CTRL__ARM_bm;
}

int enc_qei_index_irq(volatile enc_qei_chan_t *q)
{
    uint32_t pending = q->EVENTS & q->IRQ_EN;
    if (!(pending & ENC_QEI__EVENTS__INDEX_bm))
        return 0;
    /* write 1 to clear this bit only; never write back what was read (that clears them all) */
    q->EVENTS = ENC_QEI__EVENTS__INDEX_bm;
    /* EVENTS.INDEX is raised by every qualified index, armed or not: homing is done when the
     * one-shot has disarmed (hardware cleared ARM) */
    if ((q->INDEX_CTRL & ENC_QEI__INDEX_CTRL__ARM_bm) == 0u) {
        q->IRQ_EN = q->IRQ_EN & ~(uint32_t)ENC_QEI__EVENTS__INDEX_bm;
        return 1;
    }
    return 0;
}

/* (meaningful with RANGE = free, less than 2^(COUNT_W-1) counts from the index) */
int64_t enc_qei_position_from_latch(volatile enc_qei_chan_t *q, unsigned count_w)
{
    uint64_t latch = enc_qei_combine64(q->INDEX_LATCH_LO, q->INDEX_LATCH_HI);
    uint64_t count = enc_qei_read_count(q);
    return enc_qei_to_signed(count - latch, count_w);
}

int enc_qei_read_errors(volatile enc_qei_chan_t *q, uint32_t *qerr, uint32_t *glitch, int clear)
{
    *qerr = ENC_QEI__QERR_COUNT__VALUE_GET(q->QERR_COUNT);
    *glitch = ENC_QEI__GLITCH_COUNT__VALUE_GET(q->GLITCH_COUNT);
    if (clear) {
        /* an error between the read and this write is not counted (EVENTS.QERR / GLITCH still
         * show it) */
        q->QERR_COUNT = 0u;
        q->GLITCH_COUNT = 0u;
    }
    return (*qerr != 0u) || (*glitch != 0u);
}
