# SPDX-License-Identifier: Apache-2.0
"""Every C block of the documentation compiles against the generated register header.

Plain pytest and gcc, no simulator. The Markdown files are README.md and every tracked ``*.md``
under doc/. The rule for a fenced block:

- A block whose info string is ``c`` is C. The last non-blank line before its opening fence must
  be an HTML comment (invisible on GitHub) that says how it compiles:

  - ``<!-- c: unit -->``: the block is a whole translation unit (declarations, definitions);
  - ``<!-- c: body SIGNATURE -->``: the block is the body of the function ``SIGNATURE``, e.g.
    ``<!-- c: body int find_build(volatile enc_qei_t *q) -->``; declarations the body needs go
    before the signature, each ending with ``;``, e.g. ``<!-- c: body void feed(uint32_t t);
    void drain(volatile enc_qei_chan_t *c) -->``.

  The test compiles ``PRELUDE`` + the block (a unit) or ``PRELUDE`` + the declarations +
  ``SIGNATURE { block }`` (a body) with ``gcc -std=c99 -Wall -Wextra -pedantic -Werror -c``,
  ``-I sw``. A C block without such a comment, or with another one, fails: the test cannot
  classify it.
- A block tagged ``h``, ``C``, ``cpp``, ``c++`` or ``cc`` fails (tag C as ``c``); so does an
  untagged block that looks like C (it uses the header's names or a ``volatile`` pointer): it
  would escape the check.
"""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

from test_links import markdown_files  # tb/docs: the tracked Markdown files

TOP = Path(__file__).resolve().parents[2]
GCC = shutil.which("gcc")
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"]
PRELUDE = "#include <stddef.h>\n#include <stdint.h>\n#include \"enc_qei_regs.h\"\n"
FENCE = re.compile(r"^(\s*)(```+|~~~+)\s*([^\s`]*)")
KIND = re.compile(r"^\s*<!--\s*c:\s*(unit|body\s+(.+?))\s*-->\s*$")
OTHER_C_TAGS = {"h", "C", "cpp", "c++", "cc"}
LOOKS_LIKE_C = re.compile(r"\benc_qei(?:_chan)?_t\b|\bENC_QEI_\w+|\bvolatile\s+\w+\s*\*")


def doc_files() -> list[str]:
    return [f for f in markdown_files() if f == "README.md" or f.startswith("doc/")]


def blocks(text: str):
    """(line of the opening fence, info string, the comment before it or None, block text)."""
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            i += 1
            continue
        start, tag, fence = i + 1, m.group(3), m.group(2)
        prev = next((lines[j] for j in range(i - 1, -1, -1) if lines[j].strip()), "")
        body = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence[:3]):
            body.append(lines[i])
            i += 1
        i += 1
        yield start, tag, prev, "\n".join(body) + "\n"


def source(comment: str, block: str) -> str | None:
    """The C source the test compiles for a block, or None when the comment does not classify it."""
    m = KIND.match(comment)
    if not m:
        return None
    if m.group(1) == "unit":
        return PRELUDE + block
    parts = [p.strip() for p in m.group(2).split(";")]
    decls, sig = parts[:-1], parts[-1]
    if not sig or "(" not in sig:
        return None
    return PRELUDE + "".join(d + ";\n" for d in decls if d) + f"{sig}\n{{\n{block}}}\n"


def c_blocks(docs: dict[str, str]):
    """(where, source or None, problem) for every block the rule covers, in {name: text}."""
    for rel, text in docs.items():
        for line, tag, prev, block in blocks(text):
            where = f"{rel}:{line}"
            if tag == "c":
                src = source(prev, block)
                yield where, src, None if src else (
                    f"{where}: a C block without `<!-- c: unit -->` or `<!-- c: body SIGNATURE -->` "
                    f"on the line before it (found: {prev.strip()[:60]!r})")
            elif tag in OTHER_C_TAGS:
                yield where, None, f"{where}: tag C blocks as ```c (found ```{tag})"
            elif tag == "" and LOOKS_LIKE_C.search(block):
                yield where, None, f"{where}: an untagged block that looks like C: tag it ```c"


def compile_c(src: str, out: Path) -> str:
    """gcc's complaints about ``src``, or '' when it compiles cleanly."""
    c = out.with_suffix(".c")
    c.write_text(src)
    proc = subprocess.run([GCC, *FLAGS, f"-I{TOP / 'sw'}", "-c", str(c), "-o", str(out)],
                          capture_output=True, text=True)
    return "" if proc.returncode == 0 else proc.stderr


def test_the_rule_classifies_and_compiles(tmp_path):
    """The rule itself: a unit, a body with a declaration, an unclassified block, a wrong tag and
    an untagged block of C are told apart, and a block that does not compile is caught."""
    text = ("<!-- c: unit -->\n```c\nuint32_t f(void);\n```\n\n"
            "<!-- c: body void drain(uint32_t x); void g(volatile enc_qei_t *q) -->\n```c\n"
            "drain(q->glb.CAPS);\n```\n"
            "```c\nint x;\n```\n```cpp\nint y;\n```\n```\nvolatile enc_qei_t *q;\n```\n"
            "```\nmake x\n```\n"
            "<!-- c: body void h(volatile enc_qei_t *q) -->\n```c\nq->chan[0].COUNT = 1;\n```\n")
    found = list(blocks(text))
    assert [b[1] for b in found] == ["c", "c", "c", "cpp", "", "", "c"]
    srcs = [source(b[2], b[3]) for b in found]
    assert srcs[0] == PRELUDE + "uint32_t f(void);\n"
    assert srcs[1] == PRELUDE + "void drain(uint32_t x);\nvoid g(volatile enc_qei_t *q)\n{\n" \
        "drain(q->glb.CAPS);\n}\n"
    assert srcs[2] is None
    problems = [p for _, _, p in c_blocks({"x.md": text}) if p]
    assert [p.split(": ")[0] for p in problems] == ["x.md:10", "x.md:13", "x.md:16"], problems
    if GCC:
        assert compile_c(srcs[1], tmp_path / "ok.o") == ""
        assert "COUNT" in compile_c(srcs[6], tmp_path / "bad.o")


def test_every_doc_c_block_compiles(tmp_path):
    if GCC is None:
        pytest.skip("gcc not installed")
    found = list(c_blocks({f: (TOP / f).read_text() for f in doc_files()}))
    assert len(found) >= 7, "the docs' C blocks were not found; did the format change?"
    problems = [p for _, _, p in found if p]
    for n, (where, src, problem) in enumerate(found):
        if src is not None:
            err = compile_c(src, tmp_path / f"block{n}.o")
            if err:
                problems.append(f"{where}: gcc {' '.join(FLAGS)}:\n{err}")
    assert not problems, "\n".join(problems)
