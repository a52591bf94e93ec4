/* SPDX-License-Identifier: Apache-2.0 */
/* enc_qei_calib_fx.c -- see enc_qei_calib_fx.h. sw/enc_qei_calib.c in integers: the same
 * decisions in the same order; angles in 2^-32 counts, vote fractions in 2^-62, and a 192-bit
 * integer (wd_t) where a product or a comparison needs more than 64 bits. */
#include "enc_qei_calib_fx.h"

#include <string.h>

#define ONE32 ((int64_t)1 << 32)        /* one count, 2^-32 counts */
#define FRAC_ONE ((uint64_t)1 << 62)    /* vote fraction 1 */
#define EDGE_LIMIT 1614090106449585664u /* 0.35 (the double constant) * 2^62, exactly */
#define EDGE_MIN_TICKS 4u               /* a vote counts when the table moves e this many ticks */
#define EDGE_SEEN 3u                    /* a vote is cast when a residual is within this x eff */
#define DEV_LIMIT ((int64_t)1 << 40)    /* |deviation from the reference| that disagrees: 256 */
#define TABLE_LIMIT ((int64_t)1 << 61)  /* |table entry|, 2^29 counts */
#define X_LIMIT ((int64_t)1 << 56)      /* |angle| in the edge check's history, 2^24 counts */
#define K2_LIMIT ((uint64_t)1 << 62)    /* |acceleration term| of a clean revolution, 2^30 */
#define MILLION 1000000u

static const unsigned EDGE_W_LOG2[2] = {5u, 2u};  /* votes averaged: 32 fine, 4 coarse */
static const uint8_t QUAD_A[4] = {0u, 1u, 1u, 0u};

/* ----------------------------------------------------------------------- 192-bit integers */
#define WL 6
typedef struct {
    uint32_t v[WL];  /* two's complement, least significant limb first */
} wd_t;

static wd_t wd_u64(uint64_t x)
{
    wd_t r;
    memset(&r, 0, sizeof r);
    r.v[0] = (uint32_t)x;
    r.v[1] = (uint32_t)(x >> 32);
    return r;
}

static wd_t wd_i64(int64_t x)
{
    wd_t r = wd_u64((uint64_t)x);
    int i;
    if (x < 0)
        for (i = 2; i < WL; i++)
            r.v[i] = 0xFFFFFFFFu;
    return r;
}

static int wd_negative(const wd_t *a)
{
    return (int)(a->v[WL - 1] >> 31);
}

static void wd_add(wd_t *a, const wd_t *b)
{
    uint64_t c = 0;
    int i;
    for (i = 0; i < WL; i++) {
        c += (uint64_t)a->v[i] + b->v[i];
        a->v[i] = (uint32_t)c;
        c >>= 32;
    }
}

static void wd_sub(wd_t *a, const wd_t *b)
{
    uint32_t br = 0;
    int i;
    for (i = 0; i < WL; i++) {
        uint64_t d = (uint64_t)a->v[i] - b->v[i] - br;
        a->v[i] = (uint32_t)d;
        br = (uint32_t)(d >> 32) & 1u;
    }
}

static void wd_neg(wd_t *a)
{
    uint64_t c = 1;
    int i;
    for (i = 0; i < WL; i++) {
        c += (uint32_t)~a->v[i];
        a->v[i] = (uint32_t)c;
        c >>= 32;
    }
}

static wd_t wd_abs(wd_t a)
{
    if (wd_negative(&a))
        wd_neg(&a);
    return a;
}

/* unsigned comparison: -1, 0, 1 */
static int wd_ucmp(const wd_t *a, const wd_t *b)
{
    int i;
    for (i = WL - 1; i >= 0; i--)
        if (a->v[i] != b->v[i])
            return a->v[i] < b->v[i] ? -1 : 1;
    return 0;
}

/* a * b modulo 2^192 (the callers keep products within 2^191) */
static wd_t wd_mul(const wd_t *a, const wd_t *b)
{
    wd_t x = wd_abs(*a), y = wd_abs(*b), r;
    int i, j, na = WL, nb = WL;
    memset(&r, 0, sizeof r);
    while (na > 0 && x.v[na - 1] == 0u)
        na--;
    while (nb > 0 && y.v[nb - 1] == 0u)
        nb--;
    for (i = 0; i < na; i++) {
        uint64_t c = 0;
        for (j = 0; j < nb && i + j < WL; j++) {
            c += (uint64_t)x.v[i] * y.v[j] + r.v[i + j];
            r.v[i + j] = (uint32_t)c;
            c >>= 32;
        }
        if (i + j < WL)
            r.v[i + j] = (uint32_t)c;
    }
    if (wd_negative(a) != wd_negative(b))
        wd_neg(&r);
    return r;
}

