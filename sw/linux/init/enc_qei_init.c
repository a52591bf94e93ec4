// SPDX-License-Identifier: Apache-2.0
/*
 * The init of `make linux-test`: runs as PID 1 in the User-Mode Linux kernel, loads the enc-qei
 * module and uses the counter the way a user does (sysfs files under /sys/bus/counter/devices/
 * counter0 and events from /dev/counter0), checking every count, signal, action and event
 * against a model of the count functions fed with the encoders' motion (../stimulus.h). The
 * motion advances only when this program writes a number of motion steps to the bridge's
 * debugfs file, so after each advance it knows exactly what every channel must show.
 *
 * The kernel passes its environment: enc_test (full, lean or refuse), enc_channels, enc_count_w,
 * enc_clk_hz. Each check prints "ok N - what" or "not ok N - what: why"; the run ends with the
 * line "init: N passed, M failed", then the machine powers off.
 */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <linux/counter.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/mount.h>
#include <sys/reboot.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include "stimulus.h"

#define DEV "/sys/bus/counter/devices/counter0"
#define ADVANCE "/sys/kernel/debug/enc_qei_bridge/advance"
#define MAX_CH 16

enum func { X4, X2A, X2B, X1A, X1B, PULSE_DIR, INCREASE, DECREASE, NFUNC };
static const char *const func_name[NFUNC] = {
	"quadrature x4", "quadrature x2 a", "quadrature x2 b", "quadrature x1 a",
	"quadrature x1 b", "pulse-direction", "increase", "decrease",
};
enum range { FREE, MODULO, LIMIT };

/* The expected state of one channel (what the hardware must show) */
struct chan {
	struct enc_stim stim;
	enum func func;
	enum range range;
	int enabled, inv_a, dir_up, last_dir;
	uint64_t count, mask, ceiling, preset, capture, compare;
	int preset_en, capture_en, oneshot, cmp_en;
	unsigned int ovf, unf, idx, cmp; /* events since the last check */
};

static struct chan ch[MAX_CH];
static unsigned int nch, count_w;
static int passed, failed;

static void result(int good, const char *fmt, ...)
{
	va_list ap;

	printf("%s %d - ", good ? "ok" : "not ok", passed + failed + 1);
	va_start(ap, fmt);
	vprintf(fmt, ap);
	va_end(ap);
	printf("\n");
	fflush(stdout);
	if (good)
		passed++;
	else
		failed++;
}

static int rd(const char *path, char *buf, size_t n)
{
	int fd = open(path, O_RDONLY);
	ssize_t got;

	if (fd < 0)
		return -errno;
	got = read(fd, buf, n - 1);
	close(fd);
	if (got < 0)
		return -errno;
	buf[got] = 0;
	while (got > 0 && buf[got - 1] == '\n')
		buf[--got] = 0;
	return 0;
}

static int wr(const char *path, const char *val)
{
	int fd = open(path, O_WRONLY);
	ssize_t n;

	if (fd < 0)
		return -errno;
	n = write(fd, val, strlen(val));
	close(fd);
	return n < 0 ? -errno : 0;
}

static char *cpath(unsigned int k, const char *attr)
{
	static char p[4][160];
	static int i;

	i = (i + 1) & 3;
	snprintf(p[i], sizeof(p[i]), DEV "/count%u/%s", k, attr);
	return p[i];
}

static uint64_t rdu(const char *path)
{
	char buf[64];

	if (rd(path, buf, sizeof(buf)))
		return UINT64_MAX - 1;
	return strtoull(buf, NULL, 0);
}

static int wru(const char *path, uint64_t v)
{
	char buf[32];

	snprintf(buf, sizeof(buf), "%" PRIu64, v);
	return wr(path, buf);
}

/* Decoder view of position p: state index 0..3 of 00, 10, 11, 01 */
static unsigned int view(const struct chan *c, int64_t p, unsigned int *a, unsigned int *b)
{
	*a = enc_stim_a(p) ^ c->inv_a;
	*b = enc_stim_b(p);
	return *a ? (*b ? 2 : 1) : (*b ? 3 : 0);
}

