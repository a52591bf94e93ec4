/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_calib.c -- see enc_qei_calib.h. Mirrors python/src/hedsmodel/calibration.py, whose
 * docstring is the specification. */
#include "enc_qei_calib.h"

#include <math.h>
#include <string.h>

#define EDGE_LIMIT 0.35      /* edge check: rejected at this fraction of worse votes */
#define EDGE_MIN_TICKS 4.0   /* a vote counts when the table moves e by this many ticks */
#define EDGE_SEEN 3.0        /* a vote is cast when a residual is within this x the table's effect */
#define JOLT_COUNTS 0.5      /* a jolt: e_cal at the fine spacing beyond this, counts */

static const double EDGE_W[2] = {32.0, 4.0};  /* votes averaged, fine and coarse spacing */
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
    return st->valid && st->phase_ok && !st->pending && st->rev_ok && st->edge_ok;
}

/* angle(b2) - angle(b1) with the table, counts */
static double cal_diff(const qei_cal_t *st, int64_t b2, int64_t b1)
{
    int64_t j2 = mod_s(b2 - st->ref, st->S);
    int64_t j1 = mod_s(b1 - st->ref, st->S);
    int64_t q = ((b2 - st->ref - j2) - (b1 - st->ref - j1)) / st->S;
    return (double)(q * st->S) + (st->table[j2] - st->table[j1]);
}

/* angle(b2) - angle(b1) as the readings use it */
static double angle_diff(const qei_cal_t *st, int64_t b2, int64_t b1)
{
    return qei_cal_calibrated(st) ? cal_diff(st, b2, b1) : (double)(b2 - b1);
}

static void edge_reset(qei_cal_t *st, double frac)
{
    st->ea_n[0] = st->ea_n[1] = 0;
    st->ea_k = 0;
    st->frac[0] = st->frac[1] = frac;
    st->edge_ok = frac < EDGE_LIMIT;
}

/* r, or r + 1 when the boundary at r is a B edge (boundary 0 is always an A edge) */
static int64_t a_edge(const qei_cal_t *st, int64_t r)
{
    return r + mod_s((int64_t)st->ab + r - st->pos + 1, 2);
}

static void set_ref(qei_cal_t *st, int64_t r)
{
    st->ref = r;
    st->a_par = (int)mod_s((int64_t)st->ab + r - st->pos + 1, 2);
    edge_reset(st, 0.0);
}

static void drop_table(qei_cal_t *st)
{
    int64_t j;
    for (j = 0; j < st->S; j++)
        st->table[j] = 0.0;
    st->valid = 0;
    st->cand_n = 0;
}

static void abort_rev(qei_cal_t *st)
{
    st->rev_dir = 0;
    st->t_prev = 0;
    st->t_prev2 = 0;
}

/* does the revolution in work agree with ref / scale (the three figures)? */
static int agrees(qei_cal_t *st, const double *ref, double scale)
{
    const int64_t S = st->S, N = st->S / 4;
    const double *w = st->work;
    const double xm = 0.5 * (double)(N - 1);
    double sm = 0.0, smm = 0.0, sxm = 0.0, sxx = 0.0, e2 = 0.0, r2, sh = 0.0, shh = 0.0, l2;
    int64_t c, j, n = 0;
    for (c = 0; c < N; c++) {
        double d0, d1, d2, d3, m, x;
        j = 4 * c;
        d0 = w[j] - ref[j] / scale;
        d1 = w[j + 1] - ref[j + 1] / scale;
        d2 = w[j + 2] - ref[j + 2] / scale;
        d3 = w[j + 3] - ref[j + 3] / scale;
        m = (d0 + d1 + d2 + d3) / 4.0;
        e2 += (d0 - m) * (d0 - m) + (d1 - m) * (d1 - m) + (d2 - m) * (d2 - m) +
              (d3 - m) * (d3 - m);
        x = (double)c - xm;
        sm += m;
        smm += m * m;
        sxm += x * m;
        sxx += x * x;
    }
    r2 = smm - sm * sm / (double)N - sxm * sxm / sxx;
    st->last_shape = sqrt((r2 > 0.0 ? r2 : 0.0) / (double)N);
    st->last_edge = sqrt(e2 / (double)S);
    for (j = 4 + st->a_par; j < S; j += 2) {
        double h = (w[j] - ref[j] / scale) - (w[j - 4] - ref[j - 4] / scale);
        sh += h;
        shh += h * h;
        n++;
    }
    l2 = shh - sh * sh / (double)n;
    st->last_line = sqrt((l2 > 0.0 ? l2 : 0.0) / (double)n);
    return st->last_shape <= st->cfg.shape_tol && st->last_line <= st->cfg.line_tol &&
           st->last_edge <= st->cfg.edge_tol;
}

