#!/usr/bin/env python3
"""Checks that the links between the repository's pages, and the docs/ paths its files name,
lead somewhere.

- Every relative Markdown link and image in a *.md file, `[text](target)`, `![alt](target)` or
  `[id]: target`: the target file or folder exists, relative to the page; a `#anchor` names a
  heading of the target page (GitHub's slug: lower case, punctuation dropped, spaces to hyphens,
  -1, -2 ... for repeats), or of the page itself for `(#anchor)`. Links to other sites, and
  links inside code (fenced blocks, `spans`), are not checked.
- Every `docs/...` path that a file names in its text (a script writing a page, a comment citing
  one, a page naming another in prose; notebooks by their cells' sources): it exists, relative
  to the repository root, with its `#anchor` if it has one. `scripts/docs/` and the like are not
  such paths (a `/` before `docs/`); `*` and `{a,b}` in a name are expanded.
Prints one line per broken link, FILE:LINE: TARGET (why), and exits 1 if there is any. Looks at
the tracked and untracked files alike, leaving out .git, node_modules and the build folders
(build, build-*). Standard library only; runs in about a second (.ci/run runs it).

Usage: scripts/ci/check_links.py [REPO_ROOT]
"""
import glob
import json
import os
import re
import sys
import unicodedata
from urllib.parse import unquote

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from check_data_named import expand  # noqa: E402  (a page's `a_{x,y}.json` names)

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                       os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
SKIP_DIRS = {".git", "node_modules", "__pycache__"}
# Files whose text may name a docs/ path: sources, scripts, build files, pages and notebooks.
TEXT_EXT = {".md", ".py", ".pyi", ".sh", ".cpp", ".h", ".hpp", ".cc", ".c", ".mjs", ".js",
            ".html", ".cmake", ".yml", ".yaml", ".ipynb"}
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")
# [text](target) and ![alt](target), found by their "](target)" end, since a link's text may
# run over several lines; the target may be <in angle brackets> and have a "title".
INLINE = re.compile(r"\]\(\s*(<[^>]*>|[^)\s]+)(?:\s+\"[^\"]*\")?\s*\)")
REFDEF = re.compile(r"^\s{0,3}\[[^\]]+\]:\s*(<[^>]*>|\S+)")
CODE_SPAN = re.compile(r"(`+)(.+?)\1")
FENCE = re.compile(r"^\s{0,3}(```|~~~)")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")
# A docs/ path in text: not part of a longer path (scripts/docs/...) or word; ../ prefixes kept
# out (those are Markdown links, checked relative to their page).
DOCS_PATH = re.compile(r"(?<![\w/.\-])docs/[\w./{},*#\-]*[\w}*]")


def slug(text):
    """GitHub's anchor for a heading's text."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link shows its text
    text = re.sub(r"<[^>]+>", "", text)                       # HTML tags show nothing
    text = text.strip().lower()
    kept = []
    for ch in text:
        cat = unicodedata.category(ch)
        if ch in " -_" or cat[0] in "LN" or cat in ("Mn", "Mc", "Pc"):
            kept.append(ch)
    return "".join(kept).replace(" ", "-")


def lines_outside_fences(text):
    """(line number, line) of the lines not inside a fenced code block."""
    fenced = None
    for n, line in enumerate(text.split("\n"), 1):
        m = FENCE.match(line)
        if m:
            if fenced is None:
                fenced = m.group(1)
            elif m.group(1) == fenced:
                fenced = None
            continue
        if fenced is None:
            yield n, line


_anchors = {}


def anchors(path):
    """The anchors of a Markdown page's headings, repeats numbered as GitHub numbers them."""
    if path not in _anchors:
        seen, out = {}, set()
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for _, line in lines_outside_fences(text):
            m = HEADING.match(line)
            if not m:
                continue
            s = slug(m.group(2))
            k = seen.get(s, 0)
            seen[s] = k + 1
            out.add(s if k == 0 else f"{s}-{k}")
            out.update(re.findall(r'<a\s+(?:name|id)="([^"]+)"', line))
        _anchors[path] = out
    return _anchors[path]


def check_target(base_dir, target, page):
    """Why the target (a path relative to base_dir, maybe with #anchor) is broken, or None."""
    path, _, anchor = target.partition("#")
    path = unquote(path)
    full = os.path.normpath(os.path.join(base_dir, path)) if path else page
    if not os.path.exists(full):
        return "no such file"
    if anchor and full.endswith(".md") and os.path.isfile(full):
        if unquote(anchor).lower() not in anchors(full):
            return f"no heading #{anchor} in {os.path.relpath(full, ROOT)}"
    return None


def check_markdown(rel, text, problems):
    page = os.path.join(ROOT, rel)
    base = os.path.dirname(page)
    for n, line in lines_outside_fences(text):
        bare = CODE_SPAN.sub("", line)
        targets = [m.group(1) for m in INLINE.finditer(bare)]
        m = REFDEF.match(bare)
        if m:
            targets.append(m.group(1))
        for t in targets:
            t = t.strip("<>")
            if not t or SCHEME.match(t) or t.startswith("//"):
                continue
            why = check_target(base, t, page)
            if why:
                problems.append(f"{rel}:{n}: {t} ({why})")


def check_docs_paths(rel, text, problems):
    for n, line in enumerate(text.split("\n"), 1):
        for m in DOCS_PATH.finditer(line):
            name = m.group(0)
            path, _, anchor = name.partition("#")
            path = path.rstrip("/.")
            found = [f for p in expand(path) for f in glob.glob(os.path.join(ROOT, p))]
            if not found or len(found) < len(expand(path)):
                problems.append(f"{rel}:{n}: {name} (no such file)")
            elif anchor:
                why = check_target(ROOT, path + "#" + anchor, None)
                if why:
                    problems.append(f"{rel}:{n}: {name} ({why})")


def notebook_text(text):
    """A notebook's cell sources, one after another (its outputs may hold anything)."""
    cells = json.loads(text).get("cells", [])
    return "\n".join("".join(c.get("source", [])) for c in cells)


def files():
    for dirpath, dirnames, filenames in os.walk(ROOT):
        top = os.path.relpath(dirpath, ROOT) == "."
        dirnames[:] = sorted(d for d in dirnames if d not in SKIP_DIRS and
                             not (top and (d == "build" or d.startswith("build-"))))
        for f in sorted(filenames):
            yield os.path.relpath(os.path.join(dirpath, f), ROOT)


def is_text_source(rel):
    name = os.path.basename(rel)
    ext = os.path.splitext(name)[1]
    if ext in TEXT_EXT or name == "CMakeLists.txt":
        return True
    if ext:
        return False
    try:  # an extensionless script, such as .ci/run
        with open(os.path.join(ROOT, rel), "rb") as f:
            return f.read(2) == b"#!"
    except OSError:
        return False


def main():
    problems, pages, sources = [], 0, 0
    for rel in files():
        if not is_text_source(rel) or rel == "scripts/ci/check_links.py":
            continue
        try:
            with open(os.path.join(ROOT, rel), encoding="utf-8") as f:
                text = f.read()
        except (UnicodeDecodeError, OSError):
            continue
        if rel.endswith(".md"):
            pages += 1
            check_markdown(rel, text, problems)
        if rel.endswith(".ipynb"):
            text = notebook_text(text)
        sources += 1
        check_docs_paths(rel, text, problems)
    for p in problems:
        print(f"check_links: {p}")
    print(f"check_links: {pages} pages, {sources} files read; {len(problems)} broken links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