static wd_t wd_mul_u64(const wd_t *a, uint64_t m)
{
    wd_t b = wd_u64(m);
    return wd_mul(a, &b);
}

/* a * 2^n, 0 <= n < 192 */
static wd_t wd_shl(const wd_t *a, unsigned n)
{
    wd_t r;
    int i, k = (int)(n / 32u);
    unsigned s = n % 32u;
    memset(&r, 0, sizeof r);
    for (i = WL - 1; i >= k; i--) {
        uint32_t hi = a->v[i - k], lo = i - k - 1 >= 0 ? a->v[i - k - 1] : 0u;
        r.v[i] = s ? (hi << s) | (lo >> (32u - s)) : hi;
    }
    return r;
}

/* bits of a non-negative a (0 for 0) */
static unsigned wd_bits(const wd_t *a)
{
    int i;
    for (i = WL - 1; i >= 0; i--)
        if (a->v[i]) {
            unsigned b = 0;
            uint32_t x = a->v[i];
            while (x) {
                b++;
                x >>= 1;
            }
            return (unsigned)i * 32u + b;
        }
    return 0u;
}

/* n / d and n mod d, both non-negative, d > 0 (bit by bit: per revolution, not per entry) */
static wd_t wd_udiv(const wd_t *n, const wd_t *d, wd_t *rem)
{
    wd_t q, r;
    int i;
    memset(&q, 0, sizeof q);
    memset(&r, 0, sizeof r);
    if (wd_bits(d) <= 32u) {                 /* limb by limb */
        uint64_t c = 0;
        for (i = WL - 1; i >= 0; i--) {
            c = (c << 32) | n->v[i];
            q.v[i] = (uint32_t)(c / d->v[0]);
            c -= (uint64_t)q.v[i] * d->v[0];
        }
        r.v[0] = (uint32_t)c;
        if (rem != NULL)
            *rem = r;
        return q;
    }
    for (i = (int)wd_bits(n) - 1; i >= 0; i--) {
        r = wd_shl(&r, 1u);
        r.v[0] |= (n->v[i / 32] >> (i % 32)) & 1u;
        if (wd_ucmp(&r, d) >= 0) {
            wd_sub(&r, d);
            q.v[i / 32] |= 1u << (i % 32);
        }
    }
    if (rem != NULL)
        *rem = r;
    return q;
}

/* a non-negative a as uint64_t, UINT64_MAX when it does not fit */
static uint64_t wd_to_u64(const wd_t *a)
{
    int i;
    for (i = 2; i < WL; i++)
        if (a->v[i])
            return UINT64_MAX;
    return ((uint64_t)a->v[1] << 32) | a->v[0];
}

/* round(n / d) for n >= 0, d > 0, saturated at UINT64_MAX */
static uint64_t wd_div_round(const wd_t *n, const wd_t *d)
{
    wd_t r, q = wd_udiv(n, d, &r);
    uint64_t x = wd_to_u64(&q);
    r = wd_shl(&r, 1u);
    if (x != UINT64_MAX && wd_ucmp(&r, d) >= 0)
        x++;
    return x;
}

/* floor(sqrt(a)) for 0 <= a < 2^128 (digit by digit, in two 64-bit halves); UINT64_MAX
 * beyond */
static uint64_t wd_isqrt(const wd_t *a)
{
    uint64_t xh, xl, rh = 0, rl = 0, oh, ol;
    unsigned b = wd_bits(a), e;
    if (b > 128u)
        return UINT64_MAX;
    if (b == 0u)
        return 0u;
    xl = ((uint64_t)a->v[1] << 32) | a->v[0];
    xh = ((uint64_t)a->v[3] << 32) | a->v[2];
    e = (b - 1u) & ~1u;                      /* one = 4^(e/2), the highest power of 4 <= a */
    oh = e >= 64u ? (uint64_t)1 << (e - 64u) : 0u;
    ol = e >= 64u ? 0u : (uint64_t)1 << e;
    while (oh | ol) {
        uint64_t tl = rl + ol, th = rh + oh + (tl < rl);
        rl = (rl >> 1) | (rh << 63);         /* res >>= 1 */
        rh >>= 1;
        if (xh > th || (xh == th && xl >= tl)) {
            xh = xh - th - (xl < tl);
            xl -= tl;
            rl += ol;
            rh += oh + (rl < ol);
        }
        ol = (ol >> 2) | (oh << 62);         /* one >>= 2 */
        oh >>= 2;
    }
    return rl;
}

