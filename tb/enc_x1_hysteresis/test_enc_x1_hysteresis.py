# SPDX-License-Identifier: Apache-2.0
"""enc_x1_hysteresis (Figure 14, the latched-hysteresis 1X counter) against its model in enctools.tb.models, clock by clock. The cocotb tests are
shared by the three decoders: enctools.tb.decoder_bench."""

import pytest

from enctools.tb.decoder_bench import COMMON_TESTS
from enctools.harness import run


def test_enc_x1_hysteresis():
    run("enc_x1_hysteresis", "enctools.tb.decoder_bench", name="enc_x1_hysteresis",
        testcase=COMMON_TESTS + ",x1_hysteresis_bound,x1_runs_after_any_history,reset_then_illegal_jump")


def test_naive_x1_fails_hysteresis():
    """A 1X counter that counts every rising edge of A (B = direction) must fail the bound test:
    this proves the test can catch the multiple-count problem."""
    with pytest.raises(SystemExit):
        run("naive_x1", "enctools.tb.decoder_bench", name="naive_x1", tb_sources=("naive_x1.v",),
            testcase="x1_hysteresis_bound")
