// SPDX-License-Identifier: GPL-2.0
/*
 * Counter driver for the enc_qei quadrature encoder interface
 *
 * enc_qei is an FPGA peripheral with 1 to 16 encoder channels behind one
 * register window: a page of 0x100 bytes per channel, with the global
 * registers (ID, CAPS, timebase, global snapshot, interrupt summary) in
 * page 0. The build (number of channels, counter and timestamp widths,
 * profile) is read from CAPS. Each channel is one Count with three Signals
 * (A, B and Index).
 */

#include <linux/bitfield.h>
#include <linux/bitops.h>
#include <linux/clk.h>
#include <linux/counter.h>
#include <linux/interrupt.h>
#include <linux/io.h>
#include <linux/iopoll.h>
#include <linux/kernel.h>
#include <linux/math64.h>
#include <linux/mod_devicetable.h>
#include <linux/module.h>
#include <linux/platform_device.h>
#include <linux/slab.h>
#include <linux/spinlock.h>
#include <linux/types.h>

/* Global registers, in page 0 */
#define ENC_QEI_ID			0x00
#define ENC_QEI_CAPS			0x04
#define ENC_QEI_TIMEBASE		0x5c
#define ENC_QEI_TB_PRESCALE		0x60
#define ENC_QEI_GSNAP_CTRL		0x90
#define ENC_QEI_GSNAP_TIME		0x98
#define ENC_QEI_IRQ_SUMMARY		0x9c

/* Channel registers, at these offsets in the channel's page */
#define ENC_QEI_PAGE_SIZE		0x100
#define ENC_QEI_CTRL			0x08
#define ENC_QEI_STATUS			0x0c
#define ENC_QEI_COUNT_LO		0x10
#define ENC_QEI_COUNT_HI		0x14
#define ENC_QEI_PRESET_LO		0x18
#define ENC_QEI_PRESET_HI		0x1c
#define ENC_QEI_CEILING_LO		0x20
#define ENC_QEI_CEILING_HI		0x24
#define ENC_QEI_COMPARE_LO		0x28
#define ENC_QEI_COMPARE_HI		0x2c
#define ENC_QEI_INDEX_CTRL		0x30
#define ENC_QEI_INDEX_LATCH_LO		0x34
#define ENC_QEI_INDEX_LATCH_HI		0x38
#define ENC_QEI_EVENTS			0x4c
#define ENC_QEI_IRQ_EN			0x50
#define ENC_QEI_SNAP_COUNT_LO		0x6c
#define ENC_QEI_SNAP_COUNT_HI		0x70

#define ENC_QEI_ID_VERSION		GENMASK(15, 0)
#define ENC_QEI_ID_MAGIC		GENMASK(31, 16)
#define ENC_QEI_MAGIC			0x5145
#define ENC_QEI_VERSION_MAJOR		1
#define ENC_QEI_VERSION_MINOR_MIN	2

#define ENC_QEI_CAPS_COUNT_W		GENMASK(7, 0)
#define ENC_QEI_CAPS_TS_W		GENMASK(15, 8)
#define ENC_QEI_CAPS_TIMING		BIT(18)
#define ENC_QEI_CAPS_PROFILE		GENMASK(21, 19)
#define ENC_QEI_CAPS_CHANNELS		GENMASK(26, 22)
#define ENC_QEI_CAPS_ENGINE		BIT(31)
#define ENC_QEI_PROFILE_COUNTING	1
#define ENC_QEI_PROFILE_FULL		2
#define ENC_QEI_PROFILE_LEAN		3
#define ENC_QEI_MAX_CHANNELS		16

#define ENC_QEI_CTRL_EN			BIT(0)
#define ENC_QEI_CTRL_INV_A		BIT(2)
#define ENC_QEI_CTRL_INV_B		BIT(3)
#define ENC_QEI_CTRL_INV_Z		BIT(4)
#define ENC_QEI_CTRL_CMP_EN		BIT(5)
#define ENC_QEI_CTRL_FUNC		GENMASK(11, 8)
#define ENC_QEI_CTRL_RANGE		GENMASK(13, 12)
#define ENC_QEI_CTRL_FILTER_LEN		GENMASK(20, 16)

/* CTRL.FUNC values */
#define ENC_QEI_FUNC_X4			0
#define ENC_QEI_FUNC_X2A		1
#define ENC_QEI_FUNC_X2B		2
#define ENC_QEI_FUNC_X1A		3
#define ENC_QEI_FUNC_X1B		4
#define ENC_QEI_FUNC_PULSE_DIR		5
#define ENC_QEI_FUNC_INCREASE		6
#define ENC_QEI_FUNC_DECREASE		7

/* CTRL.RANGE values */
#define ENC_QEI_RANGE_FREE		0
#define ENC_QEI_RANGE_MODULO		1
#define ENC_QEI_RANGE_LIMIT		2
#define ENC_QEI_RANGE_NON_RECYCLE	3

#define ENC_QEI_FILTER_LEN_MAX		16

#define ENC_QEI_STATUS_A		BIT(0)
#define ENC_QEI_STATUS_B		BIT(1)
#define ENC_QEI_STATUS_Z		BIT(2)
#define ENC_QEI_STATUS_DIR		BIT(3)

#define ENC_QEI_INDEX_CTRL_ACTION	GENMASK(1, 0)
#define ENC_QEI_INDEX_CTRL_ONESHOT	BIT(2)
#define ENC_QEI_INDEX_CTRL_ARM		BIT(8)
#define ENC_QEI_INDEX_ACTION_NONE	0
#define ENC_QEI_INDEX_ACTION_PRESET	1
#define ENC_QEI_INDEX_ACTION_LATCH	2

#define ENC_QEI_EV_OVERFLOW		BIT(0)
#define ENC_QEI_EV_UNDERFLOW		BIT(1)
#define ENC_QEI_EV_INDEX		BIT(2)
#define ENC_QEI_EV_CMP			BIT(4)
#define ENC_QEI_EV_QERR			BIT(5)
#define ENC_QEI_EV_GLITCH		BIT(6)
#define ENC_QEI_EV_SNAP_READY		BIT(9)
#define ENC_QEI_EV_ALL			GENMASK(13, 0)

#define ENC_QEI_TB_PRESCALE_PRESCALE	GENMASK(15, 0)
#define ENC_QEI_GSNAP_CTRL_CMD		BIT(0)

/* The shared engine visits each channel in 24 clocks, at least two visits */
#define ENC_QEI_ENGINE_VISIT_CLOCKS	24
#define ENC_QEI_ENGINE_MIN_VISITS	2U
/* Give up on a snapshot the timebase does not time (broken hardware) */
#define ENC_QEI_SNAPSHOT_TIMEOUT_US	USEC_PER_SEC

