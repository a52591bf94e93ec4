# SPDX-License-Identifier: Apache-2.0
"""The modules `make mutate` mutates, and where their tests are.

Each entry names the module's file and the test paths that cover it (pytest files, folders or
ids, in priority order). The tests themselves, the builds, the parameter corners and the
grouping of tests into simulations are discovered (enctools.mutation.discover). ``corners``
picks which builds give corners (patterns on pytest ids, `*` the only wildcard; default: every build of the
module's tests); every test that builds the module at a picked corner's values runs against its
mutants, also those of builds that were not picked. ``priority`` only orders: those tests run
first on the first mutants of a corner (after that, the tests that have killed go first).
"""

from __future__ import annotations

from .data import Module, Suite

# The enc_qei feature files share one environment (enctools.qei.env): one build per
# configuration, so each configuration's tests run in one simulation per mutant set. Their suites
# are long (40 to 70 s unmutated): a test runs on the unmutated design only once it has killed,
# the limit is fixed (1.5 ms of simulated time: period_capture and the count-rate bench's
# exact_at_bound take 0.7 ms; the two saturation tests of test_compare_events take 2 ms and have
# a timeout of their own, which is their limit here), and a mutant alive after a third of the
# first group's tests is checked for equivalence at once. A test that takes more than half its
# limit unmutated stops the run with its name (a timeout would not prove a kill).
QEI_SUITE = Suite(lazy=True, limit_ns=1_500_000, cap=0.35)
FEATURES = "tb/enc_qei"
CHANNELS = "tb/enc_qei/test_channels.py"  # several channels: for the modules that page them
RATE_QEI = "tb/count_rate/test_count_rate_qei.py"  # COUNT and EVENTS at the count-rate bound
WB1 = "tb/enc_qei/*[enc_qei_wb-c32-t32]"  # one channel, full profile, COUNT_W 32 / TS_W 32
AX1 = "tb/enc_qei/*[enc_qei_axil-c64-t16]"  # one channel, full profile, COUNT_W 64 / TS_W 16
WB3 = "tb/enc_qei/test_channels.py::*[enc_qei_wb-ch3-full]"  # three full channels
QEI_FIRST = ("register_walk", "register_patterns", "events_and_irq", "reset_mid_motion")


def qei(file: str, corners: tuple[str, ...], *first: str, rate: bool = False,
        channels: bool = False) -> Module:
    return Module(file, (FEATURES, RATE_QEI) if rate else (FEATURES,), corners,
                  exclude=() if channels else (CHANNELS,), suite=QEI_SUITE,
                  priority=QEI_FIRST + first)


RATE = "tb/count_rate/test_count_rate.py"
ENGINE_TESTS = ("tb/enc_qei/test_engine.py", CHANNELS, FEATURES)
ENGINE_CORNERS = ("tb/enc_qei/test_engine.py::*[enc_qei_wb-ch3-engine]",
                  "tb/enc_qei/*[enc_qei_wb-c32-t32-engine]")


# the shared engine's tests wait for its latency: the longest feature test without a timeout of
# its own takes 1.7 ms there
ENGINE_SUITE = Suite(lazy=True, limit_ns=4_000_000, cap=0.35)


def engine(file: str) -> Module:
    return Module(file, ENGINE_TESTS, ENGINE_CORNERS, suite=ENGINE_SUITE,
                  priority=("latency", "random_motion", "write_effect", "independent_walks", "global_snapshot"))