/* ----------------------------------------------------------------------- 64-bit helpers */

/* round(a * b / 2^s), 32 <= s <= 64, the result < 2^64 */
static uint64_t umul_shr(uint64_t a, uint64_t b, unsigned s)
{
    const uint64_t M = 0xFFFFFFFFu;
    uint64_t a0 = a & M, a1 = a >> 32, b0 = b & M, b1 = b >> 32;
    uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    uint64_t mid = (p00 >> 32) + (p01 & M) + (p10 & M);
    uint64_t lo = (mid << 32) | (p00 & M);
    uint64_t hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
    uint64_t lo2 = lo + ((uint64_t)1 << (s - 1u));
    hi += lo2 < lo;
    lo = lo2;
    return s >= 64u ? hi : (hi << (64u - s)) | (lo >> s);
}

static int64_t smul_shr(int64_t a, uint64_t b, unsigned s)
{
    uint64_t m = umul_shr(a < 0 ? (uint64_t)0 - (uint64_t)a : (uint64_t)a, b, s);
    return a < 0 ? -(int64_t)m : (int64_t)m;
}

static int64_t sat_add(int64_t a, int64_t b)
{
    if (b > 0 && a > INT64_MAX - b)
        return INT64_MAX;
    if (b < 0 && a < INT64_MIN - b)
        return INT64_MIN;
    return a + b;
}

static int64_t clamp64(int64_t x, int64_t lim)
{
    return x > lim ? lim : (x < -lim ? -lim : x);
}

/* round(a / n), n >= 1 */
static int64_t div_round_i64(int64_t a, uint32_t n)
{
    uint64_t ua = a < 0 ? (uint64_t)0 - (uint64_t)a : (uint64_t)a;
    uint64_t q = ua / n, r = ua - q * n;
    if (2u * r >= n)
        q++;
    return a < 0 ? -(int64_t)q : (int64_t)q;
}

/* ----------------------------------------------------------------------- the estimator */

static int64_t mod_s(int64_t x, int64_t s)
{
    int64_t r;
    if (x >= 0 && x < s)                     /* the usual cases without a 64-bit division */
        return x;
    if (x >= s && x < 2 * s)
        return x - s;
    if (x < 0 && x >= -s)
        return x + s;
    r = x % s;
    return r < 0 ? r + s : r;
}

static int quad_index(unsigned a, unsigned b)
{
    return a ? (b ? 2 : 1) : (b ? 3 : 0);
}

static uint64_t unwrap(qei_calfx_t *st, uint32_t raw)
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

int qei_calfx_calibrated(const qei_calfx_t *st)
{
    return st->valid && st->phase_ok && !st->pending && st->rev_ok && st->edge_ok;
}

/* (b2 - b1) counts in 2^-32 counts, saturated */
static int64_t raw_diff(int64_t b2, int64_t b1)
{
    return clamp64(b2 - b1, ((int64_t)1 << 31) - 1) * ONE32;
}

/* angle(b2) - angle(b1) with the table, 2^-32 counts */
static int64_t cal_diff(const qei_calfx_t *st, int64_t b2, int64_t b1)
{
    int64_t j2 = mod_s(b2 - st->ref, st->S);
    int64_t j1 = mod_s(b1 - st->ref, st->S);
    return sat_add(raw_diff(b2, b1), st->table[j2] - st->table[j1]);
}

/* angle(b2) - angle(b1) as the readings use it */
static int64_t angle_diff(const qei_calfx_t *st, int64_t b2, int64_t b1)
{
    return qei_calfx_calibrated(st) ? cal_diff(st, b2, b1) : raw_diff(b2, b1);
}

static void edge_reset(qei_calfx_t *st, uint64_t frac)
{
    st->ea_n[0] = st->ea_n[1] = 0;
    st->ea_k = 0;
    st->frac[0] = st->frac[1] = frac;
    st->edge_ok = frac < EDGE_LIMIT;
}