/* Signals of channel k: 3k + ENC_QEI_SIGNAL_x */
enum enc_qei_signal {
	ENC_QEI_SIGNAL_A,
	ENC_QEI_SIGNAL_B,
	ENC_QEI_SIGNAL_INDEX,
	ENC_QEI_SIGNALS_PER_CHANNEL,
};

/**
 * struct enc_qei_caps - the build, as CAPS describes it
 * @channels:	number of channels (Counts)
 * @count_w:	counter width in bits
 * @ts_w:	timebase width in bits
 * @profile:	CAPS.PROFILE
 * @has_range:	CEILING, COMPARE and CTRL.RANGE are built (not lean)
 * @has_timing:	timebase, snapshots and the global snapshot are built
 * @engine:	CAPS.ENGINE: the channels share one engine, which shows
 *		changes and lets writes act later, by bounds in clocks
 */
struct enc_qei_caps {
	unsigned int channels;
	unsigned int count_w;
	unsigned int ts_w;
	unsigned int profile;
	bool has_range;
	bool has_timing;
	bool engine;
};

/**
 * struct enc_qei_priv - driver data
 * @base:		register window
 * @lock:		serializes register accesses (COUNT_LO latches
 *			COUNT_HI, read-modify-writes of CTRL and INDEX_CTRL)
 * @caps:		the build
 * @count_max:		largest count, 2^COUNT_W - 1
 * @clk_rate:		bus clock rate in Hz
 * @has_irq:		the device has an interrupt: events are available
 * @irq_en:		IRQ_EN of each channel, as written
 * @functions:		count functions the build has
 * @num_functions:	number of entries in @functions
 */
struct enc_qei_priv {
	void __iomem *base;
	spinlock_t lock; /* serializes register accesses */
	struct enc_qei_caps caps;
	u64 count_max;
	unsigned long clk_rate;
	bool has_irq;
	u32 irq_en[ENC_QEI_MAX_CHANNELS];
	enum counter_function functions[8];
	size_t num_functions;
};

/* CTRL.FUNC value -> Generic Counter function, for the functions Linux has */
static const enum counter_function enc_qei_func_map[] = {
	[ENC_QEI_FUNC_X4] = COUNTER_FUNCTION_QUADRATURE_X4,
	[ENC_QEI_FUNC_X2A] = COUNTER_FUNCTION_QUADRATURE_X2_A,
	[ENC_QEI_FUNC_X2B] = COUNTER_FUNCTION_QUADRATURE_X2_B,
	[ENC_QEI_FUNC_X1A] = COUNTER_FUNCTION_QUADRATURE_X1_A,
	[ENC_QEI_FUNC_X1B] = COUNTER_FUNCTION_QUADRATURE_X1_B,
	[ENC_QEI_FUNC_PULSE_DIR] = COUNTER_FUNCTION_PULSE_DIRECTION,
	[ENC_QEI_FUNC_INCREASE] = COUNTER_FUNCTION_INCREASE,
	[ENC_QEI_FUNC_DECREASE] = COUNTER_FUNCTION_DECREASE,
};

static int enc_qei_check_id(u32 id)
{
	u32 version = FIELD_GET(ENC_QEI_ID_VERSION, id);

	if (FIELD_GET(ENC_QEI_ID_MAGIC, id) != ENC_QEI_MAGIC)
		return -ENODEV;
	if (version >> 8 != ENC_QEI_VERSION_MAJOR ||
	    (version & 0xff) < ENC_QEI_VERSION_MINOR_MIN)
		return -EOPNOTSUPP;
	return 0;
}

static int enc_qei_parse_caps(u32 word, struct enc_qei_caps *caps)
{
	caps->channels = FIELD_GET(ENC_QEI_CAPS_CHANNELS, word);
	caps->count_w = FIELD_GET(ENC_QEI_CAPS_COUNT_W, word);
	caps->ts_w = FIELD_GET(ENC_QEI_CAPS_TS_W, word);
	caps->profile = FIELD_GET(ENC_QEI_CAPS_PROFILE, word);
	caps->has_timing = word & ENC_QEI_CAPS_TIMING;
	caps->engine = word & ENC_QEI_CAPS_ENGINE;
	caps->has_range = caps->profile == ENC_QEI_PROFILE_FULL ||
			  caps->profile == ENC_QEI_PROFILE_COUNTING;

	if (caps->channels < 1 || caps->channels > ENC_QEI_MAX_CHANNELS ||
	    caps->count_w < 8 || caps->count_w > 64 ||
	    caps->ts_w < 16 || caps->ts_w > 32 ||
	    (!caps->has_range && caps->profile != ENC_QEI_PROFILE_LEAN))
		return -EINVAL;
	return 0;
}

static int enc_qei_func_to_function(u32 func, enum counter_function *function)
{
	if (func >= ARRAY_SIZE(enc_qei_func_map))
		return -EINVAL;
	*function = enc_qei_func_map[func];
	return 0;
}

static int enc_qei_function_to_func(enum counter_function function, u32 *func)
{
	u32 i;

	for (i = 0; i < ARRAY_SIZE(enc_qei_func_map); i++) {
		if (enc_qei_func_map[i] == function) {
			*func = i;
			return 0;
		}
	}
	return -EINVAL;
}

static enum counter_synapse_action
enc_qei_action(enum counter_function function, enum enc_qei_signal signal,
	       bool forward)
{
	enum counter_synapse_action x1 = forward ?
		COUNTER_SYNAPSE_ACTION_RISING_EDGE :
		COUNTER_SYNAPSE_ACTION_FALLING_EDGE;

	if (signal == ENC_QEI_SIGNAL_INDEX)
		return COUNTER_SYNAPSE_ACTION_NONE;

	switch (function) {
	case COUNTER_FUNCTION_QUADRATURE_X4:
		return COUNTER_SYNAPSE_ACTION_BOTH_EDGES;
	case COUNTER_FUNCTION_QUADRATURE_X2_A:
		return signal == ENC_QEI_SIGNAL_A ?
			COUNTER_SYNAPSE_ACTION_BOTH_EDGES :
			COUNTER_SYNAPSE_ACTION_NONE;
	case COUNTER_FUNCTION_QUADRATURE_X2_B:
		return signal == ENC_QEI_SIGNAL_B ?
			COUNTER_SYNAPSE_ACTION_BOTH_EDGES :
			COUNTER_SYNAPSE_ACTION_NONE;
	case COUNTER_FUNCTION_QUADRATURE_X1_A:
		return signal == ENC_QEI_SIGNAL_A ? x1 :
			COUNTER_SYNAPSE_ACTION_NONE;
	case COUNTER_FUNCTION_QUADRATURE_X1_B:
		return signal == ENC_QEI_SIGNAL_B ? x1 :
			COUNTER_SYNAPSE_ACTION_NONE;
	default:
		/* pulse-direction, increase, decrease: rising edges of A */
		return signal == ENC_QEI_SIGNAL_A ?
			COUNTER_SYNAPSE_ACTION_RISING_EDGE :
			COUNTER_SYNAPSE_ACTION_NONE;
	}
}

