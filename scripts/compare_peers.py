#!/usr/bin/env python3
"""Compare qem with other simplifiers on the corpus, measured by the peers harness.

usage: scripts/compare_peers.py [--meshes NAME,...] [--ratios 0.5,0.1,0.01]
                                [--tools meshopt_rs,pymeshlab_qem_q,pyfqmr] [--repeat 1]
                                [--variant NAME='ARGS' ...] [--out BENCHMARKS.md]
       scripts/compare_peers.py --agreement NAME,...   # qem measure vs the harness's metric

Default meshes: the corpus's *clean scans* — rows of `manifest.tsv` whose `category`
starts with `scan-` and whose `duplicate_vertices`, `duplicate_faces`,
`degenerate_faces`, `nonmanifold_edges` and `nonmanifold_vertices` are all 0. The script
prints which meshes that is.

For each mesh it runs the harness (`shared/tools/peers/peers.py`) once with all ratios:
the peers, and qem through the harness's `--cmd` so that qem's output is measured by the
very same metric (samples, pymeshlab distances, flipped faces, boundary loops). It then
writes a table (mesh, ratio, tool, time, Hausdorff, mean error, flipped faces, boundary
loops) and the win counts for issue 5's goal into the output file between the markers
`<!-- compare-peers:start -->` and `<!-- compare-peers:end -->` (appended when absent).

Figures: Hausdorff = the harness's `hd_sym` (max of both directed maxima); mean error =
its `mean_sym` = (mean in→out + mean out→in) / 2; both in % of the input's bbox diagonal.
Time: peers = the simplification call alone (timed by the harness); qem = the whole
process including start-up and OBJ read/write (the harness cannot time inside a CLI),
with qem's own simplification time from its --report in brackets when available.

Peer cache: the peers' rows do not depend on qem, so every measured peer row is stored
as one JSON file in `--peer-cache DIR` (default `$PEERS_HOME/compare-peers-cache`),
keyed on the mesh (name + SHA-256 of the OBJ), the ratio, the tool and the harness's
options (SHA-256 of `peers.py`, `--repeat`, `--timeout`, `--slow-cap`). A mesh whose
peer rows are all cached runs the harness for qem alone; `--no-peer-cache` measures the
peers again. `--seed-peer-cache FILE` fills the cache from the table of a previous run in
FILE (a BENCHMARKS.md with the compare-peers block): those rows carry the table's
rounding (4 decimals of % diag) and are marked `from_table` in the cache.

`--boundary` (with `--meshes`, default: every corpus mesh whose manifest `boundary_edges`
> 0) runs qem alone at the first of `--ratios` with the defaults and with
`--lock-boundary` and writes the boundary loops (harness count, by index) of the file, of
qem's cleaned input (`--triangles 1000000000`, the reference: soups have one loop per
triangle in the file) and of both outputs between
`<!-- boundary-loops:start -->` and `<!-- boundary-loops:end -->`.

`--variant NAME='ARGS'` adds another qem row with extra `qem simplify` arguments (e.g.
`--variant qem_pb='--preserve-boundary'` once that option exists); variants are shown but
not counted as peers or as qem in the win counts.

When the harness (its venv python, `$PEERS_HOME/venv/bin/python`, default
~/.cache/qem-peers) is absent, the script says so, runs qem alone (time + `qem measure`
figures, no flipped faces) and exits 0.

`--agreement` simplifies each named mesh to 10% with qem, measures input vs output with
both `qem measure --json` and the harness, and writes a comparison table between
`<!-- measure-agreement:start -->` and `<!-- measure-agreement:end -->`.

Python 3 standard library only; the harness runs in its own venv.
Build first: `cargo build --profile dist -p qem-cli`.
"""
import argparse
import hashlib
import json
import os
import shlex
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
START, END = "<!-- compare-peers:start -->", "<!-- compare-peers:end -->"
AGREE_START, AGREE_END = "<!-- measure-agreement:start -->", "<!-- measure-agreement:end -->"
BOUNDARY_START, BOUNDARY_END = "<!-- boundary-loops:start -->", "<!-- boundary-loops:end -->"
CLEAN_ZERO_COLUMNS = ["duplicate_vertices", "duplicate_faces", "degenerate_faces",
                      "nonmanifold_edges", "nonmanifold_vertices"]


