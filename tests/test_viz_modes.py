"""Viewer modes: parsing, bad strings, and falling back to a file when no viewer can show the run."""

import os
import signal
import socket
import sys
from urllib.parse import parse_qs, urlsplit

import numpy as np
import pytest

from fpga_robotics.sim.backends.base import FrameResult
from fpga_robotics.sim.records import FrameRecord
from fpga_robotics.viz import ViewerError, open_recorder, parse_mode, sinks, viewers
from fpga_robotics.viz import paths as P
from fpga_robotics.viz.modes import DEFAULT_CONNECT_URL, display_available
from fpga_robotics.viz.net import port_is_listening
from fpga_robotics.viz.readback import read_rrd


def frame(i):
    result = FrameResult(
        filtered=np.zeros((24, 32), np.uint16),
        found=False,
        proximity=0,
        centroid_x=0,
        centroid_leds=0,
        motor_left=10 * i,
        motor_right=-10 * i,
        cycles=1,
    )
    return FrameRecord(
        frame=i,
        sim_time=0.1 * i,
        camera_rgb=np.full((24, 32, 3), i, np.uint8),
        color_sel=4,
        result=result,
        robot_x=0.0,
        robot_y=0.0,
        robot_heading=0.0,
        robot_v=0.0,
        robot_w=0.0,
        cmd_v=0.0,
        cmd_w=0.0,
        camera_hfov=1.0,
    )


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(autouse=True)
def private_ports(monkeypatch):
    # Never rerun's default ports: a developer's viewer or another run may be using them.
    monkeypatch.setattr(sinks, "SERVE_GRPC_PORT", free_port())
    monkeypatch.setattr(sinks, "SERVE_WEB_PORT", free_port())


@pytest.mark.parametrize(
    "text, kind, path, url",
    [
        ("save:out/run.rrd", "save", "out/run.rrd", None),
        ("save", "save", "d.rrd", None),
        ("SPAWN", "spawn", "d.rrd", None),
        ("connect", "connect", "d.rrd", DEFAULT_CONNECT_URL),
        (
            "connect:rerun+http://10.0.0.2:9000/proxy",
            "connect",
            "d.rrd",
            "rerun+http://10.0.0.2:9000/proxy",
        ),
        ("serve", "serve", "d.rrd", None),
        ("serve:127.0.0.1", "serve", "d.rrd", None),
        ("off", "off", "d.rrd", None),
    ],
)
def test_parse_valid_modes(text, kind, path, url):
    mode = parse_mode(text, "d.rrd")
    assert (mode.kind, mode.path, mode.url) == (kind, path, url)


@pytest.mark.parametrize(
    "text, hint",
    [
        ("", "unknown viewer mode"),
        ("sav", "unknown viewer mode"),
        ("show", "save:PATH.rrd"),
        ("save:", "empty"),
        ("save:run.txt", "does not end in .rrd"),
        ("spawn:now", "takes no argument"),
        ("off:1", "takes no argument"),
        ("connect:http://localhost:9876", "not a rerun viewer URL"),
        ("connect:rerun+http://localhost:port/proxy", "port"),
        ("serve:999.1.1.1", "not an IP address"),
        ("serve:192.0.2.1", "not an address of this machine"),  # TEST-NET-1: never local
        (42, "must be a string"),
    ],
)
def test_bad_modes_are_usage_errors(text, hint):
    with pytest.raises(ViewerError, match=hint):
        parse_mode(text, "d.rrd")


@pytest.mark.parametrize(
    "kwargs",
    [
        {"log_every": 0},
        {"log_every": "2"},
        {"log_every": True},
        {"jpeg_quality": 101},
        {"jpeg_quality": -1},
        {"jpeg_quality": "high"},
    ],
)
def test_bad_options_are_usage_errors(kwargs, tmp_path):
    with pytest.raises(ViewerError):
        open_recorder("off", default_path=str(tmp_path / "x.rrd"), **kwargs)


def test_auto_picks_spawn_only_with_a_display():
    no_display = {"HOME": "/root"}
    assert not display_available(no_display, "linux")
    assert parse_mode("auto", "d.rrd", environ=no_display, platform="linux").kind == "save"
    assert parse_mode(None, "d.rrd", environ=no_display, platform="linux").path == "d.rrd"
    for env in ({"DISPLAY": ":0"}, {"WAYLAND_DISPLAY": "wayland-0"}):
        assert parse_mode("auto", "d.rrd", environ=env, platform="linux").kind == "spawn"
    assert display_available({}, "darwin")


def no_viewer_running(monkeypatch):
    # A viewer somebody left open on the default port would be reused: pretend there is none.
    monkeypatch.setattr(sinks, "port_is_listening", lambda *a, **k: False)


