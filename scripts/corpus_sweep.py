#!/usr/bin/env python3
"""Run `qem simplify` on every corpus mesh at several ratios and write a table.

usage: scripts/corpus_sweep.py [--corpus DIR] [--ratios 0.5,0.1,0.01] [--out BENCHMARKS.md]
                               [--qem target/dist/qem] [--only NAME,...]

For each `NAME.obj` in the corpus (default ../shared/corpus, or $QEM_CORPUS) and each
ratio, runs the dist binary with --report, checks the output with the corpus tools'
independent `meshcheck.py` when it is present, and writes a markdown table (mesh, in,
out, target, time, stop reason, max error, check) between the markers
`<!-- corpus-sweep:start -->` and `<!-- corpus-sweep:end -->` of the output file.
Build first: `cargo build --profile dist -p qem-cli`.
"""
import argparse, json, os, platform, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
START, END = "<!-- corpus-sweep:start -->", "<!-- corpus-sweep:end -->"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--corpus", default=os.environ.get("QEM_CORPUS", os.path.join(ROOT, "..", "shared", "corpus")))
    ap.add_argument("--ratios", default="0.5,0.1,0.01")
    ap.add_argument("--out", default=os.path.join(ROOT, "BENCHMARKS.md"))
    ap.add_argument("--qem", default=os.path.join(ROOT, "target", "dist", "qem"))
    ap.add_argument("--only", default="")
    ap.add_argument("--extra", default="", help="extra qem simplify arguments, e.g. '--pair-threshold 0.001'")
    a = ap.parse_args()
    if not os.path.isdir(a.corpus):
        sys.exit(f"corpus not found at {a.corpus} (set --corpus or QEM_CORPUS)")
    if not os.path.exists(a.qem):
        sys.exit(f"{a.qem} not found: run `cargo build --profile dist -p qem-cli` first")
    check = os.path.join(a.corpus, "..", "tools", "meshcheck.py")
    names = sorted(f for f in os.listdir(a.corpus) if f.endswith(".obj"))
    if a.only:
        keep = set(a.only.split(","))
        names = [n for n in names if n[:-4] in keep or n in keep]
    ratios = [float(r) for r in a.ratios.split(",")]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in names:
            for r in ratios:
                src = os.path.join(a.corpus, name)
                out = os.path.join(tmp, f"out.obj")
                rep = os.path.join(tmp, f"report.json")
                cmd = [a.qem, "simplify", src, "-o", out, "--ratio", str(r), "--report", rep] + a.extra.split()
                t0 = time.perf_counter()
                p = subprocess.run(cmd, capture_output=True, text=True)
                wall = time.perf_counter() - t0
                if p.returncode != 0:
                    rows.append((name[:-4], r, "-", "-", "-", f"{wall:.3f}", "error: " + p.stderr.strip().splitlines()[-1][:80], "-", "-"))
                    print(rows[-1], flush=True)
                    continue
                j = json.load(open(rep))
                ok = "-"
                if os.path.exists(check):
                    c = subprocess.run([sys.executable, check, out], capture_output=True, text=True)
                    ok = "ok" if c.returncode == 0 else "FAIL " + c.stdout.strip()[:60]
                rows.append((name[:-4], r, j["triangles_in"], j["target_triangles"], j["triangles_out"],
                             f"{j['timings_ms']['simplify'] / 1e3:.3f}", j["stop_reason"],
                             f"{j['max_error'] * 100:.4f}", ok))
                print(rows[-1], flush=True)
    head = ("| mesh | ratio | tris in | target | tris out | simplify s | stop reason | max error % diag | meshcheck |\n"
            "|---|---|---|---|---|---|---|---|---|\n")
    body = "".join("| " + " | ".join(str(x) for x in row) + " |\n" for row in rows)
    cpu = ""
    try:
        cpu = [l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")][0]
    except Exception:
        pass
    block = (f"{START}\nProduced by `scripts/corpus_sweep.py --ratios {a.ratios}{(' --extra ' + repr(a.extra)) if a.extra else ''}` "
             f"on {platform.node()} ({cpu}, {os.cpu_count()} cores), {time.strftime('%Y-%m-%d')}. "
             f"`simplify s` is the library call alone (from the JSON report, `timings_ms.simplify`); "
             f"max error is the report's `max_error` (RMS distance to accumulated planes, % of the bbox diagonal).\n\n"
             + head + body + END + "\n")
    text = open(a.out).read() if os.path.exists(a.out) else "# Benchmarks\n\n"
    if START in text and END in text:
        pre, rest = text.split(START, 1)
        post = rest.split(END, 1)[1].lstrip("\n")
        text = pre + block + post
    else:
        text = text.rstrip("\n") + "\n\n## Corpus sweep\n\n" + block
    open(a.out, "w").write(text)
    print(f"wrote {len(rows)} rows to {a.out}")


if __name__ == "__main__":
    main()
