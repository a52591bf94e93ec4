// SPDX-License-Identifier: GPL-2.0
/*
 * KUnit tests of the enc-qei driver's decisions: the ID it accepts, how it
 * reads CAPS, the count functions, Synapse actions and events it maps, the
 * spike filter conversion and the snapshot's wait on the shared engine.
 * Built into enc-qei.c when CONFIG_ENC_QEI_KUNIT_TEST is set; the tests run
 * when the module loads.
 */
#include <kunit/test.h>

static void enc_qei_test_check_id(struct kunit *test)
{
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51450102), 0);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x514501ff), 0);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51450101), -EOPNOTSUPP);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51450100), -EOPNOTSUPP);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51450202), -EOPNOTSUPP);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51450002), -EOPNOTSUPP);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x51460102), -ENODEV);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0x00000000), -ENODEV);
	KUNIT_EXPECT_EQ(test, enc_qei_check_id(0xffffffff), -ENODEV);
}

static u32 enc_qei_test_caps_word(u32 channels, u32 profile, u32 timing,
				  u32 ts_w, u32 count_w)
{
	return FIELD_PREP(ENC_QEI_CAPS_CHANNELS, channels) |
	       FIELD_PREP(ENC_QEI_CAPS_PROFILE, profile) |
	       (timing ? ENC_QEI_CAPS_TIMING : 0) |
	       FIELD_PREP(ENC_QEI_CAPS_TS_W, ts_w) |
	       FIELD_PREP(ENC_QEI_CAPS_COUNT_W, count_w);
}

static void enc_qei_test_parse_caps(struct kunit *test)
{
	struct enc_qei_caps caps;

	KUNIT_ASSERT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(4, 2, 1, 32, 32),
						 &caps), 0);
	KUNIT_EXPECT_EQ(test, caps.channels, 4U);
	KUNIT_EXPECT_EQ(test, caps.count_w, 32U);
	KUNIT_EXPECT_EQ(test, caps.ts_w, 32U);
	KUNIT_EXPECT_TRUE(test, caps.has_range);
	KUNIT_EXPECT_TRUE(test, caps.has_timing);
	KUNIT_EXPECT_FALSE(test, caps.engine);

	KUNIT_ASSERT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(4, 2, 1, 32, 32) |
						 ENC_QEI_CAPS_ENGINE, &caps), 0);
	KUNIT_EXPECT_EQ(test, caps.channels, 4U);
	KUNIT_EXPECT_TRUE(test, caps.engine);

	KUNIT_ASSERT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(16, 3, 1, 16, 64),
						 &caps), 0);
	KUNIT_EXPECT_EQ(test, caps.channels, 16U);
	KUNIT_EXPECT_EQ(test, caps.count_w, 64U);
	KUNIT_EXPECT_FALSE(test, caps.has_range);
	KUNIT_EXPECT_TRUE(test, caps.has_timing);

	KUNIT_ASSERT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(1, 1, 0, 32, 8),
						 &caps), 0);
	KUNIT_EXPECT_TRUE(test, caps.has_range);
	KUNIT_EXPECT_FALSE(test, caps.has_timing);

	KUNIT_EXPECT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(0, 2, 1, 32, 32),
						 &caps), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(17, 2, 1, 32, 32),
						 &caps), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(1, 2, 1, 32, 65),
						 &caps), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(1, 2, 1, 15, 32),
						 &caps), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_parse_caps(enc_qei_test_caps_word(1, 0, 1, 32, 32),
						 &caps), -EINVAL);
}

static void enc_qei_test_functions(struct kunit *test)
{
	enum counter_function function;
	u32 func, back;

	for (func = 0; func < ARRAY_SIZE(enc_qei_func_map); func++) {
		KUNIT_ASSERT_EQ(test, enc_qei_func_to_function(func, &function), 0);
		KUNIT_ASSERT_EQ(test, enc_qei_function_to_func(function, &back), 0);
		KUNIT_EXPECT_EQ(test, back, func);
	}
	KUNIT_EXPECT_EQ(test, enc_qei_func_to_function(ENC_QEI_FUNC_X4, &function), 0);
	KUNIT_EXPECT_EQ(test, function, COUNTER_FUNCTION_QUADRATURE_X4);
	KUNIT_EXPECT_EQ(test, enc_qei_func_to_function(ENC_QEI_FUNC_X1B, &function), 0);
	KUNIT_EXPECT_EQ(test, function, COUNTER_FUNCTION_QUADRATURE_X1_B);
	KUNIT_EXPECT_EQ(test, enc_qei_func_to_function(ENC_QEI_FUNC_PULSE_DIR, &function), 0);
	KUNIT_EXPECT_EQ(test, function, COUNTER_FUNCTION_PULSE_DIRECTION);
	/* x1_hyst (8) and the unused values have no Linux function */
	KUNIT_EXPECT_EQ(test, enc_qei_func_to_function(8, &function), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_func_to_function(15, &function), -EINVAL);
}