/* r, or r + 1 when the boundary at r is a B edge (boundary 0 is always an A edge) */
static int64_t a_edge(const qei_calfx_t *st, int64_t r)
{
    return r + mod_s((int64_t)st->ab + r - st->pos + 1, 2);
}

static void set_ref(qei_calfx_t *st, int64_t r)
{
    st->ref = r;
    st->a_par = (int)mod_s((int64_t)st->ab + r - st->pos + 1, 2);
    edge_reset(st, 0u);
}

static void drop_table(qei_calfx_t *st)
{
    int64_t j;
    for (j = 0; j < st->S; j++)
        st->table[j] = 0;
    st->valid = 0;
    st->cand_n = 0;
}

static void abort_rev(qei_calfx_t *st)
{
    st->rev_dir = 0;
    st->t_prev = 0;
    st->t_prev2 = 0;
}

/* acc += x^2, the sum within 2^128 (the agreement sums) */
static void sq_acc(uint64_t acc[2], int64_t x)
{
    const uint64_t M = 0xFFFFFFFFu;
    uint64_t u = x < 0 ? (uint64_t)0 - (uint64_t)x : (uint64_t)x;
    uint64_t a0 = u & M, a1 = u >> 32, p0 = a0 * a0, p1 = a0 * a1, p2 = a1 * a1;
    uint64_t lo = p0 + (p1 << 33), hi = p2 + (p1 >> 31) + (lo < p0);
    acc[0] += lo;
    acc[1] += hi + (acc[0] < lo);
}

static wd_t wd_u128(const uint64_t a[2])
{
    wd_t r = wd_u64(a[0]);
    r.v[2] = (uint32_t)a[1];
    r.v[3] = (uint32_t)(a[1] >> 32);
    return r;
}

/* figure <= tol / 10^6 counts, the figure's square being num / scale in 2^-64 counts^2:
 * num * 10^12 <= tol^2 * scale * 2^64 */
static int within(const wd_t *num, uint32_t tol, uint64_t scale)
{
    wd_t l = wd_mul_u64(num, (uint64_t)MILLION * MILLION);
    wd_t r = wd_u64((uint64_t)tol * tol);
    r = wd_mul_u64(&r, scale);
    r = wd_shl(&r, 64u);
    return wd_ucmp(&l, &r) <= 0;
}

/* sqrt(num / den) for logs, 2^-32 counts */
static uint64_t figure(const wd_t *num, uint64_t den)
{
    wd_t d = wd_u64(den), q = wd_udiv(num, &d, NULL);
    return wd_isqrt(&q);
}

/* does the revolution in work agree with ref (n = 0: the table) or the pass's sums ref / n
 * (the three figures)? */
static int agrees(qei_calfx_t *st, const int64_t *ref, uint32_t n)
{
    const int64_t S = st->S, N = st->S / 4;
    const int64_t *w = st->work;
    int64_t c, sm = 0, sh = 0, prev[4] = {0, 0, 0, 0}, nh = 0;
    uint64_t q_e2[2] = {0, 0}, q_smm[2] = {0, 0}, q_shh[2] = {0, 0};
    wd_t zero = wd_u64(0), sxm = zero, smm, e2, shh, A, B, t, sx2;
    int ok;
    for (c = 0; c < N; c++) {
        int64_t d[4], M;
        int k;
        for (k = 0; k < 4; k++) {
            int64_t j = 4 * c + k, r = n ? div_round_i64(ref[j], n) : ref[j];
            int64_t x = w[j] - clamp64(r, (int64_t)1 << 62);
            if (x >= DEV_LIMIT || x <= -DEV_LIMIT) {
                st->last_shape = st->last_line = st->last_edge = UINT64_MAX;
                return 0;
            }
            d[k] = x;
        }
        M = d[0] + d[1] + d[2] + d[3];
        for (k = 0; k < 4; k++) {
            int64_t j = 4 * c + k;
            sq_acc(q_e2, 4 * d[k] - M);
            if (j >= 4 && (int)(j & 1) == st->a_par) {
                int64_t h = d[k] - prev[k];
                sh += h;
                sq_acc(q_shh, h);
                nh++;
            }
            prev[k] = d[k];
        }
        sm += M;
        sq_acc(q_smm, M);
        t = wd_i64((2 * c - (N - 1)) * M);
        wd_add(&sxm, &t);
    }
    smm = wd_u128(q_smm);
    e2 = wd_u128(q_e2);
    shh = wd_u128(q_shh);
    /* shape: 16 2^64 r2 = sum M^2 - (sum M)^2 / N - (sum X M)^2 / sum X^2 */
    t = wd_i64(sm);
    t = wd_mul(&t, &t);
    {
        wd_t dn = wd_u64((uint64_t)N);
        A = wd_udiv(&t, &dn, NULL);
    }
    sx2 = wd_u64((uint64_t)N * (uint64_t)(N * N - 1) / 3u);
    t = wd_mul(&sxm, &sxm);
    B = wd_udiv(&t, &sx2, NULL);
    wd_sub(&smm, &A);
    wd_sub(&smm, &B);
    if (wd_negative(&smm))
        smm = zero;
    /* line: 2^64 line^2 = (n sum h^2 - (sum h)^2) / n^2 */
    shh = wd_mul_u64(&shh, (uint64_t)nh);
    t = wd_i64(sh);
    t = wd_mul(&t, &t);
    wd_sub(&shh, &t);
    if (wd_negative(&shh))
        shh = zero;
    st->last_shape = figure(&smm, 16u * (uint64_t)N);
    st->last_edge = figure(&e2, 16u * (uint64_t)S);
    st->last_line = figure(&shh, (uint64_t)nh * (uint64_t)nh);
    ok = within(&smm, st->cfg.shape_uc, 16u * (uint64_t)N) &&
         within(&shh, st->cfg.line_uc, (uint64_t)nh * (uint64_t)nh) &&
         within(&e2, st->cfg.edge_uc, 16u * (uint64_t)S);
    return ok;
}