def read_manifest(corpus):
    with open(os.path.join(corpus, "manifest.tsv")) as f:
        lines = f.read().splitlines()
    header = lines[0].split("\t")
    rows = []
    for line in lines[1:]:
        if line.strip():
            rows.append(dict(zip(header, line.split("\t"))))
    return rows


def mesh_name(row):
    return os.path.splitext(os.path.basename(row["file"]))[0]


def clean_scans(rows):
    """Clean scans: category `scan-*` with no duplicate, degenerate or non-manifold defects."""
    return [r for r in rows
            if r["category"].startswith("scan-") and all(int(r[c]) == 0 for c in CLEAN_ZERO_COLUMNS)]


def harness_paths(args):
    peers = os.path.join(args.peers_dir, "peers.py")
    home = os.environ.get("PEERS_HOME", os.path.join(os.path.expanduser("~"), ".cache", "qem-peers"))
    py = args.peers_python or os.path.join(home, "venv", "bin", "python")
    if os.path.isfile(peers) and os.access(py, os.X_OK):
        return peers, py
    return None, None


def qem_has_report(qem):
    h = subprocess.run([qem, "simplify", "--help"], capture_output=True, text=True)
    return "--report" in h.stdout


def replace_between(path, start, end, body, heading):
    text = open(path).read() if os.path.exists(path) else "# Benchmarks\n"
    block = f"{start}\n{body.rstrip()}\n{end}"
    if start in text and end in text:
        head, rest = text.split(start, 1)
        _, tail = rest.split(end, 1)
        text = head + block + tail
    else:
        text = text.rstrip() + f"\n\n{heading}\n\n{block}\n"
    with open(path, "w") as f:
        f.write(text)


def pct(v, digits=4):
    return "-" if v is None else f"{v * 100:.{digits}f}"


def run_harness(py, peers, mesh_path, ratios, tools, cmds, args, out_dir):
    argv = [py, peers, mesh_path, "--ratio", ",".join(str(r) for r in ratios),
            "--tools", ",".join(tools) if tools else ",", "--repeat", str(args.repeat),
            "--timeout", str(args.timeout), "--slow-cap", str(args.slow_cap),
            "--no-save", "--out", out_dir]
    for name, template in cmds:
        argv += ["--cmd", f"{name}={template}"]
    cmd = ["nice", "-n", "5"] + argv
    print("$ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        print(p.stdout[-2000:], p.stderr[-2000:], sep="\n")
        raise RuntimeError(f"harness failed on {mesh_path}")
    name = os.path.splitext(os.path.basename(mesh_path))[0]
    jpath = os.path.join(out_dir, f"results_{name}_r{'-'.join(str(r) for r in ratios)}.json")
    with open(jpath) as f:
        return json.load(f)["results"]


def qem_template(qem, extra, report_dir, name, with_report):
    t = f"{shlex.quote(qem)} simplify {{in}} -o {{out}} --ratio {{ratio}}"
    if with_report:
        t += f" --report {shlex.quote(report_dir)}/{name}.{{ratio}}.json"
    return t + (" " + extra if extra else "")


def qem_call_ms(report_dir, tool, mesh, ratio):
    path = os.path.join(report_dir, f"{mesh}.{tool}.{ratio!r}.json")
    try:
        with open(path) as f:
            return json.load(f)["timings_ms"]["simplify"]
    except (OSError, KeyError, ValueError):
        return None


def sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


class PeerCache:
    """Peer rows on disk, one JSON file per (mesh content, ratio, tool, harness options)."""

    def __init__(self, directory, peers, args):
        self.dir = directory
        self.options = {"peers_py": sha256_file(peers), "repeat": args.repeat,
                        "timeout": args.timeout, "slow_cap": args.slow_cap}
        self.mesh_sha = {}

    def _path(self, mesh_path, ratio, tool):
        if mesh_path not in self.mesh_sha:
            self.mesh_sha[mesh_path] = sha256_file(mesh_path)
        key = json.dumps({"mesh": os.path.basename(mesh_path), "sha256": self.mesh_sha[mesh_path],
                          "ratio": float(ratio), "tool": tool, **self.options}, sort_keys=True)
        return os.path.join(self.dir, hashlib.sha256(key.encode()).hexdigest()[:32] + ".json")

    def get(self, mesh_path, ratio, tool):
        try:
            with open(self._path(mesh_path, ratio, tool)) as f:
                return json.load(f)
        except (OSError, ValueError):
            return None

    def put(self, mesh_path, ratio, tool, record):
        os.makedirs(self.dir, exist_ok=True)
        path = self._path(mesh_path, ratio, tool)
        with open(path + ".tmp", "w") as f:
            json.dump(record, f, indent=1, default=float)
        os.replace(path + ".tmp", path)


def seed_cache_from_table(cache, table_file, corpus, tools):
    """Peer rows of a previous compare-peers table -> cache (rounded as printed)."""
    text = open(table_file).read()
    if START not in text or END not in text:
        sys.exit(f"{table_file}: no {START} block to seed from")
    block = text.split(START, 1)[1].split(END, 1)[0]
    n = 0
    for line in block.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) != 9 or cells[2] not in tools or cells[3].startswith("FAILED"):
            continue
        mesh, ratio, tool, tris, ms, hd, mean, flipped, loops = cells
        try:
            rec = {"mesh": mesh, "ratio": float(ratio), "tool": tool, "status": "ok",
                   "tris_out": int(tris), "t_call": float(ms.replace(",", "")) / 1e3,
                   "hd_sym": float(hd) / 100, "mean_sym": float(mean) / 100,
                   "flipped_pct": None if flipped == "-" else float(flipped),
                   "from_table": os.path.abspath(table_file)}
        except ValueError:
            continue
        if loops != "-":
            io, _, verdict = loops.partition(" ")
            a, b = io.split("→")
            rec.update(boundary_loops_in=int(a), boundary_loops_out=int(b),
                       boundary_survived={"ok": True, "LOST": False}.get(verdict))
        path = os.path.join(corpus, mesh + ".obj")
        if os.path.isfile(path):
            cache.put(path, rec["ratio"], tool, rec)
            n += 1
    print(f"[compare] seeded {n} peer rows from {table_file} into {cache.dir}")


