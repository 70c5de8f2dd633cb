"""The H200 trials of docs/studies/structures.md's looping frames, for scripts/docs/structures.py: a second
warmed run beside the first, the traversal kernels' GPU time against their modeled work, the
texture-layout trial, the kernels as the driver compiled them and the GLSL without `precise`.
Each function returns the Markdown it adds (empty where its files were not given)."""
import json
import os
import statistics
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def fmt_ms(v):
    return f"{v:,.1f}" if v < 100 else f"{v:,.0f}"


def traversal_ratios(files):
    """Per structure, the looping traversal kernel's GPU time (timer queries) over its modeled
    work (predicted_h200_work_ms, the pass's fetches and instructions without its fixed costs),
    one ratio per scene, with the longest lanes' latency the model adds to it."""
    out = {}
    for f in files:
        frames = json.load(open(f))["frames"]
        for g in frames:
            if g["engine"] != "gl-poll" or g["variant"] != "looping":
                continue
            em = next(e for e in frames if e["engine"] == "stream" and
                      all(e[k] == g[k] for k in ("scene", "accel", "variant", "bounces", "size")))
            for k in g["kernels"]:
                if "looping traversal" not in k["name"]:
                    continue
                m = next(e for e in em["kernels"] if e["name"] == k["name"])
                out.setdefault(g["accel"], []).append(
                    (g["scene"], k["gpu_ms"], m["predicted_h200_work_ms"], k["passes"],
                     m.get("predicted_h200_latency_ms", 0.0)))
    return out


def layout_trial(files):
    """The structures' textures laid out square instead of one long row: the H200's GPU time of
    the same frames, old layout against new."""
    if not files:
        return ""
    square, multi_wide, multi_square, wide = files

    def frames(f):
        return {(g["scene"], g["accel"]): g for g in json.load(open(f))["frames"]
                if g["engine"] == "gl-poll"}

    def traversal(g):
        return next(k["gpu_ms"] for k in g["kernels"] if "looping traversal" in k["name"])
    sq, wd = frames(square), frames(wide)
    loop = [traversal(sq[k]) / traversal(wd[k]) - 1 for k in sq if k in wd]
    walls = [sq[k]["wall_ms"] / wd[k]["wall_ms"] - 1 for k in sq if k in wd]
    mw, ms = frames(multi_wide), frames(multi_square)
    multi = [ms[k]["gpu_ms"] / mw[k]["gpu_ms"] - 1 for k in ms if k in mw]
    cells = [(sq[k], next(e for e in json.load(open(square))["frames"] if e["engine"] == "stream"
                          and (e["scene"], e["accel"]) == k)["predicted_ms"]["h200"]) for k in sq]
    out = [(g, p) for g, p in cells if abs(p / g["wall_ms"] - 1) > 0.35]
    return ("\n\nTried: the structures' textures laid out square. Every structure's entry "
            "texture (nodes, cells, sub-cells, lists) was one row as long as the profile allows "
            "(the bunny's two-level grid: 96,334 sub-cells in a 32768 x 3 texture), which a "
            "texture cache that keeps 2D tiles might serve badly. Laid out in the smallest "
            "power-of-two width whose square holds them instead (`host/trace/passes.cpp`, "
            "`entry_texture`; the kernels read the width from a uniform, so images and counts "
            "are unchanged, and so are the predictions), the same looping frames "
            "(`results/structures/structures_h200_looping_square.json`) show each "
            f"traversal kernel's GPU time within {100 * max(abs(x) for x in loop):.1f}% of the "
            f"wide layout's, and {len(multi)} multipass frames measured with both layouts in one "
            f"run within {100 * max(abs(x) for x in multi):.2f}%: the layout is not the grid2 "
            "shortfall. The square layout is kept: it changes nothing on the H200, and a GL "
            "driver whose textures stop at 16384 texels (llvmpipe) can now run the two-level "
            "grid of the bunny, whose 32768-wide sub-cell texture it refused. The wall times of "
            f"the square layout's run moved by {100 * min(walls):+.0f}% to {100 * max(walls):+.0f}% "
            "against the wide layout's, with the GPU time unchanged; " + str(len(out)) + " of its "
            f"{len(cells)} looping cells are outside 35% ("
            + ", ".join(f"{g['scene']} / {g['accel']} {100 * (p / g['wall_ms'] - 1):+.0f}%"
                        for g, p in out) + ").")