/* |T2 - T3| S T3 2^32 / (T2 (T2 + T3)), signed like T2 - T3: the acceleration term K2 of
 * u(x) = S x + K2 x (x - 1), x = tau / T3; 0 and *ok = 0 beyond K2_LIMIT */
static int64_t accel_term(int64_t S, uint64_t T2, uint64_t T3, int *ok)
{
    wd_t num = wd_u64(T2 > T3 ? T2 - T3 : T3 - T2), den = wd_u64(T2);
    uint64_t q;
    num = wd_mul_u64(&num, (uint64_t)S * T3);
    num = wd_shl(&num, 32u);
    den = wd_mul_u64(&den, T2 + T3);
    q = wd_div_round(&num, &den);
    *ok = q < K2_LIMIT;
    if (!*ok)
        return 0;
    return T2 >= T3 ? (int64_t)q : -(int64_t)q;
}

/* the motion check: |g2 - g1| (T2 + T3) T2 <= motion_ppm / 10^6, exactly; last_motion */
static int motion_clean(qei_calfx_t *st, uint64_t T1, uint64_t T2, uint64_t T3)
{
    wd_t a = wd_i64((int64_t)T2 - (int64_t)T3), b = wd_i64((int64_t)T1 - (int64_t)T2), den, l, r;
    a = wd_mul_u64(&a, T1);
    a = wd_mul_u64(&a, T1 + T2);
    b = wd_mul_u64(&b, T2 + T3);
    b = wd_mul_u64(&b, T3);
    wd_sub(&a, &b);                          /* (T2-T3) T1 (T1+T2) - (T1-T2) (T2+T3) T3 */
    a = wd_abs(a);
    den = wd_u64(T1);
    den = wd_mul_u64(&den, T3);
    den = wd_mul_u64(&den, T1 + T2);         /* T1 T3 (T1 + T2) */
    l = wd_shl(&a, 32u);
    st->last_motion = wd_div_round(&l, &den);
    l = wd_mul_u64(&a, MILLION);
    r = wd_mul_u64(&den, st->cfg.motion_ppm);
    return wd_ucmp(&l, &r) <= 0;
}