/* The EVENTS bits behind a Generic Counter event, 0 if the build has none */
static u32 enc_qei_event_bits(u8 event, const struct enc_qei_caps *caps)
{
	switch (event) {
	case COUNTER_EVENT_OVERFLOW:
		return ENC_QEI_EV_OVERFLOW;
	case COUNTER_EVENT_UNDERFLOW:
		return ENC_QEI_EV_UNDERFLOW;
	case COUNTER_EVENT_OVERFLOW_UNDERFLOW:
		return ENC_QEI_EV_OVERFLOW | ENC_QEI_EV_UNDERFLOW;
	case COUNTER_EVENT_THRESHOLD:
		return caps->has_range ? ENC_QEI_EV_CMP : 0;
	case COUNTER_EVENT_INDEX:
		return ENC_QEI_EV_INDEX;
	case COUNTER_EVENT_CAPTURE:
		return caps->has_timing ? ENC_QEI_EV_SNAP_READY : 0;
	default:
		return 0;
	}
}

/*
 * Timebase ticks from a global snapshot command until every channel's
 * SNAP_* registers read it: none beyond the next read on a per_channel
 * build. The shared engine (CAPS.ENGINE) takes the snapshot in the
 * command's snapshot clock (its request + 3) or up to P clocks later, while
 * a channel's capture waits, and shows it P + 44 clocks after the clock a
 * per_channel build shows it in, P = 24 * max(CHANNELS, 2) (the bounds of
 * rtl/enc_qei.rdl): 2P + 48 clocks from the command's request. One tick
 * more covers the prescaler's phase and the reads' own clocks.
 */
static u32 enc_qei_snapshot_ticks(const struct enc_qei_caps *caps,
				  u32 prescale)
{
	u32 p = ENC_QEI_ENGINE_VISIT_CLOCKS *
		max(caps->channels, ENC_QEI_ENGINE_MIN_VISITS);

	if (!caps->engine)
		return 0;
	return DIV_ROUND_UP(2 * p + 48, prescale + 1) + 1;
}

/* Pulses up to (FILTER_LEN - 1) clock periods are rejected */
static u64 enc_qei_filter_ns(u32 filter_len, unsigned long rate)
{
	filter_len = clamp_t(u32, filter_len, 1, ENC_QEI_FILTER_LEN_MAX);
	return div_u64((u64)(filter_len - 1) * NSEC_PER_SEC, rate);
}

static int enc_qei_filter_len(u64 ns, unsigned long rate, u32 *filter_len)
{
	u64 clocks;

	if (ns > NSEC_PER_SEC)
		return -EINVAL;
	clocks = DIV_ROUND_UP_ULL(ns * rate, NSEC_PER_SEC);
	if (clocks + 1 > ENC_QEI_FILTER_LEN_MAX)
		return -EINVAL;
	*filter_len = clocks + 1;
	return 0;
}

static u32 enc_qei_read(struct enc_qei_priv *priv, unsigned int chan,
			unsigned int reg)
{
	return readl(priv->base + chan * ENC_QEI_PAGE_SIZE + reg);
}

static void enc_qei_write(struct enc_qei_priv *priv, unsigned int chan,
			  unsigned int reg, u32 val)
{
	writel(val, priv->base + chan * ENC_QEI_PAGE_SIZE + reg);
}

/* A 64-bit pair: LO first (reading COUNT_LO latches COUNT_HI) */
static u64 enc_qei_read64(struct enc_qei_priv *priv, unsigned int chan,
			  unsigned int reg_lo, unsigned int reg_hi)
{
	unsigned long flags;
	u64 val;

	spin_lock_irqsave(&priv->lock, flags);
	val = enc_qei_read(priv, chan, reg_lo);
	if (priv->caps.count_w > 32)
		val |= (u64)enc_qei_read(priv, chan, reg_hi) << 32;
	spin_unlock_irqrestore(&priv->lock, flags);

	return val;
}

/* A 64-bit pair: HI first (writing COUNT_LO loads the staged COUNT_HI) */
static int enc_qei_write64(struct enc_qei_priv *priv, unsigned int chan,
			   unsigned int reg_lo, unsigned int reg_hi, u64 val)
{
	unsigned long flags;

	if (val > priv->count_max)
		return -EINVAL;

	spin_lock_irqsave(&priv->lock, flags);
	enc_qei_write(priv, chan, reg_hi, upper_32_bits(val));
	enc_qei_write(priv, chan, reg_lo, lower_32_bits(val));
	spin_unlock_irqrestore(&priv->lock, flags);

	return 0;
}

static void enc_qei_update(struct enc_qei_priv *priv, unsigned int chan,
			   unsigned int reg, u32 mask, u32 val)
{
	unsigned long flags;
	u32 old;

	spin_lock_irqsave(&priv->lock, flags);
	old = enc_qei_read(priv, chan, reg);
	enc_qei_write(priv, chan, reg, (old & ~mask) | (val & mask));
	spin_unlock_irqrestore(&priv->lock, flags);
}

static int enc_qei_count_read(struct counter_device *counter,
			      struct counter_count *count, u64 *val)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	*val = enc_qei_read64(priv, count->id, ENC_QEI_COUNT_LO,
			      ENC_QEI_COUNT_HI);
	return 0;
}

static int enc_qei_count_write(struct counter_device *counter,
			       struct counter_count *count, u64 val)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	int ret;

	ret = enc_qei_write64(priv, count->id, ENC_QEI_COUNT_LO,
			      ENC_QEI_COUNT_HI, val);
	if (ret)
		return ret;
	/* a count write clears error_noise */
	enc_qei_write(priv, count->id, ENC_QEI_EVENTS,
		      ENC_QEI_EV_QERR | ENC_QEI_EV_GLITCH);
	return 0;
}

static int enc_qei_function_read(struct counter_device *counter,
				 struct counter_count *count,
				 enum counter_function *function)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 ctrl = enc_qei_read(priv, count->id, ENC_QEI_CTRL);

	return enc_qei_func_to_function(FIELD_GET(ENC_QEI_CTRL_FUNC, ctrl),
					function);
}

static int enc_qei_function_write(struct counter_device *counter,
				  struct counter_count *count,
				  enum counter_function function)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 func;
	int ret;

	ret = enc_qei_function_to_func(function, &func);
	if (ret)
		return ret;
	enc_qei_update(priv, count->id, ENC_QEI_CTRL, ENC_QEI_CTRL_FUNC,
		       FIELD_PREP(ENC_QEI_CTRL_FUNC, func));
	return 0;
}