static void count_step(struct chan *c, int step)
{
	uint64_t old = c->count;

	c->dir_up = step > 0;
	if (c->range == MODULO) {
		if (step > 0 && c->count >= c->ceiling) {
			c->count = 0;
			c->ovf++;
		} else if (step < 0 && c->count == 0) {
			c->count = c->ceiling;
			c->unf++;
		} else {
			c->count += step;
		}
	} else if (c->range == LIMIT) {
		if (step > 0 && c->count >= c->ceiling)
			c->ovf++;
		else if (step < 0 && c->count == 0)
			c->unf++;
		else
			c->count += step;
	} else {
		if (step > 0 && c->count == c->mask)
			c->ovf++;
		if (step < 0 && c->count == 0)
			c->unf++;
		c->count = (c->count + step) & c->mask;
	}
	if (c->cmp_en && c->count != old && c->count == c->compare)
		c->cmp++;
}

/* One motion step of channel k: what the count function and the index do with it */
static void model_step(unsigned int k)
{
	struct chan *c = &ch[k];
	int64_t p0 = c->stim.pos, p1;
	unsigned int a0, b0, a1, b1, s0, s1, z0, z1;
	int d, step = 0;

	enc_stim_next(&c->stim);
	p1 = c->stim.pos;
	if (p1 == p0)
		return;
	s0 = view(c, p0, &a0, &b0);
	s1 = view(c, p1, &a1, &b1);
	d = ((s1 - s0) & 3) == 1 ? 1 : -1;
	switch (c->func) {
	case X4: step = d; break;
	case X2A: step = a0 != a1 ? d : 0; break;
	case X2B: step = b0 != b1 ? d : 0; break;
	case X1A: step = (!a0 && a1 && d > 0) ? 1 : (a0 && !a1 && d < 0) ? -1 : 0; break;
	case X1B: step = (!b0 && b1 && d > 0) ? 1 : (b0 && !b1 && d < 0) ? -1 : 0; break;
	case PULSE_DIR: step = (!a0 && a1) ? (b1 ? 1 : -1) : 0; break;
	case INCREASE: step = (!a0 && a1) ? 1 : 0; break;
	case DECREASE: step = (!a0 && a1) ? -1 : 0; break;
	default: break;
	}
	c->last_dir = d;
	if (step && c->enabled)
		count_step(c, step);
	z0 = enc_stim_z(p0);
	z1 = enc_stim_z(p1);
	if (!z0 && z1) {
		c->idx++;
		if (c->preset_en) {
			c->count = c->preset;
			if (c->cmp_en && c->count == c->compare)
				c->cmp++;
		} else if (c->capture_en) {
			c->capture = c->count;
		}
		if (c->oneshot)
			c->preset_en = c->capture_en = 0;
	}
}

static void advance(unsigned int steps)
{
	char buf[16];
	unsigned int i, k;

	snprintf(buf, sizeof(buf), "%u", steps);
	if (wr(ADVANCE, buf)) {
		result(0, "advance %u: %s", steps, strerror(errno));
		return;
	}
	for (i = 0; i < steps; i++)
		for (k = 0; k < nch; k++)
			model_step(k);
}

static void clear_event_counts(void)
{
	for (unsigned int k = 0; k < nch; k++)
		ch[k].ovf = ch[k].unf = ch[k].idx = ch[k].cmp = 0;
}

static int set_func(unsigned int k, enum func f)
{
	int rc = wr(cpath(k, "function"), func_name[f]);

	if (!rc)
		ch[k].func = f;
	return rc;
}

static int set_count(unsigned int k, uint64_t v)
{
	int rc = wru(cpath(k, "count"), v);

	if (!rc)
		ch[k].count = v;
	return rc;
}

