# SPDX-License-Identifier: Apache-2.0
"""enc_x2_xor (Figure 15, the 2X XOR decoder) against its model in enctools.tb.models, clock by clock. The cocotb tests are
shared by the three decoders: enctools.tb.decoder_bench."""

from enctools.tb.decoder_bench import COMMON_TESTS
from enctools.harness import run


def test_enc_x2_xor():
    run("enc_x2_xor", "enctools.tb.decoder_bench", name="enc_x2_xor", testcase=COMMON_TESTS)
