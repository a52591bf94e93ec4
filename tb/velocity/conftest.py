# SPDX-License-Identifier: Apache-2.0
"""The C side of the velocity tests: gcc builds of the estimators in sw/ with their test drivers
(C99, -Wall -Wextra -Werror -pedantic), skipped where gcc is missing."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

SW = Path(__file__).resolve().parents[2] / "sw"


@pytest.fixture(scope="session")
def c_driver(tmp_path_factory):
    """``build(name, sources, libs=())``: the executable of ``sources`` (paths) built with gcc."""
    gcc = shutil.which("gcc")

    def build(name: str, sources, libs=()) -> Path:
        if gcc is None:
            pytest.skip("gcc not found: the C estimator cannot be compiled here")
        out = tmp_path_factory.mktemp(name) / name
        cmd = [gcc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O2", f"-I{SW}",
               *map(str, sources), *libs, "-o", str(out)]
        res = subprocess.run(cmd, capture_output=True, text=True)
        assert res.returncode == 0, f"gcc failed:\n{' '.join(cmd)}\n{res.stderr}"
        return out

    return build


@pytest.fixture(scope="session")
def c_fixed(c_driver):
    """The test driver that runs sw/enc_qei_velocity_fx.c (which it includes) and
    sw/enc_qei_velocity.c side by side (tb/velocity/velfx_driver.c)."""
    return c_driver("velfx_driver", [SW / "enc_qei_velocity.c",
                                     Path(__file__).parent / "velfx_driver.c"])
