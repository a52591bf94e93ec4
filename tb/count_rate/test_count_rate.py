# SPDX-License-Identifier: Apache-2.0
"""Count-rate limit at the physical bound (contract of enc_conditioner + decoders), on the probe
tb/hdl/enc_quad_probe.v: the cocotb tests exact_at_bound and never_silent of
enctools.benches.count_rate_probe (the module scripts/count_rate.py measures the limit with)."""

import pytest

from enctools.harness import run


@pytest.mark.parametrize("filter_len", [1, 2, 3, 4])
def test_count_rate(filter_len):
    run("enc_quad_probe", "enctools.benches.count_rate_probe", name=f"count_rate_f{filter_len}",
        parameters={"FILTER_LEN": filter_len}, tb_sources=("enc_quad_probe.v",),
        testcase="exact_at_bound,never_silent")