/* Counts, directions, signal levels and Synapse actions against the model */
static void check_channels(const char *when)
{
	static const char *const actions[] = {"none", "rising edge", "falling edge", "both edges"};
	char path[160], buf[64];
	unsigned int k, j, a, b;

	for (k = 0; k < nch; k++) {
		struct chan *c = &ch[k];
		uint64_t got = rdu(cpath(k, "count"));
		int fwd = c->dir_up;
		const char *dir;
		int act[3], i;

		result(got == c->count, "%s: count%u (%s) = %" PRIu64 " (expected %" PRIu64 ")",
		       when, k, func_name[c->func], got, c->count);
		rd(cpath(k, "direction"), buf, sizeof(buf));
		dir = c->dir_up ? "forward" : "backward";
		result(!strcmp(buf, dir), "%s: count%u direction %s (expected %s)", when, k, buf, dir);

		view(c, c->stim.pos, &a, &b);
		for (j = 0; j < 3; j++) {
			/* the levels the peripheral sees, after CTRL.INV_A */
			unsigned int want = j == 0 ? a : j == 1 ? b : enc_stim_z(c->stim.pos);

			snprintf(path, sizeof(path), DEV "/signal%u/signal", 3 * k + j);
			rd(path, buf, sizeof(buf));
			result(!strcmp(buf, want ? "high" : "low"),
			       "%s: signal%u level %s (expected %s)", when, 3 * k + j, buf,
			       want ? "high" : "low");
		}
		for (i = 0; i < 3; i++)
			act[i] = 0;
		switch (c->func) {
		case X4: act[0] = act[1] = 3; break;
		case X2A: act[0] = 3; break;
		case X2B: act[1] = 3; break;
		case X1A: act[0] = fwd ? 1 : 2; break;
		case X1B: act[1] = fwd ? 1 : 2; break;
		default: act[0] = 1; break;
		}
		for (j = 0; j < 3; j++) {
			snprintf(path, sizeof(path), DEV "/count%u/signal%u_action", k, 3 * k + j);
			rd(path, buf, sizeof(buf));
			result(!strcmp(buf, actions[act[j]]), "%s: count%u signal%u_action %s "
			       "(expected %s)", when, k, 3 * k + j, buf, actions[act[j]]);
		}
	}
}

/* Every event read from the character device against the model's events of the chunk */
struct watch_spec {
	uint8_t event, channel;
};

static const char *const event_name[] = {
	"overflow", "underflow", "overflow_underflow", "threshold", "index",
	"change_of_state", "capture",
};

static unsigned int expected_events(const struct watch_spec *w, uint64_t *value)
{
	struct chan *c = &ch[w->channel];

	*value = c->count;
	switch (w->event) {
	case COUNTER_EVENT_OVERFLOW: return c->ovf > 0;
	case COUNTER_EVENT_UNDERFLOW: return c->unf > 0;
	case COUNTER_EVENT_OVERFLOW_UNDERFLOW: return c->ovf + c->unf > 0;
	case COUNTER_EVENT_THRESHOLD: return c->cmp > 0;
	case COUNTER_EVENT_INDEX: return c->idx > 0;
	default: return 0;
	}
}

static void check_events(int fd, const struct watch_spec *ws, unsigned int nw, const char *when)
{
	struct counter_event ev[64];
	unsigned int got[16] = {0}, i, j;
	ssize_t n = read(fd, ev, sizeof(ev));
	unsigned int count = n > 0 ? (unsigned int)(n / sizeof(ev[0])) : 0;

	for (i = 0; i < count; i++) {
		int known = 0;

		for (j = 0; j < nw; j++) {
			uint64_t value;

			if (ev[i].watch.event != ws[j].event || ev[i].watch.channel != ws[j].channel)
				continue;
			known = 1;
			got[j]++;
			expected_events(&ws[j], &value);
			result(ev[i].status == 0 && ev[i].value == value,
			       "%s: %s event of channel %u carries count %" PRIu64
			       " (expected %" PRIu64 ", status %u)", when, event_name[ws[j].event],
			       ws[j].channel, (uint64_t)ev[i].value, value, ev[i].status);
		}
		if (!known)
			result(0, "%s: unexpected event %u on channel %u", when, ev[i].watch.event,
			       ev[i].watch.channel);
	}
	for (j = 0; j < nw; j++) {
		uint64_t value;
		unsigned int want = expected_events(&ws[j], &value);

		if (want || got[j])
			result(got[j] == want, "%s: %u %s event(s) of channel %u (expected %u)",
			       when, got[j], event_name[ws[j].event], ws[j].channel, want);
	}
}

