# SPDX-License-Identifier: Apache-2.0
"""The count-rate rule through enc_qei's bus adapters (cocotb tests in
enctools.benches.count_rate_qei): one channel on each adapter, and the shared engine (ENGINE = 1)
with 16 lean channels, each playing its own walk at once: exact at 1.05 x the bound for
FILTER_LEN 1 .. 4, and every inexact channel flagged at 0.8 x (on Verilator whatever SIM says:
Icarus takes about 30 times longer). The single-channel builds also run every count function at
its bound (the A-edge functions need every level of A to last 1.05 FILTER_LEN clocks) and past
it (never_silent: exact or flagged)."""

import pytest

from enctools.harness import run
from enctools.qei.env import PROFILES


@pytest.mark.parametrize("top", ["enc_qei_wb", "enc_qei_axil"])
def test_count_rate_qei(top):
    run(top, "enctools.benches.count_rate_qei", name=f"count_rate_{top}",
        testcase="exact_at_bound,never_silent,every_function_at_bound")


def test_count_rate_engine_16_channels():
    run("enc_qei_wb", "enctools.benches.count_rate_qei", name="count_rate_enc_qei_wb_engine_ch16",
        parameters={"CHANNELS": 16, "PROFILE": PROFILES["lean"], "ENGINE": 1},
        testcase="exact_at_bound,flagged_below_bound", sim="verilator")