static int enc_qei_action_read(struct counter_device *counter,
			       struct counter_count *count,
			       struct counter_synapse *synapse,
			       enum counter_synapse_action *action)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	enum counter_function function;
	u32 status;
	int ret;

	ret = enc_qei_function_read(counter, count, &function);
	if (ret)
		return ret;
	status = enc_qei_read(priv, count->id, ENC_QEI_STATUS);
	*action = enc_qei_action(function,
				 synapse->signal->id % ENC_QEI_SIGNALS_PER_CHANNEL,
				 status & ENC_QEI_STATUS_DIR);
	return 0;
}

static int enc_qei_signal_read(struct counter_device *counter,
			       struct counter_signal *signal,
			       enum counter_signal_level *level)
{
	static const u32 status_bit[] = {
		ENC_QEI_STATUS_A, ENC_QEI_STATUS_B, ENC_QEI_STATUS_Z,
	};
	struct enc_qei_priv *priv = counter_priv(counter);
	unsigned int chan = signal->id / ENC_QEI_SIGNALS_PER_CHANNEL;
	u32 status = enc_qei_read(priv, chan, ENC_QEI_STATUS);

	*level = status & status_bit[signal->id % ENC_QEI_SIGNALS_PER_CHANNEL] ?
		 COUNTER_SIGNAL_LEVEL_HIGH : COUNTER_SIGNAL_LEVEL_LOW;
	return 0;
}

static int enc_qei_watch_validate(struct counter_device *counter,
				  const struct counter_watch *watch)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	if (!priv->has_irq)
		return -EOPNOTSUPP;
	if (watch->channel >= priv->caps.channels ||
	    !enc_qei_event_bits(watch->event, &priv->caps))
		return -EINVAL;
	return 0;
}

static int enc_qei_events_configure(struct counter_device *counter)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 irq_en[ENC_QEI_MAX_CHANNELS] = { 0 };
	struct counter_event_node *node;
	unsigned long flags;
	unsigned int k;

	list_for_each_entry(node, &counter->events_list, l)
		irq_en[node->channel] |= enc_qei_event_bits(node->event,
							    &priv->caps);

	spin_lock_irqsave(&priv->lock, flags);
	for (k = 0; k < priv->caps.channels; k++) {
		if (irq_en[k] == priv->irq_en[k])
			continue;
		/* forget what happened before the watch began */
		enc_qei_write(priv, k, ENC_QEI_EVENTS,
			      irq_en[k] & ~priv->irq_en[k]);
		enc_qei_write(priv, k, ENC_QEI_IRQ_EN, irq_en[k]);
		priv->irq_en[k] = irq_en[k];
	}
	spin_unlock_irqrestore(&priv->lock, flags);

	return 0;
}

static void enc_qei_push_events(struct counter_device *counter,
				unsigned int chan, u32 events)
{
	if (events & ENC_QEI_EV_OVERFLOW)
		counter_push_event(counter, COUNTER_EVENT_OVERFLOW, chan);
	if (events & ENC_QEI_EV_UNDERFLOW)
		counter_push_event(counter, COUNTER_EVENT_UNDERFLOW, chan);
	if (events & (ENC_QEI_EV_OVERFLOW | ENC_QEI_EV_UNDERFLOW))
		counter_push_event(counter, COUNTER_EVENT_OVERFLOW_UNDERFLOW,
				   chan);
	if (events & ENC_QEI_EV_CMP)
		counter_push_event(counter, COUNTER_EVENT_THRESHOLD, chan);
	if (events & ENC_QEI_EV_INDEX)
		counter_push_event(counter, COUNTER_EVENT_INDEX, chan);
	if (events & ENC_QEI_EV_SNAP_READY)
		counter_push_event(counter, COUNTER_EVENT_CAPTURE, chan);
}

static irqreturn_t enc_qei_irq_handler(int irq, void *data)
{
	struct counter_device *counter = data;
	struct enc_qei_priv *priv = counter_priv(counter);
	irqreturn_t ret = IRQ_NONE;
	unsigned long pending;
	unsigned int k;
	u32 events;

	for (;;) {
		pending = enc_qei_read(priv, 0, ENC_QEI_IRQ_SUMMARY) &
			  GENMASK(priv->caps.channels - 1, 0);
		if (!pending)
			return ret;
		ret = IRQ_HANDLED;

		for_each_set_bit(k, &pending, priv->caps.channels) {
			spin_lock(&priv->lock);
			events = enc_qei_read(priv, k, ENC_QEI_EVENTS) &
				 priv->irq_en[k];
			enc_qei_write(priv, k, ENC_QEI_EVENTS, events);
			spin_unlock(&priv->lock);

			enc_qei_push_events(counter, k, events);
		}
	}
}

static const struct counter_ops enc_qei_ops = {
	.signal_read = enc_qei_signal_read,
	.count_read = enc_qei_count_read,
	.count_write = enc_qei_count_write,
	.function_read = enc_qei_function_read,
	.function_write = enc_qei_function_write,
	.action_read = enc_qei_action_read,
	.events_configure = enc_qei_events_configure,
	.watch_validate = enc_qei_watch_validate,
};

/* Count extensions every build has */

static int enc_qei_direction_read(struct counter_device *counter,
				  struct counter_count *count, u32 *direction)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 status = enc_qei_read(priv, count->id, ENC_QEI_STATUS);

	*direction = status & ENC_QEI_STATUS_DIR ?
		     COUNTER_COUNT_DIRECTION_FORWARD :
		     COUNTER_COUNT_DIRECTION_BACKWARD;
	return 0;
}

static int enc_qei_enable_read(struct counter_device *counter,
			       struct counter_count *count, u8 *enable)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	*enable = !!(enc_qei_read(priv, count->id, ENC_QEI_CTRL) &
		     ENC_QEI_CTRL_EN);
	return 0;
}

static int enc_qei_enable_write(struct counter_device *counter,
				struct counter_count *count, u8 enable)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	enc_qei_update(priv, count->id, ENC_QEI_CTRL, ENC_QEI_CTRL_EN,
		       enable ? ENC_QEI_CTRL_EN : 0);
	return 0;
}

static int enc_qei_preset_read(struct counter_device *counter,
			       struct counter_count *count, u64 *preset)
{
	*preset = enc_qei_read64(counter_priv(counter), count->id,
				 ENC_QEI_PRESET_LO, ENC_QEI_PRESET_HI);
	return 0;
}

static int enc_qei_preset_write(struct counter_device *counter,
				struct counter_count *count, u64 preset)
{
	return enc_qei_write64(counter_priv(counter), count->id,
			       ENC_QEI_PRESET_LO, ENC_QEI_PRESET_HI, preset);
}

