# SPDX-License-Identifier: Apache-2.0
"""One boot of `make linux-test`: the model server, the devicetree, the root file system and the
UML kernel, and the console parsed into results.

The platform device comes from a devicetree blob (UML's ``dtb=`` option): a fixed 100 MHz bus
clock, the bridge's interrupt controller and the ``encip,enc-qei`` node, with or without
``interrupts``. The root file system is an initramfs (UML's ``initrd=`` option) holding the test
init (sw/linux/init/), the module and /dev/console. The init reads its mode and the build's
figures from its environment, which the kernel fills from the command line.
"""

from __future__ import annotations

import os
import re
import select
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from .kernel import LINUX_SW, WORK
from .model import Build

BASE = 0x10000000
CLK_HZ = 100_000_000
INIT_SRC = LINUX_SW / "init" / "enc_qei_init.c"


@dataclass
class Boot:
    """One boot: the build it runs against, the init's mode and what the console must show."""
    name: str
    build: Build
    mode: str = "full"          # the init's test: full, lean, refuse
    irq: bool = True            # the devicetree node has an interrupt
    id_word: int | None = None  # the model answers ID reads with this
    expect: list[str] = field(default_factory=list)  # console lines (regexes) that must appear


@dataclass
class Outcome:
    boot: Boot
    results: list[tuple[bool, str]]
    console: str
    seconds: float
    finished: bool
    answers: str = ""           # the model server's bus answers against the RDL's bound


ANSWERS_RE = re.compile(r"answers: the longest (\d+) clocks after its request, (\d+) later than "
                        r"the bound of (\d+) \((\d+) from a write's request after it\)")


def answers_result(text: str) -> tuple[bool, str]:
    """The model server's bus answers against the RDL's bounds (its last line; the late ones, up to
    8, are named in the console log as "late answer"; an access not answered at all is a bus
    error and a line "no answer")."""
    m = ANSWERS_RE.search(text)
    if not m:
        return False, "the model server did not report its bus answers"
    longest, late, bound, after_write = map(int, m.groups())
    unanswered = text.count("enc_qei_server: no answer")
    return late == 0 and unanswered == 0, (
        f"bus answers within the RDL's bounds: {bound} clocks from the request, {after_write} "
        f"from a write's request for the access after it: {late} later, {unanswered} not "
        f"answered, the longest {longest}")


def dts(b: Boot) -> str:
    size = 1 << b.build.addr_w
    irq = "\t\tinterrupt-parent = <&intc>;\n\t\tinterrupts = <0>;\n" if b.irq else ""
    return f"""/dts-v1/;

/ {{
\tcompatible = "encip,uml-linux-test";
\tmodel = "enc_qei in User-Mode Linux (make linux-test)";
\t#address-cells = <1>;
\t#size-cells = <1>;

\tbus_clk: clock-{CLK_HZ} {{
\t\tcompatible = "fixed-clock";
\t\t#clock-cells = <0>;
\t\tclock-frequency = <{CLK_HZ}>;
\t}};

\tintc: interrupt-controller {{
\t\tcompatible = "encip,uml-enc-qei-bridge";
\t\tinterrupt-controller;
\t\t#interrupt-cells = <1>;
\t}};

\tencoder@{BASE:x} {{
\t\tcompatible = "encip,enc-qei";
\t\treg = <{BASE:#x} {size:#x}>;
{irq}\t\tclocks = <&bus_clk>;
\t}};
}};
"""


def _cpio_entry(name: str, mode: int, data: bytes = b"", rdev: tuple[int, int] = (0, 0),
                ino: int = 0) -> bytes:
    namez = name.encode() + b"\0"
    fields = [ino, mode, 0, 0, 1, 0, len(data), 0, 0, rdev[0], rdev[1], len(namez), 0]
    head = b"070701" + b"".join(f"{v:08x}".encode() for v in fields) + namez
    head += b"\0" * (-len(head) % 4)
    return head + data + b"\0" * (-len(data) % 4)


def initramfs(init: Path, module: Path) -> bytes:
    """A newc cpio archive: /init, /enc-qei.ko, the mount points and /dev/console."""
    out = b""
    entries = [("dev", 0o40755, b"", (0, 0)), ("proc", 0o40755, b"", (0, 0)),
               ("sys", 0o40755, b"", (0, 0)), ("dev/console", 0o20600, b"", (5, 1)),
               ("init", 0o100755, init.read_bytes(), (0, 0)),
               ("enc-qei.ko", 0o100644, module.read_bytes(), (0, 0))]
    for i, (name, mode, data, rdev) in enumerate(entries, start=1):
        out += _cpio_entry(name, mode, data, rdev, ino=i)
    return out + _cpio_entry("TRAILER!!!", 0)


