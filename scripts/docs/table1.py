#!/usr/bin/python3
"""The paper's Table 1 beside ours: renders the three scenes on every profile with vgpu-rt, reads
the statistics and the cost model's predictions (host/model/cost_model.h) from --stats-json, and writes
docs/studies/table1.md and docs/studies/table1_breakdown.png (matplotlib).

Usage: /usr/bin/python3 scripts/docs/table1.py [--vgpu-rt build/host/vgpu-rt] [--reuse] [--fit]
  --reuse  keep the JSON of earlier renders (build/table1/*.json) instead of rendering again
  --fit    print the fixed costs fitted on the calibration cells (for vgpu/profile.cpp) and stop
"""
import argparse
import json
import os
import re
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# Fal, Vasconcelos & Delrieux, Table 1: 256x256, ms.
PAPER = {
    "Sphere": {"gf5700": 2800, "cpu": 2864, "gf6600": 500},
    "Bunny3": {"gf5700": 5075, "cpu": 2013, "gf6600": 1079},
    "BunnyRefl": {"gf5700": 10355, "cpu": 2504, "gf6600": 1788},
}
# Our reading of the paper's three scenes (see "Reading the paper's settings" in the output).
SCENES = [("Sphere", "sphere-alone"), ("Bunny3", "bunny"), ("BunnyRefl", "bunny-mirror")]
PROFILES = ["gf5700", "gf6600", "rtx4090"]
GPUS = ["gf5700", "gf6600"]  # the paper's two cards
NAMES = {"gf5700": "GeForce FX 5700", "gf6600": "GeForce 6600", "rtx4090": "RTX 4090", "cpu": "CPU"}
# The same settings for every cell, read from the paper: 256x256, 3 ray-tracing iterations and a
# 15x15x15 grid as Fig. 1 states, no shadow rays (the paper's 13 kernels have none).
SETTINGS = ["--size", "256x256", "--bounces", "2", "--shading", "phong", "--shadows", "off",
            "--grid", "15"]
# The paper's other timed figures (GeForce FX 5700 only): label, scene, settings the paper states
# (on top of SETTINGS), paper ms, and whether the scene is the calibration scene itself.
FIGURES = [("Fig. 1: classic scene, 848 faces, 15x15x15 grid", "classic", ["--grid", "15"], 7852, False),
           ("Fig. 2: bunny, 948 faces", "bunny-low", [], 3485, False),
           ("Fig. 2: bunny, 3851 faces (ours: 3674)", "bunny", [], 6068, True),
           ("Fig. 3: teapot, 5030 faces", "teapot", [], 7990, False)]
# Other readings of what the paper leaves unsaid: scene set x shadow rays x grid. Each is
# refitted on its own Bunny3 and predicts its own four other cells (the sensitivity table).
SCENE_SETS = {"lighter": {"Sphere": "sphere-alone", "Bunny3": "bunny", "BunnyRefl": "bunny-mirror"},
              "richer": {"Sphere": "sphere", "Bunny3": "bunny", "BunnyRefl": "bunny-refl"}}
READINGS = [(scenes, shadows, grid) for scenes in ("lighter", "richer")
            for shadows in ("off", "on") for grid in ("15", "auto")]
# The two cells the free parameters are fitted on; every other cell is a prediction.
CALIBRATION = [("Bunny3", "gf5700"), ("Bunny3", "gf6600")]
# Fixed costs per unit u (us): pass_us = u, program_load_us = u, readback_us = 2u (assumed split).
SPLIT = {"pass": 1.0, "load": 1.0, "readback": 2.0}
TARGET_CELL, TARGET_RATIO = 0.35, 0.25


def run(exe, scene, profile, work, reuse, masks="off", engine=None, extra=(), tag=""):
    """Renders one cell (SETTINGS, then `extra` overriding them) and returns its --stats-json."""
    tag = f"{scene}-{engine or profile}" + ("-masks" if masks == "on" else "") + tag
    path = os.path.join(work, tag + ".json")
    if reuse and os.path.exists(path):
        return json.load(open(path))
    opts = dict(zip(SETTINGS[::2], SETTINGS[1::2]))
    opts.update(zip(extra[::2], extra[1::2]))
    args = [*[x for kv in opts.items() for x in kv], "--profile", profile, "--masks", masks]
    if engine:
        args += ["--engine", engine]
    return vgpurt.render(exe, scene, args, stats_json=path, cwd=ROOT, echo=True)


def has_engine(exe):
    return "--engine" in vgpurt.run([exe, "render", "--help"], cwd=ROOT)


def err(pred, paper):
    return (pred - paper) / paper


def pct(x):
    return f"{100 * x:+.0f}%"


def span(values):
    lo, hi = f"{min(values):.1f}", f"{max(values):.1f}"
    return f"about {lo}" if lo == hi else f"{lo}-{hi}"


def fixed_units(t):
    """A frame's fixed costs in units of u (SPLIT), from its totals."""
    return (SPLIT["pass"] * t["passes"] + SPLIT["load"] * t["program_loads"] +
            SPLIT["readback"] * t["query_readbacks"])


def split(j, gpu):
    """A prediction as (ms that do not depend on u, units of u): total = rest + u * units."""
    b = j["predicted_breakdown"][gpu]
    fixed = b["per_pass_ms"] + b["program_load_ms"] - b["bus_ms"] + b["readback_ms"]
    return b["total_ms"] - fixed, fixed_units(j["totals"])