static void enc_qei_test_actions(struct kunit *test)
{
	const enum counter_synapse_action none = COUNTER_SYNAPSE_ACTION_NONE;
	const enum counter_synapse_action both = COUNTER_SYNAPSE_ACTION_BOTH_EDGES;
	const enum counter_synapse_action rise = COUNTER_SYNAPSE_ACTION_RISING_EDGE;
	const enum counter_synapse_action fall = COUNTER_SYNAPSE_ACTION_FALLING_EDGE;
	static const struct {
		enum counter_function function;
		enum counter_synapse_action a_fwd, a_bwd, b_fwd, b_bwd;
	} cases[] = {
		{ COUNTER_FUNCTION_QUADRATURE_X4, 3, 3, 3, 3 },
		{ COUNTER_FUNCTION_QUADRATURE_X2_A, 3, 3, 0, 0 },
		{ COUNTER_FUNCTION_QUADRATURE_X2_B, 0, 0, 3, 3 },
		{ COUNTER_FUNCTION_QUADRATURE_X1_A, 1, 2, 0, 0 },
		{ COUNTER_FUNCTION_QUADRATURE_X1_B, 0, 0, 1, 2 },
		{ COUNTER_FUNCTION_PULSE_DIRECTION, 1, 1, 0, 0 },
		{ COUNTER_FUNCTION_INCREASE, 1, 1, 0, 0 },
		{ COUNTER_FUNCTION_DECREASE, 1, 1, 0, 0 },
	};
	size_t i;

	KUNIT_ASSERT_EQ(test, both, 3);
	KUNIT_ASSERT_EQ(test, rise, 1);
	KUNIT_ASSERT_EQ(test, fall, 2);
	for (i = 0; i < ARRAY_SIZE(cases); i++) {
		enum counter_function f = cases[i].function;

		KUNIT_EXPECT_EQ(test, enc_qei_action(f, ENC_QEI_SIGNAL_A, true),
				cases[i].a_fwd);
		KUNIT_EXPECT_EQ(test, enc_qei_action(f, ENC_QEI_SIGNAL_A, false),
				cases[i].a_bwd);
		KUNIT_EXPECT_EQ(test, enc_qei_action(f, ENC_QEI_SIGNAL_B, true),
				cases[i].b_fwd);
		KUNIT_EXPECT_EQ(test, enc_qei_action(f, ENC_QEI_SIGNAL_B, false),
				cases[i].b_bwd);
		KUNIT_EXPECT_EQ(test, enc_qei_action(f, ENC_QEI_SIGNAL_INDEX, true),
				none);
	}
}

static void enc_qei_test_events(struct kunit *test)
{
	struct enc_qei_caps full = { .has_range = true, .has_timing = true };
	struct enc_qei_caps lean = { .has_range = false, .has_timing = true };
	struct enc_qei_caps counting = { .has_range = true };

	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_OVERFLOW, &full),
			ENC_QEI_EV_OVERFLOW);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_UNDERFLOW, &lean),
			ENC_QEI_EV_UNDERFLOW);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_OVERFLOW_UNDERFLOW,
						 &full),
			ENC_QEI_EV_OVERFLOW | ENC_QEI_EV_UNDERFLOW);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_THRESHOLD, &full),
			ENC_QEI_EV_CMP);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_THRESHOLD, &lean), 0);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_INDEX, &lean),
			ENC_QEI_EV_INDEX);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_CAPTURE, &full),
			ENC_QEI_EV_SNAP_READY);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_CAPTURE, &counting), 0);
	KUNIT_EXPECT_EQ(test, enc_qei_event_bits(COUNTER_EVENT_CHANGE_OF_STATE,
						 &full), 0);
}

static void enc_qei_test_spike_filter(struct kunit *test)
{
	u32 len;

	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(1, 100000000), 0ULL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(0, 100000000), 0ULL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(3, 100000000), 20ULL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(16, 100000000), 150ULL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(31, 100000000), 150ULL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_ns(3, 12000000), 166ULL);

	KUNIT_ASSERT_EQ(test, enc_qei_filter_len(0, 100000000, &len), 0);
	KUNIT_EXPECT_EQ(test, len, 1U);
	KUNIT_ASSERT_EQ(test, enc_qei_filter_len(20, 100000000, &len), 0);
	KUNIT_EXPECT_EQ(test, len, 3U);
	KUNIT_ASSERT_EQ(test, enc_qei_filter_len(21, 100000000, &len), 0);
	KUNIT_EXPECT_EQ(test, len, 4U);
	KUNIT_ASSERT_EQ(test, enc_qei_filter_len(150, 100000000, &len), 0);
	KUNIT_EXPECT_EQ(test, len, 16U);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_len(151, 100000000, &len), -EINVAL);
	KUNIT_EXPECT_EQ(test, enc_qei_filter_len(U64_MAX, 100000000, &len), -EINVAL);
}

static void enc_qei_test_snapshot_ticks(struct kunit *test)
{
	struct enc_qei_caps caps = { .channels = 4, .engine = false };

	/* per_channel: the snapshot reads at once */
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 0), 0U);
	/* shared engine: 2P + 48 clocks, P = 24 * max(CHANNELS, 2), and a tick */
	caps.engine = true;
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 0), 2 * 96 + 48 + 1U);
	caps.channels = 1;
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 0), 2 * 48 + 48 + 1U);
	caps.channels = 16;
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 0), 2 * 384 + 48 + 1U);
	/* ticks of PRESCALE + 1 clocks, rounded up */
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 1), 408 + 1U);
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 6), 117 + 1U);
	KUNIT_EXPECT_EQ(test, enc_qei_snapshot_ticks(&caps, 0xffff), 1 + 1U);
}

static struct kunit_case enc_qei_test_cases[] = {
	KUNIT_CASE(enc_qei_test_check_id),
	KUNIT_CASE(enc_qei_test_parse_caps),
	KUNIT_CASE(enc_qei_test_functions),
	KUNIT_CASE(enc_qei_test_actions),
	KUNIT_CASE(enc_qei_test_events),
	KUNIT_CASE(enc_qei_test_spike_filter),
	KUNIT_CASE(enc_qei_test_snapshot_ticks),
	{ }
};

static struct kunit_suite enc_qei_test_suite = {
	.name = "enc-qei",
	.test_cases = enc_qei_test_cases,
};

kunit_test_suite(enc_qei_test_suite);
