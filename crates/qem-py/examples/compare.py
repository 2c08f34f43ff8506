"""Times qem against pyfqmr and fast-simplification on the same NumPy arrays, and
measures every result against the input with qem.measure (Metro-style distances).

    python crates/qem-py/examples/compare.py MESH [--ratio 0.1] [--runs 3] [--cli QEM]

MESH is any file qem.load reads (.obj .ply .stl .off, optionally .gz). The peers are
optional imports (pip install pyfqmr fast-simplification); a missing one is listed as
skipped. Each tool gets the loaded arrays in the dtypes it takes (converted once, outside
the timing) and the same target triangle count; the time is the median wall time of
--runs calls of the tool's Python function, and the errors are those of the last run.
Errors are percentages of the input's bounding-box diagonal: the symmetric Hausdorff
distance and the mean distance from the input's surface to the output's and back.

With --cli QEM (a `qem` binary, e.g. target/dist/qem), qem's Python call is also timed
against the command's own simplify phase (`timings_ms.simplify` of its report) on the
same file and target, the two taking turns run by run: what the binding adds.
"""

import argparse
import json
import os
import platform
import subprocess
import tempfile
import statistics
import sys
import time

import numpy as np

import qem


def run_qem(vertices, faces, target, **options):
    v, f, report = qem.simplify(vertices, faces, triangles=target, **options)
    return v, f


def run_pyfqmr(vertices, faces, target):
    import pyfqmr

    simplifier = pyfqmr.Simplify()
    simplifier.setMesh(vertices, faces)
    # pyfqmr's defaults, with the border kept (as qem keeps it by default).
    simplifier.simplify_mesh(
        target_count=target, aggressiveness=7, preserve_border=True, verbose=False
    )
    v, f, _normals = simplifier.getMesh()
    return v, f


def run_fast_simplification(vertices, faces, target):
    import fast_simplification

    return fast_simplification.simplify(vertices, faces, target_count=target)


def available(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh")
    parser.add_argument("--ratio", type=float, default=0.1)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--cli", help="a qem binary to time the binding against")
    args = parser.parse_args()

    vertices, faces = qem.load(args.mesh)
    target = int(args.ratio * len(faces))
    faces_i32 = faces.astype(np.int32)
    tools = [
        ("qem", "qem", lambda: run_qem(vertices, faces, target)),
        ("qem fast=True", "qem", lambda: run_qem(vertices, faces, target, fast=True)),
        ("pyfqmr", "pyfqmr", lambda: run_pyfqmr(vertices, faces_i32, target)),
        (
            "fast-simplification",
            "fast_simplification",
            lambda: run_fast_simplification(vertices, faces_i32, target),
        ),
    ]
    print(
        f"{args.mesh}: {len(vertices)} vertices, {len(faces)} triangles, "
        f"target {target} (ratio {args.ratio}), median of {args.runs} runs; "
        f"Python {platform.python_version()}, qem {qem.__version__}"
    )
    print()
    print("| tool | triangles | time (s) | Hausdorff (% diag) | mean in→out (%) | mean out→in (%) |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, module, run in tools:
        if not available(module):
            print(f"| {name} | skipped: `pip install {module.replace('_', '-')}` | | | | |")
            continue
        times = []
        for _ in range(args.runs):
            start = time.perf_counter()
            v, f = run()
            times.append(time.perf_counter() - start)
        m = qem.measure((vertices, faces), (np.asarray(v), np.asarray(f)))
        print(
            f"| {name} | {len(f)} | {statistics.median(times):.3f} | "
            f"{100 * m['hausdorff']:.4f} | {100 * m['mean_ab']:.5f} | {100 * m['mean_ba']:.5f} |"
        )
        sys.stdout.flush()
    if args.cli:
        binding_against_cli(args, vertices, faces, target)


def binding_against_cli(args, vertices, faces, target):
    print()
    print("| options | qem.simplify (s) | CLI simplify phase (s) | ratio |")
    print("|---|---:|---:|---:|")
    with tempfile.TemporaryDirectory() as work:
        out, report = os.path.join(work, "out.ply"), os.path.join(work, "report.json")
        for label, flags, options in [("defaults", [], {}), ("fast=True", ["--fast"], {"fast": True})]:
            py, cli = [], []
            for _ in range(args.runs):
                subprocess.run(
                    [args.cli, "simplify", args.mesh, "-o", out, "--triangles", str(target),
                     "--report", report, "-q"] + flags,
                    check=True,
                )
                with open(report) as f:
                    cli.append(json.load(f)["timings_ms"]["simplify"] / 1e3)
                start = time.perf_counter()
                qem.simplify(vertices, faces, triangles=target, **options)
                py.append(time.perf_counter() - start)
            p, c = statistics.median(py), statistics.median(cli)
            print(f"| {label} | {p:.3f} | {c:.3f} | {p / c:.3f} |")


if __name__ == "__main__":
    main()
