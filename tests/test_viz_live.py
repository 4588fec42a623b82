"""Live viewers that do not answer, answer wrongly or stall: the run never hangs, the data is
kept in a file and the user is told where; ``serve`` listens on this machine only by default.

Every server here is in this process, on 127.0.0.1, torn down by its fixture; every wait is
bounded (subprocess timeouts, and a watchdog for the process itself).
"""

import faulthandler
import http.server
import ipaddress
import os
import signal
import socket
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest
from terminal_signals import FROM_A_TERMINAL

from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.records import FrameRecord
from fpga_robotics.viz import ViewerError, live, open_recorder, parse_mode, sinks
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.readback import read_rrd

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SETTINGS = bytes([0, 0, 0, 0x4, 0, 0, 0, 0, 0])  # an empty HTTP/2 SETTINGS frame


@pytest.fixture(autouse=True)
def watchdog():
    # The bug class under test is a hang: end the session with tracebacks rather than never.
    faulthandler.dump_traceback_later(300, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


@pytest.fixture(autouse=True)
def private_ports(monkeypatch):
    monkeypatch.setattr(sinks, "SERVE_GRPC_PORT", free_port())
    monkeypatch.setattr(sinks, "SERVE_WEB_PORT", free_port())


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def frame(i, w=160, h=120):
    result = FrameResult(
        filtered=np.zeros((h, w), np.uint16), found=False, proximity=0, centroid_x=0,
        centroid_leds=0, motor_left=i, motor_right=-i, cycles=1,
    )  # fmt: skip
    rng = np.random.default_rng(i)  # noise: rerun cannot compress it below the flow window
    return FrameRecord(
        frame=i, sim_time=i / 30, camera_rgb=rng.integers(0, 256, (h, w, 3), np.uint8),
        color_sel=4, result=result, robot_x=0.0, robot_y=0.0, robot_heading=0.0, robot_v=0.0,
        robot_w=0.0, cmd_v=0.0, cmd_w=0.0, camera_hfov=1.0,
    )  # fmt: skip


def frames_in(path):
    return read_rrd(str(path)).entities[P.MOTORS_DPS].frames


class Server:
    """A TCP server on 127.0.0.1 that accepts and then, per ``greeting``, says that much (or
    nothing) and never reads: a port that never answers, or a viewer that stalls."""

    def __init__(self, greeting=None):
        self.sock = socket.create_server(("127.0.0.1", 0))
        self.port = self.sock.getsockname()[1]
        self.url = f"rerun+http://127.0.0.1:{self.port}/proxy"
        self.greeting = greeting
        self.conns = []
        self._stop = False
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self):
        self.sock.settimeout(0.1)
        while not self._stop:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                continue
            self.conns.append(conn)
            if self.greeting:
                conn.sendall(self.greeting)

    def close(self):
        self._stop = True
        self.thread.join(5)
        for c in self.conns:
            c.close()
        self.sock.close()


@pytest.fixture
def silent_port():
    server = Server()
    yield server
    server.close()


@pytest.fixture
def stalled_viewer():
    # Answers like a gRPC server (so the first check passes), then never reads: the
    # stream's flow-control window fills and rerun waits for ever.
    server = Server(SETTINGS)
    yield server
    server.close()


@pytest.fixture
def web_server(tmp_path):
    handler = lambda *a: http.server.SimpleHTTPRequestHandler(*a, directory=str(tmp_path))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    server.url = f"rerun+http://127.0.0.1:{server.server_address[1]}/proxy"
    yield server
    server.shutdown()
    server.server_close()
    thread.join(5)


def run_cli(args, cwd, timeout=180):
    proc = subprocess.run(
        [sys.executable, "-m", "fpga_robotics.run", "--backend", "model", "--quiet", *args],
        cwd=cwd, capture_output=True, text=True, timeout=timeout, check=False,
    )  # fmt: skip
    return proc


# A viewer that is not there, or not a viewer ----------------------------------------------------


@pytest.mark.parametrize("peer", ["silent_port", "web_server"])
def test_connect_to_something_that_is_not_a_viewer_saves_to_a_file(peer, tmp_path, request):
    server = request.getfixturevalue(peer)
    default = tmp_path / "runs" / "run.rrd"
    rec = open_recorder(f"connect:{server.url}", default_path=str(default))
    assert rec.mode == "save"
    told = " ".join(rec.pop_notices())
    assert f"the recording goes to {default} instead" in told
    assert ("did not answer" if peer == "silent_port" else "not like a rerun viewer") in told
    for i in range(5):
        rec.log_frame(frame(i))
    msg = rec.close()
    assert "saved 5 frames" in msg and f"rerun {default}" in msg
    assert frames_in(default) == list(range(5))