def fit(data):
    """u (us) that makes each calibration cell's prediction equal the paper's time."""
    out = {}
    for scene, gpu in CALIBRATION:
        rest, units = split(data[(scene, gpu)], gpu)
        out[gpu] = 1e3 * (PAPER[scene][gpu] - rest) / units
    return out


def parse_parameters():
    """Every profile figure with its source comment, from vgpu/profile.cpp."""
    text = open(os.path.join(ROOT, "vgpu/profile.cpp")).read()
    # Each profile's fields follow its `VAR.name = "NAME";` (a variable may be reused: h200's m).
    rows, current = {}, {}
    for m in re.finditer(r"^\s+(fx|ati|g6|m)\.(\w+) = (.+?);[ \t]*(?://[ \t]*(.*))?$", text, re.M):
        v, field, value, source = m.group(1), m.group(2), m.group(3), (m.group(4) or "").strip()
        if field == "name":
            current[v] = value.strip('"')
            rows.setdefault(current[v], [])
            continue
        if field in ("display", "cg_profile", "gl_renderer"):
            continue
        if "fitted" in source:
            status = "fitted"
        elif "measured" in source:
            status = "measured"
        elif "model parameter" in source:
            status = "assumed"
        else:
            status = "public" if source else "-"
        rows[current[v]].append((field, value, source, status))
    return rows


def parse_cost_params():
    """The cost model's own assumed parameters, from host/model/cost_model.h and .cpp."""
    h = open(os.path.join(ROOT, "host/model/cost_model.h")).read()
    ops = re.search(r"double scalar_ops_per_instruction = ([\d.]+);", h).group(1)
    body = re.search(r"double branch_body_share = ([\d.]+);", h).group(1)
    return [
        ("scalar_ops_per_instruction", ops, "assumed: hand count, the ray-triangle test's 62 counted "
         "scalar operations are about 22 fp30 vec4 instructions, voxel_exits' 27 about 9; capped "
         "by alu_lanes (1 on the RTX 4090: scalar cores)"),
        ("batches skipping a branch", "counted, not a parameter",
         "measured by the virtual GPU per pass: branch-idle fragments in 8x4 (warp) and 32x32 "
         "(NV4x, about 1000 pixels) tiles where no fragment takes the branch "
         "(`idle_in_batch32`, `idle_in_batch1024`); the profile's branch_granularity picks one"),
        ("branch_body_share", body, "assumed: hand count of the kernels, intersecciones keeps 132 of "
         "135 operations and 6 of 8 fetches (84 of 116 bytes) inside its branch"),
        ("fixed-cost split", "pass_us : program_load_us : readback_us = 1 : 1 : 2",
         "assumed: the data cannot separate them (every pass loads a program; a read-back every "
         "~3 passes), so one unit per GPU is fitted and split this way"),
    ]


def breakdown_chart(data, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    segs = [("arithmetic (useful)", "#4c72b0"), ("texture (useful)", "#55a868"),
            ("memory (useful)", "#8172b2"),
            ("idle fragments (finished rays)", "#c44e52"), ("per-pass", "#dd8452"),
            ("program loads", "#937860"), ("read-backs", "#da8bc3")]

    def parts(b):
        work = b["arithmetic_ms"] + b["texture_ms"] + b["memory_ms"]
        live = 1 - b["wasted_ms"] / work if work > 0 else 1
        return [b["arithmetic_ms"] * live, b["texture_ms"] * live, b["memory_ms"] * live,
                b["wasted_ms"], b["per_pass_ms"], b["program_load_ms"], b["readback_ms"]]

    fig, axes = plt.subplots(2, len(GPUS), figsize=(12, 8.2), sharex=True)
    x = range(len(SCENES))
    for col, gpu in enumerate(GPUS):
        vals = [parts(data[(s, gpu)]["predicted_breakdown"][gpu]) for s, _ in SCENES]
        for row, share in ((0, False), (1, True)):
            ax = axes[row][col]
            bottoms = [0.0] * len(SCENES)
            for k, (name, color) in enumerate(segs):
                v = [p[k] / (sum(p) / 100 if share else 1e3) for p in vals]
                ax.bar(x, v, bottom=bottoms, color=color, label=name, width=0.6)
                bottoms = [a + b for a, b in zip(bottoms, v)]
            ax.grid(axis="y", alpha=0.3)
            if share:
                ax.set_ylabel("share of the predicted time, %")
                ax.set_ylim(0, 100)
                continue
            ax.scatter(x, [PAPER[s][gpu] / 1e3 for s, _ in SCENES], marker="_", s=900,
                       color="black", linewidths=2.5, zorder=3, label="paper (Table 1)")
            for i, (s, _) in enumerate(SCENES):
                label = "fitted" if (s, gpu) in CALIBRATION else "predicted"
                ax.annotate(label, (i, bottoms[i]), ha="center", va="bottom", fontsize=8,
                            xytext=(0, 2), textcoords="offset points")
            ax.set_ylabel("predicted time, s")
            ax.set_ylim(0, max(bottoms) * 1.08)
            ax.set_title(f"{NAMES[gpu]}: where the predicted time goes")
        axes[1][col].set_xticks(list(x), [s for s, _ in SCENES])
    handles, labels = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=9, frameon=False)
    fig.suptitle("Cost model: " + " ".join(SETTINGS) + ", masks off (fixed costs fitted on "
                 "Bunny3)\nscenes: " + ", ".join(f"{n} = {f}" for n, f in SCENES), fontsize=9)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build/host/vgpu-rt"))
    ap.add_argument("--work", default=os.path.join(ROOT, "build/table1"))
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--fit", action="store_true")
    a = ap.parse_args()
    exe = os.path.abspath(a.vgpu_rt)
    os.makedirs(a.work, exist_ok=True)

    data = {}
    for scene, file in SCENES:
        for p in (GPUS if a.fit else PROFILES):
            data[(scene, p)] = run(exe, file, p, a.work, a.reuse)
            if "predicted_ms" not in data[(scene, p)]:
                sys.exit(f"{exe} writes no predicted_ms: rebuild it")
    if a.fit:
        for gpu, u in fit(data).items():
            print(f"{gpu}: pass_us = program_load_us = {u:.0f}, readback_us = {2 * u:.0f}")
        return
    masks = {scene: run(exe, file, "gf5700", a.work, a.reuse, masks="on") for scene, file in SCENES}
    # MRT executed: the fused two-output passes (--mrt on) need a profile with several outputs;
    # the counters do not depend on the profile, and every profile's prediction is in the JSON.
    mrt = {scene: run(exe, file, "gf6600", a.work, a.reuse, extra=["--mrt", "on"], tag="-mrt")
           for scene, file in SCENES}
    mrt_masks = {scene: run(exe, file, "gf6600", a.work, a.reuse, masks="on",
                            extra=["--mrt", "on"], tag="-mrt")
                 for scene, file in SCENES}
    if not all(j.get("mrt") for j in mrt.values()):
        sys.exit(f"{exe} did not run --mrt on: rebuild it")
    figures = [run(exe, file, "gf5700", a.work, a.reuse, extra=extra, tag="-fig")
               for _, file, extra, _, _ in FIGURES]
    readings = {}
    for rd in READINGS:
        sset, shadows, grid = rd
        for scene, file in SCENE_SETS[sset].items():
            readings[(rd, scene)] = run(exe, file, "gf5700", a.work, a.reuse,
                                        extra=["--shadows", shadows, "--grid", grid],
                                        tag=f"-read-sh{shadows}-g{grid}")
    cpu = None
    if has_engine(exe):
        cpu = {scene: run(exe, file, "gf5700", a.work, a.reuse, engine="cpu")
               for scene, file in SCENES}
    write_doc(data, masks, cpu, figures, readings, mrt, mrt_masks)
    breakdown_chart(data, os.path.join(ROOT, "docs/studies/table1_breakdown.png"))
    print("wrote docs/studies/table1.md and docs/studies/table1_breakdown.png", file=sys.stderr)


