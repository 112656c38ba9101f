"""``aeroexec report RUN_DIR --autopilot-log FILE`` (issue 46): the autopilot's own log — a PX4 ULog or an ArduPilot
DataFlash log — drawn on the mission's clock beside the behaviors.

The flights are real MAVSDK flights against ``aeroexec sim --logs`` in both personalities, at real time as an
autopilot flies; the vehicle writes its log on its own boot clock and GPS time, the run's event log keeps its wall
clock to the millisecond, so the true shift between the two clocks is known and the report's alignment (found from
the motion alone) is checked against it. Real logs of PX4 and ArduPilot (tests/export/data/autopilot_logs/
SOURCES.md) prove the readers read what the autopilots write.
"""

from __future__ import annotations

import datetime
import gzip
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest
from aeroexec.cli.reporting.autopilot_chart import autopilot_figure
from aeroexec.cli.reporting.autopilot_log import AutopilotLogError, align, read_autopilot_log
from aeroexec.cli.reporting.labels import drawn_texts, overlaps
from aeroexec.flight.journal import read_records
from aeroexec.flight.summary import summarize
from free_ports import free_udp_port
from patience import hang_guard
from pymavlink import DFReader
from pyulog import ULog

ROOT = Path(__file__).parents[2]
DATA = Path(__file__).parent / "data" / "autopilot_logs"
FIGURE10 = ROOT / "missions" / "figure10.py"
ALIGNED = re.compile(r"boot time = engine time \+ (-?[\d.]+) s \(([\d.]+) m RMS over (\d+) positions\)")


def aeroexec(*argv: str, cwd: Path, timeout: float = 120.0) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "aeroexec.cli.main", *argv], capture_output=True, text=True,
                          cwd=cwd, timeout=hang_guard(timeout))


@pytest.fixture(scope="module", params=["px4", "ardupilot"])
def flown(request, tmp_path_factory):
    """figure10.py flown through MAVSDK against ``aeroexec sim --logs`` at real time: (run folder, the vehicle's
    log file, autopilot)."""
    autopilot = request.param
    folder = tmp_path_factory.mktemp(autopilot)
    port = free_udp_port()
    sim = subprocess.Popen([sys.executable, "-m", "aeroexec.cli.main", "sim", "--autopilot", autopilot,
                            "--connect", f"udpout://127.0.0.1:{port}", "--logs", str(folder / "vehicle")],
                           stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, cwd=folder)
    try:
        result = aeroexec("run", str(FIGURE10), "--drone", f"mavsdk:udpin://127.0.0.1:{port}", "--output",
                          str(folder / "run"), "--quiet", cwd=folder, timeout=150)
    finally:
        sim.terminate()
        sim.wait(timeout=hang_guard(10))
    assert result.returncode == 0, result.stderr
    logs = sorted((folder / "vehicle").rglob("*.ulg" if autopilot == "px4" else "*.BIN"))
    assert len(logs) == 1, f"one arming, one log: {logs}"
    return folder / "run", logs[0], autopilot


def true_shift(run: Path, log: Path) -> float:
    """Seconds from the engine's clock to the vehicle's boot clock, from the two wall clocks (the run's start to the
    millisecond, the vehicle's GPS time: both read this machine's clock)."""
    first = json.loads((run / "events.jsonl").read_text().splitlines()[0])
    engine_zero = datetime.datetime.fromisoformat(first["wall_time"]).timestamp() - first["time"]
    if log.suffix == ".ulg":
        gps = ULog(str(log), ["vehicle_gps_position"]).get_dataset("vehicle_gps_position").data
        boot_utc = gps["time_utc_usec"][0] / 1e6 - gps["timestamp"][0] / 1e6
    else:
        reader = DFReader.DFReader_binary(str(log))
        fix = reader.recv_match(type="GPS")
        gps_s = fix.GWk * 7 * 86400 + fix.GMS / 1000.0
        boot_utc = gps_s + datetime.datetime(1980, 1, 6, tzinfo=datetime.UTC).timestamp() - 18 - fix.TimeUS / 1e6
    return engine_zero - boot_utc


def engine_period(run: Path) -> float:
    for line in (run / "events.jsonl").read_text().splitlines():
        record = json.loads(line)
        if record["kind"] == "engine_started":
            return 1.0 / float(re.search(r"([\d.]+) Hz", record["detail"]).group(1))
    raise AssertionError("no engine_started")


def test_the_vehicle_writes_the_log_its_autopilot_would_from_arming_to_disarming(flown):
    run, log, autopilot = flown
    read = read_autopilot_log(log)
    assert read.kind == ("PX4 ULog" if autopilot == "px4" else "ArduPilot DataFlash")
    assert "aeroexec sim" in read.system  # never passed off as a flight of PX4 or ArduPilot itself
    assert [armed for _, armed in read.armed] == [True, False]
    assert max(-read.estimate[:, 2]) > 1.5  # figure10 climbs to 2 m
    modes = [mode for _, mode in read.modes]
    assert ("TAKEOFF" if autopilot == "px4" else "GUIDED") in modes and "LAND" in modes


