# SPDX-License-Identifier: Apache-2.0
"""A copy of the RTL (the working tree's, or a git revision's) for a run to read, and the harness
hook that makes simulations use it: the one snapshotter of mutation testing (`make mutate
--rev`, and its copy that rtl/ edits during a long run cannot reach) and of the velocity
benchmark (`--rtl-rev`).

    copy = RtlCopy.take(dest, rev="HEAD~3")   # rtl/ files and includes as of that revision
    harness.add_hook(copy.hook())             # simulations now read the copy
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass, field
from pathlib import Path

from . import core
from .paths import RTL, TOP


def revision(rev: str) -> str:
    """The full commit id of ``rev``; ValueError when it is not a revision of this repository."""
    res = subprocess.run(["git", "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"], cwd=TOP,
                         capture_output=True, text=True)
    if res.returncode != 0:
        raise ValueError(f"{rev!r} is not a git revision of this repository")
    return res.stdout.strip()


@dataclass
class RtlCopy:
    root: Path  # the copy's top: root/rtl/... mirrors the repository's rtl/
    rev: str | None = None
    files: list = field(default_factory=list)  # repository-relative paths copied

    @classmethod
    def take(cls, dest: Path, rev: str | None = None) -> "RtlCopy":
        """Copy every file of rtl/ (the working tree's, or ``rev``'s) under ``dest``."""
        if rev is None:
            names = [str(p.relative_to(TOP)) for p in sorted(RTL.iterdir()) if p.is_file()]
        else:
            rev = revision(rev)
            names = subprocess.run(["git", "ls-tree", "--name-only", rev, "rtl/"], cwd=TOP,
                                   capture_output=True, text=True, check=True).stdout.split()
        for name in names:
            dst = dest / name
            dst.parent.mkdir(parents=True, exist_ok=True)
            if rev is None:
                dst.write_bytes((TOP / name).read_bytes())
            else:
                dst.write_bytes(subprocess.run(["git", "show", f"{rev}:{name}"], cwd=TOP,
                                               capture_output=True, check=True).stdout)
        return cls(dest, rev, names)

    def path(self, name: str) -> Path:
        """The copy of repository file ``name`` (e.g. "rtl/enc_qei.v")."""
        return self.root / name

    def hook(self, replace: dict | None = None) -> "CopyHook":
        """A harness hook: rtl/ sources and include folders come from the copy; ``replace`` maps
        repository paths to other files still (a mutant in place of its module)."""
        return CopyHook(self, dict(replace or {}))


@dataclass
class CopyHook:
    copy: RtlCopy
    replace: dict  # "rtl/x.v" -> Path

    def configure(self, spec) -> None:
        out = []
        for src in spec.sources:
            p = Path(src)
            try:
                name = str(p.resolve().relative_to(TOP))
            except ValueError:
                out.append(p)
                continue
            if name in self.replace:
                out.append(Path(self.replace[name]))
            elif name in self.copy.files:
                out.append(self.copy.path(name))
            else:
                out.append(p)
        spec.sources = out
        spec.includes = [self.copy.root / Path(d).resolve().relative_to(TOP)
                         if Path(d).resolve() == RTL else d for d in spec.includes]

    def judge(self, spec, tests: int, failed: int) -> bool:
        return False


def core_rtl(copy: RtlCopy) -> list[Path]:
    """The copy's files of the core's rtl fileset, in core order."""
    return [copy.path(f) for f in core.rtl_files()]
