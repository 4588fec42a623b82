"""The on-disk build cache: keys, damaged entries, concurrent builds, missing compiler."""

import json
import multiprocessing
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fpga_robotics.hw.params import FollowTargetParams
from fpga_robotics.sim.backends import (
    BackendError,
    available_backends,
    build_cache,
    fastest_backend_name,
    get_backend,
)
from fpga_robotics.sim.backends.cxxrtl import CXX_FLAGS, CxxrtlBackend, cxxrtl_build_plan
from fpga_robotics.sim.backends.designs import DesignSource

SMALL = FollowTargetParams(width=40, height=16)


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    root = tmp_path / "cache"
    monkeypatch.setenv(build_cache.CACHE_ENV, str(root))
    return root


def test_cache_location_follows_the_environment(cache_dir, monkeypatch):
    assert build_cache.cache_root() == cache_dir and cache_dir.is_dir()
    monkeypatch.delenv(build_cache.CACHE_ENV)
    assert build_cache.cache_root() == Path.home() / ".cache" / "fpga_robotics"


def test_key_changes_with_params_design_flags_and_variant():
    base = cxxrtl_build_plan(DesignSource(SMALL, "passthrough"), "plain")
    same = cxxrtl_build_plan(
        DesignSource(FollowTargetParams(width=40, height=16), "passthrough"), "plain"
    )
    assert base.key == same.key
    others = [
        cxxrtl_build_plan(DesignSource(SMALL.replace(height=18), "passthrough"), "plain"),
        cxxrtl_build_plan(DesignSource(SMALL.replace(diff_min=5), "passthrough"), "plain"),
        cxxrtl_build_plan(DesignSource(SMALL, "follow_target"), "plain"),
        cxxrtl_build_plan(DesignSource(SMALL, "passthrough"), "vcd"),
        cxxrtl_build_plan(
            DesignSource(SMALL, "passthrough"), "plain", flags=[*CXX_FLAGS, "-DSOMETHING"]
        ),
    ]
    keys = {base.key, *(p.key for p in others)}
    assert len(keys) == 1 + len(others)


def _slow_build(log):
    def build(directory):
        with open(log, "a") as f:
            f.write(f"{os.getpid()}\n")
        time.sleep(0.5)  # long enough for the other process to arrive meanwhile
        (directory / "lib.bin").write_bytes(b"x" * 4096)
        (directory / "junk.o").write_bytes(b"objects are not kept")

    return build


def _build_in_process(root, log, queue):
    entry = build_cache.get_or_build(
        "test-entry", "k" * 64, ["lib.bin"], _slow_build(log), root=root
    )
    queue.put((str(entry.path), (entry.path / "lib.bin").read_bytes() == b"x" * 4096))


