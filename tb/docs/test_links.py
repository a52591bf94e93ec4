# SPDX-License-Identifier: Apache-2.0
"""Every link in the repository's Markdown resolves inside the repository.

Plain pytest, no simulator. For README.md, doc/**/*.md and every other tracked Markdown file
(formal/README.md, python/README.md, ...), each link -- inline ``[text](target)``, image
``![alt](target)``, reference definition ``[id]: target``, HTML ``href=`` / ``src=`` --
outside code blocks and code spans must be one of:

- an http(s) URL (not fetched: the tests run offline);
- ``#anchor``: a heading (GitHub's slug) or an explicit ``id=`` / ``name=`` anchor of the same
  file;
- a relative path to a file or folder the repository tracks (``git ls-files``; without git, one
  that exists), optionally with ``#anchor``, which must then be an anchor of that Markdown file.

Anything else fails: a missing target, a path that leaves the repository (``../../x``, ``/abs``),
an untracked or generated file (``sim/waves/...``), another scheme (``file:``, ``mailto:``).
"""

from __future__ import annotations

import re
import subprocess
import unicodedata
from functools import lru_cache
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[2]

# Links that are broken in files this test's owner may not edit, with the reason. The test of such
# a file reports xfail while they stay broken, fails on any other broken link in it, and fails
# when a listed link resolves again (remove it here then).
KNOWN_BROKEN: dict[str, set[str]] = {}

FENCE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN = re.compile(r"(`+)(?:(?!\1).)+?\1")
INLINE = re.compile(r"!?\[(?:[^\[\]]|\[[^\[\]]*\])*\]"  # [text] or ![alt], one level of [] inside
                    r"\(\s*(<[^>]*>|[^)\s]+)"  # (target or (<target>
                    r"(?:\s+(?:\"[^\"]*\"|'[^']*'|\([^)]*\)))?\s*\)")  # an optional title, )
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
HTML = re.compile(r"\b(?:href|src)\s*=\s*[\"']([^\"']+)[\"']", re.I)
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
HTML_ANCHOR = re.compile(r"<[^>]+\b(?:id|name)\s*=\s*[\"']([^\"']+)[\"']", re.I)


