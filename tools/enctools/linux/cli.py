# SPDX-License-Identifier: Apache-2.0
"""``make linux-test`` (scripts/linux_test.py): build the UML kernel with the enc-qei driver,
hold the driver to checkpatch --strict and W=1, check the devicetree binding, build the model
servers and the init, boot once per case and print every result, ending with
``N passed, M failed``."""

from __future__ import annotations

import argparse
import time

from .. import regmap
from . import binding, boot, kernel, model

FULL4 = model.Build("full4", {"CHANNELS": 4, "PROFILE": 2, "COUNT_W": 32, "TS_W": 32})
LEAN2 = model.Build("lean2", {"CHANNELS": 2, "PROFILE": 3, "COUNT_W": 64, "TS_W": 16,
                              "FUNC_MASK": 1})
# the same tests with the channels sharing one engine (CAPS.ENGINE = shared): the full test needs
# channels 0 to 3; the lean one runs on 3 channels (P = 72 clocks, a channel count that is not a
# power of two)
FULL4_ENGINE = model.Build("full4-engine", {**FULL4.params, "ENGINE": 1})
LEAN3_ENGINE = model.Build("lean3-engine", {**LEAN2.params, "CHANNELS": 3, "ENGINE": 1})
WANT_VERSION = 0x0102  # the register map the driver is written for (ENC_QEI_VERSION_MINOR_MIN)


def boots(present_id: int | None) -> list[boot.Boot]:
    return [
        boot.Boot("full4", FULL4, "full", True, present_id,
                  [r"enc-qei 10000000\.encoder: 4 channels, 32-bit counts, full profile$"]),
        boot.Boot("lean2-noirq", LEAN2, "lean", False, present_id,
                  [r"2 channels, 64-bit counts, lean profile, no interrupt: no events$"]),
        boot.Boot("full4-engine", FULL4_ENGINE, "full", True, present_id,
                  [r"enc-qei 10000000\.encoder: 4 channels, 32-bit counts, full profile, "
                   r"shared engine$"]),
        boot.Boot("lean3-engine-noirq", LEAN3_ENGINE, "lean", False, present_id,
                  [r"3 channels, 64-bit counts, lean profile, shared engine, no interrupt: "
                   r"no events$"]),
        boot.Boot("wrong-id", FULL4, "refuse", True, 0x12345678,
                  [r"error -19: not an enc_qei \(ID 0x12345678\)"]),
        boot.Boot("wrong-version", FULL4, "refuse", True, 0x51450201,
                  [r"register map 2\.1 not supported \(ID 0x51450201\): need 1\.2"]),
        boot.Boot("old-version", FULL4, "refuse", True, 0x51450101,
                  [r"register map 1\.1 not supported \(ID 0x51450101\): need 1\.2"]),
    ]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--jobs", type=int, default=2, help="parallel jobs of the builds")
    ap.add_argument("--boot", action="append", default=[],
                    help="run only this boot (repeatable): full4, lean2-noirq, full4-engine, "
                         "lean3-engine-noirq, wrong-id, wrong-version, old-version")
    args = ap.parse_args(argv)
    if args.jobs < 1:
        ap.error("--jobs must be at least 1")
    t0 = time.monotonic()
    results: list[tuple[bool, str]] = []

    tree = kernel.source_tree()
    kernel.overlay(tree)
    obj = kernel.configure(tree)
    kernel.build(tree, obj, args.jobs)
    kernel.say("checkpatch.pl --strict and W=1 on the driver and the bridge")
    found = kernel.checkpatch_findings(tree)
    results.append((not found, "checkpatch --strict: " + ("clean" if not found else
                                                           "; ".join(found))))
    found = kernel.w1_findings(tree, obj)
    results.append((not found, "W=1 build: " + ("no warnings" if not found else
                                                "; ".join(found))))
    linux = kernel.build(tree, obj, args.jobs)  # back to the normal flags after W=1
    module = obj / "drivers/counter/enc-qei.ko"
    dtc = obj / "scripts/dtc/dtc"
    init = boot.build_init()

    rtl_version = regmap.field("ID", "VERSION").reset
    present = None
    if rtl_version < WANT_VERSION and rtl_version >> 8 == WANT_VERSION >> 8:
        present = 0x5145_0000 | WANT_VERSION
        kernel.say(f"the RTL reports register map {rtl_version >> 8}.{rtl_version & 0xff}; "
                    f"the model servers answer ID reads with {present:#010x} until the RTL "
                    "reports 1.2")
    todo = [b for b in boots(present) if not args.boot or b.name in args.boot]
    unknown = set(args.boot) - {b.name for b in boots(present)}
    if unknown:
        ap.error(f"unknown --boot {', '.join(sorted(unknown))}")
    servers = {b.build.name: model.build(b.build, args.jobs) for b in todo}
    dts_files = []
    for b in todo:
        kernel.say(f"boot {b.name}: {b.mode} test against {b.build.name}"
                    + ("" if b.irq else ", no interrupt"))
        out = boot.run(b, linux, servers[b.build.name], dtc, module, init)
        dts_files.append(kernel.WORK / "boots" / b.name / "test.dts")
        if not out.finished:
            out.results.append((False, "the init did not finish (see "
                                f"build/linux/boots/{b.name}/console.log)"))
        good = sum(r[0] for r in out.results)
        kernel.say(f"boot {b.name}: {good} passed, {len(out.results) - good} failed "
                    f"({out.seconds:.1f} s; {out.answers})")
        results += [(ok, f"{b.name}: {what}") for ok, what in out.results]
    kernel.say("devicetree binding: dtschema")
    results += binding.check(tree, dtc, dts_files)

    bad = [what for ok, what in results if not ok]
    for what in bad:
        print(f"FAILED: {what}")
    print(f"linux-test: {time.monotonic() - t0:.0f} s")
    print(f"{len(results) - len(bad)} passed, {len(bad)} failed")
    return 1 if bad else 0
