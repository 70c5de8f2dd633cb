"""Frames measured on an H200 through the GL device (bench_gl JSON from
scripts/h200/streams_sampling.sh) beside the cost model's h200 prediction from the emulator's
statistics of the same frame: the tables of docs/studies/materials.md's and docs/studies/sampling.md's H200
sections (scripts/docs/materials.py --h200, scripts/docs/sampling.py --h200), and the marked section they
replace. Times are ms; "vs" columns are (predicted - measured) / measured.
"""
import csv
import datetime
import json
import os
import statistics

# The frame's settings that must agree between a GL frame and the emulator frame it is priced by.
KEYS = ("scene", "accel", "variant", "bounces", "size", "shadows", "ray_streams", "sampling")
# The ray streams' own kernels (host/trace/stream/ray_streams.h) and the sampling modes' (sampling.h).
STREAM_KERNELS = ["split rays", "stream scan", "stream count", "stream compaction", "row copy",
                  "children gather", "shadow through glass"]
SAMPLING_KERNELS = ["generate sample rays", "accumulate samples", "resolve samples", "keep hits",
                    "mark pixels", "marked pixels", "mark lattice", "mark gaps", "fill gaps"]


def frames(paths):
    """Each GL frame (polled read-backs) of the files with its emulator twin's prediction: a dict
    with the frame's settings, passes, read-backs, wall and GPU ms (medians), the predicted ms,
    and per kernel (passes, GPU ms, predicted ms)."""
    out = []
    for path in paths:
        doc = json.load(open(path))
        fs = doc["frames"]
        for g in fs:
            if g["engine"] != "gl-poll":
                continue
            em = next(e for e in fs if e["engine"] == "stream" and all(e[k] == g[k] for k in KEYS))
            pred = {k["name"]: k for k in em["kernels"]}
            out.append({**{k: g[k] for k in KEYS}, "streams_ran": g["streams_ran"],
                        "renderer": doc.get("renderer", ""),
                        "gl_version": doc.get("gl_version", ""),
                        "runs": g["runs"], "passes": g["passes"],
                        "warmup_frames": g.get("warmup_frames", 0),
                        "warmup_ms": g.get("warmup_ms", 0),
                        "timed": (g.get("timed_from_s"), g.get("timed_to_s")),
                        "readbacks": g["query_readbacks"], "rays": g["rays_traced"],
                        "wall_ms": g["wall_ms"], "gpu_ms": g["gpu_ms"],
                        "predicted_ms": em["predicted_ms"]["h200"],
                        "kernels": {k["name"]: (k["passes"], k["gpu_ms"],
                                                pred[k["name"]]["predicted_h200_ms"])
                                    for k in g["kernels"]}})
    return out


def fmt(v):
    return f"{v:,.1f}" if v < 100 else f"{v:,.0f}"


def vs(pred, meas):
    return f"{100 * (pred - meas) / meas:+.0f}%" if meas > 0 else "-"


def frame_table(rows, label_cols):
    """label_cols: [(header, function of a row)] naming each frame."""
    L = ["| " + " | ".join(h for h, _ in label_cols) + " | passes | read-backs | H200 wall ms | "
         "GPU ms | predicted ms | predicted vs wall |",
         "|" + "---|" * len(label_cols) + "---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        L.append("| " + " | ".join(str(f(r)) for _, f in label_cols) +
                 f" | {r['passes']:,} | {r['readbacks']:,} | {fmt(r['wall_ms'])} | "
                 f"{fmt(r['gpu_ms'])} | {fmt(r['predicted_ms'])} | "
                 f"{vs(r['predicted_ms'], r['wall_ms'])} |")
    return L


def kernel_sums(r, names):
    """Passes, GPU ms and predicted ms of the frame's kernels named in names."""
    ks = [r["kernels"][n] for n in names if n in r["kernels"]]
    return sum(k[0] for k in ks), sum(k[1] for k in ks), sum(k[2] for k in ks)


def kernel_sum_table(rows, names):
    """Per frame, the named kernels summed: passes, GPU ms, the model's ms, and their share of
    the frame's GPU time."""
    L = ["| frame | passes | GPU ms | predicted ms | predicted vs GPU | share of the frame's "
         "GPU ms |", "|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        p, g, m = kernel_sums(r, names)
        L.append(f"| {r['_label']} | {p:,} | {g:.2f} | {m:.2f} | {vs(m, g)} | "
                 f"{100 * g / r['gpu_ms']:.1f}% |")
    return L


def kernel_table(rows, label, names):
    """Per frame, each of the named kernels it ran: passes, GPU ms (timer queries, medians),
    the model's ms and per pass in us."""
    L = [f"| {label} | kernel | passes | GPU ms | predicted ms | GPU us / pass | "
         "predicted us / pass | predicted vs GPU |",
         "|---|---|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        for n in names:
            if n not in r["kernels"] or r["kernels"][n][0] == 0:
                continue
            p, g, m = r["kernels"][n]
            L.append(f"| {r['_label']} | {n} | {p:,} | {g:.2f} | {m:.2f} | {1e3 * g / p:.1f} | "
                     f"{1e3 * m / p:.1f} | {vs(m, g)} |")
    return L


def sm_clock(path):
    """Median SM clock (MHz) and GPU utilization samples while the GPU was busy, from the
    nvidia-smi log; None if there is none."""
    if not path or not os.path.exists(path):
        return None
    busy = []
    with open(path) as f:
        for row in csv.DictReader(f, skipinitialspace=True):
            sm = row.get("clocks.current.sm [MHz]") or row.get("clocks.sm [MHz]")
            util = row.get("utilization.gpu [%]")
            if sm and util and int(util.split()[0]) > 0:
                busy.append(int(sm.split()[0]))
    return (statistics.median(busy), min(busy), max(busy), len(busy)) if busy else None


def clock_samples(path, t0, t1):
    """The SM clock samples (MHz) of the nvidia-smi log stamped from t0 to t1 (seconds since the
    Unix epoch; the log's stamps are the GPU host's local time, UTC there)."""
    if not path or not os.path.exists(path) or t0 is None or t1 is None:
        return []
    got = []
    with open(path) as f:
        for row in csv.DictReader(f, skipinitialspace=True):
            sm = row.get("clocks.current.sm [MHz]") or row.get("clocks.sm [MHz]")
            stamp = row.get("timestamp")
            if not sm or not stamp:
                continue
            t = datetime.datetime.strptime(stamp.strip(), "%Y/%m/%d %H:%M:%S.%f")
            t = t.replace(tzinfo=datetime.timezone.utc).timestamp()
            if t0 <= t <= t1:
                got.append(int(sm.split()[0]))
    return got


def replace_section(path, begin, end, text):
    """Puts text between the begin and end markers of the file (at its end, markers and all,
    where they are not there yet)."""
    doc = open(path).read()
    if begin in doc and end in doc:
        a, b = doc.index(begin) + len(begin), doc.index(end)
        doc = doc[:a] + "\n" + text + "\n" + doc[b:]
    else:
        doc = doc.rstrip("\n") + "\n\n" + begin + "\n" + text + "\n" + end + "\n"
    with open(path, "w") as f:
        f.write(doc)


def section(path, begin, end):
    """The marked section of the file, markers included, or "" where it has none."""
    if not os.path.exists(path):
        return ""
    doc = open(path).read()
    if begin in doc and end in doc:
        return doc[doc.index(begin):doc.index(end) + len(end)]
    return ""