def build_init() -> Path:
    """The init, a static executable of the host (UML runs host binaries)."""
    out = WORK / "init" / "enc_qei_init"
    srcs = [INIT_SRC, LINUX_SW / "stimulus.h"]
    if out.exists() and all(s.stat().st_mtime <= out.stat().st_mtime for s in srcs):
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    res = subprocess.run(["gcc", "-static", "-O2", "-Wall", "-Wextra", "-Werror",
                          f"-I{LINUX_SW}", "-o", str(out), str(INIT_SRC)],
                         capture_output=True, text=True)
    if res.returncode:
        raise SystemExit(f"linux-test: the init did not build:\n{res.stderr[-3000:]}")
    return out


RESULT_RE = re.compile(r"^(ok|not ok) \d+ - (.*)$")


def parse(console: str) -> tuple[list[tuple[bool, str]], bool]:
    results = []
    finished = False
    for line in console.splitlines():
        m = RESULT_RE.match(line.strip())
        if m:
            results.append((m.group(1) == "ok", m.group(2)))
        elif re.match(r"^init: \d+ passed, \d+ failed$", line.strip()):
            finished = True
    return results, finished


def run(b: Boot, linux: Path, server: Path, dtc: Path, module: Path, init: Path,
        timeout: float = 240.0) -> Outcome:
    work = WORK / "boots" / b.name
    work.mkdir(parents=True, exist_ok=True)
    (work / "test.dts").write_text(dts(b))
    res = subprocess.run([str(dtc), "-q", "-I", "dts", "-O", "dtb", "-o", str(work / "test.dtb"),
                          str(work / "test.dts")], capture_output=True, text=True)
    if res.returncode:
        raise SystemExit(f"linux-test: dtc failed on {work / 'test.dts'}:\n{res.stderr}")
    (work / "initramfs.cpio").write_bytes(initramfs(init, module))

    tmp = Path(tempfile.mkdtemp(prefix="encqei-"))
    sock = tmp / "model.sock"
    t0 = time.monotonic()
    cmd = [str(server), "--socket", str(sock)]
    if b.id_word is not None:
        cmd += ["--id", f"{b.id_word:#x}"]
    srv = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    try:
        ready = srv.stdout.readline()
        if "listening" not in ready:
            raise SystemExit(f"linux-test: the model server did not start: {ready}"
                             f"{srv.stdout.read()}")
        env_args = [f"enc_test={b.mode}", f"enc_channels={b.build.channels}",
                    f"enc_count_w={b.build.params.get('COUNT_W', 32)}"]
        uml = [str(linux), "mem=128M", f"initrd={work / 'initramfs.cpio'}",
               f"dtb={work / 'test.dtb'}", f"enc_qei_bridge.socket_path={sock}",
               "con0=null,fd:1", "con=null", "ssl=null", "rdinit=/init", "panic=-1",
               *env_args]
        env = {**os.environ, "TMPDIR": str(tmp)}
        proc = subprocess.Popen(uml, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, env=env, cwd=tmp)
        console, deadline = [], time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                proc.kill()
                console.append(f"\nlinux-test: the boot {b.name} timed out after {timeout:.0f} s\n")
                break
            r, _, _ = select.select([proc.stdout], [], [], min(left, 5))
            if r:
                chunk = os.read(proc.stdout.fileno(), 65536)
                if not chunk:
                    break
                console.append(chunk.decode(errors="replace"))
        proc.wait()
    finally:
        try:
            srv.wait(timeout=10)
        except subprocess.TimeoutExpired:
            srv.kill()
        server_out = srv.stdout.read() if srv.stdout else ""
        shutil.rmtree(tmp, ignore_errors=True)
    text = "".join(console).replace("\r\n", "\n") + server_out
    (work / "console.log").write_text(text)
    results, finished = parse(text)
    answers = answers_result(text)
    results.append(answers)
    for pattern in b.expect:
        results.append((re.search(pattern, text, re.M) is not None,
                        f"console shows /{pattern}/"))
    return Outcome(b, results, text, time.monotonic() - t0, finished, answers[1])
