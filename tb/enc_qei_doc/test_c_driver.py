# SPDX-License-Identifier: Apache-2.0
"""The bare-metal driver API (sw/enc_qei_drv.c) and the servo example (sw/examples/enc_qei_servo.c)
against a model of enc_qei's registers (tb/enc_qei_doc/drv_model.c, compiled with them by gcc).

The model has the side effects a plain struct lacks (write-1-to-clear EVENTS, IRQ_SUMMARY,
SNAP_READY, the COUNT_LO latch, the unit timer) and can play a shared-engine build: every write
lands LATENCY bus accesses late and a snapshot shows in channel k STAGGER * k accesses after that,
its SNAP_READY with it. The checks (in the C harness) compare what the driver returns with the
model's own record: the instant of every snapshot and the motion. Today's build is latency 0;
with latency a driver that reads SNAP_* straight after a command, does a read-modify-write of
IRQ_EN, or returns before a clear of EVENTS has landed fails here (each was tried).
"""

from __future__ import annotations

import random
import shutil
import subprocess
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[2]
SW = TOP / "sw"
GCC = shutil.which("gcc")


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    if GCC is None:
        pytest.skip("gcc not installed")
    exe = tmp_path_factory.mktemp("drv_model") / "drv_model"
    cmd = [GCC, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-O1", f"-I{SW}",
           f"-I{SW / 'examples'}", str(Path(__file__).parent / "drv_model.c"),
           str(SW / "examples" / "enc_qei_servo.c"), str(SW / "enc_qei_velocity_fx.c"),
           "-o", str(exe)]
    res = subprocess.run(cmd, capture_output=True, text=True)
    assert res.returncode == 0, f"{' '.join(cmd)}\n{res.stderr}"
    return exe


def run(exe: Path, *args) -> str:
    res = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True, timeout=60)
    out = res.stdout
    assert res.returncode == 0 and "failures 0" in out, \
        f"drv_model {' '.join(map(str, args))}:\n{out}{res.stderr}"
    return out


def test_init_refuses_other_blocks_and_versions(model):
    """Wrong MAGIC (also all ones, what an unmapped read returns on VexRiscv), major 0 and 2,
    minor 0 and 1, CHANNELS 0 and 17: refused after reading ID and CAPS only; 1.2, 1.3 and
    1.255 with 1 to 16 channels accepted."""
    run(model, "init")


# channels, COUNT_W, TS_W, timing unit, full profile, write latency, snapshot stagger
BUILDS = [
    (4, 32, 32, 1, 1, 0, 0),       # the simulated SoC's build, today's timing
    (1, 32, 32, 1, 1, 0, 0),
    (16, 64, 32, 1, 1, 0, 0),
    (3, 48, 24, 1, 0, 0, 0),       # lean
    (4, 32, 32, 1, 1, 20, 7),      # shared engine
    (16, 64, 32, 1, 1, 37, 11),
    (2, 8, 16, 1, 0, 5, 3),
    (16, 32, 32, 0, 0, 0, 0),      # counting: no timing unit
    (5, 64, 32, 0, 0, 9, 0),
]


@pytest.mark.parametrize("build", BUILDS,
                         ids=lambda b: "ch{}_cw{}_tw{}_t{}_f{}_lat{}_stg{}".format(*b))
def test_driver_against_the_model(model, build):
    """Positions, IRQ_EN without read-modify-write, events taken once, command snapshots (global
    and per channel, also with a stale one pending), SNAP_CTRL kept, ESKEW, the bounded wait, the
    servo example on the unit timer (every timer snapshot once, positions and fixed-point
    velocities exact), ENOTSUP without the timing unit, no access beyond page CHANNELS - 1."""
    out = run(model, "run", *build)
    print(out.splitlines()[-2] if build[3] else out.splitlines()[-1])


def test_driver_random_builds(model):
    seed = random.randrange(1 << 30)
    print(f"seed {seed}")
    rng = random.Random(seed)
    for _ in range(6):
        timing = rng.random() < 0.8
        build = (rng.randint(1, 16), rng.choice([8, 16, 32, 33, 48, 63, 64]),
                 rng.choice([16, 24, 32]), int(timing), int(timing and rng.random() < 0.5),
                 rng.choice([0, 1, 3, 50]), rng.choice([0, 1, 13]))
        run(model, "run", *build)
