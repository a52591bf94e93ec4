# SPDX-License-Identifier: Apache-2.0
"""The UML kernel with the enc-qei driver: source, overlay, configuration, build and checks.

The kernel source is Debian's ``linux-source-6.1`` (/usr/src/linux-source-6.1.tar.xz), extracted
once into build/linux/src/ without the sources this configuration never compiles (SKIPPED). The
files of sw/linux/ are laid into that tree as they would be upstream (drivers/counter/, the
binding under Documentation/, the UML bridge under arch/um/drivers/), with their Kconfig and
Makefile lines inserted between marker comments. The object tree is build/linux/obj-<key>/, the
key a hash of the kernel version and the configuration (the fragment
sw/linux/uml/enc-qei-uml.config and both Kconfig entries), so a changed configuration builds
afresh and an unchanged one rebuilds only what changed.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

from ..paths import BUILD, SW

LINUX_SW = SW / "linux"
WORK = BUILD / "linux"
SRC_PARENT = WORK / "src"
TARBALL_GLOB = "linux-source-6.1*.tar.xz"
CONFIG_FRAGMENT = LINUX_SW / "uml" / "enc-qei-uml.config"
ARCH = ["ARCH=um", "SUBARCH=x86_64"]

# files of sw/linux/ -> their place in the kernel tree
OVERLAY = {
    "drivers/counter/enc-qei.c": "drivers/counter/enc-qei.c",
    "drivers/counter/enc-qei-test.c": "drivers/counter/enc-qei-test.c",
    "Documentation/devicetree/bindings/counter/encip,enc-qei.yaml":
        "Documentation/devicetree/bindings/counter/encip,enc-qei.yaml",
    "uml-bridge/enc_qei_bridge.c": "arch/um/drivers/enc_qei_bridge.c",
}
# (sw/linux file, kernel file, the line the block goes before; None: at the end)
INSERTS = [
    ("drivers/counter/Kconfig", "drivers/counter/Kconfig", "endif # COUNTER"),
    ("drivers/counter/Makefile", "drivers/counter/Makefile", None),
    ("uml-bridge/Kconfig", "arch/um/drivers/Kconfig", None),
    ("uml-bridge/Makefile", "arch/um/drivers/Makefile", None),
]
VENDOR = ('  "^encip,.*":\n'
          '    description: enc_qei encoder interface IP (HEDS-5000 encoder interface library)\n')
BEGIN, END = "# enc-qei overlay begin", "# enc-qei overlay end"
# the files checkpatch --strict and W=1 hold to zero findings (kernel-tree paths)
DRIVER_FILES = ["drivers/counter/enc-qei.c", "drivers/counter/enc-qei-test.c",
                "Documentation/devicetree/bindings/counter/encip,enc-qei.yaml",
                "arch/um/drivers/enc_qei_bridge.c"]
W1_OBJECTS = ["drivers/counter/enc-qei.o", "arch/um/drivers/enc_qei_bridge.o"]


class KernelError(SystemExit):
    pass


def say(msg: str) -> None:
    print(f"linux-test: {msg}", flush=True)


def tarball() -> Path:
    found = sorted(Path("/usr/src").glob(TARBALL_GLOB))
    if not found:
        raise KernelError("linux-test: no /usr/src/linux-source-6.1*.tar.xz; install Debian's "
                          "linux-source-6.1 (scripts/bootstrap.sh --linux does it as root)")
    return found[-1]


# The tree is extracted without sources this UML configuration never compiles (about 1.1 GB of the
# 1.5 GB: the other architectures, the largest driver families, sound, networking and tools).
# Every Kconfig, Makefile and Kbuild file stays, so configuration sees the whole tree. A
# configuration that compiles one of them stops its build naming the missing file.
SKIPPED_DRIVERS = ["crypto", "gpu", "iio", "infiniband", "media", "net", "pinctrl", "scsi",
                   "staging", "usb"]
SKIPPED = (["arch/*.[chS]", "arch/*.dts", "arch/*.dtsi", "sound/*.[chS]", "net/*.[ch]", "tools/*",
            "Documentation/*.rst", "Documentation/*.txt"]
           + [f"drivers/{d}/*.[chS]" for d in SKIPPED_DRIVERS])
# taken back from what SKIPPED leaves out: the architecture (um on x86)
RESTORED = ["arch/um", "arch/x86"]


def source_tree() -> Path:
    """The extracted kernel tree (extracted on first use; ~30 s, ~400 MB)."""
    tb = tarball()
    st = tb.stat()
    stamp_text = f"{tb.name} {st.st_size} {int(st.st_mtime)} {SKIPPED} {RESTORED}\n"
    stamp = SRC_PARENT / ".extracted"
    name = tb.name.removesuffix(".tar.xz")
    tree = SRC_PARENT / name
    if stamp.exists() and stamp.read_text() == stamp_text and (tree / "Makefile").exists():
        return tree
    say(f"extracting {tb} into {tree} (once)")
    if SRC_PARENT.exists():
        shutil.rmtree(SRC_PARENT)
    SRC_PARENT.mkdir(parents=True)
    top = name + "/"
    subprocess.run(["tar", "xJf", str(tb), "-C", str(SRC_PARENT)]
                   + [f"--exclude={top}{pattern}" for pattern in SKIPPED], check=True)
    subprocess.run(["tar", "xJf", str(tb), "-C", str(SRC_PARENT)]
                   + [top + d for d in RESTORED], check=True)
    if not (tree / "Makefile").exists():
        raise KernelError(f"linux-test: {tb} did not extract to {tree}")
    stamp.write_text(stamp_text)
    return tree


def kernel_version(tree: Path) -> str:
    text = (tree / "Makefile").read_text()
    v = {k: re.search(rf"^{k} = (\S*)", text, re.M).group(1)
         for k in ("VERSION", "PATCHLEVEL", "SUBLEVEL")}
    return f"{v['VERSION']}.{v['PATCHLEVEL']}.{v['SUBLEVEL']}"


def _write_if_changed(path: Path, text: str) -> None:
    if not path.exists() or path.read_text() != text:
        path.write_text(text)


def _insert_block(text: str, block: str, before: str | None) -> str:
    text = re.sub(rf"\n?{re.escape(BEGIN)}\n.*?{re.escape(END)}\n", "\n", text, flags=re.S)
    wrapped = f"{BEGIN}\n{block.rstrip()}\n{END}\n"
    if before is None:
        return text.rstrip("\n") + "\n\n" + wrapped
    at = text.rindex(before)
    return text[:at] + wrapped + "\n" + text[at:]


def overlay(tree: Path) -> None:
    """Lay the sw/linux files into the tree (a file is rewritten only when it changed)."""
    for src, dst in OVERLAY.items():
        _write_if_changed(tree / dst, (LINUX_SW / src).read_text())
    for src, dst, before in INSERTS:
        path = tree / dst
        original = path.read_text()
        _write_if_changed(path, _insert_block(original, (LINUX_SW / src).read_text(), before))
    prefixes = tree / "Documentation/devicetree/bindings/vendor-prefixes.yaml"
    text = prefixes.read_text()
    if '"^encip,.*"' not in text:
        keys = list(re.finditer(r'^  "\^([a-z0-9-]+),\.\*":\n', text, re.M))
        after = next(m for m in keys if m.group(1) > "encip")
        prefixes.write_text(text[:after.start()] + VENDOR + text[after.start():])


def config_key(tree: Path) -> str:
    h = hashlib.sha256()
    h.update(kernel_version(tree).encode())
    for p in (CONFIG_FRAGMENT, LINUX_SW / "drivers/counter/Kconfig",
              LINUX_SW / "uml-bridge/Kconfig"):
        h.update(p.read_bytes())
    return h.hexdigest()[:12]


def _make(tree: Path, obj: Path, *args: str, log: Path | None = None,
          jobs: int = 1) -> subprocess.CompletedProcess:
    cmd = ["make", "-C", str(tree), f"O={obj}", *ARCH, f"-j{jobs}", *args]
    res = subprocess.run(cmd, capture_output=True, text=True)
    if log is not None:
        log.write_text(res.stdout + res.stderr)
    return res


def configure(tree: Path) -> Path:
    """The object tree of this configuration, configured (tinyconfig + the fragment)."""
    obj = WORK / f"obj-{config_key(tree)}"
    if (obj / ".config").exists() and (obj / ".config-ok").exists():
        return obj
    say(f"configuring the kernel in {obj} (tinyconfig + {CONFIG_FRAGMENT.name})")
    obj.mkdir(parents=True, exist_ok=True)
    res = _make(tree, obj, "tinyconfig")
    if res.returncode:
        raise KernelError(f"linux-test: make tinyconfig failed:\n{res.stderr[-2000:]}")
    res = subprocess.run([str(tree / "scripts/kconfig/merge_config.sh"), "-m", "-O", str(obj),
                          str(obj / ".config"), str(CONFIG_FRAGMENT)],
                         capture_output=True, text=True, cwd=tree,
                         env={**os.environ, **dict(a.split("=") for a in ARCH)})
    if res.returncode:
        raise KernelError(f"linux-test: merge_config.sh failed:\n{res.stdout[-2000:]}")
    res = _make(tree, obj, "olddefconfig")
    if res.returncode:
        raise KernelError(f"linux-test: make olddefconfig failed:\n{res.stderr[-2000:]}")
    have = (obj / ".config").read_text()
    missing = [line for line in CONFIG_FRAGMENT.read_text().splitlines()
               if line.startswith("CONFIG_") and f"\n{line}\n" not in f"\n{have}"]
    if missing:
        raise KernelError("linux-test: the kernel configuration lost " + ", ".join(missing)
                          + f" (see {obj}/.config: a dependency is missing)")
    (obj / ".config-ok").write_text("")
    return obj


def build(tree: Path, obj: Path, jobs: int) -> Path:
    """Build the UML kernel and its modules; the path of the `linux` binary."""
    cold = not (obj / "linux").exists()
    say("building the UML kernel" + (" (a cold build: about 2 minutes on 2 cores)"
                                      if cold else ""))
    t0 = time.monotonic()
    log = obj / "build.log"
    res = _make(tree, obj, "all", log=log, jobs=jobs)
    if res.returncode:
        tail = "\n".join((res.stdout + res.stderr).splitlines()[-30:])
        raise KernelError(f"linux-test: the kernel build failed ({log}):\n{tail}")
    say(f"kernel built in {time.monotonic() - t0:.0f} s")
    return obj / "linux"


def w1_findings(tree: Path, obj: Path) -> list[str]:
    """Warnings of the driver and the bridge built with W=1 (empty: clean)."""
    for o in W1_OBJECTS:  # force a recompile: W=1 output appears only when the file compiles
        (obj / o).unlink(missing_ok=True)
    res = _make(tree, obj, "W=1", *W1_OBJECTS)
    out = res.stdout + res.stderr
    findings = [line for line in out.splitlines()
                if ("warning:" in line or "error:" in line)
                and ("enc-qei" in line or "enc_qei" in line)]
    if res.returncode and not findings:
        findings = out.splitlines()[-20:]
    return findings


def checkpatch_findings(tree: Path) -> list[str]:
    """checkpatch.pl --strict on the driver's files (empty: clean)."""
    findings = []
    for f in DRIVER_FILES:
        res = subprocess.run(["perl", "scripts/checkpatch.pl", "--strict", "--no-summary",
                              "--terse", "--show-types", "-f", f],
                             capture_output=True, text=True, cwd=tree)
        findings += [line for line in (res.stdout + res.stderr).splitlines() if line.strip()]
    return findings