def compiled_bodies(a):
    """The looping traversal kernels as NVIDIA's driver compiled them (bench_gl
    --dump-programs): each loop body's assembly lines, divisions, fetches and IF blocks, beside
    the scalar operations the vgpu counts for one iteration (loop_body_instructions)."""
    if not a.h200_programs:
        return ""
    L = ["", "", "The same kernels as the H200's driver compiled them (`bench_gl --dump-programs`, "
         "the program binary's NV_gpu_program5 assembly, in `results/structures/h200_programs/`; the "
         "bunny's frames), one loop iteration: the driver turns each of the GLSL's selects "
         "into an IF / ELSE block, and each division into a DIV.", "",
         "| structure | assembly lines | DIV | TXF (fetches) | IF blocks | vgpu's scalar "
         "operations | lines / operation | traversal GPU / modeled work (second run) |",
         "|---|---:|---:|---:|---:|---:|---:|---|"]
    seen = {}
    with tempfile.TemporaryDirectory() as tmp:
        for acc in ("grid", "grid2", "bvh", "kdtree"):
            path = os.path.join(a.h200_programs, f"{acc}_looping_traversal.nvfp")
            if not os.path.exists(path):
                continue
            asm = open(path).read().split("\n")
            body = asm[next(i for i, x in enumerate(asm) if x.startswith("REP")):
                       next(i for i, x in enumerate(asm) if x.startswith("ENDREP")) + 1]
            js = os.path.join(tmp, acc + ".json")
            st = a.run(a.vgpu_rt, os.path.join(ROOT, "scenes", "bunny.gltf"),
                     ["--accel", acc, "--kernels", "looping", "--profile", "h200",
                      "--bounces", "0", "--shadows", "off", "--size", "64x64"], js)
            ops = next(k["loop_body_instructions"] for k in st["kernels"]
                       if "looping traversal" in k["name"])
            count = lambda op: sum(x.startswith(op) for x in body)  # noqa: E731
            ratios = sorted(g / m for _, g, m, _, _ in a.kernel_ratios.get(acc, []))
            span = f"{ratios[0]:.2f}-{ratios[-1]:.2f}x" if ratios else "-"
            seen[acc] = (len(body) / ops, count("DIV"))
            L.append(f"| {acc} | {len(body)} | {count('DIV')} | {count('TXF')} | {count('IF')} | "
                     f"{ops} | {len(body) / ops:.2f} | {span} |")
    if "grid2" in seen and "bvh" in seen:
        shortest = min(seen, key=lambda k: seen[k][0])
        L += ["", f"Per scalar operation the vgpu counts, grid2's compiled body is "
              f"{seen['grid2'][0]:.2f} assembly lines against {min(v[0] for v in seen.values()):.2f}-"
              f"{max(v[0] for v in seen.values()):.2f} over the four (shortest: {shortest}), and "
              f"its {seen['grid2'][1]} divisions against the BVH's {seen['bvh'][1]} are a few "
              "percent of its lines: its code, as compiled, does not explain its GPU time either."]
    return "\n".join(L)


def precise_trial(files):
    """The looping traversal kernels' GPU time with and without the GLSL's precise qualifiers."""
    if not files:
        return ""

    def traversal(f):
        return {(g["scene"], g["accel"]): next(k["gpu_ms"] for k in g["kernels"]
                                               if "looping traversal" in k["name"])
                for g in json.load(open(f))["frames"] if g["engine"] == "gl-poll"}
    on, off = traversal(files[0]), traversal(files[1])
    by = {}
    for k in on:
        by.setdefault(k[1], []).append(off[k] / on[k] - 1)
    return ("\n\nTried: the GLSL without `precise`. The generated shaders mark every "
            "arithmetic statement `precise` (no fused or reordered operations, so that the GL "
            "device gives the emulator's bits). The same looping frames (bunny, bunny-refl, "
            "classic, scales; `results/structures/structures_h200_precise_{on,off}.json`, one run, an "
            "experiment binary without the qualifier) change each traversal kernel's GPU time "
            "by " + ", ".join(f"{acc} {100 * min(v):+.0f} to {100 * max(v):+.0f}%"
                              for acc, v in sorted(by.items())) +
            ": exact arithmetic, divisions included, costs the H200 little, and grid2 no more "
            "than the others.")


