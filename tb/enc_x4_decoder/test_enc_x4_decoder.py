# SPDX-License-Identifier: Apache-2.0
"""enc_x4_decoder (the look-up-table 4X decoder) against its model in tb/common/models.py, clock by clock. The cocotb tests are
shared by the three decoders: tb/common/decoder_bench.py."""

from decoder_bench import COMMON_TESTS
from harness import run


def test_enc_x4_decoder():
    run("enc_x4_decoder", "decoder_bench", name="enc_x4_decoder", testcase=COMMON_TESTS)