def test_without_a_default_path_an_unreachable_viewer_is_an_error(silent_port):
    with pytest.raises(ViewerError, match="did not answer.*save:PATH.rrd"):
        open_recorder(f"connect:{silent_port.url}", default_path=None)


@pytest.mark.parametrize("peer", ["silent_port", "web_server"])
def test_the_command_line_finishes_and_says_where_the_data_is(peer, tmp_path, request):
    # Issue 11's report: this ran forever, ignoring Ctrl-C, with no verdict and no summary.
    server = request.getfixturevalue(peer)
    proc = run_cli(
        ["--duration", "3", "--rerun", f"connect:{server.url}", "--summary", "s.json"], tmp_path
    )
    assert proc.returncode in (0, 1), proc.stderr
    assert (tmp_path / "s.json").exists()
    saved = tmp_path / "runs" / "follow_person.rrd"
    assert f"rerun {os.path.join('runs', 'follow_person.rrd')}" in proc.stdout
    assert len(frames_in(saved)) == 90
    assert os.listdir(saved.parent) == ["follow_person.rrd"]


# A viewer that stalls or goes away during the run ------------------------------------------------


def test_a_viewer_that_stalls_costs_bounded_time_and_the_copy_is_kept(
    stalled_viewer, tmp_path, monkeypatch
):
    monkeypatch.setattr(live, "FLUSH_TIMEOUT_S", 1.0)
    monkeypatch.setattr(live, "DISCONNECT_TIMEOUT_S", 1.0)
    default = tmp_path / "run.rrd"
    rec = open_recorder(f"connect:{stalled_viewer.url}", default_path=str(default))
    assert rec.mode == "connect"
    for i in range(40):
        rec.log_frame(frame(i))
    msg = rec.close()
    assert rec.delivered is False
    assert "did not take all the data" in msg and f"saved to {default}" in msg
    assert rec.path == str(default) and frames_in(default) == list(range(40))
    assert os.listdir(tmp_path) == ["run.rrd"]


def test_the_command_line_with_a_stalled_viewer_finishes(stalled_viewer, tmp_path):
    proc = run_cli(
        ["--duration", "3", "--rerun", f"connect:{stalled_viewer.url}", "--summary", "s.json"],
        tmp_path,
    )
    assert proc.returncode in (0, 1), proc.stderr
    assert (tmp_path / "s.json").exists()
    assert "not every frame may have reached it" in proc.stdout
    assert len(frames_in(tmp_path / "runs" / "follow_person.rrd")) == 90


@pytest.fixture
def viewer_process():
    # A real rerun gRPC server in its own process, on this machine only, that a test can kill.
    from fpga_robotics.viz.net import port_is_listening
    from fpga_robotics.viz.viewers import viewer_command

    port = free_port()
    proc = subprocess.Popen(
        [*viewer_command(port), "--serve-grpc"],
        stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, **FROM_A_TERMINAL
    )  # fmt: skip
    try:
        for _ in range(600):
            if port_is_listening("127.0.0.1", port) or proc.poll() is not None:
                break
            time.sleep(0.05)
        assert port_is_listening("127.0.0.1", port), "the rerun server did not start"
        proc.url = f"rerun+http://127.0.0.1:{port}/proxy"
        yield proc
    finally:
        proc.kill()
        proc.wait(30)


def test_a_viewer_that_goes_away_mid_run_leaves_a_full_copy(viewer_process, tmp_path):
    default = tmp_path / "run.rrd"
    rec = open_recorder(f"connect:{viewer_process.url}", default_path=str(default))
    assert rec.mode == "connect"
    for i in range(10):
        rec.log_frame(frame(i, 32, 24))
    rec._columns.flush()
    viewer_process.kill()  # the viewer goes away
    viewer_process.wait(30)
    for i in range(10, 20):
        rec.log_frame(frame(i, 32, 24))
    msg = rec.close()
    assert rec.delivered is False and "not every frame may have reached it" in msg
    assert frames_in(default) == list(range(20))


def test_a_call_blocked_on_a_stalled_viewer_gets_it_cut_off(silent_port, monkeypatch):
    from fpga_robotics.viz.sockets import Connections

    monkeypatch.setattr(live, "STALL_TIMEOUT_S", 0.5)
    connections = Connections(silent_port.port, "127.0.0.1")
    client = socket.create_connection(("127.0.0.1", silent_port.port), timeout=60)
    watch = live.StallWatch(connections.sever)
    try:
        with watch:
            pass  # a quick call: nothing happens
        assert not watch.stalled and connections.alive() == 1
        with watch:  # stands for a logging call stuck in rerun's native code
            got = client.recv(1)  # returns only when the watch cuts the connection
        assert watch.stalled and got == b"" and connections.alive() == 0
    finally:
        watch.stop()
        client.close()