/* Whether the index performs @action (INDEX_CTRL.ACTION, armed) */
static bool enc_qei_index_does(struct enc_qei_priv *priv, unsigned int chan,
			       u32 action)
{
	u32 index_ctrl = enc_qei_read(priv, chan, ENC_QEI_INDEX_CTRL);

	return FIELD_GET(ENC_QEI_INDEX_CTRL_ACTION, index_ctrl) == action &&
	       (index_ctrl & ENC_QEI_INDEX_CTRL_ARM);
}

/* Enable: the index performs @action; disable: it performs none */
static void enc_qei_index_set(struct enc_qei_priv *priv, unsigned int chan,
			      u32 action, bool enable)
{
	unsigned long flags;
	u32 index_ctrl;

	spin_lock_irqsave(&priv->lock, flags);
	index_ctrl = enc_qei_read(priv, chan, ENC_QEI_INDEX_CTRL);
	if (enable) {
		index_ctrl &= ~ENC_QEI_INDEX_CTRL_ACTION;
		index_ctrl |= FIELD_PREP(ENC_QEI_INDEX_CTRL_ACTION, action) |
			      ENC_QEI_INDEX_CTRL_ARM;
	} else if (FIELD_GET(ENC_QEI_INDEX_CTRL_ACTION, index_ctrl) == action) {
		index_ctrl &= ~ENC_QEI_INDEX_CTRL_ACTION;
	}
	enc_qei_write(priv, chan, ENC_QEI_INDEX_CTRL, index_ctrl);
	spin_unlock_irqrestore(&priv->lock, flags);
}

static int enc_qei_preset_enable_read(struct counter_device *counter,
				      struct counter_count *count, u8 *enable)
{
	*enable = enc_qei_index_does(counter_priv(counter), count->id,
				     ENC_QEI_INDEX_ACTION_PRESET);
	return 0;
}

static int enc_qei_preset_enable_write(struct counter_device *counter,
				       struct counter_count *count, u8 enable)
{
	enc_qei_index_set(counter_priv(counter), count->id,
			  ENC_QEI_INDEX_ACTION_PRESET, enable);
	return 0;
}

static int enc_qei_capture_read(struct counter_device *counter,
				struct counter_count *count, u64 *capture)
{
	*capture = enc_qei_read64(counter_priv(counter), count->id,
				  ENC_QEI_INDEX_LATCH_LO,
				  ENC_QEI_INDEX_LATCH_HI);
	return 0;
}

static int enc_qei_capture_enable_read(struct counter_device *counter,
				       struct counter_count *count, u8 *enable)
{
	*enable = enc_qei_index_does(counter_priv(counter), count->id,
				     ENC_QEI_INDEX_ACTION_LATCH);
	return 0;
}

static int enc_qei_capture_enable_write(struct counter_device *counter,
					struct counter_count *count, u8 enable)
{
	enc_qei_index_set(counter_priv(counter), count->id,
			  ENC_QEI_INDEX_ACTION_LATCH, enable);
	return 0;
}

static int enc_qei_index_oneshot_read(struct counter_device *counter,
				      struct counter_count *count, u8 *oneshot)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	*oneshot = !!(enc_qei_read(priv, count->id, ENC_QEI_INDEX_CTRL) &
		      ENC_QEI_INDEX_CTRL_ONESHOT);
	return 0;
}

static int enc_qei_index_oneshot_write(struct counter_device *counter,
				       struct counter_count *count, u8 oneshot)
{
	enc_qei_update(counter_priv(counter), count->id, ENC_QEI_INDEX_CTRL,
		       ENC_QEI_INDEX_CTRL_ONESHOT,
		       oneshot ? ENC_QEI_INDEX_CTRL_ONESHOT : 0);
	return 0;
}

static const char *const enc_qei_noise_states[] = {
	"No excessive noise is present at the count inputs",
	"Excessive noise is present at the count inputs",
};

static DEFINE_COUNTER_ENUM(enc_qei_noise_enum, enc_qei_noise_states);

static int enc_qei_error_noise_read(struct counter_device *counter,
				    struct counter_count *count, u32 *noise)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	*noise = !!(enc_qei_read(priv, count->id, ENC_QEI_EVENTS) &
		    (ENC_QEI_EV_QERR | ENC_QEI_EV_GLITCH));
	return 0;
}

static int enc_qei_spike_filter_ns_read(struct counter_device *counter,
					struct counter_count *count, u64 *ns)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 ctrl = enc_qei_read(priv, count->id, ENC_QEI_CTRL);

	*ns = enc_qei_filter_ns(FIELD_GET(ENC_QEI_CTRL_FILTER_LEN, ctrl),
				priv->clk_rate);
	return 0;
}

static int enc_qei_spike_filter_ns_write(struct counter_device *counter,
					 struct counter_count *count, u64 ns)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 filter_len;
	int ret;

	ret = enc_qei_filter_len(ns, priv->clk_rate, &filter_len);
	if (ret)
		return ret;
	enc_qei_update(priv, count->id, ENC_QEI_CTRL, ENC_QEI_CTRL_FILTER_LEN,
		       FIELD_PREP(ENC_QEI_CTRL_FILTER_LEN, filter_len));
	return 0;
}

/* Count extensions of the builds with ranges and compare (not lean) */

static int enc_qei_ceiling_read(struct counter_device *counter,
				struct counter_count *count, u64 *ceiling)
{
	*ceiling = enc_qei_read64(counter_priv(counter), count->id,
				  ENC_QEI_CEILING_LO, ENC_QEI_CEILING_HI);
	return 0;
}

static int enc_qei_ceiling_write(struct counter_device *counter,
				 struct counter_count *count, u64 ceiling)
{
	return enc_qei_write64(counter_priv(counter), count->id,
			       ENC_QEI_CEILING_LO, ENC_QEI_CEILING_HI, ceiling);
}

static int enc_qei_floor_read(struct counter_device *counter,
			      struct counter_count *count, u64 *floor)
{
	*floor = 0;
	return 0;
}

/* CTRL.RANGE value -> count mode */
static const enum counter_count_mode enc_qei_count_modes[] = {
	[ENC_QEI_RANGE_FREE] = COUNTER_COUNT_MODE_NORMAL,
	[ENC_QEI_RANGE_MODULO] = COUNTER_COUNT_MODE_MODULO_N,
	[ENC_QEI_RANGE_LIMIT] = COUNTER_COUNT_MODE_RANGE_LIMIT,
	[ENC_QEI_RANGE_NON_RECYCLE] = COUNTER_COUNT_MODE_NON_RECYCLE,
};