def test_spawn_without_display_saves_to_the_default_file(tmp_path, monkeypatch, capsys):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    no_viewer_running(monkeypatch)
    path = tmp_path / "fallback.rrd"
    rec = open_recorder("spawn", default_path=str(path))
    assert rec.mode == "save"
    assert "no display" in " ".join(rec.pop_notices())
    assert capsys.readouterr().err == ""  # told through notices, never printed
    for i in range(3):
        rec.log_frame(frame(i))
    msg = rec.close()
    assert "spawn" in msg and "no display" in msg and "saved" in msg and str(path) in msg
    assert read_rrd(str(path)).entities[P.MOTORS_DPS].frames == [0, 1, 2]


def test_spawn_whose_viewer_fails_saves_to_the_default_file(tmp_path, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")
    no_viewer_running(monkeypatch)
    failing = [sys.executable, "-c", "import sys; sys.exit('Error: Failed to open X server')"]
    monkeypatch.setattr(viewers, "viewer_command", lambda port: failing)
    path = tmp_path / "fallback.rrd"
    rec = open_recorder("spawn", default_path=str(path))
    rec.log_frame(frame(0))
    msg = rec.close()
    assert "exited with code 1" in msg and "Failed to open X server" in msg
    assert path.exists()


def test_spawn_without_any_file_to_fall_back_on_is_a_usage_error(monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    monkeypatch.setattr(sys, "platform", "linux")
    no_viewer_running(monkeypatch)
    with pytest.raises(ViewerError, match="save:PATH.rrd"):
        open_recorder("spawn", default_path=None)


def test_spawn_starts_a_viewer_and_streams_to_it(tmp_path, monkeypatch):
    # A gRPC-only rerun stands in for the viewer window (no display or GPU needed).
    monkeypatch.setenv("DISPLAY", ":99")
    port = free_port()
    monkeypatch.setattr(sinks, "VIEWER_PORT", port)
    real_command = viewers.viewer_command
    monkeypatch.setattr(viewers, "viewer_command", lambda p: [*real_command(p), "--serve-grpc"])
    rec = open_recorder("spawn", default_path=str(tmp_path / "unused.rrd"))
    try:
        assert rec.mode == "spawn" and rec.viewer_pid is not None
        assert port_is_listening("127.0.0.1", port)
        rec.log_frame(frame(0))
        msg = rec.close()
        assert f"port {port}" in msg and "1 frames" in msg
        assert not (tmp_path / "unused.rrd").exists()
    finally:
        if rec.viewer_pid is not None:
            os.kill(
                rec.viewer_pid, signal.SIGKILL
            )  # the viewer ignores SIGTERM while a client is connected


def test_connect_streams_to_a_listening_viewer(tmp_path):
    server = open_recorder("serve", default_path=str(tmp_path / "a.rrd"))
    try:
        url = server.live_url
        rec = open_recorder(f"connect:{url}", default_path=str(tmp_path / "b.rrd"))
        assert rec.mode == "connect"
        rec.log_frame(frame(0))
        assert f"to the rerun viewer at {url}" in rec.close()
        assert rec.delivered
    finally:
        server.close()
    assert not (tmp_path / "b.rrd").exists()  # delivered: the copy is not kept


def test_connect_with_nobody_listening_saves_to_the_default_file(tmp_path):
    url = f"rerun+http://127.0.0.1:{free_port()}/proxy"
    path = tmp_path / "fallback.rrd"
    rec = open_recorder(f"connect:{url}", default_path=str(path))
    assert rec.mode == "save"
    rec.log_frame(frame(0))
    msg = rec.close()
    assert "no rerun viewer is listening at 127.0.0.1:" in msg and path.exists()


def test_serve_hosts_grpc_and_web_viewer_and_keeps_a_copy(tmp_path, capsys):
    copy = tmp_path / "copy.rrd"
    rec = open_recorder("serve", default_path=str(copy))
    try:
        assert rec.mode == "serve"
        grpc = urlsplit(rec.live_url)
        assert grpc.scheme == "rerun+http" and grpc.path == "/proxy"
        assert port_is_listening("127.0.0.1", grpc.port)
        web = urlsplit(rec.web_url)
        assert port_is_listening("127.0.0.1", web.port)
        assert parse_qs(web.query)["url"] == [rec.live_url]
        told = " ".join(rec.pop_notices())  # told when it starts, not printed
        assert rec.live_url in told and "this machine only" in told
        assert capsys.readouterr().err == ""
        rec.log_frame(frame(0))
    finally:
        msg = rec.close()
    assert "1 frames" in msg and f"saved to {copy}" in msg and f"rerun {copy}" in msg
    assert read_rrd(str(copy)).entities[P.MOTORS_DPS].frames == [0]
    assert not port_is_listening("127.0.0.1", grpc.port)  # stopped with the run
    assert not port_is_listening("127.0.0.1", web.port)
