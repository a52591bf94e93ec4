/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The encoders' motion in `make linux-test`: a pure function of the motion step, shared by the
 * model server (which drives enc_qei's inputs with it) and the test init (which computes from it
 * what every count, signal and event must be).
 *
 * Channel k's quadrature position starts at 0 and changes by enc_stim_next() (-1, 0 or +1) at
 * each motion step. Position p puts (A, B) in state p mod 4 of the forward sequence
 * 00 -> 10 -> 11 -> 01, and Z high while p mod ENC_STIM_INDEX_PERIOD = 0 (one state wide, so
 * Z rises whenever the shaft enters that state from either side). The motion is made of
 * segments: runs forward or backward at one step per 1, 2 or 3 motion steps, pauses, and
 * dithers (+1, -1, +1, ...), each 8 to 135 motion steps long, drawn from a per-channel
 * xorshift generator. The model holds each motion step's inputs for ENC_STIM_STEP_CLOCKS clocks
 * (every state far longer than the input filter needs) and holds them during bus accesses, so
 * the count after N motion steps does not depend on how many accesses came in between.
 */
#ifndef ENC_STIM_H
#define ENC_STIM_H

#include <stdint.h>

#define ENC_STIM_STEP_CLOCKS 32
#define ENC_STIM_INDEX_PERIOD 64

struct enc_stim {
	uint32_t rng;      /* xorshift32 state */
	int64_t pos;       /* quadrature position */
	uint32_t left;     /* motion steps left in the segment */
	uint32_t phase;    /* motion step within the segment */
	int kind;          /* 0 run, 1 pause, 2 dither */
	int dir;           /* +1 or -1 */
	uint32_t period;   /* motion steps per position step in a run */
};

static inline uint32_t enc_stim_rand(struct enc_stim *s)
{
	uint32_t x = s->rng;

	x ^= x << 13;
	x ^= x >> 17;
	x ^= x << 5;
	s->rng = x;
	return x;
}

static inline void enc_stim_init(struct enc_stim *s, unsigned int channel)
{
	s->rng = 0x9e3779b9u * (channel + 1u) ^ 0x5145u;
	s->pos = 0;
	s->left = 0;
	s->phase = 0;
	s->kind = 0;
	s->dir = 1;
	s->period = 1;
	enc_stim_rand(s);
}

/* The position change of the next motion step: -1, 0 or +1. */
static inline int enc_stim_next(struct enc_stim *s)
{
	int d = 0;

	if (s->left == 0) {
		uint32_t r = enc_stim_rand(s);

		s->kind = (r & 7) < 5 ? 0 : (r & 7) < 6 ? 1 : 2;
		s->dir = (r >> 3) & 1 ? 1 : -1;
		s->period = 1 + (r >> 4) % 3;
		s->left = 8 + (r >> 8) % 128;
		s->phase = 0;
	}
	if (s->kind == 0)
		d = (s->phase % s->period) == s->period - 1 ? s->dir : 0;
	else if (s->kind == 2)
		d = (s->phase & 1) ? -s->dir : s->dir;
	s->phase++;
	s->left--;
	s->pos += d;
	return d;
}

/* (A, B) and Z at position p */
static inline unsigned int enc_stim_a(int64_t p)
{
	unsigned int s = (unsigned int)(p & 3);

	return s == 1 || s == 2;
}

static inline unsigned int enc_stim_b(int64_t p)
{
	unsigned int s = (unsigned int)(p & 3);

	return s == 2 || s == 3;
}

static inline unsigned int enc_stim_z(int64_t p)
{
	int64_t m = p % ENC_STIM_INDEX_PERIOD;

	return m == 0;
}

#endif