static DEFINE_COUNTER_AVAILABLE(enc_qei_count_modes_available,
				enc_qei_count_modes);

static int enc_qei_count_mode_read(struct counter_device *counter,
				   struct counter_count *count, u32 *mode)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 ctrl = enc_qei_read(priv, count->id, ENC_QEI_CTRL);

	*mode = enc_qei_count_modes[FIELD_GET(ENC_QEI_CTRL_RANGE, ctrl)];
	return 0;
}

static int enc_qei_count_mode_write(struct counter_device *counter,
				    struct counter_count *count, u32 mode)
{
	u32 range;

	for (range = 0; range < ARRAY_SIZE(enc_qei_count_modes); range++) {
		if (enc_qei_count_modes[range] != mode)
			continue;
		enc_qei_update(counter_priv(counter), count->id, ENC_QEI_CTRL,
			       ENC_QEI_CTRL_RANGE,
			       FIELD_PREP(ENC_QEI_CTRL_RANGE, range));
		return 0;
	}
	return -EINVAL;
}

static int enc_qei_compare_read(struct counter_device *counter,
				struct counter_count *count, u64 *compare)
{
	*compare = enc_qei_read64(counter_priv(counter), count->id,
				  ENC_QEI_COMPARE_LO, ENC_QEI_COMPARE_HI);
	return 0;
}

static int enc_qei_compare_write(struct counter_device *counter,
				 struct counter_count *count, u64 compare)
{
	return enc_qei_write64(counter_priv(counter), count->id,
			       ENC_QEI_COMPARE_LO, ENC_QEI_COMPARE_HI, compare);
}

static int enc_qei_compare_enable_read(struct counter_device *counter,
				       struct counter_count *count, u8 *enable)
{
	struct enc_qei_priv *priv = counter_priv(counter);

	*enable = !!(enc_qei_read(priv, count->id, ENC_QEI_CTRL) &
		     ENC_QEI_CTRL_CMP_EN);
	return 0;
}

static int enc_qei_compare_enable_write(struct counter_device *counter,
					struct counter_count *count, u8 enable)
{
	enc_qei_update(counter_priv(counter), count->id, ENC_QEI_CTRL,
		       ENC_QEI_CTRL_CMP_EN, enable ? ENC_QEI_CTRL_CMP_EN : 0);
	return 0;
}

/* Count and device extensions of the builds with the timing unit */

static int enc_qei_snapshot_count_read(struct counter_device *counter,
				       struct counter_count *count, u64 *val)
{
	*val = enc_qei_read64(counter_priv(counter), count->id,
			      ENC_QEI_SNAP_COUNT_LO, ENC_QEI_SNAP_COUNT_HI);
	return 0;
}

static int enc_qei_snapshot_read(struct counter_device *counter, u8 *val)
{
	*val = 0;
	return 0;
}

/*
 * A global snapshot; the write returns once every channel's snapshot_count
 * reads it. The shared engine shows it later than the next read (see
 * enc_qei_snapshot_ticks()): the timebase times the wait, so the wait
 * follows the peripheral's clock, however slow the bus between.
 */
static int enc_qei_snapshot_write(struct counter_device *counter, u8 val)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 mask = GENMASK(priv->caps.ts_w - 1, 0);
	u32 ticks, t0, t;

	if (!val)
		return 0;
	ticks = enc_qei_snapshot_ticks(&priv->caps,
				       FIELD_GET(ENC_QEI_TB_PRESCALE_PRESCALE,
						 enc_qei_read(priv, 0,
							      ENC_QEI_TB_PRESCALE)));
	t0 = enc_qei_read(priv, 0, ENC_QEI_TIMEBASE);
	enc_qei_update(priv, 0, ENC_QEI_GSNAP_CTRL, ENC_QEI_GSNAP_CTRL_CMD,
		       ENC_QEI_GSNAP_CTRL_CMD);
	if (!ticks)
		return 0;
	return readl_poll_timeout(priv->base + ENC_QEI_TIMEBASE, t,
				  ((t - t0) & mask) >= ticks, 0,
				  ENC_QEI_SNAPSHOT_TIMEOUT_US);
}

static int enc_qei_snapshot_time_read(struct counter_device *counter,
				      u64 *val)
{
	*val = enc_qei_read(counter_priv(counter), 0, ENC_QEI_GSNAP_TIME);
	return 0;
}

static int enc_qei_timebase_read(struct counter_device *counter, u64 *val)
{
	*val = enc_qei_read(counter_priv(counter), 0, ENC_QEI_TIMEBASE);
	return 0;
}

static int enc_qei_timebase_frequency_read(struct counter_device *counter,
					   u64 *val)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	u32 prescale = FIELD_GET(ENC_QEI_TB_PRESCALE_PRESCALE,
				 enc_qei_read(priv, 0, ENC_QEI_TB_PRESCALE));

	*val = div_u64(priv->clk_rate, prescale + 1);
	return 0;
}

/* Signal extensions */

static const u32 enc_qei_signal_inv[] = {
	ENC_QEI_CTRL_INV_A, ENC_QEI_CTRL_INV_B, ENC_QEI_CTRL_INV_Z,
};

static const enum counter_signal_polarity enc_qei_polarities[] = {
	COUNTER_SIGNAL_POLARITY_POSITIVE,
	COUNTER_SIGNAL_POLARITY_NEGATIVE,
};

static DEFINE_COUNTER_AVAILABLE(enc_qei_polarities_available,
				enc_qei_polarities);

static int enc_qei_polarity_read(struct counter_device *counter,
				 struct counter_signal *signal, u32 *polarity)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	unsigned int chan = signal->id / ENC_QEI_SIGNALS_PER_CHANNEL;
	u32 inv = enc_qei_signal_inv[signal->id % ENC_QEI_SIGNALS_PER_CHANNEL];

	*polarity = enc_qei_read(priv, chan, ENC_QEI_CTRL) & inv ?
		    COUNTER_SIGNAL_POLARITY_NEGATIVE :
		    COUNTER_SIGNAL_POLARITY_POSITIVE;
	return 0;
}

static int enc_qei_polarity_write(struct counter_device *counter,
				  struct counter_signal *signal, u32 polarity)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	unsigned int chan = signal->id / ENC_QEI_SIGNALS_PER_CHANNEL;
	u32 inv = enc_qei_signal_inv[signal->id % ENC_QEI_SIGNALS_PER_CHANNEL];

	enc_qei_update(priv, chan, ENC_QEI_CTRL, inv,
		       polarity == COUNTER_SIGNAL_POLARITY_NEGATIVE ? inv : 0);
	return 0;
}

static struct counter_comp enc_qei_signal_ext[] = {
	COUNTER_COMP_POLARITY(enc_qei_polarity_read, enc_qei_polarity_write,
			      enc_qei_polarities_available),
};

