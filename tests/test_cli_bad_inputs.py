"""Bad command-line input to every subcommand: exit code 2, one line on stderr naming the
problem, no traceback, nothing written or replaced, and no design model built first.

Each case runs ``fpga-robotics ...`` in-process in an empty working folder that holds only
what the case prepares, with no terminal on standard input; afterwards the folder must hold
exactly that again, and a device given as an output must still be a device. Every output and
optional dependency is checked before the work: building a model (or any simulator other than
the numpy model) fails the case.
"""

import io
import os
import socket
import stat
import sys

import numpy as np
import pytest

from fpga_robotics import cli

#: Designs of one's own the cases name.
DESIGNS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data", "user_designs")

#: (case id, argv, a word the message must contain). ``{dir}``, ``{file}``, ``{frames}`` are
#: an existing folder, an existing regular file and a folder of two PNG frames; ``{latin1}`` a
#: TOML file with a Latin-1 byte in a comment.
CASES = [
    ("no command", [], "command"),
    ("port map not UTF-8", ["ports", "{latin1}"], "not UTF-8 text (byte 0xe9 at position 5)"),
    ("scenario not UTF-8", ["run", "--scenario", "{latin1}"], "not UTF-8"),
    ("campaign not UTF-8", ["sweep", "{latin1}", "--dry-run"], "not UTF-8"),
    ("unknown command", ["fly"], "unknown command"),
    ("unknown benchmark", ["bench", "gpu"], "unknown benchmark"),
    ("formal ports without a design", ["formal", "--ports", "{file}"], "--ports"),
    ("formal list with a depth", ["formal", "--list", "--depth", "3"], "got --depth"),
    (
        "list scenarios with run options",
        ["run", "--list-scenarios", "--duration", "-5", "--summary", "ls.json"],
        "--list-scenarios takes no other option; got --duration, --summary",
    ),
    (
        "designs ports of an Amaranth design",
        ["designs", "follow_target", "--ports", "{file}"],
        "--ports",
    ),
    ("mutate fork without a campaign", ["mutate", "--mutants", "2", "--no-fork"], "--campaign"),
    (
        "mutate recordings without a campaign",
        ["mutate", "--mutants", "2", "--recordings", "3"],
        "--recordings go with --campaign",
    ),
    ("bench negative seed", ["bench", "design", "--backends", "model", "--seed", "-1"], "--seed"),
    ("bench empty backends", ["bench", "design", "--backends", ","], "--backends"),
    (
        "bench resolution the design refuses",
        ["bench", "design", "--backends", "model", "--resolutions", "160x120,1x1"],
        "1x1",
    ),
    ("bench negative pysim pixels", ["bench", "design", "--pysim-max-pixels", "-5"], "pixels"),
    ("bench render3d unknown backend", ["bench", "render3d", "--backend", "foo"], "--backend"),
    ("bench mutant_replay negative seed", ["bench", "mutant_replay", "--seed", "-1"], "--seed"),
    # run: outputs checked before the run, never replaced when not a regular file
    ("summary to a device", ["run", "--summary", "/dev/full"], "not a regular file"),
    ("summary to a folder", ["run", "--summary", "{dir}"], "is a folder"),
    ("summary below a file", ["run", "--summary", "{file}/s.json"], "not a folder"),
    ("empty summary path", ["run", "--summary", ""], "empty"),
    ("negative seed", ["run", "--seed", "-1"], "--seed"),
    ("zero duration", ["run", "--duration", "0"], "--duration"),
    ("nan duration", ["run", "--duration", "nan"], "--duration"),
    ("max-frames without source", ["run", "--max-frames", "5"], "--source"),
    ("duration with source", ["run", "--source", "{frames}", "--duration", "1"], "--duration"),
    # the simulated world's options, which real frames would take and drop
    ("seed with source", ["run", "--source", "{frames}", "--seed", "3"], "--seed fixes the"),
    ("realtime with source", ["run", "--source", "{frames}", "--realtime"], "--realtime paces"),
    (
        "colour of a design without a camera",
        ["run", "--scenario", "line_track", "--color", "green"],
        "no camera input",
    ),
    (
        "colour of a design of one's own without a camera",
        ["run", "--scenario", os.path.join(DESIGNS, "wall_stop.toml"), "--color", "green"],
        "no camera input",
    ),
    (
        "colour of a camera design without a colour select (it was ignored)",
        ["run", "--scenario", os.path.join(DESIGNS, "red_frames.toml"), "--color", "green"],
        "RedFrames (scenario 'red_frames') has none (a color_sel input; in a port map, [color])",
    ),
    (
        "colour of a Verilog design without a camera",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--design",
            "verilog:" + os.path.join(DESIGNS, "bump_stop_noreset.v"),
            "--ports",
            os.path.join(DESIGNS, "bump_stop_noreset_ports.toml"),
            "--color",
            "green",
        ],
        "no camera input",
    ),
    (
        "a sensor pin the Verilog design does not bind",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--design",
            "verilog:" + os.path.join(DESIGNS, "bump_stop_noreset.v"),
            "--ports",
            os.path.join(DESIGNS, "bump_stop_noreset_ports.toml"),
        ],
        "has no port for its pin 'trig'",
    ),
    (
        "parameter shadow in real-clock timing",
        ["run", "--scenario", "line_track", "--shadow", "diff_min=5"],
        "real-clock timing, where --shadow takes a design reference",
    ),
    ("negative max-frames", ["run", "--source", "{frames}", "--max-frames", "-1"], "--max-frames"),
    ("log-every zero", ["run", "--log-every", "0", "--rerun", "save:x.rrd"], "--log-every"),
    # run: options that would do nothing
    ("log-every without a recording", ["run", "--log-every", "5", "--rerun", "off"], "--log-every"),
    (
        "camera format without a recording",
        ["run", "--record-camera", "rgb888", "--rerun", "off"],
        "--record-camera",
    ),
    ("shadow backend without a shadow", ["run", "--shadow-backend", "model"], "give --shadow"),
    ("unknown backend", ["run", "--backend", "iverilog"], "invalid choice"),
    ("unknown camera format", ["run", "--record-camera", "rgb565"], "invalid choice"),
    ("video with no codec", ["run", "--save-video", "clip.mkv"], ".mp4"),
    ("video to a folder", ["run", "--save-video", "{dir}"], "is a folder"),
    ("shadow with nothing", ["run", "--shadow", ";"], "--shadow"),
    ("shadow with an unknown key", ["run", "--shadow", "frob=1"], "design.frob"),
    ("shadow with a bad value", ["run", "--shadow", "diff_min=99"], "--shadow diff_min=99: design"),
    (
        "shadow of another built-in in compressed timing",
        ["run", "--shadow", "top=follow_line"],
        "--shadow top=follow_line: in compressed timing the shadow is FollowTarget",
    ),
    (
        "preset shadow in real-clock timing",
        ["run", "--scenario", os.path.join(DESIGNS, "wall_stop.toml"), "--shadow", "published"],
        "--shadow published: a preset or KEY=VALUE items shadow FollowTarget",
    ),
    # Beside a design of one's own the shadow would be FollowTarget, not that design: under
    # auto the reason was an untrue "runs in real-clock timing", compressed compared silently.
    *(
        (
            f"preset shadow beside a camera design of one's own ({timing})",
            [
                "run",
                "--scenario",
                os.path.join(DESIGNS, "red_frames.toml"),
                "--shadow",
                "published;diff_min=5",
                *sets,
            ],
            (
                "--shadow published;diff_min=5: a preset or KEY=VALUE items shadow FollowTarget "
                "with other parameters; the design here is "
                + os.path.join(DESIGNS, "red_frames.py")
                + ":RedFrames: shadow it with a design reference, --shadow "
                + os.path.join(DESIGNS, "red_frames.py")
                + ":RedFrames --shadow-param NAME=VALUE"
            ),
        )
        for timing, sets in (("auto", []), ("compressed", ["--set", 'sim.timing="compressed"']))
    ),
    (
        "shadow design file missing",
        ["run", "--scenario", os.path.join(DESIGNS, "wall_stop.toml"), "--shadow", "no.py:X"],
        "--shadow no.py:X: design",
    ),
    (
        "shadow design param it does not take",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--shadow",
            os.path.join(DESIGNS, "wall_stop.py") + ":WallStop",
            "--shadow-param",
            "stop_cm=10",
        ],
        "--shadow-param stop_cm: ",
    ),
    (
        "shadow design param of a bad type",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--shadow",
            os.path.join(DESIGNS, "wall_stop.py") + ":WallStop",
            "--shadow-param",
            "stop_mm=near",
        ],
        "--shadow-param stop_mm must be an integer",
    ),
    (
        "shadow param of a built-in shadow",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--shadow",
            "follow_target",
            "--shadow-param",
            "diff_min=5",
        ],
        "the built-in design 'follow_target' takes its parameters from the scenario's [design]",
    ),
    ("shadow param without a shadow design", ["run", "--shadow-param", "a=1"], "--shadow FILE.py"),
    (
        "shadow param of a preset shadow",
        ["run", "--shadow", "published", "--shadow-param", "a=1"],
        "--shadow-param gives a shadow design its parameters",
    ),
    ("shadow with --source", ["run", "--source", "{frames}", "--shadow", "diff_min=5"], "--shadow"),
    (
        "shadow design on the model backend",
        [
            "run",
            "--scenario",
            os.path.join(DESIGNS, "wall_stop.toml"),
            "--shadow",
            os.path.join(DESIGNS, "wall_stop.py") + ":WallStop",
            "--shadow-backend",
            "model",
        ],
        "--shadow-backend model runs whole frames",
    ),
    (
        "video with --source",
        ["run", "--source", "{frames}", "--save-video", "clip.mp4"],
        "--save-video",
    ),
    (
        "target colour without a target",
        ["run", "--set", "people=[]", "--target-color", "green"],
        "no target",
    ),
    # run: ROS bags in and out, live control (issue 16); {bag} is a ROS 2 bag of two
    # 32FC1 images on /cam, {emptybag} one whose only image topic has no messages
    ("bag source with a missing topic", ["run", "--source", "bag:{bag}:/nope"], "no topic"),
    (
        "bag source with a bad encoding",
        ["run", "--source", "bag:{bag}", "--backend", "model"],
        "32FC1",
    ),
    ("empty bag source", ["run", "--source", "bag:{emptybag}"], "no messages"),
    ("missing bag source", ["run", "--source", "bag:nothing_here"], "no such bag"),
    ("bag out over a file", ["run", "--bag", "{file}"], "--bag"),
    ("bag out over a folder", ["run", "--bag", "{dir}"], "not a ROS 2 bag"),
    ("live with a bad kind", ["run", "--live", "rviz"], "--live"),
    ("live with a bad port", ["run", "--live", "foxglove:99999"], "port"),
    ("live on a port in use", ["run", "--live", "foxglove:{busyport}"], "cannot serve"),
    ("replay of a missing file", ["run", "--replay-inputs", "nope.json"], "no such file"),
    ("replay of a bad input", ["run", "--replay-inputs", "{file}"], "JSON"),
    (
        "replay with live",
        ["run", "--replay-inputs", "{file}", "--live", "foxglove"],
        "does not go with",
    ),
    ("interactive with source", ["run", "--source", "{frames}", "--interactive"], "--interactive"),
    ("live with a file source", ["run", "--source", "{frames}", "--live", "foxglove:0"], "camera"),
    (
        "paused with source",
        ["run", "--source", "{frames}", "--live", "foxglove:0", "--paused"],
        "--paused",
    ),
    ("paused alone", ["run", "--paused"], "--paused"),
    ("bag out where nothing can be written", ["run", "--bag", "/proc/bag"], "cannot write"),
    ("interactive without a terminal", ["run", "--interactive"], "needs a terminal"),
    # the recording: checked before the design is built
    (
        "recording where nothing can be written",
        ["run", "--rerun", "save:/proc/r.rrd"],
        "cannot write",
    ),
    ("recording below a file", ["run", "--rerun", "save:{file}/r.rrd"], "not a folder"),
    ("recording to a folder", ["run", "--rerun", "save:folder.rrd"], "is a folder"),
    ("default recording below a file", ["run", "--rerun", "save"], "not a folder"),
    # a LIDAR the run cannot carry: refused at load, before the recording is opened
    (
        "lidar serial link slower than its samples",
        ["run", "--scenario", "corridor_uart", "--set", "robot.sensors.0.sample_rate=8000"],
        "need baud at least 400000",
    ),
    (
        "lidar clock slower than two edges a sample",
        ["run", "--scenario", "corridor", "--set", "sim.clock_hz=3000", "--rerun", "save:x.rrd"],
        "sim.clock_hz at least 4000",
    ),
    (
        "lidar above the ceiling",
        ["run", "--scenario", "corridor", "--set", "robot.sensors.0.height=2.6"],
        "below the ceiling",
    ),
    (
        "serving on an address not of this machine",
        ["run", "--rerun", "serve:192.0.2.1"],
        "not an address of this machine",
    ),
    # run: outputs written over one another or over an input
    (
        "summary and recording to one file",
        ["run", "--summary", "x.rrd", "--rerun", "save:x.rrd"],
        "give each output its own path",
    ),
    (
        "summary and video to one file",
        ["run", "--save-video", "v.mp4", "--summary", "v.mp4"],
        "--save-video 'v.mp4'",
    ),
    (
        "summary inside the bag",
        ["run", "--bag", "b", "--summary", "b/metadata.yaml"],
        "is inside --bag 'b'",
    ),
    ("recording inside the bag", ["run", "--bag", "b", "--rerun", "save:b/x.rrd"], "--bag 'b'"),
    ("video inside the bag", ["run", "--bag", "b", "--save-video", "b/v.mp4"], "--bag 'b'"),
    (
        "bag out over the bag source",
        ["run", "--source", "bag:{bag}", "--bag", "{bag}"],
        "the input --source",
    ),
    (
        "summary into the bag source",
        ["run", "--source", "bag:{bag}/bag.mcap", "--summary", "{bag}/s.json"],
        "the input --source",
    ),
    (
        "summary over the video source",
        ["run", "--source", "{file}", "--summary", "{file}"],
        "the input --source",
    ),
    (
        "recording into the frames source",
        ["run", "--source", "{frames}", "--rerun", "save:{frames}/r.rrd"],
        "inside the input --source",
    ),
    # a 3D scenario without the realistic extra (MuJoCo not importable)
    ("3D scenario without the realistic extra", ["run", "--scenario", "divider_3d"], "MuJoCo"),
    # export
    ("export seed without board", ["export", "--seed", "3"], "--seed"),
    (
        "board seed nextpnr refuses",
        ["board", "-o", "out", "--bitstream", "--seed", "99999999999999999999"],
        "--seed must be from -2**63",
    ),
    (
        "export board seed nextpnr refuses",
        ["export", "--board", "ulx3s-85f", "--bitstream", "--seed", str(-(2**63) - 1)],
        "--seed must be from -2**63",
    ),
    ("export bitstream without board", ["export", "--bitstream"], "--board"),
    ("export to a device", ["export", "-o", "/dev/full"], "not a regular file"),
    ("export to a folder", ["export", "-o", "{dir}"], "is a directory"),
    ("export below a file", ["export", "-o", "{file}/x.v"], "cannot write"),
    ("export bad width", ["export", "--width", "17", "-o", "x.v"], "width"),
    ("board into a file", ["export", "--board", "ulx3s-85f", "-o", "{file}"], "not a folder"),
    (
        "board seed without bitstream",
        ["board", "--board", "ulx3s-85f", "--seed", "2", "-o", "out"],
        "--bitstream",
    ),
    ("unknown board", ["board", "--board", "nexys", "-o", "out"], "unknown board"),
    # a design of one's own on the board, mutated, proved
    (
        "board design without wheels",
        ["board", "--design", f"{DESIGNS}/counters.py:Saturating", "-o", "out"],
        "has no output 'motor_left'",
    ),
    ("board param without design", ["board", "--param", "a=1", "-o", "out"], "--param goes"),
    (
        "formal Verilog without assertions",
        ["formal", "--design", f"verilog:{DESIGNS}/bump_stop_noreset.v"],
        "no assert or cover statement",
    ),
    (
        "formal port map of an Amaranth design",
        ["formal", "--design", f"{DESIGNS}/counters.py:Saturating", "--ports", "p.toml"],
        "--ports is the port map of a Verilog design",
    ),
    (
        "mutate Verilog without its port map",
        ["mutate", "--design", f"verilog:{DESIGNS}/bump_stop_noreset.v"],
        "needs its port map",
    ),
    (
        "mutate Verilog with a parameter",
        [
            "mutate",
            "--design",
            f"verilog:{DESIGNS}/bump_stop_noreset.v",
            "--ports",
            f"{DESIGNS}/bump_stop_noreset_ports.toml",
            "--param",
            "a=1",
        ],
        "has no parameter 'a' to set",
    ),
    ("mutate port map without design", ["mutate", "--ports", "p.toml"], "--ports"),
    (
        "mutate resolution of a design without a camera",
        ["mutate", "--design", f"{DESIGNS}/counters.py:Saturating", "--resolution", "40x8"],
        "--resolution sizes the frames of a camera design's unit judge; Saturating has no",
    ),
    (
        "mutate resolution of a Verilog design without a camera",
        [
            "mutate",
            "--design",
            f"verilog:{DESIGNS}/bump_stop_noreset.v",
            "--ports",
            f"{DESIGNS}/bump_stop_noreset_ports.toml",
            "--resolution",
            "40x8",
        ],
        "bump_stop_noreset has no camera input",
    ),
    # a design parameter given twice: one parser for every command, no silent last value
    *(
        (
            f"{command} parameter given twice",
            [command, *ref, "--param", "limit=3", "--param", " limit =4", *rest],
            "--param limit is given twice; give each parameter once",
        )
        for command, ref, rest in (
            ("designs", [f"{DESIGNS}/counters.py:Saturating"], []),
            ("mutate", ["--design", f"{DESIGNS}/counters.py:Saturating"], []),
            ("export", ["--design", f"{DESIGNS}/counters.py:Saturating"], ["-o", "x.v"]),
            ("board", ["--design", f"{DESIGNS}/counters.py:Saturating"], ["-o", "out"]),
            ("formal", ["--design", f"{DESIGNS}/counters.py:Saturating"], ["--list"]),
        )
    ),
    # an empty input path is named as empty, not read as the current folder
    ("empty port map", ["ports", ""], "the port map's path is empty"),
    (
        "empty port map of a design",
        ["designs", f"verilog:{DESIGNS}/bump_stop_noreset.v", "--ports", ""],
        "the port map's path is empty",
    ),
    ("empty scenario", ["run", "--scenario", ""], "the scenario is empty"),
    ("empty campaign", ["sweep", "", "--dry-run"], "the campaign is empty"),
    ("mutate empty campaign", ["mutate", "--campaign", ""], "the campaign is empty"),
    ("empty results folder", ["sweep", "report", ""], "'' is not a folder of campaign results"),
    ("empty recording", ["readback", ""], "no recording at ''"),
    # an empty output path is refused, never taken for the default folder
    ("mutate empty out", ["mutate", "--mutants", "1", "--out", ""], "the path is empty"),
    (
        "mutate design empty out",
        ["mutate", "--design", f"{DESIGNS}/counters.py:Saturating", "--out", ""],
        "the path is empty",
    ),
    ("board empty output", ["board", "-o", ""], "the path is empty"),
    (
        "sweep empty out",
        ["sweep", "--scenarios", "approach", "--out", "", "--dry-run"],
        "--out: the path is empty",
    ),
    (
        "formal empty trace folder",
        ["formal", "--only", "color_filter.table@zero", "--trace-dir", ""],
        "the path is empty",
    ),
    # bench
    ("bench negative min-seconds", ["bench", "--min-seconds", "-5"], "--min-seconds"),
    ("bench nan min-seconds", ["bench", "design", "--min-seconds", "nan"], "--min-seconds"),
    (
        "bench json to a device",
        ["bench", "--backends", "model", "--json", "/dev/full"],
        "not a regular file",
    ),
    ("bench json to a folder", ["bench", "--backends", "model", "--json", "{dir}"], "is a folder"),
    ("pysim bench zero frames", ["bench", "pysim", "--frames", "0"], "--frames"),
    # bench options that cannot apply to the mode asked for
    (
        "bench camera noise of the sensor table",
        ["bench", "camera", "--sensor", "--noise", "3"],
        "--noise",
    ),
    (
        "bench camera stage images with figures",
        ["bench", "camera", "--stage-images", "st", "--json", "st.json"],
        "--json",
    ),
    (
        "bench camera stage images calibrated",
        ["bench", "camera", "--stage-images", "st", "--calibrate"],
        "--calibrate",
    ),
    (
        "bench render3d figures with timing options",
        ["bench", "render3d", "--figures", "fig", "--sizes", "160x120"],
        "--sizes",
    ),
    ("bench fork calibrated", ["bench", "fork", "--calibrate"], "--calibrate"),
    ("bench calibrate calibrated", ["bench", "calibrate", "--calibrate"], "--calibrate"),
    ("bench cameras unknown backend", ["bench", "cameras", "--backend", "foo"], "--backend"),
    ("bench pins infinite seconds", ["bench", "pins", "--seconds", "inf"], "--seconds"),
    ("bench pins endless seconds", ["bench", "pins", "--seconds", "1e30"], "--seconds"),
    ("bench pins infinite step", ["bench", "pins", "--step", "inf"], "--step"),
    ("bench pins infinite clock", ["bench", "pins", "--clock-hz", "inf"], "--clock-hz"),
    ("bench pins zero pysim seconds", ["bench", "pins", "--pysim-seconds", "0"], "--pysim-seconds"),
    (
        "bench pins negative pysim seconds",
        ["bench", "pins", "--pysim-seconds", "-1"],
        "--pysim-seconds",
    ),
    ("bench pins empty backends", ["bench", "pins", "--backends", ","], "--backends"),
    # benches that build FollowTarget's frame models, on a scenario of another design
    (
        "bench loop of a real-clock scenario",
        ["bench", "loop", "--scenario", "line_track"],
        "real_clock",
    ),
    ("bench loop of another design", ["bench", "loop", "--scenario", "turret"], "turret_tracker"),
    (
        "bench shadow of a real-clock scenario",
        ["bench", "shadow", "--scenario", "corridor"],
        "corridor_follow",
    ),
    (
        "bench mutant_replay of a real-clock scenario",
        ["bench", "mutant_replay", "--scenario", "obstacle_between"],
        "follow_target_safe",
    ),
]


