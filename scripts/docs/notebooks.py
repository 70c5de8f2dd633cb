#!/usr/bin/env python3
"""Runs the learners' path's notebooks (docs/learn/*.ipynb) and checks or rewrites their outputs.

Usage: /usr/bin/python3 scripts/docs/notebooks.py [--build build] [--write] [NOTEBOOK...]

Each notebook runs top to bottom in a fresh Python kernel (nbclient, ipykernel), with the build's
Python module on the path (BUILD/python). Without --write it checks: every cell runs without an
error and every code cell's text output (what it prints, and the value it ends with) is the one
committed, so the notebook's words and numbers cannot drift from the code; the pictures are not
compared (they depend on matplotlib's version). With --write the outputs, pictures included, are
written back into the notebook, to commit. CTest runs the check (python/CMakeLists.txt).
"""
import argparse
import copy
import glob
import os
import sys

import nbformat
from nbclient import NotebookClient

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def texts(cell):
    """A code cell's text outputs: printed streams and text/plain results, in order."""
    out = []
    for o in cell.get("outputs", []):
        if o.get("output_type") == "stream":
            out.append(o.get("text", ""))
        elif o.get("output_type") in ("execute_result", "display_data"):
            data = o.get("data", {})
            if "text/plain" in data and "image/png" not in data:
                out.append(data["text/plain"])
        elif o.get("output_type") == "error":
            out.append(f"error: {o.get('ename')}: {o.get('evalue')}")
    return "".join(out)


def run(path):
    nb = nbformat.read(path, as_version=4)
    executed = copy.deepcopy(nb)
    NotebookClient(executed, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": ROOT}}).execute()
    return nb, executed


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build", default=os.path.join(ROOT, "build"), help="the CMake build folder")
    ap.add_argument("--write", action="store_true", help="write the outputs into the notebooks")
    ap.add_argument("notebooks", nargs="*")
    a = ap.parse_args()
    module = os.path.join(os.path.abspath(a.build), "python")
    if not os.path.isdir(os.path.join(module, "vgpu_rt")):
        sys.exit(f"notebooks: {module}/vgpu_rt is missing (build the target _vgpu_rt)")
    os.environ["PYTHONPATH"] = module + os.pathsep + os.environ.get("PYTHONPATH", "")
    os.environ["PYDEVD_DISABLE_FILE_VALIDATION"] = "1"  # the kernel's debugger: no start-up notes
    paths = a.notebooks or sorted(glob.glob(os.path.join(ROOT, "docs", "learn", "*.ipynb")))
    failed = False
    for path in paths:
        name = os.path.relpath(path, ROOT)
        try:
            committed, executed = run(path)
        except Exception as e:  # a cell raised: nbclient names it
            print(f"notebooks: {name}: {str(e).strip().splitlines()[-1]}", file=sys.stderr)
            failed = True
            continue
        if a.write:
            nbformat.write(executed, path)
            print(f"notebooks: wrote {name}")
            continue
        code = [(i, c, e) for i, (c, e) in enumerate(zip(committed.cells, executed.cells))
                if c.cell_type == "code"]
        for i, c, e in code:
            if texts(c) != texts(e):
                print(f"notebooks: {name}: cell {i} prints something else than the committed "
                      f"notebook (rerun with --write if the change is meant):\n--- committed\n"
                      f"{texts(c)}--- now\n{texts(e)}", file=sys.stderr)
                failed = True
                break
            if not any(o.get("output_type") for o in c.get("outputs", [])) and e.get("outputs"):
                print(f"notebooks: {name}: cell {i} has outputs the committed notebook lacks",
                      file=sys.stderr)
                failed = True
                break
        else:
            print(f"notebooks: {name}: {len(code)} code cells ran, their outputs as committed")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