def quartiles(v):
    v = sorted(v)
    return v[len(v) // 4], v[(3 * len(v)) // 4]


def looping_second(a):
    """The second warmed run of the looping frames (15 frames each) beside the first, and the
    traversal kernels' GPU time against their modeled work."""
    pairs = a.looping_again
    if not pairs:
        return ""
    within = sum(abs(w["predicted_ms"] / w["wall_ms"] - 1) <= 0.35 for _, w in pairs)
    first_within = sum(abs(r["predicted_ms"] / r["wall_ms"] - 1) <= 0.35 for r, _ in pairs)
    runs = len(pairs[0][1]["wall_runs_ms"])
    mv = max(pairs, key=lambda p: abs(p[1]["wall_ms"] / p[0]["wall_ms"] - 1))
    L = ["", "", f"A second warmed run (`LOOPING=1 RUNS={runs} scripts/h200/structures.sh`, "
         "`results/structures/structures_h200_looping_warm2.json`) timed "
         f"{runs} frames of each configuration instead of 5, and keeps every frame's time: within "
         "a configuration the frames agree closely (the quartiles below), but between the two "
         f"runs the same frame moved by up to {100 * abs(mv[1]['wall_ms'] / mv[0]['wall_ms'] - 1):.0f}% "
         f"({mv[1]['scene']} / {mv[1]['accel']}: wall {mv[0]['wall_ms']:.2f} to "
         f"{mv[1]['wall_ms']:.2f} ms, GPU {mv[0]['gpu_ms']:.2f} to {mv[1]['gpu_ms']:.2f} ms: the "
         "move is outside the GPU's timer queries, on the host). "
         f"{within} of its {len(pairs)} looping cells are within 35% (the first "
         f"warmed run: {first_within}).", "",
         "| scene | structure | first warmed wall ms | vs | second: wall ms | quartiles | GPU ms | "
         "predicted ms | vs |", "|---|---|---:|---:|---:|---|---:|---:|---:|"]
    for r, w in pairs:
        q1, q3 = quartiles(w["wall_runs_ms"])
        L.append(f"| {w['scene']} | {w['accel']} | {fmt_ms(r['wall_ms'])} | "
                 f"{100 * (r['predicted_ms'] / r['wall_ms'] - 1):+.0f}% | "
                 f"{fmt_ms(w['wall_ms'])} | {q1:.2f}-{q3:.2f} | {fmt_ms(w['gpu_ms'])} | "
                 f"{fmt_ms(w['predicted_ms'])} | "
                 f"{100 * (w['predicted_ms'] / w['wall_ms'] - 1):+.0f}% |")
    if a.kernel_ratios:
        L += ["", "Where the two-level grid's shortfall sits: each structure's looping traversal "
              "kernel alone, its GPU time (timer queries) over the work the model prices for it "
              "(the pass's fetches, instructions and idle lanes, without the pass's fixed costs), "
              "over the seven scenes of the second run:", "",
              "| structure | GPU / modeled work, lowest | median | highest | scene of the highest |",
              "|---|---:|---:|---:|---|"]
        for acc in ("grid", "grid2", "bvh", "kdtree"):
            v = a.kernel_ratios.get(acc)
            if not v:
                continue
            rs = sorted((g / m, sc) for sc, g, m, _, _ in v)
            L.append(f"| {acc} | {rs[0][0]:.2f} | {statistics.median(x for x, _ in rs):.2f} | "
                     f"{rs[-1][0]:.2f} | {rs[-1][1]} |")
    return "\n".join(L)


def slower_sentence(pairs):
    """Which looping frames came out slower warmed up than in the first runs: their spread."""
    up = [(w["wall_ms"] / r["wall_ms"] - 1, w) for r, w in pairs if w["wall_ms"] > r["wall_ms"]]
    if not up:
        return ""
    most = max(e for e, _ in up)
    return ("Frames of a few ms are noisy: warmed up, where most got faster, " +
            ", ".join(f"{w['scene']}'s {w['accel']}" for _, w in up) +
            f" came out up to {100 * most:.0f}% slower than in the first runs (the table above). ")


def grid2_again(a):
    """The second warmed run's grid2 cells and the traversal kernels' ratios, for Left out."""
    g = [w for _, w in a.looping_again if w["accel"] == "grid2"]
    if not g:
        return ""
    out = [w for w in g if abs(w["predicted_ms"] / w["wall_ms"] - 1) > 0.35]
    text = (f" In the second warmed run (15 frames each) {len(out)} of {len(g)} are outside 35% ("
            + (", ".join(f"{w['scene']} {100 * (w['predicted_ms'] / w['wall_ms'] - 1):+.0f}%"
                         for w in out) or "none") + ").")
    kr = a.kernel_ratios
    pp = sorted(gm * 1000 / n for _, gm, _, n, _ in kr.get("grid2", []))
    per_pass = f"{pp[0]:.0f}-{pp[-1]:.0f} us on the GPU" if pp else "longer"
    if kr.get("grid2") and kr.get("bvh"):
        r2 = sorted(gm / m for _, gm, m, _, _ in kr["grid2"])
        rb = sorted(gm / m for _, gm, m, _, _ in kr["bvh"])
        rk = sorted(gm / m for _, gm, m, _, _ in kr.get("kdtree", []))
        r2l = sorted(gm / (m + sp) for _, gm, m, _, sp in kr["grid2"])
        text += (f" Its traversal kernel alone takes {r2[0]:.2f}-{r2[-1]:.2f}x the GPU time the "
                 f"model priced for its pass work before the latency term, where the BVH's took "
                 f"{rb[0]:.2f}-{rb[-1]:.2f}x"
                 + (f" and the kd-tree's {rk[0]:.2f}-{rk[-1]:.2f}x" if rk else "") +
                 f", with passes of {per_pass}. An earlier version of this page ruled out the "
                 "longest lane's latency by counting only the body's fetches (9 of them at 300 "
                 "clocks: 45 us a pass). Counted with the dependent arithmetic between them and "
                 "priced at latencies measured on the H200, the longest lanes come to a tenth "
                 "to a third of a looping frame, and the term that adds them (\"The looping "
                 "passes' longest lane\", above) puts every looping cell of a fresh run within "
                 "35%. The trials above stand as measured: the step's arithmetic waits on its "
                 "fetches, which is what the term prices for one lane. What remains is grid2's "
                 f"own: with the term its kernel still takes {r2l[0]:.2f}-{r2l[-1]:.2f}x what "
                 "the model prices, because its iteration waits longer than the in-order count "
                 "says (the 8x8 frames, above), and on scales its textures total 58 MB, more "
                 "than the H200's 50 MB L2 (the other structures' 24-29 MB).")
    return text


def ablation_trial(files):
    """grid2's looping traversal with half its body taken out (experiment binaries: the step
    alone, no triangle test; the triangle test alone, no step), each kernel's GPU time against
    the work the model prices for it, and the frame's modeled arithmetic and texture demand."""
    if not files:
        return ""
    L = ["", "", "Tried: grid2's loop body in halves. Two experiment binaries (not kept; their "
         "images are wrong) ran the same looping frames with the triangle test taken out of the "
         "loop (the step alone: the nested DDA, climbing to the coarse cell and descending into "
         "the next) and with the step taken out (the triangle test alone: rays stay in their "
         "sub-cell until the pass cap), `results/structures/structures_h200_grid2_ablation_{full,step,test}"
         ".json`, one run:", "",
         "| body | scene | passes | traversal GPU ms | modeled work ms | GPU / modeled | frame's "
         "modeled arithmetic / texture demand ms |", "|---|---|---:|---:|---:|---:|---|"]
    ratio = {}
    for label, f in zip(("whole", "step alone", "triangle test alone"), files):
        frames = json.load(open(f))["frames"]
        for g in frames:
            if g["engine"] != "gl-poll":
                continue
            e = next(x for x in frames if x["engine"] == "stream" and x["scene"] == g["scene"])
            k = next(x for x in g["kernels"] if "looping traversal" in x["name"])
            m = next(x for x in e["kernels"] if "looping traversal" in x["name"])
            p = e["predicted_h200"]
            r = k["gpu_ms"] / m["predicted_h200_work_ms"]
            ratio.setdefault(label, []).append(r)
            L.append(f"| {label} | {g['scene']} | {k['passes']:,} | {fmt_ms(k['gpu_ms'])} | "
                     f"{fmt_ms(m['predicted_h200_work_ms'])} | {r:.2f} | "
                     f"{fmt_ms(p['arithmetic_demand_ms'])} / {fmt_ms(p['texture_demand_ms'])} |")
    st, te = ratio.get("step alone", []), ratio.get("triangle test alone", [])
    if st and te:
        L += ["", f"The shortfall is the step's: alone it runs {min(st):.2f}-{max(st):.2f}x its "
              f"modeled work, where the triangle test alone runs {min(te):.2f}-{max(te):.2f}x. "
              "The model takes a pass's work as the largest of its arithmetic, texture and "
              "memory demands, as if they overlapped fully. The step's arithmetic computes the "
              "next fetch's address from the last fetch's texel (coarse cell, sub-grid, list), "
              "so its arithmetic and its fetches follow one another, and on these frames its "
              "GPU time comes near the sum of the two demands. A triangle test's fetches and "
              "arithmetic overlap, and it comes in under the texture demand alone. A model term "
              "for how much of a body's arithmetic waits on its own fetches is what the "
              "two-level grid needs: built since (\"The fetch wait\", below)."]
    return "\n".join(L)


def looping_8x8(a, files):
    """Per structure, from the H200's looping frames at 8x8 (two warps: a frame of longest lanes)
    and the emulator's run of each: the traversal body's chain as the vgpu counts it
    (vgpu/span.h: fetches and operation units of one iteration), and the GPU ns of one of its
    iterations, the traversal kernel's GPU time over its loop_span_iterations, least squares
    through zero over the scenes but scales."""
    chain, runs = {}, {}
    with tempfile.TemporaryDirectory() as tmp:
        for f in files:
            for g in json.load(open(f))["frames"]:
                if (g["engine"] != "gl-poll" or g["variant"] != "looping" or g["size"] != 8
                        or g["scene"] == "scales"):
                    continue
                scene = os.path.join(ROOT, "scenes", g["scene"] + ".gltf")
                if not os.path.exists(scene):
                    scene = os.path.join(ROOT, ".h200", g["scene"] + ".gltf")
                if not os.path.exists(scene):
                    continue
                st = a.run(a.vgpu_rt, scene,
                           ["--accel", g["accel"], "--kernels", "looping", "--profile", "h200",
                            "--bounces", "0", "--shadows", "off", "--size", "8x8"],
                           os.path.join(tmp, "s.json"))
                k = next(k for k in st["kernels"] if "looping traversal" in k["name"])
                it = k["loop_span_iterations"]
                chain[g["accel"]] = (k["loop_span_fetches"] // it, k["loop_span_operations"] // it)
                gpu = next(k for k in g["kernels"] if "looping traversal" in k["name"])["gpu_ms"]
                runs.setdefault(g["accel"], []).append((it, gpu))
    per = {acc: sum(i * g for i, g in v) / sum(i * i for i, _ in v) * 1e6
           for acc, v in runs.items()}
    order = [acc for acc in ("grid", "grid2", "bvh", "kdtree") if acc in chain]
    return {acc: chain[acc] for acc in order}, per


def latency_term(a):
    """The looping passes' longest lane: the latency probes, each structure's chain against its
    8x8 frames, the traversal kernels with and without the term, and a run measured after it."""
    if not a.h200_latency:
        return ""
    probes = json.load(open(a.h200_latency))["latency"]
    alu = next(p for p in probes if p["chain_fetches"] == 0)
    op_clk = alu["clocks_per_iteration_at_boost"] / alu["chain_operations"]
    far = max((p for p in probes if p["chain_fetches"] == 1), key=lambda p: p["texels"])
    mid = [p for p in probes if p["chain_fetches"] == 1 and 256 < p["texels"] < far["texels"]]
    fetch_clk = far["clocks_per_iteration_at_boost"] - far["chain_operations"] * op_clk
    mhz = 1e3 * far["clocks_per_iteration_at_boost"] / far["ns_per_iteration"]  # the probes' clock
    L = ["", "", "### The looping passes' longest lane: the latency term", "",
         "The model took a pass as long as the largest of its arithmetic, texture and memory "
         "demands: the work spread over every pipeline. That is a lower bound, and so is the "
         "pass's longest lane, which cannot finish before its own iterations have waited for "
         "their fetches and their dependent arithmetic one after another. A greedy scheduler "
         "finishes within the sum of the two (Brent 1974, the work-span bound). On the GH100 "
         "only 4 SMs run pixel shaders, and a 256x256 frame is 2048 warps for them, so the last "
         "warps of a pass run nearly alone and the span shows. The model now adds it: per "
         "looping pass, the most iterations one fragment ran (`loop_span_iterations`) times the "
         "body's longest chain of dependent operations, found in the recorded program "
         "(`vgpu/span.h`: one iteration issued in order, one operation unit each, a fetched "
         "texel ready a fetch latency after its fetch issued), priced at two latencies the "
         "`h200` profile takes from the H200 itself. `bench_gl --latency` "
         "(`results/structures/structures_h200_latency.json`) runs one fragment through 1,024 and 8,192 "
         "iterations of a chain and divides the difference:", "",
         "| probe | texture | ns an iteration | clocks at 1980 MHz | the model's chain: fetches, "
         "operation units |", "|---|---|---:|---:|---|"]
    for p in probes:
        side = int(round(p["texels"] ** 0.5))
        tex = (f"{side}x{side} RGBA32F ({p['bytes'] / 1024:,.0f} KB)" if p["chain_fetches"]
               else "-")
        L.append(f"| {p['what']} | {tex} | {p['ns_per_iteration']:.1f} | "
                 f"{p['clocks_per_iteration_at_boost']:.0f} | {p['chain_fetches']}, "
                 f"{p['chain_operations']} |")
    side = int(round(far["texels"] ** 0.5))
    L += ["", f"So an operation unit is {op_clk:.2f} clocks and a fetch from the {side}x{side} "
          f"texture {fetch_clk:.0f}"
          + (f" (from the {int(round(mid[0]['texels'] ** 0.5))}x"
             f"{int(round(mid[0]['texels'] ** 0.5))} one, which fits the L2, within "
             f"{100 * abs(mid[0]['ns_per_iteration'] / far['ns_per_iteration'] - 1):.0f}%)"
             if mid else "") +
          ": the `h200` profile's `operation_latency_clocks` and `fetch_latency_clocks`. The "
          "structures' textures are MBs; where a texture stays in the first-level cache a fetch "
          "takes under half as long, which the model does not price. Both are per lane, whatever "
          "the lanes beside it do. Only the `h200` profile has them: the 2004 cards' latencies "
          "were not measured, and their predictions are unchanged."]
    ch, per = looping_8x8(a, a.h200_sizes + a.h200_sizes_grid)
    if ch:
        L += ["", "Each looping walk's iteration as the model counts it, priced, against the H200's "
              "8x8 frames (`SIZES=1 scripts/h200/structures.sh`; two warps, so the traversal "
              "kernel's GPU time is its longest lanes: GPU ms over the emulator's "
              "`loop_span_iterations` of the same frame, least squares through zero over the "
              "six scenes but scales, whose first frames also fetch 58 MB of textures cold):", "",
              "| structure | fetches, operation units | model clocks an iteration | measured at "
              "8x8 | model / measured |", "|---|---|---:|---:|---:|"]
        for acc, (f, o) in ch.items():
            model = f * fetch_clk + o * op_clk
            m = per.get(acc)
            L.append(f"| {acc} | {f}, {o} | {model:,.0f} | "
                     + (f"{m * mhz / 1000:,.0f} | {model / (m * mhz / 1000):.2f} |" if m else
                        "- | - |"))
        if per.get("grid2") and per.get("grid"):
            L += ["", f"The count misses part of grid2's iteration: measured, it waits "
                  f"{per['grid2'] / per['grid']:.1f} times as long as the grid's; counted, "
                  f"{(ch['grid2'][0] * fetch_clk + ch['grid2'][1] * op_clk) / (ch['grid'][0] * fetch_clk + ch['grid'][1] * op_clk):.1f} "
                  "times. The driver's code for it has 29 divisions and 109 IF/ELSE blocks "
                  "against the grid's 9 and 64 (above); an in-order count of the recorded "
                  "operations prices neither a division's nor a branch's own latency."]
    if a.kernel_ratios:
        L += ["", "Each looping traversal kernel's GPU time over what the model prices for it, "
              "before (the pass work alone) and with the longest lanes (the second warmed run):",
              "", "| structure | GPU / work | GPU / (work + longest lanes) |", "|---|---|---|"]
        for acc in ("grid", "grid2", "bvh", "kdtree"):
            v = a.kernel_ratios.get(acc, [])
            if not v:
                continue
            r0 = sorted(g / m for _, g, m, _, _ in v)
            r1 = sorted(g / (m + s) for _, g, m, _, s in v)
            L.append(f"| {acc} | {r0[0]:.2f}-{r0[-1]:.2f} | {r1[0]:.2f}-{r1[-1]:.2f} |")
    third = a.looping_third
    if third:
        within = sum(abs(w["predicted_ms"] / w["wall_ms"] - 1) <= 0.35 for w in third)
        e = [100 * (w["predicted_ms"] / w["wall_ms"] - 1) for w in third]
        L += ["", "Every H200 table in the docs prices its frames with the term (the stored "
              "runs' predictions were brought up to date, their measurements untouched: "
              "`results/structures/README.md`). The 28 looping frames measured again with the "
              "binary that carries the term (`results/structures/structures_h200_looping_warm3.json`, "
              "2 s of warm-up, 5 frames each, predicted before they ran): "
              f"{within} of {len(third)} cells within 35%, from {min(e):+.0f}% to "
              f"{max(e):+.0f}%:", "",
              "| scene | structure | wall ms | GPU ms | predicted ms | of it, longest lanes | "
              "vs |", "|---|---|---:|---:|---:|---:|---:|"]
        for w in third:
            L.append(f"| {w['scene']} | {w['accel']} | {fmt_ms(w['wall_ms'])} | "
                     f"{fmt_ms(w['gpu_ms'])} | {fmt_ms(w['predicted_ms'])} | "
                     f"{w['latency_ms']:.2f} | "
                     f"{100 * (w['predicted_ms'] / w['wall_ms'] - 1):+.0f}% |")
    return "\n".join(L)


def fetch_wait(a):
    """The fetch wait: a loop body's arithmetic between two of its fetches, the looping traversal
    kernels priced without and with it (results/structures/loop_kernels.json, written by
    scripts/docs/loop_kernels.py), and what was tried and not kept."""
    if not a.loop_kernels:
        return ""
    import loop_kernels
    rows = json.load(open(a.loop_kernels))["kernels"]
    structures = ("grid", "grid2", "bvh", "kdtree")

    def median(card, acc, f):
        v = [f(r) for r in rows if r["card"] == card and r["accel"] == acc]
        return statistics.median(v) if v else float("nan")
    share = {acc: statistics.median(r["share"] for r in rows if r["accel"] == acc)
             for acc in structures}
    before = {(c, acc): median(c, acc, lambda r: r["gpu"] / r["without"])
              for c in ("h100", "h200") for acc in structures}
    after = {(c, acc): median(c, acc, lambda r: r["gpu"] / r["with"])
             for c in ("h100", "h200") for acc in structures}
    others = max(abs(after[k] / before[k] - 1) for k in before if k[1] != "grid2")
    bvh = sorted(r["gpu"] / r["with"] for r in rows if r["card"] == "h100" and r["accel"] == "bvh")
    pct = ", ".join(f"{100 * share[acc]:.0f}% of the {name}"
                    for acc, name in (("grid", "grid's arithmetic"), ("grid2", "two-level grid's"),
                                      ("bvh", "BVH's"), ("kdtree", "kd-tree's")))
    L = ["", "", "### The fetch wait: a loop body's arithmetic between two of its fetches", "",
         "The ablation above found the two-level grid's step running near the sum of its "
         "arithmetic and texture demands, where the model took the larger. The step computes "
         "each fetch's address from the texel the fetch before it returned (the coarse cell, then "
         "the sub-cell, then the list), so a lane cannot overlap that arithmetic with its own "
         "fetches. The recorded program says which operations do so "
         "(`vgpu::loop_dependent_operations`, `vgpu/span.h`): those of one iteration of the body "
         "that depend on a texel fetched in the same iteration and that a later fetch of it "
         "depends on. A fetch whose address passes through a select's value is left out of that: "
         "the driver turns each select into an IF/ELSE block (above), so such a fetch is made on "
         "one side only, and what feeds it through the select waits only on the iterations that "
         "take that side (the BVH's list entry, fetched when a walk enters a leaf, is one). It "
         "counts within one iteration: an address carried to the next (the BVH's next node, the "
         "vertices of the triangle a list entry named) is waited for across iterations, which "
         "the longest lanes price. Counted once per active iteration "
         "(`loop_dependent_instructions`), the operations between fetches are "
         f"{pct} (of each traversal kernel's arithmetic, nearly all of it its loop body's).", "",
         "The cost model adds that share of a looping pass's arithmetic time to the pass's "
         "bottleneck, at most the texture time it waits through (`fetch_wait_ms`), on the "
         "profiles whose latencies were measured (`h200`, `h100`; every other profile, the 2004 "
         "cards and `rtx4090`, is priced as before). Nothing was fitted: the share is counted and "
         "the arithmetic rate is the profile's. Each looping traversal kernel's GPU time over its price (pass work and "
         "longest lanes), on the H100's looping frames (256² to 1024², primary rays and full "
         "frames) and the H200's third warmed run (`scripts/docs/loop_kernels.py`, "
         "`results/structures/loop_kernels.json`):", "",
         loop_kernels.table(rows), "",
         f"The two-level grid comes from {before[('h100', 'grid2')]:.2f} to "
         f"{after[('h100', 'grid2')]:.2f} and {after[('h200', 'grid2')]:.2f} times its price "
         f"(medians, H100 and H200); the others' medians move by {100 * others:.0f}% at most. "
         "Over the cells (\"Every cell against its target\", `docs/studies/real_gpu.md`), when "
         "this was written, 94 of the H100's 116 looping cells were within 15% (87 before) and "
         "55 of the H200's 67 (51). What the BVH's walk is priced over (its GPU time "
         f"{bvh[0]:.2f} to {bvh[-1]:.2f} of its price on the H100) is not this term: its counted "
         "share is 4%, and it was priced as high before. Nor does the count reach what the "
         f"two-level grid is still priced under ({after[('h100', 'grid2')]:.2f} times its price "
         "at the median).", "",
         "Tried and not kept (experiments whose binaries were not kept: their figures are this "
         "page's record, not regenerated):", "",
         "- **All the arithmetic between fetches, selects or not.** Following a fetch's address "
         "back through selects' values too counts 19%, 70%, 59% and 44% of the four bodies (the "
         "BVH's box test, which feeds the leaf's list entry through the select that loads it). It "
         "brought the two-level grid to 1.08 (median) but the BVH to 0.72, and the cells to 92 of "
         "116 and 56 of 67, the BVH's misses up to +38%.",
         "- **Neighbours fetching the same texel.** An experiment binary counted, for each fetch "
         "of a loop body, whether the fragment before it in its row's group of 8 pixels had "
         "fetched the same texel at the same point of the same iteration: 42% to 87% of the loop "
         "bodies' bytes do (median 75%, the H100's 76 looping frames: the coherent walks of "
         "neighbouring primary rays), which a texture unit would serve once. Priced so, the rest "
         "at a rate fitted on the H100's 256² looping frames (46 bytes a clock), on top of the "
         "item above's fetch wait (selects followed), the 256² cells went from 25 to 28 of 36 "
         "within 15% and "
         "the larger frames (512² to 1024², and full frames) from 33 to 8 of 40: what is "
         "repeated does not explain what grows with the image. Not kept, nor counted.",
         "- **A free least-squares fit** of the traversal kernels' GPU time at 256² (1.32 x "
         "arithmetic + 2.13 x longest lanes + 0.99 x the idle lanes' bytes at the in-cache rate + "
         "0.26 x the loop's bytes) fits both cards at 256² (the H200's kernels, not fitted, take "
         "0.90 to 1.20 times it) and not the larger frames, which take a median 1.34 times it: at "
         "one size, arithmetic, bytes and longest lanes grow together and a fit cannot tell them "
         "apart."]
    return "\n".join(L)
