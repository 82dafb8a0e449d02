"""Collections from Python (docs/collections.md): ``shapecorr.batch`` locally and on a Dask
``LocalCluster`` with 2 worker processes gives every pair the answer of ``shapecorr.match``;
a worker killed during the run loses and duplicates no pair; bad entries are failed pairs."""

import json
import os
import signal
import threading
from pathlib import Path

import numpy as np
import pytest

import shapecorr
from shapecorr import batch

SIZE = 1000
#: What may differ between two runs of one pair: the time it took.
TIMING = ("seconds", "stages")


def write_off(path, shape):
    v, t = shape.vertices, shape.triangles
    lines = ["OFF", f"{len(v)} {len(t)} 0"]
    lines += [f"{x!r} {y!r} {z!r}" for x, y, z in v.tolist()]
    lines += [f"3 {i} {j} {k}" for i, j, k in t.tolist()]
    Path(path).write_text("\n".join(lines) + "\n")


@pytest.fixture(scope="module")
def figures(tmp_path_factory):
    """8 generated humanoids (poses 0-3, two bodies each) as OFF files."""
    folder = tmp_path_factory.mktemp("figures")
    for pose in range(4):
        write_off(folder / f"h{pose}.off", shapecorr.Shape.figure("humanoid", pose, SIZE))
        write_off(folder / f"q{pose}.off", shapecorr.Shape.figure("quadruped", pose, SIZE))
    return folder


def records(out):
    lines = (Path(out) / "pairs.jsonl").read_text().splitlines()
    return [json.loads(line) for line in lines]


def by_pair(out):
    found = {}
    for r in records(out):
        key = (r["a"], r["b"])
        assert key not in found, f"pair {key} recorded twice"
        found[key] = {k: v for k, v in r.items() if k not in TIMING}
    return found


@pytest.fixture(scope="module")
def local_run(figures, tmp_path_factory):
    out = tmp_path_factory.mktemp("local")
    seen = []
    batch.match_pairs(figures, out, workers=2, progress=lambda done, total, r: seen.append((done, total)))
    assert seen[-1] == (28, 28)
    return out


def test_local_batch_gives_every_pair_the_answer_of_match(local_run, figures):
    results = by_pair(local_run)
    assert len(results) == 28
    shapes = [json.loads(line) for line in (local_run / "shapes.jsonl").read_text().splitlines()]
    assert sorted(s["name"] for s in shapes if s["computed"]) == sorted(p.stem for p in figures.iterdir())
    for (a, b), r in list(results.items())[:6]:
        assert r["ok"], r
        alone = shapecorr.match(shapecorr.Shape.read(figures / f"{a}.off"), shapecorr.Shape.read(figures / f"{b}.off"))
        assert r["k"] == alone.k
        assert np.array_equal(r["regions_a"], alone.regions_a)
        assert np.array_equal(r["regions_b"], alone.regions_b)
        assert np.array_equal(np.asarray(r["matches_one_to_one"]).reshape(-1, 2), alone.matches_one_to_one)
        assert r["confidence"] == alone.confidence


def test_summary_matrix_and_a_resumed_run(local_run, figures, tmp_path):
    rows = batch.summary(local_run)
    assert len(rows) == 28 and all(r["ok"] for r in rows)
    names, m = batch.write_matrix(local_run, "confidence", tmp_path / "c.csv", tmp_path / "c.png")
    assert len(names) == 8 and np.count_nonzero(~np.isnan(m)) == 28
    assert (tmp_path / "c.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "c.csv").read_text().count("\n") == 9
    # Nothing left to do: the log is unchanged.
    before = (local_run / "pairs.jsonl").read_bytes()
    batch.match_pairs(figures, local_run, workers=2)
    assert (local_run / "pairs.jsonl").read_bytes() == before
    with pytest.raises(shapecorr.ShapecorrError, match="other settings"):
        batch.match_pairs(figures, local_run, k_max=8)


def test_one_to_many_consistent_labels(figures, tmp_path):
    out = tmp_path / "template"
    batch.match_pairs(figures, out, pairs="one-to-many:h0", cache=tmp_path / "cache", workers=2)
    labels = batch.consistent_labels(out)
    assert set(labels) == {p.stem for p in figures.iterdir()}
    truth = lambda a, b: (np.arange(labels[a].size), np.arange(labels[b].size))  # noqa: E731
    # Same kind and vertex order: most vertices take the template's region of the same vertex.
    for pose in (1, 2, 3):
        agree = np.mean(labels[f"h{pose}"] == labels["h0"])
        assert agree > 0.6, (pose, agree)
    rows = batch.summary(out, truth=lambda a, b: truth(a, b) if b.startswith("h") else None)
    assert all(0.0 <= r["accuracy"] <= 1.0 for r in rows if "accuracy" in r)


def test_bad_entries_are_failed_pairs(figures, tmp_path):
    (tmp_path / "broken.ply").write_bytes(b"ply\nformat nonsense\n")
    tiny = tmp_path / "tiny.off"
    tiny.write_text("OFF\n10 8 0\n" + "".join(f"{i * 0.1} {(i % 3) * 0.2} {i % 2}\n" for i in range(10))
                    + "".join(f"3 {i} {i + 1} {i + 2}\n" for i in range(8)))
    shapes = {"h0": figures / "h0.off", "h1": figures / "h1.off", "broken": tmp_path / "broken.ply", "tiny": tiny}
    out = tmp_path / "out"
    with pytest.warns(RuntimeWarning, match=r"2 of 3 pairs failed \(2 now, 0 in an earlier run\)"):
        batch.match_pairs(shapes, out, pairs=[("h0", "h1"), ("h0", "broken"), ("tiny", "h1")], workers=2)
    # A resumed run reports them again.
    with pytest.warns(RuntimeWarning, match=r"2 of 3 pairs failed \(0 now, 2 in an earlier run\)"):
        batch.match_pairs(shapes, out, pairs=[("h0", "h1"), ("h0", "broken"), ("tiny", "h1")], workers=2)
    results = by_pair(out)
    assert results[("h0", "h1")]["ok"]
    assert not results[("h0", "broken")]["ok"]
    assert results[("h0", "broken")]["error"].startswith("shape broken: ")
    assert "broken.ply" in results[("h0", "broken")]["error"]
    assert not results[("tiny", "h1")]["ok"]
    assert results[("tiny", "h1")]["error"].startswith("shape tiny: ")


def test_maps_are_those_of_pointwise_map(figures, tmp_path):
    out = tmp_path / "maps"
    batch.match_pairs(figures, out, pairs=[("h0", "q1"), ("h2", "h3")], maps=True, workers=2)
    for a, b in [("h0", "q1"), ("h2", "h3")]:
        alone = shapecorr.pointwise_map(shapecorr.Shape.read(figures / f"{a}.off"), shapecorr.Shape.read(figures / f"{b}.off"))
        assert np.array_equal(batch.read_map(out, a, b), alone.map_b_to_a)


distributed = pytest.importorskip("distributed", reason="dask[distributed] is not installed")


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None, silence_logs=50,
    ) as cluster, distributed.Client(cluster) as client:
        yield cluster, client