#: Cases run as if the ``realistic`` extra were not installed.
WITHOUT_MUJOCO = {"3D scenario without the realistic extra"}
#: Cases run where ``runs`` (the default recordings' folder) is a file.
RUNS_IS_A_FILE = {"default recording below a file"}


def _snapshot(folder):
    return sorted(
        (str(p.relative_to(folder)), p.stat().st_size if p.is_file() else -1)
        for p in folder.rglob("*")
    )


def _float_image_bag(path, n):
    """A ROS 2 bag of ``n`` 32FC1 images on /cam (an encoding the design cannot take)."""
    from rosbags.rosbag2 import StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    T = store.types
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        conn = writer.add_connection("/cam", "sensor_msgs/msg/Image", typestore=store)
        for k in range(n):
            msg = T["sensor_msgs/msg/Image"](
                header=T["std_msgs/msg/Header"](
                    stamp=T["builtin_interfaces/msg/Time"](sec=k, nanosec=0), frame_id=""
                ),
                height=2,
                width=2,
                encoding="32FC1",
                is_bigendian=0,
                step=8,
                data=np.zeros(16, np.uint8),
            )
            writer.write(conn, k + 1, store.serialize_cdr(msg, "sensor_msgs/msg/Image"))
    return path


@pytest.fixture
def busy_port():
    """A port on 127.0.0.1 that something listens on."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        yield s.getsockname()[1]


@pytest.mark.parametrize("case, argv, word", CASES, ids=[c[0] for c in CASES])
def test_bad_input_is_one_line_and_exit_2(
    case, argv, word, tmp_path, monkeypatch, capsys, busy_port
):
    import cv2

    (tmp_path / "folder").mkdir()
    (tmp_path / "file").write_text("keep me\n")
    (tmp_path / "latin1.toml").write_bytes(b"# caf\xe9\n")
    frames = tmp_path / "frames"
    frames.mkdir()
    for i in range(2):
        cv2.imwrite(str(frames / f"{i}.png"), np.full((12, 16, 3), 40 * i, np.uint8))
    names = {
        "dir": str(tmp_path / "folder"),
        "file": str(tmp_path / "file"),
        "latin1": str(tmp_path / "latin1.toml"),
        "frames": str(frames),
        "bag": str(_float_image_bag(tmp_path / "bag", 2)),
        "emptybag": str(_float_image_bag(tmp_path / "emptybag", 0)),
        "busyport": str(busy_port),
    }
    argv = [a.format(**names) for a in argv]
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.rrd").mkdir()
    if case in RUNS_IS_A_FILE:
        (tmp_path / "runs").write_text("keep me\n")
    monkeypatch.setattr(sys, "stdin", io.StringIO())  # no terminal
    if case in WITHOUT_MUJOCO:
        monkeypatch.setitem(sys.modules, "mujoco", None)  # `import mujoco` fails
    builds = _forbid_builds(monkeypatch)
    before = _snapshot(tmp_path)

    with pytest.raises(SystemExit) as exit_info:
        cli.main(argv)

    out, err = capsys.readouterr()
    assert exit_info.value.code == 2, err
    assert out == "", f"printed before the error: {out!r}"
    assert "Traceback" not in err
    lines = [line for line in err.splitlines() if line.strip()]
    assert "error:" in lines[-1] and word in lines[-1], err
    # One line, or argparse's usage block first and the one error line last.
    assert len(lines) == 1 or (
        lines[0].startswith("usage:") and sum("error:" in line for line in lines) == 1
    ), err
    assert _snapshot(tmp_path) == before
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)
    assert builds == [], f"a simulator was started before the error: {builds}"


def _forbid_builds(monkeypatch):
    """Record (and refuse) every start of a design simulator but the numpy model's."""
    from fpga_robotics.cli import run
    from fpga_robotics.loop import compressed, real_clock
    from fpga_robotics.sim.backends import foreign, foreign_choice

    builds = []
    real_make_backend = compressed.make_backend

    def make_backend(name, *args, **kwargs):
        if name == "model":
            return real_make_backend(name, *args, **kwargs)
        builds.append(("make_backend", name))
        raise RuntimeError("no simulator may start in a bad-input case")

    def refuse(what):
        def start(*args, **kwargs):
            builds.append((what,))
            raise RuntimeError("no simulator may start in a bad-input case")

        return start

    # Each where it is defined and where it is imported by name.
    for module in (compressed, run):
        monkeypatch.setattr(module, "make_backend", make_backend)
    for module in (real_clock, run):
        monkeypatch.setattr(module, "make_pin_backend", refuse("make_pin_backend"))
    for module in (foreign, foreign_choice):
        monkeypatch.setattr(module, "ForeignVerilatorBackend", refuse("ForeignVerilatorBackend"))
    return builds