def compare(args, corpus, names, peers, py, cache):
    ratios = [float(r) for r in args.ratios.split(",")]
    tools = [t for t in args.tools.split(",") if t]
    variants = []
    for v in args.variant:
        name, _, extra = v.partition("=")
        variants.append((name, extra))
    work = tempfile.mkdtemp(prefix="compare_peers_")
    report_dir = os.path.join(work, "reports")
    os.makedirs(report_dir)
    with_report = qem_has_report(args.qem)
    records = []
    t_start = time.time()
    for mesh in names:
        path = os.path.join(corpus, mesh + ".obj")
        cmds = [(n, qem_template(args.qem, extra, report_dir, f"{mesh}.{n}", with_report))
                for n, extra in [("qem", args.qem_args)] + variants]
        cached = {(t, r): cache.get(path, r, t) for t in tools for r in ratios} if cache else {}
        run_tools = [t for t in tools if any(cached.get((t, r)) is None for r in ratios)]
        if cache and len(run_tools) < len(tools):
            print(f"[compare] {mesh}: peer rows from the cache for "
                  f"{', '.join(t for t in tools if t not in run_tools)}", flush=True)
        fresh = run_harness(py, peers, path, ratios, run_tools, cmds, args, os.path.join(work, "results"))
        by_key = {(r["tool"], float(r["ratio"])): r for r in fresh}
        for r in fresh:
            if r["tool"] == "qem" or r["tool"] in dict(variants):
                r["qem_call_ms"] = qem_call_ms(report_dir, r["tool"], mesh, r["ratio"])
            elif cache and r.get("status") == "ok":
                cache.put(path, r["ratio"], r["tool"], r)
        for ratio in ratios:
            for t in tools:
                if (t, ratio) in by_key:
                    records.append(by_key[(t, ratio)])
                elif cached.get((t, ratio)) is not None:
                    records.append(dict(cached[(t, ratio)], cached=True))
            records += [by_key[(n, ratio)] for n in ["qem"] + [v for v, _ in variants] if (n, ratio) in by_key]
        print(f"[compare] {mesh} done ({time.time() - t_start:.0f}s so far)", flush=True)
    return records, tools, [n for n, _ in variants], ratios, time.time() - t_start


def fmt_time(r):
    t = r.get("t_call")
    if t is None:
        return "-"
    s = f"{t * 1e3:,.1f}"
    if r.get("qem_call_ms") is not None:
        s += f" ({r['qem_call_ms']:,.1f})"
    return s


