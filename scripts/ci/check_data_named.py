#!/usr/bin/env python3
"""Checks that docs/ and results/ stay apart and that every file there is accounted for.

- docs/ holds the pages (the learners' path in docs/learn/, the studies in docs/studies/, the
  reference pages): Markdown, notebooks and the images they show, nothing else.
- Every file in results/<study>/ (the raw measurements) is named, by its file name, in that
  study's README.md or in a page (docs/**/*.md, README.md); every image in docs/ is named by a
  page.
- Every path a page or a results README names under docs/, results/ or scripts/ exists (a
  `{a,b}` or `*` in the name is expanded).
Prints each problem and exits 1 if there is any; runs in well under a second (.ci/run runs it).

Usage: scripts/ci/check_data_named.py [REPO_ROOT]
"""
import glob
import os
import re
import sys

ROOT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")
ROOT = os.path.abspath(ROOT)
# Notebooks (.ipynb) are pages too: prose and code, run by CTest (scripts/docs/notebooks.py).
PAGE_FILES = (".md", ".ipynb", ".png", ".jpg", ".svg")
IMAGES = (".png", ".jpg", ".svg")
# A repository path in prose: docs/..., results/... or scripts/..., up to a space, a quote or a
# bracket; braces and stars are kept for expansion.
PATH = re.compile(r"(?<![\w/.-])((?:docs|results|scripts)/[\w./{},*#-]*[\w/}*])")


def read(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


def expand(pattern):
    """`a_{x,y}.json` -> a_x.json, a_y.json (one level of braces, as the pages write them)."""
    m = re.search(r"\{([^{}]*)\}", pattern)
    if not m:
        return [pattern]
    return [p for alt in m.group(1).split(",")
            for p in expand(pattern[:m.start()] + alt + pattern[m.end():])]


def exists(rel):
    rel = rel.split("#")[0].rstrip("/.")
    return all(glob.glob(os.path.join(ROOT, p)) for p in expand(rel))


def main():
    problems = []
    pages = sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    pages.append(os.path.join(ROOT, "README.md"))
    readmes = sorted(glob.glob(os.path.join(ROOT, "results", "*", "README.md")))
    page_text = {p: read(p) for p in pages}
    all_pages = "\n".join(page_text.values())

    # docs/: pages and their images only.
    for dirpath, _, files in os.walk(os.path.join(ROOT, "docs")):
        for f in files:
            rel = os.path.relpath(os.path.join(dirpath, f), ROOT)
            if not f.endswith(PAGE_FILES):
                problems.append(f"{rel}: docs/ holds pages and images; measurements go to results/")
            elif f.endswith(IMAGES) and f not in all_pages:
                problems.append(f"{rel}: an image no page shows or names")

    # results/<study>/: every file named by its README or a page.
    for dirpath, _, files in os.walk(os.path.join(ROOT, "results")):
        rel_dir = os.path.relpath(dirpath, os.path.join(ROOT, "results"))
        if rel_dir == ".":
            problems += [f"results/{f}: a file outside any study folder" for f in files]
            continue
        study = rel_dir.split(os.sep)[0]
        readme = os.path.join(ROOT, "results", study, "README.md")
        text = all_pages + (read(readme) if os.path.exists(readme) else "")
        if not os.path.exists(readme):
            problems.append(f"results/{study}: no README.md (the script and command that write it)")
        for f in files:
            if f != "README.md" and f not in text:
                problems.append(f"results/{rel_dir}/{f}: named by no page and not by "
                                f"results/{study}/README.md")

    # Paths named in the pages and the READMEs exist.
    for path in pages + readmes:
        for m in PATH.finditer(read(path)):
            if not exists(m.group(1)):
                problems.append(f"{os.path.relpath(path, ROOT)}: names {m.group(1)}, which is "
                                "not there")

    for p in problems:
        print("check_data_named:", p)
    data = sum(len(fs) for d, _, fs in os.walk(os.path.join(ROOT, "results")))
    print(f"check_data_named: {data - len(readmes)} files in results/, {len(readmes)} READMEs, "
          f"{len(pages)} pages; {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