def test_the_report_lays_the_autopilots_log_on_the_missions_clock_within_one_engine_period(flown, tmp_path):
    run, log, autopilot = flown
    result = aeroexec("report", str(run), "--autopilot-log", str(log), "--output", str(tmp_path), cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    found = ALIGNED.search(result.stderr)
    assert found, result.stderr
    shift, rms, positions = found.groups()
    truth = true_shift(run, log)
    assert abs(float(shift) - truth) <= engine_period(run), f"{shift} s found, {truth:.4f} s true\n{result.stderr}"
    assert float(rms) < 0.5 and int(positions) >= 10
    assert (tmp_path / "autopilot.png").stat().st_size > 10_000
    page = (tmp_path / "report.html").read_text()
    assert "autopilot.png" in page or "The autopilot" in page


def test_no_two_texts_of_the_autopilot_chart_overlap_nor_leave_the_image(flown):
    run, log, _ = flown
    summary = summarize(read_records(run / "events.jsonl"))
    read = read_autopilot_log(log)
    figure = autopilot_figure(summary, read, align(read, summary))
    assert overlaps(figure) == []
    renderer = figure.canvas.get_renderer()
    texts = [text.get_text() for text in drawn_texts(figure)]
    assert {"TAKE_OFF", "GO_TO_POINT", "LAND", "modes"} <= set(texts)
    for text in drawn_texts(figure):
        extent = text.get_window_extent(renderer)
        assert figure.bbox.x0 - 1 <= extent.x0 and extent.x1 <= figure.bbox.x1 + 1, text.get_text()


def test_a_real_px4_sitl_ulog_is_read(tmp_path):
    unpacked = tmp_path / "sample_px4_events.ulg"
    unpacked.write_bytes(gzip.decompress((DATA / "sample_px4_events.ulg.gz").read_bytes()))
    log = read_autopilot_log(unpacked)
    assert log.kind == "PX4 ULog" and log.system == "PX4"
    assert [armed for _, armed in log.armed] == [False, True, False]  # armed by command, disarmed after landing
    assert [mode for _, mode in log.modes][:4] == ["HOLD", "TAKEOFF", "HOLD", "RETURN"]
    assert 2.0 < max(-log.estimate[:, 2]) < 3.0  # PX4's default take-off height is 2.5 m
    assert len(log.setpoint) and len(log.setpoint) == len(log.setpoint_time)


def test_a_real_ardupilot_dataflash_log_is_read():
    log = read_autopilot_log(DATA / "arduplane_test.BIN")
    assert log.kind == "ArduPilot DataFlash" and log.system.startswith("ArduPlane V3.8.2")
    assert log.modes and log.modes[0][1] == "MANUAL"  # Plane's mode 0, named by the vehicle the log says
    assert len(log.time) > 10 and abs(log.estimate[0][0] - 0.93) < 0.01  # NKF1's PN, EKF2 as 3.8 logs it


def test_a_log_of_another_flight_or_no_log_at_all_is_one_clear_line(flown, tmp_path):
    run, _, _ = flown
    other = aeroexec("report", str(run), "--autopilot-log", str(DATA / "arduplane_test.BIN"), "--output",
                     str(tmp_path), cwd=tmp_path)
    assert other.returncode == 1
    assert "does not match this run's flight" in other.stderr and "Traceback" not in other.stderr
    text = tmp_path / "notes.txt"
    text.write_text("not a log\n")
    wrong = aeroexec("report", str(run), "--autopilot-log", str(text), "--output", str(tmp_path), cwd=tmp_path)
    assert wrong.returncode == 1
    assert wrong.stderr.strip().splitlines()[-1] == (
        f"{text}: not an autopilot log this report reads (expected a PX4 ULog .ulg or an ArduPilot DataFlash .bin)")
    with pytest.raises(AutopilotLogError, match="cannot read"):
        read_autopilot_log(tmp_path / "missing.ulg")


def test_a_position_that_came_before_the_engines_clock_started_is_stamped_on_the_engines_clock():
    """The adapter stamps what comes before the engine's first tick on the monotonic clock; once the engine's clock
    starts, the position's time moves to it, or the first state lines would say it was measured hours away."""
    from aeroexec.drones.mavsdk.telemetry_cache import TelemetryCache

    now = {"t": 5000.0}  # the monotonic clock, before the engine's clock starts
    cache = TelemetryCache(lambda: now["t"])
    cache.set(position=(47.0, 8.0, 500.0), home=(47.0, 8.0, 500.0))
    cache.retime(lambda stamp: 0.0 - (5000.2 - stamp))  # the engine starts 0.2 s later at engine time 0
    assert cache.snapshot().position_time == pytest.approx(-0.2)