def test_dask_gives_the_local_results(local_run, figures, cluster, tmp_path):
    _, client = cluster
    out = tmp_path / "dask"
    batch.match_pairs(figures, out, client=client)
    assert by_pair(out) == by_pair(local_run)


def test_a_killed_dask_worker_loses_and_duplicates_no_pair(local_run, figures, cluster, tmp_path):
    _, client = cluster
    pids = client.run(os.getpid)
    victim = sorted(pids.values())[0]
    killed = threading.Event()

    def kill_once(done, total, record):
        if done == 4 and not killed.is_set():
            os.kill(victim, signal.SIGKILL)
            killed.set()

    out = tmp_path / "killed"
    batch.match_pairs(figures, out, client=client, progress=kill_once)
    assert killed.is_set()
    assert victim not in client.run(os.getpid).values()
    assert by_pair(out) == by_pair(local_run)


def test_pair_files_are_read_by_the_library_and_names_get_maps_of_their_own(figures, tmp_path):
    pair_file = tmp_path / "pairs.txt"
    pair_file.write_text("# a\tb\nx--y\tz\tcategory\nx\ty--z left\n")
    assert batch.read_pairs(pair_file) == [("x--y", "z"), ("x", "y--z left")]
    shapes = {"x--y": figures / "h0.off", "z": figures / "h1.off", "x": figures / "h2.off",
              "y--z left": figures / "h3.off"}
    out = tmp_path / "out"
    batch.match_pairs(shapes, out, pairs=pair_file, maps=True, workers=2)
    results = by_pair(out)
    assert {results[p]["map"] for p in [("x--y", "z"), ("x", "y--z left")]} == {
        "maps/x%2D%2Dy--z.u32", "maps/x--y%2D%2Dz left.u32"}
    assert len(list((out / "maps").iterdir())) == 2
    for a, b in results:
        assert len(batch.read_map(out, a, b)) == len(results[(a, b)]["regions_b"])
    pair_file.write_text("x\tz\nlonely\n")
    with pytest.raises(shapecorr.ShapecorrError, match="line 2"):
        batch.read_pairs(pair_file)


def test_a_held_folder_or_other_settings_are_refused(figures, tmp_path):
    shapes = {"h0": figures / "h0.off", "h1": figures / "h1.off"}
    out = tmp_path / "out"
    refused = []

    def second_run(done, total, record):
        try:
            batch.match_pairs(shapes, out, workers=1, k_max=6)
        except shapecorr.ShapecorrError as error:
            refused.append(str(error))

    batch.match_pairs(shapes, out, workers=1, k_max=6, progress=second_run)
    assert len(refused) == 1 and "another batch is running" in refused[0], refused
    assert len(records(out)) == 1
    batch.match_pairs(shapes, out, workers=1, k_max=6)  # released: resumes
    with pytest.raises(shapecorr.ShapecorrError, match="other settings"):
        batch.match_pairs(shapes, out, workers=1)
    settings = json.loads((out / "batch.json").read_text())
    assert settings["options"]["k_max"] == 6 and "cache" not in settings


def test_a_damaged_cache_entry_is_computed_again_with_a_warning(figures, tmp_path):
    shapes = {"h0": figures / "h0.off", "h1": figures / "h1.off"}
    cache = tmp_path / "cache"
    batch.match_pairs(shapes, tmp_path / "first", cache=cache, workers=1)
    expected = by_pair(tmp_path / "first")
    # A copy of the cache (this process keeps the shapes prepared from the first one).
    damaged = tmp_path / "damaged"
    damaged.mkdir()
    for entry in cache.glob("*.basis"):
        (damaged / entry.name).write_bytes(entry.read_bytes())
    entry = sorted(damaged.glob("*.basis"))[0]
    data = bytearray(entry.read_bytes())
    data[len(data) // 2] ^= 0x10
    entry.write_bytes(bytes(data))
    with pytest.warns(RuntimeWarning, match="checksum does not match"):
        batch.match_pairs(shapes, tmp_path / "second", cache=damaged, workers=1)
    assert by_pair(tmp_path / "second") == expected