/* revolution of period T complete (work[j]: ticks from its start to boundary j) */
static void revolution(qei_calfx_t *st, uint64_t T, int d)
{
    const int64_t S = st->S;
    const uint64_t T1 = st->t_prev2, T2 = st->t_prev, T3 = T;
    int64_t *w = st->work, K2, j;
    uint64_t R;
    unsigned sh = 0;
    int ok;
    if (T1 >> 32 || T2 >> 32 || T3 >> 32 || !motion_clean(st, T1, T2, T3)) {
        if (T1 >> 32 || T2 >> 32 || T3 >> 32)
            st->last_motion = UINT64_MAX;
        st->n.unclean++;
        return;
    }
    K2 = accel_term(S, T2, T3, &ok);
    if (!ok) {
        st->n.unclean++;
        return;
    }
    /* x = tau / T3 in 2^-62 through R = (2^95 - 1) / (T3 2^sh), T3 2^sh in [2^31, 2^32) */
    while (((T3 << sh) >> 31) == 0u)
        sh++;
    {
        wd_t n = wd_u64(0), dd = wd_u64(T3 << sh), q;
        n.v[2] = 0x7FFFFFFFu;
        n.v[1] = n.v[0] = 0xFFFFFFFFu;
        q = wd_udiv(&n, &dd, NULL);
        R = wd_to_u64(&q);
    }
    for (j = 1; j < S; j++) {
        uint64_t x = umul_shr((uint64_t)w[j] << sh, R, 33u);
        int64_t inner = S * ONE32 - smul_shr(K2, FRAC_ONE - x, 62u);
        int64_t u = smul_shr(inner, x, 62u);
        w[j] = (d > 0 ? u : S * ONE32 - u) - j * ONE32;
    }
    w[0] = 0;
    if (st->valid) {
        if (agrees(st, st->table, 0u)) {
            st->rev_ok = 1;
            st->cand_n = 0;
            return;
        }
        st->rev_ok = 0;
        st->n.disagree++;
    }
    if (st->cand_n > 0u && !agrees(st, st->acc, st->cand_n)) {
        st->n.rejected++;
        st->cand_n = 0;
    }
    if (st->cand_n == 0u) {
        for (j = 0; j < S; j++)
            st->acc[j] = w[j];
    } else {
        for (j = 0; j < S; j++)
            st->acc[j] = sat_add(st->acc[j], w[j]);
    }
    st->cand_n++;
    if (st->cand_n >= st->cfg.learn_revs) {
        for (j = 0; j < S; j++)
            st->table[j] = clamp64(div_round_i64(st->acc[j], st->cand_n), TABLE_LIMIT);
        if (st->valid)
            st->n.changes++;
        else
            st->n.learned++;
        st->valid = 1;
        st->rev_ok = 1;
        st->cand_n = 0;
        edge_reset(st, 0u);
    }
}

static void learn(qei_calfx_t *st, int64_t b, int d, uint64_t t)
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
            uint64_t tau = t - st->rev_t0;
            st->work[slot] = (int64_t)(tau >> 32 ? (uint64_t)1 << 32 : tau);
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

/* x3 D + x1 C1 - x2 C2: the residual of edge 3 against the constant-acceleration
 * extrapolation through edges 0..2, times D = tau1 tau2 (tau2 - tau1) */
static wd_t residual(const wd_t *D, const wd_t *C1, const wd_t *C2, const int64_t *x)
{
    wd_t a = wd_i64(x[2]), b = wd_i64(x[0]), c = wd_i64(x[1]);
    a = wd_mul(&a, D);
    b = wd_mul(&b, C1);
    c = wd_mul(&c, C2);
    wd_add(&a, &b);
    wd_sub(&a, &c);
    return a;
}

/* products of three taus (< 2^32): p q r */
static wd_t tau3(uint64_t p, uint64_t q, uint64_t r)
{
    wd_t a = wd_u64(p * q);
    return wd_mul_u64(&a, r);
}

/* one sample (b, t) of a spacing against its history: 0 when the four times do not strictly
 * increase (no vote), else 1 with the decisions: *jolt, *vote (-1: none, 0: better or no
 * objection, 1: worse) */
