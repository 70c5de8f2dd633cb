#!/usr/bin/env python3
"""Writes docs/studies/sampling.md and docs/studies/sampling.png: the sampling modes (--spp, --aa adaptive,
--aa undersample) on the bundled scenes, error against a 256-sample reference beside rays,
passes and modeled time.

Usage: /usr/bin/python3 scripts/docs/sampling.py [--bench build/bench/bench_sampling] [--size 128]
    [--reps 3] [--scenes sphere,bunny,...] [--other-scenes hop,teapot,...] [--changed-size 256]
       /usr/bin/python3 scripts/docs/sampling.py --h200 FILE... [--h200-clocks CSV]
           [--h200-looping FILE... [--h200-looping-control FILE...] [--h200-looping-clocks CSV]]
       /usr/bin/python3 scripts/docs/sampling.py --bounds-only [--bounds-bench FILE]
--bounds-only rewrites only the section on how far any choice of traced gaps can go (between
the undersample-bounds markers; bench/bench_undersample_bounds.cpp, a few seconds), which a
full regeneration writes too.
--h200 runs nothing: it reads bench_gl's JSON from an H200 (scripts/h200/streams_sampling.sh) and
rewrites only docs/studies/sampling.md's H200 section (between the h200-measured markers), which a full
regeneration keeps as it is. --h200-looping takes the looping rows from a second run with a warm-up
before timing (scripts/h200/sampling_looping.sh), --h200-looping-control its run without one.

The figures are bench_sampling's (bench/bench_sampling.cpp), which this script runs with --json:
every image is the stream engine's (the emulator) on gf6600, the reference the CPU tracer at
256 samples (double precision), both as the 8-bit PNG would store them. The main scenes run
every mode and make the chart, with the Pareto front (no other mode both cheaper in modeled
gf6600 time and lower in RMS) marked; the other scenes run the adaptive and undersampling
modes beside spp 1 and 16, to check the rules hold there too. Undersampling's changed pixels
(against the one-ray render) are counted at --changed-size, the paper's 256x256.
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile


sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import h200_frames as hf  # noqa: E402
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MAIN = "sphere,bunny,bunny-refl,classic"
OTHERS = "bunny-low,bunny-mirror,hop,sphere-alone,teapot,textured"


HOW_2004 = """## How a 2004 GPU would have done each mode

Every mode runs as passes, textures and occlusion queries a GeForce FX or 6 has, at the image's
size, so the profile's texture limits (4096 x 4096 on both cards) bind only the image.

- **`--spp N`: the accumulation buffer.** One whole frame per sample, the camera moved by the
  sample's sub-pixel offset (`generadorRayosMuestra`; the same offset in every pixel, as
  jittering the projection did), each frame added into a sum texture (`acumularMuestras`), then
  one box-filter pass (`resolverMuestras`). The FX cannot blend into float targets and the 6
  blends only fp16, so the sum is a ping-pong pair of fp32 textures and the add is a pass.
  The other way, a sqrt(N) times wider and taller ray texture with a down-sampling pass, needs
  every per-ray texture N times larger: at 256 x 256 it reaches 4096 x 4096 at N = 256, and
  the pipeline's ten or more image-sized fp32 textures (1 MiB each at 256 x 256) would take
  160 MiB or more at N = 16.
