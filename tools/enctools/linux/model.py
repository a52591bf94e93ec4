# SPDX-License-Identifier: Apache-2.0
"""The model server of `make linux-test`: sw/linux/model-server/enc_qei_server.cpp around a
Verilator model of enc_qei_wb, one build per parameter set, in build/linux/model-<name>/."""

from __future__ import annotations

import math
import os
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from .. import core
from ..paths import TOP
from ..toolenv import simulator_env, tool_path
from .kernel import LINUX_SW, WORK, say

SERVER_SRC = LINUX_SW / "model-server" / "enc_qei_server.cpp"


@dataclass(frozen=True)
class Build:
    """One enc_qei build: its name and the enc_qei_wb parameters it sets."""
    name: str
    params: dict = field(default_factory=dict, hash=False, compare=False)

    @property
    def channels(self) -> int:
        return int(self.params.get("CHANNELS", 1))

    @property
    def addr_w(self) -> int:
        return 8 + math.ceil(math.log2(self.channels)) if self.channels > 1 else 8


def build(b: Build, jobs: int) -> Path:
    """The server binary of build ``b`` (Verilator compiles it when a source changed)."""
    out = WORK / f"model-{b.name}"
    exe = out / "enc_qei_server"
    sources = [TOP / f for f in core.rtl_files()]
    inputs = sources + [SERVER_SRC, LINUX_SW / "stimulus.h", Path(__file__)]
    stamp = out / "params.txt"
    params_text = repr(sorted(b.params.items()))
    if (exe.exists() and stamp.exists() and stamp.read_text() == params_text
            and all(p.stat().st_mtime <= exe.stat().st_mtime for p in inputs)):
        return exe
    say(f"building the model server {b.name} ({', '.join(f'{k} {v}' for k, v in b.params.items())})")
    t0 = time.monotonic()
    out.mkdir(parents=True, exist_ok=True)
    gparams = [f"-G{k}={v}" for k, v in b.params.items()] + [f"-GADDR_W={b.addr_w}"]
    cmd = ["verilator", "--cc", "--exe", "--build", "-j", str(jobs), "-O2", "-Wno-fatal",
           "-Wno-lint", "-Wno-style", "--top-module", "enc_qei_wb", "--Mdir", str(out / "obj"),
           "-o", str(exe), *gparams,
           *[f"-I{d}" for d in core.include_dirs()],
           "-CFLAGS", f"-O1 -I{LINUX_SW} -DENC_QEI_ADDR_W={b.addr_w}",
           str(TOP / "rtl" / "lint_waivers.vlt"), *map(str, sources), str(SERVER_SRC)]
    env = {**os.environ, **simulator_env(), "PATH": tool_path()}
    res = subprocess.run(cmd, capture_output=True, text=True, env=env)
    (out / "build.log").write_text(res.stdout + res.stderr)
    if res.returncode or not exe.exists():
        tail = "\n".join((res.stdout + res.stderr).splitlines()[-25:])
        raise SystemExit(f"linux-test: the model server {b.name} did not build "
                         f"({out / 'build.log'}):\n{tail}")
    stamp.write_text(params_text)
    say(f"model server {b.name} built in {time.monotonic() - t0:.0f} s")
    return exe
