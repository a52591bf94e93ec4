/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_calib.c -- see enc_qei_calib.h. Mirrors python/src/hedsmodel/calibration.py. */
#include "enc_qei_calib.h"

#include <math.h>
#include <string.h>

static const uint8_t QUAD_A[4] = {0u, 1u, 1u, 0u};

static int64_t mod_s(int64_t x, int64_t s)
{
    int64_t r = x % s;
    return r < 0 ? r + s : r;
}

static int quad_index(unsigned a, unsigned b)
{
    return a ? (b ? 2 : 1) : (b ? 3 : 0);
}

static uint64_t unwrap(qei_cal_t *st, uint32_t raw)
{
    raw &= st->mask;
    if (!st->started) {
        st->started = 1;
        st->t = raw;
    } else {
        st->t += (uint64_t)((uint32_t)(raw - st->t_raw) & st->mask);
    }
    st->t_raw = raw;
    return st->t;
}

int qei_cal_calibrated(const qei_cal_t *st)
{
    return st->valid && st->phase_ok;
}

static double angle_diff(const qei_cal_t *st, int64_t b2, int64_t b1)
{
    int64_t j2, j1, q;
    if (!qei_cal_calibrated(st))
        return (double)(b2 - b1);
    j2 = mod_s(b2 - st->ref, st->S);
    j1 = mod_s(b1 - st->ref, st->S);
    q = ((b2 - st->ref - j2) - (b1 - st->ref - j1)) / st->S;
    return (double)(q * st->S) + (st->table[j2] - st->table[j1]);
}

static void drop_table(qei_cal_t *st)
{
    int64_t j;
    for (j = 0; j < st->S; j++)
        st->table[j] = 0.0;
    st->valid = 0;
    st->acc_revs = 0;
    st->bad = 0;
}

static void abort_rev(qei_cal_t *st)
{
    st->rev_dir = 0;
    st->t_prev = 0;
}

static double check(const qei_cal_t *st)
{
    const int64_t S = st->S;
    const double *w = st->work, *tb = st->table;
    double total = 0.0;
    int64_t c;
    for (c = 0; c < S; c += 4) {
        double diff[4], mean;
        int k;
        for (k = 0; k < 4; k++) {
            int64_t j = c + k;
            double hi_w = j + 1 < S ? w[j + 1] : (double)S;
            double hi_t = j + 1 < S ? tb[j + 1] : (double)S;
            diff[k] = (hi_w - w[j]) - (hi_t - tb[j]);
        }
        mean = (diff[0] + diff[1] + diff[2] + diff[3]) / 4.0;
        for (k = 0; k < 4; k++) {
            double e = diff[k] - mean;
            total += e * e;
        }
    }
    return sqrt(total / (double)S);
}

static void fit(qei_cal_t *st, uint64_t T, int d)
{
    const int64_t S = st->S;
    const double Sd = (double)S, Tr = (double)T, Tp = (double)st->t_prev;
    const double acc = 2.0 * Sd * (Tp - Tr) / (Tr * Tp * (Tr + Tp));
    double *w = st->work;
    int64_t j;
    for (j = 1; j < S; j++) {
        double tau = w[j];
        double u = Sd * tau / Tr + 0.5 * acc * tau * (tau - Tr);
        w[j] = d > 0 ? u : Sd - u;
    }
    w[0] = 0.0;
    if (!st->valid) {
        for (j = 1; j < S; j++)
            st->table[j] += w[j];
        st->acc_revs++;
        if (st->acc_revs >= st->cfg.learn_revs) {
            double k = (double)st->acc_revs;
            for (j = 1; j < S; j++)
                st->table[j] = st->table[j] / k;
            st->table[0] = 0.0;
            st->valid = 1;
            st->n_learned++;
        }
        return;
    }
    st->last_check = check(st);
    st->bad = st->last_check > st->cfg.change_threshold ? st->bad + 1u : 0u;
    if (st->bad >= st->cfg.change_revs) {
        st->n_changes++;
        drop_table(st);
    }
}

static void learn(qei_cal_t *st, int64_t b, int d, uint64_t t)
{
    const int64_t S = st->S;
    int64_t slot = mod_s(b - st->ref, S);
    if (st->rev_dir != 0) {
        if (d != st->rev_dir || slot != st->rev_next) {
            abort_rev(st);
        } else if (slot == 0) {
            uint64_t T = t - st->rev_t0;
            if (st->t_prev > 0u && T > 0u)
                fit(st, T, d);
            st->t_prev = T;
            st->rev_t0 = t;
            st->rev_next = d > 0 ? 1 : S - 1;
            return;
        } else {
            st->work[slot] = (double)(t - st->rev_t0);
            st->rev_next = mod_s(slot + d, S);
            return;
        }
    }
    if (slot == 0) {
        st->rev_dir = d;
        st->rev_t0 = t;
        st->rev_next = d > 0 ? 1 : S - 1;
    }
}

