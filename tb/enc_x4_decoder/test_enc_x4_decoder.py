# SPDX-License-Identifier: Apache-2.0
"""enc_x4_decoder (the look-up-table 4X decoder) against its model in enctools.tb.models, clock by clock. The cocotb tests are
shared by the three decoders: enctools.tb.decoder_bench."""

from enctools.tb.decoder_bench import COMMON_TESTS
from enctools.harness import run


def test_enc_x4_decoder():
    run("enc_x4_decoder", "enctools.tb.decoder_bench", name="enc_x4_decoder", testcase=COMMON_TESTS)