def boundary_cell(r):
    if r.get("boundary_loops_in") is None:
        return "-"
    s = f"{r['boundary_loops_in']}→{r['boundary_loops_out']}"
    if r.get("boundary_survived") is not None:
        s += " ok" if r["boundary_survived"] else " LOST"
    return s


def table(records):
    out = ["| mesh | ratio | tool | tris out | time ms | Hausdorff %diag | mean %diag | flipped % | boundary loops |",
           "|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        if r.get("status") != "ok":
            err = str(r.get("error", ""))[:80].replace("|", "/").replace("\n", " ")
            out.append(f"| {r['mesh']} | {r['ratio']} | {r['tool']} | FAILED: {err} | | | | | |")
            continue
        flipped = "-" if r.get("flipped_pct") is None else f"{r['flipped_pct']:.2f}"
        out.append(f"| {r['mesh']} | {r['ratio']} | {r['tool']} | {r.get('tris_out', '-')} | {fmt_time(r)} | "
                   f"{pct(r.get('hd_sym'))} | {pct(r.get('mean_sym'))} | {flipped} | {boundary_cell(r)} |")
    return "\n".join(out)


def wins(records, tools, clean):
    """Per (mesh, ratio) of the clean scans: qem vs the best peer on mean and Hausdorff."""
    cases = {}
    for r in records:
        if r.get("status") == "ok" and r["mesh"] in clean:
            cases.setdefault((r["mesh"], r["ratio"]), {})[r["tool"]] = r
    lines, losses = [], []
    n = mean_wins = hd_wins = 0
    flipped_cases = []
    for (mesh, ratio), by_tool in sorted(cases.items(), key=lambda kv: (kv[0][0], -kv[0][1])):
        q = by_tool.get("qem")
        peers = [by_tool[t] for t in tools if t in by_tool and by_tool[t].get("mean_sym") is not None]
        if q is None or q.get("mean_sym") is None or not peers:
            continue
        n += 1
        best_mean = min(peers, key=lambda r: r["mean_sym"])
        best_hd = min(peers, key=lambda r: r["hd_sym"])
        mw = q["mean_sym"] <= best_mean["mean_sym"]
        hw = q["hd_sym"] <= best_hd["hd_sym"]
        mean_wins += mw
        hd_wins += hw
        if not (mw and hw):
            losses.append(f"| {mesh} | {ratio} | {pct(q['mean_sym'])} | {pct(best_mean['mean_sym'])} ({best_mean['tool']}) | "
                          f"{q['mean_sym'] / best_mean['mean_sym']:.2f} | {pct(q['hd_sym'])} | "
                          f"{pct(best_hd['hd_sym'])} ({best_hd['tool']}) | {q['hd_sym'] / best_hd['hd_sym']:.2f} |")
        if ratio == 0.1 and (q.get("flipped_pct") or 0) > 0:
            flipped_cases.append(f"{mesh} ({q['flipped_pct']:.2f}%)")
    if n == 0:
        return "No clean-scan case with both qem and a peer measured.", None
    lines.append(f"Clean-scan cases (mesh × ratio) with qem and at least one peer measured: {n}.\n")
    lines.append(f"- qem mean error ≤ best peer's: **{mean_wins}/{n} = {100 * mean_wins / n:.0f}%** (goal ≥ 80%)")
    lines.append(f"- qem Hausdorff ≤ best peer's: **{hd_wins}/{n} = {100 * hd_wins / n:.0f}%** (goal ≥ 60%)")
    lines.append(f"- qem flipped faces at ratio 0.1: "
                 + ("0% on every clean scan" if not flipped_cases else "non-zero on " + ", ".join(flipped_cases)))
    if losses:
        lines.append("\nCases qem loses (ratio = qem / best peer; > 1 means qem is worse):\n")
        lines.append("| mesh | ratio | qem mean | best peer mean | ratio | qem HD | best peer HD | ratio |")
        lines.append("|---|---|---|---|---|---|---|---|")
        lines += losses
    return "\n".join(lines), (mean_wins, hd_wins, n)


def qem_alone(args, corpus, names):
    ratios = [float(r) for r in args.ratios.split(",")]
    rows = ["| mesh | ratio | tool | tris out | time ms | Hausdorff %diag | mean %diag | flipped % | boundary loops |",
            "|---|---|---|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        for mesh in names:
            src = os.path.join(corpus, mesh + ".obj")
            for ratio in ratios:
                out = os.path.join(tmp, "out.obj")
                t0 = time.perf_counter()
                p = subprocess.run([args.qem, "simplify", src, "-o", out, "--ratio", str(ratio)] + shlex.split(args.qem_args),
                                   capture_output=True, text=True)
                wall = time.perf_counter() - t0
                if p.returncode != 0:
                    rows.append(f"| {mesh} | {ratio} | qem | FAILED: {p.stderr.strip()[:80]} | | | | | |")
                    continue
                m = subprocess.run([args.qem, "measure", src, out, "--json"], capture_output=True, text=True)
                j = json.loads(m.stdout) if m.returncode == 0 else {}
                mean = 0.5 * (j["mean_ab"] + j["mean_ba"]) if j else None
                rows.append(f"| {mesh} | {ratio} | qem | {j.get('triangles_b', '-')} | {wall * 1e3:,.1f} | "
                            f"{pct(j.get('hausdorff'))} | {pct(mean)} | - | - |")
                print(rows[-1], flush=True)
    return "\n".join(rows)


def agreement(args, corpus, names, peers, py):
    """qem measure vs the harness on qem's 10% output of each mesh."""
    work = tempfile.mkdtemp(prefix="measure_agreement_")
    figures = [("hausdorff", "hd_sym"), ("mean_ab", "mean_in_out"), ("mean_ba", "mean_out_in"),
               ("rms_ab", "rms_in_out"), ("rms_ba", "rms_out_in")]
    rows = ["| mesh | figure | qem measure %diag | harness %diag | relative difference |", "|---|---|---|---|---|"]
    worst = {k: 0.0 for k, _ in figures}
    counts = []
    for mesh in names:
        src = os.path.join(corpus, mesh + ".obj")
        kept = os.path.join(work, f"{mesh}.q10.obj")
        template = (f"{shlex.quote(args.qem)} simplify {{in}} -o {{out}} --ratio {{ratio}} "
                    f"&& cp {{out}} {shlex.quote(kept)}")
        rec = [r for r in run_harness(py, peers, src, [0.1], [], [("qem", template)], args, os.path.join(work, "h"))
               if r["tool"] == "qem"][0]
        cmd = ["nice", "-n", "5", args.qem, "measure", src, kept, "--json"]
        print("$ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
        m = json.loads(subprocess.run(cmd, capture_output=True, text=True, check=True).stdout)
        counts.append(f"{mesh}: qem {m['samples_ab']:,} / {m['samples_ba']:,}, "
                      f"harness {rec['samples_in']:,} / {rec['samples_out']:,}")
        for ours, theirs in figures:
            a, b = m[ours], rec[theirs]
            rel = (a - b) / b if b else float("nan")
            worst[ours] = max(worst[ours], abs(rel))
            rows.append(f"| {mesh} | {ours} | {a * 100:.5f} | {b * 100:.5f} | {rel * 100:+.2f}% |")
    summary = ["", "Largest |relative difference| per figure: "
               + ", ".join(f"{k} {v * 100:.2f}%" for k, v in worst.items()) + ".", "",
               "Samples (A→B / B→A): " + "; ".join(counts) + "."]
    return "\n".join(rows + summary)


def boundary_loops(args, corpus, names, peers, py):
    """qem at one ratio, defaults vs --lock-boundary: boundary loops in->out as the harness counts them.

    The harness counts loops by vertex index, so an unwelded input (a triangle soup) has one
    loop per triangle. The reference is therefore qem's own cleaned input: `qem simplify
    --ratio 1` (load, weld, clean, no contraction), measured by the same harness.
    """
    ratio = float(args.ratios.split(",")[0])
    work = tempfile.mkdtemp(prefix="compare_boundary_")
    rows = ["| mesh | tris in | loops in (file) | loops after cleaning (ratio 1) | defaults: loops out | "
            "defaults: boundary HD %diag | --lock-boundary: loops out | --lock-boundary: boundary HD %diag |",
            "|---|---|---|---|---|---|---|---|"]
    kept = {"qem": 0, "qem_lock": 0}
    n = 0
    for mesh in names:
        path = os.path.join(corpus, mesh + ".obj")
        ref = f"{shlex.quote(args.qem)} simplify {{in}} -o {{out}} --triangles 1000000000 -q"
        cmds = [("qem_clean", ref),
                ("qem", qem_template(args.qem, args.qem_args, work, mesh, False)),
                ("qem_lock", qem_template(args.qem, (args.qem_args + " --lock-boundary").strip(), work, mesh, False))]
        recs = {r["tool"]: r for r in run_harness(py, peers, path, [ratio], [], cmds, args, os.path.join(work, "h"))}
        clean = recs.get("qem_clean", {})
        ref_loops = clean.get("boundary_loops_out") if clean.get("status") == "ok" else None
        cells = []
        for tool in ("qem", "qem_lock"):
            r = recs.get(tool, {})
            if r.get("status") != "ok":
                cells += ["FAILED: " + str(r.get("error", "no record"))[:60].replace("|", "/"), ""]
                continue
            same = ref_loops is not None and r.get("boundary_loops_out") == ref_loops
            kept[tool] += same
            bhd = r.get("boundary_hd")
            cells += [f"{r.get('boundary_loops_out')}" + ("" if same else " **changed**"),
                      "-" if bhd is None else pct(bhd)]
        n += 1
        rows.append(f"| {mesh} | {clean.get('tris_in', '-')} | {clean.get('boundary_loops_in', '-')} | "
                    f"{'-' if ref_loops is None else ref_loops} | " + " | ".join(cells) + " |")
        print(rows[-1], flush=True)
    summary = (f"Ratio {ratio}, {n} meshes: the number of boundary loops after cleaning is kept on "
               f"**{kept['qem']}/{n}** with the defaults and **{kept['qem_lock']}/{n}** with `--lock-boundary`. "
               "Boundary HD = the harness's sampled Hausdorff distance between the input's and the "
               "output's boundary edges (both directions).")
    return summary + "\n\n" + "\n".join(rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--corpus", default=os.environ.get("QEM_CORPUS", os.path.join(ROOT, "..", "shared", "corpus")))
    ap.add_argument("--peers-dir", default=os.path.join(ROOT, "..", "shared", "tools", "peers"))
    ap.add_argument("--peers-python", default=None, help="the harness venv's python")
    ap.add_argument("--qem", default=os.path.join(ROOT, "target", "dist", "qem"))
    ap.add_argument("--qem-args", default="", help="extra `qem simplify` arguments for the qem row")
    ap.add_argument("--variant", action="append", default=[], help="NAME='extra qem simplify args' (repeatable)")
    ap.add_argument("--meshes", default="", help="comma list of corpus names (default: the clean scans)")
    ap.add_argument("--ratios", default="0.5,0.1,0.01")
    ap.add_argument("--tools", default="meshopt_rs,pymeshlab_qem_q,pyfqmr")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=900)
    ap.add_argument("--slow-cap", type=float, default=60)
    ap.add_argument("--out", default=os.path.join(ROOT, "BENCHMARKS.md"))
    ap.add_argument("--agreement", default="", help="comma list of meshes: qem measure vs the harness")
    ap.add_argument("--peer-cache", default=os.path.join(
        os.environ.get("PEERS_HOME", os.path.join(os.path.expanduser("~"), ".cache", "qem-peers")),
        "compare-peers-cache"), help="directory of cached peer rows")
    ap.add_argument("--no-peer-cache", action="store_true", help="measure the peers again, cache nothing")
    ap.add_argument("--seed-peer-cache", default="", help="FILE: fill the cache from FILE's compare-peers table")
    ap.add_argument("--boundary", action="store_true",
                    help="boundary loops, qem defaults vs --lock-boundary, on meshes with borders")
    args = ap.parse_args()
    args.corpus, args.peers_dir, args.qem = (os.path.normpath(p) for p in (args.corpus, args.peers_dir, args.qem))

    if not os.path.isfile(os.path.join(args.corpus, "manifest.tsv")):
        sys.exit(f"corpus not found at {args.corpus} (set --corpus or QEM_CORPUS)")
    if not os.path.exists(args.qem):
        sys.exit(f"{args.qem} not found: run `cargo build --profile dist -p qem-cli` first")
    rows = read_manifest(args.corpus)
    clean = [mesh_name(r) for r in clean_scans(rows)]
    print(f"clean scans (category scan-*, all of {', '.join(CLEAN_ZERO_COLUMNS)} = 0): {', '.join(clean)}")
    peers, py = harness_paths(args)

    if args.agreement:
        if peers is None:
            print(f"harness not found ({args.peers_dir}, venv python): cannot compare with it")
            return 0
        names = [n for n in args.agreement.split(",") if n]
        body = agreement(args, args.corpus, names, peers, py)
        replace_between(args.out, AGREE_START, AGREE_END, body, "## qem measure vs the harness")
        print(body)
        return 0

    if args.boundary:
        if peers is None:
            print(f"harness not found ({args.peers_dir}, venv python): cannot count loops with it")
            return 0
        names = ([n for n in args.meshes.split(",") if n]
                 or [mesh_name(r) for r in rows if int(r["boundary_edges"]) > 0])
        command = "scripts/compare_peers.py " + " ".join(shlex.quote(a) for a in sys.argv[1:])
        body = f"`{command.strip()}`\n\n" + boundary_loops(args, args.corpus, names, peers, py)
        replace_between(args.out, BOUNDARY_START, BOUNDARY_END, body, "## Boundary loops (issue 5)")
        print(body)
        return 0

    names = [n for n in args.meshes.split(",") if n] or clean
    if peers is None:
        print(f"harness not found ({args.peers_dir}/peers.py and its venv python): running qem alone")
        body = ("Harness absent: qem alone (time = whole process; figures from `qem measure`; "
                "mean = average of both directions).\n\n" + qem_alone(args, args.corpus, names))
        replace_between(args.out, START, END, body, "## qem vs peers on the corpus (issue 5)")
        print(body)
        return 0

    tools = [t for t in args.tools.split(",") if t]
    cache = None if args.no_peer_cache else PeerCache(args.peer_cache, peers, args)
    if args.seed_peer_cache:
        if cache is None:
            sys.exit("--seed-peer-cache needs the cache (drop --no-peer-cache)")
        seed_cache_from_table(cache, args.seed_peer_cache, args.corpus, tools)
    records, tools, variants, ratios, seconds = compare(args, args.corpus, names, peers, py, cache)
    from_table = sorted({r["from_table"] for r in records if r.get("from_table")})
    n_cached = sum(1 for r in records if r["tool"] in tools and r.get("cached"))
    summary, _ = wins(records, tools, set(clean))
    for v in variants:
        # Each variant counted as if it were qem (its rows renamed), against the same peers.
        renamed = [dict(r, tool="qem") for r in records if r["tool"] == v] + \
                  [r for r in records if r["tool"] in tools]
        _, counts = wins(renamed, tools, set(clean))
        if counts:
            mw, hw, n = counts
            summary += (f"\n- variant `{v}` in qem's place: mean ≤ best peer's {mw}/{n} = {100 * mw / n:.0f}%, "
                        f"Hausdorff ≤ best peer's {hw}/{n} = {100 * hw / n:.0f}%")
    command = "scripts/compare_peers.py " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    body = "\n".join([
        f"`{command.strip()}` — meshes: {', '.join(names)}; ratios {', '.join(map(str, ratios))}; "
        f"peers: {', '.join(tools)}" + (f"; qem variants: {', '.join(variants)}" if variants else "")
        + f"; qem args: `{args.qem_args or '(defaults)'}`; total {seconds / 60:.1f} min.",
        "",
        (f"{n_cached} peer rows came from the peer cache (measured by an earlier run with the same "
         "harness, options and mesh files)"
         + (f"; seeded from the table of {', '.join(os.path.basename(f) for f in from_table)} "
            "as printed there, i.e. rounded to 4 decimals of % diag" if from_table else "")
         + "." if n_cached else "All peer rows measured in this run."),
        "",
        "Distances in % of the input's bbox diagonal, measured by the harness for every tool alike "
        "(Hausdorff = max of both directions; mean = average of the two directed means). "
        "Time: peers = simplification call only; qem = whole process incl. OBJ read/write, "
        "with qem's own simplification time in brackets. flipped % = output faces whose normal "
        "opposes the nearest input face's. boundary loops: input→output, ok/LOST as the harness judges.",
        "",
        summary,
        "",
        table(records),
    ])
    replace_between(args.out, START, END, body, "## qem vs peers on the corpus (issue 5)")
    print(body)
    return 0


if __name__ == "__main__":
    sys.exit(main())
