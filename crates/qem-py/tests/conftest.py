"""Shared meshes for the qem tests: small, made here, so the suite needs no files (but
the tile tests, which cut the repository's cow, assets/spot.obj), and the qem command
the tile tests compare with."""

import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[3]

SPOT = REPO / "assets" / "spot.obj"
"""The cow: 5,856 triangles, closed, with UVs and normals."""


def qem_command():
    """The qem command of this checkout: CARGO_TARGET_DIR/debug/qem (relative to the
    repository when relative; target/ when unset), which `cargo test --workspace` builds
    before .ci/run runs pytest. Fails (not skips) when it is missing: the tile tests
    exist to show the Python package writes the command's bytes."""
    target = Path(os.environ.get("CARGO_TARGET_DIR") or "target")
    if not target.is_absolute():
        target = REPO / target
    exe = target / "debug" / ("qem.exe" if os.name == "nt" else "qem")
    if not exe.is_file():
        pytest.fail(
            f"the qem command is not built: no {exe}. The tile tests compare the Python "
            "package's files with the command's; build it first with "
            "`cargo build -p qem-cli` (.ci/run's `cargo test --workspace` does)."
        )
    return exe


def run_qem(*args):
    """Runs the qem command with `args` (paths converted); fails the test if it fails."""
    cmd = [str(qem_command()), *map(str, args)]
    done = subprocess.run(cmd, capture_output=True, text=True)
    assert done.returncode == 0, f"{' '.join(cmd)}: {done.stderr}"
    return done


def files(directory):
    """Every file of `directory`: name -> bytes."""
    return {p.name: p.read_bytes() for p in sorted(Path(directory).iterdir())}


def uv_sphere(n=48, m=24):
    """A closed UV sphere: n x m quads split in two; each pole row repeats one point
    (qem welds them and drops the faces that collapse). float64 vertices, int64 faces."""
    theta, phi = np.meshgrid(
        np.linspace(0, 2 * np.pi, n, endpoint=False), np.linspace(0, np.pi, m + 1)
    )
    vertices = np.stack(
        [np.sin(phi) * np.cos(theta), np.sin(phi) * np.sin(theta), np.cos(phi)], axis=-1
    ).reshape(-1, 3)
    # Exact poles (sin(pi) is 1.2e-16, not 0): each pole row is one point n times.
    vertices[:n] = [0.0, 0.0, 1.0]
    vertices[-n:] = [0.0, 0.0, -1.0]
    i, j = np.meshgrid(np.arange(n), np.arange(m))
    a, b = j * n + i, j * n + (i + 1) % n
    faces = np.concatenate(
        [np.stack([a, a + n, b], -1), np.stack([b, a + n, b + n], -1)]
    ).reshape(-1, 3)
    return vertices, faces


def grid(n=20):
    """An open, bumpy n x n grid of squares (2 n^2 triangles): it has a border."""
    x, y = np.meshgrid(np.arange(n + 1, dtype=float), np.arange(n + 1, dtype=float))
    z = 0.3 * np.sin(x) * np.cos(y)
    vertices = np.stack([x, y, z], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    v = j * (n + 1) + i
    faces = np.concatenate(
        [np.stack([v, v + 1, v + n + 1], -1), np.stack([v + 1, v + n + 2, v + n + 1], -1)]
    ).reshape(-1, 3)
    return vertices, faces


@pytest.fixture
def sphere():
    return uv_sphere()


def assert_valid(vertices, faces):
    """What qem guarantees of every output."""
    assert vertices.ndim == 2 and vertices.shape[1] == 3
    assert faces.ndim == 2 and faces.shape[1] == 3
    assert len(faces) >= 1
    assert np.isfinite(vertices).all()
    assert faces.min() >= 0 and faces.max() < len(vertices)
    a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
    assert ((a != b) & (b != c) & (a != c)).all(), "a face repeats a vertex"
    p = vertices.astype(np.float64)
    area2 = np.linalg.norm(np.cross(p[b] - p[a], p[c] - p[a]), axis=1)
    assert (area2 > 0).all(), "a zero-area face"


def assert_gil_released(work):
    """Runs `work()` in a thread and checks the main thread kept running Python code
    meanwhile: with the GIL held through the call it could not run at all."""
    span = {}

    def timed():
        span["start"] = time.perf_counter()
        work()
        span["end"] = time.perf_counter()

    thread = threading.Thread(target=timed)
    ticks = []
    thread.start()
    while thread.is_alive():
        ticks.append(time.perf_counter())
    thread.join()
    start, end = span["start"], span["end"]
    assert end - start > 0.05, "the run is too short to tell"
    # Ticks inside the middle 80% of the call: none could happen with the GIL held.
    margin = 0.1 * (end - start)
    inside = [t for t in ticks if start + margin < t < end - margin]
    assert len(inside) > 100