def write_doc(data, masks, cpu, figures, readings, mrt, mrt_masks):
    """docs/studies/table1.md: the calibration, Table 1 beside the model, the statistics, where the
    time goes, the what-ifs, the parameters and the reading of the paper's settings."""
    L = intro_section()
    L += table_section(data, cpu)
    L += statistics_section(data)
    L += breakdown_section(data)
    L += what_if_section(data, masks, mrt, mrt_masks)
    L += parameters_section()
    L.append(explain_readings(data, figures, readings))
    open(os.path.join(ROOT, "docs/studies/table1.md"), "w").write("\n".join(L))


def intro_section():
    """The page's title, how it is written, the settings and the calibration."""
    L = []
    w = L.append
    w("# Table 1: the paper's times, our measurements and the cost model's predictions\n")
    w("Written by `/usr/bin/python3 scripts/docs/table1.py` (do not edit by hand). It renders every scene "
      "on every profile with `vgpu-rt render --stats-json`, and reads the statistics and the cost "
      "model's predictions (`host/model/cost_model.h`, also printed by `vgpu-rt render --predict`).\n")
    w("Settings, the same for every cell: `" + " ".join(SETTINGS) + "`, masks off unless said. "
      "Scenes: " + ", ".join(f"{n} = `scenes/{f}.gltf`" for n, f in SCENES) + ". The paper "
      "states none of this for Table 1; *Reading the paper's settings* at the end says why these, "
      "and how every prediction moves under the other readings.\n")
    cal = ", ".join(f"{s} on the {NAMES[g]} ({PAPER[s][g]} ms)" for s, g in CALIBRATION)
    w(f"**Calibration.** One free parameter per GPU, the fixed cost unit u (µs) of a pass, a "
      f"program load (u each) and a query read-back (2u each), is fitted on two of the six GPU "
      f"cells: {cal}. The other four GPU cells, every ratio but Bunny3's, and every what-if are "
      f"predictions. Everything else is a public hardware figure or an assumption stated below.\n")
    return L


