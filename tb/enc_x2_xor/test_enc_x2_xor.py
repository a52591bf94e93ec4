# SPDX-License-Identifier: Apache-2.0
"""enc_x2_xor (Figure 15, the 2X XOR decoder) against its model in tb/common/models.py, clock by clock. The cocotb tests are
shared by the three decoders: tb/common/decoder_bench.py."""

from decoder_bench import COMMON_TESTS
from harness import run


def test_enc_x2_xor():
    run("enc_x2_xor", "decoder_bench", name="enc_x2_xor", testcase=COMMON_TESTS)
