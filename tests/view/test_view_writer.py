"""The view's writer: in a process of its own by default, in a thread as the fallback; a writer
that dies does not stop the run; a writer whose run's process vanished closes its recording."""

from __future__ import annotations

import io
import logging

import pytest

pytest.importorskip("rerun")

from pycram.language import par, seq  # noqa: E402
from pycram.trace.view.rrd import RecordingContents  # noqa: E402
from pycram.trace.view.session import ViewSession, _ProcessSink, _ThreadSink  # noqa: E402
from pycram.trace.view.writer import read_message, send_message, serve  # noqa: E402


def _plan() -> None:
    seq(lambda: None, lambda: par(lambda: None, lambda: None))
    logging.getLogger("pycram.test").warning("a line of the run's log")


@pytest.mark.parametrize("process", [True, False], ids=["process", "thread"])
def test_the_writer_logs_the_same_in_a_process_as_in_a_thread(tmp_path, process):
    session = ViewSession(rrd=tmp_path / "run.rrd", process=process).start()
    assert isinstance(session._sink, _ProcessSink if process else _ThreadSink)
    try:
        _plan()
    finally:
        path = session.close()
    contents = RecordingContents.read(path)
    # seq, its two steps, par and its two branches: started and ended; the thread's root task
    assert contents.rows["/tree/status"] == session.counts["task status"] == 13
    assert contents.rows["/log"] == 1
    assert session.error is None
    if process:
        assert session._sink.process.poll() == 0  # the writer ended by itself


def test_a_writer_process_that_dies_does_not_stop_the_run(tmp_path):
    session = ViewSession(rrd=tmp_path / "run.rrd").start()
    sink = session._sink
    assert isinstance(sink, _ProcessSink)
    sink.kill()
    _plan()  # the run goes on; its events have nowhere to go
    session.close(timeout=30.0)
    assert not session._thread.is_alive()
    assert session.error is not None and "Error" in session.error


def test_a_writer_whose_run_vanished_closes_its_recording(tmp_path):
    """The run's process ends without "stop" (killed): at the end of its input the writer logs
    what it has, closes the file and says "done"."""
    incoming = io.BytesIO()
    send_message(incoming, (str(tmp_path / "run.rrd"), None, "pycram-test", "a run"))
    send_message(incoming, [("log", 1.0, 1.7e9, "INFO", "pycram.test: hello"), ("log", 2.0, 1.7e9, "WARN", "bye")])
    incoming.seek(0)
    answers = io.BytesIO()
    assert serve(incoming, answers) == 0
    answers.seek(0)
    kind, counts, _, error = read_message(answers)
    assert (kind, counts["log lines"], error) == ("done", 2, None)
    assert RecordingContents.read(tmp_path / "run.rrd").rows["/log"] == 2


def test_an_unknown_event_is_reported_once_and_logging_goes_on(tmp_path):
    incoming = io.BytesIO()
    send_message(incoming, (str(tmp_path / "run.rrd"), None, "pycram-test", "a run"))
    send_message(incoming, [("nonsense",), ("nonsense",), ("log", 1.0, 1.7e9, "INFO", "after")])
    send_message(incoming, "stop")
    incoming.seek(0)
    answers = io.BytesIO()
    serve(incoming, answers)
    answers.seek(0)
    _, counts, _, error = read_message(answers)
    assert error == "ValueError: unknown view event 'nonsense'"
    assert counts["log lines"] == 1


def test_ctrl_c_does_not_kill_the_writer_before_the_run_closes_it(tmp_path):
    """The writer runs in a session of its own (a terminal's Ctrl-C reaches the run, not the
    writer) and ignores SIGINT: the run, interrupted, still closes a whole recording."""
    import os
    import signal

    import mujoco

    model = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body name='b'><geom size='.1'/></body></worldbody></mujoco>"
    )
    session = ViewSession(rrd=tmp_path / "run.rrd").start()
    sink = session._sink
    assert os.getsid(sink.process.pid) != os.getsid(0)
    sink.send([("attach", model, "b", [], None, "a robot", None)])
    sink.wait_ready()  # (the writer is up: its signal handling is in place)
    os.kill(sink.process.pid, signal.SIGINT)
    _plan()
    session.close()
    assert session.error is None and sink.process.returncode == 0
    assert RecordingContents.read(tmp_path / "run.rrd").rows["/tree/status"] == 13