def table_section(data, cpu):
    """Table 1 beside the model's predictions, the 5700/6600 ratios and the targets."""
    L = []
    w = L.append
    w("## Table 1 beside the model\n")
    w("Times in ms. *paper*: Table 1. *pred.*: the cost model. *err*: (pred. - paper) / paper. "
      "*host*: wall time of this emulator on the build machine (a shared 2-core host; it measures "
      "the emulator, not any GPU).\n")
    hdr = "| scene | paper 5700 | pred. 5700 | err | paper 6600 | pred. 6600 | err | paper CPU |"
    sep = "|---|---:|---:|---:|---:|---:|---:|---:|"
    if cpu:
        hdr += " our CPU |"
        sep += "---:|"
    hdr += " pred. RTX 4090 | host ms (5700 / 6600) |"
    sep += "---:|---:|"
    w(hdr)
    w(sep)
    for scene, _ in SCENES:
        row = f"| {scene} |"
        for gpu in GPUS:
            pred = data[(scene, gpu)]["predicted_ms"][gpu]
            mark = " (fitted)" if (scene, gpu) in CALIBRATION else ""
            row += f" {PAPER[scene][gpu]} | {pred:.0f}{mark} | {pct(err(pred, PAPER[scene][gpu]))} |"
        row += f" {PAPER[scene]['cpu']} |"
        if cpu:
            row += f" {cpu[scene]['render_ms']:.0f} |"
        row += (f" {data[(scene, 'rtx4090')]['predicted_ms']['rtx4090']:.1f} |"
                f" {data[(scene, 'gf5700')]['render_ms']:.0f} / {data[(scene, 'gf6600')]['render_ms']:.0f} |")
        w(row)
    w("")
    if not cpu:
        w("The measured CPU column is left out: this build's `vgpu-rt render` has no `--engine cpu` "
          "yet (the CPU reference tracer is being added by another engineer); the paper's CPU "
          "times are shown as published, and nothing is predicted for them.\n")
    else:
        w("*our CPU*: `vgpu-rt render --engine cpu` (the host reference tracer, double precision, "
          "all host cores), wall time on the build machine.\n")

    w("**Ratio GeForce FX 5700 / GeForce 6600**, per scene:\n")
    w("| scene | paper | predicted | err |")
    w("|---|---:|---:|---:|")
    ratio_errs = {}
    for scene, _ in SCENES:
        rp = PAPER[scene]["gf5700"] / PAPER[scene]["gf6600"]
        rm = data[(scene, "gf5700")]["predicted_ms"]["gf5700"] / data[(scene, "gf6600")]["predicted_ms"]["gf6600"]
        ratio_errs[scene] = err(rm, rp)
        fitted = " (both cells fitted)" if all((scene, g) in CALIBRATION for g in GPUS) else ""
        w(f"| {scene} | {rp:.2f} | {rm:.2f}{fitted} | {pct(err(rm, rp))} |")
    w("")
    cells = [(s, g) for s, _ in SCENES for g in GPUS if (s, g) not in CALIBRATION]
    in_cell = [(s, g) for s, g in cells
               if abs(err(data[(s, g)]["predicted_ms"][g], PAPER[s][g])) <= TARGET_CELL]
    in_ratio = [s for s, _ in SCENES if abs(ratio_errs[s]) <= TARGET_RATIO]
    w(f"**Targets.** Predicted GPU cells within ±{TARGET_CELL:.0%} of the paper: "
      f"{len(in_cell)} of {len(cells)} predicted cells"
      + (f" ({', '.join(f'{s} {NAMES[g]}' for s, g in in_cell)})" if in_cell else "") +
      f". 5700/6600 ratios within ±{TARGET_RATIO:.0%}: {len(in_ratio)} of {len(SCENES)}"
      + (f" ({', '.join(in_ratio)})" if in_ratio else "") + ". *Reading the paper's "
      "settings* below shows how these counts move with the settings the paper leaves unsaid.\n")
    return L


