"""The build cache under a campaign's load: many processes building and loading the same
models at once, and a builder killed half way, never leave a half-written entry in use."""

import hashlib
import multiprocessing
import os
import signal
import time
from pathlib import Path

from fpga_robotics.sim.backends import build_cache

PAYLOAD = bytes(range(256)) * 256  # 64 KiB, written in two halves with a pause between


def _build(log):
    def build(directory):
        with open(log, "a") as f:
            f.write(f"{os.getpid()}\n")
        with open(directory / "model.bin", "wb") as f:
            f.write(PAYLOAD[: len(PAYLOAD) // 2])
            f.flush()
            time.sleep(0.3)  # a reader arriving now must wait, not see half a model
            f.write(PAYLOAD[len(PAYLOAD) // 2 :])

    return build


def _worker(root, log, keys, queue):
    seen = []
    for key in keys:
        entry = build_cache.get_or_build("model", key, ["model.bin"], _build(log), root=root)
        seen.append((key, (entry.path / "model.bin").read_bytes() == PAYLOAD))
    queue.put(seen)


def test_many_processes_build_each_model_once_and_load_it_whole(tmp_path):
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    log = tmp_path / "builds.log"
    keys = [hashlib.sha256(str(i).encode()).hexdigest() for i in range(3)]
    # Six processes, each wanting the three models in its own order.
    procs = [
        ctx.Process(target=_worker, args=(tmp_path, log, keys[i % 3 :] + keys[: i % 3], queue))
        for i in range(6)
    ]
    for p in procs:
        p.start()
    results = [queue.get(timeout=120) for _ in procs]
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    assert all(ok for seen in results for _key, ok in seen)
    assert len(log.read_text().split()) == len(keys)  # one build per model
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.endswith(".lock")) == sorted(
        ["builds.log", *(f"model-{k[:32]}" for k in keys)]
    )


def _build_forever(root, log):
    build_cache.get_or_build(
        "model", "f" * 64, ["model.bin"], lambda d: (_build(log)(d), time.sleep(3600)), root=root
    )


def test_a_builder_killed_half_way_leaves_no_entry_and_the_next_one_builds(tmp_path):
    ctx = multiprocessing.get_context("spawn")
    log = tmp_path / "builds.log"
    proc = ctx.Process(target=_build_forever, args=(tmp_path, log))
    proc.start()
    end = time.monotonic() + 60
    while not log.exists() and time.monotonic() < end:
        time.sleep(0.05)
    time.sleep(0.4)  # inside the build, the lock held
    os.kill(proc.pid, signal.SIGKILL)
    proc.join(timeout=30)
    entry_dir = tmp_path / f"model-{'f' * 32}"
    assert not entry_dir.exists()
    # The lock died with its holder: the next process builds at once.
    t0 = time.monotonic()
    entry = build_cache.get_or_build("model", "f" * 64, ["model.bin"], _build(log), root=tmp_path)
    assert entry.built and time.monotonic() - t0 < 30
    assert (entry.path / "model.bin").read_bytes() == PAYLOAD
    assert Path(entry.path) == entry_dir