static int add_watch(int fd, uint8_t event, uint8_t channel, uint8_t type, uint8_t parent,
		     uint8_t id)
{
	struct counter_watch w = {
		.component = { .type = type, .scope = COUNTER_SCOPE_COUNT, .parent = parent,
			       .id = id },
		.event = event, .channel = channel,
	};

	return ioctl(fd, COUNTER_ADD_WATCH_IOCTL, &w) ? -errno : 0;
}

static void check_kunit(void)
{
	char buf[8192], *line, *save;
	int n = 0;

	if (rd("/sys/kernel/debug/kunit/enc-qei/results", buf, sizeof(buf))) {
		result(0, "kunit: no results in debugfs");
		return;
	}
	for (line = strtok_r(buf, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
		while (*line == ' ' || *line == '\t')
			line++;
		if (!strncmp(line, "ok ", 3) && strstr(line, "enc_qei_test_")) {
			result(1, "kunit: %s", line);
			n++;
		} else if (!strncmp(line, "not ok ", 7)) {
			result(0, "kunit: %s", line);
			n++;
		}
	}
	result(n >= 7, "kunit: %d test cases reported", n);
}

/* A write the driver must refuse with err, leaving the attribute as it was */
static void check_refused(const char *path, const char *val, int err)
{
	char before[128], after[128];
	int rc;

	rd(path, before, sizeof(before));
	rc = wr(path, val);
	rd(path, after, sizeof(after));
	result(rc == -err && !strcmp(before, after), "writing \"%s\" to %s: %s (expected %s), "
	       "value %s -> %s", val, path + strlen(DEV) + 1, rc ? strerror(-rc) : "accepted",
	       strerror(err), before, after);
}

static void counting_rounds(const enum func *funcs, unsigned int nfuncs, unsigned int rounds)
{
	static const unsigned int chunk[] = {173, 257, 311, 97, 401, 229};
	char when[64];

	for (unsigned int r = 0; r < rounds; r++) {
		for (unsigned int k = 0; k < nch; k++) {
			enum func f = funcs[(k + r) % nfuncs];
			int rc = set_func(k, f);

			if (rc)
				result(0, "count%u: function %s: %s", k, func_name[f], strerror(-rc));
			rc = set_count(k, r == 0 ? 0 : (uint64_t)(1000 * k + 37 * r) & ch[k].mask);
			if (rc)
				result(0, "count%u: count write: %s", k, strerror(-rc));
		}
		advance(chunk[r % 6]);
		snprintf(when, sizeof(when), "round %u", r);
		check_channels(when);
	}
}

static void test_full(int fd_events)
{
	static const enum func all[] = {X4, X2A, X2B, X1A, X1B, PULSE_DIR, INCREASE, DECREASE};
	static const struct watch_spec ws[] = {
		{COUNTER_EVENT_INDEX, 0}, {COUNTER_EVENT_OVERFLOW, 2}, {COUNTER_EVENT_UNDERFLOW, 2},
		{COUNTER_EVENT_OVERFLOW_UNDERFLOW, 1}, {COUNTER_EVENT_THRESHOLD, 3},
		{COUNTER_EVENT_INDEX, 3},
	};
	char buf[256], when[64];
	unsigned int k, i;
	int rc;

	counting_rounds(all, 8, 16);

	/* enable */
	rc = wr(cpath(0, "enable"), "0");
	ch[0].enabled = 0;
	advance(120);
	check_channels("enable 0");
	rc |= wr(cpath(0, "enable"), "1");
	ch[0].enabled = 1;
	result(!rc, "enable written");

	/* polarity of A inverts the direction of x4 */
	set_func(1, X4);
	rc = wr(DEV "/signal3/polarity", "negative");
	ch[1].inv_a = 1;
	rd(DEV "/signal3/polarity", buf, sizeof(buf));
	result(!rc && !strcmp(buf, "negative"), "signal3 polarity negative (%s)", buf);
	advance(200);
	check_channels("polarity negative");
	wr(DEV "/signal3/polarity", "positive");
	ch[1].inv_a = 0;

	/* spike filter: 3 clocks at the bus clock, then 6 */
	rd(cpath(2, "spike_filter_ns"), buf, sizeof(buf));
	result(!strcmp(buf, "20"), "count2 spike_filter_ns %s (expected 20 at 100 MHz, "
	       "FILTER_LEN 3)", buf);
	rc = wr(cpath(2, "spike_filter_ns"), "50");
	rd(cpath(2, "spike_filter_ns"), buf, sizeof(buf));
	result(!rc && !strcmp(buf, "50"), "count2 spike_filter_ns 50 -> %s", buf);
	advance(150);
	check_channels("spike filter 50 ns");

	/* ranges, index preset and capture, compare, and the events of it all */
	for (k = 0; k < nch; k++)
		set_func(k, X4);
	rc = wru(cpath(2, "ceiling"), 99) | wr(cpath(2, "count_mode"), "modulo-n");
	ch[2].ceiling = 99;
	ch[2].range = MODULO;
	rc |= set_count(2, 50) | set_count(1, 5);
	rd(cpath(2, "count_mode"), buf, sizeof(buf));
	result(!rc && !strcmp(buf, "modulo-n") && rdu(cpath(2, "ceiling")) == 99,
	       "count2 modulo-n, ceiling 99 (%s)", buf);
	rc = wru(cpath(0, "preset"), 500) | wr(cpath(0, "index_oneshot"), "1") |
	     wr(cpath(0, "preset_enable"), "1");
	ch[0].preset = 500;
	ch[0].oneshot = ch[0].preset_en = 1;
	rc |= wr(cpath(1, "capture_enable"), "1");
	ch[1].capture_en = 1;
	ch[3].compare = (ch[3].count + 3) & ch[3].mask;
	rc |= wru(cpath(3, "compare"), ch[3].compare) | wr(cpath(3, "compare_enable"), "1");
	ch[3].cmp_en = 1;
	result(!rc, "preset, index_oneshot, preset_enable, capture_enable, compare written");
	rc = 0;
	for (i = 0; i < sizeof(ws) / sizeof(ws[0]); i++)
		rc |= add_watch(fd_events, ws[i].event, ws[i].channel, COUNTER_COMPONENT_COUNT,
				ws[i].channel, 0);
	rc |= ioctl(fd_events, COUNTER_ENABLE_EVENTS_IOCTL) ? -errno : 0;
	result(!rc, "watches added and enabled");
	clear_event_counts();
	for (i = 0; i < 60; i++) {
		advance(23 + (i * 7) % 31);
		snprintf(when, sizeof(when), "events chunk %u", i);
		check_events(fd_events, ws, sizeof(ws) / sizeof(ws[0]), when);
		clear_event_counts();
		if (i % 10 == 9) {
			check_channels(when);
			result(rdu(cpath(1, "capture")) == ch[1].capture,
			       "%s: count1 capture %" PRIu64 " (expected %" PRIu64 ")", when,
			       rdu(cpath(1, "capture")), ch[1].capture);
			rd(cpath(0, "preset_enable"), buf, sizeof(buf));
			result(atoi(buf) == ch[0].preset_en, "%s: count0 preset_enable %s "
			       "(expected %d)", when, buf, ch[0].preset_en);
		}
	}
	ioctl(fd_events, COUNTER_DISABLE_EVENTS_IOCTL);

	/* the global snapshot: every count's snapshot_count, and a capture event */
	rc = add_watch(fd_events, COUNTER_EVENT_CAPTURE, 0, COUNTER_COMPONENT_COUNT, 0, 0);
	rc |= ioctl(fd_events, COUNTER_ENABLE_EVENTS_IOCTL) ? -errno : 0;
	advance(50);
	read(fd_events, buf, sizeof(buf));  /* nothing is watched but capture */
	rc |= wr(DEV "/snapshot", "1");
	rdu(DEV "/timebase");  /* one more access: the interrupt follows the snapshot */
	for (k = 0; k < nch; k++)
		result(rdu(cpath(k, "snapshot_count")) == ch[k].count,
		       "snapshot: count%u snapshot_count %" PRIu64 " (expected %" PRIu64 ")", k,
		       rdu(cpath(k, "snapshot_count")), ch[k].count);
	{
		struct counter_event ev[4];
		ssize_t n = read(fd_events, ev, sizeof(ev));

		result(!rc && n == sizeof(ev[0]) && ev[0].watch.event == COUNTER_EVENT_CAPTURE &&
		       ev[0].value == ch[0].count, "snapshot: one capture event on channel 0 "
		       "with its count (%zd bytes)", n);
	}
	ioctl(fd_events, COUNTER_DISABLE_EVENTS_IOCTL);
	result(rdu(DEV "/timebase_frequency") == 100000000, "timebase_frequency %" PRIu64,
	       rdu(DEV "/timebase_frequency"));

	/* writes the driver refuses, changing nothing */
	check_refused(cpath(2, "ceiling"), "4294967296", EINVAL);
	check_refused(cpath(0, "count"), "4294967296", EINVAL);
	check_refused(cpath(0, "preset"), "18446744073709551615", EINVAL);
	check_refused(cpath(0, "compare"), "4294967296", EINVAL);
	check_refused(cpath(2, "count_mode"), "sideways", EINVAL);
	check_refused(cpath(1, "function"), "quadrature x8", EINVAL);
	check_refused(cpath(1, "spike_filter_ns"), "1000", EINVAL);
	rc = add_watch(fd_events, COUNTER_EVENT_INDEX, nch, COUNTER_COMPONENT_COUNT, 0, 0);
	result(rc == -EINVAL, "a watch on event channel %u: %s (expected EINVAL)", nch,
	       strerror(-rc));
	rc = add_watch(fd_events, COUNTER_EVENT_INDEX, 0, COUNTER_COMPONENT_COUNT, nch, 0);
	result(rc == -EINVAL, "a watch on count%u: %s (expected EINVAL)", nch, strerror(-rc));
	rc = add_watch(fd_events, COUNTER_EVENT_CHANGE_OF_STATE, 0, COUNTER_COMPONENT_COUNT, 0,
		       0);
	result(rc == -EINVAL, "a change-of-state watch: %s (expected EINVAL)", strerror(-rc));
	rc = wr(cpath(nch, "count"), "1");
	result(rc == -ENOENT, "count%u does not exist: %s", nch, strerror(-rc));
	check_channels("after the refused writes");
}

static void test_lean(int fd_events)
{
	static const enum func x4[] = {X4};
	char buf[256];
	int rc;

	rd(DEV "/count0/function_available", buf, sizeof(buf));
	result(!strcmp(buf, "quadrature x4"), "function_available of the x4-only build: %s", buf);
	counting_rounds(x4, 1, 4);
	check_refused(cpath(1, "function"), "quadrature x2 a", EINVAL);
	rc = access(cpath(0, "ceiling"), F_OK) ? -errno : 0;
	result(rc == -ENOENT, "no ceiling in the lean profile (%s)", strerror(-rc));
	rc = access(cpath(0, "count_mode"), F_OK) ? -errno : 0;
	result(rc == -ENOENT, "no count_mode in the lean profile (%s)", strerror(-rc));

	/* 64-bit counts across bit 32 and across 0 */
	set_count(0, 0xffffff80ULL);
	set_count(1, 0x100000010ULL);
	advance(600);
	check_channels("64-bit");
	set_count(0, 2);
	set_count(1, 0);
	advance(700);
	check_channels("64-bit near 0");

	rc = wr(DEV "/snapshot", "1");
	for (unsigned int k = 0; k < nch; k++)
		result(!rc && rdu(cpath(k, "snapshot_count")) == ch[k].count,
		       "snapshot: count%u snapshot_count %" PRIu64 " (expected %" PRIu64 ")", k,
		       rdu(cpath(k, "snapshot_count")), ch[k].count);

	rc = add_watch(fd_events, COUNTER_EVENT_INDEX, 0, COUNTER_COMPONENT_COUNT, 0, 0);
	result(rc == -EOPNOTSUPP, "without an interrupt a watch is refused: %s (expected %s)",
	       strerror(-rc), strerror(EOPNOTSUPP));
}

static void finish(void)
{
	printf("init: %d passed, %d failed\n", passed, failed);
	fflush(stdout);
	sync();
	reboot(RB_POWER_OFF);
	for (;;)
		pause();
}

int main(void)
{
	const char *mode = getenv("enc_test") ?: "full";
	unsigned int k;
	char buf[256];
	int fd, rc;

	mount("proc", "/proc", "proc", 0, NULL);
	mount("sysfs", "/sys", "sysfs", 0, NULL);
	mount("debugfs", "/sys/kernel/debug", "debugfs", 0, NULL);
	mount("devtmpfs", "/dev", "devtmpfs", 0, NULL);
	nch = (unsigned int)atoi(getenv("enc_channels") ?: "1");
	count_w = (unsigned int)atoi(getenv("enc_count_w") ?: "32");
	printf("init: enc_test=%s, %u channels, %u-bit counts\n", mode, nch, count_w);

	fd = open("/enc-qei.ko", O_RDONLY);
	rc = fd < 0 ? -errno : syscall(SYS_finit_module, fd, "", 0) ? -errno : 0;
	result(rc == 0, "insmod enc-qei.ko: %s", rc ? strerror(-rc) : "loaded");
	if (!strcmp(mode, "refuse")) {
		rc = access(DEV, F_OK) ? -errno : 0;
		result(rc == -ENOENT, "the driver refused the device: no counter0 (%s)",
		       rc ? strerror(-rc) : "counter0 exists");
		finish();
	}
	check_kunit();
	rc = rd(DEV "/name", buf, sizeof(buf));
	result(!rc, "counter0 bound: %s", rc ? strerror(-rc) : buf);
	if (rc)
		finish();
	result(rdu(DEV "/num_counts") == nch, "num_counts %" PRIu64 " (expected %u)",
	       rdu(DEV "/num_counts"), nch);
	result(rdu(DEV "/num_signals") == 3 * nch, "num_signals %" PRIu64,
	       rdu(DEV "/num_signals"));
	for (k = 0; k < nch; k++) {
		char want[32];

		rd(cpath(k, "name"), buf, sizeof(buf));
		snprintf(want, sizeof(want), "channel%u", k);
		result(!strcmp(buf, want), "count%u name %s", k, buf);
		enc_stim_init(&ch[k].stim, k);
		ch[k].mask = count_w == 64 ? UINT64_MAX : (1ULL << count_w) - 1;
		ch[k].enabled = 1;
		ch[k].dir_up = 1;
		ch[k].func = X4;
	}
	snprintf(buf, sizeof(buf), DEV "/signal%u/name", 3 * nch - 1);
	{
		char name[64], want[64];

		rd(buf, name, sizeof(name));
		snprintf(want, sizeof(want), "channel%u Index", nch - 1);
		result(!strcmp(name, want), "signal%u name %s", 3 * nch - 1, name);
	}
	check_channels("after probe");

	fd = open("/dev/counter0", O_RDONLY | O_NONBLOCK);
	result(fd >= 0, "open /dev/counter0: %s", fd < 0 ? strerror(errno) : "ok");
	if (!strcmp(mode, "lean"))
		test_lean(fd);
	else
		test_full(fd);
	close(fd);

	rc = rd("/sys/kernel/debug/enc_qei_bridge/bus_errors", buf, sizeof(buf));
	result(!rc && !strcmp(buf, "0"), "no bus errors (%s)", buf);
	rc = syscall(SYS_delete_module, "enc_qei", O_NONBLOCK) ? -errno : 0;
	result(!rc && access(DEV, F_OK), "rmmod enc-qei: %s", rc ? strerror(-rc) : "unloaded");
	finish();
	return 0;
}
