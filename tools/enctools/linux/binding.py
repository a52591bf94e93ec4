# SPDX-License-Identifier: Apache-2.0
"""The devicetree binding, checked the way the kernel's `make dt_binding_check` does, with the
PyPI dtschema tools (requirements-linux.txt): dt-doc-validate checks the YAML against the
meta-schemas; its example is extracted (dt-extract-example), preprocessed with the kernel's
dt-bindings headers, compiled with the kernel's dtc and validated with dt-validate against the
binding; so is every devicetree a boot of `make linux-test` uses."""

from __future__ import annotations

import subprocess
from pathlib import Path

from ..toolenv import tool
from .kernel import WORK

BINDING = "Documentation/devicetree/bindings/counter/encip,enc-qei.yaml"


def _run(cmd: list[str], **kw) -> subprocess.CompletedProcess:
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def _problems(res: subprocess.CompletedProcess, ignore: tuple[str, ...] = ()) -> list[str]:
    lines = [ln for ln in (res.stdout + res.stderr).splitlines() if ln.strip()
             and not any(i in ln for i in ignore)]
    if res.returncode and not lines:
        lines = [f"exit status {res.returncode}"]
    return lines


def check(tree: Path, dtc: Path, boot_dts: list[Path]) -> list[tuple[bool, str]]:
    """(passed, what) for the binding's own check, its example and each boot's devicetree."""
    work = WORK / "binding"
    work.mkdir(parents=True, exist_ok=True)
    yaml = tree / BINDING
    results = []

    p = _problems(_run([tool("dt-doc-validate"), str(yaml)]))
    results.append((not p, "dt-doc-validate: the binding follows the meta-schemas"
                    + ("" if not p else ": " + "; ".join(p[:5]))))
    schema = work / "processed-schema.json"
    res = _run([tool("dt-mk-schema"), "-j", str(yaml)])
    schema.write_text(res.stdout)
    if res.returncode:
        return results + [(False, "dt-mk-schema: " + "; ".join(_problems(res)[:5]))]

    example = work / "example.dts"
    example.write_text(_run([tool("dt-extract-example"), str(yaml)]).stdout)
    sources = [("the binding's example", example, True)] + \
              [(f"the devicetree of boot {d.parent.name}", d, False) for d in boot_dts]
    for what, dts, cpp in sources:
        dtb = work / (dts.parent.name + "-" + dts.stem + ".dtb")
        src = dts
        if cpp:
            src = work / (dts.stem + ".pp.dts")
            res = _run(["cpp", "-nostdinc", "-I", str(tree / "include"), "-I",
                        str(tree / "scripts/dtc/include-prefixes"), "-undef", "-D__DTS__",
                        "-x", "assembler-with-cpp", "-o", str(src), str(dts)])
            if res.returncode:
                results.append((False, f"{what}: cpp: " + "; ".join(_problems(res)[:5])))
                continue
        res = _run([str(dtc), "-q", "-@", "-I", "dts", "-O", "dtb", "-o", str(dtb), str(src)])
        if res.returncode:
            results.append((False, f"{what}: dtc: " + "; ".join(_problems(res)[:5])))
            continue
        # the bridge's own node and the fixed clock have no schema in this processed set
        p = _problems(_run([tool("dt-validate"), "-s", str(schema), str(dtb)]),
                      ignore=("failed to match any schema",))
        results.append((not p, f"dt-validate: {what} follows the binding"
                        + ("" if not p else ": " + "; ".join(p[:5]))))
    return results
