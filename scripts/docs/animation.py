#!/usr/bin/env python3
"""Writes docs/studies/animation.png and the measured tables of docs/studies/animation.md (issue 23): what a
moving scene costs per frame, per structure and update mode, on the emulator and modeled.

For each scene (default: the bundled `hop`, 1,436 triangles, and `scatter`, 37,228 triangles,
which scripts/scenes/scatter_scene.py writes into build/scenes/ when it is missing), each structure of
--structures, and each update mode the structure has (rebuild for all; refit and auto for those
of --refit, the BVH), vgpu-rt renders --frames with --stats-json, one run each. From the
per-frame records it charts and tabulates, per frame:

  update     the host's work between frames: pose (animation sampled, scene flattened), the
             structure's build or refit, and the static textures rewritten (host ms, measured)
  render     the emulator's render (host ms, measured) and the cost model's frame on gf6600 and
             h200 (ms, from the frame's passes; the upload over the profile's bus added)
  quality    a refitted BVH's SAH cost over the cost of a BVH built for the same frame (the
             rebuild run's), and its node visits over the rebuilt tree's

Usage: /usr/bin/python3 scripts/docs/animation.py [--vgpu-rt build/host/vgpu-rt] [--scenes hop,scatter]
         [--structures grid,bvh,kdtree] [--refit bvh] [--kernels multipass,looping]
         [--frames 0:2:25] [--size 128] [--probe-sizes 256,512] [--probe-time 1] [--threads 0]
         [--runs build/animation_runs] [--reuse] [--doc docs/studies/animation.md]
         [--png docs/studies/animation.png]
  --kernels      multipass: the paper's kernels on gf5700; looping: the looping kernels on gf6600
  --probe-sizes  one frame at --probe-time s at each size, per structure and kernels
  --reuse   read the runs' JSON already in --runs instead of rendering (a missing one is run)
  --png ''  no chart (then matplotlib is not needed)
  --doc     the Markdown file whose block between the markers
            '<!-- animation.py: begin -->' and '<!-- animation.py: end -->' is replaced by the
            tables ('-' prints them instead)
"""
import argparse
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "lib"))
import vgpurt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PROFILES = ["gf6600", "h200"]
BEGIN, END = "<!-- animation.py: begin -->", "<!-- animation.py: end -->"
INTERACTIVE_MS = 100.0  # 10 frames per second
STYLE = {"rebuild": "-", "refit": "--", "auto": ":"}


def scene_path(name):
    """A bundled scene by name, or scatter (generated), or a path."""
    if name == "scatter":
        path = os.path.join(ROOT, "build", "scenes", "scatter.gltf")
        if not os.path.exists(path):
            subprocess.run([sys.executable, os.path.join(ROOT, "scripts", "scenes", "scatter_scene.py"),
                            os.path.dirname(path)], check=True, stdout=subprocess.DEVNULL)
        return path
    return name


def kernel_options(variant):
    """The multipass kernels on the default profile (gf5700), or the looping kernels on gf6600
    (the 2004 card with data-dependent loops; the FX 5700 cannot run them)."""
    return ["--kernels", "looping", "--profile", "gf6600"] if variant == "looping" else []


def run(a, scene, structure, mode, variant, when=None, size=None):
    """One vgpu-rt run's JSON, rendered unless --reuse finds it: the frames of --frames, or the
    one frame at `when` seconds (--time) at `size`."""
    size = size or a.size
    what = ["--time", when] if when else ["--frames", a.frames]
    tag = f"t{when}" if when else a.frames.replace(":", "-")
    path = os.path.join(a.runs, f"{scene}_{structure}_{mode}_{variant}_{size}_{tag}.json")
    if not (a.reuse and os.path.exists(path)):
        return vgpurt.render(a.vgpu_rt, scene_path(scene),
                             [*what, "--size", f"{size}x{size}", "--threads", str(a.threads),
                              "--accel", structure, "--update", mode, *kernel_options(variant)],
                             stats_json=path, echo=True)
    return vgpurt.read_stats(path)


def update_ms(r):
    u = r["update"]
    return u["pose_ms"] + u["build_ms"] + u["write_ms"]