@lru_cache(maxsize=None)
def tracked() -> frozenset[str] | None:
    """The repository's tracked files and their folders (relative, '/'-separated), or None
    without git (then a target only has to exist)."""
    try:
        out = subprocess.run(["git", "ls-files", "-z"], cwd=TOP, capture_output=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    files = [f for f in out.stdout.decode().split("\0") if f]
    paths = set(files)
    for f in files:
        parts = f.split("/")
        for i in range(1, len(parts)):
            paths.add("/".join(parts[:i]))
    return frozenset(paths)


def markdown_files() -> list[str]:
    """README.md, doc/**/*.md and every other tracked Markdown file."""
    files = tracked()
    if files is not None:
        found = {f for f in files if f.endswith(".md")}
    else:
        found = {str(p.relative_to(TOP)) for p in TOP.rglob("*.md")
                 if not any(part.startswith(".") for part in p.relative_to(TOP).parts)}
    assert "README.md" in found
    return sorted(found)


def text_lines(text: str):
    """(line number, line) outside fenced code blocks."""
    fence = None
    for n, line in enumerate(text.splitlines(), 1):
        m = FENCE.match(line)
        if m:
            if fence is None:
                fence = m.group(1)
            elif line.strip().startswith(fence):
                fence = None
            continue
        if fence is None:
            yield n, line


def prose_lines(text: str):
    """(line number, line) outside fenced code blocks, with code spans blanked."""
    for n, line in text_lines(text):
        yield n, CODE_SPAN.sub(lambda s: " " * len(s.group(0)), line)


def links(text: str):
    """(line number, target) of every link of a Markdown text."""
    for n, line in prose_lines(text):
        for rx in (INLINE, REFDEF, HTML):
            for m in rx.finditer(line):
                target = m.group(1)
                if target.startswith("<") and target.endswith(">"):
                    target = target[1:-1]
                yield n, target.strip()


def slug(heading: str) -> str:
    """GitHub's anchor for a heading: the text without Markdown markup, lower case, punctuation
    other than '-' and '_' removed, each space a '-'."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # a link: its text
    text = re.sub(r"<[^>]+>", "", text)
    text = text.replace("`", "").lower()
    out = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in "-_" or cat[0] in "LN" or cat == "Mn":
            out.append(ch)
        elif ch == " ":
            out.append("-")
    return "".join(out)


@lru_cache(maxsize=None)
def anchors(rel: str) -> frozenset[str]:
    """The anchors of a Markdown file: heading slugs (a repeated one gets -1, -2, ...) and
    explicit id= / name= anchors."""
    text = (TOP / rel).read_text(encoding="utf-8")
    found, seen = set(), {}
    for _, line in text_lines(text):  # a heading's code spans are part of its slug
        m = HEADING.match(line)
        if m:
            s = slug(m.group(2))
            k = seen.get(s, 0)
            seen[s] = k + 1
            found.add(s if k == 0 else f"{s}-{k}")
        found.update(HTML_ANCHOR.findall(line))
    return frozenset(found)


def problem(rel: str, target: str) -> str | None:
    """Why the link ``target`` in file ``rel`` does not resolve inside the repository, or None."""
    if re.match(r"https?://", target, re.I):
        return None
    if re.match(r"[a-z][a-z0-9+.-]*:", target, re.I):
        return "a URL that is not http(s)"
    path, _, anchor = target.partition("#")
    path = re.sub(r"\?.*$", "", path)
    if not path:
        return None if anchor in anchors(rel) else f"no anchor #{anchor} in {rel}"
    if path.startswith("/"):
        return "an absolute path (use a path relative to the file)"
    full = (TOP / rel).parent / path
    try:
        dest = full.resolve().relative_to(TOP).as_posix()
    except ValueError:
        return "leaves the repository"
    files = tracked()
    if files is not None and dest not in files:
        return f"{dest} is not a file or folder of the repository" + (
            " (it exists but is not tracked)" if full.exists() else "")
    if files is None and not full.exists():
        return f"{dest} does not exist"
    if anchor and dest.endswith(".md") and anchor not in anchors(dest):
        return f"no anchor #{anchor} in {dest}"
    return None


def broken(rel: str) -> dict[str, list[str]]:
    """target -> what is wrong where, for the links of one file that do not resolve."""
    out: dict[str, list[str]] = {}
    for n, target in links((TOP / rel).read_text(encoding="utf-8")):
        why = problem(rel, target)
        if why:
            out.setdefault(target, []).append(f"{rel}:{n}: ({target}) {why}")
    return out


FILES = markdown_files()


def test_the_docs_are_checked():
    assert "README.md" in FILES
    assert any(f.startswith("doc/") for f in FILES), "no doc/*.md found"
    assert sum(len(list(links((TOP / f).read_text(encoding="utf-8")))) for f in FILES) > 100


@pytest.mark.parametrize("rel", FILES)
def test_links_resolve(rel):
    bad = broken(rel)
    known = KNOWN_BROKEN.get(rel, set())
    new = [why for t, whys in bad.items() if t not in known for why in whys]
    if new:
        pytest.fail("links that do not resolve inside the repository:\n"
                    + "\n".join(new), pytrace=False)
    fixed = known - set(bad)
    if fixed:
        pytest.fail(f"{rel}: these links resolve now; remove them from KNOWN_BROKEN: "
                    f"{sorted(fixed)}", pytrace=False)
    if known:
        pytest.xfail(f"{rel} has known broken links (not editable here): {sorted(known)}")


# ---- the checker itself ---------------------------------------------------------------------
def test_slug_follows_github():
    assert slug("Board top (boards/icebreaker)") == "board-top-boardsicebreaker"
    assert slug("Compare (COMPARE, cmp_out)") == "compare-compare-cmp_out"
    assert slug("enc_qei — the bus-attached interface") == "enc_qei--the-bus-attached-interface"
    assert slug("The `make demo` run") == "the-make-demo-run"
    assert slug("What `make regs` writes") == "what-make-regs-writes"


def test_link_forms_are_found():
    text = "\n".join([
        "[a](x.md) and ![b](y.png \"title\") and [c](<z z.md>)",
        "`[not](code.md)` and <a href=\"h.md\">h</a>",
        "[ref]: r.md",
        "```",
        "[not](block.md)",
        "```",
    ])
    assert [t for _, t in links(text)] == ["x.md", "y.png", "z z.md", "h.md", "r.md"]


def test_problems_are_named():
    assert problem("README.md", "https://example.com/x") is None
    assert problem("README.md", "LICENSE") is None
    assert problem("README.md", "doc/") is None
    assert "leaves the repository" in problem("doc/enc_qei.md", "../../outside.md")
    assert "absolute" in problem("README.md", "/etc/passwd")
    assert "not http" in problem("README.md", "file:///etc/passwd")
    assert problem("README.md", "no/such/file.md") is not None
    assert "no anchor" in problem("README.md", "#no-such-heading-anywhere")
