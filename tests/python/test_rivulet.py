"""`import rivulet` (runtime/python) against the command line: the same meshes, the same messages."""
import json
import os
import subprocess

import numpy as np
import pytest

import rivulet

CLI = os.environ.get("RIVULET_CLI", "rivulet")


def ball(spacing=0.02, rings=6, seed=1, jitter=0.1):
    """A ball of particles on a lattice, each moved by up to `jitter` spacings along each axis."""
    r = np.arange(-rings, rings + 1)
    g = np.stack(np.meshgrid(r, r, r, indexing="ij"), axis=-1).reshape(-1, 3)
    g = g[(g**2).sum(axis=1) <= rings * rings].astype(np.float32) * spacing
    rng = np.random.default_rng(seed)
    return (g + rng.uniform(-jitter, jitter, g.shape).astype(np.float32) * spacing).astype(np.float32)


def cli(*args):
    return subprocess.run([CLI, *args], capture_output=True, text=True)


def cli_mesh_hash(path, method, tmp_path):
    out = tmp_path / "mesh.json"
    r = cli("mesh", str(path), "--method", method, "--json", str(out))
    assert r.returncode == 0, r.stdout + r.stderr
    return int(json.loads(out.read_text())["mesh_hash"], 16)


@pytest.mark.parametrize("method", ["slices", "scan", "volume"])
def test_reconstruct_gives_the_command_lines_mesh(method, tmp_path):
    # nearly a lattice: with more disorder the estimated radius leaves cavities inside the slices surface
    points = ball(jitter=0.05)
    path = tmp_path / "ball.ply"
    rivulet.write_particles(str(path), points)
    vertices, normals, triangles = rivulet.reconstruct(points, method=method)
    assert vertices.dtype == np.float32 and vertices.shape[1] == 3
    assert normals.shape == vertices.shape
    assert triangles.dtype == np.uint32 and triangles.shape[1] == 3 and len(triangles) > 200
    assert triangles.max() < len(vertices)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-3)
    assert np.linalg.norm(vertices, axis=1).max() < 0.12 + 0.03  # the ball's radius, plus a particle's
    if method != "scan":  # closed surfaces around the ball (scan's cylinder ends inside it face up and down)
        assert (np.einsum("ij,ij->i", vertices, normals) > 0).mean() > 0.99
    assert rivulet.mesh_hash(vertices, normals, triangles) == cli_mesh_hash(path, method, tmp_path)


def test_float64_and_strided_input_give_the_same_bytes():
    points = ball()
    reference = rivulet.reconstruct(points, radius=0.011)
    wide = np.asfortranarray(points.astype(np.float64))
    for a, b in zip(reference, rivulet.reconstruct(wide, radius=0.011)):
        np.testing.assert_array_equal(a, b)


def test_a_reused_extractor_equals_fresh_calls_at_any_thread_count():
    extractor = rivulet.SurfaceExtractor()
    for seed, spacing in [(1, 0.02), (2, 0.013), (3, 0.03)]:
        points = ball(spacing, 5, seed)
        one = rivulet.reconstruct(points, threads=1)
        two = extractor.extract(points, threads=2)
        for a, b in zip(one, two):
            np.testing.assert_array_equal(a, b)


def test_simulate_yields_each_frame_deterministically():
    frames = list(rivulet.simulate("dambreak", 3, warmup=0, threads=1))
    again = list(rivulet.simulate("dambreak", 3, warmup=0, threads=2))
    assert len(frames) == 3
    for a, b in zip(frames, again):
        assert a.dtype == np.float32 and a.shape[1] == 3 and len(a) > 1000
        # Equal NaNs would compare equal: every particle is a real point inside the 1 x 0.75 x 0.3 m tank.
        assert np.isfinite(a).all()
        assert (a > -1e-3).all() and (a < np.array([1.0, 0.75, 0.3]) + 1e-3).all()
        np.testing.assert_array_equal(a, b)
    assert not np.array_equal(frames[0], frames[2])  # the column falls
    assert "dambreak" in rivulet.scenes()


def test_read_particles_reads_what_simulate_writes(tmp_path):
    r = cli("simulate", "--scene", "dambreak", "--frames", "1", "--warmup", "0", "--threads", "1",
            "--out", str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    points = rivulet.read_particles(str(tmp_path / "frame_00000.ply"))
    np.testing.assert_array_equal(points, next(iter(rivulet.simulate("dambreak", 1, warmup=0))))


def test_errors_carry_the_command_lines_message(tmp_path):
    bad = tmp_path / "bad.ply"
    bad.write_text("ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nend_header\n1\n")
    r = cli("mesh", str(bad))
    assert r.returncode != 0
    cli_message = r.stderr.strip().removeprefix("rivulet: error: ")
    with pytest.raises(rivulet.Error) as e:
        rivulet.read_particles(str(bad))
    assert str(e.value) == cli_message
    with pytest.raises(rivulet.Error, match="NaN or infinite"):
        rivulet.reconstruct(np.array([[0, 0, 0], [np.nan, 0, 0]], dtype=np.float32))
    with pytest.raises(rivulet.Error, match=r"\(N, 3\)"):
        rivulet.reconstruct(np.zeros((4, 2), dtype=np.float32))
    with pytest.raises(rivulet.Error, match="no particles"):
        rivulet.reconstruct(np.zeros((0, 3), dtype=np.float32))
    with pytest.raises(rivulet.Error, match="method"):
        rivulet.reconstruct(ball(), method="marching")
    with pytest.raises(rivulet.Error, match="no_such_scene"):
        rivulet.simulate("no_such_scene", 1)


def test_replay_agrees_with_the_command_line(tmp_path):
    golden = os.path.join(os.path.dirname(__file__), "..", "golden", "faucet_scan.rivrec")
    r = rivulet.replay(golden, frames=2, threads=1)
    assert r["identical"] and r["frames"] == 2 and r["recorded"] == 100
    assert (r["scene"], r["method"]) == ("faucet", "scan")
    cut = tmp_path / "cut.rivrec"
    cut.write_bytes(open(golden, "rb").read()[:-40])
    c = cli("replay", str(cut))
    assert c.returncode != 0
    with pytest.raises(rivulet.Error) as e:
        rivulet.replay(str(cut))
    assert str(e.value) == c.stderr.strip().removeprefix("rivulet: error: ")
