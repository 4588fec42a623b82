"""``fpga-robotics bench ros``: what writing a ROS 2 bag and publishing live to Foxglove cost
per frame.

Synthetic frames (a red target over noise, the design's filtered frame from the golden model;
``fpga_robotics.bench.viewer.make_records``) at 160x120 by default. Bag: every frame through
``BagWriter.log_frame`` (all topics, both images) into a temporary bag; printed: the median
and the mean milliseconds of a ``log_frame`` call after the first (the mean includes the
chunk writes, and any time the machine gave to other processes), the CPU milliseconds per
frame of the writing thread, the first call alone
(it builds the serialisers), and opening plus closing the bag: the last two are paid once
per run. Live: the same frames through ``LivePublisher.log_frame`` with one
WebSocket client on loopback subscribed to every topic, paced at the camera's 30 fps as in
a live run; printed: the median milliseconds of a ``log_frame`` call and how many of the
messages sent the client received. Each figure is the median over ``--repeats`` runs.
"""

import contextlib
import json
import shutil
import statistics
import tempfile
import threading
import time
from pathlib import Path

from websockets.sync.client import connect

from fpga_robotics.bench import scaffold
from fpga_robotics.bench.viewer import make_records
from fpga_robotics.cli.errors import UsageError
from fpga_robotics.ros.bag_writer import BagWriter
from fpga_robotics.ros.foxglove_live import LivePublisher
from fpga_robotics.ros.messages import TOPICS, CameraGeometry, FrameMessages

__all__ = ["bench_bag", "bench_live", "main"]


def _geometry(width, height):
    return CameraGeometry(
        width=width,
        height=height,
        hfov=1.047,
        mount_forward=0.1,
        mount_height=0.3,
        tilt=0.0,
        wheel_radius=0.035,
        wheel_separation=0.23,
    )


def bench_bag(records, geometry, folder):
    """Per-call seconds of ``log_frame``, the seconds of opening plus closing the bag (once
    per run: the connections, the MCAP summary, the rename) and the CPU seconds per frame."""
    path = Path(folder) / f"bag-{time.monotonic_ns()}"
    t0 = time.perf_counter()
    writer = BagWriter(path, geometry)
    fixed = time.perf_counter() - t0
    times = []
    cpu0 = time.thread_time()
    for r in records:
        t0 = time.perf_counter()
        writer.log_frame(r)
        times.append(time.perf_counter() - t0)
    cpu = (time.thread_time() - cpu0) / len(records)
    t0 = time.perf_counter()
    writer.close()
    fixed += time.perf_counter() - t0
    shutil.rmtree(path)
    return times, fixed, cpu


class _Client(threading.Thread):
    """One Foxglove WebSocket client subscribed to every topic, counting what it receives."""

    def __init__(self, port):
        super().__init__(daemon=True)
        self.port = port
        self.received = 0
        self.subscribed = threading.Event()
        self.stop = threading.Event()
        self.error = None

    def run(self):
        try:
            with connect(
                f"ws://127.0.0.1:{self.port}", subprotocols=["foxglove.sdk.v1"], open_timeout=5
            ) as ws:
                channels = {}

                while len(channels) < len(TOPICS):
                    msg = json.loads(ws.recv(timeout=5))
                    if msg.get("op") == "advertise":
                        channels.update({c["topic"]: c["id"] for c in msg["channels"]})
                ws.send(
                    json.dumps(
                        {
                            "op": "subscribe",
                            "subscriptions": [
                                {"id": i, "channelId": cid}
                                for i, cid in enumerate(channels.values())
                            ],
                        }
                    )
                )
                time.sleep(0.3)  # the server takes the subscription
                self.subscribed.set()
                while not self.stop.is_set():
                    with contextlib.suppress(TimeoutError):
                        if isinstance(ws.recv(timeout=0.2), bytes):
                            self.received += 1
        except Exception as exc:  # noqa: BLE001 - reported by the benchmark
            self.error = exc
            self.subscribed.set()


def bench_live(records, geometry, fps=30.0):
    """Per-call seconds of ``LivePublisher.log_frame`` with one client; messages sent and
    received."""
    live = LivePublisher(0, geometry)
    client = _Client(live.port)
    client.start()
    try:
        if not client.subscribed.wait(10) or client.error is not None:
            raise UsageError(
                f"bench ros: the benchmark's client could not subscribe ({client.error})"
            )
        sent = sum(len(FrameMessages(geometry).encode(r)) for r in records)
        times = []
        start = time.perf_counter()
        for k, r in enumerate(records):
            t0 = time.perf_counter()
            live.log_frame(r)
            times.append(time.perf_counter() - t0)
            ahead = start + (k + 1) / fps - time.perf_counter()
            if ahead > 0:
                time.sleep(ahead)
        time.sleep(0.5)  # what is in flight arrives
    finally:
        client.stop.set()
        client.join(2)
        live.close()
    return times, sent, client.received


def _options(p):
    p.add_argument("--resolution", default="160x120", metavar="WxH")
    p.add_argument("--only", choices=("bag", "live"), help="run one of the two")


def run(args):
    width, height = scaffold.parse_size(args.resolution, "--resolution")
    figures = {}
    records = make_records(width, height, args.frames)
    geometry = _geometry(width, height)
    print(
        f"ROS outputs per {width}x{height} frame ({args.frames} frames, median of "
        f"{args.repeats} runs)"
    )
    if args.only in (None, "bag"):
        folder = tempfile.mkdtemp(prefix="fpga-ros-bench-")
        try:
            runs = [bench_bag(records, geometry, folder) for _ in range(args.repeats)]
        finally:
            shutil.rmtree(folder, ignore_errors=True)
        call = statistics.median(statistics.median(t) for t, _, _ in runs)
        mean = statistics.median(statistics.fmean(t[1:] or t) for t, _, _ in runs)
        first = statistics.median(t[0] for t, _, _ in runs)
        fixed = statistics.median(f for _, f, _ in runs)
        cpu = statistics.median(c for _, _, c in runs)
        figures["bag"] = {
            "call_median_ms": 1000 * call,
            "call_mean_ms": 1000 * mean,
            "cpu_ms": 1000 * cpu,
            "first_call_ms": 1000 * first,
            "open_close_ms": 1000 * fixed,
        }
        print(
            f"  bag  (--bag): log_frame median {1000 * call:.3f} ms, mean {1000 * mean:.3f} "
            f"ms after the first, CPU {1000 * cpu:.3f} ms/frame; the first call "
            f"{1000 * first:.1f} ms; opening and closing the bag {1000 * fixed:.1f} ms once"
        )
    if args.only in (None, "live"):
        runs = [bench_live(records, geometry) for _ in range(args.repeats)]
        call = statistics.median(statistics.median(t) for t, _, _ in runs)
        sent = sum(s for _, s, _ in runs)
        got = sum(g for _, _, g in runs)
        figures["live"] = {"call_median_ms": 1000 * call, "sent": sent, "received": got}
        print(
            f"  live (--live foxglove, one client): log_frame median {1000 * call:.3f} ms; "
            f"client received {got}/{sent} messages"
        )
    return figures


main = scaffold.command(run, __doc__, name="ros", options=_options, repeats=3, frames=120)