MODULES: dict[str, Module] = {
    "ls168": Module("rtl/ls168.v", ("tb/ls168/test_ls168.py",)),
    # corners: the conditioner's own test (FILTER_LEN 1, 2, 3, 8); the count-rate bench runs
    # at 1, 2, 3 too (its FILTER_LEN 4 build is not a corner of its own)
    "enc_conditioner": Module("rtl/enc_conditioner.v", ("tb/enc_conditioner", RATE),
                              ("tb/enc_conditioner/*",)),
    "enc_x4_decoder": Module("rtl/enc_x4_decoder.v", ("tb/enc_x4_decoder", RATE)),
    "enc_x2_xor": Module("rtl/enc_x2_xor.v", ("tb/enc_x2_xor", RATE)),
    "enc_x1_hysteresis": Module("rtl/enc_x1_hysteresis.v", ("tb/enc_x1_hysteresis", RATE)),
    "enc_updown_buffer": Module("rtl/enc_updown_buffer.v", ("tb/enc_updown_buffer",)),
    # the behaviour tests at WINDOW_LOG2 13 only: the runs at 16 and 17 are accuracy runs
    # (+-64 LSB) that by design cannot see a wrong LSB or a broken reset (doc/mutation.md)
    "enc_phase_meter": Module("rtl/enc_phase_meter.v",
                              ("tb/enc_phase_meter/test_enc_phase_meter.py::test_enc_phase_meter",)),
    "enc_characterizer": Module("rtl/enc_characterizer.v", ("tb/enc_characterizer",)),
    # enc_qei's parts. The conditioner has one parameter set in every build (MAX_FILTER_LEN 16).
    "enc_conditioner_rt": qei("rtl/enc_conditioner_rt.v", (WB1,), "filter_lengths",
                              "filter_len_clamp", "reset_on_rejection_clock", "step_soon_after_reset",
                              "reset_in_each_state", rate=True),
    "enc_qei_core": qei("rtl/enc_qei_core.v", (WB1, AX1), "swap_and_invert", "latches_wide",
                        "coherent_64bit", "compare", "func_walks", "range_modes", "ceiling_wide",
                        "bounded_range_fast", "steps_in_consecutive_clocks", "index_at_steps",
                        rate=True),
    "enc_qei_timing": qei("rtl/enc_qei_timing.v", (WB1, AX1), "snapshot_deltas_across_wraps",
                          "snapshot_deltas_held", "stall_timeout_exact", "period_large_n",
                          "snapshot_wide_values", "period_capture"),
    "enc_qei_regs": qei("rtl/enc_qei_regs.v", (WB1, AX1), "byte_enables", "byte_enables_all",
                        "unmapped_offsets", "irq_low_in_reset"),
    "enc_qei": qei("rtl/enc_qei.v", (WB1, AX1), "irq_low_in_reset", "global_snapshot_one_channel",
                   "snapshot_wide_values"),
    "enc_qei_channel": qei("rtl/enc_qei_channel.v", (WB1, AX1), "swap_and_invert",
                           "filter_lengths", "snapshot_wide_values"),
    "enc_qei_timebase": qei("rtl/enc_qei_timebase.v", (AX1,), "prescaler_and_snap_in",
                            "prescaler_long", "unit_timer_prescaled"),
    "enc_qei_snaptrig": qei("rtl/enc_qei_snaptrig.v", (AX1,), "prescaler_and_snap_in",
                            "unit_timer_period", "unit_timer_prescaled"),
    # the multi-channel corner: the Wishbone adapter at three channels (ADDR_W 10), under
    # test_channels.py's traffic to every page
    # the edge FIFO, at its two builds (one full channel with 16 entries on Wishbone, two lean
    # channels with 32 on AXI4-Lite): its own feature file only
    "enc_qei_efifo": Module("rtl/enc_qei_efifo.v", ("tb/enc_qei/test_efifo.py",),
                            ("tb/enc_qei/test_efifo.py::*[enc_qei_wb-ch1-full-e4]",
                             "tb/enc_qei/test_efifo.py::*[enc_qei_axil-ch2-lean-e5]"),
                            suite=QEI_SUITE),
    "enc_qei_wb": qei("rtl/enc_qei_wb.v", (WB1, WB3), "wb_abandoned_cycle", "wb_abandoned_request",
                      "byte_enables", "isolation", "channel_map", channels=True),
    "enc_qei_axil": qei("rtl/enc_qei_axil.v", (AX1,), "concurrent_reads_and_writes",
                        "byte_enables"),
    # the shared engine (ENGINE = 1) at two corners: three lean channels on Wishbone (the
    # engine's own tests against a per-channel build, and test_channels' traffic), and one full
    # channel on Wishbone, the feature files' build (every unit: stall, period, ranges, compare,
    # ...; on Icarus here, on Verilator in make test). The three full channels on AXI4-Lite
    # (test_channels) are not a corner: that traffic alone leaves the full profile's units
    # untested.
    # enc_qei_ram is not mutated: every engine build instantiates it at two widths (one mutant
    # design cannot serve both), and it is a plain two-port memory the engine's tests read through
    "enc_qei_engine": engine("rtl/enc_qei_engine.v"),
    # the edge FIFOs beside the engine (ENGINE 1, EFIFO_LOG2 > 0): the edge-FIFO feature file on
    # its two engine builds (one full channel on Wishbone, three lean on AXI4-Lite)
    "enc_qei_efifo_bank": Module("rtl/enc_qei_efifo_bank.v", ("tb/enc_qei/test_efifo.py",),
                                 ("tb/enc_qei/test_efifo.py::*[enc_qei_wb-ch1-full-e4-engine]",
                                  "tb/enc_qei/test_efifo.py::*[enc_qei_axil-ch3-lean-e5-engine]"),
                                 suite=ENGINE_SUITE),
    "enc_qei_lane": engine("rtl/enc_qei_lane.v"),
    # shared by both architectures: the per-channel build's feature tests first
    "enc_qei_decode": qei("rtl/enc_qei_decode.v", (WB1,), "func_walks", "swap_and_invert",
                          "steps_in_consecutive_clocks", rate=True),
    "enc_filter_rt": qei("rtl/enc_filter_rt.v", (WB1,), "filter_lengths", "filter_len_clamp",
                         "reset_in_each_state", rate=True),
}
