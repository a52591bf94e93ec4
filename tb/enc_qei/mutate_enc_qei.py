# SPDX-License-Identifier: Apache-2.0
"""pytest driver of the enc_qei mutant runs (scripts/mutate.py maps the enc_qei modules here).

Not a `make test` file (its name does not match test_*.py; pytest collects it only when named on
the command line): it builds the same configurations as test_enc_qei.py and runs the cocotb
module qei_mutate_suite, which runs the regression's enc_qei cocotb tests listed in
ENC_QEI_MUT_TESTS (set per module and corner by scripts/mutate.py), in that order, stopping at the
first failure.
"""

import pytest

from enctools.core import rtl_files
from enctools.harness import TOP, run
from enctools.qei.bus import QEI_RTL


def extra_sources() -> tuple:
    """The enc_qei files enc_ip.core does not list (none today). Not qei_tb.extra_sources(): that
    compares file names, and a mutant under ENC_RTL_OVERRIDE has another name (it would add the
    original file next to the mutant)."""
    core = set(rtl_files())
    return tuple(TOP / "rtl" / f for f in QEI_RTL if f"rtl/{f}" not in core)


# the configurations of test_enc_qei.py (enc_qei_wb at COUNT_W 32 / TS_W 32 is also the default
# configuration that test_count_rate_qei.py builds)
CONFIGS = [("enc_qei_wb", 32, 32), ("enc_qei_axil", 64, 16)]


@pytest.mark.parametrize("top,count_w,ts_w", CONFIGS, ids=[f"{t}-c{c}-t{s}" for t, c, s in CONFIGS])
def test_enc_qei_mutate(top, count_w, ts_w):
    run(top, "qei_mutate_suite", name=f"mut_{top}_c{count_w}_t{ts_w}",
        parameters={"COUNT_W": count_w, "TS_W": ts_w}, extra_sources=extra_sources())