static int edge_sample(const qei_calfx_t *st, const int64_t *hb, const uint64_t *ht, int64_t b,
                       uint64_t t, int *jolt, int *vote)
{
    uint64_t tau1 = ht[1] - ht[0], tau2 = ht[2] - ht[0], tau3v = t - ht[0];
    unsigned k = 0;
    int64_t xr[3], xc[3];
    wd_t D, C1, C2, Er, Ec, diff, l, r, ar, ac;
    int i;
    if (!(0u < tau1 && tau1 < tau2 && tau2 < tau3v))
        return 0;
    while ((tau3v >> k) >> 32)
        k++;
    if (k) {                                 /* the ratios do not change with the scale */
        tau1 >>= k;
        tau2 >>= k;
        tau3v >>= k;
        if (!(0u < tau1 && tau1 < tau2 && tau2 < tau3v))
            return 0;
    }
    for (i = 0; i < 3; i++) {
        int64_t bi = i < 2 ? hb[i + 1] : b;
        if (bi - hb[0] >= ((int64_t)1 << 21) || hb[0] - bi >= ((int64_t)1 << 21))
            return 0;
        xr[i] = (bi - hb[0]) * ONE32;
        xc[i] = cal_diff(st, bi, hb[0]);
        if (xc[i] >= X_LIMIT || xc[i] <= -X_LIMIT)
            return 0;
    }
    D = tau3(tau1, tau2, tau2 - tau1);
    C1 = tau3(tau2, tau3v, tau3v - tau2);
    C2 = tau3(tau1, tau3v, tau3v - tau1);
    Er = residual(&D, &C1, &C2, xr);
    Ec = residual(&D, &C1, &C2, xc);
    ac = wd_abs(Ec);
    r = wd_shl(&D, 31u);                     /* |e_cal| > 0.5 count */
    *jolt = wd_ucmp(&ac, &r) > 0;
    ar = wd_abs(Er);
    diff = Er;
    wd_sub(&diff, &Ec);
    diff = wd_abs(diff);                     /* eff D */
    l = wd_mul_u64(&diff, tau3v);
    r = wd_mul_u64(&D, (uint64_t)EDGE_MIN_TICKS * (uint64_t)(b > hb[0] ? b - hb[0] : hb[0] - b));
    r = wd_shl(&r, 32u - k);                 /* k <= 32: tau3 < 2^64 */
    if (wd_ucmp(&l, &r) < 0) {
        *vote = 0;                           /* eff < 4 ticks' worth: no objection */
    } else {
        wd_t m = wd_ucmp(&ar, &ac) < 0 ? ar : ac, e3 = wd_mul_u64(&diff, EDGE_SEEN);
        *vote = wd_ucmp(&m, &e3) <= 0 ? wd_ucmp(&ac, &ar) > 0 : -1;
    }
    return 1;
}