def statistics_section(data):
    """The virtual GPU's counts per scene that the predictions come from."""
    L = []
    w = L.append
    j0 = data[("Sphere", "gf5700")]
    w("## The statistics the predictions come from\n")
    w("Counted by the virtual GPU (identical for every profile: the counters are static per-fragment "
      "counts times shaded fragments). *instructions* are the counted scalar operations of the "
      "kernel code, fetches included; *idle*: shaded fragments with nothing to do in their pass; "
      "*bytes* = texture bytes read + render-target bytes written.\n")
    w("| scene | triangles | grid | iterations | passes | program loads | read-backs | "
      "fragments shaded | of them idle | instructions | fetches | bytes |")
    w("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for scene, _ in SCENES:
        j = data[(scene, "gf5700")]
        t = j["totals"]
        fin = sum(min(k["fragments_shaded"], k["lanes_idle"] + k["fragments_discarded"])
                  for k in j["kernels"])
        w(f"| {scene} | {j['triangles']} | {'x'.join(map(str, j['grid']))} | {j['iterations']} | "
          f"{t['passes']} | {t['program_loads']} | {t['query_readbacks']} | "
          f"{t['fragments_shaded'] / 1e6:.0f} M | {100 * fin / t['fragments_shaded']:.0f}% | "
          f"{t['instructions'] / 1e9:.1f} G | {t['texture_fetches'] / 1e9:.2f} G | "
          f"{(t['bytes_read'] + t['bytes_written']) / 1e9:.1f} GB |")
    w("")
    w("Passes by kernel (Sphere): " + ", ".join(
        f"{k['paper_name']} {k['passes']}" for k in j0["kernels"]) + ".\n")
    return L


def breakdown_section(data):
    """Where the predicted time goes, per GPU and scene, and the FX 5700's overhead."""
    L = []
    w = L.append
    w("## Where the time goes\n")
    w("![breakdown](table1_breakdown.png)\n")
    w("Pass work is attributed to each pass's bottleneck (the larger of arithmetic, texture and "
      "memory time), so the columns add up to the total; *idle* is the part of the pass work "
      "spent on fragments with nothing to do in that pass: their ray is finished, or has no "
      "triangle left in its voxel while other rays still test theirs (the fragments `--masks on` "
      "would skip; in the chart it is taken out of the bottleneck columns in proportion). "
      "*demand* shows each unit's whole need, overlapped or not. ms:\n")
    w("| GPU | scene | arithmetic | texture | memory | per-pass | program loads (bus) | "
      "read-backs | total | idle | arith. / tex. / mem. demand |")
    w("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for gpu in PROFILES:
        for scene, _ in SCENES:
            b = data[(scene, gpu)]["predicted_breakdown"][gpu]
            w(f"| {NAMES[gpu]} | {scene} | {b['arithmetic_ms']:.0f} | {b['texture_ms']:.0f} | "
              f"{b['memory_ms']:.0f} | {b['per_pass_ms']:.0f} | {b['program_load_ms']:.0f} "
              f"({b['bus_ms']:.1f}) | {b['readback_ms']:.0f} | {b['total_ms']:.0f} | "
              f"{b['wasted_ms']:.0f} ({100 * b['wasted_ms'] / b['total_ms']:.0f}%) | "
              f"{b['arithmetic_demand_ms']:.0f} / {b['texture_demand_ms']:.0f} / "
              f"{b['memory_demand_ms']:.0f} |")
    w("")
    w(explain_fx(data))
    return L


def what_if_section(data, masks, mrt, mrt_masks):
    """What MRT, masks and resident programs would change on the FX 5700 and the 6600."""
    L = []
    w = L.append
    w("## What if the GeForce FX 5700 had ...\n")
    w("Every row is predicted by the same model and parameters from transformed or re-rendered "
      "statistics:\n")
    w("- **MRT, modeled** (multiple render targets): pairs of kernels that always run back to back "
      "become one pass writing both targets (`host::mrt_pairs`): intersecciones + proximoTriangulo "
      "(both read the voxel state) and traversal + actualizarVoxel (the second reads the first's "
      "output). The merged pass shades each fragment once, does both programs' operations and "
      "fetches minus the one shared 16-byte own-texel read, writes both targets, and is one program "
      "load.")
    w("- **MRT, executed**: rendered again with `--mrt on` (on the gf6600 profile, the FX 5700 "
      "has one output; the counters do not depend on the profile), the host loop running the "
      "fused two-output programs of `kernels/fused.h` (`intersections + next triangle`, "
      "`traversal + update voxel`), with images, hit ids and depths identical to the baseline's. "
      "It keeps one plain actualizarVoxel per trace (the first voxel of each ray, before any "
      "traversal step to fuse it with), so it has that many more passes than the modeled row.")
    w("- **masks**: rendered again with `--masks on`: early-z/stencil masks skip the fragments of "
      "finished rays in the traversal and intersection loops, at no cost.")
    w("- **resident programs**: every program loaded once, on first use, instead of at every "
      "switch (fewer program switches).")
    w("- **all three** together: modeled MRT on the masked frame, and (*MRT executed*) the "
      "`--mrt on --masks on` frame with resident programs modeled on it.\n")
    for gpu in GPUS:
        w(f"{NAMES[gpu]}, predicted ms (change against the baseline) and the totals that change:\n")
        w("| scene | scenario | passes | program loads | GB moved | predicted ms | change |")
        w("|---|---|---:|---:|---:|---:|---:|")
        for scene, _ in SCENES:
            base = data[(scene, "gf5700")]
            m = masks[scene]
            wi = {x["name"]: x for x in base["predicted_what_if"]}
            wim = {x["name"]: x for x in m["predicted_what_if"]}
            e, em = mrt[scene], mrt_masks[scene]
            wiem = {x["name"]: x for x in em["predicted_what_if"]}
            rows = [("baseline", base["totals"], base["predicted_breakdown"][gpu]),
                    ("MRT, modeled", wi["mrt"]["totals"], wi["mrt"]["predicted_breakdown"][gpu]),
                    ("MRT, executed", e["totals"], e["predicted_breakdown"][gpu]),
                    ("masks", m["totals"], m["predicted_breakdown"][gpu]),
                    ("resident programs", wi["resident programs"]["totals"],
                     wi["resident programs"]["predicted_breakdown"][gpu]),
                    ("all three, modeled", wim["mrt + resident programs"]["totals"],
                     wim["mrt + resident programs"]["predicted_breakdown"][gpu]),
                    ("all three, MRT executed", wiem["resident programs"]["totals"],
                     wiem["resident programs"]["predicted_breakdown"][gpu])]
            b0 = rows[0][2]["total_ms"]
            for name, t, b in rows:
                gb = (t["bytes_read"] + t["bytes_written"]) / 1e9
                w(f"| {scene} | {name} | {t['passes']} | {t['program_loads']} | {gb:.1f} | "
                  f"{b['total_ms']:.0f} | {pct(b['total_ms'] / b0 - 1) if name != 'baseline' else ''} |")
        w("")
    w(explain_what_if(data, masks, mrt))
    return L


def parameters_section():
    """The page's Parameters section: each profile's hardware figures and fixed costs, and the
    cost model's own parameters, as lines."""
    L = []
    w = L.append
    w("## Parameters\n")
    w("Hardware figures and fixed costs, read from `vgpu/profile.cpp` with their source comments. "
      "*public*: a published figure (the comment names it); *assumed*: no public figure, set a "
      "priori and not fitted; *fitted*: fitted on the calibration cells above.\n")
    for prof, rows in parse_parameters().items():
        w(f"**{prof}**\n")
        w("| field | value | status | source |")
        w("|---|---|---|---|")
        for field, value, source, status in rows:
            w(f"| {field} | {value} | {status} | {source} |")
        w("")
    w("The cost model's own parameters (`host/model/cost_model.h`), the same for every profile:\n")
    w("| parameter | value | status and source |")
    w("|---|---|---|")
    for name, value, src in parse_cost_params():
        w(f"| {name} | {value} | {src} |")
    w("")
    w("Fixed costs: per pass `pass_us`; per program load the program's bytes (static instructions "
      "x `instruction_bytes`) over `bus_mbps` plus `program_load_us`; per query read-back "
      "`readback_us`; per clear its bytes over `mem_gbps` (or `output_bytes_per_clock` where "
      "given); per texture download (the image at the end of a frame) `download_us` plus its "
      "bytes over `download_gbps` where given, and over `download_host_gbps` (the host filling "
      "the frame's arrays from them; the H200 and the H100; 0 elsewhere). Arithmetic: counted "
      "operations minus "
      "fetches, / `scalar_ops_per_instruction`, / (`pipelines` x `core_mhz` x `alu_per_clock` x "
      "the part's rate for the precision each operation ran at: `fp32_rate`, `fp24_rate`, or 1 "
      "for fp16, counted per pass as `alu_fp24` / `alu_fp16`). Texture: fetches / (`pipelines` x `core_mhz` x "
      "`texels_per_clock`), or texel bytes / (`texture_bytes_per_clock` x `core_mhz`) where "
      "given and longer, at `texture_spilled_bytes_per_clock` instead where the pass's footprint "
      "(`footprint_bytes`, counted) is over `l2_bytes` (the H200 and the H100). Memory: bytes / `mem_gbps`, or written bytes / "
      "(`output_bytes_per_clock` x `core_mhz`) where given and longer. Looping passes: idle lane "
      "slots pay the body's operations and fetches, every slot `loop_overhead_clocks`; each "
      "looping pass also waits for its longest lane, added to its work: the most iterations one "
      "fragment ran times the body's longest chain of dependent operations (`vgpu/span.h`), "
      "its fetches at `fetch_latency_clocks` and its operations at `operation_latency_clocks` "
      "(measured on the H200 and the H100 by `bench_gl --latency`; 0, not modeled, "
      "elsewhere); on those two profiles the body's arithmetic between two of its fetches (an "
      "address computed from a fetched texel, `loop_dependent_instructions`, counted from the "
      "recorded program) does not overlap the fetches: its share of the pass's arithmetic time is "
      "added to the pass's work, at most the texture time. Dynamic branching (6600, RTX 4090): "
      "the pass's branch-idle fragments that sit in all-idle batches of the profile's granularity "
      "(counted) skip `branch_body_share` of the program's operations, fetches and bytes read. Not modeled: texture caches other than "
      "the H200's and the H100's L2 (every fetched byte is charged to memory), the branch instruction's own cost, early-z rejection cost "
      "(masked fragments are free), CPU-GPU overlap beyond the fitted fixed costs.\n")
    return L


def explain_fx(data):
    s = []
    s.append("**The FX 5700's overhead, as the model reads it.** ")
    parts = []
    s.append("The fixed per-pass costs are fitted (on Bunny3), the rest follows from the counters "
             "and the public figures. ")
    for scene, _ in SCENES:
        b = data[(scene, "gf5700")]["predicted_breakdown"]["gf5700"]
        fixed = b["per_pass_ms"] + b["program_load_ms"] + b["readback_ms"]
        parts.append(f"{scene}: fixed per-pass costs {100 * fixed / b['total_ms']:.0f}% "
                     f"(program bytes over AGP alone {b['bus_ms']:.1f} ms), idle-fragment work "
                     f"{100 * b['wasted_ms'] / b['total_ms']:.0f}%, useful fragment work "
                     f"{100 * (b['total_ms'] - fixed - b['wasted_ms']) / b['total_ms']:.0f}%")
    s.append("; ".join(parts) + ". ")
    b5 = data[("BunnyRefl", "gf5700")]["predicted_breakdown"]["gf5700"]
    b6 = data[("BunnyRefl", "gf6600")]["predicted_breakdown"]["gf6600"]
    s.append(
        "Against the paper's reasons: (1) *every fragment runs every pass* is the largest single "
        "term: the traversal and intersection loops run until the slowest ray is done, so nearly "
        "every fragment of nearly every pass is idle, and fp30 can neither branch around it nor "
        "(without masks) skip it; on the 5700 the useful fragment work is a few percent of the "
        "time. (2) The *per-pass overhead* (a pass, a program switch and, every third pass, a "
        "query read-back that drains the pipeline) is the other half; its size is fitted, not "
        "derived. (3) *Program loads congesting the bus* are not supported as bus traffic: a "
        "program is at most a few KB, so all the loads of a frame move a few MB, milliseconds over "
        "AGP; a load can only be expensive as the driver's work per switch, which these data "
        "cannot tell apart from the per-pass cost (every pass switches program). (4) *No MRT, no "
        "branching*: the what-ifs below price MRT; branching (finished batches skip the body) and "
        "raw fp32 rate are what make the 6600 faster in the model. "
        f"On the 6600 the same frame is {'memory' if b6['memory_ms'] >= b6['arithmetic_ms'] else 'arithmetic'}"
        f"-bound (BunnyRefl: arithmetic demand {b6['arithmetic_demand_ms']:.0f} ms, memory demand "
        f"{b6['memory_demand_ms']:.0f} ms against the 5700's {b5['arithmetic_demand_ms']:.0f} and "
        f"{b5['memory_demand_ms']:.0f} ms): fp32 at full rate on two ALUs per pipe, twice the pipes, "
        "and batches of idle fragments skipping the branch. The predicted 5700/6600 ratio hardly "
        "changes from scene to scene because in every scene both the fixed costs and the work "
        "scale with the number of passes; its value comes from the hardware figures and the two "
        "fitted fixed costs.\n")
    return "".join(s)


def explain_what_if(data, masks, mrt):
    out = []
    for scene, _ in SCENES:
        base = data[(scene, "gf5700")]["predicted_ms"]["gf5700"]
        wi = {x["name"]: x for x in data[(scene, "gf5700")]["predicted_what_if"]}
        wim = {x["name"]: x for x in masks[scene]["predicted_what_if"]}
        out.append(
            f"{scene}: MRT {pct(wi['mrt']['predicted_breakdown']['gf5700']['total_ms'] / base - 1)} "
            f"modeled, {pct(mrt[scene]['predicted_ms']['gf5700'] / base - 1)} executed, "
            f"masks {pct(masks[scene]['predicted_ms']['gf5700'] / base - 1)}, resident programs "
            f"{pct(wi['resident programs']['predicted_breakdown']['gf5700']['total_ms'] / base - 1)}, "
            f"all three {pct(wim['mrt + resident programs']['predicted_breakdown']['gf5700']['total_ms'] / base - 1)}")
    vs = [{x["name"]: x for x in masks[sc]["predicted_what_if"]}["mrt + resident programs"]
          ["predicted_breakdown"]["gf5700"]["total_ms"] / data[(sc, "gf6600")]["predicted_ms"]["gf6600"]
          for sc, _ in SCENES]
    v0 = [data[(sc, "gf5700")]["predicted_ms"]["gf5700"] / data[(sc, "gf6600")]["predicted_ms"]["gf6600"]
          for sc, _ in SCENES]
    t = data[("BunnyRefl", "gf5700")]["totals"]
    per_pass = fixed_units(t) / t["passes"]
    gaps = [mrt[sc]["totals"]["passes"] -
            {x["name"]: x for x in data[(sc, "gf5700")]["predicted_what_if"]}["mrt"]["totals"]["passes"]
            for sc, _ in SCENES]
    gap_text = f"{min(gaps)}" if min(gaps) == max(gaps) else f"{min(gaps)}-{max(gaps)}"
    worst_gap = max(
        abs(mrt[sc]["predicted_ms"]["gf5700"] /
            {x["name"]: x for x in data[(sc, "gf5700")]["predicted_what_if"]}["mrt"]
            ["predicted_breakdown"]["gf5700"]["total_ms"] - 1) for sc, _ in SCENES)
    return ("**Reading the what-ifs (FX 5700).** " + "; ".join(out) + ". Masks remove the largest "
            "term, the work on idle fragments, and almost all memory traffic. MRT removes about a "
            "third of the passes and program loads, but none of the arithmetic: the merged pass "
            "still runs both programs on every fragment; executed, it keeps every query read-back "
            "(the host steers by the same counts) and one actualizarVoxel pass per trace, "
            f"{gap_text} more passes than modeled; the executed FX 5700 time is within "
            f"{100 * worst_gap:.1f}% of the modeled one. Resident programs remove the driver cost "
            f"of the loads, which is an assumed share of the fitted fixed cost ({SPLIT['load']:.0f} "
            f"of the {per_pass:.2f} units a pass costs, read-backs included): were the fitted cost "
            f"all per switch, the gain would be {per_pass / SPLIT['load']:.1f} times larger; were "
            "it all per pass, nil. The three together bring the 5700 to "
            f"{span(vs)} times the 6600's baseline (instead of {span(v0)} times).\n")


def refit(cells):
    """Predictions of one reading: u per GPU refitted on its Bunny3, as fit() does.

    cells: scene -> --stats-json of that scene (rendered once; the JSON predicts every profile).
    Returns ({gpu: u_us}, {(scene, gpu): predicted ms})."""
    us, pred = {}, {}
    for gpu in GPUS:
        rest, units = split(cells["Bunny3"], gpu)
        u = (PAPER["Bunny3"][gpu] - rest) / units
        us[gpu] = 1e3 * u
        for scene, j in cells.items():
            rest, units = split(j, gpu)
            pred[(scene, gpu)] = rest + u * units
    return us, pred


def explain_readings(data, figures, readings):
    L = ["## Reading the paper's settings\n"]
    w = L.append
    w("The paper gives Table 1's scene names and times, and nothing else: no scene contents, grid, "
      "iteration count or shadow setting. Each choice above is read from the rest of the paper:\n")
    w("- **No shadow rays.** The paper's 13 fragment programs and its ray-state textures have no "
      "shadow-ray kernel or state (the shader \"can\" emit shadow rays, but no kernel traces them), "
      "and Fig. 3's three lighting models take the same 7990 ms. Our shadow rays are an extension "
      "(`--shadows on`, the CLI default).")
    w("- **3 ray-tracing iterations** (`--bounces 2`), as Fig. 1 states; the loop stops early when "
      "no ray reflects (the paper's section 3.4), so a scene without mirrors runs one.")
    w("- **A 15x15x15 grid**, the one resolution the paper states (Fig. 1). `--grid auto` (4 voxels "
      "per triangle, our own rule) is in the table below.")
    bl = PAPER["Bunny3"]["gf5700"] / PAPER["Sphere"]["gf5700"]
    rr5 = PAPER["BunnyRefl"]["gf5700"] / PAPER["Bunny3"]["gf5700"]
    rr6 = PAPER["BunnyRefl"]["gf6600"] / PAPER["Bunny3"]["gf6600"]
    w(f"- **Scenes.** The paper's Sphere is faster than its Bunny3 ({bl:.2f}x) and than its own "
      f"948-face bunny of Fig. 2 (3485 ms) on the same card, so it is a light scene: we read it as "
      f"the sphere alone (`sphere-alone`), as Bunny3 is the bunny alone. BunnyRefl takes "
      f"{rr5:.2f}x Bunny3's time on the 5700 and {rr6:.2f}x on the 6600, so its reflections add "
      f"about one Bunny3 of work: we read it as the bunny on a mirror floor (`bunny-mirror`). Our "
      f"richer scenes (`sphere`: the sphere over a 14x14 floor; `bunny-refl`: the bunny in a mirror "
      f"corner, for Fig. 4's mutual reflections) stay for the figures, the sweep and the stability "
      f"suite.")
    w("- **Disclosure.** These readings were chosen after the first version of this table (richer "
      "scenes, shadow rays, `--grid auto`) missed every absolute cell by +470% to +910%. So that "
      "the choice is visible rather than hidden, the table below gives every combination of the "
      "readings, each refitted on its own Bunny3 (the same one-parameter fit) and predicting its "
      "own four other cells.\n")
    w("| scenes | shadow rays | grid | u 5700 (µs) | u 6600 (µs) | Sphere 5700 | Sphere 6600 | "
      "BunnyRefl 5700 | BunnyRefl 6600 | cells within ±35% | ratios within ±25% |")
    w("|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    chosen = (next(k for k, v in SCENE_SETS.items() if v == dict(SCENES)),
              dict(zip(SETTINGS[::2], SETTINGS[1::2]))["--shadows"],
              dict(zip(SETTINGS[::2], SETTINGS[1::2]))["--grid"])
    for rd in READINGS:
        cells = {scene: readings[(rd, scene)] for scene in PAPER}
        us, pred = refit(cells)
        errs = {k: err(v, PAPER[k[0]][k[1]]) for k, v in pred.items()}
        inside = sum(abs(errs[(s, g)]) <= TARGET_CELL for s in ("Sphere", "BunnyRefl") for g in GPUS)
        ratios = sum(abs(err(pred[(s, "gf5700")] / pred[(s, "gf6600")],
                             PAPER[s]["gf5700"] / PAPER[s]["gf6600"])) <= TARGET_RATIO
                     for s in PAPER)
        name = " / ".join(SCENE_SETS[rd[0]][s] for s in PAPER)
        mark = "**" if rd == chosen else ""
        w(f"| {mark}{rd[0]} ({name}){mark} | {rd[1]} | {rd[2]} | {us['gf5700']:.0f} | "
          f"{us['gf6600']:.0f} | " + " | ".join(pct(errs[(s, g)]) for s in ("Sphere", "BunnyRefl")
                                              for g in GPUS) + f" | {inside} of 4 | {ratios} of 3 |")
    w("")
    w("(Bold: the reading used above. The cells are errors against the paper.)\n")
    work = {(s, g): sum(data[(s, g)]["predicted_breakdown"][g][k]
                        for k in ("arithmetic_ms", "texture_ms", "memory_ms"))
            for s, _ in SCENES for g in GPUS}
    over = [(s, g) for (s, g), v in work.items() if v > PAPER[s][g]]
    if over:
        w("**Work alone exceeds the paper's time** in " +
          ", ".join(f"{s} on the {NAMES[g]} ({work[(s, g)]:.0f} ms of pass work against "
                    f"{PAPER[s][g]} ms)" for s, g in over) +
          ": with zero fixed costs these cells would still be overpredicted.\n")
    r_cal = data[("Bunny3", "gf5700")]["predicted_ms"]["gf5700"] / \
        data[("Bunny3", "gf6600")]["predicted_ms"]["gf6600"]
    bands = []
    for scene in ("Sphere", "BunnyRefl"):
        k = (PAPER[scene]["gf5700"] / PAPER[scene]["gf6600"]) / r_cal
        bands.append(f"{scene}: {k:.2f}x, so both of its cells fall within ±{TARGET_CELL:.0%} only "
                     f"if its 5700 cell lies between {pct(max(-TARGET_CELL, (1 - TARGET_CELL) / k - 1))}"
                     f" and {pct((1 + TARGET_CELL) / k - 1)}")
    w(f"**Why the 6600 cells sit above the 5700 cells.** In the model both cards' times grow "
      f"with the pass count, so its 5700/6600 ratio is nearly the same in every scene "
      f"({r_cal:.2f} on the calibration scene), while the paper's ratio varies from scene to scene "
      f"(4.70, 5.60, 5.79). A scene whose paper ratio is higher than Bunny3's has its 6600 cell "
      f"predicted that much higher, relative to the paper, than its 5700 cell: " +
      "; ".join(bands) + ". No reading that only changes pass counts can move the two cards "
      "apart.\n")
    w("What holds under every reading is what depends on the cards rather than the scenes: the "
      "5700/6600 ratio, and the FX 5700's composition (fixed costs and idle-fragment work far "
      "outweighing useful work). What moves is the absolute time of the scenes other than the "
      "calibration one, by their pass counts: the fitted unit u is a cost per pass, so a reading "
      "whose Sphere or BunnyRefl needs more passes relative to Bunny3 than the paper's did "
      "predicts proportionally more.\n")

    w("### The paper's other timed figures (GeForce FX 5700), predicted\n")
    w("Same settings as the table, plus what the paper states. Not used in the fit, except that "
      "Fig. 2's large bunny is the calibration scene itself.\n")
    w("| figure | passes | paper ms | predicted ms | err |")
    w("|---|---:|---:|---:|---:|")
    for (label, _, _, paper, calib), j in zip(FIGURES, figures):
        pred = j["predicted_ms"]["gf5700"]
        note = " (calibration scene)" if calib else ""
        w(f"| {label}{note} | {j['totals']['passes']} | {paper} | {pred:.0f} | {pct(err(pred, paper))} |")
    w("")
    return "\n".join(L)


if __name__ == "__main__":
    main()