static struct counter_comp enc_qei_count_ext_all[] = {
	COUNTER_COMP_DIRECTION(enc_qei_direction_read),
	COUNTER_COMP_ENABLE(enc_qei_enable_read, enc_qei_enable_write),
	COUNTER_COMP_PRESET(enc_qei_preset_read, enc_qei_preset_write),
	COUNTER_COMP_PRESET_ENABLE(enc_qei_preset_enable_read,
				   enc_qei_preset_enable_write),
	COUNTER_COMP_CAPTURE(enc_qei_capture_read, NULL),
	COUNTER_COMP_COUNT_BOOL("capture_enable", enc_qei_capture_enable_read,
				enc_qei_capture_enable_write),
	COUNTER_COMP_COUNT_BOOL("index_oneshot", enc_qei_index_oneshot_read,
				enc_qei_index_oneshot_write),
	COUNTER_COMP_COUNT_ENUM("error_noise", enc_qei_error_noise_read, NULL,
				enc_qei_noise_enum),
	COUNTER_COMP_COUNT_U64("spike_filter_ns", enc_qei_spike_filter_ns_read,
			       enc_qei_spike_filter_ns_write),
};

static struct counter_comp enc_qei_count_ext_range[] = {
	COUNTER_COMP_CEILING(enc_qei_ceiling_read, enc_qei_ceiling_write),
	COUNTER_COMP_FLOOR(enc_qei_floor_read, NULL),
	COUNTER_COMP_COUNT_MODE(enc_qei_count_mode_read,
				enc_qei_count_mode_write,
				enc_qei_count_modes_available),
	COUNTER_COMP_COUNT_U64("compare", enc_qei_compare_read,
			       enc_qei_compare_write),
	COUNTER_COMP_COUNT_BOOL("compare_enable", enc_qei_compare_enable_read,
				enc_qei_compare_enable_write),
};

static struct counter_comp enc_qei_count_ext_timing[] = {
	COUNTER_COMP_COUNT_U64("snapshot_count", enc_qei_snapshot_count_read,
			       NULL),
};

static struct counter_comp enc_qei_device_ext[] = {
	COUNTER_COMP_DEVICE_BOOL("snapshot", enc_qei_snapshot_read,
				 enc_qei_snapshot_write),
	COUNTER_COMP_DEVICE_U64("snapshot_time", enc_qei_snapshot_time_read,
				NULL),
	COUNTER_COMP_DEVICE_U64("timebase", enc_qei_timebase_read, NULL),
	COUNTER_COMP_DEVICE_U64("timebase_frequency",
				enc_qei_timebase_frequency_read, NULL),
};

static const enum counter_synapse_action enc_qei_actions_ab[] = {
	COUNTER_SYNAPSE_ACTION_NONE,
	COUNTER_SYNAPSE_ACTION_RISING_EDGE,
	COUNTER_SYNAPSE_ACTION_FALLING_EDGE,
	COUNTER_SYNAPSE_ACTION_BOTH_EDGES,
};

static const enum counter_synapse_action enc_qei_actions_index[] = {
	COUNTER_SYNAPSE_ACTION_NONE,
};

/*
 * The functions the build has: all eight Linux ones, unless CTRL.FUNC is
 * fixed (a build with one count function ignores writes of CTRL.FUNC).
 */
static int enc_qei_find_functions(struct enc_qei_priv *priv)
{
	u32 ctrl = enc_qei_read(priv, 0, ENC_QEI_CTRL);
	u32 func = FIELD_GET(ENC_QEI_CTRL_FUNC, ctrl);
	u32 other = func == ENC_QEI_FUNC_X4 ? ENC_QEI_FUNC_X2A : ENC_QEI_FUNC_X4;
	u32 probe;
	size_t i;

	enc_qei_write(priv, 0, ENC_QEI_CTRL, (ctrl & ~ENC_QEI_CTRL_FUNC) |
		      FIELD_PREP(ENC_QEI_CTRL_FUNC, other));
	probe = FIELD_GET(ENC_QEI_CTRL_FUNC,
			  enc_qei_read(priv, 0, ENC_QEI_CTRL));
	enc_qei_write(priv, 0, ENC_QEI_CTRL, ctrl);

	if (probe == func) {
		if (enc_qei_func_to_function(func, &priv->functions[0]))
			return -EINVAL;
		priv->num_functions = 1;
		return 0;
	}
	for (i = 0; i < ARRAY_SIZE(enc_qei_func_map); i++)
		priv->functions[i] = enc_qei_func_map[i];
	priv->num_functions = ARRAY_SIZE(enc_qei_func_map);
	return 0;
}

static struct counter_comp *enc_qei_count_ext(struct device *dev,
					      const struct enc_qei_caps *caps,
					      size_t *num_ext)
{
	size_t n = ARRAY_SIZE(enc_qei_count_ext_all);
	struct counter_comp *ext;

	ext = devm_kcalloc(dev, n + ARRAY_SIZE(enc_qei_count_ext_range) +
			   ARRAY_SIZE(enc_qei_count_ext_timing), sizeof(*ext),
			   GFP_KERNEL);
	if (!ext)
		return NULL;
	memcpy(ext, enc_qei_count_ext_all, sizeof(enc_qei_count_ext_all));
	if (caps->has_range) {
		memcpy(ext + n, enc_qei_count_ext_range,
		       sizeof(enc_qei_count_ext_range));
		n += ARRAY_SIZE(enc_qei_count_ext_range);
	}
	if (caps->has_timing) {
		memcpy(ext + n, enc_qei_count_ext_timing,
		       sizeof(enc_qei_count_ext_timing));
		n += ARRAY_SIZE(enc_qei_count_ext_timing);
	}
	*num_ext = n;
	return ext;
}

static int enc_qei_init_components(struct device *dev,
				   struct counter_device *counter)
{
	struct enc_qei_priv *priv = counter_priv(counter);
	unsigned int channels = priv->caps.channels;
	struct counter_synapse *synapses;
	struct counter_signal *signals;
	struct counter_count *counts;
	struct counter_comp *ext;
	unsigned int k, s, id;
	size_t num_ext;

	counts = devm_kcalloc(dev, channels, sizeof(*counts), GFP_KERNEL);
	signals = devm_kcalloc(dev, channels * ENC_QEI_SIGNALS_PER_CHANNEL,
			       sizeof(*signals), GFP_KERNEL);
	synapses = devm_kcalloc(dev, channels * ENC_QEI_SIGNALS_PER_CHANNEL,
				sizeof(*synapses), GFP_KERNEL);
	ext = enc_qei_count_ext(dev, &priv->caps, &num_ext);
	if (!counts || !signals || !synapses || !ext)
		return -ENOMEM;