/* revolution of period T complete (work[j]: ticks from its start to boundary j) */
static void revolution(qei_cal_t *st, uint64_t T, int d)
{
    const int64_t S = st->S;
    const double Sd = (double)S, T1 = (double)st->t_prev2, T2 = (double)st->t_prev,
                 T3 = (double)T;
    const double acc = 2.0 * Sd * (T2 - T3) / (T3 * T2 * (T3 + T2));
    double *w = st->work, g1, g2;
    int64_t j;
    for (j = 1; j < S; j++) {
        double tau = w[j];
        double u = Sd * tau / T3 + 0.5 * acc * tau * (tau - T3);
        w[j] = d > 0 ? u : Sd - u;
    }
    w[0] = 0.0;
    g1 = (1.0 / T2 - 1.0 / T1) / (T1 + T2);
    g2 = (1.0 / T3 - 1.0 / T2) / (T2 + T3);
    st->last_motion = fabs(g2 - g1) * (T2 + T3) * T2;
    if (!(st->last_motion <= st->cfg.motion_tol)) {
        st->n.unclean++;
        return;
    }
    if (st->valid) {
        if (agrees(st, st->table, 1.0)) {
            st->rev_ok = 1;
            st->cand_n = 0;
            return;
        }
        st->rev_ok = 0;
        st->n.disagree++;
    }
    if (st->cand_n > 0u && !agrees(st, st->acc, (double)st->cand_n)) {
        st->n.rejected++;
        st->cand_n = 0;
    }
    if (st->cand_n == 0u) {
        for (j = 0; j < S; j++)
            st->acc[j] = w[j];
    } else {
        for (j = 0; j < S; j++)
            st->acc[j] += w[j];
    }
    st->cand_n++;
    if (st->cand_n >= st->cfg.learn_revs) {
        double k = (double)st->cand_n;
        for (j = 0; j < S; j++)
            st->table[j] = st->acc[j] / k;
        if (st->valid)
            st->n.changes++;
        else
            st->n.learned++;
        st->valid = 1;
        st->rev_ok = 1;
        st->cand_n = 0;
        edge_reset(st, 0.0);
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
            if (st->t_prev > 0u && st->t_prev2 > 0u && T > 0u)
                revolution(st, T, d);
            st->t_prev2 = st->t_prev;
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

/* edge (b, t) less the constant-acceleration extrapolation through the history, raw and with
 * the table, counts; 0 when the four times do not strictly increase */
static int residuals(const qei_cal_t *st, const int64_t *hb, const uint64_t *ht, int64_t b,
                     uint64_t t, double *e_raw, double *e_cal)
{
    const double tau1 = (double)(ht[1] - ht[0]), tau2 = (double)(ht[2] - ht[0]),
                 tau3 = (double)(t - ht[0]);
    double l1, l2;
    if (!(0.0 < tau1 && tau1 < tau2 && tau2 < tau3))
        return 0;
    l1 = tau3 * (tau3 - tau2) / (tau1 * (tau1 - tau2));
    l2 = tau3 * (tau3 - tau1) / (tau2 * (tau2 - tau1));
    *e_raw = (double)(b - hb[0]) - ((double)(hb[1] - hb[0]) * l1 + (double)(hb[2] - hb[0]) * l2);
    *e_cal = cal_diff(st, b, hb[0]) -
             (cal_diff(st, hb[1], hb[0]) * l1 + cal_diff(st, hb[2], hb[0]) * l2);
    return 1;
}

/* one A-rising edge while there is a table and a phase */
static void edge_check(qei_cal_t *st, int64_t b, uint64_t t)
{
    int k, ok;
    st->ea_k++;
    for (k = 0; k < 2; k++) {
        int64_t *hb = st->ea_b[k];
        uint64_t *ht = st->ea_t[k];
        double e_raw = 0.0, e_cal = 0.0;
        int n = st->ea_n[k];
        if (k == 1) {
            if (st->ea_k < st->coarse)
                break;
            st->ea_k = 0;
        }
        if (n < 3) {
            hb[n] = b;
            ht[n] = t;
            st->ea_n[k] = n + 1;
            continue;
        }
        ok = residuals(st, hb, ht, b, t, &e_raw, &e_cal);
        if (ok && k == 0 && fabs(e_cal) > JOLT_COUNTS) {
            st->n.jolts++;
            if (st->edge_ok)
                st->n.edge_alarms++;
            edge_reset(st, 1.0);
            st->ea_b[0][0] = b;
            st->ea_t[0][0] = t;
            st->ea_n[0] = 1;
            return;
        }
        if (ok) {
            double eff = fabs(e_raw - e_cal);
            double ar = fabs(e_raw), ac = fabs(e_cal);
            if (eff < EDGE_MIN_TICKS * fabs((double)(b - hb[0])) / (double)(t - ht[0])) {
                st->frac[k] -= st->frac[k] / EDGE_W[k];
            } else if ((ar < ac ? ar : ac) <= EDGE_SEEN * eff) {
                double vote = e_cal * e_cal > e_raw * e_raw ? 1.0 : 0.0;
                st->frac[k] += (vote - st->frac[k]) / EDGE_W[k];
            }
        }
        hb[0] = hb[1];
        hb[1] = hb[2];
        hb[2] = b;
        ht[0] = ht[1];
        ht[1] = ht[2];
        ht[2] = t;
    }
    ok = st->frac[0] < EDGE_LIMIT && st->frac[1] < EDGE_LIMIT;
    if (st->edge_ok && !ok)
        st->n.edge_alarms++;
    st->edge_ok = ok;
}

/* a LOST or missed entry at boundary b */
static void lose(qei_cal_t *st, int64_t b)
{
    abort_rev(st);
    st->cand_n = 0;
    st->ea_n[0] = st->ea_n[1] = 0;
    st->pending = 0;
    if (st->cfg.use_index) {
        st->phase_ok = 0;
    } else {
        drop_table(st);
        set_ref(st, a_edge(st, b));
        st->phase_ok = 1;
    }
}

static void index_step(qei_cal_t *st, int d)
{
    const int64_t S = st->S;
    const int k = d > 0 ? 1 : 0;
    int64_t f;
    if (!st->framed) {
        st->framed = 1;
        set_ref(st, a_edge(st, st->pos));
        st->idx_off[k] = mod_s(st->pos - st->ref, S);
        st->phase_ok = 1;
        abort_rev(st);
        return;
    }
    if (st->idx_off[k] < 0) {
        if (st->phase_ok && !st->pending) {
            int64_t j = mod_s(st->pos - st->ref, S);
            if (st->idx_cand[k] == j)
                st->idx_off[k] = j;
            else
                st->idx_cand[k] = j;
        }
        return;
    }
    f = st->pos - st->idx_off[k];
    if (!st->phase_ok) {
        set_ref(st, f);
        st->phase_ok = 1;
        st->pending = 0;
        return;
    }
    if (mod_s(f - st->ref, S) == 0) {
        st->pending = 0;
        return;
    }
    if (st->pending && mod_s(f - st->alt_ref, S) == 0) {
        st->n.reindex++;
        set_ref(st, f);
        st->pending = 0;
        st->rev_ok = 1;
        st->cand_n = 0;
        st->idx_off[1 - k] = -1;
        st->idx_cand[0] = st->idx_cand[1] = -1;
        abort_rev(st);
        return;
    }
    st->n.suspect++;
    st->pending = 1;
    st->alt_ref = f;
}

int qei_cal_init(qei_cal_t *st, const qei_cal_cfg_t *cfg, double *buf, size_t buf_len)
{
    memset(st, 0, sizeof *st);
    if (!(cfg->tick_s > 0.0) || cfg->ts_w < 1u || cfg->ts_w > 32u || cfg->cycles < 2u ||
        cfg->cycles > (1ul << 20) || cfg->learn_revs < 1u || !(cfg->motion_tol > 0.0) ||
        !(cfg->shape_tol > 0.0) || !(cfg->line_tol > 0.0) || !(cfg->edge_tol > 0.0) ||
        buf == NULL || buf_len < QEI_CAL_BUF_LEN(cfg->cycles))
        return -1;
    st->cfg = *cfg;
    st->S = 4 * (int64_t)cfg->cycles;
    st->table = buf;
    st->acc = buf + st->S;
    st->work = buf + 2 * st->S;
    memset(buf, 0, (size_t)(3 * st->S) * sizeof *buf);
    st->mask = cfg->ts_w >= 32u ? 0xFFFFFFFFu : (uint32_t)((1ul << cfg->ts_w) - 1ul);
    st->ab = -1;
    st->edge_ok = 1;
    st->idx_off[0] = st->idx_off[1] = -1;
    st->idx_cand[0] = st->idx_cand[1] = -1;
    st->coarse = cfg->cycles / 8u > 1u ? cfg->cycles / 8u : 1u;
    st->m[0].cpe = 4u;
    st->m[1].cpe = 1u;
    return 0;
}

void qei_cal_push(qei_cal_t *st, const qei_cal_entry_t *e)
{
    const uint64_t t = unwrap(st, e->time);
    const int d = e->up ? 1 : -1;
    int64_t b;
    int s, a_before, missed, reversal, broken, a_rise, i;
    st->pos += d;
    b = d > 0 ? st->pos : st->pos + 1;
    s = quad_index(e->a, e->b);
    a_before = QUAD_A[(s - d + 4) % 4];
    missed = st->ab >= 0 && !e->lost && s != (st->ab + d + 4) % 4;
    st->ab = s;
    reversal = st->dir != 0 && d != st->dir;
    st->dir = d;
    broken = e->lost || missed;
    if (broken) {
        if (e->lost)
            st->n.lost++;
        else
            st->n.missed++;
        lose(st, b);
    } else if (reversal) {
        abort_rev(st);
        st->ea_n[0] = st->ea_n[1] = 0;
    }
    if (!st->cfg.use_index && !st->phase_ok) {
        set_ref(st, a_edge(st, b));
        st->phase_ok = 1;
    }
    if (st->cfg.use_index && e->idx)
        index_step(st, d);
    if (st->phase_ok)
        learn(st, b, d, t);
    a_rise = a_before == 0 && e->a == 1;
    if (a_rise && st->valid && st->phase_ok)
        edge_check(st, b, t);
    for (i = 0; i < 2; i++) {
        qei_cal_method_t *m = &st->m[i];
        int sel = i == 1 || a_rise;
        if (broken || reversal) {
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