@pytest.mark.slow  # fills rerun's queues: a few hundred MB through memory and the disk
def test_a_viewer_that_stalls_mid_run_does_not_stop_the_run(stalled_viewer, tmp_path, monkeypatch):
    import dataclasses

    monkeypatch.setattr(live, "STALL_TIMEOUT_S", 1.0)
    monkeypatch.setattr(live, "FLUSH_TIMEOUT_S", 1.0)
    default = tmp_path / "run.rrd"
    rec = open_recorder(f"connect:{stalled_viewer.url}", default_path=str(default), jpeg_quality=0)
    frames = [frame(i, 640, 480) for i in range(4)]  # raw noise: ~0.9 MB a frame
    n = 0
    while n < 600 and not rec._output.link.watch.stalled:
        rec.log_frame(dataclasses.replace(frames[n % 4], frame=n))
        n += 1
    for i in range(n, n + 10):  # the run goes on after the viewer was cut off
        rec.log_frame(dataclasses.replace(frames[i % 4], frame=i))
    msg = rec.close()
    assert "stopped taking data for 1 s during the run and was cut off" in msg
    assert frames_in(default) == list(range(n + 10))
    default.unlink()  # hundreds of MB: not left for pytest's kept temporary folders


STALLED_CLOSE = textwrap.dedent(
    """
    import sys
    sys.path.insert(0, {tests!r})
    from test_viz_live import frame
    from fpga_robotics.viz import open_recorder

    rec = open_recorder({mode!r}, default_path={default!r})
    try:
        for i in range(40):
            rec.log_frame(frame(i))
        print("closing", flush=True)
    finally:
        rec.close()
    """
)


def test_ctrl_c_while_closing_on_a_stalled_viewer(stalled_viewer, tmp_path):
    default = tmp_path / "run.rrd"
    script = STALLED_CLOSE.format(
        tests=os.path.join(ROOT, "tests"), mode=f"connect:{stalled_viewer.url}",
        default=str(default),
    )  # fmt: skip
    proc = subprocess.Popen(
        [sys.executable, "-c", script],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        **FROM_A_TERMINAL,
    )
    try:
        assert proc.stdout.readline().strip() == "closing", proc.stderr.read()
        proc.send_signal(signal.SIGINT)  # while close() waits for the stalled viewer
        _out, err = proc.communicate(timeout=60)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    # Python ends on an uncaught KeyboardInterrupt by SIGINT itself, after the finally blocks.
    assert proc.returncode == -signal.SIGINT and "KeyboardInterrupt" in err
    assert os.listdir(tmp_path) == ["run.rrd"] and frames_in(default) == list(range(40))


# Where serve listens --------------------------------------------------------------------------


def listening_addresses(port):
    """The addresses sockets of this machine listen on at ``port`` (Linux: /proc/net)."""
    found = set()
    for name, v6 in (("/proc/net/tcp", False), ("/proc/net/tcp6", True)):
        with open(name) as f:
            rows = [line.split() for line in f.read().splitlines()[1:]]
        for row in rows:
            address, hex_port = row[1].split(":")
            if row[3] != "0A" or int(hex_port, 16) != port:  # 0A: LISTEN
                continue
            raw = bytes.fromhex(address)
            if v6:
                words = b"".join(raw[i : i + 4][::-1] for i in range(0, 16, 4))
                found.add(str(ipaddress.IPv6Address(words)))
            else:
                found.add(str(ipaddress.IPv4Address(raw[::-1])))
    return found


@pytest.mark.skipif(not os.path.exists("/proc/net/tcp"), reason="reads /proc/net/tcp")
@pytest.mark.parametrize("mode", ["serve", "serve:127.0.0.1"])
def test_serve_listens_on_this_machine_only(mode, tmp_path):
    rec = open_recorder(mode, default_path=str(tmp_path / "copy.rrd"))
    try:
        grpc_port = int(rec.live_url.rsplit(":", 1)[1].split("/")[0])
        web_port = int(rec.web_url.split(":")[2].split("/")[0])
        assert listening_addresses(grpc_port) == {"127.0.0.1"}
        assert listening_addresses(web_port) == {"127.0.0.1"}
    finally:
        rec.close()


def test_serve_takes_an_address_to_listen_on():
    assert parse_mode("serve", "d.rrd").bind == "127.0.0.1"
    assert parse_mode("serve:0.0.0.0", "d.rrd").bind == "0.0.0.0"
    assert parse_mode("serve:::1", "d.rrd").bind == "::1"
    with pytest.raises(ViewerError, match="not an IP address"):
        parse_mode("serve:everywhere", "d.rrd")