static void index_step(qei_cal_t *st, int d)
{
    const int64_t S = st->S;
    const int k = d > 0 ? 1 : 0;
    if (st->idx_state[0] < 0 && st->idx_state[1] < 0) {
        st->ref = st->pos;
        st->idx_state[k] = 0;
        st->phase_ok = 1;
        abort_rev(st);
        return;
    }
    if (st->idx_state[k] < 0) {
        if (st->phase_ok)
            st->idx_state[k] = mod_s(st->pos - st->ref, S);
        return;
    }
    if (!st->phase_ok) {
        st->ref = st->pos - st->idx_state[k];
        st->phase_ok = 1;
        return;
    }
    if (mod_s(st->pos - st->ref, S) != st->idx_state[k]) {
        st->n_reindex++;
        st->ref = st->pos - st->idx_state[k];
        drop_table(st);
        abort_rev(st);
    }
}

int qei_cal_init(qei_cal_t *st, const qei_cal_cfg_t *cfg, double *buf, size_t buf_len)
{
    memset(st, 0, sizeof *st);
    if (!(cfg->tick_s > 0.0) || cfg->ts_w < 1u || cfg->ts_w > 32u || cfg->cycles < 1u ||
        cfg->cycles > (1ul << 20) || cfg->learn_revs < 1u || cfg->change_revs < 1u ||
        !(cfg->change_threshold > 0.0) || buf == NULL || buf_len < QEI_CAL_BUF_LEN(cfg->cycles))
        return -1;
    st->cfg = *cfg;
    st->S = 4 * (int64_t)cfg->cycles;
    st->table = buf;
    st->work = buf + st->S;
    memset(buf, 0, (size_t)(2 * st->S) * sizeof *buf);
    st->mask = cfg->ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)((1ul << cfg->ts_w) - 1ul);
    st->idx_state[0] = st->idx_state[1] = -1;
    st->m[0].cpe = 4u;
    st->m[1].cpe = 1u;
    return 0;
}

void qei_cal_push(qei_cal_t *st, const qei_cal_entry_t *e)
{
    const uint64_t t = unwrap(st, e->time);
    const int d = e->up ? 1 : -1;
    int64_t b;
    int s, a_before, reversal, i;
    st->pos += d;
    b = d > 0 ? st->pos : st->pos + 1;
    s = quad_index(e->a, e->b);
    a_before = QUAD_A[(s - d + 4) % 4];
    reversal = st->dir != 0 && d != st->dir;
    st->dir = d;
    if (e->lost) {
        st->n_lost++;
        abort_rev(st);
        if (st->cfg.use_index) {
            st->phase_ok = 0;
        } else {
            drop_table(st);
            st->ref = b;
            st->phase_ok = 1;
        }
    } else if (reversal) {
        abort_rev(st);
    }
    if (!st->cfg.use_index && !st->phase_ok && !e->lost) {
        st->ref = b;
        st->phase_ok = 1;
    }
    if (st->cfg.use_index && e->idx)
        index_step(st, d);
    if (st->phase_ok)
        learn(st, b, d, t);
    for (i = 0; i < 2; i++) {
        qei_cal_method_t *m = &st->m[i];
        int sel = i == 1 || (a_before == 0 && e->a == 1);
        if (e->lost || reversal) {
            m->has_ref = 0;
            m->mag = 0.0;
            m->dir = d;
        }
        if (sel) {
            m->has_last = 1;
            m->last_b = b;
            m->last_t = t;
            m->new_edge = 1;
            if (!m->has_ref) {
                m->has_ref = 1;
                m->ref_b = b;
                m->ref_t = t;
                m->dir = d;
            }
        }
    }
}

qei_cal_reading_t qei_cal_read(qei_cal_t *st, uint32_t time)
{
    const uint64_t t = unwrap(st, time);
    const double tick = st->cfg.tick_s;
    double out[2] = {0.0, 0.0};
    qei_cal_reading_t r;
    int i;
    for (i = 0; i < 2; i++) {
        qei_cal_method_t *m = &st->m[i];
        uint64_t since;
        double mag;
        if (!m->has_last)
            continue;
        if (m->new_edge && m->has_ref && m->last_t != m->ref_t) {
            double dang = angle_diff(st, m->last_b, m->ref_b);
            m->mag = fabs(dang) / ((double)(m->last_t - m->ref_t) * tick);
        }
        since = t - m->last_t;
        mag = m->mag;
        if (st->cfg.stall_ticks > 0u && since >= st->cfg.stall_ticks) {
            mag = 0.0;
        } else if (!m->new_edge && since > 0u) {
            double ext = fabs(angle_diff(st, m->last_b + (int64_t)m->cpe * m->dir, m->last_b));
            double bound = ext / ((double)since * tick);
            if (bound < mag)
                mag = bound;
        }
        out[i] = (double)m->dir * mag;
        if (m->new_edge) {
            m->ref_b = m->last_b;
            m->ref_t = m->last_t;
            m->has_ref = 1;
            m->new_edge = 0;
        }
    }
    r.mt_a = out[0];
    r.any = out[1];
    r.calibrated = qei_cal_calibrated(st);
    return r;
}