def modeled_ms(r, p):
    """The modeled frame on profile p: its passes plus its upload over p's bus."""
    return r["predicted_ms"][p] + r["update"]["predicted"][p]["upload_ms"]


def series(rs):
    """Per-frame quantities of one run (frame 1's update is the initialization: None)."""
    f = rs["frames"]
    out = {
        "time": [r["time"] for r in f],
        "update_ms": [None] + [update_ms(r) for r in f[1:]],
        "build_ms": [None] + [r["update"]["build_ms"] for r in f[1:]],
        "uploaded": [None] + [r["update"]["uploaded_bytes"] for r in f[1:]],
        "action": [r["update"]["mode"] for r in f],
        "render_ms": [r["render_ms"] for r in f],
        "passes": [r["totals"]["passes"] for r in f],
        "nodes": [r["accel"]["work"]["nodes_visited"] for r in f],
        "voxels": [r["accel"]["work"]["voxel_steps"] for r in f],
        "loops": [r["accel"]["work"]["loop_iterations"] for r in f],
        "sah": [r["accel"].get("sah_cost") for r in f],
        "triangles": f[0]["triangles"],
        "upload_gf6600": [None] + [r["update"]["predicted"]["gf6600"]["upload_ms"] for r in f[1:]],
    }
    for p in PROFILES:
        out[p] = [modeled_ms(r, p) for r in f]
    return out


