# SPDX-License-Identifier: Apache-2.0
"""The count-rate rule through enc_qei's bus adapters (cocotb tests in qei_count_rate.py)."""

import pytest

from enctools.harness import run


@pytest.mark.parametrize("top", ["enc_qei_wb", "enc_qei_axil"])
def test_count_rate_qei(top):
    run(top, "enctools.benches.count_rate_qei", name=f"count_rate_{top}", testcase="exact_at_bound,never_silent")
