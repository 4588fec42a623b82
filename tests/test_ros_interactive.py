"""``--interactive``: the run driven by keys typed into a pseudo-terminal (issue 16).

The run starts paused; the keys ``b`` (colour blue), ``l`` (target +x) and ``s`` (one frame)
act on frame 0; ``x`` (stop the target) and ``p`` (resume) on frame 1, where the run waits
paused again. The summary lists them at those frames, the bag shows their effect, and the
terminal's modes are restored at the end. Every wait is bounded."""

import json
import os
import pty
import select
import subprocess
import sys
import termios
import time

import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from fpga_robotics.ros.controls import TELEOP_SPEED

DEADLINE_S = 90  # includes the child's start-up (imports)


def read_until(fd, text, output, deadline):
    """Read the terminal into ``output`` (a bytearray) until ``text`` shows or EOF."""
    while text.encode() not in output:
        left = deadline - time.monotonic()
        assert left > 0, f"no {text!r} from the run; it printed: {bytes(output)!r}"
        ready, _, _ = select.select([fd], [], [], min(left, 0.5))
        if ready:
            try:
                chunk = os.read(fd, 4096)
            except OSError:  # EIO: the child closed the terminal
                return
            if not chunk:
                return
            output += chunk


def test_keys_in_a_terminal_control_the_run(tmp_path):
    master, slave = pty.openpty()
    cmd = [
        sys.executable,
        "-m",
        "fpga_robotics.run",
        "--backend",
        "model",
        "--resolution",
        "80x60",
        "--duration",
        "0.5",
        "--rerun",
        "off",
        "--interactive",
        "--paused",
        "--summary",
        "s.json",
        "--bag",
        "bag",
    ]
    proc = subprocess.Popen(
        cmd, stdin=slave, stdout=slave, stderr=slave, cwd=tmp_path, start_new_session=True
    )
    os.close(slave)
    output = bytearray()
    deadline = time.monotonic() + DEADLINE_S
    try:
        read_until(master, "keys:", output, deadline)
        os.write(master, b"bls")
        time.sleep(1.0)  # frame 0 runs; the run waits, paused, at frame 1
        os.write(master, b"xp")
        read_until(master, "verdict:", output, deadline)
        proc.wait(timeout=max(1.0, deadline - time.monotonic()))
        read_until(master, "\0never", output, time.monotonic() + 2)  # the rest, up to EOF
        attrs = termios.tcgetattr(master)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
        os.close(master)
    assert proc.returncode in (0, 1), bytes(output)
    assert b"5 live input(s) applied" in output
    assert attrs[3] & termios.ICANON and attrs[3] & termios.ECHO  # the terminal restored

    inputs = json.loads((tmp_path / "s.json").read_text())["inputs"]
    assert [(i["frame"], i["kind"], i["value"]) for i in inputs] == [
        (0, "color", "blue"),
        (0, "target_velocity", [TELEOP_SPEED, 0.0]),
        (0, "step", None),
        (1, "target_velocity", [0.0, 0.0]),
        (1, "resume", None),
    ]

    store = get_typestore(Stores.ROS2_HUMBLE)
    with AnyReader([tmp_path / "bag"], default_typestore=store) as reader:
        msgs = {}
        for conn, stamp, raw in reader.messages():
            msgs.setdefault(conn.topic, []).append((stamp, reader.deserialize(raw, conn.msgtype)))
    assert not any(m.data for _, m in msgs["/fpga/found"])  # blue from frame 0: nothing found
    xs = [
        next(mk.pose.position.x for mk in m.markers if mk.color.r > mk.color.g)
        for _, m in msgs["/people"]
    ]
    # Driven +x for exactly one frame period (1/30 s), then standing still.
    assert xs[1] - xs[0] == pytest.approx(TELEOP_SPEED / 30, abs=1e-6)
    assert xs[2:] == pytest.approx([xs[1]] * (len(xs) - 2), abs=1e-9)
    assert len(xs) == 15