def test_concurrent_builds_of_one_entry_build_once(tmp_path):
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    log = tmp_path / "builds.log"
    procs = [ctx.Process(target=_build_in_process, args=(tmp_path, log, queue)) for _ in range(2)]
    for p in procs:
        p.start()
    results = [queue.get(timeout=120) for _ in procs]
    for p in procs:
        p.join(timeout=60)
        assert p.exitcode == 0
    assert len(log.read_text().split()) == 1  # one process built, the other waited
    assert results[0] == results[1] and results[0][1]
    leftovers = [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert leftovers == []
    entry = Path(results[0][0])
    assert sorted(p.name for p in entry.iterdir()) == ["lib.bin", "manifest.json"]


@pytest.mark.parametrize("damage", ["truncate", "delete", "manifest", "garbage"])
def test_damaged_entry_is_detected_and_rebuilt(tmp_path, damage):
    log = tmp_path / "builds.log"
    args = ("test-entry", "k" * 64, ["lib.bin"], _slow_build(log))
    first = build_cache.get_or_build(*args, root=tmp_path)
    assert first.built
    assert not build_cache.get_or_build(*args, root=tmp_path).built
    lib = first.path / "lib.bin"
    if damage == "truncate":
        lib.write_bytes(lib.read_bytes()[:100])
    elif damage == "delete":
        lib.unlink()
    elif damage == "manifest":
        (first.path / "manifest.json").unlink()
    else:
        lib.write_bytes(b"y" * 4096)  # same size, other content
    again = build_cache.get_or_build(*args, root=tmp_path)
    assert again.built and again.path == first.path
    assert lib.read_bytes() == b"x" * 4096
    assert json.loads((first.path / "manifest.json").read_text())["key"] == "k" * 64
    assert len(log.read_text().split()) == 2


def test_failed_build_leaves_nothing(tmp_path):
    def failing(directory):
        (directory / "half.bin").write_bytes(b"half")
        raise BackendError("compiler exploded")

    with pytest.raises(BackendError, match="exploded"):
        build_cache.get_or_build("bad", "b" * 64, ["half.bin"], failing, root=tmp_path)
    assert [p for p in tmp_path.iterdir() if not p.name.endswith(".lock")] == []


def test_damaged_compiled_model_is_rebuilt_and_runs(cache_dir):
    frame = np.random.default_rng(0).integers(0, 4096, (16, 40), dtype=np.uint16)
    # Build without loading (a loaded library must not be damaged under the process's feet).
    plan = CxxrtlBackend.build_plan(DesignSource(SMALL, "passthrough"), "plain")
    entry = build_cache.get_or_build(*plan)
    lib = entry.file("libfollow_target.so")
    lib.write_bytes(lib.read_bytes()[:1000])  # a build killed half way through copying
    with get_backend("cxxrtl", SMALL, design="passthrough") as b:
        assert b.cache_entry.built and b.cache_entry.path == entry.path
        result = b.process_frame(frame)
    # The pass-through design: filtered is the frame itself, the count is every pixel.
    assert np.array_equal(result.filtered, frame)
    assert result.motor_left == 40 * 16


def test_missing_compiler_is_a_clear_error(monkeypatch, cache_dir):
    monkeypatch.setenv("CXX", "/nonexistent/bin/g++-missing")
    with pytest.raises(BackendError, match=r"g\+\+-missing.*install a C\+\+ compiler"):
        get_backend("cxxrtl", SMALL)
    with pytest.raises(BackendError, match="install"):
        get_backend("verilator", SMALL)
    assert fastest_backend_name() == "model"
    assert "cxxrtl" not in available_backends() and "model" in available_backends()


def test_registry_names():
    assert fastest_backend_name() in ("cxxrtl", "verilator")
    assert {"model", "cxxrtl", "verilator"} <= set(available_backends())
    with pytest.raises(ValueError, match="model, pysim, cxxrtl, verilator"):
        get_backend("iverilog")


def test_bench_cli_reports_missing_compiler_with_exit_2(tmp_path):
    env = dict(os.environ, CXX="/nonexistent/g++", **{build_cache.CACHE_ENV: str(tmp_path)})
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "fpga_robotics.bench",
            "--backends",
            "cxxrtl",
            "--resolutions",
            "40x16",
            "--frames",
            "1",
            "--no-trivial",
        ],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 2
    assert "install" in proc.stderr and "Traceback" not in proc.stderr


@pytest.mark.slow  # compiles a Verilator model split into many files (about a minute)
def test_a_verilator_model_split_into_files_builds(tmp_path):
    # A model big enough for Verilator to split (1000 mutants) compiles each file with the
    # precompiled header; pip's verilated.mk gives it no flag, so it named the header as a
    # bare input file and every such build failed. --output-split 1 splits a small one.
    from fpga_robotics.sim.backends.toolchain import find_compiler, find_make, verilator_root
    from fpga_robotics.sim.backends.verilator import MAKE_FLAGS

    try:
        root, cxx = verilator_root(), find_compiler().path
        find_make()
    except BackendError as exc:
        pytest.skip(str(exc))
    (tmp_path / "top.v").write_text(
        "module top(input clk, input [7:0] a, output reg [7:0] r0, output reg [7:0] r1);\n"
        "  always @(posedge clk) r0 <= r0 + a;\n"
        "  always @(posedge clk) r1 <= r1 ^ (a << 1);\n"
        "endmodule\n"
    )
    make = " ".join([*MAKE_FLAGS, f"CXX={cxx}", f"LINK={cxx}"])
    argv = [root / "bin" / "verilator", "--cc", "--build", "--output-split", "1"]
    argv += ["--output-split-cfuncs", "1", "-j", "2", "--Mdir", "obj", "-MAKEFLAGS", make]
    done = subprocess.run(
        [*argv, "top.v"],
        cwd=tmp_path,
        env=dict(os.environ, VERILATOR_ROOT=str(root)),
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert len(list((tmp_path / "obj").glob("Vtop___024root__*.cpp"))) > 1  # split it was