- **`--aa adaptive`: masks and queries.** The centre frame (the paper's) keeps each pixel's
  surface key (`guardarImpactos`); a mark pass (`marcarPixeles`, five fetches of the colour
  and five of the keys) flags pixels whose neighbours hit another surface or whose colour
  bends, an occlusion query (`pixelesMarcados`) counts them, exactly as the paper's
  `rayosReflejados` counts live rays, and the host loops while the count is above 0. A level's
  sample frames give rays only to flagged pixels (the others get "no ray", which the walk and
  the early-z masks skip) and accumulate only theirs. One more pair of image-sized textures
  (the marks), one mark pass and one query per level.
- **`--aa undersample:K`: a lattice, then the gaps.** A mark pass flags the lattice
  (`marcarReticula`), one gated frame traces it, a second mark pass (`marcarHuecos`, four
  fetches of the lattice pixels around each pixel) flags the pixels whose blended lattice
  pixels disagree, a query counts them, a second gated frame traces them, and a fill pass
  (`rellenarHuecos`) blends the rest bilinearly from the same four fetches (the lattice is not
  a texture of its own, so the texture unit's bilinear filter cannot do it; four nearest
  fetches and the blend in the program can), less a correction for the colour's curvature
  from eight more fetches of the lattice pixels one step beyond the cell (below).

On these cards a pass costs every fragment of the target (the FX) or every fragment the early-z
test lets through (the 6, with `--masks on`), so a gated frame that traces a tenth of the
pixels would still run all the passes its walk needs over the whole target (the rows marked
*gated* below, `--compact off`: how the modes ran before issue 35).

## Sampling that saves time: the marked pixels as a dense stream

The adaptive levels and the undersampling lattice and gaps (`--compact on`, the default) trace
only the pixels the marks flag, packed into the first rows of the frame's textures, with the
stream reduction glass's ray streams use (Horn, GPU Gems 2 ch. 36):

1. `sumaPrefijos` over the marks: log2(W H) passes leave each pixel the count of marked pixels
   up to and including it.
2. `compactarMarcados`: slot j of the dense stream finds the j-th marked pixel by a binary search
   over those sums (a fixed number of dependent fetches, no loop: the FX runs it) and keeps its
   centre. Once per set of marks.
3. `generadorRayosDensos`: the sample rays of those pixels, slot after slot. An adaptive level's
   n samples of m marked pixels go into one stream, sample after sample (slot k m + j holds
   sample k of pixel j, its offset from a small table), as many samples per frame as W H slots
   hold: a level that marks a tenth of the pixels traces its 16 samples in two frames, not 16.
4. The frame: every pass of the walk, the shading, the shadow and the reflected rays draws only
   the rows the stream fills (a rectangle from the top of the target; the counts and the early-z
   masks see only those fragments).
5. `acumularDensos`: each marked pixel adds its slot's colour for sample k to its sum, one pass
   per sample as `acumularMuestras` did, in the same order, so the sums have the same bits;
   `reunirMarcados` brings the undersampling frames' primary hits back to their pixels the same
   way (for the surface keys and the depth and id AOVs).

The rays are the gated frames' rays, the sums the same additions: the images, depths and ids
are the same bits (tested on every structure, both emulator walks, any thread count and the GL
device). What changes is the cost: fewer fragments per pass, and for adaptive sampling fewer
frames, so fewer passes, program loads and query read-backs. `--compact off` runs the gated
frames, to compare. The statistics table's `dense streams` line and the JSON's `compact` object
count the frames, the live rays, the share of the target their passes drew, and the scan,
compaction and gather passes.
""".split("\n")

RULES = """## Where adaptive sampling spends its rays

1. The centre ray of every pixel (the one-ray image, with each pixel's surface key: the
   material its ray hit, -1 for none).
2. Each level (2 x 2 samples, then 4 x 4, ... up to `--spp`) in the pixels of the level before
   where a 4-neighbour hit another surface, or where the colour bends: its second difference
   along x or y (left + right - 2 x own, above + below - 2 x own) exceeds `--aa-threshold` T in
   some channel. A step bends at the pixels on both sides of it; a shade or a reflection that
   changes evenly does not, though its pixels differ from their neighbours, so it keeps its one
   ray. (The rule before compared each pixel with its neighbours, and refined every even
   gradient steeper than T per pixel: on `bunny-refl` at T 0.05 that cost 6.5 rays per pixel,
   41% of uniform 16's.)

A pixel that reached the last level has 1 + 4 + 16 = 21 rays at `--spp 16`: each level's
samples replace the ones before (the centre ray and the 2 x 2 level are not averaged in), but
they were traced and are counted.

That is the image criterion (`--aa-criterion image`, the rows *adaptive 16, T ...* below). The
default is the budget (`--aa-criterion budget`, the rows *budget 16*; `kernels/cone_budget.h`):
each level scores its candidates by the cones' evidence (the colour step across a surface,
reflected-surface or fold edge, or the colour's bend), refines the highest scores above 0.05 but
no more pixels that hit than a share of the image's (30% at the 2 x 2 level, 28% at the 4 x 4;
the threshold found by a binary search of counting passes and occlusion queries), and its 4 x 4
level keeps the 2 x 2 samples and traces the 12 strata they leave empty: 1 + 4 + 12 = 17 rays.
The sections "The object-space criterion: cones" and "One default for every scene" below say why.
""".split("\n")


def bench(exe, args, work, name):
    out = os.path.join(work, name + ".json")
    print(f"sampling.py: {exe} {' '.join(args)}", file=sys.stderr)
    subprocess.run([exe, *args, "--json", out], check=True, stdout=subprocess.DEVNULL)
    return json.load(open(out))


BOUNDS_BEGIN = "<!-- undersample-bounds:begin -->"
BOUNDS_END = "<!-- undersample-bounds:end -->"
BOUNDS_T = 0.05  # the threshold the table shows (the others are in the JSON and the ranges)

# Measured once by hand (session 11, a scratch program over the same full renders, not kept),
# kept here so that a regeneration keeps it.
BOUNDS_TRIED = """**Tried: other rankings, and the shading's part.** With the same full renders at 256x256
(T 0.05), other scores for ranking the gaps, cut at exactly a third of the rays, against the
spread's 1.42% (bunny) and 1.15% (bunny-mirror): the largest second difference of the lattice
at the cell's corners, 1.53% and 1.39%; spread plus that second difference, 1.35% and 1.32%;
spread plus twice it, 1.33% and 1.27%; the spread weighted down where the corners hit one
triangle, 1.33% and 1.25%; centres weighted 0.7, 1.44% and 1.13%. None reaches 1% on either
scene: each ranks about half of its traced gaps right, where 1% at a third of the rays needs
about 55%. The shading's part: with `--shading diffuse` (no highlight) bunny's rule meets the
target at T 0.05 (0.327 rays, 0.95% changed; bunny-mirror 0.318 rays, 1.28%), so Phong's
highlights are what tips it; and a fill that took the highlight exactly from each gap's own
surface (an upper bound for filling the surface's attributes and shading them instead of its
colour: the diffuse image's fill plus the highlight the full render has) leaves bunny at 0.84%
changed, but still at 0.346 rays, the marks unchanged. A better fill lowers the floors: an
edge-directed blend for the cell's centre pixel (the mean of the diagonal pair whose ends differ
less, where the two pairs' differences are more than 0.02 apart) takes the fill's changes at
T 0.1 from 12.22% to 10.69% of bunny-refl's pixels (floor 4.28% to 2.75%), textured's from
15.20% to 14.22% (7.26% to 6.27%), bunny's from 5.91% to 5.29%; not enough for either floor to
reach 1%, and not built into the kernels."""


def bounds_section(exe, work, size):
    """How far any choice of traced gaps can take --aa undersample:2 (bench_undersample_bounds)."""
    out = os.path.join(work, "bounds.json")
    print(f"sampling.py: {exe} --size {size}", file=sys.stderr)
    subprocess.run([exe, "--size", str(size), "--json", out], check=True,
                   stdout=subprocess.DEVNULL)
    j = json.load(open(out))
    rows = [b for b in j["bounds"] if abs(b["threshold"] - BOUNDS_T) < 1e-9]
    by = {}
    for b in j["bounds"]:
        by.setdefault(b["scene"], []).append(b)

    def pct(v):
        return f"{100 * v:.2f}%"

    def span(scene, key):
        v = sorted(b[key] for b in by[scene])
        return f"{100 * v[0]:.2f}-{100 * v[-1]:.2f}%"
    budget = rows[0]["budget"]
    L = ["## How far any choice of traced gaps can go", "",
         "The fill of a gap reads lattice pixels only, so one render of every pixel tells, for "
         "each gap, whether the fill would change it (by more than 1/255): and so, for any "
         "choice of gaps to trace, how many pixels change. `bench/bench_undersample_bounds` "
         f"does this on the CPU tracer's images at {j['size']}x{j['size']}, K = {j['k']} "
         f"(its rule's images equal the tracer's own `--aa undersample:2`, which it checks). A "
         f"third of the rays leaves {pct(budget)} of the pixels to gaps after the lattice. If "
         f"the fill changes C of the pixels when no gap is traced, no choice gets below C less "
         f"that budget (the floor: the best choice traces exactly the gaps the fill would "
         f"change). Shares of the pixels, T {BOUNDS_T}:", "",
         "| scene | lattice | budget | key marks | fill changes (none traced) | floor | best "
         "after the key marks | marcarHuecos: rays / changed | its ranking cut at 1/3 | pixels "
         "per triangle hit |", "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for b in rows:
        L.append(f"| {b['scene']} | {pct(b['lattice'])} | {pct(b['budget'])} | {pct(b['keys'])}"
                 f" | {pct(b['fill_changes'])} | {pct(b['floor'])} | {pct(b['after_keys'])} | "
                 f"{b['rule_rays']:.3f} / {pct(b['rule_changed'])} | {pct(b['ranked_changed'])}"
                 f" | {b['pixels_per_triangle']:.1f} |")
    no_way = [b for b in rows if min(x["floor"] for x in by[b["scene"]]) > 0.01]
    could = [b for b in rows if b not in no_way and
             min(x["ranked_changed"] for x in by[b["scene"]]) > 0.01]
    L += ["", "Key marks: gaps whose lattice pixels hit different surfaces (silhouettes), traced "
          "by every rule. Its ranking: key marks first, then the colour spread, largest first, "
          "traced down to exactly a third of the rays (the rule itself stops at T instead)."]
    if no_way:
        L += ["", "- **No choice of gaps meets the target on " +
              ", ".join(f"{b['scene']} (floor {span(b['scene'], 'floor')} over T "
                        f"{', '.join(str(x['threshold']) for x in by[b['scene']])})"
                        for b in no_way) +
              "**: their fill changes more pixels than a third of the rays can trace. There the "
              "image carries detail between lattice pixels that no colour blend recovers: the "
              "mirrors repeat the bunny's shading and its silhouette (reflected keys are not "
              "surface keys), and a texture's texels are finer than the lattice. Meeting the "
              "target there needs a better fill (the best tried below lowers the floors, not to "
              "1%; or one from the surfaces' attributes rather than their colour) or more rays, "
              "not another rule for choosing gaps."]
    if could:
        L += ["", "- **An ideal choice could meet it on " +
              ", ".join(b["scene"] for b in could) + "** (floor 0), but the spread ranks gaps "
              "poorly there: cut at a third of the rays it leaves " +
              ", ".join(f"{b['scene']} {span(b['scene'], 'ranked_changed')}" for b in could) +
              " changed. Their meshes give " +
              ", ".join(f"{b['pixels_per_triangle']:.0f}" for b in could) +
              " pixels per triangle hit (edges about 4 pixels apart), and each edge kinks the "
              "smooth-shaded colour by a few 8-bit steps, most where a highlight crosses it: a "
              "gap beside a kink differs from the blend while its lattice pixels look alike."]
    L += ["", BOUNDS_TRIED]
    return "\n".join(L)


def pareto(points):
    """Indices of the points no other point beats in both cost and error."""
    front = []
    for i, (c, e) in enumerate(points):
        if not any((c2 <= c and e2 <= e) and (c2 < c or e2 < e) for c2, e2 in points):
            front.append(i)
    return front


def adaptive_verdict(rs):
    """The adaptive rows meeting the target: RMS within 1.5x of spp 16's, at most 35% of its
    rays (5.6 primary rays per pixel)."""
    u16 = rs["spp 16"]
    return u16, [r for k, r in rs.items() if k.startswith("adaptive 16")
                 and not k.endswith(", gated")
                 and r["rms"] <= 1.5 * u16["rms"] and r["rays_mean"] <= 0.35 * 16]


def table(rows, with_pareto):
    front = pareto([(r["gf6600"], r["rms"]) for r in rows]) if with_pareto else []
    out = ["| mode | RMS | edge RMS | rays / pixel (max) | passes | gf5700 ms | gf6600 ms | "
           "h200 ms | emulator ms |" + (" Pareto |" if with_pareto else ""),
           "|---|---:|---:|---:|---:|---:|---:|---:|---:|" + (":-:|" if with_pareto else "")]
    for i, r in enumerate(rows):
        out.append(f"| {r['mode']} | {r['rms']:.4f} | {r['edge_rms']:.4f} | "
                   f"{r['rays_mean']:.2f} ({r['rays_max']:.0f}) | {r['passes']:,} | "
                   f"{r['gf5700']:,.0f} | {r['gf6600']:,.0f} | {r['h200']:,.1f} | "
                   f"{r['emulator_ms']:,.0f} |" + (f" {'*' if i in front else ''} |"
                                                    if with_pareto else ""))
    return out


TRIED_BEND = """**Tried and not kept: marking gaps by the lattice's second difference.** The fill is exact
where the colour changes linearly, so a gap could be marked by how the lattice bends (second
differences from the lattice pixels one step further out, 16 more fetches per pixel) instead of
by the spread of its corners (the key test kept). Measured with `bench_sampling --size 256
--ref-spp 0 --modes 'undersample 2'` on the ten bundled scenes (rays per pixel, changed >
1/255, changed > 0.05), against the straight (bilinear) fill of the time, before the
correction below:
- Bend = |f(a-K) - f(a) - f(b) + f(b+K)| (the cubic's correction at the midpoint): bunny-low
  meets the target at T 0.05 (0.329, 0.95%), but a step inside one surface does not bend by
  this sum, so visible errors grow (changed > 0.05 at T 0.1: bunny-refl 1.90%, sphere 0.55%,
  classic 0.73%, against 0.22%, 0.00%, 0.13%) and classic misses (0.333, 1.07% at T 0.1; 0.337
  at T 0.05).
- Bend = the larger |second difference| at a or b: visible errors as low as the spread's
  (at most 0.12% at T 0.1), bunny 0.382 rays / 0.30% at T 0.02, but classic rises to 0.340
  rays at T 0.1 (steps mark the lines beside them too) and misses; no curved mesh meets.
Neither meets the target on more scenes without breaking one that passed.

**Kept: correcting the fill for curvature.** Rather than trace where the lattice bends, the fill
now subtracts what a straight blend misses on a curving shade: t(1 - t)/2 times the lattice's
second difference along each axis (the blend's error for a quadratic at fraction t of the
way), the smaller of the cell's two ends' (minmod, 0 where their signs differ), and only where
both are within T / 2. A quadratic shade comes back exactly; a step beyond the cell (second
difference large at one end only) or a stripe two lattice steps wide (large at both) keeps the
straight blend. The marks, and so the rays, are unchanged. Measured at 256x256 against the
bilinear fill (changed > 1/255 at T 0.1 / 0.05 / 0.02, same rays): bunny 2.56 / 1.23 / 0.38% to
2.13 / 1.12 / 0.38%, bunny-low 2.09 / 1.03 / 0.27% to 1.72 / 0.91 / 0.27% (the target met at
T 0.05, 0.332 rays), bunny-mirror 2.64 / 1.43 / 0.45% to 2.36 / 1.36 / 0.45%, teapot 1.27 /
0.58 / 0.12% to 1.15 / 0.53 / 0.12%, classic 0.76 / 0.44 / 0.11% to 0.74 / 0.43 / 0.11%, hop
0.35% to 0.36% at T 0.1; changed > 0.05 moved by at most 0.01 points. With the limit at T
instead of T / 2 the curved meshes gain more (bunny 1.96%, bunny-low 0.81% at T 0.05) but
checkerboards lose (hop 0.56%, classic 0.84% at T 0.1: a checker stripe of low contrast bends
like a curve)."""


DOC = os.path.join(ROOT, "docs", "studies", "sampling.md")
from sampling_h200 import (BUDGET_BEGIN, BUDGET_END, BUDGET_PROSE, COMPACT_BEGIN,  # noqa: E402
                           COMPACT_END, H200_BEGIN, H200_END, h200, h200_budget, h200_compact)


def plot_chart(main_rows, scenes, size):
    """docs/studies/sampling.png: per scene, each mode's RMS error against its modeled gf6600 time,
    the Pareto front outlined; each gated mode (before the dense streams) hollow, joined to its
    dense twin (the same image)."""
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.2 * len(scenes), 4.2), sharey=False)
    markers = {"spp": "o", "adaptive": "s", "undersample": "^", "budget": "D"}
    colours = {"spp": "tab:blue", "adaptive": "tab:orange", "undersample": "tab:green",
               "budget": "tab:red"}
    for ax, scene in zip(axes, scenes):
        rs = [r for r in main_rows if r["scene"] == scene]
        pts = [(r["gf6600"], r["rms"]) for r in rs]
        front = pareto(pts)
        by_mode = {r["mode"]: r for r in rs}
        for i, r in enumerate(rs):
            kind = r["mode"].split()[0]
            if r["mode"].endswith(", gated"):
                ax.scatter(r["gf6600"] / 1000, r["rms"], marker=markers[kind], s=30,
                           facecolors="none", edgecolors=colours[kind], lw=0.8)
                twin = by_mode[r["mode"][:-len(", gated")]]
                ax.plot([r["gf6600"] / 1000, twin["gf6600"] / 1000], [r["rms"], twin["rms"]],
                        color=colours[kind], lw=0.5, ls=":")
                continue
            ax.scatter(r["gf6600"] / 1000, r["rms"], marker=markers[kind],
                       s=60 if i in front else 30, color=colours[kind],
                       edgecolors="black" if i in front else "none")
        fr = sorted((pts[i][0] / 1000, pts[i][1]) for i in front)
        ax.plot([p[0] for p in fr], [p[1] for p in fr], "k--", lw=0.8, label="Pareto front")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.autoscale_view()
        # Labels from the top down, each moved down past the labels already placed near it (in
        # points on the page), so that clustered modes stay readable.
        placed = []
        for r in sorted((r for r in rs if not r["mode"].endswith(", gated")),
                        key=lambda r: -r["rms"]):
            x, y = ax.transData.transform((r["gf6600"] / 1000, r["rms"])) * 72 / fig.dpi
            dy = 3
            while any(abs(y + dy - py) < 7 and abs(x - px) < 75 for px, py in placed):
                dy -= 7
            placed.append((x, y + dy))
            ax.annotate(r["mode"], (r["gf6600"] / 1000, r["rms"]), fontsize=6,
                        xytext=(3, dy), textcoords="offset points",
                        arrowprops=None if dy == 3 else dict(arrowstyle="-", lw=0.3, color="0.5"))
        ax.set_title(f"{scene}, {size}x{size}")
        ax.set_xlabel("predicted gf6600 time (s)")
        ax.grid(True, which="both", lw=0.3)
    axes[0].set_ylabel("RMS error against 256 samples")
    axes[0].legend(loc="lower left", fontsize=7)
    fig.suptitle("Sampling modes: error against modeled time (circles: --spp; squares: "
                 "--aa adaptive by the image criterion; diamonds: by the budget, the default;\n"
                 "triangles: --aa undersample; outlined: on the Pareto front; hollow, dotted to "
                 "their dense twins: the gated frames of before)", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(ROOT, "docs/studies/sampling.png"), dpi=110)


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bench", default=os.path.join(ROOT, "build/bench/bench_sampling"))
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--scenes", default=MAIN)
    ap.add_argument("--other-scenes", default=OTHERS)
    ap.add_argument("--changed-size", type=int, default=256)
    ap.add_argument("--bounds-bench",
                    default=os.path.join(ROOT, "build/bench/bench_undersample_bounds"))
    ap.add_argument("--bounds-only", action="store_true",
                    help="only rewrite docs/studies/sampling.md's section on how far any choice of "
                    "traced gaps can go")
    ap.add_argument("--h200", nargs="+", metavar="FILE",
                    help="bench_gl JSON measured on an H200 (results/sampling/sampling_h200*.json): only "
                    "rewrite docs/studies/sampling.md's H200 section")
    ap.add_argument("--h200-clocks", metavar="CSV",
                    default=os.path.join(ROOT, "results", "sampling", "streams_sampling_h200_clocks.csv"),
                    help="nvidia-smi's clock log of the same run")
    ap.add_argument("--h200-budget", nargs="+", metavar="FILE",
                    help="write only the budget criterion's H200 section from "
                    "scripts/h200/budget_sampling.sh's bench_gl JSON files")
    ap.add_argument("--h200-compact", nargs="+", metavar="FILE",
                    help="bench_gl JSON of the dense streams on an H200 "
                    "(results/sampling/compact_h200_*.json): only rewrite docs/studies/sampling.md's "
                    "section on them")
    ap.add_argument("--h200-looping", nargs="+", metavar="FILE",
                    help="bench_gl JSON of the looping frames run again with --warmup-ms "
                    "(results/sampling/sampling_h200_looping*.json): the section's looping rows")
    ap.add_argument("--h200-looping-control", nargs="+", metavar="FILE",
                    help="the same run's frames without warm-up "
                    "(results/sampling/sampling_h200_looping_nowarm*.json)")
    ap.add_argument("--h200-looping-clocks", metavar="CSV",
                    default=os.path.join(ROOT, "results", "sampling", "sampling_h200_looping_clocks.csv"),
                    help="nvidia-smi's clock log of the looping run")
    return ap.parse_args()


def measure(args, scenes, others):
    """Runs bench_sampling three times (every mode on the main scenes; the adaptive and
    undersampling modes on the others; undersampling's changed pixels at --changed-size) and
    bench_undersample_bounds. Returns their rows and the bounds section's text."""
    common = ["--size", str(args.size), "--reps", str(args.reps)]
    with tempfile.TemporaryDirectory() as work:
        main_rows = bench(args.bench, [*common, "--scenes", args.scenes, "--modes",
                                       "spp,adaptive,undersample,budget 16"], work, "main")["rows"]
        other_rows = bench(args.bench, [*common, "--scenes", ",".join(others), "--modes",
                                        "spp 16,adaptive 16,undersample 2,budget 16"],
                           work, "others")["rows"] if others else []
        changed = bench(args.bench, ["--size", str(args.changed_size), "--reps", "1", "--ref-spp",
                                     "0", "--modes", "undersample", "--scenes",
                                     ",".join(scenes + others)], work, "changed")["rows"]
        bounds = bounds_section(args.bounds_bench, work, args.changed_size)
        timed = bench(args.bench, ["--size", str(TIME_SIZE), "--reps", "1", "--ref-spp", "0",
                                   "--modes", "spp 16,adaptive 16,undersample 2,budget 16", "--scenes",
                                   TIME_SCENES], work, "time")["rows"]
    return main_rows, other_rows, changed, bounds, timed


def intro(args):
    """The page's title, how the figures were made, the chart, and the prose before the tables."""
    return [
        "# Sampling: error against rays, passes and modeled time",
        "",
        "Written by `scripts/docs/sampling.py` from `bench_sampling`'s figures (do not edit by hand; "
        "the prose around the tables is in the script). Scenes at "
        f"{args.size}x{args.size}, the CLI's default options (2 bounces, Phong, shadows, grid), "
        "the stream engine on gf6600 (predictions for every profile come from the same "
        "statistics). Reference: the CPU tracer at 256 samples per pixel. RMS over the 8-bit "
        "images (as the PNG stores them); edge pixels: where the one-ray image differs from the "
        "reference by more than 0.05 (the pixels aliasing spoils). Rays: primary rays per pixel, "
        "mean (largest). Emulator ms: this machine, median of "
        f"{args.reps} runs, to be read as ratios.",
        "",
        "![error against modeled time](sampling.png)",
        "",
    ] + HOW_2004 + RULES


def scene_tables(scenes, others, main_rows, other_rows):
    """One table per main scene (Pareto front marked), then the other scenes' tables."""
    out = []
    for scene in scenes:
        rs = [r for r in main_rows if r["scene"] == scene]
        out += [f"## {scene} ({rs[0]['edge_pixels']} edge pixels)", ""] + table(rs, True) + [""]
    if others:
        out += ["## The other bundled scenes", "",
                "The adaptive and undersampling modes beside the one-ray and 16-sample images.",
                ""]
        for scene in others:
            rs = [r for r in other_rows if r["scene"] == scene]
            out += [f"### {scene} ({rs[0]['edge_pixels']} edge pixels)", ""] + \
                table(rs, False) + [""]
    return out


def adaptive_target(scenes, others, main_rows, other_rows):
    """Adaptive supersampling against its target: the best mode meeting it per scene, then
    which scenes each single threshold meets it on."""
    out = ["## Against the targets", "",
           "**Adaptive supersampling**: the RMS error of 16 samples per pixel within 1.5x, with "
           "at most 35% of their rays (5.6 primary rays per pixel, the centre ray and every "
           "level's counted).", "",
           "| scene | spp 16 RMS | best adaptive 16 meeting it | its RMS / spp 16's | its rays "
           "/ 16 | met |", "|---|---:|---|---:|---:|:-:|"]
    for scene in scenes + others:
        rows = main_rows if scene in scenes else other_rows
        rs = {r["mode"]: r for r in rows if r["scene"] == scene}
        u16, ok = adaptive_verdict(rs)
        if ok:
            b = min(ok, key=lambda r: r["rays_mean"])
            out.append(f"| {scene} | {u16['rms']:.4f} | {b['mode']} | "
                       f"{b['rms'] / u16['rms']:.2f}x | {100 * b['rays_mean'] / 16:.0f}% | yes |")
        else:
            t = rs["adaptive 16, T 0.1"]
            out.append(f"| {scene} | {u16['rms']:.4f} | none (T 0.1: RMS "
                       f"{t['rms'] / u16['rms']:.2f}x with {100 * t['rays_mean'] / 16:.0f}% of the "
                       "rays) | | | no |")
    # One threshold for every scene: where each adaptive threshold meets the target.
    out.append("")
    for t in ("0.05", "0.1", "0.2"):
        mode = f"adaptive 16, T {t}"
        met, missed = [], []
        for scene in scenes + others:
            rows = main_rows if scene in scenes else other_rows
            rs = {r["mode"]: r for r in rows if r["scene"] == scene}
            _, ok = adaptive_verdict(rs)
            (met if any(r["mode"] == mode for r in ok) else missed).append(
                scene if any(r["mode"] == mode for r in ok) else
                f"{scene} ({rs[mode]['rms'] / rs['spp 16']['rms']:.2f}x, "
                f"{100 * rs[mode]['rays_mean'] / 16:.0f}%)")
        out.append(f"- T {t} alone meets the target on {len(met)} of {len(met) + len(missed)} "
                   f"scenes" + (f"; not on {', '.join(missed)}." if missed else "."))
    # The default, the budget criterion: one setting for every scene.
    met, worst_rms, worst_rays = [], 0.0, 0.0
    for scene in scenes + others:
        rows = main_rows if scene in scenes else other_rows
        rs = {r["mode"]: r for r in rows if r["scene"] == scene}
        b, u16 = rs["budget 16"], rs["spp 16"]
        worst_rms = max(worst_rms, b["rms"] / u16["rms"])
        worst_rays = max(worst_rays, b["rays_mean"] / 16)
        if b["rms"] <= 1.5 * u16["rms"] and b["rays_mean"] <= 0.35 * 16:
            met.append(scene)
    n = len(scenes + others)
    out.append(f"- **The default, the budget criterion** (`--aa adaptive --spp 16` with nothing "
               f"else), meets the target on {len(met)} of {n} scenes"
               + ("" if len(met) == n else
                  f" (not on {', '.join(s for s in scenes + others if s not in met)})")
               + f": RMS at most {worst_rms:.2f}x uniform 16's, at most "
               f"{100 * worst_rays:.1f}% of its primary rays (every ray counted, shadow and "
               "reflected too: the cones section below).")
    return out


def undersample_target(scenes, others, changed, changed_size):
    """Undersampling against its target: rays and changed pixels per scene and threshold, which
    scenes meet it, and why the modeled time does not follow the rays."""
    out = ["", "**Undersampling, K = 2**: at most 1% of the pixels of a full render changed, with "
           "a third of its primary rays or fewer (0.333 per pixel), at "
           f"{changed_size}x{changed_size}. A pixel *changes* when some channel of its "
           "8-bit value differs from the one-ray render's by more than 1/255: a difference of "
           "one step is the rounding of two nearly equal floats (the traced and the "
           "interpolated colour of a smooth shade), not something a viewer sees; the share "
           "differing by more than 0.05 (visibly) is given too. T: `--aa-threshold`, the "
           "colour spread of the lattice pixels a pixel's fill blends above which it is traced.", "",
           "| scene | mode | rays / pixel | changed > 1/255 | changed > 0.05 | met |",
           "|---|---|---:|---:|---:|:-:|"]
    for scene in scenes + others:
        for r in changed:
            if (r["scene"] == scene and r["mode"].startswith("undersample 2")
                    and not r["mode"].endswith(", gated")):
                met = r["changed_255"] <= 0.01 and r["rays_mean"] <= 1 / 3
                out.append(f"| {scene} | {r['mode']} | {r['rays_mean']:.3f} | "
                           f"{100 * r['changed_255']:.2f}% | {100 * r['changed_005']:.2f}% | "
                           f"{'yes' if met else 'no'} |")
    good = sorted({r["scene"] for r in changed if r["mode"].startswith("undersample 2")
                   and r["changed_255"] <= 0.01 and r["rays_mean"] <= 1 / 3})
    bad = [sc for sc in scenes + others if sc not in good]
    out += ["", f"- Met (at some T) on {', '.join(good) or 'no scene'}; not on "
            f"{', '.join(bad) or 'any'}: there, every threshold that keeps the changed pixels "
            "under 1% traces more than a third of the rays. What the fill still misses there is "
            "not curvature but kinks: bunny's difference image (x30) shows the mesh's triangles, "
            "whose interpolated normals turn the shade by a few 8-bit steps at each edge (about "
            "4 pixels apart at this size), reflections of them, and a texture's detail. The "
            "section \"How far any choice of traced gaps can go\" below measures which of these "
            "misses another rule for choosing gaps could mend (bunny, bunny-mirror) and which "
            "no rule can (bunny-refl, textured). By "
            "more than 0.05, undersampling changes at most "
            f"{100 * max(r['changed_005'] for r in changed if r['mode'] == 'undersample 2'):.2f}%"
            " of the pixels of any scene at the default T 0.1."]
    return out


TIME_SIZE = 256
TIME_SCENES = "classic,bunny"


def time_targets(rows):
    """Sampling that saves time against its targets at 256x256: undersampling (K = 2) at most
    0.5x the one-ray frame's modeled time, adaptive 16 (T 0.1) at most 0.5x uniform 16's, on
    gf6600 and h200, dense and gated."""
    out = ["", "**Sampling that saves time** (issue 35): at "
           f"{TIME_SIZE}x{TIME_SIZE}, modeled time on gf6600 and h200, the CLI's defaults "
           "(shadows on), undersampling (K = 2) at most 0.5x the one-ray frame, adaptive 16 at "
           "most 0.5x uniform 16 samples. Dense: `--compact on`; gated: `--compact off`, as "
           "before.", "",
           "| scene | profile | spp 1 ms | undersample 2: dense / gated ms | dense / spp 1 | "
           "met | spp 16 ms | adaptive 16, T 0.1: dense / gated ms | dense / spp 16 | met |",
           "|---|---|---:|---:|---:|:-:|---:|---:|---:|:-:|"]
    floor, adaptive_met, budget_ratio = {}, [], []
    for scene in TIME_SCENES.split(","):
        rs = {r["mode"]: r for r in rows if r["scene"] == scene}
        for prof in ("gf6600", "h200"):
            one, u16 = rs["spp 1"][prof], rs["spp 16"][prof]
            us, usg = rs["undersample 2"][prof], rs["undersample 2, gated"][prof]
            ad, adg = rs["adaptive 16, T 0.1"][prof], rs["adaptive 16, T 0.1, gated"][prof]
            adaptive_met.append(ad <= 0.5 * u16)
            out.append(f"| {scene} | {prof} | {one:,.1f} | {us:,.1f} / {usg:,.1f} | "
                       f"{us / one:.2f}x | {'yes' if us <= 0.5 * one else 'no'} | {u16:,.1f} | "
                       f"{ad:,.1f} / {adg:,.1f} | {ad / u16:.2f}x | "
                       f"{'yes' if adaptive_met[-1] else 'no'} |")
            floor[(scene, prof)] = rs["undersample 2"][prof + "_fixed"] / one
            budget_ratio.append(f"{scene} {prof} {rs['budget 16'][prof] / u16:.2f}x")
    lo = min(floor.values())
    out += ["", "- The default criterion, the budget (*budget 16*, dense), against uniform 16: "
            + ", ".join(budget_ratio) + ".",
            f"- Adaptive 16 (T 0.1, the image criterion) meets its target on {sum(adaptive_met)} of "
            f"{len(adaptive_met)} "
            "scenes and cards: a level's samples of "
            "the marked pixels share frames, so it runs a handful of frames instead of 21 "
            "(the centre frame, then 4 + 16 gated frames), each over the rows its rays fill.",
            "- Undersampling does not, and cannot while it runs two frames one after the other: "
            "the lattice frame's marks decide the gaps' frame, and each frame's walk runs as many "
            "passes as the longest ray's path needs, however few rays it holds. Each pass pays "
            "the card's fixed costs (a pass, a program load, a query read-back per step of the "
            "walk), and those of the undersampled render alone are "
            f"{lo:.2f}x the one-ray frame's whole time or more ("
            + ", ".join(f"{sc} {p} {v:.2f}x" for (sc, p), v in floor.items()) +
            "), above 0.5x before any fragment is shaded. The dense streams cut the pass work "
            "(the lattice a quarter of the fragments, the gaps fewer), which is what brings "
            "undersampling from dearer than the one-ray frame to about its price on the H200; "
            "fewer passes per frame (the looping walk) or a way to decide the gaps without a "
            "second walk would make it cheaper, and the section below measures how cheap either "
            "could make it.", ""]
    return out


def main():
    args = parse_args()
    if args.bounds_only:
        with tempfile.TemporaryDirectory() as work:
            hf.replace_section(DOC, BOUNDS_BEGIN, BOUNDS_END,
                               bounds_section(args.bounds_bench, work, args.changed_size))
        print("sampling.py: wrote docs/studies/sampling.md's bounds section", file=sys.stderr)
        return
    if args.h200_budget:
        hf.replace_section(DOC, BUDGET_BEGIN, BUDGET_END,
                           h200_budget(args.h200_budget, BUDGET_PROSE))
        print("sampling.py: wrote docs/studies/sampling.md's budget H200 section", file=sys.stderr)
        return
    if args.h200_compact:
        hf.replace_section(DOC, COMPACT_BEGIN, COMPACT_END, h200_compact(args.h200_compact))
        print("sampling.py: wrote docs/studies/sampling.md's dense-stream H200 section", file=sys.stderr)
        return
    if args.h200:
        hf.replace_section(DOC, H200_BEGIN, H200_END,
                           h200(args.h200, args.h200_clocks, args.h200_looping,
                                args.h200_looping_control, args.h200_looping_clocks))
        print("sampling.py: wrote docs/studies/sampling.md's H200 section", file=sys.stderr)
        return
    scenes = args.scenes.split(",")
    others = [s for s in args.other_scenes.split(",") if s]
    main_rows, other_rows, changed, bounds, timed = measure(args, scenes, others)

    plot_chart(main_rows, scenes, args.size)

    out = intro(args)
    out += scene_tables(scenes, others, main_rows, other_rows)
    out += adaptive_target(scenes, others, main_rows, other_rows)
    out += undersample_target(scenes, others, changed, args.changed_size)
    out += time_targets(timed)
    # How cheap undersampling can get (scripts/docs/undersample_time_bound.py): kept as it is.
    bound = hf.section(DOC, "<!-- time-bound:begin -->", "<!-- time-bound:end -->")
    if bound:
        out += [bound, ""]
    # Measured once by hand (session 9, bench_sampling), kept here so that a regeneration keeps it.
    out += [TRIED_BEND, ""]
    out += [BOUNDS_BEGIN, bounds, BOUNDS_END, ""]
    # The object criterion's section (scripts/docs/sampling_cones.py writes it): kept as it is.
    cones = hf.section(DOC, "<!-- cones:begin -->", "<!-- cones:end -->")
    if cones:
        out += [cones, ""]
    # The rules tried offline for one default (scripts/docs/sampling_rules.py): kept as it is.
    rules = hf.section(DOC, "<!-- rules:begin -->", "<!-- rules:end -->")
    if rules:
        out += [rules, ""]
    kept = hf.section(DOC, H200_BEGIN, H200_END)  # measured on other hardware: kept as it is
    if kept:
        out += [kept, ""]
    kept = hf.section(DOC, COMPACT_BEGIN, COMPACT_END)
    if kept:
        out += [kept, ""]
    kept = hf.section(DOC, BUDGET_BEGIN, BUDGET_END)
    if kept:
        out += [kept, ""]
    with open(DOC, "w") as f:
        f.write("\n".join(out))
    print("sampling.py: wrote docs/studies/sampling.md and docs/studies/sampling.png", file=sys.stderr)


if __name__ == "__main__":
    main()