/* one A-rising edge while there is a table and a phase */
static void edge_check(qei_calfx_t *st, int64_t b, uint64_t t)
{
    int k, ok;
    st->ea_k++;
    for (k = 0; k < 2; k++) {
        int64_t *hb = st->ea_b[k];
        uint64_t *ht = st->ea_t[k];
        int n = st->ea_n[k], jolt = 0, vote = -1;
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
        ok = edge_sample(st, hb, ht, b, t, &jolt, &vote);
        if (ok && k == 0 && jolt) {
            st->n.jolts++;
            if (st->edge_ok)
                st->n.edge_alarms++;
            edge_reset(st, FRAC_ONE);
            st->ea_b[0][0] = b;
            st->ea_t[0][0] = t;
            st->ea_n[0] = 1;
            return;
        }
        if (ok && vote >= 0) {
            uint64_t f = st->frac[k];
            unsigned s = EDGE_W_LOG2[k];
            st->frac[k] = vote ? f + ((FRAC_ONE - f) >> s) : f - (f >> s);
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
static void lose(qei_calfx_t *st, int64_t b)
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

static void index_step(qei_calfx_t *st, int d)
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

int qei_calfx_init(qei_calfx_t *st, const qei_calfx_cfg_t *cfg, int64_t *buf, size_t buf_len)
{
    memset(st, 0, sizeof *st);
    if (cfg->tick_hz < 1u || cfg->frac_bits > 31u || cfg->ts_w < 1u || cfg->ts_w > 32u ||
        cfg->cycles < 2u || cfg->cycles > (1ul << 20) || cfg->learn_revs < 1u ||
        cfg->motion_ppm < 1u || cfg->motion_ppm > MILLION || cfg->shape_uc < 1u ||
        cfg->line_uc < 1u || cfg->edge_uc < 1u || buf == NULL ||
        buf_len < QEI_CALFX_BUF_LEN(cfg->cycles))
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

void qei_calfx_push(qei_calfx_t *st, const qei_calfx_entry_t *e)
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
        qei_calfx_method_t *m = &st->m[i];
        int sel = i == 1 || a_rise;
        if (broken || reversal) {
            m->has_ref = 0;
            m->mag = 0u;
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

/* 128-bit unsigned a >= b, a - b, a + b on (hi, lo) pairs, for rate() */
static int ge128(uint64_t ah, uint64_t al, uint64_t bh, uint64_t bl)
{
    return ah > bh || (ah == bh && al >= bl);
}

static void sub128(uint64_t *ah, uint64_t *al, uint64_t bh, uint64_t bl)
{
    *ah -= bh + (*al < bl);
    *al -= bl;
}

static void add128(uint64_t *ah, uint64_t *al, uint64_t bh, uint64_t bl)
{
    *al += bl;
    *ah += bh + (*al < bl);
}

/* |ang| (2^-32 counts) over dt ticks (> 0) in 2^-F count/s, rounded (ties up), saturated at
 * QEI_CALFX_MAX: q = (2 num + den) / (2 den), num = |ang| tick_hz < 2^95, den = dt 2^(32-F)
 * < 2^96; q from one 64-bit division of the leading bits, corrected with the exact remainder */
static uint32_t rate(const qei_calfx_t *st, int64_t ang, uint64_t dt)
{
    const uint64_t M = 0xFFFFFFFFu;
    const unsigned s = 32u - st->cfg.frac_bits;
    uint64_t a = ang < 0 ? (uint64_t)0 - (uint64_t)ang : (uint64_t)ang;
    uint64_t p0 = (a & M) * st->cfg.tick_hz, p1 = (a >> 32) * st->cfg.tick_hz;
    uint64_t nl = p0 + (p1 << 32), nh = (p1 >> 32) + (nl < p0);
    uint64_t dl = dt << s, dh = dt >> (64u - s);
    uint64_t lh, ll, ph, pl, q, qd0, qd1, k = 0;
    add128(&nh, &nl, nh, nl);                /* 2 num + den, 2 den */
    add128(&nh, &nl, dh, dl);
    add128(&dh, &dl, dh, dl);
    lh = (dh << 31) | (dl >> 33);            /* 2 den 2^31 < 2^128 */
    ll = dl << 31;
    if (ge128(nh, nl, lh, ll))
        return QEI_CALFX_MAX;
    while ((dh >> k) != 0u || ((dh << (63u - k) << 1) | (dl >> k)) >> 32)
        k++;                                 /* (2 den) >> k < 2^32 */
    q = k ? ((nh << (64u - k)) | (nl >> k)) / ((dh << (64u - k)) | (dl >> k)) : nl / dl;
    qd0 = (dl & M) * q;                      /* q 2 den, q < 2^33 */
    qd1 = (dl >> 32) * q;
    pl = qd0 + (qd1 << 32);
    ph = dh * q + (qd1 >> 32) + (pl < qd0);
    while (!ge128(nh, nl, ph, pl)) {
        q--;
        sub128(&ph, &pl, dh, dl);
    }
    lh = nh;
    ll = nl;
    sub128(&lh, &ll, ph, pl);
    while (ge128(lh, ll, dh, dl)) {
        q++;
        sub128(&lh, &ll, dh, dl);
    }
    return q > (uint64_t)QEI_CALFX_MAX ? QEI_CALFX_MAX : (uint32_t)q;
}

qei_calfx_reading_t qei_calfx_read(qei_calfx_t *st, uint32_t time)
{
    const uint64_t t = unwrap(st, time);
    int32_t out[2] = {0, 0};
    qei_calfx_reading_t r;
    int i;
    for (i = 0; i < 2; i++) {
        qei_calfx_method_t *m = &st->m[i];
        uint64_t since;
        uint32_t mag;
        if (!m->has_last)
            continue;
        if (m->new_edge && m->has_ref && m->last_t != m->ref_t)
            m->mag = rate(st, angle_diff(st, m->last_b, m->ref_b), m->last_t - m->ref_t);
        since = t - m->last_t;
        mag = m->mag;
        if (st->cfg.stall_ticks > 0u && since >= st->cfg.stall_ticks) {
            mag = 0u;
        } else if (!m->new_edge && since > 0u) {
            uint32_t bound =
                rate(st, angle_diff(st, m->last_b + (int64_t)m->cpe * m->dir, m->last_b), since);
            if (bound < mag)
                mag = bound;
        }
        out[i] = m->dir < 0 ? -(int32_t)mag : (int32_t)mag;
        if (m->new_edge) {
            m->ref_b = m->last_b;
            m->ref_t = m->last_t;
            m->has_ref = 1;
            m->new_edge = 0;
        }
    }
    r.mt_a = out[0];
    r.any = out[1];
    r.calibrated = qei_calfx_calibrated(st);
    return r;
}