	for (k = 0; k < channels; k++) {
		for (s = 0; s < ENC_QEI_SIGNALS_PER_CHANNEL; s++) {
			id = k * ENC_QEI_SIGNALS_PER_CHANNEL + s;
			signals[id].id = id;
			signals[id].name = devm_kasprintf(dev, GFP_KERNEL,
							  "channel%u %s", k,
							  s == ENC_QEI_SIGNAL_A ? "A" :
							  s == ENC_QEI_SIGNAL_B ? "B" :
							  "Index");
			if (!signals[id].name)
				return -ENOMEM;
			signals[id].ext = enc_qei_signal_ext;
			signals[id].num_ext = ARRAY_SIZE(enc_qei_signal_ext);

			synapses[id].signal = &signals[id];
			if (s == ENC_QEI_SIGNAL_INDEX) {
				synapses[id].actions_list = enc_qei_actions_index;
				synapses[id].num_actions =
					ARRAY_SIZE(enc_qei_actions_index);
			} else {
				synapses[id].actions_list = enc_qei_actions_ab;
				synapses[id].num_actions =
					ARRAY_SIZE(enc_qei_actions_ab);
			}
		}

		counts[k].id = k;
		counts[k].name = devm_kasprintf(dev, GFP_KERNEL, "channel%u", k);
		if (!counts[k].name)
			return -ENOMEM;
		counts[k].functions_list = priv->functions;
		counts[k].num_functions = priv->num_functions;
		counts[k].synapses = &synapses[k * ENC_QEI_SIGNALS_PER_CHANNEL];
		counts[k].num_synapses = ENC_QEI_SIGNALS_PER_CHANNEL;
		counts[k].ext = ext;
		counts[k].num_ext = num_ext;
	}

	counter->counts = counts;
	counter->num_counts = channels;
	counter->signals = signals;
	counter->num_signals = channels * ENC_QEI_SIGNALS_PER_CHANNEL;
	if (priv->caps.has_timing) {
		counter->ext = enc_qei_device_ext;
		counter->num_ext = ARRAY_SIZE(enc_qei_device_ext);
	}
	return 0;
}

static int enc_qei_probe(struct platform_device *pdev)
{
	struct device *dev = &pdev->dev;
	struct counter_device *counter;
	struct enc_qei_priv *priv;
	struct resource *res;
	unsigned int k;
	struct clk *clk;
	int irq, ret;
	u32 id, caps;

	counter = devm_counter_alloc(dev, sizeof(*priv));
	if (!counter)
		return -ENOMEM;
	priv = counter_priv(counter);
	spin_lock_init(&priv->lock);

	priv->base = devm_platform_get_and_ioremap_resource(pdev, 0, &res);
	if (IS_ERR(priv->base))
		return PTR_ERR(priv->base);

	id = enc_qei_read(priv, 0, ENC_QEI_ID);
	ret = enc_qei_check_id(id);
	if (ret == -ENODEV)
		return dev_err_probe(dev, ret, "not an enc_qei (ID 0x%08x)\n",
				     id);
	if (ret)
		return dev_err_probe(dev, -ENODEV,
				     "register map %u.%u not supported (ID 0x%08x): need %u.%u or a later %u.x\n",
				     (id >> 8) & 0xff, id & 0xff, id,
				     ENC_QEI_VERSION_MAJOR,
				     ENC_QEI_VERSION_MINOR_MIN,
				     ENC_QEI_VERSION_MAJOR);

	caps = enc_qei_read(priv, 0, ENC_QEI_CAPS);
	if (enc_qei_parse_caps(caps, &priv->caps))
		return dev_err_probe(dev, -ENODEV, "bad CAPS 0x%08x\n", caps);
	if (resource_size(res) < priv->caps.channels * ENC_QEI_PAGE_SIZE)
		return dev_err_probe(dev, -EINVAL,
				     "reg %pR too small for %u channels\n", res,
				     priv->caps.channels);
	priv->count_max = GENMASK_ULL(priv->caps.count_w - 1, 0);

	clk = devm_clk_get_enabled(dev, NULL);
	if (IS_ERR(clk))
		return dev_err_probe(dev, PTR_ERR(clk), "no bus clock\n");
	priv->clk_rate = clk_get_rate(clk);
	if (!priv->clk_rate)
		return dev_err_probe(dev, -EINVAL, "bus clock rate is 0\n");

	ret = enc_qei_find_functions(priv);
	if (ret)
		return dev_err_probe(dev, ret, "unknown fixed count function\n");

	for (k = 0; k < priv->caps.channels; k++) {
		enc_qei_write(priv, k, ENC_QEI_IRQ_EN, 0);
		enc_qei_write(priv, k, ENC_QEI_EVENTS, ENC_QEI_EV_ALL);
	}

	irq = platform_get_irq_optional(pdev, 0);
	if (irq < 0 && irq != -ENXIO)
		return irq;
	priv->has_irq = irq > 0;

	counter->name = dev_name(dev);
	counter->parent = dev;
	counter->ops = &enc_qei_ops;
	ret = enc_qei_init_components(dev, counter);
	if (ret)
		return ret;

	if (priv->has_irq) {
		ret = devm_request_irq(dev, irq, enc_qei_irq_handler, 0,
				       dev_name(dev), counter);
		if (ret)
			return dev_err_probe(dev, ret, "cannot request IRQ %d\n",
					     irq);
	}

	ret = devm_counter_add(dev, counter);
	if (ret)
		return dev_err_probe(dev, ret, "failed to add counter\n");

	dev_info(dev, "%u channels, %u-bit counts, %s profile%s%s\n",
		 priv->caps.channels, priv->caps.count_w,
		 priv->caps.profile == ENC_QEI_PROFILE_LEAN ? "lean" :
		 priv->caps.profile == ENC_QEI_PROFILE_FULL ? "full" :
		 "counting", priv->caps.engine ? ", shared engine" : "",
		 priv->has_irq ? "" : ", no interrupt: no events");
	return 0;
}

static const struct of_device_id enc_qei_of_match[] = {
	{ .compatible = "encip,enc-qei" },
	{ }
};
MODULE_DEVICE_TABLE(of, enc_qei_of_match);

static struct platform_driver enc_qei_driver = {
	.probe = enc_qei_probe,
	.driver = {
		.name = "enc-qei",
		.of_match_table = enc_qei_of_match,
	},
};
module_platform_driver(enc_qei_driver);

#if IS_ENABLED(CONFIG_ENC_QEI_KUNIT_TEST)
#include "enc-qei-test.c"
#endif

MODULE_DESCRIPTION("enc_qei quadrature encoder interface counter driver");
MODULE_LICENSE("GPL");
MODULE_IMPORT_NS(COUNTER);