def med(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


def fmt(v, digits=3):
    if v is None:
        return "-"
    if abs(v) >= 1000:
        return f"{v:,.0f}"
    return f"{v:.{digits}g}"


def rate(ms):
    """Frames per second of a frame of `ms` milliseconds."""
    x = 1000.0 / ms
    return f"{x:.2g}" if x < 100 else f"{x:,.0f}"


def pct(x):
    return f"{100 * x:.2f}%" if x < 0.1 else f"{100 * x:,.0f}%"


def tables(a, runs, probes):
    """The Markdown tables of docs/studies/animation.md."""
    n = len(next(iter(runs.values()))["time"])
    lines = [f"Measured by `scripts/docs/animation.py --size {a.size} --frames {a.frames} "
             f"--structures {','.join(a.structures)}`: one run per scene, structure, update mode "
             f"and kernels, {a.size}x{a.size}, 2 bounces, shadows, phong, --threads {a.threads} "
             "(0: every host thread); multipass kernels on gf5700 (the paper's), looping kernels "
             f"on gf6600. Medians over frames 2 to {n} (frame 1's update is the initialization). "
             "*update* is the host's work between two frames (pose, structure, textures), "
             "measured; *upload* is the uploaded bytes over the 6600's bus (PCI Express), "
             "modeled; the modeled frame is the cost model's passes plus that upload; *fps* is "
             "1000 / (modeled frame + update), with the update as measured on this host.", ""]
    for scene in a.scenes:
        keys = [k for k in runs if k[0] == scene]
        tri = runs[keys[0]]["triangles"]
        lines += [f"**{scene}** ({tri:,} triangles)", "",
                  "| structure | kernels | update | update ms | of which build/refit ms "
                  "| uploaded bytes | upload gf6600 ms | render ms (emulator) | update / render "
                  "| rebuilds | passes | nodes visited | voxel steps | loop iterations "
                  "| modeled gf6600 ms | gf6600 fps | modeled h200 ms | h200 fps |",
                  "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
                  "---:|---:|"]
        for k in keys:
            r = runs[k]
            later = lambda key: r[key][1:]  # noqa: E731
            ratio = med([u / x for u, x in zip(later("update_ms"), later("render_ms"))])
            rebuilds = sum(1 for x in r["action"][1:] if x == "rebuild")
            upd = med(later("update_ms"))
            fps = {p: rate(med(later(p)) + upd) for p in PROFILES}
            lines.append(
                f"| {k[1]} | {k[3]} | {k[2]} | {fmt(upd)} | {fmt(med(later('build_ms')))} | "
                f"{fmt(med(later('uploaded')))} | {fmt(med(later('upload_gf6600')))} | "
                f"{fmt(med(later('render_ms')))} | {pct(ratio)} | {rebuilds} | "
                f"{fmt(med(later('passes')))} | {fmt(med(later('nodes')))} | "
                f"{fmt(med(later('voxels')))} | {fmt(med(later('loops')))} | "
                f"{fmt(med(later('gf6600')))} | {fps['gf6600']} | {fmt(med(later('h200')))} | "
                f"{fps['h200']} |")
        lines.append("")
        for s in a.refit:
            base = runs.get((scene, s, "rebuild", "multipass"))
            for m in ("refit", "auto"):
                r = runs.get((scene, s, m, "multipass"))
                if not (base and r):
                    continue
                q = [x / y for x, y in zip(r["sah"], base["sah"])]
                v = [x / y if y else None for x, y in zip(r["nodes"], base["nodes"])]
                ur = [u / x for u, x in zip(r["update_ms"][1:], r["render_ms"][1:])]
                lines.append(
                    f"- {s} `--update {m}`, multipass: the tree's SAH cost over that of a tree "
                    f"built for the same frame is {q[0]:.3g} at frame 1, {q[-1]:.3g} at frame {n}, "
                    f"at most {max(q):.3g}; its node visits over the built tree's at most "
                    f"{max(x for x in v if x is not None):.3g} ({v[-1]:.3g} at frame {n}); the "
                    f"update over the emulator's render: median {pct(statistics.median(ur))}, at "
                    f"most {pct(max(ur))}.")
        lines.append("")
    if probes:
        lines += [f"One frame at t = {a.probe_time} s at larger sizes, `--update rebuild` (the first "
                  "frame: structure built, everything uploaded), the same settings:", "",
                  "| scene | size | structure | kernels | passes | render ms (emulator) "
                  "| modeled gf6600 ms | gf6600 fps | modeled h200 ms | h200 fps |",
                  "|---|---:|---|---|---:|---:|---:|---:|---:|---:|"]
        for (scene, size, s, variant), j in sorted(probes.items()):
            g, h = j["predicted_ms"]["gf6600"], j["predicted_ms"]["h200"]
            lines.append(f"| {scene} | {size}x{size} | {s} | {variant} | "
                         f"{j['totals']['passes']:,} | {fmt(j['render_ms'])} | {fmt(g)} | "
                         f"{rate(g)} | {fmt(h)} | {rate(h)} |")
        lines.append("")
    return "\n".join(lines)


def chart(a, runs):
    import matplotlib  # here, so that --png '' runs where matplotlib is missing

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cols = (("update_ms", "multipass", "update, host ms (pose + build/refit + textures)"),
            ("render_ms", "multipass", "render, emulator host ms (multipass)"),
            ("gf6600", "multipass", "modeled GeForce 6600, multipass, ms"),
            ("gf6600", "looping", "modeled GeForce 6600, looping kernels, ms"),
            ("h200", "multipass", "modeled H200, multipass, ms"))
    # Per scene two rows of three panels: the five quantities and the refit's quality.
    fig, axes = plt.subplots(2 * len(a.scenes), 3, figsize=(16, 8.4 * len(a.scenes)),
                             squeeze=False)
    colours = {s: f"C{i}" for i, s in enumerate(a.structures)}
    for i, scene in enumerate(a.scenes):
        row = axes[2 * i:2 * i + 2].flatten()
        tri = next(r for k, r in runs.items() if k[0] == scene)["triangles"]
        for ax, (key, variant, title) in zip(row, cols):
            for k in [k for k in runs if k[0] == scene and k[3] == variant]:
                r = runs[k]
                pts = [(t, y) for t, y in zip(r["time"], r[key]) if y is not None]
                ax.plot(*zip(*pts), STYLE[k[2]], color=colours[k[1]], label=f"{k[1]} {k[2]}",
                        lw=1.4)
                if k[2] == "auto":  # the frames auto rebuilt
                    rb = [(t, y) for t, y, act in zip(r["time"], r[key], r["action"])
                          if act == "rebuild" and y is not None]
                    if rb:
                        ax.plot(*zip(*rb), "o", color=colours[k[1]], ms=4, mfc="none")
            if key in PROFILES:
                ax.axhline(INTERACTIVE_MS, color="k", lw=0.8, ls="-.")
                ax.text(0.01, INTERACTIVE_MS * 1.08, "10 fps", fontsize=7,
                        transform=ax.get_yaxis_transform())
            ax.set_yscale("log")
            ax.set_xlabel("animation time, s")
            ax.set_title(f"{scene} ({tri:,} triangles): {title}", fontsize=10)
            ax.grid(True, which="major", lw=0.3)
        row[0].legend(fontsize=7, ncol=2)
        ax = row[len(cols)]
        for s in a.refit:
            base = runs.get((scene, s, "rebuild", "multipass"))
            for m in ("refit", "auto"):
                r = runs.get((scene, s, m, "multipass"))
                if not (base and r):
                    continue
                ax.plot(r["time"], [x / y for x, y in zip(r["sah"], base["sah"])], STYLE[m],
                        color=colours[s], label=f"{s} {m}: SAH cost / rebuild's", lw=1.6)
                ax.plot(r["time"], [x / y if y else None for x, y in zip(r["nodes"], base["nodes"])],
                        STYLE[m], color="C7", label=f"{s} {m}: nodes visited / rebuild's", lw=1.2)
        ax.axhline(1.0, color="k", lw=0.6)
        if max(y for line in ax.get_lines() for y in line.get_ydata() if y is not None) > 3:
            ax.set_yscale("log")
        ax.set_xlabel("animation time, s")
        ax.set_title(f"{scene}: refit quality against a rebuild of the same frame", fontsize=10)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7)
    fig.suptitle(f"Moving scenes, {a.size}x{a.size}, frames {a.frames}: per frame, per structure "
                 "(colour) and update mode (solid rebuild, dashed refit, dotted auto;\ncircles: "
                 "frames auto rebuilt); dash-dot: 10 frames per second", fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.98))
    fig.savefig(a.png, dpi=80)
    print(f"wrote {a.png}", file=sys.stderr)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vgpu-rt", default=os.path.join(ROOT, "build", "host", "vgpu-rt"))
    ap.add_argument("--scenes", default="hop,scatter")
    ap.add_argument("--structures", default="grid,bvh,kdtree",
                    help="comma-separated --accel values, e.g. grid,grid2,bvh,kdtree")
    ap.add_argument("--refit", default="bvh", help="structures that also run refit and auto")
    ap.add_argument("--kernels", default="multipass,looping")
    ap.add_argument("--frames", default="0:2:25")
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--probe-sizes", default="256,512",
                    help="sizes of the one-frame probes ('' for none)")
    ap.add_argument("--probe-time", default="1")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--runs", default=os.path.join(ROOT, "build", "animation_runs"))
    ap.add_argument("--reuse", action="store_true")
    ap.add_argument("--doc", default=os.path.join(ROOT, "docs", "studies", "animation.md"))
    ap.add_argument("--png", default=os.path.join(ROOT, "docs", "studies", "animation.png"))
    a = ap.parse_args()
    a.scenes = a.scenes.split(",")
    a.structures = a.structures.split(",")
    a.refit = [s for s in a.refit.split(",") if s in a.structures]
    a.kernels = a.kernels.split(",")
    os.makedirs(a.runs, exist_ok=True)
    runs, probes = {}, {}
    for scene in a.scenes:
        for s in a.structures:
            for m in ["rebuild"] + (["refit", "auto"] if s in a.refit else []):
                for v in a.kernels:
                    runs[(scene, s, m, v)] = series(run(a, scene, s, m, v))
        for size in [int(x) for x in a.probe_sizes.split(",") if x]:
            for s in a.structures:
                for v in a.kernels:
                    probes[(scene, size, s, v)] = run(a, scene, s, "rebuild", v, a.probe_time, size)
    text = tables(a, runs, probes)
    if a.png:
        chart(a, runs)
    if a.doc == "-":
        print(text)
        return
    doc = open(a.doc).read()
    if BEGIN not in doc or END not in doc:
        sys.exit(f"{a.doc}: no '{BEGIN}' ... '{END}' block to replace")
    head, rest = doc.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    open(a.doc, "w").write(head + BEGIN + "\n" + text + "\n" + END + tail)
    print(f"wrote {a.doc}", file=sys.stderr)


if __name__ == "__main__":
    main()
